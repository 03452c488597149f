// The sparse block principal pivoting stage of DantzigSolver (see "Block stage" in
// mlcp/dantzig.hpp for the method). Internal to the library.
#pragma once

#include <Eigen/SparseLU>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "sparse_pattern.hpp"

namespace mlcp {
class RowSystem;
}

namespace mlcp::detail {

class BodySpaceSystem;

// K = L D U without pivoting (L unit lower, U unit upper) for a sparse square K whose pattern
// is symmetric, in the given order: up-looking, row k of L and column k of U from two sparse
// triangular solves over the elimination tree (built as it goes), so L and U^T share one
// pattern, that of the Cholesky factor of the pattern. Twice an LDL^T's work; the symbolic pass
// (elimination tree, column counts) is skipped when the pattern is the last factorization's.
// factorSymmetric is the same for a symmetric K (U = L^T, one triangular solve per row).
class SymmetricPatternLu {
 public:
  // K (m x m) in compressed columns, rows in any order within a column; kt holds the values of
  // K^T on the same pattern (kt at the entry (i, j) is K(j, i)). False when a pivot's magnitude
  // is at most pivotTolerance (or not finite).
  bool factor(int m, const std::vector<int>& outer, const std::vector<int>& inner,
              const std::vector<double>& k, const std::vector<double>& kt, double pivotTolerance);
  bool factorSymmetric(int m, const std::vector<int>& outer, const std::vector<int>& inner,
                       const std::vector<double>& k, double pivotTolerance);
  void solve(Vector& y) const;  // y <- K^-1 y
  // y <- L^-1 y for a y that is zero outside idx; idx becomes the rows where the result may be
  // nonzero (idx's reach in the elimination tree: L(r, i) != 0 only for ancestors r of i), in
  // increasing order. Costs the entries of L in those columns, not m.
  void forward(std::vector<int>& idx, Vector& y);
  double pivot(int c) const { return d_[c]; }                         // D's entry c
  int entries() const { return start_.empty() ? 0 : start_.back(); }  // L's off-diagonal entries

 private:
  bool run(int m, const std::vector<int>& outer, const std::vector<int>& inner,
           const std::vector<double>& k, const std::vector<double>* kt, double pivotTolerance);
  // Column c of L (and row c of U) at [start_[c], start_[c + 1]): rows_, l_ = L(row, c),
  // u_ = U(c, row) (unused when symmetric_), sized by a symbolic pass over the elimination tree.
  std::vector<int> start_, fill_, rows_;
  std::vector<double> l_, u_, d_, y_, z_;
  std::vector<int> parent_, tag_, stack_;
  std::vector<int> analyzedOuter_, analyzedInner_;  // the pattern parent_ and start_ are for
  std::vector<char> reached_;
  bool symmetric_ = false;
};

class BlockPivoting {
 public:
  BlockPivoting();
  ~BlockPivoting();
  // The rows the next runs' problem was assembled from (nullptr: none): block steps may then be
  // solved in body space (linalg/body_space.hpp). Not owned; must outlive the runs. Prepared once,
  // at the first run after this call (DantzigSolver's cold trial and warm stage share it): call it
  // again for another problem.
  void setRows(const RowSystem* rows) {
    rows_ = rows;
    rowsPrepared_ = false;
  }

  struct Report {
    bool settled = false;    // x solves the problem to Options::tolerance (checked by residual())
    int steps = 0;           // block steps (each one linear solve of the index sets' equations)
    bool symmetric = false;  // A passed the symmetry check (else the stage did not run)
    int factorizations = 0;  // of the steps, those that factored their clamped block afresh
    int bodyFactorizations = 0;  // of those, the ones factored in body space
    std::string message;
  };

  // Runs from x (all zero: the cold guess "every row clamped"); leaves in x the solution when
  // settled, else the iterate with the fewest violated rows. A must be symmetric (checked unless
  // symmetryKnown: a previous run() on the same problem found it so). A trial takes full steps
  // only and ends at the first one that brings no new lowest merit.
  Report run(const Problem& problem, Vector& x, const Options& options, int maxSteps,
             bool trial = false, bool symmetryKnown = false, bool atGuess = false);

  int orderings() const { return aPattern_.analyses(); }

