// mlcp sweep SCENES... --engines E --solvers S --setting iterations|tolerance --values V,...:
// every scene x engine x solver x value of one solver setting, stepped through the shared run
// loop (scene_runs.hpp) into one tidy CSV, one row per step. tools/chart.py reads it.
//
// What is swept and how (skipped pairs, stock solvers run once, repeats): sweeps.hpp.
// --repeat N runs every combination N times, in N passes over all of them (so that a slow
// spell of a shared machine hits different combinations in different passes); the rows are
// written after the last pass. A run that blows up (non-finite body state) keeps its rows up to
// and including the step that blew up; the sweep goes on and exits 1 at the end, listing it.
//
// --jobs N runs the passes of the combinations in N child processes at once (forked_jobs.hpp;
// 0: one per core), each pass in a process of its own. The parent takes their answers in the
// serial order (pass by pass, combination by combination), so the CSV, the messages and the exit
// code are the serial sweep's; only the times differ (N runs share the machine). A run that
// throws ends the sweep with the message the serial sweep prints for the first such run in that
// order; a child that crashes is named (scene, engine, solver, value) and the sweep goes on
// without its rows and exits 1.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "forked_jobs.hpp"
#include "mlcp/input_limits.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "progress.hpp"
#include "scene_runs.hpp"
#include "sweeps.hpp"

