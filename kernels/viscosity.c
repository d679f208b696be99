/* Viscosities and tangent coefficients where the stresses live (kernels.h). */
#include <math.h>
#include "kernels/kernels.h"
#include "stencil.h"
#include "rheology_inline.h"

/* cell[q] + w * the sum over the three planes of the mean of the four edges
 * of plane c around cell q (faces q, q + o along the plane's directions): the
 * cell's |D|^2 from its normal and edge parts, and (w = 2) its linearisation,
 * which must use the same averaging. */
static inline double cell_edges_sum(const double *cell, double *const edge[3], double w,
                                    ptrdiff_t q, const ptrdiff_t *o)
{
    double s = 0.0;
    for (int c = 0; c < 3; c++) {
        int a, b;
        plane_dirs(c, &a, &b);
        s += mean4(edge[c], q + o[a] + o[b], o[a], o[b]);
    }
    return cell[q] + w * s;
}

/* The loops of the two viscosity kernels, instantiated per law,
 * regularisation and friction curve (RHEOLOGY_DISPATCH) inside one parallel region: the
 * worksharing `omp for` is orphaned here, so the loop body is inlined with law
 * and reg as constants (a `parallel for` would be outlined before inlining and
 * keep them as run-time values). */
#define KERNEL_INLINE static inline __attribute__((always_inline))

KERNEL_INLINE void viscosity_cells_loop(const struct grid *g, const struct rheology *r,
                                        double *const vel[3], const double *cn2,
                                        double *const e2[3], const double *p, double *eta,
                                        double *tan_c[3], double *shear2, double *preg,
                                        double *b_c, const enum rheology_law law,
                                        const enum regularisation reg,
                                        const enum rheology_curve curve)
{
    const ptrdiff_t *o = g->stride;
    const double *h = g->h;
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double s2 = cell_edges_sum(cn2, e2, 1.0, q, o);
                double shear = sqrt(s2);
                double pr = rheo_pressure(r, p[q], NULL);
                struct rheology_point pt;
                rheo_eval(r, law, reg, curve, shear, pr, &pt);
                eta[q] = pt.eta;
                shear2[q] = s2;
                preg[q] = pr;
                if (b_c) /* d|D|^2 vanishes with |D|: b d|D|^2 -> 0 at rest */
                    b_c[q] = shear > 0.0 ? pt.deta_dshear / (2.0 * shear) : 0.0;
                if (tan_c)
                    for (int a = 0; a < 3; a++) {
                        const int ia = a == 0 ? i : a == 1 ? j : k;
                        double ha = g->axis[a] ? grid_hc(g, a, ia) : h[a];
                        double gn = 2.0 * (vel[a][q + o[a]] - vel[a][q]) / ha;
                        /* gamma_aa^2 / (2 |D|) <= |D|: the coefficient stays >= eta + eta' |D|,
                         * the slope of the stress-shear curve, positive for every law */
                        tan_c[a][q] = shear > 0.0 ? pt.eta + pt.deta_dshear * gn * gn / (2.0 * shear)
                                                  : pt.eta;
                    }
            }
}

void kernel_viscosity_cells(const struct grid *g, const struct rheology *r, double *const vel[3],
                            const double *cn2, double *const e2[3], const double *p,
                            double *eta, double *tan_c[3], double *shear2, double *preg,
                            double *b_c)
{
#define CELLS(law, reg, curve)                                                             \
    viscosity_cells_loop(g, r, vel, cn2, e2, p, eta, tan_c, shear2, preg, b_c, law, reg, curve)
#pragma omp parallel if (kernel_parallel(g))
    RHEOLOGY_DISPATCH(r, CELLS);
#undef CELLS
}

/* Edges of plane c (a, b the plane's directions): face indices 0..n along a
 * and b, interior cells along c; along a direction of wraps (a bit per
 * direction) face indices 0..n-1, face n being copied from face 0 after
 * (copy_wrapped). */
KERNEL_INLINE void viscosity_edges_loop(const struct grid *g, const struct rheology *r, int c,
                                        const double *cn2, double *const e2[3], const double *p,
                                        double *ee, double *te, double *be, int wraps,
                                        const enum rheology_law law,
                                        const enum regularisation reg,
                                        const enum rheology_curve curve)
{
    const ptrdiff_t *o = g->stride;
    int a, b;
    plane_dirs(c, &a, &b);
    int hi[3];
    hi[a] = g->n[a] - ((wraps >> a) & 1);
    hi[b] = g->n[b] - ((wraps >> b) & 1);
    hi[c] = g->n[c] - 1;
    /* the other two shear components: plane b holds (a, c), plane a holds (b, c) */
    const double *eac = e2[b], *ebc = e2[a], *own2 = e2[c];
    const ptrdiff_t oa = o[a], ob = o[b], oc = o[c];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i <= hi[0]; i++)
        for (int j = 0; j <= hi[1]; j++)
            for (int k = 0; k <= hi[2]; k++) {
                ptrdiff_t e = grid_idx(g, i, j, k);
                double own = own2[e];
                /* normal strains: the four cells around the edge; (a, c) edges:
                 * same a-face, c-faces k, k+1, b-cells on both sides; (b, c) alike */
                double s2 = own + mean4(cn2, e, oa, ob) + mean4(eac, e + oc, oc, ob) +
                            mean4(ebc, e + oc, oc, oa);
                double shear = sqrt(s2);
                double pr = rheo_pressure(r, mean4(p, e, oa, ob), NULL);
                struct rheology_point pt;
                rheo_eval(r, law, reg, curve, shear, pr, &pt);
                ee[e] = pt.eta;
                if (te)
                    te[e] = shear > 0.0 ? pt.eta + pt.deta_dshear * own / shear : pt.eta;
                if (be)
                    be[e] = shear > 0.0 ? pt.deta_dshear / (2.0 * shear) : 0.0;
            }
}

