// linalg/min_norm.hpp: the minimum-norm least-squares answer of A x = rhs for a symmetric
// positive semidefinite A, from one factorization of A + delta I.
//
// Why. Bilateral engine rows are singular wherever joints are redundant (a plank hung on two
// point-to-point constraints per side: 6 rows for 5 freedoms), and once a closed loop drifts
// their right-hand side leaves A's range: A x = rhs has no solution. The factorization of
// A + delta I alone, refined against A, then pushes the inconsistent part rhs_0 of rhs (its part
// in A's null space) into x as k rhs_0 / delta after k refinements: impulses of 1e9 times the
// drift, bodies at thousands of m/s. The least-squares answer with the smallest norm is what the
// drifted loop can still be given: the motion that best meets every row, no impulse along the
// rows' dependencies.
//
// The method: iterated filtered Tikhonov. With F = (A + delta I)^-1 A (A + delta I)^-1,
//     x_0 = 0,   x_{k+1} = x_k + F (rhs - A x_k).
// Along an eigenvector of A with eigenvalue lambda the error e = x+ - x (x+ = A^+ rhs, the
// minimum-norm least-squares answer) becomes e (1 - lambda^2 / (lambda + delta)^2) per step, so
//  - directions with lambda >> delta converge at a rate of about 2 delta / lambda a step;
//  - null directions (lambda = 0) receive nothing: x stays in A's range, which is what makes it
//    the minimum-norm answer, for a consistent system as for an inconsistent one;
//  - directions with lambda ~ delta (nearly singular) converge slowly and stay bounded by
//    |rhs_lambda| / lambda, and after k steps those below delta / sqrt(k) have received almost
//    nothing: delta is the rank decision, as a truncated SVD's threshold is.
// The least-squares stationarity ||A (A x - rhs)|| left is then about delta ||rhs||.
//
// Cost: per step two solves with the factor and two products with A; at most kMinNormSteps
// steps, stopping once a step changes x by less than 1e-15 of its size.
#pragma once

#include <algorithm>

#include "mlcp/problem.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp::linalg {

// Steps of the iteration above at most. Dimensionless.
inline constexpr int kMinNormSteps = 40;
// The rank decision: delta = kMinNormShift (thresholds.hpp) * max(1, max |A_ii|).

// delta for a matrix whose largest |A_ii| is maxDiagonal.
inline double minNormShift(double maxDiagonal) {
  return kMinNormShift * std::max(1.0, maxDiagonal);
}

// x = A^+ rhs as above. solveShifted(r, out) solves (A + delta I) out = r with the caller's
// factorization; multiply(v, out) sets out = A v. Returns the steps taken.
template <class SolveShifted, class Multiply>
int minNormSolve(const Vector& rhs, SolveShifted&& solveShifted, Multiply&& multiply, Vector& x) {
  const Eigen::Index n = rhs.size();
  x.setZero(n);
  Vector r = rhs, g(n), h(n), dx(n);
  int steps = 0;
  while (steps < kMinNormSteps) {
    solveShifted(r, g);
    multiply(g, h);
    solveShifted(h, dx);
    x += dx;
    ++steps;
    if (!x.allFinite()) break;
    if (!(dx.lpNorm<Eigen::Infinity>() > 1e-15 * x.lpNorm<Eigen::Infinity>())) break;
    multiply(x, h);
    r = rhs - h;
  }
  return steps;
}

}  // namespace mlcp::linalg
