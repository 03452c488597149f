#include "pivoting/lemke_revised.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "linalg/sparse_lu.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp::detail {

namespace {

// Ties of the ratio test up to this many keep their rows of B^-1 for the column-by-column
// lexicographic filter (as the tableau does); more are decided pairwise, two rows at a time.
constexpr size_t kStoredRows = 64;

// Iterative refinement steps a refactorization spends on basic values whose backward error
// exceeds kLemkeBackwardError, and wrong bases a run recovers from before it ends as it would.
constexpr int kRefinementSteps = 2;
constexpr int kMaxRecoveries = 3;

// The basis matrix B = B0 E_1 ... E_k: a KLU factor of B0 and the eta file.
class FactoredBasis {
 public:
  FactoredBasis(const ColumnMatrix& M, const Vector& cover,
                double pivotThreshold = kLemkeBasisPivotThreshold)
      : M_(M), m_(static_cast<int>(M.cols())), cover_(cover) {
    lu_.setPivotTolerance(pivotThreshold);
  }

  void setPivotThreshold(double t) { lu_.setPivotTolerance(t); }

  // out <- the column of variable v in [I, -M, -c].
  void column(int v, Vector& out) const {
    out.setZero(m_);
    if (v < m_) {
      out[v] = 1;
    } else if (v < 2 * m_) {
      for (ColumnMatrix::InnerIterator it(M_, v - m_); it; ++it) out[it.row()] = -it.value();
    } else {
      out = -cover_;
    }
  }

  // Factors the basis matrix of `basis` and empties the eta file. False when it is singular.
  bool factor(const std::vector<int>& basis) {
    // B by columns is B' by rows, the form SparseLu takes: its solve() is then B' y = c and
    // solveTransposed() B y = c.
    colStart_.assign(1, 0);
    rows_.clear();
    values_.clear();
    for (int v : basis) {
      if (v < m_) {
        push(v, 1.0);
      } else if (v < 2 * m_) {
        for (ColumnMatrix::InnerIterator it(M_, v - m_); it; ++it) push(it.row(), -it.value());
      } else {
        for (int i = 0; i < m_; ++i)
          if (cover_[i] != 0) push(i, -cover_[i]);
      }
      colStart_.push_back(static_cast<int>(rows_.size()));
    }
    etas_.clear();
    etaIndex_.clear();
    etaValue_.clear();
    denseValue_.clear();
    return lu_.analyze(m_, colStart_, rows_) && lu_.factor(values_);
  }

  // y <- B^-1 y.
  bool ftran(Vector& y) {
    if (!lu_.solveTransposed(y)) return false;
    for (const Eta& e : etas_) {
      const double yr = y[e.row] / e.pivot;
      if (e.dense) {
        y -= Eigen::Map<const Vector>(&denseValue_[e.begin], m_) * yr;
      } else {
        for (size_t k = e.begin; k < e.end; ++k) y[etaIndex_[k]] -= etaValue_[k] * yr;
      }
      y[e.row] = yr;
    }
    return y.allFinite();
  }

  // y <- B^-T y.
  bool btran(Vector& y) {
    for (auto e = etas_.rbegin(); e != etas_.rend(); ++e) {
      double s = y[e->row];
      if (e->dense) {
        s -= Eigen::Map<const Vector>(&denseValue_[e->begin], m_).dot(y);
      } else {
        for (size_t k = e->begin; k < e->end; ++k) s -= etaValue_[k] * y[etaIndex_[k]];
      }
      y[e->row] = s / e->pivot;
    }
    return lu_.solve(y);
  }

  // Records the pivot on row r with the tableau column d = B^-1 a: its nonzeros with their rows,
  // or, when they are over a third of the column, all m entries (d_r stored as 0), which the
  // solves apply as one vector operation.
  void update(int r, const Vector& d) {
    Eta e;
    e.row = r;
    e.pivot = d[r];
    const Eigen::Index nonzeros = (d.array() != 0).count() - (d[r] != 0);
    e.dense = 3 * nonzeros > m_;
    if (e.dense) {
      e.begin = denseValue_.size();
      denseValue_.insert(denseValue_.end(), d.data(), d.data() + m_);
      denseValue_[e.begin + r] = 0;
    } else {
      e.begin = etaIndex_.size();
      for (int i = 0; i < m_; ++i)
        if (i != r && d[i] != 0) {
          etaIndex_.push_back(i);
          etaValue_.push_back(d[i]);
        }
    }
    e.end = e.dense ? e.begin + m_ : etaIndex_.size();
    etas_.push_back(e);
  }

  int etas() const { return static_cast<int>(etas_.size()); }

