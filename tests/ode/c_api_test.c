/* The C interface (mlcp/ode/stepper.h), compiled as C: every setting set and rejected, errors
 * reported through the return code and mlcp_ode_last_error, and a spinning, sliding box with
 * dContactApprox1 friction stepped with dantzig whose friction bounds are fixed once, as
 * dWorldStep fixes them, following dWorldStep's trajectory to round-off. Exit 0 on success. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mlcp/ode/stepper.h"

static int failures = 0;

#define CHECK(cond)                                                     \
  do {                                                                  \
    if (!(cond)) {                                                      \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                       \
    }                                                                   \
  } while (0)

/* The call failed and the last error starts with the function's name. */
#define CHECK_ERROR(call, function)                                       \
  do {                                                                    \
    CHECK((call) == MLCP_ODE_ERROR);                                      \
    CHECK(strncmp(mlcp_ode_last_error(), function, strlen(function)) == 0); \
  } while (0)

static void settersAcceptValidValues(void) {
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("dantzig");
  int which;
  CHECK(s != NULL);
  for (which = MLCP_ODE_PRIMARY; which <= MLCP_ODE_FALLBACK; ++which) {
    CHECK(mlcp_ode_stepper_set_solver_tolerance(s, which, 1e-8) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_max_iterations(s, which, 50) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_max_pivots(s, which, 0) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_relaxation(s, which, 1.3) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_check_every(s, which, 5) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_friction_bounds(s, which, MLCP_ODE_FRICTION_FIXED_ONCE) ==
          MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_pivot_tolerance(s, which, 1e-13) == MLCP_ODE_OK);
    CHECK(mlcp_ode_stepper_set_solver_time_budget(s, which, 0.5) == MLCP_ODE_OK);
  }
  CHECK(mlcp_ode_stepper_set_tolerance(s, 1e-7) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_max_iterations(s, 30) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_fallback(s, "ldlt") == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_fallback(s, NULL) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_fallback(s, "pgs") == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_accept_residual(s, INFINITY) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_accept_residual(s, 1e-4) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_dense_max_rows(s, 16) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_engine_iterations(s, 0) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_warm_start(s, 0) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_contact_match_distance(s, 0.01) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_reset_warm_start(s) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_friction_model(s, MLCP_ODE_FRICTION_MODEL_CONE, 8) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_friction_model(s, MLCP_ODE_FRICTION_MODEL_BOX, 4) == MLCP_ODE_OK);
  mlcp_ode_stepper_destroy(s);
}

