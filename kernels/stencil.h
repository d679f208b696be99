/* Stencil pieces shared by the kernels (internal to kernels/). */
#ifndef MUFLOW_STENCIL_H
#define MUFLOW_STENCIL_H

#include "grid/grid.h"

/* Shear strain rate gamma_ab on edge e of plane (a, b): v_a at cells e and
 * e - o_b along b, v_b at cells e and e - o_a along a (symmetric in a, b). */
static inline double edge_gamma(double *const vel[3], int a, int b, ptrdiff_t e, ptrdiff_t oa,
                                ptrdiff_t ob, double ha, double hb)
{
    return (vel[a][e] - vel[a][e - ob]) / hb + (vel[b][e] - vel[b][e - oa]) / ha;
}

/* Mean of f over the four nodes p, p - s1, p - s2, p - s1 - s2. */
static inline double mean4(const double *f, ptrdiff_t p, ptrdiff_t s1, ptrdiff_t s2)
{
    return 0.25 * (f[p] + f[p - s1] + f[p - s2] + f[p - s1 - s2]);
}

/* The two directions (a < b) of the edge plane normal to direction c. */
static inline void plane_dirs(int c, int *a, int *b)
{
    *a = (c + 1) % 3;
    *b = (c + 2) % 3;
    if (*a > *b) {
        int t = *a;
        *a = *b;
        *b = t;
    }
}

/* Inclusive index range of the edges of plane c that kernel_strain fills:
 * face indices 0..n along a and b, cells -1..n along c. */
static inline void edge_range(const struct grid *g, int c, int *a, int *b, int lo[3], int hi[3])
{
    plane_dirs(c, a, b);
    lo[*a] = lo[*b] = 0;
    hi[*a] = g->n[*a];
    hi[*b] = g->n[*b];
    lo[c] = -1;
    hi[c] = g->n[c];
}

#endif
