// The reduced systems of an MLCP assembled from rows, solved in body space: NewtonSolver's damped
// steps (newton.hpp, "Linear algebra") and the block steps of its pivoting phase
// (block_pivoting.hpp, "Body space"). Internal to the library.
//
// For a problem assembled from rows (rows.hpp: A = J W J^T + diag(cfm), W = M^-1), the matrix on
// a set C of clamped (free) rows, with sliding rows t (x_t = c_t x_n(t)) substituted, is
//
//     K = D + J_C W G_C^T,   D = diag(cfm_c + rho),   G_c = J_c + sum_{t: n(t) = c} c_t J_t.
//
// With W = R R^T per body (R = sqrt(invMass) on the linear part, Q sqrt(Lambda) of the eigen
// decomposition of invInertia on the angular part: singular inertia allowed; Eigen's iterative
// 3x3 solver, as its closed form loses up to 1e-6 of A's diagonal on a rotated cube's equal
// eigenvalues, which the callers' check against A then refuses) and U = J_C R,
// V = G_C R, Woodbury gives
//
//     K^-1 r = D^-1 (r - U y),   S y = V^T D^-1 r,   S = I + V^T D^-1 U,
//
// S of size 6 x (dynamic bodies), 6 x 6 blocks on the body graph (symmetric pattern; symmetric
// positive definite, eigenvalues >= 1, without sliding rows). Valid when every d_c is not tiny
// (callers: at least kBodyMinDiagonal max |A_ii|, thresholds.hpp).
//
// Cost. S's factor is a block LU on the body graph in CHOLMOD's fill-reducing order (the lower
// fill of AMD and nested dissection, linalg/ordering.hpp; kept while the graph is the last
// problem's): O(sum over bodies of (fill blocks below it)^2 216) per factorization, independent
// of how many rows each contact has. Its block updates run in AVX2 where the CPU has it
// (mlcp/cpu.hpp, linalg/block_update.hpp). Memory is O(fill blocks + elimination updates); no
// limit on the bodies. Why a block LU of our own: it is faster on the pyramids' S than CHOLMOD,
// KLU and UMFPACK (docs/benchmarks.md, "Body space: the factorization of S"; docs/decisions.md,
// "body space").
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <vector>

#include "block_update.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/rows.hpp"

namespace mlcp::detail {

class BodySpaceSystem {
 public:
  // Per solve: the rows A was assembled from. False when they do not fit a problem of n rows.
  bool prepare(const RowSystem& rows, int n);
  // The same for `problem`, and true only when the rows are its A (A = J W J^T + diag(cfm),
  // checked on the diagonal to 1e-10 of its largest entry, dMax).
  bool prepareFor(const RowSystem& rows, const Problem& problem, double dMax);
  // Whether products through the rows (multiply) may stand for A's: every cfm > 0 (on a singular
  // A, cfm = 0 and coplanar contacts, their round-off differences from A's rows are not damped:
  // a test's sliding pyramid went from settling to 120 unsettled steps in block pivoting).
  bool productsStandForA() const {
    return !cfm_.empty() && *std::min_element(cfm_.begin(), cfm_.end()) > 0;
  }
  // Factors S for the clamped rows order (pos: row -> index in order, or -1) and the sliding rows
  // with their coefficients (findex: each sliding row's normal). False when it does not apply
  // (some cfm_c + rho below minDiagonal, a sliding row on other bodies than its normal's) or S
  // is singular; the caller then factors K itself.
  bool factor(const std::vector<int>& order, const std::vector<int>& pos,
              const std::vector<int>& sliding, const std::vector<double>& coeff,
              const std::vector<int>& findex, double rho, double minDiagonal);
  // factor()'s two stages: S assembled (false where factor() does not apply), then its block LU
  // (false when S is singular).
  bool assemble(const std::vector<int>& order, const std::vector<int>& pos,
                const std::vector<int>& sliding, const std::vector<double>& coeff,
                const std::vector<int>& findex, double rho, double minDiagonal);
  bool eliminate();
  // S as assemble() left it, by compressed columns (6 p + i: coordinate i of the body at rank
  // p), its blocks that are not zero: for comparisons with library factorizations.
  void assembled(std::vector<int>& start, std::vector<int>& index,
                 std::vector<double>& values) const;
  // y <- K^-1 y (y indexed as order).
  void solve(Vector& y);
  // Products with A = (J R)(J R)^T + diag(cfm) in factored form: 12 multiply-adds a row into the
  // bodies' R^T J^T x and 12 out of them, instead of A's row (~110 entries at Bullet's 55 boxes).
  // out = A x (all rows), or out[c] = (A x)_{which[c]}.
  void multiply(const Vector& x, Vector& out);
  void multiply(const Vector& x, const std::vector<int>& which, Vector& out);
  // One projected Gauss-Seidel sweep on `problem` (the prepared one, its A these rows'), as
  // detail::pgsSweep with omega = 1, each row's slack from the bodies' R^T J^T x kept up to date
  // (24 multiply-adds a row and 12 a row per sweep to start, instead of A's row).
  void sweep(const Problem& problem, const Vector& invDiag, Vector& x);
  int size() const { return 6 * bodies_; }
  double diagonal(int i) const {  // A_ii from the rows
    const RowData& rd = rows_[i];
    double d = cfm_[i];
    for (int l = 0; l < 12; ++l) d += rd.jr[l] * rd.jr[l];
    return d;
  }

