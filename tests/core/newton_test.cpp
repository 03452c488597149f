// NewtonSolver (mlcp/solvers/newton.hpp): answers checked by residual.hpp and against dantzig's
// incremental pivoting and lemke, the sparse LU path and its symbolic-analysis reuse, friction
// islands warm-started, nonsymmetric problems, the limits.
#include "mlcp/solvers/newton.hpp"

#include <gtest/gtest.h>

#include "common/contact_scenes.hpp"
#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp {
namespace {

// A pyramid of levels boxes at the bottom, friction coefficient mu, horizontal velocities up to
// side.
test::PyramidSpec pyramidSpec(int levels, double mu, double side = 0) {
  test::PyramidSpec spec;
  spec.levels = levels;
  spec.muLo = spec.muHi = mu;
  spec.sideVelocity = side;
  return spec;
}

// Its rows' problem, sparse.
Problem pyramidProblem(int levels, double mu, double side) {
  test::BoxPyramid pyramid(pyramidSpec(levels, mu, side));
  return pyramid.rows().assemble(true);
}

// The friction pyramid's answer by dantzig (to 1e-10) in `answer`, then the next step's problem,
// of which that answer is a near warm start.
Problem nextStepAfterAnswer(Vector& answer) {
  test::BoxPyramid pyramid(pyramidSpec(6, 0.6));
  DantzigSolver dantzig;
  dantzig.options().tolerance = 1e-10;
  EXPECT_TRUE(dantzig.solve(pyramid.rows().assemble(true), answer).converged());
  pyramid.nextStep(1e-3);
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

// Large enough for the sparse LU (n > denseFactorMaxRows), frictionless: the same answer as the
// incremental pivoting to the tolerance's order.
TEST(Newton, PyramidSparseMatchesDantzig) {
  for (double mu : {0.0}) {
    const Problem p = pyramidProblem(6, mu, 0.3);
    ASSERT_GT(p.size(), NewtonParams().denseFactorMaxRows);
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

// A warm start at the answer of a nearby problem settles in a few steps.
TEST(Newton, WarmSequenceTakesFewSteps) {
  test::BoxPyramid pyramid(pyramidSpec(6, 0));
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
    // 2, 3, 6, 2, 3 steps (the third 5 with the monotone line search, nonmonotoneMemory 0).
    EXPECT_LE(r.iterations, 6) << "step " << step;
    x = y;
  }
}

// With the problem's rows (Solver::useRows, as RowSolver passes them) the reduced systems are
// factored in body space and the iterates are those of the sparse LU without them, warm steps
// of a friction pyramid from dantzig's answer (sliding rows couple to their normals). With
// cfm = 0 the last steps' tiny proximal weight leaves body space to the sparse LU.
TEST(Newton, RowsFactorInBodySpaceWithTheSparseLusIterates) {
  for (const double cfm : {1e-5 * 60, 0.0}) {
    test::PyramidSpec spec = pyramidSpec(6, 0.6);
    spec.cfm = cfm;
    test::BoxPyramid pyramid(spec);
    DantzigSolver dantzig;
    dantzig.options().tolerance = 1e-10;
    Vector x;
    ASSERT_TRUE(dantzig.solve(pyramid.rows().assemble(true), x).converged());
    Vector y = x;
    NewtonSolver with, without;
    with.options().tolerance = without.options().tolerance = 1e-9;
    int inBodySpace = 0, factorizations = 0;
    for (int step = 0; step < 4; ++step) {
      pyramid.nextStep(1e-3);
      const Problem p = pyramid.rows().assemble(true);
      ASSERT_GT(p.size(), with.params().denseFactorMaxRows);
      const Vector gx = x, gy = y;
      with.useRows(&pyramid.rows());
      const Result r = with.solveWithGuess(p, gx, x);
      with.useRows(nullptr);
      const Result ref = without.solveWithGuess(p, gy, y);
      ASSERT_TRUE(ref.converged()) << cfm << " step " << step << ": " << ref.message;
      ASSERT_TRUE(r.converged()) << cfm << " step " << step << ": " << r.message;
      EXPECT_LE(accuracy(p, x).residual, 1e-9) << step;
      if (cfm > 0) {
        EXPECT_EQ(r.iterations, ref.iterations) << step;
        EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-8 * (1 + y.lpNorm<Eigen::Infinity>()))
            << step;
      }
      EXPECT_EQ(without.bodyFactorizations(), 0);
      inBodySpace += with.bodyFactorizations();
      factorizations += with.factorizations();
    }
    EXPECT_GT(inBodySpace, 0) << cfm;
    if (cfm > 0) {
      EXPECT_EQ(inBodySpace, factorizations);
    }
  }
}

// A solver that took a problem with its rows (body space) and then one without them, or a small
// one on the dense path, uses A's own products there: the body-space state of the last problem
// was left set for the dense path, whose slack then came from the old rows (read past x's end).
TEST(Newton, BodySpaceStateDoesNotOutliveItsProblem) {
  test::BoxPyramid large(pyramidSpec(6, 0));
  NewtonSolver newton;
  Vector last, x;
  const Problem p = nextStepAfterAnswer(last);
  newton.useRows(&large.rows());
  newton.solve(large.rows().assemble(true), x);
  newton.useRows(nullptr);
  EXPECT_GT(newton.bodyFactorizations(), 0);
  test::BoxPyramid small(pyramidSpec(2, 0.6));
  const Problem q = small.rows().assemble(true);
  ASSERT_LE(q.size(), newton.params().denseFactorMaxRows);
  const Result r = newton.solve(q, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(accuracy(q, x).residual, newton.options().tolerance);
  const Result again = newton.solveWithGuess(p, last, x);  // sparse, without rows
  ASSERT_TRUE(again.converged()) << again.message;
  EXPECT_EQ(newton.bodyFactorizations(), 0);
}

// A warm start far from an answer (scaled residual above warmSweepsResidual, as ODE's impulses
// of the last step on new contacts are) is swept before the first Newton step; a near one is
// used as given. With no Newton step allowed (and no pivoting phase) the answer is the better of
// the start and the swept point.
TEST(Newton, FarWarmStartIsSweptNearOneIsKept) {
  Vector answer;
  const Problem p = nextStepAfterAnswer(answer);
  const Vector far = 4.0 * answer;
  const double farResidual = accuracy(p, far).residual;
  ASSERT_GT(farResidual, NewtonParams().warmSweepsResidual);
  ASSERT_LT(accuracy(p, answer).residual, NewtonParams().warmSweepsResidual);
  auto startOf = [&](const Vector& guess, int sweeps) {
    NewtonSolver newton;
    newton.options().maxIterations = 0;
    newton.params().warmSweeps = sweeps;
    newton.params().pivotingSteps = 0;
    Vector x;
    newton.solveWithGuess(p, guess, x);
    return x;
  };
  const Vector swept = startOf(far, NewtonParams().warmSweeps);
  EXPECT_LT(accuracy(p, swept).residual, 0.5 * farResidual);
  EXPECT_TRUE((startOf(far, 0).array() == far.array()).all());
  EXPECT_TRUE((startOf(answer, NewtonParams().warmSweeps).array() == answer.array()).all());
}

// A step limit and a time budget return the best iterate (never worse than the start) with an
// honest status.
TEST(Newton, LimitsReturnTheBestIterate) {
  const Problem p = pyramidProblem(8, 0.6, 0.5);
  const Vector start = Vector::Zero(p.size());
  const double startResidual = residual(p, start);
  NewtonSolver newton;
  newton.options().tolerance = 1e-14;
  newton.options().maxIterations = 1;
  newton.params().coldSweeps = 0;
  Vector x;
  const Result r = newton.solve(p, x);
  ASSERT_EQ(r.status, Status::MaxIterations) << r.message;
  EXPECT_LE(r.residual, startResidual);
  EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
}

// A time budget ends the solve with TimeLimit near the budget, and the answer is better than the
// start: the budget was spent on steps, not on returning the start.
TEST(Newton, TimeBudgetEndsWithProgress) {
  const Problem p = pyramidProblem(8, 0.6, 0.5);
  const double startResidual = residual(p, Vector::Zero(p.size()));
  NewtonSolver newton;
  newton.options().tolerance = 1e-14;
  newton.options().maxIterations = 100000;
  newton.options().timeBudget = 0.05;
  Vector x;
  const Result r = newton.solve(p, x);
  EXPECT_EQ(r.status, Status::TimeLimit) << r.message;
  EXPECT_GE(r.iterations, 1);
  EXPECT_LT(r.residual, 0.5 * startResidual) << r.message;
  EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
  EXPECT_LT(r.seconds, 2.0);  // the budget plus one step's work, with room for sanitizers
}

// Cold on a sliding friction pyramid the step limit ends the solve with MaxIterations, the best
// iterate and its true residual, below the start's.
TEST(Newton, FrictionPyramidStepLimitIsHonest) {
  const Problem p = pyramidProblem(6, 0.6, 0.3);
  NewtonSolver newton;
  newton.options().tolerance = 1e-12;
  newton.options().maxIterations = 10;
  Vector x;
  const Result r = newton.solve(p, x);
  ASSERT_NE(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.status, Status::MaxIterations) << r.message;
  EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
  EXPECT_LT(r.residual, residual(p, Vector::Zero(p.size())));
}

// A friction island warm-started from the last step's answer, where the lagged friction bounds
// (one refresh per step, each step symmetric) ended at 2e-6 after 100 steps: with the friction
// rows' exact Jacobian it converges to 1e-6 in a few steps, to dantzig's answer.
TEST(Newton, WarmFrictionPyramidConvergesWhereLaggedBoundsStalled) {
  Vector last;
  const Problem p = nextStepAfterAnswer(last);
  ASSERT_GT(p.size(), NewtonParams().denseFactorMaxRows);  // the sparse path
  NewtonSolver newton;
  newton.options().tolerance = 1e-6;
  newton.options().maxIterations = 10;
  Vector x;
  const Result r = newton.solveWithGuess(p, last, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(accuracy(p, x).residual, 1e-6);
  DantzigSolver dantzig;
  dantzig.options().tolerance = 1e-10;
  Vector xd;
  ASSERT_TRUE(dantzig.solve(p, xd).converged());
  EXPECT_LE((x - xd).lpNorm<Eigen::Infinity>(), 1e-3 * (1 + xd.lpNorm<Eigen::Infinity>()));
}

// Friction islands captured from scenes (`mlcp run SCENE --capture 30`: a box sliding down an
// incline in both engines, a row of dominoes in Bullet), cold on the dense path: newton
// converges to 1e-9 with dantzig, and the answers agree.
TEST(Newton, CapturedFrictionIslandsAgreeWithDantzig) {
  for (const char* name : {"incline_slide_bullet", "incline_slide_ode", "dominoes_bullet"}) {
    const Problem p =
        io::readProblem(std::string(MLCP_SOURCE_DIR) + "/tests/data/islands/" + name + ".json");
    ASSERT_TRUE(p.hasFindex()) << name;
    NewtonSolver newton;
    DantzigSolver dantzig;
    newton.options().tolerance = dantzig.options().tolerance = 1e-9;
    Vector xn, xd;
    const Result rn = newton.solve(p, xn);
    ASSERT_TRUE(rn.converged()) << name << ": " << rn.message;
    ASSERT_TRUE(dantzig.solve(p, xd).converged()) << name;
    EXPECT_LE((xn - xd).lpNorm<Eigen::Infinity>(), 1e-6 * (1 + xd.lpNorm<Eigen::Infinity>()))
        << name;
  }
}

// Nonsymmetric positive definite A (a P-matrix: one solution), on the dense path and on the
// sparse one: newton's answer is lemke's.
TEST(Newton, NonsymmetricProblemsAreSolved) {
  test::Generator gen(3);
  for (int n : {12, 40}) {
    DenseMatrix a = gen.spd(n);
    DenseMatrix skew = DenseMatrix::Zero(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < i; ++j) skew(i, j) = -(skew(j, i) = gen.uniform(-1, 1));
    for (const test::KnownProblem& kp : {gen.standard(a + skew), gen.boxed(a + skew)}) {
      NewtonSolver newton;
      newton.options().tolerance = 1e-10;
      Vector x;
      const Result r = newton.solve(kp.problem, x);
      ASSERT_TRUE(r.converged()) << kp.name << " n = " << n << ": " << r.message;
      EXPECT_LE((x - kp.solution).lpNorm<Eigen::Infinity>(),
                1e-7 * (1 + kp.solution.lpNorm<Eigen::Infinity>()));
    }
  }
  // Sparse: a banded nonsymmetric M-matrix, n above the dense limit.
  const int n = 400;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 4.0);
    if (i + 1 < n) t.emplace_back(i, i + 1, -1.5);
    if (i > 0) t.emplace_back(i, i - 1, -0.5);
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(0.1 * i);
  const Problem p(a, b);
  NewtonSolver newton;
  LemkeSolver lemke;
  newton.options().tolerance = lemke.options().tolerance = 1e-10;
  Vector xn, xl;
  const Result rn = newton.solve(p, xn);
  ASSERT_TRUE(rn.converged()) << rn.message;
  ASSERT_TRUE(lemke.solve(p, xl).converged());
  EXPECT_LE((xn - xl).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LE(newton.analyses(), newton.factorizations());
}

// A warm sequence of a resting pyramid without cfm (Bullet's contacts), mu 0.6, b moved by 1% of
// g dt a step: with the monotone Armijo rule no solve reaches 1e-6 in 50 steps (the steps across
// the sliding rows' kinks are halved and the proximal weight grows); with the non-monotone rule
// (docs/methods/newton.md, "Step") some do, in fewer steps overall.
TEST(Newton, NonmonotoneLineSearchLetsFullStepsAcrossKinks) {
  int steps[2] = {0, 0}, converged[2] = {0, 0};
  for (const int memory : {0, 1}) {
    test::PyramidSpec spec = pyramidSpec(6, 0.6);
    spec.cfm = 0;
    test::BoxPyramid pyramid(spec);
    NewtonSolver newton;
    newton.params().nonmonotoneMemory = memory;
    newton.options().tolerance = 1e-6;
    newton.options().maxIterations = 50;
    newton.useRows(&pyramid.rows());
    Vector x = Vector::Zero(pyramid.rows().size());
    for (int step = 0; step < 6; ++step) {
      if (step > 0) pyramid.nextStep(1e-2);
      Vector y;
      const Result r = newton.solveWithGuess(pyramid.rows().assemble(true), x, y);
      steps[memory] += r.iterations;
      converged[memory] += r.converged() ? 1 : 0;
      x = y;
    }
  }
  EXPECT_EQ(converged[0], 0);
  EXPECT_GE(converged[1], 1);
  EXPECT_LT(steps[1], steps[0]);
}

// The pivoting phase (newton.hpp): ten damped steps leave a cold friction pyramid short of the
// tolerance; block principal pivoting from their best iterate ends within it, without and with
// the rows (body space). Without the phase the damped steps' answer stands,
// with an honest status.
TEST(Newton, PivotingPhaseFinishesWhatTheDampedStepsLeftShort) {
  test::PyramidSpec spec;
  spec.levels = 5;
  test::BoxPyramid pyramid(spec);
  const Problem p = pyramid.rows().assemble(true);
  ASSERT_GT(p.size(), NewtonParams().denseFactorMaxRows);  // the sparse path
  for (const bool rows : {false, true}) {
    NewtonSolver newton;
    newton.options().tolerance = 1e-6;
    newton.options().maxIterations = 10;
    newton.useRows(rows ? &pyramid.rows() : nullptr);
    newton.params().pivotingSteps = newton.params().bodyPivotingSteps = 0;
    Vector x;
    const Result without = newton.solve(p, x);
    ASSERT_EQ(without.status, Status::MaxIterations) << without.message;
    EXPECT_EQ(newton.pivotingSteps(), 0);
    EXPECT_GT(without.residual, 1e-6);
    newton.params() = NewtonParams();
    newton.params().pivotingSteps = newton.params().bodyPivotingSteps;  // the same steps
    const Result with = newton.solve(p, x);
    EXPECT_TRUE(with.converged()) << with.message;
    EXPECT_GT(newton.pivotingSteps(), 0);
    EXPECT_EQ(with.iterations, 10 + newton.pivotingSteps());
    EXPECT_EQ(rows, newton.bodyFactorizations() > 0) << with.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-6);
  }
}

}  // namespace
}  // namespace mlcp
