// RowSolver: classification and auto's choice on small row systems, the verified fallback with
// injected broken primaries, workspace reuse per island, the capture hook.
#include "mlcp/island/row_solver.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/broken_solvers.hpp"
#include "common/contact_scenes.hpp"
#include "common/redundant_joint.hpp"
#include "mlcp/io.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/ldlt.hpp"

namespace mlcp {
namespace {

BodyInverseMass unitBody() {
  BodyInverseMass b;
  b.invMass = 1;
  b.invInertia = Eigen::Matrix3d::Identity();
  return b;
}

// Appends a row on body 0 (and the world) with linear part `lin` and angular part `ang`.
void addRow(RowSystem& s, const Eigen::Vector3d& lin, const Eigen::Vector3d& ang, double b,
            double lo, double hi, double cfm, int findex = -1) {
  ConstraintRow r;
  r.bodyA = 0;
  r.jA << lin, ang;
  s.rows.push_back(r);
  const int n = s.size();
  s.b.conservativeResize(n);
  s.lo.conservativeResize(n);
  s.hi.conservativeResize(n);
  s.cfm.conservativeResize(n);
  s.b[n - 1] = b;
  s.lo[n - 1] = lo;
  s.hi[n - 1] = hi;
  s.cfm[n - 1] = cfm;
  s.findex.push_back(findex);
}

// A ball joint holding one body to the world: 3 bilateral rows.
RowSystem ballJoint() {
  RowSystem s;
  s.bodies = {unitBody()};
  const Eigen::Vector3d arm(0, 0.5, 0);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
    addRow(s, e, arm.cross(e), 0.1 * (k + 1), -kInf, kInf, 0);
  }
  return s;
}

// A box on the ground at four corners, pressed down (b < 0): frictionless contacts; with
// friction two tangent rows per corner coupled to the normal.
RowSystem boxOnGround(bool friction) {
  RowSystem s;
  s.bodies = {unitBody()};
  const Eigen::Vector3d n(0, 0, 1);
  const double corner[4][2] = {{0.5, 0.5}, {-0.5, 0.5}, {-0.5, -0.5}, {0.5, -0.5}};
  for (const auto& c : corner) {
    const Eigen::Vector3d r(c[0], c[1], -0.5);
    addRow(s, n, r.cross(n), -0.2 - 0.01 * c[0], 0, kInf, 1e-4);
  }
  if (friction)
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d r(corner[k][0], corner[k][1], -0.5);
      for (const Eigen::Vector3d& t : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)})
        addRow(s, t, r.cross(t), 0.05, -0.5, 0.5, 1e-4, k);
    }
  return s;
}

// Two bilateral rows pushing one point of a body along directions 1e-5 rad apart, whose rhs
// disagree by 1e-3: nearly dependent rows (the ragdoll pile's and AllConstraints' islands).
RowSystem nearlyDependentPair() {
  RowSystem rows;
  rows.bodies = {unitBody()};
  const Eigen::Vector3d arm(0, 0.5, 0);
  const double angle = 1e-5;
  for (const Eigen::Vector3d& e :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(std::cos(angle), std::sin(angle), 0)})
    addRow(rows, e, arm.cross(e), 0, -kInf, kInf, 0);
  rows.b << 0.1, 0.1 + 1e-3;
  return rows;
}

// Stage 5's tests: the exploding test solver as the primary, no fallback (keepSafe runs pgs for
// the comparison, at pgsSweeps sweeps).
RowSolverSettings explodingPrimary(int pgsSweeps) {
  test::registerBrokenSolvers();
  RowSolverSettings settings;
  settings.solver = "test-explode";
  settings.fallback = "";
  settings.fallbackOptions.maxIterations = pgsSweeps;
  return settings;
}

double rowResidual(const RowSystem& s, const Vector& x) { return residual(s.assemble(false), x); }

TEST(RowSolver, ClassifiesRowsByTheirBounds) {
  EXPECT_EQ(classify(RowSystem()), ProblemClass::Empty);
  EXPECT_EQ(classify(ballJoint()), ProblemClass::Linear);
  EXPECT_EQ(classify(boxOnGround(false)), ProblemClass::StandardLcp);
  EXPECT_EQ(classify(boxOnGround(true)), ProblemClass::Findex);
  RowSystem limited = ballJoint();
  limited.lo[0] = -1;  // a joint limit: bounded rows without friction
  EXPECT_EQ(classify(limited), ProblemClass::Boxed);
}

