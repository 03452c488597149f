// A unit cube on the ground as an engine hands its contacts to a solver: factored rows
// (rows.hpp), three per contact (normal, two tangents with findex), for closed-form friction
// tests of the box and the cone.
#pragma once

#include <vector>

#include "mlcp/rows.hpp"

namespace mlcp::test {

// A unit cube of mass 1 on the ground (the world), contact frame n = z, t1 = x, t2 = y, one
// contact at each given point (relative to the centre of mass), three rows each: normal, t1, t2
// with findex to the normal. b = J v for the velocity v the cube would have without contact.
inline RowSystem cubeOnGround(const std::vector<Eigen::Vector3d>& points, const Vector6& velocity,
                              double mu, double cfm = 0) {
  RowSystem s;
  BodyInverseMass body;
  body.invMass = 1;
  body.invInertia = Eigen::Matrix3d::Identity() * 6.0;  // I = m s^2 / 6 for s = 1
  s.bodies.push_back(body);
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY()};
  const int n = 3 * static_cast<int>(points.size());
  s.b.resize(n);
  s.lo.resize(n);
  s.hi.resize(n);
  s.cfm = Vector::Constant(n, cfm);
  s.findex.assign(n, -1);
  for (std::size_t c = 0; c < points.size(); ++c) {
    for (int k = 0; k < 3; ++k) {
      const int i = static_cast<int>(3 * c) + k;
      ConstraintRow row;
      row.bodyA = 0;
      row.jA << axes[k], points[c].cross(axes[k]);
      s.rows.push_back(row);
      s.b[i] = row.jA.dot(velocity);
      s.lo[i] = k == 0 ? 0 : -mu;
      s.hi[i] = k == 0 ? kInf : mu;
      if (k > 0) s.findex[i] = static_cast<int>(3 * c);
    }
  }
  return s;
}

// rows with a third friction row on the first contact's normal (row 0), as Bullet's rolling
// friction adds: bounds -0.1..0.1 times the normal impulse, the first tangent's Jacobian.
inline RowSystem withRollingFriction(RowSystem rows) {
  const int n = rows.size();
  rows.rows.push_back(rows.rows[1]);
  rows.b.conservativeResize(n + 1);
  rows.lo.conservativeResize(n + 1);
  rows.hi.conservativeResize(n + 1);
  rows.cfm.conservativeResize(n + 1);
  rows.b[n] = 0;
  rows.lo[n] = -0.1;
  rows.hi[n] = 0.1;
  rows.cfm[n] = rows.cfm[1];
  rows.findex.push_back(0);
  return rows;
}

}  // namespace mlcp::test
