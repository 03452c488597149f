// mlcp diff: per-body deviation between two trajectories, either two solvers run on one scene
// from the same initial state, or two files written by `mlcp run --trajectory`. Deviations
// are defined in trajectory.hpp. Exit 0 within the tolerances, 1 past them (or when one run
// blew up), 2 on bad input, so that the command serves as a regression check.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "scene_runs.hpp"
#include "trajectory.hpp"

namespace mlcp::cli {

namespace {

struct DiffArgs {
  std::vector<std::string> inputs;
  std::string engine;
  std::vector<std::string> solvers;
  std::vector<int> iterations;
  int steps = -1;
  double tol = 1e-3;
  double angleTol = -1;
  std::string csv;
};

struct Worst {
  double value = 0;
  int step = -1;
  std::string body;
  void offer(double v, int s, const std::string& b) {
    if (step < 0 || v > value || std::isnan(v)) {
      if (std::isnan(value) && step >= 0) return;  // keep the first NaN
      value = v, step = s, body = b;
    }
  }
};

struct DiffResult {
  Worst position, orientation;
  int firstPast = -1;  // first step past a tolerance
  std::string firstPastWhat;
};

// Checks that b can be compared with a step by step; throws FormatError naming b's file/line.
void checkComparable(const Trajectory& a, const Trajectory& b) {
  if (a.bodies != b.bodies) {
    std::size_t i = 0;
    while (i < a.bodies.size() && i < b.bodies.size() && a.bodies[i] == b.bodies[i]) ++i;
    const auto name = [&](const Trajectory& t) {
      return i < t.bodies.size() ? "'" + t.bodies[i] + "'" : std::string("nothing");
    };
    throw scene::FormatError(b.source + ": line " + std::to_string(b.lines[0] + int(i)) +
                             ": the bodies differ from " + a.source + "'s: body " +
                             std::to_string(i + 1) + " is " + name(b) + " here, " + name(a) +
                             " there (" + std::to_string(b.bodies.size()) + " against " +
                             std::to_string(a.bodies.size()) + " bodies)");
  }
  for (std::size_t k = 0; k < a.steps.size() && k < b.steps.size(); ++k)
    if (a.steps[k] != b.steps[k])
      throw scene::FormatError(b.source + ": line " + std::to_string(b.lines[k]) + ": step " +
                               std::to_string(b.steps[k]) + " where " + a.source + " (line " +
                               std::to_string(a.lines[k]) + ") has step " +
                               std::to_string(a.steps[k]));
  if (a.steps.size() != b.steps.size()) {
    const Trajectory& shorter = a.steps.size() < b.steps.size() ? a : b;
    const Trajectory& longer = a.steps.size() < b.steps.size() ? b : a;
    throw scene::FormatError(shorter.source + ": ends after step " +
                             std::to_string(shorter.steps.back()) + ", " + longer.source +
                             " goes on to step " + std::to_string(longer.steps.back()) + " (line " +
                             std::to_string(longer.lines.back()) + ")");
  }
}

DiffResult compare(const Trajectory& a, const Trajectory& b, double tol, double angleTol,
                   std::ostream* csv) {
  DiffResult r;
  if (csv) *csv << "step,body,position_deviation,orientation_deviation\n" << std::setprecision(9);
  const std::size_t n = std::min(a.steps.size(), b.steps.size());
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < a.bodies.size(); ++i) {
      const double dp = positionDeviation(a.poses[k][i], b.poses[k][i]);
      const double dq = orientationDeviation(a.poses[k][i], b.poses[k][i]);
      const std::string& body = a.bodies[i];
      r.position.offer(dp, a.steps[k], body);
      r.orientation.offer(dq, a.steps[k], body);
      if (r.firstPast < 0 && (!(dp <= tol) || !(dq <= angleTol))) {
        r.firstPast = a.steps[k];
        std::ostringstream what;
        what << body << ": position " << dp << " m, orientation " << dq << " rad";
        r.firstPastWhat = what.str();
      }
      if (csv) *csv << a.steps[k] << ',' << body << ',' << dp << ',' << dq << "\n";
    }
  }
  return r;
}

int report(const DiffResult& r, const Trajectory& a, const Trajectory& b, double tol,
           double angleTol) {
  std::cout << "diff " << a.source << " against " << b.source << ": " << a.steps.size()
            << " steps, " << a.bodies.size() << " bodies; tolerance " << tol << " m, " << angleTol
            << " rad\n"
            << "  max position deviation     " << r.position.value << " m (" << r.position.body
            << ", step " << r.position.step << ")\n"
            << "  max orientation deviation  " << r.orientation.value << " rad ("
            << r.orientation.body << ", step " << r.orientation.step << ")\n";
  if (r.firstPast < 0) {
    std::cout << "  within tolerance\n";
    return kSolved;
  }
  std::cout << "  first step past tolerance  " << r.firstPast << " (" << r.firstPastWhat << ")\n";
  return kNotSolved;
}

