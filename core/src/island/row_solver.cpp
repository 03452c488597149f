#include "mlcp/island/row_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "island/row_solver_impl.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "short_number.hpp"

namespace mlcp {

using detail::shortNumber;

ProblemClass classify(const RowSystem& rows) {
  return classifyBounds(rows.lo, rows.hi, rows.findex);
}

// --- choice counts --------------------------------------------------------------------------

void ChoiceCounts::add(const std::string& choice, int count) {
  auto it =
      std::lower_bound(counts_.begin(), counts_.end(), choice,
                       [](const auto& entry, const std::string& c) { return entry.first < c; });
  if (it != counts_.end() && it->first == choice)
    it->second += count;
  else
    counts_.insert(it, {choice, count});
}

void ChoiceCounts::add(const ChoiceCounts& other) {
  for (const auto& [choice, count] : other.counts_) add(choice, count);
}

int ChoiceCounts::count(const std::string& choice) const {
  for (const auto& [name, n] : counts_)
    if (name == choice) return n;
  return 0;
}

int ChoiceCounts::total() const {
  int n = 0;
  for (const auto& entry : counts_) n += entry.second;
  return n;
}

std::string ChoiceCounts::toString() const {
  std::string s;
  for (const auto& [name, n] : counts_)
    s += (s.empty() ? "" : " ") + name + ":" + std::to_string(n);
  return s;
}

// --- the row solver -------------------------------------------------------------------------

namespace {
// The largest residual of a start that stage 3 returns unsolved: kExactStart times the tolerance,
// at most kExactStartLimit. Exact methods' answers stay exact: the stock pivoting solvers' answers
// are at 1e-16..1e-13, ours within 1e-12 of theirs (the engine tests), and a last answer merely
// within the tolerance is solved again (returned as it is, each step's answer would lag its
// problem by up to the tolerance).
constexpr double kExactStart = 1e-4;
constexpr double kExactStartLimit = 1e-12;
// IslandSolve::choice of an island that the start answered (no solver ran).
constexpr const char* kStartChoice = "start";
// Stage 5's trigger for an acceptable answer: some body's linear velocity change exceeds this
// multiple of ||b||_inf (the largest velocity error a row states). A sane answer changes a
// body's velocity by about the errors of the rows on it (a landing ragdoll: 1-2x); an answer
// along nearly dependent rows, exact to 1e-7, by thousands of times. Dimensionless.
constexpr double kSpeedFactor = 10;
// Stage 0's bound on a start: it is dropped when it changes some body's linear velocity by more
// than this multiple of ||b||_inf. A step's answer changes velocities by up to ~10 ||b|| where
// the rows are unsettled (ODE's 10-box stack at QuickStep's 7 sweeps: a start above 10x, rightly
// kept); last step's impulses along nearly dependent rows matched to rows that moved, by 1e5 and
// more (Bullet's ragdolls: 9e6 m/s against ||b|| = 21). Dimensionless.
constexpr double kStartSpeedFactor = 1000;
// Stage 5's bound: a judged answer is applied when its impulse energy is at most this multiple
// of pgs's (keepSafe), 2x in speed: "no worse than the engine's own method at its cost". 100
// (10x in speed) let an unsettled answer on Bullet's Bridge through that threw the planks in
// the next step; 4 keeps every example within twice the stock run's fastest body (docs/
// benchmarks.md). Dimensionless.
constexpr double kEnergyFactor = 4;
}  // namespace

// What is kept per island: its assembled-problem solvers by name, when it was last solved, how
// many more `auto` solves run pgs first after a pivoting answer broke down, and how many of its
// last `auto` solves in a row the time budget cut.
struct RowSolver::Impl::Slot {
  std::vector<std::pair<std::string, std::unique_ptr<Solver>>> solvers;
  std::uint64_t lastUse = 0;
  int pgsFirst = 0;
  int cutsInRow = 0;
  // More solves by the large-island solver under the engine-relative cap: set after an uncapped
  // one ended short of the tolerance.
  int cappedSolves = 0;
  // More solves by the policy's singular-island solver first: set after an exact method ended
  // short of the tolerance on the island's contact rows.
  int singularFirst = 0;
  // More dantzig solves on A + delta I at once (DantzigParams::regularised): set after one broke
  // down on A and was retried regularised. A resting pile breaks down every step (coplanar
  // contacts without cfm), and the attempt on A before the retry cost as much as the retry.
  int regulariseFirst = 0;
};

namespace {
// Islands not solved for this many calls lose their workspaces (once there are this many).
constexpr std::size_t kSlotLimit = 1024;
// Solves of an island that go to dantzig's regularised problem at once after a breakdown before
// the plain problem is tried again (the contacts may have changed). The cost of a wrong guess is
// one cold solve on A + delta I where a warm one on A would have done.
constexpr int kRegulariseSolves = 8;
}  // namespace

namespace {
// s == literal, sizes first (std::string == const char* measures the literal on every call,
// and solve() compares names on every island).
template <std::size_t N>
bool equals(const std::string& s, const char (&literal)[N]) {
  return s.size() == N - 1 && std::memcmp(s.data(), literal, N - 1) == 0;
}

}  // namespace

bool RowSolver::known(const std::string& name) {
  return name == "auto" || name == "pgs" || makeSolver(name) != nullptr;
}

RowSolver::Impl::Impl(const RowSolverSettings& settings) : settings_(settings) {
  auto refuse = [](const char* what, const std::string& name, const char* extra) {
    throw std::invalid_argument("mlcp::RowSolver: unknown " + std::string(what) + " '" + name +
                                "' (known: " + solverNames() + extra + ")");
  };
  if (!known(settings_.solver)) refuse("solver", settings_.solver, "");
  if (!settings_.fallback.empty() && (settings_.fallback == "auto" || !known(settings_.fallback)))
    refuse("fallback", settings_.fallback, "; auto only as the primary");
  if (!(settings_.acceptResidual >= 0))
    throw std::invalid_argument("mlcp::RowSolver: acceptResidual must be >= 0");
  setTimeBudget(settings_.timeBudget);
  if (!(settings_.minShare > 0 && settings_.minShare <= 1))
    throw std::invalid_argument("mlcp::RowSolver: minShare must be in (0, 1]");
  if (!(settings_.engineCostFactor == 0 ||
        (settings_.engineCostFactor >= 1 && std::isfinite(settings_.engineCostFactor))))
    throw std::invalid_argument("mlcp::RowSolver: engineCostFactor must be 0 or finite and >= 1");
  if (const std::string why =
          frictionSettingsError(settings_.friction, settings_.frictionDirections, settings_.solver);
      !why.empty())
    throw std::invalid_argument("mlcp::RowSolver: " + why);
}

// The step's budget is spent when this island's share is down to the minimal one (policy.hpp:
// auto then takes pgs, which improves any start in any share).
bool RowSolver::Impl::budgetSpent(double share) const {
  return share > 0 && share <= settings_.minShare * settings_.timeBudget;
}

void RowSolver::Impl::setTimeBudget(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds))
    throw std::invalid_argument("mlcp::RowSolver: timeBudget must be finite and >= 0 seconds");
  settings_.timeBudget = seconds;
}

