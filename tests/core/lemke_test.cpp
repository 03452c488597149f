// Lemke: the worked example and its tableaux, an LP, infeasible and degenerate
// problems, random problems with known solutions, boxed / equality / findex problems and the
// Siconos corpus. Every answer is judged by mlcp::accuracy, recomputed here.
#include "mlcp/solvers/lemke.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

using test::Generator;
using test::KnownProblem;

Problem standardLcp(const DenseMatrix& M, const Vector& q) { return Problem(M, q); }

Vector vec(std::initializer_list<double> v) {
  Vector x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double d : v) x[i++] = d;
  return x;
}

// Solves and checks the solver's claims against the recomputed accuracy.
Result solveChecked(const Problem& p, Vector& x, const Options& opt = Options()) {
  LemkeSolver lemke;
  lemke.setOptions(opt);
  const Result r = lemke.solve(p, x);
  if (r.status != Status::Unsupported && r.status != Status::InvalidInput) {
    const Accuracy a = checkedAccuracy(p, x, p.slack(x), opt.tolerance);
    EXPECT_DOUBLE_EQ(r.residual, a.residual);
    if (r.converged()) {
      EXPECT_LE(a.residual, opt.tolerance);
    }
  }
  return r;
}

// The rows of the last table a trace printed: basis label -> cells (entries, then rhs).
std::map<std::string, std::vector<std::string>> lastTable(const std::string& trace) {
  std::istringstream in(trace.substr(trace.rfind("\npivot ")));
  std::string line;
  std::getline(in, line);  // blank
  std::getline(in, line);  // "pivot k: ..."
  std::getline(in, line);  // header
  std::map<std::string, std::vector<std::string>> rows;
  while (std::getline(in, line) && !line.empty()) {
    std::istringstream cells(line);
    std::string label, cell;
    cells >> label;
    while (cells >> cell)
      if (cell != "|") rows[label].push_back(cell);
  }
  return rows;
}

TEST(Lemke, IsRegistered) {
  std::unique_ptr<Solver> s = makeSolver("lemke");
  ASSERT_NE(s, nullptr);
  EXPECT_STREQ(s->name(), "lemke");
}

TEST(Lemke, SeedExample) {
  const Problem p = test::seedLemkeExample();
  Vector x;
  const Result r = solveChecked(p, x);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.iterations, 3);
  EXPECT_LT(residual(p, x), 1e-12);
  EXPECT_NEAR(x[0], 20.0 / 19, 1e-14);
  EXPECT_NEAR(x[1], 21.0 / 19, 1e-14);
  EXPECT_NEAR(x[2], 0.0, 1e-14);
}

TEST(LemkeTrace, SeedPivotsAndFinalTableEqualTheNotes) {
  const Problem p = test::seedLemkeExample();
  std::ostringstream out;
  Vector x;
  const Result r = traceLemke(p, out, Options(), &x);
  const std::string text = out.str();
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.iterations, 3);
  EXPECT_NE(text.find("(exact fractions)"), std::string::npos);
  EXPECT_NE(text.find("pivot 1: z0 enters, w2 leaves (row 2)"), std::string::npos) << text;
  EXPECT_NE(text.find("pivot 2: z2 enters, w1 leaves (row 1)"), std::string::npos) << text;
  EXPECT_NE(text.find("pivot 3: z1 enters, z0 leaves (row 2)"), std::string::npos) << text;
  EXPECT_EQ(text.find("pivot 4"), std::string::npos);
  // The worked example's last tableau: columns w1 w2 w3 z1 z2 z3 z0 | q.
  const std::map<std::string, std::vector<std::string>> expected = {
      {"z2", {"-1/19", "-2/19", "0", "0", "1", "7/19", "3/19", "21/19"}},
      {"z1", {"-10/19", "-1/19", "0", "1", "0", "32/19", "11/19", "20/19"}},
      {"w3", {"32/19", "7/19", "1", "0", "0", "-110/19", "-58/19", "12/19"}},
  };
  EXPECT_EQ(lastTable(text), expected) << text;
  EXPECT_NE(text.find("z = (20/19, 21/19, 0)"), std::string::npos);
  EXPECT_NE(text.find("w = (0, 0, 12/19)"), std::string::npos);
  EXPECT_LT(residual(p, x), 1e-12);
}

TEST(LemkeTrace, DecimalsForNonIntegerData) {
  Problem p = test::seedLemkeExample();
  p.b[0] = -1.5;
  std::ostringstream out;
  const Result r = traceLemke(p, out);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_EQ(out.str().find('/'), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("pivot 1: z0 enters"), std::string::npos);
}

