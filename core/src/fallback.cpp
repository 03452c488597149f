#include "mlcp/fallback.hpp"

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
  Vector best;
  Result bestResult;
  bool haveBest = false;
  for (std::size_t k = 0; k < chain_.size(); ++k) {
    Solver& solver = *chain_[k];
    solver.setOptions(options());
    Vector xk;
    Result rk = solver.solveWithGuess(problem, start, xk);
    if (rk.converged()) {
      x = std::move(xk);
      const int earlier = static_cast<int>(k);
      result = std::move(rk);
      result.fallbacks += earlier;
      if (earlier > 0) result.message += " (after " + attempts.str() + ")";
      return;
    }
    attempts << (k ? "; " : "") << solver.name() << ": " << toString(rk.status) << " ("
             << rk.message << ")";
    const bool usable = xk.size() == problem.size() && std::isfinite(rk.residual);
    if (usable && (!haveBest || rk.residual < bestResult.residual)) {
      best = std::move(xk);
      bestResult = std::move(rk);
      haveBest = true;
    }
  }
  result.fallbacks = static_cast<int>(chain_.size());
  if (haveBest) {
    x = std::move(best);
    result.status = bestResult.status;
    result.iterations = bestResult.iterations;
    result.solver = bestResult.solver;
  } else {
    result.status = Status::Failed;
  }
  result.message = "no solver converged: " + attempts.str();
}

namespace {

// The chain for these names, made once and kept so that workspaces are reused.
Solver* cachedChain(std::vector<std::pair<std::string, std::unique_ptr<Solver>>>& cache,
                    const std::string& chain) {
  for (auto& [key, solver] : cache)
    if (key == chain) return solver.get();
  std::unique_ptr<Solver> solver = makeSolver(chain);
  if (!solver) return nullptr;
  cache.emplace_back(chain, std::move(solver));
  return cache.back().second.get();
}

bool registered(const char* name) {
  for (const SolverInfo& info : solvers())
    if (std::string(info.name) == name) return true;
  return false;
}

// Joins the registered names of `wanted` with '>'.
std::string chainOf(std::initializer_list<const char*> wanted) {
  std::string s;
  for (const char* name : wanted)
    if (registered(name)) s += (s.empty() ? "" : ">") + std::string(name);
  return s;
}

bool hasNonPositiveDiagonal(const Problem& p) {
  for (int i = 0; i < p.size(); ++i)
    if (!(p.diagonal(i) > 0)) return true;
  return false;
}

}  // namespace

void AutoSolver::run(const Problem& problem, Vector& x, Result& result) {
  const ProblemClass c = problem.classify();
  if (c == ProblemClass::Empty) {
    result.status = Status::Converged;
    result.message = "auto: empty problem";
    return;
  }
  std::string chain;
  std::string why;
  if (c == ProblemClass::Linear) {
    chain = chainOf({"ldlt", "pgs"});
    why = "linear";
  } else if (hasNonPositiveDiagonal(problem)) {
    chain = chainOf({"lemke", "dantzig"});
    why = "zero or negative diagonal";
  } else if (problem.size() <= pivotingLimit) {
    chain = chainOf({"dantzig", "lemke", "pgs"});
    why = std::string(toString(c)) + ", n <= " + std::to_string(pivotingLimit);
  } else {
    chain = chainOf({"pgs", "dantzig"});
    why = std::string(toString(c)) + ", n > " + std::to_string(pivotingLimit);
  }
  Solver* solver = chain.empty() ? nullptr : cachedChain(cache_, chain);
  if (!solver) {
    result.status = Status::Unsupported;
    result.message = "auto: no registered solver for this problem (" + why + ")";
    return;
  }
  solver->setOptions(options());
  Vector out;
  result = solver->solveWithGuess(problem, x, out);
  if (result.status != Status::InvalidInput && result.status != Status::Unsupported) x = out;
  result.message = "auto (" + why + " -> " + chain + "): " + result.message;
}

}  // namespace mlcp
