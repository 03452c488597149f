// The friction models through the ODE stepper (Settings::friction, friction_model.hpp): a flat
// box on the ground plane under gravity tilted by the slope angle alpha toward the direction psi
// (the incline, without a tilted body), and a box pushed along the ground, against the closed
// forms of tests/common/cone_closed_form.hpp for the box and the cone with k = 4 and k = 8.
// The contact frame is ODE's dPlaneSpace of the normal +z (+-x, +-y), dContactApprox1 friction.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "common/cone_closed_form.hpp"
#include "mlcp/ode/stepper.h"
#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

using namespace mlcp::test;  // cone_closed_form.hpp

constexpr double kG = 9.81, kMu = 0.5;
constexpr dReal kH = 0.01;

// k = 0: the box.
Settings settingsFor(int k) {
  Settings s;
  mlcp::test::useModel(s, k);
  return s;
}

struct SlabRun {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Stepper> stepper;
  int coneIslands = 0, islands = 0, rejected = 0;
  double worstResidual = 0;

  void step(int n) {
    const auto fn = [&](dWorldID w, dReal dt) { ASSERT_TRUE(stepper->step(w, dt)); };
    for (int i = 0; i < n; ++i) {
      scene->step(fn, kH);
      for (const IslandStats& st : stepper->lastStep().islands) {
        if (st.rows == 0) continue;
        ++islands;
        coneIslands += st.friction == FrictionModel::Cone;
        rejected += !st.accepted;
        worstResidual = std::max(worstResidual, st.residual);
      }
    }
  }
  dBodyID body() const { return scene->bodies[0]; }
  // The body's horizontal velocity.
  std::pair<double, double> velocity() const {
    const dReal* v = dBodyGetLinearVel(body());
    return {v[0], v[1]};
  }
};

// A 1 x 1 x 0.2 m slab of 1 kg resting on the ground (friction kMu), gravity tilted by alpha
// toward psi: flat, so friction's tipping moment is small and the four corners stay in contact.
SlabRun slabOnGround(int k, double alpha, double psi, double vx = 0, double vy = 0) {
  SlabRun r;
  r.scene = std::make_unique<Scene>();
  Scene& s = *r.scene;
  s.surface.mu = kMu;
  // The scenes' world CFM: lemke on the cone's LCP needs a little (friction_model.hpp); ODE's
  // double-precision default of 1e-10 leaves its ratio tests on near-singular pivots.
  dWorldSetCFM(s.world, 1e-5);
  s.addPlane(0, 0, 1, 0);
  dBodyID b = s.addBox(0, 0, 0.1, 1, 1, 0.2, 5.0);  // density 5: 1 kg
  dBodySetLinearVel(b, vx, vy, 0);
  dWorldSetGravity(s.world, kG * std::sin(alpha) * std::cos(psi),
                   kG * std::sin(alpha) * std::sin(psi), -kG * std::cos(alpha));
  r.stepper = std::make_unique<Stepper>(settingsFor(k));
  return r;
}

void expectModelRan(const SlabRun& r, int k) {
  EXPECT_EQ(r.rejected, 0);
  if (k > 0) {
    EXPECT_EQ(r.coneIslands, r.islands);
    EXPECT_LE(r.worstResidual, 1e-6);  // the cone LCP's, recomputed by RowSolver
  } else {
    EXPECT_EQ(r.coneIslands, 0);
  }
}

TEST(OdeFrictionCone, AnInclineSticksBelowAndSlidesAboveTheModelsCriticalSlope) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double critical = kMu * frictionRadius(c.k, c.psi);
    for (double factor : {0.95, 1.05}) {
      const double alpha = std::atan(factor * critical);
      SlabRun r = slabOnGround(c.k, alpha, c.psi);
      r.step(10);
      const dReal* p = dBodyGetPosition(r.body());
      const double x0 = p[0], y0 = p[1];
      r.step(100);
      const double moved = std::hypot(p[0] - x0, p[1] - y0);
      const double slide = 0.5 * kG * (std::sin(alpha) - critical * std::cos(alpha));  // 1 s
      if (factor < 1)
        EXPECT_LT(moved, 1e-3) << "alpha " << alpha;
      else
        EXPECT_GT(moved, 0.5 * slide) << "alpha " << alpha;
      expectModelRan(r, c.k);
    }
  }
}

