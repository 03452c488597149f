// NewtonSolver (mlcp/newton.hpp): answers checked by residual.hpp and against dantzig's
// incremental pivoting, the CHOLMOD path and its symbolic-analysis reuse, the limits.
#include "mlcp/newton.hpp"

#include <gtest/gtest.h>

#include "common/contact_scenes.hpp"
#include "common/generators.hpp"
#include "mlcp/dantzig.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

// A sparse problem of the pyramid's rows (levels boxes at the bottom).
Problem pyramidProblem(int levels, double mu, double side, unsigned seed = 1) {
  test::PyramidSpec spec;
  spec.levels = levels;
  spec.muLo = spec.muHi = mu;
  spec.sideVelocity = side;
  spec.seed = seed;
  test::BoxPyramid pyramid(spec);
  return pyramid.rows().assemble(true);
}

// Generated problems with known solutions: newton converges and agrees with dantzig where the
// solution is unique.
TEST(Newton, AgreesWithDantzigOnGeneratedProblems) {
  test::Generator gen(7);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 5 + gen.pick(40);
    const test::KnownProblem kp = trial % 3 == 0   ? gen.standard(gen.spd(n))
                                  : trial % 3 == 1 ? gen.boxed(gen.spd(n))
                                                   : gen.friction(2 + gen.pick(12));
    NewtonSolver newton;
    DantzigSolver dantzig;
    newton.options().tolerance = dantzig.options().tolerance = 1e-10;
    Vector xn, xd;
    const Result rn = newton.solve(kp.problem, xn);
    const Result rd = dantzig.solve(kp.problem, xd);
    ASSERT_TRUE(rn.converged()) << kp.name << " n = " << n << ": " << rn.message;
    EXPECT_LE(accuracy(kp.problem, xn).residual, 1e-10);
    if (kp.unique && rd.converged()) {
      EXPECT_LE((xn - xd).lpNorm<Eigen::Infinity>(), 1e-7 * (1 + xd.lpNorm<Eigen::Infinity>()))
          << kp.name;
    }
  }
}

// Large enough for CHOLMOD (n > denseMaxRows), frictionless: the same answer as the incremental
// pivoting to the tolerance's order.
TEST(Newton, PyramidCholmodMatchesDantzig) {
  for (double mu : {0.0}) {
    const Problem p = pyramidProblem(6, mu, 0.3);
    ASSERT_GT(p.size(), NewtonParams().denseMaxRows);
    NewtonSolver newton;
    DantzigSolver dantzig;
    newton.options().tolerance = dantzig.options().tolerance = 1e-10;
    Vector xn, xd;
    const Result rn = newton.solve(p, xn);
    const Result rd = dantzig.solve(p, xd);
    ASSERT_TRUE(rn.converged()) << "mu " << mu << ": " << rn.message;
    ASSERT_TRUE(rd.converged()) << rd.message;
    EXPECT_LE(accuracy(p, xn).boundViolation, 1e-12);
    EXPECT_LE((xn - xd).lpNorm<Eigen::Infinity>(), 1e-6 * (1 + xd.lpNorm<Eigen::Infinity>()));
    EXPECT_GT(newton.factorizations(), 0);
  }
}

// A warm start at the answer of a nearby problem settles in a few steps, and the symbolic
// analysis is done once for the pattern.
TEST(Newton, WarmSequenceTakesFewStepsAndOneAnalysis) {
  test::PyramidSpec spec;
  spec.levels = 6;
  spec.muLo = spec.muHi = 0;
  test::BoxPyramid pyramid(spec);
  NewtonSolver newton;
  newton.options().tolerance = 1e-10;
  Vector x;
  ASSERT_TRUE(newton.solve(pyramid.rows().assemble(true), x).converged());
  for (int step = 0; step < 5; ++step) {
    pyramid.nextStep(1e-3);
    const Problem p = pyramid.rows().assemble(true);
    Vector y;
    const Result r = newton.solveWithGuess(p, x, y);
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LE(r.iterations, 3) << "step " << step;
    x = y;
  }
  EXPECT_EQ(newton.analyses(), 1);
}

// Limits: a step limit and a time budget return the best iterate (never worse than the start)
// with an honest status.
TEST(Newton, LimitsReturnTheBestIterate) {
  const Problem p = pyramidProblem(8, 0.6, 0.5);
  const Vector start = Vector::Zero(p.size());
  const double startResidual = residual(p, start);
  {
    NewtonSolver newton;
    newton.options().tolerance = 1e-14;
    newton.options().maxIterations = 1;
    newton.params().coldSweeps = 0;
    Vector x;
    const Result r = newton.solve(p, x);
    if (!r.converged()) {
      EXPECT_EQ(r.status, Status::MaxIterations) << r.message;
      EXPECT_LE(r.residual, startResidual);
    }
  }
  {
    NewtonSolver newton;
    newton.options().tolerance = 1e-14;
    newton.options().timeBudget = 1e-9;
    Vector x;
    const Result r = newton.solve(p, x);
    EXPECT_EQ(r.status, Status::TimeLimit) << r.message;
    EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
    EXPECT_LE(r.iterations, 1);
  }
}

// With friction on a sliding pyramid the bounds' outer refresh converges slowly: a step limit
// ends the solve with MaxIterations, the best iterate and its true residual, below the start's.
TEST(Newton, FrictionPyramidStepLimitIsHonest) {
  const Problem p = pyramidProblem(6, 0.6, 0.3);
  NewtonSolver newton;
  newton.options().tolerance = 1e-12;
  newton.options().maxIterations = 30;
  Vector x;
  const Result r = newton.solve(p, x);
  ASSERT_NE(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.status, Status::MaxIterations) << r.message;
  EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
  EXPECT_LT(r.residual, residual(p, Vector::Zero(p.size())));
  EXPECT_LE(accuracy(p, x).boundViolation, 1e-12);
}

// A nonsymmetric A is refused, not solved wrongly.
TEST(Newton, NonsymmetricIsUnsupported) {
  test::Generator gen(3);
  const int n = 12;
  DenseMatrix a = gen.spd(n);
  a(0, 1) += 0.5;
  Problem p(a, Vector::Constant(n, -1.0));
  NewtonSolver newton;
  Vector x;
  EXPECT_EQ(newton.solve(p, x).status, Status::Unsupported);
}

}  // namespace
}  // namespace mlcp
