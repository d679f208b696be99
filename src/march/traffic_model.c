/* One step's traffic over the ranks by its model (march/traffic_model.h),
 * counted from the stages' code: which fields each fills, which sums and
 * maxima each takes, and the pieces the all-to-alls and FFTW's transposes
 * move between the ranks' blocks and FFTW's slabs. */
#include "march/traffic_model.h"

#include <string.h>

#define DOUBLE_BYTES ((long)sizeof(double))
/* the Fourier line blocks' probes (solvers/fourier_lines.c): combs of 2
 * BAND + 1 = 3 nodes, the plane wavenumbers (0,0), (pi,0), (0,pi), (pi,pi) */
#define FOURIER_PROBES 3
#define FOURIER_PATTERNS 4

/* times fills of a whole field: per direction split over the ranks one
 * exchange, one plane (n_e1 + 2)(n_e2 + 2) a rank border side. */
static void fills(const struct decomp *dc, long times, struct decomp_traffic *t)
{
    for (int d = 0; d < 3; d++) {
        const long sides = dc->border[d][0] + dc->border[d][1];
        if (sides == 0)
            continue;
        const long plane = (long)(dc->n[d == 0 ? 1 : 0] + 2) * (dc->n[d == 2 ? 1 : 2] + 2);
        t->exchanges += times;
        t->messages += times * sides;
        t->bytes += times * sides * plane * DOUBLE_BYTES;
    }
}

/* FFTW's default block of n over P ranks: rank r's first and count. */
static void fftw_block(long n, int P, int r, long *first, long *count)
{
    const long b = (n + P - 1) / P;
    *first = r * b < n ? r * b : n;
    *count = *first + b < n ? b : n - *first;
}

static long overlap(long a0, long na, long b0, long nb)
{
    const long lo = a0 > b0 ? a0 : b0, hi = a0 + na < b0 + nb ? a0 + na : b0 + nb;
    return hi > lo ? hi - lo : 0;
}

/* Rank r's block along d: first cell and count (decomp.c's row-major ranks). */
static void block_along(const struct decomp *dc, int r, int d, long *first, long *count)
{
    const int *dims = dc->cart->dims;
    const int c = d == 2 ? r % dims[2] : d == 1 ? r / dims[2] % dims[1] : r / (dims[2] * dims[1]);
    *first = dc->start[d][c];
    *count = dc->start[d][c + 1] - dc->start[d][c];
}

/* One all-to-all each way between the blocks and FFTW's slabs along a
 * (n_a rows; block_slabs.c): a row of this rank's block holds `rest`
 * values, one of rank r's its count along b times b_values.  Adds both
 * ways' messages and bytes of this rank. */
static void block_slab_moves(const struct decomp *dc, int a, long n_a, long rest, int b,
                             long b_values, struct comm_traffic *t)
{
    const int P = dc->cart->size, me = dc->cart->rank;
    long s0, sn;
    fftw_block(n_a, P, me, &s0, &sn);
    for (int r = 0; r < P; r++) {
        if (r == me)
            continue;
        long r0, rn, a0, an, b0, bn;
        fftw_block(n_a, P, r, &r0, &rn);
        block_along(dc, r, a, &a0, &an);
        block_along(dc, r, b, &b0, &bn);
        const long to_slab = overlap(dc->lo[a], dc->n[a], r0, rn) * rest;
        const long back = overlap(s0, sn, a0, an) * bn * b_values;
        t->alltoall_messages += (to_slab > 0) + (back > 0);
        t->alltoall_bytes += (to_slab + back) * DOUBLE_BYTES;
    }
    t->alltoalls += 2;
}

/* FFTW's transposes of one forward and one inverse execution: n_in rows
 * in (FFTW's blocks of them), n_out out, `values` bytes per (in, out)
 * pair. */
static void fftw_transposes(const struct decomp *dc, long n_in, long n_out, long bytes,
                            struct step_traffic *m)
{
    const int P = dc->cart->size, me = dc->cart->rank;
    long i0, in, o0, on;
    fftw_block(n_in, P, me, &i0, &in);
    fftw_block(n_out, P, me, &o0, &on);
    for (int r = 0; r < P; r++) {
        if (r == me)
            continue;
        long ri0, rin, ro0, ron;
        fftw_block(n_in, P, r, &ri0, &rin);
        fftw_block(n_out, P, r, &ro0, &ron);
        const long fwd = in * ron * bytes, bwd = on * rin * bytes;
        m->fft_messages += (fwd > 0) + (bwd > 0);
        m->fft_bytes += fwd + bwd;
    }
    m->coll.fft_executions += 2;
}

