// core/src/island/friction_cone.hpp (internal): contact friction as a polyhedral cone, a standard
// LCP (Stewart and Trinkle 1996, Anitescu and Potra 1997).
//
// Engines model friction as a box: per contact a normal row n and one or two tangent rows t1, t2
// with findex pointing at n, bounded by -mu x_n .. mu x_n each. The box is cheap for pgs and
// dantzig but it is not a linear complementarity problem (the bounds move with x_n), and it
// lets the friction force reach mu x_n sqrt(2) along a diagonal. The polyhedral cone of Stewart
// and Trinkle / Anitescu and Potra replaces it by a standard LCP in nonnegative unknowns:
//
//   per contact k directions d_j = cos(theta_j) t1 + sin(theta_j) t2, theta_j = 2 pi j / k (the
//   engine's tangents +-t1, +-t2 are among them when 4 divides k), impulses beta_j >= 0 along
//   them, the normal impulse f >= 0 and one more unknown lambda >= 0 (the sliding speed):
//
//     [ D'WD + C   D'WN   E ] [beta  ]   [ D'v ]      [beta  ]
//     [ N'WD       N'WN   0 ] [f     ] + [ N'v ] >= 0, [f     ] >= 0, complementary,
//     [ -E'        mu     0 ] [lambda]   [  0  ]      [lambda]
//
//   with W = M^-1, C the friction rows' cfm, E the 0/1 matrix that adds a contact's lambda to
//   each of its direction rows. The last row says sum_j beta_j <= mu f (the force lies in the
//   polygon with vertices mu f d_j, inscribed in the circle of radius mu f); a direction row says
//   d_j'v + lambda >= 0, so when the contact slides, lambda is the largest -d_j'v and only the
//   directions most opposed to the sliding carry force (maximal dissipation over the polygon).
//
// Rows without friction (joints, frictionless contacts) are kept as they are, with their bounds:
// the result is an MLCP whose coupled part is a standard LCP, which lemke takes directly (free
// joint rows by its Schur elimination). A normal row's finite upper bound, which engines use as
// a large stand-in for infinity (Bullet's 1e10), is dropped: the cone form has no upper bounds on
// contacts.
//
// What it buys and costs. The friction force stays within mu f in every direction up to the
// discretisation: along a direction the limit is exact, between two of them it is mu f
// cos(pi / k) (0.707 mu f at k = 4, 0.924 at k = 8). An incline whose slope runs along an
// engine tangent sticks exactly while tan(angle) <= mu. The LCP has k + 1 unknowns per contact
// where the box has 2 or 3, its lambda rows have zero diagonals and A is not symmetric, so it
// suits pivoting (lemke), not pgs. toBox() maps an answer back to the engine's rows: the
// normal impulse, and t1 = sum_j beta_j cos(theta_j), t2 = sum_j beta_j sin(theta_j).
//
// mu = 0: the tangent rows answer 0 and the normal stays a plain LCP row (frictionless()).
// mu = +inf never reaches it (findex needs a finite mu; ODE's dInfinity arrives as free rows).
//
// Contacts the cone cannot express are refused with a reason, and the caller keeps the box:
// more than two friction rows on one normal (Bullet's rolling friction), two tangents with
// different mu (anisotropic friction), bounds not of the form -mu..mu, tangents on other bodies
// than their normal, a normal row whose lower bound is not 0.
#pragma once

#include <string>
#include <vector>

#include "mlcp/island/friction_model.hpp"
#include "mlcp/problem.hpp"
#include "mlcp/rows.hpp"

namespace mlcp {

class FrictionCone {
 public:
  // Builds the cone form of the rows with `directions` directions per contact (>= 3; a contact
  // with a single tangent row gets its two directions +-t1). Returns "" on success; otherwise the
  // reason the rows do not fit (nothing usable is built). Rows without findex are kept.
  std::string build(const RowSystem& rows, int directions = kDefaultConeDirections,
                    bool sparse = false);

  // The standard-LCP (plus kept rows) problem: unknowns [kept rows; per contact its directions;
  // one lambda per contact].
  const Problem& problem() const { return problem_; }
  // Contacts in cone form (mu > 0), and those with mu = 0 (see above).
  int contacts() const { return static_cast<int>(contacts_.size()); }
  int frictionless() const { return frictionless_; }
  int directions() const { return directions_; }

  // A box-form start (size of the rows) in cone form: kept rows copied, each contact's tangent
  // impulse split over the two directions around it (nonnegative), lambda 0.
  Vector toCone(const Vector& xBox) const;
  // A cone-form answer as the engine's rows' impulses (size of the rows).
  Vector toBox(const Vector& xCone) const;

 private:
  struct Contact {
    int normal = -1;       // box row of the normal
    int t1 = -1, t2 = -1;  // box rows of the tangents (t2 = -1: a single tangent)
    double mu = 0;
    int firstDirection = 0;  // cone index of its first direction
    int directions = 0;
    int lambda = 0;  // cone index of its lambda
  };
  std::string groupContacts(const RowSystem& rows);
  void buildDirections(const RowSystem& rows, int directions);
  void assembleWithLambdas(bool sparse);

  std::vector<Contact> contacts_;
  std::vector<int> dropped_;  // tangent rows of mu = 0 contacts (answer 0)
  int frictionless_ = 0, directions_ = kDefaultConeDirections;
  std::vector<int> kept_;       // cone index i < kept_.size() holds box row kept_[i]
  std::vector<double> angles_;  // per cone direction index, theta_j (others unused)
  int boxSize_ = 0;
  RowSystem directionRows_;  // kept rows, then every direction row
  Problem problem_;
};

}  // namespace mlcp
