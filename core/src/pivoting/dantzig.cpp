#include "mlcp/solvers/dantzig.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>

#include "linalg/sparse_pattern.hpp"
#include "linalg/symmetry.hpp"
#include "mlcp/residual.hpp"
#include "pivoting/dantzig_small.hpp"
#include "pivoting/dantzig_workspace.hpp"
#include "short_number.hpp"

namespace mlcp {

using namespace dantzig;  // the workspace's vocabulary (dantzig_workspace.hpp)

namespace {

// Largest residual (residual.hpp) of a guess whose friction values set the first pass's bounds.
constexpr double kTrustedGuess = 1e-2;

// A pass that ended early (a breakdown, the pivot limit or the time budget): status and message.
void reportStopped(Outcome o, const std::string& why, bool frictionPasses, int pass,
                   Result& result) {
  std::ostringstream os;
  result.status = o == Outcome::Failed       ? Status::Failed
                  : o == Outcome::PivotLimit ? Status::MaxIterations
                                             : Status::TimeLimit;
  os << why;
  if (frictionPasses) os << " (friction pass " << pass << ")";
  result.message = os.str();
}

// Redundant rows (a singular A) are said: their x is one of many answers.
std::string redundantRowsNote(int redundant) {
  return redundant > 0
             ? "; " + std::to_string(redundant) + " redundant rows left free (A is singular)"
             : "";
}

// After an exact friction pass with residual res: true with the result set when the bounds
// settled (Converged) or the passes ran out (MaxIterations).
bool frictionPassesEnd(double res, int pass, const Options& opt, const std::string& singular,
                       Result& result) {
  if (res <= opt.tolerance) {
    // Every converged friction solve writes this: built without an ostringstream, whose locale
    // set-up costs more than a small island's pivoting.
    result.status = Status::Converged;
    result.message = "friction bounds settled after ";
    result.message += std::to_string(pass);
    result.message += pass > 1 ? " passes" : " pass";
    result.message += singular;
    return true;
  }
  if (pass >= opt.maxIterations) {
    std::ostringstream os;
    result.status = Status::MaxIterations;
    os << "friction bounds still moving after " << pass << " passes (residual " << res << ")";
    result.message = os.str();
    return true;
  }
  return false;
}

}  // namespace

// ============================================================================ set-up

void DantzigSolver::Workspace::setUp(const Problem& pb, const Vector& start, const Options& opt,
                                     bool useGuess, bool trustFriction) {
  build(pb, start, useGuess, trustFriction);
  if (shift > 0) shiftDiagonal(shift);
  pivTol *= opt.pivotTolerance;
  pivots = 0;
  pivotLimit = opt.maxPivots > 0 ? opt.maxPivots : 50 * n + 100;
  deadline = budgetDeadline(opt);  // the solve's (Solver sets budgetStart)
  clockEvery = std::max(1, 1024 / std::max(1, n));
  message.clear();
  for (int p = 0; p < n; ++p) {
    const int i = perm[p];
    const bool guessed =
        isFreeRow(pb.lo[i], pb.hi[i]) || (useGuess && x[p] > lo[p] && x[p] < hi[p]);
    set[p] = guessed ? Set::Clamped : Set::Unprocessed;
  }
}

void DantzigSolver::Workspace::build(const Problem& pb, const Vector& guess, bool useGuess,
                                     bool exactFriction) {
  n = pb.size();
  order(pb, guess, useGuess, exactFriction);
  sizeVectors();
  copyRows(pb, guess, useGuess, exactFriction);
  sparse = pb.isSparse();
  if (sparse)
    buildSparse(pb);
  else
    buildDense(pb);
  setScales(pb);
}

// Groups: 0 equality, 1 guessed clamped, 2 other rows, 3 friction rows; a counting sort (one
// classification per row) keeps the caller's order within a group.
void DantzigSolver::Workspace::order(const Problem& pb, const Vector& guess, bool useGuess,
                                     bool exactFriction) {
  const bool hasF = pb.hasFindex();
  auto friction = [&](int i) { return hasF && pb.findex[i] >= 0; };
  auto interior = [&](int i) {
    if (isFreeRow(pb.lo[i], pb.hi[i])) return true;
    if (!useGuess) return false;
    if (friction(i)) {
      if (!exactFriction) return false;
      const double bound = pb.hi[i] * std::abs(guess[pb.findex[i]]);
      return std::abs(guess[i]) < bound;
    }
    return guess[i] > pb.lo[i] && guess[i] < pb.hi[i];
  };
  inv.resize(n);  // the group of each row until the positions are known
  int start[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const int g = isFreeRow(pb.lo[i], pb.hi[i]) ? 0 : interior(i) ? 1 : friction(i) ? 3 : 2;
    inv[i] = g;
    ++start[g + 1];
  }
  for (int g = 0; g < 4; ++g) start[g + 1] += start[g];
  perm.resize(n);
  for (int i = 0; i < n; ++i) {
    const int p = start[inv[i]]++;
    perm[p] = i;
    inv[i] = p;
  }
}

// Only dxFull (kept zero between steps), w, normal and diag (a sparse row may lack its diagonal)
// are read before they are written.
void DantzigSolver::Workspace::sizeVectors() {
  for (std::vector<double>* v :
       {&b, &lo, &hi, &muLo, &muHi, &x, &xStart, &a, &r, &u, &l, &z, &dwN, &xs, &ys, &D})
    v->resize(n);
  for (std::vector<double>* v : {&w, &dxFull, &normal, &diag}) {
    v->resize(n);
    std::fill(v->begin(), v->end(), 0.0);
  }
  findex.assign(n, -1);
  set.assign(n, Set::Unprocessed);
  slot.assign(n, -1);
  C.assign(n, -1);
  N.clear();
  N.reserve(n);
}

// b, the bounds (friction rows': mu times their normal's start) and the start x, in processing
// order.
void DantzigSolver::Workspace::copyRows(const Problem& pb, const Vector& guess, bool useGuess,
                                        bool exactFriction) {
  const bool hasF = pb.hasFindex();
  for (int p = 0; p < n; ++p) {
    const int i = perm[p];
    b[p] = pb.b[i];
    muLo[p] = lo[p] = pb.lo[i];
    muHi[p] = hi[p] = pb.hi[i];
    if (hasF && pb.findex[i] >= 0) {
      findex[p] = inv[pb.findex[i]];
      // Bounds of the first pass: from the guess (exact, warm) or set when reached (cold).
      normal[p] = useGuess && exactFriction ? std::abs(guess[pb.findex[i]]) : 0.0;
      lo[p] = muLo[p] * normal[p];
      hi[p] = muHi[p] * normal[p];
    }
  }
  frictionRows.clear();
  for (int p = 0; p < n; ++p)
    if (findex[p] >= 0) frictionRows.push_back(p);
  for (int p = 0; p < n; ++p) {
    const double g = useGuess ? guess[perm[p]] : 0.0;
    x[p] = findex[p] >= 0 && !(useGuess && exactFriction) ? 0.0 : std::clamp(g, lo[p], hi[p]);
  }
}

// The zero tests' scales (pivots: max |A_ii|; w: 1 + ||b||_inf) and the factors' storage.
void DantzigSolver::Workspace::setScales(const Problem& pb) {
  double dMax = 0;
  for (int p = 0; p < n; ++p) dMax = std::max(dMax, std::abs(diag[p]));
  const double scale = dMax > 0 ? dMax : (aMax > 0 ? aMax : 1.0);
  pivTol = scale;  // multiplied by Options::pivotTolerance in setUp()
  this->scale = scale;
  const double bNorm = n ? pb.b.lpNorm<Eigen::Infinity>() : 0.0;
  epsW = 1e-12 * (1.0 + bNorm);
  const size_t nn = size_t(n) * n;
  L.resize(nn);
  if (!symmetric) Ut.resize(nn);
}

void DantzigSolver::Workspace::buildDense(const Problem& pb) {
  const DenseMatrix& A = pb.denseA();
  aMax = n ? A.cwiseAbs().maxCoeff() : 0.0;
  double asym = 0;
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i < n; ++i) asym = std::max(asym, std::abs(A(i, j) - A(j, i)));
  symmetric = detail::symmetricWithin(asym, aMax);
  dense.resize(size_t(n) * n);
  bool identity = true;  // the usual case of a joint island: equality rows come first
  for (int p = 0; p < n && identity; ++p) identity = perm[p] == p;
  if (identity) {
    std::memcpy(dense.data(), A.data(), sizeof(double) * size_t(n) * n);
  } else {
    for (int q = 0; q < n; ++q) {
      const double* src = A.data() + size_t(perm[q]) * n;
      double* dst = dense.data() + size_t(q) * n;
      for (int p = 0; p < n; ++p) dst[p] = src[perm[p]];
    }
  }
  if (!symmetric) {
    denseT.resize(size_t(n) * n);
    for (int q = 0; q < n; ++q)
      for (int p = 0; p < n; ++p) denseT[q + size_t(p) * n] = dense[p + size_t(q) * n];
  }
  for (int p = 0; p < n; ++p) diag[p] = dense[p + size_t(p) * n];
}

