#include "mlcp/bullet/islands.hpp"

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "mlcp/bullet/constraint_solver.hpp"

namespace mlcp::bullet {

namespace {

Eigen::Vector3d toEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Contacts use 1e10 as "unbounded" and joints BT_INFINITY; both mean +inf to us.
double bound(btScalar v) {
  const double d = static_cast<double>(v);
  if (d >= 1e10) return kInf;
  if (d <= -1e10) return -kInf;
  return d;
}

// A friction row's direction (the impulse on body A per unit x). Bullet zeroes the normal of a
// side without a rigid body (static ground), so it is taken from the side that has one.
btVector3 frictionDirection(const btSolverConstraint& c) {
  return c.m_contactNormal1.isZero() ? -c.m_contactNormal2 : c.m_contactNormal1;
}

}  // namespace

int IslandBuilder::find(int k) {
  while (parent_[k] != k) {
    parent_[k] = parent_[parent_[k]];
    k = parent_[k];
  }
  return k;
}

void IslandBuilder::build(const BulletRows& in, const btContactSolverInfo& info, CfmModel cfm,
                          Start start) {
  const btAlignedObjectArray<btSolverBody>& bodies = *in.bodies;
  const int nb = bodies.size();
  const int nj = in.joints->size(), nc = in.contacts->size(), nf = in.friction->size(),
            nr = in.rolling->size();
  const int n = nj + nc + nf + nr;

  dynamic_.resize(nb);
  parent_.resize(nb);
  for (int k = 0; k < nb; ++k) {
    const btRigidBody* rb = bodies[k].m_originalBody;
    dynamic_[k] = (rb && rb->getInvMass() != 0) ? k : -1;
    parent_[k] = k;
  }

  // One pass over Bullet's rows for the graph: rows in the stock order, friction rows pointing at
  // their contact row, each row's dynamic bodies kept compact for the passes below.
  all_.resize(n);
  findex_.resize(n);
  rowBodies_.resize(n);
  auto add = [&](int i, btSolverConstraint& c, int f) {
    all_[i] = &c;
    findex_[i] = f;
    const int a = c.m_solverBodyIdA >= 0 ? dynamic_[c.m_solverBodyIdA] : -1;
    const int b = c.m_solverBodyIdB >= 0 ? dynamic_[c.m_solverBodyIdB] : -1;
    rowBodies_[i] = {a, b};
    if (a >= 0 && b >= 0) parent_[find(a)] = find(b);
  };
  for (int i = 0; i < nj; ++i) add(i, (*in.joints)[i], -1);
  for (int i = 0; i < nc; ++i) add(nj + i, (*in.contacts)[i], -1);
  for (int i = 0; i < nf; ++i) {
    btSolverConstraint& c = (*in.friction)[i];
    add(nj + nc + i, c, nj + c.m_frictionIndex);
  }
  for (int i = 0; i < nr; ++i) {
    btSolverConstraint& c = (*in.rolling)[i];
    add(nj + nc + nf + i, c, nj + c.m_frictionIndex);
  }

  // Islands numbered by first appearance in row order; rows keep their relative order.
  islandOfRoot_.assign(nb, -1);
  bodyLocal_.assign(nb, -1);
  rowIsland_.resize(n);
  rowLocal_.resize(n);
  count_ = 0;
  inert_ = 0;
  std::vector<int>& rowsPer = bodyCount_;  // reused: rows per island
  rowsPer.clear();
  for (int i = 0; i < n; ++i) {
    const auto [a, b] = rowBodies_[i];
    if (a < 0 && b < 0) {
      rowIsland_[i] = -1;
      ++inert_;
      continue;
    }
    const int root = find(a >= 0 ? a : b);
    if (islandOfRoot_[root] < 0) {
      islandOfRoot_[root] = count_++;
      rowsPer.push_back(0);
    }
    rowIsland_[i] = islandOfRoot_[root];
    rowLocal_[i] = rowsPer[rowIsland_[i]]++;
  }
  if (static_cast<int>(islands_.size()) < count_) islands_.resize(count_);
  for (int k = 0; k < count_; ++k) {
    Island& isl = islands_[k];
    const int m = rowsPer[k];
    RowSystem& s = isl.system;
    s.rows.resize(m);
    s.bodies.clear();
    s.b.resize(m);
    s.lo.resize(m);
    s.hi.resize(m);
    s.cfm.resize(m);
    s.findex.resize(m);
    isl.rows.resize(m);
    isl.start.resize(m);
    isl.splitB.resize(m);
    isl.splitStart.resize(m);
    isl.point.assign(m, nullptr);
    isl.hasSplit = false;
  }

  // A dynamic body's local index in its island, created on first use.
  auto localBody = [&](Island& isl, int d) -> int {
    if (d < 0) return -1;
    if (bodyLocal_[d] < 0) {
      const btSolverBody& sb = bodies[d];
      const btRigidBody* rb = sb.m_originalBody;
      BodyInverseMass m;
      m.invMass = rb->getInvMass();
      const Eigen::Vector3d af = toEigen(sb.m_angularFactor);
      const btMatrix3x3& I = rb->getInvInertiaTensorWorld();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m.invInertia(r, c) = af[r] * I[r][c] * af[c];
      bodyLocal_[d] = static_cast<int>(isl.system.bodies.size());
      isl.system.bodies.push_back(m);
    }
    return bodyLocal_[d];
  };
  // One side's Jacobian block: [n * linearFactor; r x n].
  auto jacobian = [](Vector6& j, const btVector3& normal, const btVector3& linearFactor,
                     const btVector3& torqueAxis) {
    for (int k = 0; k < 3; ++k) {
      j[k] = normal[k] * linearFactor[k];
      j[3 + k] = torqueAxis[k];
    }
  };

  const double stockCfm = info.m_globalCfm / info.m_timeStep;
  // SI starts contacts and friction from the cached impulse times m_warmstartingFactor (0.85); a
  // solver that can use a guess gets the cached impulse itself.
  const double unscaleContacts = (start == Start::CachedImpulse && info.m_warmstartingFactor > 0 &&
                                  (info.m_solverMode & SOLVER_USE_WARMSTARTING))
                                     ? 1.0 / info.m_warmstartingFactor
                                     : 1.0;
  const bool warm = start != Start::Zero;
  // Bullet 3's setup starts every friction row at 0 (setFrictionConstraintImpulse); the impulse
  // it wrote back last step (m_appliedImpulseLateral1/2, kept with the manifold point) is the
  // warm start, when the friction directions persist between steps.
  const bool lateralCache =
      start == Start::CachedImpulse && (info.m_solverMode & SOLVER_USE_WARMSTARTING) &&
      (info.m_solverMode & (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                            SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION));
  // Last step's answer at this manifold point, if it is the same point (see remember()).
  auto remembered = [&](const btManifoldPoint& point) -> const Remembered* {
    const auto last = last_.find(&point);
    if (last == last_.end() ||
        (point.m_localPointA - last->second.localA).length() >= gContactBreakingThreshold)
      return nullptr;
    return &last->second;
  };
  for (int i = 0; i < n; ++i) {
    if (rowIsland_[i] < 0) continue;
    Island& isl = islands_[rowIsland_[i]];
    RowSystem& s = isl.system;
    const int r = rowLocal_[i];
    btSolverConstraint& c = *all_[i];
    isl.rows[r] = &c;
    ConstraintRow& row = s.rows[r];
    row.bodyA = localBody(isl, rowBodies_[i].first);
    row.bodyB = localBody(isl, rowBodies_[i].second);
    if (row.bodyA >= 0)
      jacobian(row.jA, c.m_contactNormal1, bodies[c.m_solverBodyIdA].m_linearFactor,
               c.m_relpos1CrossNormal);
    else
      row.jA.setZero();
    if (row.bodyB >= 0)
      jacobian(row.jB, c.m_contactNormal2, bodies[c.m_solverBodyIdB].m_linearFactor,
               c.m_relpos2CrossNormal);
    else
      row.jB.setZero();
    // rhs and cfm are stored pre-multiplied by 1 / A_ii; undo it (as btMLCPSolver does).
    const double jd = c.m_jacDiagABInv;
    const bool scaled = !btFuzzyZero(c.m_jacDiagABInv);
    s.b[r] = scaled ? -c.m_rhs / jd : 0.0;
    isl.splitB[r] = scaled ? -c.m_rhsPenetration / jd : 0.0;
    if (isl.splitB[r] != 0) isl.hasSplit = true;
    if (cfm == CfmModel::StockMlcp)
      s.cfm[r] = stockCfm;
    else
      s.cfm[r] = scaled ? std::max(0.0, c.m_cfm / jd) : 0.0;
    if (cfm == CfmModel::Regularized && findex_[i] >= 0 && s.cfm[r] == 0) s.cfm[r] = stockCfm;
    s.findex[r] = findex_[i] >= 0 ? rowLocal_[findex_[i]] : -1;
    if (findex_[i] >= 0) {
      s.lo[r] = -std::abs(static_cast<double>(c.m_friction));
      s.hi[r] = std::abs(static_cast<double>(c.m_friction));
    } else if (i >= nj) {  // contact
      s.lo[r] = 0;
      s.hi[r] = kInf;
    } else {
      s.lo[r] = bound(c.m_lowerLimit);
      s.hi[r] = bound(c.m_upperLimit);
    }
    const double unscale = i >= nj ? unscaleContacts : 1.0;
    isl.start[r] = warm ? unscale * static_cast<double>(c.m_appliedImpulse) : 0.0;
    if (i >= nj && i < nj + nc + nf) {  // a contact or friction row
      const bool contact = i < nj + nc;
      const auto* point = static_cast<const btManifoldPoint*>(
          contact ? c.m_originalContactPoint
                  : (*in.contacts)[c.m_frictionIndex].m_originalContactPoint);
      isl.point[r] = point;
      if (point && start == Start::CachedImpulse) {
        if (const Remembered* last = remembered(*point)) {
          isl.start[r] = contact ? last->normal : last->friction.dot(frictionDirection(c));
        } else if (!contact && lateralCache) {
          const bool first = i - nj - nc == (*in.contacts)[c.m_frictionIndex].m_frictionIndex;
          isl.start[r] = first ? point->m_appliedImpulseLateral1 : point->m_appliedImpulseLateral2;
        }
      }
    }
    isl.splitStart[r] = warm ? static_cast<double>(c.m_appliedPushImpulse) : 0.0;
  }
}

void IslandBuilder::newStep() {
  last_.swap(this_);
  this_.clear();
}

void IslandBuilder::remember(const Island& island, const Vector& x) {
  for (int r = 0; r < static_cast<int>(island.point.size()); ++r) {
    const btManifoldPoint* point = island.point[r];
    if (!point) continue;
    auto [it, added] = this_.try_emplace(point);
    Remembered& m = it->second;
    if (added) {
      m.friction.setZero();
      m.localA = point->m_localPointA;
    }
    if (island.system.findex[r] < 0)
      m.normal = x[r];
    else
      m.friction += static_cast<btScalar>(x[r]) * frictionDirection(*island.rows[r]);
  }
}

}  // namespace mlcp::bullet
