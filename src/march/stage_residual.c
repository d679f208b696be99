/* Stage 2, residual: the steady momentum residual
 *   R = f - grad p_dyn + div(eta gamma(u)) - rho div(u u)  (+ the modules'),
 * its size against the round-off of its terms, and the divergence (step.h). */
#include <float.h>
#include <math.h>
#include "march/step.h"

/* Round-off allowance of the residual, in machine epsilons of its terms. */
#define ROUNDOFF_EPS (16.0 * DBL_EPSILON)

void stage_residual(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    kernel_stress_divergence(g, st->act, eta_cell, (const double *const *)st->field.viscosity_edges,
                             st->field.velocity, st->field.residual);
    kernel_axpy(g, st->act, 1.0, st->field.force, st->field.residual);
    bc_fill_pressure(g, &st->bc, st->field.p_dyn);
    kernel_gradient_update(g, st->act, st->field.p_dyn, 1.0, st->field.residual);
    if (cs->advection) {
        if (cs->advection_scheme != ADVECTION_CENTRED) {
            enum advection_face face = ADVECTION_FACE_QUICK;
            if (cs->advection_scheme == ADVECTION_UPWIND)
                face = ADVECTION_FACE_DONOR;
            else if (cs->advection_scheme == ADVECTION_VANLEER)
                face = ADVECTION_FACE_VANLEER;
            kernel_advection_upwind(g, st->act, st->field.velocity, face, st->field.advection);
        } else {
            kernel_advection(g, st->act, st->field.velocity, st->field.advection);
        }
        if (st->density_uniform)
            kernel_axpy(g, st->act, cs->density, st->field.advection, st->field.residual);
        else
            kernel_multiply_add(g, st->act, st->field.density_faces, st->field.advection,
                                st->field.residual);
    }
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->residual)
            st->modules[m]->residual(st, st->module_state[m]);
    if (st->aug) {
        /* The grad-div augmentation r = kappa max(eta) of the implicit
         * operator.  It enters the operator and the Uzawa update only, not
         * this residual: u is solenoidal to round-off after each projection,
         * where grad(r div u) would be that round-off times r.  One r for the
         * whole field, not kappa eta per cell: the Uzawa update contracts the
         * pressure error by 1/(1 + r s) for each eigenvalue s of the Schur
         * complement div A^-1 grad, and s can be as small as 1/max(eta) in any
         * cell (a pressure mode in a yielded layer is resisted by the plug
         * beside it).  With r = kappa eta_cell a Vola Bn = 1000 cavity
         * contracted by 0.994 per step; with r = kappa max(eta) by < 1/kappa. */
        double r = cs->augmentation * march_max(st, kernel_max_abs_cells(g, st->field.viscosity));
        for (size_t p = 0; p < g->size; p++)
            st->aug[p] = r;
    }
    if (st->force_ref == 0.0) {
        double rg = cs->density * cs->gravity;
        st->force_ref = rg > 0.0 ? rg : march_max(st, kernel_max_abs(g, st->act, st->field.residual));
    }
    double scale = march_force_scale(st);
    st->residual = march_max(st, kernel_max_abs(g, st->act, st->field.residual)) / scale;
    {
        double n = 0.0;
        for (int c = 0; c < 3; c++)
            n += (double)(st->act[c].hi[0] - st->act[c].lo[0]) *
                 (st->act[c].hi[1] - st->act[c].lo[1]) * (st->act[c].hi[2] - st->act[c].lo[2]);
        double sums[2] = {n, kernel_dot(g, st->act, st->field.residual, st->field.residual)};
        march_sum_array(st, sums, 2);
        st->residual_rms = sums[0] > 0.0 ? sqrt(sums[1] / sums[0]) / scale : 0.0;
    }
    kernel_stress_magnitude(g, st->act, eta_cell, (const double *const *)st->field.viscosity_edges,
                            st->field.velocity, st->field.increment);
    st->residual_excess =
        march_max(st, kernel_residual_excess(g, st->act, st->field.residual, st->field.increment,
                                             st->field.force, ROUNDOFF_EPS)) /
        scale;
    /* the modules' own equations (a second velocity): both must vanish */
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->residual_max) {
            double x = 0.0;
            double r = st->modules[m]->residual_max(st, st->module_state[m], &x) / scale;
            st->residual = fmax(st->residual, r);
            st->residual_excess = fmax(st->residual_excess, x / scale);
        }
    stage_divergence(st, st->field.velocity, st->field.divergence);
    double umax = st->velocity_max = march_max(st, kernel_max_abs(g, st->act, st->field.velocity));
    double dmax = march_max(st, kernel_max_abs_cells(g, st->field.divergence));
    st->divergence = umax > 0.0 ? dmax * march_min_spacing(march_global_grid(st)) / umax : dmax;
}

double stage_residual_velocity_roundoff(struct march_state *st)
{
    const struct grid *g = &st->g;
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    double umax = march_max(st, kernel_max_abs(g, st->act, st->field.velocity));
    /* st->field.increment is the magnitude's scratch here as in stage_residual */
    kernel_stress_magnitude_at(g, st->act, eta_cell,
                               (const double *const *)st->field.viscosity_edges, st->field.velocity,
                               umax, st->field.increment);
    double x = march_max(st, kernel_residual_excess(g, st->act, st->field.residual,
                                                    st->field.increment, st->field.force,
                                                    ROUNDOFF_EPS)) /
               march_force_scale(st);
    /* a module's own equations keep their measure */
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->residual_max) {
            double xm = 0.0;
            st->modules[m]->residual_max(st, st->module_state[m], &xm);
            x = fmax(x, xm / march_force_scale(st));
        }
    return x;
}
