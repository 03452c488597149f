// mlcp/scene/scene.hpp: engine-neutral scenes (mlcp-scene/1 JSON, see scenes/README.md).
//
// A scene file is data: bodies (plane, box, sphere, capsule, cylinder, convex hull), joints
// (ball, hinge, slider, fixed, cone-twist, 6-dof with springs, universal, hinge-2, gear),
// materials, gravity, engine settings and solver defaults. Generators ("stack", "pyramid", "grid")
// keep big regular structures small on disk. loadScene() returns the expanded, validated model
// below: every generator replaced by its bodies, every default filled in, every name resolved to an
// index, and the inertia of every body computed from its shape and mass. The engine loaders
// (Bullet, ODE) build worlds from these structs alone, so both engines see the same numbers;
// nothing here depends on an engine.
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
#include <vector>

#include "mlcp/io.hpp"
#include "mlcp/island/friction_model.hpp"

namespace mlcp::scene {

using FormatError = mlcp::io::FormatError;

// The format tag every scene file carries in its "format" field.
inline constexpr const char* kFormat = "mlcp-scene/1";

using Vec3 = std::array<double, 3>;

// Unit quaternion (w, x, y, z); the identity by default.
struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
};

// The rotation q v q^-1 of a vector.
Vec3 rotate(const Quat& q, const Vec3& v);
// The unit quaternion of a rotation by `radians` about `axis` (which need not be unit length,
// but must not be zero).
Quat fromAxisAngle(const Vec3& axis, double radians);

enum class ShapeType { Plane, Box, Sphere, Capsule, Cylinder, ConvexHull };
// "plane", "box", "sphere", "capsule", "cylinder", "convex_hull": the names used in the files.
const char* toString(ShapeType type);

// Geometry in the body frame (the centre of mass is the frame's origin).
struct Shape {
  ShapeType type = ShapeType::Box;
  // Box: full edge lengths along the body's x, y, z axes, m.
  Vec3 size{0, 0, 0};
  // Sphere, capsule and cylinder: radius, m.
  double radius = 0;
  // Capsule: length of the cylindrical part along the body's z axis, caps excluded, m (the
  // capsule's total length is length + 2 radius; Bullet's btCapsuleShapeZ "height" and ODE's
  // dCreateCapsule "length" mean the same). Cylinder: its full length along the body's z axis
  // (flat ends; Bullet's btCylinderShapeZ half extent z is length / 2, ODE's dCreateCylinder
  // length is this).
  double length = 0;
  // Convex hull: its corners in the body frame, m, shifted by the loader so that the solid's
  // centroid (its centre of mass at uniform density) is the origin; every point is a corner.
  // `faces` lists each face's corners (indices into hullPoints) counter-clockwise seen from
  // outside, as convexHullOf() (convex_hull.hpp) found them.
  std::vector<Vec3> hullPoints;
  std::vector<std::vector<int>> hullFaces;
  // Convex hull: principal moments of inertia per kg about the centroid (body axes), m^2.
  Vec3 hullInertiaPerKg{0, 0, 0};
  // Plane (static, world frame): the points p with dot(normal, p) = offset; normal is unit
  // length and points out of the solid half-space. offset in m.
  Vec3 normal{0, 0, 1};
  double offset = 0;
};

// Principal moments of inertia about the centre of mass, body frame, kg m^2, of a solid of
// uniform density and the given mass (kg). Box: m/12 (b^2 + c^2, ...). Sphere: 2/5 m r^2.
// Capsule (cylinder of length h plus two hemispheres, mass split by volume): axial
// m_c r^2/2 + m_s 2r^2/5; transverse m_c (h^2/12 + r^2/4) + m_s (2r^2/5 + h^2/4 + 3hr/8).
// Cylinder: axial m r^2/2, transverse m (3 r^2 + h^2) / 12. Convex hull: m hullInertiaPerKg
// (exact, from the hull's tetrahedra).
// A plane, or mass 0, gives zeros.
Vec3 inertiaOf(const Shape& shape, double mass);

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

enum class JointType { Ball, Hinge, Slider, Fixed, ConeTwist, SixDof, Universal, Hinge2, Gear };
// "ball", "hinge", "slider", "fixed", "cone_twist", "six_dof", "universal", "hinge2", "gear".
const char* toString(JointType type);

