// adapters/bullet/src/row_values.hpp (internal): the conversion rules of Bullet's rows to the
// canonical form (docs/methods/adapters.md, "Bullet: the drop-in's stages", stage 3), written
// once for both row types: btSolverConstraint (rigid pools) and btMultiBodySolverConstraint
// (multibody pools) name their fields alike.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSolverBody.h>

#include <algorithm>
#include <cmath>

#include "mlcp/bullet/settings.hpp"
#include "mlcp/rows.hpp"

namespace mlcp::bullet::detail {

// Contacts use 1e10 as "unbounded" and joints BT_INFINITY; both mean +inf to us.
inline double bound(btScalar v) {
  const double d = static_cast<double>(v);
  if (d >= 1e10) return kInf;
  if (d <= -1e10) return -kInf;
  return d;
}

// A row's cfm: m_cfm and m_rhs are stored pre-multiplied by m_jacDiagABInv = 1 / A_ii (as
// btMLCPSolver undoes it); CfmModel says what else (settings.hpp). stockCfm = globalCfm / dt.
inline double rowCfm(double cfm, double jacDiagABInv, bool scaled, CfmModel model, double stockCfm,
                     bool friction) {
  if (model == CfmModel::StockMlcp) return stockCfm;
  const double own = scaled ? std::max(0.0, cfm / jacDiagABInv) : 0.0;
  return model == CfmModel::Regularized && friction && own == 0 ? stockCfm : own;
}

// A row's bounds: friction rows (findex >= 0) -mu..mu, contacts [0, inf), joints their own.
template <class Row>
void rowBounds(const Row& c, bool contact, int findex, double& lo, double& hi) {
  if (findex >= 0) {
    lo = -std::abs(c.m_friction);
    hi = std::abs(c.m_friction);
  } else if (contact) {
    lo = 0;
    hi = kInf;
  } else {
    lo = bound(c.m_lowerLimit);
    hi = bound(c.m_upperLimit);
  }
}

// A dynamic rigid body's inverse mass as our M^-1 sees it: 1 / m, and the world inverse inertia
// scaled by the angular factor on both sides.
inline BodyInverseMass inverseMassOf(const btSolverBody& sb) {
  const btRigidBody* rb = sb.m_originalBody;
  BodyInverseMass m;
  m.invMass = rb->getInvMass();
  const btVector3& af = sb.m_angularFactor;
  const btMatrix3x3& I = rb->getInvInertiaTensorWorld();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      m.invInertia(r, c) = static_cast<double>(af[r]) * I[r][c] * static_cast<double>(af[c]);
  return m;
}

// One rigid side's J = [normal * linearFactor; torqueAxis].
inline Vector6 rigidJacobian(const btSolverBody& sb, const btVector3& normal,
                             const btVector3& torqueAxis) {
  Vector6 j;
  for (int k = 0; k < 3; ++k) {
    j[k] = normal[k] * sb.m_linearFactor[k];
    j[3 + k] = torqueAxis[k];
  }
  return j;
}

}  // namespace mlcp::bullet::detail
