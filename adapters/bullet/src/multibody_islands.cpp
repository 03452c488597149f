#include "multibody_islands.hpp"

#include <BulletCollision/NarrowPhaseCollision/btManifoldPoint.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>

#include "row_values.hpp"

namespace mlcp::bullet::detail {

namespace {
// How far past its limit a one-sided multibody row aims with multiBodyPositionCorrection, in the
// row's unit (rad for a revolute limit, m for a prismatic one).
constexpr double kLimitSlop = 1e-3;
}  // namespace

int MultiBodyIslands::rigidNode(int solverBody) const {
  if (solverBody < 0 || solverBody >= nb_) return -1;
  const btRigidBody* rb = (*in_.rigid.bodies)[solverBody].m_originalBody;
  return rb && rb->getInvMass() != 0 ? solverBody : -1;
}

int MultiBodyIslands::multiBodyNode(btMultiBody* body) {
  // Static or kinematic and without joints: nothing in it moves (its W is zero).
  if (body->isBaseStaticOrKinematic() && body->getNumDofs() == 0) return -1;
  auto [it, added] = multiBodyIndex_.emplace(body, static_cast<int>(multiBodies_.size()));
  if (added) multiBodies_.push_back(body);
  return nb_ + it->second;
}

int MultiBodyIslands::find(int k) {
  while (parent_[k] != k) {
    parent_[k] = parent_[parent_[k]];
    k = parent_[k];
  }
  return k;
}

void MultiBodyIslands::collect(const MultiBodyPools& in) {
  rows_.clear();
  multiBodies_.clear();
  multiBodyIndex_.clear();
  auto rigidPool = [&](btConstraintArray& pool, Kind kind, int normals) {
    for (int i = 0; i < pool.size(); ++i) {
      btSolverConstraint& c = pool[i];
      Row row;
      row.ref.rigid = &c;
      row.kind = kind;
      row.findex = kind == Kind::Friction ? normals + c.m_frictionIndex : -1;
      row.nodeA = rigidNode(c.m_solverBodyIdA);
      row.nodeB = rigidNode(c.m_solverBodyIdB);
      rows_.push_back(row);
    }
  };
  auto multiPool = [&](btMultiBodyConstraintArray& pool, Kind kind, int normals) {
    for (int i = 0; i < pool.size(); ++i) {
      btMultiBodySolverConstraint& c = pool[i];
      Row row;
      row.ref.multi = &c;
      row.kind = kind;
      row.findex = kind == Kind::Friction ? normals + c.m_frictionIndex : -1;
      row.nodeA = c.m_multiBodyA ? multiBodyNode(c.m_multiBodyA) : rigidNode(c.m_solverBodyIdA);
      row.nodeB = c.m_multiBodyB ? multiBodyNode(c.m_multiBodyB) : rigidNode(c.m_solverBodyIdB);
      rows_.push_back(row);
    }
  };
  const int nj = in.rigid.joints->size();
  rigidPool(*in.rigid.joints, Kind::Joint, 0);
  rigidPool(*in.rigid.contacts, Kind::Contact, 0);
  rigidPool(*in.rigid.friction, Kind::Friction, nj);
  rigidPool(*in.rigid.rolling, Kind::Friction, nj);
  multiPool(*in.nonContact, Kind::Joint, 0);
  const int normals = static_cast<int>(rows_.size());
  multiPool(*in.normal, Kind::Contact, 0);
  multiPool(*in.lateral, Kind::Friction, normals);
  multiPool(*in.torsional, Kind::Friction, normals);
  multiPool(*in.spinning, Kind::Friction, normals);
}

void MultiBodyIslands::number() {
  const int nodes = nb_ + static_cast<int>(multiBodies_.size());
  parent_.resize(nodes);
  for (int k = 0; k < nodes; ++k) parent_[k] = k;
  for (const Row& r : rows_)
    if (r.nodeA >= 0 && r.nodeB >= 0) parent_[find(r.nodeA)] = find(r.nodeB);
  // Islands by first appearance in row order; nodes numbered by first use in their island.
  islandOf_.assign(nodes, -1);
  bodyLocal_.assign(nodes, -1);
  rowIsland_.assign(rows_.size(), -1);
  rowLocal_.assign(rows_.size(), -1);
  count_ = 0;
  inert_ = 0;
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const Row& r = rows_[i];
    if (r.nodeA < 0 && r.nodeB < 0) {
      ++inert_;
      continue;
    }
    const int root = find(r.nodeA >= 0 ? r.nodeA : r.nodeB);
    if (islandOf_[root] < 0) {
      islandOf_[root] = count_++;
      if (static_cast<int>(islands_.size()) < count_) islands_.resize(count_);
      MultiBodyIsland& isl = islands_[count_ - 1];
      isl.rows.clear();
      RowSystem& s = isl.system;
      s.bodies.clear();
      s.articulated.clear();
      s.sides.clear();
      s.jacobian.clear();
      s.unitImpulse.clear();
    }
    const int k = islandOf_[root];
    MultiBodyIsland& isl = islands_[k];
    for (const int node : {r.nodeA, r.nodeB}) {
      if (node < 0 || bodyLocal_[node] >= 0) continue;
      if (node < nb_) {
        bodyLocal_[node] = static_cast<int>(isl.system.bodies.size());
        isl.system.bodies.push_back(inverseMassOf((*in_.rigid.bodies)[node]));
      } else {
        bodyLocal_[node] = static_cast<int>(isl.system.articulated.size());
        isl.system.articulated.push_back(6 + multiBodies_[node - nb_]->getNumDofs());
      }
    }
    rowIsland_[i] = k;
    rowLocal_[i] = static_cast<int>(isl.rows.size());
    isl.rows.push_back(r.ref);
  }
}

