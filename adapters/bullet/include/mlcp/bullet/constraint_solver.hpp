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
//     directions not from the velocity). Once a stack has come to rest under exact answers the
//     start's residual is 4e-5-1e-3 instead of 0.06-0.12 (bullet_bench's 55-box pyramid after 30
//     SI steps); the first ~20 steps after SI, while the stack moves from SI's approximate state
//     to the exact answers', start at 0.2-0.7 (docs/benchmarks.md).
//  5. solve and 6. check — mlcp::RowSolver (mlcp/row_solver.hpp), shared with the ODE adapter:
//     it classifies the island (bilateral only, frictionless contacts, boxed, friction), runs
//     the named solver or `auto`'s choice ("pgs" on the rows, others on an assembled A, dense up
//     to Settings::denseMaxRows rows), accepts the answer only when it is finite, not Failed
//     and its recomputed residual is <= Settings::acceptResidual, and otherwise runs the
//     fallback from the same start and keeps the better answer. StepStats counts the choices,
//     the fallbacks and the answers rejected even after the fallback.
//  7. store impulses — per row delta = x - appliedImpulse goes through btSolverBody::
//     internalApplyImpulse (as btMLCPSolver does); SI's finish then writes contact impulses,
//     joint feedback, breaking thresholds, velocities and transforms.
//  With split impulse on (Bullet's default) and a non-zero penetration rhs in an island, a second
//  problem with the same A and b = -m_rhsPenetration / m_jacDiagABInv gives push impulses.
//
// Cost against SI, "pgs" at SI's sweep count (bulletIterations, bullet_bench --pgs-vs-si; CPU
// time per step, median of 300 steps, 10 sweeps, two runs): Bullet's row setup and finish are
// the same code in both. "pgs" islands take a path of their own (solveIslandFast): RowPgs packs
// in place from Bullet's rows (IslandBuilder::solvePgs; no RowSystem copy), the answer goes to the
// bodies per body (RowPgs::velocityChange: M^-1 J^T (x - applied), what the per-row
// internalApplyImpulse calls sum to) and the applied impulses are stored in remember()'s pass.
// The two are the same only where our mass model is Bullet's body update. Bullet's solver body
// holds invMass l (l the linear factor) and internalApplyImpulse multiplies by l again: v +=
// invMass l^2 n x, ours invMass l n x (J's linear part n l); the angular factor f enters as
// w += diag(f)^2 I^-1 (r x n) x, ours diag(f) I^-1 diag(f) (r x n) x. They agree when l's
// components are 0 or 1 and f's are equal (any rotation); an island with another body
// (Island::perRowWriteBack) is written back row by row as the
// RowSolver path does (tested with factors (0.3, 1, 0.5) and linear factors (1, 0.5, 1)).
// Its answer passes the same acceptable() rule; a rejected one (or keepIslands, or a caller
// holding rowSolver()) goes through RowSolver on a RowSystem copy like every other solver. The
// iterates are the same as RowSolver's pgs bit for bit (one packing code); the write-back differs
// by round-off (the bodies' velocities, 1e-9 apart after ~17 steps of a settling pyramid).
// Session 4: 15 / 55 / 210 boxes 1.29-1.31x / 1.34-1.36x / 1.34-1.37x SI -> 1.15-1.17x /
// 1.21-1.23x / 1.21-1.23x; at 50 sweeps 0.96-0.97x -> 0.77-0.79x. At 210 boxes our stages take
// ~0.87 ms against SI's iterations ~0.67 ms: the sweeps ~0.37 ms (~8 ns a row; SI's ~14 ns),
// then ~100 ns a row of work SI does not have, because SI sweeps Bullet's rows in place:
// packing ~0.18 ms (rows.hpp), the island split and numbering ~0.10 ms, the conversion of
// Bullet's rows ~0.07 ms, storing impulses and remembering the points' answers ~0.08 ms (first
// touches of Bullet's rows after the sweeps), the check ~0.05 ms (perf shares).
// Round 2 (numbering in index passes, conversion without a store-forwarding stall, rows and
// points fetched ahead, remember() without reads of Bullet's rows): 10 sweeps 1.14x / 1.18-1.19x
// / 1.19x SI (50 sweeps 0.78x / 0.81x / 0.77-0.79x); our stages at 210 boxes ~0.90 ms against
// SI's iterations ~0.70 ms: sweeps 40%, packing 23%, numbering 15%, conversion 12%, storing and
// remembering 5.5%, the check ~5% (perf shares of our symbols). The stages around the sweeps
// still cost ~2x the gap to SI (~0.2 ms); the hot spots left are the first touches of Bullet's
// rows and points (1.4 MB of rows; with 1.1 MB of packed rows more than a 2 MB L2 holds) and
// the packing's division, the rest spread thin.
// Session 5 (rows read in place by the packing, inlined: no Row batch copy; M^-1 J^T's angular
// part read from Bullet's m_angularComponentA/B (islands.hpp); manifold points and remembered
// answers only for the cached-impulse start; couplings two at a time; rows fetched further
// ahead): 10 sweeps 1.08-1.12x / 1.11-1.13x / 1.08-1.09x SI at 15 / 55 / 210 boxes (the same
// two runs with round 2's code: 1.30-1.31x / 1.22x / 1.17-1.20x on a busier machine), 20 sweeps
// 0.88-0.90x / 0.92x / 0.90x, 50 sweeps 0.74-0.75x / 0.76x / 0.73-0.74x; residuals unchanged
// (the same iterates). Stage timers at 210 boxes, per step: island split and numbering ~60 us,
// packing (with the reading of Bullet's rows) ~250 us, sweeps ~430 us, check ~50 us, storing
// impulses ~23 us: ~0.80 ms against SI's iterations ~0.66 ms. 1.0x at 10 sweeps is not reached:
// the packing alone costs more than the gap (rows.hpp lists what it spends and what was tried).
// The cached-impulse start (the default, not what --pgs-vs-si times) still reads the manifold
// points in build() and keeps answers in remember().
// Session 6 (packing with shorter addition chains and its rows fetched for writing, the check in
// L1 blocks, one-component groups numbered without a per-row island lookup: rows.hpp,
// islands.hpp): 10 sweeps 1.06-1.07x / 1.12x / 1.05-1.07x SI at 15 / 55 / 210 boxes against
// 1.09-1.10x / 1.15-1.17x / 1.11-1.13x for session 5's code in the same two runs (alternated
// per run, three more: 55 boxes 1.15-1.16x -> 1.09-1.10x, 210 boxes 1.12-1.16x -> 1.04-1.08x);
// 20 sweeps 0.90-0.91x / 0.92-0.93x / 0.88-0.89x, 50 sweeps 0.78-0.81x / 0.78-0.88x /
// 0.75x. Stage timers at 210 boxes (median per step, quiet runs, session 5's code in brackets):
// split and numbering ~42-46 us (~53-56), packing ~200-220 us (~250-255), sweeps ~425-460 us
// (~425-450, unchanged), check ~46 us (~49), storing impulses ~20 us (~20): ~0.75 ms (~0.80)
// against SI's iterations ~0.67-0.72 ms. Still above 1.0x at 10 sweeps. The iterates moved by
// round-off (the packing's sums), so over 300 steps of the pyramid the worst residuals differ
// from session 5's (15 boxes 4.20e-3 -> 4.69e-3, SI's 4.22e-3) while the medians are the same.
// Session 7 (the sweep ~20% faster, rows.hpp; min-median of 6 runs alternated with session 6's
// code): 10 sweeps 1.02-1.03x / 1.06-1.07x / 1.00-1.04x SI at 15 / 55 / 210 boxes against
// 1.06-1.07x / 1.10-1.11x / 1.05-1.06x; 20 sweeps 0.90-0.91x / 0.89x / 0.85-0.88x, 50 sweeps
// 0.70-0.72x / 0.75x / 0.70x. The iterates and residuals are session 6's. Our stages at 55 boxes
// (stage timers, mean per step): split ~10 us, packing ~48 us, sweeps ~93 us, check ~11 us,
// storing ~2 us (~0.16 ms against SI's iterations ~0.15 ms); the fixed passes (~70 us) still
// cost more than the sweeps save. (Round 4's timers below put the split at ~5 us: the two sets
// were taken over Bullet's two solveGroup calls a step differently, one call has no rows; the
// sum of round 3's matches the bench's "ours stages ms" column.) The first sweep fused into the
// packing did not pay (rows.hpp).
// Session 7, round 4 (the one-component split numbered in its graph pass, islands.hpp; runs
// alternated with round 3's code, min / median, 7 and 11 runs on a busy machine): 10 sweeps 1.00x /
// 1.00-1.10x, 1.04x / 1.05-1.11x, 1.01-1.02x / 1.02-1.05x SI at 15 / 55 / 210 boxes against 1.02x /
// 1.02-1.10x, 1.05x / 1.09-1.13x, 1.02x / 1.04-1.08x. The split at 55 boxes is now ~4.4 us of a ~10
// us gap (4% at the min); the graph pass (~3.3 us) is what is left of it, and folding it into the
// packing cost the packing more than it saved (islands.hpp).
// Session 9 (mlcp/cpu.hpp, rows.hpp): the packing, sweeps and check compiled for AVX2 too and
// chosen at run time, and the sweep's and check's 12-wide products and velocity updates written as
// generic vectors (4 + 2 wide with AVX2, pairs in the baseline; Eigen's order, the same iterates
// bit for bit). Two runs, ours stages / SI's iterations at 55 boxes, 10 sweeps: 0.124 / 0.126-0.128
// ms (0.135-0.137 / 0.126-0.128 before); 10 sweeps 0.93x / 0.97x / 0.92x SI at 15 / 55 / 210
// boxes in both runs (AVX2), 0.95x / 1.00x / 0.96x with MLCP_CPU_PATH=baseline; 20 sweeps
// 0.75x / 0.75-0.76x / 0.75-0.77x, 50 sweeps 0.54-0.56x / 0.59-0.60x / 0.59-0.60x. The whole
// library built for x86-64-v3 instead (tools/build.sh DIR -DCMAKE_CXX_FLAGS="-march=x86-64-v3
// -ffp-contract=off", before the generic vectors) gained about what the dispatch alone gained
// (55 boxes ~1.00x against 1.01-1.02x, alternated runs), so the rest of our stages gain little
// from AVX2.
//
// "si" runs Bullet's own SI iterations instead (for side-by-side runs with the same statistics).
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <memory>
#include <string>
#include <vector>

