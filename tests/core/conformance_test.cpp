// The conformance harness: every registered solver runs on the same problem families and the
// Siconos corpus. Answers are judged by mlcp::accuracy (recomputed here from the problem, never
// taken from the solver) and, where the solution is unique, by the distance to the known x*.
//
// Each solver declares what it must solve and what it must refuse in kExpectations; a solver
// without an entry for a family is still checked for honesty (a Converged claim must hold).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>

#include "common/generators.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp {
namespace {

using test::Generator;
using test::KnownProblem;

// What each solver must solve and must refuse (Unsupported or Failed, never a wrong
// Converged). Families: standard, degenerate, boxed, linear, friction, psd-singular, seed.
struct Declared {
  std::set<std::string> solves, refuses;
  bool warmStartFromSolutionIsFree = false;  // started at x*, it stops within one iteration
};
const std::map<std::string, Declared> kExpectations = {
    {"gs", {{"linear"}, {"standard", "boxed", "friction", "seed"}}},
    {"pgs", {{"standard", "degenerate", "boxed", "linear", "friction"}, {"seed"}, true}},
    {"lemke", {{"standard", "degenerate", "boxed", "linear", "friction", "seed"}, {}}},
    {"dantzig", {{"standard", "degenerate", "boxed", "linear", "friction", "seed"}, {}}},
    {"newton", {{"standard", "degenerate", "boxed", "linear", "friction", "seed"}, {}}},
    {"proximal", {{"standard", "degenerate", "boxed", "linear", "friction", "seed"}, {}}},
    {"ldlt", {{"linear"}, {"standard", "boxed", "friction", "seed"}}},
    {"auto", {{"standard", "degenerate", "boxed", "linear", "friction", "seed"}, {}}},
};

constexpr double kTol = 1e-10;

// Runs the solver and checks what holds for every solver on every problem: the reported
// accuracy is the recomputed one, and Converged is claimed only within tolerance.
Result runHonest(Solver& solver, const Problem& problem, Vector& x) {
  solver.options().tolerance = kTol;
  solver.options().maxIterations = 20000;
  Result r = solver.solve(problem, x);
  if (r.status == Status::InvalidInput || r.status == Status::Unsupported) {
    EXPECT_FALSE(r.message.empty()) << solver.name();
    return r;
  }
  EXPECT_EQ(x.size(), problem.size());
  // The measure the status comes from (plain w, compensated near the tolerance), from x alone.
  const Accuracy a = checkedAccuracy(problem, x, problem.slack(x), kTol);
  if (a.finite) {
    EXPECT_DOUBLE_EQ(r.residual, a.residual) << solver.name();
  }
  if (r.converged()) {
    EXPECT_TRUE(a.finite);
    EXPECT_LE(a.residual, kTol) << solver.name() << " claims convergence";
  } else {
    EXPECT_FALSE(r.message.empty()) << solver.name() << " says " << toString(r.status);
  }
  return r;
}

void checkExpectation(const std::string& solverName, const std::string& family,
                      const KnownProblem& kp) {
  std::unique_ptr<Solver> solver = makeSolver(solverName);
  ASSERT_TRUE(solver);
  Vector x;
  const Result r = runHonest(*solver, kp.problem, x);
  const auto entry = kExpectations.find(solverName);
  if (entry == kExpectations.end()) return;
  const bool solves = entry->second.solves.count(family) > 0;
  const bool refuses = entry->second.refuses.count(family) > 0;
  SCOPED_TRACE(solverName + " on " + family + " (" + kp.name + ", n = " +
               std::to_string(kp.problem.size()) + "): " + toString(r.status) + ": " + r.message);
  if (refuses) {
    EXPECT_FALSE(r.converged());
    EXPECT_TRUE(r.status == Status::Unsupported || r.status == Status::Failed)
        << toString(r.status);
    return;
  }
  if (!solves) return;
  ASSERT_EQ(r.status, Status::Converged);
  EXPECT_LE(residual(kp.problem, x), kTol);
  if (kp.unique && kp.solution.size() == x.size()) {
    EXPECT_LE((x - kp.solution).lpNorm<Eigen::Infinity>(),
              1e-6 * (1 + kp.solution.lpNorm<Eigen::Infinity>()));
  }
}

class Conformance : public ::testing::TestWithParam<std::string> {};

TEST_P(Conformance, GeneratedFamilies) {
  const std::string name = GetParam();
  for (unsigned seed = 1; seed <= 3; ++seed) {
    for (int n : {4, 17, 50}) {
      Generator g(seed * 1000 + n);
      checkExpectation(name, "standard", g.standard(g.spd(n)));
      checkExpectation(name, "degenerate", g.standard(g.spd(n), /*degenerate=*/true));
      checkExpectation(name, "boxed", g.boxed(g.spd(n)));
      checkExpectation(name, "linear", g.linear(g.spd(n)));
      checkExpectation(name, "friction", g.friction(std::max(1, n / 3)));
      checkExpectation(name, "psd-singular", g.standard(g.psdSingular(n, std::max(1, n / 2))));
    }
  }
}

TEST_P(Conformance, SeedExample) {
  KnownProblem kp{"seed", test::seedLemkeExample(),
                  (Vector(3) << 20.0 / 19, 21.0 / 19, 0).finished(), true};
  checkExpectation(GetParam(), "seed", kp);
}

TEST_P(Conformance, WarmStartFromSolution) {
  std::unique_ptr<Solver> solver = makeSolver(GetParam());
  Generator g(7);
  const KnownProblem kp = g.boxed(g.spd(12));
  solver->options().warmStart = true;
  Vector x = kp.solution;
  const Result r = runHonest(*solver, kp.problem, x);
  const auto entry = kExpectations.find(GetParam());
  if (r.converged() && entry != kExpectations.end() && entry->second.warmStartFromSolutionIsFree) {
    EXPECT_LE(r.iterations, 1) << "warm start from x* should finish at once";
  }
}

TEST_P(Conformance, InvalidInputLeavesXUntouched) {
  std::unique_ptr<Solver> solver = makeSolver(GetParam());
  Problem p = test::seedLemkeExample();
  p.lo[1] = 5;
  p.hi[1] = 1;
  Vector x = Vector::Constant(3, 42.0);
  const Result r = solver->solve(p, x);
  EXPECT_EQ(r.status, Status::InvalidInput);
  EXPECT_NE(r.message.find("lo"), std::string::npos) << r.message;
  EXPECT_EQ(x, Vector::Constant(3, 42.0));
}

TEST_P(Conformance, EmptyProblem) {
  std::unique_ptr<Solver> solver = makeSolver(GetParam());
  Problem p(DenseMatrix(0, 0), Vector(0));
  Vector x;
  const Result r = solver->solve(p, x);
  EXPECT_NE(r.status, Status::InvalidInput) << r.message;
  EXPECT_NE(r.status, Status::NumericalIssue) << r.message;
}

TEST_P(Conformance, Deterministic) {
  std::unique_ptr<Solver> a = makeSolver(GetParam()), b = makeSolver(GetParam());
  Generator g(11);
  const KnownProblem kp = g.friction(6);
  Vector xa, xb;
  const Result ra = a->solve(kp.problem, xa), rb = b->solve(kp.problem, xb);
  EXPECT_EQ(ra.status, rb.status);
  EXPECT_EQ(ra.iterations, rb.iterations);
  if (xa.size() == xb.size()) {
    EXPECT_EQ(xa, xb);
  }
}

// Which Siconos LCP files each solver must solve to the tolerance; every other (file, solver)
// pair is still checked for honesty. Reasons for the files a solver is not expected to solve
// are in docs/benchmarks.md's Siconos table.
const std::set<std::string> kLemkeSolves = {
    "lcp_CPS_1",     "lcp_CPS_2",        "lcp_CPS_4",
    "lcp_CPS_4bis",  "lcp_CPS_5",        "lcp_Pang_isolated_sol",
    "lcp_deudeu",    "lcp_deudeu_block", "lcp_enum_fails",
    "lcp_exp_murty", "lcp_exp_murty2",   "lcp_inf_sol_perturbed",
    "lcp_mmc",       "lcp_ortiz",        "lcp_ortiz_block",
    "lcp_tobenna",   "lcp_trivial",      "lcp_trivial_block"};
const std::map<std::string, std::set<std::string>> kSiconosSolves = {
    {"pgs",
     {"lcp_CPS_1", "lcp_CPS_5", "lcp_deudeu", "lcp_deudeu_block", "lcp_exp_murty", "lcp_exp_murty2",
      "lcp_mmc", "lcp_ortiz", "lcp_ortiz_block", "lcp_trivial", "lcp_trivial_block"}},
    // Every file but lcp_CPS_3 (no solution is reachable: Lemke ends on a ray, as Siconos' does)
    // and lcp_Pang_isolated_sol_perturbed (ray termination; see docs/benchmarks.md's Siconos
    // table).
    {"lemke", kLemkeSolves},
    // The files with zero diagonals or non-P matrices that need the 2x2 exchange pivot
    // (CPS_2, CPS_3, both Pang files, inf_sol_perturbed, tobenna, enum_fails) fail honestly.
    {"dantzig",
     {"lcp_CPS_1", "lcp_CPS_4", "lcp_CPS_4bis", "lcp_CPS_5", "lcp_deudeu", "lcp_deudeu_block",
      "lcp_exp_murty", "lcp_exp_murty2", "lcp_mmc", "lcp_ortiz", "lcp_ortiz_block", "lcp_trivial",
      "lcp_trivial_block"}},
    // lemke's, and lcp_CPS_3 by newton, the fallback of the zero-diagonal chain.
    {"auto",
     [] {
       std::set<std::string> s = kLemkeSolves;
       s.insert("lcp_CPS_3");
       return s;
     }()},
};

TEST_P(Conformance, SiconosCorpus) {
  const std::string name = GetParam();
  const std::filesystem::path dir = std::filesystem::path(MLCP_SICONOS_DIR) / "lcp";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  std::set<std::string> expected;
  if (auto it = kSiconosSolves.find(name); it != kSiconosSolves.end()) expected = it->second;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".dat") continue;
    ++files;
    const std::string stem = entry.path().stem().string();
    SCOPED_TRACE(name + " on " + stem);
    const Problem p = io::readSiconosLcp(entry.path().string());
    std::unique_ptr<Solver> solver = makeSolver(name);
    Vector x;
    const Result r = runHonest(*solver, p, x);
    if (expected.count(stem)) {
      EXPECT_EQ(r.status, Status::Converged) << r.message;
      expected.erase(stem);
    }
  }
  EXPECT_GE(files, 20);
  EXPECT_TRUE(expected.empty()) << "expected files missing from the corpus";
}

