// Settings::keepProblems: the kept island problems are the ones the solver received, their
// lambda is the one the bodies felt, and keeping them changes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mlcp/ode/stepper.hpp"
#include "mlcp/residual.hpp"
#include "ode/feedback_lambda.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

// The bench's pgs (ode_pgs_bench): 20 sweeps, no convergence test, no fallback.
Settings fixedPgs(bool keep) { return fixedSweepPgs(20, keep); }

std::unique_ptr<Scene> pileWithContactFeedback() {
  auto s = boxPyramid(3);
  s->recordContacts = s->contactFeedback = true;
  return s;
}

TEST(OdeDiagnostics, KeptProblemsLeaveTheTrajectoryBitwiseUnchanged) {
  for (const char* name : {"pgs", "auto"}) {
    auto on = boxPyramid(3), off = boxPyramid(3);
    const bool pgs = std::string(name) == "pgs";
    Settings withKeep = pgs ? fixedPgs(true) : Settings{};
    withKeep.keepProblems = true;
    withKeep.timeBudget = 0;  // compared bit for bit: no wall-clock cut
    Settings without = pgs ? fixedPgs(false) : Settings{};
    without.timeBudget = 0;
    Stepper keeping(name, withKeep), notKeeping(name, without);
    for (int k = 0; k < 80; ++k) {
      on->step([&](dWorldID w, dReal h) { ASSERT_TRUE(keeping.step(w, h)); }, 0.01);
      off->step([&](dWorldID w, dReal h) { ASSERT_TRUE(notKeeping.step(w, h)); }, 0.01);
      ASSERT_EQ(on->state(), off->state()) << name << " step " << k;
      ASSERT_TRUE(notKeeping.lastProblems().empty());
      ASSERT_EQ(keeping.lastProblems().size(), keeping.lastStep().islands.size())
          << name << " step " << k;
    }
  }
}

// Recovers every kept joint's lambda from the feedback our stepper wrote and checks it against
// the applied lambda and the residual the stepper reported. Returns the number of joints seen.
int checkFeedbackAgainstKept(const Stepper& stepper, int step, const char* what) {
  int joints = 0;
  for (const IslandProblem& p : stepper.lastProblems()) {
    const int m = p.rows.size();
    EXPECT_EQ(p.lambda.size(), m);
    Vector recovered = Vector::Constant(m, kUnset);
    for (const IslandProblem::JointRange& j : p.joints) {
      const dJointFeedback* fb = dJointGetFeedback(j.joint);
      if (!fb) {
        ADD_FAILURE() << what << ": a joint without feedback";
        return joints;
      }
      EXPECT_LE(lambdaFromFeedback(p.rows, j.first, j.count, *fb, recovered), 1e-14)
          << what << " step " << step;
      ++joints;
    }
    const double scale = 1 + p.lambda.lpNorm<Eigen::Infinity>();
    EXPECT_LE((recovered - p.lambda).lpNorm<Eigen::Infinity>(), 1e-9 * scale)
        << what << " step " << step;
    const IslandStats& st = stepper.lastStep().islands.at(p.island);
    const Problem problem = p.rows.assemble(false);
    EXPECT_NEAR(accuracy(problem, p.lambda).residual, st.residual, 1e-10)
        << what << " step " << step;
    EXPECT_NEAR(accuracy(problem, recovered).residual, st.residual, 1e-9)
        << what << " step " << step;
  }
  return joints;
}

TEST(OdeDiagnostics, LambdaFromFeedbackIsTheAppliedLambda) {
  struct Case {
    const char* name;
    std::unique_ptr<Scene> (*make)();
    const char* solver;
  };
  const Case cases[] = {
      {"pile, pgs", pileWithContactFeedback, "pgs"},
      {"pile, dantzig", pileWithContactFeedback, "dantzig"},
      {"pendulum chain, auto", [] { return pendulumChain(3); }, "auto"},
      {"hinge with limit and motor, pgs", hingeLimitMotor, "pgs"},
  };
  for (const Case& c : cases) {
    auto scene = c.make();
    Settings o = std::string(c.solver) == "pgs" ? fixedPgs(true) : Settings{};
    o.keepProblems = true;
    Stepper stepper(c.solver, o);
    int joints = 0;
    for (int k = 0; k < 60; ++k)
      scene->step(
          [&](dWorldID w, dReal h) {
            ASSERT_TRUE(stepper.step(w, h));
            // Inside the step: the contact joints are destroyed right after it.
            joints += checkFeedbackAgainstKept(stepper, k, c.name);
          },
          0.01);
    EXPECT_GE(joints, 60) << c.name;
  }
}

// The recovered residual is not trivially the applied one: lambda from the feedback of a
// different answer (the pile's contacts stepped by dWorldQuickStep from the same state) gives
// a different residual on the same kept problem.
TEST(OdeDiagnostics, RecoveredLambdaTellsAnswersApart) {
  // Both piles are set to a third one's state before each step: a copy normalizes the
  // quaternion, so a pile copied onto another would not collide bitwise like it.
  auto base = boxPyramid(3), ours = pileWithContactFeedback(), quick = pileWithContactFeedback();
  Stepper baseStepper("pgs", fixedPgs(false)), stepper("pgs", fixedPgs(true));
  dWorldSetQuickStepNumIterations(quick->world, 20);
  double worstDifference = 0;
  for (int k = 0; k < 40; ++k) {
    copyState(*base, *ours);
    copyState(*base, *quick);
    base->step([&](dWorldID w, dReal h) { ASSERT_TRUE(baseStepper.step(w, h)); }, 0.01);
    ours->step([&](dWorldID w, dReal h) { ASSERT_TRUE(stepper.step(w, h)); }, 0.01);
    quick->step([](dWorldID w, dReal h) { dWorldQuickStep(w, h); }, 0.01);
    const auto &a = ours->contactRecords(), &b = quick->contactRecords();
    ASSERT_EQ(a.size(), b.size());
    ASSERT_FALSE(stepper.lastProblems().empty());
    for (const IslandProblem& p : stepper.lastProblems()) {
      Vector fromQuick = Vector::Constant(p.rows.size(), kUnset);
      for (const IslandProblem::JointRange& j : p.joints) {
        const auto it = std::find_if(
            a.begin(), a.end(), [&](const Scene::ContactRecord& r) { return r.joint == j.joint; });
        ASSERT_NE(it, a.end());
        const Scene::ContactRecord& twin = b[it - a.begin()];
        for (int d = 0; d < 3; ++d) {
          ASSERT_EQ(it->geom.pos[d], twin.geom.pos[d]);
          ASSERT_EQ(it->geom.normal[d], twin.geom.normal[d]);
        }
        ASSERT_LE(lambdaFromFeedback(p.rows, j.first, j.count, *twin.feedback, fromQuick), 1e-12);
      }
      ASSERT_TRUE(fromQuick.allFinite());
      const Problem problem = p.rows.assemble(false);
      worstDifference = std::max(worstDifference, std::abs(accuracy(problem, fromQuick).residual -
                                                           accuracy(problem, p.lambda).residual));
    }
  }
  EXPECT_GT(worstDifference, 1e-6);
}

}  // namespace
}  // namespace mlcp::ode::test