  // The backward error of x as the basic values of `basis`: ||B x - q||_inf / (||q||_inf +
  // ||B||_inf ||x||_inf), O(nnz B). Scale-free and blind to B's conditioning: what an accurate
  // solve leaves is a few units of round-off whatever the basis. r <- q - B x.
  double backwardError(const std::vector<int>& basis, const Vector& x, const Vector& q,
                       Vector& r) const {
    r = -q;
    Vector rowSum = Vector::Zero(m_);
    for (int k = 0; k < m_; ++k) {
      const int v = basis[k];
      if (v < m_) {
        r[v] += x[k];
        rowSum[v] += 1;
      } else if (v < 2 * m_) {
        for (ColumnMatrix::InnerIterator it(M_, v - m_); it; ++it) {
          r[it.row()] -= it.value() * x[k];
          rowSum[it.row()] += std::abs(it.value());
        }
      } else {
        r -= cover_ * x[k];
        rowSum += cover_.cwiseAbs();
      }
    }
    const double scale =
        q.lpNorm<Eigen::Infinity>() + rowSum.maxCoeff() * x.lpNorm<Eigen::Infinity>();
    r = -r;
    return scale > 0 ? r.lpNorm<Eigen::Infinity>() / scale : 0.0;
  }

 private:
  void push(int row, double value) {
    rows_.push_back(row);
    values_.push_back(value);
  }
  struct Eta {
    int row = 0;
    double pivot = 1;
    bool dense = false;
    size_t begin = 0, end = 0;  // into etaIndex_ and etaValue_, or denseValue_
  };
  const ColumnMatrix& M_;
  int m_;
  Vector cover_;
  linalg::SparseLu lu_;
  std::vector<Eta> etas_;
  std::vector<int> etaIndex_;
  std::vector<double> etaValue_, denseValue_;
  std::vector<int> colStart_, rows_;
  std::vector<double> values_;
};

class RevisedRun {
 public:
  RevisedRun(const ColumnMatrix& M, const Vector& q, const RevisedLemkeSettings& s,
             const Vector& cover)
      : m_(static_cast<int>(M.cols())),
        q_(q),
        s_(s),
        basis_(M, cover, s.basisPivotThreshold),
        period_(s.refactorPeriod),
        strict_(s.basisPivotThreshold >= 1.0) {}

  // Runs from `basis` (the slack basis, or a warm one whose covering vector is `cover`).
  LemkeOutcome run(std::vector<int> basis, int maxPivots, RevisedLemkeResult& res) {
    LemkeOutcome out;
    order_ = std::move(basis);
    if (refactor(res, /*checkUpdates=*/false) == Check::Singular) return singular(out, res);
    bool feasible = true;
    for (int i = 0; i < m_; ++i) feasible = feasible && !(x_[i] < 0);
    if (feasible) return out;
    const ToleranceRules& rules = s_.rules;
    int entering = 2 * m_;
    int row = 0;
    for (int i = 1; i < m_; ++i)
      if (rules.compare(x_[i], x_[row]) <= 0) row = i;
    saved_ = {order_, entering, row};
    Vector d;
    if (!enteringColumn(entering, d)) return singular(out, res);
    for (;;) {
      if (out.pivots >= maxPivots) {
        out.end = LemkeEnd::PivotLimit;
        return out;
      }
      if (s_.stop && s_.stop()) {
        out.end = LemkeEnd::Stopped;
        return out;
      }
      const int leaving = order_[row];
      const double theta = x_[row] / d[row];
      x_ -= theta * d;
      x_[row] = theta;
      order_[row] = entering;
      basis_.update(row, d);
      ++out.pivots;
      // The end is checked too: a wrong basis is seen before it is returned.
      if (basis_.etas() >= period_ || leaving == 2 * m_) {
        const Check c = refactor(res, true);
        if (c == Check::Singular) return singular(out, res);
        if (c == Check::Wrong && res.recoveries < kMaxRecoveries) {
          // Back to the last basis checked right, with strict pivoting and a shorter period.
          ++res.recoveries;
          strictPivoting();
          period_ = std::max(4, period_ / 2);
          order_ = saved_.order;
          if (refactor(res, false) == Check::Singular) return singular(out, res);
          entering = saved_.entering;
          row = saved_.row;
          if (!enteringColumn(entering, d)) return singular(out, res);
          continue;
        }
        if (c == Check::Right && leaving != 2 * m_) {
          const int next = leaving < m_ ? leaving + m_ : leaving - m_;
          if (!enteringColumn(next, d)) return singular(out, res);
          saved_ = {order_, next, leavingRow(d)};
          if (saved_.row < 0) {
            out.end = LemkeEnd::Ray;
            out.entering = next;
            return out;
          }
          entering = next;
          row = saved_.row;
          continue;
        }
      }
      if (leaving == 2 * m_) return out;
      entering = leaving < m_ ? leaving + m_ : leaving - m_;
      if (!enteringColumn(entering, d)) return singular(out, res);
      row = leavingRow(d);
      if (row < 0) {
        out.end = LemkeEnd::Ray;
        out.entering = entering;
        return out;
      }
    }
  }

