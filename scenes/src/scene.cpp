#include "mlcp/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "mlcp/input_limits.hpp"
#include "mlcp/scene/convex_hull.hpp"
#include "mlcp/scene/scene_limits.hpp"
#include "scene_parse.hpp"

namespace mlcp::scene {

// The parser's pieces live in parse (scene_parse.hpp), shared with articulation.cpp.
namespace parse {

Quat parseOrientation(const Node& n) {
  if (n.value().is_array()) {
    const json& a = n.value();
    if (a.size() != 4 || !std::all_of(a.begin(), a.end(), [](const json& e) {
          return e.is_number() && std::isfinite(e.get<double>());
        }))
      n.fail("expected a quaternion [w, x, y, z] or {\"axis\": [x, y, z], \"degrees\": a}, got " +
             shortDump(a));
    Quat q{a[0].get<double>(), a[1].get<double>(), a[2].get<double>(), a[3].get<double>()};
    double len = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    // Normalise rounding in hand-written values, but catch quaternions that are not rotations.
    if (std::abs(len - 1) > 1e-3) {
      std::ostringstream os;
      os << "quaternion [w, x, y, z] must have length 1, has " << len
         << " (or write {\"axis\": [x, y, z], \"degrees\": a})";
      n.fail(os.str());
    }
    return {q.w / len, q.x / len, q.y / len, q.z / len};
  }
  if (!n.value().is_object())
    n.fail("expected a quaternion [w, x, y, z] or {\"axis\": [x, y, z], \"degrees\": a}, got " +
           shortDump(n.value()));
  n.allowOnly({"axis", "degrees", "radians"});
  Vec3 axis = n.at("axis").unitVec3();
  if (n.has("degrees") == n.has("radians"))
    n.fail("give exactly one of \"degrees\" or \"radians\"");
  double angle =
      n.has("degrees") ? n.child("degrees").number() * kPi / 180.0 : n.child("radians").number();
  return fromAxisAngle(axis, angle);
}

// The hull's corners, moved so that its centroid is the body origin, its faces and its
// inertia per kg; the body axes must be the hull's principal axes.
void parseHull(const Node& n, Shape& s) {
  const std::size_t count = n.arraySize();
  if (count > std::size_t(kMaxHullPoints))
    n.fail("a convex hull takes at most " + std::to_string(kMaxHullPoints) + " points, got " +
           std::to_string(count));
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < count; ++i) points.push_back(n.item(i).vec3());
  ConvexHull h;
  try {
    h = convexHullOf(points);
  } catch (const std::invalid_argument& e) {
    n.fail(e.what());
  }
  const auto& I = h.inertiaPerKg;
  const double scale = I[0] + I[1] + I[2];
  if (std::max({std::abs(I[3]), std::abs(I[4]), std::abs(I[5])}) > 1e-9 * scale)
    n.fail(
        "the hull's products of inertia are not 0: give the points in its principal axes "
        "(and turn the body by its orientation)");
  for (Vec3 p : h.points)
    s.hullPoints.push_back({p[0] - h.centroid[0], p[1] - h.centroid[1], p[2] - h.centroid[2]});
  s.hullFaces = h.faces;
  s.hullInertiaPerKg = {I[0], I[1], I[2]};
}

Shape parseShape(const Node& n) {
  n.requireObject();
  const std::string type = n.at("type").string();
  Shape s;
  if (type == "box") {
    n.allowOnly({"type", "size"});
    s.type = ShapeType::Box;
    s.size = n.at("size").positiveVec3();
  } else if (type == "sphere") {
    n.allowOnly({"type", "radius"});
    s.type = ShapeType::Sphere;
    s.radius = n.at("radius").positive();
  } else if (type == "capsule") {
    n.allowOnly({"type", "radius", "length"});
    s.type = ShapeType::Capsule;
    s.radius = n.at("radius").positive();
    s.length = n.at("length").nonNegative();
  } else if (type == "cylinder") {
    n.allowOnly({"type", "radius", "length"});
    s.type = ShapeType::Cylinder;
    s.radius = n.at("radius").positive();
    s.length = n.at("length").positive();
  } else if (type == "convex_hull") {
    n.allowOnly({"type", "points"});
    s.type = ShapeType::ConvexHull;
    parseHull(n.at("points"), s);
  } else if (type == "plane") {
    n.allowOnly({"type", "normal", "offset"});
    s.type = ShapeType::Plane;
    s.normal = n.has("normal") ? n.child("normal").unitVec3() : Vec3{0, 0, 1};
    s.offset = numberOr(n, "offset", 0.0, &Node::number);
  } else {
    n.child("type").fail("unknown shape " + inQuotes(type) +
                         " (known: plane, box, sphere, capsule, cylinder, convex_hull)");
  }
  return s;
}

// Lowest and highest z of an unrotated shape in its body frame (what a stack piles up).
std::pair<double, double> zRangeOf(const Shape& s) {
  switch (s.type) {
    case ShapeType::Box: return {-s.size[2] / 2, s.size[2] / 2};
    case ShapeType::Sphere: return {-s.radius, s.radius};
    case ShapeType::Capsule: return {-s.length / 2 - s.radius, s.length / 2 + s.radius};
    case ShapeType::Cylinder: return {-s.length / 2, s.length / 2};
    case ShapeType::ConvexHull: {
      auto [lo, hi] = std::minmax_element(s.hullPoints.begin(), s.hullPoints.end(),
                                          [](const Vec3& a, const Vec3& b) { return a[2] < b[2]; });
      return {(*lo)[2], (*hi)[2]};
    }
    case ShapeType::Plane: break;
  }
  return {0, 0};
}

// Parses a body, or a generator's template body (no name or position: the generator sets
// them; stacks and pyramids also keep their bodies unrotated).
// The fields each role may have ("comment" aside).
void allowBodyFields(const Node& n, BodyRole role) {
  switch (role) {
    case BodyRole::Explicit:
      n.allowOnly({"name", "shape", "mass", "material", "position", "orientation", "velocity",
                   "angular_velocity"});
      return;
    case BodyRole::Link:
    case BodyRole::FixedBase:
      n.allowOnly({"name", "shape", "mass", "inertia", "material", "position", "orientation",
                   "parent", "joint"});
      return;
    case BodyRole::Template:
    case BodyRole::UnrotatedTemplate:
      n.forbid("name", "the generator names its bodies");
      n.forbid("position", "the generator places its bodies");
      if (role == BodyRole::UnrotatedTemplate)
        n.forbid("orientation", "stack and pyramid bodies are not rotated (use a grid)");
      n.allowOnly({"shape", "mass", "material", "orientation", "velocity", "angular_velocity"});
      return;
  }
}

// Mass, pose and velocity of a body that is not a plane.
void parseMassAndPose(const Node& n, BodyRole role, Body& b) {
  if (role == BodyRole::FixedBase) {
    if (n.has("mass") && n.child("mass").number() != 0)
      n.child("mass").fail("a fixed base is static: its mass must be 0 or omitted");
  } else {
    if (!n.has("mass")) n.fail("missing field \"mass\" (kg; 0 makes the body static)");
    b.mass = n.child("mass").nonNegative();
    const bool template_ = role == BodyRole::Template || role == BodyRole::UnrotatedTemplate;
    if (template_ && b.mass == 0)
      n.child("mass").fail("a generator's bodies must be dynamic (mass > 0)");
    if (role == BodyRole::Link && b.mass == 0)
      n.child("mass").fail("a link or floating base must be dynamic (mass > 0)");
  }
  b.position = vec3Or(n, "position", b.position);
  if (n.has("orientation")) b.orientation = parseOrientation(n.child("orientation"));
  b.velocity = vec3Or(n, "velocity", b.velocity);
  b.angularVelocity = vec3Or(n, "angular_velocity", b.angularVelocity);
  if (b.mass == 0 && (norm(b.velocity) != 0 || norm(b.angularVelocity) != 0))
    n.fail("a static body (mass 0) cannot have a velocity");
}

Body parseBody(const Node& n, BodyRole role, const Scene& scene) {
  n.requireObject();
  allowBodyFields(n, role);
  Body b;
  if (role == BodyRole::Explicit) b.name = n.at("name").string();
  b.shape = parseShape(n.at("shape"));
  if (b.shape.type == ShapeType::Plane) {
    if (role != BodyRole::Explicit)
      n.child("shape").fail("a plane can only be an entry of \"bodies\"");
    if (n.has("mass") && n.child("mass").number() != 0)
      n.child("mass").fail("a plane is static: its mass must be 0 or omitted");
    const char* why = "a plane is placed by shape.normal and shape.offset and does not move";
    for (const char* key : {"position", "orientation", "velocity", "angular_velocity"})
      n.forbid(key, why);
  } else {
    parseMassAndPose(n, role, b);
  }
  if (n.has("material")) {
    const std::string m = n.child("material").string();
    b.material = scene.findMaterial(m);
    if (b.material < 0) n.child("material").fail("no material named " + inQuotes(m));
  }
  return b;
}

void expandStack(const Node& n, const Body& t, const std::string& name, const Vec3& base,
                 std::vector<Body>& out) {
  n.allowOnly({"generator", "name", "body", "position", "count", "gap", "mass_factor"});
  const long long count = n.at("count").integer(1, kMaxGeneratedBodies);
  const double gap = numberOr(n, "gap", 0.0, &Node::nonNegative);
  const double factor = numberOr(n, "mass_factor", 1.0, &Node::positive);
  const auto [zLow, zHigh] = zRangeOf(t.shape);
  const double h = zHigh - zLow;
  double mass = t.mass;
  for (long long i = 0; i < count; ++i) {
    Body b = t;
    b.name = name + "." + std::to_string(i);
    b.position = {base[0], base[1], base[2] + double(i) * (h + gap) - zLow};
    b.mass = mass;
    mass *= factor;
    out.push_back(std::move(b));
  }
  if (!std::isfinite(mass / factor)) n.child("mass_factor").fail("the masses overflow");
}

void expandPyramid(const Node& n, const Body& t, const std::string& name, const Vec3& base,
                   std::vector<Body>& out) {
  n.allowOnly({"generator", "name", "body", "position", "base", "dimensions", "gap"});
  if (t.shape.type != ShapeType::Box)
    n.at("body").child("shape").fail("a pyramid is made of boxes");
  const long long layers = n.at("base").integer(1, 1000);
  const long long dims = n.has("dimensions") ? n.child("dimensions").integer(2, 3) : 2;
  const long long total =
      dims == 2 ? layers * (layers + 1) / 2 : layers * (layers + 1) * (2 * layers + 1) / 6;
  if (total > kMaxGeneratedBodies) n.child("base").fail("too many bodies");
  const double gap = numberOr(n, "gap", 0.0, &Node::nonNegative);
  const double px = t.shape.size[0] + gap, py = t.shape.size[1] + gap, h = t.shape.size[2];
  int index = 0;
  for (long long k = 0; k < layers; ++k) {
    const long long m = layers - k;  // boxes per row in this layer
    const long long rows = dims == 2 ? 1 : m;
    for (long long j = 0; j < rows; ++j) {
      for (long long i = 0; i < m; ++i) {
        Body b = t;
        b.name = name + "." + std::to_string(index++);
        const double y = dims == 2 ? 0.0 : (double(j) - double(m - 1) / 2) * py;
        b.position = {base[0] + (double(i) - double(m - 1) / 2) * px, base[1] + y,
                      base[2] + double(k) * h + h / 2};
        out.push_back(std::move(b));
      }
    }
  }
}

void expandGrid(const Node& n, const Body& t, const std::string& name, const Vec3& first,
                std::vector<Body>& out) {
  n.allowOnly({"generator", "name", "body", "position", "count", "spacing"});
  const Node c = n.at("count");
  if (c.arraySize() != 3) c.fail("expected 3 integers [nx, ny, nz], got " + shortDump(c.value()));
  long long count[3];
  for (std::size_t a = 0; a < 3; ++a) count[a] = c.item(a).integer(1, kMaxGeneratedBodies);
  if (count[0] * count[1] * count[2] > kMaxGeneratedBodies) c.fail("too many bodies");
  const Vec3 spacing = n.at("spacing").vec3("3 numbers >= 0");
  if (std::any_of(spacing.begin(), spacing.end(), [](double d) { return d < 0; }))
    n.child("spacing").fail("expected 3 numbers >= 0, got " +
                            shortDump(n.child("spacing").value()));
  int index = 0;
  for (long long k = 0; k < count[2]; ++k)
    for (long long j = 0; j < count[1]; ++j)
      for (long long i = 0; i < count[0]; ++i) {
        Body b = t;
        b.name = name + "." + std::to_string(index++);
        b.position = {first[0] + double(i) * spacing[0], first[1] + double(j) * spacing[1],
                      first[2] + double(k) * spacing[2]};
        out.push_back(std::move(b));
      }
}

void expandGenerator(const Node& n, const Scene& scene, std::vector<Body>& out) {
  const std::string kind = n.at("generator").string();
  const std::string name = n.at("name").string();
  const Vec3 position = vec3Or(n, "position", Vec3{0, 0, 0});
  const bool rotatable = kind == "grid";
  const Body t =
      parseBody(n.at("body"), rotatable ? BodyRole::Template : BodyRole::UnrotatedTemplate, scene);
  if (kind == "stack") {
    expandStack(n, t, name, position, out);
  } else if (kind == "pyramid") {
    expandPyramid(n, t, name, position, out);
  } else if (kind == "grid") {
    expandGrid(n, t, name, position, out);
  } else {
    n.child("generator")
        .fail("unknown generator " + inQuotes(kind) + " (known: stack, pyramid, grid)");
  }
}

void parseMaterials(const Node& n, Scene& scene) {
  n.requireObject();
  for (auto it = n.value().begin(); it != n.value().end(); ++it) {
    if (it.key() == "comment") continue;
    const Node m = n.child(it.key());
    m.allowOnly({"friction", "restitution"});
    Material mat;
    mat.name = it.key();
    mat.friction = numberOr(m, "friction", mat.friction, &Node::nonNegative);
    if (m.has("restitution")) mat.restitution = m.child("restitution").inRange(0, 1);
    int existing = scene.findMaterial(mat.name);
    if (existing >= 0)
      scene.materials[existing] = mat;  // only "default" can already be there
    else
      scene.materials.push_back(mat);
  }
}

void parseSettings(const Node& n, Settings& s) {
  n.allowOnly({"time_step", "steps", "erp", "cfm", "sleeping", "max_contacts_per_pair"});
  s.timeStep = numberOr(n, "time_step", s.timeStep, &Node::positive);
  if (n.has("steps")) s.steps = int(n.child("steps").integer(1, 100000000));
  if (n.has("erp")) s.erp = n.child("erp").inRange(0, 1);
  s.cfm = numberOr(n, "cfm", s.cfm, &Node::nonNegative);
  if (n.has("sleeping")) s.sleeping = n.child("sleeping").boolean();
  if (n.has("max_contacts_per_pair"))
    s.maxContactsPerPair = int(n.child("max_contacts_per_pair").integer(1, 64));
}

void parseSolver(const Node& n, SolverDefaults& s) {
  n.allowOnly({"name", "iterations", "tolerance", "warm_start", "friction", "friction_directions"});
  if (n.has("name")) s.name = n.child("name").string();
  if (n.has("iterations")) s.iterations = int(n.child("iterations").integer(1, 100000000));
  s.tolerance = numberOr(n, "tolerance", s.tolerance, &Node::positive);
  if (n.has("warm_start")) s.warmStart = n.child("warm_start").boolean();
  if (n.has("friction") && !parseFrictionModel(n.child("friction").string(), s.friction))
    n.child("friction").fail("must be \"box\" or \"cone\"");
  if (n.has("friction_directions"))
    s.frictionDirections =
        int(n.child("friction_directions").integer(kMinConeDirections, kMaxConeDirections));
}

int jointBody(const Node& n, const Scene& scene) {
  const std::string name = n.string();
  const int i = scene.findBody(name);
  if (i < 0) n.fail("no body named " + inQuotes(name));
  if (scene.bodies[i].isStatic())
    n.fail("body " + inQuotes(name) +
           " is static; a joint to the fixed world lists only the moving body");
  return i;
}

void parseJointLimitsAndMotor(const Node& n, Joint& j) {
  if (n.has("limits")) {
    const Node l = n.child("limits");
    l.allowOnly({"lower", "upper"});
    j.limits.enabled = true;
    j.limits.lower = l.at("lower").number();
    j.limits.upper = l.at("upper").number();
    if (j.limits.lower > j.limits.upper) {
      std::ostringstream os;
      os << "lower (" << j.limits.lower << ") is above upper (" << j.limits.upper << ")";
      l.fail(os.str());
    }
  }
  if (n.has("motor")) {
    const Node m = n.child("motor");
    m.allowOnly({"velocity", "max_force"});
    j.motor.enabled = true;
    j.motor.velocity = m.at("velocity").number();
    j.motor.maxForce = m.at("max_force").nonNegative();
  }
}

JointSpring parseSpring(const Node& n) {
  n.allowOnly({"stiffness", "damping"});
  JointSpring sp;
  sp.enabled = true;
  sp.stiffness = n.at("stiffness").nonNegative();
  sp.damping = numberOr(n, "damping", 0.0, &Node::nonNegative);
  return sp;
}

void parseCone(const Node& n, ConeLimits& c) {
  n.allowOnly({"swing1", "swing2", "twist"});
  c.swing1 = n.at("swing1").inRange(1e-6, kPi - 1e-6);
  c.swing2 = n.has("swing2") ? n.child("swing2").inRange(1e-6, kPi - 1e-6) : c.swing1;
  c.twist = n.at("twist").inRange(0, kPi - 1e-6);
}

// "locked", "free" or {"lower": l, "upper": u, "spring": {...}} (limits both or neither).
AxisDof parseDof(const Node& n) {
  AxisDof d;
  if (n.value().is_string()) {
    const std::string mode = n.string();
    if (mode == "free")
      d.mode = AxisDof::Mode::Free;
    else if (mode != "locked")
      n.fail("expected \"locked\", \"free\" or {\"lower\", \"upper\", \"spring\"}, got " +
             shortDump(n.value()));
    return d;
  }
  n.allowOnly({"lower", "upper", "spring"});
  if (n.has("lower") != n.has("upper")) n.fail("give both \"lower\" and \"upper\" or neither");
  d.mode = n.has("lower") ? AxisDof::Mode::Limited : AxisDof::Mode::Free;
  if (n.has("lower")) {
    d.lower = n.child("lower").number();
    d.upper = n.child("upper").number();
    if (d.lower > d.upper) n.fail("lower is above upper");
  }
  if (n.has("spring")) d.spring = parseSpring(n.child("spring"));
  return d;
}

void parseDofs(const Node& n, const char* key, AxisDof* dofs) {
  if (!n.has(key)) return;
  const Node list = n.child(key);
  if (list.arraySize() != 3) list.fail("expected 3 axes [x, y, z]");
  for (std::size_t a = 0; a < 3; ++a) dofs[a] = parseDof(list.item(a));
}

// The world axis least aligned with `axis`, made perpendicular to it.
Vec3 defaultNormal(const Vec3& axis) {
  int k = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(axis[a]) < std::abs(axis[k])) k = a;
  Vec3 e{0, 0, 0};
  e[k] = 1;
  const double d = dot(e, axis);
  Vec3 v{e[0] - d * axis[0], e[1] - d * axis[1], e[2] - d * axis[2]};
  const double l = norm(v);
  return {v[0] / l, v[1] / l, v[2] / l};
}

