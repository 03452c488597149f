// mlcp/bullet/islands.hpp: Bullet's solver rows as connected components in canonical form.
//
// Input: the pools btSequentialImpulseConstraintSolver's setup fills (solver bodies; joint,
// contact, friction and rolling-friction rows). Output: one Island per connected component of
// the dynamic-body graph, each holding an mlcp::RowSystem (mlcp/rows.hpp; rows in
// Bullet's order: joints, contacts, friction, rolling friction, the stock btMLCPSolver's order)
// and pointers back to Bullet's rows for the write-back. The conversion rules are stage 3 of
// docs/methods/adapters.md, "Bullet: the drop-in's stages".
//
// Static bodies (Bullet maps them all to one fixed solver body) and kinematic bodies (inverse
// mass 0) are "the world": they couple nothing, so two boxes resting on the same ground are two
// islands.
//
// Two passes over Bullet's rows: a graph pass (union-find on the body indices only; a group that
// is one component is decided there and kept in Bullet's order, Island::inOrder), then the
// conversion, into each island's RowSystem or read in place by RowPgs through Source (one
// conversion function, view(), for both). Both passes fetch rows and manifold points a few rows
// ahead, and what remember() needs after the solve is kept in Island::memo, so after the sweeps
// only the applied impulses are written into Bullet's rows (docs/methods/adapters.md, "Bullet:
// islands, the two passes").
// Invariants: both numberings give the same island and row order; Source and fillSystem give the
// same values bit for bit. Cost: O(rows + bodies) per group, near-linear union-find included; no
// allocation once the buffers have grown.
#pragma once

#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>

#include <utility>
#include <vector>

#include "mlcp/bullet/island.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp::bullet {

enum class CfmModel;

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
  // J and M^-1 J^T's angular part are Bullet's own vectors where the body's factors are
  // (1, 1, 1): the same doubles the RowSystem's products give, bit for bit, where neither side is
  // built with fused multiply-adds (docs/methods/adapters.md, "Bullet: rows read in place").
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

  // Warm start across steps from our own answers, per manifold point (docs/methods/adapters.md,
  // "Bullet: the warm start"): remember() keeps each point's normal impulse and friction impulse
  // (a world vector: the sum of x_r times the row's direction); the next step's build() starts
  // the point's contact row at that normal impulse and its friction rows at the vector's
  // components along their new directions. A point is "the same" when it sits in the same slot
  // (pointer) with m_localPointA within gContactBreakingThreshold of the remembered one.
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
  // view()'s parts, i being the row's builder index: one side's J and M^-1's angular part
  // (own: 6 doubles for what is not read in place); the start; b and cfm (returns the split
  // problem's b); findex and the bounds.
  void viewSide(int body, const btVector3& normal, const btVector3& torqueAxis,
                const btVector3& invAngular, const double*& lin, const double*& ang,
                const double*& invAng, double* own) const;
  double viewStart(const Island& island, int r, int i, const btSolverConstraint& c, double base,
                   bool split) const;
  double viewRhs(Island& island, const btSolverConstraint& c, int findex, bool split,
                 RowPgs::RowView& out) const;
  void viewBounds(const btSolverConstraint& c, int i, int findex, RowPgs::RowView& out) const;

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
  // first; only a miss builds the address index over last_ (once per step).
  const Remembered* lookup(const btManifoldPoint* point);
  std::vector<Remembered> last_, this_;  // in the order remember() met the points
  std::size_t cursor_ = 0;               // where lookup() tries first
  bool indexed_ = false;                 // index_ holds last_
  std::vector<std::pair<const btManifoldPoint*, int>> index_;  // open addressing, null = empty
  std::vector<int> entry_;  // remember(): each contact row's entry in this_
};

}  // namespace mlcp::bullet
