// The friction models through the Bullet drop-in (Settings::friction, friction_model.hpp): a 1 m
// box on the ground under gravity tilted by the slope angle alpha toward the direction psi (the
// incline, without a tilted body), and a box pushed along the ground, against the closed forms
// of tests/common/cone_closed_form.hpp for the box and the cone with k = 4 and k = 8.
//
// The contact frame is Bullet's btPlaneSpace1 of the ground normal (+-x, +-z): the friction
// direction is kept from following the velocity (SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_
// DIRECTION), else t1 turns into the slide and every model is exact along it.
#include <gtest/gtest.h>

#include <cmath>

#include "common/cone_closed_form.hpp"
#include "mlcp/bullet/constraint_solver.hpp"
#include "scenes.hpp"

namespace {

namespace sc = mlcp::bullet::scenes;
using mlcp::FrictionModel;
using mlcp::bullet::ConstraintSolver;
using mlcp::bullet::Settings;
using namespace mlcp::test;  // cone_closed_form.hpp

constexpr double kG = 9.81, kMu = 0.5;
// A flat slab (1 x 0.2 x 1 m) that does not rotate (angular factor 0): a particle. Bullet's
// manifold of a sliding box keeps 1 to 4 of its corner points from step to step (each moves past
// the breaking threshold), so a box free to rotate rocks on them and the closed forms hold only
// on average.
constexpr double kHalfHeight = 0.1;

// k = 0: the box.
Settings settingsFor(int k) {
  Settings s;
  mlcp::test::useModel(s, k);
  s.cfm = mlcp::bullet::CfmModel::StockMlcp;  // globalCfm / dt on friction rows too
  return s;
}

struct Box {
  std::unique_ptr<sc::World> world;
  btRigidBody* body = nullptr;
  ConstraintSolver* solver = nullptr;
};

// The box resting on the ground (friction kMu), gravity tilted by alpha toward psi.
Box boxOnGround(int k, double alpha, double psi, const btVector3& velocity = btVector3(0, 0, 0)) {
  Box b;
  b.world = std::make_unique<sc::World>(1.0 / 60.0, true);
  sc::World& w = *b.world;
  w.info().m_globalCfm = 1e-5;
  w.info().m_solverMode |= SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
  auto solver = std::make_unique<ConstraintSolver>(settingsFor(k));
  b.solver = solver.get();
  w.setSolver(std::move(solver));
  w.world().setGravity(btVector3(kG * std::sin(alpha) * std::cos(psi), -kG * std::cos(alpha),
                                 kG * std::sin(alpha) * std::sin(psi)));
  w.addGround(1.0);  // combined friction = 1.0 * kMu
  btTransform pose;
  pose.setIdentity();
  pose.setOrigin(btVector3(0, kHalfHeight, 0));
  b.body = w.addBox(btVector3(0.5, kHalfHeight, 0.5), 1.0, pose, kMu);
  b.body->setLinearVelocity(velocity);
  b.body->setAngularFactor(0);
  return b;
}

btVector3 horizontal(const btVector3& v) { return btVector3(v.x(), 0, v.z()); }

// The cone islands answered by the cone's LCP within its residual; the box's by the box.
void expectModelRan(const Box& b, int k) {
  const auto& t = b.solver->totals();
  EXPECT_EQ(t.failures, 0) << t.message;
  if (k > 0) {
    EXPECT_EQ(t.coneIslands, t.islands) << t.message;
    EXPECT_LE(b.solver->lastStep().residual, 1e-6);
  } else {
    EXPECT_EQ(t.coneIslands, 0);
  }
}

TEST(BulletFrictionCone, AnInclineSticksBelowAndSlidesAboveTheModelsCriticalSlope) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double critical = kMu * frictionRadius(c.k, c.psi);
    for (double factor : {0.95, 1.05}) {
      const double alpha = std::atan(factor * critical);
      Box b = boxOnGround(c.k, alpha, c.psi);
      b.world->step(10);
      const btVector3 settled = b.body->getCenterOfMassPosition();
      b.world->step(60);
      const double moved = (b.body->getCenterOfMassPosition() - settled).length();
      // Sliding for 1 s from about rest: half the closed-form acceleration, seconds squared.
      const double slide = 0.5 * kG * (std::sin(alpha) - critical * std::cos(alpha));
      if (factor < 1)
        EXPECT_LT(moved, 1e-3) << "alpha " << alpha;
      else
        EXPECT_GT(moved, 0.5 * slide) << "alpha " << alpha;
      expectModelRan(b, c.k);
    }
  }
}

TEST(BulletFrictionCone, AnInclineSlidesWithTheModelsAcceleration) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double alpha = std::atan(1.6 * kMu * frictionRadius(c.k, c.psi));
    Box b = boxOnGround(c.k, alpha, c.psi);
    const btVector3 down(std::cos(c.psi), 0, std::sin(c.psi));
    b.world->step(10);
    const double v0 = b.body->getLinearVelocity().dot(down);
    b.world->step(30);
    const double a = (b.body->getLinearVelocity().dot(down) - v0) / (30 * b.world->dt());
    const double expected =
        kG * (std::sin(alpha) - kMu * frictionSupport(c.k, c.psi) * std::cos(alpha));
    EXPECT_NEAR(a, expected, 0.01 * expected);
    // The slide keeps its direction (psi is a direction or a midpoint of the polygon).
    const btVector3 v = horizontal(b.body->getLinearVelocity());
    EXPECT_NEAR(std::atan2(v.z(), v.x()), c.psi, 1e-3);
    expectModelRan(b, c.k);
  }
}

TEST(BulletFrictionCone, ABoxPushedAlongTheGroundSlowsWithTheModelsFriction) {
  for (const FrictionCase& c : kFrictionCases) {
    SCOPED_TRACE(caseName(c));
    const double speed = 3;
    Box b = boxOnGround(c.k, 0, 0, speed * btVector3(std::cos(c.psi), 0, std::sin(c.psi)));
    b.world->step(5);  // the contact forms and carries the box's weight
    const double v0 = horizontal(b.body->getLinearVelocity()).length();
    b.world->step(20);
    const btVector3 v = horizontal(b.body->getLinearVelocity());
    const double decel = (v0 - v.length()) / (20 * b.world->dt());
    const double expected = kMu * frictionSupport(c.k, c.psi) * kG;
    EXPECT_NEAR(decel, expected, 0.01 * expected);
    EXPECT_NEAR(std::atan2(v.z(), v.x()), c.psi, 1e-3);
    expectModelRan(b, c.k);
  }
}

TEST(BulletFrictionCone, TheConeNeedsACoreSolverThatTakesAnLcp) {
  Settings s = settingsFor(4);
  for (const char* name : {"si", "pgs"}) {
    s.solver = name;
    try {
      ConstraintSolver solver(s);
      FAIL() << "no exception for " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("friction 'cone'"), std::string::npos) << e.what();
    }
  }
  s.solver = "lemke";
  s.frictionDirections = 2;
  EXPECT_THROW(ConstraintSolver{s}, std::invalid_argument);
}

}  // namespace
