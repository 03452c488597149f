#include "scene_runs.hpp"

#include <algorithm>
#include <ostream>
#include <stdexcept>

#include "csv_rows.hpp"

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
#endif
#ifdef MLCP_HAVE_ODE
  list.push_back("ode");
#endif
  return list;
}

std::string engineNames() {
  std::string s;
  for (const std::string& e : engineList()) s += (s.empty() ? "" : ", ") + e;
  return s.empty() ? "none (built without engine adapters)" : s;
}

std::unique_ptr<scene::World> makeWorld(const std::string& engine, const scene::Scene& s,
                                        const scene::RunSettings& run) {
#ifdef MLCP_HAVE_BULLET
  if (engine == "bullet") return bullet::loadWorld(s, run);
#endif
#ifdef MLCP_HAVE_ODE
  if (engine == "ode") return ode::loadWorld(s, run);
#endif
  (void)s;
  (void)run;
  throw std::invalid_argument("unknown engine '" + engine + "' (known: " + engineNames() + ")");
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