Vec3 perpendicularTo(const Node& n, const Vec3& axis) {
  const Vec3 v = n.unitVec3();
  if (std::abs(dot(v, axis)) > 1e-6) n.fail("must be perpendicular to \"axis\"");
  return v;
}

struct JointFields {
  JointType type;
  std::initializer_list<const char*> allowed;
  bool twoBodies;       // needs [A, B]
  bool anchorRequired;  // else A's position
};

const JointFields* jointFields(const std::string& type) {
  static const JointFields table[] = {
      {JointType::Ball, {"name", "type", "bodies", "anchor", "collide_connected"}, false, true},
      {JointType::Hinge,
       {"name", "type", "bodies", "anchor", "axis", "limits", "motor", "collide_connected"},
       false,
       true},
      {JointType::Slider,
       {"name", "type", "bodies", "anchor", "axis", "limits", "motor", "collide_connected"},
       false,
       false},
      {JointType::Fixed, {"name", "type", "bodies", "anchor", "collide_connected"}, false, false},
      {JointType::ConeTwist,
       {"name", "type", "bodies", "anchor", "axis", "normal", "cone", "collide_connected"},
       false,
       true},
      {JointType::SixDof,
       {"name", "type", "bodies", "anchor", "axis", "normal", "linear", "angular",
        "collide_connected"},
       false,
       false},
      {JointType::Universal,
       {"name", "type", "bodies", "anchor", "axis", "axis2", "collide_connected"},
       false,
       true},
      {JointType::Hinge2,
       {"name", "type", "bodies", "anchor", "axis", "axis2", "limits", "suspension",
        "collide_connected"},
       true,
       true},
      {JointType::Gear,
       {"name", "type", "bodies", "anchor", "anchor2", "axis", "axis2", "ratio",
        "collide_connected"},
       true,
       false},
  };
  for (const JointFields& f : table)
    if (type == toString(f.type)) return &f;
  return nullptr;
}

