// The C interface's exception paths: an exception thrown from inside ODE's step (a solver that
// throws, reached through dxProcessIslands) and from the stepper's own checks comes back as
// MLCP_ODE_ERROR with the message in mlcp_ode_last_error, and the stepper stays usable.
#include <gtest/gtest.h>

#include <string>
#include <thread>

#include "common/broken_solvers.hpp"
#include "mlcp/ode/stepper.h"
#include "ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

struct BoxOnPlane {
  Scene scene;
  BoxOnPlane() {
    scene.addPlane(0, 0, 1, 0);
    scene.addBox(0, 0, 0.099, 0.4, 0.4, 0.2);
  }
  int step(mlcp_ode_stepper* s) {
    int rc = MLCP_ODE_ERROR;
    scene.step([&](dWorldID w, dReal h) { rc = mlcp_ode_stepper_step(s, w, h); }, 0.01);
    return rc;
  }
};

TEST(OdeCApi, ExceptionFromInsideTheStepIsReportedNotThrown) {
  mlcp::test::registerBrokenSolvers();
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("test-throw");
  ASSERT_NE(s, nullptr) << mlcp_ode_last_error();
  ASSERT_EQ(mlcp_ode_stepper_set_fallback(s, ""), MLCP_ODE_OK);
  BoxOnPlane box;
  EXPECT_EQ(box.step(s), MLCP_ODE_ERROR);
  EXPECT_EQ(std::string(mlcp_ode_last_error()), "mlcp_ode_stepper_step: injected exception");
  // The world is no longer marked as being stepped: the next step fails for the same reason.
  EXPECT_EQ(box.step(s), MLCP_ODE_ERROR);
  EXPECT_EQ(std::string(mlcp_ode_last_error()), "mlcp_ode_stepper_step: injected exception");
  mlcp_ode_stepper_destroy(s);

  // The same world then steps with a working solver.
  mlcp_ode_stepper* good = mlcp_ode_stepper_create("dantzig");
  ASSERT_NE(good, nullptr);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(box.step(good), MLCP_ODE_OK) << mlcp_ode_last_error();
  EXPECT_GT(mlcp_ode_stepper_last_rows(good), 0);
  mlcp_ode_stepper_destroy(good);
}

TEST(OdeCApi, StepperChecksComeBackAsErrors) {
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("pgs");
  ASSERT_NE(s, nullptr);
  BoxOnPlane box;
  EXPECT_EQ(mlcp_ode_stepper_step(s, box.scene.world, -0.01), MLCP_ODE_ERROR);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("stepsize must be > 0"), std::string::npos);
  EXPECT_EQ(mlcp_ode_stepper_step(s, box.scene.world, 0.01), MLCP_ODE_OK);
  mlcp_ode_stepper_destroy(s);
}

TEST(OdeCApi, LastErrorIsPerThread) {
  mlcp_ode_stepper_create(nullptr);
  const std::string here = mlcp_ode_last_error();
  std::string there = "unset";
  std::thread([&] { there = mlcp_ode_last_error(); }).join();
  EXPECT_NE(here.find("mlcp_ode_stepper_create: solver name is NULL"), std::string::npos);
  EXPECT_EQ(there, "");
}

TEST(OdeCApi, SettingsChangeTheStepper) {
  // A fallback set from C is the one that runs: a failing primary falls back to it.
  mlcp::test::registerBrokenSolvers();
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("test-fail");
  ASSERT_NE(s, nullptr);
  ASSERT_EQ(mlcp_ode_stepper_set_fallback(s, ""), MLCP_ODE_OK);
  BoxOnPlane box;
  for (int k = 0; k < 3; ++k) ASSERT_EQ(box.step(s), MLCP_ODE_OK);
  EXPECT_EQ(mlcp_ode_stepper_last_fallbacks(s), 0);
  EXPECT_EQ(mlcp_ode_stepper_last_failures(s), 1);
  ASSERT_EQ(mlcp_ode_stepper_set_fallback(s, "dantzig"), MLCP_ODE_OK);
  ASSERT_EQ(box.step(s), MLCP_ODE_OK);
  EXPECT_EQ(mlcp_ode_stepper_last_fallbacks(s), 1);
  EXPECT_EQ(mlcp_ode_stepper_last_failures(s), 0);
  EXPECT_LE(mlcp_ode_stepper_last_residual(s), 1e-6);
  mlcp_ode_stepper_destroy(s);
}

}  // namespace
}  // namespace mlcp::ode::test
