// dantzig specifics: the seed example, random P-matrix / SPD / boxed / mixed / findex problems
// against known solutions, FixedOnce versus Exact friction, infeasible and singular problems,
// warm start, workspace reuse, sparse input. Every answer is checked with mlcp::accuracy().
#include "mlcp/dantzig.hpp"

#include <gtest/gtest.h>

#include <random>

#include "../core/src/dantzig_block.hpp"      // SymmetricPatternLu (internal)
#include "../core/src/dantzig_small.hpp"      // the tiny dense path (internal)
#include "../core/src/linalg/body_space.hpp"  // BodySpaceSystem (internal)
#include "common/contact_scenes.hpp"
#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/ldlt.hpp"
#include "mlcp/pgs.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/rows.hpp"

namespace mlcp {
namespace {

using test::Generator;
using test::KnownProblem;

// Solves and checks the answer independently: residual, and x* when the solution is unique.
Result expectSolved(DantzigSolver& s, const KnownProblem& kp, double tol = 1e-9) {
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

// Random J (rows x 6 bodies' worth of columns), A = J J^T + eps I.
DenseMatrix jacobianGram(Generator& g, int rows, int cols, double eps) {
  DenseMatrix J(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) J(i, j) = g.uniform(-1, 1);
  return J * J.transpose() + eps * DenseMatrix::Identity(rows, rows);
}

// Friction pyramids: per contact a normal row [0, inf) and two rows [-mu, mu] -> normal.
Problem frictionPyramids(DenseMatrix A, Generator& g, double mu) {
  const int n = static_cast<int>(A.rows());
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = g.uniform(-1, 1);
  for (int k = 0; k < n; k += 3) b[k] = -g.uniform(0.2, 1);  // approaching contacts
  Problem p(std::move(A), b);
  p.findex.assign(n, -1);
  for (int k = 0; k < n; k += 3)
    for (int t = 1; t <= 2; ++t) {
      p.lo[k + t] = -mu;
      p.hi[k + t] = mu;
      p.findex[k + t] = k;
    }
  return p;
}

TEST(Dantzig, IsRegistered) {
  auto s = makeSolver("dantzig");
  ASSERT_NE(s, nullptr);
  EXPECT_STREQ(s->name(), "dantzig");
}

TEST(Dantzig, SeedExample) {
  // Not symmetric, not a P-matrix (A_33 = 0), but positive semidefinite: solvable here.
  const Problem p = test::seedLemkeExample();
  DantzigSolver s;
  Vector x;
  const Result r = s.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(residual(p, x), 1e-12);
  EXPECT_NEAR(x[0], 20.0 / 19, 1e-12);
  EXPECT_NEAR(x[1], 21.0 / 19, 1e-12);
  EXPECT_NEAR(x[2], 0.0, 1e-12);
  EXPECT_GE(r.iterations, 2);
}

TEST(Dantzig, RandomSpdStandardLcps) {
  Generator g(11);
  DantzigSolver s;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + g.pick(40);
    expectSolved(s, g.standard(g.spd(n), trial % 3 == 0));
  }
}

TEST(Dantzig, RandomNonsymmetricPMatrices) {
  // Diagonally dominant with positive diagonal: a P-matrix, not symmetric.
  Generator g(12);
  DantzigSolver s;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 2 + g.pick(30);
    DenseMatrix A(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = g.uniform(-1, 1);
    for (int i = 0; i < n; ++i) A(i, i) = A.row(i).cwiseAbs().sum() + 0.5;
    expectSolved(s, g.standard(A));
    expectSolved(s, g.boxed(A));
  }
}

TEST(Dantzig, BoxedAndMixedEqualityRows) {
  Generator g(13);
  DantzigSolver s;
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + g.pick(50);
    const KnownProblem kp = g.boxed(g.spd(n, trial % 2 ? 0.1 : 0.01));
    expectSolved(s, kp);
  }
  expectSolved(s, g.linear(g.spd(25)));
}

TEST(Dantzig, FindexExactSatisfiesTheFinalBounds) {
  Generator g(14);
  DantzigSolver s;
  for (int trial = 0; trial < 20; ++trial) {
    const KnownProblem kp = g.friction(1 + g.pick(12));
    const Result r = expectSolved(s, kp);
    EXPECT_GE(s.passes(), 1);
    (void)r;
  }
}

TEST(Dantzig, FrictionPyramidsFromJacobians) {
  Generator g(15);
  DantzigSolver s;
  for (int trial = 0; trial < 10; ++trial) {
    const int contacts = 2 + g.pick(10);
    const Problem p = frictionPyramids(jacobianGram(g, 3 * contacts, 12, 1e-3), g, 0.5);
    Vector x;
    const Result r = s.solve(p, x);
    EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
    const Accuracy a = accuracy(p, x);
    EXPECT_LE(a.residual, 1e-9);
    EXPECT_LE(a.boundViolation, 1e-9 * (1 + p.b.lpNorm<Eigen::Infinity>()));
  }
}

// On random pyramids FixedOnce runs, reports its status truthfully (the base class checks the
// true findex bounds) and, at mu = 1, sometimes returns an answer outside the final bounds.
TEST(Dantzig, FixedOnceRunsAndCanViolateTheFinalBounds) {
  Generator g(16);
  DantzigSolver exact, stock;
  stock.options().frictionBounds = FrictionBounds::FixedOnce;
  int violated = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const int contacts = 2 + g.pick(6);
    const Problem p = frictionPyramids(jacobianGram(g, 3 * contacts, 12, 1e-3), g, 1.0);
    Vector xe, xs;
    const Result re = exact.solve(p, xe);
    const Result rs = stock.solve(p, xs);
    EXPECT_TRUE(re.converged()) << re.message;
    EXPECT_EQ(stock.passes(), 1);
    // FixedOnce is never wrong about its own status: the base class checks the true bounds.
    const Accuracy as = accuracy(p, xs);
    EXPECT_EQ(rs.converged(), as.residual <= stock.options().tolerance);
    if (as.boundViolation > 1e-9) {
      ++violated;
      EXPECT_FALSE(rs.converged());
    }
  }
  EXPECT_GT(violated, 0) << "no case showed the stock behaviour's bound violation";
}

