// Tests of the scene model and loader (mlcp/scene/scene.hpp): every file in scenes/ loads with
// the counts it promises and is geometrically sane (nothing interpenetrates, resting bodies
// touch their supports, the incline and domino set-ups do what their names say); inertia
// formulas against an independent integration; generator expansion; bad files.
#include "mlcp/scene/scene.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mlcp/scene/convex_hull.hpp"
#include "mlcp/scene/world.hpp"

namespace {

using namespace mlcp::scene;

const std::string kScenesDir = std::string(MLCP_SOURCE_DIR) + "/scenes";
constexpr double kPi = 3.14159265358979323846;

Scene load(const std::string& name) { return loadScene(kScenesDir + "/" + name + ".json"); }

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double length(const Vec3& a) { return std::sqrt(dot(a, a)); }

// ---------------------------------------------------------------------------------------------
// A small geometric checker, independent of the engines: signed separation of two shapes
// (negative = interpenetration depth). Exact for plane-anything, box-box (separating axes,
// whose best axis gives the penetration depth) and sphere-box; capsules are sampled as rows of
// spheres, which can only under-report an overlap by a sliver far below the sizes used here.

struct Placed {
  const Body* body;
  Vec3 axis[3];  // body axes in the world
};

Placed place(const Body& b) {
  Placed p{&b, {}};
  for (int i = 0; i < 3; ++i) {
    Vec3 e{0, 0, 0};
    e[i] = 1;
    p.axis[i] = rotate(b.orientation, e);
  }
  return p;
}

// Points along a sphere's centre or a capsule's axis segment.
std::vector<Vec3> spine(const Placed& p, int samples) {
  const Body& b = *p.body;
  if (b.shape.type == ShapeType::Sphere || b.shape.length == 0) return {b.position};
  std::vector<Vec3> pts;
  for (int i = 0; i <= samples; ++i) {
    double t = b.shape.length * (double(i) / samples - 0.5);
    pts.push_back(add(b.position, scale(p.axis[2], t)));
  }
  return pts;
}

double boxRadiusAlong(const Placed& p, const Vec3& l) {
  const Vec3& s = p.body->shape.size;
  return 0.5 * (s[0] * std::abs(dot(p.axis[0], l)) + s[1] * std::abs(dot(p.axis[1], l)) +
                s[2] * std::abs(dot(p.axis[2], l)));
}

double boxBox(const Placed& a, const Placed& b) {
  std::vector<Vec3> axes;
  for (int i = 0; i < 3; ++i) axes.push_back(a.axis[i]), axes.push_back(b.axis[i]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Vec3 c = cross(a.axis[i], b.axis[j]);
      if (length(c) > 1e-9) axes.push_back(scale(c, 1 / length(c)));
    }
  const Vec3 d = sub(b.body->position, a.body->position);
  double best = -1e300;
  for (const Vec3& l : axes)
    best = std::max(best, std::abs(dot(d, l)) - boxRadiusAlong(a, l) - boxRadiusAlong(b, l));
  return best;
}

double pointBox(const Vec3& q, const Placed& box) {
  const Vec3 d = sub(q, box.body->position);
  double outside = 0, inside = -1e300;
  for (int i = 0; i < 3; ++i) {
    double h = box.body->shape.size[i] / 2, c = dot(d, box.axis[i]);
    double e = std::abs(c) - h;
    if (e > 0) outside += e * e;
    inside = std::max(inside, e);
  }
  return outside > 0 ? std::sqrt(outside) : inside;
}

double pointSegment(const Vec3& q, const Vec3& a, const Vec3& b) {
  const Vec3 ab = sub(b, a);
  const double l2 = dot(ab, ab);
  const double t = l2 > 0 ? std::clamp(dot(sub(q, a), ab) / l2, 0.0, 1.0) : 0.0;
  return length(sub(q, add(a, scale(ab, t))));
}

double planeSeparation(const Body& plane, const Placed& p) {
  const Vec3& n = plane.shape.normal;
  const Body& b = *p.body;
  if (b.shape.type == ShapeType::Box)
    return dot(n, b.position) - plane.shape.offset - boxRadiusAlong(p, n);
  double lowest = 1e300;
  for (const Vec3& q : spine(p, 1)) lowest = std::min(lowest, dot(n, q));
  return lowest - plane.shape.offset - b.shape.radius;
}

double separation(const Placed& a, const Placed& b) {
  const ShapeType ta = a.body->shape.type, tb = b.body->shape.type;
  if (ta == ShapeType::Plane) return planeSeparation(*a.body, b);
  if (tb == ShapeType::Plane) return planeSeparation(*b.body, a);
  if (ta == ShapeType::Box && tb == ShapeType::Box) return boxBox(a, b);
  if (tb == ShapeType::Box) return separation(b, a);
  const double rb = b.body->shape.radius;
  double best = 1e300;
  if (ta == ShapeType::Box) {
    for (const Vec3& q : spine(b, 400)) best = std::min(best, pointBox(q, a) - rb);
    return best;
  }
  const std::vector<Vec3> sa = spine(a, 1);
  for (const Vec3& q : spine(b, 400))
    best = std::min(best, pointSegment(q, sa.front(), sa.back()) - a.body->shape.radius - rb);
  return best;
}

// Radius of a sphere about the centre that holds the whole shape (planes: infinite).
double boundingRadius(const Body& b) {
  switch (b.shape.type) {
    case ShapeType::Box: return length(b.shape.size) / 2;
    case ShapeType::Sphere: return b.shape.radius;
    case ShapeType::Capsule: return b.shape.length / 2 + b.shape.radius;
    case ShapeType::Cylinder: return std::hypot(b.shape.length / 2, b.shape.radius);
    case ShapeType::ConvexHull: {
      double r = 0;
      for (const Vec3& p : b.shape.hullPoints) r = std::max(r, length(p));
      return r;
    }
    case ShapeType::Plane: break;
  }
  return 1e300;
}

// Cylinders and convex hulls are checked through shapes that contain them: a cylinder as the
// capsule of its radius and length, a hull as the box of its corners' bounds (exact for the
// scenes' prisms, which rest on their flat faces). Overlaps can then only be over-reported.
std::vector<Body> checkedShapes(const Scene& s) {
  std::vector<Body> out = s.bodies;
  for (Body& b : out) {
    if (b.shape.type == ShapeType::Cylinder) {
      b.shape.type = ShapeType::Capsule;
    } else if (b.shape.type == ShapeType::ConvexHull) {
      Vec3 lo = b.shape.hullPoints[0], hi = lo;
      for (const Vec3& p : b.shape.hullPoints)
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
      b.shape.type = ShapeType::Box;
      b.shape.size = sub(hi, lo);
      b.position = add(b.position, rotate(b.orientation, scale(add(lo, hi), 0.5)));
    }
  }
  return out;
}

// The separation, or a lower bound of it (> `margin`) when the bounding spheres are farther
// apart than `margin`: keeps the all-pairs checks fast (pyramid_1000 has half a million pairs).
double separationOrFar(const Placed& a, const Placed& b, double margin) {
  const double gap = length(sub(a.body->position, b.body->position)) - boundingRadius(*a.body) -
                     boundingRadius(*b.body);
  return gap > margin ? gap : separation(a, b);
}

// Pairs that may touch or overlap by design: both static, or joined by a joint that lets them.
bool exempt(const Scene& s, int i, int j) {
  if (s.bodies[i].isStatic() && s.bodies[j].isStatic()) return true;
  for (const Joint& jt : s.joints)
    if (!jt.collideConnected &&
        ((jt.body0 == i && jt.body1 == j) || (jt.body0 == j && jt.body1 == i)))
      return true;
  for (const auto& [link, base] : s.fixedBaseNeighbours())
    if ((link == i && base == j) || (link == j && base == i)) return true;
  return false;
}

// ---------------------------------------------------------------------------------------------

struct Expected {
  const char* file;
  int bodies, dynamic, joints;
};

// Every scene file, with the counts its description in scenes/README.md promises (the static bodies
// are the ground, the ramp and the pit's walls).
const Expected kScenes[] = {
    {"dominoes", 21, 20, 0},
    {"heavy_on_small", 4, 3, 0},
    {"hinge_motor_limits", 1, 1, 1},
    {"incline_slide", 3, 1, 0},
    {"incline_stick", 3, 1, 0},
    {"mass_ratio_stack", 7, 6, 0},
    {"pendulum_chain", 11, 11, 11},
    {"pyramid_1000", 1016, 1015, 0},
    {"pyramid_15", 16, 15, 0},
    {"pyramid_210", 211, 210, 0},
    {"pyramid_55", 56, 55, 0},
    {"ragdoll", 12, 11, 10},
    {"resting_box", 2, 1, 0},
    {"slider_motor_limits", 2, 2, 2},
    {"sphere_pit", 221, 216, 0},
    {"stack_10", 11, 10, 0},
    {"ragdoll_pile", 67, 66, 60},
    {"plank_bridge", 15, 14, 26},
    {"vehicle", 6, 5, 4},
    {"six_dof_spring", 3, 2, 2},
    {"gear_pair", 3, 2, 3},
    {"stack_1000", 1001, 1000, 0},
    {"boxes_3000", 3001, 3000, 0},
    {"hull_stack", 9, 8, 0},
    {"slide_diagonal", 2, 1, 0},  // the friction models' anisotropy
    {"wall_120", 121, 120, 0},
    {"basic_demo", 126, 125, 0},  // Bullet's BasicDemo
    // Articulated bodies: a link joint each.
    {"arm_push", 8, 6, 4},
    {"legged_base", 10, 9, 8},
    {"spherical_chain", 8, 6, 5},  // Bullet's MultiDofDemo
    {"limit_chain", 8, 6, 6},
};

TEST(SceneFiles, EveryFileIsListedAndLoadsWithItsCounts) {
  std::set<std::string> listed;
  for (const Expected& e : kScenes) listed.insert(e.file);
  std::set<std::string> found;
  for (const std::string& path : listSceneFiles(kScenesDir))
    found.insert(std::filesystem::path(path).stem().string());
  EXPECT_EQ(found, listed) << "a scene file was added or removed: update kScenes";

  for (const Expected& e : kScenes) {
    SCOPED_TRACE(e.file);
    const Scene s = load(e.file);
    EXPECT_EQ(s.name, e.file);
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(int(s.bodies.size()), e.bodies);
    EXPECT_EQ(s.dynamicBodyCount(), e.dynamic);
    EXPECT_EQ(int(s.joints.size()), e.joints);
    for (const Body& b : s.bodies) {
      EXPECT_EQ(b.isStatic(), b.inertia == (Vec3{0, 0, 0})) << b.name;
      EXPECT_GE(b.material, 0);
      EXPECT_LT(b.material, int(s.materials.size()));
    }
  }
}

TEST(SceneFiles, NothingInterpenetrates) {
  for (const Expected& e : kScenes) {
    SCOPED_TRACE(e.file);
    const Scene s = load(e.file);
    const std::vector<Body> shapes = checkedShapes(s);
    std::vector<Placed> placed;
    for (const Body& b : shapes) placed.push_back(place(b));
    int overlaps = 0;
    for (std::size_t i = 0; i < placed.size(); ++i)
      for (std::size_t j = i + 1; j < placed.size(); ++j) {
        if (exempt(s, int(i), int(j))) continue;
        const double sep = separationOrFar(placed[i], placed[j], 0.0);
        if (sep < -1e-9 && ++overlaps <= 5)
          ADD_FAILURE() << s.bodies[i].name << " and " << s.bodies[j].name << " overlap by " << -sep
                        << " m";
      }
    EXPECT_EQ(overlaps, 0);
  }
}

// Scenes that start at rest: every dynamic body touches (within 1 micrometre) a body or plane
// whose centre is lower, so nothing drops at the first step.
TEST(SceneFiles, RestingBodiesTouchTheirSupports) {
  for (const char* name :
       {"resting_box", "incline_stick", "incline_slide", "stack_10", "pyramid_15", "pyramid_55",
        "pyramid_210", "pyramid_1000", "heavy_on_small", "mass_ratio_stack", "stack_1000",
        "hull_stack", "wall_120"}) {
    SCOPED_TRACE(name);
    const Scene s = load(name);
    const std::vector<Body> shapes = checkedShapes(s);
    std::vector<Placed> placed;
    for (const Body& b : shapes) placed.push_back(place(b));
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      if (s.bodies[i].isStatic()) continue;
      bool supported = false;
      for (std::size_t j = 0; j < s.bodies.size() && !supported; ++j) {
        if (j == i) continue;
        const bool lower = s.bodies[j].shape.type == ShapeType::Plane ||
                           s.bodies[j].position[2] < s.bodies[i].position[2];
        supported = lower && std::abs(separationOrFar(placed[i], placed[j], 1e-3)) <= 1e-6;
      }
      EXPECT_TRUE(supported) << s.bodies[i].name << " hangs in the air";
    }
  }
}

