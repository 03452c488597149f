#include "linalg/sparse_lu.hpp"

#include <suitesparse/klu.h>

#include <algorithm>

namespace mlcp::linalg {

struct SparseLu::State {
  int n = 0;
  std::vector<int> rowStart, columns;
  std::vector<double> values;
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  State() { klu_defaults(&common); }
  ~State() { clear(); }
  void clearNumeric() {
    if (numeric) klu_free_numeric(&numeric, &common);
  }
  void clear() {
    clearNumeric();
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
};

SparseLu::SparseLu() : s_(std::make_unique<State>()) {}
SparseLu::~SparseLu() = default;

bool SparseLu::analyze(int n, const std::vector<int>& rowStart, const std::vector<int>& columns) {
  State& s = *s_;
  if (s.symbolic && s.n == n && s.rowStart == rowStart && s.columns == columns) return true;
  s.clear();
  s.n = n;
  s.rowStart = rowStart;
  s.columns = columns;
  s.values.assign(columns.size(), 0.0);
  s.symbolic = klu_analyze(n, s.rowStart.data(), s.columns.data(), &s.common);
  if (!s.symbolic) return false;
  ++analyses_;
  return true;
}

void SparseLu::setPivotTolerance(double tol) { s_->common.tol = tol; }

bool SparseLu::factor(const std::vector<double>& values) {
  State& s = *s_;
  s.clearNumeric();
  if (!s.symbolic || values.size() != s.columns.size()) return false;
  std::copy(values.begin(), values.end(), s.values.begin());
  s.numeric =
      klu_factor(s.rowStart.data(), s.columns.data(), s.values.data(), s.symbolic, &s.common);
  if (s.numeric && s.common.status == KLU_OK) return true;
  s.clearNumeric();
  return false;
}

bool SparseLu::solve(Vector& y) {
  State& s = *s_;
  if (!s.numeric || y.size() != s.n) return false;
  // The stored arrays are J^T by columns: J y = b is the transposed solve.
  if (!klu_tsolve(s.symbolic, s.numeric, s.n, 1, y.data(), &s.common)) return false;
  return y.allFinite();
}

bool SparseLu::solveTransposed(Vector& y) {
  State& s = *s_;
  if (!s.numeric || y.size() != s.n) return false;
  if (!klu_solve(s.symbolic, s.numeric, s.n, 1, y.data(), &s.common)) return false;
  return y.allFinite();
}

}  // namespace mlcp::linalg
