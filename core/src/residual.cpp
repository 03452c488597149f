#include "mlcp/residual.hpp"

#include <algorithm>
#include <cmath>

namespace mlcp {

namespace {
// w's violation times the distance to the bound it points at; with an infinite bound there is
// no distance to measure and the violation is |w| itself.
double gapTimes(double bound, double x, double force, double sign) {
  if (force <= 0) return 0;
  return std::isfinite(bound) ? force * std::max(sign * (x - bound), 0.0) : force;
}
}  // namespace

Accuracy accuracy(const Vector& x, const Vector& w, const Vector& lo, const Vector& hi,
                  const std::vector<int>& findex, double bInfNorm) {
  Accuracy a;
  double r = 0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(w[i])) {
      a.finite = false;
      a.residual = a.complementarity = a.boundViolation = kInf;
      return a;
    }
    double l = lo[i], h = hi[i];
    if (!findex.empty() && findex[i] >= 0) {
      const double normal = std::abs(x[findex[i]]);
      l *= normal;
      h *= normal;
    }
    const double xi = x[i], wi = w[i];
    r = std::max(r, std::abs(xi - std::clamp(xi - wi, l, h)));
    const double cLo = gapTimes(l, xi, wi, 1.0);
    const double cHi = gapTimes(h, xi, -wi, -1.0);
    a.complementarity = std::max(a.complementarity, cLo + cHi);
    a.boundViolation = std::max({a.boundViolation, l - xi, xi - h});
  }
  a.residual = r / (1.0 + bInfNorm);
  return a;
}

Accuracy accuracy(const Problem& problem, const Vector& x, const Vector& w) {
  const double bNorm = problem.size() ? problem.b.lpNorm<Eigen::Infinity>() : 0.0;
  return accuracy(x, w, problem.lo, problem.hi, problem.findex, bNorm);
}

Accuracy accuracy(const Problem& problem, const Vector& x) {
  return accuracy(problem, x, problem.slack(x));
}

double residual(const Problem& problem, const Vector& x) { return accuracy(problem, x).residual; }

}  // namespace mlcp
