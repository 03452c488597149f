// mlcp/bullet/island.hpp: one island of Bullet's rigid rows in canonical form, what
// IslandBuilder (islands.hpp) writes and ConstraintSolver solves and writes back.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <vector>

#include "mlcp/rows.hpp"

namespace mlcp::bullet {

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
  // w = A x + b with b from m_rhs. Its bodies and findex are always filled; the rest only with
  // build(..., system = true) or after fillSystem() (`filled`).
  RowSystem system;
  bool filled = false;
  std::vector<btSolverConstraint*> rows;  // Bullet's row for each system row
  std::vector<int> rowIndex;              // the builder's index of each row (for view())
  bool inOrder = false;                   // row r is the builder's row r (rowIndex not written)
  std::vector<int> solverBody;            // Bullet's solver body of each system body
  Vector start;                           // applied impulses (warm start)
  Vector splitB;                          // b of the split-impulse problem (m_rhsPenetration)
  Vector splitStart;                      // applied push impulses
  bool hasSplit = false;                  // splitB has a non-zero entry
  // point, last and memo: only with the cached-impulse start (Start::CachedImpulse), the only
  // start that reads them (remember() keeps answers for it); empty otherwise (no reads of the
  // manifold points, no answers kept: SI's start and a cold start need neither).
  // Each contact and friction row's manifold point (null for other rows), for
  // IslandBuilder::remember.
  std::vector<const btManifoldPoint*> point;
  // Each contact and friction row's remembered answer from last step (null: none), found once
  // per point by build().
  std::vector<const void*> last;
  // What remember() needs of each row with a point, kept here so that it reads neither Bullet's
  // rows nor the points after the sweeps: a contact row's point's m_localPointA (build()), a
  // friction row's direction (the impulse on body A per unit x; view()).
  std::vector<btVector3> memo;
  // A body's linear factor has a component other than 0 and 1, or its angular factor unequal
  // components: Bullet's body update is not M^-1 J^T there (docs/methods/adapters.md, "Bullet:
  // the pgs path"), so a per-body write-back would differ from Bullet's.
  bool perRowWriteBack = false;
  // A row's b is beyond reach (mlcp/island/row_screen.hpp: Bullet's 6-dof limit at 1e30): the
  // packed pgs, which screens nothing, leaves the island to RowSolver, whose screening fixes the
  // row. Set by view().
  bool beyondReach = false;
};

// The pools of one solveGroup call, as btSequentialImpulseConstraintSolver holds them.
struct BulletRows {
  btAlignedObjectArray<btSolverBody>* bodies = nullptr;
  btConstraintArray* joints = nullptr;
  btConstraintArray* contacts = nullptr;
  btConstraintArray* friction = nullptr;
  btConstraintArray* rolling = nullptr;
};

}  // namespace mlcp::bullet
