// core/src/pivoting/dantzig_workspace.hpp (internal): the state of DantzigSolver's pivoting
// (mlcp/solvers/dantzig.hpp) in three layers:
//
//   OrderedProblem  the problem in processing order (position p holds the caller's row perm[p]),
//                   A dense (column-major) or sparse (CSR, plus CSC when not symmetric);
//   ClampedSet      the index sets C and N and the factors A_CC = L D U of the clamped block;
//   Workspace       the method's stages (dantzig.cpp) with their scratch, pivot count and budget.
//
// Invariants between pivots: C[0..m) are the clamped positions with slot[C[c]] = c, and L, D
// (Ut) factor A(C, C) in that order; N lists the positions at a bound, free or fixed, with
// slot[N[k]] = k; set[p] names the set of every position; dxFull is zero everywhere; span is
// one past the largest position that can hold a nonzero of x's step, so products stop there.
// Storage is sized by build() and reused by every pass and solve while n does not grow.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/solvers/dantzig.hpp"

namespace mlcp {

namespace dantzig {

enum class Set : unsigned char { Unprocessed, Clamped, AtLo, AtHi, Fixed, Free };
enum class Outcome { Done, Failed, PivotLimit, TimeUp };
enum class Block { None, SelfZero, SelfBound, CBound, NZero };

using VMap = Eigen::Map<Vector>;
using Strided = Eigen::Map<DenseMatrix, 0, Eigen::OuterStride<>>;

inline VMap vmap(std::vector<double>& v, int len, int offset = 0) {
  return VMap(v.data() + offset, len);
}

// An allocator that leaves new doubles uninitialised: the factors' n x n storage is written
// before it is read (it keeps the last solve's values between solves anyway), and zeroing
// 8 n^2 bytes up front cost a 10,816-row island 0.4 s of a 0.05 s budget and 0.9 GB of pages
// it never touched; untouched pages now stay unmapped.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
using FactorStorage = std::vector<double, UninitializedAllocator<double>>;

// The problem in processing order (position p holds the caller's row perm[p]): A dense or
// sparse, the bounds (friction rows' from their normals), x and w, the tolerances, and the
// retry's diagonal shift.
struct OrderedProblem {
  int n = 0;
  bool symmetric = true;
  bool sparse = false;
  std::vector<int> perm, inv, findex;
  std::vector<double> dense, denseT;  // column-major n x n; denseT only when not symmetric
  std::vector<int> rowPtr, rowIdx, colPtr, colIdx;  // CSR; CSC only when not symmetric
  std::vector<double> rowVal, colVal, scatter;
  std::vector<double> diag, b, lo, hi, muLo, muHi, x, w, xStart;
  std::vector<double> normal;  // friction rows: the normal magnitude their bounds come from
  std::vector<int> frictionRows;
  DenseMatrix histG, histF;  // Anderson history of the friction fixed point (columns)
  // Anderson's least-squares step (nextFrictionBounds): its differences, their QR, gamma and
  // the next bounds, kept so that passes of one size allocate nothing.
  DenseMatrix andersonDF, andersonDG;
  Eigen::ColPivHouseholderQR<DenseMatrix> andersonQr;
  Vector andersonGamma, andersonStep, andersonNext;
  double pivTol = 0, epsW = 0, aMax = 0;
  // Rows nothing limits whose w is 0 (a zero Schur pivot: A singular, e.g. redundant joints)
  // stay free at their value; redundant counts them for the message.
  int redundant = 0;
  // Added to A's diagonal after build() (0: none). runPivoting sets it for its one retry of a
  // pivoting that broke down on a singular A: A + shift I is positive definite, its answer
  // solves A's (consistent, or nearly: engines' drift) system up to ~shift |x|.
  double shift = 0, scale = 0;
  bool regularised = false;  // the last solve's answer is the one on A + shift I

