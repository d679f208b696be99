/* A box decomposition of the grid (grid/decomp.h). */
#include "grid/decomp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static struct decomp_traffic traffic;

void decomp_traffic_read(struct decomp_traffic *t)
{
    *t = traffic;
}

void decomp_traffic_reset(void)
{
    memset(&traffic, 0, sizeof traffic);
    comm_traffic_reset();
}

void decomp_collectives_read(struct comm_traffic *t)
{
    comm_traffic_read(t);
}

/* Slots of a plane across d: the other two directions' ext. */
static size_t plane_len(const struct grid *g, int d)
{
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
    return (size_t)g->ext[e1] * (size_t)g->ext[e2];
}

static void set_borders(struct decomp *dc)
{
    const struct comm_cart *c = dc->cart;
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            dc->border[d][s] = c->dims[d] > 1 && c->nbr[d][s] >= 0;
}

int decomp_create(struct decomp *dc, const struct comm_cart *cart, const int n_global[3],
                  char *err, size_t errlen)
{
    memset(dc, 0, sizeof *dc);
    dc->cart = cart;
    size_t longest = 0;
    for (int d = 0; d < 3; d++) {
        const int p = cart->dims[d], n = n_global[d];
        if (p > DECOMP_MAX_SPLIT || p > n) {
            snprintf(err, errlen, "decomposition: %d ranks along %c for %d cells (at most %d, "
                                  "and one cell each)", p, "xyz"[d], n, DECOMP_MAX_SPLIT);
            return -1;
        }
        dc->n_global[d] = n;
        for (int c = 0; c <= p; c++)
            dc->start[d][c] = c * (n / p) + (c < n % p ? c : n % p);
        dc->lo[d] = dc->start[d][cart->coords[d]];
        dc->n[d] = dc->start[d][cart->coords[d] + 1] - dc->lo[d];
    }
    set_borders(dc);
    for (int d = 0; d < 3; d++) {
        const size_t a = (size_t)(dc->n[d == 0 ? 1 : 0] + 2) * (size_t)(dc->n[d == 2 ? 1 : 2] + 2);
        longest = a > longest ? a : longest;
    }
    dc->buflen = 4 * longest;
    if (decomp_split(dc) && !(dc->buf = malloc(dc->buflen * sizeof(double)))) {
        snprintf(err, errlen, "decomposition: out of memory");
        return -1;
    }
    dc->owns_buf = 1;
    return 0;
}

void decomp_free(struct decomp *dc)
{
    if (dc->owns_buf)
        free(dc->buf);
    dc->buf = NULL;
}

double decomp_sum(const struct decomp *dc, double v)
{
    if (dc && dc->cart->size > 1)
        comm_sum(&v, 1);
    return v;
}

void decomp_sum_array(const struct decomp *dc, double *v, int n)
{
    if (dc && dc->cart->size > 1)
        comm_sum(v, n);
}

void decomp_max_array(const struct decomp *dc, double *v, int n)
{
    if (dc && dc->cart->size > 1)
        comm_max(v, n);
}

double decomp_max(const struct decomp *dc, double v)
{
    if (!dc || dc->cart->size <= 1)
        return v;
    /* MPI's maximum of a NaN is undefined: it is carried apart, so that one
     * rank's NaN is every rank's */
    double w[2] = {isnan(v) ? -INFINITY : v, isnan(v) ? 1.0 : 0.0};
    comm_max(w, 2);
    return w[1] > 0.0 ? NAN : w[0];
}

int decomp_split(const struct decomp *dc)
{
    for (int d = 0; d < 3; d++)
        if (dc->border[d][0] || dc->border[d][1])
            return 1;
    return 0;
}

int decomp_coarsen(const struct decomp *fine, const int halve[3], struct decomp *coarse)
{
    struct decomp c = *fine;
    for (int d = 0; d < 3; d++) {
        if (!halve[d])
            continue;
        for (int b = 0; b <= fine->cart->dims[d]; b++) {
            if (fine->start[d][b] % 2 != 0)
                return -1;
            c.start[d][b] = fine->start[d][b] / 2;
        }
        c.n_global[d] = fine->n_global[d] / 2;
        c.lo[d] = fine->lo[d] / 2;
        c.n[d] = fine->n[d] / 2;
        if (c.n[d] < 1)
            return -1;
    }
    c.owns_buf = 0;
    *coarse = c;
    return 0;
}