TEST(LemkeTrace, OverflowFallsBackToDecimalsAndSaysSo) {
  // Integer data whose fractions outgrow 64 bits: the trace restarts in decimals.
  Generator g(7);
  const int n = 12;
  DenseMatrix M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) M(i, j) = std::round(g.uniform(-1e6, 1e6));
  M += 1e7 * DenseMatrix::Identity(n, n);  // diagonally dominant: a P-matrix
  Vector q(n);
  for (int i = 0; i < n; ++i) q[i] = std::round(g.uniform(-1e6, 1e6));
  const Problem p(M, q);
  std::ostringstream out;
  Vector x;
  const Result r = traceLemke(p, out, Options(), &x);
  EXPECT_NE(out.str().find("overflowed 64 bits"), std::string::npos);
  EXPECT_EQ(out.str().find("(exact fractions)"), std::string::npos);
  EXPECT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(p, x), 1e-10);
}

TEST(LemkeTrace, RefusesOtherProblemClasses) {
  Problem p = test::seedLemkeExample();
  p.hi[0] = 2;
  std::ostringstream out;
  const Result r = traceLemke(p, out);
  EXPECT_EQ(r.status, Status::Unsupported);
  EXPECT_NE(r.message.find("standard LCPs only"), std::string::npos) << r.message;
  EXPECT_TRUE(out.str().empty());
}

TEST(LemkeTrace, ReportsRayTermination) {
  std::ostringstream out;
  const Result r = traceLemke(standardLcp(DenseMatrix::Constant(1, 1, -1), vec({-1})), out);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_NE(out.str().find("ray termination at pivot 2"), std::string::npos) << out.str();
}

// The appendix LP max 2x1 + x2 s.t. 5x2 <= 15, 6x1 + 2x2 <= 24, x1 + x2 <= 5 as the LCP
// M = [[0, A'], [-A, 0]], q = [-c; b]: z = (x, duals).
TEST(Lemke, SeedAppendixLinearProgram) {
  DenseMatrix A(3, 2);
  A << 0, 5, 6, 2, 1, 1;
  DenseMatrix M = DenseMatrix::Zero(5, 5);
  M.block(0, 2, 2, 3) = A.transpose();
  M.block(2, 0, 3, 2) = -A;
  const Problem p = standardLcp(M, vec({-2, -1, 15, 24, 5}));
  Vector z;
  const Result r = solveChecked(p, z);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LT(residual(p, z), 1e-12);
  const Vector expected = vec({3.5, 1.5, 0, 0.25, 0.5});
  EXPECT_LT((z - expected).lpNorm<Eigen::Infinity>(), 1e-12) << z.transpose();
}