void DantzigSolver::Workspace::buildSparse(const Problem& pb) {
  const SparseMatrix& S = pb.sparseA();
  const int* outer = S.outerIndexPtr();
  const int* inner = S.innerIndexPtr();
  const double* val = S.valuePtr();
  aMax = 0;
  for (int k = 0; k < S.nonZeros(); ++k) aMax = std::max(aMax, std::abs(val[k]));
  symmetric = detail::isSymmetric(S);
  const int nnz = static_cast<int>(S.nonZeros());
  // CSR of the permuted matrix: row p is the caller's row perm[p] with columns renumbered.
  rowPtr.assign(n + 1, 0);
  for (int p = 0; p < n; ++p) rowPtr[p + 1] = rowPtr[p] + (outer[perm[p] + 1] - outer[perm[p]]);
  rowIdx.resize(nnz);
  rowVal.resize(nnz);
  for (int p = 0; p < n; ++p) {
    int k = rowPtr[p];
    for (int e = outer[perm[p]]; e < outer[perm[p] + 1]; ++e, ++k) {
      rowIdx[k] = inv[inner[e]];
      rowVal[k] = val[e];
      if (rowIdx[k] == p) diag[p] = val[e];
    }
  }
  if (!symmetric) {
    colPtr.assign(n + 1, 0);
    for (int k = 0; k < nnz; ++k) ++colPtr[rowIdx[k] + 1];
    for (int q = 0; q < n; ++q) colPtr[q + 1] += colPtr[q];
    colIdx.resize(nnz);
    colVal.resize(nnz);
    std::vector<int>& next = slot;  // borrowed as a cursor; reset by the pass
    next.assign(colPtr.begin(), colPtr.end() - 1);
    for (int p = 0; p < n; ++p)
      for (int k = rowPtr[p]; k < rowPtr[p + 1]; ++k) {
        const int at = next[rowIdx[k]]++;
        colIdx[at] = p;
        colVal[at] = rowVal[k];
      }
  }
  scatter.assign(n, 0.0);
}

