// RowScreen: each reason a row is screened for, the compaction (findex renumbered, inert rows
// answered 0), and RowSolver solving the rest of an island around a degenerate row.
#include "mlcp/island/row_screen.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Appends a row along `lin` on body 0 (arm (0, 0.5, 0)) with the given rhs and bounds.
void addRow(RowSystem& s, const Eigen::Vector3d& lin, double b, double lo, double hi, int findex) {
  ConstraintRow r;
  r.bodyA = 0;
  r.jA << lin, Eigen::Vector3d(0, 0.5, 0).cross(lin);
  s.rows.push_back(r);
  const int n = s.size();
  for (Vector* v : {&s.b, &s.lo, &s.hi, &s.cfm}) v->conservativeResize(n);
  s.b[n - 1] = b;
  s.lo[n - 1] = lo;
  s.hi[n - 1] = hi;
  s.cfm[n - 1] = 0;
  s.findex.push_back(findex);
}

// One unit body (mass 1, inertia 1) held to the world: a ball joint's three rows 0-2, a contact
// row 3 along y with its friction row 4 along x, and nothing else.
RowSystem island() {
  RowSystem s;
  BodyInverseMass body;
  body.invMass = 1;
  body.invInertia = Eigen::Matrix3d::Identity();
  s.bodies = {body};
  for (int k = 0; k < 3; ++k) addRow(s, Eigen::Vector3d::Unit(k), 0.1 * (k + 1), -kInf, kInf, -1);
  addRow(s, Eigen::Vector3d::UnitY(), -1, 0, kInf, -1);
  addRow(s, Eigen::Vector3d::UnitX(), 0.2, -0.5, 0.5, 3);
  return s;
}

TEST(RowScreen, CleanRowsPassUntouched) {
  RowScreen screen;
  EXPECT_FALSE(screen.screen(island()));
  EXPECT_EQ(screen.counts().total(), 0);
  EXPECT_EQ(screen.counts().toString(), "");
}

TEST(RowScreen, NonFiniteRhsIsInert) {
  RowSystem s = island();
  s.b[1] = -kInf;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().nonFiniteRhs, 1);
  EXPECT_EQ(screen.counts().inert(), 1);
  EXPECT_EQ(screen.kept().size(), 4);
  EXPECT_EQ(screen.keptIndex(), (std::vector<int>{0, 2, 3, 4}));
  EXPECT_EQ(screen.kept().findex[3], 2);  // the friction row follows its contact's new place
  EXPECT_EQ(screen.kept().validate(), "");
}

TEST(RowScreen, NonFiniteJacobianOrCfmIsInert) {
  RowSystem s = island();
  s.rows[0].jA[4] = kNaN;
  s.cfm[2] = kInf;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().nonFiniteRow, 2);
  EXPECT_EQ(screen.kept().validate(), "");
}

TEST(RowScreen, ZeroJacobianIsInert) {
  RowSystem s = island();
  s.rows[1].jA.setZero();
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().noJacobian, 1);
  // A row on the world only (both body indices -1) moves nothing either.
  s = island();
  s.rows[2].bodyA = -1;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().noJacobian, 1);
}

TEST(RowScreen, ZeroDiagonalWithoutCfmIsInertWithCfmKept) {
  // A body that cannot turn (Bullet's angular factor 0): a purely angular row has A_ii = 0.
  RowSystem s = island();
  s.bodies[0].invInertia.setZero();
  s.rows[0].jA << 0, 0, 0, 1, 0, 0;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().zeroDiagonal, 1);
  EXPECT_EQ(screen.counts().inert(), 1);
  // The same row with cfm has A_ii = cfm > 0: a regular row.
  s.cfm[0] = 1e-5;
  EXPECT_FALSE(screen.screen(s));
  // Round-off above zero is still zero: the test is relative to the row's scale.
  s.cfm[0] = 0;
  s.bodies[0].invInertia = Eigen::Matrix3d::Identity() * 1e-20;
  s.bodies[0].invInertia(1, 1) = 1;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().zeroDiagonal, 1);
}

TEST(RowScreen, EmptyBoundsAreInert) {
  RowSystem s = island();
  s.lo[0] = kInf;
  s.lo[1] = 2;
  s.hi[1] = 1;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().emptyBounds, 2);
}

TEST(RowScreen, NaNBoundsClampToInfinityAndStay) {
  RowSystem s = island();
  s.lo[0] = kNaN;
  s.hi[1] = kNaN;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().clampedBound, 2);
  EXPECT_EQ(screen.counts().inert(), 0);
  ASSERT_EQ(screen.kept().size(), 5);
  EXPECT_EQ(screen.kept().lo[0], -kInf);
  EXPECT_EQ(screen.kept().hi[1], kInf);
  EXPECT_EQ(screen.kept().validate(), "");
}

TEST(RowScreen, FrictionOfAnInertNormalIsInert) {
  RowSystem s = island();
  s.b[3] = kNaN;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().nonFiniteRhs, 1);
  EXPECT_EQ(screen.counts().inertNormal, 1);
  EXPECT_EQ(screen.kept().size(), 3);
  EXPECT_EQ(screen.counts().toString(), "non-finite-rhs:1 inert-normal:1");
}

