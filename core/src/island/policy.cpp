#include "mlcp/island/policy.hpp"

#include <cmath>

namespace mlcp {

Choice Policy::choose(ProblemClass c, int rows, double tolerance, bool positiveDiagonal,
                      bool budgetSpent, bool freeRows) const {
  switch (c) {
    case ProblemClass::Empty: return {"none", "", "empty"};
    case ProblemClass::Linear: return {"ldlt", "pgs", "bilateral rows only"};
    default: break;
  }
  if (!positiveDiagonal) return {"lemke", "newton", "a row with A_ii <= 0"};
  if (rows <= (freeRows ? smallIslandRows : smallContactRows))
    return {"dantzig", "pgs", "small contact island"};
  if (budgetSpent) return {"pgs", "", "large contact island, step budget spent"};
  if (tolerance >= looseTolerance)
    return {"pgs", "dantzig", "large contact island, loose tolerance"};
  // Held by this Policy: the pointer is valid while the Policy is unchanged.
  return {largeIslandSolver.c_str(), "pgs", "large contact island"};
}

bool Policy::continuesShort(ProblemClass c, const std::string& primary) const {
  const bool contacts =
      c == ProblemClass::Findex || c == ProblemClass::Boxed || c == ProblemClass::StandardLcp;
  return contacts && !singularIslandSolver.empty() &&
         (primary == "dantzig" || primary == largeIslandSolver);
}

bool Policy::demotes(const Result& rejected, double acceptResidual, int cutsInRow) const {
  if (rejected.status == Status::Failed || rejected.status == Status::NumericalIssue) return true;
  if (!std::isfinite(rejected.residual)) return true;
  if (rejected.status == Status::TimeLimit && cutsInRow < cutsBeforeDemotion) return false;
  return !(rejected.residual <= nearMiss * acceptResidual);
}

bool acceptable(const Result& r, double acceptResidual) {
  switch (r.status) {
    case Status::Failed:
    case Status::NumericalIssue:
    case Status::InvalidInput:
    case Status::Unsupported: return false;
    case Status::LeastSquares: return std::isfinite(r.residual);  // verified; none does better
    default: break;
  }
  return std::isfinite(r.residual) && r.residual <= acceptResidual;
}

bool better(const Result& candidate, const Result& best) {
  if (!std::isfinite(candidate.residual)) return false;
  return !std::isfinite(best.residual) || candidate.residual < best.residual;
}

}  // namespace mlcp
