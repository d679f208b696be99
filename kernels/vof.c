/* Geometric VOF: PLIC reconstruction, volume/plane-constant relations and the
 * conservative direction-split sweep (see kernels/vof.h). */
#include <math.h>
#include "kernels/kernels.h"
#include "kernels/vof.h"

/* ---- volume / plane constant (Scardovelli & Zaleski 2000) ----------------
 *
 * Canonical form: components sorted 0 <= m1 <= m2 <= m3, m1 + m2 + m3 = 1,
 * plane constant al in [0, 1/2] (the other half follows from the symmetry
 * V(al) = 1 - V(1 - al)).  Inclusion-exclusion over the cube's vertices gives
 *   6 m1 m2 m3 V = al^3 - (al - m1)^3 - (al - m2)^3 - (al - m3)^3 + ...
 * with only the positive brackets kept.  Written that way it cancels
 * catastrophically when m1 is tiny (an interface nearly aligned with a grid
 * plane, the usual case): the terms are O(1) and their sum O(m1).  Each piece
 * below is the same polynomial with the factor m1 divided out by hand, using
 * al^3 - (al - m1)^3 = m1 [3 al (al - m1) + m1^2] and, where al - m_j is
 * positive, (al - m_j)^3 / m1 = (al - m_j)^2 t_j with t_j = (al - m_j)/m1 in
 * [0, 1]: every term is then bounded and no piece divides by a zero m1 (the
 * pieces that would are empty when m1 = 0, which is the 2D case). */

/* Volume below the plane for al in [0, 1/2], canonical normal. */
static double volume_low(double m1, double m2, double m3, double al)
{
    double m12 = m1 + m2;
    if (al < m1)
        return (al / m1) * (al / m2) * (al / m3) / 6.0;
    if (al < m2)
        return (3.0 * al * (al - m1) + m1 * m1) / (6.0 * m2 * m3);
    double core = 3.0 * al * (al - m1) + m1 * m1;
    if (al < m3 && al < m12) { /* the plane cuts the edges past m2 */
        double d2 = al - m2, t2 = d2 / m1;
        return (core - d2 * d2 * t2) / (6.0 * m2 * m3);
    }
    if (m3 < m12) { /* al in [m3, 1/2]: six-sided section (m1 > 0 here) */
        double d2 = al - m2, t2 = d2 / m1, d3 = al - m3, t3 = d3 / m1;
        return (core - d2 * d2 * t2 - d3 * d3 * t3) / (6.0 * m2 * m3);
    }
    return (al - 0.5 * m12) / m3; /* al in [m12, 1/2]: a prism along m3 */
}

/* dV/dal (the section's area over the normal's m3-projection) on the two
 * cubic pieces, al in [m2, 1/2] with m1 > 0. */
static double area_cubic(double m1, double m2, double m3, double al)
{
    double d2 = al - m2, a = 2.0 * al - m1 - d2 * (d2 / m1);
    if (al > m3) {
        double d3 = al - m3;
        a -= d3 * (d3 / m1);
    }
    return a / (2.0 * m2 * m3);
}

/* Inverse of volume_low for v in [0, 1/2].  The linear, quadratic and
 * cube-root pieces are Scardovelli & Zaleski's closed forms.  On the two cubic
 * pieces V is increasing and convex (its derivative, the section area, grows
 * until al = 1/2), so Newton's method started at the upper end of the piece
 * decreases monotonically onto the root: it converges to round-off in a few
 * steps, where the trigonometric closed form of the cubic loses digits as m1
 * goes to zero. */
static double alpha_low(double m1, double m2, double m3, double v)
{
    double m12 = m1 + m2;
    if (m1 > 0.0) {
        double v1 = m1 * m1 / (6.0 * m2 * m3);
        if (v < v1)
            return m1 * cbrt(v / v1);
    }
    if (m2 > 0.0 && v < volume_low(m1, m2, m3, m2))
        return 0.5 * m1 + sqrt(2.0 * m2 * m3 * v - m1 * m1 / 12.0);
    double hi = m3 < m12 ? 0.5 : m12; /* end of the cubic pieces */
    if (m1 > 0.0 && (m3 < m12 || v < volume_low(m1, m2, m3, hi))) {
        double lo = m2, al = hi;
        for (int it = 0; it < 100; it++) {
            double f = volume_low(m1, m2, m3, al) - v;
            double next = al - f / area_cubic(m1, m2, m3, al);
            if (next < lo)
                next = lo;
            if (!(next < al))
                break; /* f <= 0 at round-off: the root */
            al = next;
        }
        return al;
    }
    return m3 * v + 0.5 * m12;
}

/* Sorted magnitudes normalised to sum 1 (the largest takes the rounding so
 * the sum is 1 to the last bit the symmetry relies on), the L1 norm, and the
 * shift that moves the origin to the vertex where every m_c xi_c is lowest. */
