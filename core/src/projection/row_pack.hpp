// core/src/projection/row_pack.hpp (internal): RowPgs' packed rows and body velocities, and the
// passes over them (the three stages of mlcp/solvers/row_pgs.hpp): the packing pass as a template
// over the row source, so that solve(RowSystem) and the engine entry point (row_pgs.cpp) share
// one packing code with each source's row() inlined into the loop; the sweep and check bodies
// are in row_sweep.hpp. Each pass runs as compiled for the baseline or, where cpuPath() says so,
// its AVX2 variant (cpu_dispatch.hpp): the same source, the same bits.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <vector>

#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "projection/cpu_dispatch.hpp"
#include "projection/row_checks.hpp"

namespace mlcp {

struct RowPgs::Packing {
  // Everything the sweep reads per row, in one stream: bodies remapped so that "the world" is
  // a zero-velocity slot (no branches in the inner loop), M^-1 J^T, and the update
  //     x_i <- clamp(x_i - step (J_i v + cfm_i x_i + b_i), lo', hi'),   step = omega / A_ii,
  // regrouped as clamp(keep x_i - shift - (step J_i) v) with keep = 1 - step cfm_i and
  // shift = step b_i: only the product with v depends on the rows just visited, so the row's
  // latency chain (load v, dot, clamp, update v) holds one subtraction instead of a
  // multiplication and three additions (the same iterates up to round-off).
  // The change moving v is clamped apart, dx = clamp((c - x_i) - J v', lo - x_i, hi - x_i) with
  // c = keep x_i - shift, while x_i itself becomes clamp(c - J v', lo, hi): the chain does not
  // wait for x_new - x_i, v and x agree up to round-off, and x stays exactly within its bounds.
  struct PackedRow {
    Vector6 sA, sB;  // step * J
    Vector6 mA, mB;  // M^-1 J^T
    double keep, shift, lo, hi;
    int a, b, findex;
    int run;  // first row of a run: how many rows from here join the same two bodies a != b
  };
  // A body's velocity change padded to one cache line.
  struct alignas(64) BodyVelocity {
    Vector6 v;
    double pad[2];
  };
  // Zero-velocity slots standing for "the world", taken by ground rows in turn.
  static constexpr int kWorldSlots = 8;
  // Longest run of rows on the same two bodies swept as one (longer ones are split): its
  // couplings take (kMaxRun - 1) kMaxRun / 2 numbers. 8 = a box face's 4 contacts' friction rows.
  static constexpr int kMaxRun = 8;
  // Fills packed_ and velocity_ from rowAt(i); false at the first invalid row or non-positive
  // A_ii (bad_, badDiagonal_ say which). relaxation is Options::relaxation.
  // pack(), sweepOnce() and packedAccuracy() run their body (packRows, sweepRows, checkRows) as
  // compiled for the baseline or, where cpuPath() says so, its AVX2 variant.
  template <class RowAt>
  bool pack(const std::vector<BodyInverseMass>& bodies, int n, RowAt&& rowAt, double relaxation,
            bool warm, double* x, bool withBase);
  template <class RowAt>
  bool packRows(const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt, double relaxation,
                bool warm, double* x, bool withBase);
  // packRows' first and last stage: the buffers sized and zeroed; after the pass, the forward
  // findex rows checked (from `later`, the first of them), the world slots zeroed and the bases
  // completed. stop() records the row that failed (bad_, badDiagonal_) and returns false.
  void beginPack(int n, int world, bool withBase);
  bool endPack(int n, int world, int later, bool withBase);
  bool stop(int i, double d) {
    bad_ = i;
    badDiagonal_ = d;
    return false;
  }
#if MLCP_CPU_DISPATCH
  template <class RowAt>
  MLCP_AVX2_VARIANT bool packAvx2(const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt,
                                  double relaxation, bool warm, double* x, bool withBase);
  MLCP_AVX2_VARIANT void sweepAvx2(double* x);
  MLCP_AVX2_VARIANT Accuracy checkAvx2(const Vector& x, double bNorm) const;
#endif
  // Wide: with 4-wide vectors (the AVX2 variants), else in pairs (row_simd.hpp).
  template <bool Wide>
  void sweepRows(double* x);
  template <bool Wide>
  Accuracy checkRows(const Vector& x, double bNorm) const;
  // One row's update from jv = step J_i v (x[i] takes its new value); returns the change of x_i
  // that moves the velocities.
  static double update(const PackedRow& p, double* x, int i, double jv);
  // One sweep over packed_ (x and the velocities updated in place).
  void sweepOnce(double* x);
  // The check: accuracy() of x with w = J v + cfm x + b from the packed rows and velocities.
  Accuracy packedAccuracy(const Vector& x, double bNorm) const;

