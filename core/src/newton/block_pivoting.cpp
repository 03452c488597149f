#include "newton/block_pivoting.hpp"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "linalg/body_space.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::detail {

namespace {
constexpr double kMinStep = 1.0 / 1024;  // shortest line-search step before the stage gives up
// Proximal weight of a Newton step, times max |A_ii| and min(1, ||H||): damps the null-space
// part of nearly singular clamped blocks far from the answer, vanishes near it.
constexpr double kProximal = 1e-2;
constexpr int kUphill = 2;  // full steps in a row taken without descent before handing over
// A guess's row within this fraction of its bound counts as at the bound (guess() with atGuess):
// an engine hands a sliding friction row's last answer back rotated onto the new friction
// direction, a relative change of the order of the rotation squared.
constexpr double kAtBound = 1e-6;
bool isFriction(const Problem& pb, int i) { return !pb.findex.empty() && pb.findex[i] >= 0; }
double signOf(double v) { return v < 0 ? -1.0 : 1.0; }
// The value a non-clamped, uncoupled row is held at.
double heldValue(double lo, double hi, bool atHi) { return atHi ? hi : lo; }
// Appends to a sparse column list (idx, val, start) row `row` of A restricted to the base set
// (basePos), scaled (a column of G or H in buildCapacitance).
void pushColumn(const SparseMatrix& A, const std::vector<int>& basePos, std::vector<int>& idx,
                std::vector<double>& val, std::vector<int>& start, int row, double scale) {
  for (SparseMatrix::InnerIterator it(A, row); it; ++it)
    if (basePos[it.index()] >= 0) {
      idx.push_back(basePos[it.index()]);
      val.push_back(scale * it.value());
    }
  start.push_back(static_cast<int>(idx.size()));
}
// Appends the column with the single entry v at `at` (empty when at < 0).
void pushUnit(std::vector<int>& idx, std::vector<double>& val, std::vector<int>& start, int at,
              double v) {
  if (at >= 0) {
    idx.push_back(at);
    val.push_back(v);
  }
  start.push_back(static_cast<int>(idx.size()));
}
}  // namespace

BlockPivoting::BlockPivoting() : body_(std::make_unique<BodySpaceSystem>()) {}
BlockPivoting::~BlockPivoting() = default;

// ||H(x)||^2 with H_i = x_i - clamp(x_i - w_i, lo'_i, hi'_i): zero exactly at a solution.
double BlockPivoting::meritAt(const Problem& pb, const Vector& x, const Vector& w) const {
  double sum = 0;
  for (int i = 0; i < pb.size(); ++i) {
    const double lo = pb.effectiveLo(i, x), hi = pb.effectiveHi(i, x);
    const double h = x[i] - std::clamp(x[i] - w[i], lo, hi);
    sum += h * h;
  }
  return sum;
}

double BlockPivoting::frictionBound(const Problem& pb, int t, Set s, const Vector& x) const {
  return (s == Set::AtHi ? pb.hi[t] : pb.lo[t]) * std::abs(x[pb.findex[t]]);
}

