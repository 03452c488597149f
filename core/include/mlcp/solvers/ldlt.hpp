// mlcp/solvers/ldlt.hpp: a direct solve for problems without bounds (registry "ldlt").
//
// When every row is an equality (bilateral joints only: Problem::classify() == Linear) the
// MLCP is the linear system A x = -b, and one factorization solves it exactly: no iteration,
// no pivoting on an active set. In sparse storage a symmetric A (J M^-1 J^T + diag(cfm)
// always is) is factored as L D L^T (Eigen's SimplicialLDLT, fill-reducing AMD ordering); a
// non-symmetric one with a sparse LU. The symbolic analysis (ordering, elimination tree) depends
// only on the sparsity pattern and is kept between calls: a simulation whose joint graph does not
// change pays for it once and refactorizes numerically each step, as SuiteSparse's
// analyze/factorize split does. One step of iterative refinement follows the solve. Bounded rows
// are refused (Unsupported). A singular symmetric A (redundant joints) whose LDL^T fails or
// leaves a residual gets the minimum-norm least-squares answer (linalg/min_norm.hpp: the LL^T of
// A + delta I, delta = 1e-6 max |A_ii|, iterated so that nothing enters A's null space): a
// consistent system is then solved (Converged), an inconsistent one (a closed loop of joints
// that has drifted, whose rows disagree) gets Status::LeastSquares, which the base verifies.
// Why not A + delta I refined against A: each refinement adds the inconsistent part / delta
// along the rows' dependency, impulses of 1e9 times the drift. A singular non-symmetric A is
// reported as Failed.
//
// The storage chooses the path. A dense A (RowSolver assembles islands up to denseAssemblyMaxRows =
// 64 rows dense) is factored without pivoting inside its envelope: row i of L starts at A's first
// nonzero column of row i, so a chain's band costs O(n bw^2) and a full matrix n^3/6, with no
// ordering, analysis or storage conversion. Only A's lower triangle is read; the refined answer
// is kept when it solves the whole A to a scaled residual of 1e-11, which checks symmetry in
// passing. Otherwise (a pivot below 1e-13 relative, or that residual missed) the exact symmetry
// check sends A to Eigen's pivoting dense LDL^T (a residual it leaves takes the least-squares
// path above) or, non-symmetric, to dense partial-pivoting LU. The base's check has the final say.
// The sparse path likewise tries LDL^T first and runs the exact symmetry check (A - A^T) only
// when the answer misses 1e-11 (a pattern found non-symmetric goes to the check and LU directly
// next time): forming A - A^T costs more than the factorization of a small island.
// Why an envelope factorization for small A: it needs no ordering, analysis or storage
// conversion and reads only the band, where Eigen's dense LDLT calls a gemv per column and the
// sparse path pays for the symmetry check and the conversion; it costs about a third of either
// on a 33-row joint chain. Dense wins up to 60-100 rows on a thin band, further on a wider one
// and always on a full matrix, so RowSolver's 64-row limit sits at the crossover
// (docs/benchmarks.md, docs/decisions.md).
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
