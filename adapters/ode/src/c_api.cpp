// The C interface (mlcp/ode/stepper.h): every entry point runs its body inside guarded(), so no
// exception crosses into C; failures set the thread's last error and return MLCP_ODE_ERROR.
#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

#include "mlcp/ode/stepper.h"
#include "mlcp/ode/stepper.hpp"

struct mlcp_ode_stepper {
  std::unique_ptr<mlcp::ode::Stepper> stepper;
};

namespace {

using mlcp::ode::Settings;
using mlcp::ode::Stepper;

thread_local std::string lastError;

// A rejected argument: its message becomes the last error.
struct BadArgument : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Runs body() and returns its value; any exception becomes "<function>: <what>" in the last
// error and `failed` is returned.
template <class F, class R>
R guarded(const char* function, R failed, F&& body) noexcept {
  try {
    return body();
  } catch (const std::exception& e) {
    try {
      lastError = std::string(function) + ": " + e.what();
    } catch (...) {
      lastError.clear();  // no memory for the message
    }
  } catch (...) {
    try {
      lastError = std::string(function) + ": unknown exception";
    } catch (...) {
      lastError.clear();
    }
  }
  return failed;
}

void require(bool ok, const char* what) {
  if (!ok) throw BadArgument(what);
}

Stepper& stepperOf(mlcp_ode_stepper* s) {
  require(s != nullptr && s->stepper != nullptr, "stepper is NULL");
  return *s->stepper;
}

const Stepper* stepperOrNull(const mlcp_ode_stepper* s) { return s ? s->stepper.get() : nullptr; }

mlcp::Options& optionsOf(mlcp_ode_stepper* s, int which) {
  Stepper& stepper = stepperOf(s);
  require(which == MLCP_ODE_PRIMARY || which == MLCP_ODE_FALLBACK,
          "which must be MLCP_ODE_PRIMARY or MLCP_ODE_FALLBACK");
  return which == MLCP_ODE_PRIMARY ? stepper.solverOptions() : stepper.fallbackOptions();
}

// Sets one option of the primary or fallback (live: read at the next step).
template <class F>
int setOption(const char* function, mlcp_ode_stepper* s, int which, F&& set) {
  return guarded(function, MLCP_ODE_ERROR, [&] {
    set(optionsOf(s, which));
    return MLCP_ODE_OK;
  });
}

// Changes one of the stepper's settings by building a new stepper with them (the settings are
// validated by the constructor; on failure the old stepper stays).
template <class F>
int rebuild(const char* function, mlcp_ode_stepper* s, F&& change) {
  return guarded(function, MLCP_ODE_ERROR, [&] {
    Settings settings = stepperOf(s).settings();
    change(settings);
    s->stepper = std::make_unique<Stepper>(settings);
    return MLCP_ODE_OK;
  });
}

bool finiteAtLeast(double v, double lo) { return std::isfinite(v) && v >= lo; }

}  // namespace