// The axes, limits and springs of the joint types beyond ball, hinge, slider and fixed.
void parseJointAxes(const Node& n, const Scene& scene, Joint& j) {
  switch (j.type) {
    case JointType::Hinge:
    case JointType::Slider:
      j.axis = n.at("axis").unitVec3();
      parseJointLimitsAndMotor(n, j);
      break;
    case JointType::ConeTwist:
      j.axis = n.at("axis").unitVec3();
      j.normal =
          n.has("normal") ? perpendicularTo(n.child("normal"), j.axis) : defaultNormal(j.axis);
      parseCone(n.at("cone"), j.cone);
      break;
    case JointType::SixDof:
      j.axis = n.has("axis") ? n.child("axis").unitVec3() : Vec3{1, 0, 0};
      j.normal =
          n.has("normal") ? perpendicularTo(n.child("normal"), j.axis) : defaultNormal(j.axis);
      parseDofs(n, "linear", &j.dofs[0]);
      parseDofs(n, "angular", &j.dofs[3]);
      break;
    case JointType::Universal:
    case JointType::Hinge2:
      j.axis = n.at("axis").unitVec3();
      j.axis2 = perpendicularTo(n.at("axis2"), j.axis);
      if (j.type == JointType::Hinge2) {
        j.limits.enabled = true;  // steering locked at 0 unless the file says otherwise
        parseJointLimitsAndMotor(n, j);
        if (n.has("suspension")) j.suspension = parseSpring(n.child("suspension"));
      }
      break;
    case JointType::Gear:
      j.axis = n.at("axis").unitVec3();
      j.axis2 = n.has("axis2") ? n.child("axis2").unitVec3() : j.axis;
      j.anchor2 = n.has("anchor2") ? n.child("anchor2").vec3() : scene.bodies[j.body1].position;
      j.ratio = n.at("ratio").positive();
      if (norm(Vec3{j.anchor2[0] - j.anchor[0], j.anchor2[1] - j.anchor[1],
                    j.anchor2[2] - j.anchor[2]}) < 1e-9)
        n.fail("a gear pair needs two different centres (anchor, anchor2)");
      break;
    case JointType::Ball:
    case JointType::Fixed: break;
  }
}

