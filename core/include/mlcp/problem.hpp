// mlcp/problem.hpp: the canonical mixed linear complementarity problem.
//
// Find x and w with
//
//     w = A x + b,    lo <= x <= hi,
//
// and, for every row i,
//
//     x_i = lo_i        =>  w_i >= 0
//     x_i = hi_i        =>  w_i <= 0
//     lo_i < x_i < hi_i =>  w_i  = 0.
//
// lo may be -inf and hi +inf. A row with (-inf, +inf) is an equality (a bilateral joint row);
// (0, +inf) is a standard LCP row. This is the `Ax + b >= 0` form of the LCP literature. ODE and
// Bullet write `A x = b + w`: their b is minus ours, and the conversion happens in the adapters
// only.
//
// Friction coupling: findex[i] = j >= 0 makes row i's effective bounds
//
//     lo'_i = lo_i * |x_j|,   hi'_i = hi_i * |x_j|,
//
// where lo_i = -mu and hi_i = +mu (ODE's and Bullet's convention). findex[i] = -1 means none.
// Rows may only point at rows that are themselves uncoupled (no chains).
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <limits>
#include <string>
#include <vector>

namespace mlcp {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

using Vector = Eigen::VectorXd;
using DenseMatrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// What kind of problem this is; solvers and `auto` choose by it.
enum class ProblemClass {
  Empty,        // n == 0
  Linear,       // every row an equality: a linear system A x = -b
  StandardLcp,  // every row [0, +inf)
  Boxed,        // general bounds (possibly mixed with equality rows), no findex
  Findex,       // at least one friction-coupled row
};
const char* toString(ProblemClass c);
// The class from the bounds and findex alone (size n = lo.size(); findex may be empty).
ProblemClass classifyBounds(const Vector& lo, const Vector& hi, const std::vector<int>& findex);
// A free row, lo = -inf and hi = +inf: an equality (a joint's bilateral row), w = 0 at the answer.
inline bool isFreeRow(double lo, double hi) { return lo == -kInf && hi == kInf; }
// Whether any row is free.
bool hasFreeRows(const Vector& lo, const Vector& hi);

class Problem {
 public:
  Problem() = default;
  // A dense problem with default bounds lo = 0, hi = +inf (a standard LCP) and no findex.
  Problem(DenseMatrix A, Vector b);
  // A sparse problem with default bounds lo = 0, hi = +inf and no findex.
  Problem(SparseMatrix A, Vector b);

  int size() const { return static_cast<int>(b.size()); }
  bool isSparse() const { return sparse_; }

  // The matrix. Exactly one storage is used; the other is empty.
  const DenseMatrix& denseA() const { return dense_; }
  const SparseMatrix& sparseA() const { return sparseA_; }
  // A copy of A in dense storage (converts if sparse).
  DenseMatrix toDense() const;
  // A copy of A in sparse storage (converts if dense; drops exact zeros).
  SparseMatrix toSparse() const;
  void setA(DenseMatrix A);
  void setA(SparseMatrix A);
  // Exchanges A's storage with `A` in O(1), copying nothing: a caller that refills A every step
  // (RowSystem::assemble) takes the buffer out, writes it and swaps it back, allocating nothing
  // once the size has been seen. Afterwards the problem holds the given matrix (compressed, for
  // sparse storage; the other kind is emptied) and `A` what the problem held of that kind.
  void swapA(DenseMatrix& A);
  void swapA(SparseMatrix& A);

  // A_ii, read from whichever storage holds A.
  double diagonal(int i) const;
  // Row i of A times x.
  double rowDot(int i, const Vector& x) const;
  // w = A x + b.
  Vector slack(const Vector& x) const;

  // Returns "" when the problem is well formed, otherwise a message naming the first thing
  // wrong (sizes, NaN/Inf in A or b, NaN in the bounds, lo > hi, findex out of range, chained
  // or self-referencing, friction rows whose bounds are not -mu..mu).
  std::string validate() const;
  bool hasFindex() const;
  ProblemClass classify() const;

  // Effective bounds of row i at the point x (findex applied).
  double effectiveLo(int i, const Vector& x) const;
  double effectiveHi(int i, const Vector& x) const;

  Vector b;                 // size n
  Vector lo;                // size n, may hold -inf
  Vector hi;                // size n, may hold +inf
  std::vector<int> findex;  // size n or empty (= all -1)

 private:
  bool sparse_ = false;
  DenseMatrix dense_;
  SparseMatrix sparseA_;
};

}  // namespace mlcp