// The slope of a ramp's top face and the friction the contact will use.
void rampSlopeAndFriction(const Scene& s, double& tanSlope, double& mu) {
  const Body& ramp = s.bodies[s.findBody("ramp")];
  const Body& box = s.bodies[s.findBody("box")];
  const Vec3 n = rotate(ramp.orientation, {0, 0, 1});
  tanSlope = std::sqrt(n[0] * n[0] + n[1] * n[1]) / n[2];
  mu = combinedFriction(s.materials[ramp.material], s.materials[box.material]);
}

TEST(SceneFiles, InclinesStickAndSlideByAClearMargin) {
  double tanSlope = 0, mu = 0;
  rampSlopeAndFriction(load("incline_stick"), tanSlope, mu);
  EXPECT_NEAR(std::atan(tanSlope) * 180 / kPi, 20, 1e-9);
  EXPECT_LT(tanSlope, mu - 0.2);
  rampSlopeAndFriction(load("incline_slide"), tanSlope, mu);
  EXPECT_NEAR(std::atan(tanSlope) * 180 / kPi, 35, 1e-9);
  EXPECT_GT(tanSlope, mu + 0.3);
}

TEST(SceneFiles, MassRatiosAreThePromisedOnes) {
  const Scene stack = load("mass_ratio_stack");
  for (int i = 1; i <= 5; ++i)
    EXPECT_DOUBLE_EQ(stack.bodies[i + 1].mass / stack.bodies[i].mass, 4.0);
  EXPECT_GT(stack.bodies[6].position[2], stack.bodies[1].position[2]);  // heaviest on top

  const Scene heavy = load("heavy_on_small");
  EXPECT_DOUBLE_EQ(
      heavy.bodies[heavy.findBody("heavy")].mass / heavy.bodies[heavy.findBody("small_left")].mass,
      400.0);

  const Scene chain = load("pendulum_chain");
  EXPECT_DOUBLE_EQ(
      chain.bodies[chain.findBody("end")].mass / chain.bodies[chain.findBody("link.0")].mass,
      100.0);
  // A chain: the first link hangs from the world, every other body from the one before it,
  // and each anchor is where the two bodies meet.
  ASSERT_EQ(chain.joints.size(), 11u);
  EXPECT_EQ(chain.joints[0].body1, -1);
  for (std::size_t k = 1; k < chain.joints.size(); ++k) {
    const Joint& j = chain.joints[k];
    EXPECT_EQ(j.body1, j.body0 - 1);
    const Vec3 mid =
        scale(add(chain.bodies[j.body0].position, chain.bodies[j.body1].position), 0.5);
    EXPECT_LT(std::abs(j.anchor[0] - mid[0]), 0.13) << j.name;
  }
}