int decomp_local_grid(const struct decomp *dc, const struct grid *gg, struct grid *g)
{
    double len[3];
    for (int d = 0; d < 3; d++)
        len[d] = gg->h[d] * dc->n[d];
    if (grid_init_like(g, dc->n, len, gg) != 0)
        return -1;
    for (int d = 0; d < 3; d++)
        g->h[d] = gg->h[d]; /* the global spacing to the bit */
    return 0;
}

/* What plane_move does with plane t of f and buf. */
enum plane_move_kind { PLANE_TO_BUF, PLANE_FROM_BUF, PLANE_ADD_BUF };

/* Plane t (-1 .. n) across d of f to buf, from buf or plus buf, every slot
 * of the other two. */
static void plane_move(const struct grid *g, double *f, int d, int t, double *buf,
                       enum plane_move_kind kind)
{
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
    size_t q = 0;
    for (int u = grid_slot_lo(g, e1); u <= grid_slot_hi(g, e1); u++)
        for (int v = grid_slot_lo(g, e2); v <= grid_slot_hi(g, e2); v++) {
            int c[3];
            c[d] = t;
            c[e1] = u;
            c[e2] = v;
            const ptrdiff_t p = grid_idx(g, c[0], c[1], c[2]);
            if (kind == PLANE_TO_BUF)
                buf[q++] = f[p];
            else if (kind == PLANE_FROM_BUF)
                f[p] = buf[q++];
            else
                f[p] += buf[q++];
        }
}

/* Sends planes `lo` and `hi` across d of f to the neighbours on the low and
 * high border sides (where there are borders) and receives theirs into
 * dc->buf: returns the plane's length; *sent[2], *recv[2] the buffers by
 * side.  Counted in the traffic tally. */
static size_t shift_planes(const struct decomp *dc, const struct grid *g, double *f, int d,
                           int lo, int hi, double *sent[2], double *recv[2])
{
    const size_t len = plane_len(g, d);
    sent[0] = dc->buf;
    sent[1] = sent[0] + len;
    recv[0] = sent[1] + len;
    recv[1] = recv[0] + len;
    if (dc->border[d][0])
        plane_move(g, f, d, lo, sent[0], PLANE_TO_BUF);
    if (dc->border[d][1])
        plane_move(g, f, d, hi, sent[1], PLANE_TO_BUF);
    comm_cart_shift(dc->cart, d, sent[0], recv[0], sent[1], recv[1], (int)len);
    const long sides = dc->border[d][0] + dc->border[d][1];
    traffic.exchanges++;
    traffic.messages += sides;
    traffic.bytes += sides * (long)(len * sizeof(double));
    return len;
}

void decomp_exchange(const struct decomp *dc, const struct grid *g, double *f, int d)
{
    if (!dc->border[d][0] && !dc->border[d][1])
        return;
    double *sent[2], *recv[2];
    const int n = g->n[d];
    shift_planes(dc, g, f, d, 0, n - 1, sent, recv);
    if (dc->border[d][0])
        plane_move(g, f, d, -1, recv[0], PLANE_FROM_BUF);
    if (dc->border[d][1])
        plane_move(g, f, d, n, recv[1], PLANE_FROM_BUF);
}

void decomp_exchange_add(const struct decomp *dc, const struct grid *g, double *f, int d)
{
    if (!dc->border[d][0] && !dc->border[d][1])
        return;
    double *sent[2], *recv[2];
    const int n = g->n[d];
    const size_t len = shift_planes(dc, g, f, d, -1, n, sent, recv);
    /* the ghost planes sent are spent: zeroed */
    for (int s = 0; s < 2; s++) {
        if (!dc->border[d][s])
            continue;
        plane_move(g, f, d, s ? n - 1 : 0, recv[s], PLANE_ADD_BUF);
        for (size_t q = 0; q < len; q++)
            sent[s][q] = 0.0;
        plane_move(g, f, d, s ? n : -1, sent[s], PLANE_FROM_BUF);
    }
}

