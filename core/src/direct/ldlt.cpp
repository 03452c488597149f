#include "mlcp/solvers/ldlt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

#include "linalg/min_norm.hpp"
#include "linalg/sparse_pattern.hpp"
#include "linalg/symmetry.hpp"

namespace mlcp {

namespace {
// Largest scaled residual at which the envelope LDL^T's answer is kept (see runDense).
constexpr double kEnvelopeResidual = 1e-11;
}  // namespace

using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor>;

namespace {
// The singular path's answer (linalg/min_norm.hpp) and its status: Converged when it solves A
// x = -b to kEnvelopeResidual (a consistent system, e.g. a redundant joint that has not
// drifted), LeastSquares otherwise (the base verifies its stationarity, solver.hpp).
void reportSingular(const Vector& residual, const Vector& rhs, int steps, const char* storage,
                    Result& result) {
  const bool consistent =
      residual.lpNorm<Eigen::Infinity>() <= kEnvelopeResidual * (1 + rhs.lpNorm<Eigen::Infinity>());
  result.status = consistent ? Status::Converged : Status::LeastSquares;
  result.iterations = steps;
  result.message = std::string("A is singular (redundant rows): minimum-norm ") +
                   (consistent ? "answer" : "least-squares answer, the rows are inconsistent") +
                   " from the " + storage + " LL^T of A + delta I, " + std::to_string(steps) +
                   " steps";
}
}  // namespace

struct LdltSolver::Impl {
  Eigen::SimplicialLDLT<ColMajor> ldlt;
  Eigen::SparseLU<ColMajor> lu;
  detail::PatternCache pattern;  // tagged 1 for LDL^T, 0 for LU
  bool lastSymmetric = true;     // the last exact symmetry check's verdict
  // The dense path: L (unit lower, row-major so each row's envelope is contiguous) and D of
  // A = L D L^T, each row's first nonzero column, Eigen's pivoting LDL^T and LU for what the
  // envelope factorization cannot take; kept, so no allocation per solve once the size is seen.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> L;
  Vector d, w, rhs, correction;
  std::vector<Eigen::Index> first;
  Eigen::LDLT<DenseMatrix> denseLdlt;
  Eigen::PartialPivLU<DenseMatrix> denseLu;
  // The singular path's factorizations of A + delta I (linalg/min_norm.hpp).
  Eigen::LLT<DenseMatrix> shifted;
  Eigen::SimplicialLDLT<ColMajor> shiftedSparse;

  // Each row's first nonzero column (first).
  void envelope(const DenseMatrix& A);
  // L D L^T without pivoting inside the envelope; false on a pivot <= 1e-13 relative.
  bool factorEnvelope(const DenseMatrix& A);
  // x = (L D L^T)^-1 r.
  void solveEnvelope(const Vector& r, Vector& x) const;
};

void LdltSolver::Impl::envelope(const DenseMatrix& A) {
  const Eigen::Index n = A.rows();
  // Row i's first nonzero column, read as column i's first nonzero row (a contiguous scan that
  // stops at the envelope): right for a symmetric pattern, and an unsymmetric A shows up in the
  // residual that decides whether the answer is kept.
  first.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Index k = 0;
    while (k < i && A(k, i) == 0) ++k;
    first[i] = k;
  }
}

bool LdltSolver::Impl::factorEnvelope(const DenseMatrix& A) {
  const Eigen::Index n = A.rows();
  L.resize(n, n);
  d.resize(n);
  w.resize(n);
  const double pivotFloor = 1e-13 * std::max(1.0, A.diagonal().cwiseAbs().maxCoeff());
  // Row by row (the envelope of L is A's): w_k = L_ik d_k, L_ij = (A_ij - w . L_j) / d_j.
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index fi = first[i];
    for (Eigen::Index j = fi; j < i; ++j) {
      const Eigen::Index k0 = std::max(fi, first[j]);
      const double s =
          A(i, j) - w.segment(k0, j - k0).dot(L.row(j).segment(k0, j - k0).transpose());
      w[j] = s;
      L(i, j) = s / d[j];
    }
    const double di = A(i, i) - w.segment(fi, i - fi).dot(L.row(i).segment(fi, i - fi).transpose());
    if (!(std::abs(di) > pivotFloor)) return false;
    d[i] = di;
  }
  return true;
}

void LdltSolver::Impl::solveEnvelope(const Vector& r, Vector& x) const {
  const Eigen::Index n = r.size();
  x = r;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index fi = first[i];
    x[i] -= L.row(i).segment(fi, i - fi).dot(x.segment(fi, i - fi).transpose());
  }
  x.array() /= d.array();
  for (Eigen::Index i = n - 1; i > 0; --i) {
    const Eigen::Index fi = first[i];
    x.segment(fi, i - fi) -= x[i] * L.row(i).segment(fi, i - fi).transpose();
  }
}

