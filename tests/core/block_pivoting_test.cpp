// Block principal pivoting (core/src/newton/block_pivoting.hpp, newton's pivoting phase), its
// sparse factorizations (SymmetricPatternLu, the bordered updates, Woodbury on the sliding rows)
// and body space (linalg/body_space.hpp), on engine-like contact scenes
// (tests/common/contact_scenes.hpp) and generated families. Answers are checked with
// mlcp::accuracy() and against dantzig's incremental pivoting.
#include "newton/block_pivoting.hpp"  // BlockPivoting, SymmetricPatternLu (internal)

#include <gtest/gtest.h>

#include "common/contact_scenes.hpp"
#include "common/expect_solved.hpp"
#include "common/generators.hpp"
#include "linalg/body_space.hpp"  // BodySpaceSystem (internal)
#include "mlcp/residual.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/pgs.hpp"
#include "projection/pgs_sweep.hpp"  // pgsSweep (internal)

namespace mlcp {
namespace {

using test::expectSolved;
using test::frictionPyramids;
using test::Generator;
using test::jacobianGram;
using test::KnownProblem;

// Block pivoting as a solver for these tests: a run from the guess (its first sets from where a
// warm guess lies when its residual is within setsAtGuessResidual and trustedSets is on: newton's
// pivoting phase runs it so), then, when it does not settle, dantzig from its best iterate, so
// that every solve ends with an answer to compare.
class BlockStage {
 public:
  PivotingLimits limits;
  int maxSteps = 40;
  bool trustedSets = true;
  double setsAtGuessResidual = kInf;

  Options& options() { return options_; }
  void useRows(const RowSystem* rows) { rows_ = rows; }
  Result solve(const Problem& p, Vector& x) { return solveWithGuess(p, Vector::Zero(p.size()), x); }
  Result solveWithGuess(const Problem& p, const Vector& guess, Vector& x) {
    x = guess;
    const bool atGuess = trustedSets && !x.isZero(0.0) && residual(p, x) <= setsAtGuessResidual;
    block_.setRows(rows_);
    block_.setLimits(limits);
    report_ = block_.run(p, x, options_, rows_ ? 3 * maxSteps : maxSteps, atGuess);
    Result r;
    if (report_.settled) {
      r.status = Status::Converged;
      r.residual = residual(p, x);
      r.message = report_.message;
      return r;
    }
    DantzigSolver finish;
    finish.setOptions(options_);
    Vector y;
    r = finish.solveWithGuess(p, x, y);
    x = y;
    r.message = report_.message + "; dantzig: " + r.message;
    return r;
  }
  int blockSteps() const { return report_.steps; }
  int blockFactorizations() const { return report_.factorizations; }
  int blockBodyFactorizations() const { return report_.bodyFactorizations; }
  bool blockSettled() const { return report_.settled; }

