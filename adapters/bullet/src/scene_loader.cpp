// An mlcp-scene/1 scene in a stock btDiscreteDynamicsWorld (see scene_loader.hpp).
#include "mlcp/bullet/scene_loader.hpp"

#include <BulletDynamics/ConstraintSolver/btGearConstraint.h>
#include <BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h>
#include <BulletDynamics/ConstraintSolver/btHinge2Constraint.h>
#include <BulletDynamics/ConstraintSolver/btNNCGConstraintSolver.h>
#include <BulletDynamics/ConstraintSolver/btUniversalConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyMLCPConstraintSolver.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btLemkeSolver.h>
#include <BulletDynamics/MLCPSolvers/btSolveProjectedGaussSeidel.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "mlcp/bullet/worlds.hpp"
#include "mlcp/registry.hpp"
#include "scene_bullet.hpp"
#include "scenes.hpp"

namespace mlcp::bullet {

namespace {

using scene::Vec3;

double now() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// The scene's restitution rule, max(e_a, e_b), in place of Bullet's product.
btScalar maxRestitution(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRestitution(), b->getRestitution());
}

// Forwards to the real solver and times its solveGroup calls (stock solvers have no timer).
class TimedSolver : public btConstraintSolver {
 public:
  explicit TimedSolver(std::unique_ptr<btConstraintSolver> inner) : inner_(std::move(inner)) {}
  void prepareSolve(int numBodies, int numManifolds) override {
    inner_->prepareSolve(numBodies, numManifolds);
  }
  btScalar solveGroup(btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds,
                      int numManifolds, btTypedConstraint** constraints, int numConstraints,
                      const btContactSolverInfo& info, btIDebugDraw* debugDrawer,
                      btDispatcher* dispatcher) override {
    const double t0 = now();
    const btScalar r = inner_->solveGroup(bodies, numBodies, manifolds, numManifolds, constraints,
                                          numConstraints, info, debugDrawer, dispatcher);
    seconds += now() - t0;
    return r;
  }
  void allSolved(const btContactSolverInfo& info, btIDebugDraw* debugDrawer) override {
    inner_->allSolved(info, debugDrawer);
  }
  void reset() override { inner_->reset(); }
  btConstraintSolverType getSolverType() const override { return inner_->getSolverType(); }

  btConstraintSolver* inner() const { return inner_.get(); }
  double seconds = 0;

