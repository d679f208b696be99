/* Divergence of the viscous stress with coefficients at the stresses'
 * own locations (kernels.h). */
#include <math.h>
#include "kernels/kernels.h"
#include "stencil.h"

/* One component a of the divergence on the k-row (i, j), faces k in
 * [k0, k1): everything that depends on a (the two other directions b1, b2,
 * their arrays, strides and inverse spacings) is chosen by the caller, so the
 * k loop is a unit-stride stencil of 7 loads without run-time selection or
 * division (bench/analysis.md, section 1).  The shear plane (a, b) is normal
 * to the third direction: its edge coefficients are A_edge[3 - a - b].
 *
 * With magnitude set, every difference v1 - v2 becomes |v1| + |v2| and every
 * term its absolute value: the size of what the residual sums, from which
 * its round-off follows. */
struct stress_dir {
    const double *Ae; /* edge coefficients of the plane (a, b) */
    const double *vb; /* velocity component b */
    ptrdiff_t ob;     /* stride along b */
    double ihb;       /* 1 / h_b */
};

/* A velocity's size in the magnitude sum: at least vf, the round-off scale
 * of the velocities (0: their own sizes). */
#define M(x) fmax(fabs(x), vf)

static inline __attribute__((always_inline)) void
stress_row(const double *restrict Aa, const double *restrict va, ptrdiff_t oa, double iha,
           const struct stress_dir *d1, const struct stress_dir *d2, double *restrict res,
           ptrdiff_t p0, int k0, int k1, const int magnitude, const double vf)
{
    const double *restrict Ae1 = d1->Ae, *restrict vb1 = d1->vb;
    const double *restrict Ae2 = d2->Ae, *restrict vb2 = d2->vb;
    const ptrdiff_t ob1 = d1->ob, ob2 = d2->ob;
    const double ihb1 = d1->ihb, ihb2 = d2->ihb;
    const double iha2 = iha * iha;
    if (magnitude) {
        for (int k = k0; k < k1; k++) {
            ptrdiff_t p = p0 + k;
            double f = (fabs(Aa[p]) * 2.0 * (M(va[p + oa]) + M(va[p])) +
                        fabs(Aa[p - oa]) * 2.0 * (M(va[p]) + M(va[p - oa]))) * iha2;
            ptrdiff_t e = p + ob1;
            f += fabs(Ae1[p]) * ((M(va[p]) + M(va[p - ob1])) * ihb1 +
                                 (M(vb1[p]) + M(vb1[p - oa])) * iha) * ihb1 +
                 fabs(Ae1[e]) * ((M(va[e]) + M(va[e - ob1])) * ihb1 +
                                 (M(vb1[e]) + M(vb1[e - oa])) * iha) * ihb1;
            e = p + ob2;
            f += fabs(Ae2[p]) * ((M(va[p]) + M(va[p - ob2])) * ihb2 +
                                 (M(vb2[p]) + M(vb2[p - oa])) * iha) * ihb2 +
                 fabs(Ae2[e]) * ((M(va[e]) + M(va[e - ob2])) * ihb2 +
                                 (M(vb2[e]) + M(vb2[e - oa])) * iha) * ihb2;
            res[p] = f;
        }
        return;
    }
    for (int k = k0; k < k1; k++) {
        ptrdiff_t p = p0 + k;
        /* normal stress at the cells p (above) and p - o_a (below) */
        double tp = Aa[p] * 2.0 * (va[p + oa] - va[p]);
        double tm = Aa[p - oa] * 2.0 * (va[p] - va[p - oa]);
        double f = (tp - tm) * iha2;
        /* shear stresses on the edges p + o_b (above) and p (below) */
        ptrdiff_t e = p + ob1;
        double s1 = Ae1[e] * ((va[e] - va[e - ob1]) * ihb1 + (vb1[e] - vb1[e - oa]) * iha);
        double s0 = Ae1[p] * ((va[p] - va[p - ob1]) * ihb1 + (vb1[p] - vb1[p - oa]) * iha);
        f += (s1 - s0) * ihb1;
        e = p + ob2;
        s1 = Ae2[e] * ((va[e] - va[e - ob2]) * ihb2 + (vb2[e] - vb2[e - oa]) * iha);
        s0 = Ae2[p] * ((va[p] - va[p - ob2]) * ihb2 + (vb2[p] - vb2[p - oa]) * iha);
        f += (s1 - s0) * ihb2;
        res[p] = f;
    }
}

/* Every slot of out[a] is written: the divergence on the active box of a,
 * 0 elsewhere (ghosts and prescribed faces). */
static inline __attribute__((always_inline)) void
stress_loop(const struct grid *g, const struct box act[3], const double *const A_cell[3],
            const double *const A_edge[3], double *const v[3], double *out[3],
            const int magnitude, const double vf, const int only)
{
    const ptrdiff_t *o = g->stride;
    const int par = kernel_parallel(g);
    for (int a = 0; a < 3; a++) {
        if (only >= 0 && a != only)
            continue;
        const struct box *bx = &act[a];
        const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
        const struct stress_dir d1 = {A_edge[3 - a - b1], v[b1], o[b1], 1.0 / g->h[b1]};
        const struct stress_dir d2 = {A_edge[3 - a - b2], v[b2], o[b2], 1.0 / g->h[b2]};
        const double *Aa = A_cell[a], *va = v[a];
        const ptrdiff_t oa = o[a];
        const double iha = 1.0 / g->h[a];
        double *res = out[a];
        const int klo = bx->lo[2], khi = bx->hi[2], kend = g->n[2] + 1;
#pragma omp parallel for collapse(2) schedule(static) if (par)
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++) {
                ptrdiff_t p0 = grid_idx(g, i, j, 0); /* slot of k = 0; k runs -1 .. n */
                if (i < bx->lo[0] || i >= bx->hi[0] || j < bx->lo[1] || j >= bx->hi[1]) {
                    for (int k = -1; k < kend; k++)
                        res[p0 + k] = 0.0;
                    continue;
                }
                for (int k = -1; k < klo; k++)
                    res[p0 + k] = 0.0;
                stress_row(Aa, va, oa, iha, &d1, &d2, res, p0, klo, khi, magnitude, vf);
                for (int k = khi; k < kend; k++)
                    res[p0 + k] = 0.0;
            }
    }
}

