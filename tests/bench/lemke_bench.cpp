// Lemke's dense tableau against its factored basis (mlcp/solvers/lemke.hpp) in one run: standard
// LCPs with a banded SPD matrix and a known solution (banded_lcp.hpp) of several sizes, dense SPD
// ones (tests/common/generators.hpp, B B' + 0.1 n I) for the crossover on dense data, and findex
// contact problems (tests/common/generators.hpp: J J^T of a random J, friction pyramids with
// mu = 0.6). Each solve is cold and timed alone (wall clock, the best of --repeat runs); a
// path is skipped above --dense-max rows for the tableau. Prints one table row per problem and
// path: rows, seconds, pivots, status, residual, max |x - x*| where x* is known, and the
// tableau's time over the factored one's.
//
// The stress family (banded_lcp.hpp: the 1/7/131 stencil, random sparse bands of bandwidth 300
// symmetric and not, 3-row blocks coupled within 100 blocks symmetric and not; --seeds seeds
// each) at the --stress sizes, factored basis only, prints a second table: the answer checked
// against the constructed x*, the time per pivot, and what KLU takes on the final basis: an
// analysis and factorization (F, a refactorization's work) and a solve (S, the least a pivot
// does). Two ratios: the time per pivot over F / P + S (P the refactorization period: a pivot's
// own solve and its share of refactoring) and over (F + S) / P. Last, findex
// contact problems on the block SPD matrices (contactLcp), checked by their residual; their KLU
// column factors the basis of the answer's x > 0 in A's columns, a proxy for the bases of their
// standard form (tangent rows split in two).
//
//   lemke_bench [--sizes 100,300,1000,3000,20000] [--dense-max 3000] [--repeat 3]
//               [--dense 10,30,100,300,1000] [--findex 150,600] [--period 50]
//               [--stress 1000,20000,50000] [--seeds 3] [--family NAME]   (NAME: a part of
//               the family's name, e.g. "stencil", "block P"; default every family)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench/banded_lcp.hpp"
#include "common/generators.hpp"
#include "linalg/sparse_lu.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace {

using namespace mlcp;

std::vector<int> parseList(const char* s) {
  std::vector<int> v;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) v.push_back(std::atoi(item.c_str()));
  return v;
}

struct Timing {
  double seconds = 0;
  Result result;
  Vector x;
};

Timing timeSolve(const Problem& p, bool dense, int repeat, int period, const Options& opt) {
  Timing best;
  best.seconds = 1e300;
  for (int k = 0; k < repeat; ++k) {
    LemkeSolver lemke;
    lemke.setOptions(opt);
    lemke.denseRows = dense ? p.size() : 0;
    lemke.refactorPeriod = period;
    Vector x;
    const double t0 = nowSeconds();
    Result r = lemke.solve(p, x);
    const double t = nowSeconds() - t0;
    if (t < best.seconds) best = {t, std::move(r), std::move(x)};
  }
  return best;
}

void row(const std::string& problem, int n, const char* path, const Timing& t,
         const Vector* solution, double ratio) {
  std::printf("| %s | %d | %s | %.4g | %d | %s | %.1e | ", problem.c_str(), n, path, t.seconds,
              t.result.iterations, toString(t.result.status), t.result.residual);
  if (solution)
    std::printf("%.1e |", (t.x - *solution).lpNorm<Eigen::Infinity>());
  else
    std::printf(" |");
  if (ratio > 0)
    std::printf(" %.2f |\n", ratio);
  else
    std::printf(" |\n");
  std::fflush(stdout);
}

void compare(const std::string& name, const Problem& p, const Vector* solution, int denseMax,
             int repeat, int period, const Options& opt) {
  const Timing revised = timeSolve(p, false, repeat, period, opt);
  if (p.size() <= denseMax) {
    const Timing dense = timeSolve(p, true, repeat, period, opt);
    row(name, p.size(), "tableau", dense, solution, 0);
    row(name, p.size(), "factored", revised, solution, dense.seconds / revised.seconds);
  } else {
    row(name, p.size(), "factored", revised, solution, 0);
  }
}

struct KluSeconds {
  double factor = -1, solve = -1;
};

// KLU on the basis of the answer x (y_j basic where x_j > 0, w_i otherwise): seconds of an
// analysis and factorization and of one solve, each the best of 3.
KluSeconds kluSeconds(const Problem& p, const Vector& x) {
  const int n = p.size();
  const SparseMatrix& A = p.sparseA();  // row-major: row j of A is column j of A'
  SparseMatrix At = A.transpose();      // rows of At: columns of A
  // B by columns is B' by rows (SparseLu's form; lemke_revised.cpp factors it the same way).
  std::vector<int> start = {0}, rows;
  std::vector<double> values;
  for (int j = 0; j < n; ++j) {
    if (x[j] > 0) {
      for (SparseMatrix::InnerIterator it(At, j); it; ++it) {
        rows.push_back(static_cast<int>(it.col()));
        values.push_back(-it.value());
      }
    } else {
      rows.push_back(j);
      values.push_back(1);
    }
    start.push_back(static_cast<int>(rows.size()));
  }
  KluSeconds best{1e300, 1e300};
  for (int k = 0; k < 3; ++k) {
    linalg::SparseLu lu;
    lu.setPivotTolerance(kLemkeBasisPivotThreshold);
    Vector y = p.b;
    const double t0 = nowSeconds();
    if (!lu.analyze(n, start, rows) || !lu.factor(values)) return {};
    const double t1 = nowSeconds();
    if (!lu.solveTransposed(y)) return {};
    const double t2 = nowSeconds();
    best.factor = std::min(best.factor, t1 - t0);
    best.solve = std::min(best.solve, t2 - t1);
  }
  return best;
}

