#include "mlcp/newton.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "linalg/cholmod_factor.hpp"
#include "mlcp/pgs.hpp"
#include "newton_system.hpp"

namespace mlcp {

namespace {

// The widest band inside a bound in which a row pushing outward is held (Bertsekas' eps).
constexpr double kActiveBand = 1e-3;

// Squared 2-norm of the natural map at (x, w) with the bounds at x; inf holds its inf-norm.
double naturalMerit(const Problem& pb, const Vector& x, const Vector& w, double& inf) {
  double sum = 0;
  inf = 0;
  for (int i = 0; i < pb.size(); ++i) {
    const double h = x[i] - std::clamp(x[i] - w[i], pb.effectiveLo(i, x), pb.effectiveHi(i, x));
    sum += h * h;
    inf = std::max(inf, std::abs(h));
  }
  return std::isfinite(sum) ? sum : kInf;
}

}  // namespace

// Per-solve vectors, kept so that repeated solves of one size do not allocate.
struct NewtonSolver::Work {
  explicit Work(linalg::CholmodFactor& cholmod) : system(cholmod) {}
  detail::NewtonSystem system;
  Vector w, dx, xt, wt, best, invDiag, lo, hi;
  std::vector<char> inC;
};

NewtonSolver::NewtonSolver() : cholmod_(std::make_unique<linalg::CholmodFactor>()) {
  work_ = std::make_unique<Work>(*cholmod_);
}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

int NewtonSolver::analyses() const { return cholmod_->analyses(); }

namespace {

// x onto its bounds: the normals (rows without findex) first, then the friction rows' bounds
// from them.
void project(const Problem& pb, Vector& x) {
  const bool coupled = pb.hasFindex();
  for (int i = 0; i < pb.size(); ++i)
    if (!coupled || pb.findex[i] < 0) x[i] = std::clamp(x[i], pb.lo[i], pb.hi[i]);
  if (coupled)
    for (int i = 0; i < pb.size(); ++i)
      if (pb.findex[i] >= 0) x[i] = std::clamp(x[i], pb.effectiveLo(i, x), pb.effectiveHi(i, x));
}

// f(x) = x^T A x / 2 + b^T x, from w = A x + b.
double quadratic(const Problem& pb, const Vector& x, const Vector& w) {
  return 0.5 * x.dot(w + pb.b);
}

// Projected Newton's sets at a feasible x (Bertsekas' eps-active set): a row is held when it is
// fixed, or within eps of a bound with w pushing outward; the others are free (inC). rhs gets -w
// on the free rows, the scaled gradient step -w_i / A_ii on the held ones (0 on fixed rows), which
// the projection ends at the bound. Returns the free rows' count.
int freeRows(const Vector& x, const Vector& w, const Vector& lo, const Vector& hi,
             const Vector& invDiag, double eps, std::vector<char>& inC, Vector& rhs) {
  int free = 0;
  for (int i = 0; i < x.size(); ++i) {
    const bool fixed = lo[i] == hi[i];
    const bool held =
        fixed || (x[i] - lo[i] <= eps && w[i] > 0) || (hi[i] - x[i] <= eps && w[i] < 0);
    inC[i] = !held;
    rhs[i] = !held ? -w[i] : fixed ? 0.0 : -w[i] * invDiag[i];
    free += !held;
  }
  return free;
}

}  // namespace

// One step from x (w, lo, hi of x in the work vectors): the free rows' direction and the
// projected Armijo search on f along it (newton.hpp "Step"); on success the new point is in
// work_->xt. A direction without an acceptable step length is recomputed with a larger mu.
bool NewtonSolver::search(const Problem& pb, const Vector& x, double res, double dMax, double& mu) {
  Work& wk = *work_;
  const NewtonParams& par = params_;
  const double f = quadratic(pb, x, wk.w);
  const double band = std::min(kActiveBand, res * (1.0 + pb.b.lpNorm<Eigen::Infinity>()));
  for (;;) {
    const int free = freeRows(x, wk.w, wk.lo, wk.hi, wk.invDiag, band, wk.inC, wk.dx);
    const double rho = mu * dMax * std::min(1.0, res);
    ++factorizations_;
    const bool solved = free > 0 && wk.system.factor(wk.inC, rho) && wk.system.solve(wk.dx);
    for (int h = 0; solved && h <= par.maxHalvings; ++h) {
      wk.xt = (x + std::ldexp(1.0, -h) * wk.dx).cwiseMax(wk.lo).cwiseMin(wk.hi);
      wk.wt = pb.slack(wk.xt);
      if (quadratic(pb, wk.xt, wk.wt) <= f + 1e-4 * wk.w.dot(wk.xt - x)) {
        if (h == 0) mu = std::max(mu * 0.1, 1e-12);
        return true;
      }
    }
    if (mu >= par.proximalMax) return false;
    mu *= 10;
  }
}

void NewtonSolver::run(const Problem& pb, Vector& x, Result& result) {
  const Options& opt = options();
  const NewtonParams& par = params_;
  const int n = pb.size();
  factorizations_ = 0;
  result.iterations = 0;
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  const bool symmetric = detail::symmetricMatrix(pb);
  if (!symmetric) {
    result.status = Status::Unsupported;
    result.message = "newton needs a symmetric A (use dantzig or lemke)";
    return;
  }
  Work& wk = *work_;
  std::string why;
  if (!wk.system.prepare(pb, par.denseMaxRows, why)) {
    result.status = Status::Failed;
    result.message = why;
    return;
  }
  const double start = opt.timeBudget > 0 ? nowSeconds() : 0.0;
  const bool haveDiag = detail::inverseDiagonal(pb, wk.invDiag) < 0;
  if (x.isZero(0.0) && par.coldSweeps > 0 && haveDiag)
    for (int k = 0; k < par.coldSweeps; ++k) detail::pgsSweep(pb, wk.invDiag, 1.0, x);
  double dMax = 0;
  for (int i = 0; i < n; ++i) dMax = std::max(dMax, std::abs(pb.diagonal(i)));
  if (!(dMax > 0)) dMax = 1;
  const double scale = 1.0 + pb.b.lpNorm<Eigen::Infinity>();
  wk.inC.assign(n, 0);
  wk.dx.resize(n);
  wk.lo.resize(n);
  wk.hi.resize(n);
  wk.w = pb.slack(x);
  double startInf = 0;
  double bestTheta = naturalMerit(pb, x, wk.w, startInf);  // the start counts as an iterate
  wk.best = x;
  double mu = par.proximal;
  int stalls = 0;
  std::ostringstream os;
  for (int step = 0;; ++step) {
    if (step > 0 && par.stepSweeps > 0 && haveDiag)  // sweeps settle the sets of the step
      for (int k = 0; k < par.stepSweeps; ++k) detail::pgsSweep(pb, wk.invDiag, 1.0, x);
    // The outer refresh: friction bounds from the current normals, x onto them.
    project(pb, x);
    for (int i = 0; i < n; ++i) {
      wk.lo[i] = pb.effectiveLo(i, x);
      wk.hi[i] = pb.effectiveHi(i, x);
    }
    wk.w = pb.slack(x);
    double inf = 0;
    const double theta = naturalMerit(pb, x, wk.w, inf);
    if (theta <= bestTheta) {
      bestTheta = theta;
      wk.best = x;
    }
    const double res = inf / scale;
    if (res <= opt.tolerance) {
      result.status = Status::Converged;
      os << "converged after " << step << " Newton step" << (step == 1 ? "" : "s");
      break;
    }
    if (step >= opt.maxIterations) {
      result.status = Status::MaxIterations;
      os << step << " Newton steps, residual " << res;
      break;
    }
    if (opt.timeBudget > 0 && nowSeconds() - start > opt.timeBudget) {
      result.status = Status::TimeLimit;
      os << "time budget spent after " << step << " Newton steps, residual " << res;
      break;
    }
    result.iterations = step + 1;
    const bool moved = search(pb, x, res, dMax, mu);
    if (!moved) {
      if (++stalls > par.maxStalls) {
        result.status = Status::Failed;
        os << "no descent after " << step + 1 << " Newton steps, residual " << res;
        break;
      }
      continue;
    }
    stalls = 0;
    x = wk.xt;
  }
  if (result.status != Status::Converged) x = wk.best;
  result.message = os.str();
}

}  // namespace mlcp
