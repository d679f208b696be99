/* Stage 4, projection: u = u + du - beta grad phi with div(beta grad phi) =
 * div du, beta = rho_ref / rho_f on faces (1 for one density), the pressure
 * increments of the projection and of the augmented Lagrangian (step.h). */
#include <string.h>

#include "march/open_faces.h"
#include "march/step.h"

/* max |div u| h / max |u| above which a state is not solenoidal to round-off
 * (it is projected once more). */
#define DIVERGENCE_ROUNDOFF 1e-12
/* The projection's pressure solve stops once the divergence it leaves is
 * below this share of max |u| / h.  The VOF transport conserves the grains'
 * volume only as far as u is solenoidal: with 1e-13 the bagnold2 transient
 * (500 steps) lost 2e-12 of it, with 1e-15 none to the printed digits. */
#define DIVERGENCE_FLOOR 1e-15

void stage_divergence(const struct march_state *st, double *const v[3], double *out)
{
    if (st->embedded)
        embedded_divergence(&st->g, st->embedded, v, out);
    else
        kernel_divergence(&st->g, v, out);
}

/* vel -= beta grad phi (phi's ghosts filled). */
static void subtract_gradient(struct march_state *st, const double *phi)
{
    if (st->density_uniform)
        kernel_gradient_update(&st->g, st->act, phi, 1.0, st->field.velocity);
    else
        kernel_gradient_update_coef(&st->g, st->act, phi, 1.0, st->beta, st->field.velocity);
}

/* Open faces (boundary.h).  The normal velocity on an open face is not an
 * unknown of the implicit step: the step's operator moves it with the inner
 * face (the homogeneous fill copies the inner face's increment), so that
 * the step solves for the flow the face will carry.  With the face held
 * instead, a flow falling through open ends under gravity never became
 * steady: each step the inner faces moved and the open ones lagged, and the
 * projection turned the lag into a pressure that held the column up
 * (docs/numerics/open-boundaries.md).  Its increment is set
 * here, before the projection: the face's momentum balance is the inner
 * face's with zero normal gradient for every term but the pressure and the
 * body force, which are taken on the face itself with the Dirichlet ghost
 * (p = 0 on it):
 *   delta_f = delta_i + dt (a_f - a_i),  a = (F - grad p_dyn) / rho,
 * F = rho g - grad p_hyd.  Steady, delta = 0 on the face, so the pressure
 * gradient reaching the face equals the inner face's: the pressure falls to
 * 0 on the open face as it falls inside (without the a terms the level of
 * p_dyn would be whatever the march's history left).  The projection then
 * corrects the face with the same Dirichlet ghost, so that div u = 0 to
 * round-off in the boundary cells too. */

/* The open faces' increments and predicted velocities (see above). */
static void open_predict(struct march_state *st, double dt)
{
    FOR_OPEN_FACES(st, {
        double af = open_acceleration(st, d, pf, 1, pc, s);
        double ai = open_acceleration(st, d, pi, 0, pc, s);
        st->field.increment[d][pf] = st->field.increment[d][pi] + dt * (af - ai);
        st->field.velocity[d][pf] += st->field.increment[d][pf];
    })
}

/* The projection's correction -beta grad phi on the open faces (phi = 0 on
 * them). */
static void open_correct(struct march_state *st, const double *phi)
{
    FOR_OPEN_FACES(st, {
        (void)pi;
        double beta = st->density_uniform ? 1.0 : st->beta[d][pf];
        st->field.velocity[d][pf] -= beta * face_gradient(phi, pc, s, st->g.h[d]);
    })
}

/* The Poisson solve in place; its iterations and a failure to converge are
 * counted (the run reports them: the projection still takes the iterate). */