double RowSolver::Impl::islandBudget(double now) {
  const double budget = settings_.timeBudget;
  if (!(budget > 0)) return 0;
  if (!stepOpen_ || stepPending_) {
    stepStart_ = now;
    stepPending_ = false;
  }
  return std::max(budget - (now - stepStart_), settings_.minShare * budget);
}

namespace {
// o bounded by `share` seconds from `start` as well (the tighter of the two budgets).
Options withBudget(const Options& o, double share, double start) {
  Options b = o;
  if (share > 0 && (!(o.timeBudget > 0) || share < o.timeBudget)) {
    b.timeBudget = share;
    b.budgetStart = start;
  }
  return b;
}
}  // namespace

void RowSolver::Impl::setCapture(const std::string& prefix) {
  capturePrefix_ = prefix;
  captured_.clear();
}

RowSolver::Impl::Slot& RowSolver::Impl::slot(std::uint64_t key) {
  // The same island as last time (one island, or a run of steps of it): no hash lookup.
  if (lastSlot_ && key == lastKey_) {
    lastSlot_->lastUse = calls_;
    return *lastSlot_;
  }
  auto it = slots_.find(key);
  if (it == slots_.end()) {
    if (slots_.size() >= kSlotLimit) {
      // Forget islands that have not been solved for a while (they merged, split or slept).
      lastSlot_ = nullptr;
      for (auto old = slots_.begin(); old != slots_.end();)
        old = old->second->lastUse + kSlotLimit < calls_ ? slots_.erase(old) : std::next(old);
    }
    it = slots_.emplace(key, std::make_unique<Slot>()).first;
  }
  it->second->lastUse = calls_;
  lastKey_ = key;
  lastSlot_ = it->second.get();
  return *it->second;
}

