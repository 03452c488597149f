#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include "island.hpp"
#include "mlcp/registry.hpp"

namespace mlcp::ode {

namespace {

// ODE's stepper and estimator callbacks carry no user pointer: they find the stepper through
// the world being stepped (the estimator through its bodies' world). Worlds being stepped at
// once are few: a flat list, searched linearly, that allocates nothing once it has grown.
std::mutex registryMutex;
std::vector<std::pair<const dxWorld*, Stepper::Impl*>>& activeSteppers() {
  static std::vector<std::pair<const dxWorld*, Stepper::Impl*>> list;
  return list;
}

auto findActive(const dxWorld* world) {
  auto& list = activeSteppers();
  return std::find_if(list.begin(), list.end(), [&](const auto& e) { return e.first == world; });
}

Stepper::Impl* activeStepper(const dxWorld* world) {
  std::lock_guard<std::mutex> lock(registryMutex);
  const auto it = findActive(world);
  return it == activeSteppers().end() ? nullptr : it->second;
}

// Registers the stepper for the duration of one step.
class ActiveScope {
 public:
  ActiveScope(const dxWorld* world, Stepper::Impl* impl) : world_(world) {
    std::lock_guard<std::mutex> lock(registryMutex);
    if (findActive(world) != activeSteppers().end())
      throw std::logic_error("mlcp::ode::Stepper::step: the world is being stepped already");
    activeSteppers().emplace_back(world, impl);
  }
  ~ActiveScope() {
    std::lock_guard<std::mutex> lock(registryMutex);
    activeSteppers().erase(findActive(world_));
  }

