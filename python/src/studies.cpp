// mlcp._mlcp's sweeps and stability grids, as the CLI plans and runs them (tools/mlcp/sweeps.hpp,
// stability_grid.hpp): a plan lists independent runs as plain tuples (picklable, so that any
// executor can send them to other processes or machines); each run is then one call here. The
// runs hold the GIL: ODE's worlds may not be stepped from two threads at once, so a thread pool
// runs them one at a time (processes run them in parallel).
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.hpp"
#include "columns.hpp"
#include "mlcp/stability_grid.hpp"
#include "mlcp/sweeps.hpp"

namespace mlcp::python {

namespace {

// (scene file, engine, solver, setting, value, setting applies)
using ComboTuple = std::tuple<std::string, std::string, std::string, std::string, double, bool>;
// (engine, solver, scene, x name, y name, x, y)
using CellTuple =
    std::tuple<std::string, std::string, std::string, std::string, std::string, double, double>;

template <typename F>
auto valueErrors(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw nb::value_error(e.what());
  } catch (const scene::FormatError& e) {
    throw nb::value_error(e.what());
  }
}

cli::SweepSpec sweepSpec(int steps, bool warmStart, const std::string& fallback) {
  cli::SweepSpec spec;
  spec.steps = steps;
  spec.warmStart = warmStart;
  spec.fallback = fallback;
  return spec;
}

nb::tuple sweepPlan(const std::vector<std::string>& scenes, const std::vector<std::string>& engines,
                    const std::optional<std::vector<std::string>>& solvers,
                    const std::string& setting, const std::vector<std::string>& values, int steps,
                    bool warmStart, const std::string& fallback) {
  cli::SweepSpec spec = sweepSpec(steps, warmStart, fallback);
  spec.scenes = scenes;
  spec.engines = engines;
  if (solvers) spec.solvers = *solvers;
  spec.setting = setting;
  spec.values = values;
  const cli::SweepPlan plan = valueErrors([&] { return cli::planSweep(spec); });
  std::vector<ComboTuple> combos;
  for (const cli::SweepCombo& c : plan.combos)
    combos.emplace_back(c.scene, c.engine, c.solver, c.setting, c.value, c.applies);
  return nb::make_tuple(combos, plan.skipped);
}

// One combination, `repeat` passes; the first pass's steps with the fastest times.
nb::dict sweepRun(const ComboTuple& t, int steps, bool warmStart, const std::string& fallback,
                  int repeat) {
  const cli::SweepSpec spec = sweepSpec(steps, warmStart, fallback);
  const auto& [file, engine, solver, setting, value, applies] = t;
  const cli::SweepCombo combo{file, engine, solver, setting, value, applies};
  cli::SweepRun run;
  valueErrors([&] {
    const scene::Scene s = scene::loadScene(file);
    for (int pass = 0; pass < repeat; ++pass) cli::runSweepPass(spec, s, combo, run);
    return 0;
  });
  Columns c;
  for (const scene::StepMeasures& m : run.steps) c.add(m);
  nb::dict out;
  out["scene"] = run.scene;
  out["engine"] = run.engine;
  out["finite"] = run.first.finite;
  out["differing"] = run.differing;
  c.moveInto(out);
  return out;
}

cli::StabilityGrid stabilityGrid(const nb::dict& settings) {
  cli::StabilityGrid g;
  for (auto [key, value] : settings) {
    const std::string k = nb::cast<std::string>(key);
    auto set = [&](const char* name, auto& field) {
      if (k != name) return false;
      field = nb::cast<std::decay_t<decltype(field)>>(value);
      return true;
    };
    cli::StabilityThresholds& t = g.thresholds;
    if (!(set("engines", g.engines) || set("solvers", g.solvers) || set("grids", g.grids) ||
          set("ratios", g.ratios) || set("heights", g.heights) || set("time_steps", g.timeSteps) ||
          set("iteration_counts", g.iterationCounts) || set("step_height", g.stepHeight) ||
          set("step_ratio", g.stepRatio) || set("seconds", g.seconds) ||
          set("iterations", g.iterations) || set("cfm", g.cfm) || set("fallback", g.fallback) ||
          set("quick", g.quick) || set("max_speed", t.maxSpeed) ||
          set("failure_share", t.failureShare) || set("collapse_fraction", t.collapseFraction) ||
          set("collapse_penetration", t.collapsePenetration) || set("drift", t.drift)))
      throw nb::value_error(("unknown stability setting '" + k + "'").c_str());
  }
  return g;
}

std::vector<CellTuple> stabilityCells(const nb::dict& settings) {
  const cli::StabilityGrid g = stabilityGrid(settings);
  std::vector<CellTuple> out;
  for (const cli::StabilityCell& c : valueErrors([&] { return cli::stabilityCells(g); }))
    out.emplace_back(c.engine, c.solver, c.scene, c.xName, c.yName, c.x, c.y);
  return out;
}

// One cell's row of the stability CSV, by column name.
nb::dict stabilityCell(const CellTuple& t, const nb::dict& settings) {
  const cli::StabilityGrid g = stabilityGrid(settings);
  const auto& [engine, solver, scene, xName, yName, x, y] = t;
  const cli::StabilityCell cell{engine, solver, scene, xName, yName, x, y};
  const cli::StabilityResult r = valueErrors([&] { return cli::runStabilityCell(g, cell); });
  const cli::CellMeasures& m = r.measures;
  nb::dict out;
  out["engine"] = engine;
  out["solver"] = solver;
  out["x_name"] = xName;
  out["x_value"] = x;
  out["y_name"] = yName;
  out["y_value"] = y;
  out["outcome"] = std::string(cli::toString(r.classification.outcome));
  out["scene"] = scene;
  out["steps"] = m.steps;
  out["max_speed"] = m.maxSpeed;
  out["max_displacement"] = m.maxDisplacementRatio;
  out["top_displacement"] = m.topDisplacement;
  out["max_penetration"] = m.maxPenetration;
  out["failed_steps"] = m.failedSteps;
  out["fallback_steps"] = m.fallbackSteps;
  out["worst_residual"] = r.summary.worstResidual;
  out["mean_solver_ms"] = r.summary.meanSolverMs;
  out["reason"] = r.classification.reason;
  return out;
}

}  // namespace

void bindStudies(nb::module_& m) {
  m.def("sweep_plan", &sweepPlan, nb::arg("scenes"), nb::arg("engines"), nb::arg("solvers").none(),
        nb::arg("setting"), nb::arg("values"), nb::arg("steps"), nb::arg("warm_start"),
        nb::arg("fallback"));
  m.def("sweep_run", &sweepRun, nb::arg("combo"), nb::arg("steps"), nb::arg("warm_start"),
        nb::arg("fallback"), nb::arg("repeat"));
  m.def("sweep_columns", [] { return std::string(cli::kSweepCsvColumns) + cli::kStepCsvHeader; });
  m.def("stability_cells", &stabilityCells, nb::arg("settings"));
  m.def("stability_cell", &stabilityCell, nb::arg("cell"), nb::arg("settings"));
  m.def("stability_columns", [] { return std::string(cli::kStabilityCsvHeader); });
}

}  // namespace mlcp::python
