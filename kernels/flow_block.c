/* The implicit operator's block of the flow component of a cross-section
 * (kernels.h, kernel_flow_block). */
#include "kernels/kernels.h"
#include "stencil.h"

/* The base strain gamma_cd(base) = edge_gamma on the edges of the shear
 * plane of c and d (its index 3 - c - d): face indices along c and d, cells
 * -1 .. n along the third direction e (what plane_products reads; the
 * flow component's index along c is 0). */
static void plane_gammas(const struct grid *g, int c, int d, double *const base[3], double *gb)
{
    const int e = 3 - c - d;
    const ptrdiff_t od = g->stride[d], oe = g->stride[e];
    int lo, hi;
    plane_dirs(e, &lo, &hi);
#pragma omp for schedule(static) nowait
    for (int j = 0; j <= grid_slot_hi(g, d); j++) /* faces 0..n: one slot compact */
        for (int k = grid_slot_lo(g, e); k <= grid_slot_hi(g, e); k++) {
            const ptrdiff_t p = grid_idx(g, 0, 0, 0) + (ptrdiff_t)j * od + (ptrdiff_t)k * oe;
            gb[p] = edge_gamma(base, lo, hi, p, g->stride[lo], g->stride[hi], g->h[lo], g->h[hi]);
        }
}

void kernel_flow_gammas(const struct grid *g, int c, double *const base[3], double *gb[2])
{
    const int dirs[2] = {c == 0 ? 1 : 0, c == 2 ? 1 : 2};
#pragma omp parallel if (kernel_parallel(g))
    for (int t = 0; t < 2; t++)
        plane_gammas(g, c, dirs[t], base, gb[t]);
}

/* The products gamma(base) gamma(v) on the edges of the shear plane of c
 * and d, as kernel_strain_products computes them, gb that plane's
 * gamma(base) (plane_gammas), over the same edges; the flow component is
 * the only one of v. */
static void plane_products(const struct grid *g, int c, int d, const double *gb, const double *v,
                           double *pe)
{
    const int e = 3 - c - d;
    const ptrdiff_t od = g->stride[d], oe = g->stride[e];
    const double hd = g->h[d];
#pragma omp for schedule(static) nowait
    for (int j = 0; j <= grid_slot_hi(g, d); j++)
        for (int k = grid_slot_lo(g, e); k <= grid_slot_hi(g, e); k++) {
            const ptrdiff_t p = grid_idx(g, 0, 0, 0) + (ptrdiff_t)j * od + (ptrdiff_t)k * oe;
            /* gamma_cd(v): v_c's difference along d (v_d is 0) */
            pe[p] = gb[p] * ((v[p] - v[p - od]) / hd);
        }
}

/* The shear stress of the tangent on the edges of the plane of c and d: the
 * viscosity's part A gamma(v), and b gamma(base) d(|D|^2)[v], whose d is
 * 2 pe of the edge and 2 the mean of the other plane's pe around it
 * (kernel_tangent_edges: the normal strains and the third plane's products
 * vanish for a v along c alone). */
static void plane_stress(const struct grid *g, int c, int d, const double *gb, const double *v,
                         const double *A, const double *b, const double *pe,
                         const double *pe_other, double *S)
{
    const int e = 3 - c - d;
    const ptrdiff_t od = g->stride[d], oe = g->stride[e];
    const double ihd = 1.0 / g->h[d];
#pragma omp for schedule(static) nowait
    for (int j = 0; j <= grid_slot_hi(g, d); j++)
        for (int k = 0; k < g->n[e]; k++) {
            const ptrdiff_t p = grid_idx(g, 0, 0, 0) + (ptrdiff_t)j * od + (ptrdiff_t)k * oe;
            double s = A[p] * ((v[p] - v[p - od]) * ihd);
            if (b) {
                const double dD = 2.0 * pe[p] + 2.0 * mean4(pe_other, p + oe, oe, od);
                s += b[p] * dD * gb[p];
            }
            S[p] = s;
        }
}

/* The three passes in one parallel region (a region's wake-up costs more
 * than a pass over a cross-section of 28,000 cells), reading the base
 * strains gb (kernel_flow_gammas, once a Newton step): the products of both
 * planes, a barrier, the stresses of both, a barrier, the divergence.  The
 * loops are orphaned worksharing: plain loops outside a region. */
static void flow_block_passes(const struct grid *g, int c, const double *const gb[2],
                              const double *v,
                              const double *const A_edge[3], const double *const b_edge[3],
                              const double *mass_face, double mass, double *pe[2], double *S[2],
                              double *out)
{
    const int a = c == 0 ? 1 : 0, b = c == 2 ? 1 : 2;
    const int dirs[2] = {a, b};
    if (b_edge) {
        for (int t = 0; t < 2; t++)
            plane_products(g, c, dirs[t], gb[t], v, pe[t]);
#pragma omp barrier
    }
    for (int t = 0; t < 2; t++) {
        const int d = dirs[t], plane = 3 - c - d;
        plane_stress(g, c, d, b_edge ? gb[t] : NULL, v, A_edge[plane],
                     b_edge ? b_edge[plane] : NULL, pe[t], pe[1 - t], S[t]);
    }
#pragma omp barrier
    const ptrdiff_t oa = g->stride[a], ob = g->stride[b];
    const double iha = 1.0 / g->h[a], ihb = 1.0 / g->h[b];
    const double *Sa = S[0], *Sb = S[1];
#pragma omp for schedule(static)
    for (int j = 0; j < g->n[a]; j++)
        for (int k = 0; k < g->n[b]; k++) {
            const ptrdiff_t p = grid_idx(g, 0, 0, 0) + (ptrdiff_t)j * oa + (ptrdiff_t)k * ob;
            const double div = (Sa[p + oa] - Sa[p]) * iha + (Sb[p + ob] - Sb[p]) * ihb;
            out[p] = (mass_face ? mass_face[p] : mass) * v[p] - div;
        }
}

void kernel_flow_block(const struct grid *g, int c, const double *const gb[2], const double *v,
                       const double *const A_edge[3], const double *const b_edge[3],
                       const double *mass_face, double mass, double *pe[2], double *S[2],
                       double *out)
{
#pragma omp parallel if (kernel_parallel(g))
    flow_block_passes(g, c, gb, v, A_edge, b_edge, mass_face, mass, pe, S, out);
}

void kernel_cross_coefficients(const struct grid *g, int c, const double *const gb[2],
                               const double *const b_edge[3], double *k[2])
{
    const int dirs[2] = {c == 0 ? 1 : 0, c == 2 ? 1 : 2};
    for (int t = 0; t < 2; t++) {
        const int d = dirs[t], e = dirs[1 - t];
        const ptrdiff_t sd = g->stride[d], se = g->stride[e];
        const double *b = b_edge[3 - c - d], *own = gb[t], *across = gb[1 - t];
        double *kt = k[t];
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[d] = g->n[d] - 1; /* interior faces 1 .. n-1 */
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = 0; i < hi[0]; i++)
            for (int j = 0; j < hi[1]; j++)
                for (int l = 0; l < hi[2]; l++) {
                    int q[3] = {i, j, l};
                    q[d] += 1;
                    const ptrdiff_t p = grid_idx(g, q[0], q[1], q[2]);
                    /* the base strain gamma_ce on the four edges of the other
                     * plane around this one */
                    const double mean = 0.25 * (across[p] + across[p + se] + across[p - sd] +
                                                across[p - sd + se]);
                    kt[p] = 2.0 * b[p] * own[p] * mean;
                }
    }
}
