// Lemke on findex friction as one LCP (box_friction_lcp.hpp): a block on an incline sticking and
// sliding (one contact, and four contacts without CFM: A singular), mu = 0 rows, a normal's
// Bullet-style finite upper bound, a normal row that is free (the fixed point then), random
// findex problems against dantzig and newton, and the pivot limit's contact problems. Every
// answer is judged by mlcp::residual on the findex problem, recomputed here.
#include <gtest/gtest.h>

#include <cmath>

#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp {
namespace {

using test::Generator;

constexpr double kGravity = 9.81, kStep = 1.0 / 60;

Result solveLemke(const Problem& p, Vector& x, bool frictionLcp, double tolerance = 1e-9) {
  LemkeSolver lemke;
  lemke.frictionLcp = frictionLcp;
  Options opt;
  opt.tolerance = tolerance;
  lemke.setOptions(opt);
  const Result r = lemke.solve(p, x);
  EXPECT_NEAR(r.residual, residual(p, x), 1e-15);
  return r;
}

bool solvedAsOneLcp(const Result& r) {
  return r.message.find("friction as one LCP") != std::string::npos;
}

// A block of mass m on an incline of angle theta, contact frame (n, t1 down the slope, t2
// across), one contact per point `corners` (body frame, relative to the centre of mass), inertia
// of a box with half extents (hx, hy, hz). Rows per contact: normal, t1, t2; the normal's upper
// bound is Bullet's 1e10. b is the contact velocities after gravity's step.
Problem incline(double theta, double mu, const std::vector<Eigen::Vector3d>& corners,
                double mass = 2) {
  const double hx = 0.5, hy = 0.4, hz = 0.1;
  const Eigen::Vector3d inertia(mass / 3 * (hy * hy + hz * hz), mass / 3 * (hx * hx + hz * hz),
                                mass / 3 * (hx * hx + hy * hy));
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY()};
  const int n = 3 * static_cast<int>(corners.size());
  DenseMatrix J(n, 6);
  for (size_t c = 0; c < corners.size(); ++c)
    for (int k = 0; k < 3; ++k) {
      J.row(3 * c + k) << axes[k].transpose(), corners[c].cross(axes[k]).transpose();
    }
  Eigen::Matrix<double, 6, 1> inverseMass, velocity;
  inverseMass << Eigen::Vector3d::Constant(1 / mass), inertia.cwiseInverse();
  velocity << kGravity * kStep * std::sin(theta), 0, -kGravity * kStep * std::cos(theta), 0, 0, 0;
  Problem p(DenseMatrix(J * inverseMass.asDiagonal() * J.transpose()), Vector(J * velocity));
  p.findex.assign(n, -1);
  for (int k = 0; k < n; k += 3) {
    p.hi[k] = 1e10;
    for (int t = 1; t <= 2; ++t) {
      p.lo[k + t] = -mu;
      p.hi[k + t] = mu;
      p.findex[k + t] = k;
    }
  }
  return p;
}

// Sums of the normal, down-slope and across impulses.
Eigen::Vector3d totals(const Vector& x) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int i = 0; i < x.size(); ++i) s[i % 3] += x[i];
  return s;
}

TEST(LemkeFrictionLcp, OneContactSticksBelowTheFrictionAngle) {
  const double theta = 0.35, mu = 0.5, mass = 2;  // tan 0.35 = 0.365 < 0.5
  const Problem p = incline(theta, mu, {Eigen::Vector3d::Zero()}, mass);
  Vector x;
  const Result r = solveLemke(p, x, true);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_TRUE(solvedAsOneLcp(r)) << r.message;
  EXPECT_NEAR(x[0], mass * kGravity * kStep * std::cos(theta), 1e-12);
  EXPECT_NEAR(x[1], -mass * kGravity * kStep * std::sin(theta), 1e-12);
  EXPECT_NEAR(x[2], 0, 1e-12);
}

TEST(LemkeFrictionLcp, OneContactSlidesAboveTheFrictionAngle) {
  const double theta = 0.7, mu = 0.5, mass = 2;  // tan 0.7 = 0.84 > 0.5
  const Problem p = incline(theta, mu, {Eigen::Vector3d::Zero()}, mass);
  Vector x;
  const Result r = solveLemke(p, x, true);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_TRUE(solvedAsOneLcp(r)) << r.message;
  const double normal = mass * kGravity * kStep * std::cos(theta);
  EXPECT_NEAR(x[0], normal, 1e-12);
  EXPECT_NEAR(x[1], -mu * normal, 1e-12);
  EXPECT_NEAR(x[2], 0, 1e-12);
  // The block keeps sliding down the slope at g h (sin - mu cos).
  EXPECT_NEAR(p.slack(x)[1], kGravity * kStep * (std::sin(theta) - mu * std::cos(theta)), 1e-12);
}