void MultiBodyIslands::build(const MultiBodyPools& pools, const btContactSolverInfo& info,
                             const Settings& settings, Start start) {
  in_ = pools;
  nb_ = pools.rigid.bodies->size();
  collect(pools);
  number();
  for (int k = 0; k < count_; ++k) {
    MultiBodyIsland& isl = islands_[k];
    const int n = static_cast<int>(isl.rows.size());
    RowSystem& s = isl.system;
    s.rows.assign(n, ConstraintRow());
    s.b.resize(n);
    s.lo.resize(n);
    s.hi.resize(n);
    s.cfm.resize(n);
    s.findex.assign(n, -1);
    isl.start.resize(n);
  }
  for (int i = 0; i < static_cast<int>(rows_.size()); ++i)
    if (rowIsland_[i] >= 0) fill(islands_[rowIsland_[i]], i, rowLocal_[i], info, settings, start);
}

void MultiBodyIslands::addArticulated(MultiBodyIsland& isl, int row, int node, const btScalar* j,
                                      const btScalar* w, const btScalar* j2, const btScalar* w2) {
  RowSystem& s = isl.system;
  const int body = bodyLocal_[node];
  const int width = s.articulated[body];
  s.sides.push_back({row, body, static_cast<int>(s.jacobian.size())});
  for (int e = 0; e < width; ++e) {
    s.jacobian.push_back(static_cast<double>(j[e]) + (j2 ? static_cast<double>(j2[e]) : 0.0));
    s.unitImpulse.push_back(static_cast<double>(w[e]) + (w2 ? static_cast<double>(w2[e]) : 0.0));
  }
}

void MultiBodyIslands::fill(MultiBodyIsland& isl, int r, int local, const btContactSolverInfo& info,
                            const Settings& settings, Start start) {
  const Row& row = rows_[r];
  RowSystem& s = isl.system;
  ConstraintRow& cr = s.rows[local];
  const btAlignedObjectArray<btSolverBody>& bodies = *in_.rigid.bodies;
  auto values = [&](const auto& c, double rhs) {
    const double jd = c.m_jacDiagABInv;
    const bool scaled = !btFuzzyZero(jd);
    s.b[local] = scaled ? -rhs / jd : 0.0;
    const double stockCfm = info.m_globalCfm / info.m_timeStep;
    s.cfm[local] = rowCfm(c.m_cfm, jd, scaled, settings.cfm, stockCfm, row.findex >= 0);
    rowBounds(c, row.kind == Kind::Contact, row.findex, s.lo[local], s.hi[local]);
  };
  if (row.findex >= 0) s.findex[local] = rowLocal_[row.findex];
  if (const btSolverConstraint* rc = row.ref.rigid) {
    if (row.nodeA >= 0) {
      cr.bodyA = bodyLocal_[row.nodeA];
      cr.jA = rigidJacobian(bodies[row.nodeA], rc->m_contactNormal1, rc->m_relpos1CrossNormal);
    }
    if (row.nodeB >= 0) {
      cr.bodyB = bodyLocal_[row.nodeB];
      cr.jB = rigidJacobian(bodies[row.nodeB], rc->m_contactNormal2, rc->m_relpos2CrossNormal);
    }
    values(*rc, rc->m_rhs);
  } else {
    const btMultiBodySolverConstraint& c = *row.ref.multi;
    const btMultiBodyJacobianData& data = *in_.data;
    const btScalar* J = &data.m_jacobians[0];
    const btScalar* W = &data.m_deltaVelocitiesUnitImpulse[0];
    const bool same = c.m_multiBodyA && c.m_multiBodyA == c.m_multiBodyB;
    if (c.m_multiBodyA && row.nodeA >= 0) {
      addArticulated(isl, local, row.nodeA, J + c.m_jacAindex, W + c.m_jacAindex,
                     same ? J + c.m_jacBindex : nullptr, same ? W + c.m_jacBindex : nullptr);
    } else if (!c.m_multiBodyA && row.nodeA >= 0) {
      cr.bodyA = bodyLocal_[row.nodeA];
      cr.jA = rigidJacobian(bodies[row.nodeA], c.m_contactNormal1, c.m_relpos1CrossNormal);
    }
    if (c.m_multiBodyB && row.nodeB >= 0 && !same) {
      addArticulated(isl, local, row.nodeB, J + c.m_jacBindex, W + c.m_jacBindex, nullptr, nullptr);
    } else if (!c.m_multiBodyB && row.nodeB >= 0) {
      cr.bodyB = bodyLocal_[row.nodeB];
      cr.jB = rigidJacobian(bodies[row.nodeB], c.m_contactNormal2, c.m_relpos2CrossNormal);
    }
    const double penetration = settings.multiBodyPositionCorrection ? c.m_rhsPenetration : 0.0;
    values(c, c.m_rhs + penetration);
    // A one-sided multibody row (a joint limit) made only past its limit: aimed kLimitSlop inside
    // the violation, so that it stays there at rest instead of vanishing the step after an exact
    // answer puts the joint on the limit (and the joint falling free for a step).
    if (settings.multiBodyPositionCorrection && row.kind == Kind::Joint && s.lo[local] == 0 &&
        s.hi[local] > 0)
      s.b[local] += kLimitSlop * info.m_erp / info.m_timeStep;
  }
  const bool warm = info.m_warmstartingFactor > 0 && (info.m_solverMode & SOLVER_USE_WARMSTARTING);
  isl.start[local] = startOf(row, start, warm ? 1.0 / info.m_warmstartingFactor : 1.0);
}

