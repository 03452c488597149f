// core/src/pivoting/lemke_tableau.hpp (internal): Lemke's complementary pivoting on a dense
// tableau, generic in the number type so that the solver (double, with tolerances) and the
// teaching trace (exact fractions, rational.hpp) share one copy of the pivoting rules. The
// method and its guarantees: mlcp/solvers/lemke.hpp and docs/methods/pivoting.md.
//
// Tableau of the standard LCP w = M z + q, w, z >= 0, w'z = 0, with the artificial z0:
//
//     columns   w_1..w_n | z_1..z_n | z_0 | rhs
//     rows      [  I     |   -M     | -e  |  q ]     (basis w at the start)
//
// After any sequence of pivots the w-columns hold B^-1 (B the basis matrix), which is what the
// lexicographic ratio test compares: rows of [rhs, B^-1] divided by the pivot-column entry.
// Cost: n x (2n + 2) entries; a Gauss-Jordan pivot O(n^2), skipping the pivot row's zeros.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pivoting/rational.hpp"

namespace mlcp::detail {

inline double absValue(double v) { return std::abs(v); }
inline Rational absValue(const Rational& v) { return v < Rational(0) ? -v : v; }

// Exact comparisons, for fractions.
struct ExactRules {
  bool positive(const Rational& v, const Rational& /*colMaxAbs*/) const { return Rational(0) < v; }
  int compare(const Rational& a, const Rational& b) const { return a < b ? -1 : (b < a ? 1 : 0); }
  Rational clampRhs(const Rational& v) const { return v; }
};

// Floating-point comparisons: a pivot must exceed pivotTolerance * max(1, largest |entry| of
// its column); two ratios within tieTolerance (relative) are a tie.
struct ToleranceRules {
  double pivotTolerance = 1e-12;
  double tieTolerance = 1e-11;
  bool positive(double v, double colMaxAbs) const {
    return v > pivotTolerance * std::max(1.0, colMaxAbs);
  }
  int compare(double a, double b) const {
    if (std::abs(a - b) <= tieTolerance * std::max({1.0, std::abs(a), std::abs(b)})) return 0;
    return a < b ? -1 : 1;
  }
  // Round-off may leave a basic value at -1e-17; it is a zero for the ratio test.
  double clampRhs(double v) const { return std::max(v, 0.0); }
};

// Variable v of an LCP of size n (w_i = i, z_i = n + i, z0 = 2 n) as "w3", "z1", "z0" (1-based,
// as in the textbook tableaux and traceLemke's print).
inline std::string variableLabel(int v, int n) {
  if (v == 2 * n) return "z0";
  return (v < n ? "w" : "z") + std::to_string(v % n + 1);
}

template <class T>
class LemkeTableau {
 public:
  // M is n x n row-major (M[i * n + j]), q has n entries.
  LemkeTableau(int n, const std::vector<T>& M, const std::vector<T>& q)
      : n_(n), cols_(2 * n + 2), t_(static_cast<size_t>(n) * (2 * n + 2), T(0)), basis_(n) {
    for (int i = 0; i < n; ++i) {
      at(i, i) = T(1);
      for (int j = 0; j < n; ++j) at(i, n + j) = T(0) - M[static_cast<size_t>(i) * n + j];
      at(i, z0()) = T(-1);
      at(i, rhsColumn()) = q[i];
      basis_[i] = i;
    }
  }

  int size() const { return n_; }
  int z0() const { return 2 * n_; }  // variable index of z0 (w_i = i, z_i = n + i)
  int rhsColumn() const { return 2 * n_ + 1; }
  int complement(int v) const { return v < n_ ? v + n_ : v - n_; }
  std::string label(int v) const { return variableLabel(v, n_); }
  int basic(int row) const { return basis_[row]; }
  const T& at(int row, int col) const { return t_[static_cast<size_t>(row) * cols_ + col]; }
  T& at(int row, int col) { return t_[static_cast<size_t>(row) * cols_ + col]; }
  const T& rhs(int row) const { return at(row, rhsColumn()); }

  // Gauss-Jordan step: variable `col` becomes basic in `row`.
  void pivot(int row, int col) {
    const T p = at(row, col);
    T* pr = &at(row, 0);
    for (int j = 0; j < cols_; ++j) pr[j] = pr[j] / p;
    pr[col] = T(1);
    for (int i = 0; i < n_; ++i) {
      if (i == row) continue;
      T* ri = &at(i, 0);
      const T f = ri[col];
      if (f == T(0)) continue;
      for (int j = 0; j < cols_; ++j)
        if (!(pr[j] == T(0))) ri[j] = ri[j] - f * pr[j];
      ri[col] = T(0);
    }
    basis_[row] = col;
  }

