// Closed-form physics through the ODE stepper: a box on an incline and a pendulum's period.
#include <gtest/gtest.h>

#include <cmath>

#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

namespace mlcp::ode::test {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = 3.14159265358979323846;

// A 0.5 m box on a plane tilted by `angle` about y; friction directions along and across the
// slope (fdir1 uphill), so ODE's friction box is exact for sliding straight down.
std::unique_ptr<Scene> incline(double angle, double mu) {
  auto s = std::make_unique<Scene>();
  const double n[3] = {-std::sin(angle), 0, std::cos(angle)};
  s->addPlane(n[0], n[1], n[2], 0);
  s->surface.mu = mu;
  s->surface.mode = dContactApprox1 | dContactFDir1;
  s->surface.fdir1[0] = std::cos(angle);
  s->surface.fdir1[1] = 0;
  s->surface.fdir1[2] = std::sin(angle);
  dBodyID b = s->addBox(0.25 * n[0], 0, 0.25 * n[2], 0.5, 0.5, 0.5);
  dMatrix3 R;
  dRFromAxisAndAngle(R, 0, 1, 0, -angle);
  dBodySetRotation(b, R);
  return s;
}

// Velocity along the slope (uphill positive).
double slopeVelocity(const Scene& s, double angle) {
  const dReal* v = dBodyGetLinearVel(s.bodies[0]);
  return v[0] * std::cos(angle) + v[2] * std::sin(angle);
}

class OdePhysics : public ::testing::TestWithParam<const char*> {};

TEST_P(OdePhysics, BoxSticksBelowTheFrictionAngle) {
  const double mu = 0.5, angle = std::atan(mu) - 0.1;
  auto s = incline(angle, mu);
  Stepper stepper(GetParam());
  const dReal h = 0.01;
  const auto stepFn = [&](dWorldID w, dReal dt) { ASSERT_TRUE(stepper.step(w, dt)); };
  for (int k = 0; k < 20; ++k) s->step(stepFn, h);
  const std::vector<double> start = s->state();
  for (int k = 0; k < 100; ++k) s->step(stepFn, h);
  const std::vector<double> end = s->state();
  const double moved = std::hypot(end[0] - start[0], end[2] - start[2]);
  EXPECT_LT(moved, 1e-3) << "the box crept " << moved << " m in 1 s";
  EXPECT_GT(s->lastContacts(), 0);
}

TEST_P(OdePhysics, BoxSlidesWithCoulombAccelerationAboveTheFrictionAngle) {
  const double mu = 0.3, angle = 0.6;  // 34 degrees, friction angle 17 degrees
  auto s = incline(angle, mu);
  Stepper stepper(GetParam());
  const dReal h = 0.01;
  const auto stepFn = [&](dWorldID w, dReal dt) { ASSERT_TRUE(stepper.step(w, dt)); };
  for (int k = 0; k < 20; ++k) s->step(stepFn, h);
  const double v1 = slopeVelocity(*s, angle);
  for (int k = 0; k < 100; ++k) s->step(stepFn, h);
  const double v2 = slopeVelocity(*s, angle);
  const double a = (v2 - v1) / (100 * h);
  const double expected = -kG * (std::sin(angle) - mu * std::cos(angle));
  EXPECT_NEAR(a, expected, 0.01 * std::fabs(expected));
  EXPECT_GT(s->lastContacts(), 0);
}

TEST_P(OdePhysics, PendulumPeriod) {
  // A sphere of radius r, mass m on a massless rod of length L: T = 2 pi sqrt(I_pivot / (m g L))
  // for small amplitudes, I_pivot = 2/5 m r^2 + m L^2.
  const double m = 1, r = 0.05, L = 1, amplitude = 0.05;
  Scene s;
  dBodyID b = s.addSphereBody(L * std::sin(amplitude), 0, -L * std::cos(amplitude), r, m);
  dJointID j = dJointCreateHinge(s.world, nullptr);
  dJointAttach(j, b, nullptr);
  dJointSetHingeAnchor(j, 0, 0, 0);
  dJointSetHingeAxis(j, 0, 1, 0);
  const double period = 2 * kPi * std::sqrt((0.4 * m * r * r + m * L * L) / (m * kG * L));

  Stepper stepper(GetParam());
  const dReal h = 0.002;
  double prevX = dBodyGetPosition(b)[0], t = 0;
  std::vector<double> crossings;  // downward zero crossings of x, linearly interpolated
  while (t < 5.5 * period) {
    ASSERT_TRUE(stepper.step(s.world, h));
    t += h;
    const double x = dBodyGetPosition(b)[0];
    if (prevX > 0 && x <= 0) crossings.push_back(t - h * x / (x - prevX));
    prevX = x;
  }
  ASSERT_GE(crossings.size(), 5u);
  const double measured = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  EXPECT_NEAR(measured, period, 0.01 * period);
}

INSTANTIATE_TEST_SUITE_P(Solvers, OdePhysics, ::testing::Values("dantzig", "pgs"));

}  // namespace
}  // namespace mlcp::ode::test