TEST(RowSolver, AutoSolvesEachClassWithItsChoiceAndReportsIt) {
  RowSolverSettings settings;  // auto
  settings.options.tolerance = 1e-10;
  RowSolver solver(settings);
  struct Case {
    RowSystem rows;
    const char* choice;
  };
  for (const Case& c : {Case{ballJoint(), "ldlt"}, Case{boxOnGround(false), "dantzig"},
                        Case{boxOnGround(true), "dantzig"}}) {
    Vector x;
    const IslandSolve s = solver.solve(c.rows, Vector::Zero(c.rows.size()), x);
    EXPECT_EQ(s.choice, c.choice);
    EXPECT_EQ(s.result.solver, c.choice);
    EXPECT_FALSE(s.fellBack) << s.result.message;
    EXPECT_TRUE(s.accepted);
    EXPECT_EQ(s.result.status, Status::Converged) << s.result.message;
    EXPECT_LE(rowResidual(c.rows, x), 1e-10);
    EXPECT_NEAR(s.result.residual, rowResidual(c.rows, x), 1e-12);
  }
  Vector x = Vector::Ones(2);
  const IslandSolve empty = solver.solve(RowSystem(), Vector(), x);
  EXPECT_EQ(empty.choice, "none");
  EXPECT_EQ(x.size(), 0);
}

TEST(RowSolver, AcceptanceIsTheSameRuleForEveryStatus) {
  Result r;
  r.residual = 1e-5;
  for (Status s : {Status::Converged, Status::MaxIterations, Status::TimeLimit}) {
    r.status = s;
    EXPECT_TRUE(acceptable(r, 1e-3)) << toString(s);
    EXPECT_FALSE(acceptable(r, 1e-6)) << toString(s);
  }
  for (Status s :
       {Status::Failed, Status::NumericalIssue, Status::InvalidInput, Status::Unsupported}) {
    r.status = s;
    EXPECT_FALSE(acceptable(r, 1e-3)) << toString(s);
  }
  r.status = Status::Converged;
  r.residual = std::nan("");
  EXPECT_FALSE(acceptable(r, kInf));
}

// The fallback's answer from the same start, computed alone (with the fallback's options).
Vector fallbackAlone(const RowSystem& rows, const Vector& start, const std::string& name) {
  RowSolverSettings settings;
  settings.solver = name;
  settings.options = settings.fallbackOptions;
  settings.fallback = "";
  RowSolver alone(settings);
  Vector x;
  alone.solve(rows, start, x);
  return x;
}

TEST(RowSolver, InjectedNaNAndFailingPrimariesFallBackAndAreCounted) {
  test::registerBrokenSolvers();
  const RowSystem rows = boxOnGround(true);
  const Vector start = Vector::Constant(rows.size(), 0.01);
  for (const char* broken : {"test-nan", "test-fail"}) {
    for (const char* fallback : {"dantzig", "pgs"}) {
      RowSolverSettings settings;
      settings.solver = broken;
      settings.fallback = fallback;
      RowSolver solver(settings);
      Vector x;
      const IslandSolve s = solver.solve(rows, start, x);
      EXPECT_TRUE(s.fellBack) << broken;
      EXPECT_EQ(s.requested, broken);
      EXPECT_EQ(s.choice, fallback);
      EXPECT_EQ(s.result.fallbacks, 1);
      EXPECT_TRUE(s.accepted) << s.result.message;
      EXPECT_NE(s.result.message.find(std::string(broken) + " rejected"), std::string::npos)
          << s.result.message;
      EXPECT_LE(rowResidual(rows, x), settings.acceptResidual);
      EXPECT_NEAR(s.result.residual, rowResidual(rows, x), 1e-12);
      EXPECT_EQ(x, fallbackAlone(rows, start, fallback)) << broken << " > " << fallback;
    }
  }
}

