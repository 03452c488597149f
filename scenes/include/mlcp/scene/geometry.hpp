// mlcp/scene/geometry.hpp: the vectors, rotations and shapes of a scene (scene.hpp).
//
// Plain values in SI units, z up, quaternions (w, x, y, z) rotating body-frame vectors into the
// world. inertiaOf() is the one inertia the engine loaders hand to every engine, so Bullet, its
// multibody world and ODE see the same numbers (Bullet's own capsule inertia is a box
// approximation; ours is exact).
#pragma once

#include <array>
#include <vector>

namespace mlcp::scene {

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

}  // namespace mlcp::scene
