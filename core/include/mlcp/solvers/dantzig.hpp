// mlcp/solvers/dantzig.hpp: Dantzig-Cottle principal pivoting for boxed MLCPs with findex (registry
// "dantzig"), in the spirit of ODE's dSolveLCP / Bullet's btDantzigLCP, written anew.
//
// Method. Rows are added one at a time. Every processed row is in one of the index sets
//
//     C (clamped):  w_i = 0,  lo_i <= x_i <= hi_i     (x_C is unknown, solved for)
//     N (at bound): x_i = lo_i with w_i >= 0, or x_i = hi_i with w_i <= 0, or lo_i = hi_i
//
// and unprocessed rows keep x at their start value (inside their bounds). The invariant is
// that every processed row satisfies its complementarity condition. Adding row i drives x_i
// in the direction that moves w_i toward 0 while C's w stay 0 and N's x stay at their bounds:
//
//     A_CC dx_C = -A_Ci d,   dw = A_{.,C} dx_C + A_{.,i} d,   d = -sign(w_i).
//
// The step length s is the smallest of: w_i reaching 0 (i joins C), x_i reaching its own
// bound (i joins N), a C index reaching a bound (it moves to N), an N index whose w reaches
// 0 from its allowed side (it moves to C). After a C/N exchange the direction is recomputed
// and driving continues. No step limit means no solution along this path: Status::Failed
// with a message naming the row (e.g. w = -x - 1, x >= 0 is infeasible).
//
// Factorization. A_CC = L D U (unit lower L, diagonal D, unit upper U; U = L^T when A is
// symmetric, detected once per solve, which halves the work). Adding an index borders the
// factors (two triangular solves, O(|C|^2); the solve that gave dx_C already holds the new
// column); removing one deletes its row and column and restores the trailing block with a
// rank-one update (Bennett's algorithm, O(|C|^2)). There is no refactorization per pivot.
// The pivot (Schur complement) of an entering index must exceed Options::pivotTolerance
// times max |A_ii|, else Status::Failed. At the end x_C gets one step of iterative refinement
// with the factors and rows whose sign condition drifted are driven again.
//
// When it works. For a P-matrix (e.g. symmetric positive definite A, i.e. physics with
// cfm > 0) every Schur complement is positive and the method finds the unique solution. For
// symmetric positive semidefinite A (rank-deficient contacts, cfm = 0) a consistent problem
// usually solves (a zero-pivot row whose w is already 0 is left where it is, and the message
// counts such redundant rows). A pivoting that breaks down (Failed, or the default pivot limit
// reached: cycling) is run once more from zero on A + delta I, delta = 1e-10 max |A_ii| (from
// the guess that led into the breakdown the friction passes took up to 4x longer on Bullet's
// plank bridge): engines' redundant joints disagree by
// their drift (Bullet's bridge of planks joined by two ball joints each: ~1e-8 of b), which no
// zero pivot absorbs; the regularised answer leaves a residual on A at that level, and the
// message says "regularised". Otherwise, and for general non-symmetric matrices, the method may
// stop with Failed. Every answer is checked by the base class with the natural-map residual.
//
// Cost. Per pivot O(|C|^2) for the factor solve and update plus O(|N| n) for dw on N rows
// (O(nnz) of those rows when A is sparse); O(n^3) overall in the worst case, like a dense
// factorization. Memory: A permuted into processing order (dense n^2, or CSR/CSC when
// Problem::isSparse()), L (and U when A is not symmetric) at n^2 each. The workspace lives in
// the solver object and is reused: no reallocation when n does not grow. No state carries from
// one solve to the next: the same problem and start give the same answer. Large contact islands
// are newton's (newton.hpp; policy.hpp): the pivot count grows with the rows.
//
// Order of rows. Equality rows (-inf, inf) first, then the rows the start point guesses as
// clamped, then the other rows, friction rows last (so that normals are settled first).
//
// Tiny islands (a joint or two: dense A, at most 8 rows, no findex, symmetric A). The guess
// (the warm start; from zero, the rows whose bounds contain 0) is tried first on fixed-size
// arrays: one LDL^T of the guessed clamped block, x_C solved, the other rows' w checked, up to
// two block corrections of wrong guesses; wherever the general method would pivot (a small
// Schur pivot, a singular block, a set still wrong) it declines, x untouched, and the general
// method runs from the same start. Same answers to round-off (tests compare them); ODE's
// 6-row hinge island: ~1.7k instructions instead of ~7.3k (core/src/pivoting/dantzig_small.hpp).
//
// Warm start (Options::warmStart, or solveWithGuess). A nonzero start x guesses the index
// sets: rows strictly inside their bounds (and all equality rows) are guessed clamped and
// factored in one block; x_C is then solved with the other rows at their clamped start
// values; guessed rows that land outside their bounds are dropped from the block (one
// rank-one downdate each) until the block is feasible. The remaining rows are then added one
// by one as above. A right guess costs one factorization and no exchanges; a wrong guess costs
// at most a cold solve plus the block work. An all-zero x is a cold start.
//
// Friction (findex). Options::frictionBounds:
//   FixedOnce - stock ODE/Bullet behaviour: friction rows are processed last, and when the
//     first of them is reached the bounds of all of them are fixed at once to +-mu |x_normal|
//     from the normal values of that moment (ODE's dSolveLCP, lcp.cpp).
//     Later pivots may change the normal, so the answer may violate the final bounds; the
//     base class then reports Failed with the true residual. Friction rows start at x = 0.
//   Exact (default) - a fixed point over the bounds: after each pass the friction bounds are
//     recomputed from the returned normals and the boxed problem is solved again, warm started
//     from the previous factors and index sets (usually O(n^2) per pass, few exchanges),
//     until the findex residual is within Options::tolerance. The map nu -> |x_normal(nu)|
//     is piecewise affine, so the normals are extrapolated by Anderson acceleration
//     (DantzigParams::andersonDepth); when that stalls for andersonStall passes (a cycle
//     between active sets) plain damped iteration (stallDamping) takes over. Options::maxIterations
//     bounds the passes (MaxIterations when exceeded); a pass whose bounds did not move but whose
//     residual is still too large is Failed. The first pass is FixedOnce's (cold, and warm guesses
//     whose residual exceeds 1e-2) or takes its bounds from the guess (guesses within 1e-2): from
//     Bullet's cached impulses (residual 0.1-0.7) the guessed bounds made the second pass redo most
//     pivots (15 boxes, first timed step: 595 pivots against 242 with FixedOnce's first pass; 55
//     boxes, Never: 2038 against 1702). Not guaranteed: on strongly coupled random pyramids (mu =
//     1) about 5% of cases end in MaxIterations.
//
// Result::iterations counts pivots (direction computations: each row added or exchanged)
// summed over all passes; Options::maxPivots (0: 50 n + 100) limits them per pass
// (MaxIterations when exceeded). Options::timeBudget is one deadline for the whole solve: the
// pivoting checks it every max(1, 1024 / n) pivots and between
// friction passes (a clock read per ~1000 operations of pivot-column work); when it runs out
// the best iterate so far is returned with Status::TimeLimit (the start, when that is better:
// solver.hpp). One factorization is not interrupted.
#pragma once

