// mlcp/scene/convex_hull.hpp: the convex hull of a scene's `convex_hull` points, and its mass
// properties.
//
// A scene gives a hull by its corners only; ODE's dCreateConvex also needs the faces (planes
// and polygons) and both engines need the centre of mass and the inertia, so the scene loader
// computes them here, once, for both engines.
//
// Faces: every plane through three of the points that has all points on one side (within a
// tolerance of 1e-9 of the hull's size) is a face plane; its corners are the points on it,
// ordered counter-clockwise seen from outside. Every given point must be a corner (on at least
// three face planes): a point inside the hull, on a face or on an edge is an error, so that the
// file says exactly what the engines get. O(n^4) in the number of points n, which the format
// limits to kMaxHullPoints (64; docs/benchmarks.md, "Scenes: the convex hull of 64 points").
//
// Mass properties at uniform density: the solid is cut into tetrahedra (centroid of the
// corners, face corner 0, face corners k and k+1); each tetrahedron (v0..v3) has volume
// det[v1-v0, v2-v0, v3-v0] / 6 and second moment integral x x^T dV =
// V/20 (sum_i v_i v_i^T + (sum_i v_i)(sum_i v_i)^T); summed, moved to the centroid, and turned
// into the inertia tensor I = trace(C) 1 - C.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mlcp/scene/scene.hpp"

namespace mlcp::scene {

inline constexpr int kMaxHullPoints = 64;

struct ConvexHull {
  std::vector<Vec3> points;             // as given
  std::vector<std::vector<int>> faces;  // corner indices, counter-clockwise from outside
  std::vector<Vec3> normals;            // unit outward normal per face
  std::vector<double> offsets;          // per face: dot(normal, p) = offset on the face, m
  double volume = 0;                    // m^3
  Vec3 centroid{0, 0, 0};               // m
  // Inertia tensor per kg about the centroid in the points' axes, m^2:
  // xx, yy, zz, xy, xz, yz.
  std::array<double, 6> inertiaPerKg{0, 0, 0, 0, 0, 0};
};

// The hull of 4 to kMaxHullPoints points; throws std::invalid_argument saying what is wrong
// (too few or too many points, two equal points, all points in a plane, a point that is not a
// corner).
ConvexHull convexHullOf(const std::vector<Vec3>& points);

}  // namespace mlcp::scene
