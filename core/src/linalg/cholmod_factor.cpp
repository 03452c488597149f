#include "linalg/cholmod_factor.hpp"

#include <suitesparse/cholmod.h>

#include <algorithm>
#include <cstring>

namespace mlcp::linalg {

struct CholmodFactor::State {
  cholmod_common common;
  cholmod_sparse* a = nullptr;  // the analyzed pattern, values refilled by factor()
  cholmod_factor* l = nullptr;
  cholmod_dense *x = nullptr, *y = nullptr, *e = nullptr;  // solve2's reused workspaces
  std::vector<int> colStart, rowIndex;
  State() {
    cholmod_start(&common);
    common.print = 0;  // statuses are read from common.status, nothing goes to stderr
  }
  ~State() {
    clear();
    cholmod_free_dense(&x, &common);
    cholmod_free_dense(&y, &common);
    cholmod_free_dense(&e, &common);
    cholmod_finish(&common);
  }
  void clear() {
    cholmod_free_factor(&l, &common);
    cholmod_free_sparse(&a, &common);
  }
};

CholmodFactor::CholmodFactor() : s_(std::make_unique<State>()) {}
CholmodFactor::~CholmodFactor() = default;

bool CholmodFactor::analyze(int n, const std::vector<int>& colStart,
                            const std::vector<int>& rowIndex) {
  State& s = *s_;
  if (s.l && s.colStart == colStart && s.rowIndex == rowIndex) return true;
  s.clear();
  const size_t nnz = rowIndex.size();
  s.a = cholmod_allocate_sparse(n, n, std::max<size_t>(nnz, 1), 1, 1, 1, CHOLMOD_REAL, &s.common);
  if (!s.a) return false;
  std::copy(colStart.begin(), colStart.end(), static_cast<int*>(s.a->p));
  std::copy(rowIndex.begin(), rowIndex.end(), static_cast<int*>(s.a->i));
  std::fill_n(static_cast<double*>(s.a->x), nnz, 0.0);
  s.l = cholmod_analyze(s.a, &s.common);
  if (!s.l) {
    s.clear();
    return false;
  }
  s.colStart = colStart;
  s.rowIndex = rowIndex;
  ++analyses_;
  return true;
}

bool CholmodFactor::factor(const std::vector<double>& values) {
  State& s = *s_;
  if (!s.l || values.size() != s.rowIndex.size()) return false;
  std::copy(values.begin(), values.end(), static_cast<double*>(s.a->x));
  if (!cholmod_factorize(s.a, s.l, &s.common)) return false;
  return s.common.status == CHOLMOD_OK && s.l->minor == s.l->n;
}

void CholmodFactor::solve(Vector& y) {
  State& s = *s_;
  cholmod_dense b;
  std::memset(&b, 0, sizeof b);
  b.nrow = b.d = b.nzmax = static_cast<size_t>(y.size());
  b.ncol = 1;
  b.x = y.data();
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(CHOLMOD_A, s.l, &b, nullptr, &s.x, nullptr, &s.y, &s.e, &s.common)) {
    y.setConstant(std::numeric_limits<double>::quiet_NaN());  // the caller's finite check sees it
    return;
  }
  std::copy_n(static_cast<const double*>(s.x->x), y.size(), y.data());
}

double CholmodFactor::factorEntries() const {
  const State& s = *s_;
  return s.l ? s.common.lnz : 0.0;
}

bool CholmodFactor::supernodal() const { return s_->l && s_->l->is_super; }

}  // namespace mlcp::linalg
