// mlcp/thresholds.hpp: every size threshold and breakdown shift of the library, in one table.
//
// Sizes choose a storage or a method for a problem of n rows; shifts decide when a pivot, a
// diagonal or a drift counts as zero and how far a retry moves A. Each has its reason here;
// the structs that let a user change one (NewtonParams, LemkeSolver, Policy, ...) take it as
// their default. The measurements behind the sizes are in docs/benchmarks.md ("ldlt: the dense
// envelope against the other factorizations", "lemke: dense tableau against the factored
// basis", "auto's choices and the time budget"); shifts are relative to the scale named with
// each, so a problem in any unit gets the same decisions.
#pragma once

namespace mlcp {

// ---- sizes, in rows -------------------------------------------------------------------------
// dantzig's plain loops beat Eigen's vectorized kernels on products and blocks this small, and
// islands this small (a few joints) take its fixed-size unrolled path.
inline constexpr int kPlainLoopRows = 8;
// RowSolver assembles islands up to this size dense, larger ones sparse: ldlt's envelope
// factorization of a dense A wins up to 60-100 rows on a thin band (always on a full one).
inline constexpr int kDenseAssemblyRows = 64;
// newton factors J dense (Eigen's LU) up to this size, sparse (KLU) above: the sparse
// analysis costs more than the dense factorization below it.
inline constexpr int kNewtonDenseRows = 100;
// lemke pivots on its dense tableau up to this size, on its factored basis above: a tableau
// pivot is O(n^2) with no solves, a factored pivot three sparse solves and an eta update.
inline constexpr int kLemkeTableauRows = 50;
// lemke keeps the tableau up to this size when the problem has free rows: the factored basis
// of a free-row problem breaks down on singular joint blocks that the tableau pivots through.
inline constexpr int kLemkeFreeRowsTableauRows = 2000;
// auto hands contact islands up to these sizes to dantzig whatever the tolerance (with free
// rows, without): dantzig's pivots settle them in microseconds to a millisecond; above, its
// pivot count grows faster than newton's factorizations.
inline constexpr int kSmallIslandRows = 600;
inline constexpr int kSmallContactRows = 100;
// Smallest island whose pgs solve is timed for the engine-relative cap's cost per row: below
// it a solve's fixed costs dominate the sample.
inline constexpr int kTimedPgsRows = 64;

// ---- shifts and zero tests, dimensionless ---------------------------------------------------
// A pivot below this times the largest |A_ii| is zero (Options::pivotTolerance's default).
inline constexpr double kPivotTolerance = 1e-12;
// dantzig's retry after a breakdown adds this times max |A_ii| to A's diagonal: on Bullet's
// redundant bridge 1e-10 leaves a residual of 3-5e-8 on A, 1e-8 of 3-7e-7, 1e-6 of 2-7e-5.
inline constexpr double kDantzigBreakdownShift = 1e-10;
// lemke's retry after a ray adds this times max(1, max |A_ii|) to A's diagonal: a singular A
// whose rows drift ~1e-8 of b (a plank bridge) ends in a spurious ray on A and solves in a few
// pivots on the shifted A, leaving ~5e-11 on A.
inline constexpr double kLemkeRayShift = 1e-12;
// lemke's factored basis refactors more often (halves its period) when the eta-updated basic
// values' backward error ||B x - q|| / (||q|| + ||B|| ||x||) exceeds this: ~1e6 units of
// round-off, far below what changes a ratio test's choice; a fresh factorization leaves ~1e-16.
inline constexpr double kLemkeBackwardError = 1e-10;
// lemke's factored basis factors B with this KLU pivot threshold, plain partial pivoting: at
// KLU's default 0.001 (the diagonal kept down to 1e-3 of its column) a 5,000-row banded
// P-matrix basis was factored with a backward error of 0.4 and lemke ended on a wrong basis.
inline constexpr double kLemkeBasisPivotThreshold = 1.0;
// lemke's factored basis is wrong when a basic value computed fresh at a refactorization is
// below -this * (1 + max |x_B|): a right path keeps x_B >= 0 up to round-off (~1e-16 relative).
inline constexpr double kLemkeInfeasibility = 1e-9;
// The minimum-norm least-squares rank decision, times max(1, max |A_ii|): directions 1e-6
// below the stiffest are where an exact answer would throw bodies (linalg/min_norm.hpp).
inline constexpr double kMinNormShift = 1e-6;
// newton's body-space factors (its steps' and its pivoting phase's) treat a body block's diagonal
// below this, relative, as singular.
inline constexpr double kBodyMinDiagonal = 1e-11;
// A row's A_ii below this times the size it would have outside M^-1's null space is zero
// (the row screen: such a row moves nothing).
inline constexpr double kZeroDiagonal = 1e-12;

}  // namespace mlcp
