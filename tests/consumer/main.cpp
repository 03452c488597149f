// Uses the installed package as a program would: a core solve, a Bullet world and an ODE world
// stepped by our solvers. Exit 0 only when every part converged and both bodies came to rest on
// the ground.
#include <cmath>
#include <cstdio>
#include <mlcp/ode/stepper.hpp>
#include <mlcp/registry.hpp>

#include "bullet_drop.hpp"
#include "ode_drop.h"

namespace {

bool coreSolve() {
  mlcp::DenseMatrix A(2, 2);
  A << 2, 1, 1, 2;
  mlcp::Problem p(A, mlcp::Vector::Constant(2, -1.0));
  auto solver = mlcp::makeSolver("pgs");
  mlcp::Vector x;
  const mlcp::Result r = solver->solve(p, x);
  std::printf("core: %s residual %.2e x = (%g, %g)\n", mlcp::toString(r.status), r.residual, x[0],
              x[1]);
  return r.converged() && std::abs(x[0] - 1.0 / 3) < 1e-8 && std::abs(x[1] - 1.0 / 3) < 1e-8;
}

bool atRest(const char* what, double height, double speed) {
  const bool ok = std::abs(height - 0.5) < 0.01 && speed < 0.01;
  std::printf("%s: height %.4f m, speed %.2e m/s%s\n", what, height, speed,
              ok ? "" : " (not at rest)");
  return ok;
}

bool bulletWorld() {
  const BulletDrop d = bulletDrop("dantzig");
  std::printf("bullet: %d islands solved, worst residual %.2e\n", d.solvedIslands, d.worstResidual);
  return atRest("bullet", d.height, d.speed) && d.solvedIslands > 0 && d.worstResidual < 1e-6;
}

struct OdeRun {
  mlcp::ode::Stepper stepper{"dantzig"};
  int rows = 0;
  double worstResidual = 0;
};

int stepOde(void* context, dWorldID world, dReal h) {
  auto* run = static_cast<OdeRun*>(context);
  const bool ok = run->stepper.step(world, h);
  run->rows += run->stepper.lastStep().rows();
  run->worstResidual = std::max(run->worstResidual, run->stepper.lastStep().maxResidual());
  return ok ? 1 : 0;
}

bool odeWorld() {
  OdeRun run;
  double speed = 0;
  const double height = ode_drop_run(&stepOde, &run, &speed);
  std::printf("ode: %d rows solved, worst residual %.2e\n", run.rows, run.worstResidual);
  return atRest("ode", height, speed) && run.rows > 0 && run.worstResidual < 1e-6;
}

}  // namespace

int main() {
  const bool core = coreSolve();
  const bool bullet = bulletWorld();
  const bool ode = odeWorld();
  return core && bullet && ode ? 0 : 1;
}
