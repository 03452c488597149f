// core/src/island/row_solver_impl.hpp (internal): RowSolver's stages, per-island memory and
// reused buffers (mlcp/island/row_solver.hpp says what each stage does and why).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "island/friction_cone.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp {

class RowSolver::Impl {
 public:
  // Throws std::invalid_argument naming the known solvers for an unknown solver or fallback
  // name, for a negative or NaN acceptResidual, timeBudget or minShare
  // outside (0, 1], engineCostFactor neither 0 nor finite and >= 1, and for frictionDirections
  // outside [3, 64] or the cone with a primary that cannot take its LCP.
  explicit Impl(const RowSolverSettings& settings);

  const RowSolverSettings& settings() const { return settings_; }
  // The primary's and fallback's options may be changed between solves (names may not).
  Options& options() { return settings_.options; }
  Options& fallbackOptions() { return settings_.fallbackOptions; }
  // Changes the per-step budget between solves (seconds, 0 for none); throws
  // std::invalid_argument for a negative or non-finite value.
  void setTimeBudget(double seconds);

  // The engine's own solver's sweeps per step (Bullet's m_numIterations, QuickStep's
  // iterations): the unit of the engine-relative cap. 0 (the default) leaves every island to
  // timeBudget alone.
  void setEngineSweeps(int sweeps) { engineSweeps_ = sweeps > 0 ? sweeps : 0; }
  // Opens an engine step: the budget's clock starts at the next solve() and runs over every
  // solve until the next beginStep(). Without it every solve is a step of its own.
  void beginStep() {
    stepOpen_ = true;
    stepPending_ = true;
  }
  // The share of the step's budget an island starting at `now` (nowSeconds()) gets, in seconds
  // (see above); 0 without a budget. For callers that solve an island themselves (Bullet's
  // packed pgs path) under the same budget.
  double islandBudget(double now);
  // True when `share` (islandBudget()) is down to the minimal share: the step's budget is spent.
  bool budgetSpent(double share) const;

  // Solves the island's rows from `start` (size rows.size(), used as given: pass zeros for a
  // cold start) into x. islandKey identifies the island across steps (any stable number, e.g.
  // its first body's address); solver workspaces are kept per key.
  IslandSolve solve(const RowSystem& rows, const Vector& start, Vector& x,
                    std::uint64_t islandKey = 0);

  // While prefix is not "", every solve() with rows writes the island's assembled problem
  // (mlcp-problem/1, io.hpp) to prefix + "island<K>.json", K = 0, 1, ... from this call on.
  void setCapture(const std::string& prefix);
  bool capturing() const { return !capturePrefix_.empty(); }
  // The files written since the last setCapture.
  const std::vector<std::string>& capturedFiles() const { return captured_; }

  // The assembled-problem solver kept for this island and name, or null (for tests of the
  // workspace reuse, e.g. LdltSolver::analyses()).
  const Solver* cachedSolver(std::uint64_t islandKey, const std::string& name) const;

