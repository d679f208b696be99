/* The grid transfers: restriction, prolongation, and the flux-continuous
 * prolongation weights (multigrid_internal.h). */
#include "solvers/multigrid_internal.h"

#include <stdlib.h>

/* Prolongation tables of fine level f from coarse level c (see struct level). */
int mg_build_prolongation(struct level *f, const struct level *c)
{
    for (int d = 0; d < 3; d++) {
        const int n = f->g.n[d];
        f->pi[d] = malloc(2 * (size_t)n * sizeof(int));
        if (!f->pi[d])
            return -1;
        for (int i = 0; i < n; i++) {
            int *ci = f->pi[d] + 2 * i;
            if (!c->coarse[d]) {
                ci[0] = ci[1] = i;
            } else {
                ci[0] = i / 2;
                ci[1] = (i & 1) ? i / 2 + 1 : i / 2 - 1;
            }
        }
        /* a direction not halved has w = 0 (field_alloc zeroes), kept as an
         * array so that the transfer loops have no branches */
        if (!(f->pw[d] = field_alloc(&f->g)))
            return -1;
    }
    return 0;
}

/* c->b = R f->r with R = P^T / 2^(halved directions): coarse cell I gathers
 * from the fine cells 2I-1 .. 2I+2 of each halved direction with the weight
 * each of them gives I in the prolongation (1 - w for its parent, w for its
 * neighbour); the division by 2 per direction makes a constant residual
 * restrict to itself, the scaling of the rediscretised coarse operator.
 * f->r's ghosts are in HALO_MIRROR mode and the weights' in HALO_EVEN: a fine
 * ghost then carries the condition's sign and its mirror cell's weight, which
 * is exactly the transpose of the prolongation reading a coarse ghost. */
static inline __attribute__((always_inline)) void
restrict_residual_body(const struct multigrid *mg, const struct level *f, struct level *c,
                       const int flat)
{
    const struct grid *gf = &f->g, *gc = &c->g;
    int off[3][4], par[3][4], cnt[3], m[3];
    double scale = 1.0;
    for (int d = 0; d < 3; d++) {
        if (c->coarse[d] && mg->opt.prolong == MG_PROLONG_CONSTANT) {
            /* w = 0: only the two children, the neighbours' weight is 0 */
            off[d][0] = 0, off[d][1] = 1;
            par[d][0] = par[d][1] = 1;
            cnt[d] = 2;
            m[d] = 2;
            scale *= 0.5;
        } else if (c->coarse[d]) {
            static const int o[4] = {-1, 0, 1, 2}, pa[4] = {0, 1, 1, 0};
            for (int t = 0; t < 4; t++)
                off[d][t] = o[t], par[d][t] = pa[t];
            cnt[d] = 4;
            m[d] = 2;
            scale *= 0.5;
        } else {
            off[d][0] = 0;
            par[d][0] = 1;
            cnt[d] = 1;
            m[d] = 1;
        }
    }
    const double *restrict r = f->r;
    const double *restrict wx = f->pw[0], *restrict wy = f->pw[1], *restrict wz = f->pw[2];
    /* the weight of a fine cell towards I along d is A + B w: (1, -1) for its
     * parent, (0, 1) for its neighbour (branch-free inner loop) */
    double A[3][4], B[3][4];
    for (int d = 0; d < 3; d++)
        for (int t = 0; t < cnt[d]; t++) {
            A[d][t] = par[d][t] ? 1.0 : 0.0;
            B[d][t] = par[d][t] ? -1.0 : 1.0;
        }
    double *restrict b = c->bbuf;
    const unsigned char *live = c->live;
    const int nx = gc->n[0], ny = gc->n[1], nz = gc->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int I = 0; I < nx; I++)
        for (int J = 0; J < ny; J++) {
            double *restrict brow = b + grid_idx(gc, I, J, 0);
            for (int K = 0; K < nz; K++)
                brow[K] = 0.0;
            for (int p = 0; p < cnt[0]; p++) {
                const int fi = m[0] * I + off[0][p];
                for (int q = 0; q < cnt[1]; q++) {
                    const int fj = m[1] * J + off[1][q];
                    const ptrdiff_t base = grid_idx(gf, fi, fj, 0);
                    const double ax = A[0][p], bx = B[0][p], ay = A[1][q], by = B[1][q];
                    for (int t = 0; t < cnt[2]; t++) {
                        const double az = A[2][t], bz = B[2][t];
                        const int o = off[2][t], mz = m[2];
                        /* along the flat direction (never halved) the weight
                         * is 1 - 0: left out, the same product to the bit (x
                         * and y; a flat z takes the general product) */
                        for (int K = 0; K < nz; K++) {
                            const ptrdiff_t pf = base + mz * K + o;
                            if (flat == 0)
                                brow[K] += (ay + by * wy[pf]) * (az + bz * wz[pf]) * r[pf];
                            else if (flat == 1)
                                brow[K] += (ax + bx * wx[pf]) * (az + bz * wz[pf]) * r[pf];
                            else
                                brow[K] += (ax + bx * wx[pf]) * (ay + by * wy[pf]) *
                                           (az + bz * wz[pf]) * r[pf];
                        }
                    }
                }
            }
            const unsigned char *lrow = live + grid_idx(gc, I, J, 0);
            for (int K = 0; K < nz; K++)
                brow[K] = lrow[K] ? scale * brow[K] : 0.0;
        }
}

