// Degenerate rows through the ODE stepper: redundant ball joints (a singular A) and motors and
// limits with infinite parameters, against dWorldStep on the same world. ODE's own joints build
// these rows consistent and finite (its redundant anchors agree to round-off, an infinite stop
// adds no limit row), so these guard the stepper's answers rather than the screening.
#include <gtest/gtest.h>

#include <cstdio>

#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

// A chain of `planks` 0.5 x 1 x 0.1 planks along x, each joined to the next by two ball joints
// at the ends of their shared edge (y = +-0.5: six rows for five constrained directions, so A
// is singular), the first plank pinned to the world the same way, hanging under gravity
// (z down) after starting horizontal.
std::unique_ptr<Scene> redundantPlankChain(int planks) {
  auto s = std::make_unique<Scene>();
  for (int i = 0; i < planks; ++i) s->addBox(0.25 + 0.5 * i, 0, 5, 0.5, 1, 0.1);
  for (int i = 0; i < planks; ++i)
    for (const dReal y : {-0.5, 0.5}) {
      dJointID j = s->track(dJointCreateBall(s->world, nullptr), false);
      dJointAttach(j, s->bodies[i], i == 0 ? nullptr : s->bodies[i - 1]);
      dJointSetBallAnchor(j, 0.5 * i, y, 5);
    }
  return s;
}

TEST(OdeDegenerateRows, RedundantBallJointsAreSolvedLikeDWorldStep) {
  for (const char* name : {"auto", "dantzig"}) {
    // 14 planks: 84 rows, past RowSolver's dense limit (sparse LDL^T and dantzig).
    auto ours = redundantPlankChain(14), stock = redundantPlankChain(14);
    Settings options;
    options.options.tolerance = 1e-6;  // the scene files' tolerance
    Stepper stepper(name, options);
    int solved = 0, fellBack = 0;
    double worst = 0;
    for (int k = 0; k < 100; ++k) {
      ours->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
      stock->step([](dWorldID w, dReal h) { dWorldStep(w, h); }, 0.01);
      for (const IslandStats& st : stepper.lastStep().islands) {
        solved += st.accepted;
        fellBack += st.fellBack;
        worst = std::max(worst, st.residual);
      }
    }
    const double diff = maxAbsDiff(ours->state(), stock->state());
    std::printf(
        "[ figures ] %s: 100 islands, %d accepted, %d fell back, worst residual %.3g, "
        "state vs dWorldStep %.3g\n",
        name, solved, fellBack, worst, diff);
    EXPECT_EQ(solved, 100) << name;
    EXPECT_EQ(fellBack, 0) << name;
    EXPECT_LT(worst, 1e-6) << name;
    // The answer of a singular A is not unique (the redundant rows share the load as each
    // method decides), but the motion is: the chain swings as with dWorldStep.
    EXPECT_LT(diff, 1e-3) << name;
  }
}

// A box on a slider along z whose lower stop is -1 m and upper stop dInfinity, plus an angular
// motor with infinite maximum force holding its (locked) rotation: rows with infinite bounds,
// which stay infinite (not NaN) and the box rests at its stop as with dWorldStep.
std::unique_ptr<Scene> boxOnInfiniteStops() {
  auto s = std::make_unique<Scene>();
  dBodyID box = s->addBox(0, 0, 0, 1, 1, 1);
  dJointID slider = s->track(dJointCreateSlider(s->world, nullptr), false);
  dJointAttach(slider, box, nullptr);
  dJointSetSliderAxis(slider, 0, 0, 1);
  dJointSetSliderParam(slider, dParamLoStop, -1);
  dJointSetSliderParam(slider, dParamHiStop, dInfinity);
  dJointID motor = s->track(dJointCreateAMotor(s->world, nullptr), false);
  dJointAttach(motor, box, nullptr);
  dJointSetAMotorNumAxes(motor, 1);
  dJointSetAMotorAxis(motor, 0, 1, 0, 0, 1);
  dJointSetAMotorParam(motor, dParamFMax, dInfinity);
  dJointSetAMotorParam(motor, dParamVel, 0);
  dJointSetAMotorParam(motor, dParamLoStop, -dInfinity);
  dJointSetAMotorParam(motor, dParamHiStop, dInfinity);
  return s;
}

TEST(OdeDegenerateRows, InfiniteStopsAndForcesKeepTheBoxAtItsStopLikeDWorldStep) {
  for (const char* name : {"auto", "dantzig", "pgs"}) {
    auto ours = boxOnInfiniteStops(), stock = boxOnInfiniteStops();
    Stepper stepper(name);
    int accepted = 0;
    for (int k = 0; k < 300; ++k) {
      ours->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
      stock->step([](dWorldID w, dReal h) { dWorldStep(w, h); }, 0.01);
      for (const IslandStats& st : stepper.lastStep().islands) accepted += st.accepted;
    }
    const dReal z = dBodyGetPosition(ours->bodies[0])[2];
    const dReal zStock = dBodyGetPosition(stock->bodies[0])[2];
    std::printf("[ figures ] %s: z %.6f (dWorldStep %.6f), %d of 300 islands accepted\n", name, z,
                zStock, accepted);
    EXPECT_NEAR(zStock, -1, 0.02);
    EXPECT_NEAR(z, zStock, 1e-3) << name;
    EXPECT_EQ(accepted, 300) << name;
  }
}

}  // namespace
}  // namespace mlcp::ode::test
