// mlcp/solvers/newton.hpp: semismooth Newton on the natural map of a boxed MLCP with findex
// (registry "newton"), for any square A, symmetric or not. The long form is
// docs/methods/newton.md; a quoted name below ("Step") is one of its sections.
//
// Method. With w = A x + b and the friction bounds l(x), u(x) (problem.hpp) the MLCP is
//     H(x) = x - mid(l(x), x - w, u(x)) = 0,
// H piecewise linear and semismooth; ||H||_inf is the accuracy measure (residual.hpp). Each row
// takes the piece of mid() that holds at z = x - w: free, row i of J is row i of A; at a bound,
// e_i, minus c_i e_j for a friction row on normal j. The friction coupling is exact, so the rate
// is quadratic once the pieces are the answer's ("Jacobian"). The direction solves
// (J + rho D) dx = -H, D = diag(1 on the free rows); the step is the first t = 1, 1/2, ... that
// passes a non-monotone Armijo rule on theta = ||H||_2^2 (memory nonmonotoneMemory: full steps
// across the kinks of sliding friction rows get through; "Step"). rho = mu max |A_ii| min(1, r)
// on the sparse path, mu in [proximal, proximalMax] adapted to the step lengths ("Proximal
// weight"): it keeps the near-singular blocks of coplanar contacts from throwing dx far away.
//
// Linear algebra. Up to denseFactorMaxRows rows: J dense, Eigen's PartialPivLU, least squares
// for a singular J, then Levenberg-Marquardt directions. Above: the rows at a bound eliminated,
// the nonsymmetric K = A_CC + A_CT S E_T on the free rows factored by KLU (linalg/sparse_lu.hpp;
// symbolic analysis kept while the reduced pattern holds). With the rows (Solver::useRows:
// A = J W J^T + diag(cfm)) the same K + rho I in body space (linalg/body_space.hpp) while every
// cfm_c + rho >= kBodyMinDiagonal max |A_ii| (thresholds.hpp).
//
// Starts and fallback. Where sweeps apply (A symmetric, A_ii > 0): coldSweeps pgs sweeps from
// x = 0, warmSweeps from a start whose scaled residual exceeds warmSweepsResidual. No descent:
// stepSweeps sweeps, else a Cauchy step along -J^T H ("Starts", "Fallback").
//
// Pivoting phase. Damped steps that end short on the sparse path with a symmetric A hand their
// best iterate to block principal pivoting (core/src/newton/block_pivoting.hpp), up to
// pivotingSteps block steps (bodyPivotingSteps with the rows): where hundreds of friction rows
// slide, the line search crosses their kinks a few rows a step, full steps exchange the rest.
//
// Cost. A sparse step: one assembly of K (O(nnz A)), its factorization, one solve, one product
// with J^T and one with A; each trial step length O(n). Figures: docs/benchmarks.md, "newton:
// factorization costs" and "newton's pivoting phase".
//
// Limits and invariants. Options::maxIterations bounds the damped steps, PivotingLimits and the
// step counts above the pivoting phase, Options::timeBudget both. maxStalls steps in a row without
// descent end Failed, maxStagnation without a new best MaxIterations. Every non-converged end
// returns the best iterate by ||H||_inf, the start included. Only symbolic analyses (functions of
// the pattern) carry between solves: the same problem and start give the same answer.
#pragma once

#include <iosfwd>
#include <memory>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// The limits of the pivoting phase's block steps ("Pivoting phase" above), declared once:
// NewtonParams inherits them (its fields keep these names) and BlockPivoting
// (core/src/newton/block_pivoting.hpp) takes them as they are.
struct PivotingLimits {
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

struct NewtonParams : PivotingLimits {
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
  // non-monotone rule of "Method" above; docs/methods/newton.md, "Step"); 0: monotone
  // Armijo. Default 1.
  int nonmonotoneMemory = 1;
  // The pivoting phase ("Pivoting phase" above): most block steps after damped steps that ended
  // short, for a problem without its rows and for one with them (whose steps factor in body
  // space at a fraction of the cost); 0: no pivoting phase. Defaults 40 and 120.
  int pivotingSteps = 40;
  int bodyPivotingSteps = 120;
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