static void canonical(const double m[3], double *m1, double *m2, double *m3, double *norm,
                      double *shift)
{
    double a0 = fabs(m[0]), a1 = fabs(m[1]), a2 = fabs(m[2]), t;
    *norm = a0 + a1 + a2;
    *shift = 0.0;
    for (int c = 0; c < 3; c++)
        if (m[c] < 0.0)
            *shift -= m[c];
    if (a0 > a1) { t = a0; a0 = a1; a1 = t; }
    if (a1 > a2) { t = a1; a1 = a2; a2 = t; }
    if (a0 > a1) { t = a0; a0 = a1; a1 = t; }
    *m1 = a0 / *norm;
    *m2 = a1 / *norm;
    *m3 = 1.0 - *m1 - *m2;
}

double vof_plane_volume(const double m[3], double alpha)
{
    double m1, m2, m3, norm, shift;
    canonical(m, &m1, &m2, &m3, &norm, &shift);
    double al = (alpha + shift) / norm;
    if (al <= 0.0)
        return 0.0;
    if (al >= 1.0)
        return 1.0;
    return al <= 0.5 ? volume_low(m1, m2, m3, al) : 1.0 - volume_low(m1, m2, m3, 1.0 - al);
}

double vof_plane_alpha(const double m[3], double volume)
{
    double m1, m2, m3, norm, shift;
    canonical(m, &m1, &m2, &m3, &norm, &shift);
    double v = volume < 0.0 ? 0.0 : volume > 1.0 ? 1.0 : volume;
    double al = v <= 0.5 ? alpha_low(m1, m2, m3, v) : 1.0 - alpha_low(m1, m2, m3, 1.0 - v);
    return al * norm - shift;
}

double vof_box_fraction(const double m[3], double alpha, double t_uniform, const double lo[3],
                        const double width[3])
{
    /* xi = lo + width eta maps the box onto the unit cube eta */
    double ms[3], al = alpha;
    for (int d = 0; d < 3; d++) {
        ms[d] = m[d] * width[d];
        al -= m[d] * lo[d];
    }
    if (ms[0] == 0.0 && ms[1] == 0.0 && ms[2] == 0.0)
        return t_uniform;
    return vof_plane_volume(ms, al);
}

double vof_slab_fraction(const double m[3], double alpha, double t_uniform, int d, double lo,
                         double width)
{
    double los[3] = {0.0, 0.0, 0.0}, widths[3] = {1.0, 1.0, 1.0};
    los[d] = lo;
    widths[d] = width;
    return vof_box_fraction(m, alpha, t_uniform, los, widths);
}

/* ---- normals: mixed Youngs-centred (Aulisa et al. 2007) ------------------
 *
 * Both estimates work in cell-index space: the normal of the plane in the
 * cell's unit coordinates is the index-space gradient, whatever h is.  c is the
 * 3x3x3 block around the cell, c[(a * 3 + b) * 3 + e] for offsets a - 1,
 * b - 1, e - 1 along x, y, z. */

static inline double block(const double c[27], const int off[3])
{
    return c[(off[0] * 3 + off[1]) * 3 + off[2]];
}

static double l1_normalise(double m[3])
{
    double s = fabs(m[0]) + fabs(m[1]) + fabs(m[2]);
    if (s > 0.0)
        for (int c = 0; c < 3; c++)
            m[c] /= s;
    return s;
}

/* Youngs: minus the gradient averaged from the eight vertices, i.e. centred
 * differences weighted (1, 2, 1) x (1, 2, 1) across. */
static void youngs_normal(const double c[27], const int active[3], double m[3])
{
    static const double w[3] = {1.0, 2.0, 1.0};
    for (int d = 0; d < 3; d++) {
        m[d] = 0.0;
        if (!active[d])
            continue;
        int a = (d + 1) % 3, b = (d + 2) % 3, lo[3], hi[3];
        for (int ia = 0; ia < 3; ia++)
            for (int ib = 0; ib < 3; ib++) {
                lo[d] = 0; hi[d] = 2;
                lo[a] = hi[a] = ia;
                lo[b] = hi[b] = ib;
                m[d] += w[ia] * w[ib] * (block(c, lo) - block(c, hi));
            }
    }
    l1_normalise(m);
}

/* Centred columns along d: heights H = sums of the three cells along d in the
 * column of the cell and of its four neighbours across; the interface
 * xi_d = H(xi_a, xi_b) has the normal (-dH/da, -dH/db, s) with s = +1 when
 * the fluid lies below (on the low side along d), -1 above.  Returns 0 when
 * the block gives no side (s undefined). */
static int column_normal(const double c[27], const int active[3], int d, double m[3])
{
    int a = (d + 1) % 3, b = (d + 2) % 3, off[3];
    double below = 0.0, above = 0.0;
    for (int ia = 0; ia < 3; ia++)
        for (int ib = 0; ib < 3; ib++) {
            off[a] = ia; off[b] = ib;
            off[d] = 0;
            below += block(c, off);
            off[d] = 2;
            above += block(c, off);
        }
    if (below == above)
        return 0;
    double height[2][2]; /* [direction a or b][low or high neighbour] */
    for (int t = 0; t < 2; t++)
        for (int side = 0; side < 2; side++) {
            double hsum = 0.0;
            off[a] = 1; off[b] = 1;
            off[t == 0 ? a : b] = side == 0 ? 0 : 2;
            for (off[d] = 0; off[d] < 3; off[d]++)
                hsum += block(c, off);
            height[t][side] = hsum;
        }
    m[d] = below > above ? 1.0 : -1.0;
    m[a] = active[a] ? -0.5 * (height[0][1] - height[0][0]) : 0.0;
    m[b] = active[b] ? -0.5 * (height[1][1] - height[1][0]) : 0.0;
    l1_normalise(m);
    return 1;
}