/* The block of the rank at coords c: its first cell and count per direction. */
static void block_of(const struct decomp *dc, const int c[3], int lo[3], int n[3])
{
    for (int d = 0; d < 3; d++) {
        lo[d] = dc->start[d][c[d]];
        n[d] = dc->start[d][c[d] + 1] - lo[d];
    }
}

/* The coords of Cartesian rank r (row-major, as MPI numbers them). */
static void coords_of(const struct comm_cart *cart, int r, int c[3])
{
    c[2] = r % cart->dims[2];
    c[1] = r / cart->dims[2] % cart->dims[1];
    c[0] = r / (cart->dims[2] * cart->dims[1]);
}

static size_t block_slots(const int n[3])
{
    return (size_t)(n[0] + 2) * (size_t)(n[1] + 2) * (size_t)(n[2] + 2);
}

size_t decomp_gather_len(const struct decomp *dc)
{
    size_t total = 0;
    const int ranks = dc->cart->dims[0] * dc->cart->dims[1] * dc->cart->dims[2];
    for (int r = 0; r < ranks; r++) {
        int c[3], lo[3], n[3];
        coords_of(dc->cart, r, c);
        block_of(dc, c, lo, n);
        total += block_slots(n);
    }
    return total;
}

void decomp_gather(const struct decomp *dc, const struct grid *g, const double *f,
                   const struct grid *gg, double *global, double *scratch)
{
    const struct comm_cart *cart = dc->cart;
    const int ranks = cart->dims[0] * cart->dims[1] * cart->dims[2];
    int counts[DECOMP_MAX_SPLIT * 4] = {0}, displs[DECOMP_MAX_SPLIT * 4] = {0};
    int *cnt = counts, *dsp = displs;
    int *heap = NULL;
    if (ranks > DECOMP_MAX_SPLIT * 4) {
        heap = malloc(2 * (size_t)ranks * sizeof(int));
        if (!heap)
            abort();
        cnt = heap;
        dsp = heap + ranks;
    }
    size_t at = 0;
    for (int r = 0; r < ranks; r++) {
        int c[3], lo[3], n[3];
        coords_of(cart, r, c);
        block_of(dc, c, lo, n);
        cnt[r] = (int)block_slots(n);
        dsp[r] = (int)at;
        at += (size_t)cnt[r];
    }
    comm_cart_allgather(cart, f, (int)g->size, scratch, cnt, dsp);
    if (ranks > 1) {
        traffic.gathers++;
        traffic.gather_sent += (long)(g->size * sizeof(double));
        traffic.gather_received += (long)((at - g->size) * sizeof(double));
    }
    for (int r = 0; r < ranks; r++) {
        int c[3], lo[3], n[3], a[3], b[3];
        coords_of(cart, r, c);
        block_of(dc, c, lo, n);
        struct grid gb = *g; /* rank r's layout: ext n + 2, z fastest */
        gb.stride[2] = 1;
        gb.stride[1] = n[2] + 2;
        gb.stride[0] = (ptrdiff_t)(n[1] + 2) * (n[2] + 2);
        for (int d = 0; d < 3; d++) {
            /* the ghost on the domain's boundary travels with the block */
            a[d] = c[d] == 0 && !(cart->periodic[d] && cart->dims[d] > 1) ? -1 : 0;
            b[d] = c[d] == cart->dims[d] - 1 && !(cart->periodic[d] && cart->dims[d] > 1)
                       ? n[d] : n[d] - 1;
        }
        const double *src = scratch + dsp[r];
        for (int i = a[0]; i <= b[0]; i++)
            for (int j = a[1]; j <= b[1]; j++)
                for (int k = a[2]; k <= b[2]; k++)
                    global[grid_idx(gg, lo[0] + i, lo[1] + j, lo[2] + k)] =
                        src[grid_idx(&gb, i, j, k)];
    }
    free(heap);
}

void decomp_scatter(const struct decomp *dc, const struct grid *gg, const double *global,
                    const struct grid *g, double *f)
{
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                f[grid_idx(g, i, j, k)] =
                    global[grid_idx(gg, dc->lo[0] + i, dc->lo[1] + j, dc->lo[2] + k)];
}
