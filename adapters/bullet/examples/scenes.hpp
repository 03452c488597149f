// scenes.hpp: Bullet scenes built in code for the adapter tests and the benchmark (older than
// the scene files, which bullet_pyramid and `mlcp run` load through mlcp::bullet::buildWorld),
// and solvers picked by name (the scene loader's stock bullet-mlcp-* solvers come from here).
//
// Solver names (makeBulletSolver):
//   "si"                        Bullet's stock btSequentialImpulseConstraintSolver
//   "mlcp-pgs", "mlcp-dantzig", "mlcp-lemke"
//                               the stock btMLCPSolver with Bullet's own PGS/Dantzig/Lemke
//   any mlcp::solverNames() name, or "si-stats"
//                               our drop-in mlcp::bullet::ConstraintSolver ("si-stats" runs
//                               Bullet's SI iterations inside it, with our statistics)
#pragma once

#include <BulletDynamics/MLCPSolvers/btMLCPSolver.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <string>
#include <vector>

#include "mlcp/bullet/constraint_solver.hpp"

namespace mlcp::bullet::scenes {

// The stock btMLCPSolver with its btMLCPSolverInterface owned, and the residual of each answer
// measured by mlcp::accuracy on the problem it assembled (measurement time kept apart).
class StockMlcp : public btMLCPSolver {
 public:
  explicit StockMlcp(std::unique_ptr<btMLCPSolverInterface> method);
  ~StockMlcp() override;

  void prepareSolve(int numBodies, int numManifolds) override;
  // Worst residual of this step's accepted answers (NaN if none), and fallbacks so far.
  double stepResidual() const { return stepResidual_; }
  double stepMeasureSeconds() const { return stepMeasure_; }
  int fallbacks() const { return getNumFallbacks(); }
  bool measure = true;  // measure residuals (default true)

 protected:
  bool solveMLCP(const btContactSolverInfo& info) override;

 private:
  std::unique_ptr<btMLCPSolverInterface> method_;
  double stepResidual_ = 0, stepMeasure_ = 0;
};

// "si", "mlcp-pgs", "mlcp-dantzig", "mlcp-lemke", "si-stats" or a core solver name (settings
// are the drop-in's, with settings.solver replaced by the name). Throws std::invalid_argument
// for an unknown name.
std::unique_ptr<btConstraintSolver> makeBulletSolver(const std::string& name,
                                                     Settings settings = Settings());
// Every name makeBulletSolver accepts, for --help texts.
std::string bulletSolverNames();

// Which stock world World builds.
enum class WorldKind {
  Discrete,    // btDiscreteDynamicsWorld with btSequentialImpulseConstraintSolver
  DiscreteMt,  // btDiscreteDynamicsWorldMt with a btConstraintSolverPoolMt of SI solvers and an
               // SI solver for large islands (Bullet's MultiThreadedDemo puts a
               // btSequentialImpulseConstraintSolverMt there; Debian's build of it, without
               // BT_THREADSAFE, crashed in btBatchedConstraints::setup on a 55-box pyramid with
               // the batching threshold lowered to 16 manifolds)
  MultiBody,   // btMultiBodyDynamicsWorld with btMultiBodyConstraintSolver
};

// A stock Bullet world and everything it points at, destroyed in the right order.
class World {
 public:
  // dt in seconds (default 1/60); twoFrictionDirections adds SOLVER_USE_2_FRICTION_DIRECTIONS.
  explicit World(double dt = 1.0 / 60.0, bool twoFrictionDirections = false,
                 WorldKind kind = WorldKind::Discrete);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  btDiscreteDynamicsWorld& world() { return *world_; }
  btContactSolverInfo& info() { return world_->getSolverInfo(); }
  double dt() const { return dt_; }

  // Replaces the constraint solver (the world keeps using it until the next call).
  void setSolver(std::unique_ptr<btConstraintSolver> solver);
  btConstraintSolver* solver() { return solver_.get(); }

  // Bodies. mass 0 makes a static body. Positions in metres, rotations as quaternions.
  btRigidBody* addBox(const btVector3& halfExtents, double mass, const btTransform& pose,
                      double friction = 0.5, double restitution = 0);
  btRigidBody* addSphere(double radius, double mass, const btVector3& position,
                         double friction = 0.5, double restitution = 0);
  // A static 100 x 1 x 100 m slab whose top face is y = 0, tilted by `tilt` radians about z.
  btRigidBody* addGround(double friction = 1.0, double tilt = 0);
  // Any shape (capsules, cylinders, ...); the world keeps it.
  btRigidBody* addShape(std::unique_ptr<btCollisionShape> shape, double mass,
                        const btTransform& pose, double friction = 0.5);
  void addConstraint(std::unique_ptr<btTypedConstraint> c, bool disableCollisions = true);

  // One fixed step of dt (no sub-stepping, no interpolation).
  void step(int steps = 1);
  const std::vector<btRigidBody*>& dynamicBodies() const { return dynamic_; }

 private:
  double dt_;
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btConstraintSolver> solver_;
  // Solvers the world still calls after setSolver: DiscreteMt's large-island solver, and the
  // multibody solver a MultiBody world's island callback keeps.
  std::vector<std::unique_ptr<btConstraintSolver>> kept_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btMotionState>> motion_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
  std::vector<btRigidBody*> dynamic_;
};

// A 2-D pyramid of 1 m unit-mass boxes on the ground, `boxes` = k (k + 1) / 2 (15, 55, 210).
void pyramid(World& w, int boxes, double friction = 0.5);
// `count` 1 m boxes (mass 1) stacked on the ground.
void stack(World& w, int count, double friction = 0.5);
// A 1 m box (mass 1) at rest on a static plane tilted by theta (radians), combined friction mu.
btRigidBody* incline(World& w, double theta, double mu);
// Frictionless contacts: three spheres and a box dropped on the ground (no friction coupling).
void frictionlessDrop(World& w);
// Joints without contacts: a point-to-point chain of two boxes, a hinged door swinging, and a
// box on a slider with limits, all under gravity.
void joints(World& w);
// Bullet's RagdollDemo figure (11 unit-mass capsules; hips, shoulders and neck held by
// btConeTwistConstraint, knees, elbows and the spine by btHingeConstraint), `columns` x `columns`
// of them in each of `layers` layers dropped onto the ground and onto each other (a pile).
void ragdollPile(World& w, int columns, int layers);

}  // namespace mlcp::bullet::scenes
