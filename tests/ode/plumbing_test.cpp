// The adapter's plumbing against stock ODE: the same scenes stepped by dWorldStep and by our
// stepper must give the same trajectories and joint feedback.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

using SceneFactory = std::unique_ptr<Scene> (*)();

struct NamedScene {
  const char* name;
  SceneFactory make;
};

const NamedScene kScenes[] = {
    {"pendulum chain", [] { return pendulumChain(3); }},
    {"hinge with limit and motor", [] { return hingeLimitMotor(); }},
    {"slider", [] { return sliderScene(); }},
    {"box resting", [] { return boxOnPlane(0.0); }},
    {"box sliding", [] { return boxOnPlane(2.0); }},
    {"box sliding, box friction",
     [] {
       auto s = boxOnPlane(2.0, 2.0);
       s->surface.mode = 0;  // friction bounded by mu in force units, no findex
       return s;
     }},
    {"3-box stack", [] { return boxStack(3); }},
};

struct Diff {
  double state = 0, feedback = 0;
  int contacts = 0;  // contacts made over the run (to see the scene did what it should)
};

// Runs the scene twice, stock dWorldStep against `ours`, comparing after every step.
Diff compare(const NamedScene& scene, const StepFn& ours, int steps = 300, dReal h = 0.01) {
  auto stock = scene.make();
  auto mine = scene.make();
  const StepFn dWorld = [](dWorldID w, dReal dt) { dWorldStep(w, dt); };
  Diff d;
  for (int k = 0; k < steps; ++k) {
    stock->step(dWorld, h);
    mine->step(ours, h);
    d.state = std::max(d.state, maxAbsDiff(stock->state(), mine->state()));
    d.feedback = std::max(d.feedback, maxAbsDiff(stock->feedback(), mine->feedback()));
    d.contacts += mine->lastContacts();
  }
  return d;
}

StepFn with(Stepper& stepper) {
  return [&stepper](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); };
}

TEST(OdePlumbing, ForwardingToDxStepIslandIsBitwiseDWorldStep) {
  for (const NamedScene& scene : kScenes) {
    Stepper stepper("ode-step");
    const Diff d = compare(scene, with(stepper));
    EXPECT_EQ(d.state, 0.0) << scene.name;
    EXPECT_EQ(d.feedback, 0.0) << scene.name;
  }
}

TEST(OdePlumbing, OwnRowsWithOdesLcpSolverMatchDWorldStep) {
  for (const NamedScene& scene : kScenes) {
    Stepper stepper("ode-lcp");
    const Diff d = compare(scene, with(stepper));
    EXPECT_LE(d.state, 1e-12) << scene.name;
    EXPECT_LE(d.feedback, 1e-9) << scene.name;  // forces are ~1e3 x larger than states
  }
}

TEST(OdePlumbing, CompatibleDantzigMatchesDWorldStep) {
  Settings options;
  options.options.frictionBounds = FrictionBounds::FixedOnce;
  options.warmStart = false;  // stock starts every step from zero
  options.fallback = "";
  for (const NamedScene& scene : kScenes) {
    Stepper stepper("dantzig", options);
    const Diff d = compare(scene, with(stepper));
    EXPECT_LE(d.state, 1e-9) << scene.name;
    EXPECT_LE(d.feedback, 1e-6) << scene.name;
  }
}

TEST(OdePlumbing, ScenesExerciseWhatTheyClaim) {
  // Guards the comparisons above against scenes that do nothing.
  Stepper stepper("ode-lcp");
  for (const NamedScene& scene : kScenes) {
    auto s = scene.make();
    const std::vector<double> start = s->state();
    int contacts = 0, rows = 0;
    for (int k = 0; k < 50; ++k) {
      s->step(with(stepper), 0.01);
      contacts += s->lastContacts();
      rows += stepper.lastStep().rows();
    }
    EXPECT_GT(rows, 0) << scene.name;
    if (std::string(scene.name).find("box") != std::string::npos) {
      EXPECT_GT(contacts, 0) << scene.name;
    }
    if (std::string(scene.name).find("rest") == std::string::npos &&
        std::string(scene.name).find("stack") == std::string::npos) {
      EXPECT_GT(maxAbsDiff(start, s->state()), 1e-3) << scene.name << " does not move";
    }
  }
}

}  // namespace
}  // namespace mlcp::ode::test
