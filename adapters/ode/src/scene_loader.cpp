// An mlcp-scene/1 scene in an ODE world (see scene_loader.hpp).
#include "mlcp/ode/scene_loader.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mlcp/ode/stepper.hpp"
#include "mlcp/registry.hpp"

namespace mlcp::ode {

namespace {

void ensureOdeInitialized() {
  static const bool done = [] {
    dInitODE2(0);
    return true;
  }();
  (void)done;
}

void setLimitsAndMotor(dJointID joint, const scene::Joint& j, void (*set)(dJointID, int, dReal)) {
  if (j.limits.enabled) {
    set(joint, dParamLoStop, j.limits.lower);
    set(joint, dParamHiStop, j.limits.upper);
  }
  if (j.motor.enabled) {
    set(joint, dParamVel, j.motor.velocity);
    set(joint, dParamFMax, j.motor.maxForce);
  }
}

int indexOf(dBodyID b) {
  return static_cast<int>(reinterpret_cast<std::intptr_t>(dBodyGetData(b)));
}

class OdeWorld : public scene::World {
 public:
  OdeWorld(const scene::Scene& s, const scene::RunSettings& run) : scene::World(s) {
    std::string stepperName = run.solver;
    if (run.solver == "ode-world") {
      stepperName = "ode-lcp";
    } else if (run.solver == "ode-quick") {
      stepperName = "ode-quickstep";
      quick_ = true;
    } else if (!RowSolver::known(run.solver)) {
      throw std::invalid_argument("unknown solver '" + run.solver +
                                  "' for ODE (known: " + worldSolverNames() + ")");
    }
    StepperOptions options;
    options.solver.maxIterations = run.iterations;
    options.solver.tolerance = run.tolerance;
    options.warmStart = run.warmStart;
    options.fallback = run.fallback;  // the stepper never falls back from "ode-..."
    options.acceptResidual = run.fallbackResidual;
    options.timeBudget = run.timeBudget;
    stepper_ = std::make_unique<Stepper>(stepperName, options);
    iterations_ = run.iterations;
    built_ = buildWorld(s, run);
  }

  std::vector<scene::BodyState> states() const override {
    const std::vector<dBodyID>& bodies = built_->bodies();
    std::vector<scene::BodyState> out(bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const scene::Body& sb = scene().bodies[i];
      dBodyID b = bodies[i];
      if (!b) {
        out[i].position = sb.position;
        out[i].orientation = sb.orientation;
        continue;
      }
      const dReal* p = dBodyGetPosition(b);
      const dReal* q = dBodyGetQuaternion(b);
      const dReal* v = dBodyGetLinearVel(b);
      const dReal* w = dBodyGetAngularVel(b);
      out[i].position = {p[0], p[1], p[2]};
      out[i].orientation = {q[0], q[1], q[2], q[3]};
      out[i].velocity = {v[0], v[1], v[2]};
      out[i].angularVelocity = {w[0], w[1], w[2]};
    }
    return out;
  }
  const char* engine() const override { return "ode"; }

  bool captureNextStep(const std::string& folder) override {
    captured_.clear();
    if (!stepper_->rowSolver()) return false;
    capturing_ = true;
    stepper_->rowSolver()->setCapture(
        scene::capturePrefix(folder, scene().name, engine(), stepsTaken()));
    return true;
  }
  std::vector<std::string> capturedFiles() const override { return captured_; }

