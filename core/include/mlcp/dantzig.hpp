// mlcp/dantzig.hpp: Dantzig-Cottle principal pivoting for boxed MLCPs with findex (registry
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
// the solver object and is reused: no reallocation when n does not grow. No global state; the
// block stage's cold-trial memory is the caller's (useColdTrialMemory; RowSolver keeps one per
// island slot): without it the same problem and start give the same answer.
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
// 6-row hinge island: ~1.7k instructions instead of ~7.3k (core/src/dantzig_small.hpp).
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
//     is piecewise affine, so the normals are extrapolated by Anderson acceleration (depth
//     6); when that stalls for 20 passes (a cycle between active sets) plain damped
//     iteration (factor 0.3) takes over. Options::maxIterations bounds the passes
//     (MaxIterations when exceeded); a pass whose bounds did not move but whose residual is
//     still too large is Failed. The first pass is FixedOnce's (cold, and warm guesses whose
//     residual exceeds 1e-2) or takes its bounds from the guess (the block stage's iterate, and
//     guesses within 1e-2): from Bullet's cached impulses (residual 0.1-0.7) the guessed bounds
//     made the second pass redo most pivots (15 boxes, first timed step: 595 pivots against 242
//     with FixedOnce's first pass; 55 boxes, Never: 2038 against 1702). Not guaranteed: on
//     strongly coupled random pyramids (mu = 1) about 5% of cases end in MaxIterations.
//
// Block stage (DantzigParams::blockStage; sparse symmetric problems, Exact friction only). Before
// the incremental pivoting, whole index sets are guessed and exchanged at once: semismooth Newton
// steps on the natural map H(x) = x - clamp(x - w, lo', hi') (block principal pivoting, Kostreva /
// Judice-Pires, when every step is full). Each row is clamped (w_i = 0), held at lo or hi, or
// fixed, as the natural map at the current x says; a friction row at a bound is the linear
// equation x_t = mu_t s_j x_j coupling it to its normal j (s_j the normal's sign), so findex is
// exact without fixed-point passes, and friction rows whose normal is held at 0 are fixed at 0.
// One step solves those equations. A_CC + rho I is factored by an up-looking sparse LDL^T
// (core/src/dantzig_block.hpp: SymmetricPatternLu::factorSymmetric) in a fill-reducing AMD order
// of the whole A, computed once per pattern of A and inherited by every clamped block. Sliding
// rows (at a bound, normal clamped) are substituted, which makes the matrix K = B + U E^T
// nonsymmetric (B = A_CC + rho I; U's column c_t A_{C,t} per sliding row t, E's the unit vector of
// t's normal); up to DantzigParams::blockWoodburyRows of them are bordered onto B's factor
// (Woodbury: a k x k capacitance S = I + E^T B^-1 U from sparse forward solves, whose reach in
// the elimination tree is short; two solves with B per solve with K), more are factored as K = L
// D U without pivoting by the up-looking LU whose L and U^T share the Cholesky pattern (K keeps
// A_CC's pattern: a contact's friction and normal rows touch the same bodies; twice an LDL^T's
// work; a K outside that pattern falls back to Eigen's SparseLU, 3-4x more per step on the Bullet
// pyramids). A later step whose sets differ from the last factored ones by at most
// DantzigParams::blockUpdateRows rows (joined, left the clamped set, sliding), with the same rho,
// reuses that factor: the joined rows are bordered on, a left row's x is held at 0 by a
// multiplier that frees its equation, and the p x p Schur complement of the border is factored
// densely (a sparse forward solve per bordered row, one more per sliding row). One step of
// iterative refinement follows. First the steps are full (block principal pivoting; the next sets
// change only rows violated beyond 0.01 tolerance (1 + |b|), so that degenerate rows do not flip on
// rounding). A full step that brings no new lowest merit ||H||^2 but is below the step before is
// free (up to DantzigParams::blockDescentSteps per solve: from a guess that is itself the best
// point so far, Bullet's full steps often descend for several steps, residual 5e-2 -> 1e-2 -> 2e-3
// -> ..., before beating it); a full step whose sets are those of two steps before (a 2-cycle,
// which would repeat that step's x) ends the full steps at once (DantzigParams::blockBreakCycles).
// When 3 other full steps in a row bring no new lowest merit (or a block is singular), the stage
// goes back to the best point and continues damped: sets from the natural map at x, a proximal term
// rho (x_C - x_C,prev) on the clamped rows (rho = 1e-2 max|A_ii| min(1, ||H||): coplanar contacts
// make clamped blocks nearly singular, and far from the answer their exact equations throw the
// null-space part far away), and the step shortened by backtracking until ||H||^2 decreases
// (Armijo); at a kink where no step length descends the full step is taken up to 2 times in a row.
// Warm starts take the first sets from the natural map at the guess, trusted ones (below) from
// where the guess lies; cold starts clamp every row.
// The stage ends when the residual (residual.hpp) is within Options::tolerance (then it is the
// answer, projected onto the bounds when that keeps it within tolerance: Result::iterations counts
// its steps), or after DantzigParams::maxBlockSteps, no descent, a singular damped block or the
// time budget: then the best iterate is handed to the incremental pivoting below as its warm start,
// and stays the answer when the pivoting ends unconverged at a larger residual.
// Starts of the block stage. A warm start takes a few projected sweeps first
// (DantzigParams::blockPgsSweeps, up to blockPgsResidual) when its residual is large, so that the
// first sets come from an iterate that already places most rows; a guess within
// blockSetsAtGuessResidual of the answer is trusted as it lies.
//
// Body space (DantzigParams::blockBodySpace, maxBodyBlockSteps). A problem assembled from rows
// (rows.hpp, handed over by Solver::useRows: RowSolver, hence both adapters) has A = J W J^T +
// diag(cfm), so a block step's K = D + J_C W G_C^T (D = diag(cfm_c + rho), G_c = J_c plus c_t J_t
// of c's sliding rows) is solved by Woodbury in body space: K^-1 r = D^-1 (r - J_C R y), S y = R^T
// G_C^T D^-1 r, S = I + R^T G_C^T D^-1 J_C R (W = R R^T per body, R from the eigen decomposition
// of invInertia: singular inertia allowed; static bodies left out). S has 6 x (dynamic bodies)
// unknowns, fewer than the clamped rows of a contact island, and is factored as a right-looking LU
// on 6 x 6 blocks in CHOLMOD's fill-reducing order of the body graph (linalg/body_space.hpp,
// linalg/ordering.hpp). Every step whose every d_c is at least blockBodyMinDiagonal max |A_ii|
// takes it, with two steps of refinement against the true K (its conditioning is ~ 1 / d); the
// others factor A_CC as above.
// Because these steps are cheap, maxBodyBlockSteps allows more of them than maxBlockSteps before
// the hand-over to the incremental pivoting. With rows and every cfm > 0 the stage's products with
// A are formed as (J R)((J R)^T x) + cfm x, 24 multiply-adds a row (the rows are checked against
// A's diagonal first); with cfm = 0 they stay on A. Measurements: docs/benchmarks.md; what did not
// pay: docs/decisions.md.
//
// Result::iterations counts pivots (direction computations: each row added or exchanged)
// summed over all passes; Options::maxPivots (0: 50 n + 100) limits them per pass
// (MaxIterations when exceeded). Options::timeBudget is one deadline for the whole solve: the
// block stage checks it after each step, the pivoting every max(1, 1024 / n) pivots and between
// friction passes (a clock read per ~1000 operations of pivot-column work); when it runs out
// the best iterate so far is returned with Status::TimeLimit (the start, when that is better:
// solver.hpp). One factorization or block step is not interrupted.
#pragma once