 private:
  std::unique_ptr<btConstraintSolver> inner_;
};

// Collision margin of convex hulls, m: Bullet inflates a hull by its margin (0.04 m by
// default, which would lift a stack of 0.5 m hulls by 8 cm); 1 mm keeps GJK's margin without
// changing the shape visibly.
constexpr double kHullMargin = 0.001;

// Frame at `anchor` with columns x, y, x cross y (world).
btTransform frameXY(const Vec3& anchor, const Vec3& x, const Vec3& y) {
  const btVector3 ex = bt(x).normalized(), ey = bt(y).normalized(), ez = ex.cross(ey);
  btMatrix3x3 m(ex.x(), ey.x(), ez.x(), ex.y(), ey.y(), ez.y(), ex.z(), ey.z(), ez.z());
  return btTransform(m, bt(anchor));
}

// Frame at `anchor` whose `axisColumn` column is `axis` (world), right-handed.
btTransform jointFrame(const Vec3& anchor, const Vec3& axis, int axisColumn) {
  btVector3 a = bt(axis).normalized(), p, q;
  btPlaneSpace1(a, p, q);  // p, q, a right-handed
  btMatrix3x3 m;
  if (axisColumn == 2)
    m.setValue(p.x(), q.x(), a.x(), p.y(), q.y(), a.y(), p.z(), q.z(), a.z());
  else  // x = a, y = p, z = q
    m.setValue(a.x(), p.x(), q.x(), a.y(), p.y(), q.y(), a.z(), p.z(), q.z());
  return btTransform(m, bt(anchor));
}

// The adapter's settings for a core solver run by these run settings.
Settings coreSettings(const scene::RunSettings& run) {
  Settings settings;
  settings.solver = run.solver;
  settings.options.maxIterations = run.iterations;
  settings.options.tolerance = run.tolerance;
  settings.warmStart = run.warmStart;
  settings.fallback = run.fallback;
  settings.acceptResidual = run.fallbackResidual;
  settings.engineIterations = run.engineIterations;  // m_numIterations is run.iterations
  settings.timeBudget = run.timeBudget;
  if (run.pivotingSteps >= 0)
    settings.newton.pivotingSteps = settings.newton.bodyPivotingSteps = run.pivotingSteps;
  settings.friction = run.friction;
  settings.frictionDirections = run.frictionDirections;
  return settings;
}

// A btMultiBodyDynamicsWorld's solver, timed where the world hands it each island.
template <class Base>
class TimedMultiBody : public Base {
 public:
  using Base::Base;
  void solveMultiBodyGroup(btCollisionObject** bodies, int numBodies,
                           btPersistentManifold** manifolds, int numManifolds,
                           btTypedConstraint** constraints, int numConstraints,
                           btMultiBodyConstraint** multiBodyConstraints,
                           int numMultiBodyConstraints, const btContactSolverInfo& info,
                           btIDebugDraw* debugDrawer, btDispatcher* dispatcher) override {
    const double t0 = now();
    Base::solveMultiBodyGroup(bodies, numBodies, manifolds, numManifolds, constraints,
                              numConstraints, multiBodyConstraints, numMultiBodyConstraints, info,
                              debugDrawer, dispatcher);
    seconds += now() - t0;
  }
  double seconds = 0;
};

// Bullet's own MLCP solvers by the name after "bullet-mlcp-" ("pgs", "dantzig", "lemke").
std::unique_ptr<btMLCPSolverInterface> makeBulletMlcp(const std::string& which) {
  if (which == "pgs") return std::make_unique<btSolveProjectedGaussSeidel>();
  if (which == "dantzig") return std::make_unique<btDantzigSolver>();
  if (which == "lemke") return std::make_unique<btLemkeSolver>();
  return nullptr;
}

class BulletWorld : public scene::World {
 public:
  BulletWorld(const scene::Scene& s, const scene::RunSettings& run, Coordinates coordinates)
      : scene::World(s), reduced_(coordinates == Coordinates::Reduced) {
    std::unique_ptr<btConstraintSolver> solver;
    const std::string& name = run.solver;
    if (run.friction == FrictionModel::Cone && name.rfind("bullet-", 0) == 0)
      throw std::invalid_argument("friction 'cone' needs a core solver; '" + name +
                                  "' is Bullet's own (box friction)");
    iterations_ = run.iterations;
    tolerance_ = run.tolerance;
    if (reduced_) {
      makeMultiBodyWorld(s, run);
      return;
    }
    if (name == "bullet-si") {
      solver = std::make_unique<btSequentialImpulseConstraintSolver>();
      fixedSweeps_ = true;
    } else if (name == "bullet-nncg") {
      solver = std::make_unique<btNNCGConstraintSolver>();
      fixedSweeps_ = true;
    } else if (name.rfind("bullet-mlcp-", 0) == 0) {
      solver = scenes::makeBulletSolver(name.substr(7));
      stock_ = static_cast<scenes::StockMlcp*>(solver.get());
      pivoting_ = name != "bullet-mlcp-pgs";
    } else if (!RowSolver::known(name)) {
      throw std::invalid_argument("unknown solver '" + name +
                                  "' for Bullet (known: " + worldSolverNames() + ")");
    } else {
      solver = scenes::makeBulletSolver(name, coreSettings(run));  // throws for unknown names
      ours_ = static_cast<ConstraintSolver*>(solver.get());
    }
    timed_ = std::make_unique<TimedSolver>(std::move(solver));
    built_ = buildWorld(s, run);
    built_->world().setConstraintSolver(timed_.get());
  }

  std::vector<scene::BodyState> states() const override { return built_->states(); }
  const char* engine() const override { return reduced_ ? "bullet-multibody" : "bullet"; }

  bool captureNextStep(const std::string& folder) override {
    captured_.clear();
    if (!ours_ || !ours_->rowSolver()) return false;
    capturing_ = true;
    ours_->rowSolver()->setCapture(
        scene::capturePrefix(folder, scene().name, engine(), stepsTaken()));
    return true;
  }
  std::vector<std::string> capturedFiles() const override { return captured_; }

