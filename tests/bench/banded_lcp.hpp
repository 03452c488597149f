// Standard LCPs with a banded SPD matrix and a known solution, for lemke's factored basis
// (tests/core/lemke_revised_test.cpp, tests/bench/lemke_bench.cpp).
//
// A is symmetric with `band` off-diagonals on each side, entries uniform in [-1, 1], and a
// diagonal of 1 + the row's off-diagonal absolute sum (strictly diagonally dominant, so SPD and
// a P-matrix: the solution is unique). The solution is chosen first: each row is active
// (x* in [0.1, 1], w* = 0) or not (x* = 0, w* in [0.1, 1]) with probability 1/2, and
// b = w* - A x*.
#pragma once

#include <random>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::test {

struct BandedLcp {
  Problem problem;
  Vector solution;
};

inline BandedLcp bandedSpdLcp(int n, int band, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 1);
  std::vector<Eigen::Triplet<double>> t;
  Vector diag = Vector::Ones(n);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j <= std::min(n - 1, i + band); ++j) {
      const double v = u(rng);
      t.emplace_back(i, j, v);
      t.emplace_back(j, i, v);
      diag[i] += std::abs(v);
      diag[j] += std::abs(v);
    }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diag[i]);
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Vector x = Vector::Zero(n), w = Vector::Zero(n);
  for (int i = 0; i < n; ++i) (u(rng) < 0 ? x[i] : w[i]) = pos(rng);
  Vector b = w - A * x;
  return {Problem(std::move(A), std::move(b)), std::move(x)};
}

}  // namespace mlcp::test
