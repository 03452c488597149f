// mlcp/bullet/constraint_solver.hpp: any core solver as a drop-in btConstraintSolver.
//
//     mlcp::bullet::Settings s;
//     s.solver = "dantzig";                       // any mlcp::makeSolver name, or "si"
//     auto solver = std::make_unique<mlcp::bullet::ConstraintSolver>(s);
//     world->setConstraintSolver(solver.get());   // a stock btDiscreteDynamicsWorld
//     ...
//     const mlcp::bullet::StepStats& st = solver->lastStep();
//
// Pipeline of one solveGroup call (the stages are named as in Box2D v3's solver):
//
//  1. prepare rows — Bullet's own sequential-impulse (SI) setup builds every row (joints,
//     contacts, friction, rolling/torsional friction, split-impulse penetration rows) exactly as
//     SI would; we inherit it from btSequentialImpulseConstraintSolver, like btMLCPSolver does.
//  2. islands — the group is split into connected components of the dynamic-body graph (static
//     and kinematic bodies do not connect anything) and each component is solved alone. Bullet
//     merges small islands into one group (m_minimumSolverBatchSize); we undo that.
//  3. per island, the factored rows become an mlcp::RowSystem in canonical form w = A x + b:
//       J rows     [n1; r1 x n1] and [n2; r2 x n2] from the solver constraint, linear factors
//                  folded into the linear part, angular factors into M^-1's inertia block
//                  (diag(af) I^-1 diag(af), symmetric; SI itself uses af^2 I^-1 on one side);
//       b_i      = -m_rhs / m_jacDiagABInv   (Bullet's rhs is a velocity error times 1/A_ii:
//                                             its b is minus ours);
//       cfm_i    = m_cfm / m_jacDiagABInv    (the regularisation SI converges to; see CfmModel);
//       bounds     joints as given; contacts [0, inf); friction [-mu, mu] with findex = its
//                  contact row; rolling friction the same with its own coefficient (SI also
//                  caps it at mu_r in absolute terms, which is not a complementarity bound).
//  4. warm start — x0 = last step's impulses: for contacts and friction the cached impulse
//     (Bullet's applied impulse divided by m_warmstartingFactor, 0.85: SI's setup has already
//     applied the scaled impulse to the solver bodies, and the write-back below only applies
//     the difference), or with Settings::siStart SI's own start (the applied impulse as it is),
//     0 for joints (SI does not warm-start them). Contacts and friction then take our own last
//     answer at the same manifold point where there is one (IslandBuilder::remember): Bullet 3
//     starts friction rows at 0 whatever the mode, its default friction direction follows the
//     sliding velocity and changes every step (friction starts at last step's friction impulse
//     vector along the new direction), and it re-creates some points of a resting stack every
//     step with no cached impulse. Without a remembered answer, friction rows start from the
//     point's m_appliedImpulseLateral1/2 when the directions persist (direction caching, or
//     directions not from the velocity). Why our own answers: once a stack rests under exact
//     answers, they are a start about 100x closer than the cached impulse (start residual ~1e-4
//     against ~0.1 on bullet_bench's 55-box pyramid), and newton (with its pivoting phase) then
//     settles in a few steps instead of tens. Right after a switch from SI no start helps: the
//     stack moves from SI's approximate state to the exact answers' for ~20-40 steps.
//  5. solve and 6. check — mlcp::RowSolver (mlcp/island/row_solver.hpp), shared with the ODE
//  adapter:
//     it classifies the island (bilateral only, frictionless contacts, boxed, friction), runs
//     the named solver or `auto`'s choice ("pgs" on the rows, others on an assembled A, dense up
//     to Settings::denseAssemblyMaxRows rows), accepts the answer only when it is finite, not
//     Failed and its recomputed residual is <= Settings::acceptResidual, and otherwise runs the
//     fallback from the same start and keeps the better answer. StepStats counts the choices,
//     the fallbacks and the answers rejected even after the fallback.
//  7. store impulses — per row delta = x - appliedImpulse goes through btSolverBody::
//     internalApplyImpulse (as btMLCPSolver does); SI's finish then writes contact impulses,
//     joint feedback, breaking thresholds, velocities and transforms.
//  With split impulse on (Bullet's default) and a non-zero penetration rhs in an island, a second
//  problem with the same A and b = -m_rhsPenetration / m_jacDiagABInv gives push impulses.
//
// The "pgs" path. "pgs" islands take a path of their own (solveIslandFast), because at SI's
// sweep counts the passes around the sweeps cost about as much as the sweeps: RowPgs packs in
// place from Bullet's rows (IslandBuilder::solvePgs; no RowSystem copy), the answer goes to the
// bodies per body (RowPgs::velocityChange: M^-1 J^T (x - applied), what the per-row
// internalApplyImpulse calls sum to) and the applied impulses are stored in remember()'s pass.
// The two are the same only where our mass model is Bullet's body update. Bullet's solver body
// holds invMass l (l the linear factor) and internalApplyImpulse multiplies by l again: v +=
// invMass l^2 n x, ours invMass l n x (J's linear part n l); the angular factor f enters as
// w += diag(f)^2 I^-1 (r x n) x, ours diag(f) I^-1 diag(f) (r x n) x. They agree when l's
// components are 0 or 1 and f's are equal (any rotation); an island with another body
// (Island::perRowWriteBack) is written back row by row as the
// RowSolver path does (tested with factors (0.3, 1, 0.5) and linear factors (1, 0.5, 1)).
// Its answer passes the same acceptable() rule; a rejected one goes through RowSolver on a
// RowSystem copy like every other solver when RowSolver has a fallback to run (without one it
// would repeat the same sweeps from the same start: the packed answer stays, counted in
// failures), and so does every "pgs" island with Settings::packInPlace false, keepIslands, or a
// capture set on rowSolver(). The
// iterates are the same as RowSolver's pgs bit for bit (one packing code); the write-back differs
// by round-off (the bodies' velocities, 1e-9 apart after ~17 steps of a settling pyramid). The
// cached-impulse start (the default) reads the manifold points in build() and keeps answers in
// remember(); SI's start (Settings::siStart) reads neither.
// Cost against SI at the same sweep count: Bullet's row setup and finish are the same code in
// both. Ours adds one packing pass, the island split, the residual check and the write-back,
// O(rows) each, and saves on every sweep (RowPgs' sweep, rows.hpp, takes about half of SI's time
// a row), so it takes about SI's time at Bullet's default 10 sweeps and less from 20 on
// (docs/benchmarks.md, "Bullet: pgs against SI").
//
// "si" runs Bullet's own SI iterations instead (for side-by-side runs with the same statistics).
//
// Worlds served. A btDiscreteDynamicsWorld (and btSoftRigidDynamicsWorld) through
// setConstraintSolver; a btDiscreteDynamicsWorldMt through mlcp::bullet::install with a
// SolverPool (mlcp/bullet/worlds.hpp): its large islands go to a second solver slot that
// setConstraintSolver does not reach. A btMultiBodyDynamicsWorld is refused: it solves through
// its btMultiBodyConstraintSolver and never calls this solver's solveGroup. A world that steps
// (prepareSolve with bodies, then allSolved) without one solveGroup call is taken to be such a
// world: allSolved throws std::logic_error then and at every later step, so the swap never
// silently does nothing (a btDiscreteDynamicsWorld always calls solveGroup at least once a
// step, even for a group without rows). The check runs at the first step with bodies; solvers
// installed by install() (which checks the world itself) and the members of a SolverPool skip
// it.
//
// Threads. solveGroup, prepareSolve and allSolved hold a mutex: one solver called from several
// threads at once (a btDiscreteDynamicsWorldMt under a threaded task scheduler, when one
// instance fills both of its slots) solves one group at a time, correctly. For groups solved in
// parallel give each thread its own instance: SolverPool. The warm-start memory (last answers
// per manifold point) is the instance's: two worlds stepped at once through one instance start
// from each other's answers, so give each world its own solver.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mlcp/bullet/islands.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/island/rows.hpp"
#include "mlcp/result.hpp"
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
  // Start every solve from last step's impulses (stage 4 below). Default true.
  bool warmStart = true;
  // With warmStart: start contacts and friction where SI starts them, from the cached impulse
  // times m_warmstartingFactor (0.85) — the impulse SI's setup has applied — instead of the
  // cached impulse itself. SI's damping of the start lowers the residual fixed-sweep pgs reaches
  // on stacks: bullet_bench --pgs-vs-si, 210-box pyramid, worst residual over 300 steps at 10
  // sweeps 0.15 from the cached impulse, 0.052 from SI's start (SI itself 0.052). Exact solvers
  // do not depend on the start. Default false.
  bool siStart = false;
  // Regularisation model; see CfmModel. Default Regularized.
  CfmModel cfm = CfmModel::Regularized;
  // Keep every island's rows, start, answer and result of the last step (for tests and tools;
  // costs copies). Default false.
  bool keepIslands = false;
  // With "si": also measure the residual of SI's answer (costs about one sweep; excluded from
  // StepStats::seconds). Default true.
  bool measureSi = true;
  // "pgs" islands packed straight from Bullet's rows and written back per body ("The pgs path"
  // above). false: through RowSolver on a RowSystem copy like every other solver (the same
  // iterates; for side-by-side runs of the two). Default true.
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

  // Serialized by the solver's mutex (see "Threads" above).
  btScalar solveGroup(btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds,
                      int numManifolds, btTypedConstraint** constraints, int numConstraints,
                      const btContactSolverInfo& info, btIDebugDraw* debugDrawer,
                      btDispatcher* dispatcher) override;
  void prepareSolve(int numBodies, int numManifolds) override;
  // Throws std::logic_error when the world does not call solveGroup (see "Worlds served").
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
  // The world check of "Worlds served": throws once the world has stepped without solveGroup.
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
