// mlcp/island/row_solver.hpp: the one place that solves an engine island's rows (both adapters).
//
//     mlcp::RowSolver solver;                      // settings: solver "auto", fallback "pgs"
//     solver.beginStep();                          // once per engine step (the time budget's)
//     mlcp::IslandSolve s = solver.solve(rows, start, x, islandKey);
//     s.choice;    // "ldlt", "dantzig", "newton", "start", ...: whose answer x is
//     s.accepted;  // the returned answer is acceptable (policy.hpp, rule 1)
//
// The problem: an island's rows (mlcp/rows.hpp), w = A x + b with A = J M^-1 J^T + diag(cfm),
// lo <= x <= hi, friction bounds through findex (problem.hpp's canonical form). Each solve runs
// five stages: 0. screen degenerate rows (row_screen.hpp), and drop a start that would change
// a body's velocity by more than 1000 ||b||_inf (not a warm start: solved cold); 1. classify the
// rows by bounds and findex alone; 2. choose the solver (the requested name, or Policy::choose for
// "auto", with a per-island memory that sends an island whose exact answer broke down to pgs for a
// while);
// 3. solve from the caller's start, "pgs" on the rows themselves (RowPgs), every other method
// on A assembled once (dense up to denseAssemblyMaxRows rows); 4. verify the answer by the
// fallback rule of policy.hpp and run the fallback when it is not acceptable; 5. apply safely:
// an answer that would move a body far more than the engine's own method (pgs at its sweeps)
// is replaced by that method's answer (IslandSolve::energyGuard).
//
// Bounded cost. timeBudget bounds one engine step's solves: each island gets what is left of
// it, at least minShare of it, and a solver stopped by it returns its best iterate, never worse
// than its start. The engine-relative cap bounds an island auto hands to newton, once newton
// has missed it, by engineCostFactor times the measured cost of the engine's own solver on it.
//
// Invariants: x always has rows.size() finite entries on return; IslandSolve::result.residual
// is the residual of that x, recomputed from the rows; the settings' names are checked at
// construction. Cost over the chosen solver's: O(n) classification, O(nnz J) for the residual
// check (which is also the acceptance test), O(nnz A) assembly for matrix-based solvers, and
// the fallback's solve when the answer is rejected.
//
// Each stage, the budget, the cap and the defaults' reasons in full: docs/methods/island.md.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/island/friction_model.hpp"
#include "mlcp/island/policy.hpp"
#include "mlcp/island/row_screen.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/newton.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// The acceptance limit both adapters use by default (see above). Dimensionless.
inline constexpr double kDefaultAcceptResidual = 1e-3;
// The per-step time budget both adapters use by default (see above), in seconds.
inline constexpr double kDefaultTimeBudget = 0.05;
// The smallest share of timeBudget an island's solve gets (see above). Dimensionless.
inline constexpr double kDefaultMinShare = 0.05;
// The scaled natural-map residual an island's solve aims at by default, dimensionless: 1e-6 is
// an impulse error of a millionth of the island's largest velocity-error term, far below what a
// step's motion shows, and what exact solvers reach in a few pivots or Newton steps. Core's
// 1e-10 is a solver test's target: on engine rows (redundant friction, cfm-regularised contacts)
// dantzig can stall above it (ODE's tank-track rows stop at 1.6e-7) and every step then runs
// its full pivot and friction-pass limits (docs/methods/island.md, "Defaults").
inline constexpr double kDefaultIslandTolerance = 1e-6;
// What an island auto hands to the large-island solver may cost, as a multiple of the engine's
// own solver's estimated cost on it (see "The engine-relative cap"). Dimensionless.
inline constexpr double kDefaultEngineCostFactor = 3;
// Sweep limit of a pgs/gs fallback when the engine's iteration count is not used
// (RowSolverSettings::engineIterations false): 100 sweeps, ten of Bullet's and five of ODE
// QuickStep's default sweep counts, is what a rejected answer may cost at most by default.
inline constexpr int kDefaultFallbackSweeps = 100;

// Policy's defaults without the singular-island continuation (singularIslandSolver ""): under the
// engine-relative cap proximal rarely finishes a pile and its attempt costs more than the engine
// (Bullet's examples: 1.2-1.7x auto's step and more islands left to pgs). Set
// policy.singularIslandSolver = kSingularIslandSolver, with engineCostFactor 0 for no cap, where
// the exact answer on piles is worth its cost.
inline Policy engineIslandPolicy() {
  Policy p;
  p.singularIslandSolver = "";
  return p;
}

// Options with the islands' default tolerance (kDefaultIslandTolerance), core defaults otherwise.
inline Options islandOptions() {
  Options o;
  o.tolerance = kDefaultIslandTolerance;
  return o;
}

