// Lemke's factored basis on the generated stress family (tests/bench/banded_lcp.hpp): sparse
// banded and block-sparse P-matrix and SPD LCPs with constructed solutions and findex contact
// problems, at the sizes a test affords (lemke_bench runs them to 50,000 rows), and the check
// that sees a wrong basis before the end. Every answer is checked here, not by the solver: the
// natural-map residual from A and b, and the distance to the constructed x*.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bench/banded_lcp.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "pivoting/lemke_revised.hpp"

namespace mlcp {
namespace {

// ||x - clamp(x - w, lo', hi')||_inf / (1 + ||b||_inf), w = A x + b, a friction row's bounds
// at mu |x_normal|: the natural map, written out here.
double naturalMap(const Problem& p, const Vector& x) {
  const Vector w = p.sparseA() * x + p.b;
  double r = 0;
  for (int i = 0; i < p.size(); ++i) {
    const int j = p.findex.empty() ? -1 : p.findex[i];
    const double lo = j >= 0 ? p.lo[i] * std::abs(x[j]) : p.lo[i];
    const double hi = j >= 0 ? p.hi[i] * std::abs(x[j]) : p.hi[i];
    r = std::max(r, std::abs(x[i] - std::clamp(x[i] - w[i], lo, hi)));
  }
  return r / (1 + p.b.lpNorm<Eigen::Infinity>());
}

void expectSolved(const test::BandedLcp& lcp) {
  SCOPED_TRACE(lcp.name + ", " + std::to_string(lcp.problem.size()) + " rows");
  LemkeSolver lemke;
  lemke.options().tolerance = 1e-9;
  Vector x;
  const Result r = lemke.solve(lcp.problem, x);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(naturalMap(lcp.problem, x), 1e-9);
  if (lcp.solution.size() > 0) {
    EXPECT_LT((x - lcp.solution).lpNorm<Eigen::Infinity>(), 1e-9);
  }
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

// Findex contact problems on the block SPD matrices (friction pyramids, mu = 0.6): the friction
// passes converge to 1e-9, checked by the residual written out above.
TEST(LemkeStress, SparseContactProblemsConverge) {
  for (int n : {300, 1002})
    for (unsigned seed = 1; seed <= 3; ++seed) expectSolved(test::contactLcp(n, 100, 0.6, seed));
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