// Four corners without CFM: 12 rows on 6 freedoms, A singular, the answer not unique; its
// totals are.
std::vector<Eigen::Vector3d> fourCorners() {
  return {{0.5, 0.4, -0.1}, {-0.5, 0.4, -0.1}, {0.5, -0.4, -0.1}, {-0.5, -0.4, -0.1}};
}

// The four corners on an incline of `theta` solved as one LCP: the summed impulses (normal,
// along the slope, across it), x into `x`.
Eigen::Vector3d fourCornersTotals(double theta, double mu, double mass, Problem& p, Vector& x) {
  p = incline(theta, mu, fourCorners(), mass);
  const Result r = solveLemke(p, x, true);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_TRUE(solvedAsOneLcp(r)) << r.message;
  return x.size() == p.size() ? totals(x) : Eigen::Vector3d::Constant(kInf);
}

TEST(LemkeFrictionLcp, FourCornersStickWithoutCfm) {
  const double theta = 0.35, mu = 0.5, mass = 2;
  Problem p;
  Vector x;
  const Eigen::Vector3d s = fourCornersTotals(theta, mu, mass, p, x);
  EXPECT_NEAR(s[0], mass * kGravity * kStep * std::cos(theta), 1e-10);
  EXPECT_NEAR(s[1], -mass * kGravity * kStep * std::sin(theta), 1e-10);
  EXPECT_NEAR(s[2], 0, 1e-10);
  EXPECT_LE((p.slack(x)).lpNorm<Eigen::Infinity>(), 1e-10);  // at rest
}

TEST(LemkeFrictionLcp, FourCornersSlideWithoutCfm) {
  const double theta = 0.7, mu = 0.5, mass = 2;
  Problem p;
  Vector x;
  const Eigen::Vector3d s = fourCornersTotals(theta, mu, mass, p, x);
  const double normal = mass * kGravity * kStep * std::cos(theta);
  EXPECT_NEAR(s[0], normal, 1e-10);
  EXPECT_NEAR(s[1], -mu * normal, 1e-10);
  EXPECT_NEAR(s[2], 0, 1e-10);
}

TEST(LemkeFrictionLcp, ZeroMuRowsAnswerZero) {
  const Problem p = incline(0.35, 0.0, fourCorners());
  Vector x;
  const Result r = solveLemke(p, x, true);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  for (int i = 0; i < p.size(); ++i) {
    if (p.findex[i] >= 0) {
      EXPECT_EQ(x[i], 0) << i;
    }
  }
  EXPECT_NEAR(totals(x)[0], 2 * kGravity * kStep * std::cos(0.35), 1e-10);
}

// A normal that may be negative has no linear |x_n|: the fixed point solves it and says why.
TEST(LemkeFrictionLcp, FreeNormalRowKeepsTheFixedPoint) {
  DenseMatrix A(3, 3);
  A << 2, 0.2, 0.1, 0.2, 1, 0.1, 0.1, 0.1, 1;
  Problem p(A, Vector((Vector(3) << 2, -3, 0.5).finished()));
  p.lo << -kInf, -0.5, -0.5;
  p.hi << kInf, 0.5, 0.5;
  p.findex = {-1, 0, 0};
  Vector x;
  const Result r = solveLemke(p, x, true, 1e-12);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_FALSE(solvedAsOneLcp(r)) << r.message;
  EXPECT_NE(r.message.find("friction by the fixed point"), std::string::npos) << r.message;
  EXPECT_LT(x[0], 0);  // |x_0| bounds the friction rows
  EXPECT_NEAR(std::abs(x[1]), 0.5 * std::abs(x[0]), 1e-12);
}

