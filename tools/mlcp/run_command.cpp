// mlcp run SCENE --engine bullet|bullet-multibody|ode --solver NAME: a scene file stepped in an
// engine, one CSV row of measures per step (see mlcp/scene/world.hpp for what each column means).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "scene_runs.hpp"
#include "trajectory.hpp"

namespace mlcp::cli {

namespace {

struct RunArgs {
  std::string scene;
  std::string engine;
  RunOptions options;
  int steps = -1;  // -1 : the scene's
  std::string csv;
  std::string trajectory;
  int capture = -1;  // -1: no capture
  std::string captureDir = ".";
};

int runScene(const RunArgs& args) {
  scene::Scene s;
  try {
    s = scene::loadScene(args.scene);
  } catch (const scene::FormatError& e) {
    std::cerr << "mlcp run: " << e.what() << "\n";
    return kInvalidInput;
  }
  const int steps = args.steps >= 0 ? args.steps : s.settings.steps;
  scene::RunSettings run;
  std::unique_ptr<scene::World> world;
  try {
    run = runSettings(s, args.options);
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
    csv << kStepCsvHeader << "\n" << std::setprecision(9);
  }

  std::ofstream trajectory;
  if (!args.trajectory.empty()) {
    trajectory.open(args.trajectory);
    if (!trajectory) {
      std::cerr << "mlcp run: cannot write " << args.trajectory << "\n";
      return kInvalidInput;
    }
    trajectory << kTrajectoryCsvHeader << "\n" << std::setprecision(17);
  }
  if (args.capture >= 0) {
    const std::string error =
        prepareCapture(args.engine, s, run, args.capture, steps, args.captureDir);
    if (!error.empty()) {
      std::cerr << "mlcp run: " << error << "\n";
      return kInvalidInput;
    }
    if (args.capture == 0) world->captureNextStep(args.captureDir);
  }

  const RunSummary sum = runWorld(*world, steps, [&](const scene::World& w, int i) {
    if (csv.is_open()) {
      writeStepCsv(csv, w, run.solver, i);
      csv.flush();  // a run stopped from outside (a time limit) keeps the steps it finished
    }
    if (trajectory.is_open()) writeTrajectoryCsv(trajectory, w, run.solver, i);
    if (i + 1 == args.capture) world->captureNextStep(args.captureDir);
  });
  std::cout << s.name << " in " << world->engine() << " with " << run.solver << ": " << sum.steps
            << " steps of " << s.settings.timeStep << " s, " << s.dynamicBodyCount()
            << " dynamic bodies, " << s.joints.size() << " joints\n"
            << "  step " << sum.meanStepMs << " ms, solver " << sum.meanSolverMs
            << " ms (means); worst residual " << sum.worstResidual << ", " << sum.unconverged
            << " steps not converged, " << sum.fallbacks << " fallbacks\n"
            << "  max penetration " << sum.maxPenetration << " m, max joint error "
            << sum.maxJointError << " m; energy " << world->last().energy << " J, max speed "
            << world->last().maxSpeed << " m/s\n";
  if (!args.csv.empty()) std::cout << "  wrote " << args.csv << "\n";
  if (!args.trajectory.empty()) std::cout << "  wrote " << args.trajectory << "\n";
  if (args.capture >= 0 && args.capture < sum.steps) {
    const std::vector<std::string> files = world->capturedFiles();
    std::cout << "  captured step " << args.capture << ": " << files.size() << " problem file"
              << (files.size() == 1 ? "" : "s") << " in " << args.captureDir << "\n";
    for (const std::string& f : files) std::cout << "    " << f << "\n";
  }
  if (!sum.finite) {
    std::cerr << "mlcp run: the simulation blew up (non-finite body state) at step "
              << sum.steps - 1 << "\n";
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
          std::string(kStepCsvHeader) +
          ". Exit 0: all steps ran; 1: the simulation blew up (non-finite state); 2: bad "
          "scene file, engine or solver.");
  cmd->add_option("scene", args->scene, "scene file (.json, mlcp-scene/1)")->required();
  cmd->add_option("--engine", args->engine, "engine: " + engineNames())->required();
  cmd->add_option("--solver", args->options.solver,
                  "a core solver name (through our adapters) or a stock one: bullet-si, "
                  "bullet-nncg, bullet-mlcp-pgs, bullet-mlcp-dantzig, bullet-mlcp-lemke, "
                  "ode-world, ode-quick (default: the scene's solver.name)");
  cmd->add_option("--steps", args->steps, "steps to take (default: the scene's settings.steps)")
      ->check(nonNegativeNumber());
  cmd->add_option("--iterations", args->options.iterations,
                  "sweeps / outer iterations per solve (default: the scene's solver.iterations)")
      ->check(nonNegativeNumber());
  cmd->add_option("--tol", args->options.tolerance,
                  "tolerance of the scaled residual (default: the scene's solver.tolerance)")
      ->check(nonNegativeNumber());
  cmd->add_flag_function(
      "--no-warm-start", [args](std::int64_t) { args->options.warmStart = false; },
      "start every solve from zero");
  cmd->add_flag("--engine-iterations", args->options.engineIterations,
                "pgs/gs run exactly --iterations sweeps, checked once at the end, as the "
                "engine's own solver does (the adapters' default for a drop-in)");
  cmd->add_option("--fallback", args->options.fallback,
                  "core solver run when an answer is rejected, or none (default pgs)");
  cmd->add_option("--fallback-residual", args->options.fallbackResidual,
                  "scaled residual above which an answer is rejected (default 1e-3)")
      ->check(nonNegativeNumber());
  cmd->add_option("--time-budget", args->options.timeBudget,
                  "wall-clock budget of one step's solves in seconds, 0 for none (core solvers "
                  "only; default 0.05): islands solved after it ran out get a minimal share and "
                  "answers stopped by it report time-limit")
      ->check(nonNegativeNumber());
  cmd->add_option("--pivoting-steps", args->options.pivotingSteps,
                  "most block steps of newton's pivoting phase after damped steps that end short "
                  "(core solvers only), 0 to turn it off (default 40, 120 on an engine's rows)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--friction", args->options.friction,
                  "friction model: box (the engines' own) or cone (the polyhedral cone's LCP; "
                  "core solvers that take an LCP: auto, lemke, dantzig) (default: the scene's "
                  "solver.friction, box)")
      ->check(CLI::IsMember({"box", "cone"}));
  cmd->add_option("--friction-directions", args->options.frictionDirections,
                  "friction directions per contact of the cone, 3 to 64 (default: the scene's "
                  "solver.friction_directions, 4)")
      ->check(CLI::Range(kMinConeDirections, kMaxConeDirections));
  cmd->add_option("--csv", args->csv, "CSV file to write (one row per step)");
  cmd->add_option("--trajectory", args->trajectory,
                  "trajectory CSV to write, one row per step and dynamic body: " +
                      std::string(kTrajectoryCsvHeader) + " (for mlcp diff)");
  cmd->add_option("--capture", args->capture,
                  "write each island's MLCP of this step (0-based) as mlcp-problem/1 files, "
                  "which mlcp solve replays (our solvers only; exit 2 where the engine/solver "
                  "cannot capture)")
      ->check(nonNegativeNumber());
  cmd->add_option("--capture-dir", args->captureDir,
                  "folder for the --capture files (created if missing)")
      ->capture_default_str();
  return [args] { return runScene(*args); };
}

}  // namespace mlcp::cli
