// mlcp/solvers/row_pgs.hpp: projected Gauss-Seidel on an engine's constraint rows (RowPgs).
#pragma once

#include <memory>
#include <vector>

#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"

namespace mlcp {

// Projected Gauss-Seidel on the rows themselves (what engines' sequential impulse does), with
// the same update rule, options and status semantics as PgsSolver (pgs.hpp). It keeps one
// 6-vector per body, v = M^-1 J^T x, and visits each row in O(12).
//
// A solve runs three stages over buffers kept between solves (no allocation once they have
// grown), each one pass over the rows:
//  1. pack: each row becomes a packed row (core/src/projection/row_pack.hpp) holding step J,
//     M^-1 J^T and the constants of its update. The pass is also the validation, by the one-pass
//     rule of RowSystem::validate; only a row that fails calls validate() to say what is wrong,
//     and the caller's x is untouched until every row has passed. Engines pack straight from
//     their own rows (solve with a RowSource: no RowSystem copy; same packing, same validation).
//  2. sweep: up to Options::maxIterations sweeps over the packed rows in row order (fewer when a
//     check meets Options::tolerance).
//  3. check: every Options::checkEvery sweeps, the natural-map residual of residual.hpp at x,
//     with w = J v + cfm x + b from the velocities the sweeps maintain (w = A x + b up to
//     round-off), read from the packed rows only, in blocks of 64 rows through
//     AccuracyAccumulator (the per-row rule of accuracy()).
//
// Cost: O(rows) to pack (a row costs several sweeps of it), O(rows) per sweep and per check;
// memory 240 bytes a packed row (plus its check scale and couplings) and one cache line a body.
// The sweep is bound by the latency chain through the velocities of bodies shared by
// consecutive rows (load v, dot, clamp, update v, store), and four things keep it short:
//  - ground rows take kWorldSlots zero-velocity world slots in turn;
//  - a run of up to kMaxRun consecutive rows on the same two bodies (a manifold's normals, its
//    friction rows) is swept through its couplings c_ik = step_i J_i M^-1 J_k^T, computed when
//    packing, so a row waits for the last one only through a multiply-add;
//  - the run's loop is unrolled per length, so its changes stay in registers;
//  - the update is regrouped so that only the product with v sits on the chain.
// Invariant: packing, sweeps and check are compiled for the baseline and for AVX2 and chosen at
// run time (mlcp/cpu.hpp); the 12-wide products keep the order of Eigen's Vector6 expressions
// (core/src/projection/row_simd.hpp), so both variants, solve(RowSystem) and the engine entry
// point give the same iterates bit for bit. The step is omega / A_ii from our own A_ii, not an
// engine's 1 / A_ii. Alternatives not taken: docs/decisions.md, "RowPgs: packing, sweeps and
// check".
// Rows with articulated sides (rows.hpp) are swept unpacked, the same update through J and
// W = M^-1 J^T per side (core/src/projection/articulated_pgs.cpp): O(nnz J) a sweep, no A.
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
  // solve(RowSystem) on a system with articulated sides (see above).
  Result solveArticulated(const RowSystem& system, Vector& x, double t0);
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
