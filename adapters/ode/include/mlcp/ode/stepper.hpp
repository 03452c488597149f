// mlcp/ode/stepper.hpp: any core solver as ODE's island stepper.
//
//     mlcp::ode::Stepper stepper;               // "auto", or "dantzig", "pgs", ... by name
//     stepper.step(world, h);                   // instead of dWorldStep(world, h)
//
//     mlcp::ode::Settings s;                    // the shape of mlcp::bullet::Settings
//     s.solver = "pgs";                         // by default: the world's QuickStep
//     mlcp::ode::Stepper quick(s);              // iterations and W, dWorldQuickStep's cost
//
// From C: mlcp/ode/stepper.h (every setting, errors as return codes, no exceptions).
//
// How it plugs in: Stepper::step makes dWorldStep's two calls into ODE's world processing
// (dxReallocateWorldProcessContext, dxProcessIslands) with its own memory estimator and island
// stepper, so ODE still does everything around the solve: islands, auto-disable, joint rows
// (every joint type, contact mode, limit and motor), joint feedback and integration.
//
// The island pipeline (src/island.cpp; each stage in full in docs/methods/adapters.md, "ODE:
// the island stepper's stages"):
//   1. prepare bodies: forces, world-frame inverse inertia, gyroscopic torque, as dxStepIsland;
//   2. prepare rows: getInfo1, joints ordered unbounded | mixed | LCP as ODE orders them,
//      getInfo2 into factored rows (mlcp::RowSystem, mlcp/rows.hpp);
//   3. canonical form (core/include/mlcp/problem.hpp): ODE solves A lambda = rhs + w with
//      A = J M^-1 J^T + diag(cfm / h), rhs = c / h - J (M^-1 f_ext + v / h); so b = -rhs;
//   4. warm start: last step's lambda per joint, per contact the nearest last-step contact of
//      the same body pair (Settings::contactMatchDistance);
//   5. solve: mlcp::RowSolver (mlcp/island/row_solver.hpp), shared with the Bullet adapter;
//   6. store impulses: J^T lambda, joint feedback, v += h M^-1 (f_ext + J^T lambda), dxStepBody.
// Stage 1 repeats dxStepIsland's operations in its order, so forces and inertias equal stock's
// to the bit; stage 6 is dxStepIsland's. Cost: O(rows + bodies) around the solve, in a workspace
// reused across islands and steps.
//
// Adapter-only solver names, for diffing against stock ODE: "ode-step" and "ode-quickstep"
// forward each island to dxStepIsland / dxQuickStepIsland (equal to dWorldStep /
// dWorldQuickStep); "ode-lcp" runs stages 1-3 and 6 with ODE's dxSolveLCP on the dense A (equal
// to dWorldStep to round-off, with its residual measured).
//
// Threads. ODE may run islands on several threads; the stepper serializes its islands with a
// mutex.
#pragma once

#include <ode/ode.h>

#include <memory>
#include <string>
#include <vector>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"

