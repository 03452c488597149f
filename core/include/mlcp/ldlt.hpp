// mlcp/ldlt.hpp: a direct sparse solve for problems without bounds (registry "ldlt").
//
// When every row is an equality (bilateral joints only: Problem::classify() == Linear) the
// MLCP is the linear system A x = -b, and one factorization solves it exactly: no iteration,
// no pivoting on an active set. A symmetric A (J M^-1 J^T + diag(cfm) always is) is factored
// as L D L^T (Eigen's SimplicialLDLT, fill-reducing AMD ordering); a non-symmetric one with a
// sparse LU. The symbolic analysis (ordering, elimination tree) depends only on the sparsity
// pattern and is kept between calls: a simulation whose joint graph does not change pays for it
// once and refactorizes numerically each step, as SuiteSparse's analyze/factorize split does.
// One step of iterative refinement follows the solve. Bounded rows are refused (Unsupported);
// a singular A is reported as Failed.
#pragma once

#include <memory>

#include "mlcp/solver.hpp"

namespace mlcp {

class LdltSolver : public Solver {
 public:
  LdltSolver();
  ~LdltSolver() override;
  const char* name() const override { return "ldlt"; }
  // How many symbolic analyses were done (for tests of the pattern reuse).
  int analyses() const;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlcp
