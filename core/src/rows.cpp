#include "mlcp/rows.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <sstream>
#include <type_traits>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"
#include "rows/row_pack.hpp"
#include "rows/row_sweep.hpp"
#include "sweep_monitor.hpp"

namespace mlcp {

namespace {

// M^-1 j for one body: [invMass * linear; invInertia * angular].
inline Vector6 applyInverseMass(const BodyInverseMass& body, const Vector6& j) {
  Vector6 out;
  out.head<3>() = body.invMass * j.head<3>();
  out.tail<3>() = body.invInertia * j.tail<3>();
  return out;
}

// A problem with the same b, bounds and findex and no matrix yet: validation of those fields is
// Problem's job, so rows reuse it instead of repeating the rules.
Problem boundsOnly(const RowSystem& s) {
  Problem p;
  p.b = s.b;
  p.lo = s.lo;
  p.hi = s.hi;
  p.findex = s.findex;
  return p;
}

// One row's values wherever they are stored (a RowSystem, an engine's own rows):
// what validation and RowPgs' packing read.
using RowRef = RowPgs::RowView;

RowRef viewOf(int bodyA, int bodyB, const Vector6& jA, const Vector6& jB) {
  RowRef r;
  r.bodyA = bodyA;
  r.bodyB = bodyB;
  r.linA = jA.data();
  r.angA = jA.data() + 3;
  r.linB = jB.data();
  r.angB = jB.data() + 3;
  return r;
}

inline RowRef systemRow(const RowSystem& s, int i, const double* x) {
  const ConstraintRow& c = s.rows[i];
  RowRef r = viewOf(c.bodyA, c.bodyB, c.jA, c.jB);
  r.b = s.b[i];
  r.cfm = s.cfm[i];
  r.lo = s.lo[i];
  r.hi = s.hi[i];
  r.findex = s.findex.empty() ? -1 : s.findex[i];
  r.start = x ? x[i] : 0.0;
  return r;
}

// The rules rowValid assumes: the per-row arrays' sizes and finite, non-negative body masses.
bool arraysAndBodiesValid(const RowSystem& s) {
  const int n = s.size();
  if (s.b.size() != n || s.lo.size() != n || s.hi.size() != n || s.cfm.size() != n) return false;
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != n) return false;
  for (const BodyInverseMass& body : s.bodies)
    if (!detail::bodyValid(body)) return false;
  return true;
}

bool rowsValid(const RowSystem& s) {
  const unsigned slots = static_cast<unsigned>(s.bodies.size()) + 1;  // -1 .. nb - 1
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != s.size()) return false;
  for (int i = 0; i < s.size(); ++i) {
    const RowRef r = systemRow(s, i, nullptr);
    if (!detail::rowValid(r, s.rows[i].jA.data(), s.rows[i].jB.data(), i, s.size(), slots) ||
        (r.findex >= 0 && s.findex[r.findex] >= 0))
      return false;
  }
  return true;
}

}  // namespace

std::string RowSystem::validate() const {
  const int n = size();
  std::ostringstream os;
  if (b.size() != n || lo.size() != n || hi.size() != n || cfm.size() != n) {
    os << "row arrays disagree: " << n << " rows, b " << b.size() << ", lo " << lo.size() << ", hi "
       << hi.size() << ", cfm " << cfm.size();
    return os.str();
  }
  const int nb = static_cast<int>(bodies.size());
  for (int k = 0; k < nb; ++k) {
    const BodyInverseMass& body = bodies[k];
    if (!detail::bodyValid(body)) {
      os << "body " << k << " has an invalid inverse mass or inertia";
      return os.str();
    }
  }
  if (rowsValid(*this)) return "";
  for (int i = 0; i < n; ++i) {
    const ConstraintRow& r = rows[i];
    if (r.bodyA < -1 || r.bodyA >= nb || r.bodyB < -1 || r.bodyB >= nb) {
      os << "row " << i << " names body " << r.bodyA << "/" << r.bodyB << " of " << nb;
      return os.str();
    }
    if (!r.jA.allFinite() || !r.jB.allFinite()) {
      os << "row " << i << " has a non-finite Jacobian";
      return os.str();
    }
    if (!std::isfinite(cfm[i]) || cfm[i] < 0) {
      os << "row " << i << " has cfm " << cfm[i] << " (must be finite and >= 0)";
      return os.str();
    }
  }
  // Problem::validate checks b, bounds and findex and says what is wrong; give it a shell.
  Problem shell = boundsOnly(*this);
  shell.setA(SparseMatrix(n, n));
  return shell.validate();
}