static void settersRejectBadValues(void) {
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("pgs");
  CHECK(s != NULL);
  CHECK_ERROR(mlcp_ode_stepper_set_friction_model(s, MLCP_ODE_FRICTION_MODEL_CONE, 4),
              "mlcp_ode_stepper_set_friction_model");
  CHECK(strstr(mlcp_ode_last_error(), "pgs") != NULL);
  CHECK_ERROR(mlcp_ode_stepper_set_friction_model(s, MLCP_ODE_FRICTION_MODEL_BOX, 2),
              "mlcp_ode_stepper_set_friction_model");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_tolerance(s, MLCP_ODE_PRIMARY, 0),
              "mlcp_ode_stepper_set_solver_tolerance");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_tolerance(s, MLCP_ODE_PRIMARY, NAN),
              "mlcp_ode_stepper_set_solver_tolerance");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_tolerance(s, 7, 1e-6),
              "mlcp_ode_stepper_set_solver_tolerance");
  CHECK(strstr(mlcp_ode_last_error(), "MLCP_ODE_PRIMARY") != NULL);
  CHECK_ERROR(mlcp_ode_stepper_set_solver_max_iterations(s, MLCP_ODE_FALLBACK, 0),
              "mlcp_ode_stepper_set_solver_max_iterations");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_max_pivots(s, MLCP_ODE_PRIMARY, -1),
              "mlcp_ode_stepper_set_solver_max_pivots");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_relaxation(s, MLCP_ODE_PRIMARY, 2.0),
              "mlcp_ode_stepper_set_solver_relaxation");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_check_every(s, MLCP_ODE_PRIMARY, 0),
              "mlcp_ode_stepper_set_solver_check_every");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_friction_bounds(s, MLCP_ODE_PRIMARY, 2),
              "mlcp_ode_stepper_set_solver_friction_bounds");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_pivot_tolerance(s, MLCP_ODE_PRIMARY, -1),
              "mlcp_ode_stepper_set_solver_pivot_tolerance");
  CHECK_ERROR(mlcp_ode_stepper_set_solver_time_budget(s, MLCP_ODE_PRIMARY, INFINITY),
              "mlcp_ode_stepper_set_solver_time_budget");
  CHECK_ERROR(mlcp_ode_stepper_set_tolerance(s, -1), "mlcp_ode_stepper_set_solver_tolerance");
  CHECK_ERROR(mlcp_ode_stepper_set_fallback(s, "no-such-solver"), "mlcp_ode_stepper_set_fallback");
  CHECK(strstr(mlcp_ode_last_error(), "no-such-solver") != NULL);
  CHECK_ERROR(mlcp_ode_stepper_set_accept_residual(s, NAN), "mlcp_ode_stepper_set_accept_residual");
  CHECK_ERROR(mlcp_ode_stepper_set_dense_max_rows(s, -2), "mlcp_ode_stepper_set_dense_max_rows");
  CHECK_ERROR(mlcp_ode_stepper_set_contact_match_distance(s, -1),
              "mlcp_ode_stepper_set_contact_match_distance");
  /* A NULL stepper is an error everywhere; statistics of NULL are 0. */
  CHECK_ERROR(mlcp_ode_stepper_set_warm_start(NULL, 1), "mlcp_ode_stepper_set_warm_start");
  CHECK(strstr(mlcp_ode_last_error(), "NULL") != NULL);
  CHECK_ERROR(mlcp_ode_stepper_set_solver_tolerance(NULL, 0, 1e-6),
              "mlcp_ode_stepper_set_solver_tolerance");
  CHECK_ERROR(mlcp_ode_stepper_reset_warm_start(NULL), "mlcp_ode_stepper_reset_warm_start");
  CHECK_ERROR(mlcp_ode_stepper_step(NULL, NULL, 0.01), "mlcp_ode_stepper_step");
  CHECK_ERROR(mlcp_ode_stepper_step(s, NULL, 0.01), "mlcp_ode_stepper_step");
  CHECK(mlcp_ode_stepper_last_rows(NULL) == 0);
  CHECK(mlcp_ode_stepper_last_residual(NULL) == 0);
  mlcp_ode_stepper_destroy(s);
  mlcp_ode_stepper_destroy(NULL);

  CHECK(mlcp_ode_stepper_create("no-such-solver") == NULL);
  CHECK(strstr(mlcp_ode_last_error(), "no-such-solver") != NULL);
  CHECK(mlcp_ode_stepper_create(NULL) == NULL);
  CHECK_ERROR(0, "mlcp_ode_stepper_create");
}

/* A box sliding and spinning on a plane, dContactApprox1 friction (mu 0.6). */
typedef struct {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  dBodyID box;
  dGeomID boxGeom, plane;
} Top;

static void makeTop(Top* t) {
  dMass m;
  t->world = dWorldCreate();
  dWorldSetGravity(t->world, 0, 0, -9.81);
  t->space = dSimpleSpaceCreate(NULL);
  t->contacts = dJointGroupCreate(0);
  t->plane = dCreatePlane(t->space, 0, 0, 1, 0);
  t->box = dBodyCreate(t->world);
  dMassSetBox(&m, 1000, 0.4, 0.4, 0.2);
  dBodySetMass(t->box, &m);
  dBodySetPosition(t->box, 0, 0, 0.099);
  dBodySetLinearVel(t->box, 2.0, 0.5, 0);
  dBodySetAngularVel(t->box, 0, 0, 8.0);
  t->boxGeom = dCreateBox(t->space, 0.4, 0.4, 0.2);
  dGeomSetBody(t->boxGeom, t->box);
}

