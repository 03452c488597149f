// Degenerate rows Bullet's own constraints build: the drop-in screens them row by row
// (mlcp/island/row_screen.hpp) and solves the rest of the island, as Bullet's SI copes with them.
#include <BulletDynamics/ConstraintSolver/btGearConstraint.h>
#include <BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "mlcp/bullet/constraint_solver.hpp"
#include "scenes.hpp"

namespace {

namespace sc = mlcp::bullet::scenes;
using mlcp::bullet::ConstraintSolver;
using mlcp::bullet::Settings;

btTransform at(double x, double y, double z) {
  btTransform t;
  t.setIdentity();
  t.setOrigin(btVector3(x, y, z));
  return t;
}

// Our drop-in ("auto", "dantzig", "pgs") or Bullet's SI ("si": the reference).
std::unique_ptr<btConstraintSolver> solverNamed(const std::string& name, double tolerance = 1e-10) {
  if (name == "si") return std::make_unique<btSequentialImpulseConstraintSolver>();
  Settings s;
  s.solver = name;
  s.options.tolerance = tolerance;
  s.engineIterations = false;  // pgs sweeps toward the tolerance (its own accuracy is checked)
  return std::make_unique<ConstraintSolver>(s);
}

const mlcp::bullet::StepStats* statsOf(sc::World& w) {
  auto* ours = dynamic_cast<ConstraintSolver*>(w.solver());
  return ours ? &ours->totals() : nullptr;
}

// A 1 kg box held by a btGeneric6DofSpring2Constraint to the world: every axis locked but y,
// which may go from -1 m to SIMD_INFINITY. The y axis' limit rows (Bullet's "limited both
// ways" case) carry rhs = -inf for the infinite side (screened: beyond reach). Under gravity the
// box sinks to y = -1 and stays there. Returns the box.
btRigidBody* boxOnInfiniteLimit(sc::World& w) {
  btRigidBody* box = w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, at(0, 0, 0));
  auto c = std::make_unique<btGeneric6DofSpring2Constraint>(*box, at(0, 0, 0));
  c->setLinearLowerLimit(btVector3(0, -1, 0));
  c->setLinearUpperLimit(btVector3(0, SIMD_INFINITY, 0));
  c->setAngularLowerLimit(btVector3(0, 0, 0));
  c->setAngularUpperLimit(btVector3(0, 0, 0));
  w.addConstraint(std::move(c));
  return box;
}

class BulletDegenerateRows : public ::testing::TestWithParam<std::string> {};

TEST_P(BulletDegenerateRows, InfiniteLimitKeepsBoxAtItsLimitLikeSi) {
  sc::World si(1.0 / 60.0), ours(1.0 / 60.0);
  si.setSolver(solverNamed("si"));
  ours.setSolver(solverNamed(GetParam()));
  btRigidBody* a = boxOnInfiniteLimit(si);
  btRigidBody* b = boxOnInfiniteLimit(ours);
  si.step(300);
  ours.step(300);
  const btVector3 pa = a->getCenterOfMassPosition(), pb = b->getCenterOfMassPosition();
  std::printf("[ figures ] %s: y %.6f (SI %.6f), |p - p_SI| %.3g m\n", GetParam().c_str(), pb.y(),
              pa.y(), (pb - pa).length());
  EXPECT_NEAR(pa.y(), -1.0, 0.02);  // SI keeps it at its limit
  EXPECT_NEAR(pb.y(), -1.0, 0.02);
  EXPECT_LT((pb - pa).length(), 0.02);
  const auto* st = statsOf(ours);
  ASSERT_NE(st, nullptr);
  std::printf("[ figures ] %s: islands %d, failures %d, screened %s\n", GetParam().c_str(),
              st->islands, st->failures, st->screened.toString().c_str());
  EXPECT_EQ(st->failures, 0) << st->message;
  EXPECT_GT(st->screened.rhsBeyondReach, 0);  // the infinite side's row, fixed at its 0 bound
}