std::vector<Vector6> RowSystem::bodyVelocities(const Vector& x) const {
  std::vector<Vector6> v(bodies.size(), Vector6::Zero());
  for (int i = 0; i < size(); ++i) {
    const ConstraintRow& r = rows[i];
    if (r.bodyA >= 0) v[r.bodyA] += applyInverseMass(bodies[r.bodyA], r.jA) * x[i];
    if (r.bodyB >= 0) v[r.bodyB] += applyInverseMass(bodies[r.bodyB], r.jB) * x[i];
  }
  return v;
}

Vector RowSystem::slack(const Vector& x) const {
  const std::vector<Vector6> v = bodyVelocities(x);
  Vector w(size());
  for (int i = 0; i < size(); ++i) {
    const ConstraintRow& r = rows[i];
    double wi = cfm[i] * x[i] + b[i];
    if (r.bodyA >= 0) wi += r.jA.dot(v[r.bodyA]);
    if (r.bodyB >= 0) wi += r.jB.dot(v[r.bodyB]);
    w[i] = wi;
  }
  return w;
}

double RowSystem::impulseEnergy(const Vector& x) const { return 0.5 * x.dot(slack(x) - b); }

Problem RowSystem::assemble(bool sparse) const {
  Problem p;
  AssembleScratch scratch;
  assemble(sparse, p, scratch);
  return p;
}

void RowSystem::assemble(bool sparse, Problem& p, AssembleScratch& scratch) const {
  const int n = size();
  // Rows touching each body: only rows sharing a body couple in J M^-1 J^T.
  auto& touching = scratch.touching;
  if (touching.size() < bodies.size()) touching.resize(bodies.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) touching[k].clear();
  for (int i = 0; i < n; ++i) {
    if (rows[i].bodyA >= 0) touching[rows[i].bodyA].push_back({i, &rows[i].jA});
    if (rows[i].bodyB >= 0) touching[rows[i].bodyB].push_back({i, &rows[i].jB});
  }
  // Every entry of A as (row, column, value) in one fixed order: diag(cfm), then per body the
  // products of the rows touching it. Dense and sparse storage sum them in this order.
  auto forEachProduct = [&](auto&& add) {
    for (int i = 0; i < n; ++i) add(i, i, cfm[i]);
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      for (const auto& [i, ji] : touching[k]) {
        const Vector6 mji = applyInverseMass(bodies[k], *ji);
        for (const auto& [j, jj] : touching[k]) add(i, j, jj->dot(mji));
      }
    }
  };
  p.b = b;
  p.lo = lo;
  p.hi = hi;
  p.findex = findex;
  if (!sparse) {
    DenseMatrix& A = scratch.dense;
    p.swapA(A);  // A now holds the problem's previous dense storage
    A.setZero(n, n);
    forEachProduct([&](int i, int j, double v) { A(i, j) += v; });
    p.swapA(A);
    return;
  }
  // The pattern depends only on which bodies each row joins; `into` must still hold it (its
  // index arrays are compared, so a matrix set by anyone else is never refilled by mistake).
  auto& key = scratch.patternBodies;
  const bool samePattern = [&] {
    const SparseMatrix& held = p.sparseA();
    if (!p.isSparse() || held.rows() != n || held.cols() != n || !held.isCompressed() ||
        key.size() != 1 + 2 * static_cast<std::size_t>(n) ||
        key[0] != static_cast<int>(bodies.size()) ||
        held.nonZeros() != static_cast<Eigen::Index>(scratch.patternInner.size()))
      return false;
    for (int i = 0; i < n; ++i)
      if (key[1 + 2 * i] != rows[i].bodyA || key[2 + 2 * i] != rows[i].bodyB) return false;
    return std::equal(scratch.patternOuter.begin(), scratch.patternOuter.end(),
                      held.outerIndexPtr()) &&
           std::equal(scratch.patternInner.begin(), scratch.patternInner.end(),
                      held.innerIndexPtr());
  }();
  SparseMatrix& A = scratch.sparse;
  p.swapA(A);  // A now holds the problem's previous sparse matrix (its storage is reused)
  if (samePattern) {
    // The second assembly on a pattern finds where each product lands (row-major: a search of
    // the row's sorted columns), the next ones only write values.
    auto& slots = scratch.valueSlot;
    if (slots.empty())
      forEachProduct([&](int i, int j, double) {
        const int* first = A.innerIndexPtr() + A.outerIndexPtr()[i];
        const int* last = A.innerIndexPtr() + A.outerIndexPtr()[i + 1];
        slots.push_back(static_cast<int>(std::lower_bound(first, last, j) - A.innerIndexPtr()));
      });
    double* values = A.valuePtr();
    std::fill_n(values, A.nonZeros(), 0.0);
    const int* slot = slots.data();
    forEachProduct([&](int, int, double v) { values[*slot++] += v; });
  } else {
    // A new pattern: each row written in place, its columns the merge of its bodies' row lists.
    A.resize(n, n);
    int* outer = A.outerIndexPtr();
    outer[0] = 0;
    for (int i = 0; i < n; ++i) outer[i + 1] = outer[i] + mergeRow<false>(i, touching, nullptr);
    A.resizeNonZeros(outer[n]);
    for (int i = 0; i < n; ++i) mergeRow<true>(i, touching, &A);
    scratch.valueSlot.clear();
    scratch.patternOuter.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
    scratch.patternInner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    key.resize(1 + 2 * static_cast<std::size_t>(n));
    key[0] = static_cast<int>(bodies.size());
    for (int i = 0; i < n; ++i) {
      key[1 + 2 * i] = rows[i].bodyA;
      key[2 + 2 * i] = rows[i].bodyB;
    }
  }
  p.swapA(A);
}

