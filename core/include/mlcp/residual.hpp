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
// residual = +inf and finite = false.
Accuracy accuracy(const Problem& problem, const Vector& x);
// Same, with w supplied (w must equal A x + b; used where w is at hand already).
Accuracy accuracy(const Problem& problem, const Vector& x, const Vector& w);
// Shorthand for accuracy(problem, x).residual.
double residual(const Problem& problem, const Vector& x);

// The primitive all of the above call: for forms that compute w without an assembled A (the
// adapters' factored rows). bInfNorm is ||b||_inf of the problem; findex may be empty.
Accuracy accuracy(const Vector& x, const Vector& w, const Vector& lo, const Vector& hi,
                  const std::vector<int>& findex, double bInfNorm);

}  // namespace mlcp
