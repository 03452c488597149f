// mlcp/solvers/newton.hpp: a semismooth Newton method on the natural map of a boxed MLCP with
// findex (registry "newton"), for any square A (symmetric or not): small problems by dense LU (the
// Siconos circuit MLCPs with zero diagonals), large contact islands by a sparse LU of the
// reduced system on the free rows, warm-started from the last step's answer.
//
// Map. With w = A x + b and the bounds l(x), u(x) (a friction row i with findex j has l_i =
// lo_i |x_j|, u_i = hi_i |x_j|; problem.hpp), the MLCP is the equation
//
//     H(x) = x - mid(l(x), x - w, u(x)) = 0,
//
// H piecewise linear and semismooth. Its inf-norm is the accuracy measure (residual.hpp): the
// solve converges when ||H||_inf <= Options::tolerance (1 + ||b||_inf).
//
// Jacobian. At x each row takes the piece of mid() that holds at z_i = x_i - w_i:
//   free        (l_i < z_i < u_i)    H_i = w_i,        row i of J = row i of A;
//   at a bound  (z_i <= l_i or >= u_i; l_i = u_i)  H_i = x_i - bound_i,  row i = e_i, and for a
//               friction row also - c_i e_j, c_i = d bound_i / d x_j = (lo_i or hi_i) sign(x_j),
//               sign(0) = +1.
// J is an element of the generalized (B-) Jacobian of H. The friction rows' coupling is exact:
// eliminating the rows at their bounds leaves, on the free set C, K dx_C = r with K = A_CC +
// A_CT S E_T (T: friction rows on a bound whose normal is free, S their +-mu, E_T picking the
// normals), nonsymmetric even for symmetric A. With the coupling, Newton converges locally
// quadratically once the active pieces are the solution's; a lagged friction bound (taken from
// the normals of the last step, the system kept symmetric) converges only linearly, in mu.
//
// Step. The direction solves
//
//     (J + rho D) dx = -H,    D = diag(1 on the free rows),
//
// and the step is x + t dx with t = 1, 1/2, ... (NewtonParams::maxHalvings halvings at most,
// sparseMaxHalvings on the sparse path),
// the first t with the non-monotone Armijo rule (Grippo, Lampariello and Lucidi) on the merit
// theta = ||H||_2^2,
//
//     theta(x + t dx) <= max(theta(x_k), ..., theta(x_k-m)) + sigma t theta'(x; dx),
//     theta' = 2 (J^T H) . dx,   sigma 1e-4,   m = NewtonParams::nonmonotoneMemory (1).
//
// Why non-monotone: where many friction rows slide (Bullet's resting pyramids) the full step
// crosses kinks of H and raises theta a little before the next step lowers it far; the monotone
// rule halves such steps and raises the proximal weight, and the iterates then crawl (1% a step
// over tens of steps at residuals ~1e-4). A memory of one merit lets the full step through
// (docs/benchmarks.md, "newton's non-monotone line search"); longer memories let bad steps
// through too. The best iterate is kept either way.
//
// rho is a proximal (Levenberg-Marquardt) weight on the sparse path,
//
//     rho = mu max_i |A_ii| min(1, r),   r the scaled residual at x,
//
// that keeps the near-singular free blocks of coplanar contacts (redundant rows, only cfm on
// their null space) from throwing the null-space part of dx far away, and vanishes with the
// residual. mu starts at NewtonParams::proximal; a full step divides it by 10, a step that
// needed two or more halvings multiplies it by 10, and a direction without an acceptable t is
// recomputed from the same x with mu 10 times larger, up to NewtonParams::proximalMax. The dense
// path uses rho = 0 and answers a singular J by least squares (the least-norm solution); when
// the Newton direction fails there, Levenberg-Marquardt directions (J^T J + lambda I) dx =
// -J^T H with lambda = ||H||_2 10^k, k < 4, are tried before the fallback.
//
// Fallback. When no direction descends: NewtonParams::stepSweeps projected Gauss-Seidel sweeps
// (pgs.hpp) where they apply (A symmetric with a positive diagonal: they decrease the QP's
// objective, a restart from a point with other active pieces), otherwise a Cauchy step along
// -J^T H (the linear model's minimizer on that line) with the same line search. After
// NewtonParams::maxStalls failed Newton steps in a row or a Cauchy step that does not descend
// the solve ends Failed with its best iterate; after NewtonParams::maxStagnation steps without a
// new best iterate (the rounding floor of a tolerance below what the problem's conditioning
// allows) it ends MaxIterations with it: a limit, not a breakdown, so an island's acceptance
// judges that answer by its residual.
//
// Linear algebra. Problems of at most NewtonParams::denseFactorMaxRows rows build J densely and
// factor it with Eigen's PartialPivLU (O(n^3) per step, 0.3 ms at 108 rows); a solution that
// does not solve the system to 1e-9 relative (singular J) is replaced by
// CompleteOrthogonalDecomposition's least-squares one. Larger problems eliminate the rows at a
// bound (dx_t = -H_t + c_t dx_j: known when the normal j is at a bound too, coupled when it is
// free) and factor the reduced system on the free rows,
//
//     (K + rho I) dx_C = -H_C - A_CB dx_B^known,   K = A_CC + A_CT S E_T,
//
// by KLU (linalg/sparse_lu.hpp), assembled by rows from A's rows (duplicates summed); the
// coupled bound rows then follow from their normals. KLU's symbolic analysis (block triangular
// form, AMD order) is kept while the reduced pattern (the free set, and the coupled rows'
// normals) holds from one factorization to the next: the retries of one step with a larger rho
// and the last steps of a converging solve reuse it. The LU is taken on K's rows as the
// columns of K^T and solved transposed, so no transposed copy is made. A step costs one
// assembly of K (O(nnz A)), its factorization, one solve, one product with J^T and one with A
// (A dx); each trial step length then costs O(n), its slack being w + t A dx.
//
// Body space. A problem that comes with its rows (Solver::useRows: RowSolver, hence both
// adapters; A = J W J^T + diag(cfm)) factors the same K + rho I in body space instead
// (linalg/body_space.hpp: Woodbury on the bodies, S = I + V^T D^-1 U with D = diag(cfm + rho)),
// followed by two steps of iterative refinement on K's rows, as long as every cfm_c + rho is at
// least 1e-11 max |A_ii| (else the sparse LU above). S has 6 rows per body whatever the number
// of contact rows, so a step costs a fraction of KLU's: the same iterates, 7-20x less time per
// step on 55- and 210-box pyramids (docs/benchmarks.md). With every cfm > 0 the products with A
// (the line search's slack, J and J^T, the refinement's K) also go through the rows: 12
// multiply-adds a row instead of A's row (~80 entries on the pyramids).
//
// Why these choices. An LU of the nonsymmetric K keeps the coupling exact. The reduced K is
// far sparser than the whole-pattern J (429 free rows with 11k entries against 1140 rows with
// 81k at the captured 55-box Bullet island's answer): a solve of that island is 2.7x faster
// than with a factorization of the whole J on one kept analysis, with the same iterates. A
// Cholesky factorization of A_CC would need a correction of rank |T|, the sliding friction
// rows: ~60 on that island, i.e. ~60 extra solves per step (docs/benchmarks.md, "newton:
// factorization costs"). KLU and UMFPACK factor these patterns equally fast; KLU needs no BLAS.
// The dense path's threshold: on pyramid patterns KLU's factorization and solve overtake the
// dense LU near 100 rows (0.03 against 0.015 ms at 48 rows, 0.11 against 0.31 ms at 108, 0.89
// against 1.18 ms at 192); below it the dense path's least-squares and Levenberg-Marquardt
// steps also take singular J (the circuit MLCPs' equality blocks, up to 61 rows in the Siconos
// corpus), which the sparse LU refuses.
//
// Starts. A warm start (Options::warmStart, solveWithGuess) within
// NewtonParams::warmSweepsResidual of an answer is used as given (a resting pyramid's start
// from the last step's answers: scaled residuals ~1e-5); a farther one (the islands of a
// settling pile, whose contacts come and go: scaled residuals 1-10), where sweeps apply, first
// takes NewtonParams::warmSweeps projected Gauss-Seidel sweeps, which place most rows on their
// pieces. A cold start (x = 0), where sweeps apply, first takes NewtonParams::coldSweeps
// sweeps; pivoting from zero never runs here. Newton is fast from a start whose active pieces are
// nearly the answer's: warm-started from the previous step's exact answer, synthetic pyramids
// of 192-768 rows converge in 1-9 steps (10 of 12 cases), small captured islands in 1-6 steps
// even cold; on ODE's engine rows (pyramids of 1170 and 4740 rows, the 120-box wall) every step
// converges within the scenes' 50 steps. Where many friction rows slide at the answer (Bullet's
// resting pyramids: 272 of 740 on the 55 boxes) the pieces of hundreds of rows change a few per
// step, the line search shortens the steps across their kinks, and 50 steps end at residuals
// 1e-5..1e-3; the pivoting phase below finishes them. `auto` runs newton on contact islands
// above Policy::smallIslandRows (policy.hpp).
//
// Pivoting phase. When the damped steps end short of the tolerance (MaxIterations, no progress,
// no descent) on the sparse path with a symmetric A, block principal pivoting continues from
// their best iterate (core/src/newton/block_pivoting.hpp): full steps, each the exact solution of
// the equations of the current pieces (rho = 0, t = 1), the next pieces from where the iterate lies
// with a hysteresis of 0.01 tolerance (1 + |b|), the first ones from where the damped steps'
// best iterate lies (a row within 1e-6 of a bound held there); full steps that descend without
// a new best are allowed up to pivotingDescentSteps, a 2-cycle of sets or 3 steps without a new
// best hand over to damped block steps from the best point. Up to pivotingSteps block steps
// (bodyPivotingSteps with the rows, whose steps factor in body space). Why: where hundreds of
// friction rows slide, the line search crosses their kinks a few rows per step, while full steps
// from pieces that are nearly the answer's exchange the rest at once and end exact: Bullet's
// 55-box pyramid, 30 steps under the 0.05 s budget, converges in 30 steps with the phase against
// 22 without (docs/benchmarks.md, "newton's pivoting phase"). Its factorizations are its own
// (an LDL^T with a pivot tolerance, bordered updates between nearby sets), and in body space the
// same as the damped steps'. Result::iterations adds its block steps; the message says how it
// ended. Cost: up to pivotingSteps more factorizations for a solve that ends short, under the
// same time budget; without a budget that can triple such a solve (ODE's pyramid_1000, 41k rows:
// its unconverged settling steps take ~7 s instead of ~2 s, at residuals 1e-5 instead of 1e-4..
// 2e-3). RowSolverSettings::newton (mlcp run --pivoting-steps) bounds or turns it off.
//
// Limits and invariants. Options::maxIterations bounds the damped Newton steps
// (MaxIterations), the NewtonParams above the pivoting phase's, Options::timeBudget the wall
// time of both (checked before each step; TimeLimit). Every non-converged end returns the best
// iterate by ||H||_inf, the start included, so never worse than the start; the base class
// reports the true residual of what is returned. No state carries from one solve to the next
// except the symbolic analyses (KLU's, the pivoting phase's AMD order), functions of the
// pattern only: the same problem and start give the same answer.
#pragma once

