#include "mlcp/rows.hpp"

#include <algorithm>
#include <sstream>
#include <type_traits>

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

// One row's values wherever they are stored (a RowSystem, RowPgs::Row, an engine's own rows):
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

RowRef rowView(const RowPgs::Row& row) {
  RowRef r = viewOf(row.bodyA, row.bodyB, row.jA, row.jB);
  r.b = row.b;
  r.cfm = row.cfm;
  r.lo = row.lo;
  r.hi = row.hi;
  r.findex = row.findex;
  r.start = row.start;
  r.base = row.base;
  return r;
}

// A view's Jacobian block as [linear; angular] (a missing part reads as zeros).
inline void jacobianOf(const double* lin, const double* ang, double* j) {
  for (int k = 0; k < 3; ++k) {
    j[k] = lin ? lin[k] : 0.0;
    j[3 + k] = ang ? ang[k] : 0.0;
  }
}

// The rows of a RowFill, fetched in batches of 64 (a few kB, stays in L1).
class FillSource final : public RowPgs::RowSource {
 public:
  FillSource(const RowPgs::RowFill& fill, int n) : fill_(fill), n_(n) {}
  RowRef row(int i) override {
    if (i >= fetched_ || i < fetched_ - kBatch) {  // the next batch, or the slow path's re-read
      fill_(i, std::min(kBatch, n_ - i), batch_.data());
      fetched_ = i + kBatch;
    }
    return rowView(batch_[i - (fetched_ - kBatch)]);
  }

 private:
  static constexpr int kBatch = 64;
  const RowPgs::RowFill& fill_;
  int n_, fetched_ = 0;
  std::vector<RowPgs::Row> batch_ = std::vector<RowPgs::Row>(kBatch);
};

// Every per-row rule of RowSystem::validate and Problem::validate (b, bounds, findex) for row i of
// n as one predicate without copies, except that row findex's own findex must be -1 (the callers
// check that against the other row): the fast path of RowSystem::validate, which the adapters
// call every step, and the check RowPgs folds into its packing pass. When it says no, the checks
// in RowSystem::validate find the row and say what is wrong (Problem::validate stays the one
// statement of the bound rules' wording). A false alarm (a sum of finite Jacobian entries
// overflowing) only costs the slow path. slots = bodies + 1; the array sizes are checked.
inline bool rowValid(const RowRef& r, const double* jA, const double* jB, int i, int n,
                     unsigned slots) {
  if (static_cast<unsigned>(r.bodyA + 1) >= slots || static_cast<unsigned>(r.bodyB + 1) >= slots)
    return false;
  // Any NaN or Inf entry makes the sum NaN or Inf.
  double sum = 0;
  for (int k = 0; k < 6; ++k) sum += jA[k] + jB[k];
  if (!std::isfinite(sum)) return false;
  if (!(r.cfm >= 0 && r.cfm < kInf)) return false;
  const double lo = r.lo, hi = r.hi;
  // !(lo <= hi) also catches NaN bounds.
  if (!std::isfinite(r.b) || !(lo <= hi) || lo == kInf || hi == -kInf) return false;
  const int f = r.findex;
  if (f < 0) return f == -1;
  if (f >= n || f == i) return false;
  return hi >= 0 && std::isfinite(hi) && lo == -hi;
}

// A finite, non-negative inverse mass and a finite inverse inertia.
bool bodyValid(const BodyInverseMass& body) {
  return std::isfinite(body.invMass) && body.invMass >= 0 && body.invInertia.allFinite();
}

// The rules rowValid assumes: the per-row arrays' sizes and finite, non-negative body masses.
bool arraysAndBodiesValid(const RowSystem& s) {
  const int n = s.size();
  if (s.b.size() != n || s.lo.size() != n || s.hi.size() != n || s.cfm.size() != n) return false;
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != n) return false;
  for (const BodyInverseMass& body : s.bodies)
    if (!bodyValid(body)) return false;
  return true;
}