#include <memory>

#include "mlcp/solver.hpp"

namespace mlcp {

namespace detail {
class BlockPivoting;
}

// Parameters of DantzigSolver beyond Options (see "Block stage" above).
struct DantzigParams {
  enum class BlockStage {
    // n >= autoMinRows and at most autoMaxDensity n^2 nonzeros in A: a warm guess whose
    // residual is within 1e-2 (an engine's own last answers at rest) gets up to maxBlockSteps
    // from it at once; otherwise first a trial of autoColdSteps from the cold guess (dropped
    // when it does not settle, unless autoColdContinue applies), then warm starts with n >=
    // autoWarmMinRows get up to
    // maxBlockSteps from their guess; the others pivot from their guess (cold: from zero).
    Auto,
    Always,  // whenever it applies (Exact friction, symmetric A), cold starts too
    Never,   // incremental pivoting only (the dense path)
  };
  BlockStage blockStage = BlockStage::Auto;  // default Auto
  // Block steps (each a fresh factorization or a reuse of the last one) the block stage may take
  // before it hands over. Default 40.
  int maxBlockSteps = 40;
  // The same for a solve whose steps factor in body space (blockBodySpace with the problem's
  // rows): each costs a fraction of an A_CC factorization, so more of them pay before the
  // incremental pivoting's finish (Bullet's pyramid after the switch: none needed beyond 120).
  // Default 120.
  int maxBodyBlockSteps = 120;
  // Auto: the smallest problem (rows) that gets the block stage. Default 100.
  int autoMinRows = 100;
  // Auto: the largest fraction of nonzero entries in A. Default 0.3.
  double autoMaxDensity = 0.3;
  // Auto: most block steps of the trial from the cold guess (it ends at its first full step
  // that brings no new lowest merit). Default 3.
  int autoColdSteps = 3;
  // Auto: after a cold trial that did not settle, warm solves that share its ColdTrialMemory
  // (DantzigSolver::useColdTrialMemory) on problems of the same size skip the trial except every
  // autoColdRetry-th one (a trial that settles, or a problem of another size, resets this).
  // Default 8.
  int autoColdRetry = 8;
  // Auto: a cold solve of at least autoWarmMinRows rows whose cold trial did not settle but came
  // within 1e-2 (residual) continues the block stage from the trial's best iterate (else the
  // incremental pivoting runs from zero). Default true.
  bool autoColdContinue = true;
  // Auto: the smallest problem (rows) whose warm start gets the block stage after an unsettled
  // cold trial; smaller ones go to the incremental pivoting from their guess, which is cheaper
  // there than the damped steps (Bullet's 15-box pyramid, n = 280: ~4 ms against ~9 ms).
  // Default 500.
  int autoWarmMinRows = 500;
  // Block steps with at most this many sliding rows solve them by Woodbury on the symmetric
  // factor of A_CC (k sparse forward solves and a k x k dense LU); more: the nonsymmetric LU.
  // Default 16.
  int blockWoodburyRows = 16;
  // A block step whose sets differ from the last factored ones by at most this many rows
  // (joined + left the clamped set + sliding) reuses that factor through a bordered system;
  // 0 factors every step afresh (even one whose sets equal the factored ones). Default 40.
  int blockUpdateRows = 40;
  // Full block steps that bring no new lowest merit but descend from the step before: up to
  // this many per solve are taken without counting toward the hand-over to the damped steps
  // (they reuse the factor); 0: every such step counts. Default 8.
  int blockDescentSteps = 8;
  // A full step whose index sets are those of two steps before (a 2-cycle) hands over to the
  // damped steps at once instead of repeating that step. Default true.
  bool blockBreakCycles = true;
  // A warm guess whose residual is within blockSetsAtGuessResidual takes its first index sets from
  // where it lies (rows at a bound held there, the others clamped) instead of from the natural map
  // at it (see "Trusted guesses" above). Default true.
  bool blockTrustedSets = true;
  // The largest residual (residual.hpp) of a warm guess that blockTrustedSets applies to (1e-2:
  // an engine's own last answers at rest only, the rule before "Guesses of a moving scene"
  // above). Default infinity (every warm guess).
  double blockSetsAtGuessResidual = kInf;
  // Projected Gauss-Seidel sweeps (pgs.hpp, relaxation 1) over a warm guess whose residual
  // (residual.hpp) exceeds blockPgsResidual; the block stage starts from their iterate (its first
  // sets from where it lies, see "Pre-sweeps" above). 0: none. Default 5.
  int blockPgsSweeps = 5;
  // The smallest residual of a warm guess that gets blockPgsSweeps (0.2: Bullet's guesses right
  // after the switch from SI, 0.19-0.8, but not most of a falling pyramid's own last answers,
  // 0.01-0.3, which the sweeps make worse starts). Default 0.2.
  double blockPgsResidual = 0.2;
  // Block steps of a problem that comes with its rows (Solver::useRows; RowSolver, hence the
  // Bullet and ODE adapters) factor in body space where that applies (see "Body space" above).
  // Default true.
  bool blockBodySpace = true;
  // Body space applies to a step whose every clamped row has cfm_c + rho at least this times
  // max |A_ii| (its conditioning grows as 1 / d; two steps of refinement follow); other steps
  // factor A_CC. Default 1e-11.
  double blockBodyMinDiagonal = 1e-11;
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

