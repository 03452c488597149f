#include "dantzig_block.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::detail {

namespace {
bool isFriction(const Problem& pb, int i) { return !pb.findex.empty() && pb.findex[i] >= 0; }
double signOf(double v) { return v < 0 ? -1.0 : 1.0; }
// The value a non-clamped, uncoupled row is held at.
double heldValue(double lo, double hi, bool atHi) { return atHi ? hi : lo; }
}  // namespace

double BlockPivoting::frictionBound(const Problem& pb, int t, Set s, const Vector& x) const {
  return (s == Set::AtHi ? pb.hi[t] : pb.lo[t]) * std::abs(x[pb.findex[t]]);
}

// The first index sets. Cold: every row clamped (the Newton step of the linear system A x = -b).
// Warm: from the natural map at the guess, z = x0 - w0 against the bounds at x0 (lo' when
// z <= lo', hi' when z >= hi', clamped between), which is right for a guess that solves a
// nearby problem even where it holds rows only close to their bounds.
void BlockPivoting::guess(const Problem& pb, const Vector& x0, bool cold) {
  const int n = pb.size();
  Vector w0;
  if (!cold) w0 = *a_ * x0 + pb.b;
  set_.assign(n, Set::Clamped);
  auto place = [&](int i, double lo, double hi) {
    if (cold) return;
    const double z = x0[i] - w0[i];
    set_[i] = z <= lo ? Set::AtLo : z >= hi ? Set::AtHi : Set::Clamped;
  };
  for (int i = 0; i < n; ++i) {
    if (isFriction(pb, i)) continue;
    if (pb.lo[i] == pb.hi[i])
      set_[i] = Set::Fixed;
    else
      place(i, pb.lo[i], pb.hi[i]);
  }
  for (int t = 0; t < n; ++t) {
    if (!isFriction(pb, t)) continue;
    const int j = pb.findex[t];
    const bool normalZero =
        set_[j] != Set::Clamped && heldValue(pb.lo[j], pb.hi[j], set_[j] == Set::AtHi) == 0;
    if (normalZero || pb.lo[t] == pb.hi[t])
      set_[t] = Set::Fixed;
    else
      place(t, frictionBound(pb, t, Set::AtLo, x0), frictionBound(pb, t, Set::AtHi, x0));
  }
}