TEST(SceneFiles, DominoesAreCloseEnoughToTopple) {
  const Scene s = load("dominoes");
  std::vector<const Body*> row;
  for (const Body& b : s.bodies)
    if (!b.isStatic()) row.push_back(&b);
  ASSERT_EQ(row.size(), 20u);
  for (std::size_t i = 1; i < row.size(); ++i) {
    const double height = row[i]->shape.size[2], thickness = row[i]->shape.size[0];
    const double gap = row[i]->position[0] - row[i - 1]->position[0] - thickness;
    EXPECT_GT(gap, 0);
    EXPECT_LT(gap, 0.6 * height) << "domino " << i << " would not reach the next";
  }
  // The first one leans past its tipping point: its centre of mass is ahead of its front edge.
  const Body& first = *row[0];
  const Vec3 front =
      add(first.position,
          rotate(first.orientation, {first.shape.size[0] / 2, 0, -first.shape.size[2] / 2}));
  EXPECT_NEAR(front[2], 0, 1e-9);
  EXPECT_GT(first.position[0], front[0]);
}

TEST(SceneFiles, HingeMotorCanLiftTheBarToItsLimit) {
  const Scene s = load("hinge_motor_limits");
  const Joint& j = s.joints.at(0);
  const Body& bar = s.bodies.at(j.body0);
  ASSERT_TRUE(j.limits.enabled && j.motor.enabled);
  const double gravityTorque = bar.mass * 9.81 * length(sub(bar.position, j.anchor));
  EXPECT_GT(j.motor.maxForce, 1.5 * gravityTorque);
  EXPECT_GT(j.motor.velocity, 0);
  // Reaches the upper limit well within the run.
  EXPECT_LT(j.limits.upper / j.motor.velocity, 0.5 * s.settings.steps * s.settings.timeStep);
  // A positive angle lifts the free end: axis x (end - anchor) points up.
  EXPECT_GT(cross(j.axis, sub(bar.position, j.anchor))[2], 0);
}

// ---------------------------------------------------------------------------------------------
// Inertia

// Moments of a solid of revolution about z (radius profile rho(z) on [z0, z1]) and about a
// transverse axis through the origin, by midpoint slices: independent of the closed forms.
template <class Profile>
Vec3 sliceInertia(Profile rho, double z0, double z1, double mass) {
  const int n = 200000;
  const double dz = (z1 - z0) / n;
  double volume = 0, axial = 0, transverse = 0;
  for (int i = 0; i < n; ++i) {
    const double z = z0 + (i + 0.5) * dz, r = rho(z), dv = kPi * r * r * dz;
    volume += dv;
    axial += dv * r * r / 2;
    transverse += dv * (r * r / 4 + z * z);
  }
  const double density = mass / volume;
  return {density * transverse, density * transverse, density * axial};
}

TEST(Inertia, BoxAndSphere) {
  Shape box;
  box.type = ShapeType::Box;
  box.size = {2, 3, 4};
  const Vec3 ib = inertiaOf(box, 6);
  EXPECT_DOUBLE_EQ(ib[0], 6.0 / 12 * (9 + 16));
  EXPECT_DOUBLE_EQ(ib[1], 6.0 / 12 * (4 + 16));
  EXPECT_DOUBLE_EQ(ib[2], 6.0 / 12 * (4 + 9));
  Shape sphere;
  sphere.type = ShapeType::Sphere;
  sphere.radius = 2;
  const Vec3 s =
      sliceInertia([](double z) { return std::sqrt(std::max(0.0, 4 - z * z)); }, -2, 2, 5);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(inertiaOf(sphere, 5)[i], s[2], 1e-6 * s[2]);
  EXPECT_DOUBLE_EQ(inertiaOf(sphere, 5)[0], 0.4 * 5 * 4);
}

TEST(Inertia, CapsuleMatchesIntegration) {
  for (auto [r, h] : {std::pair{0.05, 0.4}, {0.5, 2.0}, {1.0, 0.1}}) {
    Shape cap;
    cap.type = ShapeType::Capsule;
    cap.radius = r;
    cap.length = h;
    const auto profile = [r = r, h = h](double z) {
      const double e = std::max(0.0, std::abs(z) - h / 2);
      return std::sqrt(std::max(0.0, r * r - e * e));
    };
    const Vec3 expect = sliceInertia(profile, -h / 2 - r, h / 2 + r, 3.0);
    const Vec3 got = inertiaOf(cap, 3.0);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expect[i], 1e-5 * expect[i]) << r << " " << h;
  }
  Shape ball;
  ball.type = ShapeType::Capsule;
  ball.radius = 0.3;
  Shape sphere;
  sphere.type = ShapeType::Sphere;
  sphere.radius = 0.3;
  EXPECT_NEAR(inertiaOf(ball, 2)[0], inertiaOf(sphere, 2)[0], 1e-15);
}