  // Most sliding rows handled by Woodbury on the symmetric factor (more: the LU), and most
  // unknowns by which a step's sets may differ from the last factored ones (joined, left and
  // sliding rows) for the step to reuse that factor. DantzigParams documents them.
  // descentSteps and breakCycles: see DantzigParams::blockDescentSteps / blockBreakCycles;
  // bodyMinDiagonal: DantzigParams::blockBodyMinDiagonal.
  struct Limits {
    int woodburyRows = 16;
    int updateRows = 40;
    int descentSteps = 8;
    bool breakCycles = true;
    double bodyMinDiagonal = 1e-11;
  };
  void setLimits(const Limits& limits) { limits_ = limits; }

 private:
  enum class Set : unsigned char { Clamped, AtLo, AtHi, Fixed };
  using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  void guess(const Problem& pb, const Vector& x0, const Vector& w0, bool cold,
             bool atGuess = false);
  bool solveClamped(const Problem& pb, Vector& x, const Vector& prev, double rho, std::string& why);
  bool factorCoupled(double rho, bool coupled, std::string& why);
  void applySolve(Vector& y);
  // out = A x, and out[c] = (A x)_{order_[c]}: in factored form when the rows are given and every
  // cfm > 0 (BodySpaceSystem::multiply), else from A's rows.
  void times(const Vector& x, Vector& out);
  void clampedTimes(const Vector& x, Vector& out);
  int setsAt(const Problem& pb, const Vector& x, const Vector& w);
  double meritAt(const Problem& pb, const Vector& x, const Vector& w) const;
  double frictionBound(const Problem& pb, int t, Set s, const Vector& x) const;

  void mirrorPattern();
  bool symmetricValues() const;

  SparseMatrix A_;  // row-major copy when the problem is stored dense
  const SparseMatrix* a_ = nullptr;
  PatternCache aPattern_;
  // Per entry of A's pattern the index of its mirror entry (j, i), computed with the ordering;
  // empty when the pattern is not symmetric or a row is not sorted (then isSymmetric decides).
  std::vector<int> mirror_;
  std::vector<int> byRank_;         // the rows in a fill-reducing order of A
  std::vector<int> problemFindex_;  // findex, -1 filled
  std::vector<Set> set_, setPrev1_, setPrev2_;
  std::vector<int> pos_, order_, sliding_;  // pos_: row -> unknown index in K, or -1
  std::vector<double> coeff_;               // sliding row t: x_t = coeff_ * x_normal
  bool useLu_ = false;  // more than Limits::woodburyRows sliding rows: K is factored as it is
  std::vector<Eigen::Triplet<double>> triplets_;
  // K with its sliding rows substituted: A_CC's pattern (compressed columns) with the values of
  // K and of K^T, factored by symLu_; when a sliding row touches an entry outside that pattern,
  // Kfull_ from triplets_ and the general sparse LU.
  std::vector<int> kOuter_, kInner_, mark_, slidingHead_, slidingNext_;
  std::vector<double> kVal_, ktVal_, coupled_, column_;
  SymmetricPatternLu symLu_;
  bool useSymLu_ = false;
  ColMajor Kfull_;
  Eigen::SparseLU<ColMajor, Eigen::NaturalOrdering<int>> lu_;
  bool factorGeneral(double rho, std::string& why);
  bool buildCapacitance(const Problem& pb, double rho, int maxExtra);
  // Block steps reuse the factor of the last factored clamped set C0 (the base) while the sets
  // differ from it by at most Limits::updateRows unknowns (joined, left, sliding rows) and rho is
  // the same: a bordered system with a small dense Schur complement (buildCapacitance). Sliding
  // rows on the symmetric B = A_CC + rho I (K = B + U E^T, Woodbury) are bordered the same way.
  Limits limits_;
  const RowSystem* rows_ = nullptr;
  std::unique_ptr<BodySpaceSystem> body_;
  bool rowsPrepared_ = false;      // bodyReady_ and factoredProducts_ decided for rows_
  bool bodyReady_ = false;         // body_ prepared for rows_
  bool useBody_ = false;           // the current step's K is solved in body space
  bool factoredProducts_ = false;  // times() and clampedTimes() from the rows
  int bodyFactorizations_ = 0;
  double dMax_ = 0;  // max |A_ii|
  int factorizations_ = 0;
  bool haveBase_ = false;
  double baseRho_ = 0;
  std::vector<int> basePos_, baseOrder_, extraRow_, extraOf_, reach_;
  std::vector<int> gStart_, gIdx_, hStart_, hIdx_;
  std::vector<double> gVal_, hVal_;
  Vector work_, ax_;
  Eigen::FullPivLU<DenseMatrix> capacitance_;
  double pivTolRelative_ = 0;
  double eps_ = 0, pivTol_ = 0;
};

}  // namespace mlcp::detail
