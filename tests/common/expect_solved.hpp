// expectSolved: solves a known problem and checks the answer independently of the solver.
#pragma once

#include <gtest/gtest.h>

#include "common/generators.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::test {

// Solves and checks the answer independently: residual, and x* when the solution is unique.
template <class S>
Result expectSolved(S& s, const KnownProblem& kp, double tol = 1e-9) {
  Vector x;
  const Result r = s.solve(kp.problem, x);
  EXPECT_TRUE(r.converged()) << kp.name << ": " << toString(r.status) << " " << r.message;
  const Accuracy a = accuracy(kp.problem, x);
  EXPECT_LE(a.residual, tol) << kp.name;
  EXPECT_LE(a.boundViolation, tol * (1 + kp.problem.b.lpNorm<Eigen::Infinity>())) << kp.name;
  if (kp.unique && x.size() == kp.solution.size()) {
    EXPECT_LE((x - kp.solution).lpNorm<Eigen::Infinity>(), 1e-8 * (1 + kp.solution.norm()))
        << kp.name;
  }
  return r;
}

}  // namespace mlcp::test
