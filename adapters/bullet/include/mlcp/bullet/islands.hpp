// mlcp/bullet/islands.hpp: Bullet's solver rows as connected components in canonical form.
//
// Input: the pools btSequentialImpulseConstraintSolver's setup fills (solver bodies; joint,
// contact, friction and rolling-friction rows). Output: one Island per connected component of
// the dynamic-body graph, each holding an mlcp::RowSystem (rows in Bullet's order: joints,
// contacts, friction, rolling friction — the stock btMLCPSolver's order) and pointers back to
// Bullet's rows for the write-back. The conversion rules are listed in constraint_solver.hpp.
//
// Static bodies (Bullet maps them all to one fixed solver body) and kinematic bodies (inverse
// mass 0) are "the world": they couple nothing, so two boxes resting on the same ground are two
// islands. Buffers are kept between calls so a steady scene allocates nothing per step.
//
// Two passes over Bullet's rows (288 bytes each, in double precision): the first reads only the
// body indices (union-find; each row's dynamic bodies kept in a compact array for the island
// numbering), the second converts each row into its island. ~40 ns a row (210-box pyramid),
// mostly first touches of Bullet's rows and the scattered writes of the RowSystem's arrays.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <unordered_map>
#include <utility>
#include <vector>

#include "mlcp/rows.hpp"

namespace mlcp::bullet {

enum class CfmModel;

// What each island's start (and splitStart) holds.
enum class Start {
  Zero,            // a cold start
  CachedImpulse,   // last step's impulses, the warm start: contacts' and friction's applied
                   // impulse divided by m_warmstartingFactor (SI's setup applied the scaled
                   // impulse), joints' as applied; friction rows, which Bullet 3's setup starts
                   // at 0, take the manifold point's m_appliedImpulseLateral1/2 (last step's
                   // answer) when the directions persist (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING
                   // or SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION)
  AppliedImpulse,  // the applied impulses as they are (after SI's iterations: SI's answer)
};

struct Island {
  RowSystem system;                       // w = A x + b with b from m_rhs
  std::vector<btSolverConstraint*> rows;  // Bullet's row for each system row
  Vector start;                           // applied impulses (warm start)
  Vector splitB;                          // b of the split-impulse problem (m_rhsPenetration)
  Vector splitStart;                      // applied push impulses
  bool hasSplit = false;                  // splitB has a non-zero entry
  // Each contact and friction row's manifold point (null for other rows), for
  // IslandBuilder::remember.
  std::vector<const btManifoldPoint*> point;
};

// The pools of one solveGroup call, as btSequentialImpulseConstraintSolver holds them.
struct BulletRows {
  btAlignedObjectArray<btSolverBody>* bodies = nullptr;
  btConstraintArray* joints = nullptr;
  btConstraintArray* contacts = nullptr;
  btConstraintArray* friction = nullptr;
  btConstraintArray* rolling = nullptr;
};

class IslandBuilder {
 public:
  // Splits the rows into islands. globalCfm and timeStep feed CfmModel::StockMlcp and Regularized.
  void build(const BulletRows& rows, const btContactSolverInfo& info, CfmModel cfm, Start start);

  // Warm start across steps from our own answers, per manifold point. Bullet 3 starts friction
  // rows at 0, and with its default velocity-dependent friction direction a row's direction
  // changes every step, so last step's value per row means nothing; and a point Bullet removes
  // and re-creates at the same place (m_lifeTime 0, which happens every step to some points of
  // a resting stack) has lost its cached normal impulse. remember() keeps each point's normal
  // impulse and friction impulse (a world vector: the sum of x_r times the row's direction);
  // the next step's build() starts the point's contact row at that normal impulse and its
  // friction rows at the vector's components along their new directions. A point is "the
  // same" when it sits in the same slot (pointer) with m_localPointA within
  // gContactBreakingThreshold of the remembered one: Bullet's own rule for matching a new
  // point to a cached one (a removed point's slot refilled by another point is farther away).
  // Call newStep() once per simulation step, before its build() calls.
  void newStep();
  void remember(const Island& island, const Vector& x);

  int count() const { return count_; }
  Island& island(int k) { return islands_[k]; }
  // Rows whose bodies are all static or kinematic (left untouched: they move nothing).
  int inertRows() const { return inert_; }

 private:
  int find(int k);

  std::vector<Island> islands_;
  int count_ = 0, inert_ = 0;
  std::vector<btSolverConstraint*> all_;
  std::vector<int> findex_, dynamic_, parent_, islandOfRoot_, rowIsland_, rowLocal_, bodyLocal_;
  std::vector<int> bodyCount_;
  std::vector<std::pair<int, int>> rowBodies_;  // each row's dynamic bodies (-1: none)
  struct Remembered {
    double normal = 0;   // the contact row's impulse
    btVector3 friction;  // world-space friction impulse on body A
    btVector3 localA;    // the point's m_localPointA when remembered
  };
  std::unordered_map<const btManifoldPoint*, Remembered> last_, this_;
};

}  // namespace mlcp::bullet
