// Convex hull of a few points and its mass properties (see convex_hull.hpp).
#include "mlcp/scene/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mlcp::scene {

namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Largest extent of the points along a coordinate axis.
double sizeOf(const std::vector<Vec3>& p) {
  double size = 0;
  for (int a = 0; a < 3; ++a) {
    auto [lo, hi] = std::minmax_element(p.begin(), p.end(),
                                        [a](const Vec3& u, const Vec3& v) { return u[a] < v[a]; });
    size = std::max(size, (*hi)[a] - (*lo)[a]);
  }
  return size;
}

// Every distinct plane through three points with all points on its inner side.
void findFacePlanes(ConvexHull& h, double eps) {
  const std::vector<Vec3>& p = h.points;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3 normal = cross(sub(p[j], p[i]), sub(p[k], p[i]));
        const double len = norm(normal);
        if (len < eps * eps * 1e3) continue;  // collinear
        normal = {normal[0] / len, normal[1] / len, normal[2] / len};
        double offset = dot(normal, p[i]);
        bool above = false, below = false;
        for (const Vec3& q : p) {
          const double d = dot(normal, q) - offset;
          above = above || d > eps;
          below = below || d < -eps;
        }
        if (above && below) continue;
        if (above) normal = {-normal[0], -normal[1], -normal[2]}, offset = -offset;
        const bool known = std::any_of(h.normals.begin(), h.normals.end(),
                                       [&](const Vec3& m) { return norm(sub(m, normal)) < 1e-9; });
        if (known) continue;
        h.normals.push_back(normal);
        h.offsets.push_back(offset);
      }
}

// The points on each face plane, counter-clockwise about its outward normal.
void collectFaces(ConvexHull& h, double eps) {
  std::vector<int> planesThrough(h.points.size(), 0);
  for (std::size_t f = 0; f < h.normals.size(); ++f) {
    const Vec3& nf = h.normals[f];
    std::vector<int> face;
    Vec3 c{0, 0, 0};
    for (std::size_t i = 0; i < h.points.size(); ++i)
      if (std::abs(dot(nf, h.points[i]) - h.offsets[f]) <= eps) {
        face.push_back(int(i));
        ++planesThrough[i];
        for (int a = 0; a < 3; ++a) c[a] += h.points[i][a];
      }
    for (double& v : c) v /= double(face.size());
    const Vec3 u = sub(h.points[face[0]], c);
    const Vec3 w = cross(nf, u);
    auto angle = [&](int i) {
      const Vec3 d = sub(h.points[i], c);
      return std::atan2(dot(d, w), dot(d, u));
    };
    std::sort(face.begin(), face.end(), [&](int a, int b) { return angle(a) < angle(b); });
    h.faces.push_back(std::move(face));
  }
  for (std::size_t i = 0; i < h.points.size(); ++i)
    if (planesThrough[i] < 3)
      throw std::invalid_argument("point " + std::to_string(i) +
                                  " is not a corner of the hull (it lies inside, on a face or on "
                                  "an edge): list corners only");
}

void massProperties(ConvexHull& h) {
  Vec3 inside{0, 0, 0};
  for (const Vec3& q : h.points)
    for (int a = 0; a < 3; ++a) inside[a] += q[a] / double(h.points.size());
  double volume = 0;
  Vec3 first{0, 0, 0};
  double second[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  for (const std::vector<int>& face : h.faces)
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      const Vec3 v[4] = {inside, h.points[face[0]], h.points[face[k]], h.points[face[k + 1]]};
      const double vol =
          dot(sub(v[1], v[0]), cross(sub(v[2], v[0]), sub(v[3], v[0]))) / 6;  // > 0: outward
      Vec3 s{0, 0, 0};
      for (const Vec3& q : v)
        for (int a = 0; a < 3; ++a) s[a] += q[a];
      volume += vol;
      for (int a = 0; a < 3; ++a) first[a] += vol * s[a] / 4;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          double vv = s[a] * s[b];
          for (const Vec3& q : v) vv += q[a] * q[b];
          second[a][b] += vol / 20 * vv;
        }
    }
  h.volume = volume;
  for (int a = 0; a < 3; ++a) h.centroid[a] = first[a] / volume;
  double c[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      c[a][b] = (second[a][b] - volume * h.centroid[a] * h.centroid[b]) / volume;
  const double trace = c[0][0] + c[1][1] + c[2][2];
  h.inertiaPerKg = {trace - c[0][0], trace - c[1][1], trace - c[2][2],
                    -c[0][1],        -c[0][2],        -c[1][2]};
}

}  // namespace

ConvexHull convexHullOf(const std::vector<Vec3>& points) {
  if (points.size() < 4 || points.size() > std::size_t(kMaxHullPoints))
    throw std::invalid_argument("a convex hull needs 4 to " + std::to_string(kMaxHullPoints) +
                                " points, got " + std::to_string(points.size()));
  ConvexHull h;
  h.points = points;
  const double size = sizeOf(points);
  const double eps = 1e-9 * std::max(size, 1e-300);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t j = i + 1; j < points.size(); ++j)
      if (norm(sub(points[i], points[j])) <= eps)
        throw std::invalid_argument("points " + std::to_string(i) + " and " + std::to_string(j) +
                                    " are the same point");
  findFacePlanes(h, eps);
  if (h.normals.size() < 4) throw std::invalid_argument("the points lie in one plane");
  collectFaces(h, eps);
  massProperties(h);
  return h;
}

}  // namespace mlcp::scene
