#include "pivoting/box_friction_lcp.hpp"

#include <sstream>

namespace mlcp::detail {

std::string BoxFrictionLcp::build(const Problem& problem, const SparseMatrix& A) {
  const int n = problem.size();
  n_ = n;
  tangents_.clear();
  pairOf_.assign(n, -1);
  std::vector<double> normalSign(n, 0);
  for (int i = 0; i < n; ++i) {
    const int j = problem.findex.empty() ? -1 : problem.findex[i];
    if (j < 0 || !(problem.hi[i] > 0)) continue;  // mu = 0 rows stay, fixed at 0
    if (problem.lo[j] >= 0) {
      normalSign[i] = 1;
    } else if (problem.hi[j] <= 0) {
      normalSign[i] = -1;
    } else {
      std::ostringstream os;
      os << "friction row " << i << "'s normal row " << j << " has bounds [" << problem.lo[j]
         << ", " << problem.hi[j] << "] on both sides of 0 (|x_" << j << "| is not linear)";
      return os.str();
    }
    pairOf_[i] = static_cast<int>(tangents_.size());
    tangents_.push_back(i);
  }
  const int T = static_cast<int>(tangents_.size());
  const int m = n + 2 * T;
  const int minusAt = n, slackAt = n + T;  // first l- and first g

  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(A.nonZeros()) * 2 + 7 * static_cast<size_t>(T));
  // Row r of A S, written into output row `row` with factor f.
  auto addRow = [&](int r, int row, double f) {
    for (SparseMatrix::InnerIterator it(A, r); it; ++it) {
      const int c = static_cast<int>(it.col());
      t.emplace_back(row, c, f * it.value());
      if (pairOf_[c] >= 0) t.emplace_back(row, minusAt + pairOf_[c], -f * it.value());
    }
  };
  Vector b(m), lo(m), hi(m);
  for (int r = 0; r < n; ++r) {
    addRow(r, r, 1);
    b[r] = problem.b[r];
    if (pairOf_[r] < 0) {
      const bool fixedFriction = !problem.findex.empty() && problem.findex[r] >= 0;
      lo[r] = fixedFriction ? 0.0 : problem.lo[r];
      hi[r] = fixedFriction ? 0.0 : problem.hi[r];
    } else {
      lo[r] = 0;
      hi[r] = kInf;
    }
  }
  for (int k = 0; k < T; ++k) {
    const int row = tangents_[k];
    const int normal = problem.findex[row];
    addRow(row, minusAt + k, -1);
    b[minusAt + k] = -problem.b[row];
    b[slackAt + k] = 0;
    t.emplace_back(row, slackAt + k, 1.0);
    t.emplace_back(minusAt + k, slackAt + k, 1.0);
    t.emplace_back(slackAt + k, normal, problem.hi[row] * normalSign[row]);
    t.emplace_back(slackAt + k, row, -1.0);
    t.emplace_back(slackAt + k, minusAt + k, -1.0);
  }
  lo.tail(2 * T).setZero();
  hi.tail(2 * T).setConstant(kInf);
  SparseMatrix M(m, m);
  M.setFromTriplets(t.begin(), t.end());
  M.makeCompressed();
  lcp_ = Problem(M, b);
  lcp_.lo = lo;
  lcp_.hi = hi;
  return "";
}

Vector BoxFrictionLcp::toFindex(const Vector& u) const {
  Vector x = u.head(n_);
  for (size_t k = 0; k < tangents_.size(); ++k) x[tangents_[k]] -= u[n_ + static_cast<int>(k)];
  return x;
}

}  // namespace mlcp::detail
