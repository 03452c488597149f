// core/src/linalg/symmetry.hpp (internal): the one test of whether A = A^T.
//
// A is symmetric when max_ij |A_ij - A_ji| <= kSymmetryTolerance * max_ij |A_ij|. The test is
// relative, so a problem in any unit gets the same verdict. Why 1e-14 and not an exact test: the
// rows' assembly forms A_ij = J_j . (M^-1 J_i) and A_ji = J_i . (M^-1 J_j), the same products
// summed in different orders, which differ by a few units of round-off (~1e-16 relative); a
// genuinely non-symmetric A (a motor row's coupling, a user's matrix) differs by far more.
// Symmetric methods (LDL^T, the symmetric-pattern LU, dantzig's symmetric updates) then treat
// A's lower triangle as the whole matrix. Callers that meet A's entries in a pass of their own
// (dantzig's permutation, block pivoting's mirrored values) measure the gap there and apply the
// same rule through symmetricWithin().
#pragma once

#include "mlcp/problem.hpp"

namespace mlcp::detail {

inline constexpr double kSymmetryTolerance = 1e-14;

// The rule above for a measured gap max |A_ij - A_ji| and largest entry max |A_ij|.
inline bool symmetricWithin(double gap, double largest) {
  return gap <= kSymmetryTolerance * largest;
}

bool isSymmetric(const DenseMatrix& A);
// Any sparse storage: forms A - A^T (one transposed copy).
template <class Sparse>
bool isSymmetric(const Sparse& A) {
  if (A.nonZeros() == 0) return true;
  const double largest = A.coeffs().cwiseAbs().maxCoeff();
  const Sparse difference = A - Sparse(A.transpose());
  return symmetricWithin(difference.nonZeros() ? difference.coeffs().cwiseAbs().maxCoeff() : 0.0,
                         largest);
}
// Row-major with sorted rows (what assembly writes): each A_ij above the diagonal is compared
// with A_ji found by binary search in row j, no copy; other layouts go to the template.
bool isSymmetric(const SparseMatrix& A);
// A problem's A in its storage.
bool isSymmetric(const Problem& problem);

}  // namespace mlcp::detail
