// mlcp/bullet/constraint_solver.hpp: any core solver as a drop-in btConstraintSolver.
//
//     mlcp::bullet::Settings s;
//     s.solver = "dantzig";                       // any mlcp::makeSolver name, or "si"
//     auto solver = std::make_unique<mlcp::bullet::ConstraintSolver>(s);
//     world->setConstraintSolver(solver.get());   // a stock btDiscreteDynamicsWorld
//     ...
//     const mlcp::bullet::StepStats& st = solver->lastStep();
//
// One solveGroup call, by stages (Box2D v3's names; docs/methods/adapters.md, "Bullet: the
// drop-in's stages", has each in full, with the map from Bullet's rows to the canonical form
// of core/include/mlcp/problem.hpp):
//  1. prepare rows: Bullet's own sequential-impulse (SI) setup, inherited from
//     btSequentialImpulseConstraintSolver as btMLCPSolver does;
//  2. islands: the group split into connected components of the dynamic-body graph
//     (mlcp/bullet/islands.hpp), undoing Bullet's merging of small islands;
//  3. rows to w = A x + b: b = -m_rhs / m_jacDiagABInv, cfm = m_cfm / m_jacDiagABInv (CfmModel),
//     contacts [0, inf), friction [-mu, mu] with findex its contact row;
//  4. warm start: last step's impulses, then our own last answer per manifold point;
//  5.-6. solve and check: mlcp::RowSolver (mlcp/island/row_solver.hpp), shared with the ODE
//     adapter: the named solver or auto's choice, the answer verified by its recomputed
//     residual, the fallback run on a rejected one;
//  7. store impulses: x - appliedImpulse through btSolverBody::internalApplyImpulse; SI's finish
//     writes contact impulses, joint feedback, breaking thresholds, velocities and transforms.
// With split impulse on and a non-zero penetration rhs, a second problem with the same A and
// b = -m_rhsPenetration / m_jacDiagABInv gives the push impulses.
//
// "pgs" islands are packed in place from Bullet's rows and written back per body (the same
// page, "Bullet: the pgs path"): the iterates are RowSolver's pgs bit for bit; an island whose
// linear or angular factors Bullet's body update treats differently is written back row by row.
// "si" runs Bullet's own iterations, with the same statistics.
//
// Limits. A btMultiBodyDynamicsWorld never calls solveGroup: it solves through the
// MultiBodySolver install() gives it (mlcp/bullet/multibody_solver.hpp). A world that steps
// without calling solveGroup makes allSolved throw std::logic_error, so a swap by hand that does
// nothing never goes unnoticed (install() and SolverPool members skip the check; the same page,
// "Bullet: worlds served"). solveGroup,
// prepareSolve and allSolved hold a mutex: one instance solves one group at a time; for parallel
// groups give each thread its own (SolverPool). The warm-start memory is the instance's: one
// solver per world.
// Cost: the setup and finish are SI's; ours adds O(rows) passes (split, packing, check,
// write-back) and saves on each sweep (docs/benchmarks.md, "Bullet: our pgs against SI at
// equal sweep counts").
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mlcp/bullet/islands.hpp"
#include "mlcp/bullet/settings.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"

class btDiscreteDynamicsWorld;

namespace mlcp::bullet {

class SolverPool;
class ConstraintSolver;
class MultiBodySolver;
// Puts the solver in every solver slot of the world, or refuses the world (mlcp/bullet/worlds.hpp).
void install(btDiscreteDynamicsWorld& world, ConstraintSolver& solver);

class ConstraintSolver : public btSequentialImpulseConstraintSolver {
 public:
  // Throws std::invalid_argument with the list of valid names for an unknown solver/fallback.
  explicit ConstraintSolver(const Settings& settings = Settings());
  ~ConstraintSolver() override;

  const Settings& settings() const { return settings_; }

  const StepStats& lastStep() const { return last_; }
  // Sums over all steps so far (residual/status: worst seen).
  const StepStats& totals() const { return totals_; }
  // With Settings::keepIslands: the problems of the last step.
  const std::vector<IslandRecord>& islands() const { return records_; }
  // The shared island solver (null with "si"): its capture hook writes each island's problem
  // ("pgs" islands go through it while a capture is set: the capture needs the RowSystem).
  RowSolver* rowSolver() { return rows_.get(); }
  // The drop-in for multibody worlds (multibody_solver.hpp), made on first use, owned here; it
  // solves with this solver's settings and island solver into lastStep(). install() sets it.
  MultiBodySolver& multiBodySolver();

  // Serialized by the solver's mutex (see "Limits" above).
  btScalar solveGroup(btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds,
                      int numManifolds, btTypedConstraint** constraints, int numConstraints,
                      const btContactSolverInfo& info, btIDebugDraw* debugDrawer,
                      btDispatcher* dispatcher) override;
  void prepareSolve(int numBodies, int numManifolds) override;
  // Throws std::logic_error when the world does not call solveGroup (see "Limits" above).
  void allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override;

 protected:
  btScalar solveGroupCacheFriendlyIterations(btCollisionObject** bodies, int numBodies,
                                             btPersistentManifold** manifolds, int numManifolds,
                                             btTypedConstraint** constraints, int numConstraints,
                                             const btContactSolverInfo& info,
                                             btIDebugDraw* debugDrawer) override;

 private:
  void solveIsland(Island& island, std::uint64_t key, bool split);
  // "pgs" packed straight from Bullet's rows and written back per body; false when the answer
  // is not finite, or was not accepted and rows_ has a fallback (the island then goes through
  // rows_ like every other solver).
  bool solveIslandFast(Island& island, bool split);
  // Store impulses row by row through Bullet's own body update (internalApplyImpulse or
  // internalApplyPushImpulse with x - applied), and set the applied impulses to x.
  void applyPerRow(Island& island, const Vector& x, bool split);
  void measureSi(int sweeps);
  // One island's statistics into the step: SI's answer (its residual measured), or RowSolver's.
  void recordSi(const RowSystem& s, const Vector& answer, int sweeps);
  void recordSolve(const IslandSolve& solved, int rows);
  void record(const Result& r, int rows, const std::string& choice);
  // RowSolver told the engine's sweep count; pgs/gs run it under Settings::engineIterations.
  void useEngineSweeps(const btContactSolverInfo& info);
  // prepareSolve's and allSolved's work, with the mutex held by the caller.
  void openStep(int numBodies);
  void finishStep();
  // The world check of "Limits": throws once the world has stepped without solveGroup.
  void checkWorld();

  friend class SolverPool;
  friend class MultiBodySolver;
  friend void install(btDiscreteDynamicsWorld& world, ConstraintSolver& solver);

  Settings settings_;
  std::unique_ptr<RowSolver> rows_;
  bool si_ = false;
  // "pgs" islands skip the RowSystem copy and RowSolver (solver "pgs", packInPlace, no
  // keepIslands, no capture); same iterates, same verification rule (acceptable()).
  bool fastPgs_ = false;
  RowPgs pgs_;
  IslandBuilder builder_;
  StepStats current_, last_, totals_;
  bool stepOpen_ = false;
  std::vector<IslandRecord> records_;
  Vector x_;
  std::mutex mutex_;
  int stepBodies_ = 0;         // prepareSolve's numBodies of the open step
  bool worldChecked_ = false;  // the check ran (or install()/SolverPool made it unneeded)
  bool unserved_ = false;      // the world stepped without calling solveGroup
  std::unique_ptr<MultiBodySolver> multiBody_;
};

}  // namespace mlcp::bullet
