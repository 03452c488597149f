// mlcp/fallback.hpp: a verified fallback chain (registry "a>b>c") and the `auto` solver.
//
// FallbackSolver runs its solvers in order. Each answer is checked by the Solver base class
// (residual recomputed, NaN/Inf caught); the first that converges is returned. Otherwise the
// next solver starts again from the caller's start point. Result::fallbacks counts the rejected
// attempts and Result::solver names the solver whose answer is returned; when none converges,
// the answer with the smallest residual is returned with its own status and a message listing
// every attempt. Options set on the chain are passed to every member.
//
// AutoSolver models no more than the problem needs: it classifies the problem and runs
// a chain chosen for that class and size (rules in fallback.cpp, reported in Result::message):
//   empty                 -> nothing to do
//   linear (all equality) -> ldlt > pgs
//   zero/negative A_ii    -> lemke > dantzig   (projected Gauss-Seidel cannot divide by it)
//   n <= pivotingLimit    -> dantzig > lemke > pgs
//   larger                -> pgs > dantzig
// Solvers missing from the registry are skipped.
#pragma once

#include <memory>
#include <string>
#include <vector>

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
};

class AutoSolver : public Solver {
 public:
  const char* name() const override { return "auto"; }
  // Largest problem handed to a pivoting method first. Default 600 rows.
  int pivotingLimit = 600;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  // Chains are kept per choice so that solver workspaces (and ldlt's analysis) are reused.
  std::vector<std::pair<std::string, std::unique_ptr<Solver>>> cache_;
};

}  // namespace mlcp