 private:
  Options options_;
  const RowSystem* rows_ = nullptr;
  detail::BlockPivoting block_;
  detail::BlockPivoting::Report report_;
};

// A pyramid of `levels` levels whose boxes move sideways (0.5 m/s): sliding contacts, index
// sets that change between steps.
test::PyramidSpec slidingPyramid(int levels) {
  test::PyramidSpec spec;
  spec.levels = levels;
  spec.sideVelocity = 0.5;
  return spec;
}

// Steps the pyramid `steps` times (1e-4 s each) and solves every step with both solvers, each
// warm started from its own last answer (both from x0 first); `check` gets the problem, the
// step number and both answers, after both solves were checked to converge with a residual
// within 1e-10.
template <class A, class B, class Check>
void solveSequence(test::BoxPyramid& pyramid, A& a, B& b, const Vector& x0, int steps,
                   Check check) {
  Vector xa = x0, xb = x0;
  for (int step = 0; step < steps; ++step) {
    pyramid.nextStep(1e-4);
    const Problem p = pyramid.rows().assemble(true);
    Vector ya, yb;
    const Result ra = a.solveWithGuess(p, xa, ya);
    const Result rb = b.solveWithGuess(p, xb, yb);
    ASSERT_TRUE(ra.converged()) << ra.message;
    ASSERT_TRUE(rb.converged()) << rb.message;
    EXPECT_LE(accuracy(p, ya).residual, 1e-10);
    EXPECT_LE((ya - yb).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + yb.lpNorm<Eigen::Infinity>()))
        << "step " << step;
    check(p, ya);
    xa = ya;
    xb = yb;
  }
}

// A time-step sequence on the 15-box pyramid: the block pivoting (warm) gives the dense path's
// answer, within the findex bounds, and settles in a few factorizations.
TEST(BlockPivoting, PyramidSequenceMatchesTheDensePath) {
  test::PyramidSpec spec;
  spec.levels = 5;
  test::BoxPyramid pyramid(spec);
  BlockStage block;
  DantzigSolver dense;
  dense.options().tolerance = 1e-13;
  Vector x;
  ASSERT_TRUE(dense.solve(pyramid.rows().assemble(true), x).converged());
  int settled = 0;
  solveSequence(pyramid, block, dense, x, 5, [&](const Problem& p, const Vector& y) {
    EXPECT_LE(accuracy(p, y).boundViolation, 1e-12);
    settled += block.blockSettled();
    EXPECT_GT(block.blockSteps(), 0);
  });
  EXPECT_GE(settled, 4) << "the block pivoting should settle close warm starts by itself";
}

// Cold starts: the stage rarely settles a pyramid from nothing, but the hand-over to the
// incremental pivoting still gives the dense path's answer.
TEST(BlockPivoting, PyramidColdMatchesTheDensePath) {
  test::PyramidSpec spec;
  spec.levels = 4;
  for (double mu : {0.0, 0.6}) {
    spec.muLo = spec.muHi = mu;
    const Problem p = test::BoxPyramid(spec).rows().assemble(true);
    BlockStage block;
    DantzigSolver dense;
    block.options().tolerance = dense.options().tolerance = 1e-13;
    Vector xb, xd;
    const Result rb = block.solve(p, xb), rd = dense.solve(p, xd);
    ASSERT_TRUE(rb.converged()) << rb.message;
    ASSERT_TRUE(rd.converged()) << rd.message;
    EXPECT_GT(block.blockSteps(), 0);
    EXPECT_LE(accuracy(p, xb).boundViolation, 1e-12);
    EXPECT_LE((xb - xd).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + xd.lpNorm<Eigen::Infinity>()));
  }
}

// The block pivoting runs only on a symmetric A: values made nonsymmetric on the same (symmetric)
// pattern are refused, and the pivoting still answers.
TEST(BlockPivoting, NonsymmetricValuesOnASymmetricPatternSkipTheStage) {
  test::PyramidSpec spec;
  spec.levels = 4;
  const Problem symmetric = test::BoxPyramid(spec).rows().assemble(true);
  BlockStage s;
  Vector x;
  ASSERT_TRUE(s.solve(symmetric, x).converged());
  EXPECT_GT(s.blockSteps(), 0);
  SparseMatrix A = symmetric.sparseA();
  for (int i = 0; i < A.outerSize(); ++i)
    for (SparseMatrix::InnerIterator it(A, i); it; ++it)
      if (it.index() > i) it.valueRef() *= 1 + 1e-9;
  Problem skewed = symmetric;
  skewed.setA(A);
  const Result r = s.solve(skewed, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(s.blockSteps(), 0);
  EXPECT_LE(accuracy(skewed, x).residual, 1e-9);
  ASSERT_TRUE(s.solve(symmetric, x).converged());  // same pattern again: the stage runs
  EXPECT_GT(s.blockSteps(), 0);
}

// Sliding contacts (sideways velocities) exercise the sliding rows' low-rank update.
TEST(BlockPivoting, SlidingPyramidWarmStart) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  BlockStage block;
  Vector x;
  ASSERT_TRUE(DantzigSolver().solve(pyramid.rows().assemble(true), x).converged());
  int sliding = 0;
  for (int step = 0; step < 4; ++step) {
    pyramid.nextStep(1e-4);
    const Problem p = pyramid.rows().assemble(true);
    Vector y;
    const Result r = block.solveWithGuess(p, x, y);
    ASSERT_TRUE(r.converged()) << r.message;
    const Accuracy a = accuracy(p, y);
    EXPECT_LE(a.residual, 1e-10);
    EXPECT_LE(a.boundViolation, 1e-12);
    for (int i = 0; i < p.size(); ++i)
      if (p.findex[i] >= 0 && y[p.findex[i]] > 1e-6 &&
          std::abs(std::abs(y[i]) - p.hi[i] * y[p.findex[i]]) < 1e-12)
        ++sliding;
    x = y;
  }
  EXPECT_GT(sliding, 0) << "the scene was meant to slide";
}

