/* mlcp/ode/stepper.h: the C interface of mlcp::ode::Stepper (see stepper.hpp).
 *
 *     mlcp_ode_stepper *s = mlcp_ode_stepper_create("dantzig");
 *     if (!s) fprintf(stderr, "%s\n", mlcp_ode_last_error());
 *     mlcp_ode_stepper_step(s, world, h);    // instead of dWorldStep(world, h)
 *     mlcp_ode_stepper_destroy(s);
 *
 * Everything the C++ stepper's settings hold (mlcp::ode::Settings, with the defaults documented
 * in mlcp/island/row_solver.hpp and stepper.hpp) can be set here, except the diagnostics whose
 * output is a C++ object (reference, keepProblems, Options::recordHistory).
 *
 * Errors. No C++ exception leaves these functions. Every function that can fail returns
 * MLCP_ODE_OK (1) on success and MLCP_ODE_ERROR (0) on failure (create: NULL), and then
 * mlcp_ode_last_error() names the function and the reason; the setting or the stepper is then
 * unchanged. A NULL stepper is an error for every function (the statistics then return 0).
 */
#ifndef MLCP_ODE_STEPPER_H
#define MLCP_ODE_STEPPER_H

#include <ode/ode.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct mlcp_ode_stepper mlcp_ode_stepper;

#define MLCP_ODE_OK 1
#define MLCP_ODE_ERROR 0

/* Which solver's options a setter changes. */
#define MLCP_ODE_PRIMARY 0
#define MLCP_ODE_FALLBACK 1

/* Friction bound handling (mlcp::FrictionBounds): the bounds follow the normal force exactly,
 * or are fixed once from an intermediate normal force as dWorldStep's dxSolveLCP does (for
 * trajectories equal to dWorldStep's with dContactApprox1 friction). */
#define MLCP_ODE_FRICTION_EXACT 0
#define MLCP_ODE_FRICTION_FIXED_ONCE 1

/* Friction model of contacts (mlcp::FrictionModel, mlcp/island/friction_model.hpp): ODE's own box
 * (dContactApprox1 pyramid, the default), or the polyhedral cone's LCP with k directions per
 * contact (friction within mu N in every direction; core solvers that take an LCP only). */
#define MLCP_ODE_FRICTION_MODEL_BOX 0
#define MLCP_ODE_FRICTION_MODEL_CONE 1

/* A stepper with the named solver and default settings, or NULL (see mlcp_ode_last_error). */
mlcp_ode_stepper* mlcp_ode_stepper_create(const char* solver);
void mlcp_ode_stepper_destroy(mlcp_ode_stepper* stepper);

/* Options of the primary solver (MLCP_ODE_PRIMARY) or of the fallback (MLCP_ODE_FALLBACK),
 * mlcp::Options; they take effect at the next step and keep the warm start.
 *   tolerance        scaled residual target, finite and > 0 (default 1e-6)
 *   max_iterations   sweeps / outer iterations, >= 1 (primary 1000, fallback 100; with the
 *                    engine's iterations on, pgs/gs run the world's QuickStep count instead)
 *   max_pivots       pivot limit of pivoting methods, >= 0, 0 automatic (default 0)
 *   relaxation       SOR factor of gs/pgs in (0, 2) (default 1; engine iterations: QuickStep's W)
 *   check_every      residual check every this many sweeps, >= 1 (default 1)
 *   friction_bounds  MLCP_ODE_FRICTION_EXACT (default) or MLCP_ODE_FRICTION_FIXED_ONCE
 *   pivot_tolerance  pivot magnitude treated as zero, finite and >= 0 (default 1e-12)
 *   time_budget      wall-clock seconds per solve, finite and >= 0, 0 none (default 0) */
int mlcp_ode_stepper_set_solver_tolerance(mlcp_ode_stepper* stepper, int which, double tolerance);
int mlcp_ode_stepper_set_solver_max_iterations(mlcp_ode_stepper* stepper, int which,
                                               int iterations);
int mlcp_ode_stepper_set_solver_max_pivots(mlcp_ode_stepper* stepper, int which, int pivots);
int mlcp_ode_stepper_set_solver_relaxation(mlcp_ode_stepper* stepper, int which, double omega);
int mlcp_ode_stepper_set_solver_check_every(mlcp_ode_stepper* stepper, int which, int sweeps);
int mlcp_ode_stepper_set_solver_friction_bounds(mlcp_ode_stepper* stepper, int which, int mode);
int mlcp_ode_stepper_set_solver_pivot_tolerance(mlcp_ode_stepper* stepper, int which,
                                                double tolerance);
