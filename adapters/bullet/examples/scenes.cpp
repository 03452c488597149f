#include "scenes.hpp"

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorldMt.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btLemkeSolver.h>
#include <BulletDynamics/MLCPSolvers/btSolveProjectedGaussSeidel.h>

#include <cmath>
#include <stdexcept>

#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::bullet::scenes {

StockMlcp::StockMlcp(std::unique_ptr<btMLCPSolverInterface> method)
    : btMLCPSolver(method.get()), method_(std::move(method)) {}

StockMlcp::~StockMlcp() = default;

void StockMlcp::prepareSolve(int numBodies, int numManifolds) {
  btMLCPSolver::prepareSolve(numBodies, numManifolds);
  stepResidual_ = 0;
  stepMeasure_ = 0;
}

bool StockMlcp::solveMLCP(const btContactSolverInfo& info) {
  const bool ok = btMLCPSolver::solveMLCP(info);
  if (!ok || !measure || m_A.rows() == 0) return ok;
  const double t0 = nowSeconds();
  const int n = m_A.rows();
  DenseMatrix A(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) A(r, c) = m_A(r, c);
  Problem p(std::move(A), Vector::Zero(n));
  Vector x(n);
  p.findex.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    p.b[i] = -m_b[i];
    p.lo[i] = m_lo[i];
    p.hi[i] = m_hi[i];
    p.findex[i] = m_limitDependencies[i];
    x[i] = m_x[i];
  }
  const double r = accuracy(p, x).residual;
  if (!(r <= stepResidual_)) stepResidual_ = r;  // NaN-propagating max
  stepMeasure_ += nowSeconds() - t0;
  return ok;
}

std::string bulletSolverNames() {
  return "si, mlcp-pgs, mlcp-dantzig, mlcp-lemke, si-stats, " + solverNames();
}

std::unique_ptr<btConstraintSolver> makeBulletSolver(const std::string& name, Settings settings) {
  if (name == "si") return std::make_unique<btSequentialImpulseConstraintSolver>();
  if (name == "mlcp-pgs")
    return std::make_unique<StockMlcp>(std::make_unique<btSolveProjectedGaussSeidel>());
  if (name == "mlcp-dantzig")
    return std::make_unique<StockMlcp>(std::make_unique<btDantzigSolver>());
  if (name == "mlcp-lemke") return std::make_unique<StockMlcp>(std::make_unique<btLemkeSolver>());
  settings.solver = name == "si-stats" ? "si" : name;
  if (settings.solver != "si" && !makeSolver(settings.solver))
    throw std::invalid_argument("unknown solver '" + name + "' (known: " + bulletSolverNames() +
                                ")");
  return std::make_unique<ConstraintSolver>(settings);
}

World::World(double dt, bool twoFrictionDirections, WorldKind kind) : dt_(dt) {
  config_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  switch (kind) {
    case WorldKind::Discrete:
      solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
      world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                         solver_.get(), config_.get());
      break;
    case WorldKind::DiscreteMt: {
      auto pool = std::make_unique<btConstraintSolverPoolMt>(1);
      kept_.push_back(std::make_unique<btSequentialImpulseConstraintSolver>());
      world_ = std::make_unique<btDiscreteDynamicsWorldMt>(
          dispatcher_.get(), broadphase_.get(), pool.get(), kept_.back().get(), config_.get());
      solver_ = std::move(pool);
      break;
    }
    case WorldKind::MultiBody: {
      auto mb = std::make_unique<btMultiBodyConstraintSolver>();
      world_ = std::make_unique<btMultiBodyDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                          mb.get(), config_.get());
      solver_ = std::move(mb);
      break;
    }
  }
  world_->setGravity(btVector3(0, -9.81, 0));
  if (twoFrictionDirections) info().m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
}

World::~World() {
  for (auto& c : constraints_) world_->removeConstraint(c.get());
  for (auto& b : bodies_) world_->removeRigidBody(b.get());
  world_.reset();
}