// ========================================================================= the method

Outcome DantzigSolver::Workspace::drive(int i) {
  for (;;) {
    const double wi = w[i];
    if (settleAtBound(i, wi)) return Outcome::Done;
    if (const Outcome o = checkBudget(); o != Outcome::Done) return o;
    ++pivots;
    const double d = wi < 0 ? 1.0 : -1.0;
    const double dwi = direction(i, d);
    const double sii = d * dwi;  // Schur complement of i with respect to C
    const bool interior = x[i] > lo[i] && x[i] < hi[i];
    if (interior && std::abs(wi) <= epsW && std::abs(sii) > pivTol) {
      clearDx(i);
      w[i] = 0;
      enterC(i, sii);
      return Outcome::Done;
    }
    const Step step = ratioTest(i, d, wi, dwi, sii);
    if (step.kind == Block::None) {
      clearDx(i);
      return unlimited(i, wi, sii);
    }
    takeStep(i, d, dwi, step.length);
    clearDx(i);
    if (const std::optional<Outcome> o = applyBlock(i, d, sii, step)) return *o;
  }
}

[[gnu::always_inline]] inline bool DantzigSolver::Workspace::settleAtBound(int i, double wi) {
  if (x[i] <= lo[i] && wi >= -epsW) {
    x[i] = lo[i];
    joinN(i, Set::AtLo);
    return true;
  }
  if (x[i] >= hi[i] && wi <= epsW) {
    x[i] = hi[i];
    joinN(i, Set::AtHi);
    return true;
  }
  return false;
}

