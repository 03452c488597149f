// mlcp/solvers/row_pgs.hpp: projected Gauss-Seidel on an engine's constraint rows (RowPgs).
#pragma once

#include <memory>
#include <vector>

#include "mlcp/island/rows.hpp"
#include "mlcp/result.hpp"

namespace mlcp {

// Projected Gauss-Seidel on the rows themselves (what engines' sequential impulse does), with
// the same update rule, options and status semantics as PgsSolver (pgs.hpp). It keeps one
// 6-vector per body, v = M^-1 J^T x, and visits each row in O(12).
//
// A solve runs three stages over buffers kept between solves (no allocation once they have
// grown), each one pass over the rows:
//  1. pack: each row becomes a packed row (core/src/projection/row_pack.hpp) holding step J, M^-1
//  J^T and the constants of
//     its update. The pass is also the validation: each row is checked by the one-pass rule of
//     RowSystem::validate as it is packed (the bodies and array sizes before), and only a row
//     that fails calls validate() itself to say what is wrong; the caller's x is untouched until
//     every row has passed. Engines that hold their rows in their own form pack them straight
//     from there (solve with a RowSource: no RowSystem copy in between; same packing, same
//     validation).
//  2. sweep: up to Options::maxIterations sweeps over the packed rows in row order (fewer when a
//     check meets Options::tolerance).
//  3. check: every Options::checkEvery sweeps, the natural-map residual of residual.hpp at the
//     current x, with w = J v + cfm x + b taken from the velocities the sweeps maintain (v changes
//     by M^-1 J_i^T dx_i with every change dx_i of x, so w = A x + b up to round-off). It reads
//     the packed rows only: step_i w_i = (1 - keep) x_i + shift + sA v, scaled back by 1 / step,
//     so no second pass over the engine's rows rebuilds v (tests compare it with accuracy() on
//     the assembled problem). It runs in blocks of 64 rows: w of the block into an L1 buffer,
//     then the block through AccuracyAccumulator (the per-row rule of accuracy(); bounds and
//     findex read from the packed rows, so the engine path keeps no copies of them). Two short
//     loops rather than one: a single loop holds too many accumulators and spills them to the
//     stack, chaining every row through a store and a load.
//
// Cost: O(rows) to pack (a division, M^-1 J^T and the couplings: a row costs several sweeps of
// it), O(rows) per sweep, O(rows) per check; memory 240 bytes a packed row (plus its check
// scale and couplings) and one cache line a body. The sweep is bound by the latency chain through
// the velocities of bodies shared by consecutive rows (load v, dot, clamp, update v, store), not by
// memory bandwidth, and four things keep that chain short:
//  - ground rows take kWorldSlots zero-velocity world slots in turn (one shared slot would chain
//    every ground row through its store and load);
//  - a run of up to kMaxRun consecutive rows on the same two bodies (a manifold's normals, its
//    friction rows; a contact's rows in ODE's order) is swept through its couplings: row i's
//    step J_i v is step J_i v_start + sum over the run's earlier rows k of c_ik dx_k, with
//    c_ik = step_i J_i M^-1 J_k^T computed when packing, so a row waits for the last one only
//    through a multiply-add, and v takes the run's changes at its end;
//  - the run's loop is unrolled per length, so its changes stay in registers;
//  - the update is regrouped so that only the product with v sits on the chain, and the change
//    that moves v is clamped on its own (the packed row's update).
// The packing, sweeps and check are compiled for the baseline and for AVX2 and chosen at run
// time (mlcp/cpu.hpp); the 12-wide products are written in the order of Eigen's Vector6
// expressions (core/src/projection/row_simd.hpp), so both variants, solve(RowSystem) and the engine
// entry point give the same iterates bit for bit.
//
// The first sweep is not fused into the packing: with a warm start, row i's first update needs
// v = M^-1 J^T x_start over all rows, later ones included, which exists only after the pass.
// The step is divided here rather than taken from an engine's own 1 / A_ii (Bullet's
// m_jacDiagABInv): an engine's number is another rounding of A_ii, lacks our friction CFM, and
// the RowSystem path has no such number.
class RowPgs {
 public:
  Options& options() { return options_; }
  const Options& options() const { return options_; }
  // Solve from x (used when options().warmStart and x has the right size, else from zero).
  Result solve(const RowSystem& system, Vector& x);

  // Packing straight from an engine's own rows, without a RowSystem copy (one pass where the
  // adapter would otherwise write a RowSystem and the packing read it back): one row as the
  // engine holds it, read in place by the packing pass (pointers into the engine's own rows; the
  // values must stay put until solve returns). Each 3-vector is 3 contiguous doubles:
  // J_A = [linA; angA], J_B = [linB; angB].
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
    // The row's MLCP data as in RowSystem; start is x_i's warm start, base the part of x_i the
    // engine's bodies already carry (velocityChange). lo and hi are kept apart: the packing
    // copies them to neighbouring places, and a 16-byte load of two neighbours just written as
    // 8-byte values by the source would stall store forwarding.
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
  // Each row is packed bitwise as solve(RowSystem) packs the same values, and validated by the
  // same rules as it is packed; when a row is invalid or has A_ii <= 0 the rows are fetched once
  // more into a RowSystem and solve(RowSystem) gives the answer and the message (the slow path).
  // x is output only (size rows): it starts from the rows' `start` (from zero without
  // options().warmStart or with a non-finite start).
  Result solve(const std::vector<BodyInverseMass>& bodies, int rows, RowSource& source, Vector& x);
  // After solve(bodies, rows, source, x) took the fast path: body k's M^-1 J^T (x - base),
  // [linear; angular], from the velocities the sweeps maintain (what an engine adds to its
  // body's velocity to apply the answer, instead of one impulse per row). velocityChanges()
  // is false after the slow path, after solve(RowSystem), and when a row's base is not finite
  // (then apply x row by row).
  bool velocityChanges() const { return baseValid_; }
  Vector6 velocityChange(int body) const;
  // The rows the source gives, as a RowSystem with these bodies, and their starts: the slow
  // path's copy, for callers that need a RowSystem after all.
  static void toSystem(const std::vector<BodyInverseMass>& bodies, int rows, RowSource& source,
                       RowSystem& system, Vector& start);

  RowPgs();
  RowPgs(const RowPgs& other);
  RowPgs(RowPgs&&) noexcept;
  RowPgs& operator=(const RowPgs& other);
  RowPgs& operator=(RowPgs&&) noexcept;
  ~RowPgs();

 private:
  // The packed rows, the body velocities and the packing, sweep and check over them, with their
  // CPU variants (core/src/projection/row_pack.hpp: internal).
  struct Packing;
  static Result negativeRows();
  // After the engine path's packing: per-body changes offered when the bases are finite, then
  // iterate().
  Result iteratePacked(int bodies, Vector& x, double bNorm, double t0);
  // The sweeps and checks on the packed rows from x (the check reads the bounds and findex from
  // the packed rows too); bNorm = ||b||_inf for the check.
  Result iterate(Vector& x, double bNorm, double t0);

  Options options_;
  std::unique_ptr<Packing> packing_;  // reused between solves
  bool baseValid_ = false;
};

}  // namespace mlcp