TEST(RowSolver, NothingUsableKeepsTheStart) {
  test::registerBrokenSolvers();
  RowSolverSettings settings;
  settings.solver = "test-nan";
  settings.fallback = "";
  RowSolver solver(settings);
  const RowSystem rows = boxOnGround(false);
  const Vector start = Vector::Constant(rows.size(), 0.3);
  Vector x;
  const IslandSolve s = solver.solve(rows, start, x);
  EXPECT_FALSE(s.fellBack);
  EXPECT_FALSE(s.accepted);
  EXPECT_EQ(s.result.status, Status::NumericalIssue);
  EXPECT_EQ(x, start);
  EXPECT_NEAR(s.result.residual, rowResidual(rows, start), 1e-12);
}

// Stage 5: an unacceptable answer that moves the bodies far more than pgs's is never applied
// (with no fallback configured, pgs runs for the comparison); one of sane size is.
TEST(RowSolver, AnExplodedAnswerIsNeverAppliedPgsIsInstead) {
  const RowSystem rows = boxOnGround(true);
  const Vector start = Vector::Zero(rows.size());
  RowSolverSettings settings = explodingPrimary(10);
  RowSolver solver(settings);
  Vector x;
  const IslandSolve s = solver.solve(rows, start, x);
  EXPECT_TRUE(s.energyGuard) << s.result.message;
  EXPECT_EQ(s.choice, "pgs");
  EXPECT_NE(s.result.message.find("pgs's applied"), std::string::npos) << s.result.message;
  EXPECT_LE(x.lpNorm<Eigen::Infinity>(), 10.0);
  EXPECT_NEAR(s.result.residual, rowResidual(rows, x), 1e-12);

  // A failed primary's answer of the exact answer's size (its start) is kept: the guard is
  // about explosions, not about residuals.
  settings.solver = "dantzig";
  RowSolver exact(settings);
  Vector answer;
  ASSERT_TRUE(exact.solve(rows, start, answer).accepted);
  settings.solver = "test-fail";
  RowSolver failing(settings);
  const Vector near = 1.5 * answer;
  const IslandSolve f = failing.solve(rows, near, x);
  EXPECT_FALSE(f.energyGuard) << f.result.message;
  EXPECT_EQ(f.choice, "test-fail");
  EXPECT_EQ(x, near);
}

// Bullet's Bridge (ExtendedTutorials/Bridge.cpp): planks hung on pairs of point-to-point
// constraints, 6 rows for the 5 freedoms a hinge takes, whose rhs disagree once the bridge has
// drifted. The bilateral system has no solution; ldlt's answer was A + delta I refined against
// A, 1e9 times the drift along the rows' dependency (a body at 2,495 m/s). It is now the
// minimum-norm least-squares answer, accepted and reported as such.
TEST(RowSolver, BridgeDriftedPointToPointPairsGetTheMinimumNormLeastSquaresAnswer) {
  RowSystem rows;
  rows.bodies = {unitBody()};
  const Eigen::Vector3d pivots[2] = {{0.5, 0.1, 0.2}, {-0.5, 0.1, 0.2}};  // the hinge line
  const double drift[6] = {0.10, -0.20, 0.05, 0.13, -0.17, 0.02};
  for (int p = 0; p < 2; ++p)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
      addRow(rows, e, pivots[p].cross(e), drift[3 * p + k], -kInf, kInf, 0);
    }
  RowSolver solver;
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_EQ(s.choice, "ldlt");
  EXPECT_EQ(s.result.status, Status::LeastSquares) << s.result.message;
  EXPECT_TRUE(s.accepted);
  EXPECT_NE(s.result.message.find("least-squares"), std::string::npos) << s.result.message;
  // Least squares: A (A x + b) = 0; minimum norm: x has no part along the rows' dependency (the
  // two pivots' along-axis rows are the same row, so x_0 - x_3 moves nothing and is 0).
  const Problem p = rows.assemble(false);
  const Vector w = p.denseA() * x + p.b;
  EXPECT_GT(w.lpNorm<Eigen::Infinity>(), 1e-3);  // inconsistent: no exact answer
  EXPECT_LE((p.denseA() * w).lpNorm<Eigen::Infinity>(), 1e-6);
  EXPECT_NEAR(x[0], x[3], 1e-9);
  // Bounded: the bodies move as the rows ask, not 1e9 times faster.
  for (const Vector6& v : rows.bodyVelocities(x)) EXPECT_LE(v.norm(), 1.0);
}