 protected:
  void stepEngine(scene::StepMeasures& m) override {
    built_->collide();
    stepper_->step(built_->world(), scene().settings.timeStep);
    if (capturing_) {
      captured_ = stepper_->rowSolver()->capturedFiles();
      stepper_->rowSolver()->setCapture("");
      capturing_ = false;
    }
    built_->clearContacts();
    const StepStats& st = stepper_->lastStep();
    // solver_ms, per island summed. Core solvers ("auto", "dantzig", ...): RowSolver::solve,
    // i.e. choosing, assembling A (matrix-based solvers), the solve, the recomputed residual
    // and any fallback. "ode-world" (our stages around ODE's dxSolveLCP, equal to dWorldStep
    // to round-off): the same span, i.e. assembling A (the same RowSystem::assemble), ODE's
    // layout, dxSolveLCP and the recomputed residual; so auto and ode-world compare like for
    // like, rows and integration excluded from both. "ode-quick" forwards whole islands to
    // dxQuickStepIsland, whose solve cannot be timed apart: its solver_ms is the whole island
    // (rows, solve, integration) and overstates its solve.
    double seconds = 0;
    Status worst = Status::Converged;
    m.iterations = 0;
    for (const IslandStats& is : st.islands) {
      seconds += quick_ ? is.islandSeconds : is.solveSeconds;
      m.iterations += is.iterations;
      if (is.rows > 0) worst = std::max(worst, is.status);
    }
    m.solverMs = 1e3 * seconds;
    m.fallbacks = st.fallbacks();
    if (!quick_ && stepper_->rowSolver()) m.choice = st.choices().toString();
    m.contacts = built_->contacts();
    m.maxPenetration = built_->deepestPenetration();
    if (quick_) {
      m.iterations = st.islands.empty() ? 0 : iterations_;
      m.status = "max-iterations";
    } else {
      m.residual = st.maxResidual();
      m.status = toString(worst);
    }
  }