/* MYC: of the column normals, the one whose own component is largest (the
 * columns best aligned with the normal); it is kept unless that component
 * exceeds the largest component of the Youngs normal, the sign that the
 * columns were too short to hold the interface (saturated heights flatten
 * the slope), in which case Youngs is the better estimate. */
static void myc_normal(const double c[27], const int active[3], double m[3])
{
    double best[3] = {0.0, 0.0, 0.0}, cand[3];
    int best_d = -1;
    for (int d = 0; d < 3; d++) {
        if (!active[d] || !column_normal(c, active, d, cand))
            continue;
        if (best_d < 0 || fabs(cand[d]) > fabs(best[best_d])) {
            best_d = d;
            for (int e = 0; e < 3; e++)
                best[e] = cand[e];
        }
    }
    youngs_normal(c, active, m);
    double youngs_max = fmax(fabs(m[0]), fmax(fabs(m[1]), fabs(m[2])));
    if (best_d >= 0 && (youngs_max == 0.0 || fabs(best[best_d]) <= youngs_max))
        for (int e = 0; e < 3; e++)
            m[e] = best[e];
}

void vof_reconstruct(const struct grid *g, const double *T, double *normal[3], double *alpha)
{
    const ptrdiff_t *o = g->stride;
    const int active[3] = {g->n[0] > 1, g->n[1] > 1, g->n[2] > 1};
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                double t = T[p], m[3] = {0.0, 0.0, 0.0}, al = 0.0;
                if (t > 0.0 && t < 1.0) {
                    double c[27];
                    for (int a = 0; a < 3; a++)
                        for (int b = 0; b < 3; b++)
                            for (int e = 0; e < 3; e++)
                                c[(a * 3 + b) * 3 + e] =
                                    T[p + (a - 1) * o[0] + (b - 1) * o[1] + (e - 1) * o[2]];
                    myc_normal(c, active, m);
                    if (m[0] != 0.0 || m[1] != 0.0 || m[2] != 0.0)
                        al = vof_plane_alpha(m, t);
                }
                for (int d = 0; d < 3; d++)
                    normal[d][p] = m[d];
                alpha[p] = al;
            }
}

void vof_indicator(const struct grid *g, const double *T, double *indicator)
{
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                indicator[p] = T[p] > 0.5 ? 1.0 : 0.0;
            }
}

void vof_sweep(const struct grid *g, int d, const double *vel_d, double dt,
               const double *indicator, double *const normal[3], const double *alpha, double *T,
               double *flux)
{
    const ptrdiff_t od = g->stride[d];
    const double rate = dt / g->h[d];
    int hi[3] = {g->n[0], g->n[1], g->n[2]};
    hi[d] = g->n[d] + 1; /* faces 0..n along d */
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < hi[0]; i++)
        for (int j = 0; j < hi[1]; j++)
            for (int k = 0; k < hi[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                double u = vel_d[p];
                if (u == 0.0) {
                    flux[p] = 0.0;
                    continue;
                }
                /* the upwind cell's slab that crosses the face within dt */
                double width = fmin(fabs(u) * rate, 1.0);
                ptrdiff_t up = u > 0.0 ? p - od : p;
                double lo = u > 0.0 ? 1.0 - width : 0.0;
                double m[3] = {normal[0][up], normal[1][up], normal[2][up]};
                flux[p] = vof_slab_fraction(m, alpha[up], T[up], d, lo, width) * u;
            }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                /* one bracket, then one rounding: in a full cell fed by full
                 * cells the flux is u itself and the bracket is exactly 0, so
                 * T stays exactly 1 however the sweep's divergence rounds */
                double net = indicator[p] * (vel_d[p + od] - vel_d[p]) - (flux[p + od] - flux[p]);
                T[p] += rate * net;
            }
}

double vof_cfl(const struct grid *g, double *const vel[3], double dt, double cfl[3])
{
    double largest = 0.0;
    for (int d = 0; d < 3; d++) {
        double mx = 0.0;
        if (g->n[d] > 1) {
            const double *u = vel[d];
            int hi[3] = {g->n[0], g->n[1], g->n[2]};
            hi[d] = g->n[d] + 1;
#pragma omp parallel for collapse(2) schedule(static) reduction(max : mx) if (kernel_parallel(g))
            for (int i = 0; i < hi[0]; i++)
                for (int j = 0; j < hi[1]; j++)
                    for (int k = 0; k < hi[2]; k++)
                        mx = fmax(mx, fabs(u[grid_idx(g, i, j, k)]));
            mx *= dt / g->h[d];
        }
        cfl[d] = mx;
        largest = fmax(largest, mx);
    }
    return largest;
}
