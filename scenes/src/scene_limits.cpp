#include "mlcp/scene/scene_limits.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "mlcp/input_limits.hpp"

namespace mlcp::scene {

using namespace limits;

namespace {

// The place a check names: "body \"box.3\"", "joint \"knee\"", "settings".
class Where {
 public:
  Where(const Scene& scene, std::string what) : source_(scene.source), what_(std::move(what)) {}

  [[noreturn]] void fail(const char* field, const std::string& problem) const {
    throw FormatError(source_ + ": " + what_ + ": " + field + ": " + problem);
  }

  // lo <= v <= hi (a NaN fails too); the message gives the value to 3 digits and the range.
  void range(const char* field, double v, double lo, double hi, const char* unit) const {
    if (v >= lo && v <= hi) return;
    std::ostringstream os;
    os.precision(3);
    os << v << " is outside [" << lo << ", " << hi << "]" << (*unit ? " " : "") << unit;
    fail(field, os.str());
  }
  void magnitude(const char* field, double v, double max, const char* unit) const {
    range(field, v, -max, max, unit);
  }
  void magnitude(const char* field, const Vec3& v, double max, const char* unit) const {
    for (double c : v) magnitude(field, c, max, unit);
  }
  void unit(const char* field, double length) const {
    if (std::abs(length - 1) <= kUnitTolerance) return;
    fail(field, "is not a direction of length 1 after normalisation (too large or too small)");
  }

 private:
  const std::string& source_;
  std::string what_;
};

double length(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

void checkShape(const Where& at, const Shape& s) {
  switch (s.type) {
    case ShapeType::Box:
      for (double e : s.size) at.range("shape.size", e, kMinLength, kMaxLength, "m");
      return;
    case ShapeType::Sphere: at.range("shape.radius", s.radius, kMinLength, kMaxLength, "m"); return;
    case ShapeType::Capsule:
      at.range("shape.radius", s.radius, kMinLength, kMaxLength, "m");
      at.range("shape.length", s.length, 0, kMaxLength, "m");
      return;
    case ShapeType::Cylinder:
      at.range("shape.radius", s.radius, kMinLength, kMaxLength, "m");
      at.range("shape.length", s.length, kMinLength, kMaxLength, "m");
      return;
    case ShapeType::ConvexHull:
      for (const Vec3& p : s.hullPoints) at.magnitude("shape.points", p, kMaxLength, "m");
      return;
    case ShapeType::Plane:
      at.unit("shape.normal", length(s.normal));
      at.magnitude("shape.offset", s.offset, kMaxCoordinate, "m");
      return;
  }
}

void checkBody(const Scene& scene, const Body& b) {
  const Where at(scene, "body \"" + io::capped(b.name) + "\"");
  checkShape(at, b.shape);
  if (!b.isStatic()) at.range("mass", b.mass, kMinMass, kMaxMass, "kg");
  at.magnitude("position", b.position, kMaxCoordinate, "m");
  const Quat& q = b.orientation;
  at.unit("orientation", std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z));
  at.magnitude("velocity", b.velocity, kMaxSpeed, "m/s");
  at.magnitude("angular_velocity", b.angularVelocity, kMaxAngularSpeed, "rad/s");
  for (double i : b.inertia) at.range("inertia", i, 0, kMaxInertia, "kg m^2");
}

void checkSpring(const Where& at, const char* field, const JointSpring& s) {
  if (!s.enabled) return;
  at.range(field, s.stiffness, 0, kMaxStiffness, "N/m or N m/rad");
  at.range(field, s.damping, 0, kMaxStiffness, "N s/m or N m s/rad");
}

// The fields of the joint types beyond ball, hinge, slider and fixed.
void checkJointExtras(const Where& at, const Joint& j) {
  at.unit("axis2", length(j.axis2));
  at.unit("normal", length(j.normal));
  at.magnitude("anchor2", j.anchor2, kMaxCoordinate, "m");
  for (double a : {j.cone.swing1, j.cone.swing2, j.cone.twist})
    at.range("cone", a, 0, 3.14159265358979323846, "rad");
  for (const AxisDof& d : j.dofs) {
    at.magnitude("dof limit", d.lower, kMaxDofLimit, "rad or m");
    at.magnitude("dof limit", d.upper, kMaxDofLimit, "rad or m");
    checkSpring(at, "dof spring", d.spring);
  }
  checkSpring(at, "suspension", j.suspension);
  at.magnitude("ratio", j.ratio, kMaxGearRatio, "");
}

void checkJoint(const Scene& scene, const Joint& j) {
  const Where at(scene, "joint \"" + io::capped(j.name) + "\"");
  at.magnitude("anchor", j.anchor, kMaxCoordinate, "m");
  at.unit("axis", length(j.axis));
  if (j.limits.enabled) {
    at.magnitude("limits.lower", j.limits.lower, kMaxJointLimit, "rad or m");
    at.magnitude("limits.upper", j.limits.upper, kMaxJointLimit, "rad or m");
  }
  if (j.motor.enabled) {
    at.magnitude("motor.velocity", j.motor.velocity, kMaxSpeed, "rad/s or m/s");
    at.range("motor.max_force", j.motor.maxForce, 0, kMaxForce, "N or N m");
  }
  checkJointExtras(at, j);
}

void checkCounts(const Scene& scene) {
  const Where at(scene, "scene");
  at.range("bodies", double(scene.bodies.size()), 1, double(kMaxBodies), "");
  at.range("joints", double(scene.joints.size()), 0, double(kMaxJoints), "");
  at.range("materials", double(scene.materials.size()), 1, double(kMaxMaterials), "");
}

void checkSettings(const Scene& scene) {
  const Where settings(scene, "settings");
  const Settings& s = scene.settings;
  settings.range("time_step", s.timeStep, kMinTimeStep, kMaxTimeStep, "s");
  settings.range("steps", s.steps, 1, double(kMaxSteps), "");
  settings.range("cfm", s.cfm, 0, kMaxCfm, "");
  const Where solver(scene, "solver");
  solver.range("iterations", scene.solver.iterations, 1, double(kMaxIterations), "");
  solver.range("tolerance", scene.solver.tolerance, kMinTolerance, kMaxTolerance, "");
  solver.range("friction_directions", scene.solver.frictionDirections, kMinConeDirections,
               kMaxConeDirections, "");
  Where(scene, "scene").magnitude("gravity", scene.gravity, kMaxGravity, "m/s^2");
}

}  // namespace

void checkSceneLimits(const Scene& scene) {
  checkCounts(scene);
  checkSettings(scene);
  for (const Material& m : scene.materials)
    Where(scene, "material \"" + io::capped(m.name) + "\"")
        .range("friction", m.friction, 0, kMaxFriction, "");
  for (const Body& b : scene.bodies) checkBody(scene, b);
  for (const Joint& j : scene.joints) checkJoint(scene, j);
}

}  // namespace mlcp::scene