extern "C" {

mlcp_ode_stepper* mlcp_ode_stepper_create(const char* solver) {
  lastError.clear();
  return guarded("mlcp_ode_stepper_create", static_cast<mlcp_ode_stepper*>(nullptr), [&] {
    require(solver != nullptr, "solver name is NULL");
    auto handle = std::make_unique<mlcp_ode_stepper>();
    handle->stepper = std::make_unique<Stepper>(solver);
    return handle.release();
  });
}

void mlcp_ode_stepper_destroy(mlcp_ode_stepper* s) { delete s; }

int mlcp_ode_stepper_set_solver_tolerance(mlcp_ode_stepper* s, int which, double tolerance) {
  return setOption("mlcp_ode_stepper_set_solver_tolerance", s, which, [&](mlcp::Options& o) {
    require(std::isfinite(tolerance) && tolerance > 0, "tolerance must be finite and > 0");
    o.tolerance = tolerance;
  });
}

int mlcp_ode_stepper_set_solver_max_iterations(mlcp_ode_stepper* s, int which, int iterations) {
  return setOption("mlcp_ode_stepper_set_solver_max_iterations", s, which, [&](mlcp::Options& o) {
    require(iterations >= 1, "iterations must be >= 1");
    o.maxIterations = iterations;
  });
}

int mlcp_ode_stepper_set_solver_max_pivots(mlcp_ode_stepper* s, int which, int pivots) {
  return setOption("mlcp_ode_stepper_set_solver_max_pivots", s, which, [&](mlcp::Options& o) {
    require(pivots >= 0, "pivots must be >= 0 (0: automatic)");
    o.maxPivots = pivots;
  });
}

int mlcp_ode_stepper_set_solver_relaxation(mlcp_ode_stepper* s, int which, double omega) {
  return setOption("mlcp_ode_stepper_set_solver_relaxation", s, which, [&](mlcp::Options& o) {
    require(omega > 0 && omega < 2, "relaxation must be in (0, 2)");
    o.relaxation = omega;
  });
}

int mlcp_ode_stepper_set_solver_check_every(mlcp_ode_stepper* s, int which, int sweeps) {
  return setOption("mlcp_ode_stepper_set_solver_check_every", s, which, [&](mlcp::Options& o) {
    require(sweeps >= 1, "sweeps must be >= 1");
    o.checkEvery = sweeps;
  });
}

int mlcp_ode_stepper_set_solver_friction_bounds(mlcp_ode_stepper* s, int which, int mode) {
  return setOption("mlcp_ode_stepper_set_solver_friction_bounds", s, which, [&](mlcp::Options& o) {
    require(mode == MLCP_ODE_FRICTION_EXACT || mode == MLCP_ODE_FRICTION_FIXED_ONCE,
            "mode must be MLCP_ODE_FRICTION_EXACT or MLCP_ODE_FRICTION_FIXED_ONCE");
    o.frictionBounds = mode == MLCP_ODE_FRICTION_EXACT ? mlcp::FrictionBounds::Exact
                                                       : mlcp::FrictionBounds::FixedOnce;
  });
}

int mlcp_ode_stepper_set_solver_pivot_tolerance(mlcp_ode_stepper* s, int which, double tolerance) {
  return setOption("mlcp_ode_stepper_set_solver_pivot_tolerance", s, which, [&](mlcp::Options& o) {
    require(finiteAtLeast(tolerance, 0), "tolerance must be finite and >= 0");
    o.pivotTolerance = tolerance;
  });
}

int mlcp_ode_stepper_set_solver_time_budget(mlcp_ode_stepper* s, int which, double seconds) {
  return setOption("mlcp_ode_stepper_set_solver_time_budget", s, which, [&](mlcp::Options& o) {
    require(finiteAtLeast(seconds, 0), "seconds must be finite and >= 0 (0: none)");
    o.timeBudget = seconds;
  });
}

int mlcp_ode_stepper_set_tolerance(mlcp_ode_stepper* s, double tolerance) {
  return mlcp_ode_stepper_set_solver_tolerance(s, MLCP_ODE_PRIMARY, tolerance);
}

int mlcp_ode_stepper_set_max_iterations(mlcp_ode_stepper* s, int iterations) {
  return mlcp_ode_stepper_set_solver_max_iterations(s, MLCP_ODE_PRIMARY, iterations);
}

int mlcp_ode_stepper_set_fallback(mlcp_ode_stepper* s, const char* solver) {
  return rebuild("mlcp_ode_stepper_set_fallback", s,
                 [&](Settings& settings) { settings.fallback = solver ? solver : ""; });
}

int mlcp_ode_stepper_set_accept_residual(mlcp_ode_stepper* s, double residual) {
  return rebuild("mlcp_ode_stepper_set_accept_residual", s, [&](Settings& settings) {
    require(residual >= 0, "residual must be >= 0 (+inf accepts any finite answer)");
    settings.acceptResidual = residual;
  });
}

int mlcp_ode_stepper_set_dense_max_rows(mlcp_ode_stepper* s, int rows) {
  return rebuild("mlcp_ode_stepper_set_dense_max_rows", s, [&](Settings& settings) {
    require(rows >= 0, "rows must be >= 0");
    settings.denseAssemblyMaxRows = rows;
  });
}

int mlcp_ode_stepper_set_engine_iterations(mlcp_ode_stepper* s, int on) {
  return rebuild("mlcp_ode_stepper_set_engine_iterations", s,
                 [&](Settings& settings) { settings.engineIterations = on != 0; });
}

int mlcp_ode_stepper_set_warm_start(mlcp_ode_stepper* s, int on) {
  return rebuild("mlcp_ode_stepper_set_warm_start", s,
                 [&](Settings& settings) { settings.warmStart = on != 0; });
}

int mlcp_ode_stepper_set_contact_match_distance(mlcp_ode_stepper* s, double distance) {
  return rebuild("mlcp_ode_stepper_set_contact_match_distance", s, [&](Settings& settings) {
    require(finiteAtLeast(distance, 0), "distance must be finite and >= 0");
    settings.contactMatchDistance = distance;
  });
}

int mlcp_ode_stepper_set_friction_model(mlcp_ode_stepper* s, int model, int directions) {
  return rebuild("mlcp_ode_stepper_set_friction_model", s, [&](Settings& settings) {
    require(model == MLCP_ODE_FRICTION_MODEL_BOX || model == MLCP_ODE_FRICTION_MODEL_CONE,
            "model must be MLCP_ODE_FRICTION_MODEL_BOX or MLCP_ODE_FRICTION_MODEL_CONE");
    settings.friction = model == MLCP_ODE_FRICTION_MODEL_CONE ? mlcp::FrictionModel::Cone
                                                              : mlcp::FrictionModel::Box;
    settings.frictionDirections = directions;
  });
}

int mlcp_ode_stepper_reset_warm_start(mlcp_ode_stepper* s) {
  return guarded("mlcp_ode_stepper_reset_warm_start", MLCP_ODE_ERROR, [&] {
    stepperOf(s).resetWarmStart();
    return MLCP_ODE_OK;
  });
}

int mlcp_ode_set_time_budget(mlcp_ode_stepper* s, double seconds) {
  return guarded("mlcp_ode_set_time_budget", MLCP_ODE_ERROR, [&] {
    stepperOf(s).setTimeBudget(seconds);
    return MLCP_ODE_OK;
  });
}

int mlcp_ode_stepper_step(mlcp_ode_stepper* s, dWorldID world, dReal stepsize) {
  return guarded("mlcp_ode_stepper_step", MLCP_ODE_ERROR, [&] {
    Stepper& stepper = stepperOf(s);
    require(world != nullptr, "world is NULL");
    require(stepsize > 0, "stepsize must be > 0");
    if (stepper.step(world, stepsize)) return MLCP_ODE_OK;
    throw std::runtime_error("ODE could not allocate the step's working memory");
  });
}

int mlcp_ode_stepper_last_rows(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? st->lastStep().rows() : 0;
}

int mlcp_ode_stepper_last_islands(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? static_cast<int>(st->lastStep().islands.size()) : 0;
}

int mlcp_ode_stepper_last_fallbacks(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? st->lastStep().fallbacks() : 0;
}

int mlcp_ode_stepper_last_failures(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  if (!st) return 0;
  const auto& islands = st->lastStep().islands;
  return static_cast<int>(std::count_if(islands.begin(), islands.end(),
                                        [](const auto& i) { return i.rows > 0 && !i.accepted; }));
}

double mlcp_ode_stepper_last_residual(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? st->lastStep().maxResidual() : 0;
}

int mlcp_ode_stepper_last_iterations(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? st->lastStep().maxIterations() : 0;
}

double mlcp_ode_stepper_last_seconds(const mlcp_ode_stepper* s) {
  const Stepper* st = stepperOrNull(s);
  return st ? st->lastStep().seconds : 0;
}

const char* mlcp_ode_last_error(void) { return lastError.c_str(); }

}  // extern "C"