// Sets x to the solution of the linear equations of the current index sets:
//   clamped rows:         (A x + b)_i = 0
//   uncoupled at a bound: x_i = lo_i or hi_i
//   friction at a bound:  x_t = mu_t s_j x_j (s_j = sign of the normal, mu_t = lo_t or hi_t)
// Substituting the sliding rows (normal clamped) gives K y = r with K = A_CC + U V^T, U the
// sliding columns scaled by their coefficients, V selecting their normals; A_CC is factored
// (sparse LDL^T in a fill-reducing order of A) and the rank-|T| term is handled by Woodbury.
bool BlockPivoting::solveClamped(const Problem& pb, Vector& x, std::string& why) {
  const int n = pb.size();
  const SparseMatrix& A = *a_;
  order_.clear();
  for (int k = 0; k < n; ++k) {
    const int i = byRank_[k];
    pos_[i] = set_[i] == Set::Clamped ? static_cast<int>(order_.size()) : -1;
    if (pos_[i] >= 0) order_.push_back(i);
  }
  for (int i = 0; i < n; ++i) {
    if (isFriction(pb, i)) continue;
    x[i] = set_[i] == Set::Clamped ? 0.0 : heldValue(pb.lo[i], pb.hi[i], set_[i] == Set::AtHi);
  }
  sliding_.clear();
  coeff_.clear();
  for (int t = 0; t < n; ++t) {
    if (!isFriction(pb, t)) continue;
    const int j = pb.findex[t];
    const double c = (set_[t] == Set::AtHi ? pb.hi[t] : pb.lo[t]) * signOf(x[j]);
    x[t] = 0;
    if (set_[t] != Set::AtLo && set_[t] != Set::AtHi) continue;
    if (set_[j] == Set::Clamped) {
      sliding_.push_back(t);
      coeff_.push_back(c);
    } else {
      x[t] = c * x[j];
    }
  }
  for (int i : order_) x[i] = 0;

  const int m = static_cast<int>(order_.size());
  Vector r(m);
  for (int c = 0; c < m; ++c) r[c] = -(pb.b[order_[c]] + A.row(order_[c]).dot(x));
  // The upper triangle of A_CC, column by column in the order of byRank_.
  K_.resize(m, m);
  std::vector<std::pair<int, double>> column;
  std::vector<int> outer(m + 1, 0), inner;
  std::vector<double> values;
  for (int c = 0; c < m; ++c) {
    column.clear();
    for (SparseMatrix::InnerIterator it(A, order_[c]); it; ++it) {
      const int q = pos_[it.index()];
      if (q >= 0 && q <= c) column.emplace_back(q, it.value());
    }
    std::sort(column.begin(), column.end());
    for (const auto& [q, v] : column) {
      inner.push_back(q);
      values.push_back(v);
    }
    outer[c + 1] = static_cast<int>(inner.size());
  }
  K_.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), K_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), K_.innerIndexPtr());
  std::copy(values.begin(), values.end(), K_.valuePtr());

  if (m > 0) {
    if (!kPattern_.same(K_)) {
      ldlt_.analyzePattern(K_);
      kPattern_.remember(K_);
    }
    ldlt_.factorize(K_);
    if (ldlt_.info() != Eigen::Success || !(ldlt_.vectorD().cwiseAbs().minCoeff() > pivTol_)) {
      why = "the clamped block is singular";
      return false;
    }
  }
  const int s = static_cast<int>(sliding_.size());
  if (s > 0 && m > 0) {
    DenseMatrix U = DenseMatrix::Zero(m, s);
    for (int k = 0; k < s; ++k)
      for (SparseMatrix::InnerIterator it(A, sliding_[k]); it; ++it)
        if (pos_[it.index()] >= 0) U(pos_[it.index()], k) = coeff_[k] * it.value();
    Z_ = ldlt_.solve(U);
    DenseMatrix S = DenseMatrix::Identity(s, s);
    for (int k = 0; k < s; ++k) S.row(k) += Z_.row(pos_[pb.findex[sliding_[k]]]);
    capacitance_.compute(S);
  }
  auto place = [&](const Vector& y, bool add) {
    for (int c = 0; c < m; ++c) x[order_[c]] = (add ? x[order_[c]] : 0.0) + y[c];
    for (int k = 0; k < s; ++k) x[sliding_[k]] = coeff_[k] * x[pb.findex[sliding_[k]]];
  };
  if (m == 0) return true;
  Vector y = r;
  applyWoodbury(y);
  place(y, false);
  // One step of iterative refinement: the clamped rows' w is the residual of K y = r.
  for (int c = 0; c < m; ++c) y[c] = -(pb.b[order_[c]] + A.row(order_[c]).dot(x));
  applyWoodbury(y);
  place(y, true);
  if (!x.allFinite()) {
    why = "the clamped system with its sliding rows is singular";
    return false;
  }
  return true;
}

void BlockPivoting::applyWoodbury(Vector& y) const {
  y = ldlt_.solve(y);
  const int s = static_cast<int>(sliding_.size());
  if (s == 0) return;
  Vector v(s);
  for (int k = 0; k < s; ++k) v[k] = y[pos_[problemFindex_[sliding_[k]]]];
  y -= Z_ * capacitance_.solve(v);
}