// Which Siconos MLCP files (circuits, relays, diode bridges: free rows for the equalities) each
// solver must solve to the tolerance. Rectangular_mlcp is unreadable by design (UnsupportedProblem:
// a 3 x 2 M); the diode bridges' equality blocks are singular, which the Schur elimination of
// lemke and the diagonal pivots of dantzig cannot take, and newton's least-squares steps can.
const std::set<std::string> kLemkeSolvesMlcp = {
    "Buck2_mlcp", "BuckConverter_mlcp", "BuckFirstStep_mlcp", "PDSym_mlcp",
    "RCD_mlcp",   "RLCD_mlcp",          "deudeu_mlcp",        "m2n1_mlcp",
    "m3n2_mlcp",  "relay2_mlcp",        "relay3_mlcp"};
const std::set<std::string> kEveryMlcp = {
    "Buck2_mlcp",       "BuckConverter_mlcp", "BuckFirstStep_mlcp", "PDSym_mlcp",
    "PD_mlcp",          "RCD_mlcp",           "RLCD_mlcp",          "deudeu_mlcp",
    "diodeBridge_mlcp", "diodeBridge20_mlcp", "diodeBridge40_mlcp", "m2n1_mlcp",
    "m3n2_mlcp",        "relay2_mlcp",        "relay3_mlcp"};
