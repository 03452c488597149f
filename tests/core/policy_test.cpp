// The policy (policy.hpp): auto's choices per class and size, the one fallback rule in the
// registry's chains and in RowSolver alike, the per-step time budget, lemke's limits.
#include "mlcp/island/policy.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/broken_solvers.hpp"
#include "common/contact_scenes.hpp"
#include "common/generators.hpp"
#include "common/timing_slack.hpp"
#include "mlcp/island/fallback.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "mlcp/solvers/pgs.hpp"

namespace mlcp {
namespace {

using test::BrokenSolver;

TEST(Policy, ChoosesByClassSizeAndTolerance) {
  const Policy p;
  EXPECT_STREQ(p.choose(ProblemClass::Empty, 0, 1e-6).solver, "none");
  EXPECT_STREQ(p.choose(ProblemClass::Linear, 5000, 1e-6).solver, "ldlt");
  EXPECT_STREQ(p.choose(ProblemClass::Linear, 5000, 1e-6, true, true).solver, "ldlt");
  for (ProblemClass c : {ProblemClass::StandardLcp, ProblemClass::Boxed, ProblemClass::Findex}) {
    EXPECT_STREQ(p.choose(c, 12, 1e-6).solver, "dantzig") << toString(c);
    EXPECT_STREQ(p.choose(c, p.smallIslandRows, 1e-2).solver, "dantzig") << toString(c);
    EXPECT_STREQ(p.choose(c, p.smallIslandRows, 1e-6, true, true).solver, "dantzig");
    const int large = p.smallIslandRows + 1;
    EXPECT_EQ(p.choose(c, large, 1e-6).solver, std::string(kLargeIslandSolver));
    EXPECT_STREQ(p.choose(c, large, p.looseTolerance).solver, "pgs");
    EXPECT_STREQ(p.choose(c, large, 1e-6, true, true).solver, "pgs");
    EXPECT_STREQ(p.choose(c, 12, 1e-6, false).solver, "lemke");
    EXPECT_STREQ(p.choose(c, 12, 1e-6, false).fallback, "newton");
  }
  EXPECT_STREQ(p.choose(ProblemClass::Findex, 12, 1e-6).fallback, "pgs");
}

TEST(Policy, TheLargeIslandSolverIsOneNamedParameter) {
  Policy p;
  p.largeIslandSolver = "newton";
  EXPECT_STREQ(p.choose(ProblemClass::Findex, p.smallIslandRows + 1, 1e-8).solver, "newton");
  EXPECT_STREQ(p.choose(ProblemClass::Findex, p.smallIslandRows, 1e-8).solver, "dantzig");
  p.smallIslandRows = 10;
  EXPECT_STREQ(p.choose(ProblemClass::Findex, 11, 1e-8).solver, "newton");
}

// Contact islands without free rows are newton's above smallContactRows; with a free (joint)
// row dantzig keeps them up to smallIslandRows. RowSolver reads the structure from the rows.
TEST(Policy, IslandsOfContactsOnlyAreNewtonsFromFewerRows) {
  const Policy p;
  ASSERT_LT(p.smallContactRows, p.smallIslandRows);
  for (ProblemClass c : {ProblemClass::StandardLcp, ProblemClass::Boxed, ProblemClass::Findex}) {
    const int mid = p.smallContactRows + 1;
    EXPECT_STREQ(p.choose(c, p.smallContactRows, 1e-6, true, false, false).solver, "dantzig");
    EXPECT_EQ(p.choose(c, mid, 1e-6, true, false, false).solver, std::string(kLargeIslandSolver));
    EXPECT_STREQ(p.choose(c, mid, 1e-6, true, false, true).solver, "dantzig");
    EXPECT_STREQ(p.choose(c, mid, 1e-6).solver, "dantzig");  // unknown: the joints' threshold
  }
  const Vector lo = (Vector(3) << 0, -1, -kInf).finished();
  EXPECT_TRUE(hasFreeRows(lo, Vector::Constant(3, kInf)));
  EXPECT_FALSE(hasFreeRows(lo, (Vector(3) << kInf, 1, 2).finished()));

  test::PyramidSpec spec;
  spec.levels = 4;
  const test::BoxPyramid pyramid(spec);
  RowSystem rows = pyramid.rows();
  ASSERT_GT(rows.size(), p.smallContactRows);
  ASSERT_LE(rows.size(), p.smallIslandRows);
  RowSolver solver;
  Vector x;
  EXPECT_EQ(solver.solve(rows, Vector::Zero(rows.size()), x).requested, "newton");
  rows.lo[0] = -kInf;  // a contact's normal row made a joint's
  rows.hi[0] = kInf;
  EXPECT_EQ(solver.solve(rows, Vector::Zero(rows.size()), x).requested, "dantzig");
}

TEST(Policy, BreakdownsAndFarMissesDemoteNearMissesDoNot) {
  const Policy p;
  Result r;
  r.status = Status::MaxIterations;
  r.residual = 2e-3;  // a near miss of 1e-3
  EXPECT_FALSE(p.demotes(r, 1e-3));
  r.residual = 0.5;
  EXPECT_TRUE(p.demotes(r, 1e-3));
  r.residual = 1e-4;
  r.status = Status::Failed;
  EXPECT_TRUE(p.demotes(r, 1e-3));
  r.status = Status::TimeLimit;
  r.residual = std::nan("");
  EXPECT_TRUE(p.demotes(r, 1e-3));
}

// A cold first step cut by the budget leaves the next, warm solve a start it converges from; a
// second cut in a row is a method that does not finish in the budget.
TEST(Policy, OneCutSolveDoesNotDemoteTwoInARowDo) {
  const Policy p;
  Result r;
  r.status = Status::TimeLimit;
  r.residual = 0.1;  // a far miss of 1e-3
  EXPECT_FALSE(p.demotes(r, 1e-3, 1));
  EXPECT_TRUE(p.demotes(r, 1e-3, 2));
  r.status = Status::MaxIterations;  // not a cut: the first far miss demotes
  EXPECT_TRUE(p.demotes(r, 1e-3, 0));
}

TEST(FallbackRule, BetterIsTheLowerFiniteResidual) {
  Result a, b;
  a.residual = 1e-3;
  b.residual = 1e-2;
  EXPECT_TRUE(better(a, b));
  EXPECT_FALSE(better(b, a));
  EXPECT_FALSE(better(a, a));  // a tie keeps the earlier answer
  b.residual = std::nan("");
  EXPECT_TRUE(better(a, b));
  EXPECT_FALSE(better(b, a));
  a.residual = kInf;
  EXPECT_FALSE(better(a, b));
}

// A near miss: dantzig stopped by its pivot limit keeps a finite answer above the limit; the
// chain runs pgs, and when pgs cannot do better either the better of the two is returned.
TEST(FallbackRule, ChainKeepsTheBestAnswerOfANearMiss) {
  test::Generator g(11);
  const test::KnownProblem kp = g.friction(30);
  std::unique_ptr<Solver> chain = makeSolver("dantzig>pgs");
  chain->options().maxPivots = 20;     // dantzig stops early: a finite iterate
  chain->options().maxIterations = 2;  // and pgs cannot reach 1e-10 in 2 sweeps
  Vector x;
  const Result r = chain->solve(kp.problem, x);
  ASSERT_EQ(x.size(), kp.problem.size());
  EXPECT_FALSE(r.converged());
  EXPECT_NE(r.message.find("no answer acceptable"), std::string::npos) << r.message;
  // The returned answer is the better one, its residual recomputed.
  Vector xd, xp;
  DantzigSolver d;
  d.options() = chain->options();
  PgsSolver pgs;
  pgs.options() = chain->options();
  const Result rd = d.solve(kp.problem, xd), rp = pgs.solve(kp.problem, xp);
  EXPECT_DOUBLE_EQ(residual(kp.problem, x), std::min(rd.residual, rp.residual));
  EXPECT_DOUBLE_EQ(r.residual, residual(kp.problem, x));
  EXPECT_EQ(r.solver, rd.residual <= rp.residual ? "dantzig" : "pgs");
}

TEST(FallbackRule, ChainOfBrokenSolversReturnsTheStartAndSaysSo) {
  std::vector<std::unique_ptr<Solver>> members;
  members.push_back(std::make_unique<BrokenSolver>(true));
  members.push_back(std::make_unique<BrokenSolver>(false));
  FallbackSolver chain(std::move(members));
  test::Generator g(12);
  const test::KnownProblem kp = g.boxed(g.spd(8));
  // test-fail leaves the start: a finite (bad) answer, preferred to test-nan's NaN.
  Vector x = Vector::Constant(8, 0.25);
  chain.options().warmStart = true;
  const Result r = chain.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::Failed);
  EXPECT_EQ(r.solver, "test-fail");
  EXPECT_TRUE(x.allFinite());
  EXPECT_TRUE(x.isApproxToConstant(0.25));
  EXPECT_NE(r.message.find("test-nan: numerical-issue"), std::string::npos) << r.message;
}

// RowSolver follows the same rule: a NaN primary falls back; a primary whose answer misses the
// acceptance limit keeps it when the fallback does worse (never "no impulses").
TEST(FallbackRule, RowSolverFallsBackFromNaNAndKeepsTheBetterOfTwoMisses) {
  test::registerBrokenSolvers();
  test::PyramidSpec spec;
  spec.levels = 3;
  const test::BoxPyramid pyramid(spec);
  const RowSystem& rows = pyramid.rows();
  const Vector start = Vector::Zero(rows.size());
  {
    RowSolverSettings s;
    s.solver = "test-nan";
    RowSolver solver(s);
    Vector x;
    const IslandSolve out = solver.solve(rows, start, x);
    EXPECT_TRUE(out.fellBack);
    EXPECT_EQ(out.choice, "pgs");
    EXPECT_TRUE(x.allFinite());
  }
  {
    RowSolverSettings s;
    s.solver = "pgs";
    s.options.maxIterations = 30;
    s.options.tolerance = 1e-12;
    s.acceptResidual = 1e-12;  // both miss
    s.fallback = "pgs";
    s.fallbackOptions.maxIterations = 1;  // worse than the primary's 30 sweeps
    RowSolver solver(s);
    Vector x;
    const IslandSolve out = solver.solve(rows, start, x);
    EXPECT_TRUE(out.fellBack);
    EXPECT_FALSE(out.accepted);
    EXPECT_EQ(out.choice, "pgs");
    EXPECT_EQ(out.result.iterations, 30) << out.result.message;
    EXPECT_NE(out.result.message.find("no better"), std::string::npos) << out.result.message;
    EXPECT_LT(out.result.residual, residual(rows.assemble(false), start));
  }
}

// The budget test: a cold 1200-row friction pyramid on which dantzig pivots for ~1.4 s (Release,
// measured on the development machine; ~6000 pivots). With a 20 ms budget `auto` must come back
// within a small multiple of it, say time-limit, and return an answer strictly better than the
// start (doing nothing).
test::BoxPyramid bigPyramid() {
  test::PyramidSpec spec;
  spec.levels = 10;
  return test::BoxPyramid(spec);
}

TEST(TimeBudget, AutoOnALargeIslandReturnsItsBestAnswerInTime) {
  const test::BoxPyramid pyramid = bigPyramid();
  const RowSystem& rows = pyramid.rows();
  ASSERT_GT(rows.size(), Policy().smallIslandRows);
  RowSolverSettings s;  // auto, fallback pgs
  s.options.tolerance = 1e-8;
  s.timeBudget = 0.02;
  RowSolver solver(s);
  const Vector start = Vector::Zero(rows.size());
  const double startResidual = residual(rows.assemble(true), start);
  solver.beginStep();
  Vector x;
  const double t0 = nowSeconds();
  const IslandSolve out = solver.solve(rows, start, x);
  const double elapsed = nowSeconds() - t0;
  // Slack for what cannot be interrupted (assembly, dantzig's first factorization) and for a
  // loaded or sanitized CI machine; still far from dantzig's seconds.
  EXPECT_LT(elapsed, 0.25 * test::kTimingSlack);
  EXPECT_EQ(out.requested, kLargeIslandSolver);
  EXPECT_EQ(out.result.status, Status::TimeLimit) << out.result.message;
  // Cut short of 1e-8, the answer may still pass the acceptance limit (1e-3).
  EXPECT_EQ(out.accepted, out.result.residual <= s.acceptResidual) << out.result.message;
  const double r = residual(rows.assemble(true), x);
  EXPECT_NEAR(out.result.residual, r, 1e-12);
  EXPECT_LT(r, startResidual) << out.result.message;
}

TEST(TimeBudget, LaterIslandsOfAStepGetTheMinimalShareAndACheapSolver) {
  const test::BoxPyramid pyramid = bigPyramid();
  const RowSystem& rows = pyramid.rows();
  RowSolverSettings s;
  s.options.tolerance = 1e-8;
  s.timeBudget = 0.02;
  RowSolver solver(s);
  const Vector start = Vector::Zero(rows.size());
  solver.beginStep();
  Vector x;
  solver.solve(rows, start, x, 1);  // spends the step's budget
  EXPECT_NEAR(solver.islandBudget(nowSeconds()), s.minShare * s.timeBudget, 1e-12);
  const double t0 = nowSeconds();
  const IslandSolve second = solver.solve(rows, start, x, 2);
  EXPECT_LT(nowSeconds() - t0,
            0.1 * test::kTimingSlack);  // two 1 ms shares, plus slack for a loaded machine
  EXPECT_EQ(second.requested, "pgs");   // the budget is spent: the cheap method
  EXPECT_LT(second.result.residual, residual(rows.assemble(true), start));
  // A new step has the whole budget again.
  solver.beginStep();
  EXPECT_DOUBLE_EQ(solver.islandBudget(nowSeconds()), s.timeBudget);
}

TEST(TimeBudget, EverySolverStopsInTimeAndNeverReturnsWorseThanItsStart) {
  const test::BoxPyramid pyramid = bigPyramid();
  const Problem p = pyramid.rows().assemble(true);
  const double startResidual = residual(p, Vector::Zero(p.size()));
  for (const char* name : {"dantzig", "pgs", "auto"}) {
    std::unique_ptr<Solver> solver = makeSolver(name);
    solver->options().tolerance = 1e-300;  // unreachable: only the budget stops pgs
    solver->options().maxIterations = 1 << 30;
    solver->options().timeBudget = 0.02;
    Vector x;
    const Result r = solver->solve(p, x);
    EXPECT_LT(r.seconds, 0.25 * test::kTimingSlack) << name;
    EXPECT_EQ(r.status, Status::TimeLimit) << name << ": " << r.message;
    EXPECT_LE(residual(p, x), startResidual) << name;
  }
}

TEST(TimeBudget, SettingsAreChecked) {
  RowSolverSettings s;
  s.timeBudget = -1;
  EXPECT_THROW(RowSolver{s}, std::invalid_argument);
  s.timeBudget = 0.01;
  s.minShare = 0;
  EXPECT_THROW(RowSolver{s}, std::invalid_argument);
  RowSolver ok;
  EXPECT_THROW(ok.setTimeBudget(std::nan("")), std::invalid_argument);
  ok.setTimeBudget(0);
  EXPECT_EQ(ok.islandBudget(nowSeconds()), 0);
}

TEST(LemkeLimits, PivotLimitGivesUpWithAClearMessageAndTheStart) {
  test::Generator g(13);
  const test::KnownProblem kp = g.standard(g.spd(40));
  LemkeSolver lemke;
  lemke.options().maxPivots = 3;
  Vector x;
  const Result r = lemke.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::MaxIterations);
  EXPECT_NE(r.message.find("gave up: pivot limit 3 reached"), std::string::npos) << r.message;
  EXPECT_TRUE(x.isZero(0.0));  // the start
}

