// mlcp/ode/scene_loader.hpp: an mlcp-scene/1 scene as an ODE world.
//
//     auto world = mlcp::ode::loadWorld(scene, mlcp::scene::RunSettings::fromScene(scene));
//
// or, for a program that drives ODE itself (adapters/ode/examples/pile.cpp):
//
//     auto built = mlcp::ode::buildWorld(scene);   // dWorld, space, geoms, bodies, joints
//     mlcp::ode::Stepper stepper("dantzig");
//     built->collide();                            // dSpaceCollide into the contact group
//     stepper.step(built->world(), h);             // in place of dWorldStep(world, h)
//     built->clearContacts();                      // dJointGroupEmpty
//
// loadWorld's worlds are built by buildWorld: one mapping, described here.
//
// How the scene maps onto ODE:
// - one dWorld and a hash space; geoms dCreatePlane (a x + b y + c z = d), dCreateBox,
//   dCreateSphere, dCreateCapsule (along the body's z axis). Static bodies are geoms without
//   a body (placed by their pose);
// - masses through dMassSetParameters with the scene's inertia (centre of mass at the body
//   origin); pose, velocities; auto-disable only when the scene allows sleeping;
// - contacts from dSpaceCollide in a near callback: at most max_contacts_per_pair points per
//   pair, dContactApprox1 (friction bound mu times the normal force, as Bullet), mu and
//   restitution by the scene's rules (sqrt(mu_a mu_b), max(e_a, e_b); dContactBounce with
//   bounce_vel 0.2 m/s when e > 0), a joint group emptied after every step; pairs joined by a
//   joint without collide_connected do not collide;
// - joints: dJointCreateBall / Hinge (dParamLoStop, dParamHiStop, dParamVel, dParamFMax) /
//   Slider (the same) / Fixed, attached as (A, B) or (A, 0) for the world. ODE measures the
//   hinge angle and slider offset of body 1 relative to body 2, as the scene does;
// - settings: gravity, dWorldSetERP(erp), dWorldSetCFM(cfm) (ODE adds cfm / h to A's
//   diagonal, the scene's meaning).
//
// Solver names: any mlcp::solverNames() name runs through mlcp::ode::Stepper (its island
// statistics fill the measures); the stock ones are
//   ode-world   ODE's dWorldStep algorithm: the Stepper's "ode-lcp" (ODE's own dxSolveLCP on
//               ODE's dense A; equal to dWorldStep to round-off, and its residual is measured)
//   ode-quick   dWorldQuickStep (the Stepper's "ode-quickstep", `iterations` SOR sweeps; no
//               residual, status max-iterations)
#pragma once

#include <ode/ode.h>

#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/scene/world.hpp"

namespace mlcp::ode {

// A scene in an ODE world, owning the dWorld, its space and geoms, bodies, joints and the
// contact joint group (ODE's own objects: step the world with dWorldStep, dWorldQuickStep or a
// Stepper). Initializes ODE (dInitODE2) once per process.
class OdeScene {
 public:
  // Settings used: gravity, erp, cfm, sleeping, materials, max_contacts_per_pair (scene);
  // iterations as dWorldSetQuickStepNumIterations (run).
  OdeScene(const scene::Scene& scene, const scene::RunSettings& run);
  ~OdeScene();
  OdeScene(const OdeScene&) = delete;
  OdeScene& operator=(const OdeScene&) = delete;

  dWorldID world() const { return world_; }
  dSpaceID space() const { return space_; }
  dJointGroupID contactGroup() const { return contacts_; }
  // Every scene body in scene order; nullptr for static ones (geoms without a body).
  const std::vector<dBodyID>& bodies() const { return bodies_; }

  // dSpaceCollide: this step's contact joints into contactGroup(), by the scene's rules.
  void collide();
  // dJointGroupEmpty(contactGroup()), after the step.
  void clearContacts() { dJointGroupEmpty(contacts_); }
  // Of the last collide(): contact points, and the deepest one's depth (m, >= 0).
  int contacts() const { return contactCount_; }
  double deepestPenetration() const { return deepest_; }

 private:
  void addBody(const scene::Scene& s, int index);
  void addJoint(const scene::Joint& j);
  static void nearCallback(void* data, dGeomID g1, dGeomID g2);

  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::vector<scene::Material> materials_;
  int maxContactsPerPair_ = 0;
  std::map<dGeomID, int> materialOf_;
  std::set<std::pair<int, int>> noCollide_;
  std::vector<dContact> buffer_;
  int contactCount_ = 0;
  double deepest_ = 0;
};

// The scene's ODE world; the second form takes iterations from the scene's solver defaults
// (RunSettings::fromScene).
std::unique_ptr<OdeScene> buildWorld(const scene::Scene& scene, const scene::RunSettings& run);
std::unique_ptr<OdeScene> buildWorld(const scene::Scene& scene);

// Throws std::invalid_argument for an unknown solver name (the message lists the known ones).
std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings);

// Every solver name loadWorld accepts, comma separated.
std::string worldSolverNames();

}  // namespace mlcp::ode