/* The same divergence where a direction is stretched: each difference is
 * divided by its own distance (a normal stress's by the cell's width, its
 * divergence at a face by the two centres' distance; a shear stress's at an
 * edge by the centres' distance, its divergence by the cell's width).  A
 * plain loop: the stretched grids are the coupled steady solves', whose
 * cost is the factorisation. */
static void stress_loop_stretched(const struct grid *g, const struct box act[3],
                                  const double *const A_cell[3], const double *const A_edge[3],
                                  double *const v[3], double *out[3], const int magnitude,
                                  const double vf, const int only)
{
    const ptrdiff_t *o = g->stride;
    for (int a = 0; a < 3; a++) {
        if (only >= 0 && a != only)
            continue;
        const struct box *bx = &act[a];
        const double *Aa = A_cell[a], *va = v[a];
        const ptrdiff_t oa = o[a];
        double *res = out[a];
        for (size_t q = 0; q < g->size; q++)
            res[q] = 0.0;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    const int idx[3] = {i, j, k};
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    const int ia = idx[a];
                    double hp = grid_hc(g, a, ia), hm = grid_hc(g, a, ia - 1);
                    double hfa = grid_hf(g, a, ia);
                    double f;
                    if (magnitude)
                        f = (fabs(Aa[p]) * 2.0 * (M(va[p + oa]) + M(va[p])) / hp +
                             fabs(Aa[p - oa]) * 2.0 * (M(va[p]) + M(va[p - oa])) / hm) / hfa;
                    else
                        f = (Aa[p] * 2.0 * (va[p + oa] - va[p]) / hp -
                             Aa[p - oa] * 2.0 * (va[p] - va[p - oa]) / hm) / hfa;
                    for (int t = 1; t <= 2; t++) {
                        const int b = (a + t) % 3;
                        const double *Ae = A_edge[3 - a - b], *vb = v[b];
                        const ptrdiff_t ob = o[b];
                        const int jb = idx[b];
                        double hb0 = grid_hf(g, b, jb), hb1 = grid_hf(g, b, jb + 1);
                        ptrdiff_t e = p + ob;
                        double s1, s0;
                        if (magnitude) {
                            s1 = fabs(Ae[e]) * ((M(va[e]) + M(va[e - ob])) / hb1 +
                                                (M(vb[e]) + M(vb[e - oa])) / hfa);
                            s0 = fabs(Ae[p]) * ((M(va[p]) + M(va[p - ob])) / hb0 +
                                                (M(vb[p]) + M(vb[p - oa])) / hfa);
                            f += (s1 + s0) / grid_hc(g, b, jb);
                        } else {
                            s1 = Ae[e] * ((va[e] - va[e - ob]) / hb1 + (vb[e] - vb[e - oa]) / hfa);
                            s0 = Ae[p] * ((va[p] - va[p - ob]) / hb0 + (vb[p] - vb[p - oa]) / hfa);
                            f += (s1 - s0) / grid_hc(g, b, jb);
                        }
                    }
                    res[p] = f;
                }
    }
}

void kernel_stress_divergence(const struct grid *g, const struct box act[3],
                              const double *const A_cell[3], const double *const A_edge[3],
                              double *const v[3], double *out[3])
{
    if (grid_stretched(g)) {
        stress_loop_stretched(g, act, A_cell, A_edge, v, out, 0, 0.0, -1);
        return;
    }
    stress_loop(g, act, A_cell, A_edge, v, out, 0, 0.0, -1);
}

void kernel_stress_magnitude(const struct grid *g, const struct box act[3],
                             const double *const A_cell[3], const double *const A_edge[3],
                             double *const v[3], double *out[3])
{
    kernel_stress_magnitude_at(g, act, A_cell, A_edge, v, 0.0, out);
}

void kernel_stress_magnitude_at(const struct grid *g, const struct box act[3],
                                const double *const A_cell[3], const double *const A_edge[3],
                                double *const v[3], double v_floor, double *out[3])
{
    if (grid_stretched(g)) {
        stress_loop_stretched(g, act, A_cell, A_edge, v, out, 1, v_floor, -1);
        return;
    }
    stress_loop(g, act, A_cell, A_edge, v, out, 1, v_floor, -1);
}

void kernel_stress_component(const struct grid *g, const struct box act[3], int c,
                             const double *const A_cell[3], const double *const A_edge[3],
                             double *const v[3], double *out[3])
{
    if (grid_stretched(g)) {
        stress_loop_stretched(g, act, A_cell, A_edge, v, out, 0, 0.0, c);
        return;
    }
    stress_loop(g, act, A_cell, A_edge, v, out, 0, 0.0, c);
}
