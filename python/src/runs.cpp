// mlcp._mlcp.run: a scene file stepped in an engine with a named solver, the per-step measures
// of `mlcp run`'s CSV (mlcp/scene/world.hpp) returned as columns. The settings are the CLI's
// (cli::RunOptions: negative numbers and "" mean the scene's own value), applied, captured and
// written by the CLI's own functions; errors the CLI reports as bad input raise ValueError with
// its message; a blown-up run stops and says so ("finite": False).
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <fstream>
#include <iomanip>
#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "columns.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "mlcp/scene_runs.hpp"
#include "mlcp/trajectory.hpp"

namespace mlcp::python {

namespace {

struct RunArgs {
  cli::RunOptions options;
  int steps = -1;               // -1 : the scene's
  bool states = false;          // record every body's position, orientation and velocity per step
  std::string csv, trajectory;  // files to write ("" : none)
  int capture = -1;             // step whose problems are written to captureDir (-1 : none)
  std::string captureDir = ".";
};

// An output file opened with its header line; ValueError with the CLI's message if it cannot be.
void openOutput(std::ofstream& out, const std::string& path, const char* header, int precision) {
  if (path.empty()) return;
  out.open(path);
  if (!out) throw nb::value_error(("cannot write " + path).c_str());
  out << header << "\n" << std::setprecision(precision);
}

nb::dict run(const std::string& path, const std::string& engine, const RunArgs& args) {
  scene::Scene s;
  std::unique_ptr<scene::World> world;
  scene::RunSettings settings;
  int steps = 0;
  std::string captureError;
  try {
    s = scene::loadScene(path);
    settings = cli::runSettings(s, args.options);
    world = cli::makeWorld(engine, s, settings);
    steps = args.steps >= 0 ? args.steps : s.settings.steps;
    if (args.capture >= 0)
      captureError = cli::prepareCapture(engine, s, settings, args.capture, steps, args.captureDir);
  } catch (const scene::FormatError& e) {
    throw nb::value_error(e.what());
  } catch (const std::invalid_argument& e) {
    throw nb::value_error(e.what());
  }
  if (!captureError.empty()) throw nb::value_error(captureError.c_str());
  std::ofstream csv, trajectory;
  openOutput(csv, args.csv, cli::kStepCsvHeader, 9);
  openOutput(trajectory, args.trajectory, cli::kTrajectoryCsvHeader, 17);
  if (args.capture == 0) world->captureNextStep(args.captureDir);
  Columns c;
  cli::RunSummary sum;
  {
    nb::gil_scoped_release unlocked;
    sum = cli::runWorld(*world, steps, [&](const scene::World& w, int i) {
      c.add(w.last());
      if (args.states) c.addStates(w.states());
      if (csv.is_open()) cli::writeStepCsv(csv, w, settings.solver, i);
      if (trajectory.is_open()) cli::writeTrajectoryCsv(trajectory, w, settings.solver, i);
      if (i + 1 == args.capture) world->captureNextStep(args.captureDir);
    });
  }
  nb::dict out;
  out["scene"] = s.name;
  out["engine"] = std::string(world->engine());
  out["solver"] = settings.solver;
  out["time_step"] = s.settings.timeStep;
  out["finite"] = sum.finite;
  out["captured"] = args.capture >= 0 && args.capture < sum.steps ? world->capturedFiles()
                                                                  : std::vector<std::string>();
  std::vector<std::string> names;
  for (const scene::Body& b : s.bodies) names.push_back(b.name);
  out["bodies"] = std::move(names);
  c.moveInto(out);
  const std::size_t taken = static_cast<std::size_t>(sum.steps), bodies = s.bodies.size();
  if (args.states) {
    out["positions"] = toNumpy(std::move(c.positions), {taken, bodies, 3});
    out["orientations"] = toNumpy(std::move(c.orientations), {taken, bodies, 4});
    out["velocities"] = toNumpy(std::move(c.velocities), {taken, bodies, 3});
  } else {
    out["positions"] = out["orientations"] = out["velocities"] = nb::none();
  }
  return out;
}

}  // namespace

void bindRuns(nb::module_& m) {
  m.def(
      "run",
      [](const std::string& path, const std::string& engine, const std::string& solver, int steps,
         int iterations, double tol, bool warmStart, bool engineIterations,
         const std::string& fallback, double fallbackResidual, double timeBudget, int pivotingSteps,
         const std::string& friction, int frictionDirections, const std::string& csv,
         const std::string& trajectory, int capture, const std::string& captureDir, bool states) {
        RunArgs a;
        a.options = {
            solver,           iterations, tol,           warmStart, engineIterations,  fallback,
            fallbackResidual, timeBudget, pivotingSteps, friction,  frictionDirections};
        a.steps = steps;
        a.states = states;
        a.csv = csv;
        a.trajectory = trajectory;
        a.capture = capture;
        a.captureDir = captureDir;
        return run(path, engine, a);
      },
      nb::arg("path"), nb::arg("engine"), nb::arg("solver"), nb::arg("steps"),
      nb::arg("iterations"), nb::arg("tol"), nb::arg("warm_start"), nb::arg("engine_iterations"),
      nb::arg("fallback"), nb::arg("fallback_residual"), nb::arg("time_budget"),
      nb::arg("pivoting_steps"), nb::arg("friction"), nb::arg("friction_directions"),
      nb::arg("csv"), nb::arg("trajectory"), nb::arg("capture"), nb::arg("capture_dir"),
      nb::arg("states"));
  m.def("engine_names", &cli::engineList);
}

}  // namespace mlcp::python
