// core/src/projection/row_checks.hpp (internal): the per-row rules and products RowPgs' packing
// pass applies to each row as it reads it (row_pack.hpp), and the copy of a row view into a
// RowSystem (the packing's slow path). Inline and allocation-free: they run once per row per solve.
#pragma once

#include <cmath>

#include "mlcp/rows.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp {
namespace detail {

// A view's Jacobian block as [linear; angular] (a missing part reads as zeros).
inline void jacobianOf(const double* lin, const double* ang, double* j) {
  for (int k = 0; k < 3; ++k) {
    j[k] = lin ? lin[k] : 0.0;
    j[3 + k] = ang ? ang[k] : 0.0;
  }
}

// Whether the 6 + 6 entries are all finite (any NaN or Inf entry makes the sum NaN or Inf).
inline bool jacobiansFinite(const double* jA, const double* jB) {
  double sum = 0;
  for (int k = 0; k < 6; ++k) sum += jA[k] + jB[k];
  return std::isfinite(sum);
}

// Every per-row rule of RowSystem::validate and Problem::validate except J's finiteness (b,
// bounds, findex, body indices) for row i of n as one predicate without copies, except that row
// findex's own findex must be -1 (the callers check that against the other row). slots = bodies
// + 1; the array sizes are checked.
inline bool rowRulesValid(const RowPgs::RowView& r, int i, int n, unsigned slots) {
  if (static_cast<unsigned>(r.bodyA + 1) >= slots || static_cast<unsigned>(r.bodyB + 1) >= slots)
    return false;
  if (!(r.cfm >= 0 && r.cfm < kInf)) return false;
  const double lo = r.lo, hi = r.hi;
  // !(lo <= hi) also catches NaN bounds.
  if (!std::isfinite(r.b) || !(lo <= hi) || lo == kInf || hi == -kInf) return false;
  const int f = r.findex;
  if (f < 0) return f == -1;
  if (f >= n || f == i) return false;
  return hi >= 0 && std::isfinite(hi) && lo == -hi;
}

// Every per-row rule of RowSystem::validate and Problem::validate (J, b, bounds, findex): the fast
// path of RowSystem::validate, which the adapters call every step. When it says no, the checks in
// RowSystem::validate find the row and say what is wrong (Problem::validate stays the one
// statement of the bound rules' wording). A false alarm (a sum of finite Jacobian entries
// overflowing) only costs the slow path. RowPgs' packing checks rowRulesValid and J's
// finiteness apart (pack()).
inline bool rowValid(const RowPgs::RowView& r, const double* jA, const double* jB, int i, int n,
                     unsigned slots) {
  return jacobiansFinite(jA, jB) && rowRulesValid(r, i, n, slots);
}

// A finite, non-negative inverse mass and a finite inverse inertia.
inline bool bodyValid(const BodyInverseMass& body) {
  return std::isfinite(body.invMass) && body.invMass >= 0 && body.invInertia.allFinite();
}

// M^-1 j for one body written to out[0..5], returning j . M^-1 j; the angular part is the
// engine's own invAng when given (RowPgs::RowView: the same products, computed by the engine).
// Scalar code on purpose: a Vector6 returned by value passes through a stack temporary written
// in 8- and 16-byte pieces, and reading it back in pairs stalls store forwarding on every row of
// the packing pass.
inline double inverseMassInto(const BodyInverseMass& body, const double* j, const double* invAng,
                              double* out) {
  const double im = body.invMass;
  const Eigen::Matrix3d& I = body.invInertia;
  double m[6] = {im * j[0], im * j[1], im * j[2]};
  if (invAng) {
    for (int k = 0; k < 3; ++k) m[3 + k] = invAng[k];
  } else {
    for (int k = 0; k < 3; ++k) m[3 + k] = I(k, 0) * j[3] + I(k, 1) * j[4] + I(k, 2) * j[5];
  }
  for (int k = 0; k < 6; ++k) out[k] = m[k];
  // Linear and angular parts summed apart: the division for the row's step waits on this sum
  // (a chain of 3 additions instead of 6).
  return (j[0] * m[0] + j[1] * m[1] + j[2] * m[2]) + (j[3] * m[3] + j[4] * m[4] + j[5] * m[5]);
}

inline void resizeSystem(const std::vector<BodyInverseMass>& bodies, int n, RowSystem& s,
                         Vector& start) {
  s.bodies = bodies;
  s.rows.resize(n);
  s.b.resize(n);
  s.lo.resize(n);
  s.hi.resize(n);
  s.cfm.resize(n);
  s.findex.resize(n);
  start.resize(n);
}

inline void setRow(RowSystem& s, Vector& start, int i, const RowPgs::RowView& r) {
  ConstraintRow& c = s.rows[i];
  c.bodyA = r.bodyA;
  c.bodyB = r.bodyB;
  jacobianOf(r.linA, r.angA, c.jA.data());
  jacobianOf(r.linB, r.angB, c.jB.data());
  s.b[i] = r.b;
  s.lo[i] = r.lo;
  s.hi[i] = r.hi;
  s.cfm[i] = r.cfm;
  s.findex[i] = r.findex;
  start[i] = r.start;
}

// One row's values wherever they are stored (a RowSystem, an engine's own rows):
// what validation and RowPgs' packing read.
using RowRef = RowPgs::RowView;

inline RowRef viewOf(int bodyA, int bodyB, const Vector6& jA, const Vector6& jB) {
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
inline bool arraysAndBodiesValid(const RowSystem& s) {
  const int n = s.size();
  if (s.b.size() != n || s.lo.size() != n || s.hi.size() != n || s.cfm.size() != n) return false;
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != n) return false;
  for (const BodyInverseMass& body : s.bodies)
    if (!bodyValid(body)) return false;
  return true;
}

}  // namespace detail

}  // namespace mlcp
