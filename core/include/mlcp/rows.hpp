// mlcp/rows.hpp: constraint rows in the factored form physics engines hand over.
//
// Engines do not build A. They give, per constraint row i, two 6-wide Jacobian blocks
// J_iA, J_iB (linear part first, then angular) on two bodies A and B, and per body its
// inverse mass and world-frame inverse inertia. With M^-1 the block-diagonal inverse mass
// matrix, the MLCP is
//
//     w = (J M^-1 J^T + diag(cfm)) x + b,   lo <= x <= hi,   findex as in problem.hpp,
//
// in the canonical form of problem.hpp (engines' rhs is -b: the adapters convert). Keeping
// this form lets PGS run on rows and body velocities with O(nnz J) work per sweep and no A at
// all (RowPgs below); pivoting methods get A from assemble(), sparse by the body graph (only
// rows sharing a body couple), dense only when asked.
//
// Bodies with invMass == 0 and a zero invInertia are static; a row's body index -1 means "the
// world" (its block is ignored).
#pragma once

#include <Eigen/Dense>
#include <cassert>
#include <functional>
#include <string>
#include <vector>

#include "mlcp/cpu.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/result.hpp"

namespace mlcp {

using Vector6 = Eigen::Matrix<double, 6, 1>;

struct BodyInverseMass {
  double invMass = 0;                                    // 1 / mass, 0 for static bodies
  Eigen::Matrix3d invInertia = Eigen::Matrix3d::Zero();  // world frame
};

struct ConstraintRow {
  int bodyA = -1, bodyB = -1;    // indices into RowSystem::bodies, -1 = world
  Vector6 jA = Vector6::Zero();  // [linear; angular] Jacobian on body A
  Vector6 jB = Vector6::Zero();  // [linear; angular] Jacobian on body B
};

class RowSystem {
 public:
  std::vector<BodyInverseMass> bodies;
  std::vector<ConstraintRow> rows;
  Vector b, lo, hi, cfm;    // per row; cfm >= 0 is added to A's diagonal
  std::vector<int> findex;  // per row or empty

  int size() const { return static_cast<int>(rows.size()); }
  // "" when well formed, otherwise the first thing wrong (sizes, body indices, NaN/Inf, and
  // every rule of Problem::validate for b, lo, hi, findex).
  std::string validate() const;