 protected:
  void stepEngine(scene::StepMeasures& m) override {
    double untimed = 0;  // ours in a multibody world: lastStep() has the time
    double& seconds = multiBodySeconds_ ? *multiBodySeconds_ : timed_ ? timed_->seconds : untimed;
    seconds = 0;
    const int fallbacksBefore = stock_ ? stock_->fallbacks() : 0;
    const double h = scene().settings.timeStep;
    built_->world().stepSimulation(h, 0, h);
    if (capturing_) {
      captured_ = ours_->rowSolver()->capturedFiles();
      ours_->rowSolver()->setCapture("");
      capturing_ = false;
    }
    m.solverMs = 1e3 * seconds;
    if (ours_) {
      const StepStats& st = ours_->lastStep();
      m.solverMs = 1e3 * (st.seconds);
      m.residual = st.residual;
      m.iterations = st.iterations;
      m.status = toString(st.status);
      m.fallbacks = st.fallbacks;
      m.unsolved = st.failures;
      m.choice = st.choices.toString();
    } else if (stock_) {
      m.solverMs -= 1e3 * stock_->stepMeasureSeconds();
      m.residual = stock_->stepResidual();
      m.fallbacks = stock_->fallbacks() - fallbacksBefore;
      m.iterations = pivoting_ ? 0 : iterations_;
      m.status = m.residual <= tolerance_ ? "converged" : pivoting_ ? "failed" : "max-iterations";
    } else {
      m.iterations = pivoting_ ? 0 : iterations_;
      m.status = "max-iterations";
    }
    double deepest = 0;
    int contacts = 0;
    btDispatcher& dispatcher = *built_->world().getDispatcher();
    for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
      const btPersistentManifold* pm = dispatcher.getManifoldByIndexInternal(i);
      for (int k = 0; k < pm->getNumContacts(); ++k) {
        ++contacts;
        deepest = std::max(deepest, -double(pm->getContactPoint(k).getDistance()));
      }
    }
    m.contacts = contacts;
    m.maxPenetration = deepest;
  }

 private:
  // A btMultiBodyDynamicsWorld: Bullet's own solvers by name (SI, or its MLCP path with its own
  // MLCP solvers), or ours through install().
  void makeMultiBodyWorld(const scene::Scene& s, const scene::RunSettings& run) {
    const std::string& name = run.solver;
    if (name.rfind("bullet-mlcp-", 0) == 0) mlcp_ = makeBulletMlcp(name.substr(12));
    if (name != "bullet-si" && !mlcp_ && !RowSolver::known(name))
      throw std::invalid_argument("unknown solver '" + name + "' for bullet-multibody (known: " +
                                  worldSolverNames(Coordinates::Reduced) + ")");
    built_ = buildWorld(s, run, Coordinates::Reduced);
    auto& world = static_cast<btMultiBodyDynamicsWorld&>(built_->world());
    if (mlcp_) {
      pivoting_ = name != "bullet-mlcp-pgs";
      auto solver = std::make_unique<TimedMultiBody<btMultiBodyMLCPConstraintSolver>>(mlcp_.get());
      multiBodySeconds_ = &solver->seconds;
      multiBodySolver_ = std::move(solver);
    } else if (name == "bullet-si") {
      auto solver = std::make_unique<TimedMultiBody<btMultiBodyConstraintSolver>>();
      multiBodySeconds_ = &solver->seconds;
      multiBodySolver_ = std::move(solver);
    } else {
      solver_ = std::make_unique<ConstraintSolver>(coreSettings(run));
      ours_ = solver_.get();
      try {
        install(world, *solver_);  // the one call that puts a core solver in any Bullet world
      } catch (const std::invalid_argument& e) {
        throw scene::Unsupported("unsupported in bullet-multibody: solver '" + name + "' (" +
                                 e.what() + ")");
      }
      return;
    }
    world.setMultiBodyConstraintSolver(multiBodySolver_.get());
  }

