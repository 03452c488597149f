#include "body_space.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>

#include "linalg/ordering.hpp"
#include "projection/pgs_sweep.hpp"

namespace mlcp::detail {

bool BodySpaceSystem::prepareFor(const RowSystem& rows, const Problem& problem, double dMax) {
  const int n = problem.size();
  if (!prepare(rows, n)) return false;
  for (int i = 0; i < n; ++i)
    if (!(std::abs(diagonal(i) - problem.diagonal(i)) <= 1e-10 * std::max(dMax, 1e-300)))
      return false;
  return true;
}

bool BodySpaceSystem::prepare(const RowSystem& rows, int n) {
  // Articulated sides have no 6x6 M^-1 block to factor: the callers keep to the assembled A.
  if (rows.size() != n || rows.cfm.size() != n || rows.hasArticulated()) return false;
  const int nb = static_cast<int>(rows.bodies.size());
  // R per body; bodies whose W is 0 (static) are left out of S.
  std::vector<Eigen::Matrix3d> angular(nb);
  std::vector<double> linear(nb);
  std::vector<int> compact(nb, -1);
  int dynamic = 0;
  for (int k = 0; k < nb; ++k) {
    const BodyInverseMass& body = rows.bodies[k];
    linear[k] = std::sqrt(std::max(0.0, body.invMass));
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.compute(body.invInertia);
    angular[k] = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    if (linear[k] > 0 || !angular[k].isZero(0.0)) compact[k] = dynamic++;
  }
  // A fill-reducing order of the body graph (every row's pair), so S's factor stays sparse.
  std::vector<Eigen::Triplet<double>> pairs;
  for (int k = 0; k < dynamic; ++k) pairs.emplace_back(k, k, 1.0);
  for (const ConstraintRow& r : rows.rows) {
    const int a = r.bodyA >= 0 ? compact[r.bodyA] : -1, b = r.bodyB >= 0 ? compact[r.bodyB] : -1;
    if (a >= 0 && b >= 0 && a != b) {
      pairs.emplace_back(a, b, 1.0);
      pairs.emplace_back(b, a, 1.0);
    }
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> graph(dynamic, dynamic);
  graph.setFromTriplets(pairs.begin(), pairs.end());
  const std::vector<int>& byRank = orderOf(graph);
  std::vector<int> rank(dynamic);
  for (int k = 0; k < dynamic; ++k) rank[byRank[k]] = k;
  for (int k = 0; k < nb; ++k)
    if (compact[k] >= 0) compact[k] = rank[compact[k]];
  bodies_ = dynamic;
  // The block pattern with its fill: eliminating body k joins every pair of its later neighbours.
  std::vector<std::vector<int>> later(dynamic);  // per rank, the graph's neighbours of higher rank
  for (int col = 0; col < graph.outerSize(); ++col)
    for (Eigen::SparseMatrix<double, Eigen::ColMajor, int>::InnerIterator it(graph, col); it; ++it)
      if (rank[it.index()] > rank[col]) later[rank[col]].push_back(rank[it.index()]);
  symbolic(later);
  rows_.resize(n);
  for (int i = 0; i < n; ++i) {
    const ConstraintRow& r = rows.rows[i];
    RowData& rd = rows_[i];
    rd.a = r.bodyA >= 0 ? compact[r.bodyA] : -1;
    rd.b = r.bodyB >= 0 ? compact[r.bodyB] : -1;
    auto side = [&](int body, const Vector6& j, double* out) {
      if (body < 0) {
        std::fill(out, out + 6, 0.0);
        return;
      }
      for (int l = 0; l < 3; ++l) out[l] = linear[body] * j[l];
      const Eigen::Vector3d ang = angular[body].transpose() * j.tail<3>();
      for (int l = 0; l < 3; ++l) out[3 + l] = ang[l];
    };
    side(rd.a >= 0 ? r.bodyA : -1, r.jA, rd.jr);
    side(rd.b >= 0 ? r.bodyB : -1, r.jB, rd.jr + 6);
    const int sides[2] = {rd.a, rd.b};
    for (int sp = 0; sp < 2; ++sp)
      for (int sq = 0; sq < 2; ++sq)
        rd.block[sp][sq] = sides[sp] >= 0 && sides[sq] >= 0 ? slotOf(sides[sp], sides[sq]) : -1;
  }
  cfm_.assign(rows.cfm.data(), rows.cfm.data() + n);
  return true;
}

// below(k) = k's later neighbours and, for each child c of k in the elimination tree (k the
// lowest of below(c)), below(c) without k: the pattern of L's block column k after the fill.
void BodySpaceSystem::symbolic(std::vector<std::vector<int>>& later) {
  std::vector<std::vector<int>> children(bodies_);
  belowStart_.assign(1, 0);
  below_.clear();
  for (int k = 0; k < bodies_; ++k) {
    std::vector<int>& set = later[k];
    for (int c : children[k])
      for (int a = belowStart_[c]; a < belowStart_[c + 1]; ++a)
        if (below_[a] != k) set.push_back(below_[a]);
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    below_.insert(below_.end(), set.begin(), set.end());
    belowStart_.push_back(static_cast<int>(below_.size()));
    if (!set.empty()) children[set.front()].push_back(k);
  }
  blocks_.resize(bodies_ + 2 * below_.size());
  inverse_.resize(bodies_);
  // Per pivot k and pair (a, b) of below(k), the block that the update L_ak U_kb lands in.
  updates_.clear();
  for (int k = 0; k < bodies_; ++k)
    for (int a = belowStart_[k]; a < belowStart_[k + 1]; ++a)
      for (int b = belowStart_[k]; b < belowStart_[k + 1]; ++b)
        updates_.push_back(slotOf(below_[a], below_[b]));
}

// Block (p, q) of the pattern: p's diagonal, L's (p, q) for p > q at q's column, U's (p, q) for
// p < q at p's row (slots: bodies_ diagonal blocks, then L and U of each below_ entry in turn).
int BodySpaceSystem::slotOf(int p, int q) const {
  if (p == q) return p;
  const int column = std::min(p, q), other = std::max(p, q);
  const auto first = below_.begin() + belowStart_[column];
  const auto last = below_.begin() + belowStart_[column + 1];
  const int at = static_cast<int>(std::lower_bound(first, last, other) - below_.begin());
  return bodies_ + 2 * at + (p < q ? 1 : 0);
}

const std::vector<int>& BodySpaceSystem::orderOf(
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& graph) {
  const int n = static_cast<int>(graph.rows());
  const int* start = graph.outerIndexPtr();
  const int* index = graph.innerIndexPtr();
  const bool same = static_cast<int>(graphStart_.size()) == n + 1 &&
                    std::equal(graphStart_.begin(), graphStart_.end(), start) &&
                    std::equal(graphIndex_.begin(), graphIndex_.end(), index);
  if (same) return byRank_;
  graphStart_.assign(start, start + n + 1);
  graphIndex_.assign(index, index + graph.nonZeros());
  byRank_ = linalg::fillReducingOrder(n, graphStart_, graphIndex_);
  if (static_cast<int>(byRank_.size()) != n) {  // refused: the bodies' own order
    byRank_.resize(n);
    for (int k = 0; k < n; ++k) byRank_[k] = k;
  }
  return byRank_;
}

bool BodySpaceSystem::factor(const std::vector<int>& order, const std::vector<int>& pos,
                             const std::vector<int>& sliding, const std::vector<double>& coeff,
                             const std::vector<int>& findex, double rho, double minDiagonal) {
  return assemble(order, pos, sliding, coeff, findex, rho, minDiagonal) && eliminate();
}

void BodySpaceSystem::assembled(std::vector<int>& start, std::vector<int>& index,
                                std::vector<double>& values) const {
  // Per block column q, its blocks (p, slot) in increasing p.
  std::vector<std::vector<std::pair<int, int>>> columns(bodies_);
  for (int k = 0; k < bodies_; ++k) {
    columns[k].emplace_back(k, k);
    for (int a = belowStart_[k]; a < belowStart_[k + 1]; ++a) {
      columns[k].emplace_back(below_[a], bodies_ + 2 * a);
      columns[below_[a]].emplace_back(k, bodies_ + 2 * a + 1);
    }
  }
  start.assign(1, 0);
  index.clear();
  values.clear();
  for (int q = 0; q < bodies_; ++q) {
    std::sort(columns[q].begin(), columns[q].end());
    for (int j = 0; j < 6; ++j) {
      for (const auto& [p, slot] : columns[q]) {
        if (p != q && blocks_[slot].isZero(0.0)) continue;
        for (int i = 0; i < 6; ++i) {
          index.push_back(6 * p + i);
          values.push_back(blocks_[slot](i, j));
        }
      }
      start.push_back(static_cast<int>(index.size()));
    }
  }
}

bool BodySpaceSystem::assemble(const std::vector<int>& order, const std::vector<int>& pos,
                               const std::vector<int>& sliding, const std::vector<double>& coeff,
                               const std::vector<int>& findex, double rho, double minDiagonal) {
  const int m = static_cast<int>(order.size());
  d_.resize(m);
  gr_.resize(12 * static_cast<size_t>(m));
  for (int c = 0; c < m; ++c) {
    const int i = order[c];
    d_[c] = cfm_[i] + rho;
    if (!(d_[c] >= minDiagonal)) return false;
    std::copy(rows_[i].jr, rows_[i].jr + 12, gr_.begin() + 12 * c);
  }
  for (size_t k = 0; k < sliding.size(); ++k) {
    const RowData& t = rows_[sliding[k]];
    const int i = findex[sliding[k]], c = pos[i];
    if (t.a != rows_[i].a || t.b != rows_[i].b) return false;
    for (int l = 0; l < 12; ++l) gr_[12 * c + l] += coeff[k] * t.jr[l];
  }
  for (Block& blk : blocks_) blk.setZero();
  for (int q = 0; q < bodies_; ++q) blocks_[q].setIdentity();
  // S(p, q) += (G_c R_p)^T (J_c R_q) / d_c for the sides p, q of each clamped row c.
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  for (int c = 0; c < m; ++c) {
    const RowData& rd = rows_[order[c]];
    const double inv = 1 / d_[c];
    const int side[2] = {rd.a, rd.b};
    for (int sp = 0; sp < 2; ++sp) {
      if (side[sp] < 0) continue;
      const Vec6 gp = Eigen::Map<const Vec6>(&gr_[12 * c + 6 * sp]) * inv;
      for (int sq = 0; sq < 2; ++sq)
        if (side[sq] >= 0)
          blocks_[rd.block[sp][sq]].noalias() +=
              gp * Eigen::Map<const Vec6>(rd.jr + 6 * sq).transpose();
    }
  }
  rowOf_.assign(order.begin(), order.end());
  return true;
}

bool BodySpaceSystem::eliminate() {
  // Right-looking block LU in the elimination order (no pivoting between blocks: S = I + V^T D^-1
  // U is symmetric positive definite without sliding rows, near it with them).
  constexpr double kPivot = 1e-12;
  const int* update = updates_.data();
  for (int k = 0; k < bodies_; ++k) {
    const Eigen::PartialPivLU<Block> lu(blocks_[k]);
    const double scale = std::max(1.0, blocks_[k].cwiseAbs().maxCoeff());
    if (!(lu.matrixLU().diagonal().cwiseAbs().minCoeff() > kPivot * scale)) return false;
    inverse_[k] = lu.inverse();
    const int first = belowStart_[k], last = belowStart_[k + 1];
    for (int a = first; a < last; ++a) lower(a) = lower(a) * inverse_[k];
    subtractPivotProducts(blocks_.data(), bodies_ + 2 * first, last - first, update);
    update += (last - first) * (last - first);
  }
  return inverse_.empty() || inverse_.back().allFinite();
}

void BodySpaceSystem::solve(Vector& y) {
  const int m = static_cast<int>(rowOf_.size());
  Vector& z = z_;
  z.setZero(6 * bodies_);
  for (int c = 0; c < m; ++c) {
    spread(rows_[rowOf_[c]], &gr_[12 * c], y[c] / d_[c], z);
  }
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  for (int k = 0; k < bodies_; ++k) {
    const Vec6 zk = z.segment<6>(6 * k);
    for (int a = belowStart_[k]; a < belowStart_[k + 1]; ++a)
      z.segment<6>(6 * below_[a]).noalias() -= lower(a) * zk;
  }
  for (int k = bodies_ - 1; k >= 0; --k) {
    Vec6 t = z.segment<6>(6 * k);
    for (int a = belowStart_[k]; a < belowStart_[k + 1]; ++a)
      t.noalias() -= upper(a) * z.segment<6>(6 * below_[a]);
    z.segment<6>(6 * k) = inverse_[k] * t;
  }
  for (int c = 0; c < m; ++c) {
    const RowData& rd = rows_[rowOf_[c]];
    y[c] = (y[c] - gather(rd, rd.jr, z, 0.0)) / d_[c];
  }
}

void BodySpaceSystem::bodyForces(const Vector& x) {
  v_.setZero(6 * bodies_);
  const int n = static_cast<int>(rows_.size());
  for (int i = 0; i < n; ++i) {
    if (x[i] != 0) spread(rows_[i], rows_[i].jr, x[i], v_);
  }
}

void BodySpaceSystem::sweep(const Problem& problem, const Vector& invDiag, Vector& x) {
  bodyForces(x);
  const int n = static_cast<int>(rows_.size());
  for (int i = 0; i < n; ++i) {
    const double wi = rowTimes(i, x[i]) + problem.b[i];
    const double xi = pgsUpdate(problem, i, wi, invDiag[i], 1.0, x);
    const double dx = xi - x[i];
    if (dx == 0) continue;
    x[i] = xi;
    spread(rows_[i], rows_[i].jr, dx, v_);
  }
}

void BodySpaceSystem::multiply(const Vector& x, Vector& out) {
  bodyForces(x);
  const int n = static_cast<int>(rows_.size());
  out.resize(n);
  for (int i = 0; i < n; ++i) out[i] = rowTimes(i, x[i]);
}

void BodySpaceSystem::multiply(const Vector& x, const std::vector<int>& which, Vector& out) {
  bodyForces(x);
  const int m = static_cast<int>(which.size());
  out.resize(m);
  for (int c = 0; c < m; ++c) out[c] = rowTimes(which[c], x[which[c]]);
}

}  // namespace mlcp::detail