Solver* RowSolver::Impl::assembledSolver(Slot& island, const std::string& name, const char* tag) {
  // The slot's key is tag + name, matched without building it (this runs every island solve).
  const std::string_view prefix(tag);
  for (auto& [n, solver] : island.solvers) {
    const std::string_view key(n);
    if (key.size() == prefix.size() + name.size() && key.substr(0, prefix.size()) == prefix &&
        key.substr(prefix.size()) == name)
      return solver.get();
  }
  island.solvers.emplace_back(tag + name, makeSolver(name));
  if (auto* newton = dynamic_cast<NewtonSolver*>(island.solvers.back().second.get()))
    newton->params() = settings_.newton;
  // solve() times the whole island (assembly, solve, check) with fewer clock reads.
  island.solvers.back().second->setTimed(false);
  return island.solvers.back().second.get();
}

const Solver* RowSolver::Impl::cachedSolver(std::uint64_t key, const std::string& name) const {
  const auto it = slots_.find(key);
  if (it == slots_.end()) return nullptr;
  for (const auto& [n, solver] : it->second->solvers)
    if (n == name) return solver.get();
  return nullptr;
}

Result RowSolver::Impl::run(const RowSystem& rows, const std::string& name, const Options& options,
                            const Vector& start, Vector& x, Slot& island, IslandSolve& report) {
  // The primary's assembly is timed from the solve's start (only the classification comes
  // before it): one clock read less per island, which tiny islands notice.
  const double since = solveStart_;
  solveStart_ = 0;
  Options o = options;
  o.warmStart = true;
  if (equals(name, "pgs")) {
    rowPgs_.options() = o;
    x = start;
    const bool timed = rows.size() >= kTimedPgsRows;
    const double t0 = timed ? nowSeconds() : 0;
    Result r = rowPgs_.solve(rows, x);
    if (timed) notePgsCost(rows.size(), r.iterations, nowSeconds() - t0);
    if (r.status == Status::TimeLimit) keepStartIfBetter(rows, start, x, r, o.tolerance);
    return r;
  }
  // Every assembled-problem solver follows the storage (ldlt: dense or sparse LDL^T).
  const bool sparse = rows.size() > settings_.denseAssemblyMaxRows;
  if (!haveAssembled_ || assembled_.isSparse() != sparse) {
    if (settings_.timeAssembly) {
      const double t0 = since > 0 ? since : nowSeconds();
      assemble(rows, sparse);
      report.assembleSeconds += nowSeconds() - t0;
    } else {
      assemble(rows, sparse);
    }
  }
  Solver* solver = assembledSolver(island, name);
  solver->setOptions(o);
  auto* dantzig = equals(name, "dantzig") ? dynamic_cast<DantzigSolver*>(solver) : nullptr;
  if (dantzig) {
    dantzig->params().regularised = island.regulariseFirst > 0;
    if (island.regulariseFirst > 0) --island.regulariseFirst;
  }
  // The rows for this solve only, cleared on every way out (a throw included): the solver is
  // kept per island and must not hold them past this call.
  struct Rows {
    Solver* solver;
    ~Rows() { solver->useRows(nullptr); }
  } scope{solver};
  solver->useRows(&rows);
  Result r = solver->solveWithGuess(assembled_, start, x);
  // A breakdown on A: the next solves go to A + delta I at once, the one after them tries A again.
  if (dantzig && !dantzig->params().regularised && dantzig->regularised())
    island.regulariseFirst = kRegulariseSolves;
  return r;
}

void RowSolver::Impl::notePgsCost(int rows, int sweeps, double seconds) {
  if (rows <= 0 || sweeps != engineSweeps_ || !(seconds > 0)) return;
  const double sample = seconds / rows;
  rowSeconds_ = rowSeconds_ > 0 ? 0.8 * rowSeconds_ + 0.2 * sample : sample;
}

double RowSolver::Impl::engineShare(const RowSystem& rows, const Vector& start) {
  if (!(settings_.engineCostFactor > 0) || engineSweeps_ <= 0 || !(settings_.timeBudget > 0))
    return 0;
  if (!(rowSeconds_ > 0) && rows.size() >= kTimedPgsRows && start.size() == rows.size()) {
    // No pgs timed yet: one solve of this island at the engine's sweeps measures the cost.
    Options o = settings_.fallbackOptions;
    useEngineIterations(o, engineSweeps_);
    o.warmStart = true;
    rowPgs_.options() = o;
    calibrationX_ = start;
    const double t0 = nowSeconds();
    const Result r = rowPgs_.solve(rows, calibrationX_);
    notePgsCost(rows.size(), r.iterations, nowSeconds() - t0);
  }
  if (!(rowSeconds_ > 0)) return 0;
  // A factor of 1 leaves the primary no time (a share of a nanosecond: it stops before its
  // first step, and the island goes to pgs).
  const double engine = rowSeconds_ * rows.size();
  return std::max((settings_.engineCostFactor - 1) * engine, 1e-9);
}

