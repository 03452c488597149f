// mlcp/row_solver.hpp: the one place that solves an engine island's rows (both adapters).
//
//     mlcp::RowSolver solver;                      // settings: solver "auto", fallback "pgs"
//     mlcp::IslandSolve s = solver.solve(rows, start, x, islandKey);
//     s.choice;    // "ldlt", "dantzig", "pgs", "none", ...: the solver whose answer x is
//     s.fellBack;  // the primary's answer was rejected and the fallback ran
//
// Stages per island (the Bullet drop-in and the ODE stepper both run exactly this):
//
//  0. screen the rows one by one (RowScreen, row_screen.hpp): a degenerate row (non-finite rhs
//     or Jacobian, no effect on any body, A_ii = 0 without cfm, empty bounds) takes x = 0 and
//     is left out, NaN bounds become +-inf; stages 1-4 run on the rows kept, so one such row
//     never costs the rest of its island its answer. IslandSolve::screened counts them.
//  1. classify the rows by their bounds alone (no matrix needed; ProblemClass, problem.hpp):
//       no rows                       -> Empty:       nothing to solve ("none");
//       every row -inf..inf            -> Linear:      bilateral joints only;
//       every row 0..inf               -> StandardLcp: frictionless contacts;
//       other bounds, no findex        -> Boxed:       joints with limits/motors, mixed;
//       friction-coupled rows (findex) -> Findex:      contacts with friction.
//  2. choose: the requested name, or with "auto" chooseSolver() below (the rules and the
//     measurements behind them are written there).
//  3. solve from the caller's start: "pgs" runs RowPgs on the rows themselves (O(nnz J) per
//     sweep, no matrix); every other name gets A = J M^-1 J^T + diag(cfm) assembled once per
//     island, dense up to denseMaxRows rows and sparse above. Solver objects live per island
//     key and name, so the sparse analyses of ldlt and dantzig (ordering, elimination tree) are
//     redone only when that island's pattern changes, and RowPgs' buffers are reused.
//  4. verify, the same rule for every solver (acceptable() below): the answer is finite, its
//     status is not Failed, NumericalIssue, InvalidInput or Unsupported, and its residual,
//     recomputed from the problem by residual.hpp (never the solver's claim), is <=
//     acceptResidual. A rejected answer sends the island to the fallback solver from the same
//     start; the better of the two answers (lower residual; the primary's on a tie) is kept.
//     When neither is usable (NaN/Inf, or nothing solved) the start itself is returned: the
//     engine's "no change" (Bullet: the impulses already applied; ODE: last step's forces).
//
// acceptResidual, default 1e-3 (kDefaultAcceptResidual): the scaled natural-map residual is
// ||x - clamp(x - w, lo', hi')||_inf / (1 + ||b||_inf); at 1e-3 the worst row's impulse error is
// 0.1% of the island's largest velocity error term. Warm-started pgs with the scenes' 50 sweeps
// ends at 1e-9..3e-2 on the scenes (measured with `mlcp run`): a tighter default (the Bullet
// adapter had 1e-6) re-solved most pyramid and stack steps with the fallback's 1000 sweeps, a
// looser one accepted pgs answers whose stacks visibly sink. +inf accepts any finite answer
// (SI-like fixed-sweep pgs).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/row_screen.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"

namespace mlcp {

// The acceptance limit both adapters use by default (see above). Dimensionless.
inline constexpr double kDefaultAcceptResidual = 1e-3;
// Largest island assembled dense for matrix-based solvers, in rows. Default 64.
inline constexpr int kDefaultDenseMaxRows = 64;
// The scaled natural-map residual an island's solve aims at by default, dimensionless: 1e-6 is
// an impulse error of a millionth of the island's largest velocity-error term, far below what a
// step's motion shows, and what exact solvers reach in a few pivots or Newton steps. Core's
// 1e-10 is a solver test's target: on engine rows (redundant friction, cfm-regularised contacts)
// dantzig can stall above it (ODE's tank-track rows stop at 1.6e-7) and every step then runs
// its full pivot and friction-pass limits (330x dWorldStep's time there).
inline constexpr double kDefaultIslandTolerance = 1e-6;
// Sweep limit of a pgs/gs fallback when the engine's iteration count is not used
// (RowSolverSettings::engineIterations false): 100 sweeps, 10x Bullet's and 5x ODE QuickStep's
// default cost, is what a rejected answer may cost at most by default (core's 1000 would cost
// 100x SI per rejected island).
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
  // A registry name (mlcp::solverNames(), "a>b" chains included), "auto" (chooseSolver per
  // island) or "pgs" (RowPgs on the rows). Default "auto".
  std::string solver = "auto";
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
  // Islands with at most this many rows give matrix-based solvers a dense A, larger ones a
  // sparse A (rows); ldlt then factors dense or sparse LDL^T accordingly. Default
  // kDefaultDenseMaxRows (64).
  int denseMaxRows = kDefaultDenseMaxRows;
  // Time the assembly of A apart (IslandSolve::assembleSeconds): one more clock read per
  // island, ~70 ns on a virtual machine against ~1 us for a 6-row island's whole solve. When
  // false assembleSeconds stays 0. Default true.
  bool timeAssembly = true;
  // Read by the adapters (RowSolver knows no engine): pgs and gs, as primary or fallback, run
  // the engine's own iteration count, with the residual checked once at the end, instead of
  // maxIterations sweeps toward the tolerance: Bullet's btContactSolverInfo::m_numIterations
  // (10 by default), ODE's dWorldGetQuickStepNumIterations (20) with dWorldGetQuickStepW (1.3)
  // as the relaxation. A drop-in pgs then costs what the engine's own solver costs (core's
  // 1000 sweeps toward 1e-10 cost 7-108x SI per step on Bullet's demos); a fallback of the
  // primary's own name is not run (the same sweeps from the same start give the same answer).
  // Set false (and options.maxIterations) for more accuracy. Default true.
  bool engineIterations = true;
};

