// mlcp sweep SCENES... --engines E --solvers S --setting iterations|tolerance --values V,...:
// every scene x engine x solver x value of one solver setting, stepped through the shared run
// loop (scene_runs.hpp) into one tidy CSV, one row per step. tools/chart.py reads it.
//
// Design notes
// - A combination that cannot exist (a stock solver of the other engine: bullet-* in ODE,
//   ode-* in Bullet) is skipped and listed once on stderr. A name no engine knows is an error.
// - A stock solver that ignores the swept setting runs ONCE, at the first value, and its rows
//   say setting_applies = 0: repeating an identical run per value would only measure timer
//   noise and cost time. What the stock solvers ignore (see the engine loaders):
//     tolerance   every stock solver (bullet-*, ode-*): none has a tolerance; the value only
//                 decides whether the scene loader labels a stock MLCP step "converged"
//     iterations  ode-world (dWorldStep's pivoting has no iteration count); bullet-si/-nncg,
//                 ode-quick and bullet-mlcp-* use it (btMLCPSolver's PGS and its SI fallback)
//   Core solvers (through our adapters) take both settings and run at every value.
// - A run that blows up (non-finite body state) keeps its rows up to and including the step
//   that blew up; the sweep goes on and exits 1 at the end, listing those runs.
// - --repeat N runs every combination N times, in N passes over all of them (so that a slow
//   spell of a shared machine hits different combinations in different passes), and writes
//   each step's solver_ms and step_ms as the minimum over the passes: the runs are
//   deterministic (the same trajectory, residuals and choices every pass), so the work per step
//   is the same and the minimum is the estimate least disturbed by other processes. A pass
//   whose measures of a step differ from the first pass's (residual, iterations, status,
//   choice, energy, penetration: some solver depended on time) is not used from that step
//   on, and the sweep says so on stderr. The rows are written after the last pass.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "mlcp/input_limits.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "progress.hpp"
#include "scene_runs.hpp"

