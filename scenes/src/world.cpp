// The engine-free part of a loaded scene: the body-state measures and the step wrapper.
#include "mlcp/scene/world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

namespace mlcp::scene {

namespace {

Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }

Quat multiply(const Quat& a, const Quat& b) {
  return {
      a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Body-frame point of a world point, for the body's pose (or the world frame for index -1).
Vec3 toLocal(const Body* body, const BodyState* state, const Vec3& p) {
  if (!body) return p;
  return rotate(conjugate(state->orientation), sub(p, state->position));
}

Vec3 toWorld(const BodyState* state, const Vec3& local) {
  if (!state) return local;
  return add(state->position, rotate(state->orientation, local));
}

double nowSeconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

}  // namespace

RunSettings RunSettings::fromScene(const Scene& scene) {
  RunSettings s;
  s.solver = scene.solver.name;
  s.iterations = scene.solver.iterations;
  s.tolerance = scene.solver.tolerance;
  s.warmStart = scene.solver.warmStart;
  s.friction = scene.solver.friction;
  s.frictionDirections = scene.solver.frictionDirections;
  return s;
}

std::string capturePrefix(const std::string& folder, const std::string& scene, const char* engine,
                          int step) {
  const std::string name = scene + "-" + engine + "-step" + std::to_string(step) + "-";
  return (std::filesystem::path(folder) / name).string();
}

bool isFinite(const BodyState& b) {
  for (const Vec3* v : {&b.position, &b.velocity, &b.angularVelocity})
    for (double x : *v)
      if (!std::isfinite(x)) return false;
  const Quat& q = b.orientation;
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

bool isFinite(const std::vector<BodyState>& states) {
  return std::all_of(states.begin(), states.end(), [](const BodyState& b) { return isFinite(b); });
}

double twistAngle(const Quat& q, const Vec3& axis) {
  return 2 * std::atan2(q.x * axis[0] + q.y * axis[1] + q.z * axis[2], q.w);
}

Quat relative(const Quat& q, const Quat& a) { return multiply(q, conjugate(a)); }

World::World(const Scene& scene) : scene_(scene) {
  // The anchors from the scene's start poses: every joint has zero error at creation.
  for (const Joint& j : scene_.joints) {
    BodyState s0, s1;
    const Body& b0 = scene_.bodies[j.body0];
    s0.position = b0.position;
    s0.orientation = b0.orientation;
    const Body* b1 = j.body1 >= 0 ? &scene_.bodies[j.body1] : nullptr;
    if (b1) {
      s1.position = b1->position;
      s1.orientation = b1->orientation;
    }
    anchors_.emplace_back(toLocal(&b0, &s0, j.anchor), toLocal(b1, &s1, j.anchor));
  }
}

World::~World() = default;

void World::step() {
  StepMeasures m;
  const double t0 = nowSeconds();
  stepEngine(m);
  m.stepMs = 1e3 * (nowSeconds() - t0);
  measureStates(scene_, states(), anchors_, m);
  last_ = m;
  ++steps_;
}

// Whether the joint keeps a point of the two bodies together (up to a slider's travel).
static bool anchorIsShared(const Joint& j) {
  switch (j.type) {
    case JointType::Gear: return false;
    case JointType::Hinge2: return !j.suspension.enabled;
    case JointType::SixDof:
      return std::all_of(j.dofs.begin(), j.dofs.begin() + 3,
                         [](const AxisDof& d) { return d.mode == AxisDof::Mode::Locked; });
    default: return true;
  }
}

void measureStates(const Scene& scene, const std::vector<BodyState>& states,
                   const std::vector<std::pair<Vec3, Vec3>>& anchors, StepMeasures& m) {
  Vec3 p{0, 0, 0};
  m.energy = 0;
  m.maxSpeed = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const Body& b = scene.bodies[i];
    if (b.isStatic()) continue;
    const BodyState& s = states[i];
    const Vec3 wBody = rotate(conjugate(s.orientation), s.angularVelocity);
    double rot = 0;
    for (int k = 0; k < 3; ++k) rot += b.inertia[k] * wBody[k] * wBody[k];
    m.energy += 0.5 * b.mass * dot(s.velocity, s.velocity) + 0.5 * rot -
                b.mass * dot(scene.gravity, s.position);
    for (int k = 0; k < 3; ++k) p[k] += b.mass * s.velocity[k];
    m.maxSpeed = std::max(m.maxSpeed, norm(s.velocity));
  }
  m.momentum = norm(p);
  m.jointError = 0;
  for (std::size_t i = 0; i < scene.joints.size() && i < anchors.size(); ++i) {
    const Joint& j = scene.joints[i];
    if (!anchorIsShared(j)) continue;
    const BodyState* s1 = j.body1 >= 0 ? &states[j.body1] : nullptr;
    Vec3 d = sub(toWorld(&states[j.body0], anchors[i].first), toWorld(s1, anchors[i].second));
    if (j.type == JointType::Slider) {
      // The axis moves with body1 (or stays in the world); sliding along it is no error.
      const Vec3 axis =
          s1 ? rotate(s1->orientation, rotate(conjugate(scene.bodies[j.body1].orientation), j.axis))
             : j.axis;
      const double along = dot(d, axis);
      for (int k = 0; k < 3; ++k) d[k] -= along * axis[k];
    }
    m.jointError = std::max(m.jointError, norm(d));
  }
}

}  // namespace mlcp::scene