#include <iosfwd>
#include <memory>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

struct NewtonParams {
  // Projected Gauss-Seidel sweeps over a cold start (x = 0) before the first step. Default 10.
  int coldSweeps = 10;
  // Projected Gauss-Seidel sweeps over a warm start whose scaled residual exceeds
  // warmSweepsResidual (an engine's start from the last step's impulses on new contacts, not a
  // near answer). Defaults 20 and 0.2.
  int warmSweeps = 20;
  double warmSweepsResidual = 0.2;
  // Problems of at most this many rows take the dense path (Eigen's LU of J); larger ones the
  // sparse LU (KLU). Default kNewtonDenseRows (100, thresholds.hpp).
  int denseFactorMaxRows = kNewtonDenseRows;
  // mu's start and its largest value (the sparse path's proximal weight rho = mu max |A_ii|
  // min(1, r)). Defaults 1e-3 and 1e3.
  double proximal = 1e-3;
  double proximalMax = 1e3;
  // Halvings of the step length in the line search: the dense path's (fine steps cross the
  // kinks of small nonsymmetric problems' maps) and the sparse path's (a direction that needs
  // more is recomputed with a larger proximal weight instead). Defaults 30 and 12.
  int maxHalvings = 30;
  int sparseMaxHalvings = 12;
  // Projected Gauss-Seidel sweeps of the fallback. Default 10.
  int stepSweeps = 10;
  // Newton steps in a row without descent (each followed by the fallback) before the solve
  // stops. Default 3.
  int maxStalls = 3;
  // Steps in a row without a new best iterate before the solve stops (MaxIterations). Default 50.
  int maxStagnation = 50;
  // Merits before the current one that the line search's reference takes the largest of (the
  // non-monotone rule of "Step" above); 0: monotone Armijo. Default 1.
  int nonmonotoneMemory = 1;
  // The pivoting phase ("Pivoting phase" above): most block steps after damped steps that ended
  // short, for a problem without its rows and for one with them (whose steps factor in body
  // space at a fraction of the cost); 0: no pivoting phase. Defaults 40 and 120.
  int pivotingSteps = 40;
  int bodyPivotingSteps = 120;
  // Block steps with at most this many sliding rows solve them by Woodbury on the symmetric
  // factor of A_CC + rho I (k sparse forward solves and a k x k dense LU); more: the
  // nonsymmetric LU of K. Default 16.
  int pivotingWoodburyRows = 16;
  // A block step whose sets differ from the last factored ones by at most this many rows
  // (joined + left the clamped set + sliding) reuses that factor through a bordered system; 0
  // factors every step afresh. Default 40.
  int pivotingUpdateRows = 40;
  // Full block steps that bring no new lowest merit but descend from the step before: up to
  // this many per solve do not count toward the hand-over to the damped block steps. Default 8.
  int pivotingDescentSteps = 8;
  // A full step whose index sets are those of two steps before (a 2-cycle) hands over to the
  // damped block steps at once. Default true.
  bool pivotingBreakCycles = true;
};

