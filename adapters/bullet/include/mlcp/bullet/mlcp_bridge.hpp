// mlcp/bullet/mlcp_bridge.hpp: a btMLCPSolverInterface that calls any core solver, so the stock
// btMLCPSolver can use it:
//
//     mlcp::bullet::MlcpBridge bridge("dantzig");
//     btMLCPSolver solver(&bridge);
//     world->setConstraintSolver(&solver);
//
// The stock solver hands over a dense A (it builds one for every island), Bullet's b (minus
// ours: converted here), lo/hi (contacts [0, 1e10]), limitDependency (= findex) and x holding
// the applied impulses (used as the warm start). The answer is checked by the drop-in's rule
// (mlcp::acceptable, mlcp/island/policy.hpp); returning false makes btMLCPSolver count a
// fallback and run its SI iterations. For large problems prefer the drop-in
// mlcp::bullet::ConstraintSolver: it never builds the dense matrix and splits islands.
#pragma once

#include <BulletDynamics/MLCPSolvers/btMLCPSolverInterface.h>

#include <memory>
#include <string>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::bullet {

class MlcpBridge : public btMLCPSolverInterface {
 public:
  // Throws std::invalid_argument (listing the valid names) for an unknown solver name.
  // Default options: islandOptions() (tolerance 1e-6, mlcp/island/row_solver.hpp), as the
  // drop-in's.
  explicit MlcpBridge(const std::string& solver, const Options& options = islandOptions());

  Solver& solver() { return *solver_; }
  // Largest accepted scaled residual (dimensionless). Default mlcp::kDefaultAcceptResidual.
  double acceptResidual = kDefaultAcceptResidual;
  // Problems with more rows than this are converted to sparse storage (dropping A's zeros).
  // Default mlcp::kDenseAssemblyRows (64, mlcp/thresholds.hpp).
  int denseAssemblyMaxRows = kDenseAssemblyRows;
  // pgs/gs take their sweep count from the numIterations argument (as the stock PGS does),
  // checked once at the end, instead of the options' limit (RowSolverSettings::engineIterations
  // says why). Default true.
  bool engineIterations = true;

  // The last call's result, and counts over all calls.
  const Result& lastResult() const { return last_; }
  int calls() const { return calls_; }
  int rejected() const { return rejected_; }

  bool solveMLCP(const btMatrixXu& A, const btVectorXu& b, btVectorXu& x, const btVectorXu& lo,
                 const btVectorXu& hi, const btAlignedObjectArray<int>& limitDependency,
                 int numIterations, bool useSparsity = true) override;

 private:
  std::unique_ptr<Solver> solver_;
  Options options_;
  Problem problem_;
  Vector start_, answer_;
  Result last_;
  int calls_ = 0, rejected_ = 0;
};

}  // namespace mlcp::bullet
