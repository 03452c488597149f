#include "mlcp/ldlt.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <sstream>

namespace mlcp {

using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor>;

struct LdltSolver::Impl {
  Eigen::SimplicialLDLT<ColMajor> ldlt;
  Eigen::SparseLU<ColMajor> lu;
  // The pattern the symbolic analysis was done for.
  std::vector<ColMajor::StorageIndex> outer, inner;
  bool symmetricAnalyzed = false;
  int analyses = 0;

  bool samePattern(const ColMajor& A, bool symmetric) const {
    if (symmetric != symmetricAnalyzed ||
        A.outerSize() + 1 != static_cast<Eigen::Index>(outer.size()))
      return false;
    return std::equal(outer.begin(), outer.end(), A.outerIndexPtr()) &&
           static_cast<Eigen::Index>(inner.size()) == A.nonZeros() &&
           std::equal(inner.begin(), inner.end(), A.innerIndexPtr());
  }
  void remember(const ColMajor& A, bool symmetric) {
    outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    symmetricAnalyzed = symmetric;
    ++analyses;
  }
};

LdltSolver::LdltSolver() : impl_(std::make_unique<Impl>()) {}
LdltSolver::~LdltSolver() = default;
int LdltSolver::analyses() const { return impl_->analyses; }

namespace {
bool isSymmetric(const ColMajor& A) {
  if (A.nonZeros() == 0) return true;
  const double scale = std::max(1.0, A.coeffs().cwiseAbs().maxCoeff());
  const ColMajor difference = A - ColMajor(A.transpose());
  return difference.nonZeros() == 0 || difference.coeffs().cwiseAbs().maxCoeff() <= 1e-14 * scale;
}
}  // namespace

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
  const bool symmetric = isSymmetric(A);
  Impl& m = *impl_;
  const Vector rhs = -problem.b;
  // Analyze when the pattern is new, factorize, solve, refine once.
  auto factorSolve = [&](auto& factorization) {
    if (!m.samePattern(A, symmetric)) {
      factorization.analyzePattern(A);
      m.remember(A, symmetric);
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
