// An mlcp-scene/1 scene in an ODE world (see scene_loader.hpp).
#include "mlcp/ode/scene_loader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
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

// A ball joint and an Euler angular motor whose stops limit each angle: twist about the axis
// (fixed in bodies[0]), swing1 about the normal (fixed in bodies[1]), swing2 about their cross
// product. Limits per angle make a pyramid of swings, not Bullet's elliptic cone; the middle
// Euler angle must stay below pi/2.
void addConeTwist(dWorldID world, const scene::Joint& j, dBodyID a, dBodyID b) {
  const auto& p = j.anchor;
  const auto& x = j.axis;
  if (j.cone.swing2 >= 1.5)
    throw scene::Unsupported("unsupported in ODE: cone_twist " + j.name +
                             ": swing2 of 1.5 rad or more (the middle angle of ODE's Euler "
                             "angular motor must stay below pi/2)");
  dJointID joint = dJointCreateBall(world, nullptr);
  dJointAttach(joint, a, b);
  dJointSetBallAnchor(joint, p[0], p[1], p[2]);
  dJointID motor = dJointCreateAMotor(world, nullptr);
  dJointAttach(motor, a, b);
  dJointSetAMotorMode(motor, dAMotorEuler);
  dJointSetAMotorAxis(motor, 0, 1, x[0], x[1], x[2]);
  dJointSetAMotorAxis(motor, 2, 2, j.normal[0], j.normal[1], j.normal[2]);
  const double stops[3] = {j.cone.twist, j.cone.swing2, j.cone.swing1};
  const int lo[3] = {dParamLoStop, dParamLoStop2, dParamLoStop3};
  const int hi[3] = {dParamHiStop, dParamHiStop2, dParamHiStop3};
  for (int i = 0; i < 3; ++i) {
    dJointSetAMotorParam(motor, lo[i], -stops[i]);
    dJointSetAMotorParam(motor, hi[i], stops[i]);
  }
}

void addUniversal(dWorldID world, const scene::Joint& j, dBodyID a, dBodyID b) {
  dJointID joint = dJointCreateUniversal(world, nullptr);
  dJointAttach(joint, a, b);
  dJointSetUniversalAnchor(joint, j.anchor[0], j.anchor[1], j.anchor[2]);
  dJointSetUniversalAxis1(joint, j.axis[0], j.axis[1], j.axis[2]);
  dJointSetUniversalAxis2(joint, j.axis2[0], j.axis2[1], j.axis2[2]);
}

void addHinge2(dWorldID world, double timeStep, const scene::Joint& j, dBodyID a, dBodyID b) {
  dJointID joint = dJointCreateHinge2(world, nullptr);
  dJointAttach(joint, a, b);
  dJointSetHinge2Anchor(joint, j.anchor[0], j.anchor[1], j.anchor[2]);
  dJointSetHinge2Axes(joint, j.axis.data(), j.axis2.data());
  setLimitsAndMotor(joint, j, &dJointSetHinge2Param);
  if (j.suspension.enabled) {
    // ODE's spring-damper as a soft constraint: erp = h k / (h k + c), cfm = 1 / (h k + c).
    const double hk = timeStep * j.suspension.stiffness, c = j.suspension.damping;
    if (hk + c <= 0)
      throw scene::Unsupported("unsupported in ODE: hinge2 " + j.name +
                               ": a suspension without stiffness or damping");
    dJointSetHinge2Param(joint, dParamSuspensionERP, hk / (hk + c));
    dJointSetHinge2Param(joint, dParamSuspensionCFM, 1 / (hk + c));
  }
}

// Parallel-axes mode turns the wheels in opposite senses about one common axis: the scene's
// w0 . axis = -ratio w1 . axis2 with axis2 = axis.
void addGear(dWorldID world, const scene::Joint& j, dBodyID a, dBodyID b) {
  const auto& x = j.axis;
  const auto& y = j.axis2;
  const double d = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
  if (std::abs(d - 1) > 1e-9)
    throw scene::Unsupported("unsupported in ODE: gear " + j.name +
                             ": axis2 differs from axis (dTransmissionParallelAxes turns "
                             "both wheels about one direction)");
  dJointID joint = dJointCreateTransmission(world, nullptr);
  dJointAttach(joint, a, b);
  dJointSetTransmissionMode(joint, dTransmissionParallelAxes);
  dJointSetTransmissionAnchor1(joint, j.anchor[0], j.anchor[1], j.anchor[2]);
  dJointSetTransmissionAnchor2(joint, j.anchor2[0], j.anchor2[1], j.anchor2[2]);
  dJointSetTransmissionAxis(joint, x[0], x[1], x[2]);
  // ODE's ratio is the first wheel's radius over the second's (transmission.cpp), the inverse
  // of the speed ratio the scene gives.
  dJointSetTransmissionRatio(joint, 1 / j.ratio);
}

