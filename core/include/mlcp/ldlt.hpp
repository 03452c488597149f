// mlcp/ldlt.hpp: a direct solve for problems without bounds (registry "ldlt").
//
// When every row is an equality (bilateral joints only: Problem::classify() == Linear) the
// MLCP is the linear system A x = -b, and one factorization solves it exactly: no iteration,
// no pivoting on an active set. In sparse storage a symmetric A (J M^-1 J^T + diag(cfm)
// always is) is factored as L D L^T (Eigen's SimplicialLDLT, fill-reducing AMD ordering); a
// non-symmetric one with a sparse LU. The symbolic analysis (ordering, elimination tree) depends
// only on the sparsity pattern and is kept between calls: a simulation whose joint graph does not
// change pays for it once and refactorizes numerically each step, as SuiteSparse's
// analyze/factorize split does. One step of iterative refinement follows the solve. Bounded rows
// are refused (Unsupported); a singular A is reported as Failed.
//
// The storage chooses the path. A dense A (RowSolver assembles islands up to denseMaxRows = 64
// rows dense) is factored without pivoting inside its envelope: row i of L starts at A's first
// nonzero column of row i, so a chain's band costs O(n bw^2) and a full matrix n^3/6, with no
// ordering, analysis or storage conversion. Only A's lower triangle is read; the refined answer
// is kept when it solves the whole A to a scaled residual of 1e-11, which checks symmetry in
// passing. Otherwise (a pivot below 1e-13 relative, or that residual missed) the exact symmetry
// check sends A to Eigen's pivoting dense LDL^T (which answers a consistent singular system) or,
// non-symmetric, to dense partial-pivoting LU. The base's residual check has the final say.
// Measured:
//   ODE pendulum_chain (33 rows), instructions per solve (callgrind): sparse path 72.6k
//   (isSymmetric's A - A^T alone 27k), Eigen's dense LDLT 82k (its unblocked factorization
//   calls a gemv per column), the envelope path ~25k (factor 6.6k, two solves 7.2k, two
//   products A x 4.8k, envelope scan 2.9k).
//   The sparse path likewise tries LDL^T first and runs the exact symmetry check (A - A^T)
//   only when the answer misses 1e-11 (a pattern found non-symmetric goes to the check and LU
//   directly next time).
//   Block-tridiagonal SPD chains (blocks of 3 and 5 rows), whole solve() with the base's checks,
//   dense vs sparse (us, shared machine, ranges of 3 runs): 3-row blocks 33 rows 5.4-6.6 vs
//   10-12, 63 rows 8-16 vs 9-17, 96 rows 16-34 vs 13-20, 198 rows 75 vs 43; 5-row blocks 60 rows
//   9-12 vs 13-20, 125 rows 28-37 vs 28-39. Dense wins to 60-100 rows on a thin band, further on
//   a wider one and always on a full matrix: RowSolver's 64-row limit sits at the crossover.
//
// Options::timeBudget does not stop it: the answer is one factorization and two triangular
// solves, with no iterate before they end (their cost is fixed by the pattern, not by the data).
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
