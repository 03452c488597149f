#include "mlcp/solvers/row_pgs.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <sstream>
#include <type_traits>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"
#include "projection/row_checks.hpp"
#include "projection/row_pack.hpp"
#include "projection/row_sweep.hpp"
#include "projection/sweep_monitor.hpp"

namespace mlcp {

using detail::arraysAndBodiesValid;
using detail::systemRow;

Result RowPgs::solve(const RowSystem& s, Vector& x) {
  const double t0 = nowSeconds();
  const Options& opt = options_;
  baseValid_ = false;
  Result result;
  auto invalid = [&](std::string why) {
    result.status = Status::InvalidInput;
    result.message = std::move(why);
    return result;
  };
  if (!(opt.relaxation > 0 && opt.relaxation < 2)) return invalid("relaxation outside (0, 2)");
  if (s.hasArticulated()) return solveArticulated(s, x, t0);
  // Validation is folded into the packing pass below (rowValid per row); RowSystem::validate
  // runs only to name what is wrong.
  if (!arraysAndBodiesValid(s)) return invalid(s.validate());
  const int n = s.size();
  // x is the caller's until the input is known to be valid: a cold start reads zeros.
  const bool warm = opt.warmStart && x.size() == n && x.allFinite();
  const double* start = warm ? x.data() : nullptr;
  Packing& packing = *packing_;
  if (!packing.pack(
          s.bodies, n, [&](int i) { return systemRow(s, i, start); }, opt.relaxation, warm, nullptr,
          false)) {
    // Rows after the one that stopped the packing are not checked yet: validate them all.
    if (std::string why = s.validate(); !why.empty()) return invalid(why);
    // The input is valid: a non-positive A_ii is a failure, not invalid input.
    if (!warm) x.setZero(n);
    std::ostringstream os;
    if (std::isfinite(packing.badDiagonal_))
      os << "row " << packing.bad_ << " has A_ii = " << packing.badDiagonal_
         << ": pgs needs a positive diagonal";
    else  // finite entries whose products leave the double range
      os << "row " << packing.bad_ << ": A_ii = J M^-1 J^T + cfm overflows ("
         << packing.badDiagonal_
         << ") although its entries are finite: pgs needs a positive finite diagonal";
    result.status = Status::Failed;
    result.message = os.str();
    // velocity_ does not hold M^-1 J^T x: the check uses the rows themselves.
    const double bNorm = n ? s.b.lpNorm<Eigen::Infinity>() : 0.0;
    applyAccuracy(result, accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm), opt.tolerance);
    result.seconds = nowSeconds() - t0;
    return result;
  }
  // The input is valid from here on: x is the iterate (no copy).
  if (!warm) x.setZero(n);
  return iterate(x, n ? s.b.lpNorm<Eigen::Infinity>() : 0.0, t0);
}

void RowPgs::toSystem(const std::vector<BodyInverseMass>& bodies, int n, RowSource& source,
                      RowSystem& s, Vector& start) {
  detail::resizeSystem(bodies, n, s, start);
  for (int i = 0; i < n; ++i) detail::setRow(s, start, i, source.row(i));
}

Result RowPgs::solve(const std::vector<BodyInverseMass>& bodies, int n, RowSource& source,
                     Vector& x) {
  const double t0 = nowSeconds();
  baseValid_ = false;
  // The slow path: the same rows as a RowSystem, solved (or refused) by solve(RowSystem).
  auto slow = [&] {
    RowSystem s;
    detail::resizeSystem(bodies, n, s, x);
    for (int i = 0; i < n; ++i) detail::setRow(s, x, i, source.row(i));
    return solve(s, x);
  };
  const Options& opt = options_;
  if (n < 0) return negativeRows();
  if (!(opt.relaxation > 0 && opt.relaxation < 2)) return slow();
  for (const BodyInverseMass& body : bodies)
    if (!detail::bodyValid(body)) return slow();
  x.resize(n);
  double bNorm = 0;
  const bool packed = packing_->pack(
      bodies, n,
      [&](int i) __attribute__((always_inline)) {
        const RowView r = source.row(i);
        bNorm = std::max(bNorm, std::abs(r.b));
        return r;
      },
      opt.relaxation, opt.warmStart, x.data(), true);
  if (!packed) return slow();
  // A non-finite start: solve(RowSystem) starts cold (velocity_ and base_ hold NaN here).
  if (!x.allFinite()) return slow();
  return iteratePacked(static_cast<int>(bodies.size()), x, bNorm, t0);
}

