// Closed forms of the two friction models for a body on a plane whose contact frame has its
// tangents t1, t2 along two fixed ground axes (the engines' frame for a horizontal normal when
// the friction direction does not follow the velocity), for a slope or a push in the direction
// at angle psi from t1:
//
//   cone (k directions d_j at 2 pi j / k):  sticking holds a tangential force up to mu N r(psi),
//     r = cos(pi / k) / cos(psi - nearest edge midpoint), the polygon's radius along psi; sliding
//     along psi meets mu N s(psi), s = cos(psi - nearest direction), the polygon's support
//     against the motion (maximal dissipation). At a direction both are 1; halfway between two
//     both are cos(pi / k). Elsewhere the slide turns toward the nearest direction.
//   box (|F_t1|, |F_t2| <= mu N each):  r = s = 1 / max(|cos psi|, |sin psi|) at the directions
//     where the slide keeps its direction (psi a multiple of pi / 4): 1 along a tangent,
//     sqrt(2) on a diagonal.
//
// An incline of slope alpha sticks iff tan(alpha) <= mu r(psi); sliding down it (along psi by
// symmetry) accelerates at g (sin(alpha) - mu s(psi) cos(alpha)). A push on flat ground
// decelerates at mu s(psi) g.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "mlcp/island/row_solver.hpp"

namespace mlcp::test {

inline constexpr double kConePi = 3.14159265358979323846;

// psi reduced to [0, step) modulo `step`.
inline double angleWithin(double psi, double step) {
  double a = std::fmod(psi, step);
  return a < 0 ? a + step : a;
}

// k = 0 stands for the box.
inline double frictionRadius(int k, double psi) {
  if (k == 0) return 1 / std::max(std::abs(std::cos(psi)), std::abs(std::sin(psi)));
  const double width = 2 * kConePi / k;
  const double fromMidpoint = angleWithin(psi, width) - width / 2;
  return std::cos(width / 2) / std::cos(fromMidpoint);
}

inline double frictionSupport(int k, double psi) {
  if (k == 0) return frictionRadius(0, psi);  // the box's corner: exact at multiples of pi / 4
  const double width = 2 * kConePi / k;
  const double a = angleWithin(psi, width);
  return std::cos(std::min(a, width - a));
}

// The engine tests' cases: along a direction of the polygon, halfway between two, on a diagonal,
// and the box (k = 0) on a diagonal, where it gives sqrt(2) mu.
struct FrictionCase {
  int k;  // 0: the box
  double psi;
};
inline constexpr FrictionCase kFrictionCases[] = {
    {4, 0}, {4, kConePi / 4}, {8, kConePi / 8}, {8, kConePi / 4}, {0, kConePi / 4}};

// An adapter's settings (bullet::Settings, ode::Settings) for a case's model, untimed: the box
// with dantzig, the cone with k directions and auto (lemke).
inline void useModel(RowSolverSettings& s, int k) {
  s.solver = k == 0 ? "dantzig" : "auto";
  s.friction = k == 0 ? FrictionModel::Box : FrictionModel::Cone;
  if (k > 0) s.frictionDirections = k;
  s.timeBudget = 0;
}

inline std::string caseName(const FrictionCase& c) {
  return (c.k == 0 ? std::string("box") : "cone k=" + std::to_string(c.k)) +
         " psi=" + std::to_string(c.psi);
}

}  // namespace mlcp::test