[[gnu::always_inline]] inline Outcome DantzigSolver::Workspace::checkBudget() {
  if (pivots >= pivotLimit) {
    message = "pivot limit " + std::to_string(pivotLimit) + " reached";
    return Outcome::PivotLimit;
  }
  if (pivots % clockEvery == clockEvery - 1 && deadline != kInf && nowSeconds() > deadline) {
    message = "time budget spent";
    return Outcome::TimeUp;
  }
  return Outcome::Done;
}

// Direction: keep w_C = 0 and x_N fixed while x_i moves by d (dxFull, with z = A_CC^-1 A_Ci).
[[gnu::always_inline]] inline double DantzigSolver::Workspace::direction(int i, double d) {
  gatherCol(i, u);
  forward(L, u);
  std::copy(u.begin(), u.begin() + m, z.begin());
  backward(z);
  span = std::max(span, i + 1);
  for (int c = 0; c < m; ++c) dxFull[C[c]] = -d * z[c];
  dxFull[i] = d;
  return rowDot(i, dxFull, span);
}

[[gnu::always_inline]] inline void DantzigSolver::Workspace::clearDx(int i) {
  for (int c = 0; c < m; ++c) dxFull[C[c]] = 0;
  dxFull[i] = 0;
}

[[gnu::always_inline]] inline void DantzigSolver::Workspace::enterC(int p, double pivot) {
  if (!symmetric) {
    gatherRow(p, l);
    forward(Ut, l);
  }
  joinC(p, pivot);
}

// Step length: the first event along the ray (dwN: the rates of N's rows at a bound).
[[gnu::always_inline]] inline DantzigSolver::Workspace::Step DantzigSolver::Workspace::ratioTest(
    int i, double d, double wi, double dwi, double sii) {
  double dxMax = 1;
  for (int c = 0; c < m; ++c) dxMax = std::max(dxMax, std::abs(z[c]));
  const double rateTol = 1e-13 * aMax * dxMax;
  const int nN = static_cast<int>(N.size());
  for (int k = 0; k < nN; ++k) {
    const Set s = set[N[k]];
    dwN[k] = (s == Set::AtLo || s == Set::AtHi) ? rowDot(N[k], dxFull, span) : 0.0;
  }
  Step step;
  double& best = step.length;
  if (sii > pivTol) {
    best = std::max(0.0, -wi / dwi);
    step.kind = Block::SelfZero;
  }
  const double room = d > 0 ? hi[i] - x[i] : x[i] - lo[i];
  if (room < best) {
    best = std::max(0.0, room);
    step.kind = Block::SelfBound;
  }
  for (int c = 0; c < m; ++c) {
    const int p = C[c];
    const double dx = dxFull[p];
    double s = kInf;
    if (dx > 0 && hi[p] < kInf) s = (hi[p] - x[p]) / dx;
    if (dx < 0 && lo[p] > -kInf) s = (lo[p] - x[p]) / dx;
    if (s < best) {
      best = std::max(0.0, s);
      step.kind = Block::CBound;
      step.who = c;
      step.up = dx > 0;
    }
  }
  for (int k = 0; k < nN; ++k) {
    const int p = N[k];
    const double dw = dwN[k];
    double s = kInf;
    if (set[p] == Set::AtLo && dw < -rateTol) s = -w[p] / dw;
    if (set[p] == Set::AtHi && dw > rateTol) s = -w[p] / dw;
    if (s < best) {
      best = std::max(0.0, s);
      step.kind = Block::NZero;
      step.who = k;
    }
  }
  return step;
}

[[gnu::always_inline]] inline void DantzigSolver::Workspace::takeStep(int i, double d, double dwi,
                                                                      double best) {
  const int nN = static_cast<int>(N.size());
  x[i] += d * best;
  for (int c = 0; c < m; ++c) x[C[c]] += best * dxFull[C[c]];
  w[i] += best * dwi;
  for (int k = 0; k < nN; ++k) w[N[k]] += best * dwN[k];
}

