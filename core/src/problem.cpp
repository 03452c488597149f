#include "mlcp/problem.hpp"

#include <cmath>
#include <optional>
#include <sstream>

namespace mlcp {

const char* toString(ProblemClass c) {
  switch (c) {
    case ProblemClass::Empty: return "empty";
    case ProblemClass::Linear: return "linear";
    case ProblemClass::StandardLcp: return "standard-lcp";
    case ProblemClass::Boxed: return "boxed";
    case ProblemClass::Findex: return "findex";
  }
  return "unknown";
}

Problem::Problem(DenseMatrix A, Vector bIn) : b(std::move(bIn)) {
  setA(std::move(A));
  lo = Vector::Zero(b.size());
  hi = Vector::Constant(b.size(), kInf);
}

Problem::Problem(SparseMatrix A, Vector bIn) : b(std::move(bIn)) {
  setA(std::move(A));
  lo = Vector::Zero(b.size());
  hi = Vector::Constant(b.size(), kInf);
}

void Problem::setA(DenseMatrix A) {
  dense_ = std::move(A);
  sparseA_ = SparseMatrix();
  sparse_ = false;
}

void Problem::setA(SparseMatrix A) {
  sparseA_ = std::move(A);
  sparseA_.makeCompressed();
  dense_ = DenseMatrix();
  sparse_ = true;
}

// The other kind's storage is empty already unless the kind changes (setA and swapA empty it);
// resetting it anyway would allocate (an empty SparseMatrix holds an outer index).
void Problem::swapA(DenseMatrix& A) {
  dense_.swap(A);
  if (sparse_) sparseA_ = SparseMatrix();
  sparse_ = false;
}

void Problem::swapA(SparseMatrix& A) {
  sparseA_.swap(A);
  sparseA_.makeCompressed();
  if (!sparse_) dense_ = DenseMatrix();
  sparse_ = true;
}

DenseMatrix Problem::toDense() const { return sparse_ ? DenseMatrix(sparseA_) : dense_; }

SparseMatrix Problem::toSparse() const {
  if (sparse_) return sparseA_;
  SparseMatrix s = dense_.sparseView(0.0, 0.0);
  s.makeCompressed();
  return s;
}

double Problem::diagonal(int i) const { return sparse_ ? sparseA_.coeff(i, i) : dense_(i, i); }

double Problem::rowDot(int i, const Vector& x) const {
  if (!sparse_) return dense_.row(i).dot(x);
  double s = 0;
  for (SparseMatrix::InnerIterator it(sparseA_, i); it; ++it) s += it.value() * x[it.col()];
  return s;
}

Vector Problem::slack(const Vector& x) const {
  if (sparse_) return sparseA_ * x + b;
  return dense_ * x + b;
}

bool Problem::hasFindex() const {
  for (int f : findex)
    if (f >= 0) return true;
  return false;
}

double Problem::effectiveLo(int i, const Vector& x) const {
  if (findex.empty() || findex[i] < 0) return lo[i];
  return lo[i] * std::abs(x[findex[i]]);
}

double Problem::effectiveHi(int i, const Vector& x) const {
  if (findex.empty() || findex[i] < 0) return hi[i];
  return hi[i] * std::abs(x[findex[i]]);
}

namespace {

template <class M>
std::string firstNonFinite(const M& m) {
  // NaN/Inf * 0 is NaN, anything else 0: one vectorized sum; the search only names the entry.
  if (std::isfinite((m.array() * 0.0).sum())) return "";
  for (int i = 0; i < m.rows(); ++i)
    for (int j = 0; j < m.cols(); ++j)
      if (!std::isfinite(m(i, j))) {
        std::ostringstream os;
        os << "A(" << i << "," << j << ") is " << m(i, j);
        return os.str();
      }
  return "";
}

std::string firstNonFiniteSparse(const SparseMatrix& m) {
  if (Eigen::Map<const Vector>(m.valuePtr(), m.nonZeros()).allFinite()) return "";
  for (int i = 0; i < m.outerSize(); ++i)
    for (SparseMatrix::InnerIterator it(m, i); it; ++it)
      if (!std::isfinite(it.value())) {
        std::ostringstream os;
        os << "A(" << it.row() << "," << it.col() << ") is " << it.value();
        return os.str();
      }
  return "";
}

}  // namespace

namespace {

// An ostringstream made on the first write: constructing one costs a locale set-up, and
// validate() runs before every solve while its messages are needed only when something is wrong.
class LazyMessage {
 public:
  template <class T>
  std::ostream& operator<<(const T& v) {
    if (!os_) os_.emplace();
    return *os_ << v;
  }
  std::string str() const { return os_ ? os_->str() : std::string(); }