// Bullet's ragdoll pile (BenchmarkDemo 3, under a loaded machine's time budget): an island whose
// rows were nearly dependent got dantzig's answer exact to 2e-7 that moved a body at 38,000 m/s.
// Two rows pushing one point (dantzig, as in the pile) along directions 1e-5 rad apart, whose rhs
// disagree by 1e-3: the exact answer (ldlt's, to 1e-11) is impulses of ~1e7 and a velocity change
// ~1000 times ||b||. Stage 5 catches acceptable answers like it, and pgs's answer is applied.
TEST(RowSolver, RagdollPileNearlyDependentRowsNeverThrowABody) {
  const RowSystem rows = nearlyDependentPair();
  RowSolverSettings settings;
  settings.solver = "dantzig";
  RowSolver solver(settings);
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_TRUE(s.energyGuard) << s.result.message;
  EXPECT_EQ(s.choice, "pgs");
  for (const Vector6& v : rows.bodyVelocities(x)) EXPECT_LE(v.head<3>().norm(), 1.0);
  // Without the guard's trigger the exact answer would have been applied: it throws the body.
  const Problem p = rows.assemble(false);
  const Vector exact = p.denseA().ldlt().solve(-p.b);
  double fastest = 0;
  for (const Vector6& v : rows.bodyVelocities(exact))
    fastest = std::max(fastest, v.head<3>().norm());
  EXPECT_GT(fastest, 100.0);
}

// Bullet's 3000 boxes (BenchmarkDemo 1): most unsolved islands were dantzig's friction fixed
// point still moving after its passes (residuals 2e-3..1e-2). auto hands such an answer to
// newton, which has the friction bounds' exact Jacobian, before any fallback. Here the passes
// are cut to 1 on a sliding box (bounds from a zero start), so the fixed point cannot settle.
TEST(RowSolver, BenchmarkDemoUnsettledFrictionIsHandedToNewton) {
  RowSystem rows = boxOnGround(true);
  for (int i = 4; i < rows.size(); ++i) rows.b[i] = 2.0;  // sliding hard along both tangents
  RowSolverSettings settings;
  settings.options.maxIterations = 1;
  RowSolver solver(settings);
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_EQ(s.requested, "dantzig");
  EXPECT_EQ(s.choice, "newton") << s.result.message;
  EXPECT_TRUE(s.accepted) << s.result.message;
  EXPECT_FALSE(s.fellBack);
  EXPECT_NE(s.result.message.find("newton from its answer"), std::string::npos) << s.result.message;
  EXPECT_NEAR(s.result.residual, rowResidual(rows, x), 1e-12);
}

// Bullet's AllConstraints with newton named: on an island of joint rows newton stopped at a
// residual of 1.5 with a body at 900 m/s, and pgs's answer from the same start threw it as
// well (pgs diverging on rows it cannot settle). Neither is applied: the start is (the engine's
// "no change"), or no impulses when the start throws a body too; the status says Failed.
TEST(RowSolver, AllConstraintsWhenEveryAnswerThrowsABodyNoneIsApplied) {
  const RowSystem rows = nearlyDependentPair();
  RowSolver solver(explodingPrimary(1));
  Vector x;
  // Impulses along the rows' near dependency: they throw the body (~100 m/s against ||b|| = 0.1)
  // and one pgs sweep from them keeps them; the exploding primary adds 1e4 to each.
  const Vector start = (Vector(2) << 1e7, -1e7).finished();
  const IslandSolve s = solver.solve(rows, start, x);
  EXPECT_TRUE(s.energyGuard) << s.result.message;
  EXPECT_EQ(s.result.status, Status::Failed);
  EXPECT_EQ(s.choice, "none") << s.result.message;  // the start throws the body too
  EXPECT_EQ(x, Vector::Zero(rows.size()));
  EXPECT_NE(s.result.message.find("no impulses applied"), std::string::npos) << s.result.message;
  EXPECT_NEAR(s.result.residual, rowResidual(rows, x), 1e-12);
  // From a zero start pgs's answer is sane: it is applied.
  const IslandSolve k = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_EQ(k.choice, "pgs") << k.result.message;  // pgs's answer from zero is sane
}

