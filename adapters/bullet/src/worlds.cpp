#include "mlcp/bullet/worlds.hpp"

#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <LinearMath/btThreads.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace mlcp::bullet {

namespace {

// btDiscreteDynamicsWorldMt's large-island slot is protected and has no setter: a pointer to
// the member, formed in a derived class (where it is accessible), reaches it on any world.
struct MtSlot : btDiscreteDynamicsWorldMt {
  static btConstraintSolver* btDiscreteDynamicsWorldMt::*slot() {
    return &MtSlot::m_constraintSolverMt;
  }
};

// Throws for the worlds that never call solveGroup; sets the solver in every slot otherwise.
void setEverySlot(btDiscreteDynamicsWorld& world, btConstraintSolver& solver) {
  if (dynamic_cast<btMultiBodyDynamicsWorld*>(&world))
    throw std::invalid_argument(
        "mlcp::bullet::install: a btMultiBodyDynamicsWorld solves every island through its "
        "btMultiBodyConstraintSolver and never calls a btConstraintSolver's solveGroup: "
        "multibody worlds are not supported (keep Bullet's solver there)");
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
  setEverySlot(world, solver);
  std::lock_guard<std::mutex> lock(solver.mutex_);
  solver.worldChecked_ = true;  // a world this function accepts calls solveGroup
}

void install(btDiscreteDynamicsWorld& world, SolverPool& pool) { setEverySlot(world, pool); }

}  // namespace mlcp::bullet
