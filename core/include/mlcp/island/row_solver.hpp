// mlcp/island/row_solver.hpp: the one place that solves an engine island's rows (both adapters).
//
//     mlcp::RowSolver solver;                      // settings: solver "auto", fallback "pgs"
//     solver.beginStep();                          // once per engine step (the time budget's)
//     mlcp::IslandSolve s = solver.solve(rows, start, x, islandKey);
//     s.choice;    // "ldlt", "dantzig", "newton", "start", ...: whose answer x is
//     s.accepted;  // the returned answer is acceptable (policy.hpp, rule 1)
//
// The problem: an island's rows (mlcp/rows.hpp), w = A x + b with A = J M^-1 J^T + diag(cfm),
// lo <= x <= hi, friction bounds through findex (problem.hpp's canonical form). Each solve runs
// five stages: 0. screen degenerate rows (row_screen.hpp), and drop a start that would change
// a body's velocity by more than 1000 ||b||_inf (not a warm start: solved cold); 1. classify the
// rows by bounds and findex alone; 2. choose the solver (the requested name, or Policy::choose for
// "auto", with a per-island memory that sends an island whose exact answer broke down to pgs for a
// while);
// 3. solve from the caller's start, "pgs" on the rows themselves (RowPgs), every other method
// on A assembled once (dense up to denseAssemblyMaxRows rows); 4. verify the answer by the
// fallback rule of policy.hpp and run the fallback when it is not acceptable; 5. apply safely:
// an answer that would move a body far more than the engine's own method (pgs at its sweeps)
// is replaced by that method's answer (IslandSolve::energyGuard).
//
// Bounded cost. timeBudget bounds one engine step's solves: each island gets what is left of
// it, at least minShare of it, and a solver stopped by it returns its best iterate, never worse
// than its start. The engine-relative cap bounds an island auto hands to newton, once newton
// has missed it, by engineCostFactor times the measured cost of the engine's own solver on it.
//
// Invariants: x always has rows.size() finite entries on return; IslandSolve::result.residual
// is the residual of that x, recomputed from the rows; the settings' names are checked at
// construction. Cost over the chosen solver's: O(n) classification, O(nnz J) for the residual
// check (which is also the acceptance test), O(nnz A) assembly for matrix-based solvers, and
// the fallback's solve when the answer is rejected.
//
// Each stage, the budget, the cap and the defaults' reasons in full: docs/methods/island.md.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/island/island_solve.hpp"
#include "mlcp/island/row_solver_settings.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"

namespace mlcp {

// ProblemClass of the rows from their bounds and findex alone (Problem::classify's rules).
ProblemClass classify(const RowSystem& rows);

class RowSolver {
 public:
  // Throws std::invalid_argument naming the known solvers for an unknown solver or fallback
  // name, for a negative or NaN acceptResidual, timeBudget or minShare
  // outside (0, 1], engineCostFactor neither 0 nor finite and >= 1, and for frictionDirections
  // outside [3, 64] or the cone with a primary that cannot take its LCP.
  explicit RowSolver(const RowSolverSettings& settings = RowSolverSettings());
  ~RowSolver();
  RowSolver(const RowSolver&) = delete;
  RowSolver& operator=(const RowSolver&) = delete;

  const RowSolverSettings& settings() const;
  // The primary's and fallback's options may be changed between solves (names may not).
  Options& options();
  Options& fallbackOptions();
  // Changes the per-step budget between solves (seconds, 0 for none); throws
  // std::invalid_argument for a negative or non-finite value.
  void setTimeBudget(double seconds);

  // The engine's own solver's sweeps per step (Bullet's m_numIterations, QuickStep's
  // iterations): the unit of the engine-relative cap. 0 (the default) leaves every island to
  // timeBudget alone.
  void setEngineSweeps(int sweeps);
  // Opens an engine step: the budget's clock starts at the next solve() and runs over every
  // solve until the next beginStep(). Without it every solve is a step of its own.
  void beginStep();
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
  bool capturing() const;
  // The files written since the last setCapture.
  const std::vector<std::string>& capturedFiles() const;

  // The assembled-problem solver kept for this island and name, or null (for tests of the
  // workspace reuse, e.g. LdltSolver::analyses()).
  const Solver* cachedSolver(std::uint64_t islandKey, const std::string& name) const;

  // Whether a name can be given as `solver` / `fallback`.
  static bool known(const std::string& name);

 private:
  // The stages, the per-island memory and the reused buffers (core/src/island/row_solver_impl.hpp).
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlcp
