// Problem validation: each rule names what is wrong; classification.
#include "mlcp/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/generators.hpp"

namespace mlcp {
namespace {

Problem boxedThree() {
  Problem p(DenseMatrix::Identity(3, 3), Vector::Ones(3));
  p.lo << -1, -kInf, 0;
  p.hi << 1, kInf, kInf;
  return p;
}

void expectInvalid(const Problem& p, const std::string& fragment) {
  const std::string why = p.validate();
  EXPECT_NE(why.find(fragment), std::string::npos) << "message was: '" << why << "'";
}

TEST(ProblemValidate, AcceptsWellFormed) {
  EXPECT_EQ(boxedThree().validate(), "");
  EXPECT_EQ(test::seedLemkeExample().validate(), "");
}

TEST(ProblemValidate, WrongSizes) {
  Problem p = boxedThree();
  p.setA(DenseMatrix::Identity(2, 3));
  expectInvalid(p, "A is 2x3");
  p = boxedThree();
  p.lo.resize(2);
  expectInvalid(p, "lo has 2 entries");
  p = boxedThree();
  p.hi.resize(4);
  expectInvalid(p, "hi has 4 entries");
  p = boxedThree();
  p.findex = {-1, -1};
  expectInvalid(p, "findex has 2 entries");
}

TEST(ProblemValidate, NonFiniteData) {
  Problem p = boxedThree();
  DenseMatrix A = DenseMatrix::Identity(3, 3);
  A(1, 2) = std::nan("");
  p.setA(A);
  expectInvalid(p, "A(1,2)");
  p = boxedThree();
  SparseMatrix S(3, 3);
  S.insert(2, 0) = kInf;
  p.setA(S);
  expectInvalid(p, "A(2,0)");
  p = boxedThree();
  p.b[2] = -kInf;
  expectInvalid(p, "b[2]");
  p = boxedThree();
  p.lo[0] = std::nan("");
  expectInvalid(p, "NaN");
}

TEST(ProblemValidate, Bounds) {
  Problem p = boxedThree();
  p.lo[0] = 2;
  expectInvalid(p, "lo = 2 > hi = 1");
  p = boxedThree();
  p.lo[2] = kInf;
  expectInvalid(p, "no finite x");
}

TEST(ProblemValidate, Findex) {
  Problem p = boxedThree();
  p.findex = {-1, -1, 3};
  expectInvalid(p, "out of range");
  p.findex = {-1, -1, -2};
  expectInvalid(p, "out of range");
  p.findex = {0, -1, -1};
  expectInvalid(p, "own row");
  // Row 0 is a proper friction row on row 2; row 1 would chain onto row 0.
  p.findex = {2, 0, -1};
  p.lo[1] = -0.5;
  p.hi[1] = 0.5;
  expectInvalid(p, "chains are not allowed");
  p = boxedThree();
  p.findex = {-1, 2, -1};  // row 1 has bounds -inf..inf: not -mu..mu
  expectInvalid(p, "expected [-mu, mu]");
  p.lo[1] = -0.3;
  p.hi[1] = 0.5;
  expectInvalid(p, "expected [-mu, mu]");
  p.hi[1] = 0.3;
  EXPECT_EQ(p.validate(), "");
}

TEST(ProblemClassify, Classes) {
  EXPECT_EQ(Problem(DenseMatrix(0, 0), Vector(0)).classify(), ProblemClass::Empty);
  EXPECT_EQ(test::seedLemkeExample().classify(), ProblemClass::StandardLcp);
  EXPECT_EQ(boxedThree().classify(), ProblemClass::Boxed);
  Problem p = boxedThree();
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  EXPECT_EQ(p.classify(), ProblemClass::Linear);
  p = boxedThree();
  p.findex = {-1, -1, -1};
  EXPECT_EQ(p.classify(), ProblemClass::Boxed);
  p.findex = {2, -1, -1};
  EXPECT_EQ(p.classify(), ProblemClass::Findex);
}

TEST(Problem, DenseAndSparseAgree) {
  test::Generator g(3);
  const test::KnownProblem kp = g.boxed(g.spd(9));
  Problem sparse = kp.problem;
  sparse.setA(kp.problem.toSparse());
  ASSERT_TRUE(sparse.isSparse());
  const Vector x = kp.solution;
  EXPECT_LE((sparse.slack(x) - kp.problem.slack(x)).lpNorm<Eigen::Infinity>(), 1e-12);
  for (int i = 0; i < 9; ++i) {
    EXPECT_DOUBLE_EQ(sparse.diagonal(i), kp.problem.diagonal(i));
    EXPECT_NEAR(sparse.rowDot(i, x), kp.problem.rowDot(i, x), 1e-12);
  }
  EXPECT_EQ(sparse.toDense(), kp.problem.toDense());
}

}  // namespace
}  // namespace mlcp
