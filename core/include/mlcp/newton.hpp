// mlcp/newton.hpp: a semismooth Newton method on the natural map for boxed MLCPs with findex
// (registry "newton"), the solver for large islands: each step is one sparse Cholesky solve of
// the clamped rows, factored by CHOLMOD on a symbolic analysis kept while A's pattern holds.
//
// Map. With the effective bounds l(x), u(x) (findex applied: l_i = lo_i |x_j|, u_i = hi_i |x_j|
// for a friction row i of normal j), x solves the problem exactly when the natural map
//
//     H(x) = x - clamp(x - w, l(x), u(x)),   w = A x + b,
//
// is zero; residual.hpp's accuracy is ||H||_inf / (1 + ||b||_inf).
//
// Step. At the iterate x the rows split as the natural map says: N holds the rows whose
// x_i - w_i lies at or beyond a bound (target t_i that bound; rows with l_i = u_i always), C the
// others (w_i = 0 wanted). The friction bounds are those of the current normals: inside one step
// they are constants, and every step refreshes them (the outer refresh of a fixed point over the
// bounds, done once per step). The Newton direction of H with those bounds is
//
//     dx_N = t_N - x_N,     (A_CC + rho I) dx_C = -w_C - A_CN dx_N,
//
// a symmetric positive definite system whenever A is symmetric positive semidefinite and rho > 0
// (substituting a sliding friction row's x_t = mu x_n into the system instead would make it
// nonsymmetric; lagging the bound keeps it symmetric at the price of a linear rate in the coupling
// while the sliding set changes, and quadratic convergence once the sets and the normals settle,
// because the bound's error shrinks with the normal's step). rho is a proximal weight,
//
//     rho = mu_k max_i A_ii min(1, r_k),   r_k the scaled residual at x,
//
// that keeps coplanar contacts' near-singular clamped blocks from throwing the null-space part
// far away and vanishes as the residual does (Levenberg-Marquardt's choice: superlinear rate near
// a solution). mu_k starts at NewtonParams::proximal, is divided by 10 after a full step and
// multiplied by 10 after a step that finds no descent (at most NewtonParams::proximalMax).
//
// Linear algebra. Up to NewtonParams::denseMaxRows clamped rows, A_CC + rho I is gathered and
// factored densely (Eigen's LLT). Larger systems factor the whole n x n matrix
//
//     K = P_C (A + rho I) P_C + (I - P_C),     P_C the diagonal 0/1 projector on C,
//
// whose pattern is A's whatever C is (N's rows and columns hold explicit zeros and a unit
// diagonal; the right-hand side holds dx_N there), so CHOLMOD's symbolic analysis (fill-reducing
// order, elimination tree, supernodes; linalg/cholmod_factor.hpp) is done once per pattern of A
// and reused by every step and every later solve of this object on the same pattern (an engine's
// island keeps its pattern while its contacts persist: RowSolver keeps one solver per island).
// Each step costs one numeric factorization (~ the flops of a Cholesky of A) and one solve; the
// products with A (w, A dx) cost O(nnz A) each, one per step.
//
// Globalization. Merit theta(x) = ||H(x)||_2^2 with the true (moving) bounds. Along dx the step
// length halves from 1 (at most NewtonParams::maxHalvings times, each O(n): w moves as t A dx)
// until theta decreases by Armijo's rule (1e-4 t theta); when none does, the shortest step that
// decreases theta at all is taken; when nothing decreases, rho grows and the step is recomputed
// from the same x. After NewtonParams::maxStalls such steps in a row at the largest rho the
// solve stops (Failed, "no descent"). The best iterate (lowest theta, the start included) is
// returned: never worse than the start.
//
// Starts. A warm start (Options::warmStart, solveWithGuess) is used as it is: an engine's last
// answer settles in 1-3 steps when the contact sets barely change. A cold start (x = 0) first
// takes NewtonParams::coldSweeps projected Gauss-Seidel sweeps (pgs.hpp), which place most rows
// in their final sets; pivoting from zero over thousands of rows never runs here.
//
// Limits. Options::maxIterations bounds the Newton steps (MaxIterations), Options::timeBudget
// the wall time (checked before each factorization; TimeLimit). Both return the best iterate
// with its true residual (the base class recomputes it). Result::iterations counts the steps.
//
// Applies to symmetric A (checked each solve, O(nnz)); a nonsymmetric A is solved by the dense
// path with a partially pivoted LU when n <= denseMaxRows, and is Unsupported above that. A
// clamped block that is not positive definite even with the largest rho ends the solve (Failed).
// No state carries from one solve to the next but the symbolic analysis, a function of A's
// pattern only: the same problem and start give the same answer bit for bit.
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
  std::unique_ptr<Work> work_;
  std::unique_ptr<linalg::CholmodFactor> cholmod_;
  NewtonParams params_;
  int factorizations_ = 0;
};

}  // namespace mlcp