TEST(Inertia, StaticAndPlaneAreZero) {
  Shape box;
  box.type = ShapeType::Box;
  box.size = {1, 1, 1};
  EXPECT_EQ(inertiaOf(box, 0), (Vec3{0, 0, 0}));
  Shape plane;
  plane.type = ShapeType::Plane;
  EXPECT_EQ(inertiaOf(plane, 1), (Vec3{0, 0, 0}));
}

TEST(Inertia, LoaderFillsItFromShapeAndMass) {
  const Scene s = load("resting_box");
  const Body& box = s.bodies[s.findBody("box")];
  for (double i : box.inertia) EXPECT_DOUBLE_EQ(i, 1.0 / 6);
}

// ---------------------------------------------------------------------------------------------
// Parsing: defaults, orientations, generators

std::string withBodies(const std::string& bodies, const std::string& extra = "") {
  return R"({"format": "mlcp-scene/1", )" + extra + R"("bodies": [)" + bodies + "]}";
}

const char* kBox = R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1})";

TEST(SceneParse, DefaultsAreTheDocumentedOnes) {
  const Scene s = parseScene(withBodies(kBox), "dir/my_scene.json");
  EXPECT_EQ(s.name, "my_scene");
  EXPECT_EQ(s.source, "dir/my_scene.json");
  EXPECT_EQ(s.gravity, (Vec3{0, 0, -9.81}));
  EXPECT_DOUBLE_EQ(s.settings.timeStep, 1.0 / 60);
  EXPECT_EQ(s.settings.steps, 600);
  EXPECT_DOUBLE_EQ(s.settings.erp, 0.2);
  EXPECT_DOUBLE_EQ(s.settings.cfm, 1e-5);
  EXPECT_FALSE(s.settings.sleeping);
  EXPECT_EQ(s.settings.maxContactsPerPair, 4);
  EXPECT_EQ(s.solver.name, "auto");
  EXPECT_EQ(s.solver.iterations, 50);
  EXPECT_DOUBLE_EQ(s.solver.tolerance, 1e-6);
  EXPECT_TRUE(s.solver.warmStart);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_DOUBLE_EQ(s.materials[0].friction, 0.5);
  EXPECT_DOUBLE_EQ(s.materials[0].restitution, 0);
  const Body& b = s.bodies[0];
  EXPECT_EQ(b.position, (Vec3{0, 0, 0}));
  EXPECT_DOUBLE_EQ(b.orientation.w, 1);
  EXPECT_EQ(b.material, 0);
}

TEST(SceneParse, SettingsSolverMaterialsAndGravity) {
  const Scene s = parseScene(withBodies(
      R"({"name": "b", "shape": {"type": "sphere", "radius": 0.5}, "mass": 2, "material": "ice",
          "velocity": [1, 2, 3], "angular_velocity": [0, 0, 4]})",
      R"("gravity": [0, -9.81, 0],
         "settings": {"time_step": 0.01, "steps": 7, "erp": 0.5, "cfm": 0, "sleeping": true,
                      "max_contacts_per_pair": 8},
         "solver": {"name": "dantzig", "iterations": 3, "tolerance": 1e-9, "warm_start": false},
         "materials": {"default": {"friction": 0.9}, "ice": {"friction": 0.01, "restitution": 0.5}},)"));
  EXPECT_EQ(s.gravity, (Vec3{0, -9.81, 0}));
  EXPECT_DOUBLE_EQ(s.settings.timeStep, 0.01);
  EXPECT_EQ(s.settings.steps, 7);
  EXPECT_DOUBLE_EQ(s.settings.erp, 0.5);
  EXPECT_DOUBLE_EQ(s.settings.cfm, 0);
  EXPECT_TRUE(s.settings.sleeping);
  EXPECT_EQ(s.settings.maxContactsPerPair, 8);
  EXPECT_EQ(s.solver.name, "dantzig");
  EXPECT_EQ(s.solver.iterations, 3);
  EXPECT_DOUBLE_EQ(s.solver.tolerance, 1e-9);
  EXPECT_FALSE(s.solver.warmStart);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_DOUBLE_EQ(s.materials[0].friction, 0.9);
  const Material& ice = s.materials[s.bodies[0].material];
  EXPECT_EQ(ice.name, "ice");
  EXPECT_DOUBLE_EQ(combinedFriction(ice, s.materials[0]), std::sqrt(0.01 * 0.9));
  EXPECT_DOUBLE_EQ(combinedRestitution(ice, s.materials[0]), 0.5);
  EXPECT_EQ(s.bodies[0].velocity, (Vec3{1, 2, 3}));
  EXPECT_EQ(s.bodies[0].angularVelocity, (Vec3{0, 0, 4}));
}

TEST(SceneParse, OrientationsAsQuaternionOrAxisAngle) {
  const Scene s = parseScene(withBodies(
      R"({"name": "q", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1,
          "orientation": [0.70710678, 0, 0, 0.70710678]},
         {"name": "d", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1,
          "orientation": {"axis": [0, 0, 2], "degrees": 90}},
         {"name": "r", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1,
          "orientation": {"axis": [0, 0, 1], "radians": 1.5707963267948966}})"));
  for (const Body& b : s.bodies) {
    const Vec3 x = rotate(b.orientation, {1, 0, 0});
    EXPECT_NEAR(x[0], 0, 1e-12) << b.name;
    EXPECT_NEAR(x[1], 1, 1e-12) << b.name;
    EXPECT_NEAR(x[2], 0, 1e-12) << b.name;
    const Quat& q = b.orientation;
    EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1, 1e-15) << b.name;
  }
}

TEST(SceneParse, StackGenerator) {
  const Scene s = parseScene(withBodies(
      R"({"generator": "stack", "name": "s", "count": 3, "gap": 0.1, "mass_factor": 2,
          "position": [1, 2, 3], "body": {"shape": {"type": "capsule", "radius": 0.5,
          "length": 1}, "mass": 1.5}})"));
  ASSERT_EQ(s.bodies.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Body& b = s.bodies[i];
    EXPECT_EQ(b.name, "s." + std::to_string(i));
    EXPECT_DOUBLE_EQ(b.mass, 1.5 * std::pow(2, i));
    EXPECT_DOUBLE_EQ(b.position[0], 1);
    EXPECT_DOUBLE_EQ(b.position[1], 2);
    EXPECT_DOUBLE_EQ(b.position[2], 3 + 1 + i * 2.1);  // total height 2, gap 0.1
    EXPECT_EQ(b.inertia, inertiaOf(b.shape, b.mass));
  }
}

