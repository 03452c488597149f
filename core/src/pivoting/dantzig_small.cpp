#include "pivoting/dantzig_small.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "linalg/symmetry.hpp"

// GCC vectorizes the loops over the clamped rows (run-time length m <= n) into 2-wide code
// with peeling, whose stack stores the next scalar loads cannot forward from: the scalar code is
// faster (docs/benchmarks.md, "Dantzig: the tiny-island path") and makes the same operations
// (no sum is reassociated either way, so the answers are the same to the bit).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-tree-vectorize")
#endif

namespace mlcp::detail {

namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// The guessed block's factors A_CC = L D L^T (D kept as its reciprocals), the clamped rows
// being the first m positions of the processing order. The block is padded to n x n by
// identity rows (L's row 0, D 1: the rows at a bound, which come after the clamped ones), so
// every loop runs over n, a template argument: the factor and the solves compile to
// straight-line code whose independent products overlap (with the loops over a run-time m and
// a division per pivot, the dependent chain set a 6-row island's latency).
template <int n>
struct Factors {
  int m = 0;
  const double* a = nullptr;  // A in processing order, column-major n x n
  double L[n * n];            // row-major: L[j * n + k] = L_jk, k < j
  double invD[n];

  double rowDot(int i, const double* v) const {
    const double* row = a + i * n;  // A is symmetric: column i is row i
    double s = 0;
    for (int k = 0; k < n; ++k) s += row[k] * v[k];
    return s;
  }
  // L D L^T of the first `clamped` positions (Crout, row by row); false when a pivot is at
  // most pivTol (the bordered factor's Schur pivots of dantzig.cpp, in the same order).
  bool factor(int clamped, double pivTol) {
    m = clamped;
    for (int j = 0; j < n; ++j) {
      double* Lj = L + j * n;
      if (j >= m) {
        for (int k = 0; k < n; ++k) Lj[k] = 0;
        invD[j] = 1;
        continue;
      }
      const double* col = a + j * n;
      double t[n];  // t_k = (L D)_jk = a_jk - sum_{c<k} t_c L_kc
      double pivot = col[j];
      for (int k = 0; k < j; ++k) {
        double s = col[k];
        for (int c = 0; c < k; ++c) s -= t[c] * L[k * n + c];
        t[k] = s;
        Lj[k] = s * invD[k];
        pivot -= s * Lj[k];
      }
      for (int k = j; k < n; ++k) Lj[k] = 0;
      if (!(std::abs(pivot) > pivTol)) return false;
      invD[j] = 1.0 / pivot;
    }
    return true;
  }
  // x_C -= A_CC^-1 (b + A x)_C (the padded rows' entries of the solve are exact zeros).
  void solveClamped(const double* b, double* x) const {
    double y[n];
    for (int k = 0; k < n; ++k) {
      double s = k < m ? b[k] + rowDot(k, x) : 0.0;
      for (int c = 0; c < k; ++c) s -= L[k * n + c] * y[c];
      y[k] = s;
    }
    for (int k = 0; k < n; ++k) y[k] *= invD[k];
    for (int k = n - 1; k >= 0; --k) {
      double s = y[k];
      for (int j = k + 1; j < n; ++j) s -= L[j * n + k] * y[j];
      y[k] = s;
      x[k] -= s;
    }
  }
};

enum class At : unsigned char { Clamped, Lo, Hi, Fixed };

}  // namespace

bool smallDenseApplies(const Problem& problem) {
  const int n = problem.size();
  return n > 0 && n <= kPlainLoopRows && !problem.isSparse() && !problem.hasFindex();
}

namespace {

// Tries per solve: the caller's guess and two corrected ones (solveSmallDense).
constexpr int kTries = 3;

enum class Try : unsigned char { Solved, Declined, Again };

// A value strictly inside [lo, hi] (lo < hi), for a row moved from a bound to the clamped set;
// NaN when there is none in double (a bound of 1e16 and up: lo + 1 == lo).
double inside(double lo, double hi) {
  const double v = lo > -kInf && hi < kInf ? 0.5 * (lo + hi) : lo > -kInf ? lo + 1 : hi - 1;
  return v > lo && v < hi ? v : std::numeric_limits<double>::quiet_NaN();
}

// One try's state in processing order: 0 equality rows, 1 rows guessed clamped (the start
// strictly inside the bounds; a cold start: the rows whose bounds contain 0), 2 the others. Its
// stages run in the order of solveFixed, each on the state the previous ones left.
template <int n>
struct Attempt {
  // Each stage sets what it writes (order: perm, groupAt, clamped, identity; symmetric: aMax;
  // gather: f.a, b, lo, hi, x and the tolerances), so nothing is initialized here.
  int perm[n], groupAt[n];
  int clamped;  // groups 0 and 1: positions 0 .. clamped - 1
  bool identity;
  Factors<n> f;
  double b[n], lo[n], hi[n], x[n], w[n];
  At at[n];
  double aMax, bMax, pivTol, epsW;