 private:
  const dxWorld* world_;
};

Settings withSolver(Settings settings, const std::string& solver) {
  settings.solver = solver;
  return settings;
}

unsigned sureMaxRows(dxJoint* const* joint, unsigned nj) {
  unsigned m = 0;
  for (unsigned k = 0; k < nj; ++k) {
    dxJoint::SureMaxInfo info;
    joint[k]->getSureMaxInfo(&info);
    m += info.max_m;
  }
  return m;
}

}  // namespace

int StepStats::rows() const {
  int n = 0;
  for (const IslandStats& s : islands) n += s.rows;
  return n;
}

int StepStats::fallbacks() const {
  return static_cast<int>(std::count_if(islands.begin(), islands.end(),
                                        [](const IslandStats& s) { return s.fellBack; }));
}

ChoiceCounts StepStats::choices() const {
  ChoiceCounts counts;
  for (const IslandStats& s : islands) counts.add(s.choice);
  return counts;
}

ScreenCounts StepStats::screened() const {
  ScreenCounts counts;
  for (const IslandStats& s : islands) counts.add(s.screened);
  return counts;
}

double StepStats::maxResidual() const {
  double r = 0;
  for (const IslandStats& s : islands)
    if (s.rows > 0 && !(s.residual <= r)) r = s.residual;  // NaN (not computed) wins
  return r;
}

int StepStats::maxIterations() const {
  int n = 0;
  for (const IslandStats& s : islands) n = std::max(n, s.iterations);
  return n;
}

std::string Stepper::knownSolvers() { return solverNames() + ", ode-step, ode-quickstep, ode-lcp"; }

Stepper::Stepper(const std::string& solver) : Stepper(withSolver(Settings{}, solver)) {}

Stepper::Stepper(const std::string& solver, Settings settings)
    : Stepper(withSolver(std::move(settings), solver)) {}

Stepper::Stepper(const Settings& options) : impl_(std::make_unique<Impl>()) {
  impl_->name = options.solver;
  impl_->options = options;
  impl_->stepOptions = options.options;
  RowSolverSettings rs = options;
  if (const std::string why =
          frictionSettingsError(options.friction, options.frictionDirections, options.solver);
      !why.empty())
    throw std::invalid_argument("mlcp::ode::Stepper: " + why);
  if (!options.fallback.empty() && !RowSolver::known(options.fallback))
    throw std::invalid_argument("mlcp::ode::Stepper: fallback '" + options.fallback +
                                "' is not a core solver (known: " + solverNames() + ")");
  // The same sweeps from the same start give the same answer: no second run.
  if (options.engineIterations && rs.fallback == rs.solver) rs.fallback.clear();
  // ODE's own solvers ("ode-...") are there to reproduce stock ODE, answers and all: they never
  // fall back.
  impl_->primary = makeMethod(options.solver, rs);
  if (!options.reference.empty()) {
    // The reference only measures: no fallback, every answer kept, no budget.
    RowSolverSettings ref = rs;
    ref.fallback = "";
    ref.acceptResidual = kInf;
    ref.timeBudget = 0;
    impl_->reference = makeMethod(options.reference, ref);
    if (impl_->reference.forwards())
      throw std::invalid_argument("mlcp::ode::Stepper: reference '" + options.reference +
                                  "' forwards whole islands and cannot be a reference");
    impl_->hasReference = !impl_->primary.forwards();
  }
}

Stepper::~Stepper() = default;

const std::string& Stepper::solverName() const { return impl_->name; }
const Settings& Stepper::settings() const { return impl_->options; }
mlcp::Options& Stepper::solverOptions() { return impl_->options.options; }
mlcp::Options& Stepper::fallbackOptions() { return impl_->options.fallbackOptions; }
const StepStats& Stepper::lastStep() const { return impl_->stats; }
const std::vector<IslandProblem>& Stepper::lastProblems() const { return impl_->problems; }
void Stepper::resetWarmStart() { impl_->warm.clear(); }
RowSolver* Stepper::rowSolver() { return impl_->primary.solver.get(); }

void Stepper::setTimeBudget(double seconds) {
  if (RowSolver* rows = rowSolver())
    rows->setTimeBudget(seconds);  // checks the value
  else if (!(seconds >= 0) || !std::isfinite(seconds))
    throw std::invalid_argument("mlcp::ode::Stepper: timeBudget must be finite and >= 0 seconds");
  impl_->options.timeBudget = seconds;
}

bool Stepper::step(dWorldID world, dReal h) {
  if (!world) throw std::invalid_argument("mlcp::ode::Stepper::step: null world");
  if (!(h > 0)) throw std::invalid_argument("mlcp::ode::Stepper::step: step size must be > 0");
  const double t0 = nowSeconds();
  impl_->islandsUsed = 0;
  struct DropUnused {  // last steps' entries beyond this step's islands, however step() ends
    Impl& impl;
    ~DropUnused() { impl.stats.islands.resize(impl.islandsUsed); }
  } dropUnused{*impl_};
  if (!impl_->problems.empty()) {
    // Reversed, so that island k takes last step's island k's buffers (sizes match).
    auto& spare = impl_->spareProblems;
    std::move(impl_->problems.rbegin(), impl_->problems.rend(), std::back_inserter(spare));
    impl_->problems.clear();
  }
  impl_->beginStep(world);
  ActiveScope scope(world, impl_.get());
  if (RowSolver* rows = rowSolver()) rows->beginStep();  // the time budget is per step
  // dWorldStep's two calls, with our estimator and island stepper.
  dxWorldProcessIslandsInfo islands;
  bool ok = dxReallocateWorldProcessContext(world, islands, h, &Impl::estimateMemory) &&
            dxProcessIslands(world, islands, h, &Impl::stepIsland, &Impl::estimateMaxCallCount);
  impl_->warm.endStep();
  impl_->stats.seconds = nowSeconds() - t0;
  if (impl_->pendingError) std::rethrow_exception(std::exchange(impl_->pendingError, nullptr));
  return ok;
}

void Stepper::Impl::beginStep(dxWorld* world) {
  const auto iterative = [](const std::string& name) { return name == "pgs" || name == "gs"; };
  const auto engine = [&](Options o, const std::string& name) {
    if (options.engineIterations && iterative(name)) {
      useEngineIterations(o, dWorldGetQuickStepNumIterations(world));
      o.relaxation = dWorldGetQuickStepW(world);
    }
    return o;
  };
  stepOptions = engine(options.options, options.solver);
  if (RowSolver* rows = primary.solver.get()) {
    rows->fallbackOptions() = engine(options.fallbackOptions, options.fallback);
    rows->setEngineSweeps(dWorldGetQuickStepNumIterations(world));
  }
}

void Stepper::Impl::stepIsland(const dxStepperProcessingCallContext* context) {
  Impl* impl = activeStepper(context->m_world);
  try {
    impl->runIsland(context);
  } catch (...) {
    std::lock_guard<std::mutex> lock(impl->mutex);
    if (!impl->pendingError) impl->pendingError = std::current_exception();
  }
}

void Stepper::Impl::keepProblem(IslandWork& w, int island) {
  if (spareProblems.empty()) spareProblems.emplace_back();
  problems.push_back(std::move(spareProblems.back()));
  spareProblems.pop_back();
  IslandProblem& kept = problems.back();
  kept.island = island;
  std::swap(kept.rows, w.rows);
  kept.lambda.swap(w.x);
  kept.joints.clear();
  for (const JointRows& jr : w.joints) kept.joints.push_back({jr.joint, jr.offset, jr.m});
}

sizeint Stepper::Impl::estimateMemory(dxBody* const* body, unsigned nb, dxJoint* const* joint,
                                      unsigned nj) {
  const Impl* impl = nb > 0 ? activeStepper(body[0]->world) : nullptr;
  return impl ? impl->memoryFor(body, nb, joint, nj) : 0;
}

unsigned Stepper::Impl::estimateMaxCallCount(unsigned activeThreads, unsigned allowedThreads) {
  return std::max(dxEstimateStepMaxCallCount(activeThreads, allowedThreads),
                  dxEstimateQuickStepMaxCallCount(activeThreads, allowedThreads));
}

// Arena bytes for one island: ODE's own estimate for the forwarding methods, dxSolveLCP's
// work space for "ode-lcp"; our own buffers live on the heap and are reused.
sizeint Stepper::Impl::memoryFor(dxBody* const* body, unsigned nb, dxJoint* const* joint,
                                 unsigned nj) const {
  sizeint need = 0;
  for (const Method* m : {&primary, &reference}) {
    switch (m->kind) {
      case Method::Kind::ForwardStep:
        if (m == &primary)
          need = std::max(need, dxEstimateStepMemoryRequirements(body, nb, joint, nj));
        break;
      case Method::Kind::ForwardQuickStep:
        if (m == &primary)
          need = std::max(need, dxEstimateQuickStepMemoryRequirements(body, nb, joint, nj));
        break;
      case Method::Kind::OdeLcp:
        if (m == &primary || hasReference)
          need = std::max(need, dxEstimateSolveLCPMemoryReq(sureMaxRows(joint, nj), false));
        break;
      default: break;
    }
  }
  return dEFFICIENT_SIZE(need);
}

}  // namespace mlcp::ode
