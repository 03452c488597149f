// mlcp/result.hpp: what every solver takes (Options) and gives back (Result).
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace mlcp {

enum class Status {
  Converged,       // residual <= Options::tolerance, checked by residual() (never self-reported)
  MaxIterations,   // the iteration (or pivot) limit was reached before the tolerance
  TimeLimit,       // Options::timeBudget ran out before the tolerance
  Failed,          // the method broke down: ray termination, pivot failure, cycling,
                   // divergence, a zero diagonal, or it finished above the tolerance
  Unsupported,     // the method does not apply to this class of problem
  InvalidInput,    // Problem::validate() or the guess rejected the input; x is untouched
  NumericalIssue,  // NaN or Inf appeared during the solve
  // Equality rows only (Problem::classify() == Linear) with no exact solution: redundant rows
  // whose right-hand sides disagree (a closed loop of joints that has drifted). x is the
  // minimum-norm least-squares answer; the residual is what no x removes. The base verifies it
  // (||A^T (A x + b)||_inf <= kLeastSquaresStationarity ||A||_inf (1 + ||b||_inf)), else the
  // status is Failed. Acceptable to the fallback rule (policy.hpp): no method does better.
  LeastSquares,
};
// The scaled stationarity a LeastSquares answer must meet (above). Dimensionless: it admits
// the least-squares solve's rank decision (1e-6 of A's largest diagonal, linalg/min_norm.hpp).
inline constexpr double kLeastSquaresStationarity = 1e-5;
const char* toString(Status s);

// How friction-coupled (findex) rows take their bounds.
enum class FrictionBounds {
  // The returned x satisfies |x_i| <= mu_i * |x_findex[i]| exactly: the bounds move with the
  // normal values (pgs recomputes them at each visit; pivoting methods iterate to a fixed point).
  Exact,
  // ODE/Bullet compatibility: bounds fixed once from an intermediate normal value, as stock
  // dSolveLCP does. The answer may violate the final bounds; only for diffing against stock.
  FixedOnce,
};

struct Options {
  // Target of the scaled natural-map residual (see residual.hpp); dimensionless. Default 1e-10.
  double tolerance = 1e-10;
  // Iterative methods: sweeps. Pivoting methods: outer iterations (friction fixed-point steps);
  // their pivot count is bounded separately by maxPivots. Default 1000.
  int maxIterations = 1000;
  // Pivot limit of pivoting methods; 0 means "automatic" (50 * n + 100). Default 0.
  int maxPivots = 0;
  // SOR relaxation factor omega of gs/pgs, in (0, 2). 1 is plain Gauss-Seidel. Default 1.
  double relaxation = 1.0;
  // Start from the x passed to solve() instead of from zero (methods that can use it). Default
  // false.
  bool warmStart = false;
  // Wall-clock budget in seconds; 0 means none. Every solver checks it between its steps
  // (sweeps, pivots, block steps) at a bounded cost: the clock is read about once per ~1000
  // row updates or pivot-column operations, so a check costs a few percent of the work at most
  // and the overshoot is about that much work. When it runs out the solver returns its best
  // iterate, never worse than its start (Solver keeps the start otherwise), with
  // Status::TimeLimit. Default 0.
  double timeBudget = 0.0;
  // The nowSeconds() value the budget counts from; 0 means the solve's own start. A caller that
  // has read the clock already (RowSolver: the island's start, so assembly counts against the
  // budget) passes it and spares the solver a clock read. Default 0.
  double budgetStart = 0.0;
  // Record the residual after every iteration in Result::history (costs one residual
  // evaluation, O(nnz A), per iteration). Default false.
  bool recordHistory = false;
  // Check the residual only every this many sweeps in iterative methods (the check costs about
  // one sweep). 1 checks every sweep. Default 1.
  int checkEvery = 1;
  // Friction bound handling; see FrictionBounds. Default Exact.
  FrictionBounds frictionBounds = FrictionBounds::Exact;
  // Pivot magnitude below which a pivoting method treats a pivot as zero. Default 1e-12
  // (relative to the largest entry of A's diagonal).
  double pivotTolerance = 1e-12;
};

inline constexpr double kNotComputed = std::numeric_limits<double>::quiet_NaN();

struct Result {
  Status status = Status::InvalidInput;
  // The accuracy fields are NaN when nothing was solved (InvalidInput, Unsupported).
  int iterations = 0;                     // sweeps, or pivots for pivoting methods
  double residual = kNotComputed;         // scaled natural-map residual at the returned x
  double complementarity = kNotComputed;  // max_i of the complementarity gap at the returned x
  double boundViolation = kNotComputed;   // max_i distance of x_i outside its effective bounds
  double seconds = 0;           // wall time of the solve, including the final residual check
  std::string message;          // why it stopped, in words
  std::vector<double> history;  // residual per iteration when Options::recordHistory
  // Which solver produced x ("pgs", ...): differs from the one asked for when a fallback chain
  // or `auto` chose; fallbacks counts the solvers that were tried and rejected before it.
  std::string solver;
  int fallbacks = 0;

  bool converged() const { return status == Status::Converged; }
};

}  // namespace mlcp
