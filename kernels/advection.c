/* Explicit momentum advection, conservative centred second-order form:
 * out_a = -[d(u_a u_a)/dx_a + sum_b d(u_b u_a)/dx_b], with u_a u_a at cell
 * centres and u_b u_a on the edges, each factor the mean of its two nearest
 * nodes.  Energy-neutral in the interior, as a time-accurate solver wants.
 *
 * As in the stress divergence, everything that depends on the component (the
 * two other directions, their arrays, strides and inverse spacings) is chosen
 * outside the loops, and the slots outside the active box are zeroed by the
 * same row sweep instead of a serial pass over the whole array
 * (bench/analysis.md, section 5). */
#include "kernels/kernels.h"

/* The flux difference of u_b u_a across the two edges p + o_b and p of
 * component a, divided by h_b. */
static inline double edge_flux(const double *restrict va, const double *restrict vb, ptrdiff_t p,
                               ptrdiff_t oa, ptrdiff_t ob, double ihb)
{
    ptrdiff_t e1 = p + ob, e0 = p;
    double f1 = 0.5 * (vb[e1] + vb[e1 - oa]) * 0.5 * (va[e1] + va[e1 - ob]);
    double f0 = 0.5 * (vb[e0] + vb[e0 - oa]) * 0.5 * (va[e0] + va[e0 - ob]);
    return (f1 - f0) * ihb;
}

/* The active faces k in [k0, k1) of one k-row of component a. */
static inline void advection_row(const double *restrict va, const double *restrict vb1,
                                 const double *restrict vb2, ptrdiff_t oa, ptrdiff_t ob1,
                                 ptrdiff_t ob2, double iha, double ihb1, double ihb2,
                                 double *restrict res, ptrdiff_t p0, int k0, int k1)
{
    for (int k = k0; k < k1; k++) {
        ptrdiff_t p = p0 + k;
        double cp = 0.5 * (va[p] + va[p + oa]);
        double cm = 0.5 * (va[p - oa] + va[p]);
        double f = (cp * cp - cm * cm) * iha;
        f += edge_flux(va, vb1, p, oa, ob1, ihb1);
        f += edge_flux(va, vb2, p, oa, ob2, ihb2);
        res[p] = -f;
    }
}

void kernel_advection(const struct grid *g, const struct box act[3], double *const vel[3],
                      double *out[3])
{
    const ptrdiff_t *o = g->stride;
    const int par = kernel_parallel(g);
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
        const double *va = vel[a], *vb1 = vel[b1], *vb2 = vel[b2];
        const ptrdiff_t oa = o[a], ob1 = o[b1], ob2 = o[b2];
        const double iha = 1.0 / g->h[a], ihb1 = 1.0 / g->h[b1], ihb2 = 1.0 / g->h[b2];
        double *res = out[a];
        const int klo = bx->lo[2], khi = bx->hi[2], kend = g->n[2] + 1;
#pragma omp parallel for collapse(2) schedule(static) if (par)
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++) {
                ptrdiff_t p0 = grid_idx(g, i, j, 0); /* slot of k = 0; k runs -1 .. n */
                if (i < bx->lo[0] || i >= bx->hi[0] || j < bx->lo[1] || j >= bx->hi[1]) {
                    for (int k = -1; k < kend; k++) /* clear non-unknown slots */
                        res[p0 + k] = 0.0;
                    continue;
                }
                for (int k = -1; k < klo; k++)
                    res[p0 + k] = 0.0;
                advection_row(va, vb1, vb2, oa, ob1, ob2, iha, ihb1, ihb2, res, p0, klo, khi);
                for (int k = khi; k < kend; k++)
                    res[p0 + k] = 0.0;
            }
    }
}