void World::setSolver(std::unique_ptr<btConstraintSolver> solver) {
  // A multibody world keeps its multibody solver in its island callback: the one replaced stays
  // alive.
  if (dynamic_cast<btMultiBodyDynamicsWorld*>(world_.get()) && kept_.empty())
    kept_.push_back(std::move(solver_));
  world_->setConstraintSolver(solver.get());
  // Direct solvers want one island per call (what Bullet's own demos set for them).
  if (solver->getSolverType() == BT_MLCP_SOLVER) info().m_minimumSolverBatchSize = 1;
  solver_ = std::move(solver);
}

namespace {
btRigidBody* addBody(World& w, std::vector<std::unique_ptr<btCollisionShape>>& shapes,
                     std::vector<std::unique_ptr<btMotionState>>& motion,
                     std::vector<std::unique_ptr<btRigidBody>>& bodies,
                     std::unique_ptr<btCollisionShape> shape, double mass, const btTransform& pose,
                     double friction, double restitution) {
  btVector3 inertia(0, 0, 0);
  if (mass > 0) shape->calculateLocalInertia(mass, inertia);
  motion.push_back(std::make_unique<btDefaultMotionState>(pose));
  btRigidBody::btRigidBodyConstructionInfo ci(mass, motion.back().get(), shape.get(), inertia);
  ci.m_friction = friction;
  ci.m_restitution = restitution;
  bodies.push_back(std::make_unique<btRigidBody>(ci));
  btRigidBody* body = bodies.back().get();
  // Scenes are short and measured: no deactivation, so every step solves every body.
  body->setActivationState(DISABLE_DEACTIVATION);
  shapes.push_back(std::move(shape));
  w.world().addRigidBody(body);
  return body;
}
}  // namespace

btRigidBody* World::addBox(const btVector3& halfExtents, double mass, const btTransform& pose,
                           double friction, double restitution) {
  btRigidBody* b =
      addBody(*this, shapes_, motion_, bodies_, std::make_unique<btBoxShape>(halfExtents), mass,
              pose, friction, restitution);
  if (mass > 0) dynamic_.push_back(b);
  return b;
}

btRigidBody* World::addSphere(double radius, double mass, const btVector3& position,
                              double friction, double restitution) {
  btTransform pose;
  pose.setIdentity();
  pose.setOrigin(position);
  btRigidBody* b =
      addBody(*this, shapes_, motion_, bodies_, std::make_unique<btSphereShape>(radius), mass, pose,
              friction, restitution);
  if (mass > 0) dynamic_.push_back(b);
  return b;
}

btRigidBody* World::addShape(std::unique_ptr<btCollisionShape> shape, double mass,
                             const btTransform& pose, double friction) {
  btRigidBody* b =
      addBody(*this, shapes_, motion_, bodies_, std::move(shape), mass, pose, friction, 0);
  if (mass > 0) dynamic_.push_back(b);
  return b;
}

btRigidBody* World::addGround(double friction, double tilt) {
  btTransform pose;
  pose.setIdentity();
  pose.setRotation(btQuaternion(btVector3(0, 0, 1), tilt));
  // The slab's top face passes through the origin: its centre is 0.5 m below, along its normal.
  pose.setOrigin(pose.getBasis() * btVector3(0, -0.5, 0));
  return addBox(btVector3(50, 0.5, 50), 0, pose, friction);
}

void World::addConstraint(std::unique_ptr<btTypedConstraint> c, bool disableCollisions) {
  world_->addConstraint(c.get(), disableCollisions);
  constraints_.push_back(std::move(c));
}

void World::step(int steps) {
  for (int i = 0; i < steps; ++i) world_->stepSimulation(dt_, 0, dt_);
}

namespace {
btTransform at(double x, double y, double z) {
  btTransform t;
  t.setIdentity();
  t.setOrigin(btVector3(x, y, z));
  return t;
}
}  // namespace