RowPgs::RowPgs() : packing_(std::make_unique<Packing>()) {}
RowPgs::RowPgs(const RowPgs& other)
    : options_(other.options_),
      packing_(std::make_unique<Packing>(*other.packing_)),
      baseValid_(other.baseValid_) {}
RowPgs::RowPgs(RowPgs&&) noexcept = default;
RowPgs& RowPgs::operator=(const RowPgs& other) {
  if (this != &other) *this = RowPgs(other);
  return *this;
}
RowPgs& RowPgs::operator=(RowPgs&&) noexcept = default;
RowPgs::~RowPgs() = default;

Vector6 RowPgs::velocityChange(int body) const {
  assert(baseValid_ && body >= 0 && body < static_cast<int>(packing_->base_.size()));
  return packing_->velocity_[body].v - packing_->base_[body].v;
}

Result RowPgs::negativeRows() {
  Result r;
  r.status = Status::InvalidInput;
  r.message = "negative row count";
  return r;
}

Result RowPgs::iteratePacked(int bodies, Vector& x, double bNorm, double t0) {
  // A non-finite base would make every velocityChange NaN: no per-body changes then (the
  // caller applies x row by row, as after the slow path).
  for (int k = 0; k < bodies; ++k)
    if (!packing_->base_[k].v.allFinite()) return iterate(x, bNorm, t0);
  baseValid_ = true;
  return iterate(x, bNorm, t0);
}

// Not inlined into iterate(): its loops there changed how the sweep loop was compiled (our
// stages ~20% slower at 210 boxes).
[[gnu::noinline]] Accuracy RowPgs::Packing::packedAccuracy(const Vector& x, double bNorm) const {
#if MLCP_CPU_DISPATCH
  if (detail::avx2Active()) return checkAvx2(x, bNorm);
#endif
  return checkRows<false>(x, bNorm);
}

// A function of its own: compiled apart from the checks and the stopping logic around it (the
// sweep's code and speed moved with whatever else iterate() held).
[[gnu::noinline]] void RowPgs::Packing::sweepOnce(double* xs) {
#if MLCP_CPU_DISPATCH
  if (detail::avx2Active()) return sweepAvx2(xs);
#endif
  sweepRows<false>(xs);
}

Result RowPgs::iterate(Vector& x, double bNorm, double t0) {
  const Options& opt = options_;
  Packing& packing = *packing_;
  const int n = static_cast<int>(packing.packed_.size());
  Result result;
  Accuracy last;           // accuracy of x as it is after the last check
  bool lastValid = false;  // whether x is unchanged since
  auto check = [&]() {
    last = packing.packedAccuracy(x, bNorm);
    lastValid = true;
  };
  detail::SweepMonitor monitor(opt, result, n);
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
  }
  for (int sweep = 1; n > 0 && sweep <= opt.maxIterations; ++sweep) {
    packing.sweepOnce(x.data());
    lastValid = false;
    if (!monitor.wantsCheck(sweep)) {
      if (monitor.outOfTime(sweep)) break;
      continue;
    }
    check();
    if (monitor.stop(sweep, last)) break;
  }
  if (!lastValid) check();
  applyAccuracy(result, last, opt.tolerance);
  result.seconds = nowSeconds() - t0;
  return result;
}

}  // namespace mlcp
