// mlcp/ode/scene_loader.hpp: an mlcp-scene/1 scene as an ODE world.
//
//     auto world = mlcp::ode::loadWorld(scene, mlcp::scene::RunSettings::fromScene(scene));
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

#include <memory>
#include <string>

#include "mlcp/scene/world.hpp"

namespace mlcp::ode {

// Throws std::invalid_argument for an unknown solver name (the message lists the known ones).
std::unique_ptr<scene::World> loadWorld(const scene::Scene& scene,
                                        const scene::RunSettings& settings);

// Every solver name loadWorld accepts, comma separated.
std::string worldSolverNames();

}  // namespace mlcp::ode