Joint parseJoint(const Node& n, std::size_t index, const Scene& scene) {
  n.requireObject();
  Joint j;
  j.name = n.has("name") ? n.child("name").string() : "joints[" + std::to_string(index) + "]";
  const Node typeNode = n.at("type");
  const std::string type = typeNode.string();
  const JointFields* fields = jointFields(type);
  if (!fields)
    typeNode.fail("unknown joint type " + inQuotes(type) +
                  " (known: ball, hinge, slider, fixed, cone_twist, six_dof, universal, hinge2, "
                  "gear)");
  j.type = fields->type;
  n.allowOnly(fields->allowed);

  const Node bodies = n.at("bodies");
  const std::size_t count = bodies.arraySize();
  if (count < 1 || count > 2)
    bodies.fail("expected 1 body name (jointed to the world) or 2, got " +
                shortDump(bodies.value()));
  if (fields->twoBodies && count != 2)
    bodies.fail("a " + type + " joint joins two bodies, got " + shortDump(bodies.value()));
  j.body0 = jointBody(bodies.item(0), scene);
  if (count == 2) {
    j.body1 = jointBody(bodies.item(1), scene);
    if (j.body1 == j.body0) bodies.fail("a joint needs two different bodies");
  }

  if (fields->anchorRequired || n.has("anchor"))
    j.anchor = n.at("anchor").vec3();
  else
    j.anchor = scene.bodies[j.body0].position;
  parseJointAxes(n, scene, j);
  if (n.has("collide_connected")) j.collideConnected = n.child("collide_connected").boolean();
  return j;
}