const std::map<std::string, std::set<std::string>> kSiconosMlcpSolves = {
    {"pgs", {"PDSym_mlcp", "deudeu_mlcp", "m2n1_mlcp", "m3n2_mlcp"}},
    {"lemke", kLemkeSolvesMlcp},
    {"dantzig", {"PDSym_mlcp", "RCD_mlcp", "deudeu_mlcp", "m2n1_mlcp", "m3n2_mlcp"}},
    {"newton", kEveryMlcp},
    {"auto", kEveryMlcp},
};

TEST_P(Conformance, SiconosMlcpCorpus) {
  const std::string name = GetParam();
  const std::filesystem::path dir = std::filesystem::path(MLCP_SICONOS_DIR) / "mlcp";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  std::set<std::string> expected;
  if (auto it = kSiconosMlcpSolves.find(name); it != kSiconosMlcpSolves.end())
    expected = it->second;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() != ".dat" || stem == "Rectangular_mlcp") continue;
    ++files;
    SCOPED_TRACE(name + " on " + stem);
    const Problem p = io::readSiconosMlcp(entry.path().string());
    std::unique_ptr<Solver> solver = makeSolver(name);
    solver->options().tolerance = 1e-9;
    Vector x;
    const Result r = runHonest(*solver, p, x);
    if (expected.count(stem)) {
      EXPECT_EQ(r.status, Status::Converged) << r.message;
      expected.erase(stem);
    }
  }
  EXPECT_EQ(files, 15);
  EXPECT_TRUE(expected.empty()) << "expected files missing from the corpus";
}

std::vector<std::string> registeredNames() {
  std::vector<std::string> names;
  for (const SolverInfo& info : solvers()) names.push_back(info.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(AllSolvers, Conformance, ::testing::ValuesIn(registeredNames()),
                         [](const auto& info) { return info.param; });

TEST(ConformanceTable, EverySolverDeclaresItsExpectations) {
  for (const SolverInfo& info : solvers())
    EXPECT_TRUE(kExpectations.count(info.name)) << info.name << " has no row in kExpectations";
}

}  // namespace
}  // namespace mlcp
