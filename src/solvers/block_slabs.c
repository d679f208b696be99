/* Boxes <-> slabs by one all-to-all each way (solvers/block_slabs.h). */
#include "solvers/block_slabs.h"

#include <stdlib.h>

static long overlap(long a0, long na, long b0, long nb)
{
    long lo = a0 > b0 ? a0 : b0, hi = a0 + na < b0 + nb ? a0 + na : b0 + nb;
    return hi > lo ? hi - lo : 0;
}

void block_slabs_free(struct block_slabs *x)
{
    free(x->pieces);
    free(x->counts);
    x->pieces = NULL;
    x->counts = NULL;
}

/* Every rank's box (a0, na, b0, nb, c0, nc) and slab (a0, na) gathered, the
 * counts of the two all-to-alls from them. */
#define BOX_FACTS 8
int block_slabs_init(struct block_slabs *x, const struct comm_cart *cart, const int lo[3],
                     const int n[3], const int n_global[3], long a0, long na, long rows)
{
    const int P = cart->size;
    x->cart = cart;
    x->ranks = P;
    x->n2 = n_global[2];
    x->rows = rows;
    x->a0 = a0;
    double mine[BOX_FACTS] = {lo[0], n[0], lo[1], n[1], (double)a0, (double)na, lo[2], n[2]};
    double *all = malloc((size_t)P * BOX_FACTS * sizeof(double));
    int *sizes = calloc((size_t)P * 2, sizeof(int));
    x->counts = malloc((size_t)P * 9 * sizeof(int));
    const size_t slab = (size_t)na * n_global[1] * n_global[2];
    x->pieces = malloc((slab ? slab : 1) * sizeof(double));
    if (!all || !sizes || !x->counts || !x->pieces) {
        free(all);
        free(sizes);
        block_slabs_free(x);
        return -1;
    }
    for (int r = 0; r < P; r++) {
        sizes[r] = BOX_FACTS;
        sizes[P + r] = BOX_FACTS * r;
    }
    comm_cart_allgather(cart, mine, BOX_FACTS, all, sizes, sizes + P);
    free(sizes);
    int *send = x->counts, *sdis = send + P, *recv = sdis + P, *rdis = recv + P;
    int *b0 = rdis + P, *bn = b0 + P, *pa0 = bn + P, *c0 = pa0 + P, *cn = c0 + P;
    int s = 0, t = 0;
    for (int r = 0; r < P; r++) {
        const double *o = all + BOX_FACTS * r;
        /* my box's values in r's slab: a slowest, so in rank order */
        send[r] = (int)(overlap(lo[0], n[0], (long)o[4], (long)o[5]) * n[1] * n[2]);
        sdis[r] = s;
        s += send[r];
        /* r's box's values in my slab */
        recv[r] = (int)(overlap((long)o[0], (long)o[1], a0, na) * (long)o[3] * (long)o[7]);
        rdis[r] = t;
        t += recv[r];
        b0[r] = (int)o[2];
        bn[r] = (int)o[3];
        pa0[r] = (int)(o[0] > a0 ? o[0] : a0);
        c0[r] = (int)o[6];
        cn[r] = (int)o[7];
    }
    free(all);
    return 0;
}

/* The received pieces (rank after rank, each a, b, c over the rank's box's
 * b and c) into the slab, or back (to_slab = 0). */
static void slab_copy(struct block_slabs *x, double *slab, int to_slab)
{
    const int P = x->ranks;
    const long n2 = x->n2, rows = x->rows;
    const int *recv = x->counts + 2 * P, *rdis = recv + P;
    const int *b0 = rdis + P, *bn = b0 + P, *pa0 = bn + P, *c0 = pa0 + P, *cn = c0 + P;
    for (int r = 0; r < P; r++) {
        if (!recv[r])
            continue;
        const long an = recv[r] / ((long)bn[r] * cn[r]);
        for (long i = 0; i < an; i++)
            for (int j = 0; j < bn[r]; j++) {
                double *s = slab + ((pa0[r] + i - x->a0) * rows + b0[r] + j) * n2 + c0[r];
                double *piece = x->pieces + rdis[r] + (i * bn[r] + j) * cn[r];
                if (to_slab)
                    for (int k = 0; k < cn[r]; k++)
                        s[k] = piece[k];
                else
                    for (int k = 0; k < cn[r]; k++)
                        piece[k] = s[k];
            }
    }
}

void block_slabs_to_slab(struct block_slabs *x, const double *box, double *slab)
{
    const int P = x->ranks;
    const int *send = x->counts, *sdis = send + P, *recv = sdis + P, *rdis = recv + P;
    comm_cart_alltoall(x->cart, box, send, sdis, x->pieces, recv, rdis);
    slab_copy(x, slab, 1);
}

void block_slabs_to_boxes(struct block_slabs *x, double *slab, double *box)
{
    const int P = x->ranks;
    const int *send = x->counts, *sdis = send + P, *recv = sdis + P, *rdis = recv + P;
    slab_copy(x, slab, 0);
    comm_cart_alltoall(x->cart, x->pieces, recv, rdis, box, send, sdis);
}
