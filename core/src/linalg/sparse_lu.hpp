// A general (nonsymmetric) sparse LU factorization by SuiteSparse's KLU, with the symbolic
// analysis kept while the pattern holds. Internal to the library.
//
// The matrix J is given by rows (compressed sparse rows, column indices sorted in each row): the
// same arrays are the compressed columns of J^T, which is what is analyzed and factored, and
// solve() solves with the transpose of that factor, so that no transposed copy is ever made.
// analyze() finds the block triangular form and orders each block (AMD); factor() computes L
// and U with threshold partial pivoting (preferring the diagonal) for new values
// on the same pattern (entries that are exactly zero stay in the pattern, so a caller may
// replace rows without a new analysis); solve() does the triangular solves. Cost: analyze ~
// O(nnz(L + U)), factor ~ the flops of the elimination, solve ~ O(nnz(L + U)). No global
// state: each object owns its klu_common. Why KLU: on the pyramids' Jacobians (1200 to 23000
// rows) it factors as fast as UMFPACK (docs/benchmarks.md) with less state and no BLAS.
#pragma once

#include <memory>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::linalg {

class SparseLu {
 public:
  SparseLu();
  ~SparseLu();
  SparseLu(const SparseLu&) = delete;
  SparseLu& operator=(const SparseLu&) = delete;

  // The pattern (n x n by rows: rowStart has n + 1 entries, column indices sorted in each row).
  // Returns false when the pattern is rejected. An analysis of the same pattern is kept (no
  // work).
  bool analyze(int n, const std::vector<int>& rowStart, const std::vector<int>& columns);
  // Numeric factorization for values on the analyzed pattern. False when the matrix is singular
  // to working precision.
  bool factor(const std::vector<double>& values);
  // y <- J^-1 y with the last factor. False when the factor is missing or a value is not finite.
  bool solve(Vector& y);
  // y <- J^-T y with the last factor (the same factor, no second factorization). False like
  // solve().
  bool solveTransposed(Vector& y);
  // KLU's threshold partial pivoting: a pivot is taken on the diagonal when its magnitude is at
  // least this fraction of its column's largest (1: plain partial pivoting). Default KLU's 0.001.
  void setPivotTolerance(double tol);
  // Symbolic analyses done by this object (for tests of the reuse).
  int analyses() const { return analyses_; }

 private:
  struct State;
  std::unique_ptr<State> s_;
  int analyses_ = 0;
};

}  // namespace mlcp::linalg
