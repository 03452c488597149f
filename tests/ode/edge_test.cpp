// Edge cases of the ODE stepper: no joints, disabled bodies, bilateral-only islands, bad names,
// and the C interface.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/broken_solvers.hpp"
#include "mlcp/ode/stepper.h"
#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

std::unique_ptr<Scene> freeBodies() {
  auto s = std::make_unique<Scene>();
  dBodyID a = s->addSphereBody(0, 0, 1, 0.1, 1.0);
  dBodyID b = s->addSphereBody(1, 0, 1, 0.1, 2.0);
  dBodySetAngularVel(a, 1, 2, 3);
  dBodySetLinearVel(b, 0.5, 0, 2);
  dBodySetGyroscopicMode(b, 0);
  return s;
}

TEST(OdeEdge, WorldWithoutJointsFallsLikeDWorldStep) {
  auto stock = freeBodies(), ours = freeBodies();
  Stepper stepper("dantzig");
  for (int k = 0; k < 100; ++k) {
    dWorldStep(stock->world, 0.01);
    ASSERT_TRUE(stepper.step(ours->world, 0.01));
    ASSERT_EQ(stepper.lastStep().islands.size(), 2u);
    ASSERT_EQ(stepper.lastStep().rows(), 0);
  }
  EXPECT_LE(maxAbsDiff(stock->state(), ours->state()), 1e-14);
  EXPECT_LT(ours->state()[2], 0.6) << "the body should have fallen";
}

TEST(OdeEdge, DisabledBodiesAreNotStepped) {
  auto s = freeBodies();
  dBodyDisable(s->bodies[0]);
  const std::vector<double> before = s->state();
  Stepper stepper("pgs");
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(stepper.step(s->world, 0.01));
  EXPECT_EQ(stepper.lastStep().islands.size(), 1u);
  const std::vector<double> after = s->state();
  for (int i = 0; i < 13; ++i) EXPECT_EQ(before[i], after[i]) << "disabled body, entry " << i;
  EXPECT_NE(before[13 + 2], after[13 + 2]) << "the enabled body should move";
}

TEST(OdeEdge, EachStepReportsOnlyItsOwnIslands) {
  // The statistics' entries are reused from step to step: a step with fewer islands, or an island
  // without the rows it had, reports nothing of the step before.
  auto free = freeBodies();
  Stepper stepper("dantzig");
  ASSERT_TRUE(stepper.step(free->world, 0.01));
  ASSERT_EQ(stepper.lastStep().islands.size(), 2u);
  dBodyDisable(free->bodies[0]);
  ASSERT_TRUE(stepper.step(free->world, 0.01));
  ASSERT_EQ(stepper.lastStep().islands.size(), 1u);
  EXPECT_EQ(stepper.lastStep().islands[0].bodies, 1);

  auto box = boxOnPlane();
  Stepper boxStepper("dantzig");
  box->step([&](dWorldID w, dReal h) { ASSERT_TRUE(boxStepper.step(w, h)); }, 0.01);
  ASSERT_EQ(boxStepper.lastStep().islands.size(), 1u);
  ASSERT_GT(boxStepper.lastStep().islands[0].rows, 0);
  ASSERT_TRUE(boxStepper.step(box->world, 0.01));  // no collision: no contact joints
  ASSERT_EQ(boxStepper.lastStep().islands.size(), 1u);
  const IslandStats& island = boxStepper.lastStep().islands[0];
  EXPECT_EQ(island.rows, 0);
  EXPECT_EQ(island.joints, 0);
  EXPECT_EQ(island.choice, "none");
  EXPECT_EQ(island.message, "no constraint rows");
  EXPECT_EQ(island.iterations, 0);
  EXPECT_FALSE(island.warmStarted);
}

TEST(OdeEdge, AutoDisableWorksAsWithDWorldStep) {
  auto s = boxOnPlane(0.0);
  dWorldSetAutoDisableFlag(s->world, 1);
  dWorldSetAutoDisableSteps(s->world, 10);
  dWorldSetAutoDisableTime(s->world, 0);
  dBodySetAutoDisableDefaults(s->bodies[0]);
  Stepper stepper("dantzig");
  for (int k = 0; k < 100; ++k)
    s->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
  EXPECT_FALSE(dBodyIsEnabled(s->bodies[0])) << "a resting box should fall asleep";
  EXPECT_TRUE(stepper.lastStep().islands.empty());
  EXPECT_NEAR(s->state()[2], 0.25, 1e-3);
}