TEST(Dantzig, FixedOnceViolationConstructed) {
  // Row 0 a normal, row 1 its friction (mu = 0.5, coupled to the normal through A_01 = 0.9),
  // row 2 an inactive contact. Stock order: the normal first (x_0 = 2), then the friction
  // row with bounds fixed at +-1; x_1 saturates at 1 and pulls the normal down to 1.1, so the
  // final bound 0.55 is violated by 0.45. Exact iterates x_0 <- 2 - 0.45 x_0 to 2 / 1.45.
  DenseMatrix A(3, 3);
  A << 1, 0.9, 0, 0.9, 1, 0, 0, 0, 1;
  Problem p(A, Vector((Vector(3) << -2, -5, 0.3).finished()));
  p.findex = {-1, 0, -1};
  p.lo[1] = -0.5;
  p.hi[1] = 0.5;
  DantzigSolver exact, stock;
  stock.options().frictionBounds = FrictionBounds::FixedOnce;
  Vector xe, xs;
  const Result re = exact.solve(p, xe);
  const Result rs = stock.solve(p, xs);
  ASSERT_TRUE(re.converged()) << re.message;
  EXPECT_LE(accuracy(p, xe).boundViolation, 1e-12);
  EXPECT_NEAR(xe[0], 2 / 1.45, 1e-9);
  EXPECT_NEAR(xs[0], 1.1, 1e-12);
  EXPECT_NEAR(xs[1], 1.0, 1e-12);
  EXPECT_GT(accuracy(p, xs).boundViolation, 0.4);
  EXPECT_EQ(rs.status, Status::Failed) << rs.message;
  EXPECT_GT(exact.passes(), 1);
}

TEST(Dantzig, InfeasibleIsFailed) {
  // w = -x - 1 >= 0 with x >= 0 has no solution.
  Problem p(DenseMatrix::Constant(1, 1, -1.0), Vector::Constant(1, -1.0));
  DantzigSolver s;
  Vector x;
  const Result r = s.solve(p, x);
  EXPECT_EQ(r.status, Status::Failed) << r.message;
  EXPECT_NE(r.message.find("row 0"), std::string::npos) << r.message;
  EXPECT_GT(residual(p, x), 1e-10);
}

TEST(Dantzig, InconsistentSingularLinearSystemIsFailed) {
  DenseMatrix A(2, 2);
  A << 1, 1, 1, 1;
  Problem p(A, Vector((Vector(2) << -1, -2).finished()));
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  DantzigSolver s;
  Vector x;
  const Result r = s.solve(p, x);
  EXPECT_FALSE(r.converged());
  EXPECT_NE(r.status, Status::InvalidInput);
}

TEST(Dantzig, SingularPsdContactsOfABox) {
  // 4 contact normals of one box against the ground: A = J J^T has rank 3 (no cfm). With b in
  // the range of J (consistent), a solution exists; it is not unique.
  Generator g(17);
  DantzigSolver s;
  int solved = 0;
  for (int trial = 0; trial < 20; ++trial) {
    DenseMatrix J(4, 3);
    for (int i = 0; i < 4; ++i) J.row(i) << 1, g.uniform(-1, 1), g.uniform(-1, 1);
    Vector v(3);
    v << -g.uniform(0.5, 2), g.uniform(-0.2, 0.2), g.uniform(-0.2, 0.2);
    Problem p(DenseMatrix(J * J.transpose()), J * v);
    Vector x;
    const Result r = s.solve(p, x);
    const double res = residual(p, x);
    if (r.converged()) {
      ++solved;
      EXPECT_LE(res, 1e-10);
    } else {
      EXPECT_TRUE(r.status == Status::Failed || r.status == Status::MaxIterations) << r.message;
    }
  }
  EXPECT_GE(solved, 15) << "singular but consistent contact sets should mostly solve";
}

TEST(Dantzig, SingularFrictionBoxWithSmallCfm) {
  // A box on the ground: 4 contacts with friction, 12 rows from 6 body velocities.
  Generator g(18);
  DantzigSolver s;
  for (int trial = 0; trial < 10; ++trial) {
    const Problem p = frictionPyramids(jacobianGram(g, 12, 6, trial % 2 ? 1e-6 : 0.0), g, 0.6);
    Vector x;
    const Result r = s.solve(p, x);
    const Accuracy a = accuracy(p, x);
    if (r.converged())
      EXPECT_LE(a.residual, 1e-10);
    else
      EXPECT_NE(r.status, Status::InvalidInput) << r.message;
    EXPECT_TRUE(a.finite);
  }
}

TEST(Dantzig, WarmStartFromTheSolutionNeedsNoPivots) {
  Generator g(19);
  DantzigSolver s;
  const KnownProblem kp = g.boxed(g.spd(60));
  Vector x;
  const Result cold = s.solve(kp.problem, x);
  ASSERT_TRUE(cold.converged());
  s.options().warmStart = true;
  Vector y = x;
  const Result warm = s.solve(kp.problem, y);
  ASSERT_TRUE(warm.converged()) << warm.message;
  EXPECT_LE(residual(kp.problem, y), 1e-10);
  EXPECT_LT(warm.iterations, cold.iterations);
  // A perturbed guess still gives the right answer.
  Vector guess = x + 0.3 * Vector::Random(x.size());
  const Result r = s.solveWithGuess(kp.problem, guess, y);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE((y - kp.solution).lpNorm<Eigen::Infinity>(), 1e-8);
}

TEST(Dantzig, WarmStartFindex) {
  Generator g(20);
  DantzigSolver s;
  const KnownProblem kp = g.friction(10);
  Vector x;
  ASSERT_TRUE(s.solve(kp.problem, x).converged());
  Vector y;
  const Result r = s.solveWithGuess(kp.problem, x, y);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(s.passes(), 1);
  EXPECT_LE(residual(kp.problem, y), 1e-10);
}

TEST(Dantzig, WorkspaceReuseAcrossSizes) {
  Generator g(21);
  DantzigSolver s;
  for (int n : {30, 5, 60, 1, 60, 17}) {
    expectSolved(s, g.boxed(g.spd(n)));
    expectSolved(s, g.friction(std::max(1, n / 3)));
  }
}

