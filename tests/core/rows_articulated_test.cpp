// Rows with articulated sides (mlcp/rows.hpp): A from assemble() equals J W built by brute force,
// dense and sparse; slack() is A x + b; RowPgs sweeps through J and W to the exact answer;
// screening keeps rows that touch only an articulated body.
#include <gtest/gtest.h>

#include <random>

#include "mlcp/island/row_screen.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp {
namespace {

// Rigid bodies and articulated bodies with a random SPD mass matrix M_k each; rows on one or two
// rigid bodies, on articulated bodies (W = M_k^-1 J^T), or both, like Bullet's multibody
// contacts with a rigid box, joint limits (one multibody) and link-link contacts.
struct Generated {
  RowSystem s;
  std::vector<DenseMatrix> inverseMass;  // per articulated body
};

Generated generate(unsigned seed, int rigid, int articulated, int rows) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Generated g;
  RowSystem& s = g.s;
  for (int k = 0; k < rigid; ++k) {
    BodyInverseMass b;
    b.invMass = 0.5 + 0.5 * (u(rng) + 1);
    const Eigen::Matrix3d r = Eigen::Matrix3d::Random();
    b.invInertia = r * r.transpose() + Eigen::Matrix3d::Identity();
    s.bodies.push_back(b);
  }
  for (int k = 0; k < articulated; ++k) {
    const int width = 6 + 1 + k % 4;
    s.articulated.push_back(width);
    const DenseMatrix r = DenseMatrix::Random(width, width);
    g.inverseMass.push_back((r * r.transpose() + DenseMatrix::Identity(width, width)).inverse());
  }
  auto addSide = [&](int row, int body) {
    const int width = s.articulated[body];
    Vector j(width);
    for (int e = 0; e < width; ++e) j[e] = u(rng);
    const Vector w = g.inverseMass[body] * j;
    s.sides.push_back({row, body, static_cast<int>(s.jacobian.size())});
    s.jacobian.insert(s.jacobian.end(), j.data(), j.data() + width);
    s.unitImpulse.insert(s.unitImpulse.end(), w.data(), w.data() + width);
  };
  std::uniform_int_distribution<int> pickRigid(-1, rigid - 1), pickArt(0, articulated - 1);
  s.rows.resize(rows);
  s.b.resize(rows);
  s.lo.resize(rows);
  s.hi.resize(rows);
  s.cfm.resize(rows);
  s.findex.assign(rows, -1);
  for (int i = 0; i < rows; ++i) {
    ConstraintRow& r = s.rows[i];
    const int kind = i % 3;  // 0: rigid-articulated, 1: articulated only, 2: two articulated
    if (kind == 0) {
      r.bodyA = pickRigid(rng);
      for (int e = 0; e < 6; ++e) r.jA[e] = u(rng);
    }
    addSide(i, pickArt(rng));
    if (kind == 2) addSide(i, pickArt(rng));  // may be the same body: two sides, one body
    s.b[i] = u(rng);
    s.lo[i] = i % 2 ? 0.0 : -kInf;
    s.hi[i] = kInf;
    s.cfm[i] = i % 4 == 0 ? 1e-3 : 0.0;
  }
  return g;
}

// A = J_rigid M^-1 J_rigid^T + J_art M_art^-1 J_art^T + diag(cfm), every matrix written out.
DenseMatrix bruteForce(const Generated& g) {
  const RowSystem& s = g.s;
  const int n = s.size(), nb = static_cast<int>(s.bodies.size());
  int width = 6 * nb;
  std::vector<int> offset;
  for (int w : s.articulated) {
    offset.push_back(width);
    width += w;
  }
  DenseMatrix J = DenseMatrix::Zero(n, width), Minv = DenseMatrix::Zero(width, width);
  for (int k = 0; k < nb; ++k) {
    Minv.block<3, 3>(6 * k, 6 * k) = Eigen::Matrix3d::Identity() * s.bodies[k].invMass;
    Minv.block<3, 3>(6 * k + 3, 6 * k + 3) = s.bodies[k].invInertia;
  }
  for (std::size_t k = 0; k < s.articulated.size(); ++k)
    Minv.block(offset[k], offset[k], s.articulated[k], s.articulated[k]) = g.inverseMass[k];
  for (int i = 0; i < n; ++i) {
    const ConstraintRow& r = s.rows[i];
    if (r.bodyA >= 0) J.block<1, 6>(i, 6 * r.bodyA) += r.jA.transpose();
    if (r.bodyB >= 0) J.block<1, 6>(i, 6 * r.bodyB) += r.jB.transpose();
  }
  for (const ArticulatedSide& a : s.sides)
    for (int e = 0; e < s.articulated[a.body]; ++e)
      J(a.row, offset[a.body] + e) += s.jacobian[a.at + e];
  DenseMatrix A = J * Minv * J.transpose();
  A.diagonal() += s.cfm;
  return A;
}