void pyramid(World& w, int boxes, double friction) {
  int base = 0;
  while (base * (base + 1) / 2 < boxes) ++base;
  if (base * (base + 1) / 2 != boxes)
    throw std::invalid_argument("pyramid: box count must be a triangular number (15, 55, 210)");
  w.addGround(1.0);
  for (int level = 0; level < base; ++level)
    for (int i = 0; i < base - level; ++i)
      w.addBox(btVector3(0.5, 0.5, 0.5), 1.0,
               at(i * 1.0 + level * 0.5 - base * 0.5, 0.5 + level * 1.0, 0), friction);
}

void stack(World& w, int count, double friction) {
  w.addGround(1.0);
  for (int i = 0; i < count; ++i)
    w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, at(0, 0.5 + i * 1.0, 0), friction);
}

btRigidBody* incline(World& w, double theta, double mu) {
  w.addGround(1.0, theta);  // combined friction = product of the two bodies' frictions
  btTransform pose;
  pose.setIdentity();
  pose.setRotation(btQuaternion(btVector3(0, 0, 1), theta));
  pose.setOrigin(pose.getBasis() * btVector3(0, 0.5, 0));
  return w.addBox(btVector3(0.5, 0.5, 0.5), 1.0, pose, mu);
}

void frictionlessDrop(World& w) {
  w.addGround(0.0);
  w.addSphere(0.5, 1.0, btVector3(0, 1.5, 0), 0.0);
  w.addSphere(0.3, 2.0, btVector3(2, 0.8, 0.5), 0.0);
  w.addSphere(0.4, 0.5, btVector3(-2, 2.0, -1), 0.0);
  btTransform pose = at(0, 0.7, 3);
  pose.setRotation(btQuaternion(btVector3(1, 0, 0), 0.3));
  w.addBox(btVector3(0.5, 0.25, 0.5), 1.0, pose, 0.0);
}

void joints(World& w) {
  const btVector3 half(0.1, 0.5, 0.1);
  // A chain of two links hanging from the world point (0, 3, 0), started 0.3 rad aside (small
  // swings: a wide double pendulum is chaotic and no two solvers would agree for long).
  btRigidBody* prev = nullptr;
  const double swing = 0.3;
  for (int i = 0; i < 2; ++i) {
    btTransform pose =
        at((0.5 + i * 1.0) * std::sin(swing), 3 - (0.5 + i * 1.0) * std::cos(swing), 0);
    pose.setRotation(btQuaternion(btVector3(0, 0, 1), swing));
    btRigidBody* link = w.addBox(half, 1.0 + i, pose);
    if (!prev) {
      w.addConstraint(std::make_unique<btPoint2PointConstraint>(*link, btVector3(0, 0.5, 0)));
    } else {
      w.addConstraint(std::make_unique<btPoint2PointConstraint>(*prev, *link, btVector3(0, -0.5, 0),
                                                                btVector3(0, 0.5, 0)));
    }
    prev = link;
  }
  // A door on a vertical hinge, pushed.
  btRigidBody* door = w.addBox(btVector3(0.5, 1.0, 0.05), 2.0, at(5.5, 2, 0));
  w.addConstraint(
      std::make_unique<btHingeConstraint>(*door, btVector3(-0.5, 0, 0), btVector3(0, 1, 0)));
  door->setAngularVelocity(btVector3(0, 2, 0));
  // A box on a tilted slider rail with limits, sliding down into its lower stop.
  btTransform rail = at(0, 0, 0);
  rail.setRotation(btQuaternion(btVector3(0, 0, 1), -0.5));
  btRigidBody* slider = w.addBox(btVector3(0.2, 0.2, 0.2), 1.0, at(-4, 3, 0));
  auto s = std::make_unique<btSliderConstraint>(*slider, rail, true);
  s->setLowerLinLimit(-1.0);
  s->setUpperLinLimit(1.0);
  w.addConstraint(std::move(s));
}