// A geom of ODE class `cls` around the origin (no space, no body), to probe dCollide with.
dGeomID probeGeom(int cls) {
  // A unit cube as ODE's convex data: planes (n, d), corners, polygons (count, indices).
  static dReal planes[] = {1, 0,  0, 0.5, -1, 0, 0, 0.5, 0, 1, 0,  0.5,
                           0, -1, 0, 0.5, 0,  0, 1, 0.5, 0, 0, -1, 0.5};
  static dReal points[] = {-0.5, -0.5, -0.5, 0.5, -0.5, -0.5, 0.5, 0.5, -0.5, -0.5, 0.5, -0.5,
                           -0.5, -0.5, 0.5,  0.5, -0.5, 0.5,  0.5, 0.5, 0.5,  -0.5, 0.5, 0.5};
  static unsigned polygons[] = {4, 1, 2, 6, 5, 4, 0, 4, 7, 3, 4, 3, 7, 6, 2,
                                4, 0, 1, 5, 4, 4, 4, 5, 6, 7, 4, 0, 3, 2, 1};
  switch (cls) {
    case dSphereClass: return dCreateSphere(nullptr, 0.5);
    case dBoxClass: return dCreateBox(nullptr, 1, 1, 1);
    case dCapsuleClass: return dCreateCapsule(nullptr, 0.3, 0.5);
    case dCylinderClass: return dCreateCylinder(nullptr, 0.5, 1);
    case dPlaneClass: return dCreatePlane(nullptr, 0, 0, 1, 0);
    case dConvexClass: return dCreateConvex(nullptr, planes, 6, points, 8, polygons);
    default: return nullptr;
  }
}

// Whether this ODE build collides geoms of these two classes at all: dCollide returns 0 for
// a pair it has no collider for (Debian's libode is built without libccd: no cylinder-cylinder,
// capsule-cylinder or convex-cylinder), which must not pass for "no contact".
bool hasCollider(int a, int b) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, bool> known;
  std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::minmax(a, b);
  auto it = known.find(key);
  if (it != known.end()) return it->second;
  dGeomID g1 = probeGeom(a), g2 = probeGeom(b);
  dContactGeom c[4];
  const bool any = g1 && g2 && dCollide(g1, g2, 4, c, sizeof(dContactGeom)) > 0;
  if (g1) dGeomDestroy(g1);
  if (g2) dGeomDestroy(g2);
  return known[key] = any;
}

const char* className(int cls) {
  switch (cls) {
    case dSphereClass: return "sphere";
    case dBoxClass: return "box";
    case dCapsuleClass: return "capsule";
    case dCylinderClass: return "cylinder";
    case dPlaneClass: return "plane";
    case dConvexClass: return "convex_hull";
    default: return "?";
  }
}

// The scene index of a geom's body (static ones included).
int indexOf(dGeomID g) {
  return static_cast<int>(reinterpret_cast<std::intptr_t>(dGeomGetData(g)));
}