  bool reduced_ = false;
  // Reduced: the solver in the world (ours, or Bullet's), destroyed after built_.
  std::unique_ptr<ConstraintSolver> solver_;
  std::unique_ptr<btMLCPSolverInterface> mlcp_;
  std::unique_ptr<btMultiBodyConstraintSolver> multiBodySolver_;
  double* multiBodySeconds_ = nullptr;
  std::unique_ptr<TimedSolver> timed_;
  ConstraintSolver* ours_ = nullptr;
  scenes::StockMlcp* stock_ = nullptr;
  bool fixedSweeps_ = false, pivoting_ = false, capturing_ = false;
  std::vector<std::string> captured_;
  int iterations_ = 0;
  double tolerance_ = 0;
  // After timed_: the world is destroyed before the solver it points at.
  std::unique_ptr<BulletScene> built_;
};

}  // namespace

BulletScene::BulletScene(const scene::Scene& s, const scene::RunSettings& run,
                         Coordinates coordinates)
    : timeStep_(s.settings.timeStep) {
  gCalculateCombinedRestitutionCallback = &maxRestitution;
  config_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  if (coordinates == Coordinates::Reduced) {
    auto solver = std::make_unique<btMultiBodyConstraintSolver>();
    world_ = std::make_unique<btMultiBodyDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                        solver.get(), config_.get());
    stockSolver_ = std::move(solver);
  } else {
    stockSolver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                       stockSolver_.get(), config_.get());
  }
  world_->setGravity(bt(s.gravity));
  btContactSolverInfo& info = world_->getSolverInfo();
  info.m_timeStep = s.settings.timeStep;
  info.m_erp = info.m_erp2 = s.settings.erp;
  info.m_globalCfm = s.settings.cfm;
  info.m_numIterations = run.iterations;
  info.m_minimumSolverBatchSize = 1;
  // Two friction rows per contact, as ODE's dContactApprox1 (a friction pyramid), with
  // directions kept per contact so that friction warm starts (see scene_loader.hpp).
  info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                       SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
  if (!run.warmStart) info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
  addContent(s, coordinates);
}

void BulletScene::addContent(const scene::Scene& s, Coordinates coordinates) {
  // Reduced: the articulations' bodies and link joints are the btMultiBodies' (one owner each).
  std::vector<bool> inMultiBody(s.bodies.size(), false), jointInMultiBody(s.joints.size(), false);
  if (coordinates == Coordinates::Reduced)
    for (const scene::Articulation& a : s.articulations) {
      inMultiBody[a.base] = true;
      for (const scene::ArticulatedLink& l : a.links)
        inMultiBody[l.body] = jointInMultiBody[l.joint] = true;
    }
  linkOf_.assign(s.bodies.size(), {nullptr, -1});
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (!inMultiBody[i])
      addBody(s, s.bodies[i]);
    else
      bodyPointers_.push_back(nullptr);
  }
  for (std::size_t i = 0; i < s.joints.size(); ++i)
    if (!jointInMultiBody[i]) addJoint(s.joints[i]);
  if (coordinates == Coordinates::Reduced)
    for (const scene::Articulation& a : s.articulations) addMultiBody(s, a);
  else
    ignoreFixedBaseContacts(s, {bodyPointers_.begin(), bodyPointers_.end()});
}

BulletScene::~BulletScene() {
  for (auto& c : constraints_) world_->removeConstraint(c.get());
  for (auto& b : bodies_) world_->removeRigidBody(b.get());
  if (auto* mw = dynamic_cast<btMultiBodyDynamicsWorld*>(world_.get())) {
    for (auto& c : multiBodyConstraints_) mw->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders_) mw->removeCollisionObject(c.get());
    for (auto& m : multiBodies_) mw->removeMultiBody(m.get());
  }
  world_.reset();
}

