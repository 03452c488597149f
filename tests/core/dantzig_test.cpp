// dantzig specifics: the worked Lemke example, random P-matrix / SPD / boxed / mixed / findex
// problems against known solutions, FixedOnce versus Exact friction, infeasible and singular
// problems, warm start, workspace reuse, sparse input. Every answer is checked with
// mlcp::accuracy().
#include "mlcp/solvers/dantzig.hpp"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "common/contact_scenes.hpp"
#include "common/expect_solved.hpp"
#include "common/generators.hpp"
#include "common/redundant_joint.hpp"
#include "linalg/body_space.hpp"  // BodySpaceSystem (internal)
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solvers/ldlt.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "mlcp/solvers/pgs.hpp"
#include "pivoting/dantzig_small.hpp"  // the tiny dense path (internal)

namespace mlcp {
namespace {

using test::expectSolved;
using test::frictionPyramids;
using test::Generator;
using test::jacobianGram;
using test::KnownProblem;

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

// ---- the path for tiny dense islands (core/src/pivoting/dantzig_small.hpp) ----

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
    const KnownProblem kp = smallProblem(g, 1 + trial % kPlainLoopRows, trial % 3);
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
    const int n = 2 + trial % (kPlainLoopRows - 1);
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
    // lemke's friction fixed point (its friction LCP solves this island on A: below).
    if (auto* lemke = dynamic_cast<LemkeSolver*>(s.get())) lemke->frictionLcp = false;
    s->options().tolerance = 1e-6;
    Vector x;
    const Result r = s->solve(p, x);
    EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
    EXPECT_NE(r.message.find("regularised"), std::string::npos) << r.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-6);
  }
  // The same lemke island with findex friction as one LCP (the default): solved on A itself.
  const Problem p = io::readProblemJson(std::string(MLCP_SOURCE_DIR) +
                                        "/tests/data/plank_bridge_bullet_step21.json");
  LemkeSolver lemke;
  lemke.options().tolerance = 1e-6;
  Vector x;
  const Result r = lemke.solve(p, x);
  EXPECT_TRUE(r.converged()) << toString(r.status) << " " << r.message;
  EXPECT_LE(accuracy(p, x).residual, 1e-6);
}

// DantzigParams::breakdownShift sets the retry's delta (relative to max |A_ii|): the message
// names it, and a shift 100x larger leaves a residual on A that is not smaller.
TEST(Dantzig, BreakdownShiftIsTheRetrysDelta) {
  const Problem p = io::readProblemJson(std::string(MLCP_SOURCE_DIR) +
                                        "/tests/data/plank_bridge_bullet_step26.json");
  double dMax = 0;
  for (int i = 0; i < p.size(); ++i) dMax = std::max(dMax, std::abs(p.diagonal(i)));
  double residuals[2];
  for (const int k : {0, 1}) {
    DantzigSolver s;
    s.options().tolerance = 1e-6;
    s.params().breakdownShift = k == 0 ? 1e-10 : 1e-8;
    Vector x;
    const Result r = s.solve(p, x);
    std::ostringstream delta;
    delta << "A + " << s.params().breakdownShift * dMax << " I";
    EXPECT_NE(r.message.find(delta.str()), std::string::npos) << r.message;
    residuals[k] = accuracy(p, x).residual;
  }
  EXPECT_LE(residuals[0], residuals[1]);
}

// DantzigParams::regularised goes to A + delta I at once: the same answer, bit for bit, as the
// retry after the breakdown on the bridge island, without the pivots of the attempt on A; a
// regular problem asked the same way is solved on A + delta I too, and says so.
TEST(Dantzig, RegularisedAtOnceIsTheRetrysAnswer) {
  const Problem p = io::readProblemJson(std::string(MLCP_SOURCE_DIR) +
                                        "/tests/data/plank_bridge_bullet_step26.json");
  DantzigSolver retry, atOnce;
  for (DantzigSolver* s : {&retry, &atOnce}) s->options().tolerance = 1e-6;
  atOnce.params().regularised = true;
  Vector xRetry, xAtOnce;
  const Result r = retry.solve(p, xRetry);
  const Result a = atOnce.solve(p, xAtOnce);
  EXPECT_TRUE(retry.regularised());
  EXPECT_TRUE(atOnce.regularised());
  EXPECT_NE(a.message.find("(asked for)"), std::string::npos) << a.message;
  EXPECT_EQ(xAtOnce, xRetry);
  EXPECT_LT(a.iterations, r.iterations);
  EXPECT_EQ(a.status, r.status);

  const Problem regular = test::seedLemkeExample();
  Vector x;
  EXPECT_TRUE(atOnce.solve(regular, x).converged());
  EXPECT_TRUE(atOnce.regularised());
  DantzigSolver plain;
  EXPECT_TRUE(plain.solve(regular, x).converged());
  EXPECT_FALSE(plain.regularised());
}

// Redundant joints: a ball joint given twice (the second copy's rows scaled, as Bullet's two
// point-to-point constraints on one hinge line repeat a direction), its rhs off by a drift of
// 1e-9: A is singular and the system consistent up to that drift. dantzig and ldlt (sparse) answer
// it through A + delta I and say so; the residual on A itself is at the drift's level.
TEST(Dantzig, RedundantJointsAreSolvedRegularised) {
  const RowSystem s = test::redundantBallJoint(1e-9);
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

}  // namespace
}  // namespace mlcp
