// Lemke's factored basis on the generated stress family (tests/bench/banded_lcp.hpp): sparse
// banded and block-sparse P-matrix and SPD LCPs with constructed solutions, at the sizes a test
// affords (lemke_bench runs them to 50,000 rows), and the check that sees a wrong basis before
// the end. Every answer is checked here, not by the solver: the natural-map residual from A and
// b, and the distance to the constructed x*.
#include <gtest/gtest.h>

#include "bench/banded_lcp.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "pivoting/lemke_revised.hpp"

namespace mlcp {
namespace {

// ||x - max(x - w, 0)||_inf / (1 + ||b||_inf), w = A x + b: the standard LCP's natural map.
double naturalMap(const Problem& p, const Vector& x) {
  const Vector w = p.sparseA() * x + p.b;
  return (x - (x - w).cwiseMax(0.0)).lpNorm<Eigen::Infinity>() /
         (1 + p.b.lpNorm<Eigen::Infinity>());
}

void expectSolved(const test::BandedLcp& lcp) {
  SCOPED_TRACE(lcp.name + ", " + std::to_string(lcp.problem.size()) + " rows");
  LemkeSolver lemke;
  lemke.options().tolerance = 1e-9;
  Vector x;
  const Result r = lemke.solve(lcp.problem, x);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(naturalMap(lcp.problem, x), 1e-9);
  EXPECT_LT((x - lcp.solution).lpNorm<Eigen::Infinity>(), 1e-9);
}

TEST(LemkeStress, BandedAndBlockSparseFamiliesHaveTheirConstructedSolutions) {
  for (int n : {1000, 2000})
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const unsigned s = 100 * seed + n;
      expectSolved(test::stencil131Lcp(n, s));
      expectSolved(test::sparseBandLcp(n, 300, 8, true, s));
      expectSolved(test::sparseBandLcp(n, 300, 8, false, s));
      expectSolved(test::blockSparseLcp(n, 100, 2, true, s));
      expectSolved(test::blockSparseLcp(n, 100, 2, false, s));
    }
}

// A 5,000-row LCP with 4 on the diagonal and -1, -0.5, -0.25 at offsets 1, 7 and 131 (strictly
// diagonally dominant, SPD): at KLU's default pivot threshold (0.001) a refactorization of the
// basis returned basic values with a backward error of 0.4 and one at -1.2, and lemke ended
// "z0 left the basis" on a wrong basis (residual 0.25). With plain partial pivoting every
// refactorization is accurate and no recovery is needed.
TEST(LemkeFactored, KluDiagonalPreferenceEndedOnAWrongBasis) {
  const test::BandedLcp lcp = test::stencil131Lcp(5000, 1);
  const detail::ColumnMatrix M = lcp.problem.sparseA();
  detail::RevisedLemkeSettings settings;
  settings.maxPivots = 50 * lcp.problem.size();
  const detail::RevisedLemkeResult r = detail::revisedLemke(M, lcp.problem.b, settings);
  ASSERT_EQ(r.outcome.end, detail::LemkeEnd::Solved);
  EXPECT_EQ(r.recoveries, 0);
  EXPECT_LT((r.y - lcp.solution).lpNorm<Eigen::Infinity>(), 1e-9);
  expectSolved(lcp);
}

// The check inside the method: with the old pivot threshold forced, the inaccurate basis is
// seen at a refactorization, the run returns to the last basis checked right and ends on the
// unique answer.
TEST(LemkeFactored, AWrongBasisIsSeenAndRecoveredFrom) {
  const test::BandedLcp lcp = test::stencil131Lcp(5000, 1);
  const detail::ColumnMatrix M = lcp.problem.sparseA();
  detail::RevisedLemkeSettings settings;
  settings.maxPivots = 50 * lcp.problem.size();
  settings.basisPivotThreshold = 0.001;
  const detail::RevisedLemkeResult r = detail::revisedLemke(M, lcp.problem.b, settings);
  ASSERT_EQ(r.outcome.end, detail::LemkeEnd::Solved);
  EXPECT_GE(r.recoveries, 1);
  EXPECT_LT((r.y - lcp.solution).lpNorm<Eigen::Infinity>(), 1e-9);
}

}  // namespace
}  // namespace mlcp
