// mlcp/bullet/settings.hpp: what the Bullet drop-ins take and report (ConstraintSolver, the
// multibody solver install() puts in a btMultiBodyDynamicsWorld, SolverPool).
//
//     mlcp::bullet::Settings s;                 // solver "auto", fallback "pgs", tolerance 1e-6
//     s.solver = "dantzig";                     // any mlcp::makeSolver name, "pgs", "auto", "si"
//     ...
//     const mlcp::bullet::StepStats& st = solver.lastStep();   // islands, residual, choices
//
// Settings extends the island solver's settings (mlcp::RowSolverSettings, shared with the ODE
// adapter) by Bullet's own: the warm start, the CFM model, records for tests. StepStats sums one
// simulation step; accumulate() adds steps (SolverPool members, totals()).
#pragma once

#include <string>
#include <vector>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/result.hpp"
#include "mlcp/rows.hpp"

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
  // Multibody worlds' joint limits. Bullet makes a limit row only once the joint is past its
  // limit, and with split impulse on moves a violation deeper than
  // m_splitImpulsePenetrationThreshold into m_rhsPenetration, which its multibody solver never
  // reads (SI leaves a 4-link arm 0.57 rad past +-0.25 rad limits). true: that error is put back
  // into the row's rhs (corrected at m_erp2), and every one-sided multibody row (a limit) aims
  // 1e-3 (rad or m) inside its violation, so that an exact answer does not put the joint exactly
  // on its limit, lose the row the next step and let it fall free for one (the arm then holds
  // its limits to 1e-3). false: Bullet's rows as they are. No effect on rigid rows (Bullet's
  // split impulse iterations serve them). Default true.
  bool multiBodyPositionCorrection = true;
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

}  // namespace mlcp::bullet