TEST(OdeEdge, IslandWithOnlyBilateralJoints) {
  auto ours = pendulumChain(4, 0.3), stock = pendulumChain(4, 0.3);
  Settings options;
  options.fallback = "";
  Stepper stepper("dantzig", options), reference("ode-lcp");
  for (int k = 0; k < 100; ++k) {
    ours->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
    stock->step([&](dWorldID w, dReal h) { ASSERT_TRUE(reference.step(w, h)); }, 0.01);
    ASSERT_EQ(stepper.lastStep().islands.size(), 1u);
    const IslandStats& st = stepper.lastStep().islands[0];
    ASSERT_EQ(st.rows, 20);  // 4 hinges of 5 rows
    ASSERT_EQ(st.unbounded, st.rows);
    ASSERT_EQ(st.status, Status::Converged) << st.message;
    ASSERT_LE(st.residual, 1e-10);
  }
  EXPECT_LE(maxAbsDiff(ours->state(), stock->state()), 1e-9);
}

// auto sees a bilateral-only island (a hinge chain), solves it with one sparse LDL^T, says so,
// and follows stock ODE as closely as dantzig does.
TEST(OdeEdge, AutoPicksLdltForABilateralOnlyIsland) {
  auto ours = pendulumChain(4, 0.3), stock = pendulumChain(4, 0.3);
  Stepper stepper, reference("ode-lcp");  // the default is auto
  EXPECT_EQ(stepper.solverName(), "auto");
  for (int k = 0; k < 100; ++k) {
    ours->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
    stock->step([&](dWorldID w, dReal h) { ASSERT_TRUE(reference.step(w, h)); }, 0.01);
    ASSERT_EQ(stepper.lastStep().islands.size(), 1u);
    const IslandStats& st = stepper.lastStep().islands[0];
    ASSERT_EQ(st.choice, "ldlt") << st.message;
    ASSERT_FALSE(st.fellBack);
    ASSERT_LE(st.residual, 1e-10);
    ASSERT_EQ(stepper.lastStep().choices().toString(), "ldlt:1");
  }
  EXPECT_LE(maxAbsDiff(ours->state(), stock->state()), 1e-8);
}

// An injected NaN and a failing primary: every island falls back, the statistics count it, and
// the applied answer is the fallback's own (the trajectory equals the fallback alone).
TEST(OdeEdge, BrokenPrimariesFallBackCountedAndTheFallbackAnswers) {
  mlcp::test::registerBrokenSolvers();
  for (const char* broken : {"test-nan", "test-fail"}) {
    auto withFallback = boxStack(2), alone = boxStack(2);
    Settings options;
    options.fallback = "dantzig";
    Stepper stepper(broken, options);
    options.fallback = "";
    Stepper dantzig("dantzig", options);
    int solved = 0;
    for (int k = 0; k < 50; ++k) {
      withFallback->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
      alone->step([&](dWorldID w, dReal h) { ASSERT_TRUE(dantzig.step(w, h)); }, 0.01);
      const StepStats& st = stepper.lastStep();
      int withRows = 0;
      for (const IslandStats& is : st.islands) {
        if (is.rows == 0) continue;
        ++withRows;
        EXPECT_TRUE(is.fellBack);
        EXPECT_TRUE(is.accepted);
        EXPECT_EQ(is.choice, "dantzig");
        EXPECT_NE(is.message.find(std::string(broken) + " rejected"), std::string::npos)
            << is.message;
      }
      solved += withRows;
      EXPECT_EQ(st.fallbacks(), withRows) << broken;
      EXPECT_EQ(st.choices().count("dantzig"), withRows) << st.choices().toString();
      EXPECT_LE(st.maxResidual(), 1e-9);
    }
    EXPECT_GT(solved, 40) << "the boxes should touch";
    EXPECT_EQ(maxAbsDiff(withFallback->state(), alone->state()), 0.0) << broken;
  }
}

