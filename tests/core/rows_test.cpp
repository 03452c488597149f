// The factored row form: assembly matches J M^-1 J^T + diag(cfm) built densely by hand, and
// row PGS reaches the same answer as pgs on the assembled problem.
#include "mlcp/rows.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "common/row_source.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/pgs.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp {
namespace {

// A chain of boxes resting on each other: contacts (normal + 2 friction rows) between
// consecutive bodies and with the world, like a small stack.
RowSystem stackRows(int bodies, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  RowSystem s;
  for (int k = 0; k < bodies; ++k) {
    BodyInverseMass b;
    b.invMass = 1.0 / (1.0 + k);
    b.invInertia = Eigen::Matrix3d::Identity() * (2.0 + 0.5 * k);
    s.bodies.push_back(b);
  }
  std::vector<double> lo, hi, rhs, cfm;
  for (int k = 0; k < bodies; ++k) {
    for (int c = 0; c < 2; ++c) {  // two contact points per face (A stays definite)
      const int normal = s.size();
      for (int r = 0; r < 3; ++r) {
        ConstraintRow row;
        row.bodyA = k;
        row.bodyB = k - 1;  // -1: the ground
        for (int i = 0; i < 6; ++i) row.jA[i] = u(rng);
        row.jB = -row.jA;
        s.rows.push_back(row);
        s.findex.push_back(r == 0 ? -1 : normal);
        lo.push_back(r == 0 ? 0 : -0.6);
        hi.push_back(r == 0 ? kInf : 0.6);
        rhs.push_back(r == 0 ? -1.0 - u(rng) : 0.3 * u(rng));
        cfm.push_back(1e-3);
      }
    }
  }
  const int n = s.size();
  s.b = Eigen::Map<Vector>(rhs.data(), n);
  s.lo = Eigen::Map<Vector>(lo.data(), n);
  s.hi = Eigen::Map<Vector>(hi.data(), n);
  s.cfm = Eigen::Map<Vector>(cfm.data(), n);
  return s;
}

DenseMatrix denseByHand(const RowSystem& s) {
  const int n = s.size(), nb = static_cast<int>(s.bodies.size());
  DenseMatrix J = DenseMatrix::Zero(n, 6 * nb), Minv = DenseMatrix::Zero(6 * nb, 6 * nb);
  for (int i = 0; i < n; ++i) {
    if (s.rows[i].bodyA >= 0) J.block<1, 6>(i, 6 * s.rows[i].bodyA) += s.rows[i].jA.transpose();
    if (s.rows[i].bodyB >= 0) J.block<1, 6>(i, 6 * s.rows[i].bodyB) += s.rows[i].jB.transpose();
  }
  for (int k = 0; k < nb; ++k) {
    Minv.block<3, 3>(6 * k, 6 * k) = s.bodies[k].invMass * Eigen::Matrix3d::Identity();
    Minv.block<3, 3>(6 * k + 3, 6 * k + 3) = s.bodies[k].invInertia;
  }
  DenseMatrix A = J * Minv * J.transpose();
  A.diagonal() += s.cfm;
  return A;
}

TEST(RowSystem, AssemblyMatchesDenseProduct) {
  const RowSystem s = stackRows(4, 1);
  ASSERT_EQ(s.validate(), "");
  const DenseMatrix expected = denseByHand(s);
  const Problem sparse = s.assemble(true), dense = s.assemble(false);
  EXPECT_TRUE(sparse.isSparse());
  EXPECT_LE((sparse.toDense() - expected).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LE((dense.denseA() - expected).lpNorm<Eigen::Infinity>(), 1e-12);
  // Bodies 0 and 3 share no row: their blocks are structurally zero in the sparse A.
  EXPECT_LT(sparse.sparseA().nonZeros(), s.size() * s.size());
  const Vector x = Vector::LinSpaced(s.size(), -1, 1);
  EXPECT_LE((s.slack(x) - (expected * x + s.b)).lpNorm<Eigen::Infinity>(), 1e-12);
}

// The per-step assembly into a kept problem (RowSolver's): values written into the kept sparse
// pattern (its second assembly finds the slots, later ones use them) equal a fresh assembly bit
// for bit, and the dense assembly's bits; a changed body graph or a replaced matrix gets a new
// pattern, and dense storage is reused.
TEST(RowSystem, ReusedAssemblyEqualsAFreshOne) {
  Problem kept;
  RowSystem::AssembleScratch scratch;
  int call = 0;
  auto expectFresh = [&](const RowSystem& s, bool sparse) {
    SCOPED_TRACE("assembly " + std::to_string(++call));
    s.assemble(sparse, kept, scratch);
    const Problem fresh = s.assemble(sparse);
    ASSERT_EQ(kept.isSparse(), sparse);
    EXPECT_EQ(kept.toDense(), fresh.toDense());  // exactly equal
    EXPECT_EQ(fresh.toDense(), s.assemble(!sparse).toDense());
    EXPECT_EQ(kept.b, fresh.b);
    EXPECT_EQ(kept.findex, fresh.findex);
    EXPECT_LE((kept.toDense() - denseByHand(s)).lpNorm<Eigen::Infinity>(), 1e-12);
  };
  RowSystem s = stackRows(5, 2);
  expectFresh(s, true);
  const double* values = kept.sparseA().valuePtr();
  // New Jacobian values on the same bodies: the same storage is refilled.
  s = stackRows(5, 3);
  expectFresh(s, true);
  EXPECT_EQ(kept.sparseA().valuePtr(), values);
  s = stackRows(5, 6);
  expectFresh(s, true);
  EXPECT_EQ(kept.sparseA().valuePtr(), values);
  // A row moved to another body pair: a new pattern.
  s.rows[4].bodyB = 3;
  expectFresh(s, true);
  // Fewer rows, then the matrix replaced behind the scratch's back.
  s = stackRows(3, 4);
  expectFresh(s, true);
  kept.setA(SparseMatrix(s.size(), s.size()));
  expectFresh(s, true);
  // Dense and back.
  expectFresh(s, false);
  const double* dense = kept.denseA().data();
  s = stackRows(3, 5);
  expectFresh(s, false);
  EXPECT_EQ(kept.denseA().data(), dense);
  expectFresh(s, true);
}

TEST(RowPgs, AgreesWithPgsOnTheAssembledProblem) {
  const RowSystem s = stackRows(3, 2);
  RowPgs rowPgs;
  rowPgs.options().tolerance = 1e-10;
  rowPgs.options().maxIterations = 20000;
  Vector xr;
  const Result rr = rowPgs.solve(s, xr);
  ASSERT_EQ(rr.status, Status::Converged) << rr.message;
  const Problem p = s.assemble(true);
  EXPECT_LE(residual(p, xr), 1e-10);  // checked on the assembled problem, independently

  PgsSolver pgs;
  pgs.options() = rowPgs.options();
  Vector xp;
  const Result rp = pgs.solve(p, xp);
  ASSERT_EQ(rp.status, Status::Converged) << rp.message;
  // Same sweep order and update: the iterates agree up to rounding.
  EXPECT_EQ(rr.iterations, rp.iterations);
  EXPECT_LE((xr - xp).lpNorm<Eigen::Infinity>(), 1e-8);
}

// Rows the sweep treats apart: a row joining a body to itself (its diagonal has the cross terms
// of jA and jB), a row on the world alone (A_ii = cfm), runs of rows on the same bodies broken
// by them, and many ground rows sharing the world slots.
TEST(RowPgs, AgreesWithPgsOnSelfJoinedAndWorldOnlyRows) {
  RowSystem s = stackRows(4, 11);
  s.rows[4].bodyB = s.rows[4].bodyA;  // inside a contact's run: splits it
  s.rows[9].bodyB = s.rows[9].bodyA;  // a friction row of body 1 on itself
  s.rows[13].bodyA = -1;              // body 2's contact row on nothing but the world
  s.rows[13].bodyB = -1;
  const Problem p = s.assemble(true);
  EXPECT_LE((s.assemble(false).denseA() - denseByHand(s)).lpNorm<Eigen::Infinity>(), 1e-12);
  for (int sweeps : {3, 40}) {
    RowPgs rowPgs;
    rowPgs.options().maxIterations = sweeps;
    rowPgs.options().tolerance = 1e-300;  // runs every sweep
    Vector xr;
    const Result rr = rowPgs.solve(s, xr);
    PgsSolver pgs;
    pgs.options() = rowPgs.options();
    Vector xp;
    pgs.solve(p, xp);
    EXPECT_LE((xr - xp).lpNorm<Eigen::Infinity>(), 1e-10 * (1 + xp.lpNorm<Eigen::Infinity>()))
        << sweeps;
    const Accuracy a = accuracy(p, xr);
    EXPECT_NEAR(rr.residual, a.residual, 1e-12 * (1 + a.residual)) << sweeps;
  }
}

TEST(RowPgs, WarmStartFromTheAnswerStopsAtOnce) {
  const RowSystem s = stackRows(2, 3);
  RowPgs pgs;
  pgs.options().maxIterations = 20000;
  Vector x;
  ASSERT_TRUE(pgs.solve(s, x).converged());
  pgs.options().warmStart = true;
  const Result again = pgs.solve(s, x);
  EXPECT_TRUE(again.converged());
  EXPECT_LE(again.iterations, 1);
}

// RowPgs checks its residual from the body velocities its sweeps maintain; that must be the
// residual of its x on the assembled problem, at every sweep count (warm and cold).
TEST(RowPgs, ReportedResidualIsTheAssembledProblemsResidual) {
  const RowSystem s = stackRows(4, 7);
  const Problem p = s.assemble(true);
  RowPgs pgs;
  for (int sweeps : {1, 3, 10, 200}) {
    pgs.options().maxIterations = sweeps;
    for (bool warm : {false, true}) {
      pgs.options().warmStart = warm;
      Vector x = Vector::Constant(s.size(), 0.25);
      const Result r = pgs.solve(s, x);
      const Accuracy a = accuracy(p, x);
      EXPECT_NEAR(r.residual, a.residual, 1e-12 * (1 + a.residual)) << sweeps << " " << warm;
      EXPECT_NEAR(r.complementarity, a.complementarity, 1e-12 * (1 + a.complementarity));
      EXPECT_EQ(r.iterations, sweeps);
    }
  }
}

TEST(RowPgs, RejectsBadRows) {
  RowSystem s = stackRows(2, 4);
  s.rows[3].bodyA = 7;
  Vector x = Vector::Constant(s.size(), 5.0);
  const Vector before = x;
  Result r = RowPgs().solve(s, x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.message.find("row 3"), std::string::npos) << r.message;
  EXPECT_EQ(x, before);
  s = stackRows(2, 4);
  s.lo[5] = -0.3;  // friction row with bounds that are not -mu..mu
  r = RowPgs().solve(s, x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.message.find("friction row 5"), std::string::npos) << r.message;
  s = stackRows(2, 4);
  s.cfm[0] = -1;
  EXPECT_EQ(RowPgs().solve(s, x).status, Status::InvalidInput);
  // Opposite infinities cancel in no sum: the one-pass check must still see them.
  s = stackRows(2, 4);
  s.rows[2].jA[1] = kInf;
  s.rows[2].jB[1] = -kInf;
  r = RowPgs().solve(s, x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.message.find("row 2 has a non-finite Jacobian"), std::string::npos) << r.message;
  s = stackRows(2, 4);
  s.b[4] = std::nan("");
  EXPECT_EQ(s.validate().find("b[4]"), 0u) << s.validate();
  // Large finite entries whose sum overflows are valid (the slow path confirms it).
  s = stackRows(2, 4);
  s.rows[1].jA[0] = s.rows[1].jA[1] = 1e308;
  EXPECT_EQ(s.validate(), "");
}

// The engine entry point (RowPgs::solve with a row source) must pack what solve(RowSystem) packs
// from the same values: the same iterates bit for bit, the same result, and the velocity change
// M^-1 J^T (x - base) per body.
using test::solveFromRows;

// Rows in reverse order: every friction row's findex points forward (checked after the pass).
RowSystem reversed(const RowSystem& s) {
  RowSystem r = s;
  const int n = s.size();
  for (int i = 0; i < n; ++i) {
    const int j = n - 1 - i;
    r.rows[i] = s.rows[j];
    r.b[i] = s.b[j];
    r.lo[i] = s.lo[j];
    r.hi[i] = s.hi[j];
    r.cfm[i] = s.cfm[j];
    r.findex[i] = s.findex[j] < 0 ? -1 : n - 1 - s.findex[j];
  }
  return r;
}

TEST(RowPgs, PackingFromAnEnginesRowsEqualsPackingFromTheRowSystem) {
  for (const RowSystem& s : {stackRows(30, 9), reversed(stackRows(12, 10))}) {
    const int n = s.size();
    ASSERT_GT(n, 64);  // several batches
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 0.5);
    Vector start(n), base(n);
    for (int i = 0; i < n; ++i) {
      start[i] = s.findex[i] < 0 ? u(rng) : 0.1 * u(rng);
      base[i] = i % 3 ? start[i] : 0.5 * start[i];
    }
    for (bool warm : {false, true}) {
      RowPgs a, b;
      for (RowPgs* p : {&a, &b}) {
        p->options().maxIterations = 7;
        p->options().warmStart = warm;
      }
      Vector xa = start, xb;
      const Result ra = a.solve(s, xa);
      const Result rb = solveFromRows(b, s, start, base, xb);
      EXPECT_FALSE(a.velocityChanges());
      ASSERT_TRUE(b.velocityChanges());
      EXPECT_EQ(ra.status, rb.status);
      EXPECT_EQ(ra.iterations, rb.iterations);
      EXPECT_EQ(ra.residual, rb.residual);
      ASSERT_EQ(xa.size(), xb.size());
      for (int i = 0; i < n; ++i) EXPECT_EQ(xa[i], xb[i]) << "row " << i << " warm " << warm;
      // The reported residual is that of x on the assembled problem.
      EXPECT_NEAR(rb.residual, accuracy(s.assemble(true), xb).residual, 1e-12 * (1 + rb.residual));
      // Cold or warm, x - base is what the engine's bodies lack.
      const std::vector<Vector6> dv = s.bodyVelocities(xb - base);
      for (int k = 0; k < static_cast<int>(s.bodies.size()); ++k)
        EXPECT_LE((b.velocityChange(k) - dv[k]).lpNorm<Eigen::Infinity>(),
                  1e-12 * (1 + dv[k].lpNorm<Eigen::Infinity>()))
            << "body " << k;
    }
  }
}

// Bad rows, a zero diagonal and a non-finite start through the engine entry point: the slow
// path gives what solve(RowSystem) gives, and velocityChange is not offered.
TEST(RowPgs, EngineRowsWithFaultsGetTheRowSystemsAnswer) {
  auto both = [](const RowSystem& s, Vector start = Vector()) {
    if (start.size() == 0) start = Vector::Constant(s.size(), 0.2);
    RowPgs a, b;
    a.options().warmStart = b.options().warmStart = true;
    Vector xa = start, xb;
    const Result ra = a.solve(s, xa);
    const Result rb = solveFromRows(b, s, start, start, xb);
    EXPECT_FALSE(b.velocityChanges());
    EXPECT_EQ(ra.status, rb.status);
    EXPECT_EQ(ra.message, rb.message);
    if (ra.status != Status::InvalidInput) {
      EXPECT_EQ(ra.residual, rb.residual) << toString(ra.status);
      EXPECT_EQ(xa, xb);
    }
    return rb;
  };
  RowSystem s = stackRows(30, 4);
  s.rows[100].bodyA = 99;
  EXPECT_EQ(both(s).status, Status::InvalidInput);
  s = reversed(stackRows(3, 4));
  s.findex[0] = 1;  // forward, onto a friction row
  EXPECT_EQ(both(s).status, Status::InvalidInput);
  s = stackRows(30, 4);
  s.findex[101] = 100;  // backward, onto a friction row
  EXPECT_EQ(both(s).status, Status::InvalidInput);
  s = stackRows(30, 4);
  s.rows[70].jA.setZero();
  s.rows[70].jB.setZero();
  s.cfm[70] = 0;
  EXPECT_EQ(both(s).status, Status::Failed);
  s = stackRows(3, 4);
  s.rows[2].jA[0] = std::nan("");
  EXPECT_EQ(both(s).status, Status::InvalidInput);
  // A non-finite start: both start cold.
  s = stackRows(30, 4);
  Vector start = Vector::Constant(s.size(), 0.2);
  start[5] = std::nan("");
  const Result r = both(s, start);
  RowPgs cold;
  Vector xc;
  EXPECT_EQ(cold.solve(s, xc).residual, r.residual);
}

// The packing checks a body side's Jacobian through A_ii (row_pack.hpp): NaN, +inf and -inf in
// every entry of both sides, on a ground row and a row between two bodies, with body 0 moving
// and static (M^-1 = 0, where a product with the entry is NaN), are refused by both paths.
TEST(RowPgs, EveryNonFiniteJacobianEntryIsRefused) {
  const double bad[] = {std::nan(""), kInf, -kInf};
  for (const bool fixed : {false, true})
    for (const int row : {0, 6})
      for (int side = 0; side < 2; ++side)
        for (int k = 0; k < 6; ++k)
          for (const double value : bad) {
            RowSystem s = stackRows(3, 4);
            if (fixed) s.bodies[0] = BodyInverseMass();
            (side ? s.rows[row].jB : s.rows[row].jA)[k] = value;
            const Vector start = Vector::Constant(s.size(), 0.2);
            RowPgs a, b;
            Vector xa = start, xb;
            const Result ra = a.solve(s, xa);
            const Result rb = solveFromRows(b, s, start, start, xb);
            const std::string what = "row " + std::to_string(row) + " has a non-finite Jacobian";
            EXPECT_EQ(ra.status, Status::InvalidInput) << row << " " << side << " " << k;
            EXPECT_NE(ra.message.find(what), std::string::npos) << ra.message;
            EXPECT_EQ(rb.status, Status::InvalidInput) << row << " " << side << " " << k;
            EXPECT_EQ(rb.message, ra.message);
            EXPECT_EQ(xa, start);  // the caller's x is untouched
          }
}

// A non-finite base (what the engine's bodies carry already): the same answer, but no per-body
// velocity changes on offer (they would all be NaN).
TEST(RowPgs, NonFiniteBaseOffersNoVelocityChanges) {
  const RowSystem s = stackRows(30, 4);
  const Vector start = Vector::Constant(s.size(), 0.2);
  Vector base = start;
  base[7] = std::numeric_limits<double>::infinity();
  RowPgs a, b;
  a.options().warmStart = b.options().warmStart = true;
  Vector xa, xb;
  const Result ra = solveFromRows(a, s, start, start, xa);
  const Result rb = solveFromRows(b, s, start, base, xb);
  EXPECT_TRUE(a.velocityChanges());
  EXPECT_FALSE(b.velocityChanges());
  EXPECT_EQ(ra.status, rb.status);
  EXPECT_EQ(ra.residual, rb.residual);
  EXPECT_EQ(xa, xb);
}

TEST(RowPgs, ZeroRowIsAFailureNotAConvergence) {
  RowSystem s = stackRows(1, 5);
  s.rows[0].jA.setZero();
  s.rows[0].jB.setZero();
  s.cfm[0] = 0;
  Vector x;
  const Result r = RowPgs().solve(s, x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(r.message.find("positive diagonal"), std::string::npos);
}

// Finite entries whose products overflow: the message says so instead of printing "A_ii = inf"
// as if the row were merely non-positive.
TEST(RowPgs, OverflowingDiagonalIsNamed) {
  RowSystem s = stackRows(1, 5);
  s.rows[2].jA.setConstant(1e200);
  ASSERT_EQ(s.validate(), "");
  for (bool engine : {false, true}) {
    RowPgs pgs;
    Vector x;
    const Vector zero = Vector::Zero(s.size());
    const Result r = engine ? solveFromRows(pgs, s, zero, zero, x) : pgs.solve(s, x);
    EXPECT_EQ(r.status, Status::Failed) << engine;
    EXPECT_NE(r.message.find("row 2: A_ii = J M^-1 J^T + cfm overflows"), std::string::npos)
        << r.message;
  }
}

}  // namespace
}  // namespace mlcp
