#include "mlcp/rows.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "mlcp/residual.hpp"
#include "mlcp/solver.hpp"
#include "projection/row_checks.hpp"

namespace mlcp {

namespace {

// M^-1 j for one body: [invMass * linear; invInertia * angular].
inline Vector6 applyInverseMass(const BodyInverseMass& body, const Vector6& j) {
  Vector6 out;
  out.head<3>() = body.invMass * j.head<3>();
  out.tail<3>() = body.invInertia * j.tail<3>();
  return out;
}

// A problem with the same b, bounds and findex and no matrix yet: validation of those fields is
// Problem's job, so rows reuse it instead of repeating the rules.
Problem boundsOnly(const RowSystem& s) {
  Problem p;
  p.b = s.b;
  p.lo = s.lo;
  p.hi = s.hi;
  p.findex = s.findex;
  return p;
}

using detail::arraysAndBodiesValid;
using detail::RowRef;
using detail::systemRow;

bool rowsValid(const RowSystem& s) {
  const unsigned slots = static_cast<unsigned>(s.bodies.size()) + 1;  // -1 .. nb - 1
  if (!s.findex.empty() && static_cast<int>(s.findex.size()) != s.size()) return false;
  for (int i = 0; i < s.size(); ++i) {
    const RowRef r = systemRow(s, i, nullptr);
    if (!detail::rowValid(r, s.rows[i].jA.data(), s.rows[i].jB.data(), i, s.size(), slots) ||
        (r.findex >= 0 && s.findex[r.findex] >= 0))
      return false;
  }
  return true;
}

using Touching = std::vector<std::vector<std::pair<int, const Vector6*>>>;  // per body

// The articulated bodies' widths, every side's row, body and storage, and J, W finite.
std::string articulatedError(const RowSystem& s) {
  std::ostringstream os;
  const std::size_t na = s.articulated.size();
  for (std::size_t k = 0; k < na; ++k)
    if (s.articulated[k] <= 0) {
      os << "articulated body " << k << " has width " << s.articulated[k] << " (must be > 0)";
      return os.str();
    }
  if (s.jacobian.size() != s.unitImpulse.size()) {
    os << "articulated storage disagrees: jacobian " << s.jacobian.size() << ", unitImpulse "
       << s.unitImpulse.size();
    return os.str();
  }
  for (std::size_t k = 0; k < s.sides.size(); ++k) {
    const ArticulatedSide& a = s.sides[k];
    if (a.row < 0 || a.row >= s.size() || a.body < 0 || a.body >= static_cast<int>(na) ||
        a.at < 0 || a.at + s.articulated[a.body] > static_cast<int>(s.jacobian.size())) {
      os << "articulated side " << k << " names row " << a.row << " of " << s.size() << ", body "
         << a.body << " of " << na << ", storage at " << a.at << " of " << s.jacobian.size();
      return os.str();
    }
    for (int e = 0; e < s.articulated[a.body]; ++e)
      if (!std::isfinite(s.jacobian[a.at + e]) || !std::isfinite(s.unitImpulse[a.at + e])) {
        os << "articulated side " << k << " (row " << a.row << ") has a non-finite J or W";
        return os.str();
      }
  }
  return "";
}

// J . W over one articulated side's width.
inline double sideDot(const double* j, const double* w, int width) {
  double v = 0;
  for (int e = 0; e < width; ++e) v += j[e] * w[e];
  return v;
}

// Row i of the sparse A (RowSystem::assemble): every row j sharing a body with i, in increasing
// j, A_ij = [i == j] cfm_i + sum over the bodies k of i (increasing k) of
// J_jk . (M_k^-1 J_ik), summed in the dense path's order (cfm, then body by body, and within a
// body i's sides in the order A, B and j's in touching order), so that both storages hold the
// same bits. Count only (Fill false): returns the entries; Fill: writes them at the row's start.
template <bool Fill>
int mergeRow(const RowSystem& s, int i, const Touching& touching, SparseMatrix* A) {
  const ConstraintRow& r = s.rows[i];
  // i's sides in increasing body order (A before B on one body).
  struct Side {
    const std::vector<std::pair<int, const Vector6*>>* list = nullptr;
    Vector6 m = Vector6::Zero();  // M_k^-1 J_ik
    std::size_t at = 0;
  } side[2];
  int sides = 0;
  auto addSide = [&](int body, const Vector6& j) {
    if (body < 0) return;
    side[sides].list = &touching[body];
    if (Fill) side[sides].m = applyInverseMass(s.bodies[body], j);
    ++sides;
  };
  const bool swap = r.bodyA >= 0 && r.bodyB >= 0 && r.bodyB < r.bodyA;
  addSide(swap ? r.bodyB : r.bodyA, swap ? r.jB : r.jA);
  addSide(swap ? r.bodyA : r.bodyB, swap ? r.jA : r.jB);
  int* inner = Fill ? A->innerIndexPtr() + A->outerIndexPtr()[i] : nullptr;
  double* value = Fill ? A->valuePtr() + A->outerIndexPtr()[i] : nullptr;
  int count = 0;
  bool diagonal = false;
  constexpr int kNone = std::numeric_limits<int>::max();
  for (;;) {
    int j = diagonal ? kNone : i;
    for (int s = 0; s < sides; ++s)
      if (side[s].at < side[s].list->size()) j = std::min(j, (*side[s].list)[side[s].at].first);
    if (j == kNone) break;
    double v = 0;
    if (j == i) {
      v = s.cfm[i];
      diagonal = true;
    }
    for (int s = 0; s < sides; ++s) {
      const auto& list = *side[s].list;
      for (; side[s].at < list.size() && list[side[s].at].first == j; ++side[s].at)
        if (Fill) v += list[side[s].at].second->dot(side[s].m);
    }
    if (Fill) {
      inner[count] = j;
      value[count] = v;
    }
    ++count;
  }
  return count;
}

}  // namespace

struct RowSystem::AssembleScratch::Buffers {
  Touching touching;  // per body, the rows touching it (row order) and their Jacobian there
  std::vector<std::vector<int>> articulatedTouching;  // per articulated body, its sides
  std::vector<std::vector<int>> columns;              // articulated systems: each row's columns
  std::vector<int> patternBodies;                     // bodies.size(), then bodyA, bodyB per row
  std::vector<int> patternOuter, patternInner;        // the pattern's compressed index arrays
  std::vector<int> valueSlot;  // per product, in assembly order: its index in A's values
  DenseMatrix dense;           // empty between calls: A's storage is taken from `into`
  SparseMatrix sparse;
};

RowSystem::AssembleScratch::AssembleScratch() : buffers_(std::make_unique<Buffers>()) {}
RowSystem::AssembleScratch::AssembleScratch(AssembleScratch&&) noexcept = default;
RowSystem::AssembleScratch& RowSystem::AssembleScratch::operator=(AssembleScratch&&) noexcept =
    default;
RowSystem::AssembleScratch::~AssembleScratch() = default;

std::string RowSystem::validate() const {
  const int n = size();
  std::ostringstream os;
  if (b.size() != n || lo.size() != n || hi.size() != n || cfm.size() != n) {
    os << "row arrays disagree: " << n << " rows, b " << b.size() << ", lo " << lo.size() << ", hi "
       << hi.size() << ", cfm " << cfm.size();
    return os.str();
  }
  const int nb = static_cast<int>(bodies.size());
  for (int k = 0; k < nb; ++k) {
    const BodyInverseMass& body = bodies[k];
    if (!detail::bodyValid(body)) {
      os << "body " << k << " has an invalid inverse mass or inertia";
      return os.str();
    }
  }
  if (std::string why = articulatedError(*this); !why.empty()) return why;
  if (rowsValid(*this)) return "";
  for (int i = 0; i < n; ++i) {
    const ConstraintRow& r = rows[i];
    if (r.bodyA < -1 || r.bodyA >= nb || r.bodyB < -1 || r.bodyB >= nb) {
      os << "row " << i << " names body " << r.bodyA << "/" << r.bodyB << " of " << nb;
      return os.str();
    }
    if (!r.jA.allFinite() || !r.jB.allFinite()) {
      os << "row " << i << " has a non-finite Jacobian";
      return os.str();
    }
    if (!std::isfinite(cfm[i]) || cfm[i] < 0) {
      os << "row " << i << " has cfm " << cfm[i] << " (must be finite and >= 0)";
      return os.str();
    }
  }
  // Problem::validate checks b, bounds and findex and says what is wrong; give it a shell.
  Problem shell = boundsOnly(*this);
  shell.setA(SparseMatrix(n, n));
  return shell.validate();
}

std::vector<Vector6> RowSystem::bodyVelocities(const Vector& x) const {
  std::vector<Vector6> v;
  bodyVelocities(x, v);
  return v;
}

void RowSystem::bodyVelocities(const Vector& x, std::vector<Vector6>& v) const {
  v.assign(bodies.size(), Vector6::Zero());
  for (int i = 0; i < size(); ++i) {
    const ConstraintRow& r = rows[i];
    if (r.bodyA >= 0) v[r.bodyA] += applyInverseMass(bodies[r.bodyA], r.jA) * x[i];
    if (r.bodyB >= 0) v[r.bodyB] += applyInverseMass(bodies[r.bodyB], r.jB) * x[i];
  }
}

namespace {
// Where each articulated body's velocities start in articulatedVelocities' vector (one entry
// more: the total).
std::vector<int> articulatedOffsets(const RowSystem& s) {
  std::vector<int> at(s.articulated.size() + 1, 0);
  for (std::size_t k = 0; k < s.articulated.size(); ++k) at[k + 1] = at[k] + s.articulated[k];
  return at;
}
}  // namespace

Vector RowSystem::articulatedVelocities(const Vector& x) const {
  const std::vector<int> at = articulatedOffsets(*this);
  Vector v = Vector::Zero(at.back());
  for (const ArticulatedSide& a : sides) {
    const double* w = unitImpulse.data() + a.at;
    for (int e = 0; e < articulated[a.body]; ++e) v[at[a.body] + e] += w[e] * x[a.row];
  }
  return v;
}

double RowSystem::articulatedSpeed(const Vector& x) const {
  if (sides.empty()) return 0;
  const std::vector<int> at = articulatedOffsets(*this);
  const Vector v = articulatedVelocities(x);
  double speed = 0;
  for (std::size_t k = 0; k < articulated.size(); ++k)
    for (int e = std::min(3, articulated[k]); e < articulated[k]; ++e)
      speed = std::max(speed, std::abs(v[at[k] + e]));
  return speed;
}

Vector RowSystem::slack(const Vector& x) const {
  Vector w;
  slack(x, bodyVelocities(x), w);
  return w;
}

void RowSystem::slack(const Vector& x, const std::vector<Vector6>& v, Vector& w) const {
  w.resize(size());
  for (int i = 0; i < size(); ++i) {
    const ConstraintRow& r = rows[i];
    double wi = cfm[i] * x[i] + b[i];
    if (r.bodyA >= 0) wi += r.jA.dot(v[r.bodyA]);
    if (r.bodyB >= 0) wi += r.jB.dot(v[r.bodyB]);
    w[i] = wi;
  }
  if (sides.empty()) return;
  const std::vector<int> at = articulatedOffsets(*this);
  const Vector u = articulatedVelocities(x);
  for (const ArticulatedSide& a : sides)
    w[a.row] += sideDot(jacobian.data() + a.at, u.data() + at[a.body], articulated[a.body]);
}

double RowSystem::impulseEnergy(const Vector& x) const { return 0.5 * x.dot(slack(x) - b); }

Problem RowSystem::assemble(bool sparse) const {
  Problem p;
  AssembleScratch scratch;
  assemble(sparse, p, scratch);
  return p;
}

namespace {

using Buffers = RowSystem::AssembleScratch::Buffers;

// Rows touching each body: only rows sharing a body couple in J M^-1 J^T.
void collectTouching(const RowSystem& s, Touching& touching) {
  if (touching.size() < s.bodies.size()) touching.resize(s.bodies.size());
  for (std::size_t k = 0; k < s.bodies.size(); ++k) touching[k].clear();
  for (int i = 0; i < s.size(); ++i) {
    if (s.rows[i].bodyA >= 0) touching[s.rows[i].bodyA].push_back({i, &s.rows[i].jA});
    if (s.rows[i].bodyB >= 0) touching[s.rows[i].bodyB].push_back({i, &s.rows[i].jB});
  }
}

void collectArticulated(const RowSystem& s, std::vector<std::vector<int>>& touching) {
  if (touching.size() < s.articulated.size()) touching.resize(s.articulated.size());
  for (std::size_t k = 0; k < s.articulated.size(); ++k) touching[k].clear();
  for (int k = 0; k < static_cast<int>(s.sides.size()); ++k) touching[s.sides[k].body].push_back(k);
}

// Every entry of A as add(row, column, value) in one fixed order: diag(cfm), then per body the
// products of the rows touching it. Dense and sparse storage sum them in this order.
// Articulated bodies follow the rigid ones: per articulated body, J_j . W_i over its sides.
template <class Add>
void forEachProduct(const RowSystem& s, const Buffers& scratch, Add&& add) {
  const Touching& touching = scratch.touching;
  for (int i = 0; i < s.size(); ++i) add(i, i, s.cfm[i]);
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    for (const auto& [i, ji] : touching[k]) {
      const Vector6 mji = applyInverseMass(s.bodies[k], *ji);
      for (const auto& [j, jj] : touching[k]) add(i, j, jj->dot(mji));
    }
  }
  if (s.sides.empty()) return;
  for (std::size_t k = 0; k < s.articulated.size(); ++k) {
    for (const int si : scratch.articulatedTouching[k]) {
      const ArticulatedSide& a = s.sides[si];
      const double* w = s.unitImpulse.data() + a.at;
      for (const int sj : scratch.articulatedTouching[k]) {
        const ArticulatedSide& c = s.sides[sj];
        add(a.row, c.row, sideDot(s.jacobian.data() + c.at, w, s.articulated[k]));
      }
    }
  }
}

// The pattern depends only on which bodies each row joins; `p` must still hold it (its index
// arrays are compared, so a matrix set by anyone else is never refilled by mistake).
bool samePattern(const RowSystem& s, const Problem& p, const Buffers& scratch) {
  const int n = s.size();
  const auto& key = scratch.patternBodies;
  const SparseMatrix& held = p.sparseA();
  if (!p.isSparse() || held.rows() != n || held.cols() != n || !held.isCompressed() ||
      key.size() != 1 + 2 * static_cast<std::size_t>(n) ||
      key[0] != static_cast<int>(s.bodies.size()) ||
      held.nonZeros() != static_cast<Eigen::Index>(scratch.patternInner.size()))
    return false;
  for (int i = 0; i < n; ++i)
    if (key[1 + 2 * i] != s.rows[i].bodyA || key[2 + 2 * i] != s.rows[i].bodyB) return false;
  return std::equal(scratch.patternOuter.begin(), scratch.patternOuter.end(),
                    held.outerIndexPtr()) &&
         std::equal(scratch.patternInner.begin(), scratch.patternInner.end(), held.innerIndexPtr());
}

// The values of A on its known pattern. The second assembly on a pattern finds where each
// product lands (row-major: a search of the row's sorted columns), the next ones only write.
void writeValues(const RowSystem& s, SparseMatrix& A, Buffers& scratch) {
  auto& slots = scratch.valueSlot;
  if (slots.empty())
    forEachProduct(s, scratch, [&](int i, int j, double) {
      const int* first = A.innerIndexPtr() + A.outerIndexPtr()[i];
      const int* last = A.innerIndexPtr() + A.outerIndexPtr()[i + 1];
      slots.push_back(static_cast<int>(std::lower_bound(first, last, j) - A.innerIndexPtr()));
    });
  double* values = A.valuePtr();
  std::fill_n(values, A.nonZeros(), 0.0);
  const int* slot = slots.data();
  forEachProduct(s, scratch, [&](int, int, double v) { values[*slot++] += v; });
}

// An articulated system's sparse pattern: each row's columns, the union over the bodies it
// touches (rigid and articulated) of their rows, sorted. Never remembered (samePattern keys it
// with an impossible body count): the values are then written by writeValues in
// forEachProduct's order, the dense path's.
void writeArticulatedPattern(const RowSystem& s, SparseMatrix& A, Buffers& scratch) {
  const int n = s.size();
  auto& columns = scratch.columns;
  columns.resize(n);
  for (int i = 0; i < n; ++i) columns[i].assign(1, i);
  for (std::size_t k = 0; k < s.bodies.size(); ++k)
    for (const auto& entry : scratch.touching[k])
      for (const auto& other : scratch.touching[k]) columns[entry.first].push_back(other.first);
  for (std::size_t k = 0; k < s.articulated.size(); ++k)
    for (const int a : scratch.articulatedTouching[k])
      for (const int c : scratch.articulatedTouching[k])
        columns[s.sides[a].row].push_back(s.sides[c].row);
  A.resize(n, n);
  int* outer = A.outerIndexPtr();
  outer[0] = 0;
  for (int i = 0; i < n; ++i) {
    std::sort(columns[i].begin(), columns[i].end());
    columns[i].erase(std::unique(columns[i].begin(), columns[i].end()), columns[i].end());
    outer[i + 1] = outer[i] + static_cast<int>(columns[i].size());
  }
  A.resizeNonZeros(outer[n]);
  for (int i = 0; i < n; ++i)
    std::copy(columns[i].begin(), columns[i].end(), A.innerIndexPtr() + outer[i]);
  scratch.valueSlot.clear();
  scratch.patternOuter.clear();
  scratch.patternInner.clear();
  scratch.patternBodies.assign(1, -1);  // no body count matches: never reused
  writeValues(s, A, scratch);
}

// A new pattern: each row written in place, its columns the merge of its bodies' row lists;
// the pattern and the bodies it depends on are remembered.
void writePattern(const RowSystem& s, SparseMatrix& A, Buffers& scratch) {
  const int n = s.size();
  A.resize(n, n);
  int* outer = A.outerIndexPtr();
  outer[0] = 0;
  for (int i = 0; i < n; ++i)
    outer[i + 1] = outer[i] + mergeRow<false>(s, i, scratch.touching, nullptr);
  A.resizeNonZeros(outer[n]);
  for (int i = 0; i < n; ++i) mergeRow<true>(s, i, scratch.touching, &A);
  scratch.valueSlot.clear();
  scratch.patternOuter.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
  scratch.patternInner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  auto& key = scratch.patternBodies;
  key.resize(1 + 2 * static_cast<std::size_t>(n));
  key[0] = static_cast<int>(s.bodies.size());
  for (int i = 0; i < n; ++i) {
    key[1 + 2 * i] = s.rows[i].bodyA;
    key[2 + 2 * i] = s.rows[i].bodyB;
  }
}

}  // namespace

void RowSystem::assemble(bool sparse, Problem& p, AssembleScratch& cache) const {
  Buffers& scratch = *cache.buffers_;
  collectTouching(*this, scratch.touching);
  collectArticulated(*this, scratch.articulatedTouching);
  p.b = b;
  p.lo = lo;
  p.hi = hi;
  p.findex = findex;
  if (!sparse) {
    DenseMatrix& A = scratch.dense;
    p.swapA(A);  // A now holds the problem's previous dense storage
    A.setZero(size(), size());
    forEachProduct(*this, scratch, [&](int i, int j, double v) { A(i, j) += v; });
    p.swapA(A);
    return;
  }
  const bool known = samePattern(*this, p, scratch);
  SparseMatrix& A = scratch.sparse;
  p.swapA(A);  // A now holds the problem's previous sparse matrix (its storage is reused)
  if (hasArticulated())
    writeArticulatedPattern(*this, A, scratch);
  else if (known)
    writeValues(*this, A, scratch);
  else
    writePattern(*this, A, scratch);
  p.swapA(A);
}

}  // namespace mlcp
