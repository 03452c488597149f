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
// Two passes over Bullet's rows (288 bytes each, in double precision):
//  1. the graph pass reads only the body indices: a union-find over the dynamic bodies, each
//     row's bodies kept in a compact array. When the group is one component (every dynamic body
//     under one root, no inert row: a pile, a pyramid) this pass also decides it and numbers the
//     bodies by first use as the rows come; components are counted as the bodies the rows name
//     less the unions that joined two, so no find() per body follows. Such an island takes the
//     pass's row and findex arrays by swap, in Bullet's order (Island::inOrder, no rowIndex).
//     Otherwise the numbering runs on the compact arrays in two passes: each row's island and
//     place (no find() for a row on the previous row's bodies), then each island's arrays, sized
//     once and written by index (rows, bodies, findex, manifold points, last step's entries).
//     Both numberings give the same order (tested equal bit for bit).
//  2. the conversion writes each row either into its island's RowSystem (build with system =
//     true, or fillSystem later) or straight into RowPgs' packing through Source (the "pgs"
//     path: read in place by RowPgs' engine entry point, view() inlined into Source::row, no
//     copy).
//     Both write the same values (one conversion function).
// Both passes fetch Bullet's rows and the manifold points a few rows ahead: the passes are bound
// by their first touch of each row, which sits out of cache after Bullet's setup. What remember()
// needs after the solve (points' positions, friction directions) is kept in Island::memo, so
// after the sweeps only the applied impulses are written back into Bullet's rows; without the
// cached-impulse start the manifold points are not read at all.
// Cost: O(rows + bodies) per group, near-linear union-find included; no allocation
// once the buffers have grown.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <utility>
#include <vector>

#include "mlcp/island/rows.hpp"
#include "mlcp/solvers/row_pgs.hpp"

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
  // components: Bullet's body update is not M^-1 J^T there (constraint_solver.hpp), so a
  // per-body write-back would differ from Bullet's.
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

class IslandBuilder {
 public:
  // Splits the rows into islands. globalCfm and timeStep feed CfmModel::StockMlcp and Regularized.
  // With system = false only each island's bodies, findex, rows and points are written; the
  // rows reach a solver through Source or fillSystem().
  void build(const BulletRows& rows, const btContactSolverInfo& info, CfmModel cfm, Start start,
             bool system = true);
  // The island's rows as RowPgs reads them, in place in Bullet's rows (RowPgs::RowView; the
  // same values fillSystem writes; split: b from m_rhsPenetration, the applied push impulse as
  // start and base); base is the impulse Bullet's bodies already carry (m_appliedImpulse /
  // m_appliedPushImpulse). Reading the primary problem's rows sets island.hasSplit.
  // J's linear part is m_contactNormal1/2 itself where the body's linear factor is (1, 1, 1)
  // (else n times the factor, computed), the angular part m_relpos1/2CrossNormal; M^-1 J^T's
  // angular part is Bullet's m_angularComponentA/B where the body's angular factor is (1, 1, 1).
  // Bullet 3.24's setup (setupContactConstraint, setupFrictionConstraint,
  // setupTorsionalFrictionConstraint, convertJoint) computes it as
  // getInvInertiaTensorWorld() * m_relposNCrossNormal * getAngularFactor(): with the factor 1
  // that is bit for bit our invInertia (diag(f) I^-1 diag(f) = I^-1) times the same vector, row
  // by row left to right (double precision Bullet has no SIMD dot; neither side is built with
  // fused multiply-adds: true of Debian's x86-64 builds; where a compiler contracts a * b + c
  // by default, e.g. GCC on aarch64, the two may round apart and only agree to round-off).
  // So the packing skips two 3x3 products per row and the iterates stay those of the RowSystem
  // copy (tested bit for bit on a pyramid with contact, friction and hinge rows). Bullet's
  // m_jacDiagABInv is
  // not used: it is 1 / (invMass + n . (I^-1 (r x n)) x r + Bullet's own cfm), a different
  // rounding of A_ii, and friction rows lack the cfm our CfmModel gives them.
  class Source final : public RowPgs::RowSource {
   public:
    Source(IslandBuilder& builder, Island& island, bool split)
        : builder_(builder), island_(island), split_(split) {}
    RowPgs::RowView row(int r) override;

