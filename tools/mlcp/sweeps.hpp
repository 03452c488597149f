// Sweeps as plans of independent runs, shared by `mlcp sweep` and the Python module's
// mlcp.sweep: the arguments are checked and turned into combinations (scene x engine x solver x
// value of one setting) once; each combination then runs on its own, from its scene file, in
// any order, process or machine, with the same result (the runs are deterministic; only the
// wall times differ).
//
// - A combination that cannot exist (a stock solver of the other engine: bullet-* in ODE,
//   ode-* in Bullet) is skipped and named in SweepPlan::skipped. A name no engine knows is an
//   error.
// - A stock solver that ignores the swept setting runs ONCE, at the first value, and its rows
//   say setting_applies = 0: repeating an identical run per value would only measure timer
//   noise and cost time. What the stock solvers ignore (see the engine loaders):
//     tolerance   every stock solver (bullet-*, ode-*): none has a tolerance; the value only
//                 decides whether the scene loader labels a stock MLCP step "converged"
//     iterations  ode-world (dWorldStep's pivoting has no iteration count); bullet-si/-nncg,
//                 ode-quick and bullet-mlcp-* use it (btMLCPSolver's PGS and its SI fallback)
//   Core solvers (through our adapters) take both settings and run at every value.
// - Repeats (SweepRun::add): the runs are deterministic, so the work per step is the same in
//   every pass, and each step keeps the minimum solver_ms and step_ms over the passes, the
//   estimate least disturbed by other processes. A pass whose measures of a step differ from
//   the first pass's (residual, iterations, status, choice, energy, penetration: some solver
//   depended on time) is not used from that step on.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#include "scene_runs.hpp"

namespace mlcp::cli {

// The CSV columns a sweep puts before kStepCsvHeader's.
extern const char* const kSweepCsvColumns;  // "setting,value,setting_applies,"

struct SweepSpec {
  std::vector<std::string> scenes;   // scene files
  std::vector<std::string> engines;  // empty: every engine built
  std::vector<std::string> solvers{"pgs", "dantzig", "auto", "bullet-si", "ode-quick"};
  std::string setting = "iterations";  // or "tolerance"
  std::vector<std::string> values;     // as given: whole numbers >= 1, or tolerances > 0
  int steps = -1;                      // -1: each scene's settings.steps
  bool warmStart = true;
  std::string fallback = "pgs";  // "none" or "": none
};

// One run of a sweep: self-contained (its scene is named by its file).
struct SweepCombo {
  std::string scene;  // file
  std::string engine, solver;
  std::string setting;
  double value = 0;
  bool applies = true;  // false: a stock solver that ignores the setting, run once
};

struct SweepPlan {
  std::vector<scene::Scene> scenes;  // loaded, in the order of SweepSpec::scenes
  std::vector<SweepCombo> combos;    // scenes x engines x solvers x values, in that order
  std::string skipped;               // "bullet-si in ode, ..." (not a solver of that engine)
};

// Checks the spec (setting, values, engines, solvers, scene files) and lists its combinations;
// throws std::invalid_argument with the message `mlcp sweep` prints for bad input.
SweepPlan planSweep(const SweepSpec& spec);

// The run settings of a combination over its scene's own.
scene::RunSettings comboSettings(const SweepSpec& spec, const scene::Scene& s,
                                 const SweepCombo& combo);
// "stack_10 ode pgs iterations=5" (ignored values: "iterations=(ignored)").
std::string comboLabel(const scene::Scene& s, const SweepCombo& combo);
// The combination's leading CSV fields: "iterations,5,1,".
std::string comboCsvPrefix(const SweepCombo& combo);

// What a combination's passes keep: the first pass's steps, times lowered by later passes.
struct SweepRun {
  std::string scene, engine;
  std::vector<scene::StepMeasures> steps;
  RunSummary first;  // the first pass's summary (finite: false if it blew up)
  // (pass, step): a later pass whose measures differed from that step on (times not used).
  std::vector<std::pair<int, int>> differing;
  int passes = 0;
};

// Runs one pass of `combo` in its scene `s` and adds it to `run` (addSweepPass); onStep(world,
// i) after each step. Throws std::invalid_argument if the world cannot be made.
void runSweepPass(const SweepSpec& spec, const scene::Scene& s, const SweepCombo& combo,
                  SweepRun& run, const std::function<void(const scene::World&, int)>& onStep = {});

// Adds `pass`, a run of one pass (passes == 1), to `run`: the first pass is taken whole; a later
// one lowers the times of the steps that match the first pass's, up to the first that does not
// (recorded in run.differing). Passes added in the same order give the same run wherever each
// pass ran (`mlcp sweep --jobs` runs them in child processes).
void addSweepPass(SweepRun& run, SweepRun&& pass);

// A one-pass run as bytes and back, for a child process to hand its pass to its parent: the
// numbers bit for bit. decodeSweepRun returns false when the bytes are not a whole encoding.
std::string encodeSweepRun(const SweepRun& run);
bool decodeSweepRun(const std::string& bytes, SweepRun& run);

}  // namespace mlcp::cli