namespace mlcp::cli {

namespace {

struct SweepArgs {
  SweepSpec spec;
  std::string csv;
  bool append = false;
  int repeat = 1;
  int jobs = 1;  // worker processes; 1: all runs in this process, 0: one per core
};

std::string minutes(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%d:%02d", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
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

// What the passes keep: each combination's run (sweeps.hpp), the rows written.
struct SweepRecord {
  std::vector<SweepRun> runs;
  std::size_t rows = 0;
  // --jobs: the passes whose child process crashed ("LABEL pass 2: killed by signal 11 ..."),
  // and per combination whether its first pass did (its later passes are then not used).
  std::vector<std::string> crashed;
  std::vector<bool> lost;
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

const scene::Scene& sceneOf(const SweepArgs& args, const SweepPlan& plan, const SweepCombo& c) {
  const auto& files = args.spec.scenes;
  return plan.scenes[std::find(files.begin(), files.end(), c.scene) - files.begin()];
}

// One pass of combination c: its world stepped, its rows streamed (one pass) or kept.
void runCombination(const SweepArgs& args, const SweepPlan& plan, std::size_t c, int pass, bool tty,
                    Progress& bar, std::ofstream& csv, SweepRecord& record) {
  const int passes = args.repeat;
  const SweepCombo& combo = plan.combos[c];
  const scene::Scene& sc = sceneOf(args, plan, combo);
  const int steps = args.spec.steps >= 0 ? args.spec.steps : sc.settings.steps;
  const std::string label =
      comboLabel(sc, combo) + (passes > 1 ? " pass " + std::to_string(pass + 1) : "");
  const std::string prefix = comboCsvPrefix(combo);
  bar.start(label);
  SweepRun& run = record.runs[c];
  auto lastDraw = std::chrono::steady_clock::now();
  runSweepPass(args.spec, sc, combo, run, [&](const scene::World& w, int i) {
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
  if (pass == 0) {
    csv.flush();
    record.rows += run.first.steps;
  }
  bar.done();
  if (!tty)
    printRunLine(bar, plan.combos.size(), passes, pass * plan.combos.size() + c + 1, label,
                 run.first);
}

// --jobs: pass p of combination c is unit p * combos + c, so the units' order is the serial one.
std::size_t comboOf(const SweepPlan& plan, std::size_t unit) { return unit % plan.combos.size(); }

std::string unitLabel(const SweepArgs& args, const SweepPlan& plan, std::size_t unit) {
  const SweepCombo& combo = plan.combos[comboOf(plan, unit)];
  const std::size_t pass = unit / plan.combos.size();
  return comboLabel(sceneOf(args, plan, combo), combo) +
         (args.repeat > 1 ? " pass " + std::to_string(pass + 1) : "");
}

// In a child process: one pass of one combination as bytes for the parent: 'R' and the run
// (encodeSweepRun), or, when it threw std::invalid_argument, 'E', the length of the steps taken
// until then as a run, ':', that run and the message (the serial sweep has streamed those rows).
std::string runUnit(const SweepArgs& args, const SweepPlan& plan, std::size_t unit) {
  const SweepCombo& combo = plan.combos[comboOf(plan, unit)];
  SweepRun taken;
  try {
    SweepRun run;
    runSweepPass(args.spec, sceneOf(args, plan, combo), combo, run,
                 [&](const scene::World& w, int i) {
                   if (i == 0) taken.scene = w.scene().name, taken.engine = w.engine();
                   taken.steps.push_back(w.last());
                 });
    return "R" + encodeSweepRun(run);
  } catch (const std::invalid_argument& e) {
    const std::string steps = encodeSweepRun(taken);
    return "E" + std::to_string(steps.size()) + ":" + steps + e.what();
  }
}

// What a child's pass came to: its run (with an error: the steps before it), the message of what
// it threw, or how the child ended.
struct UnitAnswer {
  SweepRun run;
  std::string error;
  std::string crash;
};

// An 'E' answer of runUnit: false when it is not whole.
bool readError(const std::string& bytes, UnitAnswer& a) {
  const std::size_t colon = bytes.find(':');
  if (colon == std::string::npos || colon < 2) return false;
  std::size_t size = 0;
  try {
    size = std::stoul(bytes.substr(1, colon - 1));
  } catch (const std::exception&) {
    return false;
  }
  if (size > bytes.size() - colon - 1 || !decodeSweepRun(bytes.substr(colon + 1, size), a.run))
    return false;
  a.error = bytes.substr(colon + 1 + size);
  return !a.error.empty();
}

UnitAnswer readAnswer(ForkedOutcome&& out) {
  UnitAnswer a;
  a.crash = std::move(out.crash);
  if (!a.crash.empty()) return a;
  const char tag = out.bytes.empty() ? '\0' : out.bytes[0];
  const bool whole = tag == 'E' ? readError(out.bytes, a)
                                : tag == 'R' && decodeSweepRun(out.bytes.substr(1), a.run);
  if (!whole) a = UnitAnswer{SweepRun(), "", "exited without its whole answer"};
  return a;
}

// A child ended: the bar advanced; off a terminal the serial sweep's line for the run; a crash
// named at once (and again at the end).
void reportUnit(const SweepArgs& args, const SweepPlan& plan, std::size_t unit, const UnitAnswer& a,
                bool tty, Progress& bar, std::size_t finished) {
  bar.done();
  const std::string label = unitLabel(args, plan, unit);
  if (!a.crash.empty())
    std::cerr << (tty ? "\r\033[K" : "") << "mlcp sweep: " << label << " crashed (" << a.crash
              << ")\n";
  else if (!tty && a.error.empty())
    printRunLine(bar, plan.combos.size(), args.repeat, finished, label, a.run.first);
}

// Adds a unit's answer to the record as the serial sweep does (rows streamed when there are no
// repeats). false, with its message in `error`, for a run that threw.
bool takeUnit(const SweepArgs& args, const SweepPlan& plan, std::size_t unit, UnitAnswer& a,
              std::ofstream& csv, SweepRecord& record, std::string& error) {
  const std::size_t c = comboOf(plan, unit);
  const bool first = unit < plan.combos.size();
  if (!a.crash.empty()) {
    record.crashed.push_back(unitLabel(args, plan, unit) + ": " + a.crash);
    if (first)
      record.lost[c] = true;
    else
      ++record.runs[c].passes;  // the passes after it keep their numbers in `differing`
    return true;
  }
  if (record.lost[c] && a.error.empty()) return true;
  const SweepCombo& combo = plan.combos[c];
  if (first && args.repeat == 1) {
    const std::string prefix = comboCsvPrefix(combo);
    for (std::size_t i = 0; i < a.run.steps.size(); ++i) {
      csv << prefix;
      writeStepCsv(csv, a.run.scene, a.run.engine, combo.solver, static_cast<int>(i),
                   a.run.steps[i]);
    }
  }
  if (!a.error.empty()) {
    error = a.error;
    return false;
  }
  if (first) record.rows += a.run.first.steps;
  addSweepPass(record.runs[c], std::move(a.run));
  return true;
}

// Every pass of every combination in child processes, `jobs` at a time, their answers taken in
// the serial order. kSolved, or kInvalidInput after printing the message of the first run (in
// that order) that threw.
int runJobs(const SweepArgs& args, const SweepPlan& plan, int jobs, bool tty, Progress& bar,
            std::ofstream& csv, SweepRecord& record) {
  const std::size_t units = plan.combos.size() * static_cast<std::size_t>(args.repeat);
  std::vector<std::optional<UnitAnswer>> answers(units);
  std::size_t taken = 0, finished = 0;
  bool threw = false;  // some run threw: start no more
  std::string error;
  csv.flush();
  runForked(
      units, jobs, [&](std::size_t u) { return runUnit(args, plan, u); },
      [&](std::size_t u) { bar.start(unitLabel(args, plan, u)); },
      [&](std::size_t u, ForkedOutcome&& out) {
        answers[u] = readAnswer(std::move(out));
        reportUnit(args, plan, u, *answers[u], tty, bar, ++finished);
        threw = threw || !answers[u]->error.empty();
        while (error.empty() && taken < units && answers[taken] &&
               takeUnit(args, plan, taken, *answers[taken], csv, record, error))
          answers[taken++].reset();
        return !threw;
      });
  if (error.empty()) return kSolved;
  std::cerr << "mlcp sweep: " << error << "\n";
  return kInvalidInput;
}

// After the passes: the kept rows (with repeats), the summary line, the runs that differed or
// blew up; the exit code.
int finishSweep(const SweepArgs& args, const SweepPlan& plan, bool fresh, Progress& bar,
                std::ofstream& csv, const SweepRecord& record) {
  const std::string me = "mlcp sweep: ";
  const int passes = args.repeat;
  const std::vector<SweepCombo>& combos = plan.combos;
  if (passes > 1)
    for (std::size_t c = 0; c < combos.size(); ++c)
      for (std::size_t i = 0; i < record.runs[c].steps.size(); ++i) {
        csv << comboCsvPrefix(combos[c]);
        writeStepCsv(csv, record.runs[c].scene, record.runs[c].engine, combos[c].solver,
                     static_cast<int>(i), record.runs[c].steps[i]);
      }
  csv.flush();
  bar.finish();
  std::cout << (fresh ? "wrote " : "appended to ") << args.csv << ": " << combos.size() << " runs"
            << (passes > 1 ? " x " + std::to_string(passes) + " passes" : "") << ", " << record.rows
            << " rows in " << std::fixed << std::setprecision(1) << bar.seconds() << " s\n";
  std::vector<std::string> differing, blownUp;
  for (std::size_t c = 0; c < combos.size(); ++c) {
    const SweepRun& run = record.runs[c];
    const std::string label = comboLabel(sceneOf(args, plan, combos[c]), combos[c]);
    for (const auto& [pass, step] : run.differing)
      differing.push_back(label + " pass " + std::to_string(pass + 1) + " from step " +
                          std::to_string(step));
    if (!run.first.finite)
      blownUp.push_back(label + " at step " + std::to_string(run.first.steps - 1));
  }
  if (!differing.empty()) {
    std::cerr << me << differing.size()
              << " repeated run(s) differed from their first pass (times not used from there):\n";
    for (const std::string& d : differing) std::cerr << "  " << d << "\n";
  }
  if (!record.crashed.empty()) {
    std::cerr << me << record.crashed.size()
              << " run(s) crashed (no rows for them; later passes of a crashed first pass not "
                 "used):\n";
    for (const std::string& c : record.crashed) std::cerr << "  " << c << "\n";
  }
  if (!blownUp.empty()) {
    std::cerr << me << blownUp.size() << " run(s) blew up (rows kept up to the blow-up):\n";
    for (const std::string& b : blownUp) std::cerr << "  " << b << "\n";
  }
  return blownUp.empty() && record.crashed.empty() ? kSolved : kNotSolved;
}

// The stages: plan the sweep (sweeps.hpp), open the CSV, run every combination in each pass,
// finish.
int runSweep(const SweepArgs& args) {
  const std::string me = "mlcp sweep: ";
  SweepPlan plan;
  std::string error;
  try {
    plan = planSweep(args.spec);
  } catch (const std::invalid_argument& e) {
    std::cerr << me << e.what() << "\n";
    return kInvalidInput;
  }
  if (!plan.skipped.empty())
    std::cerr << me << "skipped (not a solver of that engine): " << plan.skipped << "\n";
  std::ofstream csv;
  bool fresh = true;
  if (!openCsv(args, std::string(kSweepCsvColumns) + kStepCsvHeader, csv, fresh, error)) {
    std::cerr << me << error << "\n";
    return kInvalidInput;
  }

  const bool tty = isatty(fileno(stderr)) != 0;
  // On a terminal the bar redraws in place; elsewhere (CI, logs) one line per run.
  Progress bar("sweep", static_cast<int>(plan.combos.size()) * args.repeat, !tty);
  SweepRecord record;
  record.runs.resize(plan.combos.size());
  record.lost.resize(plan.combos.size());
  const std::size_t units = plan.combos.size() * static_cast<std::size_t>(args.repeat);
  const int jobs = static_cast<int>(std::min<std::size_t>(resolveJobs(args.jobs), units));
  try {
    if (jobs > 1) {
      const int code = runJobs(args, plan, jobs, tty, bar, csv, record);
      if (code != kSolved) return code;
    } else {
      for (int pass = 0; pass < args.repeat; ++pass)
        for (std::size_t c = 0; c < plan.combos.size(); ++c)
          runCombination(args, plan, c, pass, tty, bar, csv, record);
    }
  } catch (const std::invalid_argument& e) {  // the pairs were checked on the smallest scene
    std::cerr << me << e.what() << "\n";
    return kInvalidInput;
  } catch (const std::runtime_error& e) {  // --jobs: no worker process could be started
    std::cerr << me << e.what() << "\n";
    return kNotSolved;
  }
  return finishSweep(args, plan, fresh, bar, csv, record);
}

}  // namespace

Runner addSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Run scenes x engines x solvers x values of one solver setting and write one tidy CSV, "
      "one row per step: " +
          std::string(kSweepCsvColumns) + kStepCsvHeader +
          " (setting_applies 0: a stock solver that ignores the setting, run once at the first "
          "value). Combinations that cannot exist (bullet-* in ODE, ode-* in Bullet) are "
          "skipped. Progress on stderr. Exit 0: every run finished; 1: some run blew up "
          "(its rows up to then are kept) or, with --jobs, its worker process crashed; 2: bad "
          "scene file, engine, solver, setting or value.");
  cmd->add_option("scenes", args->spec.scenes, "scene files (.json, mlcp-scene/1)")->required();
  cmd->add_option("--engines", args->spec.engines,
                  "engines (known: " + engineNames() + "; default: " + defaultEngineNames() + ")")
      ->delimiter(',');
  cmd->add_option("--solvers", args->spec.solvers,
                  "core solver names and stock ones (bullet-si, bullet-nncg, bullet-mlcp-pgs, "
                  "bullet-mlcp-dantzig, bullet-mlcp-lemke, ode-world, ode-quick)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--setting", args->spec.setting,
                  "the swept setting: iterations (sweeps / outer iterations per solve) or "
                  "tolerance (scaled residual)")
      ->check(CLI::IsMember({"iterations", "tolerance"}))
      ->capture_default_str();
  cmd->add_option("--values", args->spec.values,
                  "values of the setting, e.g. 5,10,20,50 or 1e-3,1e-6")
      ->delimiter(',')
      ->required();
  cmd->add_option("--steps", args->spec.steps,
                  "steps per run (default: each scene's settings.steps)")
      ->check(nonNegativeNumber());
  cmd->add_flag_function(
      "--no-warm-start", [args](std::int64_t) { args->spec.warmStart = false; },
      "start every solve from zero");
  cmd->add_option("--fallback", args->spec.fallback,
                  "core solver run when an answer is rejected, or none (default pgs)");
  cmd->add_option("--csv", args->csv, "CSV file to write")->required();
  cmd->add_option("--repeat", args->repeat,
                  "run every combination this many times (in passes over all of them) and keep "
                  "each step's minimum solver and step time (default 1)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--jobs", args->jobs,
                  "runs at a time, each in a worker process of its own (0: one per core); the "
                  "CSV is the serial sweep's, rows in the same order, times aside (default 1)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--append", args->append,
                "add the rows to an existing sweep CSV (e.g. a second sweep with other solvers "
                "or values) instead of replacing it");
  return [args] { return runSweep(*args); };
}

}  // namespace mlcp::cli
