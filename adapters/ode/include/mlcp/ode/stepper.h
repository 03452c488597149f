/* mlcp/ode/stepper.h: the C interface of mlcp::ode::Stepper (see stepper.hpp).
 *
 *     mlcp_ode_stepper *s = mlcp_ode_stepper_create("dantzig");
 *     if (!s) fprintf(stderr, "%s\n", mlcp_ode_last_error());
 *     mlcp_ode_stepper_step(s, world, h);    // instead of dWorldStep(world, h)
 *     mlcp_ode_stepper_destroy(s);
 */
#ifndef MLCP_ODE_STEPPER_H
#define MLCP_ODE_STEPPER_H

#include <ode/ode.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mlcp_ode_stepper mlcp_ode_stepper;

/* A stepper with the named solver and default options, or NULL (see mlcp_ode_last_error). */
mlcp_ode_stepper* mlcp_ode_stepper_create(const char* solver);
void mlcp_ode_stepper_destroy(mlcp_ode_stepper* stepper);
/* Core solver settings: residual tolerance (default 1e-10) and iteration limit (default 1000).
 * Return 1, or 0 for an invalid value (the setting is then unchanged). */
int mlcp_ode_stepper_set_tolerance(mlcp_ode_stepper* stepper, double tolerance);
int mlcp_ode_stepper_set_max_iterations(mlcp_ode_stepper* stepper, int iterations);
/* Wall-clock budget of one step's island solves in seconds, 0 for none (default 0.05; see
 * mlcp/row_solver.hpp): when it runs out a solve returns its best answer so far, never worse
 * than its start. Returns 1, or 0 for a negative or non-finite value (unchanged then). */
int mlcp_ode_set_time_budget(mlcp_ode_stepper* stepper, double seconds);
/* Like dWorldStep: 1 on success, 0 when ODE could not allocate working memory. */
int mlcp_ode_stepper_step(mlcp_ode_stepper* stepper, dWorldID world, dReal stepsize);
/* Statistics of the last step: constraint rows, largest island residual, fallbacks used. */
int mlcp_ode_stepper_last_rows(const mlcp_ode_stepper* stepper);
double mlcp_ode_stepper_last_residual(const mlcp_ode_stepper* stepper);
int mlcp_ode_stepper_last_fallbacks(const mlcp_ode_stepper* stepper);
/* The message of the last failed create/set call on this thread ("" if none). */
const char* mlcp_ode_last_error(void);

#ifdef __cplusplus
}
#endif

#endif
