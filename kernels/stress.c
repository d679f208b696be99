/* Divergence of the viscous stress with coefficients at the stresses'
 * own locations (kernels.h). */
#include <math.h>
#include "kernels/kernels.h"
#include "stencil.h"

/* With magnitude set, every difference v1 - v2 becomes |v1| + |v2| and every
 * term its absolute value: the size of what the residual sums, from which
 * its round-off follows. */
static inline void stress_loop(const struct grid *g, const struct box act[3],
                               const double *const A_cell[3], const double *const A_edge[3],
                               double *const v[3], double *out[3], const int magnitude)
{
    const ptrdiff_t *o = g->stride;
    const double *h = g->h;
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        const double *Aa = A_cell[a];
        double *res = out[a];
        const double *va = v[a];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = -1; i <= g->n[0]; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    if (i < bx->lo[0] || i >= bx->hi[0] || j < bx->lo[1] || j >= bx->hi[1] ||
                        k < bx->lo[2] || k >= bx->hi[2]) {
                        res[p] = 0.0;
                        continue;
                    }
                    if (magnitude) {
                        double f = (fabs(Aa[p]) * 2.0 * (fabs(va[p + o[a]]) + fabs(va[p])) +
                                    fabs(Aa[p - o[a]]) * 2.0 * (fabs(va[p]) + fabs(va[p - o[a]]))) /
                                   (h[a] * h[a]);
                        for (int m = 1; m < 3; m++) {
                            int b = (a + m) % 3;
                            const double *Ae = A_edge[3 - a - b];
                            const double *vb = v[b];
                            for (ptrdiff_t e = p; e <= p + o[b]; e += o[b])
                                f += fabs(Ae[e]) *
                                     ((fabs(va[e]) + fabs(va[e - o[b]])) / h[b] +
                                      (fabs(vb[e]) + fabs(vb[e - o[a]])) / h[a]) / h[b];
                        }
                        res[p] = f;
                        continue;
                    }
                    /* normal stress at the cells p (above) and p - o_a (below) */
                    double tp = Aa[p] * 2.0 * (va[p + o[a]] - va[p]) / h[a];
                    double tm = Aa[p - o[a]] * 2.0 * (va[p] - va[p - o[a]]) / h[a];
                    double f = (tp - tm) / h[a];
                    for (int m = 1; m < 3; m++) {
                        int b = (a + m) % 3;
                        int c = 3 - a - b; /* the plane of (a, b) is normal to c */
                        const double *Ae = A_edge[c];
                        ptrdiff_t e1 = p + o[b], e0 = p;
                        double s1 = Ae[e1] * edge_gamma(v, a, b, e1, o[a], o[b], h[a], h[b]);
                        double s0 = Ae[e0] * edge_gamma(v, a, b, e0, o[a], o[b], h[a], h[b]);
                        f += (s1 - s0) / h[b];
                    }
                    res[p] = f;
                }
    }
}

void kernel_stress_divergence(const struct grid *g, const struct box act[3],
                              const double *const A_cell[3], const double *const A_edge[3],
                              double *const v[3], double *out[3])
{
    stress_loop(g, act, A_cell, A_edge, v, out, 0);
}

void kernel_stress_magnitude(const struct grid *g, const struct box act[3],
                             const double *const A_cell[3], const double *const A_edge[3],
                             double *const v[3], double *out[3])
{
    stress_loop(g, act, A_cell, A_edge, v, out, 1);
}