Accuracy RowSolver::Impl::rowAccuracy(const RowSystem& rows, const Vector& x, bool fresh) {
  if (fresh || velocities_.size() != rows.bodies.size()) rows.bodyVelocities(x, velocities_);
  rows.slack(x, velocities_, slack_);
  return accuracy(x, slack_, rows.lo, rows.hi, rows.findex, rows.b.lpNorm<Eigen::Infinity>());
}

bool RowSolver::Impl::startSolves(const RowSystem& rows, const Vector& start, double tolerance,
                                  bool withinTolerance, Vector& x, Result& r) {
  if (start.size() != rows.size()) return false;  // the solver reports the wrong size
  const Accuracy a = rowAccuracy(rows, start, false);
  const double limit =
      withinTolerance ? tolerance : std::min(kExactStart * tolerance, kExactStartLimit);
  if (!a.finite || !(a.residual <= limit)) return false;
  x = start;
  r = Result{};
  r.status = Status::Converged;
  r.iterations = 0;
  applyAccuracy(r, a, tolerance);
  r.message = "the start already solves the rows: no solve";
  return true;
}

void RowSolver::Impl::keepStartIfBetter(const RowSystem& rows, const Vector& start, Vector& x,
                                        Result& r, double tolerance) {
  const Accuracy a = rowAccuracy(rows, start);
  if (takeStartIfBetter(r, a, tolerance)) x = start;
}

void RowSolver::Impl::assemble(const RowSystem& rows, bool sparse) {
  rows.assemble(sparse, assembled_, assembleScratch_);
  haveAssembled_ = true;
}

void RowSolver::Impl::capture(const RowSystem& rows) {
  if (!haveAssembled_) assemble(rows, rows.size() > settings_.denseAssemblyMaxRows);
  capture(assembled_);
}

void RowSolver::Impl::capture(const Problem& problem) {
  const std::string path = capturePrefix_ + "island" + std::to_string(captured_.size()) + ".json";
  io::writeProblemJson(problem, path);
  captured_.push_back(path);
}

bool RowSolver::Impl::buildCone(const RowSystem& rows, const Vector& start, IslandSolve& out) {
  if (start.size() != rows.size()) return false;  // the box's solve reports the start
  const double t0 = settings_.timeAssembly ? nowSeconds() : 0;
  // About the cone's size (a contact's 3 rows become k + 2 unknowns), for the storage only.
  const int size = rows.size() * (settings_.frictionDirections + 2) / 3;
  coneNote_ =
      cone_.build(rows, settings_.frictionDirections, size > settings_.denseAssemblyMaxRows);
  if (settings_.timeAssembly) out.assembleSeconds += nowSeconds() - t0;
  if (!coneNote_.empty()) coneNote_ = "cone not built (" + coneNote_ + "): box friction; ";
  return coneNote_.empty();
}

// The cone's LCP from the box start, by the requested solver or auto's choice for an LCP with
// zero diagonal entries; its residual recomputed on that LCP (residual.hpp), never taken from
// the solver; the answer as the rows' impulses.
Result RowSolver::Impl::solveCone(const Vector& start, Vector& x, Slot& island, IslandSolve& out,
                                  double share, double t0) {
  const Problem& p = cone_.problem();
  if (equals(settings_.solver, "auto")) {
    const bool spent = budgetSpent(share);
    out.requested =
        settings_.policy
            .choose(ProblemClass::StandardLcp, p.size(), settings_.options.tolerance, false, spent)
            .solver;
  } else {
    out.requested = settings_.solver;
  }
  Solver* solver = assembledSolver(island, out.requested, "cone:");
  Options o = withBudget(settings_.options, share, t0);
  o.warmStart = true;
  solver->setOptions(o);
  coneStart_ = cone_.toCone(start);
  coneX_.resize(0);  // a refused problem leaves it untouched: then the start stands
  Result r = solver->solveWithGuess(p, coneStart_, coneX_);
  if (coneX_.size() == p.size()) {
    applyAccuracy(r, accuracy(p, coneX_), o.tolerance);
    x = cone_.toBox(coneX_);
  } else {
    x = start;
  }
  out.friction = FrictionModel::Cone;
  r.message = "cone k=" + std::to_string(cone_.directions()) + ", " +
              std::to_string(cone_.contacts()) + " contacts, " + std::to_string(p.size()) +
              " unknowns: " + r.message;
  return r;
}

