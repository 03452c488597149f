// The natural-map residual on hand-checked cases.
#include "mlcp/residual.hpp"

#include <gtest/gtest.h>

#include "common/generators.hpp"

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

TEST(Residual, EqualityRowsMeasureW) {
  Problem p(DenseMatrix::Identity(2, 2), Vector::Zero(2));
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  p.b << 3, 0;
  // x - clamp(x - w, -inf, inf) = w = x + b.
  EXPECT_DOUBLE_EQ(residual(p, Vector::Zero(2)), 3.0 / 4);
}

}  // namespace
}  // namespace mlcp