namespace mlcp::cli {

namespace {

const char* const kSweepColumns = "setting,value,setting_applies,";

struct SweepArgs {
  std::vector<std::string> scenes;
  std::vector<std::string> engines;
  std::vector<std::string> solvers{"pgs", "dantzig", "auto", "bullet-si", "ode-quick"};
  std::string setting = "iterations";
  std::vector<std::string> values;
  int steps = -1;  // -1: each scene's settings.steps
  bool noWarmStart = false;
  std::string fallback = "pgs";
  std::string csv;
  bool append = false;
  int repeat = 1;
};

// Whether two runs' measures of one step describe the same step (all but the times).
bool sameStep(const scene::StepMeasures& a, const scene::StepMeasures& b) {
  auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  return same(a.residual, b.residual) && a.iterations == b.iterations && a.status == b.status &&
         a.fallbacks == b.fallbacks && a.choice == b.choice && a.contacts == b.contacts &&
         same(a.maxPenetration, b.maxPenetration) && same(a.energy, b.energy);
}

bool isStock(const std::string& solver) {
  return solver.rfind("bullet-", 0) == 0 || solver.rfind("ode-", 0) == 0;
}

bool settingApplies(const std::string& solver, const std::string& setting) {
  if (!isStock(solver)) return true;
  return setting == "iterations" && solver != "ode-world";
}

// The values as numbers: iterations are whole and >= 1, tolerances > 0.
bool parseValues(const SweepArgs& args, std::vector<double>& out, std::string& error) {
  for (const std::string& text : args.values) {
    if (text.empty()) {
      error = "--values: an empty value (give e.g. --values 5,10,20)";
      return false;
    }
    std::size_t used = 0;
    double v = std::nan("");
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    const bool whole = std::isfinite(v) && v == std::floor(v) && v >= 1 && v <= 1e9;
    if (used == 0 || used != text.size() || !std::isfinite(v) ||
        (args.setting == "iterations" ? !whole : v <= 0)) {
      error = "--values: '" + io::capped(text, 24) + "' is not " +
              (args.setting == "iterations" ? "a whole number of iterations >= 1"
                                            : "a positive tolerance");
      return false;
    }
    out.push_back(v);
  }
  if (out.empty()) error = "--values: give at least one value (e.g. --values 5,10,20)";
  return !out.empty();
}

std::string fmtValue(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

std::string minutes(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%d:%02d", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

scene::RunSettings runSettings(const SweepArgs& args, const scene::Scene& s,
                               const std::string& solver) {
  scene::RunSettings run = scene::RunSettings::fromScene(s);
  run.solver = solver;
  run.warmStart = !args.noWarmStart;
  run.fallback = args.fallback == "none" ? "" : args.fallback;
  return run;
}

struct Combo {
  std::size_t scene;
  std::string engine, solver;
  double value;
  bool applies;
};

// The values, engines and scenes of the arguments; false, with the message, on bad input.
bool readInputs(const SweepArgs& args, std::vector<double>& values,
                std::vector<std::string>& engines, std::vector<scene::Scene>& scenes,
                std::string& error) {
  if (!parseValues(args, values, error)) return false;
  const std::vector<std::string> known = engineList();
  engines = args.engines.empty() ? known : args.engines;
  for (const std::string& e : engines)
    if (std::find(known.begin(), known.end(), e) == known.end()) {
      error = "unknown engine '" + e + "' (known: " + engineNames() + ")";
      return false;
    }
  if (args.solvers.empty()) {
    error = "--solvers: give at least one solver";
    return false;
  }
  for (const std::string& path : args.scenes) {
    try {
      scenes.push_back(scene::loadScene(path));
    } catch (const scene::FormatError& e) {
      error = e.what();
      return false;
    }
  }
  return true;
}

// Which engine takes which solver, asked of the engines themselves on the smallest scene: the
// (engine, solver) pairs that exist. false when a solver exists in no engine.
bool runnablePairs(const SweepArgs& args, const std::vector<std::string>& engines,
                   const std::vector<scene::Scene>& scenes,
                   std::vector<std::pair<std::string, std::string>>& runnable, std::string& skipped,
                   std::string& error) {
  const scene::Scene& probe = *std::min_element(scenes.begin(), scenes.end(),
                                                [](const scene::Scene& a, const scene::Scene& b) {
                                                  return a.bodies.size() < b.bodies.size();
                                                });
  for (const std::string& solver : args.solvers) {
    std::string lastError;
    bool anywhere = false;
    for (const std::string& engine : engines) {
      scene::RunSettings run = runSettings(args, probe, solver);
      try {
        makeWorld(engine, probe, run);
        runnable.emplace_back(engine, solver);
        anywhere = true;
      } catch (const std::invalid_argument& e) {
        lastError = e.what();
        skipped += (skipped.empty() ? "" : ", ") + solver + " in " + engine;
      }
    }
    if (!anywhere) {
      error = lastError;
      return false;
    }
  }
  return true;
}

std::vector<Combo> combinations(const SweepArgs& args, std::size_t sceneCount,
                                const std::vector<std::string>& engines,
                                const std::vector<std::pair<std::string, std::string>>& runnable,
                                const std::vector<double>& values) {
  std::vector<Combo> combos;
  for (std::size_t s = 0; s < sceneCount; ++s)
    for (const std::string& engine : engines)
      for (const auto& [e, solver] : runnable) {
        if (e != engine) continue;
        const bool applies = settingApplies(solver, args.setting);
        for (std::size_t k = 0; k < (applies ? values.size() : 1); ++k)
          combos.push_back({s, engine, solver, values[k], applies});
      }
  return combos;
}

// The CSV opened for writing (fresh: with the header) or, with --append, for appending to a sweep
// CSV of the same header. false, with the message, when it cannot be.
bool openCsv(const SweepArgs& args, const std::string& header, std::ofstream& csv, bool& fresh,
             std::string& error) {
  fresh = true;
  if (args.append && std::filesystem::exists(args.csv)) {
    try {  // a FIFO or /dev/zero would be read forever for its first line
      io::checkInputFile(args.csv, io::kMaxTrajectoryFileBytes, "sweep CSV");
    } catch (const io::FormatError& e) {
      error = std::string("--append: ") + e.what();
      return false;
    }
    std::ifstream old(args.csv);
    std::string first;
    if (old && std::getline(old, first)) {
      if (first != header) {
        error =
            "--append: " + args.csv + " is not a sweep CSV of this version (its header differs)";
        return false;
      }
      fresh = false;
    }
  }
  csv.open(args.csv, fresh ? std::ios::trunc : std::ios::app);
  if (!csv) {
    error = "cannot write " + args.csv;
    return false;
  }
  if (fresh) csv << header << "\n";
  csv << std::setprecision(9);
  return true;
}

// What the passes keep: each combination's steps from the first pass (times lowered by later
// passes), the runs that blew up or differed, the rows written.
struct SweepRecord {
  struct Kept {
    std::string scene, engine, prefix;
    std::vector<scene::StepMeasures> steps;
  };
  std::vector<Kept> kept;
  std::vector<std::string> blownUp, differing;
  std::size_t rows = 0;
};

// Off a terminal: one line per finished run, with the time elapsed and the time left.
void printRunLine(const Progress& bar, std::size_t combos, int passes, std::size_t done,
                  const std::string& label, const RunSummary& sum) {
  const double s = bar.seconds();
  const double eta = s / double(done) * double(combos * passes - done);
  std::cerr << "sweep " << done << "/" << combos * passes << " " << label << ": " << sum.steps
            << " steps, solver " << std::setprecision(3) << sum.meanSolverMs
            << " ms/step, worst residual " << sum.worstResidual << (sum.finite ? "" : ", BLEW UP")
            << " (" << minutes(s) << " elapsed, ETA " << minutes(eta) << ")\n";
}

// One pass of combination c: its world stepped, its rows streamed (one pass) or kept. false,
// with the message, when its world cannot be made.
bool runCombination(const SweepArgs& args, const std::vector<scene::Scene>& scenes,
                    const std::vector<Combo>& combos, std::size_t c, int pass, bool tty,
                    Progress& bar, std::ofstream& csv, SweepRecord& record, std::string& error) {
  const int passes = args.repeat;
  const Combo& combo = combos[c];
  const scene::Scene& sc = scenes[combo.scene];
  scene::RunSettings run = runSettings(args, sc, combo.solver);
  if (args.setting == "iterations")
    run.iterations = static_cast<int>(combo.value);
  else
    run.tolerance = combo.value;
  const int steps = args.steps >= 0 ? args.steps : sc.settings.steps;
  const std::string label = sc.name + " " + combo.engine + " " + combo.solver + " " + args.setting +
                            "=" + (combo.applies ? fmtValue(combo.value) : "(ignored)") +
                            (passes > 1 ? " pass " + std::to_string(pass + 1) : "");
  const std::string prefix =
      args.setting + "," + fmtValue(combo.value) + "," + (combo.applies ? "1" : "0") + ",";
  bar.start(label);
  std::unique_ptr<scene::World> world;
  try {
    world = makeWorld(combo.engine, sc, run);  // the pair was checked on the smallest scene
  } catch (const std::exception& e) {
    error = label + ": " + e.what();
    return false;
  }
  SweepRecord::Kept& k = record.kept[c];
  k.prefix = prefix;
  bool matching = true;  // this pass's steps still match the first pass's
  auto lastDraw = std::chrono::steady_clock::now();
  const RunSummary sum = runWorld(*world, steps, [&](const scene::World& w, int i) {
    const scene::StepMeasures& m = w.last();
    if (pass == 0) {
      if (i == 0) k.scene = w.scene().name, k.engine = w.engine();
      k.steps.push_back(m);
    } else if (matching && i < static_cast<int>(k.steps.size()) && sameStep(k.steps[i], m)) {
      k.steps[i].solverMs = std::min(k.steps[i].solverMs, m.solverMs);
      k.steps[i].stepMs = std::min(k.steps[i].stepMs, m.stepMs);
    } else if (matching) {
      matching = false;
      record.differing.push_back(label + " from step " + std::to_string(i));
    }
    if (passes == 1) {  // streamed; with repeats the first pass's rows are written last
      csv << prefix;
      writeStepCsv(csv, w, combo.solver, i);
    }
    const auto now = std::chrono::steady_clock::now();
    if (tty && now - lastDraw > std::chrono::milliseconds(200)) {
      bar.start(label + " step " + std::to_string(i + 1) + "/" + std::to_string(steps));
      lastDraw = now;
    }
  });
  if (pass == 0) {  // the rows and the blow-ups are the first pass's
    csv.flush();
    record.rows += sum.steps;
    if (!sum.finite) record.blownUp.push_back(label + " at step " + std::to_string(sum.steps - 1));
  }
  bar.done();
  if (!tty) printRunLine(bar, combos.size(), passes, pass * combos.size() + c + 1, label, sum);
  return true;
}

// After the passes: the kept rows (with repeats), the summary line, the runs that differed or
// blew up; the exit code.
int finishSweep(const SweepArgs& args, const std::vector<Combo>& combos, bool fresh, Progress& bar,
                std::ofstream& csv, const SweepRecord& record) {
  const std::string me = "mlcp sweep: ";
  const int passes = args.repeat;
  if (passes > 1)
    for (std::size_t c = 0; c < combos.size(); ++c)
      for (std::size_t i = 0; i < record.kept[c].steps.size(); ++i) {
        csv << record.kept[c].prefix;
        writeStepCsv(csv, record.kept[c].scene, record.kept[c].engine, combos[c].solver,
                     static_cast<int>(i), record.kept[c].steps[i]);
      }
  csv.flush();
  bar.finish();
  std::cout << (fresh ? "wrote " : "appended to ") << args.csv << ": " << combos.size() << " runs"
            << (passes > 1 ? " x " + std::to_string(passes) + " passes" : "") << ", " << record.rows
            << " rows in " << std::fixed << std::setprecision(1) << bar.seconds() << " s\n";
  if (!record.differing.empty()) {
    std::cerr << me << record.differing.size()
              << " repeated run(s) differed from their first pass (times not used from there):\n";
    for (const std::string& d : record.differing) std::cerr << "  " << d << "\n";
  }
  if (!record.blownUp.empty()) {
    std::cerr << me << record.blownUp.size() << " run(s) blew up (rows kept up to the blow-up):\n";
    for (const std::string& b : record.blownUp) std::cerr << "  " << b << "\n";
    return kNotSolved;
  }
  return kSolved;
}

// The stages: read the inputs, find the runnable pairs, list the combinations, open the CSV,
// run every combination in each pass, finish.
int runSweep(const SweepArgs& args) {
  const std::string me = "mlcp sweep: ";
  std::vector<double> values;
  std::vector<std::string> engines;
  std::vector<scene::Scene> scenes;
  std::vector<std::pair<std::string, std::string>> runnable;  // (engine, solver)
  std::string skipped, error;
  auto invalid = [&] {
    std::cerr << me << error << "\n";
    return kInvalidInput;
  };
  if (!readInputs(args, values, engines, scenes, error)) return invalid();
  if (!runnablePairs(args, engines, scenes, runnable, skipped, error)) return invalid();
  if (!skipped.empty())
    std::cerr << me << "skipped (not a solver of that engine): " << skipped << "\n";
  const std::vector<Combo> combos = combinations(args, scenes.size(), engines, runnable, values);
  std::ofstream csv;
  bool fresh = true;
  if (!openCsv(args, std::string(kSweepColumns) + kStepCsvHeader, csv, fresh, error))
    return invalid();

  const bool tty = isatty(fileno(stderr)) != 0;
  // On a terminal the bar redraws in place; elsewhere (CI, logs) one line per run.
  Progress bar("sweep", static_cast<int>(combos.size()) * args.repeat, !tty);
  SweepRecord record;
  record.kept.resize(combos.size());
  for (int pass = 0; pass < args.repeat; ++pass)
    for (std::size_t c = 0; c < combos.size(); ++c)
      if (!runCombination(args, scenes, combos, c, pass, tty, bar, csv, record, error))
        return invalid();
  return finishSweep(args, combos, fresh, bar, csv, record);
}

}  // namespace

Runner addSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Run scenes x engines x solvers x values of one solver setting and write one tidy CSV, "
      "one row per step: " +
          std::string(kSweepColumns) + kStepCsvHeader +
          " (setting_applies 0: a stock solver that ignores the setting, run once at the first "
          "value). Combinations that cannot exist (bullet-* in ODE, ode-* in Bullet) are "
          "skipped. Progress on stderr. Exit 0: every run finished; 1: some run blew up "
          "(its rows up to then are kept); 2: bad scene file, engine, solver, setting or "
          "value.");
  cmd->add_option("scenes", args->scenes, "scene files (.json, mlcp-scene/1)")->required();
  cmd->add_option("--engines", args->engines, "engines (default: all built: " + engineNames() + ")")
      ->delimiter(',');
  cmd->add_option("--solvers", args->solvers,
                  "core solver names and stock ones (bullet-si, bullet-nncg, bullet-mlcp-pgs, "
                  "bullet-mlcp-dantzig, bullet-mlcp-lemke, ode-world, ode-quick)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--setting", args->setting,
                  "the swept setting: iterations (sweeps / outer iterations per solve) or "
                  "tolerance (scaled residual)")
      ->check(CLI::IsMember({"iterations", "tolerance"}))
      ->capture_default_str();
  cmd->add_option("--values", args->values, "values of the setting, e.g. 5,10,20,50 or 1e-3,1e-6")
      ->delimiter(',')
      ->required();
  cmd->add_option("--steps", args->steps, "steps per run (default: each scene's settings.steps)")
      ->check(nonNegativeNumber());
  cmd->add_flag("--no-warm-start", args->noWarmStart, "start every solve from zero");
  cmd->add_option("--fallback", args->fallback,
                  "core solver run when an answer is rejected, or none (default pgs)");
  cmd->add_option("--csv", args->csv, "CSV file to write")->required();
  cmd->add_option("--repeat", args->repeat,
                  "run every combination this many times (in passes over all of them) and keep "
                  "each step's minimum solver and step time (default 1)")
      ->check(CLI::Range(1, 100));
  cmd->add_flag("--append", args->append,
                "add the rows to an existing sweep CSV (e.g. a second sweep with other solvers "
                "or values) instead of replacing it");
  return [args] { return runSweep(*args); };
}

}  // namespace mlcp::cli
