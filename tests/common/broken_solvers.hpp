// Solvers that break on purpose, to check that fallbacks happen, are counted and reported.
// registerBrokenSolvers() adds them to the registry as "test-nan", "test-fail", "test-explode" and
// "test-throw", so that the adapters (which take solvers by name) can be handed them too.
#pragma once

#include <cmath>
#include <stdexcept>

#include "mlcp/registry.hpp"
#include "mlcp/solver.hpp"

namespace mlcp::test {

class BrokenSolver : public Solver {
 public:
  // nan: answers NaN and claims Converged (a lying solver: the base class must catch it);
  // otherwise reports Failed and leaves the start.
  explicit BrokenSolver(bool nan) : nan_(nan) {}
  const char* name() const override { return nan_ ? "test-nan" : "test-fail"; }

 protected:
  void run(const Problem&, Vector& x, Result& result) override {
    if (nan_) {
      x.setConstant(std::nan(""));
      result.status = Status::Converged;
    } else {
      result.status = Status::Failed;
      result.message = "injected failure";
    }
  }

 private:
  bool nan_;
};

// Answers the start plus 1e4 in every row and claims MaxIterations: an exploded iterate, finite
// and far too large (what a diverged method or a singular system's regularised answer gives).
class ExplodingSolver : public Solver {
 public:
  const char* name() const override { return "test-explode"; }

 protected:
  void run(const Problem&, Vector& x, Result& result) override {
    x.array() += 1e4;
    result.status = Status::MaxIterations;
    result.message = "injected explosion";
  }
};

// Throws std::runtime_error("injected exception") from its solve: an exception from inside an
// engine's step, for the adapters' error paths.
class ThrowingSolver : public Solver {
 public:
  const char* name() const override { return "test-throw"; }

 protected:
  void run(const Problem&, Vector&, Result&) override {
    throw std::runtime_error("injected exception");
  }
};

inline void registerBrokenSolvers() {
  static const bool done = [] {
    registerSolver({"test-nan", "answers NaN (tests only)",
                    [] { return std::unique_ptr<Solver>(new BrokenSolver(true)); }});
    registerSolver({"test-fail", "reports Failed (tests only)",
                    [] { return std::unique_ptr<Solver>(new BrokenSolver(false)); }});
    registerSolver({"test-explode", "answers the start + 1e4 (tests only)",
                    [] { return std::unique_ptr<Solver>(new ExplodingSolver()); }});
    registerSolver({"test-throw", "throws from its solve (tests only)",
                    [] { return std::unique_ptr<Solver>(new ThrowingSolver()); }});
    return true;
  }();
  (void)done;
}

}  // namespace mlcp::test