void LdltSolver::runDense(const Problem& problem, Vector& x, Result& result) {
  Impl& m = *impl_;
  const DenseMatrix& A = problem.denseA();
  m.rhs = -problem.b;
  // Factor, solve, refine once (as the sparse path).
  auto factorSolve = [&](auto& factorization) {
    factorization.compute(A);
    x = factorization.solve(m.rhs);
    m.correction = m.rhs;
    m.correction.noalias() -= A * x;
    x += factorization.solve(m.correction);
  };
  result.iterations = 1;
  result.status = Status::Converged;
  // The envelope LDL^T reads A's lower triangle only and is kept when its refined answer
  // solves the full A to kEnvelopeResidual (scaled as residual.hpp: ||A x + b|| / (1 + ||b||)):
  // this checks symmetry in passing, at the cost of one product A x instead of an O(n^2)
  // strided comparison. Otherwise the exact check sends A to a pivoting factorization.
  m.envelope(A);
  const bool factored = m.factorEnvelope(A);
  if (factored) {
    m.solveEnvelope(m.rhs, x);
    m.correction = m.rhs;
    m.correction.noalias() -= A * x;
    m.solveEnvelope(m.correction, m.w);
    x += m.w;
    m.correction = m.rhs;
    m.correction.noalias() -= A * x;
    if (m.correction.lpNorm<Eigen::Infinity>() <=
        kEnvelopeResidual * (1 + m.rhs.lpNorm<Eigen::Infinity>())) {
      result.message = "dense LDL^T solve";
      return;
    }
  }
  const bool symmetric = detail::isSymmetric(A);
  if (symmetric) {
    // A (near-)zero pivot without pivoting, or an ill-conditioned A: Eigen's LDL^T with diagonal
    // pivoting first (it takes indefinite A too).
    factorSolve(m.denseLdlt);
    result.message = factored ? "dense pivoting LDL^T solve (envelope LDL^T residual too large)"
                              : "dense pivoting LDL^T solve";
    m.correction = m.rhs;
    m.correction.noalias() -= A * x;
    if (m.correction.lpNorm<Eigen::Infinity>() <=
        kEnvelopeResidual * (1 + m.rhs.lpNorm<Eigen::Infinity>()))
      return;
    // Still a residual: A is singular (redundant rows). The minimum-norm least-squares answer
    // (linalg/min_norm.hpp) from the LL^T of A + delta I; an indefinite A keeps the pivoting
    // answer, which the base measures.
    const double delta = linalg::minNormShift(A.diagonal().cwiseAbs().maxCoeff());
    m.shifted.compute(A + delta * DenseMatrix::Identity(A.rows(), A.cols()));
    if (m.shifted.info() != Eigen::Success) return;
    const int steps = linalg::minNormSolve(
        m.rhs, [&](const Vector& r, Vector& out) { out = m.shifted.solve(r); },
        [&](const Vector& v, Vector& out) { out.noalias() = A * v; }, x);
    reportSingular(A * x - m.rhs, m.rhs, steps, "dense", result);
  } else {
    // A zero pivot of a singular A gives Inf/NaN, which the base reports.
    factorSolve(m.denseLu);
    result.message = "dense LU solve";
  }
}

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
  if (!problem.isSparse()) return runDense(problem, x, result);
  ColMajor A = problem.toSparse();
  A.makeCompressed();
  Impl& m = *impl_;
  const Vector rhs = -problem.b;
  // Analyze when the pattern is new, factorize, solve, refine once.
  auto factorSolve = [&](auto& factorization, bool symmetric) {
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
  result.iterations = 1;
  // As the dense path: LDL^T (which reads A's lower triangle) first, kept when its answer solves
  // the whole A to kEnvelopeResidual, so the O(nnz) A - A^T of the exact check (a quarter of a
  // 33-row solve) runs only when that fails. A pattern found non-symmetric goes straight to the
  // check next time (no LDL^T and LU analyses in turn).
  bool ok = false;
  if (m.lastSymmetric) {
    ok = factorSolve(m.ldlt, true);
    if (ok && (rhs - A * x).lpNorm<Eigen::Infinity>() <=
                  kEnvelopeResidual * (1 + rhs.lpNorm<Eigen::Infinity>())) {
      result.status = Status::Converged;
      result.message = "sparse LDL^T solve";
      return;
    }
  }
  const bool symmetric = detail::isSymmetric(A);
  m.lastSymmetric = symmetric;
  if (symmetric && !ok) ok = factorSolve(m.ldlt, true);
  if (!symmetric) ok = factorSolve(m.lu, false);
  // A singular A factors with a (near-)zero pivot or not at all, or leaves a residual: the
  // minimum-norm least-squares answer (linalg/min_norm.hpp) from the LL^T of A + delta I.
  const double target = kEnvelopeResidual * (1 + rhs.lpNorm<Eigen::Infinity>());
  if (symmetric && !(ok && (rhs - A * x).lpNorm<Eigen::Infinity>() <= target)) {
    const double delta = linalg::minNormShift(A.diagonal().cwiseAbs().maxCoeff());
    m.shiftedSparse.setShift(delta);
    m.shiftedSparse.compute(A);
    if (m.shiftedSparse.info() == Eigen::Success) {
      const int steps = linalg::minNormSolve(
          rhs, [&](const Vector& r, Vector& out) { out = m.shiftedSparse.solve(r); },
          [&](const Vector& v, Vector& out) { out = A * v; }, x);
      reportSingular(A * x - rhs, rhs, steps, "sparse", result);
      return;
    }
    ok = false;
  }
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