std::unique_ptr<btCollisionShape> BulletScene::makeShape(const scene::Body& b) {
  std::unique_ptr<btCollisionShape> shape;
  switch (b.shape.type) {
    case scene::ShapeType::Plane:
      shape = std::make_unique<btStaticPlaneShape>(bt(b.shape.normal), b.shape.offset);
      break;
    case scene::ShapeType::Box: shape = std::make_unique<btBoxShape>(0.5 * bt(b.shape.size)); break;
    case scene::ShapeType::Sphere: shape = std::make_unique<btSphereShape>(b.shape.radius); break;
    case scene::ShapeType::Capsule:
      shape = std::make_unique<btCapsuleShapeZ>(b.shape.radius, b.shape.length);
      break;
    case scene::ShapeType::Cylinder:
      shape = std::make_unique<btCylinderShapeZ>(
          btVector3(b.shape.radius, b.shape.radius, b.shape.length / 2));
      break;
    case scene::ShapeType::ConvexHull: {
      auto hull = std::make_unique<btConvexHullShape>();
      for (const Vec3& p : b.shape.hullPoints) hull->addPoint(bt(p), false);
      hull->recalcLocalAabb();
      hull->setMargin(kHullMargin);
      // Face data for the separating-axis contact clipping (m_enableSatConvex), which gives
      // hull-hull pairs full contact manifolds from their first step.
      hull->initializePolyhedralFeatures();
      world_->getDispatchInfo().m_enableSatConvex = true;
      shape = std::move(hull);
      break;
    }
  }
  return shape;
}

void BulletScene::addBody(const scene::Scene& s, const scene::Body& b) {
  std::unique_ptr<btCollisionShape> shape = makeShape(b);
  btTransform pose;
  pose.setIdentity();
  if (b.shape.type != scene::ShapeType::Plane) pose = poseOf(b);
  motion_.push_back(std::make_unique<btDefaultMotionState>(pose));
  btRigidBody::btRigidBodyConstructionInfo ci(b.mass, motion_.back().get(), shape.get(),
                                              bt(b.inertia));
  bodies_.push_back(std::make_unique<btRigidBody>(ci));
  btRigidBody* body = bodies_.back().get();
  setMaterial(*body, s.materials[b.material]);
  bodyPointers_.push_back(body);
  if (!b.isStatic()) {
    body->setLinearVelocity(bt(b.velocity));
    body->setAngularVelocity(bt(b.angularVelocity));
    if (!s.settings.sleeping) body->setActivationState(DISABLE_DEACTIVATION);
  }
  shapes_.push_back(std::move(shape));
  world_->addRigidBody(body);
}

void BulletScene::addJoint(const scene::Joint& j) {
  btRigidBody& a = *bodyPointers_[j.body0];
  btRigidBody& b = j.body1 >= 0 ? *bodyPointers_[j.body1] : btTypedConstraint::getFixedBody();
  const btTransform ta = a.getCenterOfMassTransform().inverse();
  const btTransform tb = b.getCenterOfMassTransform().inverse();
  // Bullet's slider offset is B's relative to A (its hinge angle is A's relative to B, as the
  // scene's): the reversed axis gives the slider A's offset relative to B.
  const Vec3 reversed{-j.axis[0], -j.axis[1], -j.axis[2]};
  std::unique_ptr<btTypedConstraint> c;
  const double dt = timeStep_;
  switch (j.type) {
    case scene::JointType::Ball:
      c = std::make_unique<btPoint2PointConstraint>(a, b, ta * bt(j.anchor), tb * bt(j.anchor));
      break;
    case scene::JointType::Hinge: {
      const btTransform f = jointFrame(j.anchor, j.axis, 2);
      auto h = std::make_unique<btHingeConstraint>(a, b, ta * f, tb * f);
      if (j.limits.enabled) h->setLimit(j.limits.lower, j.limits.upper, 1.0, 0.3, 1.0);
      if (j.motor.enabled) h->enableAngularMotor(true, j.motor.velocity, j.motor.maxForce * dt);
      c = std::move(h);
      break;
    }
    case scene::JointType::Slider: {
      const btTransform f = jointFrame(j.anchor, reversed, 0);
      auto sl = std::make_unique<btSliderConstraint>(a, b, ta * f, tb * f, true);
      if (j.limits.enabled) {
        sl->setLowerLinLimit(j.limits.lower);
        sl->setUpperLinLimit(j.limits.upper);
      }
      if (j.motor.enabled) {
        sl->setPoweredLinMotor(true);
        sl->setTargetLinMotorVelocity(j.motor.velocity);
        sl->setMaxLinMotorForce(j.motor.maxForce);
      }
      c = std::move(sl);
      break;
    }
    case scene::JointType::Fixed: {
      const btTransform f = jointFrame(j.anchor, {0, 0, 1}, 2);
      c = std::make_unique<btFixedConstraint>(a, b, ta * f, tb * f);
      break;
    }
    default: c = makeJoint(j, a, b); break;
  }
  world_->addConstraint(c.get(), !j.collideConnected);
  constraints_.push_back(std::move(c));
}