TEST(OdeFrictionCone, AnInclineSlidesWithTheModelsAcceleration) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double alpha = std::atan(1.6 * kMu * frictionRadius(c.k, c.psi));
    SlabRun r = slabOnGround(c.k, alpha, c.psi);
    r.step(10);
    auto along = [&] {
      const auto [vx, vy] = r.velocity();
      return vx * std::cos(c.psi) + vy * std::sin(c.psi);
    };
    const double v0 = along();
    r.step(50);
    const double a = (along() - v0) / (50 * kH);
    const double expected =
        kG * (std::sin(alpha) - kMu * frictionSupport(c.k, c.psi) * std::cos(alpha));
    EXPECT_NEAR(a, expected, 0.01 * expected);
    const auto [vx, vy] = r.velocity();
    EXPECT_NEAR(std::atan2(vy, vx), c.psi, 1e-3);
    expectModelRan(r, c.k);
  }
}

TEST(OdeFrictionCone, ABoxPushedAlongTheGroundSlowsWithTheModelsFriction) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double speed = 3;
    SlabRun r = slabOnGround(c.k, 0, 0, speed * std::cos(c.psi), speed * std::sin(c.psi));
    r.step(5);
    auto [x0, y0] = r.velocity();
    r.step(30);
    const auto [vx, vy] = r.velocity();
    const double decel = (std::hypot(x0, y0) - std::hypot(vx, vy)) / (30 * kH);
    const double expected = kMu * frictionSupport(c.k, c.psi) * kG;
    EXPECT_NEAR(decel, expected, 0.01 * expected);
    EXPECT_NEAR(std::atan2(vy, vx), c.psi, 1e-3);
    expectModelRan(r, c.k);
  }
}

// mu = dInfinity (no slip) reaches the core as free tangent rows (island.cpp): with the cone
// selected they stay free rows, and the slab holds a 60 degree slope; mu = 0 slides freely.
TEST(OdeFrictionCone, InfiniteMuHoldsAndZeroMuSlidesWithTheConeSelected) {
  const double alpha = kConePi / 3;
  for (const double mu : {static_cast<double>(dInfinity), 0.0}) {
    SlabRun r = slabOnGround(8, alpha, 0.3);
    r.scene->surface.mu = mu;
    r.step(10);
    const dReal* p = dBodyGetPosition(r.body());
    const double x0 = p[0], y0 = p[1];
    r.step(50);
    const double moved = std::hypot(p[0] - x0, p[1] - y0);
    EXPECT_EQ(r.rejected, 0) << mu;
    if (mu > 0) {
      EXPECT_LT(moved, 1e-3);
    } else {  // frictionless: a = g sin(alpha); semi-implicit Euler moves a h^2 n (n + 1) / 2
      const double a = kG * std::sin(alpha);
      EXPECT_NEAR(moved, a * kH * kH * (60 * 61 - 10 * 11) / 2, 1e-3 * moved);
    }
  }
}

TEST(OdeFrictionCone, BadSettingsAreClearErrors) {
  Settings s = settingsFor(4);
  for (const char* name : {"pgs", "ode-step", "ode-lcp"}) {
    s.solver = name;
    try {
      Stepper stepper(s);
      FAIL() << "no exception for " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("friction 'cone'"), std::string::npos) << e.what();
    }
  }
  s.solver = "lemke";
  for (int k : {2, 65}) {
    s.frictionDirections = k;
    EXPECT_THROW(Stepper{s}, std::invalid_argument) << k;
  }
}

TEST(OdeFrictionCone, TheCApiSetsTheModelOrSaysWhyNot) {
  mlcp_ode_stepper* st = mlcp_ode_stepper_create("auto");
  ASSERT_NE(st, nullptr);
  EXPECT_EQ(mlcp_ode_stepper_set_friction_model(st, MLCP_ODE_FRICTION_MODEL_CONE, 8), MLCP_ODE_OK);
  EXPECT_EQ(mlcp_ode_stepper_set_friction_model(st, MLCP_ODE_FRICTION_MODEL_CONE, 2),
            MLCP_ODE_ERROR);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("friction directions must be in [3, 64]"),
            std::string::npos)
      << mlcp_ode_last_error();
  EXPECT_EQ(mlcp_ode_stepper_set_friction_model(st, 7, 4), MLCP_ODE_ERROR);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("MLCP_ODE_FRICTION_MODEL_BOX"),
            std::string::npos);
  mlcp_ode_stepper_destroy(st);
  st = mlcp_ode_stepper_create("pgs");
  ASSERT_NE(st, nullptr);
  EXPECT_EQ(mlcp_ode_stepper_set_friction_model(st, MLCP_ODE_FRICTION_MODEL_CONE, 4),
            MLCP_ODE_ERROR);
  EXPECT_NE(std::string(mlcp_ode_last_error()).find("pgs"), std::string::npos);
  EXPECT_EQ(mlcp_ode_stepper_set_friction_model(st, MLCP_ODE_FRICTION_MODEL_BOX, 4), MLCP_ODE_OK);
  mlcp_ode_stepper_destroy(st);
}

}  // namespace
}  // namespace mlcp::ode::test
