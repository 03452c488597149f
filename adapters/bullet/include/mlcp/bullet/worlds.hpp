// mlcp/bullet/worlds.hpp: the drop-in in every kind of Bullet world, or a clear refusal.
//
//     mlcp::bullet::install(*multiBodyWorld, solver);  // btMultiBodyDynamicsWorld: the solver's
//                                                       // MultiBodySolver, lastStep() as above
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
// Which world reaches what (Bullet 3.24; each in full in docs/methods/adapters.md, "Bullet:
// worlds served"):
// - btDiscreteDynamicsWorld: setConstraintSolver reaches every solveGroup call.
// - btDiscreteDynamicsWorldMt: besides its btConstraintSolverPoolMt slot it hands every island of
//   at least 250 manifolds (s_minimumContactManifoldsForBatching) to a second solver, a protected
//   member without a setter; install() fills both slots, so every island reaches the pool or
//   solver given. Its members still see merged groups and split them into connected components.
// - btMultiBodyDynamicsWorld and btSoftMultiBodyDynamicsWorld solve every island through a
//   btMultiBodyConstraintSolver (setConstraintSolver does not reach it): install() sets the
//   ConstraintSolver's MultiBodySolver there (multibody_solver.hpp); a ConstraintSolver set by
//   hand with setConstraintSolver throws from allSolved at the first step. A pool is refused
//   there (the world solves its islands on one solver), and so is
//   btDeformableMultiBodyDynamicsWorld (its solver also solves the deformable bodies).
//
// Threads. Debian's Bullet 3.24 is built without BT_THREADSAFE: btParallelFor runs on the
// calling thread and every call takes member 0. Under a user's own threaded btITaskScheduler the
// members race on Bullet's no-op locks, but each ConstraintSolver holds its own mutex, so a member
// called from two threads solves one group after the other. A Bullet built thread-safe gives each
// thread its own member.
//
// Warm start in a pool: each member remembers the answers of the islands it solved; an island
// solved by another member than last step starts from Bullet's cached impulses instead.
#pragma once

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorldMt.h>

#include <vector>

#include "mlcp/bullet/constraint_solver.hpp"
#include "mlcp/bullet/multibody_solver.hpp"

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
// setConstraintSolver, and for a btDiscreteDynamicsWorldMt also its large-island slot; in a
// btMultiBodyDynamicsWorld (or a world derived from it) the solver's MultiBodySolver, by
// setMultiBodyConstraintSolver. Throws std::invalid_argument for a deformable world, and for a
// pool in a multibody world. A single ConstraintSolver in a btDiscreteDynamicsWorldMt serializes
// the parallel part (its mutex); a SolverPool solves it in parallel where Bullet is thread-safe.
void install(btDiscreteDynamicsWorld& world, ConstraintSolver& solver);
void install(btDiscreteDynamicsWorld& world, SolverPool& pool);

}  // namespace mlcp::bullet
