// mlcp stability: a grid of stack runs per engine and solver, each cell classified stable /
// drifting / collapsed / exploded / solver-failure (the grids: stability_grid.hpp; the
// thresholds and the measures: stability.hpp). One CSV row per cell, in the format
// `tools/chart.py heatmap` reads.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "progress.hpp"
#include "scene_runs.hpp"
#include "stability_grid.hpp"

namespace mlcp::cli {

namespace {

struct StabilityArgs {
  StabilityGrid grid;
  std::string csv;
  std::string chart;
};

std::string label(const StabilityCell& c) {
  std::ostringstream s;
  s << c.engine << '/' << c.solver << ' ' << c.xName << '=' << c.x << ' ' << c.yName << '=' << c.y;
  return s.str();
}

// The grid as letters on standard output, one line per engine, solver and grid: rows from the
// largest y down, columns x ascending, e.g.
//   stack_mass_ratio bullet/pgs  height 16: DDCC | 8: DDCC | 4: SDCC | 2: SSCC  (mass_ratio 1 10
//   100 1000)
void printMaps(const std::vector<StabilityCell>& cells, const std::string& letters) {
  std::size_t i = 0;
  while (i < cells.size()) {
    std::size_t end = i;
    std::map<double, std::map<double, char>> rows;  // y -> x -> letter
    while (end < cells.size() && cells[end].engine == cells[i].engine &&
           cells[end].solver == cells[i].solver && cells[end].scene == cells[i].scene) {
      rows[cells[end].y][cells[end].x] = letters[end];
      ++end;
    }
    std::ostringstream line;
    line << cells[i].scene << ' ' << cells[i].engine << '/' << cells[i].solver << "  "
         << cells[i].yName << ' ';
    for (auto row = rows.rbegin(); row != rows.rend(); ++row) {
      line << (row == rows.rbegin() ? "" : " | ") << row->first << ": ";
      for (const auto& [x, letter] : row->second) line << letter;
    }
    line << "  (" << cells[i].xName;
    for (const auto& [x, letter] : rows.begin()->second) line << ' ' << x;
    line << ')';
    std::cout << line.str() << "\n";
    i = end;
  }
  std::cout << "(S stable, D drifting, C collapsed, E exploded, F solver-failure)\n";
}

int runStability(StabilityArgs args) {
  if (!args.chart.empty() && args.csv.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(args.chart, ec);
    args.csv = args.chart + "/stability.csv";
  }
  std::vector<StabilityCell> cells;
  try {
    cells = stabilityCells(args.grid);
  } catch (const std::invalid_argument& e) {
    std::cerr << "mlcp stability: " << e.what() << "\n";
    return kInvalidInput;
  }

  std::ofstream file;
  if (!args.csv.empty()) {
    file.open(args.csv);
    if (!file) {
      std::cerr << "mlcp stability: cannot write " << args.csv << "\n";
      return kInvalidInput;
    }
  }
  std::ostream& csv = args.csv.empty() ? std::cout : file;
  csv << kStabilityCsvHeader << "\n" << std::setprecision(9);

  std::map<Outcome, int> counts;
  std::string letters;  // one per cell, in cell order
  Progress progress("stability", int(cells.size()));
  for (const StabilityCell& c : cells) {
    progress.start(label(c));
    const StabilityResult r = runStabilityCell(args.grid, c);
    ++counts[r.classification.outcome];
    letters.push_back("SDCEF"[static_cast<int>(r.classification.outcome)]);
    writeStabilityCsv(csv, c, r);
    progress.done();
  }
  progress.finish();
  if (!args.csv.empty()) printMaps(cells, letters);
  std::cerr << "stability: " << cells.size() << " cells:";
  for (const auto& [outcome, n] : counts) std::cerr << ' ' << toString(outcome) << ' ' << n;
  std::cerr << (args.csv.empty() ? "" : "; wrote " + args.csv) << "\n";
  if (!csv) return kInvalidInput;
  if (args.chart.empty()) return kSolved;
  file.close();
  return runChart({"heatmap", args.csv, "-o", args.chart}) == 0 ? kSolved : kNotSolved;
}

// The command's description: the outcomes with their default thresholds, the grids, the CSV.
std::string stabilityHelp() {
  const StabilityThresholds t;
  std::ostringstream help;
  help << "Where methods break: stacks of 1 m cubes at rest, run per engine and solver over two "
          "grids, each cell classified by the first outcome that holds:\n"
          "  exploded        non-finite state, or a body faster than --max-speed ("
       << t.maxSpeed
       << " m/s)\n"
          "  solver-failure  more than --failure-share ("
       << t.failureShare
       << ") of the steps failed (failed / numerical-issue / unsupported status) or fell back\n"
          "  collapsed       a box moved more than --collapse-fraction ("
       << t.collapseFraction << ") of its edge from its start, or penetration > "
       << "--collapse-penetration (" << t.collapsePenetration
       << " m)\n"
          "  drifting        the top box moved more than --drift ("
       << t.drift
       << " m)\n"
          "  stable          none of these\n"
          "Grids: mass (x mass_ratio = top/bottom box mass, geometric in between; y height in "
          "boxes; time step 1/60 s) and step (x time_step in s, y iterations; a stack of "
          "--step-height boxes, mass ratio --step-ratio). Every cell runs --seconds of "
          "simulated time. One CSV row per cell (tools/chart.py heatmap reads it): "
          "engine,solver,x_name,x_value,y_name,y_value,outcome,scene and the measures "
          "steps,max_speed (m/s),max_displacement (edges),top_displacement (m),"
          "max_penetration (m),failed_steps,fallback_steps,worst_residual,mean_solver_ms,"
          "reason. Exit 0: the grid ran (and --chart drew it); 1: --chart failed; 2: bad "
          "arguments.";
  return help.str();
}

// The grids: engines, solvers and each grid's axes, and what every cell runs.
void addGridOptions(CLI::App* cmd, StabilityGrid& grid) {
  cmd->add_option("--engines", grid.engines,
                  "engines, comma separated (known: " + engineNames() +
                      "; default: " + defaultEngineNames() + ")")
      ->delimiter(',');
  cmd->add_option("--solvers", grid.solvers,
                  "solvers, comma separated; stock names (bullet-*, ode-*) run in their own "
                  "engine only")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--grids", grid.grids, "mass, step or mass,step")->capture_default_str();
  cmd->add_option("--ratios", grid.ratios, "mass grid: top/bottom mass ratios")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--heights", grid.heights, "mass grid: stack heights (boxes, >= 1)")
      ->delimiter(',')
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--time-steps", grid.timeSteps, "step grid: time steps (s)")
      ->delimiter(',')
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--iteration-counts", grid.iterationCounts, "step grid: iterations per solve")
      ->delimiter(',')
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--step-height", grid.stepHeight, "step grid: stack height (boxes)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--step-ratio", grid.stepRatio, "step grid: top/bottom mass ratio")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--cfm", grid.cfm,
                  "world cfm of the stacks (the scenes' 1e-5 is a contact spring that a heavy "
                  "stack compresses by centimetres)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--seconds", grid.seconds, "simulated time per cell (s)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--iterations", grid.iterations, "mass grid: iterations per solve")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--fallback", grid.fallback,
                  "core solver run when our adapters reject an answer, or none: each solver "
                  "alone, so that the map shows where it breaks")
      ->capture_default_str();
  cmd->add_flag("--quick", grid.quick,
                "a 2 x 2 grid of each kind and 1 s per cell (for tests; overrides the grid "
                "options)");
}