int march_step_traffic_model(const struct march_state *st, const struct step_events *ev,
                             struct step_traffic *m)
{
    memset(m, 0, sizeof *m);
    const struct muflow_case *cs = st->cs;
    if (!st->ranks || !st->density_uniform || st->precond != VISCOUS_FOURIER || cs->coupled ||
        st->nmodules > 0 || st->embedded || st->full_tangent || bc_has_open(&st->bc) ||
        !st->viscous)
        return -1;
    const struct decomp *dc = &st->ranks->dc;
    if (dc->cart->dims[viscous_line_direction(st->viscous)] > 1 || dc->cart->dims[2] > 1)
        return -1; /* the lines and the FFT's z whole on every rank */
    const int *ng = st->ranks->global.n;
    const int aug = st->aug != NULL;
    /* the lines (fourier_lines_create): along L, across o0, o1; a
     * component's line counts when its box spans both across */
    const int L = viscous_line_direction(st->viscous), o0 = (L + 1) % 3, o1 = (L + 2) % 3;
    long maxlen = 0, probed = 0;
    for (int c = 0; c < 3; c++) {
        const struct box *b = &st->act[c];
        long len = b->hi[L] - b->lo[L];
        if (len < 0 || b->hi[o0] - b->lo[o0] != dc->n[o0] || b->hi[o1] - b->lo[o1] != dc->n[o1])
            len = 0;
        maxlen = len > maxlen ? len : maxlen;
        probed += len > 0;
    }
    const long patterns = (ng[o0] > 1 ? 2 : 1) * (ng[o1] > 1 ? 2 : 1);
    const long applies = ev->iterations + ev->setups * probed * patterns * FOURIER_PROBES;
    /* evaluation: velocity (3), strain, pressure, viscosity, the tangent's
     * three (Newton), p_dyn; implicit: an operator apply fills v (3) and
     * the augmentation's r div v; projection: the increment (3), each
     * solve's phi or divergence, the velocity (3) */
    fills(dc, 7 + (cs->newton ? 3 : 0), &m->halo);
    fills(dc, applies * (3 + aug), &m->halo);
    fills(dc, 6 + ev->pressure_solves, &m->halo);
    /* sums and maxima (a maximum is two values: the NaN carried apart):
     * the residual stage's r = kappa max(eta), max |R|, the RMS's two
     * sums, the excess, max |u|, max |div u|; CG's |b| and three a
     * iteration; a set-up's averages of every pattern, component pair,
     * node and probe, and its failed blocks; the projection's test that
     * div delta is not 0 */
    const long sym = FOURIER_PATTERNS * 9 * maxlen * FOURIER_PROBES;
    m->coll.reductions = (5 + aug) + (3 * ev->iterations + 1) + 2 * ev->setups + 1;
    m->coll.reduced_values = (2 * (4 + aug) + 2) + (3 * ev->iterations + 1) +
                             ev->setups * (sym + 1) + 2;
    /* the blocks: each apply moves the lines (3 maxlen values each) to the
     * slabs of the plane transform along a (the direction across split
     * over the ranks, when one alone is and both hold several lines; else
     * the shorter) and back, unless every rank's lines are its slab; FFTW
     * transposes the half spectrum's nu complex values */
    const int split0 = dc->cart->dims[o0] > 1, split1 = dc->cart->dims[o1] > 1;
    const int one = split0 != split1 && ng[o0] > 1 && ng[o1] > 1;
    const int fa = one ? split1 : ng[o1] > ng[o0] ? 0 : 1;
    const int a = fa ? o1 : o0, b = fa ? o0 : o1;
    const long nu = 3 * (maxlen > 0 ? maxlen : 1);
    int aligned = dc->cart->dims[b] == 1;
    for (int r = 0; r < dc->cart->size; r++) {
        long s0, sn, b0, bn;
        fftw_block(ng[a], dc->cart->size, r, &s0, &sn);
        block_along(dc, r, a, &b0, &bn);
        aligned = aligned && s0 == b0 && sn == bn;
    }
    for (long k = 0; k < ev->iterations; k++) {
        if (!aligned)
            block_slab_moves(dc, a, ng[a], dc->n[b] * nu, b, nu, &m->coll);
        fftw_transposes(dc, ng[a], ng[b] / 2 + 1, nu * 2 * DOUBLE_BYTES, m);
    }
    /* the pressure's FFT: blocks to x slabs of whole y-z planes and back,
     * FFTW's 3D transform transposing x and y */
    for (long k = 0; k < ev->pressure_solves; k++) {
        block_slab_moves(dc, 0, ng[0], (long)dc->n[1] * dc->n[2], 1, dc->n[2], &m->coll);
        fftw_transposes(dc, ng[0], ng[1], (long)ng[2] * DOUBLE_BYTES, m);
    }
    return 0;
}
