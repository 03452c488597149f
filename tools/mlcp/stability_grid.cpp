#include "stability_grid.hpp"

#include <cmath>
#include <ostream>
#include <stdexcept>

namespace mlcp::cli {

namespace {

// Stock names run only in their own engine ("bullet-si" in bullet and bullet-multibody).
bool runsIn(const std::string& solver, const std::string& engine) {
  for (const std::string& e : engineList())
    if (solver.rfind(e + "-", 0) == 0) return e == engine || engine.rfind(e + "-", 0) == 0;
  return true;
}

// The grid with --quick applied.
StabilityGrid resolved(StabilityGrid g) {
  if (g.quick) {
    g.ratios = {1, 100};
    g.heights = {2, 6};
    g.timeSteps = {1.0 / 120, 1.0 / 30};
    g.iterationCounts = {3, 20};
    g.seconds = 1;
  }
  if (g.engines.empty()) g.engines = defaultEngines();
  return g;
}

scene::RunSettings cellSettings(const StabilityGrid& g, const StabilityCell& c) {
  scene::RunSettings run;
  run.iterations = c.scene == "stack_time_step" ? static_cast<int>(c.y) : g.iterations;
  run.fallback = g.fallback == "none" ? "" : g.fallback;
  run.solver = c.solver;
  return run;
}

scene::Scene cellScene(const StabilityGrid& g, const StabilityCell& c) {
  if (c.scene == "stack_time_step")
    return stackScene(c.scene, g.stepHeight, g.stepRatio, c.x, g.cfm);
  return stackScene(c.scene, static_cast<int>(c.y), c.x, g.massTimeStep, g.cfm);
}

}  // namespace

std::vector<StabilityCell> stabilityCells(const StabilityGrid& grid) {
  const StabilityGrid g = resolved(grid);
  const bool massGrid = g.grids.find("mass") != std::string::npos;
  const bool stepGrid = g.grids.find("step") != std::string::npos;
  if (!massGrid && !stepGrid)
    throw std::invalid_argument("--grids must name mass, step or both (got '" + g.grids + "')");
  std::vector<StabilityCell> cells;
  for (const std::string& engine : g.engines)
    for (const std::string& solver : g.solvers) {
      if (!runsIn(solver, engine)) continue;
      const StabilityCell probe{engine, solver, "check", "", "", 0, 0};
      makeWorld(engine, stackScene("check", 1, 1, 0.01), cellSettings(g, probe));  // names
      if (massGrid)
        for (int h : g.heights)
          for (double r : g.ratios) {
            cells.push_back(
                {engine, solver, "stack_mass_ratio", "mass_ratio", "height", r, double(h)});
            cellScene(g, cells.back());  // throws for a bad height, ratio or cfm
          }
      if (stepGrid)
        for (int it : g.iterationCounts)
          for (double dt : g.timeSteps) {
            cells.push_back(
                {engine, solver, "stack_time_step", "time_step", "iterations", dt, double(it)});
            cellScene(g, cells.back());
          }
    }
  if (cells.empty())
    throw std::invalid_argument("no cell to run (no solver of --solvers runs in --engines)");
  return cells;
}

StabilityResult runStabilityCell(const StabilityGrid& grid, const StabilityCell& cell) {
  const StabilityGrid g = resolved(grid);
  const scene::Scene built = cellScene(g, cell);
  auto world = makeWorld(cell.engine, built, cellSettings(g, cell));
  CellTracker tracker(world->scene());
  const int steps = std::max(1, int(std::lround(g.seconds / built.settings.timeStep)));
  StabilityResult r;
  r.summary = runWorld(*world, steps,
                       [&](const scene::World& w, int) { tracker.observe(w.states(), w.last()); });
  r.measures = tracker.measures();
  r.classification = classify(r.measures, g.thresholds);
  return r;
}

const char* const kStabilityCsvHeader =
    "engine,solver,x_name,x_value,y_name,y_value,outcome,scene,steps,max_speed,"
    "max_displacement,top_displacement,max_penetration,failed_steps,fallback_steps,"
    "worst_residual,mean_solver_ms,reason";

void writeStabilityCsv(std::ostream& out, const StabilityCell& c, const StabilityResult& r) {
  const CellMeasures& m = r.measures;
  out << c.engine << ',' << c.solver << ',' << c.xName << ',' << c.x << ',' << c.yName << ',' << c.y
      << ',' << toString(r.classification.outcome) << ',' << c.scene << ',' << m.steps << ','
      << m.maxSpeed << ',' << m.maxDisplacementRatio << ',' << m.topDisplacement << ','
      << m.maxPenetration << ',' << m.failedSteps << ',' << m.fallbackSteps << ','
      << r.summary.worstResidual << ',' << r.summary.meanSolverMs << ',' << r.classification.reason
      << "\n";
}

}  // namespace mlcp::cli