[[gnu::always_inline]] inline Outcome DantzigSolver::Workspace::unlimited(int i, double wi,
                                                                          double sii) {
  if (std::abs(wi) <= epsW) {  // a redundant row: its w is 0 and stays 0 along the ray
    ++redundant;
    joinN(i, Set::Free);
    return Outcome::Done;
  }
  return fail("row " + std::to_string(perm[i]) + ": nothing limits the step (w = " +
              detail::shortNumber(wi) + ", Schur pivot = " + detail::shortNumber(sii) +
              "); the problem has no solution on this path (infeasible, or A is not a P-matrix)");
}

// The event that ended the step: i settles (Done), a clamped row leaves C at its bound or a row
// of N joins C (nothing: i moves on), or the factors break down (Failed).
[[gnu::always_inline]] inline std::optional<Outcome> DantzigSolver::Workspace::applyBlock(
    int i, double d, double sii, const Step& step) {
  switch (step.kind) {
    case Block::SelfZero:
      w[i] = 0;
      enterC(i, sii);
      return Outcome::Done;
    case Block::SelfBound:
      x[i] = d > 0 ? hi[i] : lo[i];
      joinN(i, d > 0 ? Set::AtHi : Set::AtLo);
      return Outcome::Done;
    case Block::CBound: {
      const int p = C[step.who];
      const bool up = step.up;
      x[p] = up ? hi[p] : lo[p];
      w[p] = 0;
      if (!leaveC(step.who)) {
        return fail("row " + std::to_string(perm[p]) +
                    " left the clamped set and left a singular block behind");
      }
      joinN(p, up ? Set::AtHi : Set::AtLo);
      break;
    }
    case Block::NZero: {
      const int p = N[step.who];
      w[p] = 0;
      leaveN(step.who);
      const double pivot = border(p);
      if (!(std::abs(pivot) > pivTol)) {
        return fail("row " + std::to_string(perm[p]) +
                    " must join the clamped set but its pivot is " + detail::shortNumber(pivot) +
                    " (singular principal block)");
      }
      joinC(p, pivot);
      break;
    }
    case Block::None: break;
  }
  return std::nullopt;
}

// Factors the guessed clamped block (or keeps the previous pass's factors), solves x_C with
// the other rows at their start values, and drops rows that land outside their bounds until
// the block is feasible. Rows not kept are queued. False when the block could not be used.
bool DantzigSolver::Workspace::bulk(bool reuseFactors) {
  if (reuseFactors) {
    for (int c = 0; c < m; ++c) set[C[c]] = Set::Clamped;
  } else {
    m = 0;
    for (int p = 0; p < n; ++p) {
      if (set[p] != Set::Clamped) continue;  // marked as guessed by the caller
      set[p] = Set::Unprocessed;
      if (lo[p] == hi[p]) continue;
      const double pivot = border(p);
      if (std::abs(pivot) > pivTol) joinC(p, pivot);
    }
  }
  for (int c = 0; c < m; ++c) span = std::max(span, C[c] + 1);
  while (m > 0) {
    solveClamped();
    violators.clear();
    for (int c = 0; c < m; ++c)
      if (x[C[c]] < lo[C[c]] || x[C[c]] > hi[C[c]]) violators.push_back(c);
    if (violators.empty()) break;
    for (auto it = violators.rbegin(); it != violators.rend(); ++it) {
      const int p = C[*it];
      x[p] = xStart[p];
      set[p] = Set::Unprocessed;
      if (!leaveC(*it)) return false;
    }
  }
  for (int c = 0; c < m; ++c) w[C[c]] = 0;
  return true;
}

Outcome DantzigSolver::Workspace::pass(bool fixedOnce, bool reuseFactors) {
  N.clear();
  redundant = 0;
  span = 0;
  if (reuseFactors) std::fill(set.begin(), set.end(), Set::Unprocessed);
  for (int p = 0; p < n; ++p) x[p] = std::clamp(x[p], lo[p], hi[p]);
  xStart = x;
  if (!bulk(reuseFactors)) {  // the guessed block was unusable: start from nothing
    m = 0;
    x = xStart;
    std::fill(set.begin(), set.end(), Set::Unprocessed);
  }
  bool boundsFixed = false;
  for (int p = 0; p < n; ++p) {
    if (set[p] != Set::Unprocessed) continue;
    if (fixedOnce && !boundsFixed && findex[p] >= 0) {
      // As ODE's dSolveLCP: on reaching the first friction row, the bounds of every friction
      // row still to come are fixed at once from the normal values of this moment.
      boundsFixed = true;
      for (int q = p; q < n; ++q) {
        if (set[q] != Set::Unprocessed || findex[q] < 0) continue;
        normal[q] = std::abs(x[findex[q]]);
        lo[q] = muLo[q] * normal[q];
        hi[q] = muHi[q] * normal[q];
        x[q] = std::clamp(x[q], lo[q], hi[q]);
      }
    }
    w[p] = b[p] + rowDot(p, x, n);
    if (lo[p] == hi[p]) {
      x[p] = lo[p];
      joinN(p, Set::Fixed);
      continue;
    }
    const Outcome o = drive(p);
    if (o != Outcome::Done) return o;
  }
  return finish();
}

