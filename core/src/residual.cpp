#include "mlcp/residual.hpp"

#include <algorithm>
#include <cmath>

namespace mlcp {

Accuracy accuracy(const Vector& x, const Vector& w, const Vector& lo, const Vector& hi,
                  const std::vector<int>& findex, double bInfNorm) {
  AccuracyAccumulator a;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const int f = findex.empty() ? -1 : findex[i];
    if (!a.add(x[i], w[i], lo[i], hi[i], f, x.data())) break;
  }
  return a.result(bInfNorm);
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