int mlcp_ode_stepper_set_solver_time_budget(mlcp_ode_stepper* stepper, int which, double seconds);
/* The primary's tolerance and iteration limit (the set_solver_ calls with MLCP_ODE_PRIMARY). */
int mlcp_ode_stepper_set_tolerance(mlcp_ode_stepper* stepper, double tolerance);
int mlcp_ode_stepper_set_max_iterations(mlcp_ode_stepper* stepper, int iterations);

/* The stepper's own settings (mlcp::ode::Settings). Each rebuilds the stepper with the new
 * value, so it also forgets the warm start (as mlcp_ode_stepper_reset_warm_start).
 *   fallback             a core solver name, or "" / NULL for none (default "pgs")
 *   accept_residual      largest accepted scaled residual, >= 0, +inf accepts any finite answer
 *                        (default 1e-3)
 *   dense_max_rows       largest island given a dense matrix, >= 0 (default 64)
 *   engine_iterations    1: pgs/gs run the world's dWorldGetQuickStepNumIterations sweeps with
 *                        dWorldGetQuickStepW as relaxation; 0: the options' limits (default 1)
 *   warm_start           1: start from last step's forces; 0: from zero (default 1)
 *   contact_match_distance  largest distance at which last step's contact warm-starts a
 *                        contact, m, finite and >= 0 (default 0.05) */
int mlcp_ode_stepper_set_fallback(mlcp_ode_stepper* stepper, const char* solver);
int mlcp_ode_stepper_set_accept_residual(mlcp_ode_stepper* stepper, double residual);
int mlcp_ode_stepper_set_dense_max_rows(mlcp_ode_stepper* stepper, int rows);
int mlcp_ode_stepper_set_engine_iterations(mlcp_ode_stepper* stepper, int on);
int mlcp_ode_stepper_set_warm_start(mlcp_ode_stepper* stepper, int on);
int mlcp_ode_stepper_set_contact_match_distance(mlcp_ode_stepper* stepper, double distance);
/* The friction model, MLCP_ODE_FRICTION_MODEL_BOX or MLCP_ODE_FRICTION_MODEL_CONE, and the
 * cone's directions per contact, 3 to 64 (default 4; checked for either model). Rebuilds the
 * stepper like the setters above. MLCP_ODE_ERROR (stepper unchanged) for an unknown model,
 * directions out of range, or the cone with a solver that cannot take an LCP (pgs, gs, ldlt,
 * ode-step, ode-quickstep, ode-lcp). */
int mlcp_ode_stepper_set_friction_model(mlcp_ode_stepper* stepper, int model, int directions);
/* Forget the warm-start cache (e.g. after teleporting bodies). */
int mlcp_ode_stepper_reset_warm_start(mlcp_ode_stepper* stepper);

/* Wall-clock budget of one step's island solves in seconds, 0 for none (default 0.05; see
 * mlcp/island/row_solver.hpp): when it runs out a solve returns its best answer so far, never worse
 * than its start. MLCP_ODE_ERROR for a negative or non-finite value (unchanged then). */
int mlcp_ode_set_time_budget(mlcp_ode_stepper* stepper, double seconds);

/* Like dWorldStep: MLCP_ODE_OK, or MLCP_ODE_ERROR when ODE could not allocate working memory,
 * the arguments are invalid (NULL world, stepsize <= 0) or the step failed (the message says
 * why; the world may then be part-way through the step). */
int mlcp_ode_stepper_step(mlcp_ode_stepper* stepper, dWorldID world, dReal stepsize);

/* Statistics of the last step: constraint rows, islands, islands whose primary answer was
 * rejected (the fallback ran), islands whose applied answer is still rejected, the largest
 * island residual (0 without rows; NaN when not measured), the largest iteration count, and
 * the step's wall time in seconds. */
int mlcp_ode_stepper_last_rows(const mlcp_ode_stepper* stepper);
int mlcp_ode_stepper_last_islands(const mlcp_ode_stepper* stepper);
int mlcp_ode_stepper_last_fallbacks(const mlcp_ode_stepper* stepper);
int mlcp_ode_stepper_last_failures(const mlcp_ode_stepper* stepper);
double mlcp_ode_stepper_last_residual(const mlcp_ode_stepper* stepper);
int mlcp_ode_stepper_last_iterations(const mlcp_ode_stepper* stepper);
double mlcp_ode_stepper_last_seconds(const mlcp_ode_stepper* stepper);

/* The message of the last failed call on this thread ("" if none since the last create). */
const char* mlcp_ode_last_error(void);

#ifdef __cplusplus
}
#endif

#endif