// Sets options' sweep limit to an engine's iteration count, checked once at the end.
// A count below 1 is taken as 1.
inline void useEngineIterations(Options& options, int iterations) {
  options.maxIterations = options.checkEvery = iterations < 1 ? 1 : iterations;
}

// The verification every answer passes (see stage 4 above): finite residual <= acceptResidual
// and a status other than Failed, NumericalIssue, InvalidInput, Unsupported.
bool acceptable(const Result& r, double acceptResidual);

// ProblemClass of the rows from their bounds and findex alone (Problem::classify's rules).
ProblemClass classify(const RowSystem& rows);

// `auto`'s choice for an island of this class and size at this requested tolerance (scaled
// residual):
//   Empty                       -> "none"
//   Linear                      -> "ldlt"     one LDL^T solve: exact (dense up to denseMaxRows
//                                             rows, sparse above with its analysis reused)
//   StandardLcp, Boxed, Findex  -> "dantzig"  exact pivoting answer (residual ~1e-12)
//     except rows > kAutoPivotingRows at tolerance >= kAutoPgsTolerance -> "pgs"
// and RowSolver adds one rule with memory: an island whose dantzig answer broke down (failed,
// numerical issue, NaN) or missed the acceptance limit by more than kAutoNearMiss times runs pgs
// first for its next kAutoPgsAfterRejection solves (then dantzig is tried again); a near miss
// (friction passes ran out at 2e-3 against 1e-3, say) goes to the fallback for that solve only.
// Measured with `mlcp run SCENE --engine E --solver S --steps 100` (scene defaults: 50
// iterations, tolerance 1e-6, fallback pgs, acceptResidual 1e-3), mean solver ms per step and
// worst residual:
//   pendulum_chain (20 hinges, Linear)  ODE  ldlt 0.016 ms 5e-14 | dantzig 0.017 | pgs 1.35 ms 1e-1
//                                       Bullet ldlt 0.017 ms 5e-14 | dantzig 0.059 | pgs 0.66 ms
//   mass_ratio_stack (Findex)           ODE  dantzig 0.14 ms 1e-12 | pgs 4.5 ms 0.45
//   pyramid_15 (Findex, ~280 rows)      ODE  dantzig 4.6 ms 5e-15 | pgs 20 ms 1e-3
//                                       Bullet (friction rows with their contact's CFM,
//                                       bullet::CfmModel::Regularized) dantzig 3.1 ms 8e-7 |
//                                       pgs 0.74 ms 9e-3 (100 sweeps)
//   hinge_motor_limits (Boxed)          both dantzig 0.003-0.04 ms 1e-15 | pgs 0.004-0.008 1e-6
// Tiny joint islands against ODE's own solver over the same span (`mlcp run --solver ode-world`:
// the same assembly into a kept problem, dxSolveLCP, the same residual check), solver time per
// step, medians of 300 steps (shared machine: ranges of repeated runs), and instructions per
// solve (callgrind, the adapter's whole island solve):
//   pendulum_chain (33 rows, ldlt)     auto 5.0-5.2 us, 55k | ode-world 5.8-6.2 us, 77k
//     (ldlt's dense envelope LDL^T (ldlt.hpp) ~25k, assembly 15k, validation and check ~8k;
//     before it: sparse LDL^T, 9.7 us and 99.8k)
//   hinge_motor_limits (6 rows, dantzig) auto 0.61 us, 5.8k | ode-world 0.68 us, 6.7k
//     (means of 300 steps, report; dantzig's tiny-island path, dantzig_small.hpp, ~1.7k;
//     assembly 1.4k; validation and the residual check ~1k; ODE's dxSolveLCP alone 2.8k.
//     Before that path: 1.22 us, 10.4k.) The first step is cold and takes the same path from
//     the cold guess (~19 us against ode-world's 13-17 us, mostly code fetched from memory).
// Bullet, the same scenes against bullet-mlcp-dantzig (report means): pendulum 8.9 vs 20 us,
// hinge 1.4 vs 2.3 us (Bullet hands the hinge's rows over with a zero start: the cold guess).
// The memory rule dates from Bullet's zero-CFM friction rows (bullet::CfmModel::Engine), on which
// dantzig failed 29 of 30 steps of pyramid_15 (70 ms, residual 0.12): with the rule auto went
// from 47 ms to 8.6 ms there. With the default Regularized model dantzig's answers are accepted
// and the rule does not fire on the report's scenes (it did, on one near miss of Bullet's
// pyramid_15, sending 30 solves to pgs: worst residual 2e-3 instead of dantzig's, hence the
// near-miss exception); it stays as the guard for islands that defeat pivoting. Numbers of the main
// job's report: README, "Each island gets what it needs".
const char* chooseSolver(ProblemClass c, int rows, double tolerance);
// Largest contact island handed to dantzig whatever the tolerance (rows). See chooseSolver.
inline constexpr int kAutoPivotingRows = 600;
// Loosest requested tolerance at which large contact islands go to pgs. See chooseSolver.
inline constexpr double kAutoPgsTolerance = 1e-4;
// Solves of an island that run pgs first after its dantzig answer was rejected. Default 30.
inline constexpr int kAutoPgsAfterRejection = 30;
// A rejected dantzig answer within this factor of acceptResidual is a near miss (no memory).
inline constexpr double kAutoNearMiss = 10;

