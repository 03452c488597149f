#include "newton_system.hpp"

#include <algorithm>
#include <cmath>

namespace mlcp::detail {

namespace {

double largestEntry(const Problem& pb) {
  return pb.isSparse() ? (pb.sparseA().nonZeros() ? pb.sparseA().coeffs().cwiseAbs().maxCoeff() : 0)
                       : pb.denseA().cwiseAbs().maxCoeff();
}

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

bool symmetricMatrix(const Problem& pb) {
  const double tol = 1e-14 * std::max(1.0, largestEntry(pb));
  const int n = pb.size();
  if (!pb.isSparse()) {
    const DenseMatrix& a = pb.denseA();
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < j; ++i)
        if (std::abs(a(i, j) - a(j, i)) > tol) return false;
    return true;
  }
  const SparseMatrix& a = pb.sparseA();
  if (!a.isCompressed() || !rowsSorted(a)) {
    const SparseMatrix t = a.transpose();
    const SparseMatrix d = a - t;
    return d.nonZeros() == 0 || d.coeffs().cwiseAbs().maxCoeff() <= tol;
  }
  for (int i = 0; i < n; ++i)
    for (int k = a.outerIndexPtr()[i]; k < a.outerIndexPtr()[i + 1]; ++k) {
      const int j = a.innerIndexPtr()[k];
      if (j > i && std::abs(a.valuePtr()[k] - lookup(a, j, i)) > tol) return false;
    }
  return true;
}

bool NewtonSystem::prepare(const Problem& pb, int denseMaxRows, std::string& why) {
  problem_ = &pb;
  denseMaxRows_ = denseMaxRows;
  const int n = pb.size();
  a_ = nullptr;
  if (n <= denseMaxRows) return true;  // the dense path only
  if (pb.isSparse()) {
    a_ = &pb.sparseA();
  } else {
    own_ = pb.toSparse();
    a_ = &own_;
  }
  if (!a_->isCompressed()) {
    own_ = *a_;
    own_.makeCompressed();
    a_ = &own_;
  }
  // Column j of the upper triangle: row j's entries left of the diagonal (sorted), then (j, j).
  colStart_.assign(1, 0);
  rowIndex_.clear();
  source_.clear();
  column_.clear();
  std::vector<std::pair<int, int>> row;
  for (int j = 0; j < n; ++j) {
    row.clear();
    int diagonal = -1;
    for (int k = a_->outerIndexPtr()[j]; k < a_->outerIndexPtr()[j + 1]; ++k) {
      const int i = a_->innerIndexPtr()[k];
      if (i < j) row.emplace_back(i, k);
      if (i == j) diagonal = k;
    }
    std::sort(row.begin(), row.end());
    row.emplace_back(j, diagonal);
    for (const auto& [i, k] : row) {
      rowIndex_.push_back(i);
      source_.push_back(k);
      column_.push_back(j);
    }
    colStart_.push_back(static_cast<int>(rowIndex_.size()));
  }
  values_.resize(rowIndex_.size());
  if (!cholmod_.analyze(n, colStart_, rowIndex_)) {
    why = "CHOLMOD rejected the pattern of A";
    return false;
  }
  return true;
}

double NewtonSystem::entry(int i, int j) const {
  const Problem& pb = *problem_;
  return pb.isSparse() ? pb.sparseA().coeff(i, j) : pb.denseA()(i, j);
}

bool NewtonSystem::factor(const std::vector<char>& inC, double rho) {
  const int m = static_cast<int>(std::count(inC.begin(), inC.end(), 1));
  lastSparse_ = a_ != nullptr && m > denseMaxRows_;
  return lastSparse_ ? factorSparse(inC, rho) : factorDense(inC, rho);
}

bool NewtonSystem::solve(Vector& rhs) {
  if (lastSparse_) {
    cholmod_.solve(rhs);
  } else if (!clamped_.empty()) {
    const int m = static_cast<int>(clamped_.size());
    for (int c = 0; c < m; ++c) sub_[c] = rhs[clamped_[c]];
    sub_ = llt_.solve(sub_);
    for (int c = 0; c < m; ++c) rhs[clamped_[c]] = sub_[c];
  }
  return rhs.allFinite();
}

bool NewtonSystem::factorDense(const std::vector<char>& inC, double rho) {
  const Problem& pb = *problem_;
  const int n = pb.size();
  clamped_.clear();
  for (int i = 0; i < n; ++i)
    if (inC[i]) clamped_.push_back(i);
  const int m = static_cast<int>(clamped_.size());
  if (m == 0) return true;
  block_.resize(m, m);
  sub_.resize(m);
  if (pb.isSparse()) {
    pos_.assign(n, -1);
    for (int c = 0; c < m; ++c) pos_[clamped_[c]] = c;
    block_.setZero();
    const SparseMatrix& a = pb.sparseA();
    for (int c = 0; c < m; ++c)
      for (SparseMatrix::InnerIterator it(a, clamped_[c]); it; ++it)
        if (pos_[it.col()] >= 0) block_(c, pos_[it.col()]) = it.value();
  } else {
    for (int c = 0; c < m; ++c)
      for (int d = 0; d < m; ++d) block_(c, d) = entry(clamped_[c], clamped_[d]);
  }
  block_.diagonal().array() += rho;
  llt_.compute(block_);
  return llt_.info() == Eigen::Success;
}

bool NewtonSystem::factorSparse(const std::vector<char>& inC, double rho) {
  const double* a = a_->valuePtr();
  const size_t nnz = values_.size();
  for (size_t k = 0; k < nnz; ++k) {
    const int i = rowIndex_[k], j = column_[k];
    if (i == j)
      values_[k] = inC[i] ? (source_[k] >= 0 ? a[source_[k]] : 0.0) + rho : 1.0;
    else
      values_[k] = inC[i] && inC[j] ? a[source_[k]] : 0.0;
  }
  return cholmod_.factor(values_);
}

}  // namespace mlcp::detail
