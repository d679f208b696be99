/* A steady solve at a prescribed mean velocity (a scene's module, started by
 * flow_rate_restart; the cylinder's continuation in U): the
 * size of the body force, its gravity g, becomes an unknown of the coupled
 * Newton step, and the step's extra equation holds the mean velocity along
 * the force at U.
 *
 * Why: a granular flow driven past a body (scene cylinder) slides as a plug
 * on thin sheared layers, and mu(I) at small I makes the force nearly
 * independent of the speed: the Newton step's response of the plug's speed
 * to the force is large and poorly resolved, and a continuation in the
 * force crawls (pseudo-time steps cut to 1e-6 for hundreds of steps) and
 * ends short of the limit of steady flow, where dU/dF grows without bound.
 * With U given, that mode is fixed by the constraint and the force follows:
 * F(U) rises to the limit instead of U running away from it.
 *
 * The bordered step: with K the coupled step's matrix, b its right-hand side
 * and f = d(residual)/dg (the body force per unit g on the velocity
 * unknowns), K x1 = b and K x2 = f share one factorisation; the mean velocity
 * is linear, U = w . u, so dg = (U* - U - w . x1) / (w . x2) and the step
 * is x1 + dg x2: U is exact after every step.
 *
 * The gravity is a cell field (uniform, "driving_gravity"): a rejected step,
 * the line search's blend, the continuation's secant and the checkpoint
 * carry it like the velocity.  The force's hydrostatic part would depend on
 * g through the rheology's pressure: the module asks for a force along z
 * (tilt 0) through a periodic z, where it has none. */
#ifndef MUFLOW_PHYSICS_FLOW_RATE_H
#define MUFLOW_PHYSICS_FLOW_RATE_H

#include <stddef.h>
#include "march/march.h"

extern const struct module flow_rate_module;

/* NULL when a march of this case can hold its mean velocity, else why not
 * (a phrase starting "needs", for a message naming the key that asks). */
const char *flow_rate_refusal(const struct muflow_case *cs);

/* 1 while the module holds a mean velocity (started with U > 0), else 0. */
int flow_rate_held(const struct march_state *st);

/* The gravity the state holds, or NAN without the module. */
double flow_rate_gravity(const struct march_state *st);

/* A new start at gravity g and mean velocity U > 0, or U = 0: idle, the
 * force the case's (call after march_reforce, which computes the force at
 * the case's gravity; a scene lists the module and starts it idle).
 * Returns 0, or -1 with the reason in err when the march cannot hold U
 * (flow_rate_refusal, or a start at g <= 0). */
int flow_rate_restart(struct march_state *st, double g, double U, char *err, size_t errlen);

/* For the coupled step: into f (a face field triple, overwritten) the
 * residual's derivative in g, and into *gap the target less the mean
 * velocity.  Returns 0, or -1 without the module. */
int flow_rate_border(struct march_state *st, double *f[3], double *gap);

/* The mean velocity of the face field triple u along the force (the
 * constraint's functional; NAN while idle), over the whole domain: the one
 * sum of the module, taken over the ranks (collective). */
double flow_rate_mean(const struct march_state *st, double *const u[3]);

/* The step's increment of g (applied with the velocity's). */
void flow_rate_increment(struct march_state *st, double dg);

#endif
