// Contact scenes as physics engines hand them to an MLCP solver: factored constraint rows
// (rows.hpp) of box pyramids, with friction (findex), cfm and a time-step sequence.
//
// A pyramid of L levels has L boxes at the bottom, L - 1 above, ..., 1 at the top (L (L + 1) / 2
// boxes: 15 for L = 5, 55 for L = 10), unit cubes of mass 1 standing in a row along x with a
// small gap, each upper box resting on the two below it; a square pyramid (PyramidSpec::square)
// has L x L boxes at the bottom, each upper box on four below. Every touching face pair (a box and
// the ground, or a box and one below) gets 4 contact points at the corners of the overlap
// rectangle, and every contact gets three rows, as Bullet and ODE make them:
//
//     normal n = +z:     J_A = [ n; r_A x n],  J_B = [-n; -(r_B x n)],  x in [0, inf)
//     friction t = x, y: the same with t,                              x in [-mu, mu] x_normal
//
// (A the upper box, B the lower box or the world), mu drawn per contact from [muLo, muHi].
// A = J M^-1 J^T + cfm I, and b = J v_pre - erp depth / dt: v_pre is the velocity after one
// step of gravity (plus an optional random sideways velocity that makes contacts slide), and
// depth a small random penetration, as a Baumgarte term. Resting boxes need support: the
// ground contacts start with b = -g dt < 0.
//
// nextStep() perturbs b as the next time step would (the bodies' velocities change a little);
// solvers warm start from the previous answer.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "mlcp/rows.hpp"

namespace mlcp::test {

struct PyramidSpec {
  int levels = 5;          // boxes per bottom row; L (L + 1) / 2 boxes in all
  double dt = 1.0 / 60;    // time step, s
  double cfm = 1e-5 / dt;  // added to A's diagonal (engines: 1e-8 / dt .. 1e-5 / dt)
  double muLo = 0.5;       // friction coefficient range, drawn per contact
  double muHi = 0.8;
  double gap = 0.02;          // space between neighbouring boxes of one level, m
  double erp = 0.2;           // Baumgarte factor of the penetration term
  double maxDepth = 1e-3;     // penetration depths drawn from [0, maxDepth], m
  double sideVelocity = 0.0;  // random horizontal body velocities up to this, m/s (sliding)
  unsigned seed = 1;
  // Square levels (L x L boxes at the bottom, each upper box on the corners of four below, as
  // scenes/pyramid_1000.json) instead of rows along x: a body graph in three dimensions.
  bool square = false;
};

class BoxPyramid {
 public:
  explicit BoxPyramid(const PyramidSpec& spec) : spec_(spec), rng_(spec.seed) { build(); }

  const RowSystem& rows() const { return rows_; }
  int boxes() const { return static_cast<int>(rows_.bodies.size()); }

  // The next time step's b: every body's velocity before the solve changes by a random
  // 6-vector of size `noise` g dt, so b changes by J dv, in the range of J, as it does between
  // engine steps (independent noise per row would excite the directions only cfm holds).
  void nextStep(double noise = 0.01) {
    const double g = 9.81 * spec_.dt;
    std::vector<Vector6> dv(rows_.bodies.size());
    for (Vector6& v : dv)
      for (int k = 0; k < 6; ++k) v[k] = noise * g * uniform(-1, 1);
    for (int i = 0; i < rows_.size(); ++i) {
      const ConstraintRow& r = rows_.rows[i];
      rows_.b[i] = base_[i] + r.jA.dot(dv[r.bodyA]);
      if (r.bodyB >= 0) rows_.b[i] += r.jB.dot(dv[r.bodyB]);
    }
  }

 private:
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

