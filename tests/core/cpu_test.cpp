// mlcp/cpu.hpp: the CPU path can be read and set, and RowPgs' baseline and AVX2 variants of the
// packing, sweeps and check give the same answers bit for bit, through the RowSystem entry point
// and through the engine entry point (rows read in place), as do those of newton's body-space
// elimination.
#include "mlcp/cpu.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <type_traits>
#include <vector>

#include "common/contact_scenes.hpp"
#include "common/cpu_path_guard.hpp"
#include "common/row_source.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solvers/newton.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "projection/cpu_dispatch.hpp"  // MLCP_CPU_DISPATCH (internal)
#include "projection/row_simd.hpp"      // the products (internal)

namespace mlcp {
namespace {

using test::CpuPathGuard;

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(CpuPath, NamesAvailabilityAndSwitching) {
  CpuPathGuard guard;  // decides the default path if nothing has yet (tests restore it)
  const CpuPath byDefault = cpuPath();
  EXPECT_STREQ(toString(CpuPath::Baseline), "baseline");
  EXPECT_STREQ(toString(CpuPath::Avx2), "avx2");
  EXPECT_TRUE(cpuPathAvailable(CpuPath::Baseline));
  ASSERT_TRUE(setCpuPath(CpuPath::Baseline));
  EXPECT_EQ(cpuPath(), CpuPath::Baseline);
  // Asking for AVX2 succeeds exactly where it is available, and a refusal changes nothing.
  EXPECT_EQ(setCpuPath(CpuPath::Avx2), cpuPathAvailable(CpuPath::Avx2));
  EXPECT_EQ(cpuPath(), cpuPathAvailable(CpuPath::Avx2) ? CpuPath::Avx2 : CpuPath::Baseline);
#if MLCP_CPU_DISPATCH
  // A build with the dispatch offers AVX2 on every CPU that has what the variant uses, and takes
  // it by default.
  __builtin_cpu_init();
  const bool cpu = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi") &&
                   __builtin_cpu_supports("bmi2");
  EXPECT_EQ(cpuPathAvailable(CpuPath::Avx2), cpu);
  if (cpu && !std::getenv("MLCP_CPU_PATH")) {
    EXPECT_EQ(byDefault, CpuPath::Avx2);
  }
#else
  EXPECT_FALSE(cpuPathAvailable(CpuPath::Avx2));
#endif
}

// row_simd.hpp's products against the Eigen expressions whose order they keep, on random values
// of mixed sizes: the same bits, in both widths.
TEST(CpuPath, RowProductsSumInEigensOrder) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  auto value = [&] { return u(rng) * std::pow(10.0, 6 * u(rng)); };
  int differ = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Vector6 sA, sB, va, vb, m0, m1;
    for (Vector6* v : {&sA, &sB, &va, &vb, &m0, &m1})
      for (int k = 0; k < 6; ++k) (*v)[k] = value();
    const double d0 = value(), d1 = value();
    const double dot = (sA.cwiseProduct(va) + sB.cwiseProduct(vb)).sum();
    Vector6 acc = Vector6::Zero();
    acc += m0 * d0;
    acc += m1 * d1;
    const Vector6 moved = va + acc;
    auto check = [&](auto wide) {
      constexpr bool Wide = decltype(wide)::value;
      const auto a = detail::load6<Wide>(va.data()), b = detail::load6<Wide>(vb.data());
      differ += !sameBits(detail::dot12<Wide>(sA.data(), sB.data(), a, b), dot);
      detail::Six<Wide> da{};
      da = detail::addScaled<Wide>(da, m0.data(), d0);
      da = detail::addScaled<Wide>(da, m1.data(), d1);
      double out[6];
      detail::store6<Wide>(out, detail::add<Wide>(a, da));
      for (int k = 0; k < 6; ++k) differ += !sameBits(out[k], moved[k]);
    };
    check(std::false_type());
    check(std::true_type());
  }
  EXPECT_EQ(differ, 0);
}

struct Answer {
  Vector x;
  Result result;
  std::vector<Vector6> velocityChanges;  // engine entry point only
};

