#include "mlcp/solvers/dantzig.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>

#include "linalg/sparse_pattern.hpp"
#include "linalg/symmetry.hpp"
#include "mlcp/residual.hpp"
#include "pivoting/dantzig_small.hpp"
#include "pivoting/dantzig_workspace.hpp"

namespace mlcp {

using namespace dantzig;  // the workspace's vocabulary (dantzig_workspace.hpp)

namespace {

// Largest residual (residual.hpp) of a guess whose friction values set the first pass's bounds.
constexpr double kTrustedGuess = 1e-2;

}  // namespace

// ============================================================================ set-up

void DantzigSolver::Workspace::build(const Problem& pb, const Vector& guess, bool useGuess,
                                     bool exactFriction) {
  n = pb.size();
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
  // Groups: 0 equality, 1 guessed clamped, 2 other rows, 3 friction rows; a counting sort
  // (one classification per row) keeps the caller's order within a group.
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

  // Only dxFull (kept zero between steps), w, normal and diag (a sparse row may lack its
  // diagonal) are read before they are written.
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
  for (int p = 0; p < n; ++p) {
    const int i = perm[p];
    b[p] = pb.b[i];
    muLo[p] = lo[p] = pb.lo[i];
    muHi[p] = hi[p] = pb.hi[i];
    if (friction(i)) {
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

  sparse = pb.isSparse();
  if (sparse)
    buildSparse(pb);
  else
    buildDense(pb);
  double dMax = 0;
  for (int p = 0; p < n; ++p) dMax = std::max(dMax, std::abs(diag[p]));
  const double scale = dMax > 0 ? dMax : (aMax > 0 ? aMax : 1.0);
  pivTol = scale;  // multiplied by Options::pivotTolerance in run()
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
    std::ostringstream os;
    os << "pivot limit " << pivotLimit << " reached";
    message = os.str();
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
  std::ostringstream os;
  os << "row " << perm[i] << ": nothing limits the step (w = " << wi << ", Schur pivot = " << sii
     << "); the problem has no solution on this path (infeasible, or A is not a P-matrix)";
  return fail(os.str());
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
        std::ostringstream os;
        os << "row " << perm[p] << " left the clamped set and left a singular block behind";
        return fail(os.str());
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
        std::ostringstream os;
        os << "row " << perm[p] << " must join the clamped set but its pivot is " << pivot
           << " (singular principal block)";
        return fail(os.str());
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

void DantzigSolver::run(const Problem& problem, Vector& x, Result& result) {
  Workspace& ws = *ws_;
  ws.passes = 0;
  if (problem.size() == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  // A tiny island's guessed index sets (warm, or the cold guess of dantzig_small.hpp): the same
  // steps on fixed-size arrays, else the general path.
  if (detail::smallDenseApplies(problem) &&
      detail::solveSmallDense(problem, options().pivotTolerance, x)) {
    ws.passes = 1;
    result.status = Status::Converged;
    result.iterations = 0;
    result.message = "tiny-island path: guessed index sets (at most two block corrections)";
    return;
  }
  runPivoting(problem, x, result);
}

void DantzigSolver::runPivoting(const Problem& problem, Vector& x, Result& result) {
  const Options& opt = options();
  Workspace& ws = *ws_;
  const int n = problem.size();
  const bool exact = opt.frictionBounds == FrictionBounds::Exact;
  const bool useGuess = !x.isZero(0.0);
  // A guess's friction values fix the first pass's friction bounds only when the guess is
  // close (a residual within kTrustedGuess): Bullet's cached
  // impulses (residual 0.1-0.7, friction directions that turn between steps) gave bounds so far
  // off that the second pass redid most pivots, where the first pass's cold bounds (as
  // FixedOnce) needed half as many pivots in all.
  const bool trustFriction =
      useGuess && exact && problem.hasFindex() && residual(problem, x) <= kTrustedGuess;
  if (ws.shift == 0) ws.guess = x;
  ws.build(problem, x, useGuess, trustFriction);
  if (ws.shift > 0) ws.shiftDiagonal(ws.shift);
  ws.pivTol *= opt.pivotTolerance;
  ws.pivots = 0;
  ws.pivotLimit = opt.maxPivots > 0 ? opt.maxPivots : 50 * n + 100;
  ws.deadline = budgetDeadline(opt);  // the solve's (Solver sets budgetStart)
  ws.clockEvery = std::max(1, 1024 / std::max(1, n));
  ws.message.clear();
  // Pass 1 guesses the equality rows and (warm) the rows inside their bounds as clamped.
  for (int p = 0; p < n; ++p) {
    const int i = ws.perm[p];
    const bool guessed = isFreeRow(problem.lo[i], problem.hi[i]) ||
                         (useGuess && ws.x[p] > ws.lo[p] && ws.x[p] < ws.hi[p]);
    ws.set[p] = guessed ? Set::Clamped : Set::Unprocessed;
  }
  const bool friction = problem.hasFindex();
  const bool firstFixedOnce = friction && !trustFriction;
  auto writeBack = [&] {
    for (int p = 0; p < n; ++p) x[ws.perm[p]] = ws.x[p];
  };
  int totalPivots = 0;
  const int nf = static_cast<int>(ws.frictionRows.size());
  const int depth = std::max(1, params_.andersonDepth);
  int stored = 0;
  double bestF = kInf, damping = 1.0;
  int lastGain = 0;
  Vector g(nf), nu(nf), f(nf);
  if (friction && exact) {
    ws.histG.resize(nf, depth);
    ws.histF.resize(nf, depth);
  }
  for (int it = 1;; ++it) {
    ws.passes = it;
    const int before = ws.pivots;
    const Outcome o = ws.pass(it == 1 && firstFixedOnce, it > 1);
    totalPivots += ws.pivots - before;
    ws.pivots = 0;
    result.iterations = totalPivots;
    writeBack();
    // The default pivot limit (50 n + 100) is reached by cycling on a singular A as well.
    const bool cycled = o == Outcome::PivotLimit && opt.maxPivots <= 0;
    if ((o == Outcome::Failed || cycled) && ws.shift == 0) {
      // Pivoting breaks down on a singular A (redundant joints, coplanar contacts): once more
      // on A + delta I, cold (the guess led into the breakdown; from Bullet's cached impulses
      // the regularised friction passes needed more than 50); the residual is measured on A.
      const std::string first = ws.message;
      const int spent = totalPivots;
      const double delta = params_.breakdownShift * ws.scale;
      ws.shift = delta;
      x = Vector::Zero(n);
      runPivoting(problem, x, result);
      ws.shift = 0;
      result.iterations += spent;
      std::ostringstream os;
      os << "regularised: A + " << delta << " I after a breakdown (" << first << "); "
         << result.message;
      result.message = os.str();
      return;
    }
    if (o != Outcome::Done) {
      std::ostringstream os;
      result.status = o == Outcome::Failed       ? Status::Failed
                      : o == Outcome::PivotLimit ? Status::MaxIterations
                                                 : Status::TimeLimit;
      os << ws.message;
      if (friction && exact) os << " (friction pass " << it << ")";
      result.message = os.str();
      return;
    }
    // Redundant rows (a singular A) are said: their x is one of many answers.
    const std::string singular = ws.redundant > 0 ? "; " + std::to_string(ws.redundant) +
                                                        " redundant rows left free (A is singular)"
                                                  : "";
    if (!friction || !exact) {
      result.status = Status::Converged;
      result.message =
          (friction ? "pivoting finished (friction bounds fixed once)" : "pivoting finished") +
          singular;
      return;
    }
    std::ostringstream os;  // only on the friction path: its set-up costs as much as a tiny solve
    const double res = residual(problem, x);
    if (res <= opt.tolerance) {
      result.status = Status::Converged;
      os << "friction bounds settled after " << it << " pass" << (it > 1 ? "es" : "") << singular;
      result.message = os.str();
      return;
    }
    if (it >= opt.maxIterations) {
      result.status = Status::MaxIterations;
      os << "friction bounds still moving after " << it << " passes (residual " << res << ")";
      result.message = os.str();
      return;
    }
    // Anderson acceleration of nu <- g(nu) = |x_normal(nu)|: piecewise affine, so within one
    // active set a few extrapolations find the fixed point where plain iteration may spiral.
    ws.gatherNormals(g);
    for (int k = 0; k < nf; ++k) {
      nu[k] = ws.normal[ws.frictionRows[k]];
      f[k] = g[k] - nu[k];
    }
    const double fNorm = f.lpNorm<Eigen::Infinity>();
    if (fNorm == 0) {
      result.status = Status::Failed;
      os << "friction bounds stopped moving but the residual is " << res;
      result.message = os.str();
      return;
    }
    if (fNorm > 10 * bestF) stored = 0;  // extrapolation went astray: restart the history
    if (fNorm < bestF) {
      bestF = fNorm;
      lastGain = it;
    } else if (it - lastGain > params_.andersonStall && damping == 1.0) {
      damping =
          params_.stallDamping;  // stalled (a cycle between active sets): plain damped iteration
      stored = 0;
    }
    if (stored == depth) {
      for (int j = 0; j + 1 < depth; ++j) {
        ws.histG.col(j) = ws.histG.col(j + 1);
        ws.histF.col(j) = ws.histF.col(j + 1);
      }
      --stored;
    }
    ws.histG.col(stored) = g;
    ws.histF.col(stored) = f;
    ++stored;
    Vector next = nu + damping * f;
    if (damping == 1.0 && stored >= 2) {
      const int q = stored - 1;
      DenseMatrix dF(nf, q), dG(nf, q);
      for (int j = 0; j < q; ++j) {
        dF.col(j) = ws.histF.col(j + 1) - ws.histF.col(j);
        dG.col(j) = ws.histG.col(j + 1) - ws.histG.col(j);
      }
      const Vector gamma = dF.colPivHouseholderQr().solve(f);
      if (gamma.allFinite()) next -= dG * gamma;
    }
    ws.setFrictionBounds(next.cwiseMax(0.0));
    if (ws.deadline != kInf && nowSeconds() > ws.deadline) {
      result.status = Status::TimeLimit;
      result.message = "time budget spent between friction passes";
      return;
    }
  }
}

}  // namespace mlcp