// Bullet's ragdolls (BenchmarkDemo 3) with dantzig named: after an unsettled step on nearly
// dependent rows, the next step's start (last step's impulses matched to the new rows) threw a
// body at 9e6 m/s; pgs diverged from it (residual 4e4), no impulses were applied, and a body
// reached 122 m/s the step after (stock: 34). Such a start is not a warm start: the island is
// solved cold and the message says so.
TEST(RowSolver, BenchmarkRagdollsAStartThatThrowsABodyIsDiscarded) {
  const RowSystem rows = nearlyDependentPair();
  RowSolver solver(explodingPrimary(1));
  Vector x;
  // Impulses along the rows' near dependency: they throw the body (~1000 m/s against the limit
  // 1000 ||b|| = 100 m/s).
  const Vector start = (Vector(2) << 1e8, -1e8).finished();
  double thrown = 0;
  for (const Vector6& v : rows.bodyVelocities(start)) thrown = std::max(thrown, v.head<3>().norm());
  ASSERT_GT(thrown, 200.0);
  const IslandSolve s = solver.solve(rows, start, x);
  EXPECT_NE(s.result.message.find("start discarded"), std::string::npos) << s.result.message;
  EXPECT_EQ(s.choice, "pgs") << s.result.message;  // the exploding primary's answer is not
  for (const Vector6& v : rows.bodyVelocities(x)) EXPECT_LE(v.head<3>().norm(), 1.0);
  EXPECT_NEAR(s.result.residual, rowResidual(rows, x), 1e-12);
  // The same answer as from a zero start.
  Vector cold;
  solver.solve(rows, Vector::Zero(rows.size()), cold);
  EXPECT_EQ(x, cold);
  // A sane start is kept: no note.
  const IslandSolve k = solver.solve(rows, cold, x);
  EXPECT_EQ(k.result.message.find("start discarded"), std::string::npos) << k.result.message;
}

TEST(RowSolver, AnAnswerAboveTheLimitFallsBackWhateverTheSolver) {
  RowSolverSettings settings;
  settings.solver = "pgs";
  settings.options.maxIterations = 1;
  settings.acceptResidual = 1e-9;
  settings.fallback = "dantzig";
  settings.fallbackOptions.tolerance = 1e-10;
  RowSolver solver(settings);
  const RowSystem rows = boxOnGround(true);
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_TRUE(s.fellBack);
  EXPECT_EQ(s.choice, "dantzig");
  EXPECT_LE(rowResidual(rows, x), 1e-9) << s.result.residual << " " << s.result.message;

  settings.acceptResidual = kInf;  // any finite answer: no fallback
  RowSolver lenient(settings);
  const IslandSolve l = lenient.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_FALSE(l.fellBack);
  EXPECT_EQ(l.choice, "pgs");
  EXPECT_EQ(l.result.iterations, 1);
}

TEST(RowSolver, KeepsTheLdltAnalysisPerIsland) {
  RowSolverSettings settings;
  settings.denseAssemblyMaxRows = 0;  // the sparse path, whose analysis is kept
  RowSolver solver(settings);
  RowSystem rows = ballJoint();
  Vector x;
  for (int step = 0; step < 4; ++step) {
    rows.b *= 1.5;  // new values, same pattern
    rows.bodies[0].invMass = 1.0 + step;
    ASSERT_EQ(solver.solve(rows, Vector::Zero(3), x, 7).choice, "ldlt");
    EXPECT_LE(rowResidual(rows, x), 1e-12);
  }
  const auto* ldlt = dynamic_cast<const LdltSolver*>(solver.cachedSolver(7, "ldlt"));
  ASSERT_NE(ldlt, nullptr);
  EXPECT_EQ(ldlt->analyses(), 1);
  EXPECT_EQ(solver.cachedSolver(8, "ldlt"), nullptr);
  solver.solve(rows, Vector::Zero(3), x, 8);
  EXPECT_NE(solver.cachedSolver(8, "ldlt"), ldlt);
}