TEST(SceneParse, PyramidGenerator2dAnd3d) {
  const Scene wall = parseScene(withBodies(
      R"({"generator": "pyramid", "name": "p", "base": 3, "gap": 0.5, "position": [0, 0, 1],
          "body": {"shape": {"type": "box", "size": [1, 2, 0.5]}, "mass": 1}})"));
  ASSERT_EQ(wall.bodies.size(), 6u);
  const double expect[6][3] = {{-1.5, 0, 1.25},  {0, 0, 1.25},    {1.5, 0, 1.25},
                               {-0.75, 0, 1.75}, {0.75, 0, 1.75}, {0, 0, 2.25}};
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(wall.bodies[i].position[k], expect[i][k]) << i;

  const Scene square = parseScene(withBodies(
      R"({"generator": "pyramid", "name": "p", "base": 4, "dimensions": 3,
          "body": {"shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1}})"));
  ASSERT_EQ(square.bodies.size(), 16u + 9 + 4 + 1);
  EXPECT_DOUBLE_EQ(square.bodies.back().position[2], 3.5);
  EXPECT_DOUBLE_EQ(square.bodies[0].position[0], -1.5);
  EXPECT_DOUBLE_EQ(square.bodies[0].position[1], -1.5);
  EXPECT_DOUBLE_EQ(square.bodies[16].position[0], -1.0);  // second layer sits on the corners
}

TEST(SceneParse, GridGeneratorCopiesTheTemplate) {
  const Scene s = parseScene(withBodies(
      R"({"generator": "grid", "name": "g", "count": [2, 3, 4], "spacing": [1, 2, 3],
          "position": [10, 20, 30],
          "body": {"shape": {"type": "sphere", "radius": 0.1}, "mass": 2, "material": "m",
                   "orientation": {"axis": [1, 0, 0], "degrees": 30}, "velocity": [0, 0, -1]}})",
      R"("materials": {"m": {"friction": 0.2}},)"));
  ASSERT_EQ(s.bodies.size(), 24u);
  const Body& b = s.bodies[1 + 2 * (2 + 3 * 3)];  // i = 1, j = 2, k = 3
  EXPECT_EQ(b.name, "g." + std::to_string(1 + 2 * (2 + 3 * 3)));
  EXPECT_EQ(b.position, (Vec3{11, 24, 39}));
  EXPECT_EQ(s.materials[b.material].name, "m");
  EXPECT_EQ(b.velocity, (Vec3{0, 0, -1}));
  EXPECT_NEAR(b.orientation.w, std::cos(kPi / 12), 1e-15);
}

TEST(SceneParse, JointsResolveNamesAndDefaults) {
  const Scene s = parseScene(withBodies(
      R"({"name": "ground", "shape": {"type": "plane"}},
         {"generator": "stack", "name": "s", "count": 2,
          "body": {"shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1}})",
      R"("joints": [
         {"type": "hinge", "bodies": ["s.1", "s.0"], "anchor": [0, 0, 1], "axis": [0, 3, 0],
          "limits": {"lower": -1, "upper": 1}, "motor": {"velocity": 2, "max_force": 5},
          "collide_connected": true},
         {"name": "rail", "type": "slider", "bodies": ["s.0"], "axis": [1, 0, 0]},
         {"type": "fixed", "bodies": ["s.0", "s.1"]},
         {"type": "ball", "bodies": ["s.1"], "anchor": [0, 0, 2]}],)"));
  ASSERT_EQ(s.joints.size(), 4u);
  const Joint& h = s.joints[0];
  EXPECT_EQ(h.name, "joints[0]");
  EXPECT_EQ(h.type, JointType::Hinge);
  EXPECT_EQ(h.body0, 2);
  EXPECT_EQ(h.body1, 1);
  EXPECT_EQ(h.axis, (Vec3{0, 1, 0}));
  EXPECT_TRUE(h.limits.enabled && h.motor.enabled && h.collideConnected);
  EXPECT_DOUBLE_EQ(h.motor.maxForce, 5);
  const Joint& rail = s.joints[1];
  EXPECT_EQ(rail.name, "rail");
  EXPECT_EQ(rail.body1, -1);
  EXPECT_EQ(rail.anchor, s.bodies[1].position);
  EXPECT_FALSE(rail.limits.enabled || rail.motor.enabled || rail.collideConnected);
  EXPECT_EQ(s.joints[2].type, JointType::Fixed);
  EXPECT_EQ(s.joints[3].type, JointType::Ball);
  EXPECT_STREQ(toString(JointType::Slider), "slider");
  EXPECT_STREQ(toString(ShapeType::Capsule), "capsule");
}

// ---------------------------------------------------------------------------------------------
// Bad files: the message names the source, the JSON path and what is wrong.

void expectError(const std::string& text, const std::vector<std::string>& parts) {
  try {
    parseScene(text, "bad.json");
    ADD_FAILURE() << "no error for " << text;
  } catch (const FormatError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("bad.json: ", 0), 0u) << what;
    for (const std::string& p : parts) EXPECT_NE(what.find(p), std::string::npos) << what;
  }
}

const char* kPlane = R"({"name": "ground", "shape": {"type": "plane"}})";

TEST(SceneErrors, MalformedJson) {
  expectError(R"({"format": "mlcp-scene/1", "bodies": [)", {"not valid JSON", "line 1"});
  expectError("[1, 2]", {"top level: expected an object, got [1,2]"});
}

TEST(SceneErrors, FormatTag) {
  expectError(R"({"bodies": []})", {"top level: missing field \"format\""});
  expectError(R"({"format": "mlcp-scene/2", "bodies": []})",
              {"format: expected \"mlcp-scene/1\", got \"mlcp-scene/2\""});
}

TEST(SceneErrors, WrongTypes) {
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]},
                             "mass": "heavy"})"),
              {"bodies[0].mass: expected a number, got \"heavy\""});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1]}, "mass": 1})"),
              {"bodies[0].shape.size: expected 3 positive numbers, got [1,1]"});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, -1, 1]},
                             "mass": 1})"),
              {"bodies[0].shape.size: expected 3 positive numbers"});
  expectError(withBodies(kBox, R"("settings": {"steps": 2.5},)"),
              {"settings.steps: expected an integer"});
  expectError(withBodies(kBox, R"("gravity": [0, 0],)"), {"gravity: expected 3 numbers"});
  expectError(withBodies(kBox, R"("settings": {"sleeping": "no"},)"),
              {"settings.sleeping: expected true or false"});
  expectError(withBodies(kBox, R"("joints": {},)"), {"joints: expected an array"});
}

