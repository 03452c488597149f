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
// loadWorld's worlds are built by buildWorld: one mapping, described here.
//
// How the scene maps onto Bullet:
// - shapes: plane btStaticPlaneShape(normal, offset), box btBoxShape(size / 2), sphere
//   btSphereShape, capsule btCapsuleShapeZ(radius, length) (along the body's z axis), cylinder
//   btCylinderShapeZ(radius, radius, length / 2), convex hull btConvexHullShape of the corners
//   with a 1 mm margin (Bullet's 0.04 m default inflates the hull) and its polyhedral features
//   for separating-axis contact clipping (the world's m_enableSatConvex, set when a hull is
//   present);
// - mass and the scene's inertia (never Bullet's own approximation, which is a box for
//   capsules); pose, velocities; sleeping only when the scene allows it;
// - materials: Bullet multiplies the two bodies' friction, so each body gets sqrt(mu) and a
//   pair gets sqrt(mu_a mu_b) exactly; restitution is combined by max(e_a, e_b) through
//   Bullet's global gCalculateCombinedRestitutionCallback, which the loader installs (it is
//   process-wide; every world of this process then combines restitution by max);
// - joints through frames at the anchor whose z axis is the joint axis (x for the slider):
//   ball btPoint2PointConstraint, hinge btHingeConstraint (limits with softness 1, motor
//   impulse max_force * dt), slider btSliderConstraint (rotation locked; linear limits and
//   motor), fixed btFixedConstraint; joints to the world use btTypedConstraint::getFixedBody().
//   Bullet measures the hinge angle of its body A relative to B, as the scene does, but the
//   slider offset of B relative to A: the slider's frame axis is reversed so that its limits
//   and motor keep the scene's signs (world_test checks both by driving the motors into the
//   upper limits); cone_twist btConeTwistConstraint (frame x the twist axis, z the normal:
//   setLimit(swing1, swing2, twist)); six_dof btGeneric6DofSpring2Constraint (RO_XYZ, frame
//   x = axis, y = normal, its body B the scene's bodies[0] so that offsets and angles are
//   bodies[0]'s relative to bodies[1]; free axes lower 1 > upper -1, springs at the creation
//   pose; stiffness and damping as the scene gives them, setStiffness(i, k, false): by default
//   Bullet caps a spring at m / (16 dt^2) of the lighter body, which let the vehicle's 20 kN/m
//   suspension act as 2.2 kN/m and the chassis sink 0.23 m); universal
//   btUniversalConstraint(anchor, axis, axis2); hinge2 btHinge2Constraint (chassis, wheel, anchor,
//   axis, axis2), steering limits, the suspension as its spring on linear z within Bullet's +-1 m
//   travel, or linear z locked when the scene has none; gear btGearConstraint with both axes in
//   their bodies' frames and the ratio;
// - settings: gravity, one fixed step of time_step per step (no substeps), m_erp = m_erp2 =
//   erp, m_globalCfm = cfm, m_numIterations = iterations, minimumSolverBatchSize 1 (islands
//   solved one by one, as the direct solvers want), SOLVER_USE_2_FRICTION_DIRECTIONS (two
//   friction rows per contact like ODE's, so both engines solve problems of the same shape;
//   Bullet's default is one row along the sliding direction), SOLVER_ENABLE_FRICTION_DIRECTION_
//   CACHING | SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION (a contact keeps its friction
//   directions from step to step, so last step's friction impulses are a meaningful warm start:
//   with directions that follow the sliding velocity, the exact solvers' warm starts are off
//   and their steps take two to three times as long on the pyramids). max_contacts_per_pair is 4 in
//   Bullet's manifolds whatever the scene says.
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