namespace {
btTransform frame(double z, double y, double x, const btVector3& origin) {
  btTransform t;
  t.setIdentity();
  t.getBasis().setEulerZYX(z, y, x);
  t.setOrigin(origin);
  return t;
}

// RagdollDemo's figure with its pelvis at `at`.
void ragdoll(World& w, const btVector3& at) {
  struct Part {
    double radius, height, x, y, roll;
  };
  const double h = SIMD_HALF_PI;
  const Part parts[11] = {
      {0.15, 0.20, 0, 1.0, 0},      {0.15, 0.28, 0, 1.2, 0},      {0.10, 0.05, 0, 1.6, 0},
      {0.07, 0.45, -0.18, 0.65, 0}, {0.05, 0.37, -0.18, 0.2, 0},  {0.07, 0.45, 0.18, 0.65, 0},
      {0.05, 0.37, 0.18, 0.2, 0},   {0.05, 0.33, -0.35, 1.45, h}, {0.04, 0.25, -0.7, 1.45, h},
      {0.05, 0.33, 0.35, 1.45, -h}, {0.04, 0.25, 0.7, 1.45, -h}};
  btRigidBody* b[11];
  for (int i = 0; i < 11; ++i) {
    const Part& p = parts[i];
    const btTransform pose = frame(p.roll, 0, 0, at + btVector3(p.x, p.y - 1.0, 0));
    b[i] = w.addShape(std::make_unique<btCapsuleShape>(p.radius, p.height), 1.0, pose);
    b[i]->setDamping(0.05, 0.85);
  }
  auto hinge = [&](int i, int j, double ya, double yb, double lo, double hi) {
    auto c = std::make_unique<btHingeConstraint>(*b[i], *b[j], frame(0, h, 0, btVector3(0, ya, 0)),
                                                 frame(0, h, 0, btVector3(0, yb, 0)));
    c->setLimit(lo, hi);
    w.addConstraint(std::move(c));
  };
  auto cone = [&](int i, int j, const btTransform& a, const btTransform& bf, double s1, double s2,
                  double twist) {
    auto c = std::make_unique<btConeTwistConstraint>(*b[i], *b[j], a, bf);
    c->setLimit(s1, s2, twist);
    w.addConstraint(std::move(c));
  };
  const double q = SIMD_PI / 4;
  hinge(0, 1, 0.15, -0.15, -q, h);
  cone(1, 2, frame(h, 0, 0, btVector3(0, 0.30, 0)), frame(h, 0, 0, btVector3(0, -0.14, 0)), q, q,
       h);
  cone(0, 3, frame(-5 * q, 0, 0, btVector3(-0.18, -0.10, 0)),
       frame(-5 * q, 0, 0, btVector3(0, 0.225, 0)), q, q, 0);
  hinge(3, 4, -0.225, 0.185, 0, h);
  cone(0, 5, frame(q, 0, 0, btVector3(0.18, -0.10, 0)), frame(q, 0, 0, btVector3(0, 0.225, 0)), q,
       q, 0);
  hinge(5, 6, -0.225, 0.185, 0, h);
  cone(1, 7, frame(SIMD_PI, 0, 0, btVector3(-0.2, 0.15, 0)), frame(h, 0, 0, btVector3(0, -0.18, 0)),
       h, h, 0);
  hinge(7, 8, 0.18, -0.14, 0, h);
  cone(1, 9, frame(0, 0, 0, btVector3(0.2, 0.15, 0)), frame(h, 0, 0, btVector3(0, -0.18, 0)), h, h,
       0);
  hinge(9, 10, 0.18, -0.14, 0, h);
}
}  // namespace

void ragdollPile(World& w, int columns, int layers) {
  w.addGround(0.5);
  for (int layer = 0; layer < layers; ++layer)
    for (int i = 0; i < columns; ++i)
      for (int k = 0; k < columns; ++k) {
        // Each layer shifted and raised so the figures land across the ones below.
        const double shift = 0.3 * (layer % 2);
        ragdoll(w, btVector3(i * 1.0 + shift, 1.2 + 2.0 * layer, k * 0.8 + shift));
      }
}

}  // namespace mlcp::bullet::scenes