   private:
    IslandBuilder& builder_;
    Island& island_;
    bool split_;
    double scratch_[12];  // J's parts not read in place (6 a side; view())
  };
  // RowPgs' engine path on the island's rows read in place (Source).
  Result solvePgs(RowPgs& pgs, Island& island, bool split, Vector& x);
  // The island's RowSystem, start, splitB and splitStart (once per build).
  void fillSystem(Island& island);

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
  // store: also set each row's m_appliedImpulse to x (one pass over Bullet's rows for both).
  // Keeps nothing when the island has no points (build() with another start than CachedImpulse).
  void remember(const Island& island, const Vector& x, bool store = false);

  int count() const { return count_; }
  Island& island(int k) { return islands_[k]; }
  // Rows whose bodies are all static or kinematic (left untouched: they move nothing).
  int inertRows() const { return inert_; }

 private:
  int find(int k);
  // build()'s stages, in order (see the passes above):
  // Each solver body's dynamic index (-1 for static and kinematic bodies), union-find root and
  // unit factors.
  void prepareBodies();
  // The graph pass over Bullet's n rows: all_, findex_, rowBodies_, the unions, and the bodies
  // numbered by first use into island 0's solverBody. Returns whether the group is one component
  // with every row on a dynamic body (the single-island shortcut).
  bool linkRows(int n);
  // Each row's island and place (rowIsland_, rowLocal_, rowsIn_) and each island's bodies; with
  // single, island 0 takes every row in order and the first-use numbering.
  void numberIslands(int n, bool single);
  void numberComponents(int n);  // the general case of numberIslands
  // Each island's per-row arrays at their final sizes.
  void sizeIslands(bool single);
  // Each row into its island by index: Bullet's row, its builder index, findex, and with the
  // cached-impulse start its manifold point and last step's answer.
  void placeRows(int n, bool single);
  // What view() takes from the solver info: the stock CFM, the contacts' unscaling, the lateral
  // friction cache.
  void readSolverInfo(const btContactSolverInfo& info);
  // A dynamic body's inverse mass into the island (and whether it needs the per-row write-back).
  void addBody(Island& island, int body);
  // A new island, cleared, at the end (count_, rowsIn_).
  void openIsland();
  // The island's row r; split: the split-impulse problem's b, start and base. scratch: 12
  // doubles for J's parts that are not read in place (6 a side; see view()).
  RowPgs::RowView view(Island& island, int r, bool split, double* scratch);

  std::vector<Island> islands_;
  int count_ = 0, inert_ = 0;
  std::vector<btSolverConstraint*> all_;
  std::vector<int> findex_, dynamic_, parent_, islandOfRoot_, rowIsland_, rowLocal_, bodyLocal_;
  std::vector<int> rowsIn_;  // build(): rows per island
  // Per solver body: kUnitLinear / kUnitAngular when its linear / angular factor is (1, 1, 1).
  std::vector<unsigned char> unit_;
  std::vector<std::pair<int, int>> rowBodies_;  // each row's dynamic bodies (-1: none)
  // What view() needs of the last build() call.
  BulletRows in_;
  CfmModel cfm_{};
  Start start_ = Start::Zero;
  int nj_ = 0, nc_ = 0, nf_ = 0;
  double stockCfm_ = 0, unscaleContacts_ = 1;
  bool lateralCache_ = false;
  bool points_ = false;  // the islands keep their points (Start::CachedImpulse)
  struct Remembered {
    const btManifoldPoint* point = nullptr;
    double normal = 0;   // the contact row's impulse
    btVector3 friction;  // world-space friction impulse on body A
    btVector3 localA;    // the point's m_localPointA when remembered
  };
  // Last step's entry for this point, or null. Points come in nearly the same order every step
  // (manifolds and their point slots persist), so the entry after the last one found is tried
  // first; only a miss builds the address index over last_ (once per step). (An
  // std::unordered_map cleared every step allocated a node per point per step, and a hash
  // table probed per point cost a cache miss per lookup.)
  const Remembered* lookup(const btManifoldPoint* point);
  std::vector<Remembered> last_, this_;  // in the order remember() met the points
  std::size_t cursor_ = 0;               // where lookup() tries first
  bool indexed_ = false;                 // index_ holds last_
  std::vector<std::pair<const btManifoldPoint*, int>> index_;  // open addressing, null = empty
  std::vector<int> entry_;  // remember(): each contact row's entry in this_
};

}  // namespace mlcp::bullet
