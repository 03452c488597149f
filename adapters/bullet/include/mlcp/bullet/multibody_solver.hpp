// mlcp/bullet/multibody_solver.hpp: the drop-in for btMultiBodyDynamicsWorld (and
// btSoftMultiBodyDynamicsWorld), which solve through a btMultiBodyConstraintSolver.
//
//     mlcp::bullet::ConstraintSolver solver(settings);
//     mlcp::bullet::install(*multiBodyWorld, solver);   // mlcp/bullet/worlds.hpp
//     ...
//     solver.lastStep();                                 // this solver's islands
//
// install() puts the ConstraintSolver's MultiBodySolver in the world
// (setMultiBodyConstraintSolver); it shares the ConstraintSolver's settings, island solver and
// statistics, so lastStep() and totals() report the multibody world's islands.
//
// One group, by stages:
//  1. prepare rows: Bullet's own setup (btMultiBodyConstraintSolver::solveGroupCacheFriendlySetup:
//     rigid joints and contacts, multibody constraints, limits and motors, multibody contacts with
//     their lateral, torsional and spinning friction);
//  2. islands: connected components over rigid bodies and multibodies, every pool's rows in one
//     problem per island, rigid and multibody rows coupled (adapters/bullet/src/
//     multibody_islands.hpp has the conversion);
//  3.-4. rows to w = A x + b with per-row CFM kept (as the rigid drop-in: m_cfm / m_jacDiagABInv,
//     CfmModel), warm start from last step's impulses (Settings::warmStart);
//  5.-6. solve and check: the rigid drop-in's mlcp::RowSolver (any core solver, "auto", "pgs" on
//     the rows through J and W);
//  7. store impulses: x - applied through applyDeltaVee / applyDeltaVeeMultiDof2 and the rigid
//     bodies' own update, as Bullet's resolveSingleConstraintRowGeneric applies a row; Bullet's
//     finish writes joint feedback, contact impulses and velocities.
// Split impulse: Bullet's own push iterations run on the rigid contacts (the only rows they
// serve); a multibody row's positional error that split impulse sets apart, which Bullet drops,
// is put back by Settings::multiBodyPositionCorrection (settings.hpp, default on; it also keeps
// a joint limit's row alive at rest). "si" runs Bullet's own iterations, with the same
// statistics.
// Differences from Bullet's solver it replaces: friction is a box per direction (findex), not
// the implicit cone resolveConeFrictionConstraintRows projects a lateral pair on; rows on
// different islands never share a problem. Cost: Bullet's setup and finish, O(rows + nnz J) for
// the islands, then the chosen solver's.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>

#include <memory>

#include "mlcp/problem.hpp"

namespace mlcp::bullet {

class ConstraintSolver;
namespace detail {
class MultiBodyIslands;
}

class MultiBodySolver : public btMultiBodyConstraintSolver {
 public:
  // Made by ConstraintSolver::multiBodySolver(); owner outlives it (it owns it).
  explicit MultiBodySolver(ConstraintSolver& owner);
  ~MultiBodySolver() override;

  ConstraintSolver& owner() { return owner_; }

  // Serialized by the owner's mutex; the step brackets are the owner's.
  void solveMultiBodyGroup(btCollisionObject** bodies, int numBodies,
                           btPersistentManifold** manifolds, int numManifolds,
                           btTypedConstraint** constraints, int numConstraints,
                           btMultiBodyConstraint** multiBodyConstraints,
                           int numMultiBodyConstraints, const btContactSolverInfo& info,
                           btIDebugDraw* debugDrawer, btDispatcher* dispatcher) override;
  void prepareSolve(int numBodies, int numManifolds) override;
  void allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override;

 protected:
  btScalar solveGroupCacheFriendlyIterations(btCollisionObject** bodies, int numBodies,
                                             btPersistentManifold** manifolds, int numManifolds,
                                             btTypedConstraint** constraints, int numConstraints,
                                             const btContactSolverInfo& info,
                                             btIDebugDraw* debugDrawer) override;

 private:
  // Builds the islands of the group's pools (start: as Settings asks).
  void buildIslands(const btContactSolverInfo& info, bool siAnswer);

  ConstraintSolver& owner_;
  std::unique_ptr<detail::MultiBodyIslands> islands_;
  Vector x_;
};

}  // namespace mlcp::bullet
