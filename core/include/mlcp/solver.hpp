// mlcp/solver.hpp: the interface every algorithm implements, shaped like Eigen's solvers.
//
//     mlcp::PgsSolver pgs;                 // or mlcp::makeSolver("pgs")
//     pgs.options().tolerance = 1e-9;
//     mlcp::Vector x;
//     mlcp::Result r = pgs.solve(problem, x);           // starts from zero
//     mlcp::Result r = pgs.solveWithGuess(problem, g, x);  // starts from g
//
// The base class does what every solver shares, so no algorithm can skip it: it validates the
// problem (InvalidInput leaves x untouched), times the solve, and recomputes the accuracy of
// the returned x with residual.hpp. A solver that reports Converged with a residual above the
// tolerance is downgraded to Failed; a non-finite x becomes NumericalIssue. A solve stopped by
// Options::timeBudget (TimeLimit) returns its best iterate or, when that is worse than the start
// (a pivoting method's half-pivoted x), the start itself: a budget never makes x worse.
#pragma once

#include <memory>
#include <string>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"

namespace mlcp {

class RowSystem;

class Solver {
 public:
  virtual ~Solver() = default;

  // Registry name, e.g. "pgs".
  virtual const char* name() const = 0;

  Options& options() { return options_; }
  const Options& options() const { return options_; }
  Solver& setOptions(const Options& o) {
    options_ = o;
    return *this;
  }

  // Whether a solve reads the clock for Result::seconds. Default true. A caller that times the
  // solve itself turns it off (RowSolver: the two reads are a tenth of a 6-row island's
  // solve); Result::seconds is then 0. Time budgets are unaffected.
  Solver& setTimed(bool timed) {
    timed_ = timed;
    return *this;
  }

  // Solve from x = 0, or from the incoming x when options().warmStart and x has the right size.
  Result solve(const Problem& problem, Vector& x);
  // Solve from the given guess (size n), whatever options().warmStart says.
  Result solveWithGuess(const Problem& problem, const Vector& guess, Vector& x);

  // The rows (rows.hpp) the next solves' problem was assembled from, or nullptr (the default: a
  // Problem alone). A solver may use them for the same answers at less cost (dantzig's block
  // steps in body space); the default ignores them. Not owned: the caller clears it (nullptr)
  // before the rows go away or describe another problem (RowSolver sets it around each solve).
  virtual void useRows(const RowSystem* /*rows*/) {}

 protected:
  // The algorithm. x arrives sized n holding the start point; leave the answer in it. Set
  // status, iterations, message (and history). Validation, timing and the final accuracy
  // check are done by the caller.
  virtual void run(const Problem& problem, Vector& x, Result& result) = 0;

  // True when Options::timeBudget is spent (reads the clock; false without a budget). During
  // run() options().budgetStart is set whenever there is a budget, so every stage of a method
  // counts from the same start.
  bool outOfTime() const;

  // For a run() that hands the problem to another solver (auto, fallback chains): solves it
  // with `inner` from `guess` (size n, finite: this solve's start) without validating it again,
  // since this solve has. inner still checks its answer's accuracy against the problem.
  Result solveInner(Solver& inner, const Problem& problem, const Vector& guess, Vector& x);
  // Says that run() leaves x and result (status, residual and its parts) as its last
  // solveInner left them, inner having run with this solver's options (setOptions(options())):
  // that check is the one this solve would make, so it is not repeated (one residual
  // evaluation a solve, however deep the chain).
  void keepInnerCheck() { innerChecked_ = true; }

 private:
  // Runs the algorithm on start_ (holding the start point, *start or zeros when null) and swaps
  // it into x.
  Result runChecked(const Problem& problem, Vector& x, const Vector* start);
  void runGuarded(const Problem& problem, const Vector* start, Result& r);
  // TimeLimit: the start replaces the iterate when its residual is lower.
  void keepStartIfBetter(const Problem& problem, const Vector* start, Result& r);
  Options options_;
  bool timed_ = true;
  bool validated_ = false;     // the problem was validated by the caller's solve (solveInner)
  bool innerChecked_ = false;  // run() returned solveInner's checked answer (keepInnerCheck)
  // The iterate and w = A x + b of the accuracy check, kept so repeated solves of one size do
  // not allocate (an engine solves every island every step).
  Vector start_, slack_;
};

struct Accuracy;
// The final say on a result, shared by every entry point: copies the accuracy into r; NaN/Inf
// makes it NumericalIssue; a residual within tolerance upgrades MaxIterations/TimeLimit to
// Converged; a Converged claim above the tolerance becomes Failed.
void applyAccuracy(Result& r, const Accuracy& a, double tolerance);

// A TimeLimit answer is never worse than its start: when the start's accuracy is better (a lower
// residual, or r's is not finite) r takes it (with a note in the message) and true is returned;
// the caller then returns the start as x.
bool takeStartIfBetter(Result& r, const Accuracy& start, double tolerance);
// Keeps r's LeastSquares status only when x, with w = A x + b, is a least-squares answer of a
// Linear problem (result.hpp's stationarity test); otherwise r becomes Failed and says why.
void verifyLeastSquares(const Problem& problem, const Vector& w, Result& r);

// Seconds on a monotonic clock (for timing and time budgets).
double nowSeconds();

// The nowSeconds() value at which o.timeBudget runs out: budgetStart + timeBudget (the clock is
// read when budgetStart is 0), +inf without a budget.
double budgetDeadline(const Options& o);

}  // namespace mlcp
