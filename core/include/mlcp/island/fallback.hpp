// mlcp/island/fallback.hpp: a verified fallback chain (registry "a>b>c") and the registry's `auto`.
//
// FallbackSolver runs its solvers in order under the fallback rule of policy.hpp: each answer
// is checked by the Solver base class (residual recomputed, NaN/Inf caught); the first
// acceptable one (here: converged, residual <= Options::tolerance) is returned, otherwise the
// next solver starts again from the caller's start point, and when none is acceptable the best
// answer any of them found (lowest finite residual) is returned with its own status and a
// message listing every attempt. Result::fallbacks counts the answers passed over and
// Result::solver names the solver whose answer is returned. Options set on the chain are passed
// to every member; a time budget is the chain's, shared by its members (each does at least one
// bounded chunk of work before it reads the clock, so a late member still improves on the
// start).
//
// AutoSolver classifies the problem, asks Policy (policy.hpp) for a solver and its fallback and
// runs that two-member chain; an exact method's answer on contact rows still short of the
// tolerance then goes on with Policy::singularIslandSolver (proximal) from it, in the time left.
// The choice and its reason open Result::message. Solvers missing
// from the registry are skipped. `configure` reaches the solvers it makes (to set their typed
// parameters, e.g. NewtonParams): each chain is passed to it once, when made.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/island/policy.hpp"
#include "mlcp/solver.hpp"

namespace mlcp {

class FallbackSolver : public Solver {
 public:
  explicit FallbackSolver(std::vector<std::unique_ptr<Solver>> chain);
  const char* name() const override { return name_.c_str(); }
  const std::vector<std::unique_ptr<Solver>>& chain() const { return chain_; }

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  std::vector<std::unique_ptr<Solver>> chain_;
  std::string name_;
  Vector xk_, best_;  // kept across solves: a repeat solve of one size does not allocate
};

class AutoSolver : public Solver {
 public:
  const char* name() const override { return "auto"; }
  // The rules; change them between solves (e.g. policy.largeIslandSolver = "newton").
  Policy policy;
  // Called on each chain auto makes, before its first solve (a FallbackSolver: reach its
  // members through chain()); empty: none. Set it before the first solve.
  std::function<void(Solver&)> configure;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  Solver* chainFor(const Choice& choice);
  void continueSingular(const Problem& problem, ProblemClass c, const Choice& choice, Vector& x,
                        Result& result);
  // Chains are kept per choice so that solver workspaces (and ldlt's analysis) are reused.
  std::vector<std::pair<std::string, std::unique_ptr<Solver>>> cache_;
  Vector out_;  // the chain's answer, kept across solves
  struct LastChain {
    std::string first, second, chain;  // the choice's solver and fallback; the chain made
    Solver* solver = nullptr;          // null: nothing remembered
  } last_;
};

}  // namespace mlcp
