// mlcp run SCENE --engine bullet|ode --solver NAME: a scene file stepped in an engine, one CSV
// row of measures per step (see mlcp/scene/world.hpp for what each column means).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#ifdef MLCP_HAVE_BULLET
#include "mlcp/bullet/scene_loader.hpp"
#endif
#ifdef MLCP_HAVE_ODE
#include "mlcp/ode/scene_loader.hpp"
#endif

namespace mlcp::cli {

namespace {

struct RunArgs {
  std::string scene;
  std::string engine;
  std::string solver;  // "" : the scene's default
  int steps = -1;      // -1 : the scene's
  int iterations = -1;
  double tolerance = -1;
  bool noWarmStart = false;
  std::string fallback = "pgs";
  double fallbackResidual = -1;
  std::string csv;
};

const char* kHeader =
    "scene,engine,solver,step,solver_ms,step_ms,residual,iterations,status,fallbacks,"
    "max_penetration,joint_error,energy,momentum,max_speed";

std::string engines() {
  std::string s;
#ifdef MLCP_HAVE_BULLET
  s += "bullet";
#endif
#ifdef MLCP_HAVE_ODE
  s += s.empty() ? "ode" : ", ode";
#endif
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
  throw std::invalid_argument("unknown engine '" + engine + "' (known: " + engines() + ")");
}

int runScene(const RunArgs& args) {
  scene::Scene s;
  try {
    s = scene::loadScene(args.scene);
  } catch (const scene::FormatError& e) {
    std::cerr << "mlcp run: " << e.what() << "\n";
    return kInvalidInput;
  }
  scene::RunSettings run = scene::RunSettings::fromScene(s);
  if (!args.solver.empty()) run.solver = args.solver;
  if (args.iterations >= 0) run.iterations = args.iterations;
  if (args.tolerance >= 0) run.tolerance = args.tolerance;
  if (args.noWarmStart) run.warmStart = false;
  run.fallback = args.fallback == "none" ? "" : args.fallback;
  if (args.fallbackResidual >= 0) run.fallbackResidual = args.fallbackResidual;
  const int steps = args.steps >= 0 ? args.steps : s.settings.steps;

  std::unique_ptr<scene::World> world;
  try {
    world = makeWorld(args.engine, s, run);
  } catch (const std::invalid_argument& e) {
    std::cerr << "mlcp run: " << e.what() << "\n";
    return kInvalidInput;
  }
  std::ofstream csv;
  if (!args.csv.empty()) {
    csv.open(args.csv);
    if (!csv) {
      std::cerr << "mlcp run: cannot write " << args.csv << "\n";
      return kInvalidInput;
    }
    csv << kHeader << "\n" << std::setprecision(9);
  }

  double solverMs = 0, stepMs = 0, worstResidual = 0, deepest = 0, jointError = 0;
  int fallbacks = 0, unconverged = 0, done = 0;
  bool finite = true;
  for (int i = 0; i < steps && finite; ++i) {
    world->step();
    const scene::StepMeasures& m = world->last();
    if (csv.is_open())
      csv << s.name << ',' << world->engine() << ',' << run.solver << ',' << i << ',' << m.solverMs
          << ',' << m.stepMs << ',' << m.residual << ',' << m.iterations << ',' << m.status << ','
          << m.fallbacks << ',' << m.maxPenetration << ',' << m.jointError << ',' << m.energy << ','
          << m.momentum << ',' << m.maxSpeed << "\n";
    solverMs += m.solverMs;
    stepMs += m.stepMs;
    if (!(m.residual <= worstResidual)) worstResidual = m.residual;  // NaN-propagating max
    deepest = std::max(deepest, m.maxPenetration);
    jointError = std::max(jointError, m.jointError);
    fallbacks += m.fallbacks;
    if (m.status != "converged") ++unconverged;
    finite = scene::isFinite(world->states());
    ++done;
  }

  const double n = std::max(done, 1);
  std::cout << s.name << " in " << world->engine() << " with " << run.solver << ": " << done
            << " steps of " << s.settings.timeStep << " s, " << s.dynamicBodyCount()
            << " dynamic bodies, " << s.joints.size() << " joints\n"
            << "  step " << stepMs / n << " ms, solver " << solverMs / n
            << " ms (means); worst residual " << worstResidual << ", " << unconverged
            << " steps not converged, " << fallbacks << " fallbacks\n"
            << "  max penetration " << deepest << " m, max joint error " << jointError
            << " m; energy " << world->last().energy << " J, max speed " << world->last().maxSpeed
            << " m/s\n";
  if (!args.csv.empty()) std::cout << "  wrote " << args.csv << "\n";
  if (!finite) {
    std::cerr << "mlcp run: the simulation blew up (non-finite body state) at step " << done - 1
              << "\n";
    return kNotSolved;
  }
  return kSolved;
}

}  // namespace

Runner addRunCommand(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Step a scene file (mlcp-scene/1) in an engine and write one CSV row of measures per "
      "step: " +
          std::string(kHeader) +
          ". Exit 0: all steps ran; 1: the simulation blew up (non-finite state); 2: bad "
          "scene file, engine or solver.");
  cmd->add_option("scene", args->scene, "scene file (.json, mlcp-scene/1)")->required();
  cmd->add_option("--engine", args->engine, "engine: " + engines())->required();
  cmd->add_option("--solver", args->solver,
                  "a core solver name (through our adapters) or a stock one: bullet-si, "
                  "bullet-nncg, bullet-mlcp-pgs, bullet-mlcp-dantzig, bullet-mlcp-lemke, "
                  "ode-world, ode-quick (default: the scene's solver.name)");
  cmd->add_option("--steps", args->steps, "steps to take (default: the scene's settings.steps)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--iterations", args->iterations,
                  "sweeps / outer iterations per solve (default: the scene's solver.iterations)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--tol", args->tolerance,
                  "tolerance of the scaled residual (default: the scene's solver.tolerance)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-warm-start", args->noWarmStart, "start every solve from zero");
  cmd->add_option("--fallback", args->fallback,
                  "core solver run when an answer is rejected, or none (default pgs)");
  cmd->add_option("--fallback-residual", args->fallbackResidual,
                  "scaled residual above which an answer is rejected (default 1e-3)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--csv", args->csv, "CSV file to write (one row per step)");
  return [args] { return runScene(*args); };
}

}  // namespace mlcp::cli