static void project_solve(struct march_state *st, double *rhs_phi, double floor)
{
    long before = pressure_iterations(st->pressure_solver);
    st->pressure_solves++;
    if (pressure_solve(st->pressure_solver, rhs_phi, rhs_phi, floor) != 0)
        st->pressure_unconverged++;
    st->pressure_iterations += pressure_iterations(st->pressure_solver) - before;
}

/* Whether the cell field f is 0 on every cell (the divergence of an
 * increment that has no component across the grid: a cross-section's flow
 * along its periodic direction of one cell, a profile's along the plane). */
static int all_zero(const struct grid *g, const double *f)
{
    int zero = 1;
#pragma omp parallel for collapse(2) schedule(static) reduction(&& : zero) \
    if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                zero = zero && f[grid_idx(g, i, j, k)] == 0.0;
    return zero;
}

void stage_projection(struct march_state *st, double dt)
{
    const struct grid *g = &st->g;
    /* u is solenoidal to round-off after the last projection, so
     * div u* = div u + div delta is div delta but for that round-off.  The
     * pressure updates are taken from div delta alone: the Uzawa update
     * -r div u* and the projection's (rho/dt) lap^-1 div u* would carry u's
     * round-off times r (large) or rho/dt (large once a rejected step cut dt:
     * a Newton step at dt 1e-9 then raised the residual whatever its
     * length).  The projection u = u* - grad lap^-1 div delta keeps div u at
     * round-off; a state whose own divergence is above it (not one this
     * march produced) gets a second projection. */
    bc_fill_velocity_homogeneous(g, &st->bc, st->field.increment);
    int open = bc_has_open(&st->bc);
    if (open)
        open_predict(st, dt);
    stage_divergence(st, st->field.increment, st->field.phi);
    if (st->aug) /* augmented-Lagrangian (Uzawa) update p -= r div u* */
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    st->field.p_dyn[p] -= st->aug[p] * st->field.phi[p];
                }
    kernel_axpy(g, st->act, 1.0, st->field.increment, st->field.velocity);
    /* a divergence at DIVERGENCE_FLOOR of |u| / h in the 2-norm (which bounds
     * every cell's): solving further changes nothing */
    double floor = pressure_uniform(st->pressure_solver)
                       ? 0.0 /* the FFT path is direct: no floor to pass */
                       : DIVERGENCE_FLOOR *
                             march_max(st, kernel_max_abs(g, st->act, st->field.velocity)) /
                             march_min_spacing(march_global_grid(st));
    /* div delta exactly 0 (the flow of a cross-section or a profile, whose
     * implicit step moves no component across the grid): phi is 0 and the
     * solve, its fill and the gradient would change nothing (the heap at
     * 140 x 200: 4 % of the run) */
    const int nothing = march_max(st, all_zero(g, st->field.phi) ? 0.0 : 1.0) == 0.0;
    if (nothing) {
        memset(st->field.phi, 0, g->size * sizeof *st->field.phi);
    } else {
        project_solve(st, st->field.phi, floor);
        bc_fill_pressure(g, &st->bc, st->field.phi);
        subtract_gradient(st, st->field.phi);
        if (open)
            open_correct(st, st->field.phi);
    }
    bc_fill_velocity(g, &st->bc, st->field.velocity);
    if (st->divergence > DIVERGENCE_ROUNDOFF) {
        stage_divergence(st, st->field.velocity, st->field.divergence);
        project_solve(st, st->field.divergence, floor);
        bc_fill_pressure(g, &st->bc, st->field.divergence);
        subtract_gradient(st, st->field.divergence);
        if (open) {
            open_correct(st, st->field.divergence);
            bc_fill_velocity(g, &st->bc, st->field.velocity);
        }
    }
    /* incremental pressure correction (rho/dt) lap^-1 div delta; with large
     * dt it is small and the Uzawa update carries the pressure */
    if (nothing)
        return; /* phi = 0: no correction */
    double scale = st->rho_ref / dt;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                st->field.p_dyn[p] += scale * st->field.phi[p];
            }
}