std::string stem(const std::string& source) {
  std::filesystem::path p(source);
  return p.extension() == ".json" ? p.stem().string() : p.filename().string();
}

}  // namespace parse

using namespace parse;

Vec3 rotate(const Quat& q, const Vec3& v) {
  // v + 2 u x (u x v + w v), u = (x, y, z): the expanded q v q^-1 for unit q.
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t{u[1] * v[2] - u[2] * v[1] + q.w * v[0], u[2] * v[0] - u[0] * v[2] + q.w * v[1],
               u[0] * v[1] - u[1] * v[0] + q.w * v[2]};
  return {v[0] + 2 * (u[1] * t[2] - u[2] * t[1]), v[1] + 2 * (u[2] * t[0] - u[0] * t[2]),
          v[2] + 2 * (u[0] * t[1] - u[1] * t[0])};
}

Quat fromAxisAngle(const Vec3& axis, double radians) {
  const double n = norm(axis);
  const double s = std::sin(radians / 2) / n;
  return {std::cos(radians / 2), axis[0] * s, axis[1] * s, axis[2] * s};
}

const char* toString(ShapeType type) {
  switch (type) {
    case ShapeType::Plane: return "plane";
    case ShapeType::Box: return "box";
    case ShapeType::Sphere: return "sphere";
    case ShapeType::Capsule: return "capsule";
    case ShapeType::Cylinder: return "cylinder";
    case ShapeType::ConvexHull: return "convex_hull";
  }
  return "?";
}

