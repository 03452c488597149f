// The generalized Jacobian of the natural map and its linear solves for NewtonSolver
// (docs/methods/newton.md, "Jacobian" and "Linear algebra"; mlcp/solvers/newton.hpp). Internal
// to the library.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "linalg/sparse_lu.hpp"
#include "linalg/symmetry.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/rows.hpp"

namespace mlcp::detail {

class BodySpaceSystem;

// The natural map h = x - mid(l(x), x - w, u(x)) at x with w = A x + b (friction bounds at x).
// Returns ||h||_2^2 (+inf when not finite); inf gets ||h||_inf.
double naturalMap(const Problem& problem, const Vector& x, const Vector& w, Vector& h, double& inf);

class NewtonSystem {
 public:
  NewtonSystem();
  ~NewtonSystem();
  // The rows the next prepared problem was assembled from (A = J W J^T + diag(cfm)), or null.
  // With them the sparse path solves the reduced system in body space when that applies.
  void useRows(const RowSystem* rows) { rows_ = rows; }
  const RowSystem* rows() const { return rows_; }
  // Of the last solve: factorizations done in body space.
  int bodyFactorizations() const { return bodyFactorizations_; }
  // Per solve, before the steps: the problem (kept by reference until the next prepare); whole
  // problems of at most denseFactorMaxRows rows take the dense path.
  void prepare(const Problem& problem, int denseFactorMaxRows);
  // The Jacobian's rows at (x, w): free rows (x - w strictly inside the bounds) take row i of
  // A, the others e_i minus the bound's derivative in the normal. Returns the free rows' count.
  int linearize(const Vector& x, const Vector& w);
  // Factors J + rho D (D: 1 on the free rows, 0 elsewhere); the sparse path its reduced system
  // on the free rows. False when it is singular (sparse path; the dense path then answers by
  // least squares).
  bool factor(double rho);
  // rhs <- (J + rho D)^-1 rhs with the last factor. False when the result is not finite.
  bool solve(Vector& rhs);
  // Dense path: rhs <- (J^T J + lambda I)^-1 J^T rhs (Levenberg-Marquardt; J of the last
  // factor, without rho). False on the sparse path or when the result is not finite.
  bool solveRegularized(double lambda, Vector& rhs);
  // w = A x + b of the prepared problem: in body space when its products apply there (rows
  // given, every cfm > 0: 12 multiply-adds a row instead of A's row), else from A.
  void slack(const Vector& x, Vector& w) const;
  // out = A v (slack() without b).
  void product(const Vector& v, Vector& out) const;
  // One projected Gauss-Seidel sweep (omega 1) on the prepared problem: in body space when its
  // products apply there (as slack()), else detail::pgsSweep on A.
  void sweep(const Vector& invDiag, Vector& x);
  // Whether the prepared problem's A is symmetric: by construction when body space holds its
  // rows (A = J W J^T + diag(cfm)), else isSymmetric() (linalg/symmetry.hpp).
  bool symmetric() const;
  // out = J^T v (without rho).
  void transposeTimes(const Vector& v, Vector& out) const;
  // out = J v (without rho).
  void times(const Vector& v, Vector& out) const;
  // Symbolic analyses of the sparse path (one per reduced pattern seen in a row).
  int analyses() const { return lu_.analyses(); }
  bool isSparse() const { return sparse_; }

 private:
  bool factorDense(double rho);
  bool factorSparse(double rho);
  bool solveReduced(Vector& rhs);
  void prepareBody(const Problem& problem);
  bool factorBody(double rho);
  bool solveFactored(Vector& y);
  void reducedTimes(const Vector& y, Vector& out) const;

  linalg::SparseLu lu_;
  // Body space (linalg/body_space.hpp): ready when the rows are A's; used for the last factor.
  const RowSystem* rows_ = nullptr;
  std::unique_ptr<BodySpaceSystem> body_;
  bool bodyReady_ = false, useBody_ = false, bodyProducts_ = false;
  int bodyFactorizations_ = 0;
  double rho_ = 0, minDiagonal_ = 0;
  std::vector<int> sliding_, findex_;
  std::vector<double> coeff_;
  Vector refine_, product_;
  mutable Vector scratch_, spread_;  // products in body space
  const Problem* problem_ = nullptr;
  const SparseMatrix* a_ = nullptr;  // CSR A: the problem's, or own_ for dense or uncompressed
  SparseMatrix own_;
  bool sparse_ = false;

  // Row i of J: db_i A_i + da_i e_i + cf_i e_findex[i].
  Vector da_, db_, cf_;
  // The sparse path's reduced system K on the free rows (by rows, columns sorted), the free rows
  // in order and each row's position among them (-1: at a bound), and workspaces.
  std::vector<int> rowStart_, columns_, freeRows_, position_, seen_, rowColumns_;
  std::vector<double> values_, accumulator_;
  Vector known_, reduced_;
  DenseMatrix dense_;
  Eigen::PartialPivLU<DenseMatrix> denseLu_;
  Eigen::CompleteOrthogonalDecomposition<DenseMatrix> cod_;
  bool leastSquares_ = false;
  Vector check_;
  DenseMatrix normal_;
};

}  // namespace mlcp::detail