namespace mlcp::ode {

// The stepper's settings: the island solver's (mlcp::RowSolverSettings, the shape the Bullet
// adapter's settings share: solver "auto", options with tolerance 1e-6, fallback "pgs" with at
// most 100 sweeps, acceptResidual 1e-3, denseAssemblyMaxRows 64, engineIterations; documented in
// mlcp/island/row_solver.hpp), plus ODE's own. `solver` may also name one of ODE's own solvers
// ("ode-step", "ode-quickstep", "ode-lcp"; they never fall back). options.warmStart is ignored:
// warmStart below decides. engineIterations (default true) gives pgs/gs the world's QuickStep
// settings at every step: dWorldGetQuickStepNumIterations sweeps (20 by default) with
// dWorldGetQuickStepW (1.3) as the relaxation, the cost of dWorldQuickStep's solve.
struct Settings : RowSolverSettings {
  // Start each island's solve from the last step's lambda of the same joints. Default true.
  bool warmStart = true;
  // A contact of this step is warm-started by the nearest contact of the last step between the
  // same two bodies when their positions are closer than this distance (in ODE's length unit, m).
  // Default 0.05.
  double contactMatchDistance = 0.05;
  // Diagnostics: a second solver (any name the stepper accepts except the forwarding ones) run
  // on the same island problem after the primary; its residual and time go to IslandStats,
  // its answer is discarded. "" for none. Default "".
  std::string reference;
  // Diagnostics: keep each island's problem of the last step as the solver received it, with
  // the answer applied (Stepper::lastProblems), e.g. to measure another solver's lambda on the
  // very same MLCP. The rows are swapped out of the island workspace after integration, not
  // copied (the workspace takes the buffers kept two steps ago, of the same sizes on a steady
  // scene): the cost is a few pointer swaps and a copy of the joint list per island, and the
  // trajectory is bitwise the one with the option off. Nothing is kept for the forwarding
  // solvers ("ode-step", "ode-quickstep"). Default false.
  bool keepProblems = false;
};
// The name the stepper's settings had before they shared RowSolverSettings (kept for code
// written against it; the project itself says Settings).
using StepperOptions = Settings;

struct IslandStats {
  int bodies = 0;
  int joints = 0;  // active joints (getInfo1 gave m > 0)
  int rows = 0;
  int unbounded = 0;  // rows with lo = -inf, hi = +inf
  int iterations = 0;
  double residual = kNotComputed;  // of the answer applied to the bodies
  Status status = Status::Converged;
  std::string message;
  // The solver whose answer was applied: a core name ("dantzig", "ldlt", "pgs", ...; "auto"'s
  // choice), "none" for an island without rows, "start" when the start already solved its rows
  // (RowSolver, stage 3), or "ode-lcp"/"ode-step"/"ode-quickstep".
  std::string choice;
  bool fellBack = false;  // the primary's answer was rejected and the fallback ran
  bool accepted = true;   // the applied answer passes mlcp::acceptable
  // The friction model of the applied answer (Settings::friction; Box when the island has no
  // friction rows or the fallback's box answer was applied). With Cone, residual is the cone
  // LCP's.
  FrictionModel friction = FrictionModel::Box;
  // Degenerate rows screened before the solve, by reason (mlcp/island/row_screen.hpp): inert ones
  // applied no force (lambda 0), the rest of the island was solved without them.
  ScreenCounts screened;
  bool warmStarted = false;
  double solveSeconds = 0;                  // the solver(s) only
  double islandSeconds = 0;                 // the whole island, rows to integration
  double referenceResidual = kNotComputed;  // Settings::reference's answer
  // max_i |x_ref,i - x_i| / (1 + max_i |x_i|): how far the reference's lambda is from the
  // applied one, relative to the largest constraint force.
  double referenceDifference = kNotComputed;
  double referenceSeconds = 0;
};

// One island's problem as the solver received it (Settings::keepProblems).
struct IslandProblem {
  int island = 0;  // index in StepStats::islands
  // w = (J M^-1 J^T + diag(cfm)) x + b, lo <= x <= hi, findex island-global: stages 1-3's rows,
  // joints ordered unbounded | mixed | LCP. rows.assemble() is the Problem whose
  // mlcp::accuracy(problem, lambda).residual IslandStats::residual reports (up to round-off).
  RowSystem rows;
  // The constraint forces applied to the bodies (ODE's lambda: N, or N m on angular rows), per
  // row of `rows`; feedback holds J^T lambda per joint and body.
  Vector lambda;
  // Each active joint's rows in `rows`. Map answers by joint, never by row position: the row
  // order is the stepper's (by class), not the island's joint order.
  struct JointRange {
    dJointID joint;  // as during the step: contact joints are usually destroyed right after it
                     // (dJointGroupEmpty), so compare it, dereference it only before that
    int first, count;
  };
  std::vector<JointRange> joints;
};

struct StepStats {
  std::vector<IslandStats> islands;
  double seconds = 0;  // the whole step() call
  int rows() const;
  int fallbacks() const;          // islands that fell back
  ChoiceCounts choices() const;   // IslandStats::choice counted over the islands
  ScreenCounts screened() const;  // IslandStats::screened summed over the islands
  double maxResidual() const;     // over islands with rows; 0 when there are none
  int maxIterations() const;
};

class Stepper {
 public:
  // Throws std::invalid_argument naming the known solvers when settings.solver (or fallback,
  // reference) is not a name the stepper knows, or for a negative or NaN acceptResidual.
  explicit Stepper(const Settings& settings);
  // The same with settings.solver replaced by `solver` (default settings without them).
  explicit Stepper(const std::string& solver = "auto");
  Stepper(const std::string& solver, Settings settings);
  ~Stepper();
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  // One step of size h (> 0), like dWorldStep: returns false when ODE could not allocate its
  // working memory (as dWorldStep returns 0), true otherwise.
  bool step(dWorldID world, dReal h);

  const std::string& solverName() const;
  const Settings& settings() const;
  const Settings& options() const { return settings(); }
  // The core solver's options (Settings::options), adjustable between steps (with
  // engineIterations on, pgs/gs take the world's QuickStep count and factor at every step).
  mlcp::Options& solverOptions();
  // The fallback's options (Settings::fallbackOptions), adjustable between steps.
  mlcp::Options& fallbackOptions();
  // Settings::timeBudget, adjustable between steps (seconds, finite, >= 0; throws
  // std::invalid_argument otherwise). The "ode-..." solvers ignore it.
  void setTimeBudget(double seconds);
  // Statistics of the last step (cleared at the start of each step).
  const StepStats& lastStep() const;
  // The islands with rows of the last step, in step order, when Settings::keepProblems
  // is set (empty otherwise; replaced at the start of each step).
  const std::vector<IslandProblem>& lastProblems() const;
  // Forget the warm-start cache (e.g. after teleporting bodies).
  void resetWarmStart();
  // The shared island solver of a core primary (null for "ode-..."): its capture hook writes
  // each island's problem.
  RowSolver* rowSolver();

  // Every name accepted as a solver: the core registry's and the adapter's ("ode-...").
  static std::string knownSolvers();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlcp::ode
