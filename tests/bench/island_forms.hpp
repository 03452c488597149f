// island_forms.hpp: the forms of one captured engine island that a solver without friction
// coupling (findex) can take, for comparing solvers of other libraries on the same rows.
//
// An engine island (mlcp-problem/1, written by `mlcp run --capture`) is a boxed MLCP with
// friction coupling: contact rows [0, +inf) (Bullet writes [0, 1e10]), friction rows
// [-mu, mu] scaled by their normal's value (findex), joint rows with other bounds. Libraries such
// as Siconos numerics have no findex; they take
//   - the frictionless LCP: the island's rows without its friction rows (a friction row whose
//     bounds are 0 holds x = 0 and drops out exactly), w = A_nn x + b_n, 0 <= x _|_ w >= 0. Only
//     when every remaining row is a contact row [0, hi] with hi >= kLargeBound (Bullet's 1e10
//     is taken as +inf);
//   - the fixed-bound box: every row, friction bounds fixed at lo_i |x_ref f|, hi_i |x_ref f| from
//     a reference answer x_ref of the findex problem, findex dropped. Its solutions solve the
//     findex problem only where their normals equal x_ref's; a box solver's answer is therefore
//     also measured on the findex problem (the findex residual), which says how far that holds.
// Cost: O(nnz A) each, A kept in the island's storage.
#pragma once

#include <optional>
#include <string>

#include "mlcp/problem.hpp"

namespace mlcp::bench {

// Upper bounds at or above this count as +inf for the frictionless form (Bullet's contact rows
// hold 1e10).
inline constexpr double kLargeBound = 1e9;

// The frictionless LCP of an island (lo = 0, hi = +inf, no findex), or nothing with the reason in
// *why (the island has rows of other kinds).
std::optional<Problem> frictionlessLcp(const Problem& island, std::string* why);

// The island with every friction row's bounds fixed from `reference` and findex cleared.
Problem fixedBoundBox(const Problem& island, const Vector& reference);

// The box with every infinite bound replaced by +-cap (for solvers that need finite bounds:
// Siconos' relay Lemke doubles the problem with ub - lb). A cap far above the reference's
// largest |x| leaves the answer unchanged; the answer's residual on the uncapped box says
// whether it did.
Problem cappedBox(const Problem& box, double cap);

}  // namespace mlcp::bench
