// Scene runs shared by the scene commands (run, sweep, stability, diff): a world in the engine
// asked for, stepped N times, with the per-step CSV row and the run's summary computed once.
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"

namespace mlcp::cli {

// Engines this build can run ("bullet, bullet-multibody, ode"), for help texts and errors.
// "bullet-multibody" is Bullet with its articulations as btMultiBodies (reduced coordinates).
std::string engineNames();
std::vector<std::string> engineList();
// The engines a sweep or stability map runs when none is named: "bullet" and "ode".
// bullet-multibody differs from bullet only in scenes with articulated bodies (on others it gives
// the same answers, articulation_test), so it runs when named and does not double every sweep.
std::vector<std::string> defaultEngines();
std::string defaultEngineNames();  // the same, comma separated

// The scene loaded into `engine`; throws std::invalid_argument for an unknown engine or solver
// (the message lists the valid names).
std::unique_ptr<scene::World> makeWorld(const std::string& engine, const scene::Scene& s,
                                        const scene::RunSettings& run);

// The settings `mlcp run` (and the Python module's mlcp.run) lays over a scene's own: a negative
// number or an empty string keeps the scene's value or the adapters' default.
struct RunOptions {
  std::string solver;  // "" : the scene's solver.name
  int iterations = -1;
  double tolerance = -1;
  bool warmStart = true;
  bool engineIterations = false;
  std::string fallback = "pgs";  // "none" or "": no fallback
  double fallbackResidual = -1;  // -1: 1e-3
  double timeBudget = -1;        // s; -1: the adapters' default (0.05), 0: none
  int pivotingSteps = -1;        // -1: NewtonParams' defaults
  std::string friction;          // "" : the scene's; "box" or "cone"
  int frictionDirections = -1;   // -1: the scene's
};

// The scene's run settings with `o` laid over them; throws std::invalid_argument for a friction
// model other than box or cone (the engines check the rest when the world is made).
scene::RunSettings runSettings(const scene::Scene& s, const RunOptions& o);

// Makes ready to capture each island's problem at step `step` of `steps` into `folder` (created
// if missing), asking an unstepped copy of the world whether it can: "" when it can, else the
// message `mlcp run --capture` prints.
std::string prepareCapture(const std::string& engine, const scene::Scene& s,
                           const scene::RunSettings& run, int step, int steps,
                           const std::string& folder);

// The per-step CSV columns of `mlcp run` (see mlcp/scene/world.hpp for each measure).
extern const char* const kStepCsvHeader;
// One CSV row for the world's last step; `solver` is the name the run was asked for.
void writeStepCsv(std::ostream& out, const scene::World& world, const std::string& solver,
                  int step);
// The same row from kept measures (mlcp sweep --repeat writes its rows after the repeats).
void writeStepCsv(std::ostream& out, const std::string& scene, const std::string& engine,
                  const std::string& solver, int step, const scene::StepMeasures& m);

// A run's summary over its steps.
struct RunSummary {
  int steps = 0;            // steps taken
  double meanSolverMs = 0;  // means over the steps taken
  double meanStepMs = 0;
  double worstResidual = 0;   // NaN when any step's residual was not measured
  double maxPenetration = 0;  // m
  double maxJointError = 0;   // m
  double maxSpeed = 0;        // m/s, over all steps
  int fallbacks = 0;          // summed
  int unconverged = 0;        // steps whose status is not "converged"
  int failedSteps = 0;        // steps with a failed / numerical-issue / unsupported status
  bool finite = true;         // false: the body states became non-finite (the run stopped)
};

// Steps `world` up to `steps` times (stops early once a body state is non-finite), calling
// onStep(world, i) after each step. Returns the summary.
RunSummary runWorld(scene::World& world, int steps,
                    const std::function<void(const scene::World&, int)>& onStep = {});

}  // namespace mlcp::cli
