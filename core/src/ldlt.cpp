#include "mlcp/ldlt.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <sstream>

#include "sparse_pattern.hpp"

namespace mlcp {

using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor>;

struct LdltSolver::Impl {
  Eigen::SimplicialLDLT<ColMajor> ldlt;
  Eigen::SparseLU<ColMajor> lu;
  detail::PatternCache pattern;  // tagged 1 for LDL^T, 0 for LU
};

LdltSolver::LdltSolver() : impl_(std::make_unique<Impl>()) {}
LdltSolver::~LdltSolver() = default;
int LdltSolver::analyses() const { return impl_->pattern.analyses(); }

void LdltSolver::run(const Problem& problem, Vector& x, Result& result) {
  const int n = problem.size();
  if (problem.classify() != ProblemClass::Linear && n > 0) {
    result.status = Status::Unsupported;
    result.message =
        "ldlt solves problems without bounds (every row -inf..inf); use dantzig or pgs";
    return;
  }
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  ColMajor A = problem.toSparse();
  A.makeCompressed();
  const bool symmetric = detail::isSymmetric(A);
  Impl& m = *impl_;
  const Vector rhs = -problem.b;
  // Analyze when the pattern is new, factorize, solve, refine once.
  auto factorSolve = [&](auto& factorization) {
    if (!m.pattern.same(A, symmetric)) {
      factorization.analyzePattern(A);
      m.pattern.remember(A, symmetric);
    }
    factorization.factorize(A);
    if (factorization.info() != Eigen::Success) return false;
    x = factorization.solve(rhs);
    x += factorization.solve(Vector(rhs - A * x));
    return true;
  };
  const bool ok = symmetric ? factorSolve(m.ldlt) : factorSolve(m.lu);
  result.iterations = 1;
  if (!ok) {
    result.status = Status::Failed;
    result.message = symmetric ? "LDL^T factorization failed: A is singular"
                               : "LU factorization failed: A is singular";
    return;
  }
  // Singular-but-factored (a zero pivot in D) shows up as NaN/Inf, which the base reports.
  result.status = Status::Converged;
  result.message = symmetric ? "sparse LDL^T solve" : "sparse LU solve";
}

}  // namespace mlcp