TEST(SceneErrors, MissingFields) {
  expectError(R"({"format": "mlcp-scene/1"})", {"top level: missing field \"bodies\""});
  expectError(withBodies(R"({"name": "b", "mass": 1})"), {"bodies[0]: missing field \"shape\""});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "sphere"}, "mass": 1})"),
              {"bodies[0].shape: missing field \"radius\""});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}})"),
              {"bodies[0]: missing field \"mass\""});
  expectError(withBodies(kBox, R"("joints": [{"type": "hinge", "bodies": ["b"],
                                               "anchor": [0, 0, 0]}],)"),
              {"joints[0]: missing field \"axis\""});
  expectError(withBodies(""), {"bodies: a scene needs at least one body"});
  expectError(withBodies(kPlane), {"bodies: a scene needs at least one dynamic body"});
}

TEST(SceneErrors, NegativeOrOutOfRangeNumbers) {
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]},
                             "mass": -1})"),
              {"bodies[0].mass: expected a number >= 0, got -1"});
  expectError(withBodies(kBox, R"("materials": {"m": {"friction": -0.1}},)"),
              {"materials.m.friction: expected a number >= 0"});
  expectError(withBodies(kBox, R"("materials": {"m": {"restitution": 2}},)"),
              {"materials.m.restitution: expected a number in [0, 1]"});
  expectError(withBodies(kBox, R"("settings": {"time_step": 0},)"),
              {"settings.time_step: expected a positive number"});
  expectError(withBodies(kBox, R"("joints": [{"type": "hinge", "bodies": ["b"],
      "anchor": [0, 0, 0], "axis": [0, 0, 1], "limits": {"lower": 1, "upper": -1}}],)"),
              {"joints[0].limits: lower (1) is above upper (-1)"});
  expectError(withBodies(kBox, R"("joints": [{"type": "slider", "bodies": ["b"],
      "axis": [0, 0, 0]}],)"),
              {"joints[0].axis: expected a direction"});
}

TEST(SceneErrors, UnknownNames) {
  expectError(withBodies(R"({"name": "b", "shape": {"type": "cone"}, "mass": 1})"),
              {"bodies[0].shape.type: unknown shape \"cone\"",
               "plane, box, sphere, capsule, cylinder, convex_hull"});
  expectError(withBodies(kBox, R"("joints": [{"type": "ball", "bodies": ["b", "nobody"],
                                               "anchor": [0, 0, 0]}],)"),
              {"joints[0].bodies[1]: no body named \"nobody\""});
  expectError(withBodies(kBox, R"("joints": [{"type": "weld", "bodies": ["b"]}],)"),
              {"joints[0].type: unknown joint type \"weld\""});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]},
                             "mass": 1, "material": "steel"})"),
              {"bodies[0].material: no material named \"steel\""});
  expectError(withBodies(R"({"generator": "tower", "name": "t", "body": {"shape":
                             {"type": "box", "size": [1, 1, 1]}, "mass": 1}})"),
              {"bodies[0].generator: unknown generator \"tower\""});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]},
                             "mass": 1, "frction": 0.5})"),
              {"bodies[0]: unknown field \"frction\""});
}

TEST(SceneErrors, InconsistentBodiesAndJoints) {
  expectError(withBodies(std::string(kBox) + ", " + kBox),
              {"bodies[1]: body name \"b\" is already used by bodies[0]"});
  expectError(withBodies(std::string(kBox) + R"(, {"generator": "stack", "name": "b", "count": 2,
      "body": {"shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1}}, {"name": "b.1",
      "shape": {"type": "sphere", "radius": 1}, "mass": 1})"),
              {"bodies[2]: body name \"b.1\" is already used by bodies[1]"});
  expectError(withBodies(std::string(kPlane) + ", " + kBox,
                         R"("joints": [{"type": "ball", "bodies": ["b", "ground"],
                                        "anchor": [0, 0, 0]}],)"),
              {"joints[0].bodies[1]: body \"ground\" is static"});
  expectError(withBodies(kBox, R"("joints": [{"type": "ball", "bodies": ["b", "b"],
                                               "anchor": [0, 0, 0]}],)"),
              {"joints[0].bodies: a joint needs two different bodies"});
  expectError(withBodies(kBox, R"("joints": [{"type": "ball", "bodies": [],
                                               "anchor": [0, 0, 0]}],)"),
              {"joints[0].bodies: expected 1 body name"});
  expectError(withBodies(kBox, R"("joints": [{"type": "ball", "bodies": ["b"],
                                               "anchor": [0, 0, 0], "axis": [1, 0, 0]}],)"),
              {"joints[0]: unknown field \"axis\""});
  expectError(withBodies(R"({"name": "g", "shape": {"type": "plane"}, "mass": 3})"),
              {"bodies[0].mass: a plane is static"});
  expectError(withBodies(R"({"name": "g", "shape": {"type": "plane"}, "position": [0, 0, 1]})"),
              {"bodies[0].position: not allowed"});
  expectError(withBodies(R"({"name": "w", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 0,
                             "velocity": [1, 0, 0]})"),
              {"bodies[0]: a static body (mass 0) cannot have a velocity"});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1,
                             "orientation": [1, 0, 1, 0]})"),
              {"bodies[0].orientation: quaternion [w, x, y, z] must have length 1"});
  expectError(withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1,
                             "orientation": {"axis": [1, 0, 0]}})"),
              {"bodies[0].orientation: give exactly one of \"degrees\" or \"radians\""});
}

TEST(SceneErrors, BadGenerators) {
  const char* tmpl = R"("body": {"shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1})";
  expectError(
      withBodies(R"({"generator": "stack", "name": "s", "count": 0, )" + std::string(tmpl) + "}"),
      {"bodies[0].count: expected an integer in [1, "});
  expectError(withBodies(R"({"generator": "pyramid", "name": "p", "base": 3, "body": {"shape":
                             {"type": "sphere", "radius": 1}, "mass": 1}})"),
              {"bodies[0].body.shape: a pyramid is made of boxes"});
  expectError(withBodies(R"({"generator": "stack", "name": "s", "count": 2, "body": {"name": "x",
                             "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1}})"),
              {"bodies[0].body.name: not allowed"});
  expectError(withBodies(R"({"generator": "stack", "name": "s", "count": 2, "body": {"shape":
                             {"type": "box", "size": [1, 1, 1]}, "mass": 1,
                             "orientation": [1, 0, 0, 0]}})"),
              {"bodies[0].body.orientation: not allowed"});
  expectError(withBodies(R"({"generator": "grid", "name": "g", "count": [2, 2], "spacing":
                             [1, 1, 1], )" +
                         std::string(tmpl) + "}"),
              {"bodies[0].count: expected 3 integers"});
  expectError(withBodies(R"({"generator": "grid", "name": "g", "count": [2, 2, 2], "spacing":
                             [1, 1, 1], "body": {"shape": {"type": "box", "size": [1, 1, 1]},
                             "mass": 0}})"),
              {"bodies[0].body.mass: a generator's bodies must be dynamic"});
  expectError(withBodies(R"({"generator": "grid", "name": "g", "count": [1000, 1000, 1000],
                             "spacing": [1, 1, 1], )" +
                         std::string(tmpl) + "}"),
              {"bodies[0].count: too many bodies"});
}

