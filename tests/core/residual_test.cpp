// The natural-map residual on hand-checked cases.
#include "mlcp/residual.hpp"

#include <gtest/gtest.h>

#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"

namespace mlcp {
namespace {

TEST(Residual, ZeroAtTheSeedSolution) {
  const Problem p = test::seedLemkeExample();
  const Vector x = (Vector(3) << 20.0 / 19, 21.0 / 19, 0).finished();
  const Accuracy a = accuracy(p, x);
  EXPECT_LT(a.residual, 1e-14);  // 20/19 etc. are not exact in binary
  EXPECT_LT(a.complementarity, 1e-14);
  EXPECT_EQ(a.boundViolation, 0);
  EXPECT_TRUE(a.finite);
}

TEST(Residual, HandComputedStandardLcp) {
  // w = x - 1 with x = 0: x - clamp(x - w, 0, inf) = 0 - clamp(1, 0, inf) = -1; scaled by 1 + 1.
  Problem p(DenseMatrix::Identity(1, 1), Vector::Constant(1, -1));
  EXPECT_DOUBLE_EQ(residual(p, Vector::Zero(1)), 0.5);
  EXPECT_DOUBLE_EQ(residual(p, Vector::Ones(1)), 0.0);
  // x = -2 is outside the bounds: w = -3, r = -2 - clamp(1, 0, inf) = -3, scaled 3 / 2.
  const Accuracy a = accuracy(p, Vector::Constant(1, -2));
  EXPECT_DOUBLE_EQ(a.boundViolation, 2);
  EXPECT_DOUBLE_EQ(a.residual, 1.5);
}

TEST(Residual, FindexBoundsMoveWithTheNormal) {
  // Row 0 normal, row 1 friction with mu = 0.5. x = (2, 1): bound is 1, friction at its
  // upper bound, so w_1 must be <= 0.
  Problem p(DenseMatrix::Identity(2, 2), Vector::Zero(2));
  p.lo << 0, -0.5;
  p.hi << kInf, 0.5;
  p.findex = {-1, 0};
  p.b << -2, -3;  // w = x + b = (0, -2) at x = (2, 1)
  EXPECT_DOUBLE_EQ(residual(p, (Vector(2) << 2, 1).finished()), 0.0);
  // With the normal halved the friction value 1 exceeds mu * 1 = 0.5.
  const Accuracy a = accuracy(p, (Vector(2) << 1, 1).finished());
  EXPECT_DOUBLE_EQ(a.boundViolation, 0.5);
  EXPECT_GT(a.residual, 0);
}

TEST(Residual, NonFiniteIsReported) {
  Problem p(DenseMatrix::Identity(2, 2), Vector::Ones(2));
  const Accuracy a = accuracy(p, (Vector(2) << 0, std::nan("")).finished());
  EXPECT_FALSE(a.finite);
  EXPECT_EQ(a.residual, kInf);
}

// An empty x (a solver that returned no answer) read past its end.
TEST(Residual, WrongSizedXIsAnErrorNotARead) {
  Problem p(DenseMatrix::Identity(3, 3), Vector::Ones(3));
  EXPECT_THROW(accuracy(p, Vector()), std::invalid_argument);
  EXPECT_THROW(residual(p, Vector::Zero(2)), std::invalid_argument);
  EXPECT_THROW(accuracy(p, Vector::Zero(3), Vector::Zero(4)), std::invalid_argument);
  try {
    residual(p, Vector());
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "accuracy: x has 0 entries, the problem 3 rows");
  }
}

TEST(Residual, EqualityRowsMeasureW) {
  Problem p(DenseMatrix::Identity(2, 2), Vector::Zero(2));
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  p.b << 3, 0;
  // x - clamp(x - w, -inf, inf) = w = x + b.
  EXPECT_DOUBLE_EQ(residual(p, Vector::Zero(2)), 3.0 / 4);
}

// tests/data/fuzz/solver_scaled_1e12_cancellation.json: row 0 is 1e12 x0 + x1 - 1e12 x2 + b0
// with b0 = -(fl(1e12 + 0.1) - 1e12). At x = (1, 0.1, 1) the plain sum gives w0 = 0 exactly; the
// exact w0 is 2.44e-5 (0.1's low bits vanish in 1e12 + 0.1), so the scaled residual is 1.2e-5,
// not 0, and no double x0 brings it under 1e-6 (x0's ulp moves w0 by 2.2e-4).
Problem scaledCancellation() {
  return io::readProblem(std::string(MLCP_SOURCE_DIR) +
                         "/tests/data/fuzz/solver_scaled_1e12_cancellation.json");
}

TEST(ResidualFuzzRegression, Scaled1e12CancellationIsMeasuredExactly) {
  const Problem p = scaledCancellation();
  const Vector x = (Vector(3) << 1, 0.1, 1).finished();
  // w0 summed left to right, as a plain product does for 3 terms: the rounding guarded against.
  Vector plainW = p.b;
  plainW[0] = ((1e12 * x[0] + 1 * x[1]) + -1e12 * x[2]) + p.b[0];
  plainW[1] = x[1] + p.b[1];
  plainW[2] = x[2] + p.b[2];
  EXPECT_EQ(accuracy(p, x, plainW).residual, 0);
  const double exact = 2.441406250000555e-05 / 2;
  // Within the natural map's own rounding, u (|x| + |w|) / (1 + |b|).
  EXPECT_NEAR(checkedAccuracy(p, x, plainW, 1e-6).residual, exact, 1.2e-16);
  EXPECT_NEAR(compensatedSlack(p, x)[0], 2.441406250000555e-05, 1e-20);
  // Far from the tolerance the plain residual stands (no compensated pass needed).
  EXPECT_EQ(checkedAccuracy(p, x, plainW, 1.0).residual, 0);
}

TEST(ResidualFuzzRegression, Scaled1e12CancellationIsNeverCalledConverged) {
  const Problem p = scaledCancellation();
  for (const char* name : {"ldlt", "gs", "dantzig", "lemke", "pgs", "auto"}) {
    auto solver = makeSolver(name);
    solver->options().tolerance = 1e-6;
    Vector x;
    const Result r = solver->solve(p, x);
    if (r.status == Status::InvalidInput || r.status == Status::Unsupported) continue;
    ASSERT_EQ(x.size(), 3) << name;
    const double exact = std::abs(compensatedSlack(p, x)[0]) / 2;  // rows 1, 2 are exact
    if (r.converged()) {
      EXPECT_LE(exact, 1e-6) << name << ": residual " << r.residual;
    }
    if (std::string(name) == "ldlt") {  // solves the system: x = (1, 0.1, 1), within an ulp
      EXPECT_FALSE(r.converged()) << r.message;
      EXPECT_NEAR(r.residual, exact, 1e-15);
    }
  }
}

TEST(ResidualFuzzRegression, CompensatedSlackMatchesExactSumsDenseAndSparse) {
  test::Generator g(11);
  test::KnownProblem kp = g.friction(6);
  for (bool sparse : {false, true}) {
    Problem p = kp.problem;
    p.b *= 1e12;
    if (sparse) p.setA(p.toSparse());
    const Vector x = Vector::LinSpaced(p.size(), -3, 5);
    const Vector w = compensatedSlack(p, x);
    const DenseMatrix A = p.toDense();
    for (int i = 0; i < p.size(); ++i) {
      long double e = p.b[i];
      for (int j = 0; j < p.size(); ++j) e += (long double)A(i, j) * x[j];
      EXPECT_NEAR(w[i], double(e), 1e-15 * std::abs(double(e)) + 1e-300) << i;
    }
  }
}

}  // namespace
}  // namespace mlcp