static void collideTop(Top* t) {
  dContactGeom geoms[8];
  int n = dCollide(t->boxGeom, t->plane, 8, geoms, sizeof(dContactGeom)), k;
  for (k = 0; k < n; ++k) {
    dContact c;
    memset(&c, 0, sizeof c);
    c.surface.mode = dContactApprox1;
    c.surface.mu = 0.6;
    c.geom = geoms[k];
    dJointAttach(dJointCreateContact(t->world, t->contacts, &c), t->box, NULL);
  }
}

static void destroyTop(Top* t) {
  dJointGroupDestroy(t->contacts);
  dSpaceDestroy(t->space);
  dWorldDestroy(t->world);
}

/* Largest distance between the boxes' positions over `steps` steps of dWorldStep and of s. */
static double topDistance(mlcp_ode_stepper* s, int steps, int* rows) {
  Top stock, ours;
  double worst = 0;
  int i, k;
  makeTop(&stock);
  makeTop(&ours);
  *rows = 0;
  for (i = 0; i < steps; ++i) {
    const dReal *a, *b;
    collideTop(&stock);
    collideTop(&ours);
    CHECK(dWorldStep(stock.world, 0.01) == 1);
    CHECK(mlcp_ode_stepper_step(s, ours.world, 0.01) == MLCP_ODE_OK);
    *rows += mlcp_ode_stepper_last_rows(s);
    dJointGroupEmpty(stock.contacts);
    dJointGroupEmpty(ours.contacts);
    a = dBodyGetPosition(stock.box);
    b = dBodyGetPosition(ours.box);
    for (k = 0; k < 3; ++k)
      if (fabs(a[k] - b[k]) > worst) worst = fabs(a[k] - b[k]);
  }
  destroyTop(&stock);
  destroyTop(&ours);
  return worst;
}

static void fixedOnceFrictionFollowsDWorldStep(void) {
  mlcp_ode_stepper* s = mlcp_ode_stepper_create("dantzig");
  int rows = 0;
  double exact, fixedOnce;
  CHECK(s != NULL);
  /* dWorldStep's own terms: every step from zero, no fallback. */
  CHECK(mlcp_ode_stepper_set_warm_start(s, 0) == MLCP_ODE_OK);
  CHECK(mlcp_ode_stepper_set_fallback(s, "") == MLCP_ODE_OK);
  exact = topDistance(s, 150, &rows);
  CHECK(rows > 0);
  CHECK(mlcp_ode_stepper_last_islands(s) == 1);
  CHECK(mlcp_ode_stepper_last_seconds(s) > 0);
  CHECK(mlcp_ode_stepper_set_solver_friction_bounds(s, MLCP_ODE_PRIMARY,
                                                    MLCP_ODE_FRICTION_FIXED_ONCE) == MLCP_ODE_OK);
  fixedOnce = topDistance(s, 150, &rows);
  CHECK(mlcp_ode_stepper_last_failures(s) == 0);
  printf("box with dContactApprox1, 150 steps: |x - dWorldStep's| exact %.3g m, fixed once %.3g m\n",
         exact, fixedOnce);
  CHECK(fixedOnce <= 1e-9);
  CHECK(exact > 1e-6); /* the setting is what makes the difference */
  mlcp_ode_stepper_destroy(s);
}

int main(void) {
  dInitODE2(0);
  settersAcceptValidValues();
  settersRejectBadValues();
  fixedOnceFrictionFollowsDWorldStep();
  dCloseODE();
  if (failures) fprintf(stderr, "%d checks failed\n", failures);
  return failures ? 1 : 0;
}