  // Friction fixed-point passes of the last solve (1 without findex, with FixedOnce, or when
  // the block stage settled).
  int passes() const;
  // Block steps of the block stage in the last solve (0 when it did not run), and whether
  // it produced the answer (else incremental pivoting finished from its best index sets).
  int blockSteps() const { return blockSteps_; }
  // Of those, the steps that factored their clamped block afresh (the others reused a factor).
  int blockFactorizations() const { return blockFactorizations_; }
  // Of those, the ones factored in body space (DantzigParams::blockBodySpace).
  int blockBodyFactorizations() const { return blockBodyFactorizations_; }
  bool blockSettled() const { return blockSettled_; }

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 public:
  void useRows(const RowSystem* rows) override { rows_ = rows; }

  // Auto's cold-trial memory over the solves of one island (DantzigParams::autoColdRetry). The
  // caller holds it (RowSolver keeps one in each island's slot) and lends it for a solve; without
  // one (the default, nullptr) every warm solve tries the cold sets, and the same problem and
  // start give the same answer.
  struct ColdTrialMemory {
    int missed = 0;  // solves since the last cold trial, which did not settle (0: it settled)
    int rows = 0;    // that trial's problem size: another size tries again
  };
  void useColdTrialMemory(ColdTrialMemory* memory) { coldMemory_ = memory; }

 protected:
 private:
  struct Workspace;
  bool wantsBlockStage(const Problem& problem) const;
  // fromBlock: x is the block stage's best iterate (its friction values are trusted).
  void runPivoting(const Problem& problem, Vector& x, Result& result, bool fromBlock);
  std::unique_ptr<Workspace> ws_;
  std::unique_ptr<detail::BlockPivoting> block_;
  DantzigParams params_;
  int blockSteps_ = 0;
  int blockFactorizations_ = 0;
  int blockBodyFactorizations_ = 0;
  const RowSystem* rows_ = nullptr;
  bool blockSettled_ = false;
  Vector blockBest_;  // the block stage's best iterate while pivoting continues from it
  ColdTrialMemory* coldMemory_ = nullptr;  // lent per solve (useColdTrialMemory)
};

}  // namespace mlcp