void stress(const test::BandedLcp& lcp, int period, const Options& opt, const std::string& only) {
  if (lcp.name.find(only) == std::string::npos) return;
  const Problem& p = lcp.problem;
  const Timing t = timeSolve(p, false, 1, period, opt);
  const KluSeconds klu = kluSeconds(p, t.x);
  const double perPivot = t.seconds / std::max(1, t.result.iterations);
  // Checked here, not by the solver: the natural map from A, b and the bounds (a friction
  // row's at mu |x_normal|), and the distance to x* where it is known.
  const Vector w = p.sparseA() * t.x + p.b;
  double natural = 0;
  for (int i = 0; i < p.size(); ++i) {
    const int j = p.findex.empty() ? -1 : p.findex[i];
    const double lo = j >= 0 ? p.lo[i] * std::abs(t.x[j]) : p.lo[i];
    const double hi = j >= 0 ? p.hi[i] * std::abs(t.x[j]) : p.hi[i];
    natural = std::max(natural, std::abs(t.x[i] - std::clamp(t.x[i] - w[i], lo, hi)));
  }
  natural /= 1 + p.b.lpNorm<Eigen::Infinity>();
  char distance[32] = "";
  if (lcp.solution.size() == p.size())
    std::snprintf(distance, sizeof distance, "%.1e",
                  (t.x - lcp.solution).lpNorm<Eigen::Infinity>());
  std::printf(
      "| %s | %d | %lld | %.4g | %d | %s | %.1e | %s | %.3g | %.3g | %.3g | %.2f | %.2f |\n",
      lcp.name.c_str(), p.size(), static_cast<long long>(p.sparseA().nonZeros()), t.seconds,
      t.result.iterations, toString(t.result.status), natural, distance, perPivot * 1e3,
      klu.factor * 1e3, klu.solve * 1e3, perPivot / (klu.factor / period + klu.solve),
      perPivot / ((klu.factor + klu.solve) / period));
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {100, 300, 1000, 3000, 20000}, findex = {150, 600},
                   denseSizes = {10, 30, 100, 300, 1000};
  std::vector<int> stressSizes;
  int denseMax = 3000, repeat = 3, period = 50, seeds = 3;
  std::string family;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--sizes")) sizes = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--findex")) findex = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--dense")) denseSizes = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--dense-max")) denseMax = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--period")) period = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--stress")) stressSizes = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--seeds")) seeds = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--family")) family = argv[i + 1];
  }
  // A size of 0 leaves a list out (--sizes 0 --dense 0 --findex 0: the stress table alone).
  for (std::vector<int>* list : {&sizes, &denseSizes, &findex, &stressSizes})
    list->erase(std::remove_if(list->begin(), list->end(), [](int n) { return n <= 0; }),
                list->end());
  std::printf(
      "| problem | rows | path | seconds | pivots | status | residual | max abs(x - x*) | "
      "tableau / factored |\n|---|---|---|---|---|---|---|---|---|\n");
  Options opt;
  opt.tolerance = 1e-9;
  for (int n : sizes) {
    const test::BandedLcp lcp = test::bandedSpdLcp(n, 2, 1000u + n);
    compare("banded SPD LCP", lcp.problem, &lcp.solution, denseMax, repeat, period, opt);
  }
  for (int n : denseSizes) {
    test::Generator g(500u + n);
    const test::KnownProblem kp = g.standard(g.spd(n));
    compare("dense SPD LCP", kp.problem, &kp.solution, denseMax, repeat, period, opt);
  }
  for (int n : findex) {
    test::Generator g(35);
    const Problem p = test::frictionPyramids(test::jacobianGram(g, n, n / 5, 0), g, 0.6);
    Options f = opt;
    f.maxPivots = 10 * n;
    compare("findex contacts", p, nullptr, denseMax, 1, period, f);
  }
  if (stressSizes.empty()) return 0;
  std::printf(
      "\n| family | rows | nnz(A) | seconds | pivots | status | residual | max abs(x - x*) | "
      "ms / pivot | KLU F ms | KLU S ms | / (F/P + S) | / ((F + S)/P) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int n : stressSizes)
    for (int seed = 1; seed <= seeds; ++seed) {
      const unsigned s = 100u * seed + n;
      stress(test::stencil131Lcp(n, s), period, opt, family);
      stress(test::sparseBandLcp(n, 300, 8, true, s), period, opt, family);
      stress(test::sparseBandLcp(n, 300, 8, false, s), period, opt, family);
      stress(test::blockSparseLcp(n, 100, 2, true, s), period, opt, family);
      stress(test::blockSparseLcp(n, 100, 2, false, s), period, opt, family);
      stress(test::contactLcp(n, 100, 0.6, s), period, opt, family);
    }
  return 0;
}
