// The sparse block principal pivoting stage of DantzigSolver (see "Block stage" in
// mlcp/dantzig.hpp for the method). Internal to the library.
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <string>
#include <vector>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "sparse_pattern.hpp"

namespace mlcp::detail {

class BlockPivoting {
 public:
  struct Report {
    bool settled = false;  // x solves the problem to Options::tolerance (checked by residual())
    int steps = 0;         // factorizations (block or single-switch steps)
    std::string message;
  };

  // Runs from x (all zero: the cold guess "every row clamped"); leaves in x the solution when
  // settled, else the iterate with the fewest violated rows. A must be symmetric.
  Report run(const Problem& problem, Vector& x, const Options& options, int maxSteps);

  int orderings() const { return aPattern_.analyses(); }

 private:
  enum class Set : unsigned char { Clamped, AtLo, AtHi, Fixed };
  using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  using Ldlt = Eigen::SimplicialLDLT<ColMajor, Eigen::Upper, Eigen::NaturalOrdering<int>>;

  void guess(const Problem& pb, const Vector& x0, bool cold);
  bool solveClamped(const Problem& pb, Vector& x, const Vector& prev, double rho, std::string& why);
  bool factorClamped(double rho, std::string& why);
  bool factorCoupled(double rho, std::string& why);
  void applySolve(Vector& y) const;
  int setsAt(const Problem& pb, const Vector& x, const Vector& w);
  double meritAt(const Problem& pb, const Vector& x, const Vector& w) const;
  double frictionBound(const Problem& pb, int t, Set s, const Vector& x) const;

  SparseMatrix A_;  // row-major copy when the problem is stored dense
  const SparseMatrix* a_ = nullptr;
  PatternCache aPattern_, kPattern_;
  std::vector<int> byRank_;         // the rows in a fill-reducing order of A
  std::vector<int> problemFindex_;  // findex, -1 filled
  std::vector<Set> set_;
  std::vector<int> pos_, order_, sliding_;  // pos_: row -> unknown index in K, or -1
  std::vector<double> coeff_;               // sliding row t: x_t = coeff_ * x_normal
  ColMajor K_;  // upper triangle of the clamped block in the order of byRank_
  Ldlt ldlt_;
  bool useLu_ = false;  // sliding rows present: K is nonsymmetric and factored by lu_
  std::vector<Eigen::Triplet<double>> triplets_;
  ColMajor Kfull_;  // all of K (sliding rows substituted), for lu_
  Eigen::SparseLU<ColMajor, Eigen::NaturalOrdering<int>> lu_;
  double eps_ = 0, pivTol_ = 0;
};

}  // namespace mlcp::detail
