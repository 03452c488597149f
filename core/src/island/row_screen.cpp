#include "mlcp/island/row_screen.hpp"

#include <cmath>

namespace mlcp {

void ScreenCounts::add(const ScreenCounts& o) {
  clampedBound += o.clampedBound;
  rhsBeyondReach += o.rhsBeyondReach;
  nonFiniteRhs += o.nonFiniteRhs;
  nonFiniteRow += o.nonFiniteRow;
  noJacobian += o.noJacobian;
  zeroDiagonal += o.zeroDiagonal;
  emptyBounds += o.emptyBounds;
  inertNormal += o.inertNormal;
}

std::string ScreenCounts::toString() const {
  const std::pair<const char*, int> entries[] = {
      {"clamped-bound", clampedBound},  {"rhs-beyond-reach", rhsBeyondReach},
      {"non-finite-rhs", nonFiniteRhs}, {"non-finite-row", nonFiniteRow},
      {"no-jacobian", noJacobian},      {"zero-diagonal", zeroDiagonal},
      {"empty-bounds", emptyBounds},    {"inert-normal", inertNormal}};
  std::string s;
  for (const auto& [name, count] : entries)
    if (count > 0) s += (s.empty() ? "" : " ") + std::string(name) + ":" + std::to_string(count);
  return s;
}

namespace {

enum class Verdict {
  Keep,
  BeyondReach,
  NonFiniteRhs,
  NonFiniteRow,
  NoJacobian,
  ZeroDiagonal,
  EmptyBounds
};

// One side's share of A_ii (J M^-1 J^T) and of ref (see row_screen.hpp).
void side(const BodyInverseMass& body, const Vector6& j, double& aii, double& ref) {
  const Eigen::Vector3d lin = j.head<3>(), ang = j.tail<3>();
  aii += body.invMass * lin.squaredNorm() + ang.dot(body.invInertia * ang);
  ref +=
      body.invMass * lin.squaredNorm() + body.invInertia.cwiseAbs().maxCoeff() * ang.squaredNorm();
}

// The answer of a row whose b_i is beyond reach (row_screen.hpp): the bound b_i's sign names, or
// 0 for a friction row (its bounds move with its normal's x).
Verdict beyondReach(const RowSystem& s, int i, bool fx, double& fixedAt) {
  const double c = s.b[i] > 0 ? s.lo[i] : s.hi[i];
  if (fx && s.findex[i] >= 0) return Verdict::BeyondReach;
  if (!std::isfinite(c)) return Verdict::NonFiniteRhs;
  fixedAt = c;
  return Verdict::BeyondReach;
}

// A side whose row, body and storage are in range (validation reports the others).
bool sideInRange(const RowSystem& s, const ArticulatedSide& a) {
  if (a.row < 0 || a.row >= s.size() || a.body < 0 ||
      a.body >= static_cast<int>(s.articulated.size()))
    return false;
  return a.at >= 0 && a.at + s.articulated[a.body] <= static_cast<int>(s.jacobian.size()) &&
         s.unitImpulse.size() == s.jacobian.size();
}

// Each row's articulated share of A_ii and of ref (J . W and |J| |W| per side), and whether a
// side has a non-zero J (rows.hpp); empty without articulated sides.
struct ArticulatedShares {
  std::vector<double> aii, ref;
  std::vector<char> jacobian;
  explicit ArticulatedShares(const RowSystem& s) {
    if (!s.hasArticulated()) return;
    const int n = s.size();
    aii.assign(n, 0.0);
    ref.assign(n, 0.0);
    jacobian.assign(n, 0);
    for (const ArticulatedSide& a : s.sides) {
      if (!sideInRange(s, a)) continue;
      const int width = s.articulated[a.body];
      const Eigen::Map<const Vector> j(s.jacobian.data() + a.at, width);
      const Eigen::Map<const Vector> w(s.unitImpulse.data() + a.at, width);
      aii[a.row] += j.dot(w);
      ref[a.row] += j.norm() * w.norm();
      jacobian[a.row] |= !j.isZero(0);
    }
  }
};

// fixedAt: the row's answer when the verdict is BeyondReach (left 0 otherwise).
Verdict judge(const RowSystem& s, const ArticulatedShares& art, int i, bool fx, double& fixedAt) {
  const ConstraintRow& r = s.rows[i];
  const int nb = static_cast<int>(s.bodies.size());
  // Rows naming bodies out of range are validation's to report.
  if (r.bodyA < -1 || r.bodyA >= nb || r.bodyB < -1 || r.bodyB >= nb) return Verdict::Keep;
  const bool a = r.bodyA >= 0, b = r.bodyB >= 0;
  if ((a && !r.jA.allFinite()) || (b && !r.jB.allFinite()) || !std::isfinite(s.cfm[i]) ||
      s.cfm[i] < 0)
    return Verdict::NonFiniteRow;
  if (std::isnan(s.b[i])) return Verdict::NonFiniteRhs;
  const double lo = s.lo[i], hi = s.hi[i];
  if (lo == kInf || hi == -kInf || lo > hi) return Verdict::EmptyBounds;
  if (std::abs(s.b[i]) >= kBeyondReach) return beyondReach(s, i, fx, fixedAt);
  const bool articulated = !art.aii.empty();
  if ((!a || r.jA.isZero(0)) && (!b || r.jB.isZero(0)) && !(articulated && art.jacobian[i]))
    return Verdict::NoJacobian;
  double aii = articulated ? art.aii[i] : 0.0, ref = articulated ? art.ref[i] : 0.0;
  if (a) side(s.bodies[r.bodyA], r.jA, aii, ref);
  if (b) side(s.bodies[r.bodyB], r.jB, aii, ref);
  if (s.cfm[i] == 0 && !(aii > kZeroDiagonal * ref)) return Verdict::ZeroDiagonal;
  return Verdict::Keep;
}

void count(ScreenCounts& c, Verdict v) {
  switch (v) {
    case Verdict::BeyondReach: ++c.rhsBeyondReach; break;
    case Verdict::NonFiniteRhs: ++c.nonFiniteRhs; break;
    case Verdict::NonFiniteRow: ++c.nonFiniteRow; break;
    case Verdict::NoJacobian: ++c.noJacobian; break;
    case Verdict::ZeroDiagonal: ++c.zeroDiagonal; break;
    case Verdict::EmptyBounds: ++c.emptyBounds; break;
    case Verdict::Keep: break;
  }
}

}  // namespace

bool RowScreen::screen(const RowSystem& s) {
  counts_ = ScreenCounts();
  n_ = s.size();
  const int n = n_;
  if (s.b.size() != n || s.lo.size() != n || s.hi.size() != n || s.cfm.size() != n) return false;
  const bool fx = static_cast<int>(s.findex.size()) == n;
  inert_.assign(n, 0);
  fixed_.assign(n, 0.0);
  bool any = false;
  const ArticulatedShares art(s);
  for (int i = 0; i < n; ++i) {
    const Verdict v = judge(s, art, i, fx, fixed_[i]);
    count(counts_, v);
    inert_[i] = v != Verdict::Keep;
    any |= inert_[i] != 0;
    counts_.clampedBound += v == Verdict::Keep && (std::isnan(s.lo[i]) || std::isnan(s.hi[i]));
  }
  // Friction rows of an inert normal row (one level: findex has no chains); a normal fixed at a
  // non-zero bound gives its friction rows fixed bounds below.
  for (int i = 0; fx && i < n; ++i) {
    const int f = s.findex[i];
    if (!inert_[i] && f >= 0 && f < n && inert_[f] && fixed_[f] == 0) {
      inert_[i] = 1;
      ++counts_.inertNormal;
    }
  }
  if (!any && counts_.clampedBound == 0) return false;

  index_.clear();
  std::vector<int> place(n, -1);
  for (int i = 0; i < n; ++i)
    if (!inert_[i]) {
      place[i] = static_cast<int>(index_.size());
      index_.push_back(i);
    }
  const int m = static_cast<int>(index_.size());
  kept_.bodies = s.bodies;
  kept_.rows.resize(m);
  kept_.b.resize(m);
  kept_.lo.resize(m);
  kept_.hi.resize(m);
  kept_.cfm.resize(m);
  kept_.findex.assign(fx ? m : 0, -1);
  for (int k = 0; k < m; ++k) {
    const int i = index_[k];
    kept_.rows[k] = s.rows[i];
    kept_.b[k] = s.b[i];
    kept_.lo[k] = std::isnan(s.lo[i]) ? -kInf : s.lo[i];
    kept_.hi[k] = std::isnan(s.hi[i]) ? kInf : s.hi[i];
    kept_.cfm[k] = s.cfm[i];
    if (fx) {
      const int f = s.findex[i];
      kept_.findex[k] = f >= 0 && f < n ? place[f] : f;
      if (f >= 0 && f < n && inert_[f]) {  // its normal is fixed at fixed_[f] != 0
        kept_.lo[k] *= std::abs(fixed_[f]);
        kept_.hi[k] *= std::abs(fixed_[f]);
      }
    }
  }
  keepArticulated(s, place);
  for (int i = 0; i < n; ++i)
    if (fixed_[i] != 0) fix(s, i);
  return true;
}

// The kept rows' articulated sides, renumbered; J and W stay where they are stored.
void RowScreen::keepArticulated(const RowSystem& s, const std::vector<int>& place) {
  kept_.articulated = s.articulated;
  kept_.sides.clear();
  if (!s.hasArticulated()) {
    kept_.jacobian.clear();
    kept_.unitImpulse.clear();
    return;
  }
  kept_.jacobian = s.jacobian;
  kept_.unitImpulse = s.unitImpulse;
  for (ArticulatedSide a : s.sides) {
    if (!sideInRange(s, a) || place[a.row] < 0) continue;
    a.row = place[a.row];
    kept_.sides.push_back(a);
  }
}

// Row i fixed at c = fixed_[i]: each kept row's b_j += J_j M^-1 J_i^T c on the bodies they share.
void RowScreen::fix(const RowSystem& s, int i) {
  const ConstraintRow& r = s.rows[i];
  auto push = [&](int body, const Vector6& j) {
    Vector6 dv = Vector6::Zero();
    if (body < 0) return dv;
    const BodyInverseMass& m = s.bodies[body];
    dv << m.invMass * j.head<3>(), m.invInertia * j.tail<3>();
    return Vector6(dv * fixed_[i]);
  };
  const Vector6 dvA = push(r.bodyA, r.jA), dvB = push(r.bodyB, r.jB);
  auto on = [&](int body, const Vector6& j) {
    return (body >= 0 && body == r.bodyA ? j.dot(dvA) : 0.0) +
           (body >= 0 && body == r.bodyB ? j.dot(dvB) : 0.0);
  };
  for (int k = 0; k < kept_.size(); ++k) {
    const ConstraintRow& q = kept_.rows[k];
    kept_.b[k] += on(q.bodyA, q.jA) + on(q.bodyB, q.jB);
  }
  // The articulated sides of row i push the kept sides on the same bodies: J_k . W_i c.
  for (const ArticulatedSide& a : s.sides) {
    if (a.row != i || !sideInRange(s, a)) continue;
    const int width = s.articulated[a.body];
    const Eigen::Map<const Vector> w(s.unitImpulse.data() + a.at, width);
    for (const ArticulatedSide& q : kept_.sides)
      if (q.body == a.body)
        kept_.b[q.row] +=
            Eigen::Map<const Vector>(kept_.jacobian.data() + q.at, width).dot(w) * fixed_[i];
  }
}

void RowScreen::gather(const Vector& full, Vector& kept) const {
  kept.resize(static_cast<int>(index_.size()));
  for (int k = 0; k < kept.size(); ++k) kept[k] = full[index_[k]];
}

void RowScreen::scatter(const Vector& kept, Vector& full) const {
  full = Eigen::Map<const Vector>(fixed_.data(), n_);
  for (int k = 0; k < kept.size(); ++k) full[index_[k]] = kept[k];
}

}  // namespace mlcp
