#include "symmetric_pattern_lu.hpp"

#include <algorithm>
#include <cmath>

namespace mlcp::detail {

bool SymmetricPatternLu::factor(int m, const std::vector<int>& outer, const std::vector<int>& inner,
                                const std::vector<double>& k, const std::vector<double>& kt,
                                double pivotTolerance) {
  return run(m, outer, inner, k, &kt, pivotTolerance);
}

bool SymmetricPatternLu::factorSymmetric(int m, const std::vector<int>& outer,
                                         const std::vector<int>& inner,
                                         const std::vector<double>& k, double pivotTolerance) {
  return run(m, outer, inner, k, nullptr, pivotTolerance);
}

// Symbolic: the elimination tree and the column counts of L (as SimplicialLDLT's analysis),
// skipped for the pattern of the last call (a resting scene's clamped set repeats).
void SymmetricPatternLu::analyze(int m, const std::vector<int>& outer,
                                 const std::vector<int>& inner) {
  const int nz = outer[m];
  const bool same = static_cast<int>(analyzedOuter_.size()) == m + 1 &&
                    std::equal(outer.begin(), outer.begin() + m + 1, analyzedOuter_.begin()) &&
                    static_cast<int>(analyzedInner_.size()) == nz &&
                    std::equal(inner.begin(), inner.begin() + nz, analyzedInner_.begin());
  if (same) return;
  parent_.assign(m, -1);
  tag_.assign(m, -1);
  fill_.assign(m, 0);
  for (int col = 0; col < m; ++col) {
    tag_[col] = col;
    for (int e = outer[col]; e < outer[col + 1]; ++e)
      for (int i = inner[e]; i < col && tag_[i] != col; i = parent_[i]) {
        if (parent_[i] < 0) parent_[i] = col;
        ++fill_[i];
        tag_[i] = col;
      }
  }
  start_.assign(m + 1, 0);
  for (int c = 0; c < m; ++c) start_[c + 1] = start_[c] + fill_[c];
  analyzedOuter_.assign(outer.begin(), outer.begin() + m + 1);
  analyzedInner_.assign(inner.begin(), inner.begin() + nz);
}

// Scatters column col of K above the diagonal into y, row col left of it into z, and puts the
// rows of L's row col (the reach of column col's pattern in the elimination tree) on the stack
// in topological order, from the returned top to m. dk takes K(col, col).
[[gnu::always_inline]] inline int SymmetricPatternLu::scatter(
    int m, int col, const std::vector<int>& outer, const std::vector<int>& inner,
    const std::vector<double>& k, const std::vector<double>* kt, double& dk) {
  tag_[col] = col;
  int top = m;
  for (int e = outer[col]; e < outer[col + 1]; ++e) {
    int i = inner[e];
    if (i == col) dk = k[e];
    if (i >= col) continue;
    y_[i] = k[e];
    if (!symmetric_) z_[i] = (*kt)[e];
    int len = 0;
    for (; tag_[i] != col; i = parent_[i]) {
      stack_[len++] = i;
      tag_[i] = col;
    }
    while (len > 0) stack_[--top] = stack_[--len];
  }
  return top;
}

// Row col of L (and column col of U) from the scattered column: the sparse triangular solve
// over the stack, L(col, i) and U(i, col) appended to column i; dk becomes D's entry col.
[[gnu::always_inline]] inline void SymmetricPatternLu::eliminate(int m, int col, int top,
                                                                 double& dk) {
  if (symmetric_) {
    for (; top < m; ++top) {
      const int i = stack_[top];
      const double yi = y_[i];
      y_[i] = 0;
      for (int p = start_[i]; p < fill_[i]; ++p) y_[rows_[p]] -= l_[p] * yi;
      const double li = yi / d_[i];
      dk -= li * yi;
      const int p = fill_[i]++;
      rows_[p] = col;
      l_[p] = li;
    }
    return;
  }
  for (; top < m; ++top) {
    const int i = stack_[top];
    const double yi = y_[i], zi = z_[i];
    y_[i] = z_[i] = 0;
    for (int p = start_[i]; p < fill_[i]; ++p) {
      y_[rows_[p]] -= l_[p] * yi;
      z_[rows_[p]] -= u_[p] * zi;
    }
    dk -= zi * yi / d_[i];
    const int p = fill_[i]++;
    rows_[p] = col;
    l_[p] = zi / d_[i];
    u_[p] = yi / d_[i];
  }
}

bool SymmetricPatternLu::run(int m, const std::vector<int>& outer, const std::vector<int>& inner,
                             const std::vector<double>& k, const std::vector<double>* kt,
                             double pivotTolerance) {
  symmetric_ = kt == nullptr;
  analyze(m, outer, inner);
  rows_.resize(start_[m]);
  l_.resize(start_[m]);
  if (!symmetric_) u_.resize(start_[m]);
  fill_.resize(m);
  std::copy(start_.begin(), start_.end() - 1, fill_.begin());
  d_.assign(m, 0.0);
  y_.assign(m, 0.0);
  z_.assign(m, 0.0);
  tag_.assign(m, -1);
  stack_.resize(m);
  for (int col = 0; col < m; ++col) {
    double dk = 0;
    const int top = scatter(m, col, outer, inner, k, kt, dk);
    eliminate(m, col, top, dk);
    if (!(std::abs(dk) > pivotTolerance)) return false;
    d_[col] = dk;
  }
  return true;
}

void SymmetricPatternLu::solve(Vector& y) const {
  const int m = static_cast<int>(y.size());
  for (int i = 0; i < m; ++i)
    for (int p = start_[i]; p < start_[i + 1]; ++p) y[rows_[p]] -= l_[p] * y[i];
  for (int i = 0; i < m; ++i) y[i] /= d_[i];
  const std::vector<double>& u = symmetric_ ? l_ : u_;
  for (int i = m - 1; i >= 0; --i) {
    double s = y[i];
    for (int p = start_[i]; p < start_[i + 1]; ++p) s -= u[p] * y[rows_[p]];
    y[i] = s;
  }
}

void SymmetricPatternLu::forward(std::vector<int>& idx, Vector& y) {
  reached_.resize(d_.size(), 0);
  const size_t given = idx.size();
  for (size_t a = 0; a < given; ++a)
    for (int i = idx[a]; i >= 0 && !reached_[i]; i = parent_[i]) {
      reached_[i] = 1;
      idx.push_back(i);
    }
  idx.erase(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(given));
  std::sort(idx.begin(), idx.end());
  for (int i : idx) {
    reached_[i] = 0;
    const double yi = y[i];
    if (yi != 0)
      for (int p = start_[i]; p < start_[i + 1]; ++p) y[rows_[p]] -= l_[p] * yi;
  }
}

}  // namespace mlcp::detail
