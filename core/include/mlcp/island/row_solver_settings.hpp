// mlcp/island/row_solver_settings.hpp: what an island's solve is told (RowSolverSettings) and the
// defaults both adapters share: the acceptance limit, the step's time budget and an island's
// smallest share of it, the islands' tolerance, the engine-relative cap, the fallback's sweeps.
// mlcp::bullet::Settings and mlcp::ode::Settings derive from RowSolverSettings; RowSolver
// (row_solver.hpp) checks them at construction. Each default's reason in full:
// docs/methods/island.md, "Defaults".
#pragma once

#include <string>

#include "mlcp/island/friction_model.hpp"
#include "mlcp/island/policy.hpp"
#include "mlcp/options.hpp"
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

}  // namespace mlcp
