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
// counts such redundant rows). A pivoting that breaks down (Failed) is run once more from the
// caller's start on A + delta I, delta = 1e-10 max |A_ii|: engines' redundant joints disagree by
// their drift (Bullet's bridge of planks joined by two ball joints each: ~1e-8 of b), which no
// zero pivot absorbs; the regularised answer leaves a residual on A at that level, and the
// message says "regularised". Otherwise, and for general non-symmetric matrices, the method may
// stop with Failed. Every answer is checked by the base class with the natural-map residual.
//
// Cost. Per pivot O(|C|^2) for the factor solve and update plus O(|N| n) for dw on N rows
// (O(nnz) of those rows when A is sparse); O(n^3) overall in the worst case, like a dense
// factorization. Memory: A permuted into processing order (dense n^2, or CSR/CSC when
// Problem::isSparse()), L (and U when A is not symmetric) at n^2 each. The workspace lives in
// the solver object and is reused: no reallocation when n does not grow. No global state.
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
// time budget: then the best iterate is handed to the incremental pivoting below as its warm start.
// Measured (CPU time on a loaded 2-core machine, islands captured from tests/bench/bullet_bench's
// worlds, tests/bench/ode_bench.cpp). Bullet adapter's pyramids (warm start from the cached
// impulses, globalCfm 1e-5, one friction row per contact): the guesses are poor (residual
// 0.1-0.7; 5-40 normals in the wrong set: the stack is still moving) and A is nearly singular
// (four coplanar contacts per face, half the normals 0 at the answer), so full steps diverge
// (residual 0.7 -> 16 -> 53), the damped steps converge linearly (step lengths mostly 1/4-1/2) and
// settle after 55-80 steps; neither the friction-direction caching flags (the scene loader's) nor
// non-monotone line searches, other proximal weights (1e-3, 5e-2) or BPP-style set updates in
// the damped phase changed that. n = 1160 (55 boxes): 40 steps (~1 ms each) then the pivoting
// from the best iterate (~60-150 pivots, ~10 friction passes, ~20 ms): 55-105 ms per island,
// against 100-220 ms for the pivoting alone from the guess (Never: ~2000 pivots, half of them
// in the second friction pass, when the first took its bounds from the guess; ~1700 with
// FixedOnce's first pass, see Friction). n = 280 (15
// boxes): Never takes ~3-4 ms (~250 pivots) where the 40 damped steps plus the pivoting took ~9
// ms, hence autoWarmMinRows. Whole steps (tests/bench/bullet_bench, CPU ms, stock in the same
// run, two runs): 15 boxes 3.8-4.2 ms against stock btDantzigLCP's 4.1-4.4 ms (even); 55 boxes
// 79-100 ms against 383-468 ms (4.7-4.8x; the 20x goal is not met: ~40 steps of ~1 ms, a third
// of each in the LU, then ~20 ms of pivoting; fewer steps need a better globalization than
// found so far). ODE piles (A holds ~14% nonzeros): the all-clamped cold guess settles in 1 full
// step (n = 432: ~2.3 ms; n = 1728: ~30 ms) where the stepper's warm guess needed 6-9 steps, hence
// Auto's cold trial first (it stops at its first non-improving step, so it costs one factorization
// where it does not settle); ode_bench 20 5: 9.5-16x faster than dWorldStep at 588 rows, 64-71x at
// 1728, same answers. Synthetic box pyramids: a warm start settles in 1-2 full steps (55 boxes, n =
// 1200: about 8 ms per step including assembly); from a cold start the trial does not settle and
// the incremental pivoting runs from zero.
// Bullet's pyramid at rest (bullet_bench --settle 60; the adapter's guess is our own last answer
// per manifold point, residual 2e-5..1e-4): the cold trial never settled there (residual 0.14
// after its factorization of all 1160 rows, 6-12 ms, more than the rest of the solve), hence no
// trial for a guess within 1e-2 (ODE's stepper guesses have residuals 1.6-13 and keep it). From
// the guess the stage takes 2 full steps (the second reuses the first's factor): 2-4
// rows of the guessed sets are wrong (a normal at 0 whose w0 is slightly negative, ~1e-5, is
// guessed clamped and its friction row sliding; the answer holds it at 0), so the first step is
// not the answer. Symmetry is checked on a mirror map of A's pattern (isSymmetric's transposed
// copy cost ~2 ms per solve at n = 1160); AMD is computed once (A's pattern is kept at rest).
// Whole steps, CPU ms, stock in the same run, two runs: 55 boxes 5.5-6.2 ms against stock's
// 275-362 ms (44-65x; before: 13.9-24 ms, 14-19x); 15 boxes 0.43-0.74 ms against 4.0-7.9 ms
// (9-11x; before 2.2x). After the switch the trial runs once in autoColdRetry solves (it never
// settles on the moving pyramid either). Tried after the switch without gain: returning to full
// steps from the damped phase once the residual is below 1e-2 (up to 3 times; the full steps
// diverge again: residual after 40 steps 1.8-5.9e-3 against 0.9-1.3e-3, 128 against 83 ms), and
// other step budgets before the hand-over (CPU ms per step: 20 steps 123-137, 40 steps 85-88, 70
// steps 92-98: the damped steps' linear rate does not beat the pivoting's finish).
// Steady state of a demo that uses this solver from the start (bullet_bench --warmup 0 --settle
// N --steps 10, 55 boxes, n = 1160, m ~ 800 clamped rows, L ~ 43k entries), with the first sets
// from the natural map at the guess (as before blockTrustedSets; "Trusted guesses" below for
// now): each simulation step ~13 normals change set (coplanar face contacts whose share of the
// load goes to 0 and back) with their friction rows; from the guess the stage takes 4-15 steps:
// full steps, each later one reusing the first's factor (N = 80: p = 25 bordered rows on average,
// their Schur complement ~0.6 ms, against ~2-2.5 ms for a fresh LDL^T with its assembly), and when
// they stop improving damped steps whose rho changes every step (a fresh factorization each). Two
// patterns cost most of the fresh factorizations (traced at N = 150 and 300): the full steps
// 2-cycle between two sets near the answer (residual ~1e-5, merits repeating exactly) until the 3
// uphill steps are spent, then 1-2 damped steps settle; and on about every other solve the first
// full step lands above the guess's merit (residual 5e-2 from a guess at ~1e-3) while the next ones
// descend, so the 3 uphill steps ran out and 7-10 damped steps (7-10 factorizations) followed.
// blockBreakCycles and blockDescentSteps remove both: traced at N = 120, the solves then finished
// in 4-8 full steps on one factorization (one of 15 took a damped step). The counts are chaotic in
// N (rounding changes the trajectory): CPU ms per step (steps per simulation step), with both
// against without (HEAD before them), alternated, two runs (three at N = 150 and 300): N =
// 80: 11.3-12.7 (6) against 11.1-11.3 (5); N = 120: 8.8 (5) against 8.2 (4); N = 150: 9.7-11.9 (6)
// against 11.0-11.4 (6); N = 200: 10.0 (7) against 12.4 (6); N = 300: 12.7-19.2 (6)
// against 22.8-24.9 (9). Against the LU for sliding rows without reuse (earlier, other runs): N =
// 80 26-28 (8), N = 150 15-19 (4), N = 300 66-74 (15). Stock MLCP-Dantzig took 285-420 ms per step
// in earlier runs on this loaded machine (not re-measured), so 15-43x: the 20x goal is still not
// met at every N. At rest after SI
// (--warmup 30 --settle 60, 2 steps, same trajectory) 3.8-5.6 against 3.8-5.8 ms. After the
// switch (--warmup 30: 40 damped steps, then the pivoting) 270 against 263 pivots and steps per
// step, 77-100 against 79-106 ms (the machine's noise; the damped steps there have more than
// blockWoodburyRows sliding rows: the LU, no factor to reuse, and sets that change by more than
// blockUpdateRows rows). ODE piles (ode_bench 10 5, two runs each, unchanged: the cold trial
// settles in one full step): 11.4-11.5x at 588 rows, 89-100x at 1728.
// Tried without gain: CHOLMOD's supernodal LL^T (Debian's reference BLAS: 1.9 ms factor + 0.3 ms
// analysis per new pattern at m = 812, against ~1.8 ms for the up-looking LDL^T; OpenBLAS 1.3 ms,
// not a dependency worth adding), reusing a factor across a changed rho within 1e-3 or 0.1 of the
// smallest pivot (never applicable: the pivots are cfm-sized), rho rounded up to powers of 2, 4
// or 10 so that damped steps share it (step counts chaotic, no consistent gain), and a set change
// threshold of 0.3 tolerance instead of 0.01 (N = 300: 17 steps against 9). Tried in the demo's
// steady state (CPU ms per step, single runs against 10.9-13.4 / 11.0-12.5 / 20.2-24.9 ms at N =
// 80 / 150 / 300 without): single principal pivots where the full steps stop improving (only the
// most violated row changes set, its friction rows following; up to 2 per violated row; each
// reuses the factor): they 2-cycle too (a degenerate normal leaves and rejoins: residual 2e-7,
// 2e-5, 2e-7, ...) until their budget, N = 150 28.8 ms (17 steps), N = 300 41.4 (19); rho held
// across damped steps while the rule's rho stays within a factor 10 of it: 14.4 / 17.9 / 19.5 ms
// (8 / 5 / 9 steps), no change after the switch (its damped steps factor the LU, see above);
// damped steps at rho = 0 (the full steps' factor reused, the line search keeping descent) until
// one does not descend: 16.6 / 28.5 / 21.8 ms (8 / 14 / 10 steps: exact steps on the nearly
// singular blocks jump to residual ~2e-3 and the line search then creeps).
// Trusted guesses (DantzigParams::blockTrustedSets; a warm guess whose residual is within 1e-2, an
// engine's own last answer). In the demo's steady state the guess's residual is 2-5e-5, yet the
// natural map at it put 24-31 normals in the wrong set (traced at N = 300): coplanar face
// contacts whose share of the load is ~1e-6 N s, whose w0 = A x0 + b is of the same size as the
// change of b between steps (up to ~6e-5) and of either sign, so z = x0 - w0 sent loaded normals to
// 0 and unloaded ones into the clamped set, while the answer kept every one of them where the guess
// had it (the same zero / positive pattern) - and their friction rows followed the wrong normals.
// The first full step from those sets jumped to residual 2-3e-3 and 4-8 more steps (1-3 fresh
// factorizations) came back. The first sets are therefore taken from where the guess lies: a row
// at a bound (within 1e-6 of it relatively: the adapter rotates a sliding friction row's last
// impulse onto the new friction direction) is held there, the others are clamped; only the first
// sets (the damped steps' natural map at their iterates is unchanged). The steady-state solves
// then take 3 steps on one factorization (1-2 rows wrong: the normals that do go to 0 or come
// back), the at-rest solves after SI 1 step (2 before). Ours-only CPU ms per step, old (HEAD
// before) against new, alternated, two runs each: at rest after SI 5.7-6.0 -> 2.9-4.1; the demo's
// first 300 steps 21.5-22.7 -> 11.4-13.2; its steady state (N = 300) 16.8-19.6 -> 7.3-8.8; after
// the switch (the guess is SI's, not trusted) the same path, 270 pivots and steps per step.
// The demo's first step is cold (no cached impulses): its cold trial ended at residual 2.6e-3
// after 3 full steps and the pivoting from zero then took ~5600 pivots and 11 friction passes
// (~0.45 s CPU, 1.5 ms of the 300-step mean; under load its wall time passed bullet_bench's 1 s
// limit, which then stopped the configuration after that step). A trial that comes within 1e-2
// is now continued by the block stage from its best iterate (DantzigParams::autoColdContinue):
// 3 more steps, ~25 ms. Synthetic pyramids' trials end at 0.09-0.15 (unchanged: pivoting from
// zero). With both: the demo's first 300 steps 11.4-11.5 ms (5 pivots and steps per step, 23-26
// before) against 19.4-24.5 for HEAD before this session, steady state 5.1-5.3 against 12.7-17.7,
// at rest after SI 3.0-3.1 against 4.0-5.4 (ours only, CPU ms, alternated, two runs).
// Whole bullet_bench runs (stock MLCP-Dantzig in the same run, CPU ms per step, two runs, HEAD
// before this session's two changes run between them): the demo's first 300 steps 14.9-16.0
// against stock's 283.6-325.2 (19.0-20.3x; before 17.4x, and 12.8x in a run where stock's wall
// time passed the 1 s limit and it stopped early), its steady state 5.6 against 261.5-448.5
// (47-80x; before 12.5-14.7x), at rest after SI 2.9-3.6 against 258-263 (71-90x; before 50-72x),
// after the switch 76.9-112.8 against 386-518 (4.6-5.0x; before 5.8-6.0x: the same path, noise).
// ODE piles (ode_bench 10 5, two runs, alternated): the same path (the stepper's guesses are not
// trusted; the cold trial settles), 12.2x dWorldStep at 588 rows against 11.7-12.7x before, 83-101x
// at 1728 against 83-90x.
// What the demo's first 300 steps cost (traced, per solve: block steps, factorizations, sliding
// rows, set changes): about half of the block stage's time is solves 5-30 (the pyramid falling
// into place), 12-29 block steps each, every one a fresh factorization (mostly the LU: 40-240
// sliding rows), ~2.5 ms each (LDL^T with its capacitance ~2.1 ms, a reused factor ~0.4 ms);
// 70% of those solves' CPU time is the numeric factorization itself. The full steps change
// 30-570 rows each (no reuse applies), and their first sets were the natural map's: the guesses
// there (our last answers) have residuals 2e-2..5e-2, outside the trusted 1e-2.
// Tried in session 6 without gain: (a) for a normal whose zero / positive state changed between
// the last two simulation steps, the adapter's start from the answer two steps back (the chatter
// is period 2: ~5-8 such normals flip against the last step per 800 contacts, 0-1 against two
// steps back; but the wrong first sets were the natural map's, not those normals): steady state
// 17.5 against 17.7 ms without trusted sets, 8.7 against 5.4 with them (single runs); (b) more
// Woodbury rows and reuse (blockWoodburyRows / blockUpdateRows 32 / 64, 64 / 64, 64 / 96 against
// 16 / 40, with both changes above): the first 300 steps 10.3 / 11.8 / 14.4 against 11.2 ms,
// steady state 5.1 / 6.6 / 12.2 against 5.4 (single runs; the step counts are chaotic).
// Guesses of a moving scene (DantzigParams::blockSetsAtGuessResidual, session 6 round 2). The
// first sets are taken from where every warm guess lies, not only a trusted one's (the cold-trial
// rule keeps kTrustedGuess = 1e-2). Traced on the falling pyramid (solve 8): the natural map at
// the guess (residual 4.7e-2) put 566 rows in the wrong set and the first full step jumped to
// residual 1.1; from where the guess lies 113 rows changed and the first step reached 1.3e-2.
// Block steps over the demo's first 300 solves 1661 -> 1351 (any limit from 0.1 to 100 gave
// 1351-1368); after the switch (SI's guesses, residual 0.1-0.7) 674 -> 625 over 20 solves, but
// pivots and steps per step 156 -> 166; the steady state's pivots and steps per step 4 -> 3;
// ODE's piles unchanged (their cold trial settles: no warm stage). Ours-only CPU ms per step, old
// (HEAD before) against new, alternated, two runs each: the first 300 steps 13.4-13.7 -> 11.9-12.4
// (another pair 17.2 / 13.0 -> 12.9 / 10.3), steady state (--settle 300) 5.9-6.2 -> 5.6-5.7, at
// rest after SI 2.9-3.7 -> 2.7-4.5, after the switch 86-129 -> 100-109 (the machine's noise: a
// CI run used both cores). Tried without gain there: the natural map's set for rows whose |w0|
// exceeds 1e-3 / 1e-2 / 1e-1 (1 + |b|) (new contacts), the guess's elsewhere: 1532 / 2174 / 1452
// block steps against 1351; blockDescentSteps 0 / 2 / 4 against 8: 2223 / 1342 / 1350 (chaotic).
// Whole bullet_bench runs with stock in the same run (two runs, under the CI's load): the first 300
// steps 9.7 / 9.3 ms against stock's 290 / 277 ms CPU (30.1x / 29.8x; wall 41.8x / 29.3x). ODE
// (ode_bench 10 5, two runs): 11.6x and 14.2x dWorldStep at 588 rows, 77x and 105x at 1728, the
// same residuals as before. Also tried there without gain: the LU's inner loop on interleaved (L,
// U) and (y, z) pairs, plain and with SSE2 packed operations (the loop is bound by its scattered
// loads, not by instructions: the first 40 steps 36-41 (pairs) and 36-58 (SSE2) against 33-46 and
// 34-38 ms CPU without, alternated, three runs each); no iterative refinement in the block steps
// (pivots and steps per step 4 -> 5 in the first 300 steps, 3 -> 4 in the steady state, times
// within the noise).
// Pre-sweeps (DantzigParams::blockPgsSweeps, blockPgsResidual; session 7). Right after the switch
// from SI the guesses' residuals are 0.19-0.8 and every solve took 40 damped block steps (fresh
// factorizations) and then 56-540 pivots. Traced over the first 10 solves: the start had 75-407
// rows in another set than the answer (7-139 normals positive at the start and 0 at the answer,
// by up to 0.5; 80-200 friction rows inside their bounds at the start and sliding at the answer).
// Projected Gauss-Seidel from the guess (K = 10 / 30 / 100 sweeps) reaches residual ~1e-2 / 3e-3 /
// 1e-3 but still leaves 60-380 rows in the wrong set (the exact answer's split of the load among
// coplanar contacts hangs on cfm-sized terms that the sweeps do not resolve): pivoting from the
// PGS iterate after 1 block step took 600-3300 pivots, its sets alone (the block stage from the
// guess) 279 pivots and steps per step against 301 without. As a start point the iterate pays:
// the damped steps start near 1e-2 instead of 0.2-0.8 and more solves settle within maxBlockSteps.
// K = 5 (any of 2-8 alike): over 10 solves block steps 402 -> 358, pivots 2616 -> 1031; over 30
// solves 753 -> 626 and 2618 -> 1054; pivots and steps per step (bullet_bench --steps 10) 301 ->
// 138 (K = 10 / 15 / 20, sweeps above 1e-2: 135 / 217 / 297). PGS sweeps between damped steps (3 or
// 10 after each, kept when they lower the merit, as PGS-SM alternates them): 784-1209, worse. The
// falling pyramid's own last answers (residual 0.01-0.3 in solves 5-30 of a demo) are made worse
// starts by the sweeps (rows in the wrong set 67 -> 205: the guess already has the exact answer's
// structure, the sweeps blur it; block steps per solve up to 3x), hence blockPgsResidual = 0.2:
// after the switch 9 of 10 solves get them, of the demo's first 300 solves 2 (block steps 1346 ->
// 1352). Ours-only CPU ms per step, old (HEAD before) against new, alternated, two runs each,
// load average ~3: after the switch 129.8-129.9 -> 94.9-98.2 (30 steps: 69.2-84.2 -> 50.3-52.1;
// pivots and steps per step 112 -> 56); the first 300 steps 12.4-13.3 -> 10.0-16.0 (noise: 4
// per step both), steady state 5.7-7.7 -> 7.3 (the same path), at rest after SI 4.4-4.8 ->
// 3.4-5.1 (the same path). ODE (ode_bench 10 5): the same path (no solve gets the sweeps: the
// cold trial settles), 13.6-13.8x -> 11.9-12.0x dWorldStep at 588 rows, 94-103x -> 84-95x at
// 1728 (noise), the same residuals. Whole bullet_bench runs with stock in the same run (CPU ms per
// step): after the switch 83.9 / 62.1 against 438.9 / 360.8 (5.2x / 5.8x; before 4.4-5.0x; the 20x
// goal is not met: ~35 damped block steps per solve remain, ~1.5-2 ms each, a fresh LU each), the
// first 300 steps 11.0 against 299.4 (27x), steady state 8.1 against 320.0 (40x), at rest after SI
// 2.9 against 278.4 (95x). Tried with the pre-sweeps without gain: maxBlockSteps 60 / 80 (pivots
// and steps per step after the switch 138 -> 96 / 81, CPU ms within the noise: 10 steps 58-89
// against 62-75 at 40, 30 steps 43.9 / 45.8 against 41.6; the first 300 steps unchanged),
// relaxation 0.7 / 1.3 (pivots and steps per step 293 / 172 at K = 5, 184 / 215 at K = 10, against
// 138), the first sets from the natural map at the swept iterate (142 against 138, 30 steps 62
// against 56), damped steps at once from it (no full steps: 144 against 138; CPU ms per step over
// 20 steps, four alternated runs, 58.6-85.3 against 56.6-82.2: the noise).
//
// Body space (DantzigParams::blockBodySpace, maxBodyBlockSteps; session 8). A problem assembled
// from rows (rows.hpp, handed over by Solver::useRows: RowSolver, hence the Bullet and ODE
// adapters) has A = J W J^T + diag(cfm), so a block step's K = D + J_C W G_C^T (D = diag(cfm_c +
// rho), G_c = J_c plus c_t J_t of c's sliding rows) is solved by Woodbury in body space: K^-1 r =
// D^-1 (r - J_C R y), S y = R^T G_C^T D^-1 r, S = I + R^T G_C^T D^-1 J_C R (W = R R^T per body,
// R from the eigen decomposition of invInertia: singular inertia allowed; static bodies left out),
// S of size 6 x dynamic bodies, factored as a right-looking LU on 6 x 6 blocks in an AMD order of
// the body graph with its block fill (core/src/dantzig_body.hpp). Every step (damped or full)
// whose every d_c is at least blockBodyMinDiagonal max |A_ii| takes it (no factor is kept for the
// bordered updates then: a fresh S costs less than a reuse); the others factor A_CC as above.
// Conditioning ~ 1 / d: body-space steps take two steps of refinement against the true K (the
// others one). With one step and a limit of 1e-9 a test's cfm = 0 pyramid (damped steps near the
// answer: rho -> 0) ended in the friction passes' MaxIterations; with two, 1e-11 also takes ODE's
// full steps (cfm 1e-8, max A_ii 64: d = 1.6e-10 max A_ii; 1e-6 left them to A_CC).
// Bullet's 55-box pyramid after the switch (n = 1160, m ~ 550-700, 57-105 sliding rows, S 330 x
// 330; prototype, per damped step, 104 steps): one fresh factorization and solve ~0.16-0.21 ms
// against ~0.86-1.08 ms for K's LU (5.2-5.3x; with S factored by the scalar SymmetricPatternLu
// instead of 6 x 6 blocks only 1.8-2.0x: L ~10k entries against K's ~27k, but denser columns),
// relative difference of the two solutions before refinement <= 5e-11. With steps that cheap,
// solves after the switch settle in the block stage within 120 steps (iterations per step 138 ->
// 45: no pivoting finish); maxBlockSteps 40 / 60 / 80 / 100 / 120 / 200 gave 138 / 96 / 81 / 82 /
// 45 / 45, hence maxBodyBlockSteps (maxBlockSteps stays 40 for steps that factor A_CC). Ours-only
// CPU ms per step, session 8's start against this, alternated, two runs each: after the switch
// 61-69 -> 19-21, the demo's first 300 steps 14.0-14.9 -> 3.8-5.6, steady state (--settle
// 300) 6.1-7.4 -> 2.7-2.9, at rest after SI 3.0-4.3 -> 1.3-1.7; ODE (ode_bench 10 5) 11.1-11.5x
// -> 15.7-19.0x dWorldStep at 588 rows, 88-110x -> 175-178x at 1728 (residuals 4.5e-12 -> 1.2e-14).
// Whole bullet_bench runs with stock in the same run (CPU ms per step): after the switch 30.6
// / 27.7 against 535 / 496 (17.5x / 17.9x: the 20x goal is not met yet), first 300 steps 3.6
// against 306 (85x), steady state 2.9 against 298 (104x), at rest 2.0 against 267 (135x). perf
// after the switch: S's assembly and factorization 23%, the block stage's merits and line search
// 16%, the clamped rows' A x (three sparse row sweeps per step: right-hand side and two
// refinements) 18% (a plain loop over the storage instead of Eigen's sparse-row dot: the same
// share), S's solves 9%. Session 8 round 2: with rows and every cfm > 0 the block stage's products
// with A (w = A x + b, right-hand sides, refinement residuals) are formed as (J R)((J R)^T x) +
// cfm x, 24 multiply-adds a row (rows checked against A's diagonal first); with cfm = 0 they stay
// on A (on a singular A their round-off differences took a test's sliding pyramid from settling to
// 120 unsettled steps). Ours-only CPU ms, alternated with round 1, two runs each on a busy machine:
// after the switch 32.3 / 21.1 -> 22.8 / 15.9; first 300 steps (--warmup 0 --steps 300) 5.2 / 4.2
// -> 2.8 / 3.1; --settle 300 1.4 / 1.9 -> 1.8 / 1.8 (noise); ODE 588 rows 3.9 / 4.2 -> 3.1 / 3.5
// ms, 1728 rows 13.5 / 10.8 -> 10.3 / 8.9 ms. With stock in the same run after the
// switch: 24.4x, 24.4x, 20.4x (a run beside ctest: 20.1x; the lead's two runs at session 8's
// final code 25.1x / 25.9x: the 20x goal is met after the switch too). The dense bodies^2 block
// table (kMaxBodies) and S's per-run assembly are not yet replaced.
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
  // Auto: after a cold trial that did not settle, warm solves of this solver on problems of the
  // same size skip the trial except every autoColdRetry-th one (a trial that settles, or a
  // problem of another size, resets this). Default 8.
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
  int coldMissed_ = 0;      // solves since the last cold trial, which did not settle (0: it did)
  int coldMissedRows_ = 0;  // that trial's problem size: another size tries again
};

}  // namespace mlcp