// The first index sets. Cold: every row clamped (the Newton step of the linear system A x = -b).
// Warm: from the natural map at the guess (w0 = A x0 + b), z = x0 - w0 against the bounds at x0
// (lo' when z <= lo', hi' when z >= hi', clamped between), which is right for a guess that solves a
// nearby problem even where it holds rows only close to their bounds. atGuess: where x0 lies
// instead (a row at a bound, within kAtBound of it, held there; the others clamped), which is right
// for a guess that is the last answer of a slowly changing problem whose w0 is as small as x0's
// changes.
void BlockPivoting::guess(const Problem& pb, const Vector& x0, const Vector& w0, bool cold,
                          bool atGuess) {
  const int n = pb.size();
  set_.assign(n, Set::Clamped);
  auto place = [&](int i, double lo, double hi) {
    if (cold) return;
    if (atGuess) {
      set_[i] = x0[i] <= lo + kAtBound * std::abs(lo)   ? Set::AtLo
                : x0[i] >= hi - kAtBound * std::abs(hi) ? Set::AtHi
                                                        : Set::Clamped;
      return;
    }
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

// The index sets' unknowns: order_ (the clamped rows in the fill-reducing order), pos_, and the
// sliding rows with their coefficients (sliding_, coeff_); x takes the held values, zero on the
// clamped and sliding rows, and x_t = c_t x_j on a friction row held with its normal.
void BlockPivoting::gatherSets(const Problem& pb, Vector& x) {
  const int n = pb.size();
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
}

// The factor of the current sets' K: in body space when it applies (a fresh factor there costs
// less than reusing one here, so no base is kept then); with many sliding rows the LU of K;
// otherwise the base factor bordered by the changes (buildCapacitance), or a new base.
bool BlockPivoting::factorClamped(const Problem& pb, double rho, std::string& why) {
  const int m = static_cast<int>(order_.size());
  const int s = static_cast<int>(sliding_.size());
  useLu_ = s > limits_.pivotingWoodburyRows && m > 0;
  useBody_ = false;
  if (m == 0) return true;
  if (bodyReady_) {
    useBody_ = body_->factor(order_, pos_, sliding_, coeff_, problemFindex_, rho,
                             kBodyMinDiagonal * dMax_);
    if (useBody_) {
      haveBase_ = false;
      ++factorizations_;
      ++bodyFactorizations_;
      return true;
    }
  }
  if (useLu_) {
    haveBase_ = false;
    ++factorizations_;
    return factorCoupled(rho, true, why);
  }
  if (haveBase_ && limits_.pivotingUpdateRows > 0 && rho == baseRho_ &&
      buildCapacitance(pb, rho, limits_.pivotingUpdateRows))
    return true;
  // A new base: B = A_CC + rho I for the current set, the sliding rows by Woodbury.
  ++factorizations_;
  haveBase_ = false;
  if (!factorCoupled(rho, false, why)) return false;
  haveBase_ = true;
  baseRho_ = rho;
  basePos_ = pos_;
  baseOrder_ = order_;
  if (!buildCapacitance(pb, rho, m + s)) {
    why = "the clamped system with its sliding rows is singular";
    return false;
  }
  return true;
}

// Sets x to the solution of the linear equations of the current index sets:
//   clamped rows:         (A x + b)_i = 0
//   uncoupled at a bound: x_i = lo_i or hi_i
//   friction at a bound:  x_t = mu_t s_j x_j (s_j = sign of the normal, mu_t = lo_t or hi_t)
// with a proximal term: clamped rows solve w_i + rho (x_i - prev_i) = 0 (rho = 0: the exact
// equations). Substituting the sliding rows (normal clamped) gives K y = r with K = A_CC + rho I
// plus the sliding columns scaled by their coefficients added to their normals' columns: the
// sparse LDL^T of A_CC + rho I with the sliding rows bordered (Woodbury), reused by the next
// steps while their sets stay close (buildCapacitance); many sliding rows: the LU of K.
bool BlockPivoting::solveClamped(const Problem& pb, Vector& x, const Vector& prev, double rho,
                                 std::string& why) {
  gatherSets(pb, x);
  const int m = static_cast<int>(order_.size());
  Vector r(m);
  clampedTimes(x, ax_);
  for (int c = 0; c < m; ++c) r[c] = -(pb.b[order_[c]] + ax_[c]) + rho * prev[order_[c]];
  if (!factorClamped(pb, rho, why)) return false;
  const int s = static_cast<int>(sliding_.size());
  auto place = [&](const Vector& y, bool add) {
    for (int c = 0; c < m; ++c) x[order_[c]] = (add ? x[order_[c]] : 0.0) + y[c];
    for (int k = 0; k < s; ++k) x[sliding_[k]] = coeff_[k] * x[pb.findex[sliding_[k]]];
  };
  if (m == 0) return true;
  Vector y = r;
  applySolve(y);
  place(y, false);
  // Iterative refinement: the clamped rows' w is the residual of K y = r. One step; two in body
  // space, whose error grows as 1 / min d_c.
  for (int pass = 0; pass < (useBody_ ? 2 : 1); ++pass) {
    clampedTimes(x, ax_);
    for (int c = 0; c < m; ++c)
      y[c] = -(pb.b[order_[c]] + ax_[c]) - rho * (x[order_[c]] - prev[order_[c]]);
    applySolve(y);
    place(y, true);
  }
  if (!x.allFinite()) {
    why = "the clamped system with its sliding rows is singular";
    return false;
  }
  return true;
}

void BlockPivoting::times(const Vector& x, Vector& out) {
  if (factoredProducts_)
    body_->multiply(x, out);
  else
    out.noalias() = *a_ * x;
}

void BlockPivoting::clampedTimes(const Vector& x, Vector& out) {
  if (factoredProducts_) {
    body_->multiply(x, order_, out);
    return;
  }
  out.resize(order_.size());
  for (size_t c = 0; c < order_.size(); ++c) out[c] = a_->row(order_[c]).dot(x);
}

void BlockPivoting::applySolve(Vector& y) {
  if (useBody_) {
    body_->solve(y);
    return;
  }
  if (useLu_) {
    if (useSymLu_)
      symLu_.solve(y);
    else
      y = lu_.solve(y);
    return;
  }
  // [B G; H^T F] [x0; xi] = [r0; s] (see the header): x0 = B^-1 (r0 - G xi) with
  // S xi = s - H^T B^-1 r0, S = F - H^T B^-1 G.
  const int m0 = static_cast<int>(baseOrder_.size()), p = static_cast<int>(extraRow_.size());
  Vector& r0 = work_;
  r0.setZero(m0);
  Vector rhs = Vector::Zero(p);
  for (size_t c = 0; c < order_.size(); ++c) {
    const int i = order_[c];
    if (basePos_[i] >= 0)
      r0[basePos_[i]] = y[c];
    else
      rhs[extraOf_[i]] = y[c];
  }
  Vector t = r0;
  symLu_.solve(t);
  for (int a = 0; a < p; ++a)
    for (int q = hStart_[a]; q < hStart_[a + 1]; ++q) rhs[a] -= hVal_[q] * t[hIdx_[q]];
  const Vector xi = p > 0 ? Vector(capacitance_.solve(rhs)) : rhs;
  for (int a = 0; a < p; ++a)
    for (int q = gStart_[a]; q < gStart_[a + 1]; ++q) r0[gIdx_[q]] -= xi[a] * gVal_[q];
  symLu_.solve(r0);
  for (size_t c = 0; c < order_.size(); ++c) {
    const int i = order_[c];
    y[c] = basePos_[i] >= 0 ? r0[basePos_[i]] : xi[extraOf_[i]];
  }
}

// The bordered system of the current sets on the base factor B = A_{C0,C0} + rho I (C0: the
// set of the last factorization). Unknowns beyond C0 (the xi of applySolve), each a column of G
// (its coefficients in C0's equations), of H (its equation's coefficients on x0) and of F:
//   a row d that joined C:   G = H = A_{C0,d}, F(d, d') = A_dd' (+ rho on the diagonal);
//   a row r that left C:     G = H = e_r (a multiplier frees r's equation, x_r = 0);
//   a sliding row t:         z_t = x_j for its normal j; G = c_t A_{C0,t}, F(d, t) = c_t A_dt
//                            for joined rows d, and z_t - x_j = 0: H = -e_j when j is in C0,
//                            else F(t, j) = -1; F(t, t) = 1.
// S = F - H^T B^-1 G = F - (L^-1 H)^T D^-1 (L^-1 G) from sparse forward solves (G and H are
// local to a few bodies, so their reach in the elimination tree is short). False when there
// are more than maxExtra unknowns beyond C0 or S is singular.
bool BlockPivoting::buildCapacitance(const Problem& pb, double rho, int maxExtra) {
  const int n = pb.size();
  extraRow_.clear();
  extraOf_.assign(n, -1);
  for (int i : order_)
    if (basePos_[i] < 0) extraRow_.push_back(i);  // joined
  const int joined = static_cast<int>(extraRow_.size());
  for (int i : baseOrder_)
    if (pos_[i] < 0) extraRow_.push_back(i);  // left
  const int left = static_cast<int>(extraRow_.size());
  for (int t : sliding_) extraRow_.push_back(t);
  const int p = static_cast<int>(extraRow_.size());
  if (p > maxExtra) return false;
  for (int a = 0; a < left; ++a) extraOf_[extraRow_[a]] = a;
  DenseMatrix S = DenseMatrix::Zero(p, p);
  borderColumns(rho, joined, left, S);
  subtractSchur(left, S);
  if (p == 0) return true;
  capacitance_.setThreshold(pivTolRelative_);
  capacitance_.compute(S);
  return S.allFinite() && capacitance_.isInvertible();
}

// buildCapacitance's columns of G and H as sparse lists (gStart_/gIdx_/gVal_,
// hStart_/hIdx_/hVal_) and F's entries in S, for the extra unknowns extraRow_ (joined rows
// first, then the rows that left, then the sliding rows).
void BlockPivoting::borderColumns(double rho, int joined, int left, DenseMatrix& S) {
  const SparseMatrix& A = *a_;
  const int p = static_cast<int>(extraRow_.size());
  gStart_.assign(1, 0);
  hStart_.assign(1, 0);
  gIdx_.clear();
  gVal_.clear();
  hIdx_.clear();
  hVal_.clear();
  for (int a = 0; a < p; ++a) {
    const int i = extraRow_[a];
    if (a < joined) {
      pushColumn(A, basePos_, gIdx_, gVal_, gStart_, i, 1.0);
      pushColumn(A, basePos_, hIdx_, hVal_, hStart_, i, 1.0);
      for (SparseMatrix::InnerIterator it(A, i); it; ++it)
        if (extraOf_[it.index()] >= 0 && extraOf_[it.index()] < joined)
          S(a, extraOf_[it.index()]) += it.value();
      S(a, a) += rho;
    } else if (a < left) {
      pushUnit(gIdx_, gVal_, gStart_, basePos_[i], 1.0);
      pushUnit(hIdx_, hVal_, hStart_, basePos_[i], 1.0);
    } else {
      const double c = coeff_[a - left];
      const int j = problemFindex_[i];
      pushColumn(A, basePos_, gIdx_, gVal_, gStart_, i, c);
      for (SparseMatrix::InnerIterator it(A, i); it; ++it)
        if (extraOf_[it.index()] >= 0 && extraOf_[it.index()] < joined)
          S(extraOf_[it.index()], a) += c * it.value();
      pushUnit(hIdx_, hVal_, hStart_, basePos_[j], -1.0);
      if (basePos_[j] < 0) S(a, extraOf_[j]) -= 1;
      S(a, a) += 1;
    }
  }
}

// S -= (L^-1 H)^T D^-1 (L^-1 G), from sparse forward solves on the base factor: L^-1 H and
// D^-1 L^-1 H column by column (applySolve uses H itself, on B^-1 r0); a joined or left row's
// column of G equals its column of H, so L^-1 G is only solved for sliding rows.
void BlockPivoting::subtractSchur(int left, DenseMatrix& S) {
  const int p = static_cast<int>(extraRow_.size());
  work_.setZero(static_cast<Eigen::Index>(baseOrder_.size()));
  std::vector<int> hsStart(1, 0), hsIdx;
  std::vector<double> hsVal, hlVal;
  for (int a = 0; a < p; ++a) {
    reach_.assign(hIdx_.begin() + hStart_[a], hIdx_.begin() + hStart_[a + 1]);
    for (int q = hStart_[a]; q < hStart_[a + 1]; ++q) work_[hIdx_[q]] += hVal_[q];
    symLu_.forward(reach_, work_);
    for (int i : reach_) {
      hsIdx.push_back(i);
      hlVal.push_back(work_[i]);
      hsVal.push_back(work_[i] / symLu_.pivot(i));
      work_[i] = 0;
    }
    hsStart.push_back(static_cast<int>(hsIdx.size()));
  }
  for (int b = 0; b < p; ++b) {
    if (b < left) {
      reach_.assign(hsIdx.begin() + hsStart[b], hsIdx.begin() + hsStart[b + 1]);
      for (int q = hsStart[b]; q < hsStart[b + 1]; ++q) work_[hsIdx[q]] = hlVal[q];
    } else {
      reach_.assign(gIdx_.begin() + gStart_[b], gIdx_.begin() + gStart_[b + 1]);
      for (int q = gStart_[b]; q < gStart_[b + 1]; ++q) work_[gIdx_[q]] += gVal_[q];
      symLu_.forward(reach_, work_);
    }
    for (int a = 0; a < p; ++a) {
      double sum = 0;
      for (int q = hsStart[a]; q < hsStart[a + 1]; ++q) sum += hsVal[q] * work_[hsIdx[q]];
      S(a, b) -= sum;
    }
    for (int i : reach_) work_[i] = 0;
  }
}

// Factors K = A_CC + rho I, when coupled with each sliding row's column c_t A_{C,t} added to its
// normal's column. The friction coupling makes K nonsymmetric, but a contact's friction and
// normal rows touch the same bodies, so K keeps A_CC's pattern and a sparse LU in the inherited
// fill-reducing order stays cheap. Not coupled: the symmetric LDL^T of A_CC + rho I.
bool BlockPivoting::factorCoupled(double rho, bool coupled, std::string& why) {
  const SparseMatrix& A = *a_;
  const int n = static_cast<int>(pos_.size());
  const int m = static_cast<int>(order_.size());
  slidingHead_.assign(n, -1);
  slidingNext_.resize(sliding_.size());
  for (size_t k = 0; coupled && k < sliding_.size(); ++k) {
    const int j = problemFindex_[sliding_[k]];
    slidingNext_[k] = slidingHead_[j];
    slidingHead_[j] = static_cast<int>(k);
  }
  mark_.assign(n, -1);
  coupled_.assign(n, 0.0);
  column_.assign(n, 0.0);
  kOuter_.assign(m + 1, 0);
  int bound = m;  // entries of K at most: A's columns of C and a diagonal each
  for (int c = 0; c < m; ++c)
    bound += A.outerIndexPtr()[order_[c] + 1] - A.outerIndexPtr()[order_[c]];
  kInner_.resize(bound);
  kVal_.resize(bound);
  ktVal_.resize(bound);
  int nz = 0;
  auto put = [&](int q, double v, double vt) {
    kInner_[nz] = q;
    kVal_[nz] = v;
    ktVal_[nz++] = vt;
  };
  for (int c = 0; c < m; ++c) {
    const int i = order_[c];
    // Column c of K: A(C, i) plus, when i is a normal, c_t A(C, t) for its sliding rows t;
    // row c: A(i, C) plus c_t' A(i, t') at the columns of normals with sliding rows t'.
    bool diagonal = false;
    for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
      column_[it.index()] = it.value();
      mark_[it.index()] = c;
    }
    for (int k = slidingHead_[i]; k >= 0; k = slidingNext_[k])
      for (SparseMatrix::InnerIterator it(A, sliding_[k]); it; ++it) {
        if (pos_[it.index()] < 0) continue;
        if (mark_[it.index()] != c) return factorGeneral(rho, why);  // outside A_CC's pattern
        coupled_[it.index()] += coeff_[k] * it.value();
      }
    for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
      const int r = it.index();
      if (pos_[r] < 0) continue;
      double kt = it.value();
      for (int k = slidingHead_[r]; k >= 0; k = slidingNext_[k])
        kt += coeff_[k] * column_[sliding_[k]];
      const double extra = r == i ? rho : 0.0;
      diagonal |= r == i;
      put(pos_[r], it.value() + coupled_[r] + extra, kt + extra);
    }
    if (!diagonal) put(c, rho, rho);
    for (SparseMatrix::InnerIterator it(A, i); it; ++it) column_[it.index()] = 0;
    for (int k = slidingHead_[i]; k >= 0; k = slidingNext_[k])
      for (SparseMatrix::InnerIterator it(A, sliding_[k]); it; ++it) coupled_[it.index()] = 0;
    kOuter_[c + 1] = nz;
  }
  useSymLu_ = true;
  if (coupled ? symLu_.factor(m, kOuter_, kInner_, kVal_, ktVal_, pivTol_)
              : symLu_.factorSymmetric(m, kOuter_, kInner_, kVal_, pivTol_))
    return true;
  why = "the clamped system with its sliding rows is singular";
  return false;
}

