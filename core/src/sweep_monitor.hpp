// Internal: the stopping logic every sweep-based method shares (pgs on A, pgs on rows).
#pragma once

#include <algorithm>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/result.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::detail {

class SweepMonitor {
 public:
  SweepMonitor(const Options& options, Result& result)
      : opt_(options), result_(result), start_(nowSeconds()) {
    result_.status = Status::MaxIterations;
    result_.message = "iteration limit reached";
  }

  // Whether the residual should be evaluated after this sweep (1-based).
  bool wantsCheck(int sweep) const {
    return opt_.recordHistory || sweep % std::max(1, opt_.checkEvery) == 0 ||
           sweep == opt_.maxIterations;
  }

  // Record sweep's accuracy; true when the iteration must stop (status and message set).
  bool stop(int sweep, const Accuracy& a) {
    result_.iterations = sweep;
    if (opt_.recordHistory) result_.history.push_back(a.residual);
    if (!a.finite)
      return finish(Status::NumericalIssue, "the sweep produced NaN or Inf (diverged)");
    if (a.residual <= opt_.tolerance) return finish(Status::Converged, "residual within tolerance");
    if (first_ < 0) first_ = a.residual;
    if (a.residual > 1 && a.residual > 1e8 * std::max(first_, 1e-300)) {
      std::ostringstream os;
      os << "diverged: residual grew from " << first_ << " to " << a.residual
         << " (A is likely not positive definite)";
      return finish(Status::Failed, os.str());
    }
    if (opt_.timeBudget > 0 && nowSeconds() - start_ > opt_.timeBudget)
      return finish(Status::TimeLimit, "time budget spent");
    return false;
  }

 private:
  bool finish(Status s, std::string message) {
    result_.status = s;
    result_.message = std::move(message);
    return true;
  }
  const Options& opt_;
  Result& result_;
  double start_;
  double first_ = -1;
};

}  // namespace mlcp::detail