TEST(RowsArticulated, AssembleEqualsBruteForceDenseAndSparse) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Generated g = generate(seed, 3, 4, 30);
    ASSERT_EQ(g.s.validate(), "");
    const DenseMatrix expected = bruteForce(g);
    const Problem dense = g.s.assemble(false), sparse = g.s.assemble(true);
    ASSERT_TRUE(sparse.isSparse());
    const double scale = expected.cwiseAbs().maxCoeff();
    EXPECT_LE((dense.denseA() - expected).cwiseAbs().maxCoeff(), 1e-12 * scale) << seed;
    EXPECT_LE((DenseMatrix(sparse.sparseA()) - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
    // Both storages sum in one order: the same bits.
    EXPECT_EQ(DenseMatrix(sparse.sparseA()), dense.denseA()) << seed;
  }
}

TEST(RowsArticulated, SlackIsAxPlusB) {
  const Generated g = generate(7, 3, 4, 30);
  const DenseMatrix A = bruteForce(g);
  const Vector x = Vector::Random(g.s.size());
  const Vector w = g.s.slack(x);
  EXPECT_LE((w - (A * x + g.s.b)).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + A.norm()));
  EXPECT_NEAR(g.s.impulseEnergy(x), 0.5 * x.dot(A * x), 1e-10 * (1 + x.dot(A * x)));
}

TEST(RowsArticulated, ValidateNamesABadSide) {
  Generated g = generate(3, 2, 2, 9);
  g.s.sides[4].at = static_cast<int>(g.s.jacobian.size());
  EXPECT_NE(g.s.validate().find("articulated side 4"), std::string::npos) << g.s.validate();
  g = generate(3, 2, 2, 9);
  g.s.unitImpulse[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(g.s.validate().find("non-finite"), std::string::npos);
}

// pgs through J and W (no A) reaches the exact answer, the answer of dantzig on assemble()'s A.
TEST(RowsArticulated, RowPgsAgreesWithDantzigOnTheAssembledProblem) {
  Generated g = generate(11, 3, 3, 18);
  g.s.cfm.setConstant(0.05);  // regular: one answer
  RowPgs pgs;
  pgs.options().maxIterations = 20000;
  pgs.options().tolerance = 1e-10;
  Vector x;
  const Result r = pgs.solve(g.s, x);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  const Problem p = g.s.assemble(false);
  auto dantzig = makeSolver("dantzig");
  Vector y;
  const Result d = dantzig->solve(p, y);
  ASSERT_EQ(d.status, Status::Converged) << d.message;
  EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-6 * (1 + y.lpNorm<Eigen::Infinity>()));
  EXPECT_LE(accuracy(p, x).residual, 1e-9);
}

// A row with no rigid side is not "no Jacobian": screening keeps it, and a row it fixes pushes
// the kept rows on the same articulated body.
TEST(RowsArticulated, ScreeningKeepsArticulatedRowsAndPushesThroughW) {
  Generated g = generate(5, 2, 2, 12);
  EXPECT_FALSE(RowScreen().screen(g.s));
  g.s.b[1] = 2 * kBeyondReach;  // an articulated-only row fixed at its bound
  g.s.lo[1] = 0;
  g.s.hi[1] = 3;
  RowScreen screen;
  ASSERT_TRUE(screen.screen(g.s));
  const RowSystem& kept = screen.kept();
  ASSERT_EQ(kept.size(), g.s.size() - 1);
  ASSERT_EQ(kept.validate(), "");
  // kept b = b + A_{k,1} * 0 ... row 1 is fixed at lo = 0 (b > 0): nothing moves; at hi it would.
  g.s.b[1] = -2 * kBeyondReach;
  ASSERT_TRUE(screen.screen(g.s));
  const DenseMatrix A = bruteForce(g);
  for (int k = 0; k < screen.kept().size(); ++k) {
    const int i = screen.keptIndex()[k];
    EXPECT_NEAR(screen.kept().b[k], g.s.b[i] + A(i, 1) * 3, 1e-12 * (1 + A.norm())) << k;
  }
}

// Every solver RowSolver runs on an articulated island gives a verified answer.
TEST(RowsArticulated, RowSolverSolvesWithEveryMethod) {
  Generated g = generate(13, 3, 3, 24);
  g.s.cfm.setConstant(1e-3);
  for (const char* name : {"pgs", "gs", "dantzig", "lemke", "newton", "proximal", "auto"}) {
    RowSolverSettings settings;
    settings.solver = name;
    settings.options.maxIterations = 5000;
    settings.timeBudget = 0;
    RowSolver solver(settings);
    Vector x;
    const IslandSolve s = solver.solve(g.s, Vector::Zero(g.s.size()), x, 1);
    EXPECT_TRUE(s.accepted) << name << ": " << s.result.message;
    EXPECT_LE(accuracy(g.s.assemble(false), x).residual, 1e-5) << name;
  }
}

}  // namespace
}  // namespace mlcp
