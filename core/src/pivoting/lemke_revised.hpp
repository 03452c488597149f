// core/src/pivoting/lemke_revised.hpp (internal): Lemke's method on a factored basis (the
// revised method): the same pivots as the dense tableau of lemke_tableau.hpp, with every tableau
// column it reads computed by solves with an LU of the basis matrix instead. The method, its
// rules and the size at which it replaces the tableau: mlcp/solvers/lemke.hpp and
// docs/methods/pivoting.md, "Lemke: tableau or factored basis".
//
// Standard LCP w = M y + q with the artificial z0: [I, -M, -c] (w, y, z0) = q, c the covering
// vector (e cold; B0 e for a warm start from the basis B0, so that z0's column reads -e in it).
// The basis matrix B holds the columns of the basic variables in basis order (position r of B is
// row r of the tableau). Kept: a KLU factorization of B at the last refactorization and an eta
// file, the tableau columns d_k = B_{k-1}^-1 a_k of the pivots since then with their rows r_k
// (B_k = B_{k-1} E_k, E_k the identity with column r_k replaced by d_k), and the basic values
// x_B. A pivot needs one solve B d = a for the entering column a; x_B moves by the ratio step
// (x_B -= theta d, x_B[r] = theta). Ties of the ratio test read rows of B^-1, e_i' B^-1, by
// solves with B' for the tied rows only. Every refactorPeriod pivots B is factored again and
// x_B recomputed as B^-1 q; when the updated x_B's backward error ||B x_B - q|| / (||q|| +
// ||B|| ||x_B||) exceeded kLemkeBackwardError (1e-10) the period is halved. Memory: the factor
// (O(nnz(L + U))) plus at most refactorPeriod eta columns of m entries.
//
// B is factored with plain partial pivoting (kLemkeBasisPivotThreshold): the position of a
// basic variable in B is the row it entered at, unrelated to the rows its column is large in,
// so KLU's preference for the diagonal (its default threshold 0.001) buys nothing and lets the
// factor grow by up to 1e3 a step. It did: on a 5,000-row banded P-matrix LCP a refactorization
// returned basic values with a backward error of 0.4 and -1.2 among them, and the method
// pivoted on and ended, z0 leaving, on a wrong basis.
//
// The check: each refactorization (and the end, when z0 leaves) computes x_B fresh. A backward
// error above kLemkeBackwardError there means the factor itself is inaccurate: under a pivot
// threshold below 1, B is factored again with plain partial pivoting at once. x_B is then
// refined while its backward error exceeds the limit (two steps at most), and the basis is
// wrong when it stays inaccurate or has a value below -kLemkeInfeasibility (1 + ||x_B||): the
// invariant x_B >= 0 held on the right path. A wrong basis is recovered from: the run returns to
// the last basis checked right (its entering variable and row kept with it), factors it with
// plain partial pivoting, halves the period and pivots on (at most kMaxRecoveries times a run;
// after that it ends as it would have, the final answer's residual then telling). Cost: one
// residual O(nnz B) per refactorization and one factorization more at the end.
#pragma once

#include <functional>
#include <vector>

#include "mlcp/problem.hpp"
#include "mlcp/thresholds.hpp"
#include "pivoting/lemke_tableau.hpp"

namespace mlcp::detail {

using ColumnMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;

struct RevisedLemkeResult {
  LemkeOutcome outcome;
  Vector y;                  // the LCP unknowns (0 where not basic)
  std::vector<bool> yBasic;  // y_j basic in the final basis
  std::vector<int> basis;    // the final basis (variables w_i = i, y_j = m + j, z0 = 2 m)
  bool singular = false;     // a factorization of the basis failed (outcome.end is Ray then)
  int refactorizations = 0;
  int recoveries = 0;  // strict refactorizations and returns to the last basis checked right
};

struct RevisedLemkeSettings {
  ToleranceRules rules;
  int maxPivots = 0;
  // Pivots between two factorizations of the basis (halved on inaccurate updates). Default 50.
  int refactorPeriod = 50;
  // KLU's pivot threshold for B (1: plain partial pivoting; KLU's default is 0.001). Default
  // kLemkeBasisPivotThreshold.
  double basisPivotThreshold = kLemkeBasisPivotThreshold;
  // A complementary basis to start from (m variables, one of w_i / y_i per i), or empty for the
  // slack basis. A warm start uses the covering vector B0 e.
  std::vector<int> warmBasis;
  std::function<bool()> stop;  // asked before each pivot; true ends with LemkeEnd::Stopped
};

// Runs the method on w = M y + q, M square and column-major.
RevisedLemkeResult revisedLemke(const ColumnMatrix& M, const Vector& q,
                                const RevisedLemkeSettings& settings);

}  // namespace mlcp::detail
