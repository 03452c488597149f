#include "mlcp/lemke.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "lemke_tableau.hpp"
#include "mlcp/residual.hpp"

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

// A boxed problem without findex written as the standard LCP w = M y + q (lemke.hpp).
struct StandardForm {
  std::vector<int> fixed, eliminated, kept;  // original row indices
  std::vector<bool> split;                   // per kept row: a free row split as z+ - z-
  DenseMatrix G;                             // x_eliminated = G x_kept + g
  Vector g;
  std::vector<LcpVar> vars;
  Vector offset;  // x_kept = offset + sum_a sign_a y_a
  DenseMatrix M;
  Vector q;
};

bool isFree(double lo, double hi) { return lo == -kInf && hi == kInf; }

// Relative width below which a box [lo, hi] is treated as the point lo (see toStandard).
constexpr double kNarrowBox = 1e-13;

StandardForm toStandard(const DenseMatrix& A, const Vector& b, const Vector& lo, const Vector& hi) {
  StandardForm f;
  const int n = static_cast<int>(b.size());
  // Boxes narrower than round-off relative to the scale of x (the largest finite bound, or
  // ||b|| / max|A_ij|) count as fixed: friction bounds from a normal value of 1e-30 would
  // otherwise be ratio-test ties that noise decides (it led to false rays).
  const double aMax = A.size() ? A.cwiseAbs().maxCoeff() : 0.0;
  double xScale = aMax > 0 ? b.lpNorm<Eigen::Infinity>() / aMax : 0.0;
  for (int i = 0; i < n; ++i)
    for (double v : {lo[i], hi[i]})
      if (std::isfinite(v)) xScale = std::max(xScale, std::abs(v));
  const double narrow = kNarrowBox * xScale;
  std::vector<int> freeRows;
  for (int i = 0; i < n; ++i) {
    if (hi[i] - lo[i] <= narrow)
      f.fixed.push_back(i);
    else if (isFree(lo[i], hi[i]))
      freeRows.push_back(i);
    else
      f.kept.push_back(i);
  }
  Vector b1 = b;
  for (int i : f.fixed) b1 += A.col(i) * lo[i];

  DenseMatrix Ar;
  Vector br;
  bool eliminate = false;
  if (!freeRows.empty()) {
    Eigen::FullPivLU<DenseMatrix> lu(A(freeRows, freeRows));
    eliminate = lu.isInvertible() && lu.rcond() > 1e-13;
    if (eliminate) {
      f.eliminated = freeRows;
      // (Eigen's solve binds a null pointer for a right-hand side with no columns.)
      f.G = f.kept.empty() ? DenseMatrix(freeRows.size(), 0)
                           : DenseMatrix(-lu.solve(DenseMatrix(A(freeRows, f.kept))));
      f.g = -lu.solve(Vector(b1(freeRows)));
      Ar = A(f.kept, f.kept) + A(f.kept, freeRows) * f.G;
      br = b1(f.kept) + A(f.kept, freeRows) * f.g;
    }
  }
  if (!eliminate) {
    // Singular A_FF: the free rows stay and are split, x = z+ - z-.
    f.kept.insert(f.kept.end(), freeRows.begin(), freeRows.end());
    std::sort(f.kept.begin(), f.kept.end());
    Ar = A(f.kept, f.kept);
    br = b1(f.kept);
  }

  const int k = static_cast<int>(f.kept.size());
  f.offset = Vector::Zero(k);
  f.split.assign(k, false);
  for (int r = 0; r < k; ++r) {
    const int i = f.kept[r];
    if (isFree(lo[i], hi[i])) {
      f.split[r] = true;
      f.vars.push_back({r, Role::FreePlus});
      f.vars.push_back({r, Role::FreeMinus});
    } else if (hi[i] == kInf) {
      f.offset[r] = lo[i];
      f.vars.push_back({r, Role::Lower});
    } else if (lo[i] == -kInf) {
      f.offset[r] = hi[i];
      f.vars.push_back({r, Role::Upper});
    } else {
      f.offset[r] = lo[i];
      f.vars.push_back({r, Role::BoxX});
      f.vars.push_back({r, Role::BoxW});
    }
  }

  const int m = static_cast<int>(f.vars.size());
  const Vector w0 = Ar * f.offset + br;  // w of the reduced problem at y = 0
  f.M = DenseMatrix::Zero(m, m);
  f.q.resize(m);
  for (int a = 0; a < m; ++a) {
    const LcpVar& va = f.vars[a];
    const double sa = sign(va.role);
    for (int c = 0; c < m; ++c) f.M(a, c) = sa * Ar(va.row, f.vars[c].row) * sign(f.vars[c].role);
    f.q[a] = sa * w0[va.row];
    // BoxX and BoxW are adjacent: BoxX's row is w + z2, BoxW's row is hi - lo - z1.
    if (va.role == Role::BoxX) f.M(a, a + 1) = 1;
    if (va.role == Role::BoxW) {
      const int i = f.kept[va.row];
      f.M(a, a - 1) = -1;
      f.q[a] = hi[i] - lo[i];
    }
  }
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
// (the true coupled bound, x being the current answer). LU with partial pivoting plus one step
// of iterative refinement. Empty when the system is singular.
std::optional<Vector> resolveActiveSet(const Problem& p, const DenseMatrix& A,
                                       const std::vector<RowState>& states, const Vector& x) {
  const int n = p.size();
  DenseMatrix K = DenseMatrix::Zero(n, n);
  Vector rhs(n);
  for (int i = 0; i < n; ++i) {
    if (states[i] == RowState::Inside) {
      K.row(i) = A.row(i);
      rhs[i] = -p.b[i];
      continue;
    }
    const double bound = states[i] == RowState::AtLo ? p.lo[i] : p.hi[i];
    K(i, i) = 1;
    const int j = p.findex.empty() ? -1 : p.findex[i];
    if (j < 0) {
      rhs[i] = bound;
    } else {
      const double s = x[j] > 0 ? 1 : (x[j] < 0 ? -1 : 0);
      K(i, j) -= bound * s;
      rhs[i] = 0;
    }
  }
  Eigen::PartialPivLU<DenseMatrix> lu(K);
  Vector sol = lu.solve(rhs);
  sol += lu.solve(Vector(rhs - K * sol));
  if (!sol.allFinite()) return std::nullopt;
  return sol;
}

struct LcpSolution {
  LemkeOutcome outcome;
  Vector y;
  std::vector<bool> yBasic;
  std::string rayLabel;
};

template <class Stop>
LcpSolution solveLcp(const StandardForm& f, const ToleranceRules& rules, int maxPivots, Stop stop) {
  const int m = static_cast<int>(f.q.size());
  std::vector<double> M(static_cast<size_t>(m) * m), q(m);
  for (int i = 0; i < m; ++i) {
    q[i] = f.q[i];
    for (int j = 0; j < m; ++j) M[static_cast<size_t>(i) * m + j] = f.M(i, j);
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

// The retry of a ray adds kRegularization * max(1, max |A_ii|) to A's diagonal: Bullet's bridge
// of planks joined by two ball joints each (a singular A, its rows' drift ~1e-8 of b) ends in a
// spurious ray on A and solves in a few pivots on A + 1e-12 max |A_ii| I, leaving ~5e-11 on A.
constexpr double kRegularization = 1e-12;

bool boundsMoved(const Problem& p, const Vector& before, const Vector& after, double tol) {
  for (int i = 0; i < p.size(); ++i) {
    const double a = p.effectiveHi(i, before), b = p.effectiveHi(i, after);
    if (std::abs(a - b) > tol * (1 + std::abs(a))) return true;
  }
  return false;
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
    os << "lemke's dense tableau for " << n << " rows (up to " << 2 * n << " x " << 4 * n + 2
       << " doubles) exceeds LemkeSolver::maxRows = " << maxRows << "; use dantzig or pgs";
    result.status = Status::Unsupported;
    result.message = os.str();
    return;
  }
  DenseMatrix A = problem.toDense();
  const Vector start = x;
  pivot(problem, A, x, result);
  if (result.status != Status::Failed) return;
  // A ray on a singular A (redundant joints): once more from the start on A + delta I, the
  // answer measured on A; the better of the two stands.
  const double delta = kRegularization * std::max(1.0, A.diagonal().cwiseAbs().maxCoeff());
  A.diagonal().array() += delta;
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

void LemkeSolver::pivot(const Problem& problem, const DenseMatrix& A, Vector& x, Result& result) {
  const Options& opt = options();
  const int n = problem.size();
  const bool friction = problem.hasFindex();
  const bool standard = problem.classify() == ProblemClass::StandardLcp;
  const int outerLimit = friction ? std::max(1, opt.maxIterations) : 1;
  ToleranceRules rules;
  rules.pivotTolerance = opt.pivotTolerance;
  // A pivot costs O(m^2) with m >= n: the clock is read once per ~4096 / n^2 pivots (at most ~2%
  // of the pivoting's cost).
  const int clockEvery = std::max(1, 4096 / std::max(1, n * n));
  int sinceClock = 0;
  auto stop = [&] {
    if (opt.timeBudget <= 0 || ++sinceClock < clockEvery) return false;
    sinceClock = 0;
    return outOfTime();
  };

  Vector current = x;  // seeds the friction bounds
  // The pivot limit bounds the whole solve, the friction passes together: a pass that does not
  // settle the bounds cannot buy another full limit (50 m + 100 pivots a pass times 1000 passes
  // ran for minutes on a 600-row contact problem).
  int pivotLimit = -1;
  for (int outer = 1; outer <= outerLimit; ++outer) {
    Vector lo(n), hi(n);
    for (int i = 0; i < n; ++i) {
      lo[i] = problem.effectiveLo(i, current);
      hi[i] = problem.effectiveHi(i, current);
    }
    const StandardForm f = toStandard(A, problem.b, lo, hi);
    const int m = static_cast<int>(f.q.size());
    if (pivotLimit < 0) pivotLimit = opt.maxPivots > 0 ? opt.maxPivots : 50 * m + 100;
    const int maxPivots = pivotLimit - result.iterations;
    const LcpSolution s = solveLcp(f, rules, std::max(1, maxPivots), stop);
    result.iterations += s.outcome.pivots;

    std::ostringstream os;
    const std::string where = friction ? " in friction iteration " + std::to_string(outer) : "";
    const std::string lcp = standard ? "the LCP" : "the transformed LCP (see lemke.hpp)";
    switch (s.outcome.end) {
      case LemkeEnd::Solved: break;
      case LemkeEnd::Ray:
        result.status = Status::Failed;
        result.message = detail::rayMessage(s.outcome, s.rayLabel, lcp) + where;
        return;
      case LemkeEnd::PivotLimit:
        os << "gave up: pivot limit " << pivotLimit << " reached" << where
           << " (Options::maxPivots, over all friction iterations; 0 means 50 m + 100 for m = " << m
           << "): " << (outer > 1 ? "the last friction iteration's answer" : "the start")
           << " is returned";
        result.status = Status::MaxIterations;
        result.message = os.str();
        return;
      case LemkeEnd::Stopped:
        os << "gave up when the time budget (" << opt.timeBudget << " s) ran out after "
           << s.outcome.pivots << " pivots" << where << ": "
           << (outer > 1 ? "the last friction iteration's answer" : "the start") << " is returned";
        result.status = Status::TimeLimit;
        result.message = os.str();
        return;
    }

    Vector best = toOriginal(f, s.y, lo);
    Accuracy acc = accuracy(problem, best);
    const std::vector<RowState> states = rowStates(f, s.yBasic, n);
    if (std::optional<Vector> refined = resolveActiveSet(problem, A, states, best)) {
      const Accuracy a = accuracy(problem, *refined);
      if (a.finite && !(a.residual > acc.residual)) {
        best = std::move(*refined);
        acc = a;
      }
    }
    x = best;
    if (!friction || acc.residual <= opt.tolerance) {
      result.status = Status::Converged;
      os << "z0 left the basis after " << result.iterations << " pivots";
      if (friction) os << " (" << outer << " friction iterations)";
      result.message = os.str();
      return;
    }
    if (!boundsMoved(problem, current, best, 1e-15)) {
      os << "the friction bounds reached a fixed point with residual " << acc.residual
         << " above the tolerance";
      result.status = Status::Failed;
      result.message = os.str();
      return;
    }
    current = best;
  }
  std::ostringstream os;
  os << "friction bounds still moving after " << outerLimit
     << " outer iterations (Options::maxIterations)";
  result.status = Status::MaxIterations;
  result.message = os.str();
}

}  // namespace mlcp
