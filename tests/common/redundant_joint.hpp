// A ball joint given twice on one body (the second copy's rows scaled by 2, as Bullet's two
// point-to-point constraints on one hinge line repeat a direction): A = J M^-1 J^T is singular
// (rank 3 of 6), and the rows are consistent up to `drift` in the second copy's rhs. Free rows,
// cfm 0.
#pragma once

#include "mlcp/rows.hpp"

namespace mlcp::test {

inline RowSystem redundantBallJoint(double drift) {
  RowSystem s;
  BodyInverseMass body;
  body.invMass = 1;
  body.invInertia = Eigen::Matrix3d::Identity() * 2;
  s.bodies = {body};
  const Eigen::Vector3d arm(0.3, 0.5, 0);
  for (int copy = 0; copy < 2; ++copy)
    for (int k = 0; k < 3; ++k) {
      ConstraintRow r;
      r.bodyA = 0;
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * (copy ? 2.0 : 1.0);
      r.jA << e, arm.cross(e);
      s.rows.push_back(r);
    }
  s.b.resize(6);
  s.b << 0.1, -0.2, 0.3, 0.2 + drift, -0.4, 0.6 - drift;
  s.lo = Vector::Constant(6, -kInf);
  s.hi = Vector::Constant(6, kInf);
  s.cfm = Vector::Zero(6);
  return s;
}

}  // namespace mlcp::test