#include <memory>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// Parameters of DantzigSolver beyond Options.
struct DantzigParams {
  // The shift delta of the retry after a breakdown, relative to max |A_ii| ("When it works"
  // above). Default kDantzigBreakdownShift (1e-10, thresholds.hpp).
  double breakdownShift = kDantzigBreakdownShift;
  // Exact friction: the normals' history depth of Anderson's extrapolation, the passes without
  // a new lowest bound change after which plain damped iteration takes over, and its damping
  // factor ("Friction" above). Defaults 6, 20 and 0.3.
  int andersonDepth = 6;
  int andersonStall = 20;
  double stallDamping = 0.3;
};

class DantzigSolver : public Solver {
 public:
  DantzigSolver();
  ~DantzigSolver() override;
  DantzigSolver(DantzigSolver&&) noexcept;
  DantzigSolver& operator=(DantzigSolver&&) noexcept;

  const char* name() const override { return "dantzig"; }

  DantzigParams& params() { return params_; }
  const DantzigParams& params() const { return params_; }

  // Friction fixed-point passes of the last solve (1 without findex or with FixedOnce).
  int passes() const;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Workspace;
  void runPivoting(const Problem& problem, Vector& x, Result& result);
  std::unique_ptr<Workspace> ws_;
  DantzigParams params_;
};

}  // namespace mlcp