TEST(Dantzig, SparseInputMatchesDense) {
  Generator g(22);
  DantzigSolver s;
  for (int trial = 0; trial < 5; ++trial) {
    // Block tridiagonal SPD (a chain of bodies), stored sparse.
    const int n = 60;
    DenseMatrix A = DenseMatrix::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      A(i, i) = 4;
      if (i + 1 < n) A(i, i + 1) = A(i + 1, i) = g.uniform(-1, 1);
      if (i + 3 < n) A(i, i + 3) = A(i + 3, i) = g.uniform(-0.5, 0.5);
    }
    KnownProblem kp = trial % 2 ? g.boxed(A) : g.standard(A);
    kp.problem.setA(SparseMatrix(A.sparseView()));
    ASSERT_TRUE(kp.problem.isSparse());
    expectSolved(s, kp);
    // Non-symmetric sparse.
    A(0, 5) += 0.7;
    KnownProblem kn = g.boxed(A);
    kn.problem.setA(SparseMatrix(A.sparseView()));
    expectSolved(s, kn);
  }
}

TEST(Dantzig, PivotLimitIsMaxIterations) {
  Generator g(23);
  DantzigSolver s;
  s.options().maxPivots = 3;
  const KnownProblem kp = g.boxed(g.spd(40));
  Vector x;
  const Result r = s.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::MaxIterations) << r.message;
  EXPECT_LE(r.iterations, 3);
}

TEST(Dantzig, EmptyProblem) {
  DantzigSolver s;
  Problem p(DenseMatrix(0, 0), Vector(0));
  Vector x;
  EXPECT_TRUE(s.solve(p, x).converged());
}

// ---- the path for tiny dense islands (core/src/dantzig_small.hpp) ----

// A small boxed / linear / standard problem with an exactly symmetric SPD A.
KnownProblem smallProblem(Generator& g, int n, int kind) {
  DenseMatrix A = g.spd(n);
  A = (0.5 * (A + A.transpose())).eval();
  return kind == 0 ? g.linear(A) : kind == 1 ? g.standard(A) : g.boxed(A);
}

// Taken, the path's answer solves the problem and is the general path's (the same problem
// stored sparse, which the path never takes); declined, x is untouched. Guesses: the solution
// (taken unless a row sits exactly on a bound with w = 0), a perturbed solution (either), zero
// (the cold guess: rows whose bounds contain 0 clamped; either), random.
TEST(DantzigSmall, AnswersAreTheGeneralPathsOrDeclined) {
  Generator g(31);
  int taken = 0, declined = 0;
  for (int trial = 0; trial < 240; ++trial) {
    const KnownProblem kp = smallProblem(g, 1 + trial % detail::kSmallDenseRows, trial % 3);
    const Problem& p = kp.problem;
    ASSERT_TRUE(detail::smallDenseApplies(p));
    Problem sparse = p;
    sparse.setA(p.toSparse());
    ASSERT_FALSE(detail::smallDenseApplies(sparse));
    const int n = p.size();
    const Vector guesses[] = {kp.solution, kp.solution + 1e-3 * Vector::Random(n), Vector::Zero(n),
                              2 * Vector::Random(n)};
    for (const Vector& guess : guesses) {
      Vector x = guess;
      if (!detail::solveSmallDense(p, 1e-12, x)) {
        ++declined;
        EXPECT_TRUE((x.array() == guess.array()).all()) << "a declined guess was changed";
        continue;
      }
      ++taken;
      const Accuracy a = accuracy(p, x);
      EXPECT_LE(a.residual, 1e-10) << kp.name << " n=" << n;
      EXPECT_LE(a.boundViolation, 0.0) << kp.name;
      DantzigSolver general;
      Vector y;
      const Result r = general.solveWithGuess(sparse, guess, y);
      ASSERT_TRUE(r.converged()) << r.message;
      EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + y.lpNorm<Eigen::Infinity>()))
          << kp.name << " n=" << n;
    }
  }
  EXPECT_GT(taken, 300);
  EXPECT_GT(declined, 40);
}

// The path skips the general path's refinement step only where the clamped rows' w is at its
// rounding level. Symmetric indefinite blocks with a tiny first pivot (growth up to 1e8 in L)
// leave a first solve's w far above it: refined, the answers are the general path's and as
// accurate (without the refinement their residuals reach ~1e-9).
TEST(DantzigSmall, GrowthInTheFactorsIsRefined) {
  Generator g(33);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 2 + trial % (detail::kSmallDenseRows - 1);
    DenseMatrix A = DenseMatrix::Zero(n, n);
    const double tiny = std::pow(10.0, -4.0 - trial % 5);
    A(0, 0) = A(1, 1) = tiny;
    A(0, 1) = A(1, 0) = 1.0 + 0.1 * g.uniform(-1, 1);
    if (n > 2) {
      DenseMatrix S = g.spd(n - 2);
      A.bottomRightCorner(n - 2, n - 2) = 0.5 * (S + S.transpose());
      for (int i = 2; i < n; ++i) A(0, i) = A(i, 0) = 0.3 * g.uniform(-1, 1);
    }
    Vector b(n);
    for (int i = 0; i < n; ++i) b[i] = g.uniform(-1, 1);
    Problem p(A, b);
    p.lo.setConstant(-kInf);  // equality rows: the path takes them from any start
    Problem sparse = p;
    sparse.setA(p.toSparse());
    Vector x = Vector::Constant(n, 0.5);
    ASSERT_TRUE(detail::solveSmallDense(p, 1e-12, x)) << "trial " << trial;
    EXPECT_LE(residual(p, x), 1e-12) << "trial " << trial << " tiny " << tiny;
    DantzigSolver general;
    Vector y;
    ASSERT_TRUE(general.solveWithGuess(sparse, Vector::Constant(n, 0.5), y).converged());
    EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + y.lpNorm<Eigen::Infinity>()))
        << "trial " << trial;
  }
}

