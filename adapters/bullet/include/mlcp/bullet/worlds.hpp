// mlcp/bullet/worlds.hpp: the drop-in in every kind of Bullet world, or a clear refusal.
//
//     mlcp::bullet::ConstraintSolver solver(settings);
//     mlcp::bullet::install(*world, solver);        // btDiscreteDynamicsWorld: the same as
//                                                   // world->setConstraintSolver(&solver)
//
//     auto pool = std::make_unique<mlcp::bullet::SolverPool>(settings);    // one per thread
//     auto* world = new btDiscreteDynamicsWorldMt(dispatcher, broadphase, pool.get(),
//                                                 pool.get(), config);     // both slots
//     // (or install(*world, *pool) on a world built with other solvers)
//     pool->lastStep();                             // every island of the step, all members
//
// Which world calls what (Bullet 3.24, btDiscreteDynamicsWorldMt.cpp and
// btSimulationIslandManagerMt.cpp):
// - btDiscreteDynamicsWorld: prepareSolve, solveGroup per island batch (islands below
//   m_minimumSolverBatchSize merged; ConstraintSolver splits them again), one more solveGroup
//   for what was deferred, allSolved. setConstraintSolver reaches everything.
// - btDiscreteDynamicsWorldMt: its constructor takes a btConstraintSolverPoolMt (the
//   m_constraintSolver slot: prepareSolve and allSolved, and the islands solved in parallel,
//   each by a pool member locked for the call) and a "constraintSolverMt" (a protected member
//   without a setter): btSimulationIslandManagerMt::parallelIslandDispatch hands every island
//   with at least btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching
//   manifolds (default 250) to that second solver, one at a time, before the parallel part; the
//   serial dispatch and the unsplit path give it everything. Bullet's demos pass a
//   btSequentialImpulseConstraintSolverMt there: with setConstraintSolver(&ours) alone their
//   960-box walls never reach our solver. install() fills both slots; the pool passed as both
//   is what every island goes to. The world puts every island of fewer than 32 bodies
//   (m_batchIslandMinBodyCount, no setter) into one batch island, and merges islands whose batch
//   cost (bodies + 8 manifolds + 4 constraints) is below m_minimumSolverBatchSize (taken from
//   btContactSolverInfo at construction, 128): a member sees merged groups and splits them into
//   connected components as in the plain world. (Debian's btSequentialImpulseConstraintSolverMt,
//   built without BT_THREADSAFE, crashed in btBatchedConstraints::setup on a 55-box pyramid
//   with the batching threshold lowered to 16 manifolds.)
// - btMultiBodyDynamicsWorld (and the soft/deformable multibody worlds derived from it):
//   setConstraintSolver keeps its btMultiBodyConstraintSolver for every island (the island
//   callback holds it) unless the new solver is of type BT_MULTIBODY_SOLVER; it calls only
//   prepareSolve and allSolved on ours. Not supported: install() throws, and a ConstraintSolver
//   set there by hand throws from allSolved at the first step (constraint_solver.hpp, "Worlds
//   served").
//
// Debian's Bullet 3.24 is built without BT_THREADSAFE: btCreateDefaultTaskScheduler returns
// null, only the sequential task scheduler exists, btParallelFor runs on the calling thread,
// and the pool's spin mutexes do nothing (every call takes member 0). A user's own
// btITaskScheduler can still run btParallelFor on several threads: the pool's members then race
// on Bullet's no-op locks, but each ConstraintSolver holds its own mutex, so a member called
// from two threads at once solves one group after the other. A Bullet built thread-safe gives
// each thread its own member (btGetCurrentThreadIndex() % size()).
//
// Warm start in a pool: each member remembers the answers of the islands it solved
// (IslandBuilder::remember); an island solved by another member than last step starts from
// Bullet's cached impulses instead (what the plain world does for a point without a remembered
// answer). Exact solvers do not depend on the start.
#pragma once

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorldMt.h>

#include <vector>

#include "mlcp/bullet/constraint_solver.hpp"

class btDiscreteDynamicsWorld;

namespace mlcp::bullet {

// A btConstraintSolverPoolMt of ConstraintSolvers with the same settings, whose step statistics
// are the sum over its members. Give it both slots of a btDiscreteDynamicsWorldMt.
class SolverPool : public btConstraintSolverPoolMt {
 public:
  // `count` members (>= 1; default: the task scheduler's thread count, 1 without one). Throws
  // std::invalid_argument as ConstraintSolver does, and for count < 1.
  explicit SolverPool(const Settings& settings = Settings(), int count = defaultCount());
  ~SolverPool() override;  // the base deletes the members

  static int defaultCount();
  int size() const { return static_cast<int>(members_.size()); }
  ConstraintSolver& member(int k) { return *members_[k]; }

  // Forwarded to every member (the world calls them on the pool only); allSolved then sums the
  // members' steps into lastStep() and totals().
  void prepareSolve(int numBodies, int numManifolds) override;
  void allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override;

  const StepStats& lastStep() const { return last_; }
  const StepStats& totals() const { return totals_; }

 private:
  struct Members {
    std::vector<ConstraintSolver*> ours;
    std::vector<btConstraintSolver*> base;
  };
  static Members makeMembers(const Settings& settings, int count);
  SolverPool(Members members);

  std::vector<ConstraintSolver*> members_;  // owned by the base
  StepStats last_, totals_;
};

// Puts the solver (or pool) in every solver slot of the world so that every island reaches it:
// setConstraintSolver, and for a btDiscreteDynamicsWorldMt also its large-island slot. Throws
// std::invalid_argument for a btMultiBodyDynamicsWorld (or a world derived from it), which would
// never call it. A single ConstraintSolver in a btDiscreteDynamicsWorldMt serializes the
// parallel part (its mutex); a SolverPool solves it in parallel where Bullet is thread-safe.
void install(btDiscreteDynamicsWorld& world, ConstraintSolver& solver);
void install(btDiscreteDynamicsWorld& world, SolverPool& pool);

}  // namespace mlcp::bullet