  // A = J M^-1 J^T + diag(cfm) with the bounds copied: the same MLCP as a Problem.
  Problem assemble(bool sparse) const;
  // The same into `into`, reusing its vectors, A's storage (Problem::swapA) and the scratch's
  // buffers: a per-step caller (RowSolver) allocates nothing once the sizes have been seen.
  // Sparse A: when the rows join the same bodies as in the last sparse assembly with this
  // scratch and `into` still holds that pattern (index arrays compared), only the values are
  // written, in the order setFromTriplets sums them (bitwise the same A); otherwise the pattern
  // is built from triplets and remembered.
  struct AssembleScratch {
    std::vector<std::vector<std::pair<int, const Vector6*>>> touching;
    std::vector<Eigen::Triplet<double>> triplets;
    std::vector<int> patternBodies;               // bodies.size(), then bodyA, bodyB per row
    std::vector<int> patternOuter, patternInner;  // the pattern's compressed index arrays
    std::vector<int> valueSlot;  // per product, in assembly order: its index in A's values
    DenseMatrix dense;           // empty between calls: A's storage is taken from `into`
    SparseMatrix sparse;
  };
  void assemble(bool sparse, Problem& into, AssembleScratch& scratch) const;
  // w = A x + b computed through body velocities, O(nnz J).
  Vector slack(const Vector& x) const;
  // Body velocity changes M^-1 J^T x, 6 per body ([linear; angular]).
  std::vector<Vector6> bodyVelocities(const Vector& x) const;
};

// Projected Gauss-Seidel on the rows themselves (what engines' sequential impulse does), with
// the same update rule, options and status semantics as PgsSolver (pgs.hpp). It keeps one
// 6-vector per body, v = M^-1 J^T x, and visits each row in O(12).
//
// Cost per solve, for engines that call it every step with fixed sweep counts (SI-like use):
// one packing pass into buffers kept between solves (no allocation once they have grown), the
// sweeps, and one residual check per Options::checkEvery. The packing pass is also the
// validation: each row is checked by the one-pass rule of RowSystem::validate as it is packed
// (the bodies and array sizes before), and only a row that fails calls validate() itself to
// say what is wrong; the caller's x is untouched until every row has passed. Engines that hold
// their rows in their own form pack them straight from there (solve with a RowFill, a
// RowSource or solveFrom: no RowSystem copy in between; same packing, same validation). The check
// is the natural-map residual of residual.hpp at the current x, with w = J v + cfm x + b taken from
// the body velocities the sweeps maintain: v changes by M^-1 J_i^T dx_i with every change dx_i of
// x, so v = M^-1 J^T x up to round-off and w = A x + b is exact up to round-off as well. It reads
// the packed rows only: step_i w_i = (1 - keep) x_i + shift + sA v (the sweep's own terms, scaled
// back by 1 / step). The check thus needs no second pass over the rows to rebuild v (tests
// compare it with accuracy() on the assembled problem). It runs in blocks of 64 packed rows: w
// of the block into an L1 buffer, then the block's rows through AccuracyAccumulator (the per-row
// rule of accuracy(); bounds and findex read from the packed rows, so the engine path keeps no
// copies of them). Session 6 (stage timers, 210 boxes, median per step): ~46 us against ~49
// us for session 5's w vector then accuracy(); one loop for both was slower than the two
// passes (it spilled the accumulators to the stack, chaining every row through a store and a
// load).
// The sweep is bound by the latency chain through the velocities of bodies shared by
// consecutive rows (load v, dot, clamp, update v, store), not by memory. Four things keep the
// chain short: ground rows take 8 zero-velocity world slots in turn (one shared slot chained
// every ground row through its store and load); a run of up to kMaxRun consecutive rows on the
// same two bodies (a manifold's normals, its friction rows; a contact's rows in ODE's order) is
// swept through its couplings: row i's step J_i v is step J_i v_start + sum over the run's
// earlier rows k of c_ik dx_k, c_ik = step_i J_i M^-1 J_k^T computed when packing, so one row
// waits for the last only through a multiply-add (not a 12-wide velocity update and dot), and
// v takes the run's changes at its end; the run's loop is unrolled per length so its changes
// stay in registers; and the velocity change is clamped on its own (below).
// Measured through the Bullet drop-in (bullet_bench --pgs-vs-si, 210-box pyramid, 4720 rows,
// 10 sweeps, perf shares of our stages at the end of session 4): sweeps 44%, packing 21% (~0.18
// ms: ~40 ns a row, the couplings included), the check (slackFromVelocities and accuracy) 5%;
// the rest is the adapter's (islands.hpp). The couplings and the unrolling took the Bullet
// sweeps from ~51 us to ~37 us (~8 ns a row); without the unrolling the coupling sums read the
// changes back from a stack array in pairs and stalled store forwarding, and the runs gained
// nothing. Packing once lost a quarter of its time to such stalls too (Eigen's M^-1 J^T
// temporary read back from the stack; now computed in scalars). Round 2 of session 4: packing
// ~23% (~0.2 ms, ~45 ns a row; the largest single cost is waiting for step = omega / A_ii, the
// rest is spread thin), the couplings' step J_i computed once per row.
// Session 5 (timers around the stages, 210 boxes, 10 sweeps, per step): packing ~250 us (~53 ns
// a row, now with the reading of Bullet's rows: the engine's rows are read in place through a
// RowSource, or inlined through solveFrom; its angular M^-1 J^T taken from the engine), sweeps
// ~430 us (~9 ns a row a sweep), the check ~50 us (~11 ns a row: a second pass over the packed
// rows for w, then accuracy()). In packing (perf with line numbers): the first reads of the
// engine's rows ~11%, the wait for the division ~11%, the couplings ~7% (two at a time in the
// lanes of one vector; doubling them cost ~40 us), the rest spread thin. Tried without gain:
// A_ii and the divisions of 8 rows first, then the rest (staging the rows through a stack array
// cost +25%); the couplings' dots before the division and scaled after; the division moved
// ahead of the findex checks and the run bookkeeping.
// Session 6: packing ~200-220 us against ~250-255 us at 210 boxes (stage timers, median per
// step, quiet runs; ~44 ns a row) by three changes: shorter addition chains (each coupling in four
// partial sums, A_ii's linear and angular parts apart: a row's ~400 instructions retire only
// after its longest chain, and a row does not fit the reorder buffer twice, so a row's latency
// is the packing's throughput; the iterates move by round-off); the packed rows fetched for
// writing 8 rows ahead (after the engine's setup they are out of L2); friction rows validated
// from a compact findex array (reading the normal row's findex from its packed row, thousands
// of rows back, missed L1 on every friction row). Tried without gain: the sweep's last coupling
// subtracted after the clamp's other terms (one addition less on the chain between a run's
// rows: 10 sweeps 1.15 -> 1.21x SI at 55 boxes); rowValid's sum as a tree; fetching 16 rows
// ahead instead of 8 (within the noise). Not done, and why: the first sweep fused into the
// packing (the brief's first candidate) cannot keep the iterates: with a warm start row i's
// first update needs v = M^-1 J^T x_start over all rows, rows after i included, which only
// exists after the packing; an engine's bodies hold it before (SI's setup applied the start),
// but in the engine's rounding and order. Deriving step from Bullet's m_jacDiagABInv instead of
// dividing: friction rows' Bullet denominator has no CFM while ours has (StockMlcp, Regularized),
// contacts' is another rounding of A_ii (invMass + n . ((I^-1 (r x n)) x r)), and the RowSystem
// path has no such number (bit for bit would need a RowSystem field: an API change).
// Session 7 (stage timers, mean per step, min of 5 runs alternated with session 6's code): the
// row update written once (RowPgs::update, which session 6's sweep called out of line at one
// site) and one sweep a noinline function of its own (sweepOnce): sweeps ~117 -> ~93 us at 55
// boxes, ~479 -> ~379 us at 210 (~10.1 -> ~8.0 ns a row a sweep); packing ~48 / ~205 us (~43 ns
// a row), check ~11 / ~46 us, the same. Which of the two changes of the compiled code pays was
// not isolated; forcing update() inline and the run's velocity update into scalars made 55 boxes
// ~7% slower again.
// Session 7, tried without gain (stage timers, mean per step, min of 6 runs alternated with the
// code before): the first sweep fused into the packing from the velocities Bullet's setup applied
// (SI's start; our own M^-1 J^T x_start summed beside it and the velocities moved onto it after
// the pass, so the check stayed exact): the packing grew by about the sweep it saved (55 boxes
// +14-18 us packing, -8-16 us sweeps; 210 boxes +42-54 us, -32-86 us; sweeps of session 6's code),
// with row i updated right after it was packed,
// through the run's couplings, or trailing the packing by 8 rows alike: each packed row's latency
// is the packing's throughput, and the update's chain (dot, clamp, velocities) adds about what a
// sweep of the row costs. A packed row padded from 240 to 304 bytes cost the 210-box stages ~2%:
// bytes streamed are not what bounds the sweep either (so a smaller row format would gain ~1-2%).
// Session 8 (a throwaway harness: one 55-box island after the switch, 1160 rows, packed and
// checked 200 times, min of 7; callgrind instruction counts of the same, deterministic): the
// packing ~573 instructions a row (623 before), the check ~94, a sweep ~88. The Bullet source's
// row() and view() are now inlined into pack() (forced: GCC kept a call per row returning the
// view through memory: -27 instructions), and a body side's J is checked finite through A_ii's
// test (row_pack.hpp: -21). Packing ~41 -> ~38-39 ns a row in the harness on a quiet machine
// (~80 -> ~61-70 on a busy one; the check ~7, a sweep ~8.4 quiet). 10 sweeps, 8 runs
// alternated with the code before: 15 / 55 / 210 boxes min 1.00x / 1.05x / 1.00x -> 0.94x /
// 1.04x / 0.99x SI, median 1.06x / 1.08x / 1.03x -> 1.00x / 1.04x / 0.99x (a busy machine, SI
// 0.22-0.24 ms a step at 55 boxes; the residual columns identical); ODE's pgs (ode_pgs_bench,
// 5 alternated runs) the same (pgs / QuickStep min 0.87x / 0.79x / 0.69x -> 0.88x / 0.76x /
// 0.70x, residuals identical). Tried without gain:
// gapTimes without the branch on w's sign (the check 94 -> 107 instructions, ~7.4 -> ~8.3 ns a
// row in the harness, which replays one island's branch pattern); std::max of three written as
// two (the same code).
// Session 8, round 6 (the same harness and callgrind): packing 573 -> 535 instructions a row,
// pack + check ~44.0 -> ~39.9 ns a row (min of 5, harness): a run's M^-1 J^T read back from
// its packed rows (stored as 16-byte pairs, so the pair loads forward) instead of a runM copy
// (-24), the arrays' starts in locals (the pairs' memcpy stores may alias anything: -11), one
// coupling at a time with the sums j mod 4 in the lanes of two vectors (the same sums, so the
// same bits; no fewer instructions than two couplings at a time). 10 sweeps, 8 runs alternated
// with the code before: 15 / 55 / 210 boxes min 0.94x / 1.03x / 0.99x -> 0.93x / 1.02x /
// 0.97x SI, median 1.00x / 1.04x / 1.005x -> 0.98x / 1.03x / 0.98x (residual columns and the
// 55-box harness iterates and check identical); ODE pgs the same or faster (min 0.88x / 0.79x /
// 0.70x -> 0.85x / 0.76x / 0.68x QuickStep, 3 runs). 55 boxes is still above SI. Tried without
// gain: J read in place instead of copied (+41 instructions: every store may alias the
// engine's rows, so each use loaded again); M^-1 J^T formed as pairs in registers (+14
// instructions, the same time); the couplings' partial sums without their +0 start and a
// final + 0.0 (the same bits, -0.4 instructions: GCC kept the same code); rowRulesValid as one
// branch over & of its tests (+4 instructions, the same time); the check's two finiteness
// tests a row folded into one sum checked after the pass, with an exact second pass when it is
// not finite (check 94 -> 92 instructions, ~7.4 -> ~7.3 ns a row: not worth the second path).
// Session 9: the packing, sweeps and check are compiled twice, for the baseline and for AVX2, and
// the CPU picks (mlcp/cpu.hpp; the same bits). The sweep's and the check's row products
// sA . va + sB . vb and the run's velocity updates are generic vectors (detail/row_simd.hpp): 4 +
// 2 wide in the AVX2 variant, three pairs in the baseline, in the order Eigen's Vector6
// expressions summed them (the iterates did not move: bullet_bench's residual columns identical).
// Callgrind before, 55 boxes: a sweep ~71 instructions a row, the packing ~553. Stage time at 55
// boxes, 10 sweeps: ~0.136 -> ~0.124 ms (AVX2), ~0.129 ms (baseline pairs: explicit pairs beat
// Eigen's for the run's velocity stores too). Tried without gain: the packing's couplings as one
// 4-wide sum (the same bits, sA/sB and mA/mB stored 4-wide so the loads forward; within the
// noise); 4-wide generic vectors in the baseline (GCC compiles them without AVX through the stack:
// the sweeps 1.6x slower).
class RowPgs {
 public:
  Options& options() { return options_; }
  const Options& options() const { return options_; }
  // Solve from x (used when options().warmStart and x has the right size, else from zero).
  Result solve(const RowSystem& system, Vector& x);

