#include "mlcp/bullet/constraint_solver.hpp"

#include <cmath>
#include <stdexcept>

#include "mlcp/bullet/multibody_solver.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::bullet {

namespace {

// Larger is worse; the step reports its worst island.
int severity(Status s) {
  switch (s) {
    case Status::Converged: return 0;
    case Status::LeastSquares:
    case Status::MaxIterations: return 1;
    case Status::TimeLimit: return 2;
    case Status::Failed: return 3;
    case Status::Unsupported: return 4;
    case Status::InvalidInput: return 5;
    case Status::NumericalIssue: return 6;
  }
  return 6;
}

void worst(StepStats& into, const StepStats& from) {
  if (std::isnan(into.residual) || from.residual > into.residual) into.residual = from.residual;
  if (severity(from.status) > severity(into.status)) into.status = from.status;
  if (into.message.empty()) into.message = from.message;
}

constexpr const char* kUnservedWorld =
    "mlcp::bullet::ConstraintSolver: the world stepped without calling solveGroup, so this "
    "solver solves nothing in it. A btMultiBodyDynamicsWorld solves through its "
    "btMultiBodyConstraintSolver, which setConstraintSolver does not replace: use "
    "mlcp::bullet::install(world, solver), which sets the solver's MultiBodySolver there. For a "
    "btDiscreteDynamicsWorldMt use mlcp::bullet::install with a SolverPool "
    "(mlcp/bullet/worlds.hpp)";

}  // namespace

void accumulate(StepStats& into, const StepStats& from) {
  into.groups += from.groups;
  into.islands += from.islands;
  into.rows += from.rows;
  into.inertRows += from.inertRows;
  into.iterations += from.iterations;
  into.seconds += from.seconds;
  into.measureSeconds += from.measureSeconds;
  into.assembleSeconds += from.assembleSeconds;
  into.fallbacks += from.fallbacks;
  into.failures += from.failures;
  into.choices.add(from.choices);
  into.packedIslands += from.packedIslands;
  into.coneIslands += from.coneIslands;
  into.screened.add(from.screened);
  worst(into, from);
}

ConstraintSolver::ConstraintSolver(const Settings& settings) : settings_(settings) {
  si_ = settings_.solver == "si";
  if (si_ && settings_.friction == FrictionModel::Cone)
    throw std::invalid_argument(
        "mlcp::bullet::ConstraintSolver: friction 'cone' needs a core solver; si is Bullet's own "
        "(box friction)");
  if (const std::string why =
          frictionSettingsError(settings_.friction, settings_.frictionDirections, settings_.solver);
      !why.empty())
    throw std::invalid_argument("mlcp::bullet::ConstraintSolver: " + why);
  RowSolverSettings rs = settings_;
  if (si_) rs.solver = "pgs";  // only the fallback name is checked
  // The same sweeps from the same start give the same answer: no second run.
  if (settings_.engineIterations && rs.fallback == settings_.solver) rs.fallback.clear();
  try {
    auto rows = std::make_unique<RowSolver>(rs);
    if (!si_) rows_ = std::move(rows);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("mlcp::bullet::ConstraintSolver: " + std::string(e.what()) +
                                ", or si");
  }
}

ConstraintSolver::~ConstraintSolver() = default;

MultiBodySolver& ConstraintSolver::multiBodySolver() {
  if (!multiBody_) multiBody_ = std::make_unique<MultiBodySolver>(*this);
  return *multiBody_;
}

btScalar ConstraintSolver::solveGroup(btCollisionObject** bodies, int numBodies,
                                      btPersistentManifold** manifolds, int numManifolds,
                                      btTypedConstraint** constraints, int numConstraints,
                                      const btContactSolverInfo& info, btIDebugDraw* debugDrawer,
                                      btDispatcher* dispatcher) {
  std::lock_guard<std::mutex> lock(mutex_);
  return btSequentialImpulseConstraintSolver::solveGroup(bodies, numBodies, manifolds, numManifolds,
                                                         constraints, numConstraints, info,
                                                         debugDrawer, dispatcher);
}

