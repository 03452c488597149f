// Internal: the stopping logic every sweep-based method shares (pgs on A, pgs on rows).
#pragma once

#include <algorithm>
#include <limits>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/result.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::detail {

class SweepMonitor {
 public:
  // rows: the rows one sweep updates (the unit of the budget's clock reads).
  SweepMonitor(const Options& options, Result& result, int rows)
      : opt_(options),
        result_(result),
        deadline_(budgetDeadline(options)),
        sweepsPerClockRead_(std::max(1, kRowsPerClockRead / std::max(1, rows))) {
    result_.status = Status::MaxIterations;
    result_.message = "iteration limit reached";
  }

  // Between checks: true when the time budget is spent (status and message set). Reads the
  // clock once per kRowsPerClockRead row updates: ~1% of the sweeps' cost, and the budget is
  // overrun by at most that many row updates (~1-10 us).
  bool outOfTime(int sweep) {
    if (deadline_ == kNoDeadline || sweep % sweepsPerClockRead_ != 0) return false;
    if (nowSeconds() <= deadline_) return false;
    result_.iterations = sweep;
    return finish(Status::TimeLimit, "time budget spent");
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
    if (deadline_ != kNoDeadline && nowSeconds() > deadline_)
      return finish(Status::TimeLimit, "time budget spent");
    return false;
  }

 private:
  bool finish(Status s, std::string message) {
    result_.status = s;
    result_.message = std::move(message);
    return true;
  }
  static constexpr int kRowsPerClockRead = 1024;
  static constexpr double kNoDeadline = std::numeric_limits<double>::infinity();
  const Options& opt_;
  Result& result_;
  double deadline_;
  int sweepsPerClockRead_;
  double first_ = -1;
};

}  // namespace mlcp::detail
