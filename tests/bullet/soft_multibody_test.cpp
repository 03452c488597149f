// install() in a btSoftMultiBodyDynamicsWorld (pybullet's world): it derives from
// btMultiBodyDynamicsWorld and takes the solver's MultiBodySolver the same way; the deformable
// world is refused (its solver also solves the deformable bodies).
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btSoftMultiBodyDynamicsWorld.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "mlcp/bullet/worlds.hpp"
#include "multibody_chain.hpp"

namespace {

btMultiBodyDynamicsWorld* softWorld(btDispatcher* d, btBroadphaseInterface* b,
                                    btMultiBodyConstraintSolver* s, btCollisionConfiguration* c) {
  return new btSoftMultiBodyDynamicsWorld(d, b, s, c);
}

TEST(BulletSoftMultiBody, SoftMultiBodyWorldIsServed) {
  mlcp_test::Chain chain(true, -1.0, nullptr, softWorld);
  ASSERT_EQ(chain.world().getWorldType(), BT_SOFT_MULTIBODY_DYNAMICS_WORLD);
  mlcp::bullet::Settings s;
  s.solver = "dantzig";
  mlcp::bullet::ConstraintSolver solver(s);
  mlcp::bullet::install(chain.world(), solver);
  EXPECT_TRUE(std::isfinite(chain.step(120)));
  EXPECT_GT(solver.totals().islands, 0);
  EXPECT_EQ(solver.totals().failures, 0) << solver.totals().message;
}

TEST(BulletSoftMultiBody, DeformableWorldIsRefused) {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btDeformableMultiBodyConstraintSolver deformable;
  btDeformableMultiBodyDynamicsWorld world(&dispatcher, &broadphase, &deformable, &config);
  mlcp::bullet::ConstraintSolver solver;
  try {
    mlcp::bullet::install(world, solver);
    FAIL() << "install replaced a deformable world's solver";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("btDeformableMultiBodyDynamicsWorld"), std::string::npos);
  }
}

}  // namespace