// Regression (scenes/six_dof_spring.json): a 1 kg box held by a btGeneric6DofSpring2Constraint,
// every axis locked but x, limited at +-1e30 ("unlimited" as Bullet's demos write it), moving
// along x at 1 m/s under gravity. The limit rows carry rhs = fps erp (x -+ 1e30) = +-1.2e31:
// dantzig reported converged on an answer that held nothing (the residual's scale was 1.2e31),
// and the packed pgs, which screens nothing, reported residuals of 1e-32. Every solver now
// leaves them to the screen (fixed at their 0 bound), holds the box up and lets it slide on.
TEST_P(BulletDegenerateRows, LimitAt1e30IsScreenedAndTheBoxSlidesLikeSi) {
  auto run = [](sc::World& w) {
    btRigidBody* box = w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, at(0, 0, 0));
    auto c = std::make_unique<btGeneric6DofSpring2Constraint>(*box, at(0, 0, 0));
    c->setLinearLowerLimit(btVector3(-1e30, 0, 0));
    c->setLinearUpperLimit(btVector3(1e30, 0, 0));
    c->setAngularLowerLimit(btVector3(0, 0, 0));
    c->setAngularUpperLimit(btVector3(0, 0, 0));
    w.addConstraint(std::move(c));
    box->setLinearVelocity(btVector3(1, 0, 0));
    w.step(60);
    return box;
  };
  sc::World si(1.0 / 60.0), ours(1.0 / 60.0);
  si.setSolver(solverNamed("si"));
  ours.setSolver(solverNamed(GetParam()));
  const btRigidBody* a = run(si);
  const btRigidBody* b = run(ours);
  EXPECT_NEAR(a->getLinearVelocity().x(), 1.0, 1e-6);  // SI: nothing limits x
  EXPECT_NEAR(b->getLinearVelocity().x(), 1.0, 1e-6);
  EXPECT_NEAR(b->getCenterOfMassPosition().y(), a->getCenterOfMassPosition().y(), 1e-3);
  EXPECT_NEAR(b->getCenterOfMassPosition().y(), 0.0, 0.01);  // held up
  const auto* st = statsOf(ours);
  ASSERT_NE(st, nullptr);
  EXPECT_EQ(st->failures, 0) << st->message;
  EXPECT_GT(st->screened.rhsBeyondReach, 0);
  EXPECT_LT(st->residual, 1e-6);
}

// Two boxes resting on the ground, geared together about y; both have angular factor 0 (they
// cannot turn), so the gear's one row has J M^-1 J^T = 0: it moves nothing. The rest of the
// island (the contacts) must still be solved: the boxes rest on the ground. Bullet's default
// globalCfm 0 leaves the gear row without cfm.
TEST_P(BulletDegenerateRows, GearWithoutRotationLeavesIslandSolved) {
  sc::World w(1.0 / 60.0);
  w.setSolver(solverNamed(GetParam()));
  w.addGround(0.5);
  btRigidBody* a = w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, at(0, 0.5, 0));
  btRigidBody* b = w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, at(1.5, 0.5, 0));
  for (btRigidBody* body : {a, b}) body->setAngularFactor(btVector3(0, 0, 0));
  w.addConstraint(
      std::make_unique<btGearConstraint>(*a, *b, btVector3(0, 1, 0), btVector3(0, 1, 0), 2.0));
  w.step(120);
  std::printf("[ figures ] %s: y %.6f %.6f\n", GetParam().c_str(), a->getCenterOfMassPosition().y(),
              b->getCenterOfMassPosition().y());
  EXPECT_NEAR(a->getCenterOfMassPosition().y(), 0.5, 0.02);
  EXPECT_NEAR(b->getCenterOfMassPosition().y(), 0.5, 0.02);
  const auto* st = statsOf(w);
  std::printf("[ figures ] %s: islands %d, fallbacks %d, failures %d, screened %s\n",
              GetParam().c_str(), st->islands, st->fallbacks, st->failures,
              st->screened.toString().c_str());
  EXPECT_EQ(st->failures, 0) << st->message;
  EXPECT_GT(st->screened.zeroDiagonal, 0);
}

