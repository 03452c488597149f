// SymmetricPatternLu: a sparse LU without pivoting for matrices whose pattern is symmetric (the
// clamped systems of block principal pivoting, block_pivoting.hpp). Internal to the library.
#pragma once

#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::detail {

// K = L D U without pivoting (L unit lower, U unit upper) for a sparse square K whose pattern
// is symmetric, in the given order: up-looking, row k of L and column k of U from two sparse
// triangular solves over the elimination tree (built as it goes), so L and U^T share one
// pattern, that of the Cholesky factor of the pattern. Twice an LDL^T's work; the symbolic pass
// (elimination tree, column counts) is skipped when the pattern is the last factorization's.
// factorSymmetric is the same for a symmetric K (U = L^T, one triangular solve per row).
class SymmetricPatternLu {
 public:
  // K (m x m) in compressed columns, rows in any order within a column; kt holds the values of
  // K^T on the same pattern (kt at the entry (i, j) is K(j, i)). False when a pivot's magnitude
  // is at most pivotTolerance (or not finite).
  bool factor(int m, const std::vector<int>& outer, const std::vector<int>& inner,
              const std::vector<double>& k, const std::vector<double>& kt, double pivotTolerance);
  bool factorSymmetric(int m, const std::vector<int>& outer, const std::vector<int>& inner,
                       const std::vector<double>& k, double pivotTolerance);
  void solve(Vector& y) const;  // y <- K^-1 y
  // y <- L^-1 y for a y that is zero outside idx; idx becomes the rows where the result may be
  // nonzero (idx's reach in the elimination tree: L(r, i) != 0 only for ancestors r of i), in
  // increasing order. Costs the entries of L in those columns, not m.
  void forward(std::vector<int>& idx, Vector& y);
  double pivot(int c) const { return d_[c]; }                         // D's entry c
  int entries() const { return start_.empty() ? 0 : start_.back(); }  // L's off-diagonal entries

 private:
  bool run(int m, const std::vector<int>& outer, const std::vector<int>& inner,
           const std::vector<double>& k, const std::vector<double>* kt, double pivotTolerance);
  // run's stages: the symbolic pass, then per column the scatter and the elimination (both
  // inlined into run's loop).
  void analyze(int m, const std::vector<int>& outer, const std::vector<int>& inner);
  int scatter(int m, int col, const std::vector<int>& outer, const std::vector<int>& inner,
              const std::vector<double>& k, const std::vector<double>* kt, double& dk);
  void eliminate(int m, int col, int top, double& dk);
  // Column c of L (and row c of U) at [start_[c], start_[c + 1]): rows_, l_ = L(row, c),
  // u_ = U(c, row) (unused when symmetric_), sized by a symbolic pass over the elimination tree.
  std::vector<int> start_, fill_, rows_;
  std::vector<double> l_, u_, d_, y_, z_;
  std::vector<int> parent_, tag_, stack_;
  std::vector<int> analyzedOuter_, analyzedInner_;  // the pattern parent_ and start_ are for
  std::vector<char> reached_;
  bool symmetric_ = false;
};

}  // namespace mlcp::detail