TEST(LemkeLimits, TimeBudgetGivesUpWithAClearMessage) {
  test::Generator g(15);
  const test::KnownProblem kp = g.standard(g.spd(400));
  LemkeSolver lemke;
  lemke.options().timeBudget = 0.002;  // ~400 pivots of O(m^2) take tens of ms
  Vector x;
  const Result r = lemke.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::TimeLimit);
  EXPECT_LT(r.seconds, 0.1 * test::kTimingSlack);
  EXPECT_NE(r.message.find("gave up when the time budget"), std::string::npos) << r.message;
  EXPECT_LE(residual(kp.problem, x), residual(kp.problem, Vector::Zero(400)));
}

TEST(LemkeLimits, RefusesATableauBeyondItsRowLimit) {
  test::Generator g(14);
  const test::KnownProblem kp = g.standard(g.spd(30));
  LemkeSolver lemke;
  lemke.maxRows = 20;
  Vector x = Vector::Constant(30, 7.0);
  const Result r = lemke.solve(kp.problem, x);
  EXPECT_EQ(r.status, Status::Unsupported);
  EXPECT_NE(r.message.find("LemkeSolver::maxRows = 20"), std::string::npos) << r.message;
  EXPECT_TRUE(x.isApproxToConstant(7.0));  // untouched
}