// factorCoupled for a K whose pattern is not symmetric: a general sparse LU with pivoting.
bool BlockPivoting::factorGeneral(double rho, std::string& why) {
  const SparseMatrix& A = *a_;
  const int m = static_cast<int>(order_.size());
  std::fill(coupled_.begin(), coupled_.end(), 0.0);
  std::fill(column_.begin(), column_.end(), 0.0);
  triplets_.clear();
  for (int c = 0; c < m; ++c) {
    for (SparseMatrix::InnerIterator it(A, order_[c]); it; ++it)
      if (pos_[it.index()] >= 0) triplets_.emplace_back(pos_[it.index()], c, it.value());
    if (rho > 0) triplets_.emplace_back(c, c, rho);
  }
  for (size_t k = 0; k < sliding_.size(); ++k) {
    const int c = pos_[problemFindex_[sliding_[k]]];
    for (SparseMatrix::InnerIterator it(A, sliding_[k]); it; ++it)
      if (pos_[it.index()] >= 0)
        triplets_.emplace_back(pos_[it.index()], c, coeff_[k] * it.value());
  }
  Kfull_.resize(m, m);
  Kfull_.setFromTriplets(triplets_.begin(), triplets_.end());
  useSymLu_ = false;
  lu_.analyzePattern(Kfull_);
  lu_.factorize(Kfull_);
  if (lu_.info() != Eigen::Success) {
    why = "the clamped system with its sliding rows is singular";
    return false;
  }
  return true;
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

// mirror_ for a new pattern of A. Rows are visited in increasing order, so with sorted rows and a
// symmetric pattern the next unvisited entry of row j is (j, i) when (i, j) is visited.
void BlockPivoting::mirrorPattern() {
  const SparseMatrix& A = *a_;
  const int n = static_cast<int>(A.outerSize());
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  mirror_.clear();
  if (!A.isCompressed()) return;
  mirror_.resize(A.nonZeros());
  std::vector<int> next(outer, outer + n);
  for (int i = 0; i < n; ++i)
    for (int k = outer[i]; k < outer[i + 1]; ++k) {
      const int j = inner[k];
      const int m = next[j]++;
      if ((k > outer[i] && inner[k - 1] >= j) || m >= outer[j + 1] || inner[m] != i) {
        mirror_.clear();
        return;
      }
      mirror_[k] = m;
    }
}

// Whether A = A^T by the rule of linalg/symmetry.hpp, on a mirrored
// pattern: one pass over the values, no transposed copy (which cost ~2 ms per step at n = 1160).
bool BlockPivoting::symmetricValues() const {
  const double* v = a_->valuePtr();
  const int nz = static_cast<int>(a_->nonZeros());
  double scale = 0, gap = 0;
  for (int k = 0; k < nz; ++k) {
    scale = std::max(scale, std::abs(v[k]));
    gap = std::max(gap, std::abs(v[k] - v[mirror_[k]]));
  }
  return symmetricWithin(gap, scale);
}

// The per-pattern and per-problem preparation of a run: A's sparse rows, the fill-reducing order
// and mirror of a new pattern, the symmetry check (false: A is not symmetric), the tolerances and
// the body-space factor of rows given since the last run.
bool BlockPivoting::prepare(const Problem& pb, const Options& opt, bool symmetryKnown) {
  const int n = pb.size();
  if (pb.isSparse()) {
    a_ = &pb.sparseA();
  } else {
    A_ = pb.toSparse();
    a_ = &A_;
  }
  // A fill-reducing order of all of A; every clamped block is factored in the induced order,
  // whose fill is at most A's, so the ordering is computed once per pattern of A.
  if (!aPattern_.same(*a_)) {
    const ColMajor pattern = *a_;
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::AMDOrdering<int>()(pattern, perm);
    byRank_.assign(perm.indices().data(), perm.indices().data() + n);
    aPattern_.remember(*a_);
    mirrorPattern();
  }
  if (!symmetryKnown && !(mirror_.empty() ? isSymmetric(*a_) : symmetricValues())) return false;
  problemFindex_ = pb.findex.empty() ? std::vector<int>(n, -1) : pb.findex;
  double dMax = 0;
  for (int i = 0; i < n; ++i) dMax = std::max(dMax, std::abs(pb.diagonal(i)));
  pivTol_ = opt.pivotTolerance * (dMax > 0 ? dMax : 1.0);
  dMax_ = dMax;
  if (!rowsPrepared_) {
    rowsPrepared_ = true;
    bodyReady_ = rows_ != nullptr && body_->prepareFor(*rows_, pb, dMax);
    factoredProducts_ = bodyReady_ && body_->productsStandForA();
  }
  bodyFactorizations_ = 0;
  pivTolRelative_ = opt.pivotTolerance;
  eps_ = 0.01 * opt.tolerance * (1 + pb.b.lpNorm<Eigen::Infinity>());
  pos_.assign(n, -1);
  haveBase_ = false;  // A's values are new
  factorizations_ = 0;
  return true;
}

// One run's iterate bookkeeping: the slack w = A x + b, the last step's point and the new slack,
// the merit ||H||^2, the full steps' best point and the run's best point by residual.
struct BlockPivoting::RunState {
  explicit RunState(int n) : w(n), xOld(n), wOld(n), wNew(n) {}
  Vector w, xOld, wOld, wNew;
  double merit = 0, bestRes = kInf, fullBest = 0;
  int uphill = 0;
  bool damped = false;
  // Full steps without a new lowest merit that still descend from the step before (at most
  // pivotingDescentSteps per run) do not count as uphill: from a guess that is the best point so
  // far the full steps often descend over several steps before beating it (Bullet's pyramid).
  int descents = 0;
  Vector fullBestX, bestX;
};

// Damped steps from here on, from the full steps' best point.
void BlockPivoting::toDamped(const Problem& pb, Vector& x, RunState& st) {
  x = st.fullBestX;
  times(x, st.w);
  st.w += pb.b;
  st.merit = st.fullBest;
  st.damped = true;
}

// Short steps leave rows within the tolerance of their bounds but not on them: x projected
// (friction after its normal) when the projection is still within tolerance.
void BlockPivoting::project(const Problem& pb, double tolerance, Vector& x) {
  const int n = pb.size();
  Vector p = x;
  for (int i = 0; i < n; ++i)
    if (!isFriction(pb, i)) p[i] = std::clamp(p[i], pb.lo[i], pb.hi[i]);
  for (int t = 0; t < n; ++t)
    if (isFriction(pb, t)) p[t] = std::clamp(p[t], pb.effectiveLo(t, p), pb.effectiveHi(t, p));
  Vector wp(n);
  times(p, wp);
  wp += pb.b;
  if (accuracy(pb, p, wp).residual <= tolerance) x = p;
}

// The sets of the next step: after a full step from where x lies (setsAt), a 2-cycle of sets
// (which would repeat the step two back) handing over to damped steps at once; damped steps
// take the natural map's sets at x.
void BlockPivoting::nextSets(const Problem& pb, Vector& x, RunState& st) {
  if (!st.damped) {
    setsAt(pb, x, st.w);
    if (limits_.pivotingBreakCycles && set_ == setPrev2_) toDamped(pb, x, st);
    setPrev2_.swap(setPrev1_);
    setPrev1_ = set_;
  }
  if (st.damped) guess(pb, x, st.w, false);
}

// After a full step (block principal pivoting; the merit may rise for a step or two): a new
// lowest merit, a free descent, or one more step uphill; too many: damped steps from the best.
void BlockPivoting::fullStep(const Problem& pb, Vector& x, RunState& st) {
  st.w = st.wNew;
  const double before = st.merit;
  st.merit = meritAt(pb, x, st.w);
  if (st.merit < st.fullBest) {
    st.fullBest = st.merit;
    st.fullBestX = x;
    st.uphill = 0;
  } else if (st.merit < before && st.descents < limits_.pivotingDescentSteps) {
    ++st.descents;
  } else if (++st.uphill > kUphill) {  // no new best: damped steps from the best point
    st.uphill = 0;
    toDamped(pb, x, st);
  }
}

// After a damped step's solve: backtracking from the full step until ||H||^2 decreases
// (Armijo). False when no step length descends kUphill + 1 times in a row (the run ends).
bool BlockPivoting::dampedStep(const Problem& pb, Vector& x, RunState& st) {
  const Vector dx = x - st.xOld;
  double alpha = 1, trial = kInf;
  for (; alpha >= kMinStep; alpha *= 0.5) {
    x = st.xOld + alpha * dx;
    st.w = st.wOld + alpha * (st.wNew - st.wOld);
    trial = meritAt(pb, x, st.w);
    if (trial <= (1 - 2e-4 * alpha) * st.merit) break;
  }
  if (!(trial <= (1 - 2e-4 * alpha) * st.merit)) {
    // Watchdog: at a kink no short step descends, but the full step (the block pivoting
    // exchange) often settles the sets; take it a few times in a row, keeping the best point.
    if (++st.uphill > kUphill) return false;
    x = st.xOld + dx;
    st.w = st.wNew;
    trial = meritAt(pb, x, st.w);
  } else {
    st.uphill = 0;
  }
  st.merit = trial;
  return true;
}

// Full steps (block principal pivoting) while they keep finding new lowest merits ||H(x)||^2;
// then damped Newton steps on the natural map: a proximal term in the equations and
// backtracking until the merit decreases (Armijo), which keeps degenerate scenes (coplanar
// contacts: nearly singular clamped blocks whose equations throw the null-space part far away)
// from jumping between set guesses. When no step length descends the run hands over the best
// iterate.
BlockPivoting::Report BlockPivoting::run(const Problem& pb, Vector& x, const Options& opt,
                                         int maxSteps, bool atGuess, bool symmetryKnown) {
  Report rep;
  if (!prepare(pb, opt, symmetryKnown)) {
    rep.message = "A is not symmetric";
    return rep;
  }
  const bool cold = x.isZero(0.0);
  RunState st(pb.size());
  times(x, st.w);
  st.w += pb.b;
  guess(pb, x, st.w, cold, atGuess);

  // Full steps while they find new lowest merits, then damped steps (the header's "Steps").
  const double regularization = kProximal * (dMax_ > 0 ? dMax_ : 1.0);
  st.merit = meritAt(pb, x, st.w);
  st.fullBest = st.merit;
  st.fullBestX = x;
  setPrev1_ = set_;
  setPrev2_.clear();
  st.bestX = x;
  const double deadline = budgetDeadline(opt);
  std::ostringstream os;
  for (;;) {
    const double res = accuracy(pb, x, st.w).residual;
    if (res <= opt.tolerance) {
      project(pb, opt.tolerance, x);
      rep.settled = true;
      os << "block pivoting settled after " << rep.steps << " step" << (rep.steps != 1 ? "s" : "");
      break;
    }
    if (res < st.bestRes) {
      st.bestRes = res;
      st.bestX = x;
    }
    if (rep.steps >= maxSteps) {
      x = st.bestX;
      os << "residual " << st.bestRes << " after " << rep.steps << " block steps";
      break;
    }
    if (opt.timeBudget > 0 && nowSeconds() > deadline) {
      x = st.bestX;
      os << "time budget spent after " << rep.steps << " block steps";
      break;
    }
    if (rep.steps > 0) nextSets(pb, x, st);
    ++rep.steps;
    st.xOld = x;
    st.wOld = st.w;
    std::string why;
    const double rho = st.damped ? regularization * std::min(1.0, std::sqrt(st.merit)) : 0.0;
    if (!solveClamped(pb, x, st.xOld, rho, why)) {
      if (!st.damped) {  // a singular block: the proximal term regularizes it
        toDamped(pb, x, st);
        continue;
      }
      os << why << " (block step " << rep.steps << ")";
      x = st.bestX;
      break;
    }
    times(x, st.wNew);
    st.wNew += pb.b;
    if (!st.damped) {
      fullStep(pb, x, st);
    } else if (!dampedStep(pb, x, st)) {
      x = st.bestX;
      os << "residual " << st.bestRes << " after " << rep.steps << " block steps (no descent)";
      break;
    }
  }
  rep.message = os.str();
  rep.factorizations = factorizations_;
  rep.bodyFactorizations = bodyFactorizations_;
  return rep;
}

}  // namespace mlcp::detail