 private:
  using Block = Block6;  // linalg/block_update.hpp's, whose kernel updates blocks_
  struct RowData {
    int a = -1, b = -1;  // dynamic bodies in elimination order, -1: none
    double jr[12];       // [J_A R_A, J_B R_B]
    int block[2][2];     // S's blocks (side p, side q) of this row, -1 without both sides
  };
  void bodyForces(const Vector& x);  // v_ = R^T J^T x
  // v's entries of rd's bodies += amount j, and init + j . v over them (j: 12 entries, the
  // sides A and B as jr).
  static void spread(const RowData& rd, const double* j, double amount, Vector& v) {
    if (rd.a >= 0)
      for (int l = 0; l < 6; ++l) v[6 * rd.a + l] += j[l] * amount;
    if (rd.b >= 0)
      for (int l = 0; l < 6; ++l) v[6 * rd.b + l] += j[6 + l] * amount;
  }
  static double gather(const RowData& rd, const double* j, const Vector& v, double init) {
    double u = init;
    if (rd.a >= 0)
      for (int l = 0; l < 6; ++l) u += j[l] * v[6 * rd.a + l];
    if (rd.b >= 0)
      for (int l = 0; l < 6; ++l) u += j[6 + l] * v[6 * rd.b + l];
    return u;
  }
  double rowTimes(int i, double xi) const {
    return gather(rows_[i], rows_[i].jr, v_, cfm_[i] * xi);
  }
  // Of below_ entry a (body i below pivot k): L's block (i, k) and U's (k, i).
  Block& lower(int a) { return blocks_[bodies_ + 2 * a]; }
  Block& upper(int a) { return blocks_[bodies_ + 2 * a + 1]; }
  void symbolic(std::vector<std::vector<int>>& later);
  int slotOf(int p, int q) const;
  std::vector<RowData> rows_;
  int bodies_ = 0;
  // S and its factor S = L U on 6 x 6 blocks (L unit block-lower, U block-upper whose
  // diagonal blocks are kept inverted, from a 6 x 6 LU with partial pivoting), on the block pattern
  // of the body graph with its fill in the elimination order: below_[belowStart_[k] ..] the bodies
  // i > k of L's blocks (i, k) (and U's (k, i)). blocks_ holds the diagonal blocks, then L's and
  // U's block of each below_ entry; updates_ per elimination update its target block, in the
  // order the elimination makes them (memory O(fill), read in sequence).
  std::vector<int> belowStart_, below_, updates_;
  std::vector<Block, Eigen::aligned_allocator<Block>> blocks_, inverse_;  // inverse_: U's diagonal
  std::vector<double> d_, gr_, cfm_;
  Vector z_, v_;
  std::vector<int> rowOf_;  // per clamped index c: its row
  // The body graph's elimination order (byRank_[r]: the body at rank r), kept with the graph it
  // was computed for, so that next steps of an unchanged island skip the ordering.
  const std::vector<int>& orderOf(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& graph);
  std::vector<int> graphStart_, graphIndex_, byRank_;
};

}  // namespace mlcp::detail
