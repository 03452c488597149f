// mlcp/bullet/scene_loader.hpp: an mlcp-scene/1 scene as a stock btDiscreteDynamicsWorld.
//
//     auto world = mlcp::bullet::loadWorld(scene, mlcp::scene::RunSettings::fromScene(scene));
//
// or, for a program that drives Bullet itself (adapters/bullet/examples/pyramid.cpp):
//
//     auto built = mlcp::bullet::buildWorld(scene);   // the stock world, bodies and joints
//     btDiscreteDynamicsWorld& world = built->world();
//     mlcp::bullet::ConstraintSolver solver(settings);
//     world.setConstraintSolver(&solver);             // the one-line swap
//     world.stepSimulation(h, 0, h);
//
// loadWorld's worlds are built by buildWorld: one mapping, listed shape by shape and joint by
// joint in docs/methods/adapters.md, "Bullet: the scene mapping". What it guarantees:
// - the scene's numbers, not Bullet's approximations: the scene's inertia (Bullet's own is a box
//   for capsules), convex hulls with a 1 mm margin, springs as stiff as the scene says (no cap);
// - joints keep the scene's signs: angles and offsets of bodies[0] relative to bodies[1];
// - materials by the scene's rules: each body gets friction sqrt(mu), so a pair gets
//   sqrt(mu_a mu_b); restitution max(e_a, e_b) through Bullet's process-wide
//   gCalculateCombinedRestitutionCallback, which the loader installs (every world of the process
//   then combines restitution by max);
// - problems of the shape ODE's are: one fixed step per step, islands solved one by one
//   (minimumSolverBatchSize 1), two friction rows per contact whose directions persist from
//   step to step (so last step's friction impulses are a warm start); at most 4 contacts per
//   pair (Bullet's manifolds) whatever the scene says.
//
// Solver names: any mlcp::solverNames() name runs through mlcp::bullet::ConstraintSolver (its
// statistics fill the measures); the stock ones are
//   bullet-si            btSequentialImpulseConstraintSolver
//   bullet-nncg          btNNCGConstraintSolver
//   bullet-mlcp-pgs, bullet-mlcp-dantzig, bullet-mlcp-lemke
//                        btMLCPSolver with Bullet's PGS / Dantzig / Lemke (residual measured on
//                        the problem it assembled; fallbacks are its fallbacks to SI)
// Stock SI and NNCG report no residual (NaN), `iterations` sweeps and status max-iterations.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <string>
#include <vector>

#include "mlcp/scene/world.hpp"

namespace mlcp::bullet {

// A scene in a stock btDiscreteDynamicsWorld, owning the world and everything it points at
// (collision configuration, dispatcher, broadphase, shapes, motion states, bodies,
// constraints), destroyed in the right order. The world starts with a stock
// btSequentialImpulseConstraintSolver owned here; world().setConstraintSolver(&yours) swaps it
// (yours must outlive the steps; Bullet does not take ownership).
class BulletScene {
 public:
  // Settings used: gravity, time step, erp, cfm (scene), iterations and warmStart (run).
  BulletScene(const scene::Scene& scene, const scene::RunSettings& run);
  ~BulletScene();
  BulletScene(const BulletScene&) = delete;
  BulletScene& operator=(const BulletScene&) = delete;

  btDiscreteDynamicsWorld& world() { return *world_; }
  const btDiscreteDynamicsWorld& world() const { return *world_; }
  // Every scene body, static ones included, in scene order.
  const std::vector<btRigidBody*>& bodies() const { return bodyPointers_; }
  double timeStep() const { return timeStep_; }

 private:
  void addBody(const scene::Scene& s, const scene::Body& b);
  void addJoint(const scene::Joint& j);
  // The joint types beyond ball, hinge, slider and fixed (see the mapping above).
  std::unique_ptr<btTypedConstraint> makeJoint(const scene::Joint& j, btRigidBody& a,
                                               btRigidBody& b) const;

  double timeStep_;
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btConstraintSolver> stockSolver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btMotionState>> motion_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<btRigidBody*> bodyPointers_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
};

// The scene's stock world; the second form takes iterations and warmStart from the scene's
// solver defaults (RunSettings::fromScene).
std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene, const scene::RunSettings& run);
std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene);

// Throws std::invalid_argument for an unknown solver name (the message lists the known ones).
std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings);

// Every solver name loadWorld accepts, comma separated.
std::string worldSolverNames();

}  // namespace mlcp::bullet