// The fallback's default options: islandOptions() with at most kDefaultFallbackSweeps sweeps.
inline Options fallbackIslandOptions() {
  Options o = islandOptions();
  o.maxIterations = kDefaultFallbackSweeps;
  return o;
}

// The island solver's settings, the one shape both adapters' settings derive from
// (mlcp::bullet::Settings, mlcp::ode::Settings).
struct RowSolverSettings {
  // A registry name (mlcp::solverNames(), "a>b" chains included), "auto" (policy below, per
  // island) or "pgs" (RowPgs on the rows). Default "auto".
  std::string solver = "auto";
  // The rules of "auto" (policy.hpp). Default: engineIslandPolicy().
  Policy policy = engineIslandPolicy();
  // Options of the primary (tolerance, iteration and pivot limits, ...). warmStart is ignored:
  // every solve starts from the caller's start. Default islandOptions(): tolerance 1e-6
  // (kDefaultIslandTolerance), core defaults otherwise.
  Options options = islandOptions();
  // Solver run when the primary's answer is rejected (any name `solver` accepts except
  // "auto"), "" for none. Default "pgs".
  std::string fallback = "pgs";
  // Options of the fallback. Default fallbackIslandOptions(): tolerance 1e-6, at most 100
  // sweeps (kDefaultFallbackSweeps); with engineIterations a pgs/gs fallback runs the engine's
  // count instead.
  Options fallbackOptions = fallbackIslandOptions();
  // Largest accepted scaled natural-map residual (dimensionless); +inf accepts any finite
  // answer. Default kDefaultAcceptResidual (1e-3).
  double acceptResidual = kDefaultAcceptResidual;
  // Wall-clock budget of one engine step's solves, in seconds (see above); 0 for none. Options'
  // own timeBudget, when set, still bounds each solve. Default kDefaultTimeBudget (0.05 s).
  double timeBudget = kDefaultTimeBudget;
  // The engine-relative cap (see above): an island handed to the large-island solver costs at
  // most about this multiple of the engine's own solver's cost on it, >= 1; 0 turns the cap off
  // (timeBudget alone). Default kDefaultEngineCostFactor (3).
  double engineCostFactor = kDefaultEngineCostFactor;
  // The smallest share of timeBudget an island's solve (and its fallback) gets, in (0, 1].
  // Default kDefaultMinShare (0.05 of the budget).
  double minShare = kDefaultMinShare;
  // Islands with at most this many rows give matrix-based solvers a dense A, larger ones a
  // sparse A (rows); ldlt then factors dense or sparse LDL^T accordingly. Default
  // kDenseAssemblyRows (64, thresholds.hpp).
  int denseAssemblyMaxRows = kDenseAssemblyRows;
  // Time the assembly of A apart (IslandSolve::assembleSeconds): one more clock read per
  // island, a few percent of a small island's whole solve. When false assembleSeconds stays 0.
  // Default true.
  bool timeAssembly = true;
  // Read by the adapters (RowSolver knows no engine): pgs and gs, as primary or fallback, run
  // the engine's own iteration count, with the residual checked once at the end, instead of
  // maxIterations sweeps toward the tolerance: Bullet's btContactSolverInfo::m_numIterations
  // (10 by default), ODE's dWorldGetQuickStepNumIterations (20) with dWorldGetQuickStepW (1.3)
  // as the relaxation. A drop-in pgs then costs what the engine's own solver costs; a fallback of
  // the primary's own name is not run (the same sweeps from the same start give the same answer).
  // Set false (and options.maxIterations) for more accuracy. Default true.
  bool engineIterations = true;
  // Friction model of islands with friction rows (friction_model.hpp): Box, the engine's rows as
  // they are, or Cone, the polyhedral cone's standard LCP (pivoting solvers only: pgs, gs and
  // ldlt are refused as the primary; the fallback runs on the box rows). Default Box.
  FrictionModel friction = FrictionModel::Box;
  // Friction directions per contact of the cone, in [kMinConeDirections, kMaxConeDirections]
  // ([3, 64]). Default kDefaultConeDirections (4: the engine's tangents +-t1, +-t2).
  int frictionDirections = kDefaultConeDirections;
  // newton's parameters wherever it runs on an island (named, auto's choice or the fallback):
  // e.g. pivotingSteps = bodyPivotingSteps = 0 turns its pivoting phase off. Default
  // NewtonParams().
  NewtonParams newton;
};

// Sets options' sweep limit to an engine's iteration count, checked once at the end.
// A count below 1 is taken as 1.
inline void useEngineIterations(Options& options, int iterations) {
  options.maxIterations = options.checkEvery = iterations < 1 ? 1 : iterations;
}

