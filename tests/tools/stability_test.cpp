// The stability classification of `mlcp stability` (tools/mlcp/stability.hpp) on hand-made
// measures, the stack scenes it builds, and the tracker that measures a run.
#include "stability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mlcp::cli {
namespace {

CellMeasures restingStack() {
  CellMeasures m;
  m.steps = 120;
  m.maxSpeed = 0.05;
  m.maxDisplacementRatio = 0.004;
  m.topDisplacement = 0.004;
  m.maxPenetration = 0.002;
  return m;
}

TEST(Classify, EachOutcomeFromItsOwnMeasure) {
  const StabilityThresholds t;
  EXPECT_EQ(classify(restingStack(), t).outcome, Outcome::Stable);

  CellMeasures m = restingStack();
  m.topDisplacement = 0.03;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Drifting);
  EXPECT_EQ(classify(m, t).reason, "top box moved 0.03 m > 0.02 m");

  m = restingStack();
  m.maxDisplacementRatio = 0.6;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Collapsed);
  m = restingStack();
  m.maxPenetration = 0.15;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Collapsed);

  m = restingStack();
  m.maxSpeed = 26;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Exploded);
  m = restingStack();
  m.maxSpeed = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(classify(m, t).outcome, Outcome::Exploded);
  m = restingStack();
  m.finite = false;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Exploded);

  m = restingStack();
  m.failedSteps = 13;  // 10.8 % of 120
  EXPECT_EQ(classify(m, t).outcome, Outcome::SolverFailure);
  m = restingStack();
  m.fallbackSteps = 13;
  EXPECT_EQ(classify(m, t).outcome, Outcome::SolverFailure);
}

TEST(Classify, ThresholdsAreStrict) {
  const StabilityThresholds t;
  CellMeasures m = restingStack();
  m.topDisplacement = t.drift;
  m.maxDisplacementRatio = t.collapseFraction;
  m.maxPenetration = t.collapsePenetration;
  m.maxSpeed = t.maxSpeed;
  m.failedSteps = 12;  // exactly 10 %
  m.fallbackSteps = 12;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Stable);
}

TEST(Classify, WorstOutcomeWins) {
  const StabilityThresholds t;
  CellMeasures m = restingStack();
  m.topDisplacement = 3;
  m.maxDisplacementRatio = 3;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Collapsed);  // not merely drifting
  m.fallbackSteps = 60;
  EXPECT_EQ(classify(m, t).outcome, Outcome::SolverFailure);
  m.maxSpeed = 1e3;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Exploded);
}

TEST(Classify, ThresholdsAreOptions) {
  StabilityThresholds t;
  CellMeasures m = restingStack();
  t.drift = 0.001;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Drifting);
  t.collapseFraction = 0.001;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Collapsed);
  t.maxSpeed = 0.01;
  EXPECT_EQ(classify(m, t).outcome, Outcome::Exploded);
}

TEST(Classify, OutcomeNamesAreTheChartScripts) {
  EXPECT_STREQ(toString(Outcome::Stable), "stable");
  EXPECT_STREQ(toString(Outcome::Drifting), "drifting");
  EXPECT_STREQ(toString(Outcome::Collapsed), "collapsed");
  EXPECT_STREQ(toString(Outcome::Exploded), "exploded");
  EXPECT_STREQ(toString(Outcome::SolverFailure), "solver-failure");
}

TEST(StackScene, MassesGrowGeometricallyToTheRatio) {
  const scene::Scene s = stackScene("s", 4, 1000, 0.01);
  ASSERT_EQ(s.bodies.size(), 5u);
  EXPECT_TRUE(s.bodies[0].isStatic());
  EXPECT_EQ(s.dynamicBodyCount(), 4);
  EXPECT_DOUBLE_EQ(s.bodies[1].mass, 1);
  EXPECT_NEAR(s.bodies[2].mass, 10, 1e-12);
  EXPECT_NEAR(s.bodies[4].mass, 1000, 1e-9);
  for (int i = 1; i <= 4; ++i) {
    EXPECT_DOUBLE_EQ(s.bodies[i].position[2], i - 0.5);               // resting on each other
    EXPECT_NEAR(s.bodies[i].inertia[0], s.bodies[i].mass / 6, 1e-9);  // m/12 (1 + 1)
  }
  EXPECT_DOUBLE_EQ(s.settings.timeStep, 0.01);
  EXPECT_DOUBLE_EQ(s.settings.cfm, kStackCfm);  // not the scenes' 1e-5: see stability.hpp
  EXPECT_DOUBLE_EQ(stackScene("s", 2, 1, 0.01, 1e-5).settings.cfm, 1e-5);
  EXPECT_THROW(stackScene("s", 2, 1, 0.01, -1), std::invalid_argument);
  EXPECT_THROW(stackScene("s", 0, 1, 0.01), std::invalid_argument);
  EXPECT_THROW(stackScene("s", 2, 0, 0.01), std::invalid_argument);
  EXPECT_THROW(stackScene("s", 2, 1, 0), std::invalid_argument);
}

TEST(CellTracker, MeasuresDisplacementSpeedAndFailures) {
  const scene::Scene s = stackScene("s", 2, 1, 0.01);
  CellTracker tracker(s);
  std::vector<scene::BodyState> states(3);
  for (int i = 0; i < 3; ++i) states[i].position = s.bodies[i].position;
  scene::StepMeasures m;
  m.maxSpeed = 0.5;
  m.maxPenetration = 0.003;
  tracker.observe(states, m);
  states[1].position[0] += 0.3;   // bottom box: 0.3 edges
  states[2].position[2] -= 0.04;  // top box sinks 4 cm
  m.status = "failed";
  m.fallbacks = 2;
  m.maxSpeed = 0.2;
  tracker.observe(states, m);
  states[2].position[2] += 0.04;  // back: the largest distance is kept
  m.status = "max-iterations";
  m.fallbacks = 0;
  tracker.observe(states, m);
  const CellMeasures& c = tracker.measures();
  EXPECT_EQ(c.steps, 3);
  EXPECT_TRUE(c.finite);
  EXPECT_DOUBLE_EQ(c.maxSpeed, 0.5);
  EXPECT_DOUBLE_EQ(c.maxPenetration, 0.003);
  EXPECT_NEAR(c.maxDisplacementRatio, 0.3, 1e-12);
  EXPECT_NEAR(c.topDisplacement, 0.04, 1e-12);
  EXPECT_EQ(c.failedSteps, 1);
  EXPECT_EQ(c.fallbackSteps, 1);
  EXPECT_EQ(classify(c, StabilityThresholds{}).outcome, Outcome::SolverFailure);

  states[2].position[0] = std::nan("");
  tracker.observe(states, m);
  EXPECT_FALSE(tracker.measures().finite);
}

}  // namespace
}  // namespace mlcp::cli
