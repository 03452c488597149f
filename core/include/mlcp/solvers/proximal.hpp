// mlcp/solvers/proximal.hpp: the proximal point method on the impulses (registry "proximal"), for
// boxed MLCPs with findex whose A is singular: Bullet's resting piles without CFM, where the
// exact answer exists but is not unique and Newton's and pivoting's systems are singular. The
// long form is docs/methods/proximal.md.
//
// Method (Rockafellar 1976; Siconos' fc3d_proximal; Acary, Bremond and Huber 2018). Each outer
// step k solves the regular problem
//     MLCP(A + alpha_k I, b - alpha_k x_k),   the same bounds and findex,
// from x_k by the inner solver (newton by default), and x_{k+1} is its answer. At a fixed point
// x_{k+1} = x_k the proximal term vanishes, so the answer is the original problem's. With
// w = A x + b and w_k = w + alpha_k (x - x_k) the inner slack, the natural map is 1-Lipschitz in w,
// so at every outer step
//     ||H(x_{k+1})||_inf <= ||H_k(x_{k+1})||_inf + alpha_k ||x_{k+1} - x_k||_inf:
// an inner answer at tolerance eta_k leaves the original residual within alpha_k times the step.
// The friction bounds stay exact inside each inner solve (never lagged): the fixed point is the
// findex problem's answer, not a sequence of boxed ones.
//
// Why the impulses. The non-uniqueness of a pile's answer lives in the impulses (ker J^T: four
// coplanar contacts of a box face carry any split of its weight); alpha I makes A + alpha I
// positive definite on that kernel, so every inner problem has one answer and Newton's systems
// are regular. Regularising the body velocities instead changes nothing: M is regular already.
//
// Schedule. alpha_k = sigma r_k^nu mean(A_ii), clamped to [alphaMin, alphaMax] mean(A_ii), r_k the
// scaled original residual at x_k (Siconos' rule): alpha falls as the answer nears, so the outer
// steps converge superlinearly while each inner problem stays regular enough for Newton. An inner
// solve that ends short multiplies alpha by alphaGrowth (x10) for the next step and keeps x_k
// unless its answer has the lower original residual. The inner tolerance follows the outer
// residual, max(tolerance / 10, innerFactor r_k): inexact early, exact at the end.
//
// With an engine's rows (Solver::useRows) A + alpha I is J M^-1 J^T + diag(cfm + alpha): the inner
// newton gets the shifted rows and keeps its body-space factorization (6 unknowns a body).
//
// Cost. Outer steps times one inner solve each (warm-started from x_k, so late ones take a few
// Newton steps), plus O(nnz A) per step for the shifted problem and the original residual. A
// warm start at the answer (a pile at rest, last step's impulses) ends in 0-2 outer steps.
//
// Limits and invariants. Options::maxIterations bounds the outer steps (ProximalParams::maxOuter
// when smaller), Options::timeBudget the whole solve, inner solves included. Every end that is not
// Converged returns the best iterate by the original residual, never worse than the start.
// Result::iterations counts outer steps; innerIterations() the inner solvers' iterations.
#pragma once

#include <memory>
#include <string>

#include "mlcp/solver.hpp"

namespace mlcp {

struct ProximalParams {
  // The inner solver's registry name: any solver of boxed problems with findex ("newton",
  // "dantzig", "lemke", "pgs"; not "auto", a chain or "proximal"). Default "newton".
  std::string inner = "newton";
  // Run on the same shifted problem from x_k when the inner solver's answer ends short of the
  // inner tolerance ("" for none; the same rules as inner). Default "dantzig": its pivoting on
  // A + alpha I is exact where Newton's line search stalls on the kinks of many sliding rows.
  std::string innerFallback = "dantzig";
  // alpha's schedule above: sigma, nu, and its limits relative to mean(A_ii). Defaults 1, 1,
  // 1e-12 and 1e-2.
  double sigma = 1;
  double nu = 1;
  double alphaMin = 1e-12;
  double alphaMax = 1e-2;
  // Factor on alpha after an inner solve that ended short. Default 10.
  double alphaGrowth = 10;
  // The inner tolerance is max(tolerance / 10, innerFactor r_k). Default 0.1.
  double innerFactor = 0.1;
  // Outer steps at most (Options::maxIterations when smaller). Default 200.
  int maxOuter = 200;
};

class ProximalSolver : public Solver {
 public:
  ProximalSolver();
  ~ProximalSolver() override;
  ProximalSolver(ProximalSolver&&) noexcept;
  ProximalSolver& operator=(ProximalSolver&&) noexcept;

  const char* name() const override { return "proximal"; }

  ProximalParams& params() { return params_; }
  const ProximalParams& params() const { return params_; }
  // The inner solver (made from params().inner at the next solve when the name changed), for its
  // own parameters, e.g. dynamic_cast<NewtonSolver*>(proximal.inner())->params().
  Solver* inner();
  Solver* innerFallback();

  // Of the last solve: the inner solvers' iterations summed, and the last alpha used.
  int innerIterations() const { return innerIterations_; }
  double lastAlpha() const { return lastAlpha_; }

  void useRows(const RowSystem* rows) override { rows_ = rows; }

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Work;
  // The shifted problem's A (and rows) for this solve; alpha set by shift().
  void prepare(const Problem& problem);
  void shift(const Problem& problem, const Vector& xk, double alpha);
  double nextAlpha(double rel, double r, bool failedLast, double floor) const;
  Result innerSolve(Solver& inner, const Options& io);
  bool outerStep(const Problem& problem, double alpha, double r, int& fallbacks);
  std::unique_ptr<Work> work_;
  ProximalParams params_;
  const RowSystem* rows_ = nullptr;
  int innerIterations_ = 0;
  double lastAlpha_ = 0;
};

}  // namespace mlcp