// Islands solved in turn each find their own workspace (RowSolver remembers the last island's
// slot): two patterns alternating keep one sparse analysis each; a mix-up would redo them.
TEST(RowSolver, AlternatingIslandsKeepTheirOwnWorkspaces) {
  RowSolverSettings settings;
  settings.denseAssemblyMaxRows = 0;
  RowSolver solver(settings);
  const RowSystem three = ballJoint();
  RowSystem two = ballJoint();
  two.rows.pop_back();
  two.b.conservativeResize(2);
  two.lo.conservativeResize(2);
  two.hi.conservativeResize(2);
  two.cfm.conservativeResize(2);
  two.findex.pop_back();
  Vector x;
  for (int step = 0; step < 6; ++step) {
    const bool first = step % 2 == 0;
    const RowSystem& rows = first ? three : two;
    ASSERT_EQ(solver.solve(rows, Vector::Zero(rows.size()), x, first ? 7 : 8).choice, "ldlt");
    EXPECT_LE(rowResidual(rows, x), 1e-12);
  }
  for (std::uint64_t key : {7, 8}) {
    const auto* ldlt = dynamic_cast<const LdltSolver*>(solver.cachedSolver(key, "ldlt"));
    ASSERT_NE(ldlt, nullptr);
    EXPECT_EQ(ldlt->analyses(), 1) << "island " << key;
  }
}

// timeAssembly = false (the ODE stepper) leaves assembleSeconds at 0 and changes no answer.
TEST(RowSolver, AssemblyTimingIsOptional) {
  RowSolverSettings untimed;
  untimed.timeAssembly = false;
  RowSolver a, b(untimed);
  const RowSystem rows = boxOnGround(false);
  Vector xa, xb;
  const IslandSolve sa = a.solve(rows, Vector::Zero(rows.size()), xa);
  const IslandSolve sb = b.solve(rows, Vector::Zero(rows.size()), xb);
  EXPECT_GE(sa.assembleSeconds, 0.0);
  EXPECT_EQ(sb.assembleSeconds, 0.0);
  EXPECT_TRUE((xa.array() == xb.array()).all());
  EXPECT_LE(rowResidual(rows, xb), 1e-10);
  EXPECT_GT(sb.result.seconds, 0.0);  // the island is still timed as a whole
}

// Regression (Bullet's BasicDemo: a block of touching boxes in free fall, every contact's answer
// 0, cost 17 ms a step in assembly and solver set-up for answers the start already had).
TEST(RowSolver, AStartThatSolvesTheRowsIsTheAnswerWithoutAssembly) {
  for (const char* name : {"auto", "dantzig", "newton", "lemke"}) {
    RowSolverSettings settings;
    settings.solver = name;
    settings.options.tolerance = 1e-6;
    RowSolver solver(settings);
    RowSystem rows = boxOnGround(true);
    for (int i = 0; i < 4; ++i) rows.b[i] = 0.2;  // the contacts separate: x = 0 is the answer
    Vector x;
    const Vector zero = Vector::Zero(rows.size());
    const IslandSolve free = solver.solve(rows, zero, x);
    EXPECT_EQ(free.result.status, Status::Converged) << name;
    EXPECT_EQ(free.result.message, "the start already solves the rows: no solve") << name;
    EXPECT_EQ(free.choice, "start") << name;
    EXPECT_EQ(free.result.solver, "start") << name;
    EXPECT_EQ(free.result.iterations, 0) << name;
    EXPECT_EQ(free.assembleSeconds, 0.0) << name;
    EXPECT_TRUE(free.accepted) << name;
    EXPECT_TRUE((x.array() == 0).all()) << name;
    EXPECT_EQ(free.result.residual, rowResidual(rows, x)) << name;
    // A start within the tolerance but not exact is solved (exact answers stay exact).
    for (double push : {1e-9, 0.1}) {
      Vector near = zero;
      near[0] = push;
      ASSERT_GT(rowResidual(rows, near), 1e-12);
      const IslandSolve solved = solver.solve(rows, near, x);
      EXPECT_NE(solved.choice, "start") << name << push;
      EXPECT_GT(solved.assembleSeconds, 0.0) << name << push;
      EXPECT_LE(rowResidual(rows, x), 1e-6) << name << push;
    }
  }
}