// Row i of the sparse A (RowSystem::assemble): every row j sharing a body with i, in increasing
// j, A_ij = [i == j] cfm_i + sum over the bodies k of i (increasing k) of
// J_jk . (M_k^-1 J_ik), summed in the dense path's order (cfm, then body by body, and within a
// body i's sides in the order A, B and j's in touching order), so that both storages hold the
// same bits. Count only (Fill false): returns the entries; Fill: writes them at the row's start.
template <bool Fill>
int RowSystem::mergeRow(int i, const Touching& touching, SparseMatrix* A) const {
  const ConstraintRow& r = rows[i];
  // i's sides in increasing body order (A before B on one body).
  struct Side {
    const std::vector<std::pair<int, const Vector6*>>* list = nullptr;
    Vector6 m = Vector6::Zero();  // M_k^-1 J_ik
    std::size_t at = 0;
  } side[2];
  int sides = 0;
  auto addSide = [&](int body, const Vector6& j) {
    if (body < 0) return;
    side[sides].list = &touching[body];
    if (Fill) side[sides].m = applyInverseMass(bodies[body], j);
    ++sides;
  };
  const bool swap = r.bodyA >= 0 && r.bodyB >= 0 && r.bodyB < r.bodyA;
  addSide(swap ? r.bodyB : r.bodyA, swap ? r.jB : r.jA);
  addSide(swap ? r.bodyA : r.bodyB, swap ? r.jA : r.jB);
  int* inner = Fill ? A->innerIndexPtr() + A->outerIndexPtr()[i] : nullptr;
  double* value = Fill ? A->valuePtr() + A->outerIndexPtr()[i] : nullptr;
  int count = 0;
  bool diagonal = false;
  constexpr int kNone = std::numeric_limits<int>::max();
  for (;;) {
    int j = diagonal ? kNone : i;
    for (int s = 0; s < sides; ++s)
      if (side[s].at < side[s].list->size()) j = std::min(j, (*side[s].list)[side[s].at].first);
    if (j == kNone) break;
    double v = 0;
    if (j == i) {
      v = cfm[i];
      diagonal = true;
    }
    for (int s = 0; s < sides; ++s) {
      const auto& list = *side[s].list;
      for (; side[s].at < list.size() && list[side[s].at].first == j; ++side[s].at)
        if (Fill) v += list[side[s].at].second->dot(side[s].m);
    }
    if (Fill) {
      inner[count] = j;
      value[count] = v;
    }
    ++count;
  }
  return count;
}

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