// ProblemClass of the rows from their bounds and findex alone (Problem::classify's rules).
ProblemClass classify(const RowSystem& rows);

// What one island's solve gives back.
struct IslandSolve {
  // The returned answer's result: status, iterations, residual (recomputed), seconds (the
  // primary's and the fallback's, assembly included), message (with the rejection reason).
  Result result;
  ProblemClass problemClass = ProblemClass::Empty;
  // the solver whose answer was returned ("none" for no rows, "start" when the start already
  // solved them: stage 3)
  std::string choice;
  std::string requested;       // the primary that ran ("auto"'s choice, or the requested name)
  bool fellBack = false;       // the primary's answer was rejected and the fallback ran
  bool accepted = true;        // the returned answer passes acceptable()
  double assembleSeconds = 0;  // part of result.seconds spent classifying and assembling A
  ScreenCounts screened;       // rows screened in stage 0 (inert ones answered x = 0)
  // Stage 5 replaced the lowest-residual answer, whose velocity change was far above pgs's, by
  // pgs's.
  bool energyGuard = false;
  // The friction model of the returned answer: Cone when the cone's LCP answered (result then
  // holds that LCP's residual), Box otherwise (no friction rows, the cone refused the island,
  // or the fallback's box answer was returned).
  FrictionModel friction = FrictionModel::Box;
};

// Counts of IslandSolve::choice over a step, e.g. "dantzig:3 ldlt:1 none:2".
class ChoiceCounts {
 public:
  void add(const std::string& choice, int count = 1);
  void add(const ChoiceCounts& other);
  void clear() { counts_.clear(); }
  int count(const std::string& choice) const;
  int total() const;
  // "name:count" pairs in name order, space separated; "" when empty.
  std::string toString() const;
  const std::vector<std::pair<std::string, int>>& counts() const { return counts_; }

 private:
  std::vector<std::pair<std::string, int>> counts_;  // sorted by name
};

class RowSolver {
 public:
  // Throws std::invalid_argument naming the known solvers for an unknown solver or fallback
  // name, for a negative or NaN acceptResidual, timeBudget or minShare
  // outside (0, 1], engineCostFactor neither 0 nor finite and >= 1, and for frictionDirections
  // outside [3, 64] or the cone with a primary that cannot take its LCP.
  explicit RowSolver(const RowSolverSettings& settings = RowSolverSettings());
  ~RowSolver();
  RowSolver(const RowSolver&) = delete;
  RowSolver& operator=(const RowSolver&) = delete;

  const RowSolverSettings& settings() const;
  // The primary's and fallback's options may be changed between solves (names may not).
  Options& options();
  Options& fallbackOptions();
  // Changes the per-step budget between solves (seconds, 0 for none); throws
  // std::invalid_argument for a negative or non-finite value.
  void setTimeBudget(double seconds);

  // The engine's own solver's sweeps per step (Bullet's m_numIterations, QuickStep's
  // iterations): the unit of the engine-relative cap. 0 (the default) leaves every island to
  // timeBudget alone.
  void setEngineSweeps(int sweeps);
  // Opens an engine step: the budget's clock starts at the next solve() and runs over every
  // solve until the next beginStep(). Without it every solve is a step of its own.
  void beginStep();
  // The share of the step's budget an island starting at `now` (nowSeconds()) gets, in seconds
  // (see above); 0 without a budget. For callers that solve an island themselves (Bullet's
  // packed pgs path) under the same budget.
  double islandBudget(double now);
  // True when `share` (islandBudget()) is down to the minimal share: the step's budget is spent.
  bool budgetSpent(double share) const;

  // Solves the island's rows from `start` (size rows.size(), used as given: pass zeros for a
  // cold start) into x. islandKey identifies the island across steps (any stable number, e.g.
  // its first body's address); solver workspaces are kept per key.
  IslandSolve solve(const RowSystem& rows, const Vector& start, Vector& x,
                    std::uint64_t islandKey = 0);

  // While prefix is not "", every solve() with rows writes the island's assembled problem
  // (mlcp-problem/1, io.hpp) to prefix + "island<K>.json", K = 0, 1, ... from this call on.
  void setCapture(const std::string& prefix);
  bool capturing() const;
  // The files written since the last setCapture.
  const std::vector<std::string>& capturedFiles() const;

  // The assembled-problem solver kept for this island and name, or null (for tests of the
  // workspace reuse, e.g. LdltSolver::analyses()).
  const Solver* cachedSolver(std::uint64_t islandKey, const std::string& name) const;

  // Whether a name can be given as `solver` / `fallback`.
  static bool known(const std::string& name);

 private:
  // The stages, the per-island memory and the reused buffers (core/src/island/row_solver_impl.hpp).
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlcp
