#include "newton/newton_system.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "linalg/body_space.hpp"
#include "mlcp/thresholds.hpp"
#include "projection/pgs_sweep.hpp"

namespace mlcp::detail {

namespace {
// Steps of iterative refinement after a body-space solve.
constexpr int kBodyRefinements = 2;
// A refinement whose correction is below this fraction of the solution ends them: the next one
// would change y by less than round-off of the refined y.
constexpr double kRefinedEnough = 1e-13;

}  // namespace

double naturalMap(const Problem& pb, const Vector& x, const Vector& w, Vector& h, double& inf) {
  const int n = pb.size();
  h.resize(n);
  double sum = 0;
  inf = 0;
  for (int i = 0; i < n; ++i) {
    h[i] = x[i] - std::clamp(x[i] - w[i], pb.effectiveLo(i, x), pb.effectiveHi(i, x));
    sum += h[i] * h[i];
    inf = std::max(inf, std::abs(h[i]));
  }
  if (!std::isfinite(sum)) inf = sum = kInf;
  return sum;
}

NewtonSystem::NewtonSystem() : body_(std::make_unique<BodySpaceSystem>()) {}
NewtonSystem::~NewtonSystem() = default;

void NewtonSystem::prepare(const Problem& pb, int denseFactorMaxRows) {
  problem_ = &pb;
  const int n = pb.size();
  da_.setZero(n);
  db_.setZero(n);
  cf_.setZero(n);
  sparse_ = n > denseFactorMaxRows;
  a_ = nullptr;
  // Nothing of the last problem's body space carries over (the dense path has none).
  bodyReady_ = bodyProducts_ = useBody_ = false;
  bodyFactorizations_ = 0;
  if (!sparse_) return;
  if (pb.isSparse() && pb.sparseA().isCompressed()) {
    a_ = &pb.sparseA();
  } else {
    own_ = pb.isSparse() ? pb.sparseA() : pb.toSparse();
    own_.makeCompressed();
    a_ = &own_;
  }
  prepareBody(pb);
}

// Body space applies when the rows handed over are A's: checked on the diagonal.
void NewtonSystem::prepareBody(const Problem& pb) {
  const int n = pb.size();
  double dMax = 0;
  for (int i = 0; i < n; ++i) dMax = std::max(dMax, std::abs(pb.diagonal(i)));
  minDiagonal_ = kBodyMinDiagonal * dMax;
  bodyReady_ = rows_ != nullptr && body_->prepareFor(*rows_, pb, dMax);
  findex_ = pb.hasFindex() ? pb.findex : std::vector<int>(n, -1);
  bodyProducts_ = bodyReady_ && body_->productsStandForA();
}

void NewtonSystem::sweep(const Vector& invDiag, Vector& x) {
  if (bodyProducts_)
    body_->sweep(*problem_, invDiag, x);
  else
    detail::pgsSweep(*problem_, invDiag, 1.0, x);
}

bool NewtonSystem::symmetric() const { return bodyReady_ || isSymmetric(*problem_); }

void NewtonSystem::slack(const Vector& x, Vector& w) const {
  product(x, w);
  w += problem_->b;
}

void NewtonSystem::product(const Vector& v, Vector& out) const {
  if (bodyProducts_) {
    body_->multiply(v, out);
  } else if (problem_->isSparse()) {
    out.noalias() = problem_->sparseA() * v;
  } else {
    out.noalias() = problem_->denseA() * v;
  }
}

int NewtonSystem::linearize(const Vector& x, const Vector& w) {
  const Problem& pb = *problem_;
  const bool coupled = pb.hasFindex();
  int free = 0;
  for (int i = 0; i < pb.size(); ++i) {
    const double lo = pb.effectiveLo(i, x), hi = pb.effectiveHi(i, x), z = x[i] - w[i];
    // The piece of mid(l, z, u) that holds at z; a fixed row (l = u) takes the bound z points at.
    const bool atLo = z < lo || (lo == hi && z <= hi), atHi = !atLo && (z > hi || lo == hi);
    const bool isFree = !atLo && !atHi;
    da_[i] = isFree ? 0.0 : 1.0;
    db_[i] = isFree ? 1.0 : 0.0;
    cf_[i] = 0;
    free += isFree;
    const int f = coupled ? pb.findex[i] : -1;
    if (!isFree && f >= 0) {
      // l_i = lo_i |x_f|, u_i = hi_i |x_f|: minus the bound's derivative in x_f, sign(0) = +1.
      const double sign = x[f] < 0 ? -1.0 : 1.0;
      cf_[i] = -(atHi ? pb.hi[i] : pb.lo[i]) * sign;
    }
  }
  return free;
}

bool NewtonSystem::factor(double rho) { return sparse_ ? factorSparse(rho) : factorDense(rho); }

bool NewtonSystem::factorDense(double rho) {
  const Problem& pb = *problem_;
  const int n = pb.size();
  dense_.setZero(n, n);
  for (int i = 0; i < n; ++i) {
    if (db_[i] != 0) {
      if (pb.isSparse())
        for (SparseMatrix::InnerIterator it(pb.sparseA(), i); it; ++it)
          dense_(i, it.col()) = db_[i] * it.value();
      else
        dense_.row(i) = db_[i] * pb.denseA().row(i);
    }
    dense_(i, i) += da_[i] + db_[i] * rho;
    if (cf_[i] != 0) dense_(i, pb.findex[i]) += cf_[i];
  }
  denseLu_.compute(dense_);
  leastSquares_ = false;
  return true;
}

// The reduced system on the free rows C (newton.hpp, "Linear algebra"): row i of K holds A_ij for
// free j and A_it c_t at the normal j = findex[t] of each bound friction row t whose normal is
// free (c_t = -cf_t), plus rho on the diagonal; columns sorted, duplicates summed.
bool NewtonSystem::factorSparse(double rho) {
  const Problem& pb = *problem_;
  const int n = pb.size();
  const bool coupled = pb.hasFindex();
  freeRows_.clear();
  position_.assign(n, -1);
  for (int i = 0; i < n; ++i)
    if (db_[i] != 0) {
      position_[i] = static_cast<int>(freeRows_.size());
      freeRows_.push_back(i);
    }
  const int m = static_cast<int>(freeRows_.size());
  rho_ = rho;
  useBody_ = false;
  if (m > 0 && bodyReady_ && factorBody(rho)) return true;
  rowStart_.assign(1, 0);
  columns_.clear();
  values_.clear();
  accumulator_.assign(m, 0.0);
  seen_.assign(m, -1);
  std::vector<int>& row = rowColumns_;
  for (int c = 0; c < m; ++c) {
    const int i = freeRows_[c];
    row.clear();
    auto add = [&](int column, double value) {
      if (seen_[column] != c) {
        seen_[column] = c;
        accumulator_[column] = 0;
        row.push_back(column);
      }
      accumulator_[column] += value;
    };
    add(c, rho);
    for (SparseMatrix::InnerIterator it(*a_, i); it; ++it) {
      const int j = static_cast<int>(it.col());
      if (position_[j] >= 0) {
        add(position_[j], it.value());
      } else if (coupled && cf_[j] != 0 && position_[pb.findex[j]] >= 0) {
        add(position_[pb.findex[j]], -cf_[j] * it.value());
      }
    }
    std::sort(row.begin(), row.end());
    for (const int column : row) {
      columns_.push_back(column);
      values_.push_back(accumulator_[column]);
    }
    rowStart_.push_back(static_cast<int>(columns_.size()));
  }
  if (m == 0) return true;
  return lu_.analyze(m, rowStart_, columns_) && lu_.factor(values_);
}

// rhs holds the right side of J dx = rhs (all n rows); on return dx. Rows at a bound: dx_t =
// rhs_t - cf_t dx_findex; their known part moves to the free rows' right side, the free rows
// solve K, and the coupled bound rows follow from their normals.
bool NewtonSystem::solveReduced(Vector& rhs) {
  const Problem& pb = *problem_;
  const int n = pb.size();
  const bool coupled = pb.hasFindex();
  known_.setZero(n);
  for (int t = 0; t < n; ++t) {
    if (position_[t] >= 0) continue;
    const int f = coupled ? pb.findex[t] : -1;
    known_[t] = rhs[t];
    if (f >= 0 && cf_[t] != 0 && position_[f] < 0) known_[t] -= cf_[t] * rhs[f];
  }
  const int m = static_cast<int>(freeRows_.size());
  reduced_.resize(m);
  if (bodyProducts_) {  // (A known)_C through the rows (known is 0 on the free rows)
    body_->multiply(known_, freeRows_, product_);
    for (int c = 0; c < m; ++c) reduced_[c] = rhs[freeRows_[c]] - product_[c];
  } else {
    for (int c = 0; c < m; ++c) {
      const int i = freeRows_[c];
      double sum = rhs[i];
      for (SparseMatrix::InnerIterator it(*a_, i); it; ++it) sum -= it.value() * known_[it.col()];
      reduced_[c] = sum;
    }
  }
  if (m > 0 && !solveFactored(reduced_)) return false;
  for (int c = 0; c < m; ++c) rhs[freeRows_[c]] = reduced_[c];
  for (int t = 0; t < n; ++t) {
    if (position_[t] >= 0) continue;
    const int f = coupled ? pb.findex[t] : -1;
    rhs[t] = f >= 0 && cf_[t] != 0 && position_[f] >= 0 ? rhs[t] - cf_[t] * rhs[f] : known_[t];
  }
  return rhs.allFinite();
}

// K (with rho) in body space: the coupled bound rows (their normal free) are its sliding rows.
bool NewtonSystem::factorBody(double rho) {
  const Problem& pb = *problem_;
  sliding_.clear();
  coeff_.clear();
  for (int t = 0; t < pb.size(); ++t)
    if (position_[t] < 0 && cf_[t] != 0 && position_[findex_[t]] >= 0) {
      sliding_.push_back(t);
      coeff_.push_back(-cf_[t]);
    }
  useBody_ = body_->factor(freeRows_, position_, sliding_, coeff_, findex_, rho, minDiagonal_);
  bodyFactorizations_ += useBody_;
  return useBody_;
}

// y <- K^-1 y with the last factor; in body space with two steps of iterative refinement on K's
// rows (Woodbury's error grows as 1 / min(cfm + rho)).
bool NewtonSystem::solveFactored(Vector& y) {
  if (!useBody_) return lu_.solve(y);
  refine_ = y;
  body_->solve(y);
  for (int pass = 0; pass < kBodyRefinements; ++pass) {
    reducedTimes(y, product_);
    product_ = refine_ - product_;
    body_->solve(product_);
    y += product_;
    if (product_.squaredNorm() <= kRefinedEnough * kRefinedEnough * y.squaredNorm()) break;
  }
  return y.allFinite();
}

// out = K y on the free rows: row i's A_ij at free j, A_it c_t at the free normal of a coupled t.
// In body space: (A z)_C + rho y with z = y on the free rows, c_t y_n(t) on the coupled ones.
void NewtonSystem::reducedTimes(const Vector& y, Vector& out) const {
  const int m = static_cast<int>(freeRows_.size());
  if (bodyProducts_ && useBody_) {  // sliding_ and coeff_ are the last body factor's
    spread_.setZero(problem_->size());
    for (int c = 0; c < m; ++c) spread_[freeRows_[c]] = y[c];
    for (size_t k = 0; k < sliding_.size(); ++k)
      spread_[sliding_[k]] = coeff_[k] * y[position_[findex_[sliding_[k]]]];
    body_->multiply(spread_, freeRows_, out);
    out += rho_ * y;
    return;
  }
  out.resize(m);
  for (int c = 0; c < m; ++c) {
    double sum = rho_ * y[c];
    for (SparseMatrix::InnerIterator it(*a_, freeRows_[c]); it; ++it) {
      const int j = static_cast<int>(it.col());
      if (position_[j] >= 0)
        sum += it.value() * y[position_[j]];
      else if (cf_[j] != 0 && findex_[j] >= 0 && position_[findex_[j]] >= 0)
        sum -= cf_[j] * it.value() * y[position_[findex_[j]]];
    }
    out[c] = sum;
  }
}

bool NewtonSystem::solve(Vector& rhs) {
  if (sparse_) return solveReduced(rhs);
  // Partial pivoting first; a (near) singular J, seen as a solution that does not solve the
  // system, is answered by the least-squares solution of least norm.
  check_ = denseLu_.solve(rhs);
  if (check_.allFinite() &&
      (dense_ * check_ - rhs).lpNorm<Eigen::Infinity>() <=
          1e-9 * (1 + rhs.lpNorm<Eigen::Infinity>()) * (1 + check_.lpNorm<Eigen::Infinity>())) {
    rhs.swap(check_);
    return true;
  }
  if (!leastSquares_) {
    cod_.compute(dense_);
    leastSquares_ = true;
  }
  rhs = cod_.solve(rhs).eval();
  return rhs.allFinite();
}

bool NewtonSystem::solveRegularized(double lambda, Vector& rhs) {
  if (sparse_) return false;
  normal_.noalias() = dense_.transpose() * dense_;
  normal_.diagonal().array() += lambda;
  rhs = normal_.llt().solve(dense_.transpose() * rhs).eval();
  return rhs.allFinite();
}

void NewtonSystem::times(const Vector& v, Vector& out) const {
  const Problem& pb = *problem_;
  const int n = pb.size();
  if (bodyProducts_) body_->multiply(v, scratch_);
  out.resize(n);
  for (int i = 0; i < n; ++i) {
    const double av = db_[i] == 0 ? 0.0 : bodyProducts_ ? scratch_[i] : pb.rowDot(i, v);
    out[i] = da_[i] * v[i] + db_[i] * av;
    if (cf_[i] != 0) out[i] += cf_[i] * v[pb.findex[i]];
  }
}

// out = J^T v. In body space A^T (db v) = A (db v): A from rows is symmetric.
void NewtonSystem::transposeTimes(const Vector& v, Vector& out) const {
  const Problem& pb = *problem_;
  const int n = pb.size();
  if (bodyProducts_) {
    spread_ = db_.cwiseProduct(v);
    body_->multiply(spread_, out);
    for (int i = 0; i < n; ++i) {
      out[i] += da_[i] * v[i];
      if (cf_[i] != 0) out[pb.findex[i]] += cf_[i] * v[i];
    }
    return;
  }
  out.setZero(n);
  for (int i = 0; i < n; ++i) {
    const double vi = db_[i] * v[i];
    if (vi != 0) {
      if (pb.isSparse())
        for (SparseMatrix::InnerIterator it(pb.sparseA(), i); it; ++it)
          out[it.col()] += vi * it.value();
      else
        out += vi * pb.denseA().row(i).transpose();
    }
    out[i] += da_[i] * v[i];
    if (cf_[i] != 0) out[pb.findex[i]] += cf_[i] * v[i];
  }
}

}  // namespace mlcp::detail
