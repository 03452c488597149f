// The polyhedral friction cone (friction_cone.hpp) against closed-form contact physics: a block on
// an incline sticks exactly below its critical slope and slides above it, a block pushed along
// the ground loses the speed the cone's friction predicts, in every direction of the polygon.
// Every answer is lemke's on the cone LCP, checked here row by row as a standard LCP.
#include "island/friction_cone.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/cube_on_ground.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp {
namespace {

using test::cubeOnGround;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81, kDt = 1.0 / 60;

// Solves the cone LCP with lemke, checks it as a standard LCP by hand and returns the box-form
// impulses.
Vector solveCone(const RowSystem& rows, int directions) {
  FrictionCone cone;
  EXPECT_EQ(cone.build(rows, directions), "");
  const Problem& p = cone.problem();
  LemkeSolver lemke;
  lemke.options().tolerance = 1e-12;
  Vector x;
  const Result r = lemke.solve(p, x);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  const Vector w = p.toDense() * x + p.b;
  for (int i = 0; i < p.size(); ++i) {
    if (p.lo[i] == -kInf) {  // none in these scenes
      ADD_FAILURE() << "free row " << i;
      continue;
    }
    EXPECT_GE(x[i], -1e-12) << i;
    EXPECT_GE(w[i], -1e-10) << i;
    EXPECT_LE(std::abs(x[i] * w[i]), 1e-10) << i;
  }
  return cone.toBox(x);
}

// The cube's velocity after the impulses x.
Vector6 velocityAfter(const RowSystem& rows, const Vector& x, const Vector6& before) {
  return before + rows.bodyVelocities(x)[0];
}

// A contact at the centre of mass (no torque: a particle) on an incline of slope angle alpha whose
// downhill direction lies at angle psi in the tangent plane: the tangential speed after one step.
double inclineSlideSpeed(double alpha, double psi, double mu, int directions) {
  Vector6 v = Vector6::Zero();
  v.head<3>() = kG * kDt *
                Eigen::Vector3d(std::sin(alpha) * std::cos(psi), std::sin(alpha) * std::sin(psi),
                                -std::cos(alpha));
  const RowSystem rows = cubeOnGround({Eigen::Vector3d::Zero()}, v, mu);
  const Vector x = solveCone(rows, directions);
  const Vector6 after = velocityAfter(rows, x, v);
  EXPECT_NEAR(after[2], 0, 1e-12);  // the normal holds
  return after.head<2>().norm();
}

// The critical slope is tan(alpha) = mu along a direction of the polygon and mu cos(pi / k)
// halfway between two of them (the polygon's edge is nearer the centre there).
TEST(FrictionCone, InclineSticksBelowAndSlidesAboveTheCriticalSlope) {
  const double mu = 0.6;
  struct Case {
    int k;
    double psi, critical;
  };
  for (const Case& c : {Case{4, 0, mu}, Case{4, kPi / 4, mu * std::cos(kPi / 4)}, Case{8, 0, mu},
                        Case{8, kPi / 8, mu * std::cos(kPi / 8)}, Case{8, kPi / 2, mu}}) {
    SCOPED_TRACE("k = " + std::to_string(c.k) + ", psi = " + std::to_string(c.psi));
    EXPECT_LT(inclineSlideSpeed(std::atan(0.98 * c.critical), c.psi, mu, c.k), 1e-12);
    EXPECT_GT(inclineSlideSpeed(std::atan(1.02 * c.critical), c.psi, mu, c.k), 1e-4);
  }
}

// Sliding along a direction of the polygon, the friction impulse is mu f_n against the motion:
// the downhill speed after one step is g dt (sin(alpha) - mu cos(alpha)).
TEST(FrictionCone, InclineSlidesWithTheClosedFormDeceleration) {
  const double mu = 0.3, alpha = 0.5;
  const double expected = kG * kDt * (std::sin(alpha) - mu * std::cos(alpha));
  for (int k : {4, 8}) EXPECT_NEAR(inclineSlideSpeed(alpha, 0, mu, k), expected, 1e-12) << k;
}

// A cube on four corner contacts pushed at 2 m/s along the ground at angle psi loses mu' g dt of
// speed in one step, mu' = mu along a direction, mu cos(pi / k) halfway between two, and keeps
// its direction (the two neighbouring directions share the force equally).
TEST(FrictionCone, BoxPushedSidewaysSlidesWithTheConesFrictionForce) {
  const double mu = 0.5, speed = 2;
  const std::vector<Eigen::Vector3d> corners = {
      {0.5, 0.5, -0.5}, {-0.5, 0.5, -0.5}, {-0.5, -0.5, -0.5}, {0.5, -0.5, -0.5}};
  struct Case {
    int k;
    double psi, muEffective;
  };
  for (const Case& c : {Case{4, 0, mu}, Case{4, kPi / 4, mu * std::cos(kPi / 4)},
                        Case{8, kPi / 4, mu}, Case{8, kPi / 8, mu * std::cos(kPi / 8)}}) {
    SCOPED_TRACE("k = " + std::to_string(c.k) + ", psi = " + std::to_string(c.psi));
    Vector6 v = Vector6::Zero();
    v.head<3>() = Eigen::Vector3d(speed * std::cos(c.psi), speed * std::sin(c.psi), -kG * kDt);
    const RowSystem rows = cubeOnGround(corners, v, mu);
    const Vector x = solveCone(rows, c.k);
    const Vector6 after = velocityAfter(rows, x, v);
    const Eigen::Vector2d horizontal = after.head<2>();
    EXPECT_NEAR(horizontal.norm(), speed - c.muEffective * kG * kDt, 1e-9);
    EXPECT_NEAR(std::atan2(horizontal.y(), horizontal.x()), c.psi, 1e-9);
    EXPECT_NEAR(after[2], 0, 1e-9);
  }
}

TEST(FrictionCone, DenseAndSparseFormsAgree) {
  Vector6 v = Vector6::Zero();
  v << 1, 0.5, -0.2, 0.1, 0, 0.3;
  const RowSystem rows =
      cubeOnGround({{0.5, 0.5, -0.5}, {-0.5, 0.5, -0.5}, {0, -0.5, -0.5}}, v, 0.7, 1e-6);
  FrictionCone dense, sparse;
  ASSERT_EQ(dense.build(rows, 6, false), "");
  ASSERT_EQ(sparse.build(rows, 6, true), "");
  EXPECT_TRUE(sparse.problem().isSparse());
  EXPECT_EQ(dense.problem().toDense(), sparse.problem().toDense());
  EXPECT_EQ(dense.problem().b, sparse.problem().b);
  EXPECT_EQ(dense.problem().size(), 3 * (1 + 6 + 1));
  EXPECT_EQ(dense.contacts(), 3);
}

// A tangent impulse inside the polygon goes to the cone form and back unchanged.
TEST(FrictionCone, BoxStartRoundTripsThroughTheConeForm) {
  const RowSystem rows = cubeOnGround({{0, 0, -0.5}}, Vector6::Zero(), 0.5);
  FrictionCone cone;
  ASSERT_EQ(cone.build(rows, 8), "");
  for (double angle : {0.0, 0.3, 1.9, 3.5, 5.9}) {
    const Vector box = (Vector(3) << 2.0, 0.4 * std::cos(angle), 0.4 * std::sin(angle)).finished();
    const Vector coneStart = cone.toCone(box);
    EXPECT_GE(coneStart.minCoeff(), 0);
    EXPECT_LT((cone.toBox(coneStart) - box).norm(), 1e-12) << angle;
  }
}

TEST(FrictionCone, ContactsTheConeCannotExpressAreRefusedWithAReason) {
  RowSystem rows = cubeOnGround({{0, 0, -0.5}}, Vector6::Zero(), 0.5);
  FrictionCone cone;
  EXPECT_NE(cone.build(rows, 2).find("at least 3"), std::string::npos);
  RowSystem anisotropic = rows;
  anisotropic.lo[2] = -0.2;
  anisotropic.hi[2] = 0.2;
  EXPECT_NE(cone.build(anisotropic, 4).find("anisotropic"), std::string::npos);
  const RowSystem rolling = test::withRollingFriction(rows);
  EXPECT_NE(cone.build(rolling, 4).find("rolling friction"), std::string::npos);
  RowSystem lifted = rows;
  lifted.lo[0] = -1;
  EXPECT_NE(cone.build(lifted, 4).find("lower bound"), std::string::npos);
}

// mu = 0: the polygon is a point; the contact keeps its normal as a plain LCP row and no
// directions, and its tangents answer 0.
TEST(FrictionCone, AFrictionlessContactKeepsOnlyItsNormal) {
  Vector6 v = Vector6::Zero();
  v << 1, 0.5, -0.2, 0, 0, 0;
  RowSystem rows = cubeOnGround({{0, 0, -0.5}, {0.5, 0, -0.5}}, v, 0.4);
  rows.lo[1] = rows.lo[2] = rows.hi[1] = rows.hi[2] = 0;  // the first contact has mu = 0
  FrictionCone cone;
  ASSERT_EQ(cone.build(rows, 8), "");
  EXPECT_EQ(cone.contacts(), 1);
  EXPECT_EQ(cone.frictionless(), 1);
  EXPECT_EQ(cone.problem().size(), 2 + 8 + 1);
  Vector z = Vector::Constant(cone.problem().size(), 1.0);
  const Vector x = cone.toBox(z);
  EXPECT_EQ(x[1], 0);
  EXPECT_EQ(x[2], 0);
}

}  // namespace
}  // namespace mlcp
