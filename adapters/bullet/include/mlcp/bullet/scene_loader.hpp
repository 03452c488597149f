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
// Articulated bodies (mlcp/scene/articulation.hpp) load in one of two ways:
// - Coordinates::Maximal (engine "bullet"): a btDiscreteDynamicsWorld; links are btRigidBodies
//   joined by the scene's hinge, slider, point-to-point and fixed constraints, with their limits
//   and motors, exactly as any jointed bodies of a scene;
// - Coordinates::Reduced (engine "bullet-multibody"): a btMultiBodyDynamicsWorld; each articulation
//   is a btMultiBody (setupRevolute/Prismatic/Spherical/Fixed from the scene's poses, anchors and
//   axes), its shapes btMultiBodyLinkColliders, limits btMultiBodyJointLimitConstraints and motors
//   btMultiBodyJointMotors (max impulse max_force * h); no damping (btMultiBody's default is
//   0.04), self-collision on except parent and child (as the maximal loaders). Every other body is
//   the btRigidBody it is in "bullet". The world solves with Bullet's own
//   btMultiBodyConstraintSolver (SI, "bullet-si"), or with Bullet's MLCP path
//   btMultiBodyMLCPConstraintSolver ("bullet-mlcp-pgs", "-dantzig", "-lemke"); a core solver is
//   put in by mlcp::bullet::install(world, solver) (worlds.hpp), and where install() refuses the
//   world, loadWorld says so in one line (scene::Unsupported).
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

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/scene/world.hpp"

namespace mlcp::bullet {

// A scene in a stock btDiscreteDynamicsWorld, owning the world and everything it points at
// (collision configuration, dispatcher, broadphase, shapes, motion states, bodies,
// constraints), destroyed in the right order. The world starts with a stock
// btSequentialImpulseConstraintSolver owned here; world().setConstraintSolver(&yours) swaps it
// (yours must outlive the steps; Bullet does not take ownership).
enum class Coordinates { Maximal, Reduced };

class BulletScene {
 public:
  // Settings used: gravity, time step, erp, cfm (scene), iterations and warmStart (run). Reduced:
  // a btMultiBodyDynamicsWorld whose articulations are btMultiBodies (see above).
  BulletScene(const scene::Scene& scene, const scene::RunSettings& run,
              Coordinates coordinates = Coordinates::Maximal);
  ~BulletScene();
  BulletScene(const BulletScene&) = delete;
  BulletScene& operator=(const BulletScene&) = delete;

  btDiscreteDynamicsWorld& world() { return *world_; }
  const btDiscreteDynamicsWorld& world() const { return *world_; }
  // Every scene body, static ones included, in scene order; nullptr for the bodies of a
  // btMultiBody (Reduced).
  const std::vector<btRigidBody*>& bodies() const { return bodyPointers_; }
  // Reduced: the articulations' btMultiBodies, in scene order; empty in Maximal.
  const std::vector<btMultiBody*>& multiBodies() const { return multiBodyPointers_; }
  // Every scene body's pose and velocity, rigid or a btMultiBody's base or link.
  std::vector<scene::BodyState> states() const;
  double timeStep() const { return timeStep_; }

 private:
  // The bodies, joints and (Reduced) btMultiBodies of the scene.
  void addContent(const scene::Scene& s, Coordinates coordinates);
  std::unique_ptr<btCollisionShape> makeShape(const scene::Body& b);
  void addBody(const scene::Scene& s, const scene::Body& b);
  // Reduced: the articulation as a btMultiBody with its colliders, limits and motors.
  void addMultiBody(const scene::Scene& s, const scene::Articulation& a);
  btMultiBodyLinkCollider* addCollider(const scene::Scene& s, const scene::Body& b, btMultiBody* mb,
                                       int link);
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
  // Reduced: per scene body, the btMultiBody holding it and its link (-1 the base).
  std::vector<std::pair<btMultiBody*, int>> linkOf_;
  std::vector<std::unique_ptr<btMultiBody>> multiBodies_;
  std::vector<btMultiBody*> multiBodyPointers_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> multiBodyConstraints_;
};

// The scene's stock world; the second form takes iterations and warmStart from the scene's
// solver defaults (RunSettings::fromScene).
std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene, const scene::RunSettings& run,
                                        Coordinates coordinates = Coordinates::Maximal);
std::unique_ptr<BulletScene> buildWorld(const scene::Scene& scene);

// Throws std::invalid_argument for an unknown solver name (the message lists the known ones),
// scene::Unsupported for a solver the world cannot take. World::engine() is "bullet" (Maximal)
// or "bullet-multibody" (Reduced).
std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings,
                                        Coordinates coordinates = Coordinates::Maximal);

// Every solver name loadWorld accepts, comma separated.
std::string worldSolverNames(Coordinates coordinates = Coordinates::Maximal);

}  // namespace mlcp::bullet