TEST(Lemke, InfeasibleEndsOnARay) {
  const Problem p = standardLcp(DenseMatrix::Constant(1, 1, -1), vec({-1}));
  Vector x;
  const Result r = solveChecked(p, x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_EQ(r.message,
            "ray termination at pivot 2: the entering column of z1 has no positive entry; the "
            "LCP may be infeasible");
  EXPECT_GT(residual(p, x), 1e-3);
}

TEST(Lemke, InfeasiblePsdProblemIsNeverConverged) {
  // w1 = -z2 - z3 - 1e-4 < 0 for every z >= 0 (Pang's example, perturbed).
  DenseMatrix M(3, 3);
  M << 0, -1, -1, 1, 0, 0, -1, 0, 0;
  Vector x;
  const Result r = solveChecked(standardLcp(M, vec({-1e-4, -1, 1})), x);
  EXPECT_EQ(r.status, Status::Failed) << r.message;
  EXPECT_NE(r.message.find("ray termination"), std::string::npos);
}

TEST(Lemke, TrivialWhenQIsNonnegative) {
  Vector x;
  const Problem p = standardLcp(DenseMatrix::Identity(3, 3), vec({1, 0, 2}));
  const Result r = solveChecked(p, x);
  EXPECT_EQ(r.status, Status::Converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(x, Vector::Zero(3));
}

TEST(Lemke, EmptyProblem) {
  Vector x;
  const Result r = solveChecked(Problem(DenseMatrix(0, 0), Vector(0)), x);
  EXPECT_EQ(r.status, Status::Converged);
}

// Murty's example: lower triangular with 1 on the diagonal, 2 below, takes 2^n - 1 pivots for
// his q; ties everywhere for q = -e.
DenseMatrix murty(int n) {
  DenseMatrix M = DenseMatrix::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    M(i, i) = 1;
    for (int j = 0; j < i; ++j) M(i, j) = 2;
  }
  return M;
}

TEST(Lemke, MurtyExponentialExampleAndPivotLimit) {
  const int n = 6;
  Vector q(n);
  for (int i = 0; i < n; ++i) q[i] = -(std::pow(2.0, n + 1) - std::pow(2.0, n - i));
  const Problem p = standardLcp(murty(n), q);
  Vector x;
  Result r = solveChecked(p, x);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_EQ(r.iterations, 64);  // 2^n - 1 complementary pivots plus z0's entry
  EXPECT_LT(residual(p, x), 1e-12);

  Options few;
  few.maxPivots = 10;
  r = solveChecked(p, x, few);
  EXPECT_EQ(r.status, Status::MaxIterations);
  EXPECT_NE(r.message.find("pivot limit 10"), std::string::npos) << r.message;
}

// Degenerate ties: repeated q entries, identical rows, weakly active rows. The lexicographic
// rule must end each one; the exact-fraction trace must take the same pivots as the
// floating-point solver (the tolerances reproduce the exact tie-breaks).
TEST(Lemke, DegenerateTiesDoNotCycle) {
  std::vector<Problem> problems;
  problems.push_back(standardLcp(murty(6), -Vector::Ones(6)));
  DenseMatrix ones = DenseMatrix::Ones(4, 4);  // identical rows, PSD
  problems.push_back(standardLcp(ones, vec({-1, -1, -1, -1})));
  DenseMatrix J(4, 2);  // J J': rows 0/1 and 2/3 identical, PSD
  J << 1, 0, 1, 0, 0.5, 1, 0.5, 1;
  problems.push_back(standardLcp(J * J.transpose(), vec({-2, -2, -2, -2})));
  DenseMatrix cps5(2, 2);  // the Siconos CPS_5 matrix, q with a tie at zero
  cps5 << 1, -1, -1, 1;
  problems.push_back(standardLcp(cps5, vec({1, -1})));
  DenseMatrix deg(3, 3);  // zero ratios in the first test
  deg << 1, 2, 0, 0, 1, 2, 2, 0, 1;
  problems.push_back(standardLcp(deg, vec({-1, 0, -1})));
  for (size_t k = 0; k < problems.size(); ++k) {
    const Problem& p = problems[k];
    Vector x;
    const Result r = solveChecked(p, x);
    EXPECT_EQ(r.status, Status::Converged) << "problem " << k << ": " << r.message;
    EXPECT_LT(residual(p, x), 1e-12) << "problem " << k;
    std::ostringstream out;
    const Result t = traceLemke(p, out);
    EXPECT_EQ(t.iterations, r.iterations) << "problem " << k << "\n" << out.str();
  }
}

TEST(Lemke, DegenerateRandomProblems) {
  Generator g(11);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 3 + g.pick(10);
    // Duplicate some rows and columns of a singular PSD matrix: many exact ties.
    DenseMatrix A = g.psdSingular(n, std::max(1, n / 2));
    KnownProblem kp = g.standard(A, /*degenerate=*/true);
    Vector x;
    const Result r = solveChecked(kp.problem, x);
    EXPECT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    EXPECT_LE(residual(kp.problem, x), 1e-10) << "trial " << trial;
  }
}

TEST(Lemke, RandomSpdAndPMatrixProblems) {
  Generator g(3);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + g.pick(40);
    DenseMatrix A = g.spd(n);
    if (trial % 2 == 1) {  // SPD plus a skew part: positive definite, not symmetric, a P-matrix
      DenseMatrix S = g.spd(n, 0) - g.spd(n, 0);
      A += 0.5 * (S - S.transpose());
    }
    KnownProblem kp = g.standard(A, trial % 3 == 0);
    Vector x;
    const Result r = solveChecked(kp.problem, x);
    ASSERT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    EXPECT_LE(residual(kp.problem, x), 1e-12) << "trial " << trial;
    EXPECT_LT((x - kp.solution).lpNorm<Eigen::Infinity>(), 1e-9) << "trial " << trial;
  }
}