// Reusing a factor across block steps (bordered systems) and Woodbury for sliding rows give the
// answers of factoring every step afresh with the LU, on a sliding pyramid where the sets change
// between steps; the reuse happens (fewer factorizations than steps).
TEST(BlockPivoting, BorderedUpdatesMatchFreshFactorizations) {
  test::BoxPyramid pyramid(slidingPyramid(5));
  BlockStage updated;
  updated.limits.pivotingWoodburyRows = 200;  // the scene slides: every friction row by Woodbury
  updated.limits.pivotingUpdateRows = 200;
  BlockStage fresh;
  fresh.limits.pivotingUpdateRows = 0;
  fresh.limits.pivotingWoodburyRows = 0;
  // Sets from the natural map at the guess: more than one step per solve (from the sets where
  // the guess lies each solve settles in its first step, nothing to reuse).
  updated.trustedSets = fresh.trustedSets = false;
  Vector x;
  ASSERT_TRUE(DantzigSolver().solve(pyramid.rows().assemble(true), x).converged());
  int steps = 0, factorizations = 0;
  solveSequence(pyramid, updated, fresh, x, 6, [&](const Problem&, const Vector&) {
    EXPECT_EQ(fresh.blockFactorizations(), fresh.blockSteps());
    steps += updated.blockSteps();
    factorizations += updated.blockFactorizations();
  });
  EXPECT_LT(factorizations, steps) << "no block step reused a factor";
}

// A warm guess with wrong sets makes rows join the clamped set between block steps: through a
// reused factor their bordered columns (and their coupling to sliding rows) must give the steps
// of fresh factorizations, the same number of them and the same answer (the pyramid sequences
// above only ever have rows leave or slide).
TEST(BlockPivoting, JoinedRowsThroughAReusedFactorTakeTheFreshSteps) {
  test::Generator g(57);
  int reused = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const test::KnownProblem kp = trial % 2 ? g.friction(20) : g.boxed(g.spd(60));
    Vector guess = kp.solution;
    for (int i = 0; i < guess.size(); ++i)
      if (g.uniform(0, 1) < 0.3) guess[i] += g.uniform(-0.5, 0.5);
    BlockStage updated;
    updated.limits.pivotingUpdateRows = 200;
    updated.limits.pivotingWoodburyRows = 200;
    BlockStage fresh;
    fresh.limits.pivotingUpdateRows = 0;
    fresh.limits.pivotingWoodburyRows = 0;
    Vector xu, xf;
    const Result ru = updated.solveWithGuess(kp.problem, guess, xu);
    const Result rf = fresh.solveWithGuess(kp.problem, guess, xf);
    ASSERT_TRUE(ru.converged()) << trial << ": " << ru.message;
    ASSERT_TRUE(rf.converged()) << trial << ": " << rf.message;
    EXPECT_LE(accuracy(kp.problem, xu).residual, 1e-10) << trial;
    EXPECT_EQ(updated.blockSteps(), fresh.blockSteps()) << trial;
    EXPECT_EQ(fresh.blockFactorizations(), fresh.blockSteps()) << trial;
    EXPECT_LE((xu - xf).lpNorm<Eigen::Infinity>(), 1e-8 * (1 + xf.lpNorm<Eigen::Infinity>()))
        << trial;
    reused += updated.blockSteps() - updated.blockFactorizations();
  }
  EXPECT_GT(reused, 0) << "no block step reused a factor";
}

// A random guess is a bad warm start: the answer is right or the status says it is not.
TEST(BlockPivoting, RandomWarmStartConvergesOrFailsHonestly) {
  test::PyramidSpec spec;
  spec.levels = 4;
  const Problem p = test::BoxPyramid(spec).rows().assemble(true);
  Generator g(31);
  BlockStage s;
  for (int trial = 0; trial < 3; ++trial) {
    Vector guess(p.size()), x;
    for (int i = 0; i < p.size(); ++i) guess[i] = g.uniform(-1, 2);
    const Result r = s.solveWithGuess(p, guess, x);
    const Accuracy a = accuracy(p, x);
    EXPECT_EQ(r.converged(), a.residual <= s.options().tolerance) << r.message;
    EXPECT_TRUE(r.converged() || !r.message.empty());
  }
}

