// dWorldStep and dWorldQuickStep for ODE's own demos, defined in the demo's executable so they
// take the demo's calls before Debian's libode does (link-time interposition; the originals are
// reached with dlsym(RTLD_NEXT, ...)).
//
// ODE_DEMO_SOLVER (default "auto") names the solver: "stock" keeps the function the demo called
// (ODE's own dWorldStep or dWorldQuickStep); any other name steps through mlcp::ode::Stepper with
// that solver (one stepper per world, default settings), whichever function the demo called.
// Each call is timed; after each call the world's bodies are read (ODE's internal body list) for
// NaN and the largest linear speed, and the stepper's StepStats for islands not converged, fallen
// back or rejected. odeDemoShimFinish writes one JSON record to ODE_DEMO_OUT (if set).
#include "step_shim.hpp"

#include <dlfcn.h>
#include <ode/ode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mlcp/ode/stepper.hpp"
#include "objects.h"  // ODE's internal dxWorld / dxBody (the body list), from the source package

static_assert(sizeof(dReal) == 8, "the demos run against Debian's double-precision libode");

namespace {
using StepFn = int (*)(dWorldID, dReal);

struct Record {
  std::string solver;
  std::vector<double> stepSeconds;
  std::set<std::string> called;  // which of ODE's step functions the demo called
  int steps = 0, nanSteps = 0, firstNanFrame = -1;
  int stepsUnconverged = 0, stepsFallback = 0, stepsRejected = 0;
  int framesUnconverged = 0, lastUnconvergedFrame = -1;
  int islands = 0, islandsUnconverged = 0, maxRows = 0;
  long rows = 0;
  double maxSpeed = 0, worstResidual = 0;
  std::map<std::string, int> choices;
  std::string worstMessage;
  int frame = 0;
};

Record& record() {
  static Record r;
  return r;
}

const std::string& solverName() {
  static const std::string name = [] {
    const char* env = std::getenv("ODE_DEMO_SOLVER");
    return std::string(env && *env ? env : "auto");
  }();
  return name;
}

mlcp::ode::Stepper& stepperFor(dWorldID world) {
  static std::map<dWorldID, std::unique_ptr<mlcp::ode::Stepper>> steppers;
  auto& s = steppers[world];
  if (!s) {
    try {
      s = std::make_unique<mlcp::ode::Stepper>(solverName());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ODE_DEMO_SOLVER: %s\n", e.what());
      std::exit(2);
    }
  }
  return *s;
}

StepFn original(const char* name) {
  void* f = dlsym(RTLD_NEXT, name);
  if (!f) {
    std::fprintf(stderr, "step shim: dlsym(RTLD_NEXT, %s) failed: %s\n", name, dlerror());
    std::exit(2);
  }
  return reinterpret_cast<StepFn>(f);
}

void readBodies(dWorldID world, Record& r) {
  bool nan = false;
  for (dxBody* b = world->firstbody; b; b = static_cast<dxBody*>(b->next)) {
    double v2 = 0;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(b->posr.pos[k]) || !std::isfinite(b->lvel[k]) ||
          !std::isfinite(b->avel[k]))
        nan = true;
      v2 += b->lvel[k] * b->lvel[k];
    }
    if (std::isfinite(v2)) r.maxSpeed = std::max(r.maxSpeed, std::sqrt(v2));
  }
  if (nan) {
    ++r.nanSteps;
    if (r.firstNanFrame < 0) r.firstNanFrame = r.frame;
  }
}

