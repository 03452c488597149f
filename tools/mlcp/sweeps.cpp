#include "sweeps.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "mlcp/input_limits.hpp"

namespace mlcp::cli {

const char* const kSweepCsvColumns = "setting,value,setting_applies,";

namespace {

// Whether two runs' measures of one step describe the same step (all but the times).
bool sameStep(const scene::StepMeasures& a, const scene::StepMeasures& b) {
  auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  return same(a.residual, b.residual) && a.iterations == b.iterations && a.status == b.status &&
         a.fallbacks == b.fallbacks && a.choice == b.choice && a.contacts == b.contacts &&
         same(a.maxPenetration, b.maxPenetration) && same(a.energy, b.energy);
}

// Numbers (their bytes as in memory: parent and child are the same program) and strings
// (length, then the characters) appended to one string, and read back in the same order.
struct ByteWriter {
  std::string bytes;
  template <typename T>
  ByteWriter& number(T v) {
    static_assert(std::is_arithmetic_v<T>);
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  ByteWriter& text(const std::string& s) {
    number(s.size());
    bytes += s;
    return *this;
  }
};

struct ByteReader {
  const std::string& bytes;
  std::size_t at = 0;
  bool ok = true;  // false once a read ran past the end
  template <typename T>
  ByteReader& number(T& v) {
    static_assert(std::is_arithmetic_v<T>);
    ok = ok && bytes.size() - at >= sizeof v;
    if (ok) std::memcpy(&v, bytes.data() + at, sizeof v), at += sizeof v;
    return *this;
  }
  ByteReader& text(std::string& s) {
    std::size_t n = 0;
    number(n);
    ok = ok && bytes.size() - at >= n;
    if (ok) s.assign(bytes, at, n), at += n;
    return *this;
  }
};

bool isStock(const std::string& solver) {
  return solver.rfind("bullet-", 0) == 0 || solver.rfind("ode-", 0) == 0;
}

bool settingApplies(const std::string& solver, const std::string& setting) {
  if (!isStock(solver)) return true;
  return setting == "iterations" && solver != "ode-world";
}

// The values as numbers: iterations are whole and >= 1, tolerances > 0.
std::vector<double> parseValues(const SweepSpec& spec) {
  std::vector<double> out;
  for (const std::string& text : spec.values) {
    if (text.empty())
      throw std::invalid_argument("--values: an empty value (give e.g. --values 5,10,20)");
    const double v = io::parseNumber(text);
    const bool whole = std::isfinite(v) && v == std::floor(v) && v >= 1 && v <= 1e9;
    if (!std::isfinite(v) || (spec.setting == "iterations" ? !whole : v <= 0))
      throw std::invalid_argument("--values: '" + io::capped(text, 24) + "' is not " +
                                  (spec.setting == "iterations"
                                       ? "a whole number of iterations >= 1"
                                       : "a positive tolerance"));
    out.push_back(v);
  }
  if (out.empty())
    throw std::invalid_argument("--values: give at least one value (e.g. --values 5,10,20)");
  return out;
}

std::string fmtValue(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

// Which engine takes which solver, asked of the engines themselves on the smallest scene: the
// (engine, solver) pairs that exist. Throws when a solver exists in no engine.
std::vector<std::pair<std::string, std::string>> runnablePairs(
    const SweepSpec& spec, const std::vector<std::string>& engines,
    const std::vector<scene::Scene>& scenes, std::string& skipped) {
  const scene::Scene& probe = *std::min_element(scenes.begin(), scenes.end(),
                                                [](const scene::Scene& a, const scene::Scene& b) {
                                                  return a.bodies.size() < b.bodies.size();
                                                });
  std::vector<std::pair<std::string, std::string>> runnable;
  for (const std::string& solver : spec.solvers) {
    std::string lastError;
    bool anywhere = false;
    for (const std::string& engine : engines) {
      try {
        makeWorld(engine, probe,
                  comboSettings(spec, probe, {"", engine, solver, spec.setting, 0, true}));
        runnable.emplace_back(engine, solver);
        anywhere = true;
      } catch (const std::invalid_argument& e) {
        lastError = e.what();
        skipped += (skipped.empty() ? "" : ", ") + solver + " in " + engine;
      }
    }
    if (!anywhere) throw std::invalid_argument(lastError);
  }
  return runnable;
}

}  // namespace

SweepPlan planSweep(const SweepSpec& spec) {
  if (spec.setting != "iterations" && spec.setting != "tolerance")
    throw std::invalid_argument("--setting: '" + io::capped(spec.setting, 24) +
                                "' is not iterations or tolerance");
  const std::vector<double> values = parseValues(spec);
  const std::vector<std::string> known = engineList();
  const std::vector<std::string> engines = spec.engines.empty() ? defaultEngines() : spec.engines;
  for (const std::string& e : engines)
    if (std::find(known.begin(), known.end(), e) == known.end())
      throw std::invalid_argument("unknown engine '" + e + "' (known: " + engineNames() + ")");
  if (spec.solvers.empty()) throw std::invalid_argument("--solvers: give at least one solver");
  if (spec.scenes.empty()) throw std::invalid_argument("give at least one scene file");
  SweepPlan plan;
  for (const std::string& path : spec.scenes) {
    try {
      plan.scenes.push_back(scene::loadScene(path));
    } catch (const scene::FormatError& e) {
      throw std::invalid_argument(e.what());
    }
  }
  const auto runnable = runnablePairs(spec, engines, plan.scenes, plan.skipped);
  for (const std::string& path : spec.scenes)
    for (const std::string& engine : engines)
      for (const auto& [e, solver] : runnable) {
        if (e != engine) continue;
        const bool applies = settingApplies(solver, spec.setting);
        for (std::size_t k = 0; k < (applies ? values.size() : 1); ++k)
          plan.combos.push_back({path, engine, solver, spec.setting, values[k], applies});
      }
  return plan;
}

scene::RunSettings comboSettings(const SweepSpec& spec, const scene::Scene& s,
                                 const SweepCombo& combo) {
  scene::RunSettings run = scene::RunSettings::fromScene(s);
  run.solver = combo.solver;
  run.warmStart = spec.warmStart;
  run.fallback = spec.fallback == "none" ? "" : spec.fallback;
  if (combo.value > 0) {  // 0: a probe of the solver name only
    if (combo.setting == "iterations")
      run.iterations = static_cast<int>(combo.value);
    else
      run.tolerance = combo.value;
  }
  return run;
}

std::string comboLabel(const scene::Scene& s, const SweepCombo& combo) {
  return s.name + " " + combo.engine + " " + combo.solver + " " + combo.setting + "=" +
         (combo.applies ? fmtValue(combo.value) : "(ignored)");
}

std::string comboCsvPrefix(const SweepCombo& combo) {
  return combo.setting + "," + fmtValue(combo.value) + "," + (combo.applies ? "1" : "0") + ",";
}

void runSweepPass(const SweepSpec& spec, const scene::Scene& s, const SweepCombo& combo,
                  SweepRun& run, const std::function<void(const scene::World&, int)>& onStep) {
  std::unique_ptr<scene::World> world = makeWorld(combo.engine, s, comboSettings(spec, s, combo));
  const int steps = spec.steps >= 0 ? spec.steps : s.settings.steps;
  SweepRun pass;
  pass.passes = 1;
  pass.first = runWorld(*world, steps, [&](const scene::World& w, int i) {
    if (i == 0) pass.scene = w.scene().name, pass.engine = w.engine();
    pass.steps.push_back(w.last());
    if (onStep) onStep(w, i);
  });
  addSweepPass(run, std::move(pass));
}

void addSweepPass(SweepRun& run, SweepRun&& pass) {
  const int index = run.passes++;
  if (index == 0) {
    run.scene = std::move(pass.scene);
    run.engine = std::move(pass.engine);
    run.steps = std::move(pass.steps);
    run.first = pass.first;
    return;
  }
  for (std::size_t i = 0; i < pass.steps.size(); ++i) {
    const scene::StepMeasures& m = pass.steps[i];
    if (i >= run.steps.size() || !sameStep(run.steps[i], m)) {
      run.differing.emplace_back(index, static_cast<int>(i));
      return;
    }
    run.steps[i].solverMs = std::min(run.steps[i].solverMs, m.solverMs);
    run.steps[i].stepMs = std::min(run.steps[i].stepMs, m.stepMs);
  }
}

std::string encodeSweepRun(const SweepRun& run) {
  ByteWriter out;
  out.text(run.scene).text(run.engine);
  const RunSummary& f = run.first;
  out.number(f.steps).number(f.meanSolverMs).number(f.meanStepMs).number(f.worstResidual);
  out.number(f.maxPenetration).number(f.maxJointError).number(f.maxSpeed).number(f.fallbacks);
  out.number(f.unconverged).number(f.failedSteps).number(f.finite);
  out.number(run.steps.size());
  for (const scene::StepMeasures& m : run.steps) {
    out.number(m.solverMs).number(m.stepMs).number(m.residual).number(m.iterations);
    out.text(m.status).number(m.fallbacks).number(m.unsolved).text(m.choice).number(m.contacts);
    out.number(m.maxPenetration).number(m.jointError).number(m.energy).number(m.momentum);
    out.number(m.maxSpeed);
  }
  return out.bytes;
}

bool decodeSweepRun(const std::string& bytes, SweepRun& run) {
  ByteReader in{bytes};
  run = SweepRun();
  run.passes = 1;
  in.text(run.scene).text(run.engine);
  RunSummary& f = run.first;
  in.number(f.steps).number(f.meanSolverMs).number(f.meanStepMs).number(f.worstResidual);
  in.number(f.maxPenetration).number(f.maxJointError).number(f.maxSpeed).number(f.fallbacks);
  in.number(f.unconverged).number(f.failedSteps).number(f.finite);
  std::size_t n = 0;
  in.number(n);
  for (std::size_t i = 0; i < n && in.ok; ++i) {
    scene::StepMeasures& m = run.steps.emplace_back();
    in.number(m.solverMs).number(m.stepMs).number(m.residual).number(m.iterations);
    in.text(m.status).number(m.fallbacks).number(m.unsolved).text(m.choice).number(m.contacts);
    in.number(m.maxPenetration).number(m.jointError).number(m.energy).number(m.momentum);
    in.number(m.maxSpeed);
  }
  return in.ok && in.at == bytes.size();
}

}  // namespace mlcp::cli