  // Packing straight from an engine's own rows, without a RowSystem copy (one pass where the
  // adapter would otherwise write a RowSystem and the packing read it back). The rows are
  // fetched in order, in batches: fill(first, count, out) writes rows first .. first+count-1.
  // Each row is packed bitwise as solve(RowSystem) packs the same values, and validated by the
  // same rules as it is packed; when a row is invalid or has A_ii <= 0 the rows are fetched once
  // more into a RowSystem and solve(RowSystem) gives the answer and the message (the slow path).
  // x is output only (size rows): it starts from the rows' `start` (from zero without
  // options().warmStart or with a non-finite start).
  struct Row {
    int bodyA = -1, bodyB = -1;  // indices into bodies, -1 = world
    Vector6 jA, jB;              // [linear; angular] Jacobian blocks
    double b = 0, cfm = 0, lo = 0, hi = 0;
    int findex = -1;
    double start = 0;  // x_i's warm start
    double base = 0;   // the part of x_i the engine's bodies already carry (velocityChange)
  };
  using RowFill = std::function<void(int first, int count, Row* out)>;
  Result solve(const std::vector<BodyInverseMass>& bodies, int rows, const RowFill& fill,
               Vector& x);

  // The same without any copy of a row: one row as the engine holds it, read in place by the
  // packing pass (pointers into the engine's own rows; the values must stay put until solve
  // returns). Each 3-vector is 3 contiguous doubles: J_A = [linA; angA], J_B = [linB; angB].
  // invAngA / invAngB, when not null, are the engine's own I^-1 angA / I^-1 angB for the row's
  // body (I = BodyInverseMass::invInertia): packing takes them instead of the 3x3 products. The
  // caller promises they are what those products give bit for bit (invInertia(k, 0) * ang[0] +
  // invInertia(k, 1) * ang[1] + invInertia(k, 2) * ang[2], left to right, no fused
  // multiply-add), so the iterates stay those of solve(RowSystem) on the same values.
  struct RowView {
    int bodyA = -1, bodyB = -1;  // indices into bodies, -1 = world
    const double* linA = nullptr;
    const double* angA = nullptr;
    const double* linB = nullptr;
    const double* angB = nullptr;
    const double* invAngA = nullptr;
    const double* invAngB = nullptr;
    // As in Row. lo and hi are kept apart: the packing copies them to neighbouring places, and
    // a 16-byte load of two neighbours just written as 8-byte values by the source stalled
    // store forwarding (a fifth of the packing's time, measured with perf).
    double lo = 0, b = 0, hi = 0, cfm = 0;
    int findex = -1;
    double start = 0, base = 0;
  };
  // Rows fetched one at a time, in order 0 .. rows-1 by the fast path (and once more, in order,
  // by the slow path's copy); the view of row i may be overwritten by the call for row i + 1.
  class RowSource {
   public:
    virtual RowView row(int i) = 0;