std::unique_ptr<btTypedConstraint> BulletScene::makeJoint(const scene::Joint& j, btRigidBody& a,
                                                          btRigidBody& b) const {
  const btTransform ta = a.getCenterOfMassTransform().inverse();
  const btTransform tb = b.getCenterOfMassTransform().inverse();
  btVector3 anchor = bt(j.anchor), axis = bt(j.axis), axis2 = bt(j.axis2);
  switch (j.type) {
    case scene::JointType::ConeTwist: {
      // Bullet's cone-twist frame: x the twist axis, z the swing1 axis (span index 5), so
      // y = normal x axis.
      const btTransform f = frameXY(j.anchor, j.axis, vec(bt(j.normal).cross(bt(j.axis))));
      auto c = std::make_unique<btConeTwistConstraint>(a, b, ta * f, tb * f);
      c->setLimit(j.cone.swing1, j.cone.swing2, j.cone.twist);
      return c;
    }
    case scene::JointType::SixDof: {
      // Bullet measures its body B relative to A: B is the scene's bodies[0].
      const btTransform f = frameXY(j.anchor, j.axis, j.normal);
      auto c = std::make_unique<btGeneric6DofSpring2Constraint>(b, a, tb * f, ta * f, RO_XYZ);
      for (int i = 0; i < 6; ++i) {
        const scene::AxisDof& d = j.dofs[i];
        switch (d.mode) {
          case scene::AxisDof::Mode::Locked: c->setLimit(i, 0, 0); break;
          case scene::AxisDof::Mode::Free: c->setLimit(i, 1, -1); break;  // lower > upper: free
          case scene::AxisDof::Mode::Limited: c->setLimit(i, d.lower, d.upper); break;
        }
        if (d.spring.enabled) {
          c->enableSpring(i, true);
          c->setStiffness(i, d.spring.stiffness, false);  // as given, not capped (see header)
          c->setDamping(i, d.spring.damping, false);
        }
      }
      c->setEquilibriumPoint();  // the springs' rest pose is the pose at creation
      return c;
    }
    case scene::JointType::Universal:
      return std::make_unique<btUniversalConstraint>(a, b, anchor, axis, axis2);
    case scene::JointType::Hinge2: {
      auto c = std::make_unique<btHinge2Constraint>(a, b, anchor, axis, axis2);
      c->setLowerLimit(j.limits.lower);
      c->setUpperLimit(j.limits.upper);
      if (j.suspension.enabled) {
        c->setStiffness(2, j.suspension.stiffness, false);
        c->setDamping(2, j.suspension.damping, false);
        c->setEquilibriumPoint(2);
      } else {
        c->enableSpring(2, false);
        c->setLinearLowerLimit(btVector3(0, 0, 0));
        c->setLinearUpperLimit(btVector3(0, 0, 0));
      }
      return c;
    }
    case scene::JointType::Gear: {
      const btVector3 inA = a.getCenterOfMassTransform().getBasis().transpose() * axis;
      const btVector3 inB = b.getCenterOfMassTransform().getBasis().transpose() * axis2;
      return std::make_unique<btGearConstraint>(a, b, inA, inB, j.ratio);
    }
    default: break;
  }
  throw scene::Unsupported(std::string("unsupported in Bullet: joint type ") +
                           scene::toString(j.type));
}

std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene, const scene::RunSettings& run,
                                        Coordinates coordinates) {
  return std::make_unique<BulletScene>(scene, run, coordinates);
}

std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene) {
  return buildWorld(scene, scene::RunSettings::fromScene(scene));
}

std::string worldSolverNames(Coordinates coordinates) {
  const char* nncg = coordinates == Coordinates::Maximal ? ", bullet-nncg" : "";
  return solverNames() + ", bullet-si" + nncg +
         ", bullet-mlcp-pgs, bullet-mlcp-dantzig, bullet-mlcp-lemke";
}

std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings,
                                        Coordinates coordinates) {
  return std::make_unique<BulletWorld>(scene, settings, coordinates);
}

}  // namespace mlcp::bullet