  const std::vector<int>& order() const { return order_; }
  const Vector& values() const { return x_; }

 private:
  static LemkeOutcome& singular(LemkeOutcome& out, RevisedLemkeResult& res) {
    res.singular = true;
    out.end = LemkeEnd::Ray;
    return out;
  }

  bool enteringColumn(int v, Vector& d) {
    basis_.column(v, d);
    return basis_.ftran(d);
  }

  // What a refactorization found: the basic values B^-1 q accurate and feasible (Right), not
  // (Wrong: the basis or its factor went wrong somewhere), or B singular.
  enum class Check { Right, Wrong, Singular };

  // Factors B again and recomputes x_B = B^-1 q, refined while its backward error exceeds
  // kLemkeBackwardError (thresholds.hpp); halves the period when the eta-updated values it
  // replaces had a backward error above it. Why not their forward drift from the fresh values:
  // that measures B's conditioning, which a factorization cannot change (the cone LCP of a
  // 55-box pyramid drifts 1e-8 at backward errors of 1e-13, and a drift rule refactored it
  // every 4 pivots). Wrong: the fresh values stay inaccurate, or one is below
  // -kLemkeInfeasibility (1 + max |x_B|), which a right path never leaves (its values are >= 0
  // up to round-off).
  Check refactor(RevisedLemkeResult& res, bool checkUpdates) {
    ++res.refactorizations;
    Vector fresh = q_, r;
    if (!basis_.factor(order_) || !basis_.ftran(fresh)) return Check::Singular;
    double error = basis_.backwardError(order_, fresh, q_, r);
    if (error > kLemkeBackwardError && !strict_) {
      // The factor itself is inaccurate: replaced by plain partial pivoting's before any entering
      // column is solved with it.
      ++res.recoveries;
      strictPivoting();
      fresh = q_;
      if (!basis_.factor(order_) || !basis_.ftran(fresh)) return Check::Singular;
      error = basis_.backwardError(order_, fresh, q_, r);
    }
    for (int k = 0; k < kRefinementSteps && error > kLemkeBackwardError; ++k) {
      if (!basis_.ftran(r)) return Check::Singular;
      Vector refined = fresh + r, rr;
      const double e = basis_.backwardError(order_, refined, q_, rr);
      if (!(e < error)) break;
      fresh.swap(refined);
      r.swap(rr);
      error = e;
    }
    if (checkUpdates && basis_.backwardError(order_, x_, q_, r) > kLemkeBackwardError)
      period_ = std::max(4, period_ / 2);
    x_ = std::move(fresh);
    const double floor = -kLemkeInfeasibility * (1 + x_.lpNorm<Eigen::Infinity>());
    return error <= kLemkeBackwardError && x_.minCoeff() >= floor ? Check::Right : Check::Wrong;
  }

  void strictPivoting() {
    strict_ = true;
    basis_.setPivotThreshold(1.0);
  }

  // Row e_i' B^-1.
  Vector inverseRow(int i) {
    Vector r = Vector::Zero(m_);
    r[i] = 1;
    basis_.btran(r);
    return r;
  }

  // The minimum-ratio test with the lexicographic tie-break of LemkeTableau::leavingRow, on the
  // column d = B^-1 a; -1 when d has no positive entry.
  int leavingRow(const Vector& d) {
    const ToleranceRules& rules = s_.rules;
    const double colMax = d.lpNorm<Eigen::Infinity>();
    // Two passes over the column: the ratios (+inf where the entry is not a pivot) and their
    // minimum, then the rows tied with it.
    constexpr double kNone = std::numeric_limits<double>::infinity();
    ratio_.resize(m_);
    double best = kNone;
    for (int i = 0; i < m_; ++i) {
      ratio_[i] = rules.positive(d[i], colMax) ? rules.clampRhs(x_[i]) / d[i] : kNone;
      best = std::min(best, ratio_[i]);
    }
    if (best == kNone) return -1;
    std::vector<int> ties;
    for (int i = 0; i < m_; ++i)
      if (ratio_[i] != kNone && rules.compare(ratio_[i], best) == 0) ties.push_back(i);
    for (int i : ties)
      if (order_[i] == 2 * m_) return i;
    if (ties.size() > 1)
      ties = ties.size() <= kStoredRows ? byStoredRows(ties, d) : byPairs(ties, d);
    // Only round-off can leave two rows here (B^-1 has independent rows): the larger pivot.
    int row = ties[0];
    for (int i : ties)
      if (d[row] < d[i]) row = i;
    return row;
  }

