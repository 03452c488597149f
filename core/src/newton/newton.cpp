#include "mlcp/solvers/newton.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "newton/block_pivoting.hpp"
#include "newton/newton_system.hpp"
#include "projection/pgs_sweep.hpp"

namespace mlcp {

namespace {
// Armijo's constant: a step of length t is accepted when ||H||^2 falls by sigma t |slope|.
constexpr double kArmijo = 1e-4;
// Levenberg-Marquardt weights the dense path tries, lambda = ||H||_2 10^k, k < this.
constexpr int kRegularizedTries = 4;
}  // namespace

// An iterate with its slack and natural map, and the per-solve workspaces, kept so that
// repeated solves of one size do not allocate.
struct NewtonSolver::Work {
  struct Point {
    Vector x, w, h;
    double theta = kInf, inf = kInf;  // ||h||_2^2 and ||h||_inf
    void evaluate(const Problem& pb, const detail::NewtonSystem& system) {
      system.slack(x, w);
      theta = detail::naturalMap(pb, x, w, h, inf);
    }
    // The point from + t dx, its slack from + t A dx (adx): O(n), no product with A.
    void evaluateAlong(const Problem& pb, const Point& from, double t, const Vector& dx,
                       const Vector& adx) {
      x = from.x + t * dx;
      w = from.w + t * adx;
      theta = detail::naturalMap(pb, x, w, h, inf);
    }
  };
  detail::NewtonSystem system;
  detail::BlockPivoting pivoting;
  Point at, trial, best;
  Vector dx, adx, g, jg, invDiag;  // adx = A dx
  // The merits of the iterates so far, and the line search's reference: the largest of the
  // current one and the NewtonParams::nonmonotoneMemory before it.
  std::vector<double> merits;
  double reference = kInf;
};

NewtonSolver::NewtonSolver() : work_(std::make_unique<Work>()) {}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

int NewtonSolver::analyses() const { return work_->system.analyses(); }
int NewtonSolver::bodyFactorizations() const { return work_->system.bodyFactorizations(); }
void NewtonSolver::useRows(const RowSystem* rows) { work_->system.useRows(rows); }

// Backtracking from t = 1 along wk.dx from wk.at: the first t = 2^-k (k <= the halvings) with
// ||H(x + t dx)||^2 <= reference + sigma t slope (slope < 0, the directional derivative;
// reference: Work::reference). On success wk.trial holds the point; returns the halvings taken,
// or -1.
int NewtonSolver::lineSearch(const Problem& pb, double slope) {
  Work& wk = *work_;
  if (!(slope < 0)) return -1;
  const int halvings = wk.system.isSparse() ? params_.sparseMaxHalvings : params_.maxHalvings;
  wk.system.product(wk.dx, wk.adx);
  for (int k = 0; k <= halvings; ++k) {
    const double t = std::ldexp(1.0, -k);
    wk.trial.evaluateAlong(pb, wk.at, t, wk.dx, wk.adx);
    if (wk.trial.theta <= wk.reference + kArmijo * t * slope) return k;
  }
  return -1;
}

// Records the current merit and sets the line search's reference to the largest of it and the
// last NewtonParams::nonmonotoneMemory merits before it (docs/methods/newton.md, "Step").
void NewtonSolver::setReference() {
  Work& wk = *work_;
  wk.merits.push_back(wk.at.theta);
  const std::size_t count =
      std::min(wk.merits.size(), std::size_t(1) + std::max(0, params_.nonmonotoneMemory));
  wk.reference = *std::max_element(wk.merits.end() - count, wk.merits.end());
}

// The directional derivative of ||H||^2 at wk.at along wk.dx: 2 (J^T H) . dx.
double NewtonSolver::slope() {
  Work& wk = *work_;
  wk.system.transposeTimes(wk.at.h, wk.g);
  return 2 * wk.g.dot(wk.dx);
}

// One Newton step from wk.at (linearized) (docs/methods/newton.md, "Step"). On success wk.trial
// holds the new point and mu is adapted to the step length found.
bool NewtonSolver::newtonStep(const Problem& pb, double res, double rhoScale, double& mu) {
  Work& wk = *work_;
  const bool sparse = wk.system.isSparse();
  for (;;) {
    const double rho = sparse ? mu * rhoScale * std::min(1.0, res) : 0.0;
    ++factorizations_;
    wk.dx = -wk.at.h;
    const bool solved = wk.system.factor(rho) && wk.system.solve(wk.dx);
    const int halvings = solved ? lineSearch(pb, slope()) : -1;
    if (halvings == 0) mu = std::max(mu * 0.1, 1e-12);
    if (halvings >= 2) mu = std::min(mu * 10, params_.proximalMax);
    if (halvings >= 0) return true;
    if (!sparse || mu >= params_.proximalMax) break;
    mu *= 10;
  }
  if (sparse) return false;
  double lambda = std::sqrt(wk.at.theta);
  for (int k = 0; k < kRegularizedTries; ++k, lambda *= 10) {
    wk.dx = -wk.at.h;
    if (wk.system.solveRegularized(lambda, wk.dx) && lineSearch(pb, slope()) >= 0) return true;
  }
  return false;
}

// The fallback when no Newton step descends (docs/methods/newton.md, "Fallback"). Returns false
// when it does not move x.
bool NewtonSolver::fallbackStep(const Problem& pb, bool sweeps) {
  Work& wk = *work_;
  if (sweeps) {
    wk.trial.x = wk.at.x;
    for (int k = 0; k < params_.stepSweeps; ++k) wk.system.sweep(wk.invDiag, wk.trial.x);
    wk.trial.evaluate(pb, wk.system);
    return true;
  }
  wk.system.transposeTimes(wk.at.h, wk.g);
  wk.system.times(wk.g, wk.jg);
  const double gg = wk.g.squaredNorm(), jgjg = wk.jg.squaredNorm();
  if (!(gg > 0) || !(jgjg > 0)) return false;
  wk.dx = -(gg / jgjg) * wk.g;  // the Cauchy point of the linear model along -J^T H
  return lineSearch(pb, -2 * gg * gg / jgjg) >= 0;
}

// The start (docs/methods/newton.md, "Starts"), where sweeps apply: from zero coldSweeps sweeps; a
// warm start whose scaled residual exceeds warmSweepsResidual warmSweeps sweeps; otherwise x as
// given.
void NewtonSolver::start(const Problem& pb, Vector& x, bool sweeps) {
  if (!sweeps) return;
  const bool cold = x.isZero(0.0);
  const double guess = work_->best.inf / (1.0 + pb.b.lpNorm<Eigen::Infinity>());
  const int count = cold                                 ? params_.coldSweeps
                    : guess > params_.warmSweepsResidual ? params_.warmSweeps
                                                         : 0;
  for (int k = 0; k < count; ++k) work_->system.sweep(work_->invDiag, x);
}

void NewtonSolver::run(const Problem& pb, Vector& x, Result& result) {
  const Options& opt = options();
  const int n = pb.size();
  factorizations_ = 0;
  pivotingSteps_ = 0;
  result.iterations = 0;
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  Work& wk = *work_;
  wk.system.prepare(pb, params_.denseFactorMaxRows);
  // Sweeps (the cold start, the fallback) need A_ii > 0 and descend for symmetric A.
  const bool sweeps = detail::inverseDiagonal(pb, wk.invDiag) < 0 && wk.system.symmetric();
  wk.best.x = x;  // the start as given counts as an iterate: never return worse
  wk.best.evaluate(pb, wk.system);
  start(pb, x, sweeps);
  double dMax = 0;
  for (int i = 0; i < n; ++i) dMax = std::max(dMax, std::abs(pb.diagonal(i)));
  const double rhoScale = dMax > 0 ? dMax : 1.0;
  const double scale = 1.0 + pb.b.lpNorm<Eigen::Infinity>();
  wk.at.x.swap(x);
  wk.at.evaluate(pb, wk.system);
  double mu = params_.proximal;
  int stalls = 0, sinceBest = 0;
  wk.merits.clear();
  std::ostringstream os;
  for (int step = 0;; ++step) {
    if (wk.at.inf < wk.best.inf) {
      wk.best = wk.at;
      sinceBest = 0;
    }
    const double res = wk.at.inf / scale;
    if (res <= opt.tolerance) {
      result.status = Status::Converged;
      os << "converged after " << step << " Newton step" << (step == 1 ? "" : "s");
      break;
    }
    if (outOfTime()) {
      result.status = Status::TimeLimit;
      os << "time budget spent after " << step << " Newton steps, residual " << res;
      break;
    }
    if (step >= opt.maxIterations) {
      result.status = Status::MaxIterations;
      os << step << " Newton steps, residual " << res;
      break;
    }
    if (++sinceBest > params_.maxStagnation) {
      // A limit reached before the tolerance (the best iterate is the answer, measured like any
      // other), not a breakdown: the fallback rule then judges it by its residual alone.
      result.status = Status::MaxIterations;
      os << "no progress in " << params_.maxStagnation << " Newton steps, residual "
         << wk.best.inf / scale;
      break;
    }
    result.iterations = step + 1;
    setReference();
    wk.system.linearize(wk.at.x, wk.at.w);
    if (newtonStep(pb, res, rhoScale, mu)) {
      stalls = 0;
    } else if (mu = params_.proximal; ++stalls > params_.maxStalls || !fallbackStep(pb, sweeps)) {
      result.status = Status::Failed;
      os << "no descent after " << step + 1 << " Newton steps, residual " << res;
      break;
    }
    std::swap(wk.at, wk.trial);
  }
  x.swap(result.status == Status::Converged ? wk.at.x : wk.best.x);
  if (result.status == Status::MaxIterations || result.status == Status::Failed)
    pivotingPhase(pb, x, result, os);
  result.message = os.str();
}

// The pivoting phase (newton.hpp, "Pivoting phase"): block principal pivoting from x, the damped
// steps' best iterate, with its first index sets from where x lies. x and result take its answer
// when it settles, else its best iterate (never worse than x: its start counts as an iterate).
void NewtonSolver::pivotingPhase(const Problem& pb, Vector& x, Result& result, std::ostream& os) {
  Work& wk = *work_;
  const RowSystem* rows = wk.system.rows();
  const bool body = rows != nullptr && rows->size() == pb.size() && !rows->hasArticulated();
  const int steps = body ? params_.bodyPivotingSteps : params_.pivotingSteps;
  if (steps <= 0 || !wk.system.isSparse() || !wk.system.symmetric() || outOfTime()) return;
  wk.pivoting.setRows(body ? rows : nullptr);
  wk.pivoting.setLimits(params_);
  const detail::BlockPivoting::Report rep = wk.pivoting.run(pb, x, options(), steps, true, true);
  pivotingSteps_ = rep.steps;
  result.iterations += rep.steps;
  os << "; then " << rep.message;
  if (rep.settled)
    result.status = Status::Converged;
  else if (outOfTime())
    result.status = Status::TimeLimit;
}

}  // namespace mlcp
