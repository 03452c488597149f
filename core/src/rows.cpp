#include "mlcp/rows.hpp"

#include <algorithm>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"
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

// Every per-row rule of RowSystem::validate and Problem::validate (b, bounds, findex) for row i as
// one predicate without copies: the fast path of RowSystem::validate, which the adapters call
// every step, and the check RowPgs folds into its packing pass. When it says no, the checks in
// RowSystem::validate find the row and say what is wrong (Problem::validate stays the one
// statement of the bound rules' wording). A false alarm (a sum of finite Jacobian entries
// overflowing) only costs the slow path. slots = bodies + 1; the array sizes are checked.
inline bool rowValid(const RowSystem& s, int i, unsigned slots) {
  const ConstraintRow& r = s.rows[i];
  if (static_cast<unsigned>(r.bodyA + 1) >= slots || static_cast<unsigned>(r.bodyB + 1) >= slots)
    return false;
  // Any NaN or Inf entry makes the sum NaN or Inf.
  if (!std::isfinite(r.jA.sum() + r.jB.sum())) return false;
  if (!(s.cfm[i] >= 0 && s.cfm[i] < kInf)) return false;
  const double lo = s.lo[i], hi = s.hi[i];
  // !(lo <= hi) also catches NaN bounds.
  if (!std::isfinite(s.b[i]) || !(lo <= hi) || lo == kInf || hi == -kInf) return false;
  if (s.findex.empty()) return true;
  const int f = s.findex[i];
  if (f < 0) return f == -1;
  if (f >= s.size() || f == i || s.findex[f] >= 0) return false;
  return hi >= 0 && std::isfinite(hi) && lo == -hi;
}

// The rules rowValid assumes: the per-row arrays' sizes and finite, non-negative body masses.
bool arraysAndBodiesValid(const RowSystem& s) {
  const int n = s.size();
  if (s.b.size() != n || s.lo.size() != n || s.hi.size() != n || s.cfm.size() != n) return false;
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != n) return false;
  for (const BodyInverseMass& body : s.bodies)
    if (!std::isfinite(body.invMass) || body.invMass < 0 || !body.invInertia.allFinite())
      return false;
  return true;
}

// M^-1 j for one body written to out[0..5], returning j . M^-1 j. Scalar code on purpose: the
// Vector6 that applyInverseMass returns passes through a stack temporary written in 8- and
// 16-byte pieces, and reading it back in pairs stalled store forwarding on every row of the
// packing pass (a quarter of its time, measured with perf).
inline double inverseMassInto(const BodyInverseMass& body, const Vector6& j, double* out) {
  const double im = body.invMass;
  const Eigen::Matrix3d& I = body.invInertia;
  const double m[6] = {im * j[0],
                       im * j[1],
                       im * j[2],
                       I(0, 0) * j[3] + I(0, 1) * j[4] + I(0, 2) * j[5],
                       I(1, 0) * j[3] + I(1, 1) * j[4] + I(1, 2) * j[5],
                       I(2, 0) * j[3] + I(2, 1) * j[4] + I(2, 2) * j[5]};
  double d = 0;
  for (int k = 0; k < 6; ++k) {
    out[k] = m[k];
    d += j[k] * m[k];
  }
  return d;
}

