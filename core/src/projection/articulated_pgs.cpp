// RowPgs on rows with articulated sides (mlcp/rows.hpp): the sweep of row_pgs.hpp's update
// rule through J and W = M^-1 J^T, without A. Per row the rigid sides read and update their
// bodies' 6-vectors v = M^-1 J^T x, the articulated sides their body's velocity vector
// u = sum W_i x_i; A_ii = cfm_i + J_i M^-1 J_i^T + sum J_i . W_i is computed once per solve.
// Not packed: the packed rows of row_pack.hpp hold two 6-wide sides, and articulated rows are
// few (Bullet's multibody worlds: joint limits, motors and the contacts on links).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "projection/sweep_monitor.hpp"

namespace mlcp {

namespace {

struct ArticulatedRows {
  std::vector<int> first;       // per row, its sides in `order` (CSR, size n + 1)
  std::vector<int> order;       // side indices grouped by row
  std::vector<int> offset;      // per articulated body, its velocities' start in u
  std::vector<Vector6> mA, mB;  // per row, M^-1 J^T of its rigid sides
  Vector invDiag;

  // -1 when every A_ii is positive and finite, else the first row that is not (diag set).
  int build(const RowSystem& s, double& diag) {
    const int n = s.size();
    first.assign(n + 1, 0);
    for (const ArticulatedSide& a : s.sides) ++first[a.row + 1];
    for (int i = 0; i < n; ++i) first[i + 1] += first[i];
    order.resize(s.sides.size());
    std::vector<int> next(first.begin(), first.end() - 1);
    for (int k = 0; k < static_cast<int>(s.sides.size()); ++k) order[next[s.sides[k].row]++] = k;
    offset.assign(s.articulated.size() + 1, 0);
    for (std::size_t k = 0; k < s.articulated.size(); ++k)
      offset[k + 1] = offset[k] + s.articulated[k];
    mA.resize(n);
    mB.resize(n);
    invDiag.resize(n);
    auto inverseMass = [&](int body, const Vector6& j) {
      Vector6 m = Vector6::Zero();
      if (body < 0) return m;
      const BodyInverseMass& b = s.bodies[body];
      m << b.invMass * j.head<3>(), b.invInertia * j.tail<3>();
      return m;
    };
    for (int i = 0; i < n; ++i) {
      const ConstraintRow& r = s.rows[i];
      mA[i] = inverseMass(r.bodyA, r.jA);
      mB[i] = inverseMass(r.bodyB, r.jB);
      double d = s.cfm[i] + (r.bodyA >= 0 ? r.jA.dot(mA[i]) : 0.0) +
                 (r.bodyB >= 0 ? r.jB.dot(mB[i]) : 0.0);
      for (int k = first[i]; k < first[i + 1]; ++k) {
        const ArticulatedSide& a = s.sides[order[k]];
        for (int e = 0; e < s.articulated[a.body]; ++e)
          d += s.jacobian[a.at + e] * s.unitImpulse[a.at + e];
      }
      if (!(d > 0) || !std::isfinite(d)) {
        diag = d;
        return i;
      }
      invDiag[i] = 1 / d;
    }
    return -1;
  }
};

// One sweep of the projected update x_i <- clamp(x_i - omega w_i / A_ii, lo', hi') in row order,
// v and u kept equal to M^-1 J^T x.
void sweep(const RowSystem& s, const ArticulatedRows& ar, double omega, Vector& x,
           std::vector<Vector6>& v, Vector& u) {
  const bool fx = !s.findex.empty();
  for (int i = 0; i < s.size(); ++i) {
    const ConstraintRow& r = s.rows[i];
    double w = s.b[i] + s.cfm[i] * x[i];
    if (r.bodyA >= 0) w += r.jA.dot(v[r.bodyA]);
    if (r.bodyB >= 0) w += r.jB.dot(v[r.bodyB]);
    for (int k = ar.first[i]; k < ar.first[i + 1]; ++k) {
      const ArticulatedSide& a = s.sides[ar.order[k]];
      const double* j = s.jacobian.data() + a.at;
      const double* ua = u.data() + ar.offset[a.body];
      for (int e = 0; e < s.articulated[a.body]; ++e) w += j[e] * ua[e];
    }
    double lo = s.lo[i], hi = s.hi[i];
    if (fx && s.findex[i] >= 0) {
      const double normal = std::abs(x[s.findex[i]]);
      lo *= normal;
      hi *= normal;
    }
    const double xi = std::clamp(x[i] - omega * w * ar.invDiag[i], lo, hi);
    const double delta = xi - x[i];
    if (delta == 0) continue;
    x[i] = xi;
    if (r.bodyA >= 0) v[r.bodyA] += delta * ar.mA[i];
    if (r.bodyB >= 0) v[r.bodyB] += delta * ar.mB[i];
    for (int k = ar.first[i]; k < ar.first[i + 1]; ++k) {
      const ArticulatedSide& a = s.sides[ar.order[k]];
      const double* wa = s.unitImpulse.data() + a.at;
      double* ua = u.data() + ar.offset[a.body];
      for (int e = 0; e < s.articulated[a.body]; ++e) ua[e] += delta * wa[e];
    }
  }
}

}  // namespace

Result RowPgs::solveArticulated(const RowSystem& s, Vector& x, double t0) {
  const Options& opt = options_;
  Result result;
  if (std::string why = s.validate(); !why.empty()) {
    result.status = Status::InvalidInput;
    result.message = std::move(why);
    return result;
  }
  const int n = s.size();
  const bool warm = opt.warmStart && x.size() == n && x.allFinite();
  if (!warm) x.setZero(n);
  const double bNorm = n ? s.b.lpNorm<Eigen::Infinity>() : 0.0;
  ArticulatedRows ar;
  double diag = 0;
  if (const int bad = ar.build(s, diag); bad >= 0) {
    std::ostringstream os;
    os << "row " << bad << " has A_ii = " << diag << ": pgs needs a positive finite diagonal";
    result.status = Status::Failed;
    result.message = os.str();
    applyAccuracy(result, accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm), opt.tolerance);
    result.seconds = nowSeconds() - t0;
    return result;
  }
  std::vector<Vector6> v = s.bodyVelocities(x);
  Vector u = s.articulatedVelocities(x);
  detail::SweepMonitor monitor(opt, result, n);
  if (n == 0 || opt.maxIterations <= 0) {
    applyAccuracy(result, accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm), opt.tolerance);
  } else {
    for (int k = 1; k <= opt.maxIterations; ++k) {
      sweep(s, ar, opt.relaxation, x, v, u);
      if (monitor.wantsCheck(k)) {
        const Accuracy a = accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm);
        const bool stop = monitor.stop(k, a);
        applyAccuracy(result, a, opt.tolerance);
        if (stop) break;
      } else if (monitor.outOfTime(k)) {
        applyAccuracy(result, accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm), opt.tolerance);
        break;
      }
    }
  }
  result.solver = "pgs";
  result.seconds = nowSeconds() - t0;
  return result;
}

}  // namespace mlcp
