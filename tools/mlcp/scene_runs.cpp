#include "scene_runs.hpp"

#include <algorithm>
#include <filesystem>
#include <ostream>
#include <stdexcept>

#include "csv_rows.hpp"
#include "mlcp/input_limits.hpp"
#include "mlcp/island/friction_model.hpp"

#ifdef MLCP_HAVE_BULLET
#include "mlcp/bullet/scene_loader.hpp"
#endif
#ifdef MLCP_HAVE_ODE
#include "mlcp/ode/scene_loader.hpp"
#endif

namespace mlcp::cli {

std::vector<std::string> engineList() {
  std::vector<std::string> list;
#ifdef MLCP_HAVE_BULLET
  list.push_back("bullet");
  list.push_back("bullet-multibody");
#endif
#ifdef MLCP_HAVE_ODE
  list.push_back("ode");
#endif
  return list;
}

std::vector<std::string> defaultEngines() {
  std::vector<std::string> list = engineList();
  list.erase(std::remove(list.begin(), list.end(), "bullet-multibody"), list.end());
  return list;
}

namespace {
std::string joined(const std::vector<std::string>& list) {
  std::string s;
  for (const std::string& e : list) s += (s.empty() ? "" : ", ") + e;
  return s.empty() ? "none (built without engine adapters)" : s;
}
}  // namespace

std::string engineNames() { return joined(engineList()); }
std::string defaultEngineNames() { return joined(defaultEngines()); }

std::unique_ptr<scene::World> makeWorld(const std::string& engine, const scene::Scene& s,
                                        const scene::RunSettings& run) {
#ifdef MLCP_HAVE_BULLET
  if (engine == "bullet") return bullet::loadWorld(s, run);
  if (engine == "bullet-multibody") return bullet::loadWorld(s, run, bullet::Coordinates::Reduced);
#endif
#ifdef MLCP_HAVE_ODE
  if (engine == "ode") return ode::loadWorld(s, run);
#endif
  (void)s;
  (void)run;
  throw std::invalid_argument("unknown engine '" + engine + "' (known: " + engineNames() + ")");
}

scene::RunSettings runSettings(const scene::Scene& s, const RunOptions& o) {
  scene::RunSettings run = scene::RunSettings::fromScene(s);
  if (!o.solver.empty()) run.solver = o.solver;
  if (o.iterations >= 0) run.iterations = o.iterations;
  if (o.tolerance >= 0) run.tolerance = o.tolerance;
  if (!o.warmStart) run.warmStart = false;
  run.engineIterations = o.engineIterations;
  run.fallback = o.fallback == "none" ? "" : o.fallback;
  if (o.fallbackResidual >= 0) run.fallbackResidual = o.fallbackResidual;
  if (o.timeBudget >= 0) run.timeBudget = o.timeBudget;
  run.pivotingSteps = o.pivotingSteps;
  if (!o.friction.empty() && !parseFrictionModel(o.friction, run.friction))
    throw std::invalid_argument("friction: '" + io::capped(o.friction, 24) +
                                "' is not box or cone");
  if (o.frictionDirections >= 0) run.frictionDirections = o.frictionDirections;
  return run;
}

std::string prepareCapture(const std::string& engine, const scene::Scene& s,
                           const scene::RunSettings& run, int step, int steps,
                           const std::string& folder) {
  if (step >= steps)
    return "--capture " + std::to_string(step) + " is not one of the " + std::to_string(steps) +
           " steps run (0 to " + std::to_string(steps - 1) + ")";
  std::error_code ec;
  const bool existed = std::filesystem::is_directory(folder, ec);
  std::filesystem::create_directories(folder, ec);
  if (ec) return "cannot create " + folder + ": " + ec.message();
  // Asked of an unstepped copy first, so that a world that cannot capture fails at once.
  if (!makeWorld(engine, s, run)->captureNextStep(folder)) {
    if (!existed) std::filesystem::remove(folder, ec);
    return "this engine/solver cannot capture (" + engine + " with " + run.solver + ")";
  }
  return "";
}

const char* const kStepCsvHeader =
    "scene,engine,solver,step,solver_ms,step_ms,residual,iterations,status,fallbacks,choice,"
    "contacts,max_penetration,joint_error,energy,momentum,max_speed";

void writeStepCsv(std::ostream& out, const scene::World& world, const std::string& solver,
                  int step) {
  writeStepCsv(out, world.scene().name, world.engine(), solver, step, world.last());
}

void writeStepCsv(std::ostream& out, const std::string& scene, const std::string& engine,
                  const std::string& solver, int step, const scene::StepMeasures& m) {
  writeWholeRows(out, [&](std::ostream& row) {
    row << scene << ',' << engine << ',' << solver << ',' << step << ',' << m.solverMs << ','
        << m.stepMs << ',' << m.residual << ',' << m.iterations << ',' << m.status << ','
        << m.fallbacks << ',' << m.choice << ',' << m.contacts << ',' << m.maxPenetration << ','
        << m.jointError << ',' << m.energy << ',' << m.momentum << ',' << m.maxSpeed << "\n";
  });
}

RunSummary runWorld(scene::World& world, int steps,
                    const std::function<void(const scene::World&, int)>& onStep) {
  RunSummary sum;
  double solverMs = 0, stepMs = 0;
  for (int i = 0; i < steps && sum.finite; ++i) {
    world.step();
    const scene::StepMeasures& m = world.last();
    if (onStep) onStep(world, i);
    solverMs += m.solverMs;
    stepMs += m.stepMs;
    if (!(m.residual <= sum.worstResidual)) sum.worstResidual = m.residual;  // NaN-propagating
    sum.maxPenetration = std::max(sum.maxPenetration, m.maxPenetration);
    sum.maxJointError = std::max(sum.maxJointError, m.jointError);
    sum.maxSpeed = std::max(sum.maxSpeed, m.maxSpeed);
    sum.fallbacks += m.fallbacks;
    if (m.status != "converged") ++sum.unconverged;
    if (m.status == "failed" || m.status == "numerical-issue" || m.status == "unsupported")
      ++sum.failedSteps;
    sum.finite = scene::isFinite(world.states());
    ++sum.steps;
  }
  const double n = std::max(sum.steps, 1);
  sum.meanSolverMs = solverMs / n;
  sum.meanStepMs = stepMs / n;
  return sum;
}

}  // namespace mlcp::cli