class NewtonSolver : public Solver {
 public:
  NewtonSolver();
  ~NewtonSolver() override;
  NewtonSolver(NewtonSolver&&) noexcept;
  NewtonSolver& operator=(NewtonSolver&&) noexcept;

  const char* name() const override { return "newton"; }

  NewtonParams& params() { return params_; }
  const NewtonParams& params() const { return params_; }

  // Of the last solve: numeric factorizations (sparse or dense).
  int factorizations() const { return factorizations_; }
  // Symbolic analyses this object has done (one per reduced pattern seen in a row).
  int analyses() const;
  // Of the last solve: the factorizations done in body space (a problem with its rows).
  int bodyFactorizations() const;
  // Of the last solve: the block steps of the pivoting phase (0 when it did not run).
  int pivotingSteps() const { return pivotingSteps_; }

  void useRows(const RowSystem* rows) override;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Work;
  int lineSearch(const Problem& problem, double slope);
  void setReference();
  double slope();
  bool newtonStep(const Problem& problem, double res, double rhoScale, double& mu);
  bool fallbackStep(const Problem& problem, bool sweeps);
  void start(const Problem& problem, Vector& x, bool sweeps);
  void pivotingPhase(const Problem& problem, Vector& x, Result& result, std::ostream& os);
  std::unique_ptr<Work> work_;
  NewtonParams params_;
  int factorizations_ = 0;
  int pivotingSteps_ = 0;
};

}  // namespace mlcp
