/* Stage 2b, the time scheme (step.h): what BDF2 adds to the residual before
 * the implicit step, and the step's mass coefficient.
 *
 * The variable-step BDF2 with the explicit terms extrapolated (SBDF2;
 * Guermond, Minev & Shen 2006, "An overview of projection methods for
 * incompressible flows"), w = dt_n / dt_{n-1}:
 *   rho [a0 u* - (1 + w) u^n + w^2 / (1 + w) u^{n-1}] / dt
 *     = f - grad p^n + div tau(u*) + rho [(1 + w) A^n - w A^{n-1}],
 * a0 = (1 + 2w) / (1 + w), A = -div(u u).  In the increment du = u* - u^n
 * of the implicit step, with the evaluated residual R (which holds rho A^n
 * and div tau(u^n)):
 *   (rho a0 / dt) du - div tau(du)
 *     = R + rho [w (A^n - A^{n-1}) + w^2 / ((1 + w) dt) (u^n - u^{n-1})],
 * the Euler step's with the mass rho / (dt / a0) and two more terms.  The
 * projection takes the same dt / a0 (the standard incremental form:
 * p^{n+1} = p^n + (rho a0 / dt) phi, second order in the velocity).  w = 0
 * is Euler's step, the first one's: no state a step before. */
#include <string.h>

#include "kernels/embedded.h"
#include "march/step.h"

/* dst = src over the whole arrays, ghosts included */
static void copy_faces(const struct grid *g, double *dst[3], double *const src[3])
{
    for (int c = 0; c < 3; c++)
        memcpy(dst[c], src[c], g->size * sizeof *dst[c]);
}

double stage_time_scheme(struct march_state *st, double dt)
{
    const struct muflow_case *cs = st->cs;
    if (cs->time_scheme != TIME_BDF2)
        return dt;
    const struct grid *g = &st->g;
    double *const *u = st->field.velocity, *const *a = st->field.advection;
    /* without advection its arrays are not allocated (core_fields.c):
     * advection_previous is an array of three NULL pointers, not NULL */
    double **u_prev = st->field.velocity_previous;
    double **a_prev = st->field.advection_previous[0] ? st->field.advection_previous : NULL;
    double a0 = 1.0;
    if (st->bdf2_steps > 0) {
        double w = dt / st->dt, cu = w * w / ((1.0 + w) * dt);
        a0 = (1.0 + 2.0 * w) / (1.0 + w);
        /* the two terms into the previous step's arrays, which are
         * overwritten below: u_prev = cu (u - u_prev) + w (A - A_prev) */
        kernel_lincomb(g, st->act, cu, u, -cu, u_prev);
        if (a_prev) {
            kernel_axpy(g, st->act, -w, a_prev, u_prev);
            kernel_axpy(g, st->act, w, a, u_prev);
        }
        if (st->embedded) /* the held nodes' residual stays 0 (obstacle.c) */
            embedded_zero(st->embedded, u_prev);
        if (st->density_uniform)
            kernel_axpy(g, st->act, cs->density, u_prev, st->field.residual);
        else
            kernel_multiply_add(g, st->act, st->field.density_faces, u_prev, st->field.residual);
        /* the first BDF2 step changes the mass from rho / dt: a kept
         * factorisation of Euler's operator would precondition every later
         * step (and a continued run, which factorises anew, would differ) */
        if (st->bdf2_steps == 1)
            viscous_renew(st->viscous);
    }
    copy_faces(g, u_prev, u);
    if (a_prev)
        copy_faces(g, a_prev, a);
    st->bdf2_steps++;
    return dt / a0;
}
