/* The hydrostatic split of the body force (step.h). */
#include <math.h>
#include <stdio.h>
#include "march/step.h"

void body_force_vector(const struct muflow_case *cs, double f[3])
{
    double rg = cs->density * cs->gravity;
    f[0] = rg * sin(cs->tilt);
    f[1] = 0.0;
    f[2] = -rg * cos(cs->tilt);
}

/* 1 for the faces where the hydrostatic pressure vanishes. */
static int zero_pressure(enum bc_kind k) { return k == BC_SURFACE || k == BC_OPEN; }

/* The hydrostatic pressure (below) in closed form, for a grid whose
 * spacing varies (no Poisson solver takes it): where every boundary face of
 * a non-periodic direction is closed (the stretched grids have no open
 * face: case_checks.c), p = f_a scale (x_a - len_a / 2) summed over those
 * directions has the flux f_a scale on every interior face, as the force,
 * and the closed faces pass none, which is the split's discrete problem; a
 * periodic direction's uniform flux has no divergence.  Zero mean over the
 * box's volume, as the solver's singular problem. */
static void stretched_hydrostatic(struct march_state *st, const double f[3], double scale)
{
    const struct grid *g = &st->g;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const int idx[3] = {i, j, k};
                double p = 0.0;
                for (int a = 0; a < 3; a++)
                    if (st->bc.face[a][0] != BC_PERIODIC)
                        p += f[a] * scale * (grid_xc(g, a, idx[a]) - 0.5 * g->len[a]);
                st->field.p_hyd[grid_idx(g, i, j, k)] = p;
            }
}

/* Hydrostatic pressure of the body force: the pressure whose gradient removes
 * the curl-free part of the force under the walls' no-penetration condition,
 * with p = 0 on free surfaces.  The remaining force drives the flow.  With a
 * variable face density rho_f the force is rho_f g, and the part removed is
 * the one the variable projection would remove: div(beta grad p) =
 * div(beta rho_f g) = div(rho_ref g), beta = rho_ref / rho_f. */
int hydrostatic_split(struct march_state *st, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    double f[3];
    body_force_vector(st->cs, f);
    double scale = st->density_uniform ? 1.0 : st->rho_ref / st->cs->density;
    if (grid_stretched(g)) {
        stretched_hydrostatic(st, f, scale);
        bc_fill_scalar(g, &st->bc, st->field.p_hyd);
        hydrostatic_force(st);
        return 0;
    }
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) {
            enum bc_kind k = st->bc.face[d][s];
            pbc[d][s] = k == BC_PERIODIC                    ? POISSON_PERIODIC
                        : k == BC_SURFACE || k == BC_OPEN ? POISSON_DIRICHLET
                                                          : POISSON_NEUMANN;
        }
    /* fluxes of the force through every face; a closed boundary face passes
     * none (a surface or an open face, where p_hyd = 0, passes it) */
    double **flux = st->field.increment;
    for (int a = 0; a < 3; a++)
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    int idx[3] = {i, j, k};
                    int face = idx[a];
                    double v = f[a] * scale;
                    /* a rank border's faces are the domain's inner ones */
                    if (st->bc.face[a][0] != BC_PERIODIC &&
                        ((face <= 0 && !bc_border(&st->bc, a, 0) &&
                          !zero_pressure(st->bc.face[a][0])) ||
                         (face >= g->n[a] && !bc_border(&st->bc, a, 1) &&
                          !zero_pressure(st->bc.face[a][1]))))
                        v = 0.0;
                    flux[a][grid_idx(g, i, j, k)] = v;
                }
    kernel_divergence(g, flux, st->field.divergence);
    struct pressure_solver *ps;
    /* a decomposed run's: FFTW's MPI transforms over the ranks (pressure.h) */
    if (march_pressure_create(st, &ps, (const enum poisson_bc(*)[2])pbc, err, errlen) != 0)
        return -1;
    if (!st->density_uniform &&
        pressure_set_coefficient(ps, st->beta, err, errlen) != 0) {
        pressure_destroy(ps);
        return -1;
    }
    if (pressure_solve(ps, st->field.divergence, st->field.p_hyd, 0.0) != 0) {
        snprintf(err, errlen, "hydrostatic %s", pressure_message(ps));
        pressure_destroy(ps);
        return -1;
    }
    st->hydrostatic_matrices += pressure_direct_factorisations(ps);
    pressure_destroy(ps);
    bc_fill_scalar(g, &st->bc, st->field.p_hyd);
    hydrostatic_force(st);
    return 0;
}

/* force = rho_f g - grad p_hyd on the unknown faces (zero elsewhere): called
 * by the split and whenever the face density changes (a moving tracer), so
 * that gravity acts on the density the fluid has now; the pressure that the
 * fixed p_hyd no longer balances is taken up by the projection's p_dyn. */
void hydrostatic_force(struct march_state *st)
{
    const struct grid *g = &st->g;
    double f[3];
    body_force_vector(st->cs, f);
    for (int a = 0; a < 3; a++)
        for (size_t p = 0; p < g->size; p++)
            st->field.force[a][p] =
                st->density_uniform ? f[a] : f[a] * st->field.density_faces[a][p] / st->cs->density;
    kernel_gradient_update(g, st->act, st->field.p_hyd, 1.0, st->field.force);
    for (int a = 0; a < 3; a++) /* only unknown faces carry a force */
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    const struct box *b = &st->act[a];
                    if (!box_holds(b, i, j, k))
                        st->field.force[a][grid_idx(g, i, j, k)] = 0.0;
                }
}
