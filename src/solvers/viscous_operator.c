/* The implicit viscous step's operator (viscous_operator.h). */
#include "solvers/viscous_operator.h"
#include "kernels/kernels.h"

#include <string.h>

int viscous_work_create(struct viscous_work *w, const struct grid *g, int full)
{
    memset(w, 0, sizeof *w);
    int ok = (w->divbuf = field_alloc(g)) != NULL;
    if (full) {
        ok &= (w->pn = field_alloc(g)) != NULL && (w->Bc = field_alloc(g)) != NULL;
        for (int c = 0; c < 3; c++)
            ok &= (w->pe[c] = field_alloc(g)) != NULL && (w->Be[c] = field_alloc(g)) != NULL &&
                  (w->tmp[c] = field_alloc(g)) != NULL;
    }
    if (!ok)
        viscous_work_destroy(w);
    return ok ? 0 : -1;
}

void viscous_work_destroy(struct viscous_work *w)
{
    field_free(w->divbuf);
    field_free(w->pn);
    field_free(w->Bc);
    for (int c = 0; c < 3; c++) {
        field_free(w->pe[c]);
        field_free(w->Be[c]);
        field_free(w->tmp[c]);
    }
    memset(w, 0, sizeof *w);
}

double viscous_work_bytes(const struct grid *g, int full)
{
    return (1.0 + (full ? 11.0 : 0.0)) * (double)g->size * sizeof(double);
}

/* The cut cells' term -scale grad(A div v) on their lists (kernels/embedded.h):
 * the same sums as kernel_divergence and kernel_gradient_update, which
 * visit every cell and face (the cylinder benchmark's multigrid computed the
 * whole grid's divergence for each component's smoothing residual); work is
 * 0 elsewhere before and after. */
static void cut_graddiv(const struct grid *g, const struct boundary *bc,
                        const struct box act[3], const struct embedded *e, const double *A,
                        double scale, double *const v[3], double *out[3])
{
    const ptrdiff_t *o = g->stride;
    double *w = e->work;
    for (long n = 0; n < e->ncut; n++) {
        const ptrdiff_t p = e->cut_cells[n];
        int idx[3];
        grid_slot_index(g, p, idx);
        double s = 0.0;
        for (int a = 0; a < 3; a++)
            s += (v[a][p + o[a]] - v[a][p]) / (g->axis[a] ? grid_hc(g, a, idx[a]) : g->h[a]);
        w[p] = s * (A[p] * e->cut[p]);
    }
    bc_fill_scalar(g, bc, w);
    const double neg = -scale; /* kernel_gradient_update's scale */
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        const double c = neg / g->h[a];
        for (long n = 0; n < e->ncut_faces[a]; n++) {
            const ptrdiff_t q = e->cut_faces[a][n];
            int idx[3];
            grid_slot_index(g, q, idx);
            if (!box_holds(bx, idx[0], idx[1], idx[2]))
                continue;
            const double ca = g->axis[a] ? neg / grid_hf(g, a, idx[a]) : c;
            out[a][q] -= ca * (w[q] - w[q - o[a]]);
        }
    }
    for (long n = 0; n < e->ncut; n++)
        w[e->cut_cells[n]] = 0.0;
    bc_fill_scalar(g, bc, w);
}

void viscous_embedded_terms(const struct grid *g, const struct boundary *bc,
                            const struct box act[3], const struct embedded *e,
                            const double *const A_cell[3], const double *const A_edge[3],
                            double scale, double *const v[3], double *out[3])
{
    embedded_links(e, A_cell, A_edge, scale, v, out);
    if (!e->cut) /* a staircase body (a multigrid's coarse level): no cut cells */
        return;
    if (e->cut_cells) {
        cut_graddiv(g, bc, act, e, A_cell[0], scale, v, out);
        return;
    }
    kernel_divergence(g, v, e->work);
    for (size_t p = 0; p < g->size; p++)
        e->work[p] *= A_cell[0][p] * e->cut[p];
    bc_fill_scalar(g, bc, e->work);
    kernel_gradient_update(g, act, e->work, -scale, out);
}

