// mlcp/residual.hpp: the one accuracy measure every solver and every test uses.
//
// The natural map of the MLCP is
//
//     r(x) = x - clamp(x - w, lo', hi'),   w = A x + b,
//
// with lo', hi' the effective bounds (findex applied at x). r(x) = 0 exactly at a solution.
// We report ||r||_inf / (1 + ||b||_inf), so that the number is comparable across problem
// scales. It is computed here from the problem alone, independently of any solver's claims.
#pragma once

#include <algorithm>
#include <cmath>

#include "mlcp/problem.hpp"

namespace mlcp {

struct Accuracy {
  double residual = 0;  // ||x - clamp(x - w, lo', hi')||_inf / (1 + ||b||_inf)
  // max_i (w_i^+ (x_i - lo'_i)^+ + w_i^- (hi'_i - x_i)^+), a gap to an infinite bound
  // counting as 1 (the violation is then |w_i| itself).
  double complementarity = 0;
  double boundViolation = 0;  // max_i max(lo'_i - x_i, x_i - hi'_i, 0)
  bool finite = true;         // x and w hold no NaN/Inf
};

// Accuracy of x for the problem (w computed as A x + b). A non-finite x or w gives
// residual = +inf and finite = false; an x or w whose size is not the problem's throws
// std::invalid_argument naming both sizes.
Accuracy accuracy(const Problem& problem, const Vector& x);
// Same, with w supplied (w must equal A x + b; used where w is at hand already).
Accuracy accuracy(const Problem& problem, const Vector& x, const Vector& w);
// Shorthand for accuracy(problem, x).residual.
double residual(const Problem& problem, const Vector& x);

// The accuracy that decides a solve's status (Solver's final check): accuracy(problem, x, w)
// for w = fl(A x + b) as computed in plain floating point, unless the rounding of that w could
// put the residual on either side of `tolerance`; then w is recomputed by compensatedSlack()
// and the accuracy comes from it.
//
// Why: w's rounding error is up to gamma_{n+1} (||A||_inf ||x||_inf + ||b||_inf), gamma_k =
// k u / (1 - k u), u = 2^-53, and the natural map is 1-Lipschitz in w. Where A x is large
// against 1 + ||b||_inf (a problem scaled by 1e12 with b of order 1), that error alone exceeds a
// tolerance of 1e-6, and a plain residual can call converged what is not (or the reverse).
// The bound (plus 3u (||x||_inf + ||w||_inf) for the subtractions of the natural map), scaled
// like the residual, is compared with |residual - tolerance|: outside it the plain answer
// stands, so the usual solve pays one pass over A for ||A||_inf and nothing more.
Accuracy checkedAccuracy(const Problem& problem, const Vector& x, const Vector& w,
                         double tolerance);

// ||A||_inf, the largest absolute row sum (0 for an empty problem), one pass over A.
double rowSumNorm(const Problem& problem);

// w = A x + b with each row's sum compensated (Ogita, Rump and Oishi's Dot2: every product
// split exactly by an fma, every addition's error kept by TwoSum, the errors summed and added
// at the end). The result is as accurate as if computed in twice the working precision, then
// rounded: |w_i - fl(w_i)| <= u |w_i| + gamma_n^2 (|A| |x| + |b|)_i. Cost: about 4x a plain
// product (row by row over a column-major A).
Vector compensatedSlack(const Problem& problem, const Vector& x);

// The per-row rule all of the accuracy() functions run, for a solver that has w one row at a
// time (RowPgs' check computes w_i from its packed rows and feeds it here: one pass, no w
// vector). add() every row (with its findex, or with its effective bounds), then result().
class AccuracyAccumulator {
 public:
  // false once x or w was not finite: the result is then +inf whatever follows.
  bool add(double x, double w, double lo, double hi) {
    if (!std::isfinite(x) || !std::isfinite(w)) {
      finite_ = false;
      return false;
    }
    r_ = std::max(r_, std::abs(x - std::clamp(x - w, lo, hi)));
    complementarity_ =
        std::max(complementarity_, gapTimes(lo, x, w, 1.0) + gapTimes(hi, x, -w, -1.0));
    boundViolation_ = std::max({boundViolation_, lo - x, x - hi});
    return true;
  }
  // A row with friction coupling (f >= 0): its bounds are lo |x_f| .. hi |x_f| (xs: all of x).
  bool add(double x, double w, double lo, double hi, int f, const double* xs) {
    if (f >= 0) {
      const double normal = std::abs(xs[f]);
      lo *= normal;
      hi *= normal;
    }
    return add(x, w, lo, hi);
  }
  // bInfNorm: ||b||_inf of the problem.
  Accuracy result(double bInfNorm) const {
    Accuracy a;
    if (!finite_) {
      a.finite = false;
      a.residual = a.complementarity = a.boundViolation = kInf;
      return a;
    }
    a.residual = r_ / (1.0 + bInfNorm);
    a.complementarity = complementarity_;
    a.boundViolation = boundViolation_;
    return a;
  }

 private:
  // w's violation times the distance to the bound it points at; with an infinite bound there is
  // no distance to measure and the violation is |w| itself.
  static double gapTimes(double bound, double x, double force, double sign) {
    if (force <= 0) return 0;
    return std::isfinite(bound) ? force * std::max(sign * (x - bound), 0.0) : force;
  }
  double r_ = 0, complementarity_ = 0, boundViolation_ = 0;
  bool finite_ = true;
};

// The primitive all of the above call: for forms that compute w without an assembled A (the
// adapters' factored rows). bInfNorm is ||b||_inf of the problem; findex may be empty.
Accuracy accuracy(const Vector& x, const Vector& w, const Vector& lo, const Vector& hi,
                  const std::vector<int>& findex, double bInfNorm);

}  // namespace mlcp