// Stage 4's fallback (policy.hpp's rule): r is the primary's unacceptable answer, x its x.
Result RowSolver::Impl::fallBack(const RowSystem& rows, const Vector& start, Vector& x,
                                 Slot& island, IslandSolve& out, Result r, double share,
                                 double t0) {
  // Built on every rejection (a fixed-sweep pgs near the limit: every step), so without an
  // ostringstream, whose locale set-up cost more than a small island's sweep.
  const std::string why = out.requested + " rejected (" + toString(r.status) + ", residual " +
                          shortNumber(r.residual) + (r.message.empty() ? "" : ": ") + r.message +
                          ")";
  if (!settings_.fallback.empty() && !primaryWasFallback_) {
    out.fellBack = true;
    Options o = settings_.fallbackOptions;
    if (share > 0) {
      const double now = nowSeconds();
      o = withBudget(o, std::max(share - (now - t0), settings_.minShare * settings_.timeBudget),
                     now);
    }
    Result f = run(rows, settings_.fallback, o, start, xFallback_, island, out);
    const bool won = better(f, r);
    if (won) {
      f.iterations += r.iterations;
      f.message = why + "; " + settings_.fallback + ": " + f.message;
      r = std::move(f);
      x.swap(xFallback_);
      out.choice = settings_.fallback;
      out.friction = FrictionModel::Box;
    } else {
      r.message = why + "; " + settings_.fallback + " no better (" + toString(f.status) +
                  ", residual " + shortNumber(f.residual) + ")";
    }
    const bool projection = equals(settings_.fallback, "pgs") || equals(settings_.fallback, "gs");
    if (!acceptable(r, settings_.acceptResidual))
      keepSafe(rows, start, x, island, out, r, projection && !won ? &f : nullptr, share, t0);
  } else {
    r.message = why + (primaryWasFallback_ ? "; it was the fallback's own run" : "; no fallback");
    keepSafe(rows, start, x, island, out, r, nullptr, share, t0);
  }
  if (!std::isfinite(r.residual)) {
    // No solver found a finite answer: the start is the engine's "no change".
    const int n = rows.size();
    x = start.allFinite() ? start : Vector::Zero(n);
    r.message += "; start kept";
    applyAccuracy(r, rowAccuracy(rows, x), settings_.options.tolerance);
  }
  return r;
}

// o: the island's options bounded by what is left of its share (at least the minimal share).
Options RowSolver::Impl::leftOfShare(double share, double t0) const {
  if (!(share > 0)) return settings_.options;
  const double now = nowSeconds();
  return withBudget(settings_.options,
                    std::max(share - (now - t0), settings_.minShare * settings_.timeBudget), now);
}

// Stage 3's hand-over under auto: x, r (an answer that is not good enough) continued by `name`
// from x with the options o (their budget set by the caller). The better answer stands.
void RowSolver::Impl::continueWith(const std::string& name, const RowSystem& rows, Vector& x,
                                   Slot& island, IslandSolve& out, Result& r, const Options& o) {
  if (x.size() != rows.size() || !x.allFinite()) return;
  const Vector from = x;
  Result n = run(rows, name, o, from, xFallback_, island, out);
  if (!better(n, r)) return;
  n.iterations += r.iterations;
  n.message = out.choice + " ended at " + shortNumber(r.residual) + " (" + r.message + "); " +
              name + " from its answer: " + n.message;
  r = std::move(n);
  x.swap(xFallback_);
  out.choice = name;
}

// A dantzig answer on friction rows that is not acceptable (its friction fixed point did not
// settle, or its regularised retry ended short) goes on with newton, which has the friction
// bounds' exact Jacobian where the fixed point re-solves with lagged bounds, in what is left of
// the share. An exact method's answer still short of the tolerance on contact rows (a pile
// without cfm, whose A is singular) goes on with the policy's singular-island solver, under the
// engine-relative cap when the engine's cost is known, and that solver answers the island first
// for its next solves.
void RowSolver::Impl::continueShort(const RowSystem& rows, Vector& x, Slot& island,
                                    IslandSolve& out, Result& r, const Plan& plan, double t0) {
  const Policy& policy = settings_.policy;
  if (plan.fromStart) return;
  if (out.problemClass == ProblemClass::Findex && equals(out.requested, "dantzig") &&
      !acceptable(r, settings_.acceptResidual))
    continueWith("newton", rows, x, island, out, r, leftOfShare(plan.share, t0));
  if (r.status == Status::Converged || !policy.continuesShort(out.problemClass, out.requested))
    return;
  Options o = leftOfShare(plan.share, t0);
  if (const double cap = engineShare(rows, x); cap > 0 && !(o.timeBudget > 0 && o.timeBudget < cap))
    o = withBudget(settings_.options, cap, nowSeconds());
  continueWith(policy.singularIslandSolver, rows, x, island, out, r, o);
  island.singularFirst = policy.singularIslandSolves;
}