void addOutputOptions(CLI::App* cmd, StabilityArgs& args) {
  cmd->add_option("--csv", args.csv,
                  "CSV file to write (default: standard output, or DIR/stability.csv with "
                  "--chart)");
  cmd->add_option("--chart", args.chart,
                  "also draw the heat maps into this folder (tools/chart.py heatmap through "
                  "the venv, as mlcp chart does)");
}

// The outcome thresholds (stability.hpp).
void addThresholdOptions(CLI::App* cmd, StabilityThresholds& thresholds) {
  cmd->add_option("--max-speed", thresholds.maxSpeed, "exploded above this speed (m/s)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--failure-share", thresholds.failureShare,
                  "solver-failure above this share of failed or fallback steps")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--collapse-fraction", thresholds.collapseFraction,
                  "collapsed when a box moved more than this fraction of its edge")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--collapse-penetration", thresholds.collapsePenetration,
                  "collapsed above this penetration (m)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--drift", thresholds.drift, "drifting when the top box moved more than this (m)")
      ->check(positiveNumber())
      ->capture_default_str();
}

}  // namespace

Runner addStabilityCommand(CLI::App& app) {
  auto args = std::make_shared<StabilityArgs>();
  CLI::App* cmd = app.add_subcommand("stability", stabilityHelp());
  addGridOptions(cmd, args->grid);
  addOutputOptions(cmd, *args);
  addThresholdOptions(cmd, args->grid.thresholds);
  return [args] { return runStability(*args); };
}

}  // namespace mlcp::cli
