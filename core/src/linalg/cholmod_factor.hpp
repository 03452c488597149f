// A symmetric positive definite sparse factorization by CHOLMOD (SuiteSparse), with the symbolic
// analysis kept while the pattern holds. Internal to the library.
//
// The matrix is given by its upper triangle in compressed columns (CHOLMOD's stype = 1). analyze()
// orders it (AMD, or METIS/NESDIS when CHOLMOD finds them better) and computes the elimination
// tree and the factor's pattern, choosing supernodal or simplicial as CHOLMOD decides from the
// flop count; factor() computes L for new values on the same pattern (entries that are exactly
// zero stay in the pattern, so a caller may zero rows and columns without a new analysis);
// solve() does the two triangular solves. Cost: analyze ~ O(nnz(L)), factor ~ sum over columns of
// their count squared, solve ~ O(nnz(L)). No global state: each object owns a cholmod_common.
#pragma once

#include <memory>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::linalg {

class CholmodFactor {
 public:
  CholmodFactor();
  ~CholmodFactor();
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;

  // The pattern (n x n, upper triangle with the diagonal, rows sorted in each column). Returns
  // false when CHOLMOD rejects it. An analysis of the same pattern is kept (no work).
  bool analyze(int n, const std::vector<int>& colStart, const std::vector<int>& rowIndex);
  // Numeric factorization for values on the analyzed pattern. False when the matrix is not
  // positive definite to working precision (a pivot <= 0 or not finite).
  bool factor(const std::vector<double>& values);
  // y <- K^-1 y with the last factor.
  void solve(Vector& y);
  // Symbolic analyses done by this object (for tests of the reuse).
  int analyses() const { return analyses_; }
  // Entries of L in the last factor.
  double factorEntries() const;
  bool supernodal() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
  int analyses_ = 0;
};

}  // namespace mlcp::linalg
