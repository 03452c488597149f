#include "mlcp/island/fallback.hpp"

#include <cmath>

#include "mlcp/registry.hpp"

namespace mlcp {

namespace {
std::string joinNames(const std::vector<std::unique_ptr<Solver>>& chain) {
  std::string s;
  for (const auto& solver : chain) s += (s.empty() ? "" : ">") + std::string(solver->name());
  return s;
}
}  // namespace

FallbackSolver::FallbackSolver(std::vector<std::unique_ptr<Solver>> chain)
    : chain_(std::move(chain)), name_(joinNames(chain_)) {}

void FallbackSolver::run(const Problem& problem, Vector& x, Result& result) {
  std::string attempts;  // built only when a member fails: success costs no message
  Result bestResult;     // residual NaN: any finite answer is better
  for (std::size_t k = 0; k < chain_.size(); ++k) {
    Solver& solver = *chain_[k];
    solver.setOptions(options());
    Result rk = solveInner(solver, problem, x, xk_);  // x holds the start until accepted
    if (acceptable(rk, options().tolerance)) {
      x.swap(xk_);
      result = std::move(rk);
      result.fallbacks += static_cast<int>(k);
      if (k > 0) result.message += " (after " + attempts + ")";
      keepInnerCheck();
      return;
    }
    attempts += std::string(k ? "; " : "") + solver.name() + ": " + toString(rk.status) + " (" +
                rk.message + ")";
    if (xk_.size() == problem.size() && better(rk, bestResult)) {
      best_.swap(xk_);
      bestResult = std::move(rk);
    }
  }
  result.fallbacks = static_cast<int>(chain_.size());
  if (std::isfinite(bestResult.residual)) {
    x.swap(best_);
    result.status = bestResult.status;
    result.iterations = bestResult.iterations;
    result.solver = bestResult.solver;
    result.message = "no answer acceptable, the best (" + result.solver + "'s) returned: ";
  } else {
    result.status = Status::Failed;  // x is the start
    result.message = "no solver found a finite answer, the start returned: ";
  }
  result.message += attempts;
}

namespace {

// The chain for these names, made once and kept so that workspaces are reused.
Solver* cachedChain(std::vector<std::pair<std::string, std::unique_ptr<Solver>>>& cache,
                    const std::string& chain, const std::function<void(Solver&)>& configure) {
  for (auto& [key, solver] : cache)
    if (key == chain) return solver.get();
  std::unique_ptr<Solver> solver = makeSolver(chain);
  if (!solver) return nullptr;
  if (configure) configure(*solver);
  cache.emplace_back(chain, std::move(solver));
  return cache.back().second.get();
}

bool positiveDiagonal(const Problem& p) {
  for (int i = 0; i < p.size(); ++i)
    if (!(p.diagonal(i) > 0)) return false;
  return true;
}

}  // namespace

void AutoSolver::run(const Problem& problem, Vector& x, Result& result) {
  const ProblemClass c = problem.classify();
  if (c == ProblemClass::Empty) {
    result.status = Status::Converged;
    result.message = "auto: empty problem";
    return;
  }
  const Choice choice =
      policy.choose(c, problem.size(), options().tolerance, positiveDiagonal(problem), false,
                    hasFreeRows(problem.lo, problem.hi));
  Solver* solver = chainFor(choice);
  // "<why>, <class>, <n> rows": built in one string (an engine-sized message, one allocation).
  const auto why = [&](std::string& s) {
    (((s += choice.why) += ", ") += toString(c)) += ", ";
    (s += std::to_string(problem.size())) += " rows";
  };
  if (!solver) {
    result.status = Status::Unsupported;
    result.message = "auto: no registered solver for this problem (";
    why(result.message);
    result.message += ")";
    return;
  }
  solver->setOptions(options());
  result = solveInner(*solver, problem, x, out_);
  const bool answered =
      result.status != Status::InvalidInput && result.status != Status::Unsupported;
  if (answered) x.swap(out_);
  std::string message;
  message.reserve(64 + last_.chain.size() + result.message.size());
  why(message += "auto (");
  (((message += " -> ") += last_.chain) += "): ") += result.message;
  result.message.swap(message);
  if (!answered) return;
  continueSingular(problem, c, choice, x, result);
  keepInnerCheck();  // x and result are the last inner solve's, checked there
}

// The registered part of the choice's chain, made once and kept. The last choice's is
// remembered when both its solvers are registered (registration only adds): a repeat solve of
// one class and size finds it with two string comparisons.
Solver* AutoSolver::chainFor(const Choice& choice) {
  if (last_.solver && last_.first == choice.solver && last_.second == choice.fallback)
    return last_.solver;
  last_.chain.clear();
  bool all = true;
  for (const char* name : {choice.solver, choice.fallback}) {
    const bool registered = isRegistered(name);
    all = all && (registered || !*name);  // an empty fallback: none
    if (registered) last_.chain += (last_.chain.empty() ? "" : ">") + std::string(name);
  }
  Solver* solver = last_.chain.empty() ? nullptr : cachedChain(cache_, last_.chain, configure);
  last_.first = choice.solver;
  last_.second = choice.fallback;
  last_.solver = all ? solver : nullptr;
  return solver;
}

// An exact method's answer on contact rows that ended short of the tolerance (a singular A: a
// pile without cfm) goes on with the policy's singular-island solver from it, in the time left;
// the better answer stands (RowSolver does the same for engine islands).
void AutoSolver::continueSingular(const Problem& problem, ProblemClass c, const Choice& choice,
                                  Vector& x, Result& result) {
  const std::string& singular = policy.singularIslandSolver;
  if (result.status == Status::Converged || !policy.continuesShort(c, choice.solver) ||
      !isRegistered(singular) || x.size() != problem.size() || !x.allFinite() || outOfTime())
    return;
  Solver* s = cachedChain(cache_, singular, configure);
  s->setOptions(options());
  Result r = solveInner(*s, problem, x, out_);
  if (!better(r, result)) {
    result.message += "; " + singular + " from its answer no better (" + toString(r.status) + ")";
    return;
  }
  r.message = result.message + "; " + singular + " from its answer: " + r.message;
  r.iterations += result.iterations;
  result = std::move(r);
  x.swap(out_);
}

}  // namespace mlcp
