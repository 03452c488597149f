// mlcp/options.hpp: what every solver takes (Options): the tolerance, the limits on its work
// (iterations, pivots, wall-clock budget), the start and the friction-bound rule. Each solver's
// own settings (NewtonParams, DantzigParams, LemkeParams) are in its header under mlcp/solvers/.
#pragma once

#include "mlcp/thresholds.hpp"

namespace mlcp {

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
  // Pivot magnitude below which a pivoting method treats a pivot as zero, relative to the
  // largest entry of A's diagonal. Default kPivotTolerance (1e-12, thresholds.hpp).
  double pivotTolerance = kPivotTolerance;
};

}  // namespace mlcp
