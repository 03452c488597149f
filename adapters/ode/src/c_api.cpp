#include <cmath>
#include <exception>
#include <string>

#include "mlcp/ode/stepper.h"
#include "mlcp/ode/stepper.hpp"

struct mlcp_ode_stepper {
  explicit mlcp_ode_stepper(const std::string& name, const mlcp::ode::StepperOptions& o)
      : stepper(name, o) {}
  mlcp::ode::Stepper stepper;
};

namespace {
thread_local std::string lastError;
}  // namespace

extern "C" {

mlcp_ode_stepper* mlcp_ode_stepper_create(const char* solver) {
  lastError.clear();
  if (!solver) {
    lastError = "mlcp_ode_stepper_create: solver name is NULL";
    return nullptr;
  }
  try {
    return new mlcp_ode_stepper(solver, mlcp::ode::StepperOptions{});
  } catch (const std::exception& e) {
    lastError = e.what();
    return nullptr;
  }
}

void mlcp_ode_stepper_destroy(mlcp_ode_stepper* s) { delete s; }

int mlcp_ode_stepper_set_tolerance(mlcp_ode_stepper* s, double tolerance) {
  if (!s || !(tolerance > 0) || !std::isfinite(tolerance)) {
    lastError = "mlcp_ode_stepper_set_tolerance: tolerance must be finite and > 0";
    return 0;
  }
  s->stepper.solverOptions().tolerance = tolerance;
  return 1;
}

int mlcp_ode_stepper_set_max_iterations(mlcp_ode_stepper* s, int iterations) {
  if (!s || iterations < 1) {
    lastError = "mlcp_ode_stepper_set_max_iterations: iterations must be >= 1";
    return 0;
  }
  s->stepper.solverOptions().maxIterations = iterations;
  return 1;
}

int mlcp_ode_set_time_budget(mlcp_ode_stepper* s, double seconds) {
  if (!s) {
    lastError = "mlcp_ode_set_time_budget: stepper is NULL";
    return 0;
  }
  try {
    s->stepper.setTimeBudget(seconds);
    return 1;
  } catch (const std::exception& e) {
    lastError = std::string("mlcp_ode_set_time_budget: ") + e.what();
    return 0;
  }
}

int mlcp_ode_stepper_step(mlcp_ode_stepper* s, dWorldID world, dReal stepsize) {
  if (!s || !world || !(stepsize > 0)) return 0;
  return s->stepper.step(world, stepsize) ? 1 : 0;
}

int mlcp_ode_stepper_last_rows(const mlcp_ode_stepper* s) {
  return s ? s->stepper.lastStep().rows() : 0;
}

double mlcp_ode_stepper_last_residual(const mlcp_ode_stepper* s) {
  return s ? s->stepper.lastStep().maxResidual() : 0;
}

int mlcp_ode_stepper_last_fallbacks(const mlcp_ode_stepper* s) {
  return s ? s->stepper.lastStep().fallbacks() : 0;
}

const char* mlcp_ode_last_error(void) { return lastError.c_str(); }

}  // extern "C"