  // A's row i (dense storage) and its product with v over positions 0 .. len-1.
  const double* denseRow(int i) const {
    return (symmetric ? dense : denseT).data() + size_t(i) * n;
  }
  double rowDot(int i, const std::vector<double>& v, int len) const {
    if (!sparse) {
      const double* row = denseRow(i);
      if (len > kPlainLoopRows)
        return Eigen::Map<const Vector>(row, len).dot(Eigen::Map<const Vector>(v.data(), len));
      double s = 0;
      for (int k = 0; k < len; ++k) s += row[k] * v[k];
      return s;
    }
    double s = 0;
    for (int k = rowPtr[i]; k < rowPtr[i + 1]; ++k) s += rowVal[k] * v[rowIdx[k]];
    return s;
  }
};

// The index sets (C clamped, N at a bound, free or fixed) and the factors A_CC = L D U (U = L^T
// when symmetric), updated as rows join and leave C: bordering for a row that joins, Bennett's
// rank-one update for one that leaves. u, l, xs, ys are the updates' vectors.
struct ClampedSet : OrderedProblem {
  int m = 0;
  int span = 0;  // 1 + the largest position ever clamped or driven in this pass
  FactorStorage L, Ut;
  std::vector<double> D;
  std::vector<int> C, N, slot;  // slot[p]: index of p in C or in N
  std::vector<Set> set;

  std::vector<double> u, l, xs, ys;

  // out[c] = A(C[c], j): column j of A at the clamped positions.
  void gatherCol(int j, std::vector<double>& out) {
    if (!sparse) {
      const double* col = dense.data() + size_t(j) * n;
      for (int c = 0; c < m; ++c) out[c] = col[C[c]];
      return;
    }
    const bool useRows = symmetric;
    const std::vector<int>& ptr = useRows ? rowPtr : colPtr;
    const std::vector<int>& idx = useRows ? rowIdx : colIdx;
    const std::vector<double>& val = useRows ? rowVal : colVal;
    gatherSparse(ptr, idx, val, j, out);
  }
  // out[c] = A(i, C[c]): row i of A at the clamped positions.
  void gatherRow(int i, std::vector<double>& out) {
    if (!sparse) {
      const double* row = denseRow(i);
      for (int c = 0; c < m; ++c) out[c] = row[C[c]];
      return;
    }
    gatherSparse(rowPtr, rowIdx, rowVal, i, out);
  }
  void gatherSparse(const std::vector<int>& ptr, const std::vector<int>& idx,
                    const std::vector<double>& val, int j, std::vector<double>& out) {
    for (int k = ptr[j]; k < ptr[j + 1]; ++k) scatter[idx[k]] = val[k];
    for (int c = 0; c < m; ++c) out[c] = scatter[C[c]];
    for (int k = ptr[j]; k < ptr[j + 1]; ++k) scatter[idx[k]] = 0;
  }

