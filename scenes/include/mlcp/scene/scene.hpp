// mlcp/scene/scene.hpp: engine-neutral scenes (mlcp-scene/1 JSON, see scenes/README.md).
//
// A scene file is data: bodies (plane, box, sphere, capsule, cylinder, convex hull; geometry.hpp),
// joints (ball, hinge, slider, fixed, cone-twist, 6-dof with springs, universal, hinge-2, gear;
// joints.hpp), articulated bodies (trees of links; articulation.hpp), materials, gravity, engine
// settings and solver defaults. Generators ("stack", "pyramid", "grid") keep big regular
// structures small on disk. loadScene() returns the expanded, validated model below: every
// generator replaced by its bodies, every articulation by its bodies and link joints (its tree
// kept in `articulations`), every default filled in, every name resolved to an index, and the
// inertia of every body computed from its shape and mass (or given, for articulated bodies). The
// engine loaders (Bullet, its multibody world, ODE) build worlds from these structs alone, so
// every engine sees the same numbers; nothing here depends on an engine.
//
// Conventions (the README has the full list):
// - SI units: m, kg, s, rad (a file may write orientations in degrees; they arrive here in
//   radians, as quaternions).
// - z is up: the generators build along +z and the default gravity is (0, 0, -9.81). Gravity
//   is a vector, so a scene of explicit bodies may use another up axis.
// - Quaternions are (w, x, y, z), unit length, rotating body-frame vectors into the world.
// - Joint anchors and axes are given in the world frame at creation time; a joint's angle or
//   offset is 0 in the pose the bodies have when it is created. The hinge angle is the
//   rotation of bodies[0] relative to bodies[1] (or the world) about the axis, right-handed;
//   the slider offset is the displacement of bodies[0] relative to bodies[1] along the axis.
// - Contact between materials a and b uses friction sqrt(mu_a mu_b) and restitution
//   max(e_a, e_b) (Box2D's and Jolt's rules). A Bullet loader gets the first exactly by giving
//   each body the friction sqrt(mu) (Bullet multiplies the two); an ODE loader sets both in its
//   near callback.
// - Inertia is computed here and handed to both engines, so it is the same in both: Bullet's
//   own capsule inertia is a box approximation, ODE's is exact; ours is exact.
//
// Errors: a bad file throws FormatError (the one of mlcp/io.hpp) whose message reads
// "<file>: <JSON path>: <what is wrong>", e.g.
//   "pyramid_55.json: bodies[3].shape.size: expected 3 positive numbers, got [1, -1, 1]".
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/io.hpp"
#include "mlcp/island/friction_model.hpp"
#include "mlcp/scene/articulation.hpp"
#include "mlcp/scene/geometry.hpp"
#include "mlcp/scene/joints.hpp"

namespace mlcp::scene {

using FormatError = mlcp::io::FormatError;

// The format tag every scene file carries in its "format" field.
inline constexpr const char* kFormat = "mlcp-scene/1";

struct Material {
  std::string name;
  // Coulomb friction coefficient, >= 0, dimensionless. Default 0.5.
  double friction = 0.5;
  // Coefficient of restitution in [0, 1]. Default 0.
  double restitution = 0;
};

// Contact rules between two materials (see the conventions above).
double combinedFriction(const Material& a, const Material& b);
double combinedRestitution(const Material& a, const Material& b);

struct Body {
  std::string name;  // unique in the scene; generated bodies are "<generator name>.<index>"
  Shape shape;
  // kg; 0 makes the body static (planes always are). Default: none, a file must say.
  double mass = 0;
  // Computed from shape and mass by inertiaOf(); zeros for static bodies.
  Vec3 inertia{0, 0, 0};
  Vec3 position{0, 0, 0};         // centre of mass, world frame, m
  Quat orientation;               // body frame to world frame
  Vec3 velocity{0, 0, 0};         // of the centre of mass, world frame, m/s
  Vec3 angularVelocity{0, 0, 0};  // world frame, rad/s
  int material = 0;               // index into Scene::materials

  bool isStatic() const { return mass == 0; }
};

struct Settings {
  // Fixed step, s. Default 1/60.
  double timeStep = 1.0 / 60.0;
  // Steps a run takes unless told otherwise. Default 600.
  int steps = 600;
  // Error reduction parameter of joints and contacts, dimensionless in [0, 1]. Default 0.2
  // (both engines' default).
  double erp = 0.2;
  // Constraint force mixing added to every row as cfm / time step on A's diagonal (both
  // engines' meaning: Bullet's globalCfm, ODE's world CFM), >= 0. Default 1e-5: a resting box
  // has 4 redundant contacts and the pivoting solvers need some regularisation for them.
  double cfm = 1e-5;
  // Let the engines put resting bodies to sleep. Default false: every step solves everything.
  bool sleeping = false;
  // Most contact points per colliding pair (ODE's dCollide limit; Bullet's manifolds hold 4).
  // Default 4.
  int maxContactsPerPair = 4;
};

// What `mlcp run` uses when the command line names no solver settings.
struct SolverDefaults {
  // A name known to mlcp::makeSolver (registry.hpp); "auto" chooses per island. Default "auto".
  std::string name = "auto";
  // Options::maxIterations. Default 50.
  int iterations = 50;
  // Options::tolerance (scaled natural-map residual). Default 1e-6.
  double tolerance = 1e-6;
  // Start each step from the previous step's impulses. Default true.
  bool warmStart = true;
  // Friction model of contacts, "box" or "cone" (mlcp/island/friction_model.hpp). Default Box.
  FrictionModel friction = FrictionModel::Box;
  // Friction directions per contact of the cone, in [3, 64]. Default 4.
  int frictionDirections = kDefaultConeDirections;
};

struct Scene {
  std::string name;           // the file's "name", or its file name without ".json"
  std::string description;    // free text, may be empty
  std::string source;         // the path (or source name) it was read from
  Vec3 gravity{0, 0, -9.81};  // m/s^2
  Settings settings;
  SolverDefaults solver;
  std::vector<Material> materials;          // materials[0] is "default"
  std::vector<Body> bodies;                 // generators expanded, in file order
  std::vector<Joint> joints;                // the articulations' link joints included
  std::vector<Articulation> articulations;  // trees of bodies and joints above (articulation.hpp)

  // Index of the body or material of that name, or -1.
  int findBody(const std::string& name) const;
  int findMaterial(const std::string& name) const;
  int dynamicBodyCount() const;
  // (link, base) of every link hanging from a fixed base: a pair that must not collide, as a
  // link and its parent never do (the link's joint is to the world, so no joint says so).
  std::vector<std::pair<int, int>> fixedBaseNeighbours() const;
};

// Reads and validates an mlcp-scene/1 file; throws FormatError.
Scene loadScene(const std::string& path);
// The same from text; sourceName is used in messages and as the default scene name.
Scene parseScene(const std::string& text, const std::string& sourceName = "<string>");

// The *.json files of a folder, sorted by name (the scenes/ folder holds nothing else).
std::vector<std::string> listSceneFiles(const std::string& folder);

}  // namespace mlcp::scene