// Leaves the returned start's velocities in velocities_ (startSolves reads them).
const Vector& RowSolver::Impl::saneStart(const RowSystem& rows, const Vector& start) {
  if (!throwsBodies(rows, start, kStartSpeedFactor)) return start;
  coldStart_.setZero(rows.size());
  velocities_.assign(rows.bodies.size(), Vector6::Zero());
  return coldStart_;
}

// Stage 5's trigger for acceptable answers (kSpeedFactor).
bool RowSolver::Impl::throwsBodies(const RowSystem& rows, const Vector& x, double factor) {
  if (x.size() != rows.size()) {
    velocities_.clear();
    return false;
  }
  rows.bodyVelocities(x, velocities_);
  return throwsFromVelocities(rows, x, factor);
}

bool RowSolver::Impl::throwsFromVelocities(const RowSystem& rows, const Vector& x,
                                           double factor) const {
  const double limit = factor * rows.b.lpNorm<Eigen::Infinity>();
  for (const Vector6& v : velocities_)
    if (v.head<3>().squaredNorm() > limit * limit) return true;
  return rows.articulatedSpeed(x) > limit;
}

// Stage 5 (safe application): x, r are the lowest-residual answer, and it is not acceptable, or
// it is acceptable but throwsBodies() (an exact answer along nearly dependent rows). It is
// applied only when the velocity change it makes (RowSystem::impulseEnergy) is within
// kEnergyFactor of the one the engine's own method's answer from the same start makes, pgs at
// the fallback's sweeps (under engineIterations SI's and QuickStep's count): an answer that
// beats pgs on the residual but moves the bodies twice as fast is a diverged or exploded
// iterate, and pgs's answer is applied instead. projectionAnswer: pgs's result when the fallback
// was pgs or gs and lost on the residual (its x in xFallback_); else pgs runs here.
void RowSolver::Impl::keepSafe(const RowSystem& rows, const Vector& start, Vector& x, Slot& island,
                               IslandSolve& out, Result& r, Result* projectionAnswer, double share,
                               double t0) {
  if (x.size() != rows.size() || !std::isfinite(r.residual)) return;  // the start is kept below
  if (!equals(out.choice, "pgs") && !equals(out.choice, "gs")) {
    Result p;
    if (projectionAnswer) {
      p = std::move(*projectionAnswer);
    } else {
      Options o = settings_.fallbackOptions;
      if (share > 0) {
        const double now = nowSeconds();
        o = withBudget(o, std::max(share - (now - t0), settings_.minShare * settings_.timeBudget),
                       now);
      }
      p = run(rows, "pgs", o, start, xFallback_, island, out);
    }
    if (xFallback_.size() != rows.size() || !xFallback_.allFinite()) return;
    const double ex = rows.impulseEnergy(x), ep = rows.impulseEnergy(xFallback_);
    if (ex > kEnergyFactor * ep) {
      r.message += "; " + out.choice + "'s answer moves the bodies with " + shortNumber(ex) +
                   " against pgs's " + shortNumber(ep) + " (impulse energy): pgs's applied";
      p.message = r.message;
      p.iterations += r.iterations;
      r = std::move(p);
      x.swap(xFallback_);
      out.choice = "pgs";
      out.friction = FrictionModel::Box;
      out.energyGuard = true;
    }
  }
  if (throwsBodies(rows, x, kSpeedFactor)) holdStill(rows, start, x, out, r);
}

// Stage 5's last resort: the applied answer, pgs's included, still changes a body's velocity by
// more than kSpeedFactor ||b||_inf (pgs diverging on rows it cannot settle): the start (the
// engine's "no change") when it does not, else no impulses at all. Status Failed: nothing
// solved the island.
void RowSolver::Impl::holdStill(const RowSystem& rows, const Vector& start, Vector& x,
                                IslandSolve& out, Result& r) {
  const bool useStart =
      start.size() == rows.size() && start.allFinite() && !throwsBodies(rows, start, kSpeedFactor);
  x = useStart ? start : Vector::Zero(rows.size());
  r.status = Status::Failed;
  r.message += std::string("; every answer throws a body (pgs's too): ") +
               (useStart ? "the start" : "no impulses") + " applied";
  applyAccuracy(r, rowAccuracy(rows, x), settings_.options.tolerance);
  out.choice = useStart ? kStartChoice : "none";
  out.friction = FrictionModel::Box;
  out.energyGuard = true;
}