TEST(RowSolver, CaptureWritesEachIslandsProblem) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("row_solver_capture_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  RowSolver solver;
  solver.setCapture((dir / "step3-").string());
  const RowSystem a = boxOnGround(true), b = ballJoint();
  Vector x;
  solver.solve(a, Vector::Zero(a.size()), x, 1);
  solver.solve(b, Vector::Zero(b.size()), x, 2);
  solver.solve(RowSystem(), Vector(), x, 3);  // no rows: nothing to write
  ASSERT_EQ(solver.capturedFiles().size(), 2u);
  EXPECT_EQ(solver.capturedFiles()[1], (dir / "step3-island1.json").string());
  const Problem read = io::readProblemJson(solver.capturedFiles()[0]);
  const Problem built = a.assemble(false);
  EXPECT_LE((read.toDense() - built.toDense()).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_EQ(read.findex, built.findex);
  solver.setCapture("");
  solver.solve(a, Vector::Zero(a.size()), x, 1);
  EXPECT_TRUE(solver.capturedFiles().empty());
  std::filesystem::remove_all(dir);
}

// A box on six copies of its four corner contacts, no cfm: 72 rows on one body, A singular as on
// Bullet's resting piles.
RowSystem redundantCorners() {
  RowSystem rows = boxOnGround(true);
  const RowSystem corners = rows;
  for (int copy = 1; copy < 6; ++copy)  // 72 rows on one body: redundant contacts
    for (int i = 0; i < corners.size(); ++i)
      addRow(rows, corners.rows[i].jA.head<3>(), corners.rows[i].jA.tail<3>(), corners.b[i],
             corners.lo[i], corners.hi[i], corners.cfm[i],
             corners.findex[i] < 0 ? -1 : corners.findex[i] + corners.size() * copy);
  return rows;
}

// Bullet's BasicDemo: on its resting pile newton's solves end short of 1e-6 and cost 20-40x SI's
// step under the 50 ms budget alone. An island whose uncapped newton solve ended short runs its
// next newton solves under the engine-relative cap; a factor of 1 leaves newton no time (it
// stops before its first step), and the island then runs pgs at the engine's sweeps.
TEST(RowSolver, BasicDemoPileMissedByNewtonRunsUnderTheEngineCostCap) {
  const RowSystem rows = redundantCorners();
  Vector start;
  RowSolver().solve(rows, Vector::Zero(rows.size()), start);
  start.array() += 1e-6;  // near the answer: newton's answer below is acceptable, not converged
  const double startResidual = rowResidual(rows, start);
  ASSERT_GT(startResidual, 1e-6);
  ASSERT_LT(startResidual, 1e-4);
  RowSolverSettings settings;
  settings.policy.smallContactRows = settings.policy.smallIslandRows = 4;  // newton's island
  settings.options.maxIterations = 0;  // newton ends short at once, deterministically
  settings.newton.pivotingSteps = settings.newton.bodyPivotingSteps = 0;
  settings.engineCostFactor = 1;
  settings.policy.singularIslandSolver = "";  // newton's answers as they end
  RowSolver solver(settings);
  solver.setEngineSweeps(10);
  Vector x;
  const IslandSolve first = solver.solve(rows, start, x, 7);
  EXPECT_EQ(first.requested, "newton");
  EXPECT_EQ(first.result.status, Status::MaxIterations) << first.result.message;
  EXPECT_TRUE(first.accepted);
  const IslandSolve capped = solver.solve(rows, start, x, 7);
  EXPECT_EQ(capped.requested, "newton");
  EXPECT_EQ(capped.result.status, Status::TimeLimit) << capped.result.message;
  EXPECT_NE(capped.result.message.find("after 0 Newton steps"), std::string::npos)
      << capped.result.message;
  EXPECT_NEAR(capped.result.residual, rowResidual(rows, x), 1e-12);
  const IslandSolve demoted = solver.solve(rows, start, x, 7);
  EXPECT_EQ(demoted.requested, "pgs") << demoted.result.message;
  EXPECT_FALSE(demoted.fellBack);  // the fallback's own run is not repeated
  // Without the engine's sweeps there is no cap: the same second solve runs newton unbounded.
  RowSolver uncapped(settings);
  uncapped.solve(rows, start, x, 7);
  const IslandSolve second = uncapped.solve(rows, start, x, 7);
  EXPECT_EQ(second.requested, "newton");
  EXPECT_EQ(second.result.status, Status::MaxIterations) << second.result.message;
}

// A pile without cfm (36 boxes, A singular, the contacts' depths inconsistent where all hold):
// with the singular-island continuation on, newton's answer ends short of the tolerance, proximal
// goes on from it and ends exact, and the island's next solve runs proximal first.
TEST(RowSolver, SingularIslandMissedByNewtonIsFinishedByProximal) {
  test::PyramidSpec spec;
  spec.levels = 8;
  spec.cfm = 0;
  const RowSystem rows = test::BoxPyramid(spec).rows();
  RowSolverSettings settings;
  settings.timeBudget = 0;                                       // the same path on any machine
  settings.policy.singularIslandSolver = kSingularIslandSolver;  // off by default in engines
  RowSolver solver(settings);
  Vector x;
  const IslandSolve first = solver.solve(rows, Vector::Zero(rows.size()), x, 7);
  EXPECT_EQ(first.requested, "newton");
  EXPECT_EQ(first.choice, "proximal") << first.result.message;
  EXPECT_EQ(first.result.status, Status::Converged) << first.result.message;
  EXPECT_NEAR(first.result.residual, rowResidual(rows, x), 1e-15);
  EXPECT_LE(rowResidual(rows, x), kDefaultIslandTolerance);
  const Vector last = x + Vector::Constant(rows.size(), 1e-6);  // the next step's start
  const IslandSolve next = solver.solve(rows, last, x, 7);
  EXPECT_EQ(next.requested, "proximal") << next.result.message;
  EXPECT_EQ(next.result.status, Status::Converged) << next.result.message;
  EXPECT_LE(rowResidual(rows, x), kDefaultIslandTolerance);
}

TEST(RowSolver, UnknownNamesAreClearErrors) {
  RowSolverSettings settings;
  settings.solver = "nope";
  try {
    RowSolver solver(settings);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown solver 'nope'"), std::string::npos) << e.what();
  }
  settings.solver = "auto";
  settings.fallback = "auto";
  EXPECT_THROW(RowSolver{settings}, std::invalid_argument);
  settings.fallback = "pgs";
  EXPECT_NO_THROW(RowSolver{settings});
  settings.acceptResidual = -1;
  EXPECT_THROW(RowSolver{settings}, std::invalid_argument);
  settings.acceptResidual = 1e-3;
  for (double factor : {0.5, -1.0, kInf, std::nan("")}) {
    settings.engineCostFactor = factor;
    EXPECT_THROW(RowSolver{settings}, std::invalid_argument) << factor;
  }
  settings.engineCostFactor = 0;
  EXPECT_NO_THROW(RowSolver{settings});
}

TEST(ChoiceCounts, CountsInNameOrder) {
  ChoiceCounts c;
  for (const char* name : {"none", "dantzig", "ldlt", "dantzig", "none", "dantzig"}) c.add(name);
  EXPECT_EQ(c.toString(), "dantzig:3 ldlt:1 none:2");
  EXPECT_EQ(c.total(), 6);
  EXPECT_EQ(c.count("ldlt"), 1);
  EXPECT_EQ(c.count("pgs"), 0);
  ChoiceCounts d;
  d.add("pgs", 2);
  d.add(c);
  EXPECT_EQ(d.toString(), "dantzig:3 ldlt:1 none:2 pgs:2");
  d.clear();
  EXPECT_EQ(d.toString(), "");
}

}  // namespace
}  // namespace mlcp

