// mlcp/newton.hpp: a projected Newton method for boxed MLCPs with findex and a symmetric
// positive semidefinite A (registry "newton"), meant for large islands: each step is one sparse
// Cholesky factorization of the free rows, by CHOLMOD on a symbolic analysis kept while A's
// pattern holds, so that a step costs what a factorization of A costs and grows with the island
// as its fill does, not as pivot counts do.
//
// Problem. With symmetric A and fixed bounds l <= x <= u the MLCP is the optimality condition of
// the convex box-constrained quadratic program
//
//     min f(x) = x^T A x / 2 + b^T x   subject to  l <= x <= u,     grad f = w = A x + b.
//
// Friction rows (findex) have the bounds l_i = lo_i |x_j|, u_i = hi_i |x_j| of their normal j.
// Inside one step they are constants, taken from the current normals; every step refreshes them
// (an outer fixed point over the bounds, one refresh per step) and projects x onto them. The
// accuracy measure is the natural map H(x) = x - clamp(x - w, l(x), u(x)) with the true, moving
// bounds (residual.hpp): the solve converges when ||H||_inf <= Options::tolerance (1 + ||b||_inf).
//
// Step (Bertsekas' projected Newton). At a feasible x a row is held when it is fixed (l = u) or
// within eps of a bound with w pushing outward (x - l <= eps, w > 0 or u - x <= eps, w < 0; eps =
// min(1e-3, ||H||_inf), the eps-active set that lets rows near a bound leave the free set a step
// sooner); the others are free (C). The direction solves the free rows' Newton system, the held
// rows taking a diagonally scaled gradient step that the projection ends on their bound,
//
//     (A_CC + rho I) dx_C = -w_C,   dx_i = -w_i / A_ii (i held, not fixed),   0 (fixed),
//
// symmetric positive definite for rho > 0. The step is x(t) = P(x + t dx), P the projection onto
// the step's bounds, with t = 1, 1/2, ... (at most NewtonParams::maxHalvings halvings) until
// Armijo's rule on f holds, f(x(t)) <= f(x) + 1e-4 w^T (x(t) - x). f decreases at every accepted
// step, so for fixed bounds the iteration converges to the QP's minimizer, identifies its active
// set in finitely many steps and then converges quadratically (rho -> 0). rho is a proximal
// (Levenberg-Marquardt) weight,
//
//     rho = mu max_i A_ii min(1, r),   r the scaled residual at x,
//
// that keeps the near-singular clamped blocks of coplanar contacts from throwing the null-space
// part far away and vanishes with the residual. mu starts at NewtonParams::proximal, is divided
// by 10 after a full step, and multiplied by 10 (up to NewtonParams::proximalMax) with the step
// recomputed from the same x when no step length satisfies Armijo's rule; a step that finds none
// even there counts as a stall, and NewtonParams::maxStalls of them in a row end the solve
// (Failed). Before every step but the first NewtonParams::stepSweeps projected Gauss-Seidel sweeps
// (pgs.hpp; coordinate descent on the same f) move the rows the Newton step would leave held.
//
// Symmetric system. A friction row on its bound whose normal is free would, substituted as
// x_t = mu x_n, make the system nonsymmetric (K = A_CC + U E^T). Lagging its bound keeps the
// system symmetric positive definite, so one Cholesky factorization serves it; the price is that
// the coupling converges only through the per-step refresh, linearly in the friction coefficient.
//
// Linear algebra. Up to NewtonParams::denseMaxRows free rows (and for every problem of at most
// that many rows), A_CC + rho I is gathered and factored densely (Eigen's LLT). Larger systems
// factor the whole n x n matrix
//
//     K = P_C (A + rho I) P_C + (I - P_C),     P_C the diagonal 0/1 projector on C,
//
// whose pattern is A's whatever C is (held rows and columns hold explicit zeros and a unit
// diagonal, their right-hand side 0), so CHOLMOD's symbolic analysis (fill-reducing order,
// elimination tree, supernodal or simplicial as CHOLMOD decides; linalg/cholmod_factor.hpp) is
// done once per pattern of A and reused by every step and by later solves of this object on the
// same pattern (RowSolver keeps one solver object per island key, so an island's analysis lives
// in its slot as long as its contact pattern holds). A step costs one numeric factorization,
// one solve, the sweeps (O(nnz A) each) and one product with A per trial step length.
//
// Starts. A warm start (Options::warmStart, solveWithGuess) is used as it is (projected onto its
// bounds). A cold start (x = 0) first takes NewtonParams::coldSweeps projected Gauss-Seidel
// sweeps; pivoting from zero never runs here.
//
// Limits. Options::maxIterations bounds the steps (MaxIterations), Options::timeBudget the wall
// time (checked before each step; TimeLimit). Both return the best iterate by ||H||_2, the start
// included, so never worse than the start; the base class reports its true residual.
// Result::iterations counts the steps.
//
// Applies to symmetric A (checked each solve: O(nnz log) for sparse A, no transposed copy); a
// nonsymmetric A is Unsupported. No state carries from one solve to the next except the symbolic
// analysis, a function of A's pattern only: the same problem and start give the same answer.
#pragma once

#include <memory>

#include "mlcp/solver.hpp"

namespace mlcp {

namespace linalg {
class CholmodFactor;
}

struct NewtonParams {
  // Projected Gauss-Seidel sweeps over a cold start (x = 0) before the first step. Default 10.
  int coldSweeps = 10;
  // Clamped blocks of at most this many rows are factored densely (Eigen); larger ones, or any
  // block of a problem with more than denseMaxRows rows, by CHOLMOD. Default 150.
  int denseMaxRows = 150;
  // mu_k's start and its largest value (the proximal weight rho = mu_k max A_ii min(1, r_k)).
  // Defaults 1e-3 and 1e3.
  double proximal = 1e-3;
  double proximalMax = 1e3;
  // Halvings of the step length in the line search. Default 8.
  int maxHalvings = 8;
  // Projected Gauss-Seidel sweeps before each step after the first. Default 10.
  int stepSweeps = 10;
  // Steps in a row without descent at the largest proximal weight before the solve stops.
  // Default 3.
  int maxStalls = 3;
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

  // Of the last solve: numeric factorizations (CHOLMOD or dense).
  int factorizations() const { return factorizations_; }
  // Symbolic analyses this object has done (one per pattern of A seen in a row).
  int analyses() const;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Work;
  bool search(const Problem& problem, const Vector& x, double res, double dMax, double& mu);
  std::unique_ptr<Work> work_;
  std::unique_ptr<linalg::CholmodFactor> cholmod_;
  NewtonParams params_;
  int factorizations_ = 0;
};

}  // namespace mlcp