// The generic families through the block pivoting : every answer honest, most settled.
TEST(BlockPivoting, GeneratedFamiliesThroughTheBlockStage) {
  Generator g(32);
  BlockStage s;
  for (int trial = 0; trial < 10; ++trial) {
    expectSolved(s, g.standard(g.spd(5 + g.pick(40))));
    expectSolved(s, g.boxed(g.spd(5 + g.pick(40))));
    expectSolved(s, g.friction(2 + g.pick(12)));
    // Warm from the known answer: the block pivoting alone settles it.
    const KnownProblem kp = g.boxed(g.spd(30));
    Vector x;
    ASSERT_TRUE(s.solveWithGuess(kp.problem, kp.solution, x).converged());
    EXPECT_TRUE(s.blockSettled());
  }
}

// The block pivoting's LU for sliding rows: nonsymmetric values on a symmetric pattern, no
// pivoting; checked against Eigen's dense LU, and a zero pivot is reported.
TEST(BlockPivoting, SymmetricPatternLuSolves) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int m : {1, 5, 40, 120}) {
    DenseMatrix K = DenseMatrix::Zero(m, m);
    for (int i = 0; i < m; ++i) {
      K(i, i) = 4 + u(rng);
      for (int j = 0; j < i; ++j)
        if (rng() % 8 == 0) {  // symmetric pattern, unrelated values
          K(i, j) = u(rng);
          K(j, i) = u(rng);
        }
    }
    // Columns in a scrambled row order: the factorization must not rely on sorted rows.
    std::vector<int> outer(m + 1, 0), inner;
    std::vector<double> k, kt;
    for (int c = 0; c < m; ++c) {
      for (int r = m - 1; r >= 0; --r)
        if (K(r, c) != 0 || K(c, r) != 0) {
          inner.push_back(r);
          k.push_back(K(r, c));
          kt.push_back(K(c, r));
        }
      outer[c + 1] = static_cast<int>(inner.size());
    }
    detail::SymmetricPatternLu lu;
    ASSERT_TRUE(lu.factor(m, outer, inner, k, kt, 1e-12));
    Vector b = Vector::NullaryExpr(m, [&](Eigen::Index) { return u(rng); });
    Vector x = b;
    lu.solve(x);
    const Vector expected = K.partialPivLu().solve(b);
    EXPECT_LE((x - expected).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + expected.norm())) << m;
  }
  // Symmetric K: factorSymmetric solves, and the sparse forward solve gives
  // y^T K^-1 z = (L^-1 y)^T D^-1 (L^-1 z) for sparse y, z (what the block pivoting's bordered
  // systems are built from).
  for (int m : {1, 7, 60}) {
    DenseMatrix K = DenseMatrix::Zero(m, m);
    for (int i = 0; i < m; ++i) {
      K(i, i) = 6 + u(rng);
      for (int j = 0; j < i; ++j)
        if (rng() % 6 == 0) K(i, j) = K(j, i) = u(rng);
    }
    std::vector<int> outer(m + 1, 0), inner;
    std::vector<double> k;
    for (int c = 0; c < m; ++c) {
      for (int r = 0; r < m; ++r)
        if (K(r, c) != 0) {
          inner.push_back(r);
          k.push_back(K(r, c));
        }
      outer[c + 1] = static_cast<int>(inner.size());
    }
    detail::SymmetricPatternLu ldl;
    ASSERT_TRUE(ldl.factorSymmetric(m, outer, inner, k, 1e-12));
    const DenseMatrix inverse = K.inverse();
    Vector b = Vector::NullaryExpr(m, [&](Eigen::Index) { return u(rng); });
    Vector x = b;
    ldl.solve(x);
    EXPECT_LE((x - inverse * b).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + x.norm())) << m;
    Vector y = Vector::Zero(m), z = Vector::Zero(m);
    std::vector<int> yIdx = {m - 1 - m / 3}, zIdx = {m / 2, 0};
    y[yIdx[0]] = 1;
    z[zIdx[0]] = 2;
    z[zIdx[1]] = -1;
    const double expected = y.dot(inverse * z);
    ldl.forward(yIdx, y);
    ldl.forward(zIdx, z);
    EXPECT_TRUE(std::is_sorted(yIdx.begin(), yIdx.end()));
    double product = 0;
    for (int i : yIdx) product += y[i] * z[i] / ldl.pivot(i);
    EXPECT_NEAR(product, expected, 1e-12 * (1 + std::abs(expected))) << m;
  }
  // [[1, 1], [1, 1]]: the second pivot is 0.
  detail::SymmetricPatternLu lu;
  EXPECT_FALSE(lu.factor(2, {0, 2, 4}, {0, 1, 0, 1}, {1, 1, 1, 1}, {1, 1, 1, 1}, 1e-12));
}