TEST(SceneErrors, FilesNameThemselves) {
  EXPECT_THROW(
      {
        try {
          loadScene("/nonexistent/scene.json");
        } catch (const FormatError& e) {
          EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.json: cannot open"),
                    std::string::npos);
          throw;
        }
      },
      FormatError);
  const auto path = std::filesystem::temp_directory_path() /
                    ("mlcp_scene_test_bad_" + std::to_string(::getpid()) + ".json");
  {
    std::ofstream out(path);
    out << withBodies(R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]},
                          "mass": -2})");
  }
  try {
    loadScene(path.string());
    ADD_FAILURE() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": bodies[0].mass: ", 0), 0u) << e.what();
  }
  std::filesystem::remove(path);
}

// ---------------------------------------------------------------------------------------------
// Cylinders, convex hulls and the joints of real programs (cone-twist, 6-dof, universal,
// hinge-2, gear).

TEST(ConvexHull, CubeCornersGiveTheBoxAndItsInertia) {
  std::vector<Vec3> corners;
  for (double x : {-1.0, 1.0})
    for (double y : {-0.5, 0.5})
      for (double z : {-1.5, 1.5}) corners.push_back({x + 3, y, z});  // centred at (3, 0, 0)
  const ConvexHull h = convexHullOf(corners);
  EXPECT_EQ(h.faces.size(), 6u);
  for (const auto& f : h.faces) EXPECT_EQ(f.size(), 4u);
  EXPECT_NEAR(h.volume, 2 * 1 * 3, 1e-12);
  EXPECT_NEAR(h.centroid[0], 3, 1e-12);
  Shape box;
  box.type = ShapeType::Box;
  box.size = {2, 1, 3};
  const Vec3 ib = inertiaOf(box, 1);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(h.inertiaPerKg[a], ib[a], 1e-12);
  for (int a = 3; a < 6; ++a) EXPECT_NEAR(h.inertiaPerKg[a], 0, 1e-12);
  // Faces run counter-clockwise seen from outside: (p1 - p0) x (p2 - p0) along the normal.
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const auto& v = h.faces[f];
    const Vec3 n = cross(sub(h.points[v[1]], h.points[v[0]]), sub(h.points[v[2]], h.points[v[0]]));
    EXPECT_GT(dot(n, h.normals[f]), 0);
  }
}

// A regular tetrahedron of edge a: volume a^3 / (6 sqrt 2), inertia m a^2 / 20 about any axis
// through its centroid.
TEST(ConvexHull, TetrahedronMatchesItsClosedForm) {
  const double a = 2 * std::sqrt(2.0);  // corners of alternate cube vertices (+-1)
  const ConvexHull h = convexHullOf({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}});
  EXPECT_EQ(h.faces.size(), 4u);
  EXPECT_NEAR(h.volume, a * a * a / (6 * std::sqrt(2.0)), 1e-12);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(h.inertiaPerKg[i], a * a / 20, 1e-12);
}

TEST(ConvexHull, BadPointSetsAreRefused) {
  EXPECT_THROW(convexHullOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}), std::invalid_argument);
  EXPECT_THROW(convexHullOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}), std::invalid_argument);
  EXPECT_THROW(convexHullOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}}),
               std::invalid_argument);
  // The centre of a face of the tetrahedron is no corner.
  try {
    convexHullOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 0}});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 4 is not a corner"), std::string::npos) << e.what();
  }
}

TEST(Inertia, CylinderMatchesIntegration) {
  Shape cyl;
  cyl.type = ShapeType::Cylinder;
  cyl.radius = 0.3;
  cyl.length = 0.2;
  const Vec3 expect = sliceInertia([](double) { return 0.3; }, -0.1, 0.1, 10.0);
  const Vec3 got = inertiaOf(cyl, 10.0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expect[i], 1e-6 * expect[i]);
}

TEST(SceneParse, HullsAreCentredOnTheirCentroid) {
  // A square pyramid (base 2 x 2 at z = 0, apex at z = 3): centroid at z = 3/4.
  const Scene s = parseScene(withBodies(R"({"name": "p", "mass": 2, "position": [0, 0, 5],
      "shape": {"type": "convex_hull", "points": [[1, 1, 0], [1, -1, 0], [-1, 1, 0], [-1, -1, 0],
                                                  [0, 0, 3]]}})"));
  const Body& p = s.bodies[0];
  EXPECT_EQ(p.shape.hullFaces.size(), 5u);
  EXPECT_NEAR(p.shape.hullPoints[4][2], 3 - 0.75, 1e-12);
  // About the centroid: I_zz = m (a^2 + b^2) / 20 = m 8 / 20 for a base 2 x 2 (a = b = 2).
  EXPECT_NEAR(p.inertia[2], 2 * 8.0 / 20, 1e-12);
  // A stack rests hulls on their lowest corners, not at their centroid's half height: a
  // frustum (2 x 2 base, 1 x 1 top, 1 high) has its centroid below mid-height.
  const Scene st = parseScene(withBodies(R"({"generator": "stack", "name": "p", "count": 2,
      "body": {"mass": 1, "shape": {"type": "convex_hull", "points": [[1, 1, 0], [1, -1, 0],
               [-1, 1, 0], [-1, -1, 0], [0.5, 0.5, 1], [0.5, -0.5, 1], [-0.5, 0.5, 1],
               [-0.5, -0.5, 1]]}}})"));
  EXPECT_LT(st.bodies[0].position[2], 0.5);
  for (const Body& b : st.bodies) {
    double low = 1e300;
    for (const Vec3& q : b.shape.hullPoints) low = std::min(low, q[2] + b.position[2]);
    EXPECT_NEAR(low, &b == &st.bodies[0] ? 0 : 1, 1e-12) << b.name;
  }
}