 private:
  std::unique_ptr<Stepper> stepper_;
  bool quick_ = false, capturing_ = false;
  int iterations_ = 0;
  std::vector<std::string> captured_;
  // After stepper_: the world is destroyed before the stepper that steps it.
  std::unique_ptr<OdeScene> built_;
};

}  // namespace

OdeScene::OdeScene(const scene::Scene& s, const scene::RunSettings& run)
    : materials_(s.materials), maxContactsPerPair_(s.settings.maxContactsPerPair) {
  ensureOdeInitialized();
  world_ = dWorldCreate();
  // Sweep and prune, not dHashSpaceCreate: ODE 0.16's hash space never reports some pairs of
  // the sphere pit's stacked spheres (a sphere fell through the one below it, 0.5 m deep).
  space_ = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  contacts_ = dJointGroupCreate(0);
  dWorldSetGravity(world_, s.gravity[0], s.gravity[1], s.gravity[2]);
  dWorldSetERP(world_, s.settings.erp);
  dWorldSetCFM(world_, s.settings.cfm);
  dWorldSetAutoDisableFlag(world_, s.settings.sleeping ? 1 : 0);
  dWorldSetQuickStepNumIterations(world_, run.iterations);

  for (std::size_t i = 0; i < s.bodies.size(); ++i) addBody(s, static_cast<int>(i));
  for (const scene::Joint& j : s.joints) addJoint(j);
}

OdeScene::~OdeScene() {
  dJointGroupDestroy(contacts_);
  dSpaceDestroy(space_);  // destroys its geoms
  dWorldDestroy(world_);  // destroys bodies and joints
}

void OdeScene::collide() {
  contactCount_ = 0;
  deepest_ = 0;
  dSpaceCollide(space_, this, &OdeScene::nearCallback);
}

void OdeScene::addBody(const scene::Scene& s, int index) {
  const scene::Body& b = s.bodies[index];
  dGeomID g = nullptr;
  switch (b.shape.type) {
    case scene::ShapeType::Plane:
      g = dCreatePlane(space_, b.shape.normal[0], b.shape.normal[1], b.shape.normal[2],
                       b.shape.offset);
      break;
    case scene::ShapeType::Box:
      g = dCreateBox(space_, b.shape.size[0], b.shape.size[1], b.shape.size[2]);
      break;
    case scene::ShapeType::Sphere: g = dCreateSphere(space_, b.shape.radius); break;
    case scene::ShapeType::Capsule:
      g = dCreateCapsule(space_, b.shape.radius, b.shape.length);
      break;
  }
  materialOf_[g] = b.material;
  const dQuaternion q = {b.orientation.w, b.orientation.x, b.orientation.y, b.orientation.z};
  if (b.isStatic()) {
    bodies_.push_back(nullptr);
    if (b.shape.type == scene::ShapeType::Plane) return;
    dGeomSetPosition(g, b.position[0], b.position[1], b.position[2]);
    dGeomSetQuaternion(g, q);
    return;
  }
  dBodyID body = dBodyCreate(world_);
  dMass mass;
  dMassSetParameters(&mass, b.mass, 0, 0, 0, b.inertia[0], b.inertia[1], b.inertia[2], 0, 0, 0);
  dBodySetMass(body, &mass);
  dBodySetPosition(body, b.position[0], b.position[1], b.position[2]);
  dBodySetQuaternion(body, q);
  dBodySetLinearVel(body, b.velocity[0], b.velocity[1], b.velocity[2]);
  dBodySetAngularVel(body, b.angularVelocity[0], b.angularVelocity[1], b.angularVelocity[2]);
  dBodySetAutoDisableFlag(body, s.settings.sleeping ? 1 : 0);
  dBodySetData(body, reinterpret_cast<void*>(static_cast<std::intptr_t>(index)));
  dGeomSetBody(g, body);
  bodies_.push_back(body);
}

void OdeScene::addJoint(const scene::Joint& j) {
  dBodyID a = bodies_[j.body0];
  dBodyID b = j.body1 >= 0 ? bodies_[j.body1] : nullptr;
  dJointID joint = nullptr;
  const auto& p = j.anchor;
  const auto& x = j.axis;
  switch (j.type) {
    case scene::JointType::Ball:
      joint = dJointCreateBall(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetBallAnchor(joint, p[0], p[1], p[2]);
      break;
    case scene::JointType::Hinge:
      joint = dJointCreateHinge(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetHingeAnchor(joint, p[0], p[1], p[2]);
      dJointSetHingeAxis(joint, x[0], x[1], x[2]);
      setLimitsAndMotor(joint, j, &dJointSetHingeParam);
      break;
    case scene::JointType::Slider:
      joint = dJointCreateSlider(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetSliderAxis(joint, x[0], x[1], x[2]);
      setLimitsAndMotor(joint, j, &dJointSetSliderParam);
      break;
    case scene::JointType::Fixed:
      joint = dJointCreateFixed(world_, nullptr);
      dJointAttach(joint, a, b);
      dJointSetFixed(joint);
      break;
  }
  if (!j.collideConnected && j.body1 >= 0) noCollide_.insert(std::minmax(j.body0, j.body1));
}

void OdeScene::nearCallback(void* data, dGeomID g1, dGeomID g2) {
  auto* w = static_cast<OdeScene*>(data);
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (!b1 && !b2) return;
  if (b1 && b2 && w->noCollide_.count(std::minmax(indexOf(b1), indexOf(b2)))) return;
  const int n = w->maxContactsPerPair_;
  w->buffer_.resize(n);
  const int found = dCollide(g1, g2, n, &w->buffer_[0].geom, sizeof(dContact));
  const scene::Material& m1 = w->materials_[w->materialOf_.at(g1)];
  const scene::Material& m2 = w->materials_[w->materialOf_.at(g2)];
  const double mu = scene::combinedFriction(m1, m2);
  const double e = scene::combinedRestitution(m1, m2);
  for (int i = 0; i < found; ++i) {
    dContact& c = w->buffer_[i];
    c.surface.mode = dContactApprox1 | (e > 0 ? dContactBounce : 0);
    c.surface.mu = mu;
    c.surface.bounce = e;
    c.surface.bounce_vel = 0.2;
    w->deepest_ = std::max(w->deepest_, double(c.geom.depth));
    dJointAttach(dJointCreateContact(w->world_, w->contacts_, &c), b1, b2);
  }
  w->contactCount_ += found;
}

std::unique_ptr<OdeScene> buildWorld(const scene::Scene& scene, const scene::RunSettings& run) {
  return std::make_unique<OdeScene>(scene, run);
}

std::unique_ptr<OdeScene> buildWorld(const scene::Scene& scene) {
  return buildWorld(scene, scene::RunSettings::fromScene(scene));
}

std::string worldSolverNames() { return solverNames() + ", ode-world, ode-quick"; }

std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings) {
  return std::make_unique<OdeWorld>(scene, settings);
}

}  // namespace mlcp::ode