// Auto on a large island: newton limited to ten damped steps stops short of the tolerance on a
// cold pyramid (it needs 161); its pivoting phase (newton.hpp) finishes from there and ends
// exact, with or without a time budget, and the answer is newton's own (no second solver). With
// the phase off (RowSolverSettings::newton) the damped steps' answer stands, not converged.
IslandSolve solveLargeIsland(double timeBudget, Vector& x, int pivotingSteps = -1) {
  test::PyramidSpec spec;
  spec.levels = 5;
  const test::BoxPyramid pyramid(spec);
  RowSolverSettings s;                 // auto
  s.policy.smallIslandRows = 10;       // newton for this island
  s.policy.singularIslandSolver = "";  // newton's answer as it ends
  s.options.maxIterations = 10;        // newton's damped steps
  s.fallback = "";
  s.timeBudget = timeBudget;
  if (pivotingSteps >= 0) s.newton.pivotingSteps = s.newton.bodyPivotingSteps = pivotingSteps;
  RowSolver solver(s);
  return solver.solve(pyramid.rows(), Vector::Zero(pyramid.rows().size()), x);
}

TEST(AutoLargeIsland, NewtonsPivotingPhaseFinishesWhatItsDampedStepsLeftShort) {
  Vector budgeted, unbudgeted;
  for (const double budget : {10.0, 0.0}) {
    Vector& x = budget > 0 ? budgeted : unbudgeted;
    const IslandSolve out = solveLargeIsland(budget, x);
    EXPECT_EQ(out.requested, "newton");
    EXPECT_EQ(out.choice, "newton");
    EXPECT_EQ(out.result.status, Status::Converged) << out.result.message;
    EXPECT_LE(out.result.residual, kDefaultIslandTolerance);
    EXPECT_NE(out.result.message.find("10 Newton steps"), std::string::npos) << out.result.message;
    EXPECT_NE(out.result.message.find("block pivoting settled"), std::string::npos)
        << out.result.message;
  }
  EXPECT_EQ(budgeted, unbudgeted);  // the same answer bit for bit
  Vector off;
  const IslandSolve damped = solveLargeIsland(10, off, 0);
  EXPECT_EQ(damped.choice, "newton");
  EXPECT_NE(damped.result.status, Status::Converged) << damped.result.message;
  EXPECT_GT(damped.result.residual, kDefaultIslandTolerance);
  EXPECT_EQ(damped.result.message.find("block pivoting"), std::string::npos);
}

}  // namespace
}  // namespace mlcp
