// mlcp/island/policy.hpp: what `auto` runs on a problem, and the one fallback rule every chain
// follows.
//
//     mlcp::Policy policy;                             // the defaults below
//     mlcp::Choice c = policy.choose(ProblemClass::Findex, 240, 1e-6);
//     c.solver;    // "dantzig"
//     c.fallback;  // "pgs"
//     c.why;       // "small contact island"
//
// One object decides for the registry's `auto` (fallback.hpp), for both adapters' islands
// (RowSolver) and for the CLI. The choice, from the problem's class (problem.hpp), its rows,
// the requested tolerance and whether the step's time budget is spent:
//   Empty -> "none";  Linear (joints only) -> "ldlt" (one exact factorization);
//   a row with A_ii <= 0 -> "lemke" (fallback "newton");
//   contacts with joints up to smallIslandRows, contacts only up to smallContactRows
//     -> "dantzig" (exact pivoting, fast while the pivot count is small);
//   larger contact islands -> "pgs" when the budget is spent or the tolerance is loose
//     (>= looseTolerance), else largeIslandSolver ("newton", whose cost grows more slowly than
//     pivoting's with the rows);
//   a contact island whose dantzig or newton answer ended short of the tolerance (a singular A:
//     a pile without cfm) -> singularIslandSolver ("proximal") from that answer, and first for
//     that island's next singularIslandSolves solves (RowSolver's per-island memory; engine
//     islands leave it off by default: row_solver.hpp, engineIslandPolicy()).
//
// The fallback rule (a registry chain "a>b>c" and RowSolver's primary and fallback alike):
//  1. an answer is acceptable when its status is not a breakdown and its residual, recomputed
//     by residual.hpp (never a solver's claim), is finite and <= the limit (acceptResidual for
//     islands, Options::tolerance for a chain); a verified LeastSquares answer always is;
//  2. the next solver runs only when every answer so far is unacceptable, from the caller's
//     start, with the time left;
//  3. the first acceptable answer is returned, else the lowest finite residual found, else the
//     start (an engine's "no change"); never "no impulses" while a finite answer exists;
//  4. Result::status keeps the returned answer's own status and the message lists every try.
//
// The reasons and measurements behind each threshold: docs/methods/island.md, "auto's choice",
// and thresholds.hpp.
#pragma once

#include <string>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// The solver for contact islands above Policy::smallIslandRows rows (smallContactRows without
// free rows) at a tight tolerance.
inline constexpr const char* kLargeIslandSolver = "newton";
// The solver of contact islands whose exact primary (dantzig, newton) ended short of the
// tolerance: a singular A (a pile without cfm), where the proximal point loop on the impulses
// still reaches the exact answer (mlcp/solvers/proximal.hpp).
inline constexpr const char* kSingularIslandSolver = "proximal";

// What the policy picked, and why in words (for Result::message). Static strings, or (solver)
// the Policy's largeIslandSolver: choosing allocates nothing (it runs for every island).
struct Choice {
  const char* solver = "none";  // registry name, or "none" for an empty problem
  // What the registry's `auto` runs when solver's answer is not acceptable ("" for none).
  // RowSolver runs RowSolverSettings::fallback instead (the adapters' setting).
  const char* fallback = "pgs";
  const char* why = "";  // e.g. "small contact island"
};

struct Policy {
  // Largest contact island with free rows (joints) handed to dantzig whatever the tolerance, in
  // rows. Default kSmallIslandRows (600, thresholds.hpp).
  int smallIslandRows = kSmallIslandRows;
  // Largest contact island without free rows (contacts only) handed to dantzig whatever the
  // tolerance, in rows. Default kSmallContactRows (100, thresholds.hpp).
  int smallContactRows = kSmallContactRows;
  // Solver of larger contact islands at tolerances below looseTolerance. Default
  // kLargeIslandSolver ("newton").
  std::string largeIslandSolver = kLargeIslandSolver;
  // Solver that continues an island's exact primary (dantzig, newton) that ended short of the
  // tolerance, from its answer, and that answers that island first for its next
  // singularIslandSolves solves (RowSolver keeps the count per island); "" for none. Default
  // kSingularIslandSolver ("proximal").
  std::string singularIslandSolver = kSingularIslandSolver;
  int singularIslandSolves = 30;
  // Whether singularIslandSolver continues a short answer of `primary` on a problem of class c:
  // it is set, the rows are contacts (Findex, Boxed, StandardLcp) and primary is an exact method
  // this policy chooses for them (dantzig or largeIslandSolver).
  bool continuesShort(ProblemClass c, const std::string& primary) const;
  // Requested tolerance (scaled residual) at or above which large contact islands go to pgs.
  // Default 1e-4.
  double looseTolerance = 1e-4;
  // Solves of an island that run pgs first after its pivoting answer broke down (RowSolver keeps
  // the count per island). Default 30.
  int pgsAfterBreakdown = 30;
  // A rejected pivoting answer within this factor of the acceptance limit is a near miss: it
  // falls back for that solve only, without the pgsAfterBreakdown memory. Default 10.
  double nearMiss = 10;

  // The choice for a problem of this class and size. positiveDiagonal: every A_ii > 0 (always
  // true for engine rows with cfm > 0; RowSolver does not look). budgetSpent: the step's time
  // budget is spent and this solve has only its minimal share. freeRows: some row is free
  // (hasFreeRows, problem.hpp); when not known, true (the joints' threshold, the more conservative
  // one).
  Choice choose(ProblemClass c, int rows, double tolerance, bool positiveDiagonal = true,
                bool budgetSpent = false, bool freeRows = true) const;
  // Solves in a row of one island cut by the time budget before a far miss of the last demotes
  // it. Default 2: one cut solve is often a cold first step (newton's 11-20 steps on the 210-box
  // pyramid when the contacts appear) that leaves a start from which the next, warm solve
  // converges; a second cut in a row says the method does not finish in the budget.
  int cutsBeforeDemotion = 2;

  // Whether a rejected answer of a pivoting or Newton primary sends its island to pgs for the
  // next pgsAfterBreakdown solves: a breakdown (Failed, NumericalIssue, a non-finite residual),
  // or a miss by more than nearMiss times acceptResidual that is not a TimeLimit answer of the
  // island's first cutsBeforeDemotion - 1 cut solves in a row (cutsInRow counts them, this
  // one included): the island then stops spending its budget on a method that does not finish
  // in it.
  bool demotes(const Result& rejected, double acceptResidual, int cutsInRow = 1) const;
};

// Rule 1 above: the status is not Failed, NumericalIssue, InvalidInput or Unsupported and the
// residual is finite and <= acceptResidual; or the status is LeastSquares.
bool acceptable(const Result& r, double acceptResidual);
// Rule 3 above: candidate has a finite residual lower than best's (or best has none).
bool better(const Result& candidate, const Result& best);

}  // namespace mlcp
