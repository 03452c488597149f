// mlcp/island/row_solver.hpp: the one place that solves an engine island's rows (both adapters).
//
//     mlcp::RowSolver solver;                      // settings: solver "auto", fallback "pgs"
//     solver.beginStep();                          // once per engine step (the time budget's)
//     mlcp::IslandSolve s = solver.solve(rows, start, x, islandKey);
//     s.choice;    // "ldlt", "dantzig", "newton", "start", ...: whose answer x is
//     s.fellBack;  // the primary's answer was not acceptable and the fallback ran
//     s.accepted;  // the returned answer is acceptable (policy.hpp, rule 1)
//
// What it solves. An island's rows (rows.hpp): per row two 6-wide Jacobian blocks, the bodies'
// inverse masses, b, cfm, lo, hi, findex; the MLCP is w = A x + b with A = J M^-1 J^T +
// diag(cfm), lo <= x <= hi and the complementarity conditions of DESIGN's canonical form.
//
// Stages per island (the Bullet drop-in and the ODE stepper both run exactly these):
//  0. screen the rows one by one (RowScreen, row_screen.hpp): a degenerate row (non-finite rhs
//     or Jacobian, no effect on any body, A_ii = 0 without cfm, empty bounds) takes x = 0 and
//     is left out, NaN bounds become +-inf; stages 1-4 run on the rows kept, so one such row
//     never costs the rest of its island its answer. IslandSolve::screened counts them.
//  1. classify the rows by their bounds and findex alone (ProblemClass, problem.hpp; no matrix):
//     Empty (no rows, answer "none"), Linear (bilateral joints only), StandardLcp (frictionless
//     contacts), Boxed (limits, motors), Findex (contacts with friction).
//  2. choose: the requested name, or for "auto" Policy::choose (policy.hpp) from the class, the
//     row count, Options::tolerance and whether the step's time budget is spent; plus one rule
//     with memory per island: after a pivoting or Newton answer broke down (Policy::demotes; a
//     solve cut by the time budget counts only when the island's previous solve was cut too)
//     the island runs pgs first for its next Policy::pgsAfterBreakdown solves, then the
//     policy's choice is tried again.
//     Engine rows with cfm = 0 on redundant friction rows (Bullet's CfmModel::Engine) are the
//     islands that defeat pivoting; the memory keeps them from paying a failed pivoting solve
//     every step.
//  3. solve from the caller's start: "pgs" runs RowPgs on the rows themselves (O(nnz J) per sweep,
//     no matrix); every other name gets A assembled once per island, dense up to
//     denseAssemblyMaxRows rows and sparse above. Solver objects live per island key and name, so
//     the sparse analyses of ldlt and dantzig (ordering, elimination tree) are redone only when
//     that island's pattern changes, and RowPgs' buffers are reused. Under "auto", a dantzig answer
//     on friction rows that is not acceptable (its friction fixed point did not settle in its
//     passes, or its regularised retry ended short) is continued by newton from it in what is left
//     of the island's share (newton has the friction bounds' exact Jacobian); the better answer
//     goes on to stage 4. A start that already solves the rows far within the tolerance (residual
//     <= min(1e-4 tolerance, 1e-12)) is the answer of every primary but pgs (whose own first check
//     finds it), with choice "start": one product through the rows instead of an assembly and a
//     solver's set-up. Such starts are common in real content: touching bodies that nothing presses
//     together (Bullet's BasicDemo block in free fall: every contact's answer is 0). A start only
//     within the tolerance is solved again, so that exact answers stay exact and do not lag. With
//     friction "cone" (RowSolverSettings::friction, friction_model.hpp) an island with friction
//     rows is solved instead as the polyhedral cone's standard LCP (RowSolver::solveCone:
//     FrictionCone built from the rows, the start mapped into it, the requested solver or for
//     "auto" the policy's choice for an LCP with zero diagonal entries, lemke; its residual
//     recomputed on that LCP), and the answer mapped back to the rows' impulses. The pgs-first
//     memory of stage 2 is the box's: the cone runs on every solve (pgs cannot take its LCP, and
//     one rejected lemke answer would otherwise cost the island the cone for 30 steps).
//  4. verify and fall back, by the one fallback rule of policy.hpp: an answer is acceptable when
//     its status is not a breakdown and its residual, recomputed from the rows by residual.hpp,
//     is finite and <= acceptResidual; an unacceptable one sends the island to the fallback
//     from the same start, the better of the two answers (lower finite residual, the primary's
//     on a tie) is returned, and only when neither is finite the start (the engine's "no
//     change": Bullet's applied impulses, ODE's last forces).
//  5. apply safely: when the returned answer is still not acceptable, or is acceptable but
//     changes some body's linear velocity by more than 10 ||b||_inf (an exact answer along nearly
//     dependent rows: Bullet's ragdoll pile, 38,000 m/s at a residual of 2e-7), it is applied only
//     if the velocity change it makes (RowSystem::impulseEnergy: 1/2 x^T A x) is at most 4 times
//     (2x in speed) that of the engine's own method's answer from the same start, pgs at the
//     fallback's sweeps (SI's and QuickStep's count under engineIterations); otherwise pgs's
//     answer is applied (IslandSolve::energyGuard). When the applied answer still changes a
//     body's velocity by more than 10 ||b||_inf (pgs diverging too), the start is applied if it
//     does not, else no impulses, with status Failed. A residual alone cannot tell a near miss
//     from an exploded iterate (impulses along nearly dependent rows that solve them to the
//     last digit and throw the bodies); the velocity change can.
//
// The time budget. timeBudget is the wall-clock time of one engine step's solves (beginStep()
// opens a step; without it each solve is a step of its own). An island gets what is left of the
// step's budget when it starts, at least minShare * timeBudget; that share bounds its primary
// (Options::timeBudget, counted from the island's start so assembly counts) and what is left of
// it, again at least the minimal share, bounds the fallback. Once the step's budget is spent,
// large contact islands go to pgs (Policy), which improves on any start within any share; small
// ones keep dantzig, which ends in microseconds. A solver stopped by the budget returns its best
// iterate, never worse than its start (solver.hpp), with Status::TimeLimit and its recomputed
// residual. The budget therefore bounds a step by about timeBudget + (islands after the budget
// ran out) * minShare * timeBudget, plus what cannot be interrupted: assembly and one
// factorization (ldlt's, a dantzig block step's).
//
// The engine-relative cap. An island that auto hands to the large-island solver (newton) and
// whose last uncapped solve by it ended short of the tolerance (a pile whose exact answer takes
// many factorizations) is, for its next Policy::pgsAfterBreakdown such solves, also bounded by
// what the engine's own solver would spend on it: its primary gets (engineCostFactor - 1) times
// the estimated cost of engineSweeps sweeps of pgs on its rows, and the fallback, when the
// primary's answer is not acceptable, is pgs at the engine's sweeps (SI's and QuickStep's
// method at their cost), so the island costs about engineCostFactor times the engine's solver
// and its answer is the better of the two. The cost per row is measured on this machine: a
// running mean over the RowPgs solves at the engine's sweeps of islands of at least
// kTimedPgsRows rows, from one calibration solve of the first such island when no pgs has run
// yet. A capped solve that spends its share before its first step (assembly and set-up alone
// cost more) sends the island to pgs, as a breakdown does; a start within the tolerance is the
// answer of a capped island. Why: a drop-in default must cost about what the engine's solver
// costs; a fixed 50 ms cap let BasicDemo's pile cost 20-40x SI a step, because newton's steps on
// a singular pile end short of 1e-6 (newton.hpp). Islands that newton solves exactly stay
// uncapped: a 16-box stack at mass ratio 1000 needs its exact answers, at tens of times pgs's
// cost but well under a millisecond, and collapses under pgs's. The cap needs timeBudget > 0 and
// the engine's sweeps (setEngineSweeps: both adapters give them every step).
//
// Invariants: x always has rows.size() finite entries on return; IslandSolve::result.residual is
// the residual of that x; the settings' names are checked at construction.
//
// Cost over the chosen solver's: classification O(n), one clock read, the residual check O(nnz
// J) (it doubles as the acceptance test), assembly O(nnz A) for matrix-based solvers; an
// unacceptable answer adds the fallback's solve.
//
// acceptResidual, default kDefaultAcceptResidual (1e-3): the scaled natural-map residual
// ||x - clamp(x - w, lo', hi')||_inf / (1 + ||b||_inf) bounds the worst row's impulse error by
// 0.1% of the island's largest velocity-error term. Tighter limits re-solve most steps of
// warm-started fixed-sweep pgs with the fallback; looser ones accept pgs answers under which
// stacks visibly sink (docs/benchmarks.md, "Acceptance limit"). +inf accepts any finite answer
// (SI-like fixed-sweep pgs).
//
// timeBudget, default kDefaultTimeBudget (0.05 s): three frames of a 60 Hz program. A drop-in
// whose island cannot be solved exactly in time (dantzig on a 210-box pyramid takes seconds a
// step unbounded) then runs at ~20 steps a second with the best answer found instead of hanging,
// while the exact answers of the scenes up to 55 boxes and every joint island stay untouched; a
// tighter default cut pyramid_55's dantzig solves on a loaded machine (docs/benchmarks.md, "Time
// budget"). 0 disables it, for reproducible runs: an answer cut by a budget depends on the
// machine's speed and load.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/island/friction_model.hpp"
#include "mlcp/island/policy.hpp"
#include "mlcp/island/row_screen.hpp"
#include "mlcp/island/rows.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
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
// its full pivot and friction-pass limits (330x dWorldStep's time there).
inline constexpr double kDefaultIslandTolerance = 1e-6;
// What an island auto hands to the large-island solver may cost, as a multiple of the engine's
// own solver's estimated cost on it (see "The engine-relative cap"). Dimensionless.
inline constexpr double kDefaultEngineCostFactor = 3;
// Sweep limit of a pgs/gs fallback when the engine's iteration count is not used
// (RowSolverSettings::engineIterations false): 100 sweeps, 10x Bullet's and 5x ODE QuickStep's
// default cost, is what a rejected answer may cost at most by default (core's 1000 would cost
// a hundred times the engine's solver per rejected island).
inline constexpr int kDefaultFallbackSweeps = 100;

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
  // The rules of "auto" (policy.hpp). Default: Policy's defaults.
  Policy policy;
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
  // Default kDefaultMinShare (0.05: 2.5 ms of a 50 ms budget, ~50 pgs sweeps of 1000 rows).
  double minShare = kDefaultMinShare;
  // Islands with at most this many rows give matrix-based solvers a dense A, larger ones a
  // sparse A (rows); ldlt then factors dense or sparse LDL^T accordingly. Default
  // kDenseAssemblyRows (64, thresholds.hpp).
  int denseAssemblyMaxRows = kDenseAssemblyRows;
  // Time the assembly of A apart (IslandSolve::assembleSeconds): one more clock read per
  // island, ~70 ns on a virtual machine against ~1 us for a 6-row island's whole solve. When
  // false assembleSeconds stays 0. Default true.
  bool timeAssembly = true;
  // Read by the adapters (RowSolver knows no engine): pgs and gs, as primary or fallback, run
  // the engine's own iteration count, with the residual checked once at the end, instead of
  // maxIterations sweeps toward the tolerance: Bullet's btContactSolverInfo::m_numIterations
  // (10 by default), ODE's dWorldGetQuickStepNumIterations (20) with dWorldGetQuickStepW (1.3)
  // as the relaxation. A drop-in pgs then costs what the engine's own solver costs (core's
  // 1000 sweeps toward 1e-10 cost orders of magnitude more, docs/benchmarks.md); a fallback of the
  // primary's own name is not run (the same sweeps from the same start give the same answer).
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