namespace mlcp {
namespace {

// A ball joint given twice, its second copy's rhs off by a drift: A is singular, the rows are
// inconsistent and dantzig's pivoting on A breaks down (a zero pivot with nothing to stop the
// step). The island's next solves go to A + delta I at
// once (DantzigParams::regularised, set by RowSolver's per-island memory) with the same answer.
TEST(RowSolver, AnIslandWhoseDantzigBrokeDownIsRegularisedAtOnce) {
  const RowSystem s = test::redundantBallJoint(1e-4);
  RowSolverSettings settings;
  settings.solver = "dantzig";
  RowSolver solver(settings);
  Vector x1, x2;
  const IslandSolve first = solver.solve(s, Vector::Zero(6), x1, 7);
  const auto* dantzig = dynamic_cast<const DantzigSolver*>(solver.cachedSolver(7, "dantzig"));
  ASSERT_TRUE(dantzig);
  ASSERT_TRUE(dantzig->regularised()) << first.result.message;
  EXPECT_FALSE(dantzig->params().regularised);
  const IslandSolve second = solver.solve(s, Vector::Zero(6), x2, 7);
  EXPECT_TRUE(dantzig->params().regularised);
  EXPECT_NE(second.result.message.find("(asked for)"), std::string::npos) << second.result.message;
  EXPECT_EQ(x2, x1);
  EXPECT_EQ(second.result.status, first.result.status);
}

}  // namespace
}  // namespace mlcp