// Random findex problems with SPD A (contacts separating, sticking and sliding): the LCP solves
// every one to 1e-9 and reaches the answers dantzig and newton find, where they converge.
TEST(LemkeFrictionLcp, RandomSpdProblemsAgreeWithDantzigAndNewton) {
  Generator g(45);
  const int trials = 60;
  int agreed = 0, compared = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const test::KnownProblem kp = g.friction(1 + g.pick(12));
    const Problem& p = kp.problem;
    Vector x;
    const Result r = solveLemke(p, x, true);
    ASSERT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    ASSERT_TRUE(solvedAsOneLcp(r)) << r.message;
    EXPECT_LE(residual(p, x), 1e-9) << "trial " << trial;
    for (const char* name : {"dantzig", "newton"}) {
      auto other = makeSolver(name);
      other->options().tolerance = 1e-9;
      Vector y;
      if (!other->solve(p, y).converged()) continue;
      ++compared;
      if ((x - y).lpNorm<Eigen::Infinity>() <= 1e-7 * (1 + y.lpNorm<Eigen::Infinity>())) ++agreed;
    }
  }
  // findex answers need not be unique; on these problems they are, but for round-off.
  EXPECT_GE(compared, trials);
  EXPECT_EQ(agreed, compared);
}

// Contact problems without CFM, A = J J' singular (150 rows on 30 freedoms), b = J v: the LCP has
// an answer for every v (u >= 0 with u'M u = 0 has J' S u = 0, so q'u = v'J' S u = 0). On the
// factored basis one of these (the fourth) ended with z0 out of the basis and residual 1e-2 (the
// ratio tests followed round-off); the dense tableau's retry solves it.
TEST(LemkeFrictionLcp, SingularContactProblemsWithConsistentRhs) {
  Generator g(35);
  const int trials = 10;
  for (int trial = 0; trial < trials; ++trial) {
    DenseMatrix J(150, 30);
    for (int i = 0; i < J.rows(); ++i)
      for (int j = 0; j < J.cols(); ++j) J(i, j) = g.uniform(-1, 1);
    Vector v(30);
    for (int j = 0; j < 30; ++j) v[j] = g.uniform(-1, 1);
    Problem p = test::frictionPyramids(J * J.transpose(), g, 0.6);
    p.b = J * v;
    LemkeSolver lemke;
    Options opt;
    opt.tolerance = 1e-9;
    lemke.setOptions(opt);
    Vector x;
    const Result r = lemke.solve(p, x);
    EXPECT_TRUE(solvedAsOneLcp(r)) << r.message;
    EXPECT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    EXPECT_LE(residual(p, x), 1e-9);
  }
}

// Boxes resting on the ground in Bullet's BasicDemo (step 150, no CFM on the normals: each
// box's four corners make A singular). The fixed point ran island 12 to its pivot limit (22
// friction passes, residual 2.7e-2) and needed the regularised retry on island 26; as one LCP
// both are solved on A itself.
TEST(LemkeFrictionLcp, BulletRestingBoxesTheFixedPointDidNotSettle) {
  for (const char* name :
       {"basic_demo-bullet-step150-island12", "basic_demo-bullet-step150-island26"}) {
    const Problem p =
        io::readProblem(std::string(MLCP_SOURCE_DIR) + "/tests/data/islands/" + name + ".json");
    ASSERT_TRUE(p.hasFindex()) << name;
    Vector x;
    const Result r = solveLemke(p, x, true);
    EXPECT_EQ(r.status, Status::Converged) << name << ": " << r.message;
    EXPECT_TRUE(solvedAsOneLcp(r)) << r.message;
    EXPECT_EQ(r.message.find("regularised"), std::string::npos) << r.message;
    EXPECT_EQ(r.message.find("fixed point"), std::string::npos) << r.message;
    EXPECT_LE(residual(p, x), 1e-9) << name;
  }
}

// Bullet's plank bridge at step 41 (ball-joint pairs on one axis: free rows, A singular; contacts
// of the crates): the LCP ended with z0 out of the basis at residual 6e-5, the fixed point after
// it on a ray, and the solve returned that answer without the retry on A + delta I that a ray
// gets (the scene's lemke run left the island unsolved). The retry now follows and solves it.
TEST(LemkeFrictionLcp, PlankBridgeInexactAnswerGetsTheRegularisedRetry) {
  const Problem p = io::readProblem(std::string(MLCP_SOURCE_DIR) +
                                    "/tests/data/islands/plank_bridge-bullet-step41-island0.json");
  ASSERT_TRUE(p.hasFindex());
  ASSERT_TRUE(hasFreeRows(p.lo, p.hi));
  Vector x;
  const Result r = solveLemke(p, x, true);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(p, x), 1e-9);
}

}  // namespace
}  // namespace mlcp