void mg_restrict_residual(const struct multigrid *mg, const struct level *f, struct level *c)
{
#define CALL(flat) restrict_residual_body(mg, f, c, flat)
    FLAT_DISPATCH(f->flat, CALL);
#undef CALL
}

/* f->x += P c->x on live fine cells; c->x's ghosts in HALO_MIRROR mode.
 * Along f's flat direction (a constant after inlining, -1: none; never
 * halved) the weight of the neighbouring coarse line is 0, and its terms
 * are left out: (1 - 0) a + 0 b is a to the bit (x and y; a flat z takes
 * the general sum). */
static inline __attribute__((always_inline)) void
prolong_add_body(const struct level *f, const struct level *c, const int flat)
{
    const struct grid *gf = &f->g, *gc = &c->g;
    const int nx = gf->n[0], ny = gf->n[1], nz = gf->n[2];
    const int *restrict ix = f->pi[0], *restrict iy = f->pi[1], *restrict iz = f->pi[2];
    const double *wx = f->pw[0], *wy = f->pw[1], *wz = f->pw[2];
    const double *restrict e = c->x;
    double *restrict x = f->x;
    const unsigned char *live = f->live;
    const ptrdiff_t csx = gc->stride[0], csy = gc->stride[1];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(gf, i, j, 0);
            /* the four coarse lines this fine line interpolates from */
            const ptrdiff_t x0 = (ptrdiff_t)(ix[2 * i] + 1) * csx, x1 = (ptrdiff_t)(ix[2 * i + 1] + 1) * csx;
            const ptrdiff_t y0 = (ptrdiff_t)(iy[2 * j] + 1) * csy, y1 = (ptrdiff_t)(iy[2 * j + 1] + 1) * csy;
            const ptrdiff_t l00 = x0 + y0, l01 = x0 + y1, l10 = x1 + y0, l11 = x1 + y1;
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                if (!live[p])
                    continue;
                const ptrdiff_t k0 = iz[2 * k] + 1, k1 = iz[2 * k + 1] + 1;
                const double uz = wz[p];
                const double z0 = 1.0 - uz, z1 = uz;
                double v;
                if (flat == 0) {
                    const double uy = wy[p];
                    v = (1.0 - uy) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                        uy * (z0 * e[l01 + k0] + z1 * e[l01 + k1]);
                } else if (flat == 1) {
                    const double ux = wx[p];
                    v = (1.0 - ux) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                        ux * (z0 * e[l10 + k0] + z1 * e[l10 + k1]);
                } else {
                    const double ux = wx[p], uy = wy[p];
                    v = (1.0 - ux) * ((1.0 - uy) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                                      uy * (z0 * e[l01 + k0] + z1 * e[l01 + k1])) +
                        ux * ((1.0 - uy) * (z0 * e[l10 + k0] + z1 * e[l10 + k1]) +
                              uy * (z0 * e[l11 + k0] + z1 * e[l11 + k1]));
                }
                x[p] += v;
            }
        }
}

void mg_prolong_add(const struct level *f, const struct level *c)
{
#define CALL(flat) prolong_add_body(f, c, flat)
    FLAT_DISPATCH(f->flat, CALL);
#undef CALL
}