  // The factors.
  Strided lower(FactorStorage& f) { return Strided(f.data(), m, m, Eigen::OuterStride<>(n)); }
  FactorStorage& upperT() { return symmetric ? L : Ut; }
  // y <- L^{-1} y ./ D  (the new column of U for an entering index, given A_Cj in y).
  // Up to kPlainLoopRows rows, plain loops: Eigen's blocked solves cost more in set-up than in
  // flops there (the column-wise forward loop is Eigen's own order, so the same round-off).
  void forward(FactorStorage& f, std::vector<double>& y) {
    if (m == 0) return;
    if (m > kPlainLoopRows) {
      lower(f).triangularView<Eigen::UnitLower>().solveInPlace(vmap(y, m));
    } else {
      for (int k = 0; k < m; ++k) {
        const double yk = y[k];
        if (yk == 0) continue;
        const double* col = f.data() + size_t(k) * n;
        for (int i = k + 1; i < m; ++i) y[i] -= yk * col[i];
      }
    }
    for (int c = 0; c < m; ++c) y[c] /= D[c];
  }
  // y <- U^{-1} y.
  void backward(std::vector<double>& y) {
    if (m == 0) return;
    if (m > kPlainLoopRows) {
      lower(upperT()).triangularView<Eigen::UnitLower>().transpose().solveInPlace(vmap(y, m));
      return;
    }
    const double* f = upperT().data();
    for (int i = m - 2; i >= 0; --i) {
      const double* col = f + size_t(i) * n;
      double s = 0;
      for (int k = i + 1; k < m; ++k) s += col[k] * y[k];
      y[i] -= s;
    }
  }
  // y <- A_CC^{-1} y.
  void solveCC(std::vector<double>& y) {
    forward(L, y);
    backward(y);
  }
  // Prepares u = D^-1 L^-1 A_Cj and l = D^-1 U^-T A_jC; returns the Schur pivot of j.
  double border(int j) {
    gatherCol(j, u);
    forward(L, u);
    if (symmetric) {
      double s = 0;
      for (int c = 0; c < m; ++c) s += u[c] * u[c] * D[c];
      return diag[j] - s;
    }
    gatherRow(j, l);
    forward(Ut, l);
    double s = 0;
    for (int c = 0; c < m; ++c) s += l[c] * u[c] * D[c];
    return diag[j] - s;
  }
  // Appends position p to C with the bordering vectors from border()/direction() and pivot.
  void joinC(int p, double pivot) {
    const std::vector<double>& lrow = symmetric ? u : l;
    for (int c = 0; c < m; ++c) L[m + size_t(c) * n] = lrow[c];
    if (!symmetric)
      for (int c = 0; c < m; ++c) Ut[m + size_t(c) * n] = u[c];
    D[m] = pivot;
    C[m] = p;
    slot[p] = m;
    set[p] = Set::Clamped;
    ++m;
    span = std::max(span, p + 1);
  }
  static void deleteRowCol(FactorStorage& f, int c, int m, int ld) {
    const int below = m - c - 1;
    for (int j = 0; j < c; ++j) {
      double* col = f.data() + size_t(j) * ld;
      std::memmove(col + c, col + c + 1, sizeof(double) * below);
    }
    for (int j = c + 1; j < m; ++j)
      std::memmove(f.data() + size_t(j - 1) * ld + j, f.data() + size_t(j) * ld + j + 1,
                   sizeof(double) * (m - 1 - j));
  }
  // Removes C[c] from the factors: delete its row and column, then restore the trailing block
  // with the rank-one update L22 D2 U22 + d_c l_c u_c^T (Bennett). False on a zero pivot.
  bool leaveC(int c) {
    const int s = m - c - 1;
    double alpha = D[c];
    for (int k = 0; k < s; ++k) xs[k] = L[c + 1 + k + size_t(c) * n];
    if (!symmetric)
      for (int k = 0; k < s; ++k) ys[k] = Ut[c + 1 + k + size_t(c) * n];
    deleteRowCol(L, c, m, n);
    if (!symmetric) deleteRowCol(Ut, c, m, n);
    for (int k = c; k + 1 < m; ++k) {
      D[k] = D[k + 1];
      C[k] = C[k + 1];
      slot[C[k]] = k;
    }
    --m;
    const std::vector<double>& yv = symmetric ? xs : ys;
    for (int j = 0; j < s && alpha != 0; ++j) {
      const int J = c + j;
      const double pj = xs[j], qj = yv[j];
      if (pj == 0 && qj == 0) continue;
      const double dOld = D[J], dNew = dOld + alpha * pj * qj;
      if (!(std::abs(dNew) > pivTol)) return false;
      const double bl = alpha * qj / dNew, bu = alpha * pj / dNew;
      alpha *= dOld / dNew;
      D[J] = dNew;
      const int rest = s - j - 1;
      if (rest == 0) break;
      VMap xr(xs.data() + j + 1, rest), lc(L.data() + J + 1 + size_t(J) * n, rest);
      xr -= pj * lc;
      lc += bl * xr;
      if (!symmetric) {
        VMap yr(ys.data() + j + 1, rest), uc(Ut.data() + J + 1 + size_t(J) * n, rest);
        yr -= qj * uc;
        uc += bu * yr;
      }
    }
    return true;
  }

  // N.
  void joinN(int p, Set s) {
    set[p] = s;
    slot[p] = static_cast<int>(N.size());
    N.push_back(p);
  }
  // p is in N (at a bound, or free) and its w breaks that set's sign condition; false for rows
  // in C (Set::Clamped) and fixed rows.
  bool violates(int p) const {
    return (set[p] == Set::AtLo && w[p] < -epsW) || (set[p] == Set::AtHi && w[p] > epsW) ||
           (set[p] == Set::Free && std::abs(w[p]) > epsW);
  }
  void leaveN(int k) {
    const int last = N.back();
    N[k] = last;
    slot[last] = k;
    N.pop_back();
  }
};

// The exact friction fixed point nu <- g(nu) = |x_normal(nu)| between passes: Anderson
// acceleration over the last `depth` passes (their g and f = g - nu are OrderedProblem::histG
// and histF), and plain damped iteration once it stalls. nu, g, f: one entry per friction row.
struct FrictionIteration {
  int depth = 1, stored = 0, lastGain = 0;
  double bestF = kInf, damping = 1.0;
  Vector g, nu, f;
};

}  // namespace dantzig

// Everything a solve keeps between its passes (and, for a warm start, between solves): the
// problem and the index sets with their factors (above), scratch, and the pivot count and budget.

struct DantzigSolver::Workspace : dantzig::ClampedSet {
  using Outcome = dantzig::Outcome;

  // ---- scratch ----
  dantzig::FrictionIteration friction;
  Vector residualW;
  std::vector<double> a, r, z, dxFull, dwN;
  std::vector<int> queue, violators;