// A rope bridge: 16 planks joined edge to edge by two btPoint2PointConstraint each (at both
// ends of the shared edge: 6 rows for 5 constrained directions, so A is singular but the rows
// are consistent), its ends pinned to the world the same way, a box dropped on it. Every
// island gets an answer with a small residual.
TEST_P(BulletDegenerateRows, RedundantBridgeIslandsAreAllSolved) {
  sc::World w(1.0 / 60.0);
  // The scene files' tolerance: the redundant rows disagree by their drift (~1e-8 of b), so
  // the default 1e-10 is out of reach for any answer.
  w.setSolver(solverNamed(GetParam(), 1e-6));
  w.info().m_globalCfm = 0;
  const int planks = 16;
  const double half = 0.25, depth = 0.5;
  std::vector<btRigidBody*> p;
  for (int i = 0; i < planks; ++i)
    p.push_back(w.addBox(btVector3(half, 0.05, depth), 1.0, at(2 * half * i, 5, 0)));
  for (double z : {-depth, depth}) {
    auto pin = [&](btRigidBody& body, const btVector3& pivot) {
      w.addConstraint(std::make_unique<btPoint2PointConstraint>(body, pivot));
    };
    pin(*p.front(), btVector3(-half, 0, z));
    pin(*p.back(), btVector3(half, 0, z));
    for (int i = 0; i + 1 < planks; ++i)
      w.addConstraint(std::make_unique<btPoint2PointConstraint>(
          *p[i], *p[i + 1], btVector3(half, 0, z), btVector3(-half, 0, z)));
  }
  w.addBox(btVector3(0.3, 0.3, 0.3), 2.0, at(2 * half * planks / 2, 6, 0));
  w.step(120);
  const auto* st = statsOf(w);
  std::printf(
      "[ figures ] %s: islands %d, fallbacks %d, failures %d, worst residual %.3g, %s, %s\n",
      GetParam().c_str(), st->islands, st->fallbacks, st->failures, st->residual,
      st->choices.toString().c_str(), st->message.c_str());
  // Every island answered by the solver asked for (none kept its start: "no impulses").
  EXPECT_EQ(st->choices.count(GetParam() == "auto" ? "pgs" : "none"), 0);
  if (GetParam() == "pgs") {
    // 1000 sweeps on a 16-plank chain: pgs' own accuracy, answered every step.
    EXPECT_EQ(st->choices.count("pgs"), st->islands);
    EXPECT_LT(st->residual, 0.1);
  } else {
    EXPECT_EQ(st->failures, 0) << st->message;
    EXPECT_LT(st->residual, 1e-5);
  }
  EXPECT_GT(p[planks / 2]->getCenterOfMassPosition().y(), 3.0);  // the bridge holds
}

INSTANTIATE_TEST_SUITE_P(Solvers, BulletDegenerateRows,
                         ::testing::Values("auto", "dantzig", "pgs"));

// A pile of Bullet's ragdolls (RagdollDemo's figure: capsules, cone-twist and hinge joints)
// falling onto each other, with dantzig and auto: every island is answered and every capsule
// stays above the ground.
TEST(BulletRagdollPile, EveryIslandAnswered) {
  for (const char* name : {"dantzig", "auto"}) {
    sc::World w(1.0 / 60.0);
    // Without a time budget: what the solvers answer, not what a machine's speed lets them
    // (budget-cut islands under a sanitizer build let capsules sink through the ground).
    Settings s;
    s.solver = name;
    s.options.tolerance = 1e-6;
    s.engineIterations = false;
    s.timeBudget = 0;
    w.setSolver(std::make_unique<ConstraintSolver>(s));
    sc::ragdollPile(w, 2, 2);
    w.step(120);
    const auto* st = statsOf(w);
    std::printf("[ figures ] %s: islands %d, fallbacks %d, failures %d, worst residual %.3g, %s\n",
                name, st->islands, st->fallbacks, st->failures, st->residual,
                st->choices.toString().c_str());
    EXPECT_EQ(st->choices.count("none"), 0);
    for (const btRigidBody* b : w.dynamicBodies())
      EXPECT_GT(b->getCenterOfMassPosition().y(), 0.0) << name;
  }
}

}  // namespace