IslandSolve RowSolver::Impl::solve(const RowSystem& rows, const Vector& start, Vector& x,
                                   std::uint64_t key) {
  // Stage 0 (a start of the wrong size is left to the solve to report). Its one pass is not
  // timed: a clock read costs tiny islands as much as the pass.
  if (start.size() != rows.size() || !screen_.screen(rows))
    return solveScreened(rows, start, x, key);
  screen_.gather(start, keptStart_);
  IslandSolve out = solveScreened(screen_.kept(), keptStart_, keptX_, key);
  screen_.scatter(keptX_, x);
  out.screened = screen_.counts();
  const int inert = out.screened.inert();
  out.result.message = std::to_string(inert) + " of " + std::to_string(rows.size()) +
                       " rows inert, " + std::to_string(out.screened.clampedBound) +
                       " bounds clamped (" + out.screened.toString() + "); " + out.result.message;
  return out;
}

// An island without rows: answer "none", converged.
IslandSolve RowSolver::Impl::noRows(Vector& x) {
  IslandSolve out;
  x.resize(0);
  out.problemClass = ProblemClass::Empty;
  out.choice = out.requested = "none";
  out.result.status = Status::Converged;
  out.result.iterations = 0;
  out.result.residual = out.result.complementarity = out.result.boundViolation = 0;
  out.result.solver = "none";
  out.result.message = "no constraint rows";
  return out;
}

// Whether the engine-relative cap bounds this primary: the large-island solver, and the
// singular-island solver that replaces it or dantzig on islands where they end short.
bool RowSolver::Impl::cappable(const std::string& name) const {
  const Policy& policy = settings_.policy;
  return name == policy.largeIslandSolver || name == policy.singularIslandSolver;
}

// Stage 2 under auto: the policy's choice, the island's pgs-first memory and the engine-relative
// cap (which may shorten the share).
void RowSolver::Impl::chooseForAuto(const RowSystem& rows, const Vector& start, Slot& island,
                                    IslandSolve& out, Plan& plan) {
  const Policy& policy = settings_.policy;
  const bool spent = budgetSpent(plan.share);
  const Choice c = policy.choose(out.problemClass, rows.size(), settings_.options.tolerance, true,
                                 spent, hasFreeRows(rows.lo, rows.hi));
  out.requested = c.solver;
  plan.enginePgs = spent && equals(out.requested, "pgs");
  if (island.pgsFirst > 0 && !equals(out.requested, "ldlt") && !equals(out.requested, "pgs")) {
    --island.pgsFirst;
    out.requested = "pgs";
    plan.enginePgs = true;
  }
  // The singular-island solver answers under the cap whenever the engine's cost is known: it
  // runs on islands no exact method finishes, every step.
  const bool singular =
      island.singularFirst > 0 && policy.continuesShort(out.problemClass, out.requested);
  if (singular) {
    --island.singularFirst;
    out.requested = policy.singularIslandSolver;
  }
  if (singular || (cappable(out.requested) && island.cappedSolves > 0)) {
    const double cap = engineShare(rows, start);
    plan.capped = cap > 0;
    if (plan.capped && !singular) --island.cappedSolves;
    if (plan.capped && cap < plan.share) plan.share = cap;
  }
}

// Stage 3 on the box rows: the start when it already solves them, else the chosen solver (pgs
// that auto runs for cost with the fallback's options: the engine's sweeps, the engine's cost).
Result RowSolver::Impl::solvePrimary(const RowSystem& rows, const Vector& start, Vector& x,
                                     Slot& island, IslandSolve& out, Plan& plan, double t0) {
  Result r;
  plan.fromStart = !equals(out.requested, "pgs") &&
                   startSolves(rows, start, settings_.options.tolerance, plan.capped, x, r);
  if (!plan.fromStart)
    r = run(
        rows, out.requested,
        withBudget(plan.enginePgs ? settings_.fallbackOptions : settings_.options, plan.share, t0),
        start, x, island, out);
  // The same solver with the same options from the same start gives the same answer: not rerun.
  primaryWasFallback_ = plan.enginePgs && settings_.fallback == out.requested;
  return r;
}

// The island's memory under auto after its primary: the budget's cuts in a row, the capped
// solves after an uncapped large-island (or singular-island) solve ended short by itself, whatever
// the continuation found (the continuation costs more than the engine: the next solves are held
// to its cost), and pgs first after a capped solve
// that spent its share before its first step (assembly and set-up alone cost more than the cap:
// it cannot improve on pgs within the engine's cost) or after a breakdown.
void RowSolver::Impl::remember(Slot& island, const IslandSolve& out, const Result& r,
                               const Plan& plan) {
  const Policy& policy = settings_.policy;
  island.cutsInRow = r.status == Status::TimeLimit ? island.cutsInRow + 1 : 0;
  if (!plan.capped && !plan.fromStart && cappable(out.requested) && plan.primaryShort)
    island.cappedSolves = policy.pgsAfterBreakdown;
  if (plan.capped && r.status == Status::TimeLimit && r.iterations == 0)
    island.pgsFirst = policy.pgsAfterBreakdown;
  if (!acceptable(r, settings_.acceptResidual) && !equals(out.requested, "pgs") &&
      !equals(out.requested, "ldlt") &&
      policy.demotes(r, settings_.acceptResidual, island.cutsInRow))
    island.pgsFirst = policy.pgsAfterBreakdown;
}

