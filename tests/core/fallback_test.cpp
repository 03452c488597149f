// ldlt, fallback chains and auto: the fallback happens, is counted and reported.
#include "mlcp/island/fallback.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <new>
#include <string>

#include "common/broken_solvers.hpp"
#include "common/generators.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/ldlt.hpp"
#include "mlcp/solvers/pgs.hpp"

namespace mlcp {
namespace {

Problem linearSparse(int n, unsigned seed) {
  test::Generator g(seed);
  test::KnownProblem kp = g.linear(g.spd(n));
  kp.problem.setA(kp.problem.toSparse());
  return kp.problem;
}

// Writes into x, then runs out of memory, as dantzig's dense work arrays did on a 41k-row island
// (std::bad_alloc ended `mlcp run`).
class OutOfMemorySolver : public Solver {
 public:
  const char* name() const override { return "test-oom"; }

 protected:
  void run(const Problem&, Vector& x, Result&) override {
    x.setConstant(1e300);
    throw std::bad_alloc();
  }
};

TEST(Solver, DantzigBadAllocOnHugeIslandIsAFailureNotACrash) {
  const Problem p = linearSparse(20, 3);
  OutOfMemorySolver oom;
  Vector x;
  const Result r = oom.solve(p, x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("out of memory for 20 rows"), std::string::npos) << r.message;
  ASSERT_EQ(x.size(), 20);
  EXPECT_EQ(x, Vector::Zero(20));  // the start, not the half-written iterate
  const Vector guess = Vector::Constant(20, 0.5);
  oom.solveWithGuess(p, guess, x);
  EXPECT_EQ(x, guess);
}

TEST(Ldlt, SolvesSymmetricAndNonSymmetricSystems) {
  LdltSolver ldlt;
  Vector x;
  const Problem p = linearSparse(40, 1);
  Result r = ldlt.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(residual(p, x), 1e-13);
  EXPECT_EQ(r.iterations, 1);

  DenseMatrix A(3, 3);
  A << 4, 1, 0, 2, 5, 1, 0, 3, 6;  // not symmetric
  Problem q(A, Vector::Constant(3, -1.0));
  q.lo.setConstant(-kInf);
  q.hi.setConstant(kInf);
  r = ldlt.solve(q, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NE(r.message.find("LU"), std::string::npos);
  EXPECT_LE((A * x - Vector::Ones(3)).lpNorm<Eigen::Infinity>(), 1e-13);
}

TEST(Ldlt, ReusesTheSymbolicAnalysisWhileThePatternHolds) {
  LdltSolver ldlt;
  Vector x;
  Problem p = linearSparse(30, 2);
  ASSERT_TRUE(ldlt.solve(p, x).converged());
  SparseMatrix scaled = p.sparseA() * 2.0;  // same pattern, new values
  p.setA(scaled);
  ASSERT_TRUE(ldlt.solve(p, x).converged());
  EXPECT_EQ(ldlt.analyses(), 1);
  ASSERT_TRUE(ldlt.solve(linearSparse(31, 3), x).converged());
  EXPECT_EQ(ldlt.analyses(), 2);
}

TEST(Ldlt, RefusesBoundsAndReportsSingularSystems) {
  LdltSolver ldlt;
  Vector x;
  EXPECT_EQ(ldlt.solve(test::seedLemkeExample(), x).status, Status::Unsupported);
  DenseMatrix A = DenseMatrix::Zero(2, 2);
  A(0, 0) = 1;
  Problem singular(A, Vector::Ones(2));
  singular.lo.setConstant(-kInf);
  singular.hi.setConstant(kInf);
  const Result r = ldlt.solve(singular, x);
  EXPECT_FALSE(r.converged());
  // x_1 has no effect and row 1 says 0 = 1: the least-squares answer, x_1 = 0 by minimum norm.
  EXPECT_EQ(r.status, Status::LeastSquares) << r.message;
  EXPECT_NEAR(x[0], -1, 1e-9);
  EXPECT_EQ(x[1], 0);
  EXPECT_NEAR(r.residual, 1.0 / 2.0, 1e-9);
}

using test::BrokenSolver;

FallbackSolver chainWith(std::unique_ptr<Solver> primary) {
  std::vector<std::unique_ptr<Solver>> chain;
  chain.push_back(std::move(primary));
  chain.push_back(std::make_unique<PgsSolver>());
  return FallbackSolver(std::move(chain));
}

TEST(Fallback, NaNFromThePrimaryFallsBackAndIsCounted) {
  FallbackSolver chain = chainWith(std::make_unique<BrokenSolver>(true));
  test::Generator g(4);
  const test::KnownProblem kp = g.friction(5);
  Vector x;
  const Result r = chain.solve(kp.problem, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(r.fallbacks, 1);
  EXPECT_EQ(r.solver, "pgs");
  EXPECT_NE(r.message.find("test-nan: numerical-issue"), std::string::npos) << r.message;
  EXPECT_LE(residual(kp.problem, x), 1e-10);
}

TEST(Fallback, AFailingPrimaryFallsBack) {
  FallbackSolver chain = chainWith(std::make_unique<BrokenSolver>(false));
  EXPECT_EQ(chain.name(), std::string("test-fail>pgs"));
  test::Generator g(5);
  const test::KnownProblem kp = g.boxed(g.spd(10));
  Vector x;
  const Result r = chain.solve(kp.problem, x);
  ASSERT_TRUE(r.converged());
  EXPECT_EQ(r.fallbacks, 1);
  EXPECT_NE(r.message.find("injected failure"), std::string::npos) << r.message;
}

TEST(Fallback, NothingConvergesSaysSoAndKeepsTheBestAnswer) {
  std::unique_ptr<Solver> chain = makeSolver("gs>pgs");
  ASSERT_TRUE(chain);
  chain->options().maxIterations = 1;
  test::Generator g(6);
  const test::KnownProblem kp = g.boxed(g.spd(30, 0.01));
  Vector x;
  const Result r = chain->solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::MaxIterations);
  EXPECT_EQ(r.fallbacks, 2);
  EXPECT_EQ(r.solver, "pgs");
  EXPECT_NE(r.message.find("no answer acceptable"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("gs: unsupported"), std::string::npos) << r.message;
  EXPECT_EQ(x.size(), 30);
}

// Answers the start (zeros) and claims Converged: a lying member.
class ClaimsConverged : public Solver {
 public:
  const char* name() const override { return "test-liar"; }

 protected:
  void run(const Problem&, Vector&, Result& result) override { result.status = Status::Converged; }
};

// A chain's member is run without a second validation; its answer is still checked against the
// problem, once, so a false Converged is caught and the next member answers.
TEST(Fallback, AMemberThatClaimsConvergedIsCheckedAndFallsBack) {
  FallbackSolver chain = chainWith(std::make_unique<ClaimsConverged>());
  test::Generator g(9);
  const Problem p(g.spd(10), -Vector::Ones(10));
  Vector x;
  for (int repeat = 0; repeat < 2; ++repeat) {  // the second with the kept workspaces
    const Result r = chain.solve(p, x);
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_EQ(r.fallbacks, 1);
    EXPECT_NE(r.message.find("test-liar: failed"), std::string::npos) << r.message;
    EXPECT_LE(residual(p, x), 1e-6);
  }
}

TEST(Fallback, UnknownMemberIsAClearError) {
  std::string error;
  EXPECT_FALSE(makeSolver("pgs>nosuch", &error));
  EXPECT_NE(error.find("unknown solver 'nosuch'"), std::string::npos) << error;
}

TEST(Auto, ChoosesByProblemClass) {
  std::unique_ptr<Solver> solver = makeSolver("auto");
  Vector x;
  Result r = solver->solve(linearSparse(20, 7), x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(r.solver, "ldlt");
  EXPECT_NE(r.message.find("linear"), std::string::npos);

  test::Generator g(8);
  r = solver->solve(g.friction(4).problem, x);
  EXPECT_TRUE(r.converged()) << r.message;
  EXPECT_NE(r.message.find("findex"), std::string::npos) << r.message;

  r = solver->solve(Problem(DenseMatrix(0, 0), Vector(0)), x);
  EXPECT_TRUE(r.converged());
}

// Data from outside enters through Solver::solve, which validates it however deep the chain
// behind it: a NaN in A is one line of InvalidInput and x is left as it was.
TEST(Auto, InvalidInputIsRejectedAndLeavesXUntouched) {
  AutoSolver solver;
  test::Generator g(10);
  DenseMatrix A = g.spd(6);
  A(2, 3) = std::nan("");
  Vector x = Vector::Constant(6, 7.0);
  const Result r = solver.solve(Problem(A, -Vector::Ones(6)), x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(r.message.find('\n'), std::string::npos) << r.message;
  EXPECT_EQ(x, Vector::Constant(6, 7.0));
}

// auto remembers its last choice's chain; a policy changed between solves is still obeyed.
TEST(Auto, ARepeatSolveAfterAPolicyChangeTakesTheNewChain) {
  AutoSolver solver;
  test::Generator g(11);
  const Problem p(g.spd(10), -Vector::Ones(10));
  Vector x;
  Result r = solver.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NE(r.message.find("-> dantzig>pgs"), std::string::npos) << r.message;
  solver.policy.smallContactRows = 0;
  r = solver.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NE(r.message.find("-> " + solver.policy.largeIslandSolver + ">pgs"), std::string::npos)
      << r.message;
}

}  // namespace
}  // namespace mlcp
