// mlcp/solvers/ldlt.hpp: a direct solve for problems without bounds (registry "ldlt").
//
// When every row is an equality (bilateral joints only: Problem::classify() == Linear) the MLCP
// is the linear system
//
//     A x = -b,
//
// solved by one factorization and one step of iterative refinement: no iteration, no active
// set. Bounded rows are refused (Unsupported).
//
// The storage chooses the path. A dense A (RowSolver assembles islands up to
// RowSolverSettings::denseAssemblyMaxRows = kDenseAssemblyRows rows dense) is factored as
// L D L^T without pivoting inside its envelope: row i of L starts at A's first nonzero column of
// row i, so a chain's band costs O(n bw^2) and a full matrix n^3/6, with no ordering, analysis or
// storage conversion. A sparse A is factored by Eigen's SimplicialLDLT (AMD ordering), a
// non-symmetric one by a sparse LU; the symbolic analysis depends on the pattern only and is
// kept while it holds (SuiteSparse's analyze/factorize split), so a simulation whose joint graph
// does not change pays for it once.
//
// Symmetry is checked in passing: the LDL^T reads A's lower triangle only, and its refined
// answer is kept when it solves the whole A to a scaled residual of 1e-11. Otherwise (a pivot
// below 1e-13 relative, or that residual missed) the exact check (A - A^T) decides: a symmetric
// dense A goes to Eigen's pivoting LDLT, a non-symmetric one to LU (dense partial pivoting, or
// sparse); a sparse pattern found non-symmetric goes to the check and LU directly next time.
// The exact check costs more than the factorization of a small island, hence this order.
//
// Singular A: a symmetric A (redundant joints) whose LDL^T fails or leaves a residual gets the
// minimum-norm least-squares answer (linalg/min_norm.hpp: the LL^T of A + delta I,
// delta = kMinNormShift max(1, max |A_ii|), iterated so that nothing enters A's null space):
// Converged for a consistent system, Status::LeastSquares for an inconsistent one (a drifted loop
// of joints), which the base verifies. A singular non-symmetric A is Failed.
//
// Options::timeBudget does not stop it: one factorization and two triangular solves, whose cost
// the pattern fixes. Measurements: docs/benchmarks.md, "ldlt: the dense envelope against the
// other factorizations"; alternatives: docs/decisions.md, "ldlt" and "Degenerate rows and
// singular islands".
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