// The kept rows see what the full rows see: w of the full system at scatter(x) equals the kept
// system's w at x, row for row (the fixed rows' impulses moved into the kept rows' b).
void expectKeptRowsSeeTheFullSystem(const RowSystem& s, const RowScreen& screen) {
  const RowSystem& k = screen.kept();
  Vector kept = Vector::LinSpaced(k.size(), 0.1, 0.7), full;
  screen.scatter(kept, full);
  const Vector wFull = s.slack(full), wKept = k.slack(kept);
  for (int j = 0; j < k.size(); ++j)
    EXPECT_NEAR(wKept[j], wFull[screen.keptIndex()[j]], 1e-12) << "kept row " << j;
}

// A rhs beyond reach (Bullet's 6-dof limit at 1e30: rhs = fps erp (x - 1e30)) puts the row on
// the bound its sign names, as Bullet's sequential impulse does: b > 0 -> lo, b < 0 -> hi.
TEST(RowScreen, RhsBeyondReachIsFixedAtTheBoundItsSignNames) {
  RowSystem s = island();
  addRow(s, Eigen::Vector3d::UnitZ(), -1.2e31, -kInf, 0, -1);  // upper limit: x = hi = 0
  addRow(s, Eigen::Vector3d::UnitZ(), 1.2e31, 0, kInf, -1);    // lower limit: x = lo = 0
  addRow(s, Eigen::Vector3d::UnitX(), -kInf, -0.7, 0.7, -1);   // a motor at full force: 0.7
  addRow(s, Eigen::Vector3d::UnitZ(), 2e10, -kInf, kInf, -1);  // no finite answer: inert
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().rhsBeyondReach, 3);
  EXPECT_EQ(screen.counts().nonFiniteRhs, 1);
  EXPECT_EQ(screen.keptIndex(), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(screen.kept().validate(), "");
  EXPECT_LT(screen.kept().b.lpNorm<Eigen::Infinity>(), 2);  // the scale of the residual
  Vector full;
  screen.scatter(Vector::Zero(5), full);
  EXPECT_EQ(full, (Vector(9) << 0, 0, 0, 0, 0, 0, 0, 0.7, 0).finished());
  expectKeptRowsSeeTheFullSystem(s, screen);
}

// A contact pushed beyond reach onto a non-zero bound keeps its friction rows, with the fixed
// bounds mu |x_normal|; one fixed at 0 makes them inert (inert-normal).
TEST(RowScreen, FrictionOfANormalFixedBeyondReachGetsFixedBounds) {
  RowSystem s = island();
  s.b[3] = -1e12;
  s.hi[3] = 2;  // the normal row is fixed at 2
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().rhsBeyondReach, 1);
  ASSERT_EQ(screen.kept().size(), 4);
  EXPECT_EQ(screen.kept().findex[3], -1);
  EXPECT_EQ(screen.kept().lo[3], -1.0);  // -0.5 * 2
  EXPECT_EQ(screen.kept().hi[3], 1.0);
  expectKeptRowsSeeTheFullSystem(s, screen);
  s.b[3] = 1e12;  // pushed to lo = 0
  ASSERT_TRUE(screen.screen(s));
  EXPECT_EQ(screen.counts().inertNormal, 1);
  EXPECT_EQ(screen.kept().size(), 3);
}

// Two unit bodies hanging from the world on ball joints, the second from the first (6 rows), each
// held from turning about x and y (4 rows): a chain like scenes/six_dof_spring.json's, solved
// by the general paths (more rows than dantzig's tiny-island path takes).
RowSystem hangingPair() {
  RowSystem s;
  BodyInverseMass body;
  body.invMass = 1;
  body.invInertia = Eigen::Matrix3d::Identity();
  s.bodies = {body, body};
  auto add = [&](int a, int b, const Vector6& jA, const Vector6& jB, double rhs) {
    ConstraintRow r;
    r.bodyA = a;
    r.bodyB = b;
    r.jA = jA;
    r.jB = jB;
    s.rows.push_back(r);
    const int n = s.size();
    for (Vector* v : {&s.b, &s.lo, &s.hi, &s.cfm}) v->conservativeResize(n);
    s.b[n - 1] = rhs;
    s.lo[n - 1] = -kInf;
    s.hi[n - 1] = kInf;
    s.cfm[n - 1] = 1e-6;
    s.findex.push_back(-1);
  };
  const Eigen::Vector3d up(0, 0, 0.5), down(0, 0, -0.5);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
    Vector6 j0, j1;
    j0 << e, up.cross(e);
    add(0, -1, j0, Vector6::Zero(), k == 2 ? -0.16 : 0.05);  // gravity's pull on the pair
    j0 << e, down.cross(e);
    j1 << -e, -up.cross(e);
    add(0, 1, j0, j1, k == 2 ? -0.08 : -0.03);
  }
  for (int body = 0; body < 2; ++body)
    for (int k = 0; k < 2; ++k) {
      Vector6 j;
      j << Eigen::Vector3d::Zero(), Eigen::Vector3d::Unit(k);
      add(body, -1, j, Vector6::Zero(), 0.1 * (k + 1));
    }
  return s;
}