// Total block steps over a 6-step sequence of a sliding 10-box pyramid (each step's b moved by
// 1e-3 g dt), warm started from the last answer; every answer within 1e-10 of the dense path's.
int pyramidSequenceSteps(BlockStage& s) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  DantzigSolver dense;
  dense.options().tolerance = 1e-13;
  Vector x;
  EXPECT_TRUE(dense.solve(pyramid.rows().assemble(true), x).converged());
  int steps = 0;
  for (int step = 0; step < 6; ++step) {
    pyramid.nextStep(1e-3);
    const Problem p = pyramid.rows().assemble(true);
    Vector y, yd;
    const Result r = s.solveWithGuess(p, x, y);
    EXPECT_TRUE(r.converged()) << r.message;
    EXPECT_TRUE(dense.solveWithGuess(p, x, yd).converged());
    EXPECT_LE(accuracy(p, y).residual, 1e-10);
    EXPECT_LE((y - yd).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + yd.lpNorm<Eigen::Infinity>()));
    steps += s.blockSteps();
    x = y;
  }
  return steps;
}

// Full steps that descend from the step before without beating the guess's merit keep going
// (blockDescentSteps) instead of handing over to the damped steps after kUphill of them: on
// this sequence one solve takes 4 steps instead of 11; the answers are the same. (The first
// sets from the natural map at the guess: the sets where it lies need no descents here.)
TEST(BlockPivoting, DescendingFullStepsContinue) {
  BlockStage on;
  BlockStage off;
  on.trustedSets = off.trustedSets = false;
  off.limits.pivotingDescentSteps = 0;
  const int withDescents = pyramidSequenceSteps(on), without = pyramidSequenceSteps(off);
  EXPECT_LT(withDescents, without);
}

// A trusted guess (the last answer, residual within 1e-2) gives the first index sets by where it
// lies (blockTrustedSets) rather than by the natural map at it: on this sequence fewer block
// steps in all; the answers are the same (pyramidSequenceSteps checks them against the dense path).
TEST(BlockPivoting, TrustedGuessSetsTakeFewerSteps) {
  BlockStage on;
  BlockStage off;
  off.trustedSets = false;
  const int atGuess = pyramidSequenceSteps(on), naturalMap = pyramidSequenceSteps(off);
  EXPECT_LT(atGuess, naturalMap) << "block steps with and without blockTrustedSets";
}

// A guess farther off (residual above 1e-2: the last answer of a scene that moves fast, Bullet's
// falling pyramid) still takes its first sets from where it lies (blockSetsAtGuessResidual): fewer
// block steps in all than with the rule limited to 1e-2 (the natural map at the guess). A sliding
// 15-box pyramid whose b moves by 0.1 g dt per step, each solver warm started from its own last
// answer, every answer checked.
TEST(BlockPivoting, FarGuessSetsTakeFewerSteps) {
  int steps[2] = {0, 0};
  for (int cfg = 0; cfg < 2; ++cfg) {
    test::BoxPyramid pyramid(slidingPyramid(5));
    BlockStage s;
    if (cfg == 1) s.setsAtGuessResidual = 1e-2;
    Vector x;
    ASSERT_TRUE(s.solve(pyramid.rows().assemble(true), x).converged());
    for (int step = 0; step < 6; ++step) {
      pyramid.nextStep(0.1);
      const Problem p = pyramid.rows().assemble(true);
      EXPECT_GT(residual(p, x), 1e-2) << "the guess must be outside the old rule";
      Vector y;
      const Result r = s.solveWithGuess(p, x, y);
      ASSERT_TRUE(r.converged()) << r.message;
      EXPECT_LE(accuracy(p, y).residual, 1e-10);
      steps[cfg] += s.blockSteps();
      x = y;
    }
  }
  EXPECT_LT(steps[0], steps[1]) << "block steps with and without blockSetsAtGuessResidual";
}