// A problem scaled by 1e-3 or 1e3 is solved as accurately. (The tie and pivot tolerances have
// an absolute floor, so on degenerate problems the path may differ.)
TEST(Lemke, ScaleInvariance) {
  Generator g(17);
  for (int trial = 0; trial < 6; ++trial) {
    KnownProblem kp = trial % 2 ? g.boxed(g.spd(20)) : g.standard(g.psdSingular(20, 8), true);
    Vector x;
    const Result base = solveChecked(kp.problem, x);
    ASSERT_EQ(base.status, Status::Converged) << base.message;
    for (double scale : {1e-3, 1e3}) {
      Problem p = kp.problem;
      p.setA(DenseMatrix(scale * p.denseA()));
      p.b *= scale;
      const Result r = solveChecked(p, x);
      EXPECT_EQ(r.status, Status::Converged) << "scale " << scale << ": " << r.message;
      EXPECT_LE(residual(p, x), 1e-12) << "scale " << scale;
    }
  }
}

// Regression: friction bounds from normal values of ~1e-30 give boxes 1e-30 wide, whose
// ratio-test ties were decided by noise: Lemke ended on a false ray (problem 11 of this
// sequence, n = 162, before such boxes were treated as fixed).
TEST(Lemke, MicroscopicBoxesDoNotEndOnAFalseRay) {
  Generator g(5);
  for (int t = 0; t < 12; ++t) {
    const int n = 60 + g.pick(150);
    Problem p = g.friction(n / 3 + 1).problem;
    for (int i = 0; i < p.size(); ++i) {
      if (p.findex[i] < 0) continue;
      const double width = std::pow(10.0, -28 - g.pick(5)) * g.uniform(0.5, 1);
      const double mu = p.hi[i];
      p.lo[i] = -mu * width;
      p.hi[i] = mu * width;
    }
    p.findex.clear();
    if (t < 11) continue;  // the problem that failed; the loop keeps the generator's sequence
    Vector x;
    const Result r = solveChecked(p, x);
    EXPECT_EQ(r.status, Status::Converged) << "problem " << t << ": " << r.message;
  }
}

TEST(Lemke, BoxedAndEqualityRows) {
  Generator g(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + g.pick(25);
    KnownProblem kp = trial % 5 == 4 ? g.linear(g.spd(n)) : g.boxed(g.spd(n));
    Vector x;
    const Result r = solveChecked(kp.problem, x);
    ASSERT_EQ(r.status, Status::Converged) << "trial " << trial << ": " << r.message;
    EXPECT_LE(residual(kp.problem, x), 1e-12) << "trial " << trial;
    EXPECT_LT((x - kp.solution).lpNorm<Eigen::Infinity>(), 1e-9) << "trial " << trial;
  }
}

TEST(Lemke, EachBoundKind) {
  // Rows: [lo, inf) at lo, (-inf, hi] at hi, [lo, hi] inside, [lo, hi] at hi, fixed, free.
  Generator g(21);
  const int n = 6;
  const DenseMatrix A = g.spd(n);
  Problem p(A, Vector::Zero(n));
  p.lo = vec({-1, -kInf, -1, 0, 0.5, -kInf});
  p.hi = vec({kInf, 2, 1, 0.5, 0.5, kInf});
  const Vector xs = vec({-1, 2, 0.25, 0.5, 0.5, -3});
  const Vector ws = vec({0.7, -0.4, 0, -1.1, 0.3, 0});
  p.b = ws - A * xs;
  Vector x;
  const Result r = solveChecked(p, x);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(p, x), 1e-12);
  EXPECT_LT((x - xs).lpNorm<Eigen::Infinity>(), 1e-10) << x.transpose();
}

TEST(Lemke, FreeRowsWithSingularBlockAreSplit) {
  // Free rows 0 and 1 are identical (PSD A, singular A_FF): no Schur elimination; each free x
  // becomes z+ - z-. Solutions: x0 + x1 = 1, x2 = 0.
  DenseMatrix J(3, 2);
  J << 1, 0, 1, 0, 0.5, 1;
  Problem p(J * J.transpose(), vec({-1, -1, 0.2}));
  p.lo = vec({-kInf, -kInf, 0});
  p.hi = vec({kInf, kInf, kInf});
  Vector x;
  const Result r = solveChecked(p, x);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(p, x), 1e-12);
  EXPECT_NEAR(x[0] + x[1], 1, 1e-12) << x.transpose();
  EXPECT_EQ(x[2], 0);
}