void ConstraintSolver::prepareSolve(int numBodies, int numManifolds) {
  std::lock_guard<std::mutex> lock(mutex_);
  btSequentialImpulseConstraintSolver::prepareSolve(numBodies, numManifolds);
  openStep(numBodies);
}

void ConstraintSolver::openStep(int numBodies) {
  if (stepOpen_) finishStep();
  current_ = StepStats();
  records_.clear();
  builder_.newStep();
  if (rows_) rows_->beginStep();  // the time budget is per step
  stepOpen_ = true;
  stepBodies_ = numBodies;
}

void ConstraintSolver::allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) {
  std::lock_guard<std::mutex> lock(mutex_);
  btSequentialImpulseConstraintSolver::allSolved(info, debugDrawer);
  const bool stepped = stepOpen_;
  if (stepOpen_) finishStep();
  if (stepped) checkWorld();
}

void ConstraintSolver::checkWorld() {
  if (!worldChecked_ && stepBodies_ > 0) {
    worldChecked_ = true;
    unserved_ = last_.groups == 0;
  }
  if (unserved_) throw std::logic_error(kUnservedWorld);
}

void ConstraintSolver::finishStep() {
  stepOpen_ = false;
  last_ = current_;
  accumulate(totals_, current_);
}

void ConstraintSolver::record(const Result& r, int rows, const std::string& choice) {
  current_.choices.add(choice);
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
  if (ownStep) openStep(numBodies);
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
      builder_.build(rows, info, settings_.cfm, Start::AppliedImpulse);  // SI's answer
      measureSi(info.m_numIterations);
      current_.measureSeconds += nowSeconds() - t1;
    } else {
      current_.residual = kNotComputed;
      current_.status = Status::MaxIterations;
    }
  } else {
    useEngineSweeps(info);
    const Start start = !settings_.warmStart ? Start::Zero
                        : settings_.siStart  ? Start::AppliedImpulse
                                             : Start::CachedImpulse;
    fastPgs_ = settings_.solver == "pgs" && settings_.packInPlace && !settings_.keepIslands &&
               !rows_->capturing();
    builder_.build(rows, info, settings_.cfm, start, !fastPgs_);
    current_.inertRows += builder_.inertRows();
    for (int k = 0; k < builder_.count(); ++k) {
      Island& island = builder_.island(k);
      solveIsland(island, k, false);
      if (info.m_splitImpulse && island.hasSplit) solveIsland(island, k, true);
    }
    current_.seconds += nowSeconds() - t0;
  }
  if (ownStep) finishStep();
  return 0;
}

void ConstraintSolver::useEngineSweeps(const btContactSolverInfo& info) {
  rows_->setEngineSweeps(info.m_numIterations);
  if (!settings_.engineIterations) return;
  // pgs/gs as SI runs them: a fixed sweep count, the residual checked once, at the end.
  for (auto [name, options] : {std::pair(&settings_.solver, &rows_->options()),
                               std::pair(&settings_.fallback, &rows_->fallbackOptions())})
    if (*name == "pgs" || *name == "gs") useEngineIterations(*options, info.m_numIterations);
}

void ConstraintSolver::recordSi(const RowSystem& s, const Vector& answer, int sweeps) {
  Result r;
  r.status = Status::MaxIterations;
  r.iterations = sweeps;
  const Accuracy a = accuracy(answer, s.slack(answer), s.lo, s.hi, s.findex,
                              s.b.size() ? s.b.lpNorm<Eigen::Infinity>() : 0.0);
  applyAccuracy(r, a, settings_.options.tolerance);
  record(r, s.size(), "si");
  if (settings_.keepIslands) records_.push_back({s, answer, answer, r, "si", false, false});
}

void ConstraintSolver::recordSolve(const IslandSolve& solved, int rows) {
  const Result& result = solved.result;
  current_.assembleSeconds += solved.assembleSeconds;
  current_.fallbacks += solved.fellBack;
  current_.screened.add(solved.screened);
  current_.failures += !solved.accepted;
  current_.coneIslands += solved.friction == FrictionModel::Cone;
  if (current_.message.empty() && (solved.fellBack || !solved.accepted))
    current_.message = result.message;
  record(result, rows, solved.choice);
}

