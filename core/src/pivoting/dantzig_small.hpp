// core/src/pivoting/dantzig_small.hpp (internal): DantzigSolver's path for tiny dense islands
// (a joint or two: up to kPlainLoopRows rows, no friction coupling, symmetric A).
//
// A joint island's warm start nearly always guesses the index sets right: the equality rows and
// the rows strictly inside their bounds are clamped, the others stay at their bound. For that
// case the general pivoting (dantzig.cpp) does one bordered LDL^T of the guessed block, solves
// x_C, checks the other rows' w, refines x_C once and checks again: a few hundred flops, where
// its general workspace (a permuted copy of A, index-set bookkeeping, reused vectors) costs
// several times that. This path is the same steps on fixed-size arrays: the same processing
// order (equality rows, guessed clamped rows, the others; each group in the caller's order), the
// same factor, the same tolerances, so its answer is the general path's to round-off. It
// multiplies by reciprocal pivots where the general path divides (the divisions are links of the
// dependent chain that sets a small island's latency), and it skips the refinement when the
// clamped rows' w is already at the rounding level of its evaluation.
//
// A guess whose sets are off is corrected by block-pivoting steps (at most kTries - 1 = 2, in
// dantzig_small.cpp): a solved x_C outside its bounds puts those rows at the bound they crossed,
// a row at a bound whose w points inward (w < 0 at lo, w > 0 at hi) is clamped, and the path
// starts again from those sets. Any answer it returns passed every check above for its final
// sets, so it is an answer of the problem (for a positive definite A_CC, the answer). It gives
// up (returns false, x untouched) on a guessed row whose Schur pivot is at most the pivot
// tolerance, a row at a bound whose w points inward after the refinement, an A that is not
// symmetric, or sets still off after the corrections; DantzigSolver then runs the general path
// from the caller's start. Declining costs at most this path's work three times. Measurements:
// docs/benchmarks.md, "Dantzig: the tiny-island path".
#pragma once

#include "mlcp/problem.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp::detail {

// Whether the path applies: dense A, 1..kPlainLoopRows rows, no findex.
bool smallDenseApplies(const Problem& problem);

// Solves the problem from x (the start) with the guessed index sets: rows whose start lies
// strictly inside their bounds clamped. From a cold start (all zero) that guesses the rows whose
// bounds contain 0 clamped, the others at the bound 0: right for a joint island whose limit or
// contact rows are not pushing (else the corrections above find them), which spares its first
// step the general path's cold code (an engine that starts every solve from zero, as Bullet
// does, takes this path on every step).
// pivotTolerance: Options::pivotTolerance (relative to max |A_ii|). True with the answer in x
// when every row's complementarity condition holds (to 1e-12 (1 + ||b||_inf) in w); false,
// x untouched, otherwise.
bool solveSmallDense(const Problem& problem, double pivotTolerance, Vector& x);

}  // namespace mlcp::detail