void readStats(const mlcp::ode::StepStats& stats, Record& r) {
  bool unconverged = false, fallback = false, rejected = false;
  for (const auto& island : stats.islands) {
    if (island.rows == 0) continue;
    ++r.islands;
    r.rows += island.rows;
    r.maxRows = std::max(r.maxRows, island.rows);
    ++r.choices[island.choice];
    if (island.status != mlcp::Status::Converged) {
      unconverged = true;
      ++r.islandsUnconverged;
    }
    fallback |= island.fellBack;
    rejected |= !island.accepted;
    if (std::isfinite(island.residual) && island.residual > r.worstResidual) {
      r.worstResidual = island.residual;
      r.worstMessage = island.message;
    }
  }
  r.stepsUnconverged += unconverged;
  if (unconverged && r.lastUnconvergedFrame != r.frame) {
    ++r.framesUnconverged;
    r.lastUnconvergedFrame = r.frame;
  }
  r.stepsFallback += fallback;
  r.stepsRejected += rejected;
}

int step(const char* function, dWorldID world, dReal h) {
  static const StepFn stockStep = original("dWorldStep");
  static const StepFn stockQuick = original("dWorldQuickStep");
  Record& r = record();
  r.called.insert(function);
  const bool stock = solverName() == "stock";
  const bool quick = std::string(function) == "dWorldQuickStep";
  mlcp::ode::Stepper* stepper = stock ? nullptr : &stepperFor(world);
  const auto t0 = std::chrono::steady_clock::now();
  int ok = stock ? (quick ? stockQuick : stockStep)(world, h) : stepper->step(world, h);
  const auto t1 = std::chrono::steady_clock::now();
  r.stepSeconds.push_back(std::chrono::duration<double>(t1 - t0).count());
  if (stepper) readStats(stepper->lastStep(), r);
  readBodies(world, r);
  ++r.steps;
  return ok;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::string jsonEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out;
}
}  // namespace

extern "C" int dWorldStep(dWorldID world, dReal h) { return step("dWorldStep", world, h); }
extern "C" int dWorldQuickStep(dWorldID world, dReal h) {
  return step("dWorldQuickStep", world, h);
}

void odeDemoShimFrame(int frame) { record().frame = frame; }

void odeDemoShimFinish(int frames) {
  Record& r = record();
  double total = 0;
  for (double s : r.stepSeconds) total += s;
  std::string called, choices;
  for (const auto& f : r.called) called += (called.empty() ? "" : " ") + f;
  for (const auto& [name, n] : r.choices)
    choices += (choices.empty() ? "" : " ") + name + ":" + std::to_string(n);
  std::printf(
      "solver %s: %d frames, %d steps (%s), median step %.4f ms, NaN steps %d, max speed "
      "%.4g, unconverged steps %d\n",
      solverName().c_str(), frames, r.steps, called.c_str(), 1e3 * median(r.stepSeconds),
      r.nanSteps, r.maxSpeed, r.stepsUnconverged);
  const char* out = std::getenv("ODE_DEMO_OUT");
  if (!out) return;
  FILE* f = std::fopen(out, "w");
  if (!f) {
    std::fprintf(stderr, "ODE_DEMO_OUT: cannot write %s\n", out);
    return;
  }
  std::fprintf(f,
               "{\"solver\":\"%s\",\"frames\":%d,\"steps\":%d,\"called\":\"%s\","
               "\"median_step_ms\":%.6g,\"total_step_ms\":%.6g,\"nan_steps\":%d,"
               "\"first_nan_frame\":%d,\"max_speed\":%.6g,\"steps_unconverged\":%d,"
               "\"frames_unconverged\":%d,"
               "\"steps_fallback\":%d,\"steps_rejected\":%d,\"islands\":%d,"
               "\"islands_unconverged\":%d,\"rows\":%ld,\"max_rows\":%d,"
               "\"worst_residual\":%.3g,\"choices\":\"%s\",\"worst_message\":\"%s\"}\n",
               solverName().c_str(), frames, r.steps, called.c_str(), 1e3 * median(r.stepSeconds),
               1e3 * total, r.nanSteps, r.firstNanFrame, r.maxSpeed, r.stepsUnconverged,
               r.framesUnconverged, r.stepsFallback, r.stepsRejected, r.islands,
               r.islandsUnconverged, r.rows, r.maxRows, r.worstResidual, choices.c_str(),
               jsonEscape(r.worstMessage).c_str());
  std::fclose(f);
}
