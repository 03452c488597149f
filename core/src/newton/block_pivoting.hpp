// Block principal pivoting on the natural map of a sparse symmetric MLCP with findex: the
// pivoting phase of NewtonSolver (mlcp/solvers/newton.hpp, "Pivoting phase"). Internal to the
// library. The long form: docs/methods/newton.md, "Block pivoting".
//
// Method. Whole index sets are guessed and exchanged at once: semismooth Newton steps on
// H(x) = x - clamp(x - w, lo', hi') (block principal pivoting, Kostreva / Judice-Pires, when
// every step is full). Each row is clamped (w_i = 0), held at lo or hi, or fixed; a friction row
// at a bound is the equation x_t = mu_t s_j x_j on its normal j (findex exact), and friction rows
// whose normal is held at 0 are fixed at 0. One step solves those equations.
//
// Steps. Full steps first: the next sets change only rows violated beyond 0.01 tolerance
// (1 + |b|) (setsAt), so degenerate rows do not flip on rounding. A full step without a new lowest
// merit ||H||^2 that descends from the step before is free (pivotingDescentSteps per run); a
// 2-cycle of sets ends the full steps at once (pivotingBreakCycles); 3 other full steps without a
// new best (or a singular block) go back to the best point and continue damped: a proximal term
// rho (x_C - x_C,prev), rho = 1e-2 max |A_ii| min(1, ||H||), and Armijo backtracking on ||H||^2.
// First sets: cold, every row clamped; warm, from the natural map at the guess, or with atGuess
// from where the guess lies (a row within 1e-6 of a bound held there).
//
// Linear algebra. A_CC + rho I is factored by an up-looking sparse LDL^T
// (linalg/symmetric_pattern_lu.hpp) in an AMD order of the whole A, computed once per pattern.
// Sliding rows (at a bound, normal clamped) make K = B + U E^T nonsymmetric: up to
// pivotingWoodburyRows of them are bordered onto B's factor (Woodbury, capacitance from sparse
// forward solves), more factor K = L D U without pivoting (Eigen's SparseLU when K leaves A_CC's
// pattern). A step whose sets differ from the last factored ones by at most pivotingUpdateRows
// rows, at the same rho, borders the changes onto that factor (a p x p dense Schur complement).
// One step of iterative refinement follows. Why an LDL^T with a pivot tolerance: full steps run
// at rho = 0, where coplanar contacts' clamped blocks are singular up to cfm, and it reports such
// a block at once.
//
// Body space. With the rows (setRows; A = J W J^T + diag(cfm)), a step whose every cfm_c + rho is
// at least kBodyMinDiagonal max |A_ii| (thresholds.hpp) is solved in body space
// (linalg/body_space.hpp), with two steps of refinement against the true K.
//
// Invariants and cost. A run ends settled (residual within Options::tolerance; x then projected
// onto the bounds when that stays within it) or with the best iterate, the start included, after
// maxSteps, no descent, a singular damped block or the time budget. A step costs one assembly of
// K and a factorization, or a few sparse forward solves when the factor is reused.
#pragma once

#include <Eigen/SparseLU>
#include <memory>
#include <string>
#include <vector>

#include "linalg/sparse_pattern.hpp"
#include "linalg/symmetric_pattern_lu.hpp"
#include "linalg/symmetry.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/result.hpp"
#include "mlcp/solvers/newton.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {
class RowSystem;
}

namespace mlcp::detail {

class BodySpaceSystem;

class BlockPivoting {
 public:
  BlockPivoting();
  ~BlockPivoting();
  // The rows the next runs' problem was assembled from (nullptr: none): block steps may then be
  // solved in body space (linalg/body_space.hpp). Not owned; must outlive the runs. Prepared once,
  // at the first run after this call: call it again for another problem.
  void setRows(const RowSystem* rows) {
    rows_ = rows;
    rowsPrepared_ = false;
  }

  struct Report {
    bool settled = false;    // x solves the problem to Options::tolerance (checked by residual())
    int steps = 0;           // block steps (each one linear solve of the index sets' equations)
    int factorizations = 0;  // of the steps, those that factored their clamped block afresh
    int bodyFactorizations = 0;  // of those, the ones factored in body space
    std::string message;
  };

  // Runs from x (all zero: the cold guess "every row clamped"; atGuess: "Steps" above);
  // leaves in x the solution when settled, else the best iterate by residual (the start
  // included). A must be symmetric (checked unless symmetryKnown: the caller has checked it).
  Report run(const Problem& problem, Vector& x, const Options& options, int maxSteps,
             bool atGuess = false, bool symmetryKnown = false);

  // The block steps' limits (mlcp/solvers/newton.hpp, PivotingLimits; NewtonParams passes its
  // own).
  void setLimits(const PivotingLimits& limits) { limits_ = limits; }

 private:
  enum class Set : unsigned char { Clamped, AtLo, AtHi, Fixed };
  using ColMajor = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  struct RunState;
  // run()'s stages: the preparation, the first sets (guess), each step's sets, its linear solve
  // (solveClamped), and the full or damped step's bookkeeping.
  bool prepare(const Problem& pb, const Options& opt, bool symmetryKnown);
  void guess(const Problem& pb, const Vector& x0, const Vector& w0, bool cold,
             bool atGuess = false);
  void nextSets(const Problem& pb, Vector& x, RunState& st);
  void toDamped(const Problem& pb, Vector& x, RunState& st);
  void fullStep(const Problem& pb, Vector& x, RunState& st);
  bool dampedStep(const Problem& pb, Vector& x, RunState& st);
  void project(const Problem& pb, double tolerance, Vector& x);
  // solveClamped's stages: the sets' unknowns, the factor, then the solve with refinement.
  void gatherSets(const Problem& pb, Vector& x);
  bool factorClamped(const Problem& pb, double rho, std::string& why);
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
  bool useLu_ = false;  // more than pivotingWoodburyRows sliding rows: K is factored as it is
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
  void borderColumns(double rho, int joined, int left, DenseMatrix& S);
  void subtractSchur(int left, DenseMatrix& S);
  // Block steps reuse the factor of the last factored clamped set C0 (the base) while the sets
  // differ from it by at most pivotingUpdateRows unknowns (joined, left, sliding rows) and rho is
  // the same: a bordered system with a small dense Schur complement (buildCapacitance). Sliding
  // rows on the symmetric B = A_CC + rho I (K = B + U E^T, Woodbury) are bordered the same way.
  PivotingLimits limits_;
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