const char* toString(JointType type) {
  switch (type) {
    case JointType::Ball: return "ball";
    case JointType::Hinge: return "hinge";
    case JointType::Slider: return "slider";
    case JointType::Fixed: return "fixed";
    case JointType::ConeTwist: return "cone_twist";
    case JointType::SixDof: return "six_dof";
    case JointType::Universal: return "universal";
    case JointType::Hinge2: return "hinge2";
    case JointType::Gear: return "gear";
  }
  return "?";
}

Vec3 inertiaOf(const Shape& s, double m) {
  if (m <= 0) return {0, 0, 0};
  switch (s.type) {
    case ShapeType::Box: {
      const double x2 = s.size[0] * s.size[0], y2 = s.size[1] * s.size[1],
                   z2 = s.size[2] * s.size[2];
      return {m / 12 * (y2 + z2), m / 12 * (x2 + z2), m / 12 * (x2 + y2)};
    }
    case ShapeType::Sphere: {
      const double i = 0.4 * m * s.radius * s.radius;
      return {i, i, i};
    }
    case ShapeType::Capsule: {
      const double r = s.radius, h = s.length;
      const double vCyl = kPi * r * r * h, vCaps = 4.0 / 3.0 * kPi * r * r * r;
      const double mc = m * vCyl / (vCyl + vCaps), ms = m - mc;
      const double axial = mc * r * r / 2 + ms * 0.4 * r * r;
      // Each hemisphere's centre of mass sits 3r/8 from its flat face, which is h/2 from the
      // capsule's centre: the parallel-axis terms give h^2/4 + 3hr/8.
      const double transverse =
          mc * (h * h / 12 + r * r / 4) + ms * (0.4 * r * r + h * h / 4 + 3 * h * r / 8);
      return {transverse, transverse, axial};
    }
    case ShapeType::Cylinder: {
      const double r2 = s.radius * s.radius, h2 = s.length * s.length;
      const double transverse = m * (3 * r2 + h2) / 12;
      return {transverse, transverse, m * r2 / 2};
    }
    case ShapeType::ConvexHull:
      return {m * s.hullInertiaPerKg[0], m * s.hullInertiaPerKg[1], m * s.hullInertiaPerKg[2]};
    case ShapeType::Plane: break;
  }
  return {0, 0, 0};
}