  // Column-by-column filter over the rows of B^-1 / d_i, as the tableau does.
  std::vector<int> byStoredRows(std::vector<int> ties, const Vector& d) {
    std::vector<Vector> rows;
    std::vector<int> at(m_, -1);
    for (int i : ties) {
      at[i] = static_cast<int>(rows.size());
      rows.push_back(inverseRow(i));
    }
    auto key = [&](int i, int k) { return rows[at[i]][k] / d[i]; };
    for (int k = 0; k < m_ && ties.size() > 1; ++k) {
      double best = key(ties[0], k);
      for (int i : ties) best = std::min(best, key(i, k));
      std::vector<int> kept;
      for (int i : ties)
        if (s_.rules.compare(key(i, k), best) == 0) kept.push_back(i);
      ties.swap(kept);
    }
    return ties;
  }

  // The lexicographic minimum by pairwise comparison, two rows of B^-1 in memory at a time.
  std::vector<int> byPairs(const std::vector<int>& ties, const Vector& d) {
    int best = ties[0];
    Vector bestRow = inverseRow(best);
    for (size_t t = 1; t < ties.size(); ++t) {
      const int i = ties[t];
      const Vector row = inverseRow(i);
      for (int k = 0; k < m_; ++k) {
        const int c = s_.rules.compare(row[k] / d[i], bestRow[k] / d[best]);
        if (c == 0) continue;
        if (c < 0) {
          best = i;
          bestRow = row;
        }
        break;
      }
    }
    return {best};
  }

  // The last basis checked right, the variable entering it and its row.
  struct Saved {
    std::vector<int> order;
    int entering = 0;
    int row = 0;
  };

  int m_;
  const Vector& q_;
  const RevisedLemkeSettings& s_;
  FactoredBasis basis_;
  int period_;
  bool strict_;  // B is factored with plain partial pivoting
  std::vector<int> order_;
  Vector x_;
  Vector ratio_;  // leavingRow's ratios (scratch)
  Saved saved_;
};

bool complementary(const std::vector<int>& basis, int m) {
  if (static_cast<int>(basis.size()) != m) return false;
  std::vector<bool> seen(m, false);
  for (int v : basis) {
    if (v < 0 || v >= 2 * m || seen[v % m]) return false;
    seen[v % m] = true;
  }
  return true;
}

void finish(const RevisedRun& run, int m, RevisedLemkeResult& res) {
  res.basis = run.order();
  res.y = Vector::Zero(m);
  res.yBasic.assign(m, false);
  for (int r = 0; r < m; ++r) {
    const int v = res.basis[r];
    if (v >= m && v < 2 * m) {
      res.y[v - m] = std::max(run.values()[r], 0.0);
      res.yBasic[v - m] = true;
    }
  }
}

}  // namespace

RevisedLemkeResult revisedLemke(const ColumnMatrix& M, const Vector& q,
                                const RevisedLemkeSettings& settings) {
  const int m = static_cast<int>(M.cols());
  RevisedLemkeResult res;
  const int maxPivots = std::max(1, settings.maxPivots);
  std::vector<int> slack(m);
  for (int i = 0; i < m; ++i) slack[i] = i;
  if (complementary(settings.warmBasis, m) && settings.warmBasis != slack) {
    // Covering vector B0 e: z0's column is -e in the warm basis, as it is in the slack one. It
    // need not be positive, so the guarantees are the cold start's: a warm attempt that ends on
    // a ray, a singular basis or half the pivots is followed by a cold start.
    Vector cover = Vector::Zero(m);
    for (int v : settings.warmBasis) {
      Vector c;
      FactoredBasis(M, cover).column(v, c);
      cover += c;
    }
    RevisedRun warm(M, q, settings, cover);
    RevisedLemkeResult attempt;
    attempt.outcome = warm.run(settings.warmBasis, std::max(1, maxPivots / 2), attempt);
    res.refactorizations += attempt.refactorizations;
    res.recoveries += attempt.recoveries;
    if (attempt.outcome.end == LemkeEnd::Solved || attempt.outcome.end == LemkeEnd::Stopped) {
      res.outcome = attempt.outcome;
      res.refactorizations = attempt.refactorizations;
      res.recoveries = attempt.recoveries;
      finish(warm, m, res);
      return res;
    }
    res.outcome.pivots = attempt.outcome.pivots;
  }
  const int before = res.outcome.pivots;
  RevisedRun cold(M, q, settings, Vector::Ones(m));
  res.singular = false;
  res.outcome = cold.run(slack, std::max(0, maxPivots - before), res);
  res.outcome.pivots += before;
  finish(cold, m, res);
  return res;
}

}  // namespace mlcp::detail