  // The processing order (a counting sort by group).
  [[gnu::always_inline]] void order(const Problem& pb, const double* guess) {
    int group[n], start[4] = {0, 0, 0, 0};
    for (int i = 0; i < n; ++i) {
      const double rowLo = pb.lo[i], rowHi = pb.hi[i], g = guess[i];
      group[i] = isFreeRow(rowLo, rowHi) ? 0 : g > rowLo && g < rowHi ? 1 : 2;
      ++start[group[i] + 1];
    }
    start[2] += start[1];
    start[3] += start[2];
    clamped = start[2];
    identity = true;
    for (int i = 0; i < n; ++i) {
      const int p = start[group[i]]++;
      perm[p] = i;
      groupAt[p] = group[i];
      identity = identity && p == i;
    }
  }
  // Whether A is symmetric (sets aMax). Maxima are exact in any order: Eigen's vectorized
  // reduction, and the asymmetry in two independent chains.
  [[gnu::always_inline]] bool symmetric(const DenseMatrix& A) {
    const double* a = A.data();
    aMax = A.cwiseAbs().maxCoeff();
    double asym[2] = {0, 0};
    for (int j = 0; j < n; ++j)
      for (int i = j + 1; i < n; ++i)
        asym[i & 1] = std::max(asym[i & 1], std::abs(a[i + j * n] - a[j + i * n]));
    return symmetricWithin(std::max(asym[0], asym[1]), aMax);
  }
  // A (in `permuted` unless the order is the caller's), b, the bounds and the clamped start in
  // processing order; the zero tests' tolerances.
  [[gnu::always_inline]] void gather(const Problem& pb, const double* guess, double pivotTolerance,
                                     double* permuted) {
    const DenseMatrix& A = pb.denseA();
    if (identity) {
      f.a = A.data();
    } else {
      for (int q = 0; q < n; ++q)
        for (int p = 0; p < n; ++p) permuted[p + q * n] = A(perm[p], perm[q]);
      f.a = permuted;
    }
    double dMax = 0;
    for (int p = 0; p < n; ++p) {
      const int i = perm[p];
      b[p] = pb.b[i];
      lo[p] = pb.lo[i];
      hi[p] = pb.hi[i];
      x[p] = std::clamp(guess[i], lo[p], hi[p]);
      dMax = std::max(dMax, std::abs(f.a[p + p * n]));
    }
    pivTol = (dMax > 0 ? dMax : aMax > 0 ? aMax : 1.0) * pivotTolerance;
    bMax = pb.b.lpNorm<Eigen::Infinity>();
    epsW = 1e-12 * (1.0 + bMax);
  }
  // The guessed block: factor, solve x_C with the others at their start, all inside bounds
  // (Again: guess has the rows outside at the bound they crossed).
  [[gnu::always_inline]] Try solveGuessedBlock(double* guess) {
    if (!f.factor(clamped, pivTol)) return Try::Declined;
    if (clamped == 0) return Try::Solved;
    f.solveClamped(b, x);
    bool outside = false;
    for (int p = 0; p < clamped; ++p) {
      if (x[p] < lo[p]) guess[perm[p]] = lo[p];
      if (x[p] > hi[p]) guess[perm[p]] = hi[p];
      outside = outside || x[p] < lo[p] || x[p] > hi[p];
    }
    return outside ? Try::Again : Try::Solved;
  }
  // The other rows, in order, stay at their bound when their w allows it (their x is there
  // already: the clamped start), so one w of every row serves all of them. Again: guess has a
  // row at a bound whose w points inward moved inside its bounds, for the next try to clamp.
  [[gnu::always_inline]] Try settleAtBounds(double* guess) {
    for (int p = 0; p < n; ++p) w[p] = b[p] + f.rowDot(p, x);
    bool driven = false;
    for (int p = 0; p < n; ++p) {
      at[p] = At::Clamped;
      if (groupAt[p] <= 1) continue;
      const double wp = w[p];
      if (lo[p] == hi[p]) {
        x[p] = lo[p];
        at[p] = At::Fixed;
      } else if (x[p] <= lo[p] && wp >= -epsW) {
        x[p] = lo[p];
        at[p] = At::Lo;
      } else if (x[p] >= hi[p] && wp <= epsW) {
        x[p] = hi[p];
        at[p] = At::Hi;
      } else {
        guess[perm[p]] = inside(lo[p], hi[p]);
        if (std::isnan(guess[perm[p]])) return Try::Declined;
        driven = true;
      }
    }
    return driven ? Try::Again : Try::Solved;
  }
  // One step of iterative refinement, then every row at a bound checked with a fresh w; not
  // when the clamped rows' w is within the rounding error of its own evaluation,
  // (n + 1) eps (|b| + n max|A| |x|): a correction from it would be noise (the general path
  // refines always). False when a check fails.
  [[gnu::always_inline]] bool refine() {
    double wC = 0, xMax = 0;
    for (int p = 0; p < clamped; ++p) wC = std::max(wC, std::abs(w[p]));
    for (int p = 0; p < n; ++p) xMax = std::max(xMax, std::abs(x[p]));
    const double rounding = (n + 1) * kEpsilon * (bMax + n * aMax * xMax);
    if (wC <= rounding) return true;
    f.solveClamped(b, x);
    for (int p = 0; p < n; ++p) w[p] = b[p] + f.rowDot(p, x);
    for (int p = 0; p < n; ++p)
      if ((at[p] == At::Lo && w[p] < -epsW) || (at[p] == At::Hi && w[p] > epsW)) return false;
    for (int p = 0; p < clamped; ++p)  // the refined x_C must still be within its bounds
      if (!(x[p] >= lo[p] && x[p] <= hi[p])) return false;
    return true;
  }
};

// One try from guess (the caller's order): Solved with the answer in xOut; Declined; or Again
// with guess changed to the index sets one block-pivoting step corrects it to.
template <int n>
Try solveFixed(const Problem& pb, double pivotTolerance, double* guess, Vector& xOut) {
  Attempt<n> t;
  t.order(pb, guess);
  if (!t.symmetric(pb.denseA())) return Try::Declined;
  double permuted[n * n];
  t.gather(pb, guess, pivotTolerance, permuted);
  if (const Try r = t.solveGuessedBlock(guess); r != Try::Solved) return r;
  if (const Try r = t.settleAtBounds(guess); r != Try::Solved) return r;
  if (!t.refine()) return Try::Declined;
  for (int p = 0; p < n; ++p)
    if (!std::isfinite(t.x[p])) return Try::Declined;  // overflow: the general path decides
  for (int p = 0; p < n; ++p) xOut[t.perm[p]] = t.x[p];
  return Try::Solved;
}

template <int n>
bool solveTries(const Problem& pb, double pivotTolerance, Vector& x) {
  double guess[n];
  for (int i = 0; i < n; ++i) guess[i] = x[i];
  for (int t = 0; t < kTries; ++t) {
    const Try r = solveFixed<n>(pb, pivotTolerance, guess, x);
    if (r != Try::Again) return r == Try::Solved;
  }
  return false;
}

}  // namespace

bool solveSmallDense(const Problem& pb, double pivotTolerance, Vector& x) {
  static_assert(kPlainLoopRows == 8, "one instance per size below");
  switch (pb.size()) {
    case 1: return solveTries<1>(pb, pivotTolerance, x);
    case 2: return solveTries<2>(pb, pivotTolerance, x);
    case 3: return solveTries<3>(pb, pivotTolerance, x);
    case 4: return solveTries<4>(pb, pivotTolerance, x);
    case 5: return solveTries<5>(pb, pivotTolerance, x);
    case 6: return solveTries<6>(pb, pivotTolerance, x);
    case 7: return solveTries<7>(pb, pivotTolerance, x);
    case 8: return solveTries<8>(pb, pivotTolerance, x);
    default: return false;
  }
}

}  // namespace mlcp::detail