// A full step whose sets are those of two steps before would repeat that step's x: with
// blockBreakCycles the stage goes to the damped steps at once. Random friction pyramids from
// random guesses where the full steps 2-cycle: fewer steps, never a wrong status (a few of
// these coupled problems, 4 of 300, are solved neither by the block steps nor by dantzig's
// exact friction passes after them from the raw guess).
TEST(BlockPivoting, TwoCyclesOfFullStepsHandOverAtOnce) {
  Generator g(7);
  int fewer = 0, more = 0, stepsOn = 0, stepsOff = 0, failed[2] = {0, 0};
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 3 * (4 + trial % 9);
    Problem p = frictionPyramids(jacobianGram(g, n, n / 2 + 2, trial % 2 ? 1e-3 : 1e-1), g, 0.8);
    Vector guess(n);
    for (int i = 0; i < n; ++i)
      guess[i] = p.findex[i] >= 0        ? g.uniform(-0.2, 0.2)
                 : g.uniform(0, 1) < 0.3 ? 0.0
                                         : g.uniform(0, 1);
    int steps[2];
    for (int cfg = 0; cfg < 2; ++cfg) {
      BlockStage s;
      s.limits.pivotingBreakCycles = cfg == 1;
      s.limits.pivotingDescentSteps = 0;
      Vector x;
      const Result r = s.solveWithGuess(p, guess, x);
      EXPECT_EQ(r.converged(), accuracy(p, x).residual <= s.options().tolerance) << r.message;
      failed[cfg] += !r.converged();
      steps[cfg] = s.blockSteps();
    }
    fewer += steps[1] < steps[0];
    more += steps[1] > steps[0];
    stepsOff += steps[0];
    stepsOn += steps[1];
  }
  EXPECT_GT(fewer, 0) << "no 2-cycle was broken";
  EXPECT_LT(stepsOn, stepsOff);
  EXPECT_EQ(more, 0);
  EXPECT_LE(failed[1], failed[0]);
  EXPECT_LE(failed[1], 5) << "of 300; without the break " << failed[0];
}

// The body-space factors reproduce W to round-off for rotated anisotropic inertias: with
// Eigen's closed-form 3x3 eigensolver (computeDirect) R R^T missed W by up to 1e-6 of A's
// diagonal on ODE's 210-box pyramid, the check against A refused body space and those steps
// fell back to the sparse LU at 10-20x the cost.
TEST(BodySpace, BodyFactorsOfRotatedInertiasMatchTheAssembledDiagonal) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  RowSystem rows = pyramid.rows();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  double worst = 0, dMax = 0;
  for (int trial = 0; trial < 200; ++trial) {
    for (BodyInverseMass& b : rows.bodies) {
      if (b.invMass == 0) continue;
      const Eigen::Matrix3d q =
          Eigen::Quaterniond(unit(rng), unit(rng), unit(rng), unit(rng)).normalized().matrix();
      // A cube's (equal principal inverse inertias, rotated: equal up to round-off) and a thin
      // box's (1 : 1.01 : 50).
      const Eigen::Vector3d principal =
          trial % 2 == 0 ? Eigen::Vector3d(0.6, 0.6, 0.6) : Eigen::Vector3d(0.6, 0.606, 30.0);
      b.invInertia = q * principal.asDiagonal() * q.transpose();
    }
    const Problem p = rows.assemble(true);
    detail::BodySpaceSystem body;
    ASSERT_TRUE(body.prepare(rows, p.size()));
    for (int i = 0; i < p.size(); ++i) {
      worst = std::max(worst, std::abs(body.diagonal(i) - p.diagonal(i)));
      dMax = std::max(dMax, std::abs(p.diagonal(i)));
    }
  }
  EXPECT_LE(worst, 1e-13 * dMax);
}

