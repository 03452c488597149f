#include "island/friction_cone.hpp"

#include <cmath>
#include <map>

namespace mlcp {

namespace {

constexpr double kPi = 3.14159265358979323846;

// cos and sin of theta with the exact zeros and ones at multiples of pi / 2, so that the
// engine's tangents come out as exactly +-t1, +-t2.
std::pair<double, double> direction(double theta) {
  auto snap = [](double v) { return std::abs(v) < 1e-15 ? 0.0 : v; };
  return {snap(std::cos(theta)), snap(std::sin(theta))};
}

}  // namespace

std::string FrictionCone::build(const RowSystem& rows, int directions, bool sparse) {
  if (directions < 3) return "the friction cone needs at least 3 directions per contact";
  directions_ = directions;
  if (std::string why = rows.validate(); !why.empty()) return why;
  // The direction rows are combinations of 6-wide rigid blocks (buildDirections).
  if (rows.hasArticulated())
    return "rows with articulated sides: the cone is built from rigid rows only (box kept)";
  boxSize_ = rows.size();
  if (std::string why = groupContacts(rows); !why.empty()) {
    contacts_.clear();
    return why;
  }
  buildDirections(rows, directions);
  assembleWithLambdas(sparse);
  return "";
}

// Collects each normal's friction rows (findex) and checks that they form an isotropic pair
// (or a single tangent) on the normal's bodies.
std::string FrictionCone::groupContacts(const RowSystem& rows) {
  contacts_.clear();
  dropped_.clear();
  frictionless_ = 0;
  std::map<int, std::vector<int>> tangents;  // normal row -> its friction rows, in row order
  for (int i = 0; i < rows.size(); ++i)
    if (!rows.findex.empty() && rows.findex[i] >= 0) tangents[rows.findex[i]].push_back(i);
  for (const auto& [normal, ts] : tangents) {
    const std::string where = "contact row " + std::to_string(normal) + ": ";
    if (ts.size() > 2)
      return where + std::to_string(ts.size()) +
             " friction rows (rolling friction?); the cone takes one or two tangents";
    if (rows.lo[normal] != 0) return where + "a normal row's lower bound must be 0";
    Contact c;
    c.normal = normal;
    c.t1 = ts[0];
    c.t2 = ts.size() == 2 ? ts[1] : -1;
    c.mu = rows.hi[c.t1];
    for (int t : ts) {
      if (std::abs(rows.hi[t] - c.mu) > 1e-12 * (1 + c.mu))
        return where + "anisotropic friction (its tangents have different mu)";
      if (rows.lo[t] != -rows.hi[t])
        return where + "friction bounds not of the form -mu..mu (row " + std::to_string(t) + ")";
      if (rows.rows[t].bodyA != rows.rows[normal].bodyA ||
          rows.rows[t].bodyB != rows.rows[normal].bodyB)
        return where + "a friction row acts on other bodies than its normal";
    }
    if (c.mu == 0) {  // no friction (see the header)
      ++frictionless_;
      dropped_.insert(dropped_.end(), ts.begin(), ts.end());
      continue;
    }
    contacts_.push_back(c);
  }
  return "";
}

// The kept rows (all but the tangents) as they are, then each contact's direction rows
// J_d = cos(theta) J_t1 + sin(theta) J_t2 (b and cfm likewise; cfm by the squares, which keeps
// an isotropic cfm), bounds [0, inf).
void FrictionCone::buildDirections(const RowSystem& rows, int directions) {
  std::vector<int> coneIndex(rows.size(), -1);
  std::vector<bool> tangent(rows.size(), false);
  for (const Contact& c : contacts_) {
    tangent[c.t1] = true;
    if (c.t2 >= 0) tangent[c.t2] = true;
  }
  for (int t : dropped_) tangent[t] = true;
  kept_.clear();
  for (int i = 0; i < rows.size(); ++i)
    if (!tangent[i]) {
      coneIndex[i] = static_cast<int>(kept_.size());
      kept_.push_back(i);
    }
  int total = static_cast<int>(kept_.size());
  for (Contact& c : contacts_) {
    c.directions = c.t2 >= 0 ? directions : 2;
    c.firstDirection = total;
    total += c.directions;
  }
  RowSystem& d = directionRows_;
  d.bodies = rows.bodies;
  d.rows.resize(total);
  d.b.resize(total);
  d.lo.resize(total);
  d.hi.resize(total);
  d.cfm.resize(total);
  d.findex.clear();
  angles_.assign(total, 0.0);
  for (std::size_t k = 0; k < kept_.size(); ++k) {
    const int i = kept_[k];
    d.rows[k] = rows.rows[i];
    d.b[k] = rows.b[i];
    d.lo[k] = rows.lo[i];
    d.hi[k] = rows.hi[i];
    d.cfm[k] = rows.cfm[i];
  }
  for (Contact& c : contacts_) {
    d.hi[coneIndex[c.normal]] = kInf;  // see the header: no upper bound on a cone contact
    for (int j = 0; j < c.directions; ++j) {
      const int r = c.firstDirection + j;
      angles_[r] = 2 * kPi * j / c.directions;
      const auto [cs, sn] = direction(angles_[r]);
      const ConstraintRow& t1 = rows.rows[c.t1];
      const ConstraintRow* t2 = c.t2 >= 0 ? &rows.rows[c.t2] : nullptr;
      ConstraintRow& row = d.rows[r];
      row.bodyA = t1.bodyA;
      row.bodyB = t1.bodyB;
      row.jA = cs * t1.jA;
      row.jB = cs * t1.jB;
      if (t2) {
        row.jA += sn * t2->jA;
        row.jB += sn * t2->jB;
      }
      d.b[r] = cs * rows.b[c.t1] + (t2 ? sn * rows.b[c.t2] : 0.0);
      d.cfm[r] = cs * cs * rows.cfm[c.t1] + (t2 ? sn * sn * rows.cfm[c.t2] : 0.0);
      d.lo[r] = 0;
      d.hi[r] = kInf;
    }
  }
}

// A of the direction rows plus each contact's lambda column (E) and row (-E', mu at the normal).
void FrictionCone::assembleWithLambdas(bool sparse) {
  const Problem p = directionRows_.assemble(sparse);
  const int r = p.size(), n = r + contacts();
  std::vector<int> normalCone(boxSize_, -1);
  for (std::size_t k = 0; k < kept_.size(); ++k) normalCone[kept_[k]] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> extra;
  for (int c = 0; c < contacts(); ++c) {
    Contact& contact = contacts_[c];
    contact.lambda = r + c;
    extra.emplace_back(contact.lambda, normalCone[contact.normal], contact.mu);
    for (int j = 0; j < contact.directions; ++j) {
      extra.emplace_back(contact.firstDirection + j, contact.lambda, 1.0);
      extra.emplace_back(contact.lambda, contact.firstDirection + j, -1.0);
    }
  }
  if (sparse) {
    std::vector<Eigen::Triplet<double>> all;
    const SparseMatrix& a = p.sparseA();
    for (int i = 0; i < a.outerSize(); ++i)
      for (SparseMatrix::InnerIterator it(a, i); it; ++it)
        all.emplace_back(it.row(), it.col(), it.value());
    all.insert(all.end(), extra.begin(), extra.end());
    SparseMatrix A(n, n);
    A.setFromTriplets(all.begin(), all.end());
    problem_.setA(std::move(A));
  } else {
    DenseMatrix A = DenseMatrix::Zero(n, n);
    A.topLeftCorner(r, r) = p.denseA();
    for (const auto& t : extra) A(t.row(), t.col()) += t.value();
    problem_.setA(std::move(A));
  }
  problem_.b = Vector::Zero(n);
  problem_.b.head(r) = p.b;
  problem_.lo = Vector::Zero(n);
  problem_.lo.head(r) = p.lo;
  problem_.hi = Vector::Constant(n, kInf);
  problem_.hi.head(r) = p.hi;
  problem_.findex.clear();
}

Vector FrictionCone::toBox(const Vector& xCone) const {
  Vector x = Vector::Zero(boxSize_);
  for (std::size_t k = 0; k < kept_.size(); ++k) x[kept_[k]] = xCone[k];
  for (const Contact& c : contacts_) {
    for (int j = 0; j < c.directions; ++j) {
      const int r = c.firstDirection + j;
      const auto [cs, sn] = direction(angles_[r]);
      x[c.t1] += cs * xCone[r];
      if (c.t2 >= 0) x[c.t2] += sn * xCone[r];
    }
  }
  return x;
}

Vector FrictionCone::toCone(const Vector& xBox) const {
  Vector x = Vector::Zero(problem_.size());
  for (std::size_t k = 0; k < kept_.size(); ++k) x[k] = xBox[kept_[k]];
  for (const Contact& c : contacts_) {
    const double a = xBox[c.t1], b = c.t2 >= 0 ? xBox[c.t2] : 0.0;
    if (a == 0 && b == 0) continue;
    // The two directions around the tangent impulse's angle; their nonnegative weights.
    const double width = 2 * kPi / c.directions;
    double phi = std::atan2(b, a);
    if (phi < 0) phi += 2 * kPi;
    const int j = static_cast<int>(phi / width) % c.directions, j2 = (j + 1) % c.directions;
    const auto [c1, s1] = direction(angles_[c.firstDirection + j]);
    const auto [c2, s2] = direction(angles_[c.firstDirection + j2]);
    const double det = c1 * s2 - s1 * c2;
    if (c.t2 < 0 || std::abs(det) < 1e-15) {  // a single tangent: +-t1
      x[c.firstDirection] = std::max(a, 0.0);
      x[c.firstDirection + 1] = std::max(-a, 0.0);
      continue;
    }
    x[c.firstDirection + j] = std::max(0.0, (a * s2 - b * c2) / det);
    x[c.firstDirection + j2] = std::max(0.0, (c1 * b - s1 * a) / det);
  }
  return x;
}

}  // namespace mlcp
