// gs and pgs specifics: refusals, divergence, SOR, warm start, history, time budget.
#include "mlcp/solvers/pgs.hpp"

#include <gtest/gtest.h>

#include "common/generators.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

Problem linearProblem(DenseMatrix A, Vector b) {
  Problem p(std::move(A), std::move(b));
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  return p;
}

TEST(GaussSeidel, SolvesALinearSystem) {
  DenseMatrix A(2, 2);
  A << 4, 1, 1, 3;
  const Problem p = linearProblem(A, Vector::Constant(2, -1.0));
  GaussSeidelSolver gs;
  Vector x;
  const Result r = gs.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE((A * x - Vector::Constant(2, 1.0)).lpNorm<Eigen::Infinity>(), 1e-9);
}

TEST(GaussSeidel, ReportsDivergence) {
  // Not diagonally dominant and indefinite: the sweep's iteration matrix has spectral radius > 1.
  DenseMatrix A(2, 2);
  A << 1, 3, 3, 1;
  const Problem p = linearProblem(A, Vector::Constant(2, -1.0));
  GaussSeidelSolver gs;
  gs.options().maxIterations = 1000;
  Vector x;
  const Result r = gs.solve(p, x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("diverged"), std::string::npos) << r.message;
  EXPECT_LT(r.iterations, 1000);
}

TEST(GaussSeidel, RefusesZeroAndNegativeDiagonals) {
  DenseMatrix A(2, 2);
  A << 0, 1, 1, 2;
  GaussSeidelSolver gs;
  Vector x;
  Result r = gs.solve(linearProblem(A, Vector::Ones(2)), x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("A(0,0) = 0"), std::string::npos) << r.message;
  A(0, 0) = -1;
  r = gs.solve(linearProblem(A, Vector::Ones(2)), x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("A(0,0) = -1"), std::string::npos) << r.message;
}

TEST(GaussSeidel, RefusesBoundedRows) {
  GaussSeidelSolver gs;
  Vector x;
  const Result r = gs.solve(test::seedLemkeExample(), x);
  EXPECT_EQ(r.status, Status::Unsupported);
  EXPECT_NE(r.message.find("use pgs"), std::string::npos);
}

TEST(Pgs, RefusesTheSeedExample) {
  PgsSolver pgs;
  Vector x = Vector::Constant(3, 7.0);
  const Result r = pgs.solve(test::seedLemkeExample(), x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("A(2,2) = 0"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("positive diagonal"), std::string::npos);
}

TEST(Pgs, MaxIterationsIsNotConvergence) {
  test::Generator g(1);
  const test::KnownProblem kp = g.boxed(g.spd(40, 0.01));
  PgsSolver pgs;
  pgs.options().maxIterations = 2;
  Vector x;
  const Result r = pgs.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::MaxIterations);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_GT(residual(kp.problem, x), pgs.options().tolerance);
}

TEST(Pgs, OverRelaxationChangesTheIterationCount) {
  test::Generator g(2);
  const test::KnownProblem kp = g.standard(g.spd(30, 0.02));
  PgsSolver plain, sor;
  plain.options().maxIterations = sor.options().maxIterations = 100000;
  sor.options().relaxation = 1.4;
  Vector x1, x2;
  const Result r1 = plain.solve(kp.problem, x1), r2 = sor.solve(kp.problem, x2);
  ASSERT_TRUE(r1.converged());
  ASSERT_TRUE(r2.converged());
  EXPECT_NE(r1.iterations, r2.iterations);
  EXPECT_LE((x1 - x2).lpNorm<Eigen::Infinity>(), 1e-7);
  sor.options().relaxation = 2.0;
  EXPECT_EQ(sor.solve(kp.problem, x2).status, Status::InvalidInput);
}

TEST(Pgs, WarmStartHelps) {
  test::Generator g(3);
  const test::KnownProblem kp = g.friction(10);
  PgsSolver pgs;
  pgs.options().maxIterations = 100000;
  Vector x;
  const Result cold = pgs.solve(kp.problem, x);
  ASSERT_TRUE(cold.converged());
  Vector near = x + Vector::Constant(x.size(), 1e-6);
  pgs.options().warmStart = true;
  const Result warm = pgs.solve(kp.problem, near);
  ASSERT_TRUE(warm.converged());
  EXPECT_LT(warm.iterations, cold.iterations);
}

TEST(Pgs, HistoryRecordsEverySweep) {
  test::Generator g(4);
  const test::KnownProblem kp = g.boxed(g.spd(20));
  PgsSolver pgs;
  pgs.options().recordHistory = true;
  Vector x;
  const Result r = pgs.solve(kp.problem, x);
  ASSERT_TRUE(r.converged());
  ASSERT_EQ(static_cast<int>(r.history.size()), r.iterations);
  EXPECT_LE(r.history.back(), pgs.options().tolerance);
  EXPECT_GT(r.history.front(), r.history.back());
}

TEST(Pgs, CheckEveryStillStopsHonestly) {
  test::Generator g(5);
  const test::KnownProblem kp = g.boxed(g.spd(20));
  PgsSolver pgs;
  pgs.options().checkEvery = 7;
  Vector x;
  const Result r = pgs.solve(kp.problem, x);
  ASSERT_TRUE(r.converged());
  EXPECT_EQ(r.iterations % 7, 0);
  EXPECT_LE(residual(kp.problem, x), pgs.options().tolerance);
}

TEST(Pgs, TimeBudgetStopsTheSolve) {
  test::Generator g(6);
  const test::KnownProblem kp = g.standard(g.psdSingular(300, 30));
  PgsSolver pgs;
  pgs.options().tolerance = 1e-300;  // unreachable
  pgs.options().maxIterations = 1 << 30;
  pgs.options().timeBudget = 0.05;
  Vector x;
  const Result r = pgs.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::TimeLimit);
  EXPECT_LT(r.seconds, 5.0);
}

TEST(Pgs, FrictionBoundsHoldAtTheAnswer) {
  test::Generator g(8);
  const test::KnownProblem kp = g.friction(15);
  PgsSolver pgs;
  pgs.options().maxIterations = 100000;
  Vector x;
  ASSERT_TRUE(pgs.solve(kp.problem, x).converged());
  for (int i = 0; i < kp.problem.size(); ++i) {
    const int f = kp.problem.findex[i];
    if (f >= 0) {
      EXPECT_LE(std::abs(x[i]), kp.problem.hi[i] * x[f] + 1e-9) << "row " << i;
    }
  }
}

}  // namespace
}  // namespace mlcp
