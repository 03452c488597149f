// mlcp/island/row_screen.hpp: degenerate engine rows screened one by one, before any solver sees
// them.
//
// Engines hand over rows that no MLCP solver can take as they are, and their own solvers cope
// row by row: Bullet's sequential impulse gives a row whose J M^-1 J^T is below SIMD_EPSILON a
// zero m_jacDiagABInv (it never moves), clamps an impulse to +-SIMD_INFINITY limits, and lets a
// row with a non-finite rhs do nothing useful; ODE's solvers skip nothing but never see such
// rows from its own joints. Rejecting the whole island for one such row (what validation
// does) costs every other row its answer, every step. RowScreen applies the engines' rule per
// row instead, in one pass, and both adapters get it through RowSolver::solve:
//
//   reason          row                                   handling
//   clampedBound    lo or hi NaN                          kept, NaN lo -> -inf, NaN hi -> +inf
//   rhsBeyondReach  |b_i| >= kBeyondReach (or +-inf),     fixed at that bound (x_i = lo_i for
//                   pushing toward a finite bound         b_i > 0, hi_i for b_i < 0)
//   nonFiniteRhs    b_i NaN, or beyond reach toward an    inert
//                   infinite bound
//   nonFiniteRow    J or cfm_i NaN/Inf, or cfm_i < 0      inert
//   noJacobian      J_i = 0 on every body it names        inert (it moves nothing)
//   zeroDiagonal    A_ii = J_i M^-1 J_i^T <= 1e-12 * ref  inert (M^-1 J_i^T = 0: it moves
//                   and cfm_i = 0                         nothing, and A_ii = 0 breaks pivots)
//   emptyBounds     lo = +inf, hi = -inf or lo > hi       inert (no finite x is feasible)
//   inertNormal     friction row whose normal row is      inert (its bounds mu |x_normal| are
//                   inert                                 0 wide)
//
// A row whose b_i is beyond reach is an engine idiom, not an error (Bullet's 6-dof limits "at
// infinity", motors at full force): the rest of the island cannot change w_i's sign, so the
// exact answer, and Bullet's own, puts x_i on the bound b_i's sign names; left in, such a row
// makes the residual's scale 1e31 and every answer pass (docs/methods/island.md, "Row screening").
// ref = sum over the row's bodies of invMass |J_lin|^2 + max|invInertia_kl| |J_ang|^2, the
// size A_ii would have if J were not in M^-1's null space: the test is relative, so a 1 mm or a
// 1 km scene screens the same rows. An inert row takes x_i = 0 and a fixed row x_i = c; both
// are left out of the solve: the solver gets the other rows, compacted in their order, findex
// renumbered.
//
// Cost: one pass over the rows (A_ii's two 3x3 products a side, ~50 flops a row) when nothing
// is wrong, which is the usual case; the compacted copy is built only when a row is screened,
// and each row fixed at a non-zero bound costs one more pass over the kept rows.
#pragma once

#include <string>
#include <vector>

#include "mlcp/rows.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// Rows screened, by reason (see above). inert() counts the rows left out of the solve.
struct ScreenCounts {
  int clampedBound = 0;
  int rhsBeyondReach = 0;  // fixed at a bound, left out of the solve (counted by inert())
  int nonFiniteRhs = 0;
  int nonFiniteRow = 0;
  int noJacobian = 0;
  int zeroDiagonal = 0;
  int emptyBounds = 0;
  int inertNormal = 0;

  int inert() const {
    return rhsBeyondReach + nonFiniteRhs + nonFiniteRow + noJacobian + zeroDiagonal + emptyBounds +
           inertNormal;
  }
  int total() const { return clampedBound + inert(); }
  void add(const ScreenCounts& other);
  // "reason:count" for each non-zero count, space separated ("" when none), e.g.
  // "non-finite-rhs:1 zero-diagonal:2".
  std::string toString() const;
};

// A_ii <= kZeroDiagonal * ref (see above, thresholds.hpp) with cfm_i = 0 is a zero diagonal.
// |b_i| >= kBeyondReach is beyond reach (see above). In b's unit: m/s (Bullet), m/s^2 (ODE).
inline constexpr double kBeyondReach = 1e10;

class RowScreen {
 public:
  // Screens `rows` (whose array sizes and body indices must be valid: RowSystem::validate's
  // first checks; a row naming a body out of range is left to validation). True when a row was
  // changed or left out: then kept() holds the rows to solve and counts() says why. Buffers are
  // reused between calls.
  bool screen(const RowSystem& rows);
  const ScreenCounts& counts() const { return counts_; }
  // The rows to solve (valid after screen() returned true).
  const RowSystem& kept() const { return kept_; }
  // The index in the screened rows of each kept row.
  const std::vector<int>& keptIndex() const { return index_; }
  // full (size of the screened rows) -> the kept rows' entries.
  void gather(const Vector& full, Vector& kept) const;
  // The kept rows' answer -> full (size of the screened rows), inert rows 0, fixed rows their
  // bound.
  void scatter(const Vector& kept, Vector& full) const;

 private:
  void fix(const RowSystem& s, int i);
  // kept_'s articulated sides: those of kept rows, renumbered by place (-1: left out).
  void keepArticulated(const RowSystem& s, const std::vector<int>& place);

  ScreenCounts counts_;
  std::vector<unsigned char> inert_;
  std::vector<double> fixed_;  // per screened row: its answer when left out (0 unless fixed)
  std::vector<int> index_;
  RowSystem kept_;
  int n_ = 0;
};

}  // namespace mlcp