// One step of iterative refinement of x_C with the factors, then rows whose sign condition
// drifted are driven again (at most a few rounds).
Outcome DantzigSolver::Workspace::finish() {
  for (int round = 0; round < 3; ++round) {
    solveClamped();
    freshW();
    violators.clear();
    for (int p : N)
      if (violates(p)) violators.push_back(p);
    if (violators.empty()) return Outcome::Done;
    for (int p : violators) {
      // Driving an earlier violator may have moved this one: into C (its w reached 0 along
      // that ray, at once when the ray pushes its w further the wrong way), or to a w that now
      // satisfies its set. Only a row still in N and still violating leaves N here.
      if (!violates(p)) continue;
      leaveN(slot[p]);
      const Outcome o = drive(p);
      if (o != Outcome::Done) return o;
    }
  }
  return Outcome::Done;
}

bool DantzigSolver::Workspace::shiftDiagonal(double delta) {
  if (sparse) {
    for (int p = 0; p < n; ++p) {
      bool stored = false;
      for (int k = rowPtr[p]; k < rowPtr[p + 1]; ++k) stored |= rowIdx[k] == p;
      if (!stored) return false;
    }
    for (int p = 0; p < n; ++p)
      for (int k = rowPtr[p]; k < rowPtr[p + 1]; ++k)
        if (rowIdx[k] == p) rowVal[k] += delta;
    if (!symmetric)
      for (int q = 0; q < n; ++q)
        for (int k = colPtr[q]; k < colPtr[q + 1]; ++k)
          if (colIdx[k] == q) colVal[k] += delta;
  } else {
    for (int p = 0; p < n; ++p) dense[p + size_t(p) * n] += delta;
    if (!symmetric)
      for (int p = 0; p < n; ++p) denseT[p + size_t(p) * n] += delta;
  }
  for (int p = 0; p < n; ++p) diag[p] += delta;
  return true;
}

void DantzigSolver::Workspace::gatherNormals(Vector& g) const {
  for (size_t k = 0; k < frictionRows.size(); ++k) g[k] = std::abs(x[findex[frictionRows[k]]]);
}

dantzig::FrictionIteration& DantzigSolver::Workspace::startFrictionIteration(int depth,
                                                                             bool exactFriction) {
  const int nf = static_cast<int>(frictionRows.size());
  FrictionIteration& fi = friction;
  fi = FrictionIteration{0, 0, 0, kInf, 1.0, std::move(fi.g), std::move(fi.nu), std::move(fi.f)};
  fi.depth = std::max(1, depth);
  fi.g.resize(nf);
  fi.nu.resize(nf);
  fi.f.resize(nf);
  if (exactFriction) {
    histG.resize(nf, fi.depth);
    histF.resize(nf, fi.depth);
  }
  return fi;
}

double DantzigSolver::Workspace::residualOf(const Problem& pb, const Vector& xs) {
  if (pb.isSparse())
    residualW.noalias() = pb.sparseA() * xs;
  else
    residualW.noalias() = pb.denseA() * xs;
  residualW += pb.b;
  return accuracy(pb, xs, residualW).residual;
}