// A guess whose index sets are wrong is corrected by the path's block-pivoting steps; a guess
// whose clamped block is singular is declined, and DantzigSolver pivots from it instead.
TEST(DantzigSmall, WrongGuessIsCorrectedOrFallsToPivoting) {
  // x in [0, 1], w = x - 2: the answer is x = 1 (at hi), not the guessed interior 0.5.
  Problem p(DenseMatrix::Identity(1, 1), Vector::Constant(1, -2.0));
  p.hi[0] = 1;
  Vector x = Vector::Constant(1, 0.5);
  ASSERT_TRUE(detail::solveSmallDense(p, 1e-12, x));
  EXPECT_EQ(x[0], 1.0);
  // Both rows guessed clamped, A singular: the second pivot is 0.
  Problem singular(DenseMatrix::Ones(2, 2), Vector::Constant(2, -1.0));
  x = Vector::Constant(2, 0.5);
  EXPECT_FALSE(detail::solveSmallDense(singular, 1e-12, x));
  EXPECT_TRUE((x.array() == 0.5).all()) << "a declined guess was changed";
  DantzigSolver s;
  Vector y;
  const Result r = s.solveWithGuess(singular, x, y);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(residual(singular, y), 1e-12);
  // Non-symmetric A: declined (the general path has the L D U factors for it).
  Problem q(DenseMatrix{{2.0, 0.5}, {0.0, 2.0}}, Vector::Constant(2, -1.0));
  q.lo.setConstant(-kInf);
  Vector z = Vector::Constant(2, 0.1);
  EXPECT_FALSE(detail::solveSmallDense(q, 1e-12, z));
  ASSERT_TRUE(s.solveWithGuess(q, z, y).converged());
  EXPECT_LE(residual(q, y), 1e-12);
}

// One solver object reused over islands whose size, bounds pattern and row order change (in
// and out of the small path, warm and cold) answers exactly as a fresh solver per problem:
// nothing of a previous solve leaks into the next.
TEST(DantzigSmall, ReuseAcrossSizesAndBoundPatternsMatchesAFreshSolver) {
  Generator g(32);
  DantzigSolver reused;
  for (int trial = 0; trial < 120; ++trial) {
    const int n = 1 + g.pick(12);
    KnownProblem kp = smallProblem(g, n, g.pick(3));
    if (trial % 4 == 3) {  // the same rows in another order: another permutation
      Eigen::PermutationMatrix<Eigen::Dynamic> P(n);
      P.setIdentity();
      for (int i = n - 1; i > 0; --i) std::swap(P.indices()[i], P.indices()[g.pick(i + 1)]);
      const DenseMatrix A = P * kp.problem.denseA() * P.transpose();
      kp.problem.setA(A);
      kp.problem.b = P * kp.problem.b;
      kp.problem.lo = P * kp.problem.lo;
      kp.problem.hi = P * kp.problem.hi;
      kp.solution = P * kp.solution;
    }
    const Vector guess = trial % 5 == 0   ? Vector::Zero(n)
                         : trial % 5 == 1 ? Vector(2 * Vector::Random(n))
                                          : Vector(kp.solution + 1e-4 * Vector::Random(n));
    Vector a, b;
    const Result ra = reused.solveWithGuess(kp.problem, guess, a);
    DantzigSolver fresh;
    const Result rb = fresh.solveWithGuess(kp.problem, guess, b);
    ASSERT_EQ(ra.status, rb.status) << ra.message << " | " << rb.message;
    EXPECT_EQ(ra.iterations, rb.iterations);
    EXPECT_TRUE((a.array() == b.array()).all()) << "trial " << trial << " n=" << n;
    EXPECT_TRUE(ra.converged()) << ra.message;
    EXPECT_LE(residual(kp.problem, a), 1e-9);
  }
}

// ---- the sparse block stage on engine-like contact scenes (tests/common/contact_scenes.hpp) ----

// A pyramid of `levels` levels whose boxes move sideways (0.5 m/s): sliding contacts, index
// sets that change between steps.
test::PyramidSpec slidingPyramid(int levels) {
  test::PyramidSpec spec;
  spec.levels = levels;
  spec.sideVelocity = 0.5;
  return spec;
}

DantzigSolver withStage(DantzigParams::BlockStage stage) {
  DantzigSolver s;
  s.params().blockStage = stage;
  return s;
}

