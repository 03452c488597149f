#include "mlcp/bullet/worlds.hpp"

#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <LinearMath/btThreads.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "mlcp/bullet/multibody_solver.hpp"

namespace mlcp::bullet {

namespace {

// btDiscreteDynamicsWorldMt's large-island slot is protected and has no setter: a pointer to
// the member, formed in a derived class (where it is accessible), reaches it on any world.
struct MtSlot : btDiscreteDynamicsWorldMt {
  static btConstraintSolver* btDiscreteDynamicsWorldMt::*slot() {
    return &MtSlot::m_constraintSolverMt;
  }
};

// The multibody world this world is, or null; throws for the deformable world, whose solver
// (btDeformableMultiBodyConstraintSolver) also solves the deformable bodies' rows.
btMultiBodyDynamicsWorld* multiBodyWorld(btDiscreteDynamicsWorld& world) {
  if (world.getWorldType() == BT_DEFORMABLE_MULTIBODY_DYNAMICS_WORLD)
    throw std::invalid_argument(
        "mlcp::bullet::install: a btDeformableMultiBodyDynamicsWorld solves its deformable "
        "bodies in its own btDeformableMultiBodyConstraintSolver, which this library does not "
        "replace (keep Bullet's solver there)");
  return dynamic_cast<btMultiBodyDynamicsWorld*>(&world);
}

// Sets the solver in every slot of a rigid-body world.
void setEverySlot(btDiscreteDynamicsWorld& world, btConstraintSolver& solver) {
  world.setConstraintSolver(&solver);
  if (auto* mt = dynamic_cast<btDiscreteDynamicsWorldMt*>(&world)) mt->*MtSlot::slot() = &solver;
}

}  // namespace

int SolverPool::defaultCount() {
  const btITaskScheduler* scheduler = btGetTaskScheduler();
  return scheduler && scheduler->getNumThreads() > 0 ? scheduler->getNumThreads() : 1;
}

SolverPool::Members SolverPool::makeMembers(const Settings& settings, int count) {
  if (count < 1)
    throw std::invalid_argument("mlcp::bullet::SolverPool: count must be >= 1, not " +
                                std::to_string(count));
  std::vector<std::unique_ptr<ConstraintSolver>> made;
  for (int k = 0; k < count; ++k) made.push_back(std::make_unique<ConstraintSolver>(settings));
  Members m;
  for (auto& solver : made) {
    solver->worldChecked_ = true;  // the pool's world calls the pool, not its members
    m.ours.push_back(solver.get());
    m.base.push_back(solver.release());
  }
  return m;
}

SolverPool::SolverPool(const Settings& settings, int count)
    : SolverPool(makeMembers(settings, count)) {}

SolverPool::SolverPool(Members members)
    : btConstraintSolverPoolMt(members.base.data(), static_cast<int>(members.base.size())),
      members_(std::move(members.ours)) {}

SolverPool::~SolverPool() = default;

void SolverPool::prepareSolve(int numBodies, int numManifolds) {
  for (ConstraintSolver* m : members_) m->prepareSolve(numBodies, numManifolds);
}

void SolverPool::allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) {
  last_ = StepStats();
  for (ConstraintSolver* m : members_) {
    m->allSolved(info, debugDrawer);
    accumulate(last_, m->lastStep());
  }
  accumulate(totals_, last_);
}

void install(btDiscreteDynamicsWorld& world, ConstraintSolver& solver) {
  btMultiBodyDynamicsWorld* multiBody = multiBodyWorld(world);
  MultiBodySolver* served = nullptr;
  {
    std::lock_guard<std::mutex> lock(solver.mutex_);
    solver.worldChecked_ = true;  // a world this function accepts calls a solver it installs
    if (multiBody) served = &solver.multiBodySolver();
  }
  if (served)
    multiBody->setMultiBodyConstraintSolver(served);  // its rigid slot too (the same object)
  else
    setEverySlot(world, solver);
}

void install(btDiscreteDynamicsWorld& world, SolverPool& pool) {
  if (multiBodyWorld(world))
    throw std::invalid_argument(
        "mlcp::bullet::install: a btMultiBodyDynamicsWorld solves its islands one after the other "
        "through one btMultiBodyConstraintSolver: install a ConstraintSolver there, not a pool");
  setEverySlot(world, pool);
}

}  // namespace mlcp::bullet
