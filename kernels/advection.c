/* Explicit momentum advection, conservative centred second-order form:
 * out_a = -[d(u_a u_a)/dx_a + sum_b d(u_b u_a)/dx_b], with u_a u_a at cell
 * centres and u_b u_a on the edges, each factor the mean of its two nearest
 * nodes.  Energy-neutral in the interior, as a time-accurate solver wants. */
#include "kernels/kernels.h"

void kernel_advection(const struct grid *g, const struct box act[3], double *const vel[3],
                      double *out[3])
{
    const ptrdiff_t *o = g->stride;
    const double *h = g->h;
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        const double *va = vel[a];
        double *res = out[a];
        for (int i = -1; i <= g->n[0]; i++) /* clear non-unknown slots */
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++)
                    if (i < bx->lo[0] || i >= bx->hi[0] || j < bx->lo[1] || j >= bx->hi[1] ||
                        k < bx->lo[2] || k >= bx->hi[2])
                        res[grid_idx(g, i, j, k)] = 0.0;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    double cp = 0.5 * (va[p] + va[p + o[a]]);
                    double cm = 0.5 * (va[p - o[a]] + va[p]);
                    double f = (cp * cp - cm * cm) / h[a];
                    for (int m = 1; m < 3; m++) {
                        int b = (a + m) % 3;
                        const double *vb = vel[b];
                        ptrdiff_t e1 = p + o[b], e0 = p;
                        double f1 = 0.5 * (vb[e1] + vb[e1 - o[a]]) * 0.5 * (va[e1] + va[e1 - o[b]]);
                        double f0 = 0.5 * (vb[e0] + vb[e0 - o[a]]) * 0.5 * (va[e0] + va[e0 - o[b]]);
                        f += (f1 - f0) / h[b];
                    }
                    res[p] = -f;
                }
    }
}