/* Prolongation weights of fine level f for the directions c halves.  Linear:
 * w = 1/4 (the fine centre is a quarter of a coarse cell from its parent's
 * centre).  Constant: 0.  Flux (operator-dependent, after Alcouffe, Brandt,
 * Dendy and Painter, SIAM J. Sci. Stat. Comput. 2 (1981) 430): the value a
 * flux-continuous 1D profile along the cell's own grid line takes, i.e. w is
 * the fraction of the series resistance between the two coarse centres that
 * lies between the parent's centre and the fine centre.  The coarse centres
 * sit on the fine faces inside the coarse cells; each half fine cell is
 * charged to the coefficient of the fine face it touches:
 *   own side  R_a = 1/2 / a(face between parent centre and cell)
 *   far side  R_b = 1 / a(face the coarse face is) + 1/2 / a(neighbour's inner face)
 * (uniform a: 1/4, the linear weight; a jump on the coarse face: the kink of
 * the error is reproduced).  A blocked face makes its side infinitely
 * resistant.  Next to a non-periodic boundary the neighbour is the mirror
 * ghost and the linear weight is kept.  Computed at set-up; the periodic wrap
 * reads the faces by index modulo n.  On a decomposed level the last cell
 * before a rank border reads the face n + 1, the next rank's face 1: the
 * high faces of the cells, exchanged as a cell field into far_faces (the
 * solver's spare work array), hold it in their ghost slot n. */
void mg_transfer_weights(const struct multigrid *mg, struct level *f, const struct level *c)
{
    const struct grid *g = &f->g;
    double *far_faces = mg->wq;
    for (int d = 0; d < 3; d++) {
        double *w = f->pw[d];
        if (!c->coarse[d])
            continue; /* stays 0 */
        const int n = g->n[d], per = mg->periodic[d];
        const int out_lo = mg_physical_side(mg, f, d, 0), out_hi = mg_physical_side(mg, f, d, 1);
        const int border_hi = f->dc && f->dc->border[d][1];
        const ptrdiff_t sd = g->stride[d];
        if (f->dc && (f->dc->border[d][0] || border_hi)) { /* both sides of a border send */
            for (int i = 0; i < g->n[0]; i++)
                for (int j = 0; j < g->n[1]; j++)
                    for (int k = 0; k < g->n[2]; k++) {
                        const ptrdiff_t p = grid_idx(g, i, j, k);
                        far_faces[p] = f->a[d][p + sd];
                    }
            decomp_exchange(f->dc, g, far_faces, d);
        }
#pragma omp parallel for collapse(2) schedule(static) if (f->par)
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    const int cc[3] = {i, j, k};
                    const int t = cc[d];
                    const ptrdiff_t p = grid_idx(g, i, j, k);
                    const ptrdiff_t p0 = p - (ptrdiff_t)t * sd; /* cell 0 of this line */
                    double val;
                    if (mg->opt.prolong == MG_PROLONG_CONSTANT) {
                        val = 0.0;
                    } else {
                        int own, cross, far, outside;
                        if (t & 1) {
                            own = t, cross = t + 1, far = t + 2;
                            outside = t + 1 >= n && out_hi;
                        } else {
                            own = t + 1, cross = t, far = t - 1;
                            outside = t == 0 && out_lo;
                        }
                        if (mg->opt.prolong == MG_PROLONG_LINEAR || outside) {
                            val = 0.25;
                        } else {
                            /* faces by index: periodic faces wrap modulo n
                             * (the indices lie in -1 .. n + 1: one shift is
                             * the modulo, without its divisions) */
                            if (per) {
                                own = own < 0 ? own + n : own >= n ? own - n : own;
                                cross = cross < 0 ? cross + n : cross >= n ? cross - n : cross;
                                far = far < 0 ? far + n : far >= n ? far - n : far;
                            }
                            const double ao = f->a[d][p0 + (ptrdiff_t)own * sd];
                            const double ac = f->a[d][p0 + (ptrdiff_t)cross * sd];
                            const double af = far == n + 1 && border_hi
                                                  ? far_faces[p0 + (ptrdiff_t)n * sd]
                                                  : f->a[d][p0 + (ptrdiff_t)far * sd];
                            const int ra_inf = !(ao > 0.0), rb_inf = !(ac > 0.0) || !(af > 0.0);
                            if (ra_inf)
                                val = rb_inf ? 0.0 : 1.0;
                            else if (rb_inf)
                                val = 0.0;
                            else {
                                const double ra = 0.5 / ao, rb = 1.0 / ac + 0.5 / af;
                                val = ra / (ra + rb);
                            }
                        }
                    }
                    w[p] = val;
                }
        (void)c;
        mg_halo_fill(mg, f, w, HALO_EVEN);
    }
}
