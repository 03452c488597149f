// Lemke's dense tableau against its factored basis (mlcp/solvers/lemke.hpp) in one run: standard
// LCPs with a banded SPD matrix and a known solution (banded_lcp.hpp) of several sizes, dense SPD
// ones (tests/common/generators.hpp, B B' + 0.1 n I) for the crossover on dense data, and findex
// contact problems (tests/common/generators.hpp: J J^T of a random J, friction pyramids with
// mu = 0.6). Each solve is cold and timed alone (wall clock, the best of --repeat runs); a
// path is skipped above --dense-max rows for the tableau. Prints one table row per problem and
// path: rows, seconds, pivots, status, residual, max |x - x*| where x* is known, and the
// tableau's time over the factored one's.
//
//   lemke_bench [--sizes 100,300,1000,3000,20000] [--dense-max 3000] [--repeat 3]
//               [--dense 10,30,100,300,1000] [--findex 150,600] [--period 50]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench/banded_lcp.hpp"
#include "common/generators.hpp"
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

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {100, 300, 1000, 3000, 20000}, findex = {150, 600},
                   denseSizes = {10, 30, 100, 300, 1000};
  int denseMax = 3000, repeat = 3, period = 50;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--sizes")) sizes = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--findex")) findex = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--dense")) denseSizes = parseList(argv[i + 1]);
    if (!std::strcmp(argv[i], "--dense-max")) denseMax = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--period")) period = std::atoi(argv[i + 1]);
  }
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
  return 0;
}
