// mlcp stability: a grid of stack runs per engine and solver, each cell classified stable /
// drifting / collapsed / exploded / solver-failure (the thresholds and the measures are in
// stability.hpp). Two grids:
//   mass   x = mass_ratio (top box / bottom box), y = height (boxes); scene "stack_mass_ratio"
//   step   x = time_step (s), y = iterations; scene "stack_time_step", a stack of --step-height
//          boxes with the top/bottom mass ratio --step-ratio
// Every cell runs the same simulated time (--seconds), so a smaller time step takes more
// steps. One CSV row per cell, in the format `tools/chart.py heatmap` reads.
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
#include "stability.hpp"

namespace mlcp::cli {

namespace {

struct StabilityArgs {
  std::vector<std::string> engines;
  std::vector<std::string> solvers{"pgs",       "dantzig",  "bullet-si", "bullet-mlcp-dantzig",
                                   "ode-world", "ode-quick"};
  std::string grids = "mass,step";
  std::vector<double> ratios{1, 10, 100, 1000};
  std::vector<int> heights{2, 4, 8, 16};
  std::vector<double> timeSteps{1.0 / 240, 1.0 / 120, 1.0 / 60, 1.0 / 30};
  std::vector<int> iterationCounts{2, 5, 10, 20, 50};
  int stepHeight = 6;
  double stepRatio = 10;
  double seconds = 2;
  int iterations = 20;
  double massTimeStep = 1.0 / 60;
  double cfm = kStackCfm;
  std::string fallback = "none";
  bool quick = false;
  std::string csv;
  std::string chart;
  StabilityThresholds thresholds;
};

struct Cell {
  std::string engine, solver, scene, xName, yName;
  double x = 0, y = 0;
  scene::Scene built;
  scene::RunSettings run;
};

// Stock names run only in their own engine.
bool runsIn(const std::string& solver, const std::string& engine) {
  for (const std::string& e : engineList())
    if (solver.rfind(e + "-", 0) == 0) return e == engine;
  return true;
}

std::string label(const Cell& c) {
  std::ostringstream s;
  s << c.engine << '/' << c.solver << ' ' << c.xName << '=' << c.x << ' ' << c.yName << '=' << c.y;
  return s.str();
}

// The grid as letters on standard output, one line per engine, solver and grid: rows from the
// largest y down, columns x ascending, e.g.
//   stack_mass_ratio bullet/pgs  height 16: DDCC | 8: DDCC | 4: SDCC | 2: SSCC  (mass_ratio 1 10
//   100 1000)
void printMaps(const std::vector<Cell>& cells, const std::string& letters) {
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
  if (args.quick) {
    args.ratios = {1, 100};
    args.heights = {2, 6};
    args.timeSteps = {1.0 / 120, 1.0 / 30};
    args.iterationCounts = {3, 20};
    args.seconds = 1;
  }
  if (args.engines.empty()) args.engines = engineList();
  if (!args.chart.empty() && args.csv.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(args.chart, ec);
    args.csv = args.chart + "/stability.csv";
  }
  const bool massGrid = args.grids.find("mass") != std::string::npos;
  const bool stepGrid = args.grids.find("step") != std::string::npos;
  if (!massGrid && !stepGrid) {
    std::cerr << "mlcp stability: --grids must name mass, step or both (got '" << args.grids
              << "')\n";
    return kInvalidInput;
  }

  scene::RunSettings base;
  base.iterations = args.iterations;
  base.fallback = args.fallback == "none" ? "" : args.fallback;
  std::vector<Cell> cells;
  try {
    for (const std::string& engine : args.engines)
      for (const std::string& solver : args.solvers) {
        if (!runsIn(solver, engine)) continue;
        scene::RunSettings run = base;
        run.solver = solver;
        makeWorld(engine, stackScene("check", 1, 1, 0.01), run);  // unknown names throw here
        if (massGrid)
          for (int h : args.heights)
            for (double r : args.ratios)
              cells.push_back(
                  {engine, solver, "stack_mass_ratio", "mass_ratio", "height", r, double(h),
                   stackScene("stack_mass_ratio", h, r, args.massTimeStep, args.cfm), run});
        if (stepGrid)
          for (int it : args.iterationCounts)
            for (double dt : args.timeSteps) {
              Cell c{engine,
                     solver,
                     "stack_time_step",
                     "time_step",
                     "iterations",
                     dt,
                     double(it),
                     stackScene("stack_time_step", args.stepHeight, args.stepRatio, dt, args.cfm),
                     run};
              c.run.iterations = it;
              cells.push_back(std::move(c));
            }
      }
  } catch (const std::invalid_argument& e) {
    std::cerr << "mlcp stability: " << e.what() << "\n";
    return kInvalidInput;
  }
  if (cells.empty()) {
    std::cerr << "mlcp stability: no cell to run (no solver of --solvers runs in --engines)\n";
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
  csv << "engine,solver,x_name,x_value,y_name,y_value,outcome,scene,steps,max_speed,"
         "max_displacement,top_displacement,max_penetration,failed_steps,fallback_steps,"
         "worst_residual,mean_solver_ms,reason\n"
      << std::setprecision(9);

  std::map<Outcome, int> counts;
  std::string letters;  // one per cell, in cell order
  Progress progress("stability", int(cells.size()));
  for (const Cell& c : cells) {
    progress.start(label(c));
    auto world = makeWorld(c.engine, c.built, c.run);
    CellTracker tracker(world->scene());
    const int steps = std::max(1, int(std::lround(args.seconds / c.built.settings.timeStep)));
    const RunSummary sum = runWorld(
        *world, steps, [&](const scene::World& w, int) { tracker.observe(w.states(), w.last()); });
    const CellMeasures& m = tracker.measures();
    const Classification k = classify(m, args.thresholds);
    ++counts[k.outcome];
    letters.push_back("SDCEF"[static_cast<int>(k.outcome)]);
    csv << c.engine << ',' << c.solver << ',' << c.xName << ',' << c.x << ',' << c.yName << ','
        << c.y << ',' << toString(k.outcome) << ',' << c.scene << ',' << m.steps << ','
        << m.maxSpeed << ',' << m.maxDisplacementRatio << ',' << m.topDisplacement << ','
        << m.maxPenetration << ',' << m.failedSteps << ',' << m.fallbackSteps << ','
        << sum.worstResidual << ',' << sum.meanSolverMs << ',' << k.reason << "\n";
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

}  // namespace

Runner addStabilityCommand(CLI::App& app) {
  auto args = std::make_shared<StabilityArgs>();
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
  CLI::App* cmd = app.add_subcommand("stability", help.str());
  cmd->add_option("--engines", args->engines,
                  "engines, comma separated (default: all built: " + engineNames() + ")")
      ->delimiter(',');
  cmd->add_option("--solvers", args->solvers,
                  "solvers, comma separated; stock names (bullet-*, ode-*) run in their own "
                  "engine only")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--grids", args->grids, "mass, step or mass,step")->capture_default_str();
  cmd->add_option("--ratios", args->ratios, "mass grid: top/bottom mass ratios")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--heights", args->heights, "mass grid: stack heights (boxes, >= 1)")
      ->delimiter(',')
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--time-steps", args->timeSteps, "step grid: time steps (s)")
      ->delimiter(',')
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--iteration-counts", args->iterationCounts, "step grid: iterations per solve")
      ->delimiter(',')
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--step-height", args->stepHeight, "step grid: stack height (boxes)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--step-ratio", args->stepRatio, "step grid: top/bottom mass ratio")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--cfm", args->cfm,
                  "world cfm of the stacks (the scenes' 1e-5 is a contact spring that a heavy "
                  "stack compresses by centimetres)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--seconds", args->seconds, "simulated time per cell (s)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--iterations", args->iterations, "mass grid: iterations per solve")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--fallback", args->fallback,
                  "core solver run when our adapters reject an answer, or none: each solver "
                  "alone, so that the map shows where it breaks")
      ->capture_default_str();
  cmd->add_flag("--quick", args->quick,
                "a 2 x 2 grid of each kind and 1 s per cell (for tests; overrides the grid "
                "options)");
  cmd->add_option("--csv", args->csv,
                  "CSV file to write (default: standard output, or DIR/stability.csv with "
                  "--chart)");
  cmd->add_option("--chart", args->chart,
                  "also draw the heat maps into this folder (tools/chart.py heatmap through "
                  "the venv, as mlcp chart does)");
  cmd->add_option("--max-speed", args->thresholds.maxSpeed, "exploded above this speed (m/s)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--failure-share", args->thresholds.failureShare,
                  "solver-failure above this share of failed or fallback steps")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--collapse-fraction", args->thresholds.collapseFraction,
                  "collapsed when a box moved more than this fraction of its edge")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--collapse-penetration", args->thresholds.collapsePenetration,
                  "collapsed above this penetration (m)")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd->add_option("--drift", args->thresholds.drift,
                  "drifting when the top box moved more than this (m)")
      ->check(positiveNumber())
      ->capture_default_str();
  return [args] { return runStability(*args); };
}

}  // namespace mlcp::cli