double combinedFriction(const Material& a, const Material& b) {
  return std::sqrt(a.friction * b.friction);
}
double combinedRestitution(const Material& a, const Material& b) {
  return std::max(a.restitution, b.restitution);
}

int Scene::findBody(const std::string& n) const {
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].name == n) return int(i);
  return -1;
}

int Scene::findMaterial(const std::string& n) const {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == n) return int(i);
  return -1;
}

int Scene::dynamicBodyCount() const {
  return int(
      std::count_if(bodies.begin(), bodies.end(), [](const Body& b) { return !b.isStatic(); }));
}

Scene parseScene(const std::string& text, const std::string& sourceName) {
  io::checkJsonNesting(text, sourceName);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // syntax errors, and out_of_range for "1e309"
    throw FormatError(sourceName + ": " + io::jsonErrorText(e));
  }
  const Node root(doc, "", sourceName);
  root.allowOnly({"format", "name", "description", "gravity", "settings", "solver", "materials",
                  "bodies", "articulations", "joints"});
  const Node format = root.at("format");
  if (!format.value().is_string() || format.value().get<std::string>() != kFormat)
    format.fail(std::string("expected \"") + kFormat + "\", got " + shortDump(format.value()));

  Scene scene;
  scene.source = sourceName;
  scene.name = root.has("name") ? root.child("name").string() : stem(sourceName);
  if (root.has("description")) scene.description = root.child("description").string();
  scene.gravity = vec3Or(root, "gravity", scene.gravity);
  if (root.has("settings")) parseSettings(root.child("settings"), scene.settings);
  if (root.has("solver")) parseSolver(root.child("solver"), scene.solver);
  scene.materials.push_back(Material{"default"});
  if (root.has("materials")) parseMaterials(root.child("materials"), scene);

  const Node bodies = root.at("bodies");
  if (bodies.arraySize() == 0) bodies.fail("a scene needs at least one body");
  std::map<std::string, std::string> firstUse;  // body name -> path of the entry that made it
  for (std::size_t i = 0; i < bodies.arraySize(); ++i) {
    const Node entry = bodies.item(i);
    entry.requireObject();
    const std::size_t before = scene.bodies.size();
    if (entry.has("generator"))
      expandGenerator(entry, scene, scene.bodies);
    else
      scene.bodies.push_back(parseBody(entry, BodyRole::Explicit, scene));
    if (scene.bodies.size() > std::size_t(kMaxGeneratedBodies))
      entry.fail("the scene has more than " + std::to_string(kMaxGeneratedBodies) + " bodies");
    for (std::size_t b = before; b < scene.bodies.size(); ++b) {
      auto [it, fresh] = firstUse.emplace(scene.bodies[b].name, entry.path());
      if (!fresh)
        entry.fail("body name " + inQuotes(scene.bodies[b].name) + " is already used by " +
                   it->second);
    }
  }
  for (Body& b : scene.bodies) b.inertia = inertiaOf(b.shape, b.mass);
  // Articulations first: their link joints take scene.joints[0 ..), the file's joints follow.
  if (root.has("articulations")) parseArticulations(root.child("articulations"), scene);
  if (scene.dynamicBodyCount() == 0)
    bodies.fail("a scene needs at least one dynamic body (mass > 0)");

  if (root.has("joints")) {
    const Node joints = root.child("joints");
    const std::size_t first = scene.joints.size();
    for (std::size_t i = 0; i < joints.arraySize(); ++i)
      scene.joints.push_back(parseJoint(joints.item(i), i, scene));
    checkArticulationsAlone(joints, scene, first);
  }
  checkSceneLimits(scene);
  return scene;
}

Scene loadScene(const std::string& path) {
  return parseScene(io::readInputFile(path, io::kMaxSceneFileBytes, "scene file"), path);
}

std::vector<std::string> listSceneFiles(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec))
    if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace mlcp::scene
