// Standard LCPs with a sparse P-matrix and a known solution, for lemke's factored basis
// (tests/core/lemke_revised_test.cpp, tests/core/lemke_stress_test.cpp,
// tests/bench/lemke_bench.cpp).
//
// Every matrix is strictly diagonally dominant by rows with a positive diagonal, hence a
// P-matrix (every principal minor positive): the LCP has exactly one solution, whatever b. The
// solution is chosen first: each row is active (x* in [0.1, 1], w* = 0) or not (x* = 0, w* in
// [0.1, 1]) with probability 1/2, and b = w* - A x*. The families:
//
//   bandedSpdLcp       symmetric, `band` full off-diagonals a side, entries uniform in [-1, 1],
//                      diagonal 1 + the row's off-diagonal absolute sum (SPD).
//   stencilLcp         symmetric, one constant value per offset (a stencil: the same row
//                      everywhere), diagonal given; e.g. 4 with -1, -0.5, -0.25 at 1, 7, 131.
//   sparseBandLcp      `offsets` random distinct offsets in [1, bandwidth] (1 always among them),
//                      entries uniform in [-1, 1]; symmetric (SPD) or not (a P-matrix only);
//                      diagonal (1 + margin) times the row's off-diagonal absolute sum.
//   blockSparseLcp     blocks of 3 rows (a contact's normal and two tangents): dense diagonal
//                      blocks and `coupling` random off-diagonal blocks a block row, within
//                      `blockBand` blocks; symmetric or not; diagonal as above.
//   contactLcp         a findex contact problem on blockSparseLcp's SPD matrix: each block a
//                      contact, its normal row [0, inf) approaching (b in [-1, -0.2]), its two
//                      tangent rows boxed by +-mu x_normal (b in [-1, 1]). No constructed
//                      solution (`solution` is empty): answers are checked by their residual.
// Memory: nnz(A) = n (1 + 2 offsets) or n (3 + 6 coupling); fill of the KLU factor grows with the
// bandwidth.
#pragma once

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::test {

struct BandedLcp {
  Problem problem;
  Vector solution;
  std::string name;
};

namespace detail_banded {

// The problem with A and b = w* - A x* for a random half-active solution x*, w*.
inline BandedLcp withAnswer(SparseMatrix A, std::mt19937& rng, std::string name) {
  const int n = static_cast<int>(A.rows());
  std::uniform_real_distribution<double> u(-1, 1), pos(0.1, 1);
  Vector x = Vector::Zero(n), w = Vector::Zero(n);
  for (int i = 0; i < n; ++i) (u(rng) < 0 ? x[i] : w[i]) = pos(rng);
  Vector b = w - A * x;
  return {Problem(std::move(A), std::move(b)), std::move(x), std::move(name)};
}

// b = w* - A x* for a random half-active solution; A from triplets without the diagonal, which
// becomes (1 + margin) * (row's off-diagonal absolute sum) + floor.
inline BandedLcp finish(int n, std::vector<Eigen::Triplet<double>> t, double margin, double floor,
                        std::mt19937& rng, std::string name) {
  Vector rowSum = Vector::Zero(n);
  for (const auto& e : t) rowSum[e.row()] += std::abs(e.value());
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, (1 + margin) * rowSum[i] + floor);
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return withAnswer(std::move(A), rng, std::move(name));
}

}  // namespace detail_banded

inline BandedLcp bandedSpdLcp(int n, int band, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
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
  return detail_banded::withAnswer(std::move(A), rng, "banded SPD");
}

inline BandedLcp stencilLcp(int n, double diagonal, const std::vector<int>& offsets,
                            const std::vector<double>& values, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Triplet<double>> t;
  for (size_t k = 0; k < offsets.size(); ++k)
    for (int i = 0; i + offsets[k] < n; ++i) {
      t.emplace_back(i, i + offsets[k], values[k]);
      t.emplace_back(i + offsets[k], i, values[k]);
    }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diagonal);
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return detail_banded::withAnswer(std::move(A), rng, "stencil");
}

// The stencil of the 20,000-row problem that once ended lemke on a wrong basis.
inline BandedLcp stencil131Lcp(int n, unsigned seed) {
  BandedLcp lcp = stencilLcp(n, 4, {1, 7, 131}, {-1, -0.5, -0.25}, seed);
  lcp.name = "stencil 1/7/131";
  return lcp;
}

inline BandedLcp sparseBandLcp(int n, int bandwidth, int offsets, bool symmetric, unsigned seed,
                               double margin = 0.1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<int> off = {1};
  std::uniform_int_distribution<int> pick(2, std::max(2, bandwidth));
  while (static_cast<int>(off.size()) < std::min(offsets, bandwidth)) {
    const int o = pick(rng);
    if (std::find(off.begin(), off.end(), o) == off.end()) off.push_back(o);
  }
  std::vector<Eigen::Triplet<double>> t;
  for (int o : off)
    for (int i = 0; i + o < n; ++i) {
      const double v = u(rng);
      t.emplace_back(i, i + o, v);
      t.emplace_back(i + o, i, symmetric ? v : u(rng));
    }
  return detail_banded::finish(
      n, std::move(t), margin, 0.1, rng,
      std::string(symmetric ? "band SPD" : "band P") + " bw " + std::to_string(bandwidth));
}

inline BandedLcp blockSparseLcp(int n, int blockBand, int coupling, bool symmetric, unsigned seed,
                                double margin = 0.1) {
  constexpr int kBlock = 3;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const int blocks = (n + kBlock - 1) / kBlock;
  auto rows = [&](int blk) { return std::min(kBlock, n - blk * kBlock); };
  std::vector<Eigen::Triplet<double>> t;
  auto block = [&](int bi, int bj, bool mirror) {
    for (int r = 0; r < rows(bi); ++r)
      for (int c = 0; c < rows(bj); ++c) {
        const int i = bi * kBlock + r, j = bj * kBlock + c;
        if (i == j) continue;
        if (bi == bj && symmetric && j < i) continue;
        const double v = u(rng);
        t.emplace_back(i, j, v);
        if (mirror || (bi == bj && symmetric)) t.emplace_back(j, i, v);
      }
  };
  std::uniform_int_distribution<int> pick(1, std::max(1, blockBand));
  for (int bi = 0; bi < blocks; ++bi) {
    block(bi, bi, false);
    for (int k = 0; k < coupling; ++k) {
      const int bj = bi + pick(rng);
      if (bj >= blocks) continue;
      block(bi, bj, symmetric);
      if (!symmetric) block(bj, bi, false);
    }
  }
  return detail_banded::finish(
      n, std::move(t), margin, 0.1, rng,
      std::string(symmetric ? "block SPD" : "block P") + " bw " + std::to_string(blockBand));
}

inline BandedLcp contactLcp(int n, int blockBand, double mu, unsigned seed) {
  BandedLcp lcp = blockSparseLcp(n - n % 3, blockBand, 2, true, seed);
  Problem& p = lcp.problem;
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1, 1), approach(0.2, 1);
  p.findex.assign(p.size(), -1);
  for (int k = 0; k < p.size(); k += 3) {
    p.b[k] = -approach(rng);
    for (int t = 1; t <= 2; ++t) {
      p.b[k + t] = u(rng);
      p.lo[k + t] = -mu;
      p.hi[k + t] = mu;
      p.findex[k + t] = k;
    }
  }
  lcp.solution = Vector();
  lcp.name = "contacts bw " + std::to_string(blockBand);
  return lcp;
}

}  // namespace mlcp::test