void ConstraintSolver::measureSi(int sweeps) {
  current_.inertRows += builder_.inertRows();
  for (int k = 0; k < builder_.count(); ++k) {
    Island& island = builder_.island(k);
    recordSi(island.system, island.start, sweeps);
  }
}

bool ConstraintSolver::solveIslandFast(Island& island, bool split) {
  const double t0 = nowSeconds();
  pgs_.options() = rows_->options();
  pgs_.options().warmStart = true;  // as RowSolver runs it: from the start given
  if (const double share = rows_->islandBudget(t0); share > 0) {  // the step's budget
    pgs_.options().timeBudget = share;
    pgs_.options().budgetStart = t0;
  }
  const int n = static_cast<int>(island.rows.size());
  Result r = builder_.solvePgs(pgs_, island, split, x_);
  // Not finite, or a row RowSolver's screening fixes: the screened rows' path.
  if (!pgs_.velocityChanges() || island.beyondReach) return false;
  // A rejected answer goes on to RowSolver only for its fallback: without one (engineIterations
  // clears a pgs fallback of pgs) it would run the same sweeps from the same start again.
  const bool accepted = acceptable(r, settings_.acceptResidual);
  if (!accepted && !rows_->settings().fallback.empty()) return false;
  r.solver = "pgs";
  r.seconds = nowSeconds() - t0;
  record(r, n, "pgs");
  current_.packedIslands += 1;
  if (!accepted) {
    current_.failures += 1;
    if (current_.message.empty())
      current_.message = "pgs rejected (" + std::string(toString(r.status)) + ", residual " +
                         std::to_string(r.residual) + "); no fallback";
  }
  if (island.perRowWriteBack) {
    applyPerRow(island, x_, split);
    if (!split) builder_.remember(island, x_);
    return true;
  }
  // Store impulses: the bodies take M^-1 J^T (x - applied) at once (RowPgs::velocityChange),
  // what the per-row internalApplyImpulse calls sum to.
  for (int k = 0; k < static_cast<int>(island.solverBody.size()); ++k) {
    btSolverBody& body = m_tmpSolverBodyPool[island.solverBody[k]];
    const Vector6 dv = pgs_.velocityChange(k);
    const btVector3 linear(dv[0], dv[1], dv[2]), angular(dv[3], dv[4], dv[5]);
    if (split) {
      body.internalGetPushVelocity() += linear;
      body.internalGetTurnVelocity() += angular;
    } else {
      body.internalGetDeltaLinearVelocity() += linear;
      body.internalGetDeltaAngularVelocity() += angular;
    }
  }
  if (split) {
    for (int i = 0; i < n; ++i) island.rows[i]->m_appliedPushImpulse = static_cast<btScalar>(x_[i]);
  } else {
    builder_.remember(island, x_, true);
  }
  return true;
}

void ConstraintSolver::applyPerRow(Island& island, const Vector& x, bool split) {
  const int n = static_cast<int>(island.rows.size());
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
}

void ConstraintSolver::solveIsland(Island& island, std::uint64_t key, bool split) {
  if (fastPgs_) {
    if (solveIslandFast(island, split)) return;
    builder_.fillSystem(island);
  }
  RowSystem& s = island.system;
  const int n = s.size();
  // The split problem shares A and the bounds; only b and the start differ.
  if (split) s.b.swap(island.splitB);
  const Vector& start = split ? island.splitStart : island.start;
  const IslandSolve solved = rows_->solve(s, start, x_, key);
  const Result& result = solved.result;
  recordSolve(solved, n);

  // Store impulses: the change from the start goes through Bullet's own body update.
  const Vector& x = x_;
  applyPerRow(island, x, split);
  if (!split) builder_.remember(island, x);
  if (settings_.keepIslands)
    records_.push_back({s, start, x, result, solved.choice, split, solved.fellBack});
  if (split) s.b.swap(island.splitB);
}

}  // namespace mlcp::bullet
