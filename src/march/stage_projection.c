/* Stage 4, projection: u = u + du - beta grad phi with div(beta grad phi) =
 * div du, beta = rho_ref / rho_f on faces (1 for one density), the pressure
 * increments of the projection and of the augmented Lagrangian (step.h). */
#include "march/step.h"

/* max |div u| h / max |u| above which a state is not solenoidal to round-off
 * (it is projected once more). */
#define DIVERGENCE_ROUNDOFF 1e-12
/* The projection's pressure solve stops once the divergence it leaves is
 * below this share of max |u| / h.  The VOF transport conserves the grains'
 * volume only as far as u is solenoidal: with 1e-13 the bagnold2 transient
 * (500 steps) lost 2e-12 of it, with 1e-15 none to the printed digits. */
#define DIVERGENCE_FLOOR 1e-15

/* vel -= beta grad phi (phi's ghosts filled). */
static void subtract_gradient(struct march_state *st, const double *phi)
{
    if (st->density_uniform)
        kernel_gradient_update(&st->g, st->act, phi, 1.0, st->vel);
    else
        kernel_gradient_update_coef(&st->g, st->act, phi, 1.0, st->beta, st->vel);
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
    bc_fill_velocity_homogeneous(g, &st->bc, st->delta);
    kernel_divergence(g, st->delta, st->phi);
    if (st->aug) /* augmented-Lagrangian (Uzawa) update p -= r div u* */
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    st->p_dyn[p] -= st->aug[p] * st->phi[p];
                }
    kernel_axpy(g, st->act, 1.0, st->delta, st->vel);
    /* a divergence at DIVERGENCE_FLOOR of |u| / h in the 2-norm (which bounds
     * every cell's): solving further changes nothing */
    double floor = DIVERGENCE_FLOOR * kernel_max_abs(g, st->act, st->vel) /
                   march_min_spacing(g);
    pressure_solve(st->pressure_solver, st->phi, st->phi, floor);
    bc_fill_scalar(g, &st->bc, st->phi);
    subtract_gradient(st, st->phi);
    bc_fill_velocity(g, &st->bc, st->vel);
    if (st->divergence > DIVERGENCE_ROUNDOFF) {
        kernel_divergence(g, st->vel, st->div);
        pressure_solve(st->pressure_solver, st->div, st->div, floor);
        bc_fill_scalar(g, &st->bc, st->div);
        subtract_gradient(st, st->div);
    }
    /* incremental pressure correction (rho/dt) lap^-1 div delta; with large
     * dt it is small and the Uzawa update carries the pressure */
    double scale = st->rho_ref / dt;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                st->p_dyn[p] += scale * st->phi[p];
            }
}
