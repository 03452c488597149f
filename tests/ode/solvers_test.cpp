// Core solvers inside the ODE stepper: agreement between solvers and accuracy against stock.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

struct Scenes {
  const char* name;
  std::unique_ptr<Scene> (*make)();
};
const Scenes kScenes[] = {
    {"pendulum chain", [] { return pendulumChain(3); }},
    {"hinge with limit and motor", [] { return hingeLimitMotor(); }},
    {"box sliding", [] { return boxOnPlane(2.0); }},
    {"3-box stack", [] { return boxStack(3); }},
};

void run(Scene& scene, Stepper& stepper, int steps,
         const std::function<void(int, const IslandStats&)>& check) {
  for (int k = 0; k < steps; ++k) {
    scene.step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
    for (const IslandStats& island : stepper.lastStep().islands)
      if (island.rows > 0) check(k, island);
  }
}

// The answers are compared through what they do to the bodies. With cfm -> 0 (ODE's default
// world CFM in double precision is 1e-10) lambda itself is not unique (4 contacts hold a box
// in 3 directions), but for these monotone problems w and the body forces J^T lambda are, and
// so is the trajectory. Friction here is a fixed box (no findex): the coupled cone is not
// monotone, and pgs need not reach 1e-10 on it.
std::unique_ptr<Scene> boxFriction(std::unique_ptr<Scene> s) {
  s->surface.mode = 0;
  return s;
}
const Scenes kMonotoneScenes[] = {
    {"pendulum chain", [] { return pendulumChain(3); }},
    {"hinge with limit and motor", [] { return hingeLimitMotor(); }},
    {"box sliding, box friction", [] { return boxFriction(boxOnPlane(2.0)); }},
    {"3-box stack, box friction", [] { return boxFriction(boxStack(3)); }},
};

TEST(OdeSolvers, PgsAtTightToleranceReachesDantzigsAnswer) {
  Settings options;
  options.options.tolerance = 1e-10;
  options.options.maxIterations = 20000;
  options.engineIterations = false;
  options.fallback = "";
  options.timeBudget = 0;  // 20000 sweeps take seconds: the test wants them all
  for (const Scenes& s : kMonotoneScenes) {
    auto byDantzig = s.make(), byPgs = s.make();
    Stepper dantzig("dantzig", options), pgs("pgs", options);
    double worst = 0;
    for (int k = 0; k < 60; ++k) {
      byDantzig->step([&](dWorldID w, dReal h) { ASSERT_TRUE(dantzig.step(w, h)); }, 0.01);
      byPgs->step([&](dWorldID w, dReal h) { ASSERT_TRUE(pgs.step(w, h)); }, 0.01);
      ASSERT_LE(dantzig.lastStep().maxResidual(), 1e-10) << s.name << " step " << k;
      // Row pgs levels off between 1e-10 and 1e-9 on the near-singular contact rows.
      ASSERT_LE(pgs.lastStep().maxResidual(), 1e-8) << s.name << " step " << k;
      worst = std::max(worst, maxAbsDiff(byDantzig->state(), byPgs->state()));
    }
    EXPECT_LE(worst, 1e-6) << s.name;
    EXPECT_GT(pgs.lastStep().rows(), 0) << s.name;
  }
}

TEST(OdeSolvers, ExactDantzigIsNoWorseThanStockAtEveryStep) {
  Settings options;
  options.reference = "ode-lcp";  // stock dWorldStep's solver on the same island problem
  options.fallback = "";
  int stockWorse = 0;
  for (const Scenes& s : kScenes) {
    auto scene = s.make();
    Stepper stepper("dantzig", options);
    run(*scene, stepper, 300, [&](int k, const IslandStats& st) {
      ASSERT_EQ(st.status, Status::Converged) << s.name << " step " << k << ": " << st.message;
      ASSERT_LE(st.residual, st.referenceResidual + 1e-12) << s.name << " step " << k;
      stockWorse += st.referenceResidual > 1e-6;
    });
  }
  // Stock fixes friction bounds once; with sliding and landing boxes that shows.
  EXPECT_GT(stockWorse, 0);
}

