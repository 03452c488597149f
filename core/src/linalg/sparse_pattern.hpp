// Helpers shared by the sparse direct solves (ldlt.cpp, block_pivoting.cpp): a symbolic analysis
// (ordering, elimination tree) depends only on the sparsity pattern, so it is redone only when
// the pattern changes, as SuiteSparse's analyze/factorize split does.
#pragma once

#include <Eigen/SparseCore>
#include <algorithm>
#include <vector>

namespace mlcp::detail {

// The pattern a symbolic analysis was done for (compressed storage; any storage order).
class PatternCache {
 public:
  // `tag` distinguishes analyses of different kinds done for the same pattern.
  template <class Sparse>
  bool same(const Sparse& A, int tag = 0) const {
    if (tag != tag_ || A.outerSize() + 1 != static_cast<Eigen::Index>(outer_.size())) return false;
    return std::equal(outer_.begin(), outer_.end(), A.outerIndexPtr()) &&
           static_cast<Eigen::Index>(inner_.size()) == A.nonZeros() &&
           std::equal(inner_.begin(), inner_.end(), A.innerIndexPtr());
  }
  template <class Sparse>
  void remember(const Sparse& A, int tag = 0) {
    outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    tag_ = tag;
    ++analyses_;
  }
  int analyses() const { return analyses_; }

 private:
  std::vector<int> outer_, inner_;
  int tag_ = -1;
  int analyses_ = 0;
};

}  // namespace mlcp::detail
