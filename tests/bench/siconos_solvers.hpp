// siconos_solvers.hpp: Siconos numerics' LCP and relay (box-constrained) solvers on our problems,
// each solve isolated in a child process with a wall-clock limit.
//
// Siconos numerics (Debian's libsiconos-numerics-dev 4.4) states
//   LCP:    w = M z + q,  0 <= z _|_ w >= 0                            (lcp_* solvers)
//   relay:  w = M z + q,  lb <= z <= ub,  -w in N_[lb,ub](z)           (relay_* solvers)
// which are our canonical form with A = M, b = q: a standard LCP, and a box without findex
// (z = lb => w >= 0, z = ub => w <= 0, else w = 0). M is handed over dense (column-major
// NumericsMatrix, NM_DENSE): the storage every one of these solvers takes (lexicographic Lemke
// and the Newton methods factor or pivot on dense arrays, PGS reads matrix0).
//
// Tolerance. Siconos measures an LCP answer by ||z - max(0, z - w)||_2 / ||q||_2
// (lcp_compute_error) and a relay answer by ||z - proj_[lb,ub](z - w)||_2 / (1 + ||q||_2)
// (relay_compute_error): the same natural map as ours (residual.hpp), in the 2-norm, scaled by
// ||q||_2 or 1 + ||q||_2 where we take the infinity norm and 1 + ||b||_inf. Since
// ||r||_inf <= ||r||_2, Siconos' tolerance is set to
//   LCP:    tol * (1 + ||q||_inf) / ||q||_2
//   relay:  tol * (1 + ||q||_inf) / (1 + ||q||_2)
// so that an answer Siconos accepts meets our tolerance; the bench then recomputes our residual
// of every answer and decides convergence by it alone (Siconos' own error is reported beside).
//
// Iteration limits: Newton steps and PGS sweeps `maxIterations`; Lemke pivots 50 n + 100 (our
// lemke's automatic limit). Only the solver call is timed (not the copy into dense storage).
//
// Isolation: each solve runs in a fork()ed child that writes z, the time and Siconos' counters
// into shared memory; the parent kills it at the wall-clock limit (Siconos solvers take no time
// budget) and reports a crash (Siconos' numerics_error ends the process) as such. Cost: one fork
// per solve (copy-on-write pages), outside the time reported.
#pragma once

#include <string>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::bench {

enum class SiconosForm { Lcp, Relay };

struct SiconosSolverInfo {
  const char* name;  // "lcp_newton_FB", ...
  SiconosForm form;
  int id;  // SICONOS_LCP_* / SICONOS_RELAY_*
  // The size of the dense problem the solver works on, in multiples of n (relay Lemke: 2, the
  // box written as an LCP of 2n rows).
  int sizeFactor;
};

// The solvers the bench runs: lcp_newton_FB (Fischer-Burmeister), lcp_newton_min (min map),
// lcp_newton_minFB (min-FB), lcp_lexicolemke, lcp_pgs;
// relay_pgs, relay_lexicolemke, relay_avi_caoferris.
const std::vector<SiconosSolverInfo>& siconosSolvers();

struct SiconosLimits {
  double tolerance = 1e-6;   // our scaled residual's target
  int maxIterations = 1000;  // Newton steps, PGS sweeps
  double seconds = 60;       // wall-clock limit of one solve
  int repeat = 1;            // solves of the same problem from zero; ms is their median
};

struct SiconosOutcome {
  enum class End { Returned, TimeLimit, Crashed } end = End::Crashed;
  Vector z;                     // the answer (size n) when Returned
  double ms = 0;                // time of the solver call
  int info = -1;                // Siconos' return code (0: its own test passed)
  int iterations = 0;           // iparam[SICONOS_IPARAM_ITER_DONE]
  double ownError = 0;          // dparam[SICONOS_DPARAM_RESIDU]: Siconos' error of its answer
  double siconosTolerance = 0;  // the tolerance handed to Siconos (above)
  std::string message;          // for TimeLimit / Crashed
};

// Solves `problem` (a standard LCP for Lcp solvers; a box without findex for Relay solvers) with
// the Siconos solver, from z = 0.
SiconosOutcome solveWithSiconos(const SiconosSolverInfo& solver, const Problem& problem,
                                const SiconosLimits& limits);

}  // namespace mlcp::bench