bool rowsValid(const RowSystem& s) {
  const unsigned slots = static_cast<unsigned>(s.bodies.size()) + 1;  // -1 .. nb - 1
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != s.size()) return false;
  for (int i = 0; i < s.size(); ++i)
    if (!rowValid(s, i, slots)) return false;
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
    if (!std::isfinite(body.invMass) || body.invMass < 0 || !body.invInertia.allFinite()) {
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
  p.swapA(A);  // A now holds the problem's previous sparse matrix
  if (samePattern) {
    double* values = A.valuePtr();
    std::fill_n(values, A.nonZeros(), 0.0);
    const int* slot = scratch.valueSlot.data();
    forEachProduct([&](int, int, double v) { values[*slot++] += v; });
  } else {
    auto& triplets = scratch.triplets;
    triplets.clear();
    forEachProduct([&](int i, int j, double v) { triplets.emplace_back(i, j, v); });
    A.resize(n, n);
    A.setFromTriplets(triplets.begin(), triplets.end());
    A.makeCompressed();
    // Where each product landed (row-major: search the row's sorted column indices).
    scratch.valueSlot.resize(triplets.size());
    for (std::size_t t = 0; t < triplets.size(); ++t) {
      const int row = triplets[t].row();
      const int* first = A.innerIndexPtr() + A.outerIndexPtr()[row];
      const int* last = A.innerIndexPtr() + A.outerIndexPtr()[row + 1];
      scratch.valueSlot[t] =
          static_cast<int>(std::lower_bound(first, last, triplets[t].col()) - A.innerIndexPtr());
    }
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

void RowPgs::slackFromVelocities(const RowSystem& s, const Vector& x) {
  const int n = static_cast<int>(packed_.size());
  w_.resize(n);
  for (int i = 0; i < n; ++i) {
    const PackedRow& p = packed_[i];
    const ConstraintRow& r = s.rows[i];
    w_[i] = r.jA.dot(velocity_[p.a].v) + r.jB.dot(velocity_[p.b].v) + s.cfm[i] * x[i] + s.b[i];
  }
}

Result RowPgs::solve(const RowSystem& s, Vector& x) {
  const double t0 = nowSeconds();
  const Options& opt = options_;
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
  const int world = static_cast<int>(s.bodies.size());  // the first zero-velocity slot
  const unsigned slots = static_cast<unsigned>(world) + 1;
  // Ground rows take the world slots in turn (per run of rows on the same bodies): one shared
  // slot would chain them all through its store and load (see rows.hpp).
  unsigned nextWorld = 0;
  int runStart = 0;        // first row of the current run
  int runA = 0, runB = 0;  // its slots (kept here: reading them back from packed_ right after
                           // their 4-byte stores stalled store forwarding)
  auto worldSlot = [&] { return world + static_cast<int>(nextWorld++ % kWorldSlots); };
  // x is the caller's until the input is known to be valid: a cold start reads zeros.
  const bool warm = opt.warmStart && x.size() == n && x.allFinite();

  packed_.resize(n);
  velocity_.resize(world + kWorldSlots);
  for (BodyVelocity& v : velocity_) v.v.setZero();
  double d = 0;  // A_ii of the row that stopped the packing
  int bad = -1;  // that row
  for (int i = 0; i < n; ++i) {
    if (!rowValid(s, i, slots)) return invalid(s.validate());
    const ConstraintRow& r = s.rows[i];
    PackedRow& p = packed_[i];
    // "The world" (-1) becomes the zero-velocity slot (its J meets v = 0, its M^-1 J^T is 0).
    if (i > 0 && r.bodyA == s.rows[i - 1].bodyA && r.bodyB == s.rows[i - 1].bodyB &&
        r.bodyA != r.bodyB) {
      ++packed_[runStart].run;
    } else {
      runStart = i;
      p.run = 1;
      runA = r.bodyA >= 0 ? r.bodyA : worldSlot();
      runB = r.bodyB >= 0 ? r.bodyB : worldSlot();
    }
    p.a = runA;
    p.b = runB;
    double mA[6] = {}, mB[6] = {};
    const double dA = r.bodyA >= 0 ? inverseMassInto(s.bodies[r.bodyA], r.jA, mA) : 0.0;
    const double dB = r.bodyB >= 0 ? inverseMassInto(s.bodies[r.bodyB], r.jB, mB) : 0.0;
    p.lo = s.lo[i];
    p.hi = s.hi[i];
    p.findex = s.findex.empty() ? -1 : s.findex[i];
    d = dA + dB + s.cfm[i];
    // A row joining a body to itself: A_ii = (jA + jB) M^-1 (jA + jB) has the cross terms too.
    if (r.bodyA == r.bodyB && r.bodyA >= 0)
      for (int k = 0; k < 6; ++k) d += r.jA[k] * mB[k] + r.jB[k] * mA[k];
    if (!(d > 0)) {
      bad = i;
      break;
    }
    const double step = opt.relaxation / d;
    p.sA = step * r.jA;
    p.sB = step * r.jB;
    p.keep = 1 - step * s.cfm[i];
    p.shift = step * s.b[i];
    // v = M^-1 J^T x of the start (from mA, mB, not from p.mA, p.mB just stored: see above).
    const double xi = warm ? x[i] : 0.0;
    double* va = velocity_[runA].v.data();
    double* vb = velocity_[runB].v.data();
    for (int k = 0; k < 6; ++k) {
      p.mA[k] = mA[k];
      p.mB[k] = mB[k];
    }
    if (xi != 0) {
      for (int k = 0; k < 6; ++k) {
        va[k] += mA[k] * xi;
        vb[k] += mB[k] * xi;
      }
    }
  }
  // The world never moves (its blocks are zero anyway).
  for (int k = 0; k < kWorldSlots; ++k) velocity_[world + k].v.setZero();
  // The input is valid from here on (a non-positive A_ii is a failure, not invalid input):
  // x is the iterate (no copy).
  if (!warm) x.setZero(n);
  const double bNorm = n ? s.b.lpNorm<Eigen::Infinity>() : 0.0;
  Accuracy last;           // accuracy of x as it is after the last check
  bool lastValid = false;  // whether x is unchanged since
  auto check = [&]() {
    slackFromVelocities(s, x);
    last = accuracy(x, w_, s.lo, s.hi, s.findex, bNorm);
    lastValid = true;
  };
  auto finish = [&]() {
    if (!lastValid) check();
    applyAccuracy(result, last, opt.tolerance);
    result.seconds = nowSeconds() - t0;
    return result;
  };
  if (bad >= 0) {
    // Rows after it are not checked yet; validate them all before reporting the failure.
    if (std::string why = s.validate(); !why.empty()) return invalid(why);
    // velocity_ does not hold M^-1 J^T x: the final check uses the rows themselves.
    packed_.resize(bad);
    std::ostringstream os;
    os << "row " << bad << " has A_ii = " << d << ": pgs needs a positive diagonal";
    result.status = Status::Failed;
    result.message = os.str();
    last = accuracy(x, s.slack(x), s.lo, s.hi, s.findex, bNorm);
    lastValid = true;
    return finish();
  }

  detail::SweepMonitor monitor(opt, result);
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
  }
  double* xs = x.data();
  // One row's update; va and vb are the same object when the row joins a body to itself.
  auto visit = [&](const PackedRow& p, int i, Vector6& va, Vector6& vb) {
    // One reduction for both bodies: the row's latency chain is the sweep's critical path.
    const double jv = (p.sA.cwiseProduct(va) + p.sB.cwiseProduct(vb)).sum();
    double lo = p.lo, hi = p.hi;
    if (p.findex >= 0) {
      const double normal = std::abs(xs[p.findex]);
      lo *= normal;
      hi *= normal;
    }
    // The new x is clamp(c - jv, lo, hi) with c = keep x - shift. The change that moves the
    // velocities is clamped on its own, clamp((c - x) - jv, lo - x, hi - x) (the same up to
    // round-off), so that the chain does not wait for the subtraction x_new - x.
    const double xo = xs[i], c = p.keep * xo - p.shift;
    const double dx = std::clamp((c - xo) - jv, lo - xo, hi - xo);
    xs[i] = std::clamp(c - jv, lo, hi);
    va += p.mA * dx;
    vb += p.mB * dx;
  };
  for (int sweep = 1; n > 0 && sweep <= opt.maxIterations; ++sweep) {
    for (int i = 0; i < n;) {
      const PackedRow& first = packed_[i];
      if (first.a == first.b) {
        visit(first, i, velocity_[first.a].v, velocity_[first.a].v);
        ++i;
        continue;
      }
      // A run's velocities stay in registers (no store-load round trip between its rows).
      Vector6 va = velocity_[first.a].v, vb = velocity_[first.b].v;
      for (const int end = i + first.run; i < end; ++i) visit(packed_[i], i, va, vb);
      velocity_[first.a].v = va;
      velocity_[first.b].v = vb;
    }
    lastValid = false;
    if (!monitor.wantsCheck(sweep)) continue;
    check();
    if (monitor.stop(sweep, last)) break;
  }
  return finish();
}

}  // namespace mlcp
