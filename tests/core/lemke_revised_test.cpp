// Lemke on its factored basis (core/src/pivoting/lemke_revised.hpp): against constructed solutions,
// against the dense tableau on random small problems (degenerate ones included, for the
// lexicographic rule), the Siconos corpus, large banded LCPs the tableau cannot hold, and
// findex problems with the friction passes' warm start. LemkeSolver::denseRows = 0 forces the
// factored basis at every size.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "bench/banded_lcp.hpp"
#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp {
namespace {

using test::Generator;
using test::KnownProblem;

Result solveWith(const Problem& p, Vector& x, bool factored, const Options& opt = Options(),
                 int period = 50) {
  LemkeSolver lemke;
  lemke.setOptions(opt);
  lemke.denseRows = factored ? 0 : p.size();
  lemke.refactorPeriod = period;
  const Result r = lemke.solve(p, x);
  if (r.converged()) {
    EXPECT_LE(residual(p, x), opt.tolerance);
  }
  return r;
}

TEST(LemkeFactored, SeedExampleTakesTheSamePivots) {
  const Problem p = test::seedLemkeExample();
  Vector x;
  const Result r = solveWith(p, x, true);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.iterations, 3);
  EXPECT_NEAR(x[0], 20.0 / 19, 1e-14);
  EXPECT_NEAR(x[1], 21.0 / 19, 1e-14);
  EXPECT_NEAR(x[2], 0.0, 1e-14);
}

// Random SPD and P-matrix LCPs: the unique solution, and the tableau's pivot count (the same
// rules on the same columns).
TEST(LemkeFactored, AgreesWithTheTableauOnRandomProblems) {
  Generator g(41);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + g.pick(40);
    DenseMatrix A = g.spd(n);
    if (trial % 2 == 1) {
      DenseMatrix S = g.spd(n, 0) - g.spd(n, 0);
      A += 0.5 * (S - S.transpose());
    }
    const KnownProblem kp = g.standard(A);
    Vector xd, xf;
    const Result d = solveWith(kp.problem, xd, false);
    const Result f = solveWith(kp.problem, xf, true, Options(), 1 + trial % 7);
    ASSERT_EQ(f.status, Status::Converged) << "trial " << trial << ": " << f.message;
    EXPECT_EQ(f.iterations, d.iterations) << "trial " << trial;
    EXPECT_LT((xf - kp.solution).lpNorm<Eigen::Infinity>(), 1e-9) << "trial " << trial;
  }
}

// Degenerate problems (exact ties in the ratio test): the lexicographic rule on rows of B^-1
// from solves with B' ends each one, with the tableau's pivots.
TEST(LemkeFactored, DegenerateTiesFollowTheTableau) {
  std::vector<Problem> problems;
  DenseMatrix murty = DenseMatrix::Zero(6, 6);
  for (int i = 0; i < 6; ++i) {
    murty(i, i) = 1;
    for (int j = 0; j < i; ++j) murty(i, j) = 2;
  }
  problems.emplace_back(murty, -Vector::Ones(6));
  problems.emplace_back(DenseMatrix::Ones(4, 4), -Vector::Ones(4));
  DenseMatrix deg(3, 3);
  deg << 1, 2, 0, 0, 1, 2, 2, 0, 1;
  problems.emplace_back(deg, Vector((Vector(3) << -1, 0, -1).finished()));
  Generator g(11);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 3 + g.pick(10);
    problems.push_back(g.standard(g.psdSingular(n, std::max(1, n / 2)), true).problem);
  }
  int samePivots = 0;
  for (size_t k = 0; k < problems.size(); ++k) {
    Vector xd, xf;
    const Result d = solveWith(problems[k], xd, false);
    const Result f = solveWith(problems[k], xf, true, Options(), 3);
    EXPECT_EQ(f.status, Status::Converged) << "problem " << k << ": " << f.message;
    EXPECT_LE(residual(problems[k], xf), 1e-10) << "problem " << k;
    samePivots += f.iterations == d.iterations;
  }
  // The first three have exact integer data: their ties are exact and decided alike.
  EXPECT_GE(samePivots, static_cast<int>(problems.size()) - 2);
}

TEST(LemkeFactored, BoxedAndEqualityRowsAreSplitNotEliminated) {
  Generator g(5);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + g.pick(25);
    const KnownProblem kp = trial % 5 == 4 ? g.linear(g.spd(n)) : g.boxed(g.spd(n));
    Vector x;
    const Result r = solveWith(kp.problem, x, true);
    ASSERT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    EXPECT_LT((x - kp.solution).lpNorm<Eigen::Infinity>(), 1e-9) << "trial " << trial;
  }
}

TEST(LemkeFactored, InfeasibleEndsOnARay) {
  DenseMatrix M(3, 3);
  M << 0, -1, -1, 1, 0, 0, -1, 0, 0;
  Vector x;
  const Result r = solveWith(Problem(M, Vector((Vector(3) << -1e-4, -1, 1).finished())), x, true);
  EXPECT_EQ(r.status, Status::Failed) << r.message;
  EXPECT_NE(r.message.find("ray termination"), std::string::npos) << r.message;
}

// The Siconos corpus: the factored basis ends every file as the tableau does.
TEST(LemkeFactored, SiconosCorpusAsTheTableau) {
  const std::filesystem::path dir = std::filesystem::path(MLCP_SICONOS_DIR) / "lcp";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".dat") continue;
    ++files;
    const Problem p = io::readSiconosLcp(entry.path().string());
    Vector xd, xf;
    const Result d = solveWith(p, xd, false);
    const Result f = solveWith(p, xf, true);
    EXPECT_EQ(f.status, d.status) << entry.path().filename() << ": " << f.message;
  }
  EXPECT_GE(files, 20);
}

// A 3000-row banded LCP (refused by the tableau's former row limit): the known solution to
// 1e-9, with a short refactorization period to exercise the eta file and the drift check.
TEST(LemkeFactored, BandedLcpOf3000RowsHasItsKnownSolution) {
  const test::BandedLcp lcp = test::bandedSpdLcp(3000, 2, 7);
  for (int period : {5, 50}) {
    LemkeSolver lemke;
    lemke.refactorPeriod = period;
    lemke.options().tolerance = 1e-9;
    Vector x;
    const Result r = lemke.solve(lcp.problem, x);
    ASSERT_EQ(r.status, Status::Converged) << r.message;
    EXPECT_LE(r.residual, 1e-9);
    EXPECT_LT((x - lcp.solution).lpNorm<Eigen::Infinity>(), 1e-9) << "period " << period;
  }
}

// Friction passes on the factored basis, warm from the previous pass's basis: they converge as
// often as the tableau's cold passes, or say why not.
TEST(LemkeFactored, FrictionPassesWarmStart) {
  Generator g(9);
  int converged = 0, tableauConverged = 0;
  const int trials = 30;
  for (int trial = 0; trial < trials; ++trial) {
    const KnownProblem kp = g.friction(1 + g.pick(6));
    Options opt;
    opt.tolerance = 1e-9;
    opt.maxIterations = 100;
    Vector x, xd;
    const Result r = solveWith(kp.problem, x, true, opt);
    tableauConverged += solveWith(kp.problem, xd, false, opt).converged();
    if (r.converged()) {
      ++converged;
    } else {
      EXPECT_TRUE(r.status == Status::MaxIterations || r.status == Status::Failed)
          << toString(r.status);
      EXPECT_FALSE(r.message.empty());
    }
  }
  EXPECT_GE(converged, tableauConverged - 1);
  EXPECT_GE(converged, trials * 9 / 10);
}

}  // namespace
}  // namespace mlcp
