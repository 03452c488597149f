// mlcp/solvers/pgs.hpp: projected Gauss-Seidel / SOR (registry "pgs") and plain Gauss-Seidel
// ("gs").
//
// One sweep visits the rows in order and, with w_i = (A x + b)_i evaluated at the current x,
//
//     x_i <- clamp(x_i - omega * w_i / A_ii, lo'_i, hi'_i),
//
// where lo', hi' are the effective bounds: a friction row's bounds are recomputed from the
// current normal value x_findex[i] at every visit (not fixed once per solve). omega is
// Options::relaxation. Each sweep costs O(nnz A). The iteration converges for symmetric
// positive definite A (and for symmetric positive semidefinite A with a solvable problem); it
// needs A_ii > 0 and refuses a zero or negative diagonal with Status::Failed. Stopping: the
// scaled natural-map residual (residual.hpp) <= tolerance, checked every Options::checkEvery
// sweeps, or maxIterations, or the time budget.
//
// "gs" is the same sweep for problems without bounds (every row lo = -inf, hi = +inf): a
// linear system A x + b = 0. It refuses bounded problems as Unsupported and reports a sweep
// that diverges (residual grown 1e8-fold) as Failed.
#pragma once

#include "mlcp/solver.hpp"

namespace mlcp {

class PgsSolver : public Solver {
 public:
  const char* name() const override { return "pgs"; }

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;
  // Hook for gs: a message when the problem is not for this method ("" when it is).
  virtual std::string refuse(const Problem& problem) const;
};

class GaussSeidelSolver : public PgsSolver {
 public:
  const char* name() const override { return "gs"; }

 protected:
  std::string refuse(const Problem& problem) const override;
};

}  // namespace mlcp
