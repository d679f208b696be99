/* Explicit momentum advection, conservative upwind form (kernels.h):
 * out_a = -[d(U_a u_a)/dx_a + sum_b d(U_b u_a)/dx_b], the advecting velocity
 * U the mean of its two nearest nodes as in the centred form, the advected
 * u_a taken from the upwind side: first order (donor cell), or raised to
 * second order with van Leer's limited slope, or QUICK's quadratic through
 * the two upwind nodes and the downwind one, unlimited (Leonard 1979, "A
 * stable and accurate convective modelling procedure based on quadratic
 * upstream interpolation"); first order where the second upwind node would
 * lie beyond the ghost layer.
 *
 * Why: the centred form is neutral, so a forward-Euler step adds energy
 * wherever no viscosity damps it.  A granular surface has none (the
 * pressure, hence mu(I)'s viscosity, vanishes there), and with the centred
 * form the front of a collapsing column sheds droplets of grains at twice
 * the front's speed.  The limited flux damps only at extrema, and still lets
 * a few droplets go (docs/numerics/two-phase-and-vof.md, "What the collapse
 * needed"). */
#include <math.h>
#include "kernels/kernels.h"

/* The face value between qL and qR carried by U, from the side U comes
 * from; ll and rr say whether qLL and qRR exist. */
static inline double upwind_value(double qLL, double qL, double qR, double qRR, double U, int ll,
                                  int rr, enum advection_face face)
{
    if (face == ADVECTION_FACE_DONOR)
        return U >= 0.0 ? qL : qR;
    double up, d0, d1;
    if (U >= 0.0) {
        if (!ll)
            return qL;
        up = qL, d0 = qL - qLL, d1 = qR - qL;
    } else {
        if (!rr)
            return qR;
        up = qR, d0 = qR - qRR, d1 = qL - qR;
    }
    if (face == ADVECTION_FACE_QUICK) /* 3/4 up + 3/8 down - 1/8 second upwind */
        return up + 0.125 * d0 + 0.375 * d1;
    /* van Leer: the harmonic mean of the two slopes, 0 at an extremum */
    double s = d0 * d1 > 0.0 ? 2.0 * d0 * d1 / (d0 + d1) : 0.0;
    return up + 0.5 * s;
}

/* d(U u_a)/dx_d at face p of component a (index m along d, n cells). */
static inline double flux_difference(const double *restrict va, const double *restrict vd,
                                     ptrdiff_t p, ptrdiff_t oa, ptrdiff_t od, int m, int n,
                                     double ihd, enum advection_face face)
{
    /* the advecting velocity on the upper and lower interfaces: for d = a
     * the cell centres (vd = va: mean of p, p + oa and of p - oa, p), else
     * the edges (the mean of vd on the two faces of a around them) */
    double Uup = 0.5 * (vd[p + od] + vd[p + od - oa]);
    double Ulo = 0.5 * (vd[p] + vd[p - oa]);
    if (vd == va) {
        Uup = 0.5 * (va[p] + va[p + oa]);
        Ulo = 0.5 * (va[p - oa] + va[p]);
    }
    int rr_up = m + 2 <= n, ll_lo = m - 2 >= -1;
    double fup = Uup * upwind_value(va[p - od], va[p], va[p + od], rr_up ? va[p + 2 * od] : 0.0,
                                    Uup, 1, rr_up, face);
    double flo = Ulo * upwind_value(ll_lo ? va[p - 2 * od] : 0.0, va[p - od], va[p], va[p + od],
                                    Ulo, ll_lo, 1, face);
    return (fup - flo) * ihd;
}

void kernel_advection_upwind(const struct grid *g, const struct box act[3], double *const vel[3],
                             enum advection_face face, double *out[3])
{
    const ptrdiff_t *o = g->stride;
    const int par = kernel_parallel(g);
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
        const double *va = vel[a], *vb1 = vel[b1], *vb2 = vel[b2];
        double *res = out[a];
#pragma omp parallel for collapse(2) schedule(static) if (par)
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    if (!box_holds(bx, i, j, k)) {
                        res[p] = 0.0;
                        continue;
                    }
                    const int idx[3] = {i, j, k};
                    double f = flux_difference(va, va, p, o[a], o[a], idx[a], g->n[a],
                                               1.0 / g->h[a], face);
                    f += flux_difference(va, vb1, p, o[a], o[b1], idx[b1], g->n[b1],
                                         1.0 / g->h[b1], face);
                    f += flux_difference(va, vb2, p, o[a], o[b2], idx[b2], g->n[b2],
                                         1.0 / g->h[b2], face);
                    res[p] = -f;
                }
    }
}
