#include "mlcp/solvers/proximal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/rows.hpp"

namespace mlcp {

// The shifted problem and rows, kept so that repeated solves of one size reuse their storage.
struct ProximalSolver::Work {
  std::unique_ptr<Solver> inner, fallback;
  std::string innerName, fallbackName;
  Problem shifted;            // A + alpha I, b - alpha x_k, the bounds and findex
  DenseMatrix dense;          // shifted's A while its diagonal is written (swapA)
  SparseMatrix sparse;        // likewise, sparse storage
  std::vector<int> diagonal;  // sparse: the index of A_ii in the values array
  Vector baseDiagonal;        // A_ii
  RowSystem rows;             // the rows with cfm + alpha and b - alpha x_k
  bool useRows = false;
  Vector xk, next, best, first;  // first: the inner method's answer while its fallback runs
};

ProximalSolver::ProximalSolver() : work_(std::make_unique<Work>()) {}
ProximalSolver::~ProximalSolver() = default;
ProximalSolver::ProximalSolver(ProximalSolver&&) noexcept = default;
ProximalSolver& ProximalSolver::operator=(ProximalSolver&&) noexcept = default;

namespace {
// The largest alpha / mean(A_ii) that growth after failed inner solves reaches: A + alpha I is then
// dominated by its diagonal, and every inner method solves it in a few steps.
constexpr double kAlphaCeiling = 1e2;
// The most alpha falls in one outer step: the inner problem at alpha / 10 starts from the answer
// at alpha, close enough for its method; a larger fall (alpha following a residual that dropped
// 100x) left inner solves on piles short.
constexpr double kMaxAlphaDrop = 10;

// Why `name` cannot be the inner solver, or "".
std::string innerError(const std::string& name) {
  if (name == "proximal" || name == "auto" || name.find('>') != std::string::npos)
    return "proximal: inner solver '" + name + "' must be a single method other than auto";
  if (!isRegistered(name))
    return "proximal: inner solver: unknown solver '" + name + "' (known: " + solverNames() + ")";
  return "";
}

// The sparse matrix A with every diagonal entry stored (an explicit zero where A has none), so
// that alpha can be written in place.
SparseMatrix withDiagonal(const SparseMatrix& a) {
  SparseMatrix zero(a.rows(), a.cols());
  zero.reserve(Eigen::VectorXi::Constant(a.rows(), 1));
  for (int i = 0; i < a.rows(); ++i) zero.insert(i, i) = 0.0;
  SparseMatrix s = a + zero;
  s.makeCompressed();
  return s;
}
// The solver of this name kept in `slot` (made, after innerError's check, when the name
// changed), or null.
Solver* keptSolver(std::unique_ptr<Solver>& slot, std::string& slotName, const std::string& name) {
  if (slot && slotName == name) return slot.get();
  slot = name.empty() || !innerError(name).empty() ? nullptr : makeSolver(name);
  slotName = name;
  if (slot) slot->setTimed(false);
  return slot.get();
}
}  // namespace

Solver* ProximalSolver::inner() {
  return keptSolver(work_->inner, work_->innerName, params_.inner);
}

Solver* ProximalSolver::innerFallback() {
  return keptSolver(work_->fallback, work_->fallbackName, params_.innerFallback);
}

void ProximalSolver::prepare(const Problem& problem) {
  Work& wk = *work_;
  const int n = problem.size();
  wk.baseDiagonal.resize(n);
  for (int i = 0; i < n; ++i) wk.baseDiagonal[i] = problem.diagonal(i);
  wk.shifted.b = problem.b;
  wk.shifted.lo = problem.lo;
  wk.shifted.hi = problem.hi;
  wk.shifted.findex = problem.findex;
  if (problem.isSparse()) {
    wk.sparse = withDiagonal(problem.sparseA());
    wk.diagonal.assign(n, -1);
    const int* outer = wk.sparse.outerIndexPtr();
    const int* inner = wk.sparse.innerIndexPtr();
    for (int i = 0; i < n; ++i)
      for (int k = outer[i]; k < outer[i + 1]; ++k)
        if (inner[k] == i) wk.diagonal[i] = k;
    wk.shifted.swapA(wk.sparse);
  } else {
    wk.dense = problem.denseA();
    wk.shifted.swapA(wk.dense);
  }
  wk.useRows = rows_ != nullptr && rows_->size() == n && rows_->cfm.size() == n;
  if (wk.useRows) wk.rows = *rows_;
}

void ProximalSolver::shift(const Problem& problem, const Vector& xk, double alpha) {
  Work& wk = *work_;
  const int n = problem.size();
  if (wk.shifted.isSparse()) {
    wk.shifted.swapA(wk.sparse);  // out of the problem, written, and back
    double* values = wk.sparse.valuePtr();
    for (int i = 0; i < n; ++i) values[wk.diagonal[i]] = wk.baseDiagonal[i] + alpha;
    wk.shifted.swapA(wk.sparse);
  } else {
    wk.shifted.swapA(wk.dense);
    wk.dense.diagonal() = wk.baseDiagonal.array() + alpha;
    wk.shifted.swapA(wk.dense);
  }
  wk.shifted.b = problem.b - alpha * xk;
  if (wk.useRows) {
    wk.rows.cfm = rows_->cfm.array() + alpha;
    wk.rows.b = wk.shifted.b;
  }
}

// alpha / mean(A_ii) for the next outer step ("Schedule" in proximal.hpp): after a failed inner
// solve, rel times alphaGrowth; otherwise sigma r^nu within [alphaMin, alphaMax], falling by at
// most kMaxAlphaDrop a step and not below the floor a failed solve left (twice its alpha, halved
// at every solved step): an alpha that failed is not tried again at once.
double ProximalSolver::nextAlpha(double rel, double r, bool failedLast, double floor) const {
  if (failedLast) return std::min(rel * params_.alphaGrowth, kAlphaCeiling);
  const double fromResidual = params_.sigma * std::pow(std::isfinite(r) ? r : 1.0, params_.nu);
  double next = std::clamp(fromResidual, params_.alphaMin, params_.alphaMax);
  if (rel > 0) next = std::max(next, rel / kMaxAlphaDrop);
  return std::min(std::max(next, floor), kAlphaCeiling);
}

// One inner solve of the shifted problem from x_k into wk.next, with the inner tolerance.
Result ProximalSolver::innerSolve(Solver& inner, const Options& io) {
  Work& wk = *work_;
  inner.setOptions(io);
  inner.useRows(wk.useRows ? &wk.rows : nullptr);
  Result ir = inner.solveWithGuess(wk.shifted, wk.xk, wk.next);
  inner.useRows(nullptr);
  innerIterations_ += ir.iterations;
  return ir;
}

// The inner solve of one outer step: the inner method, and the inner fallback from the same x_k
// when its answer ends short of the inner tolerance (the better of the two stands). True when an
// answer met the inner tolerance.
bool ProximalSolver::outerStep(const Problem& problem, double alpha, double r, int& fallbacks) {
  Work& wk = *work_;
  const Options& o = options();
  shift(problem, wk.xk, alpha);
  Options io = o;
  io.tolerance = std::max(o.tolerance / 10, params_.innerFactor * (std::isfinite(r) ? r : 1.0));
  io.maxIterations = Options().maxIterations;
  io.warmStart = true;
  io.recordHistory = false;
  const auto solved = [&](const Result& ir) {
    return wk.next.size() == problem.size() && wk.next.allFinite() &&
           (ir.status == Status::Converged || ir.residual <= io.tolerance);
  };
  const Result ir = innerSolve(*inner(), io);
  if (solved(ir)) return true;
  Solver* fallback = innerFallback();
  if (!fallback || outOfTime()) return false;
  ++fallbacks;
  wk.first.swap(wk.next);
  const Result fr = innerSolve(*fallback, io);
  if (solved(fr)) return true;
  if (!(fr.residual < ir.residual)) wk.first.swap(wk.next);  // the inner method's answer stands
  return false;
}

void ProximalSolver::run(const Problem& problem, Vector& x, Result& result) {
  Work& wk = *work_;
  const Options& o = options();
  innerIterations_ = 0;
  lastAlpha_ = 0;
  for (const std::string& name : {params_.inner, params_.innerFallback}) {
    if (&name == &params_.innerFallback && name.empty()) continue;
    if (const std::string why = innerError(name); !why.empty()) {
      result.status = Status::InvalidInput;
      result.message = why;
      return;
    }
  }
  const int n = problem.size();
  double scale = 1;  // mean |A_ii|, the unit of alpha (set with the shifted problem)
  const auto residualOf = [&](const Vector& v) {
    if (v.size() != n) return kInf;
    const Accuracy a = accuracy(problem, v);
    return a.finite ? a.residual : kInf;
  };
  wk.xk = x;
  double r = residualOf(wk.xk);
  wk.best = wk.xk;
  double bestR = r;
  if (o.recordHistory) result.history.push_back(r);
  const int maxOuter = std::min(params_.maxOuter, o.maxIterations);
  int outer = 0, shortInner = 0, fallbacks = 0;
  bool failedLast = false, prepared = false;
  double rel = 0, floor = 0;  // alpha / mean(A_ii), and its floor after a failed inner solve
  Status stop = Status::MaxIterations;
  while (!(bestR <= o.tolerance) && outer < maxOuter) {
    if (outOfTime()) {
      stop = Status::TimeLimit;
      break;
    }
    if (!prepared) {
      prepare(problem);
      const double mean = wk.baseDiagonal.cwiseAbs().mean();
      if (mean > 0) scale = mean;
      prepared = true;
    }
    rel = nextAlpha(rel, r, failedLast, floor);
    lastAlpha_ = scale * rel;
    const bool solved = outerStep(problem, lastAlpha_, r, fallbacks);
    ++outer;
    const double nr = residualOf(wk.next);
    if (o.recordHistory) result.history.push_back(nr);
    if (nr < bestR) {
      bestR = nr;
      wk.best = wk.next;
    }
    failedLast = !solved;
    floor = solved ? floor / 2 : std::max(floor, 2 * rel);
    shortInner += solved ? 0 : 1;
    if (solved || nr < r) {  // the next proximal centre
      wk.xk.swap(wk.next);
      r = nr;
    }
  }
  x = wk.best;
  result.iterations = outer;
  result.status = bestR <= o.tolerance ? Status::Converged : stop;
  char text[200];
  std::snprintf(text, sizeof text,
                "%d outer steps (%d inner solves short, %d by %s), %d inner iterations, last "
                "alpha %.3g (%.3g mean A_ii)",
                outer, shortInner, fallbacks, params_.innerFallback.c_str(), innerIterations_,
                lastAlpha_, lastAlpha_ / scale);
  result.message = text;
}

}  // namespace mlcp
