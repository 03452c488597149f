#include "mlcp/bullet/multibody_solver.hpp"

#include <mutex>

#include "mlcp/bullet/constraint_solver.hpp"
#include "multibody_islands.hpp"

namespace mlcp::bullet {

MultiBodySolver::MultiBodySolver(ConstraintSolver& owner)
    : owner_(owner), islands_(std::make_unique<detail::MultiBodyIslands>()) {}

MultiBodySolver::~MultiBodySolver() = default;

void MultiBodySolver::solveMultiBodyGroup(btCollisionObject** bodies, int numBodies,
                                          btPersistentManifold** manifolds, int numManifolds,
                                          btTypedConstraint** constraints, int numConstraints,
                                          btMultiBodyConstraint** multiBodyConstraints,
                                          int numMultiBodyConstraints,
                                          const btContactSolverInfo& info,
                                          btIDebugDraw* debugDrawer, btDispatcher* dispatcher) {
  std::lock_guard<std::mutex> lock(owner_.mutex_);
  btMultiBodyConstraintSolver::solveMultiBodyGroup(
      bodies, numBodies, manifolds, numManifolds, constraints, numConstraints, multiBodyConstraints,
      numMultiBodyConstraints, info, debugDrawer, dispatcher);
}

void MultiBodySolver::prepareSolve(int numBodies, int numManifolds) {
  std::lock_guard<std::mutex> lock(owner_.mutex_);
  btMultiBodyConstraintSolver::prepareSolve(numBodies, numManifolds);
  owner_.openStep(numBodies);
}

void MultiBodySolver::allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) {
  std::lock_guard<std::mutex> lock(owner_.mutex_);
  btMultiBodyConstraintSolver::allSolved(info, debugDrawer);
  if (owner_.stepOpen_) owner_.finishStep();
}

void MultiBodySolver::buildIslands(const btContactSolverInfo& info, bool siAnswer) {
  const Settings& s = owner_.settings_;
  const Start start = siAnswer || s.siStart ? Start::AppliedImpulse
                      : s.warmStart         ? Start::CachedImpulse
                                            : Start::Zero;
  detail::MultiBodyPools pools;
  pools.rigid = {&m_tmpSolverBodyPool, &m_tmpSolverNonContactConstraintPool,
                 &m_tmpSolverContactConstraintPool, &m_tmpSolverContactFrictionConstraintPool,
                 &m_tmpSolverContactRollingFrictionConstraintPool};
  pools.nonContact = &m_multiBodyNonContactConstraints;
  pools.normal = &m_multiBodyNormalContactConstraints;
  pools.lateral = &m_multiBodyFrictionContactConstraints;
  pools.torsional = &m_multiBodyTorsionalFrictionContactConstraints;
  pools.spinning = &m_multiBodySpinningFrictionContactConstraints;
  pools.data = &m_data;
  islands_->build(pools, info, s, start);
  owner_.current_.inertRows += islands_->inertRows();
}

btScalar MultiBodySolver::solveGroupCacheFriendlyIterations(
    btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds, int numManifolds,
    btTypedConstraint** constraints, int numConstraints, const btContactSolverInfo& info,
    btIDebugDraw* debugDrawer) {
  ConstraintSolver& o = owner_;
  // A caller that does not bracket steps with prepareSolve/allSolved gets one step per group.
  const bool ownStep = !o.stepOpen_;
  if (ownStep) o.openStep(numBodies);
  o.current_.groups += 1;
  const double t0 = nowSeconds();
  if (o.si_) {
    // SI's iterations, which call this class's (Bullet's) multibody solveSingleIteration.
    btMultiBodyConstraintSolver::solveGroupCacheFriendlyIterations(
        bodies, numBodies, manifolds, numManifolds, constraints, numConstraints, info, debugDrawer);
    o.current_.seconds += nowSeconds() - t0;
    if (o.settings_.measureSi || o.settings_.keepIslands) {
      const double t1 = nowSeconds();
      buildIslands(info, true);
      for (int k = 0; k < islands_->count(); ++k) {
        const detail::MultiBodyIsland& island = islands_->island(k);
        o.recordSi(island.system, island.start, info.m_numIterations);
      }
      o.current_.measureSeconds += nowSeconds() - t1;
    } else {
      o.current_.residual = kNotComputed;
      o.current_.status = Status::MaxIterations;
    }
  } else {
    // The push impulses of split impulse: Bullet's own iterations on the rigid contacts.
    solveGroupCacheFriendlySplitImpulseIterations(bodies, numBodies, manifolds, numManifolds,
                                                  constraints, numConstraints, info, debugDrawer);
    o.useEngineSweeps(info);
    buildIslands(info, false);
    for (int k = 0; k < islands_->count(); ++k) {
      detail::MultiBodyIsland& island = islands_->island(k);
      const IslandSolve solved = o.rows_->solve(island.system, island.start, x_, k);
      o.recordSolve(solved, island.system.size());
      islands_->writeBack(island, x_);
      if (o.settings_.keepIslands)
        o.records_.push_back({island.system, island.start, x_, solved.result, solved.choice, false,
                              solved.fellBack});
    }
    o.current_.seconds += nowSeconds() - t0;
  }
  if (ownStep) o.finishStep();
  return 0;
}

}  // namespace mlcp::bullet
