// core/src/projection/pgs_sweep.hpp (internal): the sweep of PgsSolver (mlcp/solvers/pgs.hpp)
// and its per-row update, shared with newton's smoothing sweeps and the body-space sweeps.
#pragma once

#include <algorithm>

#include "mlcp/problem.hpp"

namespace mlcp {

namespace detail {
// One sweep (the update above) over the rows in order, with invDiag[i] = 1 / A_ii and omega the
// relaxation; shared with newton's smoothing sweeps (newton/newton_system.cpp).
void pgsSweep(const Problem& problem, const Vector& invDiag, double omega, Vector& x);
// The sweep's update of row i for its slack wi = (A x + b)_i: x_i - omega wi / A_ii projected on
// the row's bounds at x (friction bounds from x's normal). Shared with the sweeps that compute
// wi another way (in body space, linalg/body_space.hpp).
inline double pgsUpdate(const Problem& problem, int i, double wi, double invDiag, double omega,
                        const Vector& x) {
  const double xi = x[i] - omega * wi * invDiag;
  return std::clamp(xi, problem.effectiveLo(i, x), problem.effectiveHi(i, x));
}
// invDiag[i] = 1 / A_ii for the sweep; returns the first row whose A_ii is not positive (invDiag
// then unusable), or -1.
int inverseDiagonal(const Problem& problem, Vector& invDiag);
}  // namespace detail

}  // namespace mlcp