// Regression: scenes/six_dof_spring.json's +-1e30 limit gave two rows b = +-1.2e31; the
// residual's scale 1 + ||b||_inf became 1.2e31, and dantzig reported converged (residual 1e-33)
// on an answer that held nothing: the boxes fell. Now the limit rows are fixed at 0 and the rest
// of the island is solved to its own scale, checked here on the rows without the limits.
TEST(RowScreen, LimitAtInfinityDoesNotLetASolverClaimConvergence) {
  for (const char* name : {"dantzig", "auto", "lemke", "pgs"}) {
    SCOPED_TRACE(name);
    const RowSystem real = hangingPair();
    RowSystem s = real;
    const int n = real.size();
    for (double b : {-1.2e31, 1.2e31}) {  // the upper and the lower limit of the first body's x
      s.rows.push_back(real.rows[0]);
      for (Vector* v : {&s.b, &s.lo, &s.hi, &s.cfm}) v->conservativeResize(s.size());
      s.b[s.size() - 1] = b;
      s.lo[s.size() - 1] = b < 0 ? -kInf : 0;
      s.hi[s.size() - 1] = b < 0 ? 0 : kInf;
      s.cfm[s.size() - 1] = 1e-5;
      s.findex.push_back(-1);
    }
    RowSolverSettings settings;
    settings.solver = name;
    RowSolver solver(settings);
    Vector x;
    const IslandSolve out = solver.solve(s, Vector::Constant(n + 2, 0.01), x, 1);
    EXPECT_TRUE(out.accepted) << out.result.message;
    ASSERT_EQ(x.size(), n + 2);
    EXPECT_EQ(x[n], 0);
    EXPECT_EQ(x[n + 1], 0);
    const Vector xr = x.head(n);
    const Accuracy a = accuracy(xr, real.slack(xr), real.lo, real.hi, real.findex,
                                real.b.lpNorm<Eigen::Infinity>());
    EXPECT_LT(a.residual, 1e-6);
    EXPECT_EQ(out.screened.rhsBeyondReach, 2);
  }
}

TEST(RowScreen, GatherAndScatter) {
  RowSystem s = island();
  s.b[1] = kInf;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(s));
  Vector full(5), kept;
  full << 1, 2, 3, 4, 5;
  screen.gather(full, kept);
  EXPECT_EQ(kept, (Vector(4) << 1, 3, 4, 5).finished());
  screen.scatter(kept, full);
  EXPECT_EQ(full, (Vector(5) << 1, 0, 3, 4, 5).finished());
}

// One degenerate row no longer costs the island its answer: the other rows are solved exactly
// (their residual recomputed on the rows kept), the inert row answers 0, and the counts and
// the message say what was screened. Every solver name gets the same rows.
TEST(RowScreen, RowSolverSolvesTheRestOfTheIsland) {
  for (const char* name : {"auto", "dantzig", "pgs"}) {
    RowSystem s = island();
    s.b[1] = -kInf;
    s.bodies[0].invInertia(0, 0) = 0;  // no turning about x: row 0's J is (1,0,0 | 0,0,0)
    s.rows.push_back(s.rows[0]);       // ... and an angular-only row about x: A_ii = 0
    s.rows.back().jA << 0, 0, 0, 1, 0, 0;
    for (Vector* v : {&s.b, &s.lo, &s.hi, &s.cfm}) v->conservativeResize(6);
    s.b[5] = 0.3;
    s.lo[5] = -kInf;
    s.hi[5] = kInf;
    s.cfm[5] = 0;
    s.findex.push_back(-1);
    RowSolverSettings settings;
    settings.solver = name;
    RowSolver solver(settings);
    Vector x;
    const IslandSolve out = solver.solve(s, Vector::Zero(6), x, 1);
    SCOPED_TRACE(name);
    EXPECT_TRUE(out.accepted) << out.result.message;
    EXPECT_EQ(out.screened.nonFiniteRhs, 1);
    EXPECT_EQ(out.screened.zeroDiagonal, 1);
    ASSERT_EQ(x.size(), 6);
    EXPECT_EQ(x[1], 0);
    EXPECT_EQ(x[5], 0);
    RowScreen screen;
    ASSERT_TRUE(screen.screen(s));
    Vector kept;
    screen.gather(x, kept);
    const RowSystem& k = screen.kept();
    const Accuracy a =
        accuracy(kept, k.slack(kept), k.lo, k.hi, k.findex, k.b.lpNorm<Eigen::Infinity>());
    EXPECT_LT(a.residual, 1e-6);
    EXPECT_NE(out.result.message.find("2 of 6 rows inert"), std::string::npos)
        << out.result.message;
  }
}

}  // namespace
}  // namespace mlcp