   protected:
    ~RowSource() = default;
  };
  Result solve(const std::vector<BodyInverseMass>& bodies, int rows, RowSource& source, Vector& x);
  // The same for any class with RowView row(int) (a final RowSource, or none): defined in
  // mlcp/detail/row_pack.hpp, where the source's row() can be inlined into the packing loop.
  template <class Source>
  Result solveFrom(const std::vector<BodyInverseMass>& bodies, int rows, Source& source, Vector& x);
  // After solve(bodies, rows, fill, x) took the fast path: body k's M^-1 J^T (x - base),
  // [linear; angular], from the velocities the sweeps maintain (what an engine adds to its
  // body's velocity to apply the answer, instead of one impulse per row). velocityChanges()
  // is false after the slow path, after solve(RowSystem), and when a row's base is not finite
  // (then apply x row by row).
  bool velocityChanges() const { return baseValid_; }
  // The rows fill gives, as a RowSystem with these bodies, and their starts: the slow path's
  // copy, for callers that need a RowSystem after all.
  static void toSystem(const std::vector<BodyInverseMass>& bodies, int rows, const RowFill& fill,
                       RowSystem& system, Vector& start);
  static void toSystem(const std::vector<BodyInverseMass>& bodies, int rows, RowSource& source,
                       RowSystem& system, Vector& start);
  Vector6 velocityChange(int body) const {
    assert(baseValid_ && body >= 0 && body < static_cast<int>(base_.size()));
    return velocity_[body].v - base_[body].v;
  }

