// LdltSolver's dense path: the envelope LDL^T on banded and full SPD matrices agrees with the
// sparse path, a zero leading pivot goes to the pivoting LDL^T, an inconsistent singular system
// is not reported Converged. Every answer is checked with residual.hpp.
#include "mlcp/solvers/ldlt.hpp"

#include <gtest/gtest.h>

#include "common/generators.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

Problem linearProblem(DenseMatrix A, const Vector& b) {
  Problem p(std::move(A), b);
  p.lo.setConstant(-kInf);
  p.hi.setConstant(kInf);
  return p;
}

// A block-tridiagonal SPD matrix (a chain's J M^-1 J^T shape) with blocks of size `block`.
DenseMatrix chainMatrix(int links, int block, test::Generator& g) {
  const int n = links * block;
  DenseMatrix B = DenseMatrix::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, (i / block - 1) * block); j <= i; ++j) B(i, j) = g.uniform(-1, 1);
  return B * B.transpose() + 0.1 * DenseMatrix::Identity(n, n);
}

TEST(LdltDense, EnvelopeFactorMatchesTheSparsePath) {
  test::Generator g(11);
  for (const DenseMatrix& A : {chainMatrix(12, 3, g), g.spd(40), chainMatrix(1, 1, g)}) {
    const int n = static_cast<int>(A.rows());
    Vector b(n);
    for (int i = 0; i < n; ++i) b[i] = g.uniform(-1, 1);
    const Problem dense = linearProblem(A, b);
    Problem sparse = dense;
    sparse.setA(dense.toSparse());
    LdltSolver solver;
    Vector xd, xs;
    for (int repeat = 0; repeat < 2; ++repeat) {  // the kept workspace gives the same answer
      const Result r = solver.solve(dense, xd);
      ASSERT_TRUE(r.converged()) << r.message;
      EXPECT_EQ(r.message, "dense LDL^T solve");
      EXPECT_LE(residual(dense, xd), 1e-13);
    }
    ASSERT_TRUE(solver.solve(sparse, xs).converged());
    EXPECT_LE((xd - xs).lpNorm<Eigen::Infinity>(), 1e-10 * (1 + xs.lpNorm<Eigen::Infinity>()));
  }
}

TEST(LdltSparse, NonSymmetricGoesToLuEveryTime) {
  test::Generator g(5);
  DenseMatrix A = chainMatrix(10, 3, g);
  A(4, 1) += 0.5;  // one asymmetric entry inside the pattern
  Vector b(A.rows());
  for (int i = 0; i < b.size(); ++i) b[i] = g.uniform(-1, 1);
  Problem p = linearProblem(A, b);
  p.setA(p.toSparse());
  LdltSolver solver;
  Vector x;
  for (int repeat = 0; repeat < 3; ++repeat) {
    const Result r = solver.solve(p, x);
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_EQ(r.message, "sparse LU solve");
    EXPECT_LE(residual(p, x), 1e-13);
  }
  // Symmetric again: back to LDL^T.
  Problem q = linearProblem(chainMatrix(10, 3, g), b);
  q.setA(q.toSparse());
  const Result r = solver.solve(q, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_EQ(r.message, "sparse LDL^T solve");
  EXPECT_LE(residual(q, x), 1e-13);
}

TEST(LdltDense, ZeroLeadingPivotUsesThePivotingFactorization) {
  DenseMatrix A(3, 3);
  A << 0, 1, 0, 1, 0, 2, 0, 2, 1;  // symmetric, indefinite, A_00 = 0
  const Problem p = linearProblem(A, Vector::Constant(3, -1.0));
  LdltSolver solver;
  Vector x;
  const Result r = solver.solve(p, x);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NE(r.message.find("pivoting"), std::string::npos) << r.message;
  EXPECT_LE((A * x - Vector::Ones(3)).lpNorm<Eigen::Infinity>(), 1e-13);
}

TEST(LdltDense, SingularSystems) {
  // Consistent (a redundant row): an answer within tolerance.
  DenseMatrix A(2, 2);
  A << 1, 1, 1, 1;
  LdltSolver solver;
  Vector x;
  const Problem consistent = linearProblem(A, Vector::Constant(2, -2.0));
  Result r = solver.solve(consistent, x);
  EXPECT_TRUE(r.converged()) << r.message;
  EXPECT_LE(residual(consistent, x), 1e-12);
  // Inconsistent: never Converged.
  Vector b(2);
  b << -1, 1;
  const Problem inconsistent = linearProblem(A, b);
  r = solver.solve(inconsistent, x);
  EXPECT_FALSE(r.converged()) << r.message;
  EXPECT_GT(residual(inconsistent, x), 1e-3);
}

}  // namespace
}  // namespace mlcp
