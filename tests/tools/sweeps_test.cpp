// Sweep passes handed between processes (tools/mlcp/sweeps.hpp): a pass encoded and decoded is
// the same pass, bit for bit (NaN residuals, strings included), and passes added in order give
// the run that running them in one process gives.
#include "sweeps.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace mlcp::cli {
namespace {

scene::StepMeasures step(double ms, double residual, const std::string& choice) {
  scene::StepMeasures m;
  m.solverMs = ms;
  m.stepMs = 2 * ms;
  m.residual = residual;
  m.iterations = 7;
  m.status = "max-iterations";
  m.fallbacks = 1;
  m.unsolved = 2;
  m.choice = choice;
  m.contacts = 4;
  m.maxPenetration = 1e-3;
  m.jointError = 0.1 + 0.2;
  m.energy = -3.25;
  m.momentum = 1.0 / 3;
  m.maxSpeed = 5e-310;  // subnormal
  return m;
}

SweepRun onePass(double ms) {
  SweepRun run;
  run.scene = "stack_10";
  run.engine = "ode";
  run.passes = 1;
  run.steps = {step(ms, std::numeric_limits<double>::quiet_NaN(), ""),
               step(ms, 1e-12, "dantzig:3 ldlt:1")};
  run.first.steps = 2;
  run.first.worstResidual = std::numeric_limits<double>::quiet_NaN();
  run.first.finite = false;
  return run;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SweepPass, EncodedAndDecodedIsTheSamePass) {
  const SweepRun a = onePass(1.5);
  SweepRun b;
  ASSERT_TRUE(decodeSweepRun(encodeSweepRun(a), b));
  EXPECT_EQ(b.scene, a.scene);
  EXPECT_EQ(b.engine, a.engine);
  EXPECT_EQ(b.passes, 1);
  EXPECT_EQ(b.first.steps, 2);
  EXPECT_FALSE(b.first.finite);
  EXPECT_TRUE(std::isnan(b.first.worstResidual));
  ASSERT_EQ(b.steps.size(), a.steps.size());
  for (std::size_t i = 0; i < a.steps.size(); ++i) {
    const scene::StepMeasures &x = a.steps[i], &y = b.steps[i];
    for (auto f : {&scene::StepMeasures::solverMs, &scene::StepMeasures::stepMs,
                   &scene::StepMeasures::residual, &scene::StepMeasures::maxPenetration,
                   &scene::StepMeasures::jointError, &scene::StepMeasures::energy,
                   &scene::StepMeasures::momentum, &scene::StepMeasures::maxSpeed})
      EXPECT_TRUE(sameBits(x.*f, y.*f)) << i;
    EXPECT_EQ(x.iterations, y.iterations);
    EXPECT_EQ(x.status, y.status);
    EXPECT_EQ(x.fallbacks, y.fallbacks);
    EXPECT_EQ(x.unsolved, y.unsolved);
    EXPECT_EQ(x.choice, y.choice);
    EXPECT_EQ(x.contacts, y.contacts);
  }
}

TEST(SweepPass, CutBytesAreRefused) {
  const std::string bytes = encodeSweepRun(onePass(1));
  SweepRun b;
  for (std::size_t n : {std::size_t(0), std::size_t(5), bytes.size() / 2, bytes.size() - 1})
    EXPECT_FALSE(decodeSweepRun(bytes.substr(0, n), b)) << n;
  EXPECT_FALSE(decodeSweepRun(bytes + "x", b));
}

TEST(SweepPass, LaterPassesLowerTheTimesOfMatchingSteps) {
  SweepRun run;
  addSweepPass(run, onePass(3));
  addSweepPass(run, onePass(1));
  SweepRun other = onePass(0.5);
  other.steps[1].iterations = 8;  // differs from step 1 on: not used from there
  addSweepPass(run, std::move(other));
  EXPECT_EQ(run.passes, 3);
  EXPECT_EQ(run.steps[0].solverMs, 0.5);
  EXPECT_EQ(run.steps[1].solverMs, 1);
  ASSERT_EQ(run.differing.size(), 1u);
  EXPECT_EQ(run.differing[0], std::make_pair(2, 1));
}

}  // namespace
}  // namespace mlcp::cli