// What one island's solve gives back.
struct IslandSolve {
  // The returned answer's result: status, iterations, residual (recomputed), seconds (the
  // primary's and the fallback's, assembly included), message (with the rejection reason).
  Result result;
  ProblemClass problemClass = ProblemClass::Empty;
  std::string choice;          // the solver whose answer was returned ("none" for no rows)
  std::string requested;       // the primary that ran ("auto"'s choice, or the requested name)
  bool fellBack = false;       // the primary's answer was rejected and the fallback ran
  bool accepted = true;        // the returned answer passes acceptable()
  double assembleSeconds = 0;  // part of result.seconds spent classifying and assembling A
  ScreenCounts screened;       // rows screened in stage 0 (inert ones answered x = 0)
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
  // name, and for a negative or NaN acceptResidual.
  explicit RowSolver(const RowSolverSettings& settings = RowSolverSettings());
  ~RowSolver();
  RowSolver(const RowSolver&) = delete;
  RowSolver& operator=(const RowSolver&) = delete;

  const RowSolverSettings& settings() const { return settings_; }
  // The primary's and fallback's options may be changed between solves (names may not).
  Options& options() { return settings_.options; }
  Options& fallbackOptions() { return settings_.fallbackOptions; }

  // Solves the island's rows from `start` (size rows.size(), used as given: pass zeros for a
  // cold start) into x. islandKey identifies the island across steps (any stable number, e.g.
  // its first body's address); solver workspaces are kept per key.
  IslandSolve solve(const RowSystem& rows, const Vector& start, Vector& x,
                    std::uint64_t islandKey = 0);

  // While prefix is not "", every solve() with rows writes the island's assembled problem
  // (mlcp-problem/1, io.hpp) to prefix + "island<K>.json", K = 0, 1, ... from this call on.
  void setCapture(const std::string& prefix);
  // The files written since the last setCapture.
  const std::vector<std::string>& capturedFiles() const { return captured_; }

  // The assembled-problem solver kept for this island and name, or null (for tests of the
  // workspace reuse, e.g. LdltSolver::analyses()).
  const Solver* cachedSolver(std::uint64_t islandKey, const std::string& name) const;

  // Whether a name can be given as `solver` / `fallback`.
  static bool known(const std::string& name);

 private:
  struct Slot;
  // Stages 1-4 on rows that passed the screen.
  IslandSolve solveScreened(const RowSystem& rows, const Vector& start, Vector& x,
                            std::uint64_t islandKey);
  Slot& slot(std::uint64_t key);
  Solver* assembledSolver(Slot& island, const std::string& name);
  Result run(const RowSystem& rows, const std::string& name, const Options& options,
             const Vector& start, Vector& x, Slot& island, IslandSolve& report);
  void assemble(const RowSystem& rows, bool sparse);
  void capture(const RowSystem& rows);

  RowSolverSettings settings_;
  RowPgs rowPgs_;
  Problem assembled_;  // reused across solves with assembleScratch_: no per-step allocation
  RowSystem::AssembleScratch assembleScratch_;
  bool haveAssembled_ = false;
  double solveStart_ = 0;  // the current solve's start, until its primary's run() reads it
  Vector xFallback_;
  RowScreen screen_;
  Vector keptStart_, keptX_;  // the kept rows' start and answer when rows were screened
  std::unordered_map<std::uint64_t, std::unique_ptr<Slot>> slots_;
  std::uint64_t lastKey_ = 0;  // the key of lastSlot_
  Slot* lastSlot_ = nullptr;   // the island solved last (slots_ owns it)
  std::uint64_t calls_ = 0;
  std::string capturePrefix_;
  std::vector<std::string> captured_;
};

}  // namespace mlcp