TEST(OdeEdge, UnknownSolverNameIsAClearError) {
  try {
    Stepper stepper("no-such-solver");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown solver 'no-such-solver'"), std::string::npos) << what;
    EXPECT_NE(what.find("dantzig"), std::string::npos) << what;
    EXPECT_NE(what.find("ode-lcp"), std::string::npos) << what;
  }
  Settings options;
  options.fallback = "nope";
  EXPECT_THROW(Stepper("pgs", options), std::invalid_argument);
  options.fallback = "ode-step";
  EXPECT_THROW(Stepper("pgs", options), std::invalid_argument);
  auto s = freeBodies();
  Stepper stepper("pgs");
  EXPECT_THROW(stepper.step(s->world, 0), std::invalid_argument);
  EXPECT_THROW(stepper.step(nullptr, 0.01), std::invalid_argument);
}

TEST(OdeEdge, CInterface) {
  EXPECT_EQ(mlcp_ode_stepper_create("bogus"), nullptr);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("unknown solver 'bogus'"), std::string::npos);
  EXPECT_EQ(mlcp_ode_stepper_create(nullptr), nullptr);

  mlcp_ode_stepper* stepper = mlcp_ode_stepper_create("dantzig");
  ASSERT_NE(stepper, nullptr);
  EXPECT_EQ(mlcp_ode_stepper_set_tolerance(stepper, -1), 0);
  EXPECT_EQ(mlcp_ode_stepper_set_tolerance(stepper, 1e-9), 1);
  EXPECT_EQ(mlcp_ode_stepper_set_max_iterations(stepper, 0), 0);
  EXPECT_EQ(mlcp_ode_stepper_set_max_iterations(stepper, 50), 1);
  auto s = boxStack(2);
  for (int k = 0; k < 50; ++k)
    s->step([&](dWorldID w, dReal h) { ASSERT_EQ(mlcp_ode_stepper_step(stepper, w, h), 1); }, 0.01);
  EXPECT_EQ(mlcp_ode_stepper_last_rows(stepper), 24);  // 2 boxes x 4 contacts x 3 rows
  EXPECT_LE(mlcp_ode_stepper_last_residual(stepper), 1e-9);
  EXPECT_EQ(mlcp_ode_stepper_last_fallbacks(stepper), 0);
  EXPECT_EQ(mlcp_ode_stepper_step(stepper, s->world, -1), 0);
  mlcp_ode_stepper_destroy(stepper);
}

TEST(OdeEdge, CTimeBudgetSetterChecksItsValueAndReachesTheRowSolver) {
  EXPECT_EQ(mlcp_ode_set_time_budget(nullptr, 0.01), 0);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("NULL"), std::string::npos);
  mlcp_ode_stepper* stepper = mlcp_ode_stepper_create("auto");
  ASSERT_NE(stepper, nullptr);
  EXPECT_EQ(mlcp_ode_set_time_budget(stepper, -1), 0);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("timeBudget must be finite and >= 0"),
            std::string::npos)
      << mlcp_ode_last_error();
  EXPECT_EQ(mlcp_ode_set_time_budget(stepper, std::nan("")), 0);
  EXPECT_EQ(mlcp_ode_set_time_budget(stepper, 0.25), 1);
  EXPECT_EQ(mlcp_ode_set_time_budget(stepper, 0), 1);  // none
  auto s = boxStack(2);
  s->step([&](dWorldID w, dReal h) { ASSERT_EQ(mlcp_ode_stepper_step(stepper, w, h), 1); }, 0.01);
  EXPECT_LE(mlcp_ode_stepper_last_residual(stepper), 1e-9);
  mlcp_ode_stepper_destroy(stepper);
  Stepper ours("auto");
  ours.setTimeBudget(0.25);
  EXPECT_EQ(ours.rowSolver()->settings().timeBudget, 0.25);
  // The "ode-..." solvers have no row solver; the value is still checked.
  Stepper stock("ode-step");
  EXPECT_THROW(stock.setTimeBudget(-1), std::invalid_argument);
  stock.setTimeBudget(0.01);
  EXPECT_EQ(stock.options().timeBudget, 0.01);
}

}  // namespace
}  // namespace mlcp::ode::test