// Body space has no limit on the bodies (its memory is O(fill), not bodies^2): a pyramid of 1081
// boxes, every contact row clamped, solves K y = r to round-off (K's product through the rows).
TEST(BodySpace, IslandsOfMoreThanAThousandBodiesFactor) {
  test::BoxPyramid pyramid(slidingPyramid(46));
  const RowSystem& rows = pyramid.rows();
  ASSERT_GT(pyramid.boxes(), 1024);
  detail::BodySpaceSystem body;
  ASSERT_TRUE(body.prepare(rows, rows.size()));
  std::vector<int> order, pos(rows.size(), -1);
  for (int i = 0; i < rows.size(); ++i)
    if (rows.findex[i] < 0) {
      pos[i] = static_cast<int>(order.size());
      order.push_back(i);
    }
  const double rho = 1e-3;
  ASSERT_TRUE(body.factor(order, pos, {}, {}, rows.findex, rho, 1e-12));
  const int m = static_cast<int>(order.size());
  const Vector r = Vector::LinSpaced(m, -1, 1);
  Vector y = r, full = Vector::Zero(rows.size()), ky;
  body.solve(y);
  for (int c = 0; c < m; ++c) full[order[c]] = y[c];
  body.multiply(full, order, ky);
  ky += rho * y;
  EXPECT_LE((ky - r).norm(), 1e-9 * r.norm());
}

// A projected Gauss-Seidel sweep in body space (slacks from the bodies' R^T J^T x) gives the
// sweep on the assembled A, friction bounds from the current normals included, sweep after sweep
// from zero on a sliding pyramid.
TEST(BodySpace, SweepInBodySpaceIsTheSweepOnA) {
  test::BoxPyramid pyramid(slidingPyramid(5));
  const Problem p = pyramid.rows().assemble(true);
  detail::BodySpaceSystem body;
  ASSERT_TRUE(body.prepare(pyramid.rows(), p.size()));
  Vector invDiag;
  ASSERT_LT(detail::inverseDiagonal(p, invDiag), 0);
  Vector x = Vector::Zero(p.size()), y = x;
  int atBound = 0;
  for (int sweep = 0; sweep < 10; ++sweep) {
    body.sweep(p, invDiag, x);
    detail::pgsSweep(p, invDiag, 1.0, y);
    ASSERT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-10 * (1 + y.lpNorm<Eigen::Infinity>()))
        << sweep;
  }
  for (int i = 0; i < p.size(); ++i)
    if (p.findex[i] >= 0 && x[i] != 0 && std::abs(x[i]) == p.effectiveHi(i, x)) ++atBound;
  EXPECT_GT(atBound, 0) << "the sweeps should meet friction bounds";
}

// K = D + J_C W G_C^T solved in body space equals K built from the assembled A and solved densely:
// random clamped sets with sliding rows, a body with a singular (locked-axis) inertia, a static
// body; no sliding rows gives the symmetric case. cfm_c + rho below the limit declines. A row
// pyramid's body graph is a path of short cycles; a square pyramid's fills in three dimensions.
void expectClampedSystemSolved(const test::PyramidSpec& spec) {
  test::BoxPyramid pyramid(spec);
  RowSystem rows = pyramid.rows();
  // Box 0: rotation about a tilted axis locked (rank-2 inverse inertia); box 1: static.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Matrix3d lock = Eigen::Matrix3d::Identity() - axis * axis.transpose();
  rows.bodies[0].invInertia = lock * rows.bodies[0].invInertia * lock;
  rows.bodies[1] = BodyInverseMass{};
  const Problem p = rows.assemble(false);
  const DenseMatrix& A = p.denseA();
  const int n = p.size();
  detail::BodySpaceSystem body;
  ASSERT_TRUE(body.prepare(rows, n));
  EXPECT_EQ(body.size(), 6 * (pyramid.boxes() - 1));
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<int> order, pos(n, -1), sliding;
    std::vector<double> coeff;
    for (int i = 0; i < n; ++i)
      if (p.findex[i] < 0 && rng() % 4 != 0) {
        pos[i] = static_cast<int>(order.size());
        order.push_back(i);
      }
    for (int t = 0; t < n; ++t) {
      if (p.findex[t] < 0 || pos[p.findex[t]] < 0) continue;
      if (trial > 0 && rng() % 3 == 0) {
        sliding.push_back(t);
        coeff.push_back((rng() % 2 ? 0.7 : -0.6));
      } else if (rng() % 2 == 0) {
        pos[t] = static_cast<int>(order.size());
        order.push_back(t);
      }
    }
    const int m = static_cast<int>(order.size());
    const double rho = trial % 2 == 0 ? 1e-2 : 0.0;
    DenseMatrix K(m, m);
    for (int c = 0; c < m; ++c)
      for (int d = 0; d < m; ++d) K(c, d) = A(order[c], order[d]) + (c == d ? rho : 0.0);
    for (size_t k = 0; k < sliding.size(); ++k)
      for (int c = 0; c < m; ++c)
        K(c, pos[p.findex[sliding[k]]]) += coeff[k] * A(order[c], sliding[k]);
    ASSERT_TRUE(body.factor(order, pos, sliding, coeff, p.findex, rho, 1e-9)) << trial;
    Vector r(m);
    for (int c = 0; c < m; ++c) r[c] = std::sin(1.0 + c + trial);
    Vector y = r;
    body.solve(y);
    const Vector expected = K.fullPivLu().solve(r);
    EXPECT_LE((y - expected).norm(), 1e-8 * expected.norm()) << trial;
    // Conditioning ~ 1 / d: one step of refinement against K (as the block pivoting takes) restores
    // a backward error near the dense factorization's.
    Vector correction = r - K * y;
    body.solve(correction);
    y += correction;
    EXPECT_LE((K * y - r).norm(), 1e-14 * K.norm() * y.norm()) << trial;
    EXPECT_FALSE(body.factor(order, pos, sliding, coeff, p.findex, rho, 1.0)) << trial;
  }
}

