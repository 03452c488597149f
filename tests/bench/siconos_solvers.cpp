#include "siconos_solvers.hpp"

#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

// Siconos numerics' C headers (they declare extern "C" themselves).
#include "LCP_Solvers.h"
#include "LinearComplementarityProblem.h"
#include "NonSmoothDrivers.h"
#include "NumericsMatrix.h"
#include "NumericsVerbose.h"
#include "RelayProblem.h"
#include "Relay_Solvers.h"
#include "SolverOptions.h"
#include "lcp_cst.h"
#include "relay_cst.h"

namespace mlcp::bench {

const std::vector<SiconosSolverInfo>& siconosSolvers() {
  static const std::vector<SiconosSolverInfo> list = {
      {"lcp_newton_FB", SiconosForm::Lcp, SICONOS_LCP_NEWTON_FB_FBLSA, 1},
      {"lcp_newton_min", SiconosForm::Lcp, SICONOS_LCP_NEWTONMIN, 1},
      {"lcp_newton_minFB", SiconosForm::Lcp, SICONOS_LCP_NEWTON_MIN_FBLSA, 1},
      {"lcp_lexicolemke", SiconosForm::Lcp, SICONOS_LCP_LEMKE, 1},
      {"lcp_pgs", SiconosForm::Lcp, SICONOS_LCP_PGS, 1},
      {"relay_pgs", SiconosForm::Relay, SICONOS_RELAY_PGS, 1},
      {"relay_lexicolemke", SiconosForm::Relay, SICONOS_RELAY_LEMKE, 2},
      {"relay_avi_caoferris", SiconosForm::Relay, SICONOS_RELAY_AVI_CAOFERRIS, 1},
  };
  return list;
}

namespace {

// What the child leaves for the parent, followed by z (n doubles).
struct Shared {
  int done;
  int info;
  int iterations;
  double ms;
  double ownError;
};

double siconosTolerance(const SiconosSolverInfo& solver, const Problem& p, double tolerance) {
  const double qInf = p.b.lpNorm<Eigen::Infinity>(), q2 = p.b.norm();
  if (solver.form == SiconosForm::Lcp) return q2 > 0 ? tolerance * (1 + qInf) / q2 : tolerance;
  return tolerance * (1 + qInf) / (1 + q2);
}

// Column-major dense copy of A (Siconos' NM_DENSE storage).
NumericsMatrix* denseMatrix(const Problem& p) {
  const int n = p.size();
  NumericsMatrix* M = NM_create(NM_DENSE, n, n);
  const DenseMatrix A = p.toDense();
  std::memcpy(M->matrix0, A.data(), sizeof(double) * n * n);  // Eigen's default is column-major
  return M;
}

bool isPivoting(const SiconosSolverInfo& s) {
  return s.id == SICONOS_LCP_LEMKE || s.id == SICONOS_RELAY_LEMKE ||
         s.id == SICONOS_RELAY_AVI_CAOFERRIS;
}

// The child's work: solve and write the results into `out`. Never returns.
[[noreturn]] void solveInChild(const SiconosSolverInfo& solver, const Problem& p,
                               const SiconosLimits& limits, double tolerance, Shared* out,
                               double* z) {
  numerics_set_verbose(0);
  const int n = p.size();
  NumericsMatrix* M = denseMatrix(p);
  Vector q = p.b, lb = p.lo, ub = p.hi, w = Vector::Zero(n);
  std::fill(z, z + n, 0.0);
  SolverOptions* options = solver_options_create(solver.id);
  options->dparam[SICONOS_DPARAM_TOL] = tolerance;
  const int size = solver.sizeFactor * n;
  options->iparam[SICONOS_IPARAM_MAX_ITER] =
      isPivoting(solver) ? 50 * size + 100 : limits.maxIterations;
  // The median of limits.repeat solves, each from zero (tiny problems take microseconds: one
  // solve is below the clock's noise).
  std::vector<double> ms;
  int info = 0;
  for (int k = 0; k < std::max(1, limits.repeat); ++k) {
    std::fill(z, z + n, 0.0);
    w.setZero();
    const auto start = std::chrono::steady_clock::now();
    if (solver.form == SiconosForm::Lcp) {
      LinearComplementarityProblem lcp{n, M, q.data()};
      info = linearComplementarity_driver(&lcp, z, w.data(), options);
    } else {
      RelayProblem relay{n, M, q.data(), lb.data(), ub.data()};
      info = relay_driver(&relay, z, w.data(), options);
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  out->ms = ms[ms.size() / 2];
  out->info = info;
  out->iterations = options->iparam[SICONOS_IPARAM_ITER_DONE];
  out->ownError = options->dparam[SICONOS_DPARAM_RESIDU];
  out->done = 1;
  _exit(0);  // no destructors, no leak checks: the process ends here
}

// Waits for the child until the deadline; kills it then. Returns its wait status, or -1 when
// it was killed at the deadline.
int waitOrKill(pid_t child, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return status;
}

}  // namespace

SiconosOutcome solveWithSiconos(const SiconosSolverInfo& solver, const Problem& problem,
                                const SiconosLimits& limits) {
  SiconosOutcome outcome;
  const int n = problem.size();
  outcome.siconosTolerance = siconosTolerance(solver, problem, limits.tolerance);
  const std::size_t bytes = sizeof(Shared) + sizeof(double) * n;
  void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (memory == MAP_FAILED) {
    outcome.message = "mmap failed";
    return outcome;
  }
  Shared* shared = static_cast<Shared*>(memory);
  double* z = reinterpret_cast<double*>(shared + 1);
  shared->done = 0;
  const pid_t child = fork();
  if (child == 0) solveInChild(solver, problem, limits, outcome.siconosTolerance, shared, z);
  if (child < 0) {
    outcome.message = "fork failed";
  } else {
    const int status = waitOrKill(child, limits.seconds);
    if (status == -1) {
      outcome.end = SiconosOutcome::End::TimeLimit;
      outcome.message = "stopped at the " + std::to_string(limits.seconds) + " s limit";
    } else if (!shared->done) {
      outcome.message =
          WIFSIGNALED(status)
              ? "the solver died of signal " + std::to_string(WTERMSIG(status))
              : "the solver ended the process (exit " + std::to_string(WEXITSTATUS(status)) + ")";
    } else {
      outcome.end = SiconosOutcome::End::Returned;
      outcome.z = Eigen::Map<const Vector>(z, n);
      outcome.ms = shared->ms;
      outcome.info = shared->info;
      outcome.iterations = shared->iterations;
      outcome.ownError = shared->ownError;
    }
  }
  munmap(memory, bytes);
  return outcome;
}

}  // namespace mlcp::bench
