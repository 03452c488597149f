#include "mlcp/island/fallback.hpp"

#include <cmath>
#include <sstream>

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
  const Vector start = x;
  std::ostringstream attempts;
  Vector best, xk;
  Result bestResult;  // residual NaN: any finite answer is better
  for (std::size_t k = 0; k < chain_.size(); ++k) {
    Solver& solver = *chain_[k];
    solver.setOptions(options());
    Result rk = solver.solveWithGuess(problem, start, xk);
    if (acceptable(rk, options().tolerance)) {
      x.swap(xk);
      result = std::move(rk);
      result.fallbacks += static_cast<int>(k);
      if (k > 0) result.message += " (after " + attempts.str() + ")";
      return;
    }
    attempts << (k ? "; " : "") << solver.name() << ": " << toString(rk.status) << " ("
             << rk.message << ")";
    if (xk.size() == problem.size() && better(rk, bestResult)) {
      best.swap(xk);
      bestResult = std::move(rk);
    }
  }
  result.fallbacks = static_cast<int>(chain_.size());
  if (std::isfinite(bestResult.residual)) {
    x.swap(best);
    result.status = bestResult.status;
    result.iterations = bestResult.iterations;
    result.solver = bestResult.solver;
    result.message = "no answer acceptable, the best (" + result.solver + "'s) returned: ";
  } else {
    result.status = Status::Failed;  // x is the start
    result.message = "no solver found a finite answer, the start returned: ";
  }
  result.message += attempts.str();
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
  std::string chain;
  for (const char* name : {choice.solver, choice.fallback})
    if (isRegistered(name)) chain += (chain.empty() ? "" : ">") + std::string(name);
  Solver* solver = chain.empty() ? nullptr : cachedChain(cache_, chain, configure);
  const std::string why = std::string(choice.why) + ", " + toString(c) + ", " +
                          std::to_string(problem.size()) + " rows";
  if (!solver) {
    result.status = Status::Unsupported;
    result.message = "auto: no registered solver for this problem (" + why + ")";
    return;
  }
  solver->setOptions(options());
  Vector out;
  result = solver->solveWithGuess(problem, x, out);
  const bool answered =
      result.status != Status::InvalidInput && result.status != Status::Unsupported;
  if (answered) x = out;
  result.message = "auto (" + why + " -> " + chain + "): " + result.message;
  if (answered) continueSingular(problem, c, choice, x, result);
}

// An exact method's answer on contact rows that ended short of the tolerance (a singular A: a
// pile without cfm) goes on with the policy's singular-island solver from it, in the time left;
// the better answer stands (RowSolver does the same for engine islands).
void AutoSolver::continueSingular(const Problem& problem, ProblemClass c, const Choice& choice,
                                  Vector& x, Result& result) {
  const std::string& singular = policy.singularIslandSolver;
  if (!policy.continuesShort(c, choice.solver) || !isRegistered(singular) ||
      result.status == Status::Converged || x.size() != problem.size() || !x.allFinite() ||
      outOfTime())
    return;
  Solver* s = cachedChain(cache_, singular, configure);
  s->setOptions(options());
  Vector out;
  Result r = s->solveWithGuess(problem, x, out);
  if (!better(r, result)) {
    result.message += "; " + singular + " from its answer no better (" + toString(r.status) + ")";
    return;
  }
  r.message = result.message + "; " + singular + " from its answer: " + r.message;
  r.iterations += result.iterations;
  result = std::move(r);
  x = out;
}

}  // namespace mlcp
