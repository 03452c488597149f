// Closed-form physics through the drop-in, for every core solver that handles friction.
#include <gtest/gtest.h>

#include <cmath>

#include "mlcp/bullet/constraint_solver.hpp"
#include "mlcp/registry.hpp"
#include "scenes.hpp"

namespace {

namespace sc = mlcp::bullet::scenes;
using mlcp::bullet::ConstraintSolver;
using mlcp::bullet::Settings;

constexpr double kG = 9.81;

Settings settingsFor(const std::string& name) {
  Settings s;
  s.solver = name;
  s.cfm = mlcp::bullet::CfmModel::StockMlcp;  // globalCfm / dt on friction rows too
  s.options.tolerance = 1e-10;                // exact answers: the friction cone is checked to 1e-9
  s.timeBudget = 0;  // the exact solvers' physics is checked, whatever they cost (lemke)
  if (name == "pgs") {
    s.engineIterations = false;
    // Like SI with enough sweeps: the answer after 1000 sweeps is used whatever its residual
    // (these singular face-contact problems converge slowly); the physics is what is checked.
    s.options.maxIterations = 1000;
    s.options.tolerance = 1e-9;
    s.options.checkEvery = 10;
    s.acceptResidual = INFINITY;
    s.fallback = "";
  }
  return s;
}

// Every contact of every manifold keeps each friction impulse within mu times its normal
// impulse (the box friction model Bullet uses with two directions).
void expectFrictionWithinCone(sc::World& w, int step) {
  btDispatcher* d = w.world().getDispatcher();
  for (int m = 0; m < d->getNumManifolds(); ++m) {
    const btPersistentManifold* man = d->getManifoldByIndexInternal(m);
    for (int c = 0; c < man->getNumContacts(); ++c) {
      const btManifoldPoint& p = man->getContactPoint(c);
      const double limit = p.m_combinedFriction * p.m_appliedImpulse + 1e-9;
      EXPECT_LE(std::abs(p.m_appliedImpulseLateral1), limit) << "step " << step;
      EXPECT_LE(std::abs(p.m_appliedImpulseLateral2), limit) << "step " << step;
    }
  }
}

// A world for direct solvers: a box face touches in four coplanar points, so with Bullet's
// default globalCfm of 0 the matrix is singular and pivoting on it breaks down (the stock
// solvers too: ENGINE-FACTS.md). Bullet's own demos for direct solvers use 1e-5, as we do.
std::unique_ptr<sc::World> world(const std::string& solver) {
  auto w = std::make_unique<sc::World>(1.0 / 60.0, true);
  w->info().m_globalCfm = 1e-5;
  w->setSolver(std::make_unique<ConstraintSolver>(settingsFor(solver)));
  return w;
}

class BulletPhysics : public ::testing::TestWithParam<std::string> {};

TEST_P(BulletPhysics, BoxOnInclineStaysPutBelowFrictionAngle) {
  const double theta = 20 * SIMD_PI / 180, mu = 0.6;  // tan(theta) = 0.36 < mu
  auto holder = world(GetParam());
  sc::World& w = *holder;
  btRigidBody* box = sc::incline(w, theta, mu);
  w.step(10);
  const btVector3 settled = box->getCenterOfMassPosition();
  for (int i = 0; i < 120; ++i) {
    w.step();
    expectFrictionWithinCone(w, i);
  }
  EXPECT_LT((box->getCenterOfMassPosition() - settled).length(), 1e-3);
  EXPECT_EQ(static_cast<ConstraintSolver*>(w.solver())->totals().failures, 0);
}

TEST_P(BulletPhysics, BoxOnInclineSlidesWithCoulombAcceleration) {
  const double theta = 30 * SIMD_PI / 180, mu = 0.3;  // tan(theta) = 0.58 > mu
  auto holder = world(GetParam());
  sc::World& w = *holder;
  btRigidBody* box = sc::incline(w, theta, mu);
  const btVector3 down(-std::cos(theta), -std::sin(theta), 0);  // down the slope
  w.step(30);
  const double v0 = box->getLinearVelocity().dot(down);
  const int steps = 60;
  for (int i = 0; i < steps; ++i) {
    w.step();
    expectFrictionWithinCone(w, i);
  }
  const double a = (box->getLinearVelocity().dot(down) - v0) / (steps * w.dt());
  const double expected = kG * (std::sin(theta) - mu * std::cos(theta));
  EXPECT_NEAR(a, expected, 0.01 * expected);
}

TEST_P(BulletPhysics, TenBoxStackStaysAtRest) {
  auto holder = world(GetParam());
  sc::World& w = *holder;
  auto* solver = static_cast<ConstraintSolver*>(w.solver());
  sc::stack(w, 10);
  w.step(30);  // settle onto the contact slop
  std::vector<btVector3> rest;
  for (const btRigidBody* b : w.dynamicBodies()) rest.push_back(b->getCenterOfMassPosition());
  EXPECT_NEAR(rest.back().y(), 9.5, 0.01) << "sank while settling";
  double drift = 0;
  for (int i = 0; i < 600; ++i) {
    w.step();
    for (std::size_t k = 0; k < rest.size(); ++k)
      drift = std::max<double>(
          drift, (w.dynamicBodies()[k]->getCenterOfMassPosition() - rest[k]).length());
    if (i % 50 == 0) expectFrictionWithinCone(w, i);
  }
  EXPECT_LT(drift, 1e-3);
  EXPECT_EQ(solver->totals().failures, 0) << solver->totals().message;
}

INSTANTIATE_TEST_SUITE_P(CoreSolvers, BulletPhysics, ::testing::Values("pgs", "dantzig", "lemke"),
                         [](const auto& info) { return info.param; });

}  // namespace