// Range of the hinge angle (rad) or the slider offset (m); lower <= upper. Hinge-2: the
// steering angle (rad) about `axis`.
struct JointLimits {
  bool enabled = false;
  double lower = 0, upper = 0;
};

// Velocity motor: drives the hinge angle (rad/s) or the slider offset (m/s) towards
// `velocity` with at most `maxForce` (N m for a hinge, N for a slider).
struct JointMotor {
  bool enabled = false;
  double velocity = 0;
  double maxForce = 0;
};

// A spring towards the pose at creation: force -stiffness x - damping dx/dt on the offset x
// (m; N/m and N s/m) or angle (rad; N m/rad and N m s/rad).
struct JointSpring {
  bool enabled = false;
  double stiffness = 0;
  double damping = 0;
};

// Cone-twist limits, rad: the twist about `axis` stays within +-twist, the swing of the twist
// axis within +-swing1 about `normal` and +-swing2 about axis x normal (Bullet's
// btConeTwistConstraint spans: an elliptic cone). All three in (0, pi); a twist of 0 locks it.
struct ConeLimits {
  double swing1 = 0, swing2 = 0, twist = 0;
};

// One axis of a six_dof joint: the offset (m) or angle (rad) of bodies[0] relative to
// bodies[1] (or the world) in the joint frame, as for the hinge and slider, either locked at 0,
// free, or kept in [lower, upper]; a spring may act on it in every mode but locked. Large limits
// (1e30, Bullet's SIMD_INFINITY style) are allowed and kept as written.
struct AxisDof {
  enum class Mode { Locked, Free, Limited };
  Mode mode = Mode::Locked;
  double lower = 0, upper = 0;
  JointSpring spring;
};

struct Joint {
  std::string name;
  JointType type = JointType::Ball;
  int body0 = -1;        // index into Scene::bodies, always a dynamic body
  int body1 = -1;        // index into Scene::bodies (a dynamic body), or -1 for the world
  Vec3 anchor{0, 0, 0};  // world frame at creation, m (all types; gear: bodies[0]'s centre)
  // Unit, world frame at creation: hinge, slider axis; cone_twist twist axis; six_dof frame x;
  // universal axis fixed in bodies[0]; hinge2 steering axis (fixed in bodies[0], the chassis);
  // gear bodies[0]'s axis of rotation.
  Vec3 axis{0, 0, 1};
  // Unit, world frame at creation: universal axis fixed in bodies[1]; hinge2 wheel axle (fixed
  // in bodies[1]); gear bodies[1]'s axis of rotation. Perpendicular to `axis` for universal and
  // hinge2.
  Vec3 axis2{0, 0, 1};
  // Unit, perpendicular to `axis`, world frame at creation: cone_twist swing1 axis, six_dof
  // frame y (frame z is axis x normal).
  Vec3 normal{0, 1, 0};
  Vec3 anchor2{0, 0, 0};  // gear: bodies[1]'s centre, world frame at creation, m
  JointLimits limits;     // hinge, slider, hinge2 (steering; default locked at 0)
  JointMotor motor;       // hinge, slider
  ConeLimits cone;        // cone_twist
  // six_dof: linear x, y, z then angular x, y, z of the joint frame (x = axis, y = normal).
  std::array<AxisDof, 6> dofs;
  JointSpring suspension;  // hinge2: along `axis` (default: rigid)
  // Gear: bodies[0] turns `ratio` times as fast as bodies[1], the other way round:
  // w0 . axis = -ratio w1 . axis2 (an external gear pair; ratio > 0).
  double ratio = 1;
  // Whether the two bodies still collide with each other. Default false.
  bool collideConnected = false;
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
  std::vector<Material> materials;  // materials[0] is "default"
  std::vector<Body> bodies;         // generators expanded, in file order
  std::vector<Joint> joints;

  // Index of the body or material of that name, or -1.
  int findBody(const std::string& name) const;
  int findMaterial(const std::string& name) const;
  int dynamicBodyCount() const;
};

// Reads and validates an mlcp-scene/1 file; throws FormatError.
Scene loadScene(const std::string& path);
// The same from text; sourceName is used in messages and as the default scene name.
Scene parseScene(const std::string& text, const std::string& sourceName = "<string>");

// The *.json files of a folder, sorted by name (the scenes/ folder holds nothing else).
std::vector<std::string> listSceneFiles(const std::string& folder);

}  // namespace mlcp::scene