IslandSolve RowSolver::Impl::solveScreened(const RowSystem& rows, const Vector& start, Vector& x,
                                           std::uint64_t key) {
  const double t0 = nowSeconds();
  solveStart_ = t0;
  ++calls_;
  haveAssembled_ = false;
  primaryWasFallback_ = false;
  coneNote_.clear();
  if (rows.size() == 0) return noRows(x);
  const Vector& from = saneStart(rows, start);
  IslandSolve out;
  out.problemClass = classify(rows);
  Plan plan;
  plan.share = islandBudget(t0);
  const bool autoChoice = equals(settings_.solver, "auto");
  Slot& island = slot(key);
  // The cone is tried on every solve: the demotion to pgs is the box's rule (the cone is a model
  // the caller asked for, and pgs cannot take its LCP).
  const bool cone = settings_.friction == FrictionModel::Cone &&
                    out.problemClass == ProblemClass::Findex && buildCone(rows, from, out);
  if (!capturePrefix_.empty()) cone ? capture(cone_.problem()) : capture(rows);

  Result r;
  if (cone) {
    r = solveCone(from, x, island, out, plan.share, t0);
  } else {
    if (autoChoice)
      chooseForAuto(rows, from, island, out, plan);
    else
      out.requested = settings_.solver;
    r = solvePrimary(rows, from, x, island, out, plan, t0);
  }
  if (r.status == Status::InvalidInput || r.status == Status::Unsupported) x = from;
  out.choice = plan.fromStart ? kStartChoice : out.requested;
  plan.primaryShort = r.status != Status::Converged;
  if (autoChoice && !cone) continueShort(rows, x, island, out, r, plan, t0);
  if (autoChoice && !cone) remember(island, out, r, plan);
  // Stages 4 and 5.
  if (!acceptable(r, settings_.acceptResidual))
    r = fallBack(rows, from, x, island, out, std::move(r), plan.share, t0);
  else if (!plan.fromStart && !equals(out.choice, "pgs") && throwsBodies(rows, x, kSpeedFactor))
    keepSafe(rows, from, x, island, out, r, nullptr, plan.share, t0);
  out.accepted = acceptable(r, settings_.acceptResidual);
  if (!coneNote_.empty()) r.message = coneNote_ + r.message;
  if (&from != &start) r.message = "start discarded (it throws a body): solved cold; " + r.message;
  r.solver = out.choice;
  r.fallbacks = out.fellBack ? 1 : 0;
  r.seconds = nowSeconds() - t0;
  out.result = std::move(r);
  return out;
}

// --- the facade ------------------------------------------------------------------------------

RowSolver::RowSolver(const RowSolverSettings& settings) : impl_(std::make_unique<Impl>(settings)) {}
RowSolver::~RowSolver() = default;
const RowSolverSettings& RowSolver::settings() const { return impl_->settings(); }
Options& RowSolver::options() { return impl_->options(); }
Options& RowSolver::fallbackOptions() { return impl_->fallbackOptions(); }
void RowSolver::setTimeBudget(double seconds) { impl_->setTimeBudget(seconds); }
void RowSolver::setEngineSweeps(int sweeps) { impl_->setEngineSweeps(sweeps); }
void RowSolver::beginStep() { impl_->beginStep(); }
double RowSolver::islandBudget(double now) { return impl_->islandBudget(now); }
bool RowSolver::budgetSpent(double share) const { return impl_->budgetSpent(share); }
IslandSolve RowSolver::solve(const RowSystem& rows, const Vector& start, Vector& x,
                             std::uint64_t islandKey) {
  return impl_->solve(rows, start, x, islandKey);
}
void RowSolver::setCapture(const std::string& prefix) { impl_->setCapture(prefix); }
bool RowSolver::capturing() const { return impl_->capturing(); }
const std::vector<std::string>& RowSolver::capturedFiles() const { return impl_->capturedFiles(); }
const Solver* RowSolver::cachedSolver(std::uint64_t islandKey, const std::string& name) const {
  return impl_->cachedSolver(islandKey, name);
}

}  // namespace mlcp
