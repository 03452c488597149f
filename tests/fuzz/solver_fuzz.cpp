// libFuzzer target: every registered solver (and a fallback chain) on small problems decoded
// from the input, with small limits (50 iterations, 0.05 s) so that every solve is bounded.
//
// Input: text starting with '{' is read as mlcp-problem/1 JSON (n <= 12 kept); anything else is
// decoded as bytes: n = 1 + b0 % 8; b1's bits choose boxed bounds, friction rows, a symmetric
// A = M M^T + d I (which most solvers can solve), sparse storage; b2 a scale 10^(b2 % 25 - 12)
// of A and b3 one of b (problems scaled to 1e12 and beyond); b4 the tolerance 10^-(4 + b4 % 9);
// then A's, b's and the bounds' entries, one signed byte each (value / 16).
//
// Invariants, for every solver:
// - invalid input leaves x untouched;
// - a status of converged comes with a finite x whose residual, recomputed here independently
//   in long double (64-bit mantissa), is within the tolerance, plus the rounding bound of that
//   recomputation and of the double result's own rounding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_checks.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"

namespace {

using mlcp::Problem;
using mlcp::Vector;

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t next() { return pos_ < size_ ? data_[pos_++] : 0; }
  double entry() { return double(static_cast<std::int8_t>(next())) / 16; }

 private:
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

Problem decode(Bytes& in, double& tolerance) {
  const int n = 1 + in.next() % 8;
  const std::uint8_t flags = in.next();
  const double scale = std::pow(10.0, int(in.next() % 25) - 12);
  const double bScale = std::pow(10.0, int(in.next() % 25) - 12);
  tolerance = std::pow(10.0, -(4 + int(in.next() % 9)));
  mlcp::DenseMatrix M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) M(i, j) = in.entry();
  mlcp::DenseMatrix A = (flags & 4) ? mlcp::DenseMatrix(M * M.transpose()) : M;
  if (flags & 4) A.diagonal().array() += 0.1;
  A *= scale;
  Problem p;
  if (flags & 8)
    p.setA(mlcp::SparseMatrix(A.sparseView()));
  else
    p.setA(A);
  p.b.resize(n);
  for (int i = 0; i < n; ++i) p.b[i] = in.entry() * bScale;
  p.lo = Vector::Zero(n);
  p.hi = Vector::Constant(n, mlcp::kInf);
  if (flags & 1) {
    for (int i = 0; i < n; ++i) {
      const std::uint8_t k = in.next();
      p.lo[i] = k % 3 == 0 ? -mlcp::kInf : -std::abs(in.entry());
      p.hi[i] = k % 3 == 1 ? mlcp::kInf : std::abs(in.entry());
    }
  }
  if (flags & 2) {  // rows after the first are friction rows of row 0, mu = |entry|
    p.findex.assign(n, -1);
    for (int i = 1; i < n; ++i) {
      if (!(in.next() & 1)) continue;
      const double mu = std::abs(in.entry());
      p.findex[i] = 0;
      p.lo[i] = -mu;
      p.hi[i] = mu;
    }
  }
  return p;
}

// ||x - clamp(x - w, lo', hi')||_inf / (1 + ||b||_inf) in long double, and the bound of its
// rounding (that of w, 64-bit products and sums over n terms, plus the double result's own).
void independentResidual(const Problem& p, const Vector& x, long double& r, long double& bound) {
  const int n = p.size();
  const mlcp::DenseMatrix A =
      p.isSparse() ? mlcp::DenseMatrix(p.sparseA()) : mlcp::DenseMatrix(p.denseA());
  long double bNorm = 0, worst = 0, magnitude = 0;
  for (int i = 0; i < n; ++i) bNorm = std::max(bNorm, std::abs((long double)p.b[i]));
  for (int i = 0; i < n; ++i) {
    long double w = p.b[i], mag = std::abs((long double)p.b[i]);
    for (int j = 0; j < n; ++j) {
      w += (long double)A(i, j) * x[j];
      mag += std::abs((long double)A(i, j) * x[j]);
    }
    long double lo = p.lo[i], hi = p.hi[i];
    if (!p.findex.empty() && p.findex[i] >= 0) {
      lo *= std::abs((long double)x[p.findex[i]]);
      hi *= std::abs((long double)x[p.findex[i]]);
    }
    const long double t = std::min(std::max((long double)x[i] - w, lo), hi);
    worst = std::max(worst, std::abs((long double)x[i] - t));
    magnitude = std::max({magnitude, mag, std::abs((long double)x[i]) + std::abs(w)});
  }
  r = worst / (1 + bNorm);
  bound = (2 * (n + 2) * 0x1p-64L + 4 * 0x1p-53L) * magnitude / (1 + bNorm);
}

std::vector<std::string> solverList() {
  std::vector<std::string> names;
  std::stringstream list(mlcp::solverNames());
  std::string name;
  while (std::getline(list, name, ',')) {
    while (!name.empty() && name.front() == ' ') name.erase(0, 1);
    if (!name.empty()) names.push_back(name);
  }
  names.push_back("dantzig>lemke>pgs");
  return names;
}

void solveAndCheck(const std::string& name, const Problem& p, double tolerance) {
  std::unique_ptr<mlcp::Solver> solver = mlcp::makeSolver(name);
  if (!solver) mlcp::fuzz::violated("unknown solver", name);
  mlcp::Options& o = solver->options();
  o.tolerance = tolerance;
  o.maxIterations = 50;
  o.timeBudget = 0.05;
  const Vector untouched = Vector::Constant(3, 7.0);
  Vector x = untouched;
  const mlcp::Result r = solver->solve(p, x);
  if (r.status == mlcp::Status::InvalidInput) {
    if (x.size() != 3 || x != untouched) mlcp::fuzz::violated("invalid input touched x", name);
    return;
  }
  if (!r.converged()) return;
  if (x.size() != p.size() || !x.allFinite()) mlcp::fuzz::violated("converged, x not finite", name);
  long double residual = 0, bound = 0;
  independentResidual(p, x, residual, bound);
  if (residual > tolerance + bound) {
    std::ostringstream os;
    os << name << ": residual " << double(residual) << " (bound " << double(bound)
       << ") above tolerance " << tolerance << ", reported " << r.residual;
    mlcp::fuzz::violated("converged above the tolerance", os.str());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<std::string> solvers = solverList();
  Problem p;
  double tolerance = 1e-8;
  if (size > 0 && data[0] == '{') {
    try {
      p = mlcp::io::parseProblemJson(std::string(reinterpret_cast<const char*>(data), size));
    } catch (const mlcp::io::FormatError&) {
      return 0;
    }
    if (p.size() > 12) return 0;
  } else {
    Bytes in(data, size);
    p = decode(in, tolerance);
  }
  for (const std::string& name : solvers) solveAndCheck(name, p, tolerance);
  return 0;
}
