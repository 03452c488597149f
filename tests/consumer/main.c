/* The ODE stepper's C API from C, through the installed package (CMake here, pkg-config in
 * run.sh): exit 0 only when the sphere comes to rest on the plane with exact answers. */
#include <math.h>
#include <mlcp/ode/stepper.h>
#include <stdio.h>

#include "ode_drop.h"

struct run {
  mlcp_ode_stepper* stepper;
  int rows;
  double worst_residual;
};

static int step(void* context, dWorldID world, dReal h) {
  struct run* r = (struct run*)context;
  int ok = mlcp_ode_stepper_step(r->stepper, world, h);
  r->rows += mlcp_ode_stepper_last_rows(r->stepper);
  double res = mlcp_ode_stepper_last_residual(r->stepper);
  if (!(res <= r->worst_residual)) r->worst_residual = res;
  return ok;
}

int main(void) {
  if (mlcp_ode_stepper_create("no-such-solver") || mlcp_ode_last_error()[0] == '\0') {
    fprintf(stderr, "c: an unknown solver name was not refused\n");
    return 1;
  }
  struct run r = {mlcp_ode_stepper_create("dantzig"), 0, 0.0};
  if (!r.stepper) {
    fprintf(stderr, "c: %s\n", mlcp_ode_last_error());
    return 1;
  }
  double speed = 0;
  double height = ode_drop_run(&step, &r, &speed);
  mlcp_ode_stepper_destroy(r.stepper);
  int ok = fabs(height - 0.5) < 0.01 && speed < 0.01 && r.rows > 0 && r.worst_residual < 1e-6;
  printf("c: height %.4f m, speed %.2e m/s, %d rows, worst residual %.2e%s\n", height, speed,
         r.rows, r.worst_residual, ok ? "" : " (FAILED)");
  return ok ? 0 : 1;
}
