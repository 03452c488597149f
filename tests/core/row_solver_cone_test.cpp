// RowSolver with friction "cone" (friction_model.hpp): an island with friction rows is solved as
// the polyhedral cone's standard LCP and mapped back to the engine's rows. Checked against closed
// forms (a cube pushed along the ground loses mu' g dt of speed, mu' = mu along a direction of
// the polygon, mu cos(pi / k) between two, sqrt(2) mu for the box along a diagonal), and each
// answer as a solution of the cone's LCP, rebuilt here from the box impulses and the velocity.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/broken_solvers.hpp"
#include "common/cone_closed_form.hpp"
#include "common/cube_on_ground.hpp"
#include "island/friction_cone.hpp"
#include "mlcp/io.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp {
namespace {

using test::cubeOnGround;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81, kDt = 1.0 / 60;
// The rows' cfm: a little regularises the four redundant corner contacts (the engines add
// cfm / dt, 6e-4 at ODE's default 1e-5); closed forms hold to about cfm.
constexpr double kCfm = 1e-6;

const std::vector<Eigen::Vector3d> kCorners = {
    {0.5, 0.5, -0.5}, {-0.5, 0.5, -0.5}, {-0.5, -0.5, -0.5}, {0.5, -0.5, -0.5}};

Vector6 pushed(double speed, double psi) {
  Vector6 v = Vector6::Zero();
  v.head<3>() = Eigen::Vector3d(speed * std::cos(psi), speed * std::sin(psi), -kG * kDt);
  return v;
}

RowSolverSettings coneSettings(int k, const std::string& solver = "auto") {
  RowSolverSettings s;
  s.friction = FrictionModel::Cone;
  s.frictionDirections = k;
  s.solver = solver;
  s.timeBudget = 0;  // reproducible
  return s;
}

// The cone LCP's complementarity rebuilt from the box answer x: beta from the tangent impulses
// (FrictionCone::toCone, exact when at most two neighbouring directions carry force), lambda per
// contact the largest -d_j'v of its sliding velocity, then z >= 0, w = A z + b >= 0, z'w = 0
// checked row by row; returns the worst violation.
double coneViolation(const RowSystem& rows, const Vector& x, int k) {
  FrictionCone cone;
  EXPECT_EQ(cone.build(rows, k), "");
  Vector z = cone.toCone(x);
  const Problem& p = cone.problem();
  const Vector w0 = p.toDense() * z + p.b;  // lambda 0: w of a direction row is d_j'v
  const int contacts = cone.contacts(), first = p.size() - contacts * (k + 1);
  for (int c = 0; c < contacts; ++c) {
    double lambda = 0;
    for (int j = 0; j < k; ++j) lambda = std::max(lambda, -w0[first + c * k + j]);
    z[p.size() - contacts + c] = lambda;
  }
  const Vector w = p.toDense() * z + p.b;
  double worst = 0;
  for (int i = 0; i < p.size(); ++i) worst = std::max({worst, -z[i], -w[i], std::abs(z[i] * w[i])});
  return worst;
}

// Horizontal speed and direction of the cube after the impulses x.
Eigen::Vector2d slide(const RowSystem& rows, const Vector& x, const Vector6& before) {
  return (before + rows.bodyVelocities(x)[0]).head<2>();
}

TEST(RowSolverCone, ABoxPushedAlongTheGroundLosesTheConesFrictionInEveryDirection) {
  const double mu = 0.5, speed = 2;
  for (const test::FrictionCase& c : test::kFrictionCases) {
    if (c.k == 0) continue;  // the box: below
    SCOPED_TRACE(test::caseName(c));
    const double muEffective = mu * test::frictionSupport(c.k, c.psi);
    const Vector6 v = pushed(speed, c.psi);
    const RowSystem rows = cubeOnGround(kCorners, v, mu, kCfm);
    RowSolver solver(coneSettings(c.k));
    Vector x;
    const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
    EXPECT_EQ(s.friction, FrictionModel::Cone);
    EXPECT_EQ(s.choice, "lemke") << s.result.message;
    EXPECT_FALSE(s.fellBack) << s.result.message;
    EXPECT_LE(s.result.residual, 1e-9);
    const Eigen::Vector2d h = slide(rows, x, v);
    EXPECT_NEAR(h.norm(), speed - muEffective * kG * kDt, 1e-5);
    EXPECT_NEAR(std::atan2(h.y(), h.x()), c.psi, 1e-5);
    EXPECT_LE(coneViolation(rows, x, c.k), 1e-7);
  }
}

// The engine's box along a diagonal of its tangents: each tangent row reaches mu f, so the
// friction is sqrt(2) mu f; the cone (k = 4, its directions the tangents) gives mu f / sqrt(2).
TEST(RowSolverCone, TheBoxGivesSqrt2TimesMuAlongADiagonalTheConeAtMostMu) {
  const double mu = 0.5, speed = 2, psi = kPi / 4;
  const Vector6 v = pushed(speed, psi);
  const RowSystem rows = cubeOnGround(kCorners, v, mu, kCfm);
  RowSolverSettings box = coneSettings(4, "dantzig");
  box.friction = FrictionModel::Box;
  Vector xBox, xCone;
  RowSolver boxSolver(box), coneSolver(coneSettings(4, "lemke"));
  const IslandSolve b = boxSolver.solve(rows, Vector::Zero(rows.size()), xBox);
  const IslandSolve c = coneSolver.solve(rows, Vector::Zero(rows.size()), xCone);
  EXPECT_EQ(b.friction, FrictionModel::Box);
  EXPECT_EQ(c.friction, FrictionModel::Cone) << c.result.message;
  EXPECT_NEAR(slide(rows, xBox, v).norm(), speed - std::sqrt(2.0) * mu * kG * kDt, 1e-5);
  EXPECT_NEAR(slide(rows, xCone, v).norm(), speed - mu / std::sqrt(2.0) * kG * kDt, 1e-5);
}

TEST(RowSolverCone, AnInclineSticksBelowAndSlidesAboveItsCriticalSlope) {
  const double mu = 0.6;
  for (int k : {4, 8}) {
    for (double psi : {0.0, kPi / k}) {  // along a direction, between two
      const double critical = psi == 0 ? mu : mu * std::cos(kPi / k);
      for (double factor : {0.98, 1.02}) {
        const double alpha = std::atan(factor * critical);
        Vector6 v = Vector6::Zero();
        v.head<3>() = kG * kDt *
                      Eigen::Vector3d(std::sin(alpha) * std::cos(psi),
                                      std::sin(alpha) * std::sin(psi), -std::cos(alpha));
        const RowSystem rows = cubeOnGround({Eigen::Vector3d::Zero()}, v, mu);
        RowSolver solver(coneSettings(k));
        Vector x;
        const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
        ASSERT_EQ(s.friction, FrictionModel::Cone) << s.result.message;
        const double after = slide(rows, x, v).norm();
        // Sliding: the friction is the polygon's support in the slope direction.
        const double expected =
            factor < 1 ? 0 : kG * kDt * (std::sin(alpha) - critical * std::cos(alpha));
        EXPECT_NEAR(after, expected, 1e-9) << "k " << k << " psi " << psi << " x " << factor;
      }
    }
  }
}

// mu = 0 makes the cone a point: no friction. mu = +inf (ODE's dInfinity) reaches the core as
// free tangent rows without findex (the ODE adapter's rows): the cone keeps them, no slip.
TEST(RowSolverCone, DegenerateMuIsNoFrictionAtZeroAndNoSlipAtInfinity) {
  const Vector6 v = pushed(2, 0.3);
  RowSolver solver(coneSettings(8));
  Vector x;
  const RowSystem frictionless = cubeOnGround(kCorners, v, 0, kCfm);
  IslandSolve s = solver.solve(frictionless, Vector::Zero(frictionless.size()), x);
  EXPECT_TRUE(s.accepted) << s.result.message;
  EXPECT_EQ(s.friction, FrictionModel::Cone);
  EXPECT_NEAR((slide(frictionless, x, v) - v.head<2>()).norm(), 0, 1e-9);
  RowSystem stuck = cubeOnGround(kCorners, v, 0.5, kCfm);
  for (int t : {1, 2, 7, 8}) {  // two opposite corners without slip
    stuck.findex[t] = -1;
    stuck.lo[t] = -kInf;
    stuck.hi[t] = kInf;
  }
  s = solver.solve(stuck, Vector::Zero(stuck.size()), x);
  EXPECT_TRUE(s.accepted) << s.result.message;
  EXPECT_EQ(s.friction, FrictionModel::Cone);
  const Vector w = stuck.slack(x);  // J v_after + cfm x: the rows' velocities after the step
  for (int t : {1, 2, 7, 8}) EXPECT_NEAR(w[t], 0, 1e-5) << t;  // the pinned corners do not slip
  EXPECT_GT(slide(stuck, x, v).norm(), 0.1);                   // the cube trips over them
}

TEST(RowSolverCone, CaptureWritesTheConesStandardLcp) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("row_solver_cone_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const Vector6 v = pushed(2, 0.3);
  const RowSystem rows = cubeOnGround(kCorners, v, 0.5, kCfm);
  RowSolver solver(coneSettings(8));
  solver.setCapture((dir / "s-").string());
  Vector x;
  solver.solve(rows, Vector::Zero(rows.size()), x);
  ASSERT_EQ(solver.capturedFiles().size(), 1u);
  const Problem p = io::readProblemJson(solver.capturedFiles()[0]);
  ASSERT_EQ(p.size(), 4 * (1 + 8 + 1));
  EXPECT_EQ(p.classify(), ProblemClass::StandardLcp);
  LemkeSolver lemke;
  Vector z;
  ASSERT_EQ(lemke.solve(p, z).status, Status::Converged);
  EXPECT_LE(residual(p, z), 1e-9);
  FrictionCone cone;
  ASSERT_EQ(cone.build(rows, 8), "");
  EXPECT_LE((slide(rows, cone.toBox(z), v) - slide(rows, x, v)).norm(), 1e-9);
  std::filesystem::remove_all(dir);
}

TEST(RowSolverCone, BadSettingsAreClearErrors) {
  for (int k : {2, 0, -4, 65, 1 << 30}) {
    try {
      RowSolver solver(coneSettings(k));
      FAIL() << "no exception for k = " << k;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("friction directions must be in [3, 64]"),
                std::string::npos)
          << e.what();
    }
  }
  for (const char* name : {"pgs", "gs", "ldlt"}) {
    try {
      RowSolver solver(coneSettings(4, name));
      FAIL() << "no exception for " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("friction 'cone'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  RowSolverSettings box = coneSettings(4, "pgs");
  box.friction = FrictionModel::Box;
  EXPECT_NO_THROW(RowSolver{box});
}

// A primary that fails on the cone's LCP says so, and the fallback answers on the engine's box
// rows.
TEST(RowSolverCone, APrimaryThatFailsOnTheLcpFallsBackToTheBox) {
  test::registerBrokenSolvers();
  const Vector6 v = pushed(2, 0.3);
  const RowSystem rows = cubeOnGround(kCorners, v, 0.5, kCfm);
  RowSolver solver(coneSettings(4, "test-fail"));
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_TRUE(s.fellBack);
  EXPECT_EQ(s.choice, "pgs");
  EXPECT_EQ(s.friction, FrictionModel::Box);
  EXPECT_NE(s.result.message.find("test-fail"), std::string::npos) << s.result.message;
  EXPECT_TRUE(x.allFinite());
}

// A rejected cone answer falls back to the box for that solve only: the box's pgs-first memory
// after a breakdown does not take the cone from the island for its next solves. The rejection is
// lemke's pivot limit (Options::maxPivots), which a cube on 16 coplanar ground points exceeds and
// one on its 4 corners does not.
TEST(RowSolverCone, ARejectedConeAnswerDoesNotCostTheIslandTheConeLater) {
  const Vector6 v = pushed(2, kPi / 8);
  std::vector<Eigen::Vector3d> grid;
  for (const double x : {-0.5, -1.0 / 6, 1.0 / 6, 0.5})
    for (const double y : {-0.5, -1.0 / 6, 1.0 / 6, 0.5}) grid.push_back({x, y, -0.5});
  const RowSystem hard = cubeOnGround(grid, v, 0.5, kCfm);
  const RowSystem easy = cubeOnGround(kCorners, v, 0.5, kCfm);
  RowSolverSettings settings = coneSettings(8);  // auto: the memory is auto's
  settings.options.maxPivots = 60;  // the 16-point cone LCP takes 73, the 4-corner one fewer
  RowSolver solver(settings);
  Vector x;
  IslandSolve s = solver.solve(hard, Vector::Zero(hard.size()), x, 7);
  ASSERT_TRUE(s.fellBack) << "lemke solved the hard case: " << s.result.message;
  EXPECT_EQ(s.friction, FrictionModel::Box);
  for (int i = 0; i < 3; ++i) {
    s = solver.solve(easy, Vector::Zero(easy.size()), x, 7);
    EXPECT_EQ(s.friction, FrictionModel::Cone) << i << ": " << s.result.message;
    EXPECT_EQ(s.choice, "lemke") << i;
  }
}

// Contacts the cone cannot express (here rolling friction: a third friction row) keep the box.
TEST(RowSolverCone, AnIslandTheConeCannotExpressKeepsTheBoxAndSaysWhy) {
  const RowSystem rows =
      test::withRollingFriction(cubeOnGround({{0, 0, -0.5}}, pushed(1, 0), 0.5, kCfm));
  RowSolver solver(coneSettings(4, "dantzig"));
  Vector x;
  const IslandSolve s = solver.solve(rows, Vector::Zero(rows.size()), x);
  EXPECT_EQ(s.friction, FrictionModel::Box);
  EXPECT_NE(s.result.message.find("cone not built"), std::string::npos) << s.result.message;
  EXPECT_TRUE(s.accepted) << s.result.message;
}

TEST(RowSolverCone, FrictionModelNamesRoundTrip) {
  FrictionModel m = FrictionModel::Box;
  EXPECT_TRUE(parseFrictionModel("cone", m));
  EXPECT_EQ(m, FrictionModel::Cone);
  EXPECT_STREQ(toString(m), "cone");
  EXPECT_FALSE(parseFrictionModel("pyramid", m));
  EXPECT_EQ(m, FrictionModel::Cone);
  EXPECT_TRUE(parseFrictionModel("box", m));
  EXPECT_STREQ(toString(m), "box");
}

}  // namespace
}  // namespace mlcp