double MultiBodyIslands::startOf(const Row& row, Start start, double unscale) const {
  const double applied =
      row.ref.rigid ? row.ref.rigid->m_appliedImpulse : row.ref.multi->m_appliedImpulse;
  if (start == Start::Zero) return 0;
  if (start == Start::AppliedImpulse) return applied;
  if (row.ref.rigid) return row.kind == Kind::Joint ? applied : unscale * applied;
  const btMultiBodySolverConstraint& c = *row.ref.multi;
  // Limits and motors start where Bullet's setup starts them (0 unless its articulated warm
  // start is on): last step's answer kicked the arm of tests/bullet/multibody_test.cpp at 10
  // pgs sweeps (a limit at its 100 cap carried into a step that needs far less).
  if (row.kind == Kind::Joint) return applied;
  if (row.kind == Kind::Contact) {
    const auto* point = static_cast<const btManifoldPoint*>(c.m_originalContactPoint);
    return point ? point->m_appliedImpulse : applied;
  }
  // A lateral friction row: its point's last impulse along the first or second direction.
  const btMultiBodySolverConstraint& normal = *rows_[row.findex].ref.multi;
  const auto* point = static_cast<const btManifoldPoint*>(normal.m_originalContactPoint);
  const btMultiBodyConstraintArray& lateral = *in_.lateral;
  const int first = normal.m_frictionIndex;
  if (!point || first < 0 || first >= lateral.size()) return applied;
  if (&c == &lateral[first]) return point->m_appliedImpulseLateral1;
  if (first + 1 < lateral.size() && &c == &lateral[first + 1])
    return point->m_appliedImpulseLateral2;
  return applied;  // torsional and spinning rows
}

void MultiBodyIslands::writeBack(MultiBodyIsland& isl, const Vector& x) const {
  btAlignedObjectArray<btSolverBody>& bodies = *in_.rigid.bodies;
  btMultiBodyJacobianData& data = *in_.data;
  auto rigid = [&](int id, const btVector3& normal, const btVector3& angular, btScalar delta) {
    if (id < 0 || id >= nb_) return;
    btSolverBody& b = bodies[id];
    b.internalApplyImpulse(normal * b.internalGetInvMass(), angular, delta);
  };
  auto multi = [&](btMultiBody* mb, int jac, int velocity, btScalar delta) {
    const btScalar* w = &data.m_deltaVelocitiesUnitImpulse[jac];
    const int width = 6 + mb->getNumDofs();
    for (int e = 0; e < width; ++e) data.m_deltaVelocities[velocity + e] += w[e] * delta;
    mb->applyDeltaVeeMultiDof2(w, delta);
  };
  for (int i = 0; i < static_cast<int>(isl.rows.size()); ++i) {
    const btScalar xi = static_cast<btScalar>(x[i]);
    if (btSolverConstraint* c = isl.rows[i].rigid) {
      const btScalar delta = xi - c->m_appliedImpulse;
      rigid(c->m_solverBodyIdA, c->m_contactNormal1, c->m_angularComponentA, delta);
      rigid(c->m_solverBodyIdB, c->m_contactNormal2, c->m_angularComponentB, delta);
      c->m_appliedImpulse = xi;
      continue;
    }
    btMultiBodySolverConstraint& c = *isl.rows[i].multi;
    const btScalar delta = xi - c.m_appliedImpulse;
    if (c.m_multiBodyA)
      multi(c.m_multiBodyA, c.m_jacAindex, c.m_deltaVelAindex, delta);
    else
      rigid(c.m_solverBodyIdA, c.m_contactNormal1, c.m_angularComponentA, delta);
    if (c.m_multiBodyB)
      multi(c.m_multiBodyB, c.m_jacBindex, c.m_deltaVelBindex, delta);
    else
      rigid(c.m_solverBodyIdB, c.m_contactNormal2, c.m_angularComponentB, delta);
    c.m_appliedImpulse = xi;
  }
}

}  // namespace mlcp::bullet::detail
