#include "mlcp/residual.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

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

namespace {
// x (and w) of another size than the problem's is a caller's error, said in one line.
void requireSize(const Problem& problem, const Vector& v, const char* what) {
  if (v.size() != problem.size())
    throw std::invalid_argument(std::string("accuracy: ") + what + " has " +
                                std::to_string(v.size()) + " entries, the problem " +
                                std::to_string(problem.size()) + " rows");
}
}  // namespace

Accuracy accuracy(const Problem& problem, const Vector& x, const Vector& w) {
  requireSize(problem, x, "x");
  requireSize(problem, w, "w");
  const double bNorm = problem.size() ? problem.b.lpNorm<Eigen::Infinity>() : 0.0;
  return accuracy(x, w, problem.lo, problem.hi, problem.findex, bNorm);
}

Accuracy accuracy(const Problem& problem, const Vector& x) {
  requireSize(problem, x, "x");
  return accuracy(problem, x, problem.slack(x));
}

double residual(const Problem& problem, const Vector& x) { return accuracy(problem, x).residual; }

double rowSumNorm(const Problem& problem) {
  if (problem.size() == 0) return 0;
  if (!problem.isSparse()) return problem.denseA().cwiseAbs().rowwise().sum().maxCoeff();
  Vector sums = Vector::Zero(problem.size());
  const SparseMatrix& A = problem.sparseA();
  for (int k = 0; k < A.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(A, k); it; ++it) sums[it.row()] += std::abs(it.value());
  return sums.maxCoeff();
}

namespace {

constexpr double kUnitRoundoff = 0x1p-53;

// Error-free transformations: a + b = s + e and a * b = p + e exactly.
void twoSum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a;
  e = (a - (s - bv)) + (b - bv);
}
void twoProduct(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// Dot2 of row i of A with x, plus b_i.
class CompensatedRow {
 public:
  explicit CompensatedRow(double b) : sum_(b) {}
  void add(double a, double x) {
    double p, ep, es;
    twoProduct(a, x, p, ep);
    twoSum(sum_, p, sum_, es);
    error_ += ep + es;
  }
  double value() const { return sum_ + error_; }

 private:
  double sum_, error_ = 0;
};

}  // namespace

Vector compensatedSlack(const Problem& problem, const Vector& x) {
  const int n = problem.size();
  std::vector<CompensatedRow> rows;
  rows.reserve(n);
  for (int i = 0; i < n; ++i) rows.emplace_back(problem.b[i]);
  if (problem.isSparse()) {
    const SparseMatrix& A = problem.sparseA();
    for (int k = 0; k < A.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(A, k); it; ++it)
        rows[it.row()].add(it.value(), x[it.col()]);
  } else {
    const DenseMatrix& A = problem.denseA();
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) rows[i].add(A(i, j), x[j]);
  }
  Vector w(n);
  for (int i = 0; i < n; ++i) w[i] = rows[i].value();
  return w;
}

Accuracy checkedAccuracy(const Problem& problem, const Vector& x, const Vector& w,
                         double tolerance) {
  const Accuracy plain = accuracy(problem, x, w);
  if (!plain.finite || problem.size() == 0) return plain;
  const double n = problem.size();
  const double gamma = (n + 1) * kUnitRoundoff / (1 - (n + 1) * kUnitRoundoff);
  const double xNorm = x.lpNorm<Eigen::Infinity>(), bNorm = problem.b.lpNorm<Eigen::Infinity>();
  const double bound = gamma * (rowSumNorm(problem) * xNorm + bNorm) +
                       3 * kUnitRoundoff * (xNorm + w.lpNorm<Eigen::Infinity>());
  // The bound itself is rounded: 1% more covers that many times over.
  if (std::abs(plain.residual - tolerance) > 1.01 * bound / (1 + bNorm)) return plain;
  return accuracy(problem, x, compensatedSlack(problem, x));
}

}  // namespace mlcp
