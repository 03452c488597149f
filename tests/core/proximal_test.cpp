// The proximal point solver (mlcp/solvers/proximal.hpp) on singular contact problems: piles
// without cfm, whose exact answer exists but is not unique. Every answer is checked with
// mlcp::accuracy on the assembled problem, never by the solver's own claim.
#include "mlcp/solvers/proximal.hpp"

#include <gtest/gtest.h>

#include "common/contact_scenes.hpp"
#include "common/cube_on_ground.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/newton.hpp"

namespace mlcp {
namespace {

// A cube on four corner contacts, no cfm: 12 rows on 6 degrees of freedom, A of rank 6.
RowSystem restingCube(double cfm = 0) {
  const std::vector<Eigen::Vector3d> corners = {
      {0.5, 0.5, -0.5}, {-0.5, 0.5, -0.5}, {0.5, -0.5, -0.5}, {-0.5, -0.5, -0.5}};
  Vector6 v;
  v << 0.3, -0.1, -9.81 / 60, 0, 0, 0.2;  // falling, sliding and spinning a little
  return test::cubeOnGround(corners, v, 0.5, cfm);
}

RowSystem pile(int levels, bool square = false) {
  test::PyramidSpec spec;
  spec.levels = levels;
  spec.cfm = 0;  // Bullet's default: no cfm on contacts
  spec.square = square;
  return test::BoxPyramid(spec).rows();
}

// Solves p from zero to `tolerance` and checks the answer's recomputed residual.
void expectExact(ProximalSolver& s, const Problem& p, double tolerance) {
  s.options().tolerance = tolerance;
  Vector x;
  const Result r = s.solve(p, x);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(accuracy(p, x).residual, tolerance);
}

Result solveWithRows(ProximalSolver& s, const RowSystem& rows, const Problem& p, Vector& x) {
  s.useRows(&rows);
  Result r = s.solveWithGuess(p, Vector::Zero(p.size()), x);
  s.useRows(nullptr);
  return r;
}

TEST(Proximal, RestingCubeWithoutCfmIsExact) {
  const Problem p = restingCube().assemble(false);
  ProximalSolver s;
  expectExact(s, p, 1e-10);
  EXPECT_GE(s.innerIterations(), 1);  // the zero start is not the answer: outer steps ran
}

TEST(Proximal, SingularPileIsExactOnRowsAndOnTheMatrix) {
  const RowSystem rows = pile(8);  // 36 boxes, rows > newton's dense limit: the sparse paths
  for (bool withRows : {false, true}) {
    const Problem p = rows.assemble(true);
    ProximalSolver s;
    s.options().tolerance = 1e-9;
    Vector x;
    const Result r = withRows ? solveWithRows(s, rows, p, x) : s.solve(p, x);
    EXPECT_EQ(r.status, Status::Converged) << (withRows ? "rows: " : "matrix: ") << r.message;
    EXPECT_LE(accuracy(p, x).residual, 1e-9) << r.message;
    EXPECT_GT(s.innerIterations(), 0);
  }
}

TEST(Proximal, SquarePileWithoutCfmIsExact) {
  const RowSystem rows = pile(4, true);  // 30 boxes, each upper box on four below
  const Problem p = rows.assemble(true);
  ProximalSolver s;
  s.options().tolerance = 1e-9;
  Vector x;
  const Result r = solveWithRows(s, rows, p, x);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(accuracy(p, x).residual, 1e-9);
}

TEST(Proximal, StartAtTheAnswerTakesNoOuterStep) {
  const RowSystem rows = pile(5);
  const Problem p = rows.assemble(true);
  ProximalSolver s;
  s.options().tolerance = 1e-8;
  Vector x;
  ASSERT_EQ(s.solve(p, x).status, Status::Converged);
  Vector again;
  const Result r = s.solveWithGuess(p, x, again);
  EXPECT_EQ(r.status, Status::Converged);
  EXPECT_EQ(r.iterations, 0);
}

TEST(Proximal, NextStepFromTheLastAnswerTakesFewOuterSteps) {
  test::PyramidSpec spec;
  spec.levels = 6;
  spec.cfm = 0;
  test::BoxPyramid pyramid(spec);
  ProximalSolver s;
  s.options().tolerance = 1e-8;
  Vector x = Vector::Zero(pyramid.rows().size());
  int coldInner = 0;
  for (int step = 0; step < 5; ++step) {
    const RowSystem& rows = pyramid.rows();
    const Problem p = rows.assemble(true);
    s.useRows(&rows);
    Vector next;
    const Result r = s.solveWithGuess(p, x, next);
    s.useRows(nullptr);
    ASSERT_EQ(r.status, Status::Converged) << "step " << step << ": " << r.message;
    EXPECT_LE(accuracy(p, next).residual, 1e-8);
    if (step == 0) coldInner = s.innerIterations();
    if (step > 0) {  // from the last step's answer: a few outer steps of a few newton steps each
      EXPECT_LE(r.iterations, 6) << "step " << step << ": " << r.message;
      EXPECT_LT(4 * s.innerIterations(), coldInner) << "step " << step << ": " << r.message;
    }
    x = next;
    pyramid.nextStep();
  }
}

TEST(Proximal, DantzigInnerSolvesTheCubeToo) {
  const Problem p = restingCube().assemble(false);
  ProximalSolver s;
  s.params().inner = "dantzig";
  expectExact(s, p, 1e-9);
}

TEST(Proximal, AnInnerSolverThatCannotBeUsedIsInvalidInput) {
  const Problem p = restingCube().assemble(false);
  for (const char* inner : {"proximal", "auto", "pgs>newton", "nonsense"}) {
    ProximalSolver s;
    s.params().inner = inner;
    Vector x = Vector::Constant(p.size(), 7.0);
    const Result r = s.solve(p, x);
    EXPECT_EQ(r.status, Status::InvalidInput) << inner;
    EXPECT_NE(r.message.find("inner"), std::string::npos) << r.message;
  }
}

TEST(Proximal, OuterStepLimitReturnsTheBestIterateHonestly) {
  const RowSystem rows = pile(8);
  const Problem p = rows.assemble(true);
  ProximalSolver s;
  s.options().tolerance = 1e-14;  // out of reach in one step
  s.params().maxOuter = 1;
  Vector x;
  const Result r = solveWithRows(s, rows, p, x);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_NE(r.status, Status::Converged);
  EXPECT_DOUBLE_EQ(r.residual, accuracy(p, x).residual);
  EXPECT_LT(r.residual, accuracy(p, Vector::Zero(p.size())).residual);
}

TEST(Proximal, TimeBudgetIsHonoured) {
  const RowSystem rows = pile(10);
  const Problem p = rows.assemble(true);
  ProximalSolver s;
  s.options().tolerance = 1e-14;
  s.options().timeBudget = 1e-4;
  Vector x;
  const Result r = s.solve(p, x);
  EXPECT_EQ(r.status, Status::TimeLimit) << r.message;
  EXPECT_LE(r.residual, accuracy(p, Vector::Zero(p.size())).residual);
}

// A sparse A without a stored diagonal entry (the worked Lemke example's A_33 = 0): alpha is
// written into an explicit diagonal entry.
TEST(Proximal, SparseMatrixWithoutADiagonalEntryIsShifted) {
  Eigen::MatrixXd a(3, 3);
  a << 2, -1, 3, -1, 10, 2, -3, -2, 0;
  SparseMatrix sparse = a.sparseView();
  ASSERT_EQ(sparse.nonZeros(), 8);
  const Problem p(sparse, Vector((Vector(3) << -1, -10, 6).finished()));
  ProximalSolver s;
  expectExact(s, p, 1e-9);
}

// Two resting boxes' islands captured from Bullet's BasicDemo (scenes/basic_demo.json, step 150,
// cfm 0): newton ends island 26 at 1.7e-7; proximal ends both within 1e-9.
TEST(Proximal, CapturedBasicDemoIslandsAreExact) {
  for (const char* island : {"island12", "island26"}) {
    SCOPED_TRACE(island);
    const Problem p =
        io::readProblemJson(std::string(MLCP_SOURCE_DIR) +
                            "/tests/data/islands/basic_demo-bullet-step150-" + island + ".json");
    ProximalSolver s;
    expectExact(s, p, 1e-9);
  }
}

TEST(Proximal, RegisteredByName) {
  auto s = makeSolver("proximal");
  ASSERT_NE(s, nullptr);
  EXPECT_STREQ(s->name(), "proximal");
  const Problem p = restingCube().assemble(false);
  s->options().tolerance = 1e-9;
  Vector x;
  EXPECT_EQ(s->solve(p, x).status, Status::Converged);
}

}  // namespace
}  // namespace mlcp
