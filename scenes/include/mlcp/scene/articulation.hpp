// mlcp/scene/articulation.hpp: articulated bodies, trees of links, in a scene (scene.hpp).
//
// An articulation is a base (floating, or fixed to the world) and links, each hanging from one
// parent (the base or another link) on one joint: revolute, prismatic, spherical or fixed, with
// limits and a velocity motor on revolute and prismatic joints. The file writes it in the
// "articulations" array (scenes/README.md, "Articulated bodies").
//
// One scene, two coordinate systems. The parser expands every articulation into ordinary scene
// bodies (the base, then the links parent-first) and joints (one per link: revolute -> hinge,
// prismatic -> slider, spherical -> ball, fixed -> fixed; bodies [link, parent], or [link] when
// the parent is a fixed base, which is a static body), and records the tree here. So:
// - maximal coordinates (plain Bullet, ODE) load an articulated scene with the loaders they have
//   for jointed bodies: the links are rigid bodies, the joints constraint rows, the same limits
//   and motors;
// - reduced coordinates (Bullet's btMultiBody, engine "bullet-multibody") read the tree: the base
//   and links from Scene::bodies, each link's joint type, frame, limits and motor from
//   Scene::joints, so both see the same masses, inertias, poses and joint parameters.
// The joint conventions are the scene's (joints.hpp): a joint's angle or offset is the link's
// relative to its parent, 0 in the pose the file gives, anchors and axes world-frame at that pose.
//
// Invariants (checked by the parser; a file that breaks one is a one-line FormatError): every
// parent exists and the parent links form a tree (no cycle, no link its own parent); links are
// stored parent-first (links[k].parent < k), so an engine can build them in order; link and base
// bodies are dynamic, except a fixed base, which is static; a spherical joint has no limits and
// no motor (ODE's ball joint and Bullet's point-to-point have neither; Bullet's
// btMultiBodySphericalJointMotor exists but has no counterpart in the maximal engines); no other
// joint of the scene touches an articulation's bodies.
#pragma once

#include <string>
#include <vector>

namespace mlcp::scene {

struct ArticulatedLink {
  int body = -1;    // index into Scene::bodies
  int parent = -1;  // index into Articulation::links, or -1 for the base; always < this link's
  int joint = -1;   // index into Scene::joints: the joint to the parent (body0 = this link)
};

struct Articulation {
  std::string name;  // the base body's name
  // Whether the base is held by the world (then its body is static, mass 0) or floats free.
  bool fixedBase = false;
  int base = -1;                       // index into Scene::bodies
  std::vector<ArticulatedLink> links;  // parent-first
};

}  // namespace mlcp::scene
