// mlcp._mlcp.run: a scene file stepped in an engine with a named solver, the per-step measures
// of `mlcp run`'s CSV (mlcp/scene/world.hpp) returned as columns. The same settings rules as
// the CLI: negative numbers and "" mean the scene's own value; errors the CLI reports as bad
// input raise ValueError with its message; a blown-up run stops and says so ("finite": False).
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "mlcp/scene_runs.hpp"

namespace mlcp::python {

namespace {

struct RunArgs {
  std::string solver;  // "" : the scene's
  int steps = -1;      // -1 : the scene's
  int iterations = -1;
  double tolerance = -1;
  bool warmStart = true;
  std::string fallback = "pgs";  // "" : none
  double fallbackResidual = -1;
  bool states = false;  // record every body's position, orientation and velocity per step
};

// The columns of one run, filled step by step.
struct Columns {
  std::vector<double> solverMs, stepMs, residual, maxPenetration, jointError, energy, momentum,
      maxSpeed;
  std::vector<int> iterations, fallbacks, contacts;
  std::vector<std::string> status, choice;
  // With RunArgs::states, per step and scene body: x y z, w x y z, vx vy vz (flat, C order).
  std::vector<double> positions, orientations, velocities;

  void add(const scene::StepMeasures& m) {
    solverMs.push_back(m.solverMs);
    stepMs.push_back(m.stepMs);
    residual.push_back(m.residual);
    maxPenetration.push_back(m.maxPenetration);
    jointError.push_back(m.jointError);
    energy.push_back(m.energy);
    momentum.push_back(m.momentum);
    maxSpeed.push_back(m.maxSpeed);
    iterations.push_back(m.iterations);
    fallbacks.push_back(m.fallbacks);
    contacts.push_back(m.contacts);
    status.push_back(m.status);
    choice.push_back(m.choice);
  }

  void addStates(const std::vector<scene::BodyState>& bodies) {
    for (const scene::BodyState& b : bodies) {
      positions.insert(positions.end(), b.position.begin(), b.position.end());
      orientations.insert(orientations.end(),
                          {b.orientation.w, b.orientation.x, b.orientation.y, b.orientation.z});
      velocities.insert(velocities.end(), b.velocity.begin(), b.velocity.end());
    }
  }
};

scene::RunSettings settingsFor(const scene::Scene& s, const RunArgs& a) {
  scene::RunSettings run = scene::RunSettings::fromScene(s);
  if (!a.solver.empty()) run.solver = a.solver;
  if (a.iterations >= 0) run.iterations = a.iterations;
  if (a.tolerance >= 0) run.tolerance = a.tolerance;
  run.warmStart = a.warmStart;
  run.fallback = a.fallback;
  if (a.fallbackResidual >= 0) run.fallbackResidual = a.fallbackResidual;
  return run;
}

nb::dict run(const std::string& path, const std::string& engine, const RunArgs& args) {
  scene::Scene s;
  std::unique_ptr<scene::World> world;
  scene::RunSettings settings;
  try {
    s = scene::loadScene(path);
    settings = settingsFor(s, args);
    world = cli::makeWorld(engine, s, settings);
  } catch (const scene::FormatError& e) {
    throw nb::value_error(e.what());
  } catch (const std::invalid_argument& e) {
    throw nb::value_error(e.what());
  }
  const int steps = args.steps >= 0 ? args.steps : s.settings.steps;
  Columns c;
  cli::RunSummary sum;
  {
    nb::gil_scoped_release unlocked;
    sum = cli::runWorld(*world, steps, [&](const scene::World& w, int) {
      c.add(w.last());
      if (args.states) c.addStates(w.states());
    });
  }
  nb::dict out;
  out["scene"] = s.name;
  out["engine"] = std::string(world->engine());
  out["solver"] = settings.solver;
  out["time_step"] = s.settings.timeStep;
  out["finite"] = sum.finite;
  std::vector<std::string> names;
  for (const scene::Body& b : s.bodies) names.push_back(b.name);
  out["bodies"] = std::move(names);
  out["solver_ms"] = toNumpy(std::move(c.solverMs));
  out["step_ms"] = toNumpy(std::move(c.stepMs));
  out["residual"] = toNumpy(std::move(c.residual));
  out["iterations"] = toNumpy(std::move(c.iterations));
  out["status"] = std::move(c.status);
  out["fallbacks"] = toNumpy(std::move(c.fallbacks));
  out["choice"] = std::move(c.choice);
  out["contacts"] = toNumpy(std::move(c.contacts));
  out["max_penetration"] = toNumpy(std::move(c.maxPenetration));
  out["joint_error"] = toNumpy(std::move(c.jointError));
  out["energy"] = toNumpy(std::move(c.energy));
  out["momentum"] = toNumpy(std::move(c.momentum));
  out["max_speed"] = toNumpy(std::move(c.maxSpeed));
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
         int iterations, double tol, bool warmStart, const std::string& fallback,
         double fallbackResidual, bool states) {
        return run(
            path, engine,
            RunArgs{solver, steps, iterations, tol, warmStart, fallback, fallbackResidual, states});
      },
      nb::arg("path"), nb::arg("engine"), nb::arg("solver"), nb::arg("steps"),
      nb::arg("iterations"), nb::arg("tol"), nb::arg("warm_start"), nb::arg("fallback"),
      nb::arg("fallback_residual"), nb::arg("states"));
  m.def("engine_names", &cli::engineList);
}

}  // namespace mlcp::python