// Index sets of the next step at x (w = A x + b): a clamped row outside its bounds (friction
// bounds at x) goes to the bound it crossed, a row at a bound whose w has the wrong sign
// becomes clamped; both only beyond eps_, so that degenerate rows (x at a bound and w = 0 up
// to rounding) do not flip back and forth. Friction rows whose normal is held at 0 are fixed
// at 0, and clamped when it comes back. Returns the number of rows that changed set.
int BlockPivoting::setsAt(const Problem& pb, const Vector& x, const Vector& w) {
  const int n = pb.size();
  int changed = 0;
  auto move = [&](int i, double lo, double hi) {
    const Set old = set_[i];
    switch (old) {
      case Set::Clamped:
        if (x[i] < lo - eps_) set_[i] = Set::AtLo;
        if (x[i] > hi + eps_) set_[i] = Set::AtHi;
        break;
      case Set::AtLo:
        if (w[i] < -eps_) set_[i] = Set::Clamped;
        break;
      case Set::AtHi:
        if (w[i] > eps_) set_[i] = Set::Clamped;
        break;
      case Set::Fixed: set_[i] = Set::Clamped; break;
    }
    changed += set_[i] != old;
  };
  for (int i = 0; i < n; ++i)
    if (!isFriction(pb, i) && set_[i] != Set::Fixed) move(i, pb.lo[i], pb.hi[i]);
  for (int t = 0; t < n; ++t) {
    if (!isFriction(pb, t) || pb.lo[t] == pb.hi[t]) continue;
    const int j = pb.findex[t];
    if (set_[j] != Set::Clamped && heldValue(pb.lo[j], pb.hi[j], set_[j] == Set::AtHi) == 0) {
      changed += set_[t] != Set::Fixed;
      set_[t] = Set::Fixed;
      continue;
    }
    move(t, frictionBound(pb, t, Set::AtLo, x), frictionBound(pb, t, Set::AtHi, x));
  }
  return changed;
}

BlockPivoting::Report BlockPivoting::run(const Problem& pb, Vector& x, const Options& opt,
                                         int maxSteps) {
  Report rep;
  const int n = pb.size();
  if (pb.isSparse()) {
    a_ = &pb.sparseA();
  } else {
    A_ = pb.toSparse();
    a_ = &A_;
  }
  if (!isSymmetric(*a_)) {
    rep.message = "A is not symmetric";
    return rep;
  }
  problemFindex_ = pb.findex.empty() ? std::vector<int>(n, -1) : pb.findex;
  // A fill-reducing order of all of A; every clamped block is factored in the induced order,
  // whose fill is at most A's, so the ordering is computed once per pattern of A.
  if (!aPattern_.same(*a_)) {
    const ColMajor pattern = *a_;
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::AMDOrdering<int>()(pattern, perm);
    byRank_.assign(perm.indices().data(), perm.indices().data() + n);
    aPattern_.remember(*a_);
  }
  double dMax = 0;
  for (int i = 0; i < n; ++i) dMax = std::max(dMax, std::abs(pb.diagonal(i)));
  pivTol_ = opt.pivotTolerance * (dMax > 0 ? dMax : 1.0);
  eps_ = 0.01 * opt.tolerance * (1 + pb.b.lpNorm<Eigen::Infinity>());
  pos_.assign(n, -1);
  const bool cold = x.isZero(0.0);
  guess(pb, x, cold);

  // Full Newton (block principal pivoting) steps: the point that solves the equations of the
  // current sets, then the sets at that point. Near the answer one step settles it; far from
  // it the sets may oscillate, so the stage stops after `patience` steps that did not reduce
  // the number of rows that changed set, and hands over the iterate with the fewest changes.
  constexpr int patience = 2;
  int best = INT_MAX, stalled = 0;
  Vector w = *a_ * x + pb.b, bestX = x;
  const double start = nowSeconds();
  std::ostringstream os;
  for (;;) {
    const double res = accuracy(pb, x, w).residual;
    if (res <= opt.tolerance) {
      rep.settled = true;
      os << "block pivoting settled after " << rep.steps << " step" << (rep.steps != 1 ? "s" : "");
      break;
    }
    if (rep.steps >= maxSteps || stalled >= patience) {
      os << "residual " << res << " after " << rep.steps << " block steps";
      x = bestX;
      break;
    }
    if (opt.timeBudget > 0 && nowSeconds() - start > opt.timeBudget) {
      os << "time budget spent after " << rep.steps << " block steps";
      x = bestX;
      break;
    }
    const int changed = rep.steps > 0 ? setsAt(pb, x, w) : 0;
    if (rep.steps > 0) {
      if (changed < best) {
        best = changed;
        bestX = x;
        stalled = 0;
      } else {
        ++stalled;
      }
    }
    ++rep.steps;
    std::string why;
    if (!solveClamped(pb, x, why)) {
      os << why << " (block step " << rep.steps << ")";
      x = bestX;
      break;
    }
    w.noalias() = *a_ * x;
    w += pb.b;
  }
  rep.message = os.str();
  return rep;
}

}  // namespace mlcp::detail
