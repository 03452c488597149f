// mlcp/island/policy.hpp: what `auto` runs on a problem, and the one fallback rule every chain
// follows.
//
//     mlcp::Policy policy;                             // the defaults below
//     mlcp::Choice c = policy.choose(ProblemClass::Findex, 240, 1e-6);
//     c.solver;    // "dantzig"
//     c.fallback;  // "pgs"
//     c.why;       // "small contact island"
//
// One object decides for the registry's `auto` (a Problem, fallback.hpp), for both adapters'
// islands (RowSolver, row_solver.hpp) and for the CLI (which reaches them through those two).
//
// The choice, from the problem's structure (ProblemClass, problem.hpp: read from the bounds and
// findex alone, and whether any row is free: (-inf, inf), a joint's), its size in rows, the
// requested tolerance and whether a time budget is spent:
//   Empty                           -> "none"     nothing to solve
//   Linear (bilateral joints only)  -> "ldlt"     one LDL^T solve: exact, the cheapest answer
//   a row with A_ii <= 0            -> "lemke"    (fallback "newton"): neither pgs nor dantzig's
//                                                 ratio tests can divide by it; newton's dense
//                                                 LU / least-squares steps take the singular
//                                                 equality blocks (diode bridges) lemke cannot
//   contacts with free rows (joints), rows <= smallIslandRows,
//   contacts only, rows <= smallContactRows    -> "dantzig" exact pivoting answer (~1e-12)
//   larger contact islands:
//     the step's time budget spent             -> "pgs"      (improves any start in any share)
//     tolerance >= looseTolerance              -> "pgs"      (fallback "dantzig")
//     otherwise                                -> largeIslandSolver ("newton"), whose
//                                                 pivoting phase finishes the islands its
//                                                 damped steps leave short (newton.hpp)
// ("contacts": StandardLcp, Boxed and Findex islands.) Why: one LDL^T solve is exact and cheaper
// than any iteration on joint chains; pivoting is exact and fastest on small contact islands,
// but its pivot count grows with the rows, so above ~1000 rows a cold answer takes seconds a
// step, where pgs reaches a loose tolerance in a bounded number of sweeps; a tight tolerance on
// a large island still asks for an exact method: newton, whose steps on engine rows cost a
// body-space factorization (newton.hpp) and whose cold starts never pivot from zero (Bullet's
// 55-box pyramid under the 0.05 s budget: 18 of 30 steps converged, against none for dantzig,
// whose cut first steps demote the island to pgs), all bounded by the time budget
// (row_solver.hpp). Islands of contacts only are newton's from fewer rows: there its steps
// converge in a few factorizations where pivoting's cost grows with the rows (Bullet's and
// ODE's 15-box pyramids, 255 and 285 rows: newton 0.57 and 0.13 ms a step against dantzig's 2.3
// and 1.8 ms); with joint rows newton can stall where pivoting ends exact (Bullet's ragdoll
// pile, a 196-row island of 128 joint rows: newton stops at 1e-2, dantzig converges).
// The measurements: docs/benchmarks.md, "auto's choices and the time budget".
//
// The fallback rule (the same for a registry chain "a>b>c" and for RowSolver's primary and
// fallback):
//  1. Acceptable answers (acceptable()): the status is not Failed, NumericalIssue, InvalidInput
//     or Unsupported, and the residual recomputed by residual.hpp (never a solver's claim) is
//     finite and <= the limit. A LeastSquares answer (equality rows with no exact solution,
//     verified by the base) is acceptable whatever its residual: no method does better. The limit
//     is RowSolverSettings::acceptResidual for islands (default 1e-3) and Options::tolerance for a
//     registry chain (an accepted member answer is a converged one).
//  2. The next solver runs only when the answers so far are all unacceptable; it starts from the
//     caller's start point again, with the time left (RowSolver: at least a minimal share).
//  3. The returned answer is the first acceptable one, else the best answer any solver found:
//     the lowest finite recomputed residual (better(); the earlier one on a tie), whatever its
//     status. Only when no solver found a finite answer is the start returned (an engine's "no
//     change"; zeros if the start is not finite), never "no impulses" while a finite answer
//     exists.
//  4. The statistics say when the returned answer is not acceptable: Result::status keeps that
//     answer's own status (a chain whose members all missed is not Converged), the message lists
//     every attempt, and RowSolver's IslandSolve::accepted is false.
#pragma once

#include <string>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// The solver for contact islands above Policy::smallIslandRows rows (smallContactRows without
// free rows) at a tight tolerance.
inline constexpr const char* kLargeIslandSolver = "newton";

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
