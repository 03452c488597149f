// The drop-in in Bullet's other worlds (mlcp/bullet/worlds.hpp): a btDiscreteDynamicsWorldMt
// hands its large islands to a second solver slot, which install() and SolverPool fill; a
// btMultiBodyDynamicsWorld never calls solveGroup: install() gives it the solver's
// MultiBodySolver (a pool is refused there), and a swap by hand throws at the first step; one
// solver shared by threads is serialized by its mutex.
#include "mlcp/bullet/worlds.hpp"

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolverMt.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "scenes.hpp"

namespace {

namespace sc = mlcp::bullet::scenes;
using mlcp::bullet::ConstraintSolver;
using mlcp::bullet::Settings;
using mlcp::bullet::SolverPool;
using mlcp::bullet::StepStats;

// Islands with this many manifolds go to the Mt world's large-island solver (Bullet's default
// is 250, a 960-box wall; the 55-box pyramid has ~150).
class SmallBatchingThreshold {
 public:
  explicit SmallBatchingThreshold(int manifolds)
      : saved_(btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching) {
    btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching = manifolds;
  }
  ~SmallBatchingThreshold() {
    btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching = saved_;
  }

 private:
  int saved_;
};

// A 55-box pyramid (one large island) and three lone boxes (small islands: the Mt world puts
// islands of fewer than 32 bodies into one batch island, so the pile has more).
void pileAndLoneBoxes(sc::World& w) {
  sc::pyramid(w, 55);
  btTransform pose;
  pose.setIdentity();
  for (int k = 0; k < 3; ++k) {
    pose.setOrigin(btVector3(20.0 + 3 * k, 0.5, 0));
    w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, pose);
  }
}

// pgs at Bullet's sweep count: the same rows in both worlds, fast.
Settings pgs() {
  Settings s;
  s.solver = "pgs";
  return s;
}

Settings exact() {
  Settings s;
  s.solver = "dantzig";
  return s;
}

TEST(BulletWorlds, MtWorldSolvesEveryIslandThroughThePoolInBothSlots) {
  SmallBatchingThreshold threshold(16);
  sc::World plain;
  plain.setSolver(std::make_unique<ConstraintSolver>(pgs()));
  auto* reference = static_cast<ConstraintSolver*>(plain.solver());
  sc::World mt(1.0 / 60.0, false, sc::WorldKind::DiscreteMt);
  auto owned = std::make_unique<SolverPool>(pgs(), 2);
  SolverPool* pool = owned.get();
  mt.setSolver(std::move(owned));
  mlcp::bullet::install(mt.world(), *pool);
  pileAndLoneBoxes(plain);
  pileAndLoneBoxes(mt);
  for (int i = 0; i < 5; ++i) {
    plain.step();
    mt.step();
    const StepStats& a = reference->lastStep();
    const StepStats& b = pool->lastStep();
    EXPECT_GT(a.rows, 0);
    EXPECT_EQ(b.rows, a.rows) << "step " << i;
    EXPECT_EQ(b.islands, a.islands) << "step " << i;    // the pyramid and the three boxes
    EXPECT_EQ(b.failures, a.failures) << "step " << i;  // fixed-sweep pgs misses 1e-3 on the pile
  }
  EXPECT_EQ(pool->totals().rows, reference->totals().rows);
  EXPECT_GE(pool->lastStep().groups, 2);  // the large island alone, the batched boxes
}

TEST(BulletWorlds, MtWorldSwappedBySetConstraintSolverMissesTheLargeIslandUntilInstalled) {
  SmallBatchingThreshold threshold(16);
  sc::World plain;
  plain.setSolver(std::make_unique<ConstraintSolver>(pgs()));
  auto* reference = static_cast<ConstraintSolver*>(plain.solver());
  sc::World mt(1.0 / 60.0, false, sc::WorldKind::DiscreteMt);
  mt.setSolver(std::make_unique<SolverPool>(pgs(), 1));  // the pool slot only
  auto* pool = static_cast<SolverPool*>(mt.solver());
  pileAndLoneBoxes(plain);
  pileAndLoneBoxes(mt);
  plain.step();
  mt.step();
  // The large-island slot's solver took the pyramid: only the lone boxes reached us.
  EXPECT_GT(pool->lastStep().rows, 0);
  EXPECT_LT(pool->lastStep().rows, reference->lastStep().rows / 4);
  EXPECT_EQ(pool->lastStep().islands, 3);

  mlcp::bullet::install(mt.world(), *pool);
  plain.step();
  mt.step();
  EXPECT_EQ(pool->lastStep().islands, reference->lastStep().islands);
  EXPECT_GT(pool->lastStep().rows, reference->lastStep().rows * 3 / 4);
}

TEST(BulletWorlds, OneSolverInstalledInAnMtWorldTakesBothSlots) {
  SmallBatchingThreshold threshold(16);
  sc::World mt(1.0 / 60.0, false, sc::WorldKind::DiscreteMt);
  mt.setSolver(std::make_unique<ConstraintSolver>(pgs()));
  auto* mine = static_cast<ConstraintSolver*>(mt.solver());
  mlcp::bullet::install(mt.world(), *mine);
  pileAndLoneBoxes(mt);
  mt.step(3);
  EXPECT_EQ(mine->lastStep().islands, 4);  // the pyramid and the three boxes
  EXPECT_GT(mine->lastStep().rows, 300);
}

