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
// Limits. A btMultiBodyDynamicsWorld never calls solveGroup: a world that steps without it makes
// allSolved throw std::logic_error, so the swap never silently does nothing (install() and
// SolverPool members skip the check; the same page, "Bullet: worlds served"). solveGroup,
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
#include "mlcp/island/row_solver.hpp"
#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"

class btDiscreteDynamicsWorld;

namespace mlcp::bullet {

// How the diagonal regularisation (CFM) of each row is taken.
enum class CfmModel {
  // cfm_i = m_cfm / m_jacDiagABInv: what Bullet's SI iteration converges to (contacts
  // globalCfm / dt, friction 0, joints their own CFM times A_ii). With several contacts on one
  // face the friction rows are linearly dependent (4 contacts: 8 rows for 3 tangential degrees
  // of freedom), so A has singular principal blocks and pivoting methods can fail on it.
  Engine,
  // Engine, except that friction rows without a CFM of their own take their contact's,
  // globalCfm / dt, as ODE does for every row: the redundant friction rows of a resting box
  // become a regular problem (answers move by O(cfm) impulse). The default.
  Regularized,
  // globalCfm / dt on every row, per-row CFM ignored: what the stock btMLCPSolver assembles. Only
  // for diffing against stock.
  StockMlcp,
};

// The island solver's settings (mlcp::RowSolverSettings: solver "auto", options with tolerance
// 1e-6, fallback "pgs" with at most 100 sweeps, acceptResidual 1e-3, denseAssemblyMaxRows 64,
// engineIterations; documented in mlcp/island/row_solver.hpp, the shape the ODE adapter's settings
// share), plus Bullet's own. `solver` may also be "si": Bullet's own sequential impulse
// iterations. engineIterations (default true) gives pgs/gs btContactSolverInfo::m_numIterations
// sweeps, as SI and the stock MLCP solvers run. options.warmStart is governed by warmStart below.
struct Settings : RowSolverSettings {
  // Start every solve from last step's impulses (stage 4 above). Default true.
  bool warmStart = true;
  // With warmStart: start contacts and friction where SI starts them, from the cached impulse
  // times m_warmstartingFactor (0.85), the impulse SI's setup has applied, instead of the
  // cached impulse itself. SI's damping of the start lowers the residual fixed-sweep pgs reaches
  // on stacks (docs/benchmarks.md, "Bullet: pgs from SI's start"); exact solvers do not depend
  // on the start. Default false.
  bool siStart = false;
  // Regularisation model; see CfmModel. Default Regularized.
  CfmModel cfm = CfmModel::Regularized;
  // Keep every island's rows, start, answer and result of the last step (for tests and tools;
  // costs copies). Default false.
  bool keepIslands = false;
  // With "si": also measure the residual of SI's answer (costs about one sweep; excluded from
  // StepStats::seconds). Default true.
  bool measureSi = true;
  // "pgs" islands packed straight from Bullet's rows and written back per body
  // (docs/methods/adapters.md, "Bullet: the pgs path"). false: through RowSolver on a RowSystem
  // copy like every other solver (the same iterates; for side-by-side runs of the two). Default
  // true.
  bool packInPlace = true;
};

// One solved problem (an island, or its split-impulse twin) of the last step.
struct IslandRecord {
  RowSystem system;
  Vector start;        // warm start given to the solver
  Vector x;            // the answer written back
  Result result;       // of the answer written back
  std::string solver;  // which solver gave it ("dantzig", "ldlt", "pgs" after a fallback, "si")
  bool split = false;  // the split-impulse (position) problem
  bool fellBack = false;
};

// Statistics of one simulation step (every solveGroup call between prepareSolve and the next
// prepareSolve, which btDiscreteDynamicsWorld issues once per step).
struct StepStats {
  int groups = 0;       // solveGroup calls
  int islands = 0;      // problems solved (connected components, split-impulse twins included)
  int rows = 0;         // rows handed to solvers
  int inertRows = 0;    // rows touching no dynamic body (no effect; left at their start value)
  int iterations = 0;   // sweeps or pivots, summed over islands
  double residual = 0;  // worst scaled natural-map residual over islands (NaN if not measured)
  Status status = Status::Converged;  // worst status over islands (after the fallback)
  double seconds = 0;          // wall time of stages 2-7 (SI: its iterations), summed over groups
  double measureSeconds = 0;   // time spent measuring residuals outside the solve (si only)
  double assembleSeconds = 0;  // part of `seconds` spent assembling A for matrix-based solvers
  int fallbacks = 0;           // islands whose primary answer was rejected (the fallback ran)
  int failures = 0;            // islands whose returned answer is still rejected
  std::string message;         // why the first rejected answer was rejected ("" if none)
  ChoiceCounts choices;        // which solver answered, per island ("dantzig:3 ldlt:1")
  int packedIslands = 0;       // of `islands`: "pgs" answers packed straight from Bullet's rows
  int coneIslands = 0;    // of `islands`: answered by the friction cone's LCP (Settings::friction)
  ScreenCounts screened;  // degenerate rows screened by reason (row_screen.hpp), summed
};

// Adds `from`'s counts and times to `into`; keeps the worst residual and status, and the first
// message.
void accumulate(StepStats& into, const StepStats& from);

class SolverPool;
class ConstraintSolver;
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
  void record(const Result& r, int rows, const std::string& choice);
  // prepareSolve's and allSolved's work, with the mutex held by the caller.
  void openStep(int numBodies);
  void finishStep();
  // The world check of "Limits": throws once the world has stepped without solveGroup.
  void checkWorld();

  friend class SolverPool;
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
};

}  // namespace mlcp::bullet
