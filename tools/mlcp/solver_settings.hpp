// Solver settings as `mlcp solve` and `mlcp table` take them and as the Python module's
// mlcp.solve and Problem.solve do: Options' fields (result.hpp) and the typed parameters of
// newton (NewtonParams, newton.hpp), dantzig (DantzigParams, dantzig.hpp) and lemke (LemkeSolver's
// fields, lemke.hpp). One table of the typed parameters and one set of checks serve both, so the
// program and the module accept the same values and refuse the same ones with the same message.
//
// A typed parameter is named by its field in snake_case (NewtonParams::coldSweeps: cold_sweeps,
// the Python spelling); the program writes it kebab-case (cold-sweeps); either is accepted.
// A parameter is set wherever its solver runs: named alone, as a member of a fallback chain
// ("dantzig>newton") or as auto's choice (AutoSolver::configure). Unset parameters keep the
// solver's defaults.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "mlcp/result.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::cli {

// One typed parameter: whose it is, its name, the values it takes, and access to it in a solver
// of that kind (get: NaN and set: nothing for a solver of another kind).
struct SolverParam {
  const char* solver;  // "newton", "dantzig" or "lemke"
  const char* name;    // snake_case: "cold_sweeps"
  bool whole;          // an integer (a flag: 0 or 1)
  double lo, hi;       // the accepted values, inclusive
  const char* range;   // lo and hi in words, for messages: ">= 0", "in (0, 1]"
  const char* help;
  double (*get)(Solver&);
  void (*set)(Solver&, double);
};

// Every typed parameter, grouped by solver in the order of its struct's fields.
const std::vector<SolverParam>& solverParams();
// The solvers that have typed parameters: "newton, dantzig, lemke".
std::string paramSolverNames();
// "cold-sweeps (10), warm-sweeps (20), ...": the solver's parameters with their defaults, in
// the program's spelling (kebab) or Python's.
std::string paramList(const std::string& solver, bool kebab);

struct SolverSettings {
  double tolerance = 1e-10;  // Options' fields, with their defaults
  int maxIterations = 1000;
  double relaxation = 1.0;
  double timeBudget = 0;  // seconds, 0 for none
  int maxPivots = 0;      // 0: automatic
  int checkEvery = 1;
  double pivotTolerance = 1e-12;
  std::string frictionBounds = "exact";  // or "fixed-once"
  // The typed parameters given, in order, each with its value.
  std::vector<std::pair<const SolverParam*, double>> params;
};

// "expected a whole number >= 1, got '0'" when `value` (as the user wrote it: `text`) is not a
// value of that kind in [lo, hi] (`range` in words), else "".
std::string rangeError(double value, const std::string& text, bool whole, double lo, double hi,
                       const std::string& range);

// Sets `solver`'s parameter `key` (snake_case or kebab-case). Throws std::invalid_argument:
// "unknown solver 'x' for parameters (known: newton, dantzig, lemke)", "unknown parameter
// 'pivoting_stepz' (closest: pivoting_steps; known: cold_sweeps, ...)" (`kebab`: in the
// program's spelling, the list left to its --help), or "cold_sweeps: expected a whole number
// >= 0, got '-1'" (`text`: the value as the user wrote it).
void setSolverParam(SolverSettings& s, const std::string& solver, const std::string& key,
                    double value, const std::string& text, bool kebab);
// The same from the program's "KEY=VALUE" (the value a number, or true / false for a flag).
void setSolverParam(SolverSettings& s, const std::string& solver, const std::string& assignment);

// Options' fields by their Python names (tol, max_iter, time_budget, max_pivots, check_every,
// pivot_tolerance; friction_bounds, read from `text`): "" when `value` (written `text`) is one
// that field takes, else the message ("expected a whole number >= 1, got '0'"). The program
// checks its options with it.
std::string settingError(const std::string& name, double value, const std::string& text);
// All of Options' fields: throws std::invalid_argument "check_every: expected a whole number
// >= 1, got '0'" or "friction_bounds: expected exact or fixed-once, got 'x'".
void checkSettings(const SolverSettings& s);

// The settings on `solver`: its Options, and the typed parameters on it, on every member of a
// fallback chain and on the solvers auto makes.
void applySettings(const SolverSettings& s, Solver& solver);

}  // namespace mlcp::cli