// 10 sweeps from a warm start on a sliding 55-box pyramid (1200 rows, friction with findex),
// through solve(RowSystem) or through the engine entry point with a per-row base.
Answer solveOn(const RowSystem& s, const Vector& start, bool engine) {
  RowPgs pgs;
  pgs.options().maxIterations = 10;
  Answer out;
  if (!engine) {
    out.x = start;
    out.result = pgs.solve(s, out.x);
    return out;
  }
  Vector base = start;
  for (int i = 0; i < s.size(); i += 3) base[i] *= 0.5;
  out.result = test::solveFromRows(pgs, s, start, base, out.x);
  EXPECT_TRUE(pgs.velocityChanges());
  if (pgs.velocityChanges())
    for (int k = 0; k < static_cast<int>(s.bodies.size()); ++k)
      out.velocityChanges.push_back(pgs.velocityChange(k));
  return out;
}

TEST(CpuPath, BaselineAndAvx2GiveTheSameBits) {
  if (!cpuPathAvailable(CpuPath::Avx2)) GTEST_SKIP() << "no AVX2 variant on this build or CPU";
  CpuPathGuard guard;
  test::PyramidSpec spec;
  spec.levels = 10;
  spec.sideVelocity = 0.3;  // sliding contacts: friction rows at their bounds and inside
  test::BoxPyramid pyramid(spec);
  const RowSystem& s = pyramid.rows();
  // A start that is not the answer: a few sweeps from zero.
  Vector start;
  {
    RowPgs warmup;
    warmup.options().maxIterations = 3;
    ASSERT_NE(warmup.solve(s, start).status, Status::InvalidInput);
  }
  for (bool engine : {false, true}) {
    ASSERT_TRUE(setCpuPath(CpuPath::Baseline));
    const Answer a = solveOn(s, start, engine);
    ASSERT_TRUE(setCpuPath(CpuPath::Avx2));
    const Answer b = solveOn(s, start, engine);
    EXPECT_EQ(a.result.status, b.result.status);
    EXPECT_EQ(a.result.iterations, b.result.iterations);
    EXPECT_TRUE(sameBits(a.result.residual, b.result.residual))
        << a.result.residual << " " << b.result.residual;
    EXPECT_GT(a.result.residual, 0);  // not converged in 10 sweeps: the check saw real work
    ASSERT_EQ(a.x.size(), s.size());
    ASSERT_EQ(b.x.size(), s.size());
    int differ = 0;
    for (int i = 0; i < s.size(); ++i) differ += !sameBits(a.x[i], b.x[i]);
    EXPECT_EQ(differ, 0) << "engine entry point: " << engine;
    ASSERT_EQ(a.velocityChanges.size(), b.velocityChanges.size());
    for (std::size_t k = 0; k < a.velocityChanges.size(); ++k)
      for (int j = 0; j < 6; ++j)
        EXPECT_TRUE(sameBits(a.velocityChanges[k][j], b.velocityChanges[k][j])) << k << "/" << j;
  }
}

// newton's body-space factorizations (the block LU's updates, linalg/block_update.hpp) on a
// square pyramid, whose factor fills: the same iterates on both paths.
TEST(CpuPath, BodySpaceEliminationGivesTheSameBits) {
  if (!cpuPathAvailable(CpuPath::Avx2)) GTEST_SKIP() << "no AVX2 variant on this build or CPU";
  CpuPathGuard guard;
  test::PyramidSpec spec;
  spec.levels = 5;
  spec.square = true;
  spec.sideVelocity = 0.3;
  test::BoxPyramid pyramid(spec);
  const Problem p = pyramid.rows().assemble(true);
  Vector x[2];
  Result r[2];
  for (int path = 0; path < 2; ++path) {
    ASSERT_TRUE(setCpuPath(path == 0 ? CpuPath::Baseline : CpuPath::Avx2));
    NewtonSolver newton;
    newton.options().tolerance = 1e-9;
    newton.useRows(&pyramid.rows());
    r[path] = newton.solve(p, x[path]);
    EXPECT_GT(newton.bodyFactorizations(), 0);
  }
  EXPECT_EQ(r[0].iterations, r[1].iterations);
  EXPECT_TRUE(sameBits(r[0].residual, r[1].residual)) << r[0].residual << " " << r[1].residual;
  ASSERT_EQ(x[0].size(), p.size());
  ASSERT_EQ(x[1].size(), p.size());
  int differ = 0;
  for (int i = 0; i < p.size(); ++i) differ += !sameBits(x[0][i], x[1][i]);
  EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace mlcp