/* Face n of plane c's edges along each wrapped face direction d of the
 * plane, copied from face 0: the same inputs (periodic images) give the same
 * values, so a direction of one cell is evaluated once instead of twice.
 * Direction a first over faces 0..n-1 of b, then b over all of a's. */
static void copy_wrapped(const struct grid *g, int c, int wraps, double *f)
{
    int a, b;
    plane_dirs(c, &a, &b);
    const int dirs[2] = {a, b};
    for (int t = 0; t < 2; t++) {
        const int d = dirs[t];
        if (!((wraps >> d) & 1))
            continue;
        int lo[3] = {0, 0, 0}, hi[3];
        for (int e = 0; e < 3; e++)
            hi[e] = e == c ? g->n[e] - 1 : g->n[e] - (t == 0 && ((wraps >> e) & 1));
        lo[d] = hi[d] = 0;
        const ptrdiff_t shift = (ptrdiff_t)g->n[d] * g->stride[d];
#pragma omp for collapse(2) schedule(static)
        for (int i = lo[0]; i <= hi[0]; i++)
            for (int j = lo[1]; j <= hi[1]; j++)
                for (int k = lo[2]; k <= hi[2]; k++) {
                    const ptrdiff_t e = grid_idx(g, i, j, k);
                    f[e + shift] = f[e];
                }
    }
}

void kernel_viscosity_edges(const struct grid *g, const struct rheology *r, const double *cn2,
                            double *const e2[3], const double *p, double *eta_e[3],
                            double *tan_e[3], double *b_e[3], int wraps)
{
#define EDGES(law, reg, curve)                                                             \
    for (int c = 0; c < 3; c++)                                                            \
        viscosity_edges_loop(g, r, c, cn2, e2, p, eta_e[c], tan_e ? tan_e[c] : NULL,       \
                             b_e ? b_e[c] : NULL, wraps, law, reg, curve)
#pragma omp parallel if (kernel_parallel(g))
    {
        RHEOLOGY_DISPATCH(r, EDGES);
        if (wraps)
            for (int c = 0; c < 3; c++) {
                copy_wrapped(g, c, wraps, eta_e[c]);
                if (tan_e)
                    copy_wrapped(g, c, wraps, tan_e[c]);
                if (b_e)
                    copy_wrapped(g, c, wraps, b_e[c]);
            }
    }
#undef EDGES
}

void kernel_tangent_cells(const struct grid *g, const double *pn, double *const pe[3],
                          const double *b_c, double *B_c)
{
    const ptrdiff_t *o = g->stride;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                /* d(|D|^2) of cn2 + sum_planes mean4(e2): pn + sum mean4(2 pe) */
                double d = cell_edges_sum(pn, pe, 2.0, q, o);
                B_c[q] = b_c[q] * d;
            }
}

void kernel_tangent_edges(const struct grid *g, const double *pn, double *const pe[3],
                          double *const b_e[3], double *B_e[3])
{
    const ptrdiff_t *o = g->stride;
    for (int c = 0; c < 3; c++) {
        int a, b;
        plane_dirs(c, &a, &b);
        int hi[3];
        hi[a] = g->n[a];
        hi[b] = g->n[b];
        hi[c] = g->n[c] - 1;
        const double *pac = pe[b], *pbc = pe[a], *bc = b_e[c];
        double *Be = B_e[c];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    /* d of own^2 + mean4(cn2) + mean4(e2 of the other planes) */
                    double d = 2.0 * pe[c][e] + mean4(pn, e, o[a], o[b]) +
                               2.0 * mean4(pac, e + o[c], o[c], o[b]) +
                               2.0 * mean4(pbc, e + o[c], o[c], o[a]);
                    Be[e] = bc[e] * d;
                }
    }
}

double kernel_edge_shear2(const struct grid *g, const double *cn2, double *const e2[3], int c,
                          ptrdiff_t e)
{
    const ptrdiff_t *o = g->stride;
    int a, b;
    plane_dirs(c, &a, &b);
    /* the same sum as viscosity_edges_loop */
    return e2[c][e] + mean4(cn2, e, o[a], o[b]) + mean4(e2[b], e + o[c], o[c], o[b]) +
           mean4(e2[a], e + o[c], o[c], o[a]);
}