TEST(BodySpace, SolvesTheClampedSystemOfTheAssembledProblem) {
  expectClampedSystemSolved(slidingPyramid(4));
  test::PyramidSpec square = slidingPyramid(3);
  square.square = true;
  expectClampedSystemSolved(square);
}

// The block pivoting with the problem's rows (Solver::useRows, as RowSolver passes them) factors in
// body space and gives the answers of the same solver without them, step after step of a sliding
// pyramid (damped and full steps: cfm > 0). With cfm = 0 the full steps fall back to A_CC, and
// the answers are many: both paths' iterates then differ in round-off from the first step, and
// the exact friction passes after the block pivoting do not always settle (with the rows or without
// them, at different steps), so there each result is checked to say truly whether it converged.
TEST(BodySpace, RowsGiveTheAnswersOfTheProblemAlone) {
  for (const double cfm : {1e-5 * 60, 0.0}) {
    test::PyramidSpec spec = slidingPyramid(5);
    spec.cfm = cfm;
    test::BoxPyramid pyramid(spec);
    BlockStage with;
    BlockStage without;
    Vector x, y;
    int inBodySpace = 0, factorizations = 0;
    for (int step = 0; step < 5; ++step) {
      pyramid.nextStep(0.1);
      const Problem p = pyramid.rows().assemble(true);
      const Vector gx = x, gy = y;
      with.useRows(&pyramid.rows());
      const Result r = gx.size() == p.size() ? with.solveWithGuess(p, gx, x) : with.solve(p, x);
      with.useRows(nullptr);
      const Result ref =
          gy.size() == p.size() ? without.solveWithGuess(p, gy, y) : without.solve(p, y);
      if (cfm == 0) {
        const double tol = with.options().tolerance;
        EXPECT_EQ(r.converged(), accuracy(p, x).residual <= tol) << step << ": " << r.message;
        EXPECT_EQ(ref.converged(), accuracy(p, y).residual <= tol) << step << ": " << ref.message;
      } else {
        ASSERT_TRUE(r.converged()) << cfm << " step " << step << ": " << r.message;
        ASSERT_TRUE(ref.converged()) << cfm << " step " << step << ": " << ref.message;
        EXPECT_LE(accuracy(p, x).residual, 1e-9) << step;
        EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-6 * (1 + y.lpNorm<Eigen::Infinity>()))
            << step;
      }
      EXPECT_EQ(without.blockBodyFactorizations(), 0);
      inBodySpace += with.blockBodyFactorizations();
      factorizations += with.blockFactorizations();
    }
    EXPECT_GT(inBodySpace, 0) << cfm;
    if (cfm > 0) {
      EXPECT_EQ(inBodySpace, factorizations);
    } else {
      EXPECT_LT(inBodySpace, factorizations) << "full steps with cfm = 0 fall back";
    }
  }
}

}  // namespace
}  // namespace mlcp