int runDiff(const DiffArgs& args) {
  const double angleTol = args.angleTol >= 0 ? args.angleTol : args.tol;
  std::unique_ptr<std::ofstream> csv;
  if (!args.csv.empty()) {
    csv = std::make_unique<std::ofstream>(args.csv);
    if (!*csv) {
      std::cerr << "mlcp diff: cannot write " << args.csv << "\n";
      return kInvalidInput;
    }
  }
  Trajectory a, b;
  bool blewUp = false;
  try {
    if (args.inputs.size() == 2) {
      if (!args.solvers.empty() || !args.engine.empty())
        throw std::invalid_argument(
            "two trajectory files take no --engine/--solvers (those run one scene)");
      a = readTrajectoryCsv(args.inputs[0]);
      b = readTrajectoryCsv(args.inputs[1]);
      checkComparable(a, b);
    } else {
      if (args.engine.empty() || args.solvers.size() != 2)
        throw std::invalid_argument(
            "a scene needs --engine and --solvers A,B (two solvers); or give two trajectory "
            "files");
      if (args.iterations.size() > 2)
        throw std::invalid_argument("--iterations takes one value or two (one per solver)");
      const scene::Scene s = scene::loadScene(args.inputs[0]);
      const int steps = args.steps >= 0 ? args.steps : s.settings.steps;
      Trajectory* out[2] = {&a, &b};
      for (int k = 0; k < 2; ++k) {
        scene::RunSettings run = scene::RunSettings::fromScene(s);
        run.solver = args.solvers[k];
        run.timeBudget = 0;  // a diff compares solvers, not how busy the machine was
        if (!args.iterations.empty())
          run.iterations = args.iterations[std::min<std::size_t>(k, args.iterations.size() - 1)];
        auto world = makeWorld(args.engine, s, run);
        out[k]->source = s.name + " in " + args.engine + " with " + run.solver;
        if (!args.iterations.empty())
          out[k]->source += " (" + std::to_string(run.iterations) + " iterations)";
        const RunSummary sum =
            runWorld(*world, steps, [&](const scene::World& w, int i) { out[k]->record(w, i); });
        if (!sum.finite) {
          std::cerr << "mlcp diff: " << out[k]->source << " blew up (non-finite state) at step "
                    << sum.steps - 1 << "\n";
          blewUp = true;
        }
      }
    }
  } catch (const scene::FormatError& e) {
    std::cerr << "mlcp diff: " << e.what() << "\n";
    return kInvalidInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "mlcp diff: " << e.what() << "\n";
    return kInvalidInput;
  }
  const DiffResult r = compare(a, b, args.tol, angleTol, csv.get());
  const int code = report(r, a, b, args.tol, angleTol);
  if (csv) std::cout << "  wrote " << args.csv << "\n";
  return blewUp ? kNotSolved : code;
}

}  // namespace

Runner addDiffCommand(CLI::App& app) {
  auto args = std::make_shared<DiffArgs>();
  CLI::App* cmd = app.add_subcommand(
      "diff",
      "Per-body deviation between two trajectories: a scene run with two solvers from the same "
      "initial state (mlcp diff SCENE --engine E --solvers A,B), or two files of mlcp run "
      "--trajectory (mlcp diff A.csv B.csv). Position deviation |p_a - p_b| (m), orientation "
      "deviation the angle between the two orientations (rad), per step and dynamic body. "
      "Prints the largest of each (which body, which step) and the first step past the "
      "tolerance.\nExit 0: within tolerance; 1: past it (or a run blew up); 2: bad input.");
  cmd->add_option("inputs", args->inputs,
                  "a scene file (.json), or two trajectory CSV files (mlcp run --trajectory)")
      ->required()
      ->expected(1, 2);
  cmd->add_option("--engine", args->engine, "scene mode: engine (" + engineNames() + ")");
  cmd->add_option("--solvers", args->solvers, "scene mode: the two solvers, A,B")->delimiter(',');
  cmd->add_option("--iterations", args->iterations,
                  "scene mode: iterations per solve, one value for both or A,B (default: the "
                  "scene's solver.iterations)")
      ->delimiter(',')
      ->check(nonNegativeNumber());
  cmd->add_option("--steps", args->steps, "scene mode: steps (default: the scene's)")
      ->check(nonNegativeNumber());
  cmd->add_option("--tol", args->tol, "position tolerance (m)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--angle-tol", args->angleTol,
                  "orientation tolerance (rad; default: the value of --tol)")
      ->check(nonNegativeNumber());
  cmd->add_option("--csv", args->csv,
                  "per-step CSV to write: step,body,position_deviation,orientation_deviation");
  return [args] { return runDiff(*args); };
}

}  // namespace mlcp::cli
