#include "mlcp/solver.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <utility>

#include "mlcp/residual.hpp"

namespace mlcp {

const char* toString(Status s) {
  switch (s) {
    case Status::Converged: return "converged";
    case Status::MaxIterations: return "max-iterations";
    case Status::TimeLimit: return "time-limit";
    case Status::Failed: return "failed";
    case Status::Unsupported: return "unsupported";
    case Status::InvalidInput: return "invalid-input";
    case Status::NumericalIssue: return "numerical-issue";
    case Status::LeastSquares: return "least-squares";
  }
  return "unknown";
}

double nowSeconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

double budgetDeadline(const Options& o) {
  if (!(o.timeBudget > 0)) return std::numeric_limits<double>::infinity();
  return (o.budgetStart > 0 ? o.budgetStart : nowSeconds()) + o.timeBudget;
}

bool Solver::outOfTime() const {
  return options_.timeBudget > 0 && nowSeconds() > options_.budgetStart + options_.timeBudget;
}

void applyAccuracy(Result& r, const Accuracy& a, double tolerance) {
  r.residual = a.residual;
  r.complementarity = a.complementarity;
  r.boundViolation = a.boundViolation;
  if (!a.finite) {
    r.status = Status::NumericalIssue;
    if (r.message.empty()) r.message = "the iterate holds NaN or Inf";
  } else if (a.residual <= tolerance) {
    // An iterative method may stop on its own criterion; the checked residual decides.
    if (r.status == Status::LeastSquares) {
      // Inconsistent only below the tolerance: an answer like any other.
      r.status = Status::Converged;
      r.message += "; the residual is within tolerance";
    } else if (r.status == Status::MaxIterations || r.status == Status::TimeLimit) {
      r.status = Status::Converged;
      r.message = "residual within tolerance";
    }
  } else if (r.status == Status::Converged) {
    std::ostringstream os;
    os << "finished with residual " << a.residual << " above tolerance " << tolerance;
    if (!r.message.empty()) os << " (" << r.message << ")";
    r.status = Status::Failed;
    r.message = os.str();
  }
}

Result Solver::solve(const Problem& problem, Vector& x) {
  const bool useGuess = options_.warmStart && x.size() == problem.b.size() && x.allFinite();
  if (useGuess)
    start_ = x;
  else
    start_.setZero(problem.b.size());
  return runChecked(problem, x, useGuess ? &x : nullptr);
}

Result Solver::solveWithGuess(const Problem& problem, const Vector& guess, Vector& x) {
  if (guess.size() != problem.b.size()) {
    Result r;
    r.solver = name();
    r.status = Status::InvalidInput;
    std::ostringstream os;
    os << "guess has " << guess.size() << " entries, expected " << problem.b.size();
    r.message = os.str();
    return r;
  }
  if (!guess.allFinite()) {
    Result r;
    r.solver = name();
    r.status = Status::InvalidInput;
    r.message = "guess holds NaN or Inf";
    return r;
  }
  start_ = guess;
  return runChecked(problem, x, &guess);
}

Result Solver::solveInner(Solver& inner, const Problem& problem, const Vector& guess, Vector& x) {
  if (guess.size() != problem.size()) return inner.solveWithGuess(problem, guess, x);
  inner.start_ = guess;
  inner.validated_ = true;
  struct Untimed {  // this solve times the whole; restored on every way out
    bool& timed;
    const bool was;
    ~Untimed() { timed = was; }
  } untimed{inner.timed_, inner.timed_};
  inner.timed_ = false;
  return inner.runChecked(problem, x, &guess);
}

void Solver::keepStartIfBetter(const Problem& problem, const Vector* start, Result& r) {
  Vector slack = problem.b;
  Accuracy a;
  if (start) {
    slack.noalias() +=
        problem.isSparse() ? Vector(problem.sparseA() * *start) : Vector(problem.denseA() * *start);
    a = accuracy(problem, *start, slack);
  } else {
    a = accuracy(problem, Vector::Zero(problem.size()), slack);
  }
  if (!takeStartIfBetter(r, a, options_.tolerance)) return;
  if (start)
    start_ = *start;
  else
    start_.setZero(problem.size());
}

void verifyLeastSquares(const Problem& problem, const Vector& w, Result& r) {
  const bool linear = problem.classify() == ProblemClass::Linear;
  const Vector g = problem.isSparse() ? Vector(problem.sparseA().transpose() * w)
                                      : Vector(problem.denseA().transpose() * w);
  const double scale = rowSumNorm(problem) * (1 + problem.b.lpNorm<Eigen::Infinity>());
  const double stationarity = g.lpNorm<Eigen::Infinity>();
  if (linear && stationarity <= kLeastSquaresStationarity * scale) return;
  std::ostringstream os;
  if (linear)
    os << "not a least-squares answer: ||A^T w|| / (||A|| (1 + ||b||)) = " << stationarity / scale;
  else
    os << "a least-squares answer is defined for equality rows only";
  os << " (" << r.message << ")";
  r.status = Status::Failed;
  r.message = os.str();
}

bool takeStartIfBetter(Result& r, const Accuracy& start, double tolerance) {
  if (!(start.residual < r.residual) && std::isfinite(r.residual)) return false;
  applyAccuracy(r, start, tolerance);
  r.message += "; the start's residual is lower: start returned";
  return true;
}

// A method whose memory runs out (dense work arrays of a huge island) fails like any other: the
// answer is the start, measured as such, and the message says why. std::bad_alloc is the one
// exception caught here; every other error is the caller's to see.
void Solver::runGuarded(const Problem& problem, const Vector* start, Result& r) {
  try {
    run(problem, start_, r);
  } catch (const std::bad_alloc&) {
    innerChecked_ = false;  // the start is returned: measured here
    if (start)
      start_ = *start;
    else
      start_.setZero(problem.size());
    r.status = Status::Failed;
    r.iterations = 0;
    r.message = std::string(name()) + ": out of memory for " + std::to_string(problem.size()) +
                " rows; the start is returned";
  }
}

Result Solver::runChecked(const Problem& problem, Vector& x, const Vector* start) {
  const double t0 = timed_ ? nowSeconds() : 0.0;
  auto elapsed = [&] { return timed_ ? nowSeconds() - t0 : 0.0; };
  Result r;
  const bool validated = validated_;
  validated_ = false;
  if (!validated) {
    if (std::string why = problem.validate(); !why.empty()) {
      r.status = Status::InvalidInput;
      r.message = why;
      r.seconds = elapsed();
      return r;
    }
  }
  r.status = Status::Failed;
  r.solver = name();
  // Every stage of the method counts the budget from the same start.
  struct BudgetStart {
    Options& o;
    bool set;
    ~BudgetStart() {
      if (set) o.budgetStart = 0;
    }
  } budget{options_, options_.timeBudget > 0 && !(options_.budgetStart > 0)};
  if (budget.set) options_.budgetStart = t0 > 0 ? t0 : nowSeconds();
  innerChecked_ = false;
  runGuarded(problem, start, r);
  if (r.status == Status::InvalidInput || r.status == Status::Unsupported) {
    r.seconds = elapsed();
    return r;  // x untouched: nothing was solved
  }
  if (std::exchange(innerChecked_, false)) {  // checked by the inner solve, on this problem
    x.swap(start_);
    r.seconds = elapsed();
    return r;
  }
  // Up to 8 rows, Eigen's coefficient-wise product: the blocked kernel's call and set-up cost
  // more than a joint island's 36 multiplications.
  if (problem.isSparse())
    slack_.noalias() = problem.sparseA() * start_;
  else if (problem.size() <= 8)
    slack_.noalias() = problem.denseA().lazyProduct(start_);
  else
    slack_.noalias() = problem.denseA() * start_;
  slack_ += problem.b;
  applyAccuracy(r, checkedAccuracy(problem, start_, slack_, options_.tolerance),
                options_.tolerance);
  if (r.status == Status::TimeLimit) keepStartIfBetter(problem, start, r);
  if (r.status == Status::LeastSquares) verifyLeastSquares(problem, slack_, r);
  x.swap(start_);
  r.seconds = elapsed();
  return r;
}

}  // namespace mlcp