  // The row z0 enters at: the most negative rhs; among equal values the largest index, which is
  // the lexicographic minimum of [q, I] and keeps every row lexicographically positive.
  template <class Rules>
  int initialRow(const Rules& rules) const {
    int best = 0;
    for (int i = 1; i < n_; ++i)
      if (rules.compare(rhs(i), rhs(best)) <= 0) best = i;
    return best;
  }

  // Minimum-ratio test for the entering column with the lexicographic tie-break of
  // Cottle-Pang-Stone: among rows with a positive entry, the lexicographic minimum of
  // [rhs_i, (B^-1)_i.] / entry_i. The row of z0 wins every tie of the plain ratio, as it ends
  // the method. Returns -1 when the column has no positive entry (ray termination).
  template <class Rules>
  int leavingRow(int col, const Rules& rules) const {
    T colMax(0);
    for (int i = 0; i < n_; ++i) colMax = std::max(colMax, absValue(at(i, col)));
    std::vector<int> ties;
    for (int i = 0; i < n_; ++i)
      if (rules.positive(at(i, col), colMax)) ties.push_back(i);
    if (ties.empty()) return -1;
    // Key 0 is the ratio rhs / entry; key k >= 1 is (B^-1)_{i,k-1} / entry.
    auto key = [&](int i, int k) {
      const T num = k == 0 ? rules.clampRhs(rhs(i)) : at(i, k - 1);
      return num / at(i, col);
    };
    for (int k = 0; k <= n_ && ties.size() > 1; ++k) {
      T best = key(ties[0], k);
      for (int i : ties) best = std::min(best, key(i, k));
      std::vector<int> kept;
      for (int i : ties)
        if (rules.compare(key(i, k), best) == 0) kept.push_back(i);
      ties.swap(kept);
      if (k == 0)
        for (int i : ties)
          if (basis_[i] == z0()) return i;
    }
    // Only round-off can leave two rows here (B^-1 has independent rows): take the larger pivot.
    int row = ties[0];
    for (int i : ties)
      if (at(row, col) < at(i, col)) row = i;
    return row;
  }

 private:
  int n_;
  int cols_;
  std::vector<T> t_;
  std::vector<int> basis_;
};

enum class LemkeEnd { Solved, Ray, PivotLimit, Stopped };

struct LemkeOutcome {
  LemkeEnd end = LemkeEnd::Solved;
  int pivots = 0;
  int entering = -1;  // on Ray: the variable whose column had no positive entry
};

// Runs the method on the tableau. observer.pivoted(pivotNumber, entering, leaving, row) is
// called after every pivot; observer.stop() is asked before each pivot (time budgets).
template <class T, class Rules, class Observer>
LemkeOutcome runLemke(LemkeTableau<T>& tab, const Rules& rules, int maxPivots, Observer& observer) {
  LemkeOutcome out;
  const int n = tab.size();
  bool feasible = true;
  for (int i = 0; i < n; ++i) feasible = feasible && !(tab.rhs(i) < T(0));
  if (feasible) return out;  // q >= 0: (w, z) = (q, 0)
  int entering = tab.z0();
  int row = tab.initialRow(rules);
  for (;;) {
    if (out.pivots >= maxPivots) {
      out.end = LemkeEnd::PivotLimit;
      return out;
    }
    if (observer.stop()) {
      out.end = LemkeEnd::Stopped;
      return out;
    }
    const int leaving = tab.basic(row);
    tab.pivot(row, entering);
    ++out.pivots;
    observer.pivoted(out.pivots, entering, leaving, row);
    if (leaving == tab.z0()) return out;
    entering = tab.complement(leaving);
    row = tab.leavingRow(entering, rules);
    if (row < 0) {
      out.end = LemkeEnd::Ray;
      out.entering = entering;
      return out;
    }
  }
}

// The message of ray termination; `lcp` names the problem ("the LCP").
inline std::string rayMessage(const LemkeOutcome& out, const std::string& enteringLabel,
                              const std::string& lcp) {
  return "ray termination at pivot " + std::to_string(out.pivots + 1) +
         ": the entering column of " + enteringLabel + " has no positive entry; " + lcp +
         " may be infeasible";
}

}  // namespace mlcp::detail