TEST(BulletWorlds, PoolInAnMtWorldWithoutIslandsDoesNotThrow) {
  // A world of static bodies only has no island: the Mt world then calls no solveGroup.
  sc::World mt(1.0 / 60.0, false, sc::WorldKind::DiscreteMt);
  mt.setSolver(std::make_unique<SolverPool>(exact(), 1));
  mlcp::bullet::install(mt.world(), *static_cast<SolverPool*>(mt.solver()));
  mt.addGround();
  EXPECT_NO_THROW(mt.step(2));
}

TEST(BulletWorlds, MultiBodyWorldIsServedByInstall) {
  sc::World mb(1.0 / 60.0, false, sc::WorldKind::MultiBody);
  ConstraintSolver mine(exact());
  mlcp::bullet::install(mb.world(), mine);
  EXPECT_EQ(mb.world().getConstraintSolver(),
            static_cast<btConstraintSolver*>(&mine.multiBodySolver()));
  sc::stack(mb, 2);
  mb.step(5);
  EXPECT_GT(mine.lastStep().groups, 0);
  EXPECT_GT(mine.lastStep().islands, 0);
  EXPECT_EQ(mine.lastStep().status, mlcp::Status::Converged) << mine.lastStep().message;
  SolverPool pool(exact(), 1);
  try {
    mlcp::bullet::install(mb.world(), pool);
    FAIL() << "install put a pool in a btMultiBodyDynamicsWorld";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("btMultiBodyDynamicsWorld"), std::string::npos);
  }
}

TEST(BulletWorlds, MultiBodyWorldSwappedBySetConstraintSolverThrowsAtItsFirstStep) {
  sc::World mb(1.0 / 60.0, false, sc::WorldKind::MultiBody);
  mb.setSolver(std::make_unique<ConstraintSolver>(exact()));
  auto* mine = static_cast<ConstraintSolver*>(mb.solver());
  sc::stack(mb, 2);
  for (int k = 0; k < 2; ++k) {  // every step, not only the first
    try {
      mb.step();
      FAIL() << "a multibody world stepped silently past our solver";
    } catch (const std::logic_error& e) {
      EXPECT_NE(std::string(e.what()).find("mlcp::bullet::install"), std::string::npos);
    }
    EXPECT_EQ(mine->lastStep().groups, 0);
  }
}

TEST(BulletWorlds, PlainWorldPassesTheCheckWithAndWithoutDynamicBodies) {
  sc::World ground;
  ground.setSolver(std::make_unique<ConstraintSolver>(exact()));
  ground.addGround();
  EXPECT_NO_THROW(ground.step(3));  // Bullet calls solveGroup once a step even without rows
  sc::World stack;
  stack.setSolver(std::make_unique<ConstraintSolver>(exact()));
  sc::stack(stack, 3);
  EXPECT_NO_THROW(stack.step(30));
  EXPECT_GT(static_cast<ConstraintSolver*>(stack.solver())->totals().rows, 0);
}

TEST(BulletWorlds, OneSolverSteppedFromTwoThreadsAtOnceMatchesSteppedAlone) {
  // Two worlds stepped concurrently share one solver: its mutex serializes their groups, and
  // each world moves as it does with a solver of its own (without the mutex the two groups'
  // rows mix in the solver's pools: the piles blow up or drift apart).
  const auto pile = [](sc::World& w) {
    w.info().m_minimumSolverBatchSize = 1;  // a solveGroup call per island: many calls a step
    for (int k = 0; k < 6; ++k) {
      btTransform pose;
      pose.setIdentity();
      for (int level = 0; level < 3; ++level) {
        pose.setOrigin(btVector3(3.0 * k, 0.5 + level, 0));
        w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, pose);
      }
    }
    w.addGround();
  };
  // No warm start: a solver's per-point memory is one per solver, and two worlds interleaving
  // their steps would each start from answers the other's steps left (see worlds.hpp).
  Settings settings = pgs();
  settings.warmStart = false;
  sc::World alone;
  alone.setSolver(std::make_unique<ConstraintSolver>(settings));
  pile(alone);
  sc::World a, b;
  ConstraintSolver shared(settings);
  for (sc::World* w : {&a, &b}) {
    pile(*w);
    mlcp::bullet::install(w->world(), shared);
  }
  const int steps = 300;
  alone.step(steps);
  std::thread ta([&] { a.step(steps); });
  std::thread tb([&] { b.step(steps); });
  ta.join();
  tb.join();
  for (std::size_t k = 0; k < alone.dynamicBodies().size(); ++k) {
    const btVector3 p = alone.dynamicBodies()[k]->getCenterOfMassPosition();
    for (sc::World* w : {&a, &b})
      EXPECT_LT((w->dynamicBodies()[k]->getCenterOfMassPosition() - p).length(), 1e-3) << k;
  }
}

}  // namespace