  // Appends the three rows of one contact at point p between body a (above) and b (below).
  void contact(int a, int bBody, const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& c,
               const std::vector<Eigen::Vector3d>& vPre) {
    const double mu = uniform(spec_.muLo, spec_.muHi);
    const int normal = rows_.size();
    const Eigen::Vector3d dirs[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                     Eigen::Vector3d::UnitY()};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& d = dirs[k];
      ConstraintRow r;
      r.bodyA = a;
      r.bodyB = bBody;
      r.jA << d, (p - c[a]).cross(d);
      double relative = d.dot(vPre[a]);
      if (bBody >= 0) {
        r.jB << -d, -(p - c[bBody]).cross(d);
        relative -= d.dot(vPre[bBody]);
      }
      rows_.rows.push_back(r);
      base_.push_back(relative);
      if (k == 0) {
        lo_.push_back(0);
        hi_.push_back(kInf);
        findex_.push_back(-1);
      } else {
        lo_.push_back(-mu);
        hi_.push_back(mu);
        findex_.push_back(normal);
      }
    }
  }

  void build() {
    const int L = spec_.levels;
    const double pitch = 1.0 + spec_.gap, g = 9.81;
    std::vector<Eigen::Vector3d> centre, vPre;
    // level[l][i][j]: the box at column i, depth j (depth 0 only for rows along x).
    std::vector<std::vector<std::vector<int>>> level(L);
    for (int l = 0; l < L; ++l) {
      const int w = L - l, depth = spec_.square ? w : 1;
      level[l].assign(w, std::vector<int>(depth));
      for (int i = 0; i < w; ++i)
        for (int j = 0; j < depth; ++j) {
          level[l][i][j] = static_cast<int>(centre.size());
          centre.emplace_back((i - 0.5 * (w - 1)) * pitch, (j - 0.5 * (depth - 1)) * pitch,
                              0.5 + l);
          Eigen::Vector3d v(uniform(-1, 1), uniform(-1, 1), 0.0);
          vPre.push_back(spec_.sideVelocity * v + Eigen::Vector3d(0, 0, -g * spec_.dt));
        }
    }
    BodyInverseMass unit;
    unit.invMass = 1.0;
    unit.invInertia = 6.0 * Eigen::Matrix3d::Identity();  // unit cube, mass 1: I = 1/6
    rows_.bodies.assign(centre.size(), unit);
    // The four corners of the overlap of a's bottom face and b's top face (b < 0: the ground).
    auto face = [&](int a, int b, double z) {
      const Eigen::Vector3d& ca = centre[a];
      const Eigen::Vector3d cb = b >= 0 ? centre[b] : ca;
      const double x0 = std::max(ca.x(), cb.x()) - 0.5, x1 = std::min(ca.x(), cb.x()) + 0.5;
      const double y0 = std::max(ca.y(), cb.y()) - 0.5, y1 = std::min(ca.y(), cb.y()) + 0.5;
      for (double x : {x0, x1})
        for (double y : {y0, y1}) contact(a, b, Eigen::Vector3d(x, y, z), centre, vPre);
    };
    for (const auto& column : level[0])
      for (int a : column) face(a, -1, 0.0);
    const int below = spec_.square ? 2 : 1;  // supporting boxes per upper box along y
    for (int l = 1; l < L; ++l)
      for (size_t i = 0; i < level[l].size(); ++i)
        for (size_t j = 0; j < level[l][i].size(); ++j)
          for (int di = 0; di < 2; ++di)
            for (int dj = 0; dj < below; ++dj)
              face(level[l][i][j], level[l - 1][i + di][j + dj], static_cast<double>(l));
    const int n = static_cast<int>(rows_.rows.size());
    rows_.b = Eigen::Map<Vector>(base_.data(), n);
    rows_.lo = Eigen::Map<Vector>(lo_.data(), n);
    rows_.hi = Eigen::Map<Vector>(hi_.data(), n);
    rows_.cfm = Vector::Constant(n, spec_.cfm);
    rows_.findex = findex_;
    for (int i = 0; i < n; ++i)
      if (findex_[i] < 0) base_[i] -= spec_.erp * uniform(0, spec_.maxDepth) / spec_.dt;
    nextStep(0.0);
  }

  PyramidSpec spec_;
  std::mt19937 rng_;
  RowSystem rows_;
  std::vector<double> base_, lo_, hi_;
  std::vector<int> findex_;
};

}  // namespace mlcp::test
