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
// loadWorld's worlds are built by buildWorld: one mapping, listed geom by geom and joint by
// joint in docs/methods/adapters.md, "ODE: the scene mapping". What it guarantees:
// - the scene's numbers: its inertia (dMassSetParameters, centre of mass at the body origin),
//   its cfm as ODE's (ODE adds cfm / h to A's diagonal, the scene's meaning);
// - contacts by the scene's rules: dContactApprox1 (friction bound mu times the normal force,
//   as Bullet), sqrt(mu_a mu_b), max(e_a, e_b), at most max_contacts_per_pair points a pair;
// - joints keep the scene's signs (angles and offsets of bodies[0] relative to bodies[1]);
// - no silent gaps: a pair of geom classes this ODE build has no collider for (Debian's libode
//   has no libccd: cylinder-cylinder, capsule-cylinder, convex-cylinder) makes collide() throw
//   scene::Unsupported the first time such a pair's boxes overlap, and a joint ODE cannot
//   express (e.g. six_dof, a cone_twist swing2 of 1.5 rad or more, a gear whose two axes
//   differ) throws scene::Unsupported when the world is built.
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
  // The joint types beyond ball, hinge, slider and fixed (see the mapping above).
  void addOtherJoint(const scene::Joint& j, dBodyID a, dBodyID b);
  void release();  // destroys the ODE objects (the destructor, or a constructor that throws)
  dGeomID createConvex(const scene::Shape& shape);
  static void nearCallback(void* data, dGeomID g1, dGeomID g2);

  // dCreateConvex's arrays, which ODE points into for the geom's life.
  struct HullData {
    std::vector<dReal> planes, points;
    std::vector<unsigned> polygons;
  };

  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::vector<scene::Material> materials_;
  int maxContactsPerPair_ = 0;
  double timeStep_ = 0;
  std::vector<std::unique_ptr<HullData>> hulls_;
  // Set by the near callback for a pair of geom classes ODE has no collider for; collide()
  // throws scene::Unsupported with it.
  std::string missingCollider_;
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