void viscous_operator_eval(const struct grid *g, const struct boundary *bc,
                           const struct box act[3], const struct viscous_work *w,
                           const struct viscous_problem *pb, double *v[3], double *out[3])
{
    if (pb->open_given)
        bc_fill_velocity_open_given(g, bc, v);
    else
        bc_fill_velocity_homogeneous(g, bc, v);
    if (pb->embedded)
        embedded_hold(pb->embedded, v);
    kernel_stress_divergence(g, act, pb->A_cell, pb->A_edge, v, out);
    if (pb->mass_face[0]) /* mass v - div tau */
        kernel_multiply_minus(g, act, pb->mass_face, v, out);
    else
        kernel_lincomb(g, act, pb->mass, v, -1.0, out);
    if (pb->embedded)
        viscous_embedded_terms(g, bc, act, pb->embedded, pb->A_cell, pb->A_edge, 1.0, v, out);
    if (pb->b_cell && w->pn) { /* - div(b d|D|^2[v] gamma(u)) */
        kernel_strain_products(g, pb->base, v, w->pn, (double **)w->pe);
        bc_fill_scalar(g, bc, w->pn);
        kernel_tangent_cells(g, w->pn, w->pe, pb->b_cell, w->Bc);
        bc_fill_scalar(g, bc, w->Bc);
        kernel_tangent_edges(g, w->pn, w->pe, (double *const *)pb->b_edge, (double **)w->Be);
        const double *Bcell[3] = {w->Bc, w->Bc, w->Bc};
        kernel_stress_divergence(g, act, Bcell, (const double *const *)w->Be, pb->base,
                                 (double **)w->tmp);
        kernel_axpy(g, act, -1.0, w->tmp, out);
        /* the body's cut links and cut-cell grad-div move with the
         * viscosity as well: their terms of the base velocity with d eta */
        if (pb->embedded)
            viscous_embedded_terms(g, bc, act, pb->embedded, Bcell,
                                   (const double *const *)w->Be, 1.0, pb->base, out);
    }
    if (pb->augmentation) { /* - grad(r div v) */
        kernel_divergence(g, v, w->divbuf);
        for (size_t p = 0; p < g->size; p++)
            w->divbuf[p] *= pb->augmentation[p];
        bc_fill_scalar(g, bc, w->divbuf);
        kernel_gradient_update(g, act, w->divbuf, 1.0, out);
    }
    if (pb->embedded)
        embedded_release(pb->embedded, pb->mass, pb->mass_face, v, out);
}

void viscous_operator_rows(const struct grid *g, const struct boundary *bc, const struct box act[3],
                           const struct viscous_work *w, const struct viscous_problem *pb, int c,
                           double *v[3], double *out[3])
{
    struct box only[3];
    for (int a = 0; a < 3; a++) {
        only[a] = act[a];
        if (a != c)
            only[a].hi[0] = only[a].lo[0]; /* empty: the loops skip it */
    }
    if (pb->open_given)
        bc_fill_velocity_open_given(g, bc, v);
    else
        bc_fill_velocity_homogeneous(g, bc, v);
    if (pb->embedded)
        embedded_hold(pb->embedded, v);
    kernel_stress_component(g, act, c, pb->A_cell, pb->A_edge, v, out);
    if (pb->mass_face[0])
        kernel_multiply_minus(g, only, pb->mass_face, v, out);
    else
        kernel_lincomb(g, only, pb->mass, v, -1.0, out);
    if (pb->embedded)
        viscous_embedded_terms(g, bc, only, pb->embedded, pb->A_cell, pb->A_edge, 1.0, v, out);
    if (pb->augmentation) {
        kernel_divergence(g, v, w->divbuf);
        for (size_t p = 0; p < g->size; p++)
            w->divbuf[p] *= pb->augmentation[p];
        bc_fill_scalar(g, bc, w->divbuf);
        kernel_gradient_update(g, only, w->divbuf, 1.0, out);
    }
    if (pb->embedded)
        embedded_release(pb->embedded, pb->mass, pb->mass_face, v, out);
}