 private:
  // Everything the sweep reads per row, in one stream: bodies remapped so that "the world" is
  // a zero-velocity slot (no branches in the inner loop), M^-1 J^T, and the update
  //     x_i <- clamp(x_i - step (J_i v + cfm_i x_i + b_i), lo', hi'),   step = omega / A_ii,
  // regrouped as clamp(keep x_i - shift - (step J_i) v) with keep = 1 - step cfm_i and
  // shift = step b_i: only the product with v depends on the rows just visited, so the row's
  // latency chain (load v, dot, clamp, update v) holds one subtraction instead of a
  // multiplication and three additions (sweeps ~20% faster; the same iterates up to round-off).
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
  // Fills packed_ and velocity_ from rowAt(i) (detail/row_pack.hpp); false at the first invalid row
  // or non-positive A_ii (bad_, badDiagonal_ say which).
  // pack(), sweepOnce() and packedAccuracy() run their body (packRows, sweepRows, checkRows) as
  // compiled for the baseline or, where cpuPath() says so, its AVX2 variant (mlcp/cpu.hpp): the
  // same source, the same bits.
  template <class RowAt>
  bool pack(const std::vector<BodyInverseMass>& bodies, int n, RowAt&& rowAt, bool warm, double* x,
            bool withBase);
  template <class RowAt>
  bool packRows(const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt, bool warm,
                double* x, bool withBase);
#if MLCP_CPU_DISPATCH
  template <class RowAt>
  MLCP_AVX2_VARIANT bool packAvx2(const std::vector<BodyInverseMass>& bodies, int n, RowAt& rowAt,
                                  bool warm, double* x, bool withBase);
  MLCP_AVX2_VARIANT void sweepAvx2(double* x);
  MLCP_AVX2_VARIANT Accuracy checkAvx2(const Vector& x, double bNorm) const;
#endif
  // Wide: with 4-wide vectors (the AVX2 variants), else in pairs (mlcp/detail/row_simd.hpp).
  template <bool Wide>
  void sweepRows(double* x);
  template <bool Wide>
  Accuracy checkRows(const Vector& x, double bNorm) const;
  // One row's update from jv = step J_i v (x[i] takes its new value); returns the change of x_i
  // that moves the velocities.
  static double update(const PackedRow& p, double* x, int i, double jv);
  // One sweep over packed_ (x and the velocities updated in place).
  void sweepOnce(double* x);
  static Result negativeRows();
  // After the engine path's packing: per-body changes offered when the bases are finite, then
  // iterate().
  Result iteratePacked(int bodies, Vector& x, double bNorm, double t0);
  // The sweeps and checks on packed_ from x (the check reads the bounds and findex from the
  // packed rows too); bNorm = ||b||_inf for the check.
  Result iterate(Vector& x, double bNorm, double t0);
  // The check: accuracy() of x with w = J v + cfm x + b from the packed rows and velocities.
  Accuracy packedAccuracy(const Vector& x, double bNorm) const;

  Options options_;
  std::vector<PackedRow> packed_;  // reused between solves
  std::vector<int> findexOf_;      // packed_[i].findex again, compact (pack() validates with it)
  // Per row 1 / step, for the check only (kept apart: the sweep's stream stays 240 bytes a row):
  // w_i = scale_i ((1 - keep) x_i + shift + sA va + sB vb).
  std::vector<double> scale_;
  // Per row of a run after its first, its couplings to the run's earlier rows k, in row order:
  // step_i J_i M^-1 J_k^T (sA_i . mA_k + sB_i . mB_k).
  std::vector<double> coupling_;
  std::vector<BodyVelocity> velocity_, base_;
  bool baseValid_ = false;
  int bad_ = -1;            // the row that stopped pack()
  double badDiagonal_ = 0;  // its A_ii, or NaN when the row was invalid
};

}  // namespace mlcp