 private:
  std::optional<std::ostringstream> os_;
};

}  // namespace

namespace {

// The usual case, checked in one pass with no branch per row: true when nothing is wrong. False
// sends validate() through its search for the first thing that is.
bool certainlyValid(const Problem& p) {
  const Eigen::Index n = p.b.size();
  const bool sparse = p.isSparse();
  const Eigen::Index rows = sparse ? p.sparseA().rows() : p.denseA().rows();
  const Eigen::Index cols = sparse ? p.sparseA().cols() : p.denseA().cols();
  if (rows != n || cols != n || p.lo.size() != n || p.hi.size() != n) return false;
  if (!p.findex.empty() && static_cast<Eigen::Index>(p.findex.size()) != n) return false;
  bool ok = true;
  // Bitwise & on ints (no branch per term); lo <= hi is false for a NaN bound.
  for (Eigen::Index i = 0; i < n; ++i)
    ok &= static_cast<bool>(int{std::isfinite(p.b[i])} & int{p.lo[i] <= p.hi[i]} &
                            int{p.lo[i] < kInf} & int{p.hi[i] > -kInf});
  const std::vector<int>& fx = p.findex;
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(fx.size()); ++i) {
    const int f = fx[i];
    if (f == -1) continue;
    // A friction row: coupled to an uncoupled other row, bounds -mu..mu with finite mu >= 0.
    ok &= f >= 0 && f < n && f != i && fx[f] < 0 && p.hi[i] >= 0 && p.hi[i] < kInf &&
          p.lo[i] == -p.hi[i];
  }
  return ok && (sparse ? firstNonFiniteSparse(p.sparseA()) : firstNonFinite(p.denseA())).empty();
}

}  // namespace

std::string Problem::validate() const {
  if (certainlyValid(*this)) return "";
  LazyMessage os;
  const Eigen::Index n = b.size();
  const Eigen::Index rows = sparse_ ? sparseA_.rows() : dense_.rows();
  const Eigen::Index cols = sparse_ ? sparseA_.cols() : dense_.cols();
  if (rows != n || cols != n) {
    os << "A is " << rows << "x" << cols << " but b has " << n << " entries (A must be n x n)";
    return os.str();
  }
  if (lo.size() != n) {
    os << "lo has " << lo.size() << " entries, expected " << n;
    return os.str();
  }
  if (hi.size() != n) {
    os << "hi has " << hi.size() << " entries, expected " << n;
    return os.str();
  }
  if (!findex.empty() && static_cast<Eigen::Index>(findex.size()) != n) {
    os << "findex has " << findex.size() << " entries, expected " << n << " (or none)";
    return os.str();
  }
  std::string bad = sparse_ ? firstNonFiniteSparse(sparseA_) : firstNonFinite(dense_);
  if (!bad.empty()) return bad + " (A must be finite)";
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(b[i])) {
      os << "b[" << i << "] is " << b[i] << " (b must be finite)";
      return os.str();
    }
    if (std::isnan(lo[i]) || std::isnan(hi[i])) {
      os << "bound of row " << i << " is NaN";
      return os.str();
    }
    if (lo[i] > hi[i]) {
      os << "row " << i << ": lo = " << lo[i] << " > hi = " << hi[i];
      return os.str();
    }
    if (lo[i] == kInf || hi[i] == -kInf) {
      os << "row " << i << ": bounds [" << lo[i] << ", " << hi[i] << "] admit no finite x";
      return os.str();
    }
  }
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(findex.size()); ++i) {
    const int f = findex[i];
    if (f < -1 || f >= n) {
      os << "findex[" << i << "] = " << f << " is out of range [-1, " << n - 1 << "]";
      return os.str();
    }
    if (f < 0) continue;
    if (f == i) {
      os << "findex[" << i << "] points at its own row";
      return os.str();
    }
    if (findex[f] >= 0) {
      os << "findex[" << i << "] = " << f << " points at a row that is itself friction-coupled "
         << "(findex[" << f << "] = " << findex[f] << "); chains are not allowed";
      return os.str();
    }
    if (!(hi[i] >= 0) || !std::isfinite(hi[i]) || lo[i] != -hi[i]) {
      os << "friction row " << i << " (findex " << f << ") has bounds [" << lo[i] << ", " << hi[i]
         << "]; expected [-mu, mu] with finite mu >= 0";
      return os.str();
    }
  }
  return "";
}

ProblemClass classifyBounds(const Vector& lo, const Vector& hi, const std::vector<int>& findex) {
  if (lo.size() == 0) return ProblemClass::Empty;
  for (int f : findex)
    if (f >= 0) return ProblemClass::Findex;
  bool allFree = true, allStandard = true;
  for (Eigen::Index i = 0; i < lo.size(); ++i) {
    const bool freeRow = isFreeRow(lo[i], hi[i]);
    const bool standardRow = lo[i] == 0 && hi[i] == kInf;
    allFree = allFree && freeRow;
    allStandard = allStandard && standardRow;
  }
  if (allFree) return ProblemClass::Linear;
  if (allStandard) return ProblemClass::StandardLcp;
  return ProblemClass::Boxed;
}

bool hasFreeRows(const Vector& lo, const Vector& hi) {
  for (Eigen::Index i = 0; i < lo.size(); ++i)
    if (isFreeRow(lo[i], hi[i])) return true;
  return false;
}

ProblemClass Problem::classify() const {
  if (size() == 0) return ProblemClass::Empty;
  return classifyBounds(lo, hi, findex);
}

}  // namespace mlcp