TEST(SceneParse, NewJointsTakeTheirFields) {
  const std::string two = std::string(kBox) + "," +
                          R"({"name": "c", "shape": {"type": "box", "size": [1, 1, 1]},
                               "mass": 1, "position": [3, 0, 0]})";
  const Scene s = parseScene(withBodies(two, R"("joints": [
      {"type": "cone_twist", "bodies": ["c", "b"], "anchor": [1.5, 0, 0], "axis": [1, 0, 0],
       "cone": {"swing1": 0.5, "twist": 0.2}},
      {"type": "six_dof", "bodies": ["c"], "linear": ["free", {"lower": -1e30, "upper": 1e30},
       {"spring": {"stiffness": 10}}], "angular": ["locked", "free", "locked"]},
      {"type": "universal", "bodies": ["c", "b"], "anchor": [1.5, 0, 0], "axis": [0, 1, 0],
       "axis2": [0, 0, 1]},
      {"type": "hinge2", "bodies": ["b", "c"], "anchor": [3, 0, 0], "axis": [0, 0, 1],
       "axis2": [0, 1, 0], "suspension": {"stiffness": 1000, "damping": 10}},
      {"type": "gear", "bodies": ["b", "c"], "axis": [0, 0, 1], "ratio": 3}],)"));
  ASSERT_EQ(s.joints.size(), 5u);
  const Joint& cone = s.joints[0];
  EXPECT_EQ(cone.type, JointType::ConeTwist);
  EXPECT_DOUBLE_EQ(cone.cone.swing2, 0.5);  // defaults to swing1
  EXPECT_NEAR(dot(cone.normal, cone.axis), 0, 1e-15);
  const Joint& six = s.joints[1];
  EXPECT_EQ(six.dofs[0].mode, AxisDof::Mode::Free);
  EXPECT_EQ(six.dofs[1].mode, AxisDof::Mode::Limited);
  EXPECT_DOUBLE_EQ(six.dofs[1].upper, 1e30);
  EXPECT_EQ(six.dofs[2].mode, AxisDof::Mode::Free);
  EXPECT_TRUE(six.dofs[2].spring.enabled);
  EXPECT_EQ(six.dofs[3].mode, AxisDof::Mode::Locked);
  EXPECT_EQ(six.dofs[4].mode, AxisDof::Mode::Free);
  EXPECT_EQ(six.anchor, (Vec3{3, 0, 0}));  // bodies[0]'s position
  EXPECT_EQ(s.joints[2].axis2, (Vec3{0, 0, 1}));
  const Joint& h2 = s.joints[3];
  EXPECT_TRUE(h2.limits.enabled);  // steering locked at 0 by default
  EXPECT_EQ(h2.limits.lower, 0);
  EXPECT_EQ(h2.limits.upper, 0);
  EXPECT_DOUBLE_EQ(h2.suspension.stiffness, 1000);
  const Joint& gear = s.joints[4];
  EXPECT_DOUBLE_EQ(gear.ratio, 3);
  EXPECT_EQ(gear.axis2, gear.axis);
  EXPECT_EQ(gear.anchor, (Vec3{0, 0, 0}));
  EXPECT_EQ(gear.anchor2, (Vec3{3, 0, 0}));
  EXPECT_STREQ(toString(JointType::Hinge2), "hinge2");
  EXPECT_STREQ(toString(ShapeType::ConvexHull), "convex_hull");
}

TEST(SceneErrors, NewShapesAndJoints) {
  const std::string two = std::string(kBox) + "," +
                          R"({"name": "c", "shape": {"type": "box", "size": [1, 1, 1]},
                               "mass": 1, "position": [3, 0, 0]})";
  auto joints = [&](const std::string& j) { return withBodies(two, "\"joints\": [" + j + "],"); };
  expectError(withBodies(R"({"name": "h", "mass": 1, "shape": {"type": "convex_hull",
      "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]}})"),
              {"bodies[0].shape.points: the points lie in one plane"});
  expectError(withBodies(R"({"name": "h", "mass": 1, "shape": {"type": "convex_hull",
      "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]}})"),
              {"bodies[0].shape.points: the hull's products of inertia are not 0"});
  expectError(withBodies(R"({"name": "c", "mass": 1, "shape": {"type": "cylinder", "radius": 1,
      "length": 0}})"),
              {"bodies[0].shape.length: expected a positive number"});
  expectError(joints(R"({"type": "hinge2", "bodies": ["b"], "anchor": [0, 0, 0],
      "axis": [0, 0, 1], "axis2": [0, 1, 0]})"),
              {"joints[0].bodies: a hinge2 joint joins two bodies"});
  expectError(joints(R"({"type": "universal", "bodies": ["b", "c"], "anchor": [0, 0, 0],
      "axis": [0, 0, 1], "axis2": [0, 1, 1]})"),
              {"joints[0].axis2: must be perpendicular to \"axis\""});
  expectError(
      joints(R"({"type": "six_dof", "bodies": ["b"], "linear": ["loose", "free", "free"]})"),
      {"joints[0].linear[0]: expected \"locked\", \"free\""});
  expectError(joints(R"({"type": "six_dof", "bodies": ["b"], "angular": [{"lower": 1}, "free",
      "free"]})"),
              {"joints[0].angular[0]: give both \"lower\" and \"upper\" or neither"});
  expectError(joints(R"({"type": "cone_twist", "bodies": ["b"], "anchor": [0, 0, 0],
      "axis": [1, 0, 0], "cone": {"swing1": 4, "twist": 0}})"),
              {"joints[0].cone.swing1: expected a number in"});
  expectError(joints(R"({"type": "gear", "bodies": ["b", "c"], "axis": [0, 0, 1], "ratio": 1,
      "anchor": [3, 0, 0]})"),
              {"joints[0]: a gear pair needs two different centres"});
  expectError(joints(R"({"type": "gear", "bodies": ["b", "c"], "axis": [0, 0, 1],
      "limits": {"lower": 0, "upper": 1}, "ratio": 1})"),
              {"joints[0]: unknown field \"limits\""});
}

TEST(SceneParse, FrictionModelOfTheRunSettings) {
  const std::string box =
      R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1})";
  Scene s = parseScene(withBodies(box));
  EXPECT_EQ(s.solver.friction, mlcp::FrictionModel::Box);
  EXPECT_EQ(s.solver.frictionDirections, 4);
  s = parseScene(withBodies(box, R"("solver": {"friction": "cone", "friction_directions": 8},)"));
  EXPECT_EQ(s.solver.friction, mlcp::FrictionModel::Cone);
  EXPECT_EQ(s.solver.frictionDirections, 8);
  const RunSettings run = RunSettings::fromScene(s);
  EXPECT_EQ(run.friction, mlcp::FrictionModel::Cone);
  EXPECT_EQ(run.frictionDirections, 8);
}

TEST(SceneErrors, FrictionModelAndDirections) {
  const std::string box =
      R"({"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1})";
  expectError(withBodies(box, R"("solver": {"friction": "pyramid"},)"),
              {"solver.friction", "must be \"box\" or \"cone\""});
  expectError(withBodies(box, R"("solver": {"friction_directions": 2},)"),
              {"solver.friction_directions"});
  expectError(withBodies(box, R"("solver": {"friction_directions": 65},)"),
              {"solver.friction_directions"});
}

}  // namespace