TEST(OdeSolvers, EveryCoreSolverRunsTheStack) {
  for (const char* name : {"pgs", "dantzig", "lemke"}) {
    Settings options;
    options.fallback = "";
    auto scene = boxStack(3);
    Stepper stepper(name, options);
    run(*scene, stepper, 60, [&](int k, const IslandStats& st) {
      ASSERT_TRUE(std::isfinite(st.residual)) << name << " step " << k << ": " << st.message;
    });
    const std::vector<double> z = scene->state();
    EXPECT_NEAR(z[2 * 13 + 2], 1.25, 0.01) << name << ": the top box should rest on the stack";
  }
}

// pgs to 1e-6 on a box at rest for 100 steps, warm- and cold-started: this step's answer is
// last step's, so a warm start needs almost no sweeps. rotateContacts: the collider hands the
// box's contacts over in another order every step.
void expectWarmStartsHelp(bool rotateContacts) {
  Settings options;
  options.options.tolerance = 1e-6;
  options.engineIterations = false;  // sweeps to the tolerance, not QuickStep's fixed count
  auto warm = boxOnPlane(0.0), cold = boxOnPlane(0.0);
  warm->rotateContacts = cold->rotateContacts = rotateContacts;
  Stepper warmStepper("pgs", options);
  options.warmStart = false;
  Stepper coldStepper("pgs", options);
  long warmIterations = 0, coldIterations = 0;
  int warmStarted = 0;
  run(*warm, warmStepper, 100, [&](int, const IslandStats& st) {
    warmIterations += st.iterations;
    warmStarted += st.warmStarted;
    EXPECT_LE(st.residual, 1e-6);
  });
  run(*cold, coldStepper, 100, [&](int, const IslandStats& st) {
    coldIterations += st.iterations;
    EXPECT_FALSE(st.warmStarted);
  });
  EXPECT_GE(warmStarted, 90);  // not when the contact count changed in the first steps
  EXPECT_LT(warmIterations * 2, coldIterations);
}

TEST(OdeSolvers, PgsIsWarmStartedFromTheLastStep) { expectWarmStartsHelp(false); }

// A collider may hand a pair's contacts over in another order every step (ODE's box-box
// culling does on a resting pyramid). Each contact then takes the last step's answer at the
// nearest point of the same pair, not the one of the same rank.
TEST(OdeSolvers, ContactsReorderedByTheColliderKeepTheirWarmStart) { expectWarmStartsHelp(true); }

// The drop-in's default: pgs costs what dWorldQuickStep's solve costs, the world's QuickStep
// iteration count (and W), whatever options.maxIterations says; a pgs fallback is not run again.
TEST(OdeSolvers, DefaultPgsRunsTheWorldsQuickStepIterations) {
  auto scene = boxStack(3);
  Settings settings;
  settings.solver = "pgs";
  settings.options.maxIterations = 500;  // not used: engineIterations is on by default
  Stepper stepper(settings);
  EXPECT_EQ(stepper.settings().options.tolerance, kDefaultIslandTolerance);
  for (int sweeps : {20, 7}) {
    dWorldSetQuickStepNumIterations(scene->world, sweeps);
    int islands = 0;
    run(*scene, stepper, 5, [&](int, const IslandStats& st) {
      ++islands;
      EXPECT_EQ(st.iterations, sweeps);
      EXPECT_FALSE(st.fellBack);
    });
    EXPECT_GT(islands, 0);
  }
  settings.engineIterations = false;
  settings.options.maxIterations = 3;
  settings.fallback = "";
  Stepper pinned(settings);
  run(*scene, pinned, 2, [&](int, const IslandStats& st) { EXPECT_EQ(st.iterations, 3); });
}

}  // namespace
}  // namespace mlcp::ode::test