  std::vector<PackedRow> packed_;  // reused between solves
  std::vector<int> findexOf_;      // packed_[i].findex again, compact (pack() validates with it)
  // Per row 1 / step, for the check only (kept apart: the sweep's stream stays 240 bytes a row):
  // w_i = scale_i ((1 - keep) x_i + shift + sA va + sB vb).
  std::vector<double> scale_;
  // Per row of a run after its first, its couplings to the run's earlier rows k, in row order:
  // step_i J_i M^-1 J_k^T (sA_i . mA_k + sB_i . mB_k).
  std::vector<double> coupling_;
  std::vector<BodyVelocity> velocity_, base_;
  int bad_ = -1;            // the row that stopped pack()
  double badDiagonal_ = 0;  // its A_ii, or NaN when the row was invalid
};

// How many rows ahead pack() fetches the packed rows it will write.
constexpr int kPackAhead = 8;

template <class RowAt>
bool RowPgs::Packing::pack(const std::vector<BodyInverseMass>& bodies, int n, RowAt&& rowAt,
                           double relaxation, bool warm, double* xOut, bool withBase) {
#if MLCP_CPU_DISPATCH
  if (detail::avx2Active()) return packAvx2(bodies, n, rowAt, relaxation, warm, xOut, withBase);
#endif
  return packRows(bodies, n, rowAt, relaxation, warm, xOut, withBase);
}

#if MLCP_CPU_DISPATCH
template <class RowAt>
bool RowPgs::Packing::packAvx2(const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt,
                               double relaxation, bool warm, double* xOut, bool withBase) {
  return packRows(bodies, n, rowAt, relaxation, warm, xOut, withBase);
}
#endif

// The packing pass's stages for one row (packRows below), always inlined into it: the row's
// place in its run, A_ii, the stored products, the couplings, the start's velocities.
namespace pack {

using Pair = double __attribute__((vector_size(16)));

// Where the pass is in the runs of rows on the same two bodies.
struct RunCursor {
  int world = 0;               // the first zero-velocity slot
  unsigned nextWorld = 0;      // the world slot the next ground run takes
  int runStart = 0;            // first row of the current run
  int runA = 0, runB = 0;      // its slots (kept here: reading them back from packed_ right after
                               // their 4-byte stores would stall store forwarding)
  int lastA = -2, lastB = -2;  // the previous row's bodies
  int runLength = 0;
  std::size_t coupled = 0;  // couplings written
};

// Row i joins the current run or starts one; p takes its slots. "The world" (-1) becomes a
// zero-velocity slot (its J meets v = 0, its M^-1 J^T is 0); ground rows take the world slots in
// turn (per run): one shared slot would chain them all through its store and load (row_pgs.hpp).
// (lastA starts at -2: no body, no world: row 0 starts a run.)
template <class PackedRow>
[[gnu::always_inline]] inline void joinRun(PackedRow* packed, PackedRow& p, int i,
                                           const RowPgs::RowView& r, RunCursor& run,
                                           int kWorldSlots, int kMaxRun) {
  auto worldSlot = [&] { return run.world + static_cast<int>(run.nextWorld++ % kWorldSlots); };
  if (r.bodyA == run.lastA && r.bodyB == run.lastB && r.bodyA != r.bodyB &&
      run.runLength < kMaxRun) {
    ++packed[run.runStart].run;
    ++run.runLength;
  } else {
    run.runStart = i;
    run.runLength = 1;
    p.run = 1;
    run.runA = r.bodyA >= 0 ? r.bodyA : worldSlot();
    run.runB = r.bodyB >= 0 ? r.bodyB : worldSlot();
  }
  run.lastA = r.bodyA;
  run.lastB = r.bodyB;
  p.a = run.runA;
  p.b = run.runB;
}

// A_ii = J M^-1 J^T + cfm with M^-1 J^T into mA, mB.
[[gnu::always_inline]] inline double diagonal(const std::vector<BodyInverseMass>& bodies,
                                              const RowPgs::RowView& r, const double* jA,
                                              const double* jB, double* mA, double* mB) {
  const double dA =
      r.bodyA >= 0 ? detail::inverseMassInto(bodies[r.bodyA], jA, r.invAngA, mA) : 0.0;
  const double dB =
      r.bodyB >= 0 ? detail::inverseMassInto(bodies[r.bodyB], jB, r.invAngB, mB) : 0.0;
  double d = dA + dB + r.cfm;
  // A row joining a body to itself: A_ii = (jA + jB) M^-1 (jA + jB) has the cross terms too.
  if (r.bodyA == r.bodyB && r.bodyA >= 0)
    for (int k = 0; k < 6; ++k) d += jA[k] * mB[k] + jB[k] * mA[k];
  return d;
}

// step J and M^-1 J^T in pairs of entries (j, j + 1) of [A; B] (12 each), kept in sJ, mJ and
// stored as pairs: the couplings of later rows read a row's M^-1 J^T back in pairs from its
// packed row, and a 16-byte load of two 8-byte stores still in flight would stall store
// forwarding.
template <class PackedRow>
[[gnu::always_inline]] inline void storeProducts(PackedRow& p, double step, const double* jA,
                                                 const double* jB, const double* mA,
                                                 const double* mB, Pair* sJ, Pair* mJ) {
  const Pair steps = {step, step};
  for (int q = 0; q < 3; ++q) {
    sJ[q] = steps * Pair{jA[2 * q], jA[2 * q + 1]};
    sJ[3 + q] = steps * Pair{jB[2 * q], jB[2 * q + 1]};
    mJ[q] = Pair{mA[2 * q], mA[2 * q + 1]};
    mJ[3 + q] = Pair{mB[2 * q], mB[2 * q + 1]};
    std::memcpy(p.sA.data() + 2 * q, &sJ[q], sizeof(Pair));
    std::memcpy(p.sB.data() + 2 * q, &sJ[3 + q], sizeof(Pair));
    std::memcpy(p.mA.data() + 2 * q, &mJ[q], sizeof(Pair));
    std::memcpy(p.mB.data() + 2 * q, &mJ[3 + q], sizeof(Pair));
  }
}

// Couplings to the run's earlier rows k: step J_i M^-1 J_k^T on the run's two bodies, i.e.
// sA . mA_k + sB . mB_k, over entries j = 0 .. 11 of [A; B] in four partial sums (j mod 4),
// then two levels: the row's instructions wait on a chain of 5 additions instead of 12
// before they retire, and a row does not fit the reorder buffer twice, so a row's latency is
// the packing's throughput (A_ii's sums are split for the same reason). Sums j mod 4 = 0, 1
// in the lanes of one vector (pairs 0, 2, 4), 2, 3 in another (pairs 1, 3, 5). M^-1 J_k^T is
// read from row k's packed row (mA and mB are adjacent there), stored a row or more ago.
template <class PackedRow>
[[gnu::always_inline]] inline void writeCouplings(const PackedRow* packed, RunCursor& run,
                                                  const Pair* sJ, double* coupling) {
  const int earlier = run.runLength - 1;
  static_assert(offsetof(PackedRow, mB) == offsetof(PackedRow, mA) + sizeof(Vector6),
                "the couplings read mA and mB as one array of 12");
  for (int k = 0; k < earlier; ++k) {
    const double* mk = packed[run.runStart + k].mA.data();
    Pair m[6];
    std::memcpy(m, mk, sizeof m);
    Pair low = Pair{0, 0} + sJ[0] * m[0], high = Pair{0, 0} + sJ[1] * m[1];
    low += sJ[2] * m[2];
    high += sJ[3] * m[3];
    low += sJ[4] * m[4];
    high += sJ[5] * m[5];
    coupling[run.coupled + k] = (low[0] + low[1]) + (high[0] + high[1]);
  }
  run.coupled += earlier;
}

// v += M^-1 J^T x_i of the start (from the pairs in registers, not from p.mA, p.mB just
// stored), a pair at a time; va and vb are the same for a row joining a body to itself: each
// stored before the other is read.
[[gnu::always_inline]] inline void addStart(double* va, double* vb, const Pair* mJ, double xi) {
  const Pair xs = {xi, xi};
  for (int q = 0; q < 3; ++q) {
    Pair v;
    std::memcpy(&v, va + 2 * q, sizeof v);
    v += mJ[q] * xs;
    std::memcpy(va + 2 * q, &v, sizeof v);
    std::memcpy(&v, vb + 2 * q, sizeof v);
    v += mJ[3 + q] * xs;
    std::memcpy(vb + 2 * q, &v, sizeof v);
  }
}

// The packed row written a few rows ahead, fetched for writing: after the engine's own setup
// the packed rows are mostly out of L2, and ~30 stores a row waiting on their lines would fill
// the store buffer.
template <class PackedRow>
[[gnu::always_inline]] inline void fetchForWrite(const PackedRow* ahead) {
  const char* bytes = reinterpret_cast<const char*>(ahead);
  for (int line = 0; line < static_cast<int>(sizeof(PackedRow)); line += 64)
    __builtin_prefetch(bytes + line, 1);
}

// base_ += M^-1 J^T (base - start) of a row (extra = base - start); the start's velocities are
// added after the pass (an engine's base is mostly its start: no second 12-wide update per row).
[[gnu::always_inline]] inline void addBase(double* ba, double* bb, const double* mA,
                                           const double* mB, double extra) {
  for (int k = 0; k < 6; ++k) {
    ba[k] += mA[k] * extra;
    bb[k] += mB[k] * extra;
  }
}

}  // namespace pack

inline void RowPgs::Packing::beginPack(int n, int world, bool withBase) {
  if (coupling_.size() < static_cast<std::size_t>(n) * (kMaxRun - 1))
    coupling_.resize(static_cast<std::size_t>(n) * (kMaxRun - 1));
  packed_.resize(n);
  findexOf_.resize(n);
  scale_.resize(n);
  velocity_.resize(world + kWorldSlots);
  for (BodyVelocity& v : velocity_) v.v.setZero();
  if (withBase) {
    base_.resize(world + kWorldSlots);
    for (BodyVelocity& v : base_) v.v.setZero();
  }
  bad_ = -1;
}

inline bool RowPgs::Packing::endPack(int n, int world, int later, bool withBase) {
  for (int i = std::max(later, 0); later >= 0 && i < n; ++i)
    if (findexOf_[i] > i && findexOf_[findexOf_[i]] >= 0) return stop(i, std::nan(""));
  // The world never moves (its blocks are zero anyway).
  for (int k = 0; k < kWorldSlots; ++k) velocity_[world + k].v.setZero();
  if (withBase)
    for (int k = 0; k < world; ++k) base_[k].v += velocity_[k].v;
  return true;
}

template <class RowAt>
[[gnu::always_inline]] inline bool RowPgs::Packing::packRows(
    const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt, double relaxation, bool warm,
    double* xOut, bool withBase) {
  const int world = static_cast<int>(bodies.size());  // the first zero-velocity slot
  const unsigned slots = static_cast<unsigned>(world) + 1;
  pack::RunCursor run;
  run.world = world;
  beginPack(n, world, withBase);
  const bool unitRelaxation = relaxation == 1;
  int later = -1;  // the first row whose findex points forward (checked after the pass)
  // The arrays' starts in locals: the pairs' stores (memcpy) may alias anything, and the
  // vectors' own pointers would be loaded again after each.
  PackedRow* const packed = packed_.data();
  int* const findexOf = findexOf_.data();
  double* const scale = scale_.data();
  double* const coupling = coupling_.data();
  BodyVelocity* const velocity = velocity_.data();
  BodyVelocity* const base = withBase ? base_.data() : nullptr;
  for (int i = 0; i < n; ++i) {
    const RowView r = rowAt(i);
    double jA[6], jB[6];
    detail::jacobianOf(r.linA, r.angA, jA);
    detail::jacobianOf(r.linB, r.angB, jB);
    // J's finiteness: a world side's here, a body side's through A_ii (below).
    if (!detail::rowRulesValid(r, i, n, slots) ||
        ((r.bodyA < 0 || r.bodyB < 0) && !detail::jacobiansFinite(jA, jB)))
      return stop(i, std::nan(""));
    PackedRow& p = packed[i];
    if (i + kPackAhead < n) pack::fetchForWrite(&packed[i + kPackAhead]);
    p.findex = r.findex;
    // Each row's findex again in a compact array, for the check that a friction row's normal
    // row has none: reading it from the normal's packed row (thousands of rows back, out of L1)
    // would miss the cache once per friction row.
    findexOf[i] = r.findex;
    if (r.findex >= 0) {
      if (r.findex > i) {
        if (later < 0) later = i;
      } else if (findexOf[r.findex] >= 0) {
        return stop(i, std::nan(""));
      }
    }
    pack::joinRun(packed, p, i, r, run, kWorldSlots, kMaxRun);
    double mA[6] = {}, mB[6] = {};
    const double d = pack::diagonal(bodies, r, jA, jB, mA, mB);
    p.lo = r.lo;
    p.hi = r.hi;
    // NaN and inf fail too. This is also the check that a body side's J is finite: a NaN or
    // infinite entry j_k makes its term j_k (M^-1 j)_k NaN or infinite whatever the (finite)
    // body (inf times anything is inf or NaN, the engine's invAng included), and no sum with
    // such a term is finite (a separate finiteness sum would cost ~20 instructions a row).
    if (!(d > 0 && d <= std::numeric_limits<double>::max())) return stop(i, d);
    const double step = relaxation / d;
    pack::Pair sJ[6], mJ[6];
    pack::storeProducts(p, step, jA, jB, mA, mB, sJ, mJ);
    pack::writeCouplings(packed, run, sJ, coupling);
    p.keep = 1 - step * r.cfm;
    p.shift = step * r.b;
    scale[i] = unitRelaxation ? d : d / relaxation;  // d / 1 = d: no second division
    const double xi = warm ? r.start : 0.0;
    if (xOut) xOut[i] = xi;
    if (xi != 0) pack::addStart(velocity[run.runA].v.data(), velocity[run.runB].v.data(), mJ, xi);
    if (withBase && r.base != xi)
      pack::addBase(base[run.runA].v.data(), base[run.runB].v.data(), mA, mB, r.base - xi);
  }
  return endPack(n, world, later, withBase);
}

}  // namespace mlcp
