#include "mlcp/solvers/lemke.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "linalg/sparse_lu.hpp"
#include "mlcp/residual.hpp"
#include "pivoting/box_friction_lcp.hpp"
#include "pivoting/lemke_revised.hpp"
#include "pivoting/lemke_tableau.hpp"

namespace mlcp {

namespace {

using detail::LemkeEnd;
using detail::LemkeOutcome;
using detail::LemkeTableau;
using detail::ToleranceRules;

enum class RowState { AtLo, AtHi, Inside };

// How one LCP variable y_a relates to its row of the (reduced) problem; see lemke.hpp.
enum class Role { Lower, Upper, BoxX, BoxW, FreePlus, FreeMinus };

// The coefficient of y_a in x_row, which is also the coefficient of w_row in the LCP row a.
double sign(Role r) {
  switch (r) {
    case Role::Lower:
    case Role::BoxX:
    case Role::FreePlus: return 1;
    case Role::Upper:
    case Role::FreeMinus: return -1;
    case Role::BoxW: return 0;
  }
  return 0;
}

struct LcpVar {
  int row;  // index into StandardForm::kept
  Role role;
};

using detail::ColumnMatrix;
using Triplets = std::vector<Eigen::Triplet<double>>;

// A boxed problem without findex written as the standard LCP w = M y + q (lemke.hpp).
struct StandardForm {
  std::vector<int> fixed, eliminated, kept;  // original row indices
  std::vector<bool> split;                   // per kept row: a free row split as z+ - z-
  DenseMatrix G;                             // x_eliminated = G x_kept + g
  Vector g;
  std::vector<LcpVar> vars;
  Vector offset;  // x_kept = offset + sum_a sign_a y_a
  ColumnMatrix M;
  Vector q;
};

bool isFree(double lo, double hi) { return lo == -kInf && hi == kInf; }

// A friction LCP that ends short on the factored basis runs once more on the dense tableau up to
// this many rows (its n + 2T): a tableau pivot is O(m^2), 16 times cheaper here than at
// kLemkeFreeRowsTableauRows.
constexpr int kLemkeFrictionTableauRows = 500;

// On the factored basis the friction LCP's pivots are tested at this multiple of
// Options::pivotTolerance: its slack rows (q = 0) and a singular A leave round-off entries near
// 1e-12 of their column in the entering columns, and a pivot on one of them led BasicDemo's
// 1137-row pile to a false ray. The tableau keeps the option as it is: at 100x a plank bridge's
// island (free rows) ran to its pivot limit (docs/benchmarks.md, "lemke: friction as one LCP
// against the fixed point").
constexpr double kFrictionLcpPivotScale = 100;

// Relative width below which a box [lo, hi] is treated as the point lo (see toStandard).
constexpr double kNarrowBox = 1e-13;

// A(rows, cols) as a dense block.
DenseMatrix denseBlock(const SparseMatrix& A, const std::vector<int>& rows,
                       const std::vector<int>& cols) {
  std::vector<int> at(A.cols(), -1);
  for (size_t c = 0; c < cols.size(); ++c) at[cols[c]] = static_cast<int>(c);
  DenseMatrix D = DenseMatrix::Zero(rows.size(), cols.size());
  for (size_t r = 0; r < rows.size(); ++r)
    for (SparseMatrix::InnerIterator it(A, rows[r]); it; ++it)
      if (at[it.col()] >= 0) D(r, at[it.col()]) = it.value();
  return D;
}

// A(idx, idx), sparse.
SparseMatrix sparseBlock(const SparseMatrix& A, const std::vector<int>& idx) {
  std::vector<int> at(A.cols(), -1);
  for (size_t c = 0; c < idx.size(); ++c) at[idx[c]] = static_cast<int>(c);
  Triplets t;
  for (size_t r = 0; r < idx.size(); ++r)
    for (SparseMatrix::InnerIterator it(A, idx[r]); it; ++it)
      if (at[it.col()] >= 0) t.emplace_back(static_cast<int>(r), at[it.col()], it.value());
  SparseMatrix B(idx.size(), idx.size());
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

// The rows of a standard form's stages (toStandard): fixed rows, free rows, the others.
struct RowSplit {
  std::vector<bool> isFixed;
  std::vector<int> freeRows;
};

// Sorts the rows into f.fixed, the free rows and f.kept (the others). Boxes narrower than
// round-off relative to the scale of x (the largest finite bound, or ||b|| / max|A_ij|) count as
// fixed: friction bounds from a normal value of 1e-30 would otherwise be ratio-test ties that
// noise decides (it led to false rays).
RowSplit splitRows(const SparseMatrix& A, const Vector& b, const Vector& lo, const Vector& hi,
                   StandardForm& f) {
  const int n = static_cast<int>(b.size());
  double aMax = 0;
  for (int i = 0; i < n; ++i)
    for (SparseMatrix::InnerIterator it(A, i); it; ++it)
      aMax = std::max(aMax, std::abs(it.value()));
  double xScale = aMax > 0 ? b.lpNorm<Eigen::Infinity>() / aMax : 0.0;
  for (int i = 0; i < n; ++i)
    for (double v : {lo[i], hi[i]})
      if (std::isfinite(v)) xScale = std::max(xScale, std::abs(v));
  const double narrow = kNarrowBox * xScale;
  RowSplit rows;
  rows.isFixed.assign(n, false);
  for (int i = 0; i < n; ++i) {
    if (hi[i] - lo[i] <= narrow) {
      f.fixed.push_back(i);
      rows.isFixed[i] = true;
    } else if (isFree(lo[i], hi[i])) {
      rows.freeRows.push_back(i);
    } else {
      f.kept.push_back(i);
    }
  }
  return rows;
}

// The reduced problem Ar x_kept + br on f.kept after the fixed rows' x = lo is substituted:
// free rows leave by the Schur complement when eliminateFree and their block is nonsingular
// (dense G: the tableau's path), otherwise they join f.kept to be split.
void reduce(const SparseMatrix& A, const Vector& b, const Vector& lo, const RowSplit& rows,
            bool eliminateFree, StandardForm& f, SparseMatrix& Ar, Vector& br) {
  const int n = static_cast<int>(b.size());
  const std::vector<int>& freeRows = rows.freeRows;
  Vector b1 = b;
  if (!f.fixed.empty())
    for (int r = 0; r < n; ++r)
      for (SparseMatrix::InnerIterator it(A, r); it; ++it)
        if (rows.isFixed[it.col()]) b1[r] += it.value() * lo[it.col()];
  bool eliminate = false;
  if (eliminateFree && !freeRows.empty()) {
    Eigen::FullPivLU<DenseMatrix> lu(denseBlock(A, freeRows, freeRows));
    eliminate = lu.isInvertible() && lu.rcond() > 1e-13;
    if (eliminate) {
      f.eliminated = freeRows;
      const DenseMatrix AKF = denseBlock(A, f.kept, freeRows);
      // (Eigen's solve binds a null pointer for a right-hand side with no columns.)
      f.G = f.kept.empty() ? DenseMatrix(freeRows.size(), 0)
                           : DenseMatrix(-lu.solve(denseBlock(A, freeRows, f.kept)));
      f.g = -lu.solve(Vector(b1(freeRows)));
      Ar = (denseBlock(A, f.kept, f.kept) + AKF * f.G).sparseView();
      br = b1(f.kept) + AKF * f.g;
    }
  }
  if (!eliminate) {
    // Free rows stay and are split, x = z+ - z-.
    f.kept.insert(f.kept.end(), freeRows.begin(), freeRows.end());
    std::sort(f.kept.begin(), f.kept.end());
    Ar = sparseBlock(A, f.kept);
    br = b1(f.kept);
  }
}

// The LCP variables of every kept row by its bounds (lemke.hpp), with f.offset and f.split;
// returns each kept row's variables.
std::vector<std::vector<int>> addVariables(const Vector& lo, const Vector& hi, StandardForm& f) {
  const int k = static_cast<int>(f.kept.size());
  f.offset = Vector::Zero(k);
  f.split.assign(k, false);
  std::vector<std::vector<int>> varsOf(k);
  for (int r = 0; r < k; ++r) {
    const int i = f.kept[r];
    auto add = [&](Role role) {
      varsOf[r].push_back(static_cast<int>(f.vars.size()));
      f.vars.push_back({r, role});
    };
    if (isFree(lo[i], hi[i])) {
      f.split[r] = true;
      add(Role::FreePlus);
      add(Role::FreeMinus);
    } else if (hi[i] == kInf) {
      f.offset[r] = lo[i];
      add(Role::Lower);
    } else if (lo[i] == -kInf) {
      f.offset[r] = hi[i];
      add(Role::Upper);
    } else {
      f.offset[r] = lo[i];
      add(Role::BoxX);
      add(Role::BoxW);
    }
  }
  return varsOf;
}

// M and q of w = M y + q from the reduced problem: entry (a, c) is sign_a Ar(row_a, row_c)
// sign_c, q_a = sign_a w0(row_a) with w0 the reduced w at y = 0, and each box's pair coupled.
void assembleLcp(const SparseMatrix& Ar, const Vector& br, const Vector& lo, const Vector& hi,
                 const std::vector<std::vector<int>>& varsOf, StandardForm& f) {
  const int k = static_cast<int>(f.kept.size());
  const int m = static_cast<int>(f.vars.size());
  const Vector w0 = Ar * f.offset + br;  // w of the reduced problem at y = 0
  Triplets t;
  t.reserve(Ar.nonZeros() * 2 + m);
  for (int r = 0; r < k; ++r)
    for (SparseMatrix::InnerIterator it(Ar, r); it; ++it)
      for (int a : varsOf[r])
        for (int c : varsOf[it.col()]) {
          const double v = sign(f.vars[a].role) * it.value() * sign(f.vars[c].role);
          if (v != 0) t.emplace_back(a, c, v);
        }
  f.q.resize(m);
  for (int a = 0; a < m; ++a) {
    const LcpVar& va = f.vars[a];
    f.q[a] = sign(va.role) * w0[va.row];
    // BoxX and BoxW are adjacent: BoxX's row is w + z2, BoxW's row is hi - lo - z1.
    if (va.role == Role::BoxX) t.emplace_back(a, a + 1, 1.0);
    if (va.role == Role::BoxW) {
      const int i = f.kept[va.row];
      t.emplace_back(a, a - 1, -1.0);
      f.q[a] = hi[i] - lo[i];
    }
  }
  f.M.resize(m, m);
  f.M.setFromTriplets(t.begin(), t.end());
}

// The boxed problem (A, b, lo, hi) as a standard LCP, in stages: the rows split into fixed, free
// and kept; the reduced problem; the LCP variables; M and q. eliminateFree: free rows leave by
// the Schur complement when their block is nonsingular; otherwise they are split.
StandardForm toStandard(const SparseMatrix& A, const Vector& b, const Vector& lo, const Vector& hi,
                        bool eliminateFree) {
  StandardForm f;
  const RowSplit rows = splitRows(A, b, lo, hi, f);
  SparseMatrix Ar;
  Vector br;
  reduce(A, b, lo, rows, eliminateFree, f, Ar, br);
  const std::vector<std::vector<int>> varsOf = addVariables(lo, hi, f);
  assembleLcp(Ar, br, lo, hi, varsOf, f);
  return f;
}

// x of the original problem from the LCP unknowns y.
Vector toOriginal(const StandardForm& f, const Vector& y, const Vector& lo) {
  Vector x(lo.size());
  Vector xk = f.offset;
  for (size_t a = 0; a < f.vars.size(); ++a) xk[f.vars[a].row] += sign(f.vars[a].role) * y[a];
  for (int i : f.fixed) x[i] = lo[i];
  for (size_t r = 0; r < f.kept.size(); ++r) x[f.kept[r]] = xk[r];
  if (!f.eliminated.empty()) {
    const Vector xe = f.G * xk + f.g;
    for (size_t r = 0; r < f.eliminated.size(); ++r) x[f.eliminated[r]] = xe[r];
  }
  return x;
}

// Which rows the final complementary basis holds at a bound and which strictly inside.
std::vector<RowState> rowStates(const StandardForm& f, const std::vector<bool>& yBasic, int n) {
  std::vector<RowState> s(n, RowState::Inside);  // eliminated and split rows: w = 0
  for (int i : f.fixed) s[i] = RowState::AtLo;
  for (size_t a = 0; a < f.vars.size(); ++a) {
    const int i = f.kept[f.vars[a].row];
    switch (f.vars[a].role) {
      case Role::Lower: s[i] = yBasic[a] ? RowState::Inside : RowState::AtLo; break;
      case Role::Upper: s[i] = yBasic[a] ? RowState::Inside : RowState::AtHi; break;
      case Role::BoxX:
        // BoxW basic means its complementary slack hi - x is zero.
        s[i] = !yBasic[a] ? RowState::AtLo : (yBasic[a + 1] ? RowState::AtHi : RowState::Inside);
        break;
      default: break;
    }
  }
  return s;
}

// Solves the active set in the original problem: (A x + b)_i = 0 for inside rows, x_i on its
// bound for the others; a friction row's bound is the linear equation x_i = mu_i sgn(x_j) x_j
// (the true coupled bound, x being the current answer). LU with partial pivoting (dense), or
// KLU (sparse, the factored-basis path), plus one step of iterative refinement. Empty when the
// system is singular.
std::optional<Vector> resolveActiveSet(const Problem& p, const SparseMatrix& A,
                                       const std::vector<RowState>& states, const Vector& x,
                                       bool sparse) {
  const int n = p.size();
  Triplets t;
  t.reserve(A.nonZeros() + 2 * n);
  Vector rhs(n);
  for (int i = 0; i < n; ++i) {
    if (states[i] == RowState::Inside) {
      for (SparseMatrix::InnerIterator it(A, i); it; ++it) t.emplace_back(i, it.col(), it.value());
      rhs[i] = -p.b[i];
      continue;
    }
    const double bound = states[i] == RowState::AtLo ? p.lo[i] : p.hi[i];
    t.emplace_back(i, i, 1.0);
    const int j = p.findex.empty() ? -1 : p.findex[i];
    if (j < 0) {
      rhs[i] = bound;
    } else {
      const double s = x[j] > 0 ? 1 : (x[j] < 0 ? -1 : 0);
      t.emplace_back(i, j, -bound * s);
      rhs[i] = 0;
    }
  }
  SparseMatrix K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  Vector sol;
  if (!sparse) {
    const DenseMatrix Kd(K);
    Eigen::PartialPivLU<DenseMatrix> lu(Kd);
    sol = lu.solve(rhs);
    sol += lu.solve(Vector(rhs - Kd * sol));
  } else {
    K.makeCompressed();
    const std::vector<int> rowStart(K.outerIndexPtr(), K.outerIndexPtr() + n + 1);
    const std::vector<int> columns(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros());
    const std::vector<double> values(K.valuePtr(), K.valuePtr() + K.nonZeros());
    linalg::SparseLu lu;
    sol = rhs;
    if (!lu.analyze(n, rowStart, columns) || !lu.factor(values) || !lu.solve(sol))
      return std::nullopt;
    Vector correction = rhs - K * sol;
    if (lu.solve(correction)) sol += correction;
  }
  if (!sol.allFinite()) return std::nullopt;
  return sol;
}

struct LcpSolution {
  LemkeOutcome outcome;
  Vector y;
  std::vector<bool> yBasic;
  std::string rayLabel;
  bool singular = false;
};

// The dense tableau (lemke_tableau.hpp).
template <class Stop>
LcpSolution solveDense(const StandardForm& f, const ToleranceRules& rules, int maxPivots,
                       Stop stop) {
  const int m = static_cast<int>(f.q.size());
  const DenseMatrix Md(f.M);
  std::vector<double> M(static_cast<size_t>(m) * m), q(m);
  for (int i = 0; i < m; ++i) {
    q[i] = f.q[i];
    for (int j = 0; j < m; ++j) M[static_cast<size_t>(i) * m + j] = Md(i, j);
  }
  LemkeTableau<double> tab(m, M, q);
  struct Adapter {
    Stop& s;
    void pivoted(int, int, int, int) {}
    bool stop() { return s(); }
  } observer{stop};
  LcpSolution sol;
  sol.outcome = detail::runLemke(tab, rules, maxPivots, observer);
  sol.y = Vector::Zero(m);
  sol.yBasic.assign(m, false);
  for (int r = 0; r < m; ++r) {
    const int v = tab.basic(r);
    if (v >= m && v < 2 * m) {
      sol.y[v - m] = std::max(tab.rhs(r), 0.0);
      sol.yBasic[v - m] = true;
    }
  }
  if (sol.outcome.end == LemkeEnd::Ray) sol.rayLabel = tab.label(sol.outcome.entering);
  return sol;
}

// The factored basis (lemke_revised.hpp), warm from `warm` when it is a complementary basis.
LcpSolution solveRevised(const StandardForm& f, detail::RevisedLemkeSettings settings) {
  const detail::RevisedLemkeResult r = detail::revisedLemke(f.M, f.q, settings);
  LcpSolution sol;
  sol.outcome = r.outcome;
  sol.y = r.y;
  sol.yBasic = r.yBasic;
  sol.singular = r.singular;
  if (r.outcome.end == LemkeEnd::Ray && !r.singular)
    sol.rayLabel = detail::variableLabel(r.outcome.entering, static_cast<int>(f.q.size()));
  return sol;
}

// The friction passes' warm start: whether each LCP variable (original row, role) was basic at
// the end of the last pass.
class BasisMemory {
 public:
  explicit BasisMemory(int n) : state_(static_cast<size_t>(n) * kRoles, -1) {}
  void store(const StandardForm& f, const std::vector<bool>& yBasic) {
    std::fill(state_.begin(), state_.end(), -1);
    for (size_t a = 0; a < f.vars.size(); ++a) state_[key(f, a)] = yBasic[a] ? 1 : 0;
  }
  // The basis with y_a basic in position a where it was basic last time, w_a otherwise.
  std::vector<int> basis(const StandardForm& f) const {
    const int m = static_cast<int>(f.vars.size());
    std::vector<int> b(m);
    for (int a = 0; a < m; ++a) b[a] = state_[key(f, a)] == 1 ? m + a : a;
    return b;
  }

 private:
  static constexpr int kRoles = 6;
  static size_t key(const StandardForm& f, size_t a) {
    return static_cast<size_t>(f.kept[f.vars[a].row]) * kRoles + static_cast<int>(f.vars[a].role);
  }
  std::vector<signed char> state_;
};

// The largest relative move of a friction bound between two answers.
double boundsMove(const Problem& p, const Vector& before, const Vector& after) {
  double move = 0;
  for (int i = 0; i < p.size(); ++i) {
    const double a = p.effectiveHi(i, before), b = p.effectiveHi(i, after);
    if (a != b) move = std::max(move, std::abs(a - b) / (1 + std::abs(a)));
  }
  return move;
}

// A pass's boxes: the effective bounds at `current` (a friction row's: mu |x_normal| there).
void passBounds(const Problem& problem, const Vector& current, Vector& lo, Vector& hi) {
  for (int i = 0; i < problem.size(); ++i) {
    lo[i] = problem.effectiveLo(i, current);
    hi[i] = problem.effectiveHi(i, current);
  }
}

// A pass's LCP on the factored basis (from warmBasis unless it is empty) or the dense tableau.
template <class Stop>
LcpSolution solvePass(const StandardForm& f, bool revised, const ToleranceRules& rules,
                      int maxPivots, int refactorPeriod, std::vector<int> warmBasis, Stop& stop) {
  if (!revised) return solveDense(f, rules, maxPivots, stop);
  detail::RevisedLemkeSettings settings;
  settings.rules = rules;
  settings.maxPivots = maxPivots;
  settings.refactorPeriod = refactorPeriod;
  settings.stop = stop;
  settings.warmBasis = std::move(warmBasis);
  return solveRevised(f, settings);
}

// Where a pass stands, for its messages.
struct PassContext {
  int outer = 0;          // the friction iteration (1 without findex)
  bool friction = false;  // the problem has findex rows
  bool standard = false;  // the problem is a standard LCP (no change of variables)
  int pivotLimit = -1;    // for the whole solve, set by the first pass
  int m = 0;              // the pass's LCP size
  double timeBudget = 0;
};

// A pass that ended without a complementary basis (a ray, the pivot limit, the time budget):
// true with its status and message set; false when it is solved.
bool reportUnsolved(const LcpSolution& s, const PassContext& c, Result& result) {
  if (s.outcome.end == LemkeEnd::Solved) return false;  // no message to build
  std::ostringstream os;
  const std::string where = c.friction ? " in friction iteration " + std::to_string(c.outer) : "";
  const std::string lcp = c.standard ? "the LCP" : "the transformed LCP (see lemke.hpp)";
  const char* returned = c.outer > 1 ? "the last friction iteration's answer" : "the start";
  switch (s.outcome.end) {
    case LemkeEnd::Solved: return false;
    case LemkeEnd::Ray:
      result.status = Status::Failed;
      result.message = s.singular ? "the factored basis became singular after " +
                                        std::to_string(s.outcome.pivots) + " pivots" + where
                                  : detail::rayMessage(s.outcome, s.rayLabel, lcp) + where;
      return true;
    case LemkeEnd::PivotLimit:
      os << "gave up: pivot limit " << c.pivotLimit << " reached" << where
         << " (Options::maxPivots, over all friction iterations; 0 means 50 m + 100 for m = " << c.m
         << "): " << returned << " is returned";
      result.status = Status::MaxIterations;
      result.message = os.str();
      return true;
    case LemkeEnd::Stopped:
      os << "gave up when the time budget (" << c.timeBudget << " s) ran out after "
         << s.outcome.pivots << " pivots" << where << ": " << returned << " is returned";
      result.status = Status::TimeLimit;
      result.message = os.str();
      return true;
  }
  return false;
}

// The pass's answer in the original variables, replaced by the re-solve of its active set
// (resolveActiveSet) when that is finite and no less accurate; acc: the answer's accuracy.
Vector passAnswer(const Problem& problem, const SparseMatrix& A, const StandardForm& f,
                  const LcpSolution& s, const Vector& lo, bool sparse, Accuracy& acc) {
  Vector best = toOriginal(f, s.y, lo);
  acc = accuracy(problem, best);
  const std::vector<RowState> states = rowStates(f, s.yBasic, problem.size());
  if (std::optional<Vector> refined = resolveActiveSet(problem, A, states, best, sparse)) {
    const Accuracy a = accuracy(problem, *refined);
    if (a.finite && !(a.residual > acc.residual)) {
      best = std::move(*refined);
      acc = a;
    }
  }
  return best;
}

// The friction LCP's answer u polished in the original problem: its active set (a tangent row
// at a bound where its slack is positive, other rows at a bound where x sits on it) re-solved by
// resolveActiveSet with the true coupled bounds; kept only when no less accurate.
Vector polishFrictionLcp(const Problem& problem, const SparseMatrix& A,
                         const detail::BoxFrictionLcp& lcp, const Vector& u, bool sparse) {
  Vector x = lcp.toFindex(u);
  const int n = problem.size();
  std::vector<RowState> states(n, RowState::Inside);
  for (int i = 0; i < n; ++i) {
    const double lo = problem.effectiveLo(i, x), hi = problem.effectiveHi(i, x);
    const double near = 1e-12 * (1 + std::max(std::abs(lo), std::abs(hi)));
    if (x[i] <= lo + near) states[i] = RowState::AtLo;
    if (x[i] >= hi - near) states[i] = RowState::AtHi;
  }
  for (int k = 0; k < lcp.tangentRows(); ++k) {
    const int t = lcp.tangentRow(k);
    states[t] =
        !(lcp.slack(u, k) > 0) ? RowState::Inside : (x[t] >= 0 ? RowState::AtHi : RowState::AtLo);
  }
  if (std::optional<Vector> refined = resolveActiveSet(problem, A, states, x, sparse))
    if (!(residual(problem, *refined) > residual(problem, x))) return std::move(*refined);
  return x;
}

}  // namespace

void LemkeSolver::run(const Problem& problem, Vector& x, Result& result) {
  const int n = problem.size();
  result.iterations = 0;
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  if (n > maxRows) {
    std::ostringstream os;
    os << "lemke for " << n << " rows exceeds LemkeSolver::maxRows = " << maxRows
       << "; use dantzig or pgs";
    result.status = Status::Unsupported;
    result.message = os.str();
    return;
  }
  SparseMatrix A = problem.toSparse();
  A.makeCompressed();
  const Vector start = x;
  pivot(problem, A, x, result);
  if (result.status != Status::Failed) return;
  // A ray on a singular A (redundant joints): once more from the start on A + delta I, the
  // answer measured on A; the better of the two stands.
  double diag = 0;
  for (int i = 0; i < n; ++i) diag = std::max(diag, std::abs(problem.diagonal(i)));
  const double delta = kLemkeRayShift * std::max(1.0, diag);
  SparseMatrix I(n, n);
  I.setIdentity();
  A = A + delta * I;
  A.makeCompressed();
  Vector again = start;
  Result second = result;
  second.iterations = 0;
  pivot(problem, A, again, second);
  const int pivots = result.iterations + second.iterations;
  std::ostringstream os;
  if (second.status == Status::Converged || residual(problem, again) < residual(problem, x)) {
    os << "regularised: A + " << delta << " I after a ray (" << result.message << "); "
       << second.message;
    result = std::move(second);
    x = std::move(again);
  } else {
    os << result.message;  // an infeasible problem: the ray stands
  }
  result.iterations = pivots;
  result.message = os.str();
}

void LemkeSolver::pivot(const Problem& problem, const SparseMatrix& A, Vector& x, Result& result) {
  if (!frictionLcp || !problem.hasFindex()) return pivotPasses(problem, A, x, result, denseRows);
  detail::BoxFrictionLcp lcp;
  if (const std::string refused = lcp.build(problem, A); !refused.empty()) {
    pivotPasses(problem, A, x, result, denseRows);
    result.message += " (friction by the fixed point: " + refused + ")";
    return;
  }
  const Problem& p = lcp.problem();
  const int m = p.size();
  Vector u = Vector::Zero(m);
  const bool factored =
      m > denseRows && (!hasFreeRows(p.lo, p.hi) || m > kLemkeFreeRowsTableauRows);
  pivotPasses(p, p.sparseA(), u, result, denseRows, factored ? kFrictionLcpPivotScale : 1);
  std::ostringstream os;
  os << "friction as one LCP (" << lcp.tangentRows() << " tangent rows as l+ - l-, " << m
     << " rows): ";
  const double tolerance = options().tolerance;
  bool solved = result.status == Status::Converged;
  // A ray, or z0 out of the basis at values that are not the answer; the pivot limit and the
  // time budget end the solve.
  auto endedShort = [&](bool solvedNow, const Vector& answer) {
    return result.status != Status::MaxIterations && result.status != Status::TimeLimit &&
           (!solvedNow || !(residual(problem, answer) <= tolerance));
  };
  if (factored && m <= kLemkeFrictionTableauRows && endedShort(solved, lcp.toFindex(u))) {
    // The factored basis's ratio tests on a singular A can follow round-off into a basis whose
    // values are not the answer (docs/decisions.md): once more on the dense tableau, within the
    // same pivot limit.
    Vector again = Vector::Zero(m);
    Result dense = result;
    pivotPasses(p, p.sparseA(), again, dense, m);
    if (dense.status == Status::Converged &&
        (!solved || residual(problem, lcp.toFindex(again)) < residual(problem, lcp.toFindex(u)))) {
      os << "the factored basis ended with " << result.message << "; on the dense tableau: ";
      u = std::move(again);
      result = std::move(dense);
      solved = true;
    }
    result.iterations = dense.iterations;
  }
  result.message = os.str() + result.message;
  // Unsolved (a ray, the pivot limit, the time budget): the start stands.
  const Vector start = x;
  if (solved) x = polishFrictionLcp(problem, A, lcp, u, problem.size() > denseRows);
  if (!endedShort(solved, x)) return;
  // Ended short (a ray, the pivot limit, an inaccurate basis): the fixed point from the same
  // start, within what is left of the pivot limit; the more accurate answer stands.
  Vector passes = start;
  Result second = result;
  pivotPasses(problem, A, passes, second, denseRows);
  const double before = solved ? residual(problem, x) : residual(problem, start);
  if (second.status == Status::Converged || residual(problem, passes) < before) {
    second.message = result.message + "; then the fixed point: " + second.message;
    result = std::move(second);
    x = std::move(passes);
  } else {
    result.message += "; the fixed point after it did no better (" + second.message + ")";
    result.iterations = second.iterations;
    // Its pivot limit or the time budget ends the whole solve; otherwise the solve failed on A
    // and runs once more on A + delta I (run()).
    const bool spent = second.status == Status::MaxIterations || second.status == Status::TimeLimit;
    result.status = spent ? second.status : Status::Failed;
  }
}

void LemkeSolver::pivotPasses(const Problem& problem, const SparseMatrix& A, Vector& x,
                              Result& result, int tableauRows, double pivotScale) {
  const Options& opt = options();
  const int n = problem.size();
  const bool friction = problem.hasFindex();
  // Free rows keep the tableau (its Schur elimination, see lemke.hpp) up to
  // kLemkeFreeRowsTableauRows.
  const bool revised =
      n > tableauRows && (!hasFreeRows(problem.lo, problem.hi) || n > kLemkeFreeRowsTableauRows);
  const int outerLimit = friction ? std::max(1, opt.maxIterations) : 1;
  ToleranceRules rules;
  rules.pivotTolerance = opt.pivotTolerance * pivotScale;
  // A tableau pivot costs O(m^2) with m >= n, a factored one at least O(m): the clock is read
  // once per ~4096 / n^2 (tableau) or 4096 / n (factored) pivots, at most ~2% of their cost.
  const int clockEvery = std::max(1, 4096 / std::max(1, revised ? n : n * n));
  int sinceClock = 0;
  auto stop = [&] {
    if (opt.timeBudget <= 0 || ++sinceClock < clockEvery) return false;
    sinceClock = 0;
    return outOfTime();
  };

  Vector current = x;  // seeds the friction bounds
  BasisMemory memory(revised && friction ? n : 0);
  // The pivot limit bounds the whole solve, the friction passes together: a pass that does not
  // settle the bounds cannot buy another full limit (docs/benchmarks.md, "lemke: dense tableau
  // against the factored basis", the findex contact problems).
  PassContext pass;
  pass.friction = friction;
  pass.standard = problem.classify() == ProblemClass::StandardLcp;
  pass.timeBudget = opt.timeBudget;
  double lastMove = 0;
  for (int outer = 1; outer <= outerLimit; ++outer) {
    Vector lo(n), hi(n);
    passBounds(problem, current, lo, hi);
    const StandardForm f = toStandard(A, problem.b, lo, hi, !revised);
    pass.outer = outer;
    pass.m = static_cast<int>(f.q.size());
    if (pass.pivotLimit < 0)
      pass.pivotLimit = opt.maxPivots > 0 ? opt.maxPivots : 50 * pass.m + 100;
    const int maxPivots = std::max(1, pass.pivotLimit - result.iterations);
    // Passes after the first start from the last pass's basis on the factored path.
    std::vector<int> warm = revised && outer > 1 ? memory.basis(f) : std::vector<int>();
    const LcpSolution s =
        solvePass(f, revised, rules, maxPivots, refactorPeriod, std::move(warm), stop);
    result.iterations += s.outcome.pivots;
    if (reportUnsolved(s, pass, result)) return;

    Accuracy acc;
    const Vector best = passAnswer(problem, A, f, s, lo, revised, acc);
    x = best;
    if (!friction || acc.residual <= opt.tolerance) {
      result.status = Status::Converged;  // the message without a stream: a solve's usual end
      result.message = "z0 left the basis after " + std::to_string(result.iterations) + " pivots";
      if (friction) result.message += " (" + std::to_string(outer) + " friction iterations)";
      return;
    }
    lastMove = boundsMove(problem, current, best);
    if (!(lastMove > 1e-15)) {
      std::ostringstream os;
      os << "the friction bounds reached a fixed point with residual " << acc.residual
         << " above the tolerance";
      result.status = Status::Failed;
      result.message = os.str();
      return;
    }
    if (revised) memory.store(f, s.yBasic);
    current = best;
  }
  std::ostringstream os;
  os << "friction bounds still moving after " << outerLimit
     << " outer iterations (Options::maxIterations; the last moved a bound by " << lastMove
     << " relative)";
  result.status = Status::MaxIterations;
  result.message = os.str();
}

}  // namespace mlcp
