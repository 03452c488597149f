// core/src/pivoting/box_friction_lcp.hpp (internal): box friction (findex) written as one LCP
// without a fixed point, the Stewart-Trinkle / Anitescu-Potra form with one direction pair per
// tangent row (Anitescu and Potra 1997; friction_cone.hpp is the same idea on engine rows with k
// directions per contact).
//
// A findex row t with findex[t] = n and bounds -mu..mu asks for
//
//     |x_t| <= mu |x_n|,  x_t = mu |x_n| => w_t <= 0,  x_t = -mu |x_n| => w_t >= 0,  else w_t = 0,
//
// which is not an LCP (the bounds move with x_n). With x_t = l+ - l- and a slack g per row:
//
//     l+ >= 0  _|_  g + w_t             >= 0
//     l- >= 0  _|_  g - w_t             >= 0
//     g  >= 0  _|_  mu s x_n - l+ - l-  >= 0     (s = +1 when lo_n >= 0, -1 when hi_n <= 0)
//
// g > 0 puts l+ + l- at mu |x_n| and w_t at -g (l+ > 0) or +g (l- > 0): sliding on a bound; g = 0
// leaves w_t = 0 and |x_t| <= l+ + l- <= mu |x_n|: sticking. Every other row keeps its bounds
// (free joint rows, boxes, a normal's finite upper bound such as Bullet's 1e10), so lemke's own
// standard form takes the result. Unknowns u: row i of the problem keeps index i (a tangent row's
// holds l+), then l- of every tangent row, then g of every tangent row; rows in the same order:
//
//     w' = [ A S u + b ;  -(A S u + b)_T + g ;  mu s x_N - l+ - l- ],   plus g in the rows T,
//
// S the map x = S u (x_t = u_t - u_(n+k) for the k-th tangent row t), T the tangent rows, N their
// normals. Over u >= 0 (normals with lo_n = 0), u' M u = (S u)' A (S u) + sum_k g_k mu x_n (the
// g terms of the tangent rows cancel those of the g rows): PSD A gives a copositive M, and in
// exact arithmetic lemke ends with an answer whenever the friction problem has one (Anitescu and
// Potra); b = J v (no stabilisation) always has one. In floating point a singular A can still end
// it short (lemke.hpp says what follows). The answer maps back to x = S u exactly, so its
// residual is measured on the original problem.
//
// Invariants: only rows with findex and mu > 0 are expanded; mu = 0 rows stay as rows fixed at
// 0 (lo = hi = 0). A normal row whose bounds straddle 0 (a free row) has no linear |x_n|: build()
// refuses the problem with the reason, and the caller keeps the fixed point.
// Cost: n + 2T unknowns and rows for T tangent rows, nnz(A) + nnz(A's tangent rows and columns)
// + 7 T entries; lemke's standard form adds its box variables as for any problem.
#pragma once

#include <string>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::detail {

class BoxFrictionLcp {
 public:
  // The LCP form of `problem` with matrix A (the problem's own, or a regularised one). Returns ""
  // on success, otherwise the reason it does not fit (nothing usable is built).
  std::string build(const Problem& problem, const SparseMatrix& A);

  // Rows and unknowns as above, no findex: lemke's standard form takes it directly.
  const Problem& problem() const { return lcp_; }
  // Tangent rows written as l+ - l- (findex and mu > 0).
  int tangentRows() const { return static_cast<int>(tangents_.size()); }

  // The original problem's x from the LCP's unknowns u.
  Vector toFindex(const Vector& u) const;
  // The k-th expanded tangent row (an original row) and its slack g in u.
  int tangentRow(int k) const { return tangents_[k]; }
  double slack(const Vector& u, int k) const { return u[n_ + tangentRows() + k]; }

 private:
  int n_ = 0;
  std::vector<int> tangents_;  // original rows of the expanded tangent rows, in order
  std::vector<int> pairOf_;    // per original row: k (its index in tangents_) or -1
  Problem lcp_;
};

}  // namespace mlcp::detail
