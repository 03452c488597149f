// Block principal pivoting on the natural map of a sparse symmetric MLCP with findex: the
// pivoting phase of NewtonSolver (mlcp/solvers/newton.hpp, "Pivoting phase"). Internal to the
// library.
//
// Method. Whole index sets are guessed and exchanged at once: semismooth Newton steps on the
// natural map H(x) = x - clamp(x - w, lo', hi') (block principal pivoting, Kostreva /
// Judice-Pires, when every step is full). Each row is clamped (w_i = 0), held at lo or hi, or
// fixed; a friction row at a bound is the linear equation x_t = mu_t s_j x_j coupling it to its
// normal j (s_j the normal's sign), so findex is exact, and friction rows whose normal is held at
// 0 are fixed at 0. One step solves those equations.
//
// Steps. First the steps are full: the next sets change only rows violated beyond 0.01 tolerance
// (1 + |b|) (setsAt), so that degenerate rows do not flip on rounding. A full step that brings no
// new lowest merit ||H||^2 but is below the step before is free (up to Limits::descentSteps per
// run: from a guess that is itself the best point so far, Bullet's full steps often descend for
// several steps, residual 5e-2 -> 1e-2 -> 2e-3 -> ..., before beating it); a full step whose sets
// are those of two steps before (a 2-cycle, which would repeat that step's x) ends the full steps
// at once (Limits::breakCycles). When 3 other full steps in a row bring no new lowest merit (or a
// block is singular), the run goes back to the best point and continues damped: sets from the
// natural map at x, a proximal term rho (x_C - x_C,prev) on the clamped rows (rho = 1e-2
// max|A_ii| min(1, ||H||): coplanar contacts make clamped blocks nearly singular, and far from
// the answer their exact equations throw the null-space part far away), and the step shortened
// by backtracking until ||H||^2 decreases (Armijo); at a kink where no step length descends the
// full step is taken up to 2 times in a row. A run ends when the residual (residual.hpp) is within
// Options::tolerance (then x is projected onto the bounds when that keeps it within tolerance),
// or after maxSteps, no descent, a singular damped block or the time budget, with the best
// iterate (the start included).
//
// First sets. Cold (x = 0): every row clamped. Warm: from the natural map at the guess, or, with
// atGuess (newton's phase, whose guess is its damped steps' best iterate), from where the guess
// lies: a row within 1e-6 of a bound held there, the others clamped. An engine hands a sliding
// friction row's last answer back rotated onto the new friction direction, so its relative change
// is of the order of the rotation squared.
//
// Linear algebra. A_CC + rho I is factored by an up-looking sparse LDL^T (SymmetricPatternLu,
// linalg/symmetric_pattern_lu.hpp) in a fill-reducing AMD order of the whole A, computed once per
// pattern of A and inherited by every clamped block. Sliding rows (at a bound, normal clamped) are
// substituted, which makes K = B + U E^T nonsymmetric (B = A_CC + rho I; U's column c_t A_{C,t}
// per sliding row t, E's the unit vector of t's normal); up to Limits::woodburyRows of them are
// bordered onto B's factor (Woodbury: a k x k capacitance S = I + E^T B^-1 U from sparse forward
// solves, whose reach in the elimination tree is short), more are factored as K = L D U without
// pivoting (K keeps A_CC's pattern: a contact's friction and normal rows touch the same bodies;
// a K outside that pattern falls back to Eigen's SparseLU). A later step whose sets differ from
// the last factored ones by at most Limits::updateRows rows (joined, left, sliding), with the same
// rho, reuses that factor: the joined rows are bordered on, a left row's x is held at 0 by a
// multiplier that frees its equation, and the p x p Schur complement of the border is factored
// densely. One step of iterative refinement follows. Why not KLU (newton's reduced system): the
// full steps run at rho = 0, where the coplanar contacts' clamped blocks are singular up to cfm;
// the LDL^T's pivot tolerance reports such a block at once (the run then goes damped), and the
// bordered updates make most full steps near the answer a few sparse forward solves.
//
// Body space. With the rows (setRows; A = J W J^T + diag(cfm)), a step whose every cfm_c + rho is
// at least Limits::bodyMinDiagonal max |A_ii| is solved by Woodbury in body space instead
// (linalg/body_space.hpp, the factor newton's damped steps use), with two steps of refinement
// against the true K; with every cfm > 0 the products with A go through the rows too.
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

  // Runs from x (all zero: the cold guess "every row clamped"; atGuess: "First sets" above);
  // leaves in x the solution when settled, else the best iterate by residual (the start
  // included). A must be symmetric (checked unless symmetryKnown: the caller has checked it).
  Report run(const Problem& problem, Vector& x, const Options& options, int maxSteps,
             bool atGuess = false, bool symmetryKnown = false);

  // Most sliding rows handled by Woodbury on the symmetric factor (more: the LU), and most
  // unknowns by which a step's sets may differ from the last factored ones (joined, left and
  // sliding rows) for the step to reuse that factor; descentSteps and breakCycles: "Steps" above;
  // bodyMinDiagonal: "Body space" above. NewtonParams documents the first four.
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
