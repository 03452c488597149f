/* A sphere (radius 0.5 m, 1 kg) dropped from 0.2 m onto a plane in a stock ODE world, stepped
 * by the given function instead of dWorldStep. Shared by the C++ and the C consumer. */
#ifndef ODE_DROP_H
#define ODE_DROP_H

#include <ode/ode.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef int (*ode_drop_step_fn)(void* context, dWorldID world, dReal h);

/* Steps 150 times with h = 0.01 s; returns the sphere's final height (m, 0.5 at rest) and its
 * speed in *speed, or -1 when a step failed. */
double ode_drop_run(ode_drop_step_fn step, void* context, double* speed);

#ifdef __cplusplus
}
#endif

#endif