class OdeWorld : public scene::World {
 public:
  OdeWorld(const scene::Scene& s, const scene::RunSettings& run) : scene::World(s) {
    std::string stepperName = run.solver;
    if (run.friction == FrictionModel::Cone && run.solver.rfind("ode-", 0) == 0)
      throw std::invalid_argument("friction 'cone' needs a core solver; '" + run.solver +
                                  "' is ODE's own (box friction)");
    if (run.solver == "ode-world") {
      stepperName = "ode-lcp";
    } else if (run.solver == "ode-quick") {
      stepperName = "ode-quickstep";
      quick_ = true;
    } else if (!RowSolver::known(run.solver)) {
      throw std::invalid_argument("unknown solver '" + run.solver +
                                  "' for ODE (known: " + worldSolverNames() + ")");
    }
    Settings options;
    options.options.maxIterations = run.iterations;
    options.options.tolerance = run.tolerance;
    options.engineIterations = run.engineIterations;  // QuickStep iterations: run.iterations
    options.warmStart = run.warmStart;
    options.fallback = run.fallback;  // the stepper never falls back from "ode-..."
    options.acceptResidual = run.fallbackResidual;
    options.timeBudget = run.timeBudget;
    if (run.pivotingSteps >= 0)
      options.newton.pivotingSteps = options.newton.bodyPivotingSteps = run.pivotingSteps;
    options.friction = run.friction;
    options.frictionDirections = run.frictionDirections;
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
      m.unsolved = static_cast<int>(
          std::count_if(st.islands.begin(), st.islands.end(),
                        [](const IslandStats& is) { return is.rows > 0 && !is.accepted; }));
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
    : materials_(s.materials),
      maxContactsPerPair_(s.settings.maxContactsPerPair),
      timeStep_(s.settings.timeStep) {
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

  try {
    for (std::size_t i = 0; i < s.bodies.size(); ++i) addBody(s, static_cast<int>(i));
    for (const scene::Joint& j : s.joints) addJoint(j);
    for (const auto& [link, base] : s.fixedBaseNeighbours())
      noCollide_.insert(std::minmax(link, base));
  } catch (...) {  // scene::Unsupported: no destructor runs for a constructor that throws
    release();
    throw;
  }
}

OdeScene::~OdeScene() { release(); }

void OdeScene::release() {
  if (contacts_) dJointGroupDestroy(contacts_);
  if (space_) dSpaceDestroy(space_);  // destroys its geoms
  if (world_) dWorldDestroy(world_);  // destroys bodies and joints
  contacts_ = nullptr;
  space_ = nullptr;
  world_ = nullptr;
}

void OdeScene::collide() {
  contactCount_ = 0;
  deepest_ = 0;
  dSpaceCollide(space_, this, &OdeScene::nearCallback);
  if (!missingCollider_.empty()) throw scene::Unsupported(missingCollider_);
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
    case scene::ShapeType::Cylinder:
      g = dCreateCylinder(space_, b.shape.radius, b.shape.length);
      break;
    case scene::ShapeType::ConvexHull: g = createConvex(b.shape); break;
  }
  materialOf_[g] = b.material;
  dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::intptr_t>(index)));
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
    default: addOtherJoint(j, a, b); break;
  }
  if (!j.collideConnected && j.body1 >= 0) noCollide_.insert(std::minmax(j.body0, j.body1));
}

dGeomID OdeScene::createConvex(const scene::Shape& shape) {
  auto hull = std::make_unique<HullData>();
  for (const scene::Vec3& p : shape.hullPoints)
    hull->points.insert(hull->points.end(), p.begin(), p.end());
  for (const std::vector<int>& face : shape.hullFaces) {
    const scene::Vec3& p0 = shape.hullPoints[face[0]];
    const scene::Vec3& p1 = shape.hullPoints[face[1]];
    const scene::Vec3& p2 = shape.hullPoints[face[2]];
    const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& c : n) c /= len;  // outward: the corners run counter-clockwise
    hull->planes.insert(hull->planes.end(),
                        {n[0], n[1], n[2], n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]});
    hull->polygons.push_back(static_cast<unsigned>(face.size()));
    for (int i : face) hull->polygons.push_back(static_cast<unsigned>(i));
  }
  dGeomID g = dCreateConvex(space_, hull->planes.data(),
                            static_cast<unsigned>(shape.hullFaces.size()), hull->points.data(),
                            static_cast<unsigned>(shape.hullPoints.size()), hull->polygons.data());
  hulls_.push_back(std::move(hull));  // ODE keeps pointers into these arrays
  return g;
}

void OdeScene::addOtherJoint(const scene::Joint& j, dBodyID a, dBodyID b) {
  switch (j.type) {
    case scene::JointType::ConeTwist: addConeTwist(world_, j, a, b); break;
    case scene::JointType::Universal: addUniversal(world_, j, a, b); break;
    case scene::JointType::Hinge2: addHinge2(world_, timeStep_, j, a, b); break;
    case scene::JointType::Gear: addGear(world_, j, a, b); break;
    case scene::JointType::SixDof:
      throw scene::Unsupported("unsupported in ODE: six_dof joint " + j.name +
                               " (ODE has no joint with per-axis limits and springs)");
    default:
      throw scene::Unsupported(std::string("unsupported in ODE: joint type ") +
                               scene::toString(j.type));
  }
}

void OdeScene::nearCallback(void* data, dGeomID g1, dGeomID g2) {
  auto* w = static_cast<OdeScene*>(data);
  dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
  if (!b1 && !b2) return;
  if (w->noCollide_.count(std::minmax(indexOf(g1), indexOf(g2)))) return;
  const int n = w->maxContactsPerPair_;
  w->buffer_.resize(n);
  const int found = dCollide(g1, g2, n, &w->buffer_[0].geom, sizeof(dContact));
  const int c1 = dGeomGetClass(g1), c2 = dGeomGetClass(g2);
  if (found == 0 && w->missingCollider_.empty() && !hasCollider(c1, c2))
    w->missingCollider_ = std::string("unsupported in ODE: contacts between ") + className(c1) +
                          " and " + className(c2) + " (this ODE build has no collider for them)";
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