 private:
  struct Slot;
  // What stage 2 decided for this solve and what stage 3 found.
  struct Plan {
    double share = 0;           // the island's time share, seconds (0: no budget)
    bool enginePgs = false;     // pgs that auto runs for cost: the fallback's options
    bool capped = false;        // under the engine-relative cap
    bool fromStart = false;     // the start already solves the rows
    bool primaryShort = false;  // the primary's own answer ended short of the tolerance
  };
  static IslandSolve noRows(Vector& x);
  void chooseForAuto(const RowSystem& rows, const Vector& start, Slot& island, IslandSolve& out,
                     Plan& plan);
  Result solvePrimary(const RowSystem& rows, const Vector& start, Vector& x, Slot& island,
                      IslandSolve& out, Plan& plan, double t0);
  bool cappable(const std::string& name) const;
  void remember(Slot& island, const IslandSolve& out, const Result& r, const Plan& plan);
  // Stages 1-4 on rows that passed the screen.
  IslandSolve solveScreened(const RowSystem& rows, const Vector& start, Vector& x,
                            std::uint64_t islandKey);
  Slot& slot(std::uint64_t key);
  // The island's solver of this name, kept under tag + name (the cone's apart from the box's).
  Solver* assembledSolver(Slot& island, const std::string& name, const char* tag = "");
  Result run(const RowSystem& rows, const std::string& name, const Options& options,
             const Vector& start, Vector& x, Slot& island, IslandSolve& report);
  Result fallBack(const RowSystem& rows, const Vector& start, Vector& x, Slot& island,
                  IslandSolve& out, Result r, double share, double t0);
  // The primary's options bounded by what is left of the island's share.
  Options leftOfShare(double share, double t0) const;
  // Stage 3 under auto: an answer continued by `name` from it with the options o; the better
  // answer stands.
  void continueWith(const std::string& name, const RowSystem& rows, Vector& x, Slot& island,
                    IslandSolve& out, Result& r, const Options& o);
  // Stage 3 under auto after the primary: dantzig's unacceptable answer on friction rows
  // continued by newton, and an exact primary's answer short of the tolerance by the policy's
  // singular-island solver.
  void continueShort(const RowSystem& rows, Vector& x, Slot& island, IslandSolve& out, Result& r,
                     const Plan& plan, double t0);
  // Stage 5: an unacceptable answer moving the bodies far more than pgs's is replaced by pgs's.
  // throwsBodies: x changes some body's linear velocity by more than factor ||b||_inf (an
  // acceptable answer beyond kSpeedFactor = 10 is judged by keepSafe too).
  // The velocities go to velocities_ (reused: no allocation per island).
  bool throwsBodies(const RowSystem& rows, const Vector& x, double factor);
  // Whether velocities_ (some x's) move a body by more than factor ||b||_inf.
  bool throwsFromVelocities(const RowSystem& rows, const Vector& x, double factor) const;
  // Stage 0's start: `start`, or zeros (coldStart_) when it throws a body by 1000 ||b||_inf, far
  // beyond any answer's 10 (kStartSpeedFactor, row_solver.cpp). A start is the last
  // step's impulses matched to this step's rows; where last step's rows were nearly dependent
  // they can be huge and cancel, and matched to rows that moved they no longer do (Bullet's
  // ragdolls: a start at 9e6 m/s, pgs diverging from it, a body at 122 m/s two steps later).
  const Vector& saneStart(const RowSystem& rows, const Vector& start);
  // Stage 5's last resort when pgs's answer throws a body too: the start, or no impulses.
  void holdStill(const RowSystem& rows, const Vector& start, Vector& x, IslandSolve& out,
                 Result& r);
  void keepSafe(const RowSystem& rows, const Vector& start, Vector& x, Slot& island,
                IslandSolve& out, Result& r, Result* projectionAnswer, double share, double t0);
  void assemble(const RowSystem& rows, bool sparse);
  // The engine-relative cap's share for this island in seconds, 0 when it does not apply.
  double engineShare(const RowSystem& rows, const Vector& start);
  // Adds a timed RowPgs solve to the running cost per row (solves at the engine's sweeps only).
  void notePgsCost(int rows, int sweeps, double seconds);
  // Stage 3 with friction "cone": builds the cone's LCP (false: the rows do not fit, the reason
  // goes to out's message and the box runs), then solves it.
  bool buildCone(const RowSystem& rows, const Vector& start, IslandSolve& out);
  Result solveCone(const Vector& start, Vector& x, Slot& island, IslandSolve& out, double share,
                   double t0);
  // Whether the start already solves the rows far within the tolerance (see stage 3); then x and r
  // are that answer.
  // withinTolerance: the start need only meet the tolerance (an island under the engine-relative
  // cap, where a solve that would change it by less costs several times the engine's solver).
  // velocities_ must hold the start's (saneStart leaves them there).
  bool startSolves(const RowSystem& rows, const Vector& start, double tolerance,
                   bool withinTolerance, Vector& x, Result& r);
  // A time-limited answer x is replaced by the start when the start's residual is lower.
  void keepStartIfBetter(const RowSystem& rows, const Vector& start, Vector& x, Result& r,
                         double tolerance);
  // The accuracy of x on the rows (residual.hpp), through velocities_ and slack_; fresh: the
  // velocities are computed here, else velocities_ already holds x's.
  Accuracy rowAccuracy(const RowSystem& rows, const Vector& x, bool fresh = true);
  void capture(const RowSystem& rows);
  void capture(const Problem& problem);

  RowSolverSettings settings_;
  RowPgs rowPgs_;
  Problem assembled_;  // reused across solves with assembleScratch_: no per-step allocation
  RowSystem::AssembleScratch assembleScratch_;
  bool haveAssembled_ = false;
  double solveStart_ = 0;  // the current solve's start, until its primary's run() reads it
  Vector xFallback_;
  RowScreen screen_;
  Vector keptStart_, keptX_;         // the kept rows' start and answer when rows were screened
  Vector coldStart_;                 // zeros: the start that replaces one that throws a body
  std::vector<Vector6> velocities_;  // M^-1 J^T x of the last x looked at (start or answer)
  Vector slack_;                     // w = A x + b of rowAccuracy's x
  std::unordered_map<std::uint64_t, std::unique_ptr<Slot>> slots_;
  std::uint64_t lastKey_ = 0;  // the key of lastSlot_
  Slot* lastSlot_ = nullptr;   // the island solved last (slots_ owns it)
  std::uint64_t calls_ = 0;
  bool stepOpen_ = false;     // beginStep() was called: solves share a step's budget
  bool stepPending_ = false;  // the next solve starts the step's clock
  double stepStart_ = 0;
  int engineSweeps_ = 0;   // setEngineSweeps()
  double rowSeconds_ = 0;  // the running cost of a row in pgs at the engine's sweeps, 0: unknown
  Vector calibrationX_;
  bool primaryWasFallback_ = false;  // this island's primary ran as its fallback would
  FrictionCone cone_;
  Vector coneStart_, coneX_;
  std::string coneNote_;  // why the last island kept the box ("" when the cone was built)
  std::string capturePrefix_;
  std::vector<std::string> captured_;
};

}  // namespace mlcp
