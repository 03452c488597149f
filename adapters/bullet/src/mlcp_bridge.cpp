#include "mlcp/bullet/mlcp_bridge.hpp"

#include <stdexcept>
#include <vector>

#include "mlcp/bullet/constraint_solver.hpp"
#include "mlcp/registry.hpp"

namespace mlcp::bullet {

MlcpBridge::MlcpBridge(const std::string& solver, const Options& options) : options_(options) {
  std::string error;
  solver_ = makeSolver(solver, &error);
  if (!solver_) throw std::invalid_argument("mlcp::bullet::MlcpBridge: " + error);
}

bool MlcpBridge::solveMLCP(const btMatrixXu& A, const btVectorXu& b, btVectorXu& x,
                           const btVectorXu& lo, const btVectorXu& hi,
                           const btAlignedObjectArray<int>& limitDependency, int numIterations,
                           bool /*useSparsity*/) {
  const int n = b.size();
  ++calls_;
  // Bullet's A x = b + w: our b is minus Bullet's.
  problem_.b.resize(n);
  problem_.lo.resize(n);
  problem_.hi.resize(n);
  problem_.findex.assign(n, -1);
  start_.resize(n);
  for (int i = 0; i < n; ++i) {
    problem_.b[i] = -static_cast<double>(b[i]);
    problem_.lo[i] = lo[i];
    problem_.hi[i] = hi[i];
    start_[i] = x[i];
    if (i < limitDependency.size()) problem_.findex[i] = limitDependency[i];
  }
  if (n > denseAssemblyMaxRows) {
    std::vector<Eigen::Triplet<double>> t;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c)
        if (A(r, c) != 0) t.emplace_back(r, c, A(r, c));
    SparseMatrix S(n, n);
    S.setFromTriplets(t.begin(), t.end());
    problem_.setA(std::move(S));
  } else {
    DenseMatrix D(n, n);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) D(r, c) = A(r, c);
    problem_.setA(std::move(D));
  }

  Options o = options_;
  o.warmStart = true;
  const std::string name = solver_->name();
  if (engineIterations && (name == "pgs" || name == "gs")) useEngineIterations(o, numIterations);
  solver_->setOptions(o);
  last_ = solver_->solveWithGuess(problem_, start_, answer_);
  if (!acceptable(last_, acceptResidual)) {
    ++rejected_;
    return false;
  }
  for (int i = 0; i < n; ++i) x[i] = static_cast<btScalar>(answer_[i]);
  return true;
}

}  // namespace mlcp::bullet