#include "mlcp/bullet/islands.hpp"
#include "mlcp/result.hpp"
#include "mlcp/row_solver.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"

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

// The island solver's settings (mlcp::RowSolverSettings: solver "auto", options, fallback "pgs",
// fallbackOptions, acceptResidual 1e-3, denseMaxRows 64; documented in mlcp/row_solver.hpp,
// the same defaults as the ODE adapter's), plus Bullet's own. `solver` may also be "si":
// Bullet's own sequential impulse iterations. options.warmStart is governed by warmStart below.
struct Settings : RowSolverSettings {
  // pgs/gs take their sweep count from btContactSolverInfo::m_numIterations (as SI and the stock
  // MLCP solvers do) instead of options.maxIterations. Default false.
  bool bulletIterations = false;
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
};

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
  // The shared island solver (null with "si"): its capture hook writes each island's problem.
  // Once it has been asked for, "pgs" islands go through it too (see fastPgs below).
  RowSolver* rowSolver() {
    shared_ = true;
    return rows_.get();
  }

  void prepareSolve(int numBodies, int numManifolds) override;
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
  // was not accepted (the island then goes through rows_ like every other solver).
  bool solveIslandFast(Island& island, bool split);
  // Store impulses row by row through Bullet's own body update (internalApplyImpulse or
  // internalApplyPushImpulse with x - applied), and set the applied impulses to x.
  void applyPerRow(Island& island, const Vector& x, bool split);
  void measureSi(int sweeps);
  void record(const Result& r, int rows, const std::string& choice);
  void finishStep();

  Settings settings_;
  std::unique_ptr<RowSolver> rows_;
  bool si_ = false;
  // "pgs" islands skip the RowSystem copy and RowSolver (solver "pgs", no keepIslands, and
  // nobody asked for rowSolver()); same iterates, same verification rule (acceptable()).
  bool fastPgs_ = false;
  bool shared_ = false;
  RowPgs pgs_;
  IslandBuilder builder_;
  StepStats current_, last_, totals_;
  bool stepOpen_ = false;
  std::vector<IslandRecord> records_;
  Vector x_;
};

}  // namespace mlcp::bullet
