// mlcp/island/island_solve.hpp: what one island's solve reports (IslandSolve: whose answer, the
// class of the rows, whether it fell back or was judged unsafe, what the screen took out) and the
// per-step tally of those choices an adapter keeps (ChoiceCounts), e.g. "dantzig:3 ldlt:1".
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "mlcp/island/friction_model.hpp"
#include "mlcp/island/row_screen.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"

namespace mlcp {

// What one island's solve gives back.
struct IslandSolve {
  // The returned answer's result: status, iterations, residual (recomputed), seconds (the
  // primary's and the fallback's, assembly included), message (with the rejection reason).
  Result result;
  ProblemClass problemClass = ProblemClass::Empty;
  // the solver whose answer was returned ("none" for no rows, "start" when the start already
  // solved them: stage 3)
  std::string choice;
  std::string requested;       // the primary that ran ("auto"'s choice, or the requested name)
  bool fellBack = false;       // the primary's answer was rejected and the fallback ran
  bool accepted = true;        // the returned answer passes acceptable()
  double assembleSeconds = 0;  // part of result.seconds spent classifying and assembling A
  ScreenCounts screened;       // rows screened in stage 0 (inert ones answered x = 0)
  // Stage 5 replaced the lowest-residual answer, whose velocity change was far above pgs's, by
  // pgs's.
  bool energyGuard = false;
  // The friction model of the returned answer: Cone when the cone's LCP answered (result then
  // holds that LCP's residual), Box otherwise (no friction rows, the cone refused the island,
  // or the fallback's box answer was returned).
  FrictionModel friction = FrictionModel::Box;
};

// Counts of IslandSolve::choice over a step, e.g. "dantzig:3 ldlt:1 none:2".
class ChoiceCounts {
 public:
  void add(const std::string& choice, int count = 1);
  void add(const ChoiceCounts& other);
  void clear() { counts_.clear(); }
  int count(const std::string& choice) const;
  int total() const;
  // "name:count" pairs in name order, space separated; "" when empty.
  std::string toString() const;
  const std::vector<std::pair<std::string, int>>& counts() const { return counts_; }

 private:
  std::vector<std::pair<std::string, int>> counts_;  // sorted by name
};

}  // namespace mlcp
