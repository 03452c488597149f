#include "linalg/symmetry.hpp"

#include <algorithm>
#include <cmath>

namespace mlcp::detail {

namespace {

// A(j, i) from row j of a CSR matrix whose rows are sorted (0 when not stored).
double lookup(const SparseMatrix& a, int j, int i) {
  const int* begin = a.innerIndexPtr() + a.outerIndexPtr()[j];
  const int* end = a.innerIndexPtr() + a.outerIndexPtr()[j + 1];
  const int* at = std::lower_bound(begin, end, i);
  return at != end && *at == i ? a.valuePtr()[at - a.innerIndexPtr()] : 0.0;
}

bool rowsSorted(const SparseMatrix& a) {
  for (int r = 0; r < a.outerSize(); ++r)
    if (!std::is_sorted(a.innerIndexPtr() + a.outerIndexPtr()[r],
                        a.innerIndexPtr() + a.outerIndexPtr()[r + 1]))
      return false;
  return true;
}

}  // namespace

bool isSymmetric(const DenseMatrix& A) {
  const Eigen::Index n = A.rows();
  if (A.cols() != n) return false;
  double gap = 0;
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = j + 1; i < n; ++i) gap = std::max(gap, std::abs(A(i, j) - A(j, i)));
  return symmetricWithin(gap, n ? A.cwiseAbs().maxCoeff() : 0.0);
}

bool isSymmetric(const SparseMatrix& A) {
  if (!A.isCompressed() || !rowsSorted(A)) return isSymmetric<SparseMatrix>(A);
  const double* v = A.valuePtr();
  double largest = 0, gap = 0;
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) largest = std::max(largest, std::abs(v[k]));
  for (int i = 0; i < A.outerSize(); ++i)
    for (int k = A.outerIndexPtr()[i]; k < A.outerIndexPtr()[i + 1]; ++k) {
      const int j = A.innerIndexPtr()[k];
      if (j > i) gap = std::max(gap, std::abs(v[k] - lookup(A, j, i)));
    }
  return symmetricWithin(gap, largest);
}

bool isSymmetric(const Problem& problem) {
  return problem.isSparse() ? isSymmetric(problem.sparseA()) : isSymmetric(problem.denseA());
}

}  // namespace mlcp::detail
