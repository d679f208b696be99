/* Stage 3, implicit viscous step: (rho_f / dt) du - div(T : grad du) = R,
 * linearised with the consistent tangent (step.h, viscous.h). */
#include "march/step.h"

struct viscous_problem implicit_problem(const struct march_state *st, double dt)
{
    const struct muflow_case *cs = st->cs;
    /* dt = 0: the linearised stress alone (no mass term) */
    struct viscous_problem pb = {.mass = dt > 0.0 ? cs->density / dt : 0.0,
                                 .augmentation = st->aug,
                                 .embedded = st->embedded};
    if (dt > 0.0 && !st->density_uniform) {
        /* the face density of the mass term; the scalar stays as the scale
         * of the preconditioner's fallback */
        const struct grid *g = &st->g;
        pb.mass = st->rho_ref / dt;
        for (int c = 0; c < 3; c++) {
            for (size_t p = 0; p < g->size; p++)
                st->mass_face[c][p] = st->field.density_faces[c][p] / dt;
            pb.mass_face[c] = st->mass_face[c];
        }
    }
    /* Newton's basin shrinks with lambda: far from the solution the lagged
     * (Picard) viscosity is the robust step, the tangent the fast one near it.
     * A time-accurate step takes the lagged viscosity: with the tangent, a
     * linearly implicit step on the friction plateau (where d tau / d gamma
     * is small) overshoots and, without the steady march's rejections, the
     * grains' viscosity collapses (a layer under air slid freely at steps of
     * 2e-4 s; with the lagged viscosity it reaches the steady state,
     * docs/numerics/implicit-step-and-newton.md); for a Newtonian fluid both
     * are one. */
    int tangent = implicit_uses_tangent(st);
    int diagonal = tangent && !st->full_tangent;
    for (int a = 0; a < 3; a++) {
        pb.A_cell[a] = diagonal ? st->field.tangent_cells[a] : st->field.viscosity;
        pb.A_edge[a] = diagonal ? st->field.tangent_edges[a] : st->field.viscosity_edges[a];
    }
    if (tangent && st->full_tangent) {
        pb.b_cell = st->b_c;
        for (int a = 0; a < 3; a++) {
            pb.b_edge[a] = st->b_e[a];
            /* what a Cholesky factorises in the tangent's place */
            pb.sym_cell[a] = st->field.tangent_cells[a];
            pb.sym_edge[a] = st->field.tangent_edges[a];
        }
        pb.base = st->field.velocity;
    }
    return pb;
}

int stage_implicit(struct march_state *st, double dt)
{
    const struct muflow_case *cs = st->cs;
    /* a module that owns unknowns coupled to the velocity solves the step */
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->implicit) {
            int rc = st->modules[m]->implicit(st, st->module_state[m], dt);
            if (rc <= 0)
                return rc < 0 ? -1 : 0;
        }
    struct viscous_problem pb = implicit_problem(st, dt);
    if (cs->coupled)
        return stage_coupled(st, &pb);
    double tol = implicit_tolerance(st, pb.b_cell != NULL);
    struct viscous_precond_info before, after;
    viscous_precond_info(st->viscous, &before);
    viscous_precondition(st->viscous, &pb);
    struct viscous_stats vs;
    int rc = viscous_solve(st->viscous, &pb, st->field.residual, st->field.increment, tol,
                           cs->max_linear_iterations, &vs);
    st->linear_iterations = vs.iterations;
    viscous_precond_info(st->viscous, &after);
    st->grid_matrices += after.grid_matrices - before.grid_matrices;
    st->linear_residual = vs.relative_residual;
    /* the step goes on with the iterate, counted (the run tells it) */
    if (rc == 1)
        st->linear_unconverged++;
    return rc < 0 ? -1 : 0;
}
