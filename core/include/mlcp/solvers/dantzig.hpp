// mlcp/solvers/dantzig.hpp: Dantzig-Cottle principal pivoting for boxed MLCPs with findex (registry
// "dantzig"), in the spirit of ODE's dSolveLCP and Bullet's btDantzigLCP.
//
// Rows (in the form of problem.hpp) are added one at a time, each processed row clamped (C:
// w_i = 0, lo_i <= x_i <= hi_i) or at a bound (N: x_i = lo_i with w_i >= 0, x_i = hi_i with
// w_i <= 0). Adding row i drives x_i along
//
//     A_CC dx_C = -A_Ci d,   dw = A_{.,C} dx_C + A_{.,i} d,   d = -sign(w_i),
//
// until the first event: w_i = 0 (i joins C), x_i at a bound (i joins N), a C row at a bound
// (it moves to N), an N row's w at 0 (it moves to C); after an exchange i drives on. Invariant:
// every processed row satisfies its complementarity condition; unprocessed rows keep their
// start. Order: equality rows, rows the start guesses clamped, the others, friction rows last
// (their bounds follow the normals).
//
// Factors: A_CC = L D U (U = L^T when A is symmetric, detected once per solve), bordered when a
// row joins C and restored by Bennett's rank-one update when one leaves; no refactorization. A
// pivot below Options::pivotTolerance max |A_ii| is a breakdown. At the end x_C is refined once
// and rows whose sign condition drifted are driven again.
//
// Cost: a pivot O(|C|^2) plus O(|N| n) (O(nnz) of N's rows for sparse A), O(n^3) at worst;
// memory A permuted (dense n^2, or CSR/CSC) and L (U) at n^2, reused while n does not grow. No
// state carries from one solve to the next (regularised() only reports the last one). Large
// contact islands are newton's (policy.hpp).
//
// Limits: a P-matrix (SPD A: cfm > 0) always solves; a consistent PSD problem (cfm = 0) usually
// does, rows with a zero pivot and w = 0 left free (counted in the message). A breakdown (Failed,
// or the default pivot limit: cycling) runs once more from zero on A + delta I, delta =
// DantzigParams::breakdownShift max |A_ii| ("regularised" in the message). No step limit is
// Failed, naming the row; a non-symmetric A that is not a P-matrix may fail.
//
// Warm start: rows strictly inside their bounds are factored as one clamped block, the rows
// that land outside it dropped, the rest added as above. Dense islands of at most
// kPlainLoopRows rows without findex try their guessed sets on fixed-size arrays first
// (core/src/pivoting/dantzig_small.hpp). Friction (Options::frictionBounds): FixedOnce fixes
// every friction bound at the first friction row, as ODE and Bullet do; Exact iterates the
// bounds to a fixed point with Anderson acceleration (DantzigParams below).
// Result::iterations counts pivots over all passes; Options::maxPivots (0: 50 n + 100) limits
// each pass; Options::timeBudget is checked between pivots and passes (TimeLimit).
// Details: docs/methods/pivoting.md, the "Dantzig: ..." sections.
#pragma once

#include <memory>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

// Parameters of DantzigSolver beyond Options.
struct DantzigParams {
  // The shift delta of the retry after a breakdown, relative to max |A_ii| ("Limits" above).
  // Default kDantzigBreakdownShift (1e-10, thresholds.hpp).
  double breakdownShift = kDantzigBreakdownShift;
  // Solve A + delta I from zero at once (delta as after a breakdown), without the attempt on A:
  // for a caller that knows the problem breaks down (RowSolver, for an island whose last solve
  // did). The answer is the retry's; the residual is still measured on A. Default false.
  bool regularised = false;
  // Exact friction: the normals' history depth of Anderson's extrapolation, the passes without
  // a new lowest bound change after which plain damped iteration takes over, and its damping
  // factor (docs/methods/pivoting.md, "Dantzig: friction bounds"). Defaults 6, 20 and 0.3.
  int andersonDepth = 6;
  int andersonStall = 20;
  double stallDamping = 0.3;
};

class DantzigSolver : public Solver {
 public:
  DantzigSolver();
  ~DantzigSolver() override;
  DantzigSolver(DantzigSolver&&) noexcept;
  DantzigSolver& operator=(DantzigSolver&&) noexcept;

  const char* name() const override { return "dantzig"; }

  DantzigParams& params() { return params_; }
  const DantzigParams& params() const { return params_; }

  // Friction fixed-point passes of the last solve (1 without findex or with FixedOnce).
  int passes() const;
  // Whether the last solve's answer came from A + delta I (a breakdown's retry, or
  // DantzigParams::regularised).
  bool regularised() const;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  struct Workspace;
  void runPivoting(const Problem& problem, Vector& x, Result& result);
  void regularise(const Problem& problem, Vector& x, Result& result, double scale,
                  const std::string& why, int spent);
  std::unique_ptr<Workspace> ws_;
  DantzigParams params_;
};

}  // namespace mlcp
