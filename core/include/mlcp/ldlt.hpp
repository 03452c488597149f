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
//
// The storage chooses the path. A dense A (RowSolver assembles islands up to denseMaxRows = 64
// rows dense) is factored without pivoting inside its envelope: row i of L starts at A's first
// nonzero column of row i, so a chain's band costs O(n bw^2) and a full matrix n^3/6, with no
// ordering, analysis or storage conversion. The symmetry check rides on the same pass. A pivot
// below 1e-13 relative hands the matrix to Eigen's pivoting dense LDL^T (which answers a
// consistent singular system), a non-symmetric one to dense partial-pivoting LU.
// Measured (callgrind, ODE pendulum_chain, 33 rows, per solve): the sparse path cost 72.6k
// instructions (isSymmetric's A - A^T alone 27k), Eigen's dense LDLT 82k (its unblocked
// column-by-column gemv calls), the envelope path 32k of which the symmetry pass is 15k.
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
  void runDense(const Problem& problem, Vector& x, Result& result);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlcp
