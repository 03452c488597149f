#include "mlcp/bullet/constraint_solver.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::bullet {

namespace {

// Larger is worse; the step reports its worst island.
int severity(Status s) {
  switch (s) {
    case Status::Converged: return 0;
    case Status::MaxIterations: return 1;
    case Status::TimeLimit: return 2;
    case Status::Failed: return 3;
    case Status::Unsupported: return 4;
    case Status::InvalidInput: return 5;
    case Status::NumericalIssue: return 6;
  }
  return 6;
}

// "pgs" runs on the rows (no matrix); any other name is a core solver fed an assembled A.
std::unique_ptr<Solver> make(const std::string& name, bool& rowPgs) {
  rowPgs = name == "pgs";
  if (rowPgs) return nullptr;
  std::string error;
  std::unique_ptr<Solver> s = makeSolver(name, &error);
  if (!s) throw std::invalid_argument("mlcp::bullet::ConstraintSolver: " + error + ", or si");
  return s;
}

void worst(StepStats& into, const StepStats& from) {
  if (std::isnan(into.residual) || from.residual > into.residual) into.residual = from.residual;
  if (severity(from.status) > severity(into.status)) into.status = from.status;
  if (into.message.empty()) into.message = from.message;
}

}  // namespace

bool acceptable(const Result& r, double acceptResidual) {
  if (r.status == Status::InvalidInput || r.status == Status::Unsupported) return false;
  return std::isfinite(r.residual) && r.residual <= acceptResidual;
}

ConstraintSolver::ConstraintSolver(const Settings& settings) : settings_(settings) {
  si_ = settings_.solver == "si";
  if (!si_) primary_ = make(settings_.solver, primaryIsRowPgs_);
  if (!settings_.fallback.empty()) secondary_ = make(settings_.fallback, secondaryIsRowPgs_);
  if (!(settings_.acceptResidual >= 0))
    throw std::invalid_argument("mlcp::bullet::ConstraintSolver: acceptResidual must be >= 0");
}

ConstraintSolver::~ConstraintSolver() = default;

void ConstraintSolver::prepareSolve(int numBodies, int numManifolds) {
  btSequentialImpulseConstraintSolver::prepareSolve(numBodies, numManifolds);
  if (stepOpen_) finishStep();
  current_ = StepStats();
  records_.clear();
  stepOpen_ = true;
}

void ConstraintSolver::allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) {
  btSequentialImpulseConstraintSolver::allSolved(info, debugDrawer);
  if (stepOpen_) finishStep();
}

void ConstraintSolver::finishStep() {
  stepOpen_ = false;
  last_ = current_;
  totals_.groups += current_.groups;
  totals_.islands += current_.islands;
  totals_.rows += current_.rows;
  totals_.inertRows += current_.inertRows;
  totals_.iterations += current_.iterations;
  totals_.seconds += current_.seconds;
  totals_.measureSeconds += current_.measureSeconds;
  totals_.assembleSeconds += current_.assembleSeconds;
  totals_.fallbacks += current_.fallbacks;
  totals_.failures += current_.failures;
  worst(totals_, current_);
}

void ConstraintSolver::record(const Result& r, int rows) {
  StepStats one;
  one.residual = r.residual;
  one.status = r.status;
  current_.islands += 1;
  current_.rows += rows;
  current_.iterations += r.iterations;
  worst(current_, one);
}

btScalar ConstraintSolver::solveGroupCacheFriendlyIterations(
    btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds, int numManifolds,
    btTypedConstraint** constraints, int numConstraints, const btContactSolverInfo& info,
    btIDebugDraw* debugDrawer) {
  // A caller that does not bracket steps with prepareSolve/allSolved gets one step per group.
  const bool ownStep = !stepOpen_;
  if (ownStep) prepareSolve(numBodies, numManifolds);
  current_.groups += 1;
  const double t0 = nowSeconds();
  const BulletRows rows{
      &m_tmpSolverBodyPool, &m_tmpSolverNonContactConstraintPool, &m_tmpSolverContactConstraintPool,
      &m_tmpSolverContactFrictionConstraintPool, &m_tmpSolverContactRollingFrictionConstraintPool};
  if (si_) {
    btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyIterations(
        bodies, numBodies, manifolds, numManifolds, constraints, numConstraints, info, debugDrawer);
    current_.seconds += nowSeconds() - t0;
    if (settings_.measureSi || settings_.keepIslands) {
      const double t1 = nowSeconds();
      builder_.build(rows, info, settings_.cfm, true);  // start = SI's final impulses
      measureSi(info.m_numIterations);
      current_.measureSeconds += nowSeconds() - t1;
    } else {
      current_.residual = kNotComputed;
      current_.status = Status::MaxIterations;
    }
  } else {
    builder_.build(rows, info, settings_.cfm, settings_.warmStart);
    current_.inertRows += builder_.inertRows();
    for (int k = 0; k < builder_.count(); ++k) {
      Island& island = builder_.island(k);
      solveIsland(island, info, false);
      if (info.m_splitImpulse && island.hasSplit) solveIsland(island, info, true);
    }
    current_.seconds += nowSeconds() - t0;
  }
  if (ownStep) finishStep();
  return 0;
}

void ConstraintSolver::measureSi(int sweeps) {
  current_.inertRows += builder_.inertRows();
  for (int k = 0; k < builder_.count(); ++k) {
    Island& island = builder_.island(k);
    const RowSystem& s = island.system;
    Result r;
    r.status = Status::MaxIterations;
    r.iterations = sweeps;
    const Accuracy a = accuracy(island.start, s.slack(island.start), s.lo, s.hi, s.findex,
                                s.b.size() ? s.b.lpNorm<Eigen::Infinity>() : 0.0);
    applyAccuracy(r, a, settings_.options.tolerance);
    record(r, s.size());
    if (settings_.keepIslands)
      records_.push_back({s, island.start, island.start, r, "si", false, false});
  }
}

void ConstraintSolver::solveIsland(Island& island, const btContactSolverInfo& info, bool split) {
  RowSystem& s = island.system;
  const int n = s.size();
  // The split problem shares A and the bounds; only b and the start differ.
  if (split) s.b.swap(island.splitB);
  const Vector& start = split ? island.splitStart : island.start;

  std::optional<Problem> assembled;
  auto run = [&](Solver* solver, bool rowPgs, Options o, Vector& x) {
    o.warmStart = true;
    if (settings_.bulletIterations && (rowPgs || std::string(solver->name()) == "gs")) {
      // Fixed sweep count like SI: check the residual once, at the end.
      o.maxIterations = info.m_numIterations;
      o.checkEvery = o.maxIterations;
    }
    Result r;
    if (rowPgs) {
      RowPgs pgs;
      pgs.options() = o;
      x = start;
      r = pgs.solve(s, x);
    } else {
      if (!assembled) {
        const double t0 = nowSeconds();
        assembled = s.assemble(n > settings_.denseMaxRows);
        current_.assembleSeconds += nowSeconds() - t0;
      }
      solver->setOptions(o);
      r = solver->solveWithGuess(*assembled, start, x);
    }
    if (r.status == Status::InvalidInput || r.status == Status::Unsupported) x = start;
    return r;
  };

  const char* used = si_ ? "si" : settings_.solver.c_str();
  Result result = run(primary_.get(), primaryIsRowPgs_, settings_.options, xPrimary_);
  Vector* answer = &xPrimary_;
  bool fellBack = false;
  if (!acceptable(result, settings_.acceptResidual)) {
    current_.fallbacks += 1;
    if (current_.message.empty())
      current_.message = settings_.solver + ": " + toString(result.status) + ", " + result.message;
    fellBack = true;
    if (secondary_ || secondaryIsRowPgs_) {
      Result second =
          run(secondary_.get(), secondaryIsRowPgs_, settings_.fallbackOptions, xSecondary_);
      const bool better = std::isfinite(second.residual) &&
                          !(std::isfinite(result.residual) && result.residual <= second.residual);
      if (!acceptable(second, settings_.acceptResidual)) current_.failures += 1;
      if (better || acceptable(second, settings_.acceptResidual)) {
        result = second;
        answer = &xSecondary_;
        used = settings_.fallback.c_str();
      }
    } else {
      current_.failures += 1;
    }
    if (!std::isfinite(result.residual)) {
      // Nothing usable: keep the start (no impulse change).
      xPrimary_ = start;
      answer = &xPrimary_;
    }
  }
  record(result, n);

  // Store impulses: the change from the start goes through Bullet's own body update.
  const Vector& x = *answer;
  for (int i = 0; i < n; ++i) {
    btSolverConstraint& c = *island.rows[i];
    btSolverBody& a = m_tmpSolverBodyPool[c.m_solverBodyIdA];
    btSolverBody& b = m_tmpSolverBodyPool[c.m_solverBodyIdB];
    const btScalar xi = static_cast<btScalar>(x[i]);
    if (split) {
      const btScalar delta = xi - c.m_appliedPushImpulse;
      a.internalApplyPushImpulse(c.m_contactNormal1 * a.internalGetInvMass(), c.m_angularComponentA,
                                 delta);
      b.internalApplyPushImpulse(c.m_contactNormal2 * b.internalGetInvMass(), c.m_angularComponentB,
                                 delta);
      c.m_appliedPushImpulse = xi;
    } else {
      const btScalar delta = xi - c.m_appliedImpulse;
      a.internalApplyImpulse(c.m_contactNormal1 * a.internalGetInvMass(), c.m_angularComponentA,
                             delta);
      b.internalApplyImpulse(c.m_contactNormal2 * b.internalGetInvMass(), c.m_angularComponentB,
                             delta);
      c.m_appliedImpulse = xi;
    }
  }
  if (settings_.keepIslands) records_.push_back({s, start, x, result, used, split, fellBack});
  if (split) s.b.swap(island.splitB);
}

}  // namespace mlcp::bullet
