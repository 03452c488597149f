// adapters/bullet/src/multibody_islands.hpp (internal): the rows of a btMultiBodyConstraintSolver
// group as connected components in canonical form (mlcp/rows.hpp with articulated bodies).
//
// Input: every pool the multibody solver's setup fills: the rigid pools of the SI base (joints,
// contacts, friction, rolling friction) and the multibody pools (non-contact rows: joint limits,
// motors, multibody constraints; normal contacts; friction; torsional (rolling) and spinning
// friction). Nodes of the graph: dynamic rigid solver bodies and multibodies (a multibody whose
// base is static or kinematic and that has no joints is "the world", as static rigid bodies are).
// Each row joins its sides' nodes; each island's RowSystem holds its rows in pool order, rigid
// sides as 6-wide blocks and multibody sides as articulated sides: J = m_jacobians and
// W = m_deltaVelocitiesUnitImpulse at m_jacAindex (6 + ndof entries), a row with one multibody
// on both sides (joint limits, motors) as one side with J_A + J_B and W_A + W_B.
// Conversion (row_values.hpp): b = -m_rhs / m_jacDiagABInv (plus m_rhsPenetration's share with
// Settings::multiBodyPositionCorrection), cfm by CfmModel, friction rows findex at their normal
// with mu = m_friction (lateral, torsional and spinning alike: Bullet's bound is mu times the
// normal impulse for each).
// Write-back: x - m_appliedImpulse through Bullet's own updates, as
// resolveSingleConstraintRowGeneric applies a row's change: applyDeltaVee into the solver's
// m_deltaVelocities and btMultiBody::applyDeltaVeeMultiDof2 into the body's m_deltaV (which the
// world integrates), internalApplyImpulse for rigid sides.
// Cost: O(rows + nnz J) per group; union-find over the nodes.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>

#include <unordered_map>
#include <vector>

#include "mlcp/bullet/island.hpp"
#include "mlcp/bullet/settings.hpp"
#include "mlcp/rows.hpp"

namespace mlcp::bullet::detail {

// The pools of one btMultiBodyConstraintSolver group.
struct MultiBodyPools {
  BulletRows rigid;  // the SI base's pools: solver bodies, joints, contacts, friction, rolling
  btMultiBodyConstraintArray* nonContact = nullptr;
  btMultiBodyConstraintArray* normal = nullptr;
  btMultiBodyConstraintArray* lateral = nullptr;
  btMultiBodyConstraintArray* torsional = nullptr;
  btMultiBodyConstraintArray* spinning = nullptr;
  btMultiBodyJacobianData* data = nullptr;
};

// One Bullet row of either type.
struct RowRef {
  btSolverConstraint* rigid = nullptr;
  btMultiBodySolverConstraint* multi = nullptr;
};

struct MultiBodyIsland {
  RowSystem system;
  Vector start;
  std::vector<RowRef> rows;  // Bullet's row of each system row
};

class MultiBodyIslands {
 public:
  // Splits the pools' rows into islands; start as in island.hpp (CachedImpulse: last step's
  // answers where Bullet keeps them, a contact point's impulses; limits and motors start at the
  // impulse Bullet's setup applied).
  void build(const MultiBodyPools& pools, const btContactSolverInfo& info, const Settings& settings,
             Start start);
  int count() const { return count_; }
  MultiBodyIsland& island(int k) { return islands_[k]; }
  // Rows whose sides are all static or kinematic (left untouched).
  int inertRows() const { return inert_; }
  // Store impulses: x - m_appliedImpulse through Bullet's updates; m_appliedImpulse = x.
  void writeBack(MultiBodyIsland& island, const Vector& x) const;

 private:
  enum class Kind { Joint, Contact, Friction };
  struct Row {
    RowRef ref;
    Kind kind = Kind::Joint;
    int findex = -1;  // global
    int nodeA = -1, nodeB = -1;
  };
  void collect(const MultiBodyPools& pools);
  int rigidNode(int solverBody) const;
  int multiBodyNode(btMultiBody* body);
  int find(int k);
  void number();
  void fill(MultiBodyIsland& island, int r, int local, const btContactSolverInfo& info,
            const Settings& settings, Start start);
  double startOf(const Row& row, Start start, double unscale) const;
  // A multibody side (j2, w2: the row's other side on the same multibody, or null).
  void addArticulated(MultiBodyIsland& island, int row, int node, const btScalar* j,
                      const btScalar* w, const btScalar* j2, const btScalar* w2);

  MultiBodyPools in_;
  std::vector<Row> rows_;
  std::vector<MultiBodyIsland> islands_;
  std::vector<btMultiBody*> multiBodies_;
  std::unordered_map<const btMultiBody*, int> multiBodyIndex_;
  std::vector<int> parent_, islandOf_, rowIsland_, rowLocal_, bodyLocal_;
  int count_ = 0, inert_ = 0, nb_ = 0;
};

}  // namespace mlcp::bullet::detail