// Anderson acceleration of nu <- g(nu) = |x_normal(nu)|: piecewise affine, so within one active
// set a few extrapolations find the fixed point where plain iteration may spiral.
bool DantzigSolver::Workspace::nextFrictionBounds(FrictionIteration& fi, int it,
                                                  const DantzigParams& params) {
  const int nf = static_cast<int>(frictionRows.size());
  gatherNormals(fi.g);
  for (int k = 0; k < nf; ++k) {
    fi.nu[k] = normal[frictionRows[k]];
    fi.f[k] = fi.g[k] - fi.nu[k];
  }
  const double fNorm = fi.f.lpNorm<Eigen::Infinity>();
  if (fNorm == 0) return false;
  if (fNorm > 10 * fi.bestF) fi.stored = 0;  // extrapolation went astray: restart the history
  if (fNorm < fi.bestF) {
    fi.bestF = fNorm;
    fi.lastGain = it;
  } else if (it - fi.lastGain > params.andersonStall && fi.damping == 1.0) {
    fi.damping = params.stallDamping;  // stalled (a cycle between active sets): damped iteration
    fi.stored = 0;
  }
  if (fi.stored == fi.depth) {
    for (int j = 0; j + 1 < fi.depth; ++j) {
      histG.col(j) = histG.col(j + 1);
      histF.col(j) = histF.col(j + 1);
    }
    --fi.stored;
  }
  histG.col(fi.stored) = fi.g;
  histF.col(fi.stored) = fi.f;
  ++fi.stored;
  Vector& next = andersonNext;
  next = fi.nu + fi.damping * fi.f;
  if (fi.damping == 1.0 && fi.stored >= 2) {
    const int q = fi.stored - 1;
    DenseMatrix &dF = andersonDF, &dG = andersonDG;
    dF.resize(nf, q);
    dG.resize(nf, q);
    for (int j = 0; j < q; ++j) {
      dF.col(j) = histF.col(j + 1) - histF.col(j);
      dG.col(j) = histG.col(j + 1) - histG.col(j);
    }
    andersonQr.compute(dF);
    andersonGamma = andersonQr.solve(fi.f);
    if (andersonGamma.allFinite()) {
      andersonStep.noalias() = dG * andersonGamma;  // as a temporary would: the same bits
      next -= andersonStep;
    }
  }
  next = next.cwiseMax(0.0);
  setFrictionBounds(next);
  return true;
}

// New friction bounds from the normal magnitudes nu (one per friction row); rows at a bound
// follow it, so that the previous index sets stay a consistent guess.
void DantzigSolver::Workspace::setFrictionBounds(const Vector& nu) {
  for (size_t k = 0; k < frictionRows.size(); ++k) {
    const int p = frictionRows[k];
    normal[p] = nu[k];
    lo[p] = muLo[p] * nu[k];
    hi[p] = muHi[p] * nu[k];
    if (set[p] == Set::AtLo) x[p] = lo[p];
    if (set[p] == Set::AtHi) x[p] = hi[p];
  }
}

// ======================================================================= the solver

DantzigSolver::DantzigSolver() : ws_(std::make_unique<Workspace>()) {}
DantzigSolver::~DantzigSolver() = default;
DantzigSolver::DantzigSolver(DantzigSolver&&) noexcept = default;
DantzigSolver& DantzigSolver::operator=(DantzigSolver&&) noexcept = default;

int DantzigSolver::passes() const { return ws_->passes; }
bool DantzigSolver::regularised() const { return ws_->regularised; }

