// The grids of `mlcp stability` as lists of independent cells, shared by the command and the
// Python module's mlcp.stability: a cell names its engine, solver, grid and coordinates, and
// runs on its own (its stack scene is built from the grid), in any order or process. Two grids:
//   mass   x = mass_ratio (top box / bottom box), y = height (boxes); scene "stack_mass_ratio"
//   step   x = time_step (s), y = iterations; scene "stack_time_step", a stack of stepHeight
//          boxes with the top/bottom mass ratio stepRatio
// Every cell runs the same simulated time (seconds), so a smaller time step takes more steps.
// The measures and the classification: stability.hpp.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "scene_runs.hpp"
#include "stability.hpp"

namespace mlcp::cli {

struct StabilityGrid {
  std::vector<std::string> engines;  // empty: every engine built
  // Stock names (bullet-*, ode-*) run in their own engine only.
  std::vector<std::string> solvers{"pgs",       "dantzig",  "bullet-si", "bullet-mlcp-dantzig",
                                   "ode-world", "ode-quick"};
  std::string grids = "mass,step";
  std::vector<double> ratios{1, 10, 100, 1000};                             // mass grid
  std::vector<int> heights{2, 4, 8, 16};                                    // mass grid, boxes
  std::vector<double> timeSteps{1.0 / 240, 1.0 / 120, 1.0 / 60, 1.0 / 30};  // step grid, s
  std::vector<int> iterationCounts{2, 5, 10, 20, 50};                       // step grid
  int stepHeight = 6;                                                       // step grid: boxes
  double stepRatio = 10;  // step grid: top/bottom mass ratio
  double seconds = 2;     // simulated time per cell, s
  int iterations = 20;    // mass grid: iterations per solve
  double massTimeStep = 1.0 / 60;
  double cfm = kStackCfm;
  std::string fallback = "none";  // each solver alone, so that the map shows where it breaks
  bool quick = false;  // a 2 x 2 grid of each kind and 1 s per cell (overrides the grid options)
  StabilityThresholds thresholds;
};

struct StabilityCell {
  std::string engine, solver, scene, xName, yName;
  double x = 0, y = 0;
};

// The grid's cells, engine by engine, solver by solver, grid by grid (y outer, x inner); throws
// std::invalid_argument with the message `mlcp stability` prints for bad arguments.
std::vector<StabilityCell> stabilityCells(const StabilityGrid& grid);

struct StabilityResult {
  CellMeasures measures;
  Classification classification;
  RunSummary summary;
};

// Builds the cell's stack and runs it for the grid's simulated time.
StabilityResult runStabilityCell(const StabilityGrid& grid, const StabilityCell& cell);

// The stability CSV (tools/chart.py heatmap reads it): the header and one row per cell.
extern const char* const kStabilityCsvHeader;
void writeStabilityCsv(std::ostream& out, const StabilityCell& cell, const StabilityResult& r);

}  // namespace mlcp::cli
