#include "mlcp/bullet/islands.hpp"

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mlcp/bullet/constraint_solver.hpp"
#include "mlcp/island/row_screen.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "row_values.hpp"

namespace mlcp::bullet {

namespace {

// A friction row's direction (the impulse on body A per unit x). Bullet zeroes the normal of a
// side without a rigid body (static ground), so it is taken from the side that has one.
btVector3 frictionDirection(const btSolverConstraint& c) {
  return c.m_contactNormal1.isZero() ? -c.m_contactNormal2 : c.m_contactNormal1;
}

// Whether Bullet's body update (internalApplyImpulse) is M^-1 J^T for our mass model: the linear
// factor l enters Bullet's update squared (m_invMass = invMass l, times l again) and ours once
// (J's n l, invMass); the angular factor f as diag(f)^2 I^-1 and diag(f) I^-1 diag(f).
bool sameUpdate(const btSolverBody& b) {
  const btVector3& l = b.m_linearFactor;
  const btVector3& f = b.m_angularFactor;
  for (int k = 0; k < 3; ++k)
    if (l[k] != 0 && l[k] != 1) return false;
  return f[0] == f[1] && f[1] == f[2];
}

// How many rows ahead the passes over Bullet's rows fetch what they read or write next.
constexpr int kAhead = 6;
// How many rows ahead the packing pass fetches Bullet's rows (~50 ns a row: 0.5 us ahead).
constexpr int kRowsAhead = 10;

constexpr unsigned char kUnitLinear = 1, kUnitAngular = 2;
bool allOnes(const btVector3& v) { return v[0] == 1 && v[1] == 1 && v[2] == 1; }

// J of a side without a dynamic body (ignored by the solver; zeros as a RowSystem would hold).
constexpr double kZeros[3] = {0, 0, 0};

// Bullet's 3-vector as 3 contiguous doubles: in place with double-precision Bullet; copied to
// `own` with single precision (MLCP_BULLET_FLOAT).
inline const double* doubles(const btVector3& v, double* own) {
#ifdef BT_USE_DOUBLE_PRECISION
  static_assert(sizeof(btScalar) == sizeof(double), "rows are read in place as doubles");
  (void)own;
  return v;
#else
  for (int k = 0; k < 3; ++k) own[k] = v[k];
  return own;
#endif
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
                          Start start, bool system) {
  in_ = in;
  cfm_ = cfm;
  start_ = start;
  nj_ = in.joints->size();
  nc_ = in.contacts->size();
  nf_ = in.friction->size();
  const int n = nj_ + nc_ + nf_ + in.rolling->size();
  prepareBodies();
  const bool single = linkRows(n);
  numberIslands(n, single);
  sizeIslands(single);
  placeRows(n, single);
  readSolverInfo(info);
  if (system)
    for (int k = 0; k < count_; ++k) fillSystem(islands_[k]);
}

void IslandBuilder::prepareBodies() {
  const btAlignedObjectArray<btSolverBody>& bodies = *in_.bodies;
  const int nb = bodies.size();
  dynamic_.resize(nb);
  parent_.resize(nb);
  unit_.resize(nb);
  bodyLocal_.assign(nb, -1);
  if (islands_.empty()) islands_.resize(1);
  islands_[0].solverBody.clear();
  for (int k = 0; k < nb; ++k) {
    const btSolverBody& sb = bodies[k];
    const btRigidBody* rb = sb.m_originalBody;
    dynamic_[k] = (rb && rb->getInvMass() != 0) ? k : -1;
    parent_[k] = k;
    if (dynamic_[k] >= 0)
      unit_[k] = (allOnes(sb.m_linearFactor) ? kUnitLinear : 0) |
                 (allOnes(sb.m_angularFactor) ? kUnitAngular : 0);
  }
}

bool IslandBuilder::linkRows(int n) {
  const BulletRows& in = in_;
  const int nj = nj_, nc = nc_, nf = nf_, nr = in.rolling->size();
  std::vector<int>& firstUse = islands_[0].solverBody;
  // One pass over Bullet's rows for the graph: rows in the stock order, friction rows pointing at
  // their contact row, each row's dynamic bodies kept compact for the passes below.
  all_.resize(n);
  findex_.resize(n);
  rowBodies_.resize(n);
  int lastA = -2, lastB = -2;  // the last row's pair (a manifold's rows repeat it)
  int inert = 0;               // rows on no dynamic body
  int joined = 0;              // unions of two components
  // Bodies numbered by first use in row order as they come (island 0's solverBody), for the
  // case that the group is one component; the general numbering below starts again otherwise.
  auto number = [&](int d) {
    if (d >= 0 && bodyLocal_[d] < 0) {
      bodyLocal_[d] = static_cast<int>(firstUse.size());
      firstUse.push_back(d);
    }
  };
  auto add = [&](int i, btSolverConstraint& c, int f) {
    all_[i] = &c;
    findex_[i] = f;
    const int a = c.m_solverBodyIdA >= 0 ? dynamic_[c.m_solverBodyIdA] : -1;
    const int b = c.m_solverBodyIdB >= 0 ? dynamic_[c.m_solverBodyIdB] : -1;
    rowBodies_[i] = {a, b};
    inert += a < 0 && b < 0;
    if (a != lastA || b != lastB) {
      if (a >= 0 && b >= 0) {
        const int ra = find(a), rb = find(b);
        if (ra != rb) {
          parent_[ra] = rb;
          ++joined;
        }
      }
      number(a);
      number(b);
      lastA = a;
      lastB = b;
    }
  };
  // The first touch of each row's last line (its body indices): fetched ahead.
  auto ahead = [](btConstraintArray& pool, int i) {
    if (i + kRowsAhead < pool.size()) __builtin_prefetch(&pool[i + kRowsAhead].m_solverBodyIdA);
  };
  for (int i = 0; i < nj; ++i) {
    ahead(*in.joints, i);
    add(i, (*in.joints)[i], -1);
  }
  for (int i = 0; i < nc; ++i) {
    ahead(*in.contacts, i);
    add(nj + i, (*in.contacts)[i], -1);
  }
  for (int i = 0; i < nf; ++i) {
    ahead(*in.friction, i);
    btSolverConstraint& c = (*in.friction)[i];
    add(nj + nc + i, c, nj + c.m_frictionIndex);
  }
  for (int i = 0; i < nr; ++i) {
    btSolverConstraint& c = (*in.rolling)[i];
    add(nj + nc + nf + i, c, nj + c.m_frictionIndex);
  }
  // The bodies the rows name less the unions that joined two components is the number of
  // components.
  return n > 0 && inert == 0 && static_cast<int>(firstUse.size()) - joined == 1;
}

void IslandBuilder::addBody(Island& isl, int d) {
  const btSolverBody& sb = (*in_.bodies)[d];
  if (!sameUpdate(sb)) isl.perRowWriteBack = true;
  isl.system.bodies.push_back(detail::inverseMassOf(sb));
}

void IslandBuilder::openIsland() {
  if (static_cast<int>(islands_.size()) < ++count_) islands_.resize(count_);
  rowsIn_.push_back(0);
  Island& isl = islands_[count_ - 1];
  isl.system.bodies.clear();
  isl.solverBody.clear();
  isl.hasSplit = false;
  isl.filled = false;
  isl.perRowWriteBack = false;
  isl.beyondReach = false;
}

void IslandBuilder::numberIslands(int n, bool single) {
  // Islands numbered by first appearance in row order; rows keep their relative order, bodies
  // are numbered by first use in their island's rows.
  islandOfRoot_.assign(dynamic_.size(), -1);
  rowIsland_.resize(n);
  rowLocal_.resize(n);
  count_ = 0;
  inert_ = 0;
  rowsIn_.clear();
  const std::vector<int>& firstUse = islands_[0].solverBody;
  // One component with every row on a dynamic body (a pile, a pyramid): the rows are island 0 in
  // their own order, its bodies were numbered in the pass above (first use, as the general
  // numbering does), its rows and findex are the pass's arrays themselves (swapped in) and its
  // rowIndex the identity (not written).
  if (single) {
    count_ = 1;
    rowsIn_.push_back(n);
    Island& isl = islands_[0];
    isl.system.bodies.clear();
    isl.hasSplit = false;
    isl.filled = false;
    isl.perRowWriteBack = false;
    isl.beyondReach = false;
    for (const int d : firstUse) addBody(isl, d);
    return;
  }
  for (const int d : firstUse) bodyLocal_[d] = -1;
  numberComponents(n);
}

void IslandBuilder::numberComponents(int n) {
  auto localBody = [&](Island& isl, int d) -> int {
    if (d < 0) return -1;
    if (bodyLocal_[d] < 0) {
      bodyLocal_[d] = static_cast<int>(isl.system.bodies.size());
      addBody(isl, d);
      isl.solverBody.push_back(d);
    }
    return bodyLocal_[d];
  };
  // First each row's island and its place there (a manifold's rows repeat the previous row's
  // bodies: no find() for them), then each island's arrays at their final sizes, written by
  // index (no growth checks per row; sizeIslands, placeRows).
  int lastPairA = -2, lastPairB = -2, lastIsland = -1;
  // The current island's row count kept here (written back when the island changes): counting
  // in rowsIn_ chained every row through a store and a load.
  int counted = 0;
  for (int i = 0; i < n; ++i) {
    const auto [a, b] = rowBodies_[i];
    if (a < 0 && b < 0) {
      rowIsland_[i] = -1;
      ++inert_;
      continue;
    }
    int k = lastIsland;
    if (a != lastPairA || b != lastPairB) {
      const int root = find(a >= 0 ? a : b);
      if (islandOfRoot_[root] < 0) {
        islandOfRoot_[root] = count_;
        openIsland();
      }
      k = islandOfRoot_[root];
      if (k != lastIsland) {
        if (lastIsland >= 0) rowsIn_[lastIsland] = counted;
        counted = rowsIn_[k];
      }
      localBody(islands_[k], a);
      localBody(islands_[k], b);
      lastPairA = a;
      lastPairB = b;
      lastIsland = k;
    }
    rowIsland_[i] = k;
    rowLocal_[i] = counted++;
  }
  if (lastIsland >= 0) rowsIn_[lastIsland] = counted;
}

void IslandBuilder::sizeIslands(bool single) {
  for (int k = 0; k < count_; ++k) {
    Island& isl = islands_[k];
    const std::size_t m = static_cast<std::size_t>(rowsIn_[k]);
    isl.inOrder = single;
    if (!single) {
      isl.rows.resize(m);
      isl.rowIndex.resize(m);
      isl.system.findex.resize(m);
    }
    // Only the cached-impulse start reads the points (and remember() keeps answers for it).
    const std::size_t withPoints = start_ == Start::CachedImpulse ? m : 0;
    isl.point.resize(withPoints);
    isl.last.resize(withPoints);
    isl.memo.resize(withPoints);
  }
  points_ = start_ == Start::CachedImpulse;
}

void IslandBuilder::placeRows(int n, bool single) {
  const int nj = nj_, nc = nc_, nf = nf_;
  for (int i = 0; i < n && (points_ || !single); ++i) {
    const int k = single ? 0 : rowIsland_[i];
    if (k < 0) continue;
    Island& isl = islands_[k];
    const int r = single ? i : rowLocal_[i];
    btSolverConstraint& c = *all_[i];
    const int f = single ? findex_[i] : findex_[i] >= 0 ? rowLocal_[findex_[i]] : -1;
    if (!single) {
      isl.rows[r] = &c;
      isl.rowIndex[r] = i;
      isl.system.findex[r] = f;
    }
    if (!points_) continue;
    const btManifoldPoint* point = nullptr;
    const Remembered* last = nullptr;
    btVector3 memo(0, 0, 0);
    // The manifold points are read here first (their local position): fetched ahead.
    if (i >= nj && i + kAhead < nj + nc)
      __builtin_prefetch(all_[i + kAhead]->m_originalContactPoint);
    if (i >= nj && i < nj + nc + nf) {  // a contact or friction row
      // Last step's answer at this manifold point, if it is the same point (see remember());
      // a friction row's point is its contact row's (listed already: contacts come first).
      if (i >= nj + nc) {
        point = isl.point[f];
        last = static_cast<const Remembered*>(isl.last[f]);
      } else {
        point = static_cast<const btManifoldPoint*>(c.m_originalContactPoint);
        if (point) memo = point->m_localPointA;
        if (point) {
          last = lookup(point);
          if (last && (memo - last->localA).length() >= gContactBreakingThreshold) last = nullptr;
        }
      }
    }
    isl.point[r] = point;
    isl.last[r] = last;
    isl.memo[r] = memo;
  }
  if (single) {
    // all_ and findex_ take the island's old buffers (written whole by the next build()).
    islands_[0].rows.swap(all_);
    islands_[0].system.findex.swap(findex_);
  }
}

void IslandBuilder::readSolverInfo(const btContactSolverInfo& info) {
  const Start start = start_;
  stockCfm_ = info.m_globalCfm / info.m_timeStep;
  // SI starts contacts and friction from the cached impulse times m_warmstartingFactor (0.85); a
  // solver that can use a guess gets the cached impulse itself.
  unscaleContacts_ = (start == Start::CachedImpulse && info.m_warmstartingFactor > 0 &&
                      (info.m_solverMode & SOLVER_USE_WARMSTARTING))
                         ? 1.0 / info.m_warmstartingFactor
                         : 1.0;
  // Bullet 3's setup starts every friction row at 0 (setFrictionConstraintImpulse); the impulse
  // it wrote back last step (m_appliedImpulseLateral1/2, kept with the manifold point) is the
  // warm start, when the friction directions persist between steps.
  lateralCache_ = start == Start::CachedImpulse && (info.m_solverMode & SOLVER_USE_WARMSTARTING) &&
                  (info.m_solverMode & (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                                        SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION));
}

// One side's J = [n * linearFactor; r x n] and M^-1's angular part, read in place (see
// islands.hpp); own: 6 doubles for what is not (with single-precision Bullet: J, copied, and no
// angular part of M^-1: Bullet's own is rounded to float, not what our products give).
[[gnu::always_inline]] inline void IslandBuilder::viewSide(
    int body, const btVector3& normal, const btVector3& torqueAxis, const btVector3& invAngular,
    const double*& lin, const double*& ang, const double*& invAng, double* own) const {
  const unsigned char unit = unit_[body];
  if (unit & kUnitLinear) {
    lin = doubles(normal, own);
  } else {
    const btVector3& linearFactor = (*in_.bodies)[body].m_linearFactor;
    for (int k = 0; k < 3; ++k) own[k] = normal[k] * linearFactor[k];
    lin = own;
  }
  ang = doubles(torqueAxis, own + 3);
#ifdef BT_USE_DOUBLE_PRECISION
  invAng = (unit & kUnitAngular) ? doubles(invAngular, nullptr) : nullptr;
#else
  (void)invAngular;
  invAng = nullptr;
#endif
}

[[gnu::always_inline]] inline double IslandBuilder::viewStart(const Island& isl, int r, int i,
                                                              const btSolverConstraint& c,
                                                              double base, bool split) const {
  const bool warm = start_ != Start::Zero;
  if (split) return warm ? base : 0.0;
  if (!warm) return 0.0;
  double start = (i >= nj_ ? unscaleContacts_ : 1.0) * base;
  const btManifoldPoint* point = points_ ? isl.point[r] : nullptr;
  if (point) {
    const bool contact = i >= nj_ && i < nj_ + nc_;
    if (const auto* last = static_cast<const Remembered*>(isl.last[r])) {
      start = contact ? last->normal : last->friction.dot(frictionDirection(c));
    } else if (!contact && lateralCache_) {
      const bool first = i - nj_ - nc_ == (*in_.contacts)[c.m_frictionIndex].m_frictionIndex;
      start = first ? point->m_appliedImpulseLateral1 : point->m_appliedImpulseLateral2;
    }
  }
  return start;
}

[[gnu::always_inline]] inline double IslandBuilder::viewRhs(Island& isl,
                                                            const btSolverConstraint& c, int findex,
                                                            bool split,
                                                            RowPgs::RowView& out) const {
  const double jd = c.m_jacDiagABInv;
  // rhs and cfm are stored pre-multiplied by 1 / A_ii; undo it (as btMLCPSolver does).
  const bool scaled = !btFuzzyZero(jd);
  // Most rows have no penetration rhs: no division for them (-0 / jd would be 0 as well).
  const double rhsPenetration = c.m_rhsPenetration;
  const double splitB = scaled && rhsPenetration != 0 ? -rhsPenetration / jd : 0.0;
  out.b = split ? splitB : scaled ? -c.m_rhs / jd : 0.0;
  if (std::abs(out.b) >= kBeyondReach) isl.beyondReach = true;
  out.cfm = detail::rowCfm(c.m_cfm, jd, scaled, cfm_, stockCfm_, findex >= 0);
  return splitB;
}

[[gnu::always_inline]] inline void IslandBuilder::viewBounds(const btSolverConstraint& c, int i,
                                                             int findex,
                                                             RowPgs::RowView& out) const {
  out.findex = findex;
  detail::rowBounds(c, i >= nj_, findex, out.lo, out.hi);
}

[[gnu::always_inline]] inline RowPgs::RowView IslandBuilder::view(Island& isl, int r, bool split,
                                                                  double* scratch) {
  const int i = isl.inOrder ? r : isl.rowIndex[r];
  const btSolverConstraint& c = *isl.rows[r];
  const int a = rowBodies_[i].first, b = rowBodies_[i].second;
  const int findex = isl.system.findex[r];
  RowPgs::RowView out;
  if (a >= 0) {
    viewSide(a, c.m_contactNormal1, c.m_relpos1CrossNormal, c.m_angularComponentA, out.linA,
             out.angA, out.invAngA, scratch);
  } else {
    out.linA = out.angA = kZeros;
  }
  if (b >= 0) {
    viewSide(b, c.m_contactNormal2, c.m_relpos2CrossNormal, c.m_angularComponentB, out.linB,
             out.angB, out.invAngB, scratch + 6);
  } else {
    out.linB = out.angB = kZeros;
  }
  const double base = split ? c.m_appliedPushImpulse : c.m_appliedImpulse;
  const double start = viewStart(isl, r, i, c, base, split);
  out.bodyA = a >= 0 ? bodyLocal_[a] : -1;
  out.bodyB = b >= 0 ? bodyLocal_[b] : -1;
  const double splitB = viewRhs(isl, c, findex, split, out);
  viewBounds(c, i, findex, out);
  out.base = base;
  out.start = start;
  if (split) return out;
  if (splitB != 0) isl.hasSplit = true;
  if (points_ && findex >= 0 && isl.point[r]) isl.memo[r] = frictionDirection(c);
  return out;
}

RowPgs::RowView IslandBuilder::Source::row(int r) {
  // Bullet's row r + kRowsAhead fetched: its 288 bytes start 16-byte aligned and span five or
  // six lines; the first five hold every field view() reads (bytes 0-264; m_rhsPenetration
  // among the fields past byte 224).
  if (r + kRowsAhead < static_cast<int>(island_.rows.size())) {
    const char* ahead = reinterpret_cast<const char*>(island_.rows[r + kRowsAhead]);
    for (int line = 0; line < 5; ++line) __builtin_prefetch(ahead + 64 * line);
  }
  return builder_.view(island_, r, split_, scratch_);
}

Result IslandBuilder::solvePgs(RowPgs& pgs, Island& island, bool split, Vector& x) {
  Source rows(*this, island, split);
  return pgs.solve(island.system.bodies, static_cast<int>(island.rows.size()), rows, x);
}

void IslandBuilder::fillSystem(Island& isl) {
  if (isl.filled) return;
  isl.filled = true;
  const int m = static_cast<int>(isl.rows.size());
  // toSystem replaces bodies and findex with the same values.
  const std::vector<BodyInverseMass> bodies = isl.system.bodies;
  Source rows(*this, isl, false);
  RowPgs::toSystem(bodies, m, rows, isl.system, isl.start);
  isl.splitB.resize(m);
  isl.splitStart.resize(m);
  double scratch[12];
  for (int r = 0; r < m; ++r) {
    const RowPgs::RowView push = view(isl, r, true, scratch);
    isl.splitB[r] = push.b;
    isl.splitStart[r] = push.start;
  }
}

void IslandBuilder::newStep() {
  std::swap(last_, this_);
  this_.clear();
  cursor_ = 0;
  indexed_ = false;
}

void IslandBuilder::remember(const Island& island, const Vector& x, bool store) {
  const int n = static_cast<int>(island.rows.size());
  const bool points = !island.point.empty();  // build() kept them (the cached-impulse start)
  if (points) entry_.assign(n, -1);
  for (int r = 0; r < n; ++r) {
    // After the sweeps Bullet's rows are out of the near caches: fetch the line written.
    if (store && r + kAhead < n) __builtin_prefetch(&island.rows[r + kAhead]->m_appliedImpulse, 1);
    if (store) island.rows[r]->m_appliedImpulse = static_cast<btScalar>(x[r]);
    if (!points) continue;
    const btManifoldPoint* point = island.point[r];
    if (!point) continue;
    // A friction row's point is its contact row's (earlier in the island): the same entry.
    const int f = island.system.findex[r];
    if (f < 0) {
      entry_[r] = static_cast<int>(this_.size());
      this_.push_back({point, x[r], btVector3(0, 0, 0), island.memo[r]});
    } else if (entry_[f] >= 0) {
      this_[entry_[f]].friction += static_cast<btScalar>(x[r]) * island.memo[r];
    }
  }
}

const IslandBuilder::Remembered* IslandBuilder::lookup(const btManifoldPoint* point) {
  if (cursor_ < last_.size() && last_[cursor_].point == point) return &last_[cursor_++];
  // Fibonacci hashing of the address into a table at most half full.
  auto home = [&](const btManifoldPoint* p) {
    const auto h =
        static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(p)) * 0x9E3779B97F4A7C15ull;
    return static_cast<std::size_t>(h >> 32) & (index_.size() - 1);
  };
  if (!indexed_) {
    indexed_ = true;
    std::size_t size = 64;
    while (size < 2 * last_.size()) size *= 2;
    index_.assign(size, {nullptr, -1});
    for (int e = 0; e < static_cast<int>(last_.size()); ++e) {
      std::size_t k = home(last_[e].point);
      while (index_[k].first && index_[k].first != last_[e].point) k = (k + 1) & (size - 1);
      index_[k] = {last_[e].point, e};  // a point met twice: its later entry
    }
  }
  for (std::size_t k = home(point); index_[k].first; k = (k + 1) & (index_.size() - 1)) {
    if (index_[k].first == point) {
      cursor_ = static_cast<std::size_t>(index_[k].second) + 1;
      return &last_[index_[k].second];
    }
  }
  return nullptr;
}

}  // namespace mlcp::bullet
