// mlcp/result.hpp: what every solver gives back (Result) and how it ended (Status).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mlcp/options.hpp"

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