TEST(Lemke, FrictionByFixedPoint) {
  Generator g(9);
  int converged = 0;
  const int trials = 30;
  for (int trial = 0; trial < trials; ++trial) {
    KnownProblem kp = g.friction(1 + g.pick(6));
    Options opt;
    opt.tolerance = 1e-9;
    opt.maxIterations = 100;
    Vector x;
    const Result r = solveChecked(kp.problem, x, opt);
    // The fixed point may fail to settle; it must then say so and never claim convergence.
    if (r.converged()) {
      ++converged;
      EXPECT_LE(residual(kp.problem, x), 1e-9);
    } else {
      EXPECT_TRUE(r.status == Status::MaxIterations || r.status == Status::Failed)
          << toString(r.status);
      EXPECT_FALSE(r.message.empty());
    }
  }
  EXPECT_GE(converged, trials * 9 / 10);
}

// A findex contact problem without CFM whose contact rows outnumber the bodies' freedoms (A
// singular): its friction passes ran a full pivot limit each, 1000 times (minutes at 600 rows).
// The one limit now bounds the passes together, and the status says how the solve ended.
void expectFindexContactProblemEndsWithin(int rows, int maxPivots) {
  Generator g(35);
  const Problem p = test::frictionPyramids(test::jacobianGram(g, rows, rows / 5, 0), g, 0.6);
  Options opt;
  opt.tolerance = 1e-9;
  opt.maxPivots = maxPivots;
  LemkeSolver lemke;
  lemke.setOptions(opt);
  Vector x;
  const Result r = lemke.solve(p, x);
  EXPECT_LE(r.iterations, opt.maxPivots) << r.message;
  if (r.converged()) {
    EXPECT_LE(r.residual, opt.tolerance);
  } else {
    EXPECT_TRUE(r.status == Status::MaxIterations || r.status == Status::Failed) << r.message;
    EXPECT_FALSE(r.message.empty());
  }
  EXPECT_NEAR(r.residual, residual(p, x), 1e-12);
}

TEST(Lemke, FindexContactProblemEndsWithinOnePivotLimit) {
  expectFindexContactProblemEndsWithin(150, 1500);
}

// The 600-row one (more than 120 s without an answer when each pass had its own limit), on the
// factored basis.
TEST(Lemke, FindexContactProblemOf600RowsEndsWithinOnePivotLimit) {
  expectFindexContactProblemEndsWithin(600, 6000);
}

TEST(Lemke, FrictionSingleContactSliding) {
  // One contact pushed sideways: normal x0 = 1, friction saturates at mu = 0.5.
  DenseMatrix A(3, 3);
  A << 2, 0.2, 0.1, 0.2, 1, 0.1, 0.1, 0.1, 1;
  Problem p(A, vec({-2, -3, 0.5}));
  p.lo = vec({0, -0.5, -0.5});
  p.hi = vec({kInf, 0.5, 0.5});
  p.findex = {-1, 0, 0};
  Vector x;
  Options opt;
  opt.tolerance = 1e-12;
  const Result r = solveChecked(p, x, opt);
  ASSERT_EQ(r.status, Status::Converged) << r.message;
  EXPECT_LE(residual(p, x), 1e-12);
  EXPECT_NEAR(std::abs(x[1]), 0.5 * x[0], 1e-12);  // sliding on the cone's edge
}

TEST(Lemke, InvalidInputLeavesXUntouched) {
  Problem p = test::seedLemkeExample();
  p.lo[1] = 5;
  p.hi[1] = 1;
  Vector x = vec({7, 8, 9});
  const Result r = solveChecked(p, x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_EQ(x, vec({7, 8, 9}));
}

// The Siconos LCP corpus: every file is solved to 1e-10 except a bimatrix game (CPS_3: Lemke
// with a positive covering vector always ends on a ray at pivot 2 for zero diagonal blocks) and
// an infeasible problem (Pang_isolated_sol_perturbed).
TEST(Lemke, SiconosCorpus) {
  const std::filesystem::path dir = std::filesystem::path(MLCP_SICONOS_DIR) / "lcp";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  const std::set<std::string> rays = {"lcp_CPS_3.dat", "lcp_Pang_isolated_sol_perturbed.dat"};
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".dat") continue;
    ++files;
    const std::string name = entry.path().filename().string();
    const Problem p = io::readSiconosLcp(entry.path().string());
    Vector x;
    const Result r = solveChecked(p, x);
    if (rays.count(name)) {
      EXPECT_EQ(r.status, Status::Failed) << name;
      EXPECT_NE(r.message.find("ray termination"), std::string::npos) << name << ": " << r.message;
    } else {
      EXPECT_EQ(r.status, Status::Converged) << name << ": " << r.message;
      EXPECT_LE(residual(p, x), 1e-10) << name;
    }
  }
  EXPECT_GE(files, 20);
}

}  // namespace
}  // namespace mlcp
