// The linear system of one Newton step of NewtonSolver (see "Linear algebra" in mlcp/newton.hpp):
// (A_CC + rho I) dx_C = r_C with dx_N given, factored densely for small clamped sets and by
// CHOLMOD on the whole-pattern matrix K = P_C (A + rho I) P_C + (I - P_C) for large ones.
// Internal to the library.
#pragma once

#include <vector>

#include "linalg/cholmod_factor.hpp"
#include "mlcp/problem.hpp"

namespace mlcp::detail {

// Whether A equals A^T (to 1e-14 of its largest entry) without forming A^T: O(nnz log) for
// sparse A with sorted rows, O(n^2) dense.
bool symmetricMatrix(const Problem& problem);

class NewtonSystem {
 public:
  explicit NewtonSystem(linalg::CholmodFactor& cholmod) : cholmod_(cholmod) {}
  // Per solve, before the steps: the problem (symmetric A, kept by reference until the next
  // prepare). False (with why) when CHOLMOD rejects the pattern.
  bool prepare(const Problem& problem, int denseMaxRows, std::string& why);
  // Factors the system of the clamped rows inC with the proximal weight rho. False when the block
  // is not positive definite.
  bool factor(const std::vector<char>& inC, double rho);
  // With the last factor: rhs (size n) holds r_C on the clamped rows and dx_N on the others; on
  // return dx (both parts). False when the result is not finite.
  bool solve(Vector& rhs);
  // Whether the last factor is CHOLMOD's.
  bool lastSparse() const { return lastSparse_; }

 private:
  bool factorDense(const std::vector<char>& inC, double rho);
  bool factorSparse(const std::vector<char>& inC, double rho);
  double entry(int i, int j) const;

  linalg::CholmodFactor& cholmod_;
  const Problem* problem_ = nullptr;
  const SparseMatrix* a_ = nullptr;  // CSR A: the problem's, or own_ for dense storage
  SparseMatrix own_;
  int denseMaxRows_ = 0;
  bool lastSparse_ = false;
  // The upper triangle of A in compressed columns: per stored entry its row, column and the
  // index of its value in a_'s storage (-1: a diagonal A lacks, value 0).
  std::vector<int> colStart_, rowIndex_, source_, column_;
  std::vector<double> values_;
  std::vector<int> clamped_, pos_;  // the dense path's gathered rows and their positions
  DenseMatrix block_;
  Eigen::LLT<DenseMatrix> llt_;
  Vector sub_;
};

}  // namespace mlcp::detail