// M^-1 j for one body written to out[0..5], returning j . M^-1 j; the angular part is the
// engine's own invAng when given (RowPgs::RowView: the same products, computed by the engine).
// Scalar code on purpose: the Vector6 that applyInverseMass returns passes through a stack
// temporary written in 8- and 16-byte pieces, and reading it back in pairs stalled store
// forwarding on every row of the packing pass (a quarter of its time, measured with perf).
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
  for (int i = 0; i < s.size(); ++i) {
    const RowRef r = systemRow(s, i, nullptr);
    if (!rowValid(r, s.rows[i].jA.data(), s.rows[i].jB.data(), i, s.size(), slots) ||
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
    if (!bodyValid(body)) {
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

void RowPgs::slackFromVelocities(const Vector& x) {
  const int n = static_cast<int>(packed_.size());
  w_.resize(n);
  for (int i = 0; i < n; ++i) {
    const PackedRow& p = packed_[i];
    // step w_i = (1 - keep) x_i + shift + step J v: the sweep's own terms (see rows.hpp).
    const double jv =
        (p.sA.cwiseProduct(velocity_[p.a].v) + p.sB.cwiseProduct(velocity_[p.b].v)).sum();
    w_[i] = scale_[i] * ((1 - p.keep) * x[i] + p.shift + jv);
  }
}

template <class RowAt>
bool RowPgs::pack(const std::vector<BodyInverseMass>& bodies, int n, RowAt&& rowAt, bool warm,
                  double* xOut, bool withBase) {
  const int world = static_cast<int>(bodies.size());  // the first zero-velocity slot
  const unsigned slots = static_cast<unsigned>(world) + 1;
  // Ground rows take the world slots in turn (per run of rows on the same bodies): one shared
  // slot would chain them all through its store and load (see rows.hpp).
  unsigned nextWorld = 0;
  int runStart = 0;            // first row of the current run
  int runA = 0, runB = 0;      // its slots (kept here: reading them back from packed_ right after
                               // their 4-byte stores stalled store forwarding)
  int lastA = -2, lastB = -2;  // the previous row's bodies
  int runLength = 0;
  double runM[kMaxRun][12];  // the run's M^-1 J^T so far (for its couplings)
  std::size_t coupled = 0;   // couplings written
  if (coupling_.size() < static_cast<std::size_t>(n) * (kMaxRun - 1))
    coupling_.resize(static_cast<std::size_t>(n) * (kMaxRun - 1));
  auto worldSlot = [&] { return world + static_cast<int>(nextWorld++ % kWorldSlots); };
  packed_.resize(n);
  scale_.resize(n);
  velocity_.resize(world + kWorldSlots);
  for (BodyVelocity& v : velocity_) v.v.setZero();
  if (withBase) {
    base_.resize(world + kWorldSlots);
    for (BodyVelocity& v : base_) v.v.setZero();
  }
  bad_ = -1;
  const bool unitRelaxation = options_.relaxation == 1;
  auto stop = [&](int i, double d) {
    bad_ = i;
    badDiagonal_ = d;
    return false;
  };
  int later = -1;  // the first row whose findex points forward (checked after the pass)
  for (int i = 0; i < n; ++i) {
    const RowRef r = rowAt(i);
    double jA[6], jB[6];
    jacobianOf(r.linA, r.angA, jA);
    jacobianOf(r.linB, r.angB, jB);
    if (!rowValid(r, jA, jB, i, n, slots)) return stop(i, std::nan(""));
    PackedRow& p = packed_[i];
    p.findex = r.findex;
    if (r.findex >= 0) {
      if (r.findex > i) {
        if (later < 0) later = i;
      } else if (packed_[r.findex].findex >= 0) {
        return stop(i, std::nan(""));
      }
    }
    // "The world" (-1) becomes the zero-velocity slot (its J meets v = 0, its M^-1 J^T is 0).
    if (i > 0 && r.bodyA == lastA && r.bodyB == lastB && r.bodyA != r.bodyB &&
        runLength < kMaxRun) {
      ++packed_[runStart].run;
      ++runLength;
    } else {
      runStart = i;
      runLength = 1;
      p.run = 1;
      runA = r.bodyA >= 0 ? r.bodyA : worldSlot();
      runB = r.bodyB >= 0 ? r.bodyB : worldSlot();
    }
    lastA = r.bodyA;
    lastB = r.bodyB;
    p.a = runA;
    p.b = runB;
    double mA[6] = {}, mB[6] = {};
    const double dA = r.bodyA >= 0 ? inverseMassInto(bodies[r.bodyA], jA, r.invAngA, mA) : 0.0;
    const double dB = r.bodyB >= 0 ? inverseMassInto(bodies[r.bodyB], jB, r.invAngB, mB) : 0.0;
    p.lo = r.lo;
    p.hi = r.hi;
    double d = dA + dB + r.cfm;
    // A row joining a body to itself: A_ii = (jA + jB) M^-1 (jA + jB) has the cross terms too.
    if (r.bodyA == r.bodyB && r.bodyA >= 0)
      for (int k = 0; k < 6; ++k) d += jA[k] * mB[k] + jB[k] * mA[k];
    if (!(d > 0)) return stop(i, d);
    const double step = options_.relaxation / d;
    for (int k = 0; k < 6; ++k) {
      p.sA[k] = step * jA[k];
      p.sB[k] = step * jB[k];
    }
    // Couplings to the run's earlier rows k: step J_i M^-1 J_k^T on the run's two bodies, i.e.
    // sA . mA_k + sB . mB_k (scalars from locals: no reading back of what was just stored).
    // step J_i in scalars once (the products the sums used, so the same couplings to the bit).
    double sJ[12];
    for (int j = 0; j < 6; ++j) {
      sJ[j] = step * jA[j];
      sJ[6 + j] = step * jB[j];
    }
    for (int k = 0; k + 1 < runLength; ++k) {
      double c = 0;
      for (int j = 0; j < 12; ++j) c += sJ[j] * runM[k][j];
      coupling_[coupled++] = c;
    }
    for (int j = 0; j < 6; ++j) {
      runM[runLength - 1][j] = mA[j];
      runM[runLength - 1][6 + j] = mB[j];
    }
    p.keep = 1 - step * r.cfm;
    p.shift = step * r.b;
    scale_[i] = unitRelaxation ? d : d / options_.relaxation;  // d / 1 = d: no second division
    // v = M^-1 J^T x of the start (from mA, mB, not from p.mA, p.mB just stored: see above).
    const double xi = warm ? r.start : 0.0;
    if (xOut) xOut[i] = xi;
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
    // base_ holds M^-1 J^T (base - start) here; the start's velocities are added after the
    // pass (an engine's base is mostly its start: no second 12-wide update per row).
    if (withBase && r.base != xi) {
      const double extra = r.base - xi;
      double* ba = base_[runA].v.data();
      double* bb = base_[runB].v.data();
      for (int k = 0; k < 6; ++k) {
        ba[k] += mA[k] * extra;
        bb[k] += mB[k] * extra;
      }
    }
  }
  for (int i = std::max(later, 0); later >= 0 && i < n; ++i)
    if (packed_[i].findex > i && packed_[packed_[i].findex].findex >= 0)
      return stop(i, std::nan(""));
  // The world never moves (its blocks are zero anyway).
  for (int k = 0; k < kWorldSlots; ++k) velocity_[world + k].v.setZero();
  if (withBase)
    for (int k = 0; k < world; ++k) base_[k].v += velocity_[k].v;
  return true;
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
  if (!pack(
          s.bodies, n, [&](int i) { return systemRow(s, i, start); }, warm, nullptr, false)) {
    // Rows after the one that stopped the packing are not checked yet: validate them all.
    if (std::string why = s.validate(); !why.empty()) return invalid(why);
    // The input is valid: a non-positive A_ii is a failure, not invalid input.
    if (!warm) x.setZero(n);
    std::ostringstream os;
    os << "row " << bad_ << " has A_ii = " << badDiagonal_ << ": pgs needs a positive diagonal";
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
  return iterate(x, s.lo, s.hi, s.findex, n ? s.b.lpNorm<Eigen::Infinity>() : 0.0, t0);
}

namespace {

void resizeSystem(const std::vector<BodyInverseMass>& bodies, int n, RowSystem& s, Vector& start) {
  s.bodies = bodies;
  s.rows.resize(n);
  s.b.resize(n);
  s.lo.resize(n);
  s.hi.resize(n);
  s.cfm.resize(n);
  s.findex.resize(n);
  start.resize(n);
}

void setRow(RowSystem& s, Vector& start, int i, const RowRef& r) {
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

}  // namespace

void RowPgs::toSystem(const std::vector<BodyInverseMass>& bodies, int n, const RowFill& fill,
                      RowSystem& s, Vector& start) {
  resizeSystem(bodies, n, s, start);
  std::vector<Row> all(n);
  if (n > 0) fill(0, n, all.data());
  for (int i = 0; i < n; ++i) setRow(s, start, i, rowView(all[i]));
}

void RowPgs::toSystem(const std::vector<BodyInverseMass>& bodies, int n, RowSource& source,
                      RowSystem& s, Vector& start) {
  resizeSystem(bodies, n, s, start);
  for (int i = 0; i < n; ++i) setRow(s, start, i, source.row(i));
}

Result RowPgs::solve(const std::vector<BodyInverseMass>& bodies, int n, const RowFill& fill,
                     Vector& x) {
  FillSource source(fill, std::max(n, 0));
  return solve(bodies, n, source, x);
}

Result RowPgs::solve(const std::vector<BodyInverseMass>& bodies, int n, RowSource& source,
                     Vector& x) {
  const double t0 = nowSeconds();
  baseValid_ = false;
  // The slow path: the same rows as a RowSystem, solved (or refused) by solve(RowSystem).
  auto slow = [&] {
    RowSystem s;
    toSystem(bodies, n, source, s, x);
    return solve(s, x);
  };
  const Options& opt = options_;
  if (n < 0) {
    Result r;
    r.status = Status::InvalidInput;
    r.message = "negative row count";
    return r;
  }
  if (!(opt.relaxation > 0 && opt.relaxation < 2)) return slow();
  for (const BodyInverseMass& body : bodies)
    if (!bodyValid(body)) return slow();
  x.resize(n);
  lo_.resize(n);
  hi_.resize(n);
  findex_.resize(n);
  double bNorm = 0;
  const bool packed = pack(
      bodies, n,
      [&](int i) {
        const RowRef r = source.row(i);
        lo_[i] = r.lo;
        hi_[i] = r.hi;
        findex_[i] = r.findex;
        bNorm = std::max(bNorm, std::abs(r.b));
        return r;
      },
      opt.warmStart, x.data(), true);
  if (!packed) return slow();
  // A non-finite start: solve(RowSystem) starts cold (velocity_ and base_ hold NaN here).
  if (!x.allFinite()) return slow();
  // A non-finite base would make every velocityChange NaN: no per-body changes then (the
  // caller applies x row by row, as after the slow path).
  for (int k = 0; k < static_cast<int>(bodies.size()); ++k)
    if (!base_[k].v.allFinite()) return iterate(x, lo_, hi_, findex_, bNorm, t0);
  baseValid_ = true;
  return iterate(x, lo_, hi_, findex_, bNorm, t0);
}

Result RowPgs::iterate(Vector& x, const Vector& lo, const Vector& hi,
                       const std::vector<int>& findex, double bNorm, double t0) {
  const Options& opt = options_;
  const int n = static_cast<int>(packed_.size());
  Result result;
  Accuracy last;           // accuracy of x as it is after the last check
  bool lastValid = false;  // whether x is unchanged since
  auto check = [&]() {
    slackFromVelocities(x);
    last = accuracy(x, w_, lo, hi, findex, bNorm);
    lastValid = true;
  };
  detail::SweepMonitor monitor(opt, result);
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
  }
  double* xs = x.data();
  // One row's update from jv = step J_i v; returns the change of x_i that moves the velocities.
  auto update = [&](const PackedRow& p, int i, double jv) {
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
    return dx;
  };
  for (int sweep = 1; n > 0 && sweep <= opt.maxIterations; ++sweep) {
    const double* coupling = coupling_.data();
    for (int i = 0; i < n;) {
      const PackedRow& first = packed_[i];
      if (first.a == first.b) {
        // A row joining a body to itself: va and vb are the same object.
        Vector6& v = velocity_[first.a].v;
        const double dx =
            update(first, i, (first.sA.cwiseProduct(v) + first.sB.cwiseProduct(v)).sum());
        v += first.mA * dx;
        v += first.mB * dx;
        ++i;
        continue;
      }
      // A run on two bodies: each row's step J v is its product with the velocities at the
      // run's start plus its couplings to the changes of the run's earlier rows, so the chain
      // from one row to the next is a multiply-add instead of the 12-wide dot after a 12-wide
      // velocity update; the velocities take the run's changes at its end. Unrolled per length
      // so that the changes stay in registers (reading them back from a stack array in pairs
      // stalled store forwarding on every coupling).
      const int length = first.run;
      auto sweepRun = [&](auto size) {
        constexpr int L = decltype(size)::value;
        const Vector6 va = velocity_[first.a].v, vb = velocity_[first.b].v;
        double dxs[L];
#pragma GCC unroll 8
        for (int k = 0; k < L; ++k) {
          const PackedRow& p = packed_[i + k];
          double jv = (p.sA.cwiseProduct(va) + p.sB.cwiseProduct(vb)).sum();
#pragma GCC unroll 8
          for (int m = 0; m < k; ++m) jv += coupling[m] * dxs[m];
          coupling += k;
          dxs[k] = update(p, i + k, jv);
        }
        Vector6 da = Vector6::Zero(), db = Vector6::Zero();
#pragma GCC unroll 8
        for (int k = 0; k < L; ++k) {
          da += packed_[i + k].mA * dxs[k];
          db += packed_[i + k].mB * dxs[k];
        }
        velocity_[first.a].v = va + da;
        velocity_[first.b].v = vb + db;
      };
      static_assert(kMaxRun == 8, "one case per run length");
      switch (length) {
        case 1: sweepRun(std::integral_constant<int, 1>()); break;
        case 2: sweepRun(std::integral_constant<int, 2>()); break;
        case 3: sweepRun(std::integral_constant<int, 3>()); break;
        case 4: sweepRun(std::integral_constant<int, 4>()); break;
        case 5: sweepRun(std::integral_constant<int, 5>()); break;
        case 6: sweepRun(std::integral_constant<int, 6>()); break;
        case 7: sweepRun(std::integral_constant<int, 7>()); break;
        default: sweepRun(std::integral_constant<int, 8>()); break;
      }
      i += length;
    }
    lastValid = false;
    if (!monitor.wantsCheck(sweep)) continue;
    check();
    if (monitor.stop(sweep, last)) break;
  }
  if (!lastValid) check();
  applyAccuracy(result, last, opt.tolerance);
  result.seconds = nowSeconds() - t0;
  return result;
}

}  // namespace mlcp