  // ---- pivot count and budget ----
  int pivots = 0, pivotLimit = 0, passes = 0;
  // Options::timeBudget's deadline (+inf for none), read once per clockEvery pivots (a pivot
  // costs O(n) to O(n |C|): 1024 / n pivots between reads keep a read under ~5% of the work).
  double deadline = 0;
  int clockEvery = 1;
  std::string message;

  // -------------------------------------------------------------------- set-up
  // A solve's start from `start`: build(), the retry's shift, the pivot count and budget, and
  // pass 1's guessed clamped rows (the equality rows and, warm, the rows inside their bounds).
  void setUp(const Problem& pb, const Vector& start, const Options& opt, bool useGuess,
             bool trustFriction);
  // The problem in processing order, in stages: the order (perm, inv), the vectors sized, the
  // rows' b, bounds and start, A (dense or sparse), the scales of the zero tests.
  void build(const Problem& pb, const Vector& guess, bool useGuess, bool exactFriction);
  void order(const Problem& pb, const Vector& guess, bool useGuess, bool exactFriction);
  void sizeVectors();
  void copyRows(const Problem& pb, const Vector& guess, bool useGuess, bool exactFriction);
  void buildDense(const Problem& pb);
  void buildSparse(const Problem& pb);
  void setScales(const Problem& pb);

  // ----------------------------------------------------------------- the method
  // Moves row i's x along the ray that keeps w_C = 0 and x_N fixed until i settles (at a bound,
  // in C with w_i = 0, or free when redundant), pivoting C and N at each block on the way.
  Outcome drive(int i);
  // drive()'s stages, one pivot each: i already at a bound whose sign condition holds (joins
  // N); the pivot limit and time budget (Done: go on); the direction dxFull (returns dw_i);
  // the ratio test (the first event along the ray); the step; the block applied (nothing when
  // i moves on); no block (redundant or failed).
  struct Step {
    double length = kInf;
    dantzig::Block kind = dantzig::Block::None;
    int who = -1;     // CBound: the index in C; NZero: the index in N
    bool up = false;  // CBound: the clamped row hit its upper bound
  };
  bool settleAtBound(int i, double wi);
  Outcome checkBudget();
  double direction(int i, double d);
  Step ratioTest(int i, double d, double wi, double dwi, double sii);
  void takeStep(int i, double d, double dwi, double length);
  std::optional<Outcome> applyBlock(int i, double d, double sii, const Step& step);
  Outcome unlimited(int i, double wi, double sii);
  // dxFull back to zero; row p into C with its pivot (its row factor first when not symmetric).
  void clearDx(int i);
  void enterC(int p, double pivot);
  // One pass over the rows in order (bulk: the guessed clamped block first; finish: iterative
  // refinement and the rows that drifted driven again).
  Outcome pass(bool fixedOnce, bool reuseFactors);
  bool bulk(bool reuseFactors);
  Outcome finish();
  // x_C -= A_CC^{-1} (b + A x)_C: the clamped rows' residual made zero with the factors.
  void solveClamped() {
    for (int c = 0; c < m; ++c) a[c] = b[C[c]] + rowDot(C[c], x, n);
    solveCC(a);
    for (int c = 0; c < m; ++c) x[C[c]] -= a[c];
  }
  void freshW() {
    for (int p = 0; p < n; ++p) w[p] = b[p] + rowDot(p, x, n);
  }
  // ------------------------------------------------------------ friction passes
  // The fixed point's state for this solve (histories sized only for exact friction).
  // The solve's friction iteration (friction below), reset; its vectors keep their storage.
  dantzig::FrictionIteration& startFrictionIteration(int depth, bool exactFriction);
  // The residual (residual.hpp) of xs (in the problem's order) on pb, w in residualW: no
  // allocation once the size has been seen.
  double residualOf(const Problem& pb, const Vector& xs);
  // The next pass's friction bounds from this pass's normals; false when they did not move.
  bool nextFrictionBounds(dantzig::FrictionIteration& fi, int it, const DantzigParams& params);
  void setFrictionBounds(const Vector& nu);
  void gatherNormals(Vector& g) const;
  // A += delta I in the workspace's copies of A. False when a sparse A stores no diagonal entry
  // for some row (nothing changed then).
  bool shiftDiagonal(double delta);
  Outcome fail(const std::string& why) {
    message = why;
    return Outcome::Failed;
  }
};

}  // namespace mlcp