void DantzigSolver::run(const Problem& problem, Vector& x, Result& result) {
  Workspace& ws = *ws_;
  ws.passes = 0;
  ws.regularised = false;
  if (problem.size() == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  // A tiny island's guessed index sets (warm, or the cold guess of dantzig_small.hpp): the same
  // steps on fixed-size arrays, else the general path.
  if (!params_.regularised && detail::smallDenseApplies(problem) &&
      detail::solveSmallDense(problem, options().pivotTolerance, x)) {
    ws.passes = 1;
    result.status = Status::Converged;
    result.iterations = 0;
    result.message = "tiny-island path: guessed index sets (at most two block corrections)";
    return;
  }
  runPivoting(problem, x, result);
}

namespace {
// max |A_ii| (max |A_ij|, or 1, when the diagonal is zero): Workspace::setScales's pivot scale,
// read from the problem before any set-up.
double diagonalScale(const Problem& pb) {
  double dMax = 0, aMax = 0;
  if (pb.isSparse()) {
    const SparseMatrix& A = pb.sparseA();
    for (int k = 0; k < A.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(A, k); it; ++it) {
        aMax = std::max(aMax, std::abs(it.value()));
        if (it.row() == it.col()) dMax = std::max(dMax, std::abs(it.value()));
      }
  } else {
    dMax = pb.denseA().diagonal().cwiseAbs().maxCoeff();
    if (!(dMax > 0)) aMax = pb.denseA().cwiseAbs().maxCoeff();
  }
  return dMax > 0 ? dMax : (aMax > 0 ? aMax : 1.0);
}
}  // namespace

// The solve on A + delta I from zero (Limits in dantzig.hpp): after a breakdown of the solve on A
// (why: its message, spent: its pivots), or at once when DantzigParams::regularised asks for it.
void DantzigSolver::regularise(const Problem& problem, Vector& x, Result& result, double scale,
                               const std::string& why, int spent) {
  Workspace& ws = *ws_;
  const double delta = params_.breakdownShift * scale;
  ws.shift = delta;
  x = Vector::Zero(problem.size());
  runPivoting(problem, x, result);
  ws.shift = 0;
  ws.regularised = true;
  result.iterations += spent;
  result.message =
      "regularised: A + " + detail::shortNumber(delta) + " I " + why + "; " + result.message;
}

void DantzigSolver::runPivoting(const Problem& problem, Vector& x, Result& result) {
  const Options& opt = options();
  Workspace& ws = *ws_;
  const int n = problem.size();
  if (ws.shift == 0 && params_.regularised) {
    regularise(problem, x, result, diagonalScale(problem), "(asked for)", 0);
    return;
  }
  const bool exact = opt.frictionBounds == FrictionBounds::Exact;
  const bool friction = problem.hasFindex();
  const bool useGuess = !x.isZero(0.0);
  // A guess's friction values fix the first pass's friction bounds only when the guess is close
  // (a residual within kTrustedGuess): an engine's cached impulses give bounds so far off that
  // the second pass redoes most pivots (docs/methods/pivoting.md, "Dantzig: friction bounds").
  const bool trustFriction =
      useGuess && exact && friction && ws.residualOf(problem, x) <= kTrustedGuess;
  ws.setUp(problem, x, opt, useGuess, trustFriction);
  const bool firstFixedOnce = friction && !trustFriction;
  FrictionIteration& fi = ws.startFrictionIteration(params_.andersonDepth, friction && exact);
  int totalPivots = 0;
  for (int it = 1;; ++it) {
    ws.passes = it;
    const int before = ws.pivots;
    const Outcome o = ws.pass(it == 1 && firstFixedOnce, it > 1);
    totalPivots += ws.pivots - before;
    ws.pivots = 0;
    result.iterations = totalPivots;
    for (int p = 0; p < n; ++p) x[ws.perm[p]] = ws.x[p];
    // The default pivot limit (50 n + 100) is reached by cycling on a singular A as well.
    const bool cycled = o == Outcome::PivotLimit && opt.maxPivots <= 0;
    if ((o == Outcome::Failed || cycled) && ws.shift == 0) {
      // Pivoting breaks down on a singular A (redundant joints, coplanar contacts): once more
      // on A + delta I, cold (the guess led into the breakdown: docs/decisions.md, "Degenerate
      // rows and singular islands"); the residual is measured on A.
      regularise(problem, x, result, ws.scale, "after a breakdown (" + ws.message + ")",
                 totalPivots);
      return;
    }
    if (o != Outcome::Done) {
      reportStopped(o, ws.message, friction && exact, it, result);
      return;
    }
    const std::string singular = redundantRowsNote(ws.redundant);
    if (!friction || !exact) {
      result.status = Status::Converged;
      result.message =
          (friction ? "pivoting finished (friction bounds fixed once)" : "pivoting finished") +
          singular;
      return;
    }
    // Exact friction: the bounds settle, the passes run out, or the next pass gets new bounds.
    const double res = ws.residualOf(problem, x);
    if (frictionPassesEnd(res, it, opt, singular, result)) return;
    if (!ws.nextFrictionBounds(fi, it, params_)) {
      std::ostringstream os;
      os << "friction bounds stopped moving but the residual is " << res;
      result.status = Status::Failed;
      result.message = os.str();
      return;
    }
    if (ws.deadline != kInf && nowSeconds() > ws.deadline) {
      result.status = Status::TimeLimit;
      result.message = "time budget spent between friction passes";
      return;
    }
  }
}

}  // namespace mlcp