// Steps the pyramid `steps` times (1e-4 s each) and solves every step with both solvers, each
// warm started from its own last answer (both from x0 first); `check` gets the problem, the
// step number and both answers, after both solves were checked to converge with a residual
// within 1e-10.
template <class Check>
void solveSequence(test::BoxPyramid& pyramid, DantzigSolver& a, DantzigSolver& b, const Vector& x0,
                   int steps, Check check) {
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

// A time-step sequence on the 15-box pyramid: the block stage (warm) gives the dense path's
// answer, within the findex bounds, and settles in a few factorizations.
TEST(DantzigBlock, PyramidSequenceMatchesTheDensePath) {
  test::PyramidSpec spec;
  spec.levels = 5;
  test::BoxPyramid pyramid(spec);
  DantzigSolver block = withStage(DantzigParams::BlockStage::Always);
  DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
  dense.options().tolerance = 1e-13;
  Vector x;
  ASSERT_TRUE(dense.solve(pyramid.rows().assemble(true), x).converged());
  int settled = 0;
  solveSequence(pyramid, block, dense, x, 5, [&](const Problem& p, const Vector& y) {
    EXPECT_LE(accuracy(p, y).boundViolation, 1e-12);
    settled += block.blockSettled();
    EXPECT_GT(block.blockSteps(), 0);
  });
  EXPECT_GE(settled, 4) << "the block stage should settle close warm starts by itself";
}

// Cold starts: the stage rarely settles a pyramid from nothing, but the hand-over to the
// incremental pivoting still gives the dense path's answer.
TEST(DantzigBlock, PyramidColdMatchesTheDensePath) {
  test::PyramidSpec spec;
  spec.levels = 4;
  for (double mu : {0.0, 0.6}) {
    spec.muLo = spec.muHi = mu;
    const Problem p = test::BoxPyramid(spec).rows().assemble(true);
    DantzigSolver block = withStage(DantzigParams::BlockStage::Always);
    DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
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

// Auto's cold trial (autoColdSteps full steps from "every row clamped"): it either settles
// within its step budget or is dropped and the pivoting starts cold; either way the answer is
// the dense path's.
TEST(DantzigBlock, AutoColdTrialSettlesOrIsDropped) {
  test::PyramidSpec spec;
  spec.levels = 4;
  for (double side : {0.0, 0.5}) {
    spec.sideVelocity = side;
    test::BoxPyramid pyramid(spec);
    pyramid.nextStep(1e-4);
    const Problem p = pyramid.rows().assemble(true);
    ASSERT_GE(p.size(), DantzigParams().autoMinRows);
    DantzigSolver autoStage = withStage(DantzigParams::BlockStage::Auto);
    DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
    autoStage.options().tolerance = dense.options().tolerance = 1e-13;
    Vector xa, xd;
    const Result ra = autoStage.solve(p, xa), rd = dense.solve(p, xd);
    ASSERT_TRUE(ra.converged()) << ra.message;
    ASSERT_TRUE(rd.converged()) << rd.message;
    EXPECT_GT(autoStage.blockSteps(), 0);
    EXPECT_LE(autoStage.blockSteps(), autoStage.params().autoColdSteps);
    if (!autoStage.blockSettled()) {
      EXPECT_GT(ra.iterations, autoStage.blockSteps());
    }
    EXPECT_LE(accuracy(p, xa).boundViolation, 1e-12);
    EXPECT_LE((xa - xd).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + xd.lpNorm<Eigen::Infinity>()))
        << "side velocity " << side;
  }
}

// Auto with a guess already close to the answer (an engine's own last answers at rest) skips
// the cold trial: the guess that solves the problem costs no factorization at all, a guess
// from the previous time step settles in the block stage alone.
TEST(DantzigBlock, AutoTrustedGuessSkipsTheColdTrial) {
  test::PyramidSpec spec;
  spec.levels = 5;
  test::BoxPyramid pyramid(spec);
  DantzigSolver autoStage = withStage(DantzigParams::BlockStage::Auto);
  autoStage.options().tolerance = 1e-12;
  const Problem p0 = pyramid.rows().assemble(true);
  ASSERT_GE(p0.size(), autoStage.params().autoMinRows);
  ASSERT_LT(p0.size(), autoStage.params().autoWarmMinRows);
  DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
  dense.options().tolerance = 1e-13;
  Vector x, y;
  ASSERT_TRUE(dense.solve(p0, x).converged());
  ASSERT_TRUE(autoStage.solveWithGuess(p0, x, y).converged());
  EXPECT_EQ(autoStage.blockSteps(), 0);
  EXPECT_TRUE(autoStage.blockSettled());
  pyramid.nextStep(1e-4);
  const Problem p1 = pyramid.rows().assemble(true);
  ASSERT_LE(residual(p1, x), 1e-2);
  const Result r = autoStage.solveWithGuess(p1, x, y);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_LE(accuracy(p1, y).residual, 1e-12);
  EXPECT_TRUE(autoStage.blockSettled()) << r.message;
  EXPECT_EQ(r.message.find("cold trial"), std::string::npos) << r.message;
}

// Auto's cold trial after a miss: warm solves lent the same ColdTrialMemory skip it until
// autoColdRetry solves have passed (Bullet's moving pyramid never settles from the cold sets),
// then try again. Without a memory every solve tries it and answers alike: no state carries.
TEST(DantzigBlock, AutoColdTrialAfterAMissIsRetriedEveryAutoColdRetrySolves) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  pyramid.nextStep(1e-4);
  const Problem p = pyramid.rows().assemble(true);
  DantzigSolver autoStage = withStage(DantzigParams::BlockStage::Auto);
  autoStage.params().autoColdRetry = 3;
  Vector exact, x, first;
  ASSERT_TRUE(withStage(DantzigParams::BlockStage::Never).solve(p, exact).converged());
  const Vector guess = 0.5 * exact;  // a poor guess (residual above 1e-2)
  ASSERT_GT(residual(p, guess), 1e-2);
  DantzigSolver::ColdTrialMemory memory;
  for (const bool lent : {true, false}) {
    autoStage.useColdTrialMemory(lent ? &memory : nullptr);
    for (int solve = 0; solve < 7; ++solve) {
      const Result r = autoStage.solveWithGuess(p, guess, x);
      ASSERT_TRUE(r.converged()) << r.message;
      EXPECT_LE(accuracy(p, x).residual, autoStage.options().tolerance);
      const bool tried = r.message.find("cold trial") != std::string::npos;
      if (solve == 0) {
        ASSERT_TRUE(tried) << "the cold trial settled: pick a scene where it misses";
        first = x;
      }
      EXPECT_EQ(tried, !lent || solve % 3 == 0) << lent << " solve " << solve << ": " << r.message;
      if (!lent) {
        EXPECT_TRUE((x.array() == first.array()).all()) << "solve " << solve;
      }
    }
  }
}

// The block stage runs only on a symmetric A: values made nonsymmetric on the same (symmetric)
// pattern are refused, and the pivoting still answers.
TEST(DantzigBlock, NonsymmetricValuesOnASymmetricPatternSkipTheStage) {
  test::PyramidSpec spec;
  spec.levels = 4;
  const Problem symmetric = test::BoxPyramid(spec).rows().assemble(true);
  DantzigSolver s = withStage(DantzigParams::BlockStage::Always);
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
TEST(DantzigBlock, SlidingPyramidWarmStart) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  DantzigSolver block = withStage(DantzigParams::BlockStage::Always);
  Vector x;
  ASSERT_TRUE(withStage(DantzigParams::BlockStage::Never)
                  .solve(pyramid.rows().assemble(true), x)
                  .converged());
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
TEST(DantzigBlock, BorderedUpdatesMatchFreshFactorizations) {
  test::BoxPyramid pyramid(slidingPyramid(5));
  DantzigSolver updated = withStage(DantzigParams::BlockStage::Always);
  updated.params().blockWoodburyRows = 200;  // the scene slides: every friction row by Woodbury
  updated.params().blockUpdateRows = 200;
  DantzigSolver fresh = withStage(DantzigParams::BlockStage::Always);
  fresh.params().blockUpdateRows = 0;
  fresh.params().blockWoodburyRows = 0;
  // Sets from the natural map at the guess: more than one step per solve (from the sets where
  // the guess lies each solve settles in its first step, nothing to reuse).
  updated.params().blockTrustedSets = fresh.params().blockTrustedSets = false;
  Vector x;
  ASSERT_TRUE(withStage(DantzigParams::BlockStage::Never)
                  .solve(pyramid.rows().assemble(true), x)
                  .converged());
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
TEST(DantzigBlock, JoinedRowsThroughAReusedFactorTakeTheFreshSteps) {
  test::Generator g(57);
  int reused = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const test::KnownProblem kp = trial % 2 ? g.friction(20) : g.boxed(g.spd(60));
    Vector guess = kp.solution;
    for (int i = 0; i < guess.size(); ++i)
      if (g.uniform(0, 1) < 0.3) guess[i] += g.uniform(-0.5, 0.5);
    DantzigSolver updated = withStage(DantzigParams::BlockStage::Always);
    updated.params().blockUpdateRows = 200;
    updated.params().blockWoodburyRows = 200;
    DantzigSolver fresh = withStage(DantzigParams::BlockStage::Always);
    fresh.params().blockUpdateRows = 0;
    fresh.params().blockWoodburyRows = 0;
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
TEST(DantzigBlock, RandomWarmStartConvergesOrFailsHonestly) {
  test::PyramidSpec spec;
  spec.levels = 4;
  const Problem p = test::BoxPyramid(spec).rows().assemble(true);
  Generator g(31);
  DantzigSolver s = withStage(DantzigParams::BlockStage::Always);
  for (int trial = 0; trial < 3; ++trial) {
    Vector guess(p.size()), x;
    for (int i = 0; i < p.size(); ++i) guess[i] = g.uniform(-1, 2);
    const Result r = s.solveWithGuess(p, guess, x);
    const Accuracy a = accuracy(p, x);
    EXPECT_EQ(r.converged(), a.residual <= s.options().tolerance) << r.message;
    EXPECT_TRUE(r.converged() || !r.message.empty());
  }
}

// FixedOnce (ODE compatibility) never takes the block stage: same answer as the dense path.
TEST(DantzigBlock, FixedOnceIgnoresTheBlockStage) {
  test::PyramidSpec spec;
  spec.levels = 4;
  const Problem p = test::BoxPyramid(spec).rows().assemble(true);
  DantzigSolver block = withStage(DantzigParams::BlockStage::Always);
  DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
  block.options().frictionBounds = dense.options().frictionBounds = FrictionBounds::FixedOnce;
  Vector xb, xd;
  const Result rb = block.solve(p, xb), rd = dense.solve(p, xd);
  EXPECT_EQ(block.blockSteps(), 0);
  EXPECT_EQ(rb.status, rd.status);
  EXPECT_EQ(block.passes(), 1);
  EXPECT_EQ((xb - xd).lpNorm<Eigen::Infinity>(), 0.0);
}

// The generic families through the block stage (Always): every answer honest, most settled.
TEST(DantzigBlock, GeneratedFamiliesThroughTheBlockStage) {
  Generator g(32);
  DantzigSolver s = withStage(DantzigParams::BlockStage::Always);
  for (int trial = 0; trial < 10; ++trial) {
    expectSolved(s, g.standard(g.spd(5 + g.pick(40))));
    expectSolved(s, g.boxed(g.spd(5 + g.pick(40))));
    expectSolved(s, g.friction(2 + g.pick(12)));
    // Warm from the known answer: the block stage alone settles it.
    const KnownProblem kp = g.boxed(g.spd(30));
    Vector x;
    ASSERT_TRUE(s.solveWithGuess(kp.problem, kp.solution, x).converged());
    EXPECT_TRUE(s.blockSettled());
  }
}

// The block stage's LU for sliding rows: nonsymmetric values on a symmetric pattern, no
// pivoting; checked against Eigen's dense LU, and a zero pivot is reported.
TEST(DantzigBlock, SymmetricPatternLuSolves) {
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
  // y^T K^-1 z = (L^-1 y)^T D^-1 (L^-1 z) for sparse y, z (what the block stage's bordered
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
int pyramidSequenceSteps(DantzigSolver& s) {
  test::BoxPyramid pyramid(slidingPyramid(4));
  DantzigSolver dense = withStage(DantzigParams::BlockStage::Never);
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
TEST(DantzigBlock, DescendingFullStepsContinue) {
  DantzigSolver on = withStage(DantzigParams::BlockStage::Always);
  DantzigSolver off = withStage(DantzigParams::BlockStage::Always);
  on.params().blockTrustedSets = off.params().blockTrustedSets = false;
  off.params().blockDescentSteps = 0;
  const int withDescents = pyramidSequenceSteps(on), without = pyramidSequenceSteps(off);
  EXPECT_LT(withDescents, without);
}

// A trusted guess (the last answer, residual within 1e-2) gives the first index sets by where it
// lies (blockTrustedSets) rather than by the natural map at it: on this sequence fewer block
// steps in all; the answers are the same (pyramidSequenceSteps checks them against the dense path).
TEST(DantzigBlock, TrustedGuessSetsTakeFewerSteps) {
  DantzigSolver on = withStage(DantzigParams::BlockStage::Always);
  DantzigSolver off = withStage(DantzigParams::BlockStage::Always);
  off.params().blockTrustedSets = false;
  const int atGuess = pyramidSequenceSteps(on), naturalMap = pyramidSequenceSteps(off);
  EXPECT_LT(atGuess, naturalMap) << "block steps with and without blockTrustedSets";
}

// A guess farther off (residual above 1e-2: the last answer of a scene that moves fast, Bullet's
// falling pyramid) still takes its first sets from where it lies (blockSetsAtGuessResidual): fewer
// block steps in all than with the rule limited to 1e-2 (the natural map at the guess). A sliding
// 15-box pyramid whose b moves by 0.1 g dt per step, each solver warm started from its own last
// answer, every answer checked.
TEST(DantzigBlock, FarGuessSetsTakeFewerSteps) {
  int steps[2] = {0, 0};
  for (int cfg = 0; cfg < 2; ++cfg) {
    test::BoxPyramid pyramid(slidingPyramid(5));
    DantzigSolver s = withStage(DantzigParams::BlockStage::Always);
    if (cfg == 1) s.params().blockSetsAtGuessResidual = 1e-2;
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

// Auto, cold: a trial that does not settle but comes within 1e-2 is continued by the block stage
// from its best iterate (autoColdContinue) instead of pivoting from zero. A 15-box pyramid with
// cfm 1e-3 / dt (its trial ends at residual ~8e-3): the stage settles in 2 more steps where the
// pivoting took ~430 pivots; the same answer (A is positive definite).
TEST(DantzigBlock, AutoColdTrialWithinTrustContinues) {
  test::PyramidSpec spec;
  spec.cfm = 1e-3 / spec.dt;
  test::BoxPyramid pyramid(spec);
  pyramid.nextStep(1e-4);
  const Problem p = pyramid.rows().assemble(true);
  Vector x[2];
  int pivotsAndSteps[2];
  for (int cfg = 0; cfg < 2; ++cfg) {
    DantzigSolver s = withStage(DantzigParams::BlockStage::Auto);
    s.params().autoWarmMinRows = 100;  // n = 300
    s.params().autoColdContinue = cfg == 1;
    const Result r = s.solve(p, x[cfg]);
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LE(accuracy(p, x[cfg]).residual, s.options().tolerance);
    ASSERT_NE(r.message.find("cold trial"), std::string::npos) << r.message;
    EXPECT_EQ(s.blockSettled(), cfg == 1) << r.message;
    pivotsAndSteps[cfg] = r.iterations;
  }
  EXPECT_LT(pivotsAndSteps[1], pivotsAndSteps[0]);
  EXPECT_LE((x[1] - x[0]).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + x[0].lpNorm<Eigen::Infinity>()));
}

// A full step whose sets are those of two steps before would repeat that step's x: with
// blockBreakCycles the stage goes to the damped steps at once. Random friction pyramids from
// random guesses where the full steps 2-cycle: fewer steps, never a wrong status (a few of
// these coupled problems are not solved by either; see Friction).
TEST(DantzigBlock, TwoCyclesOfFullStepsHandOverAtOnce) {
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
      DantzigSolver s = withStage(DantzigParams::BlockStage::Always);
      s.params().blockBreakCycles = cfg == 1;
      s.params().blockDescentSteps = 0;
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
  EXPECT_LE(failed[1], 3) << "of 300";
}

// A guess far from the answer (residual above blockPgsResidual; Bullet's cached impulses right
// after the switch from SI) starts the block stage from blockPgsSweeps projected Gauss-Seidel
// sweeps over it: the same steps, pivots and answer as the option off from the pgs solver's
// iterate after as many sweeps; a guess within blockPgsResidual is left as it is. (The gain is
// measured on Bullet's pyramid, tests/bench/bullet_bench; on these synthetic pyramids the total
// block steps and pivots went either way.) A sliding 15-box pyramid, guesses one pgs sweep from
// zero (residual ~0.13).
TEST(DantzigBlock, PreSweepsOverAFarGuess) {
  test::BoxPyramid pyramid(slidingPyramid(5));
  std::unique_ptr<Solver> pgs = makeSolver("pgs");
  pgs->options().tolerance = 0;  // exactly maxIterations sweeps
  int swept = 0;
  for (int step = 0; step < 4; ++step) {
    pyramid.nextStep(0.1);
    const Problem p = pyramid.rows().assemble(true);
    Vector guess, presweptGuess;
    pgs->options().maxIterations = 1;
    pgs->solve(p, guess);
    DantzigSolver on = withStage(DantzigParams::BlockStage::Always);
    on.params().blockPgsResidual = step % 2 == 0 ? 0.05 : 1.0;
    const bool far = residual(p, guess) > on.params().blockPgsResidual;
    swept += far;
    pgs->options().maxIterations = on.params().blockPgsSweeps;
    pgs->solveWithGuess(p, guess, presweptGuess);
    DantzigSolver off = withStage(DantzigParams::BlockStage::Always);
    off.params().blockPgsSweeps = 0;
    Vector x, y;
    const Result r = on.solveWithGuess(p, guess, x);
    const Result ref = off.solveWithGuess(p, far ? presweptGuess : guess, y);
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-10);
    EXPECT_EQ(r.iterations, ref.iterations) << "step " << step;
    EXPECT_TRUE((x.array() == y.array()).all()) << "step " << step;
  }
  EXPECT_EQ(swept, 2);
}

// The body-space factors reproduce W to round-off for rotated anisotropic inertias: with
// Eigen's closed-form 3x3 eigensolver (computeDirect) R R^T missed W by up to 1e-6 of A's
// diagonal on ODE's 210-box pyramid, the check against A refused body space and those steps
// fell back to the sparse LU at 10-20x the cost.
TEST(DantzigBody, BodyFactorsOfRotatedInertiasMatchTheAssembledDiagonal) {
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
TEST(DantzigBody, IslandsOfMoreThanAThousandBodiesFactor) {
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
TEST(DantzigBody, SweepInBodySpaceIsTheSweepOnA) {
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
    // Conditioning ~ 1 / d: one step of refinement against K (as the block stage takes) restores
    // a backward error near the dense factorization's.
    Vector correction = r - K * y;
    body.solve(correction);
    y += correction;
    EXPECT_LE((K * y - r).norm(), 1e-14 * K.norm() * y.norm()) << trial;
    EXPECT_FALSE(body.factor(order, pos, sliding, coeff, p.findex, rho, 1.0)) << trial;
  }
}

TEST(DantzigBody, SolvesTheClampedSystemOfTheAssembledProblem) {
  expectClampedSystemSolved(slidingPyramid(4));
  test::PyramidSpec square = slidingPyramid(3);
  square.square = true;
  expectClampedSystemSolved(square);
}

// The block stage with the problem's rows (Solver::useRows, as RowSolver passes them) factors in
// body space and gives the answers of the same solver without them, step after step of a sliding
// pyramid (damped and full steps: cfm > 0). With cfm = 0 the full steps fall back to A_CC, and
// the answers are many: both paths' iterates then differ in round-off from the first step, and
// the exact friction passes after the block stage do not always settle (with the rows or without
// them, at different steps), so there each result is checked to say truly whether it converged.
TEST(DantzigBody, RowsGiveTheAnswersOfTheProblemAlone) {
  for (const double cfm : {1e-5 * 60, 0.0}) {
    test::PyramidSpec spec = slidingPyramid(5);
    spec.cfm = cfm;
    test::BoxPyramid pyramid(spec);
    DantzigSolver with = withStage(DantzigParams::BlockStage::Always);
    DantzigSolver without = withStage(DantzigParams::BlockStage::Always);
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

// finish() collects the rows of N whose sign condition drifted, then drives them one by one.
// Driving one can move a later one into C (its w reaches 0 along that ray: at once when the ray
// pushes it further the wrong way); removing that row from N again corrupted N (slot[] then
// holds its place in C), and on an empty N read before N's buffer (a heap-buffer-overflow under
// AddressSanitizer, seen on Bullet's ragdoll piles). This problem (13 rows on 4 bodies: joint,
// contact and box rows, some rows repeated with scaled Jacobians, b from a known solution) takes
// that path from a cold start: with the corrupted N the pivoting ended "failed" at residual
// 1.2e-4; skipping the moved row solves it.
TEST(Dantzig, DantzigIncrementalFinishSkipsRowsMovedByEarlierDrives) {
  const Problem p = io::readProblemJson(std::string(MLCP_SOURCE_DIR) +
                                        "/tests/data/dantzig_finish_moved_violator.json");
  for (const bool sparse : {false, true}) {
    Problem q = p;
    if (sparse) q.setA(p.toSparse());
    DantzigSolver s;
    Vector x;
    const Result r = s.solve(q, x);
    EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
    EXPECT_LE(accuracy(q, x).residual, 1e-12);
  }
}

// Regression: islands of scenes/plank_bridge.json in Bullet (13 pairs of ball joints on one axis
// each, so A is singular with cfm 0, and the crates' contacts with friction). On step 26 (108
// rows) dantzig's pivoting cycled on its zero pivots to the pivot limit (5500) and ended
// MaxIterations at residual 0.44; on step 21 (90 rows) lemke ended on a spurious ray at residual
// 0.21. Both now retry on A + delta I and answer with a residual on A at delta's level.
TEST(Dantzig, SingularBridgeIslandsAreRetriedRegularised) {
  for (const auto& [name, file] : {std::pair("dantzig", "plank_bridge_bullet_step26.json"),
                                   std::pair("lemke", "plank_bridge_bullet_step21.json")}) {
    SCOPED_TRACE(name);
    const Problem p = io::readProblemJson(std::string(MLCP_SOURCE_DIR) + "/tests/data/" + file);
    std::unique_ptr<Solver> s = makeSolver(name);
    ASSERT_TRUE(s);
    s->options().tolerance = 1e-6;
    Vector x;
    const Result r = s->solve(p, x);
    EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
    EXPECT_NE(r.message.find("regularised"), std::string::npos) << r.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-6);
  }
}

// Redundant joints: a ball joint given twice (the second copy's rows scaled, as Bullet's two
// point-to-point constraints on one hinge line repeat a direction), its rhs off by a drift of
// 1e-9: A is singular and the system consistent up to that drift. dantzig and ldlt (sparse) answer
// it through A + delta I and say so; the residual on A itself is at the drift's level.
TEST(Dantzig, RedundantJointsAreSolvedRegularised) {
  RowSystem s;
  BodyInverseMass body;
  body.invMass = 1;
  body.invInertia = Eigen::Matrix3d::Identity() * 2;
  s.bodies = {body};
  const Eigen::Vector3d arm(0.3, 0.5, 0);
  for (int copy = 0; copy < 2; ++copy)
    for (int k = 0; k < 3; ++k) {
      ConstraintRow r;
      r.bodyA = 0;
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * (copy ? 2.0 : 1.0);
      r.jA << e, arm.cross(e);
      s.rows.push_back(r);
    }
  s.b.resize(6);
  s.b << 0.1, -0.2, 0.3, 0.2 + 1e-9, -0.4, 0.6 - 1e-9;
  s.lo = Vector::Constant(6, -kInf);
  s.hi = Vector::Constant(6, kInf);
  s.cfm = Vector::Zero(6);
  const Problem p = s.assemble(true);
  DantzigSolver d;
  LdltSolver l;
  for (Solver* solver : {static_cast<Solver*>(&d), static_cast<Solver*>(&l)}) {
    Vector x;
    Options o;
    o.tolerance = 1e-6;
    solver->setOptions(o);
    const Result r = solver->solve(p, x);
    SCOPED_TRACE(solver->name());
    EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-8);
    const bool said = r.message.find("regularised") != std::string::npos ||
                      r.message.find("singular") != std::string::npos;
    EXPECT_TRUE(said) << r.message;
  }
}

// A block stage that does not settle hands its best iterate to the pivoting; a pivoting cut
// short (here after one pivot per pass) must not return something worse than that iterate
// (Bullet's 55-box pyramid polished from newton's answer: 120 block steps reached 6.7e-5, the
// cut pivoting returned newton's 5.4e-4).
TEST(Dantzig, ACutPivotingNeverReturnsWorseThanTheBlockStage) {
  test::PyramidSpec spec;
  spec.levels = 5;
  const Problem problem = test::BoxPyramid(spec).rows().assemble(true);
  constexpr int kBlockSteps = 2;
  Options o;
  detail::BlockPivoting block;
  Vector blockX = Vector::Zero(problem.size());
  const detail::BlockPivoting::Report rep = block.run(problem, blockX, o, kBlockSteps);
  ASSERT_FALSE(rep.settled) << rep.message;
  const double blockResidual = residual(problem, blockX);

  DantzigSolver solver;
  solver.params().blockStage = DantzigParams::BlockStage::Always;
  solver.params().maxBlockSteps = kBlockSteps;
  o.maxPivots = 1;
  solver.setOptions(o);
  Vector x;
  const Result r = solver.solve(problem, x);
  EXPECT_NE(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(problem, x), blockResidual) << r.message;
  EXPECT_NEAR(r.residual, residual(problem, x), 1e-15);
}

}  // namespace
}  // namespace mlcp
