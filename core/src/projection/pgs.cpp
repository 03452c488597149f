#include "mlcp/solvers/pgs.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mlcp/residual.hpp"
#include "projection/pgs_sweep.hpp"
#include "projection/sweep_monitor.hpp"

namespace mlcp {

void detail::pgsSweep(const Problem& problem, const Vector& invDiag, double omega, Vector& x) {
  for (int i = 0; i < problem.size(); ++i) {
    const double wi = problem.rowDot(i, x) + problem.b[i];
    x[i] = pgsUpdate(problem, i, wi, invDiag[i], omega, x);
  }
}

int detail::inverseDiagonal(const Problem& problem, Vector& invDiag) {
  invDiag.resize(problem.size());
  for (int i = 0; i < problem.size(); ++i) {
    const double d = problem.diagonal(i);
    if (!(d > 0)) return i;
    invDiag[i] = 1.0 / d;
  }
  return -1;
}

std::string PgsSolver::refuse(const Problem&) const { return ""; }

std::string GaussSeidelSolver::refuse(const Problem& problem) const {
  if (problem.classify() != ProblemClass::Linear && problem.size() > 0)
    return "gs solves problems without bounds (every row -inf..inf); use pgs for bounded rows";
  return "";
}

void PgsSolver::run(const Problem& problem, Vector& x, Result& result) {
  const Options& opt = options();
  const int n = problem.size();
  if (!(opt.relaxation > 0 && opt.relaxation < 2)) {
    std::ostringstream os;
    os << "relaxation " << opt.relaxation << " is outside (0, 2)";
    result.status = Status::InvalidInput;
    result.message = os.str();
    return;
  }
  if (std::string why = refuse(problem); !why.empty()) {
    result.status = Status::Unsupported;
    result.message = why;
    return;
  }
  Vector invDiag;
  if (const int i = detail::inverseDiagonal(problem, invDiag); i >= 0) {
    std::ostringstream os;
    os << "A(" << i << "," << i << ") = " << problem.diagonal(i) << ": " << name()
       << " needs a positive diagonal (use lemke or dantzig)";
    result.status = Status::Failed;
    result.message = os.str();
    return;
  }
  if (n == 0) {
    result.status = Status::Converged;
    result.message = "empty problem";
    return;
  }
  const double omega = opt.relaxation;
  detail::SweepMonitor monitor(opt, result, n);
  for (int sweep = 1; sweep <= opt.maxIterations; ++sweep) {
    detail::pgsSweep(problem, invDiag, omega, x);
    if (monitor.wantsCheck(sweep) ? monitor.stop(sweep, accuracy(problem, x))
                                  : monitor.outOfTime(sweep))
      return;
  }
}

}  // namespace mlcp
