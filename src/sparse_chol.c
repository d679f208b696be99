/* Probed sparse Cholesky preconditioner (sparse_chol.h). */
#include <stdlib.h>
#include <string.h>
#include <cholmod.h>
#include "sparse_chol.h"

#define MAX_PROBES 400

struct sparse_chol {
    const struct grid *g;
    struct box act[3];
    int periodic[3];
    int period[3];             /* colour period per direction */
    long n;                    /* unknowns */
    int *index[3];             /* unknown number of each field slot, or -1 */
    int *comp;                 /* component of unknown k */
    ptrdiff_t *slot;           /* field slot of unknown k */
    int *pos;                  /* i, j, k of unknown k (3 per unknown) */
    cholmod_common cm;
    cholmod_factor *L;
    cholmod_sparse *pattern;   /* the matrix of the last analysis */
    cholmod_dense *B, *X, *Y, *E;
};

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

static int colour_period(int n, int periodic)
{
    if (!periodic || n <= 3)
        return periodic ? n : 3;
    for (int p = 3; p <= n; p++)
        if (n % p == 0)
            return p;
    return n;
}

long sparse_chol_unknowns(const struct sparse_chol *s) { return s->n; }

int sparse_chol_probes(const struct sparse_chol *s)
{
    return 3 * s->period[0] * s->period[1] * s->period[2];
}

int sparse_chol_create(struct sparse_chol **out, const struct grid *g, const int periodic[3],
                       const struct box act[3], char *err, size_t errlen)
{
    struct sparse_chol *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "sparse Cholesky: out of memory");
        return -1;
    }
    s->g = g;
    memcpy(s->act, act, sizeof s->act);
    for (int d = 0; d < 3; d++) {
        s->periodic[d] = periodic[d];
        s->period[d] = colour_period(g->n[d], periodic[d]);
    }
    if (sparse_chol_probes(s) > MAX_PROBES) {
        snprintf(err, errlen,
                 "sparse Cholesky: %d probes needed (periodic cell counts without a small "
                 "divisor); use solver.preconditioner = line",
                 sparse_chol_probes(s));
        free(s);
        return -1;
    }
    for (int c = 0; c < 3; c++) {
        const struct box *b = &act[c];
        s->n += (long)(b->hi[0] - b->lo[0]) * (b->hi[1] - b->lo[1]) * (b->hi[2] - b->lo[2]);
    }
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        s->index[c] = malloc(g->size * sizeof(int));
        ok &= s->index[c] != NULL;
    }
    s->comp = malloc((size_t)s->n * sizeof(int));
    s->slot = malloc((size_t)s->n * sizeof(ptrdiff_t));
    s->pos = malloc((size_t)s->n * 3 * sizeof(int));
    ok &= s->comp && s->slot && s->pos;
    if (!ok) {
        sparse_chol_destroy(s);
        snprintf(err, errlen, "sparse Cholesky: out of memory for %ld unknowns", s->n);
        return -1;
    }
    long k = 0;
    for (int c = 0; c < 3; c++) {
        for (size_t p = 0; p < g->size; p++)
            s->index[c][p] = -1;
        const struct box *b = &act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int kk = b->lo[2]; kk < b->hi[2]; kk++, k++) {
                    ptrdiff_t p = grid_idx(g, i, j, kk);
                    s->index[c][p] = (int)k;
                    s->comp[k] = c;
                    s->slot[k] = p;
                    s->pos[3 * k] = i;
                    s->pos[3 * k + 1] = j;
                    s->pos[3 * k + 2] = kk;
                }
    }
    cholmod_start(&s->cm);
    s->cm.error_handler = quiet_handler;
    s->cm.print = 0;
    s->B = cholmod_zeros((size_t)s->n, 1, CHOLMOD_REAL, &s->cm);
    if (!s->B) {
        sparse_chol_destroy(s);
        snprintf(err, errlen, "sparse Cholesky: out of memory");
        return -1;
    }
    *out = s;
    return 0;
}

void sparse_chol_destroy(struct sparse_chol *s)
{
    if (!s)
        return;
    for (int c = 0; c < 3; c++)
        free(s->index[c]);
    free(s->comp);
    free(s->slot);
    free(s->pos);
    if (s->B || s->L || s->pattern) {
        cholmod_free_factor(&s->L, &s->cm);
        cholmod_free_sparse(&s->pattern, &s->cm);
        cholmod_free_dense(&s->B, &s->cm);
        cholmod_free_dense(&s->X, &s->cm);
        cholmod_free_dense(&s->Y, &s->cm);
        cholmod_free_dense(&s->E, &s->cm);
        cholmod_finish(&s->cm);
    }
    free(s);
}

/* The unknown of component c at index (i, j, k) shifted by off, with periodic
 * wrap; -1 if there is none. */
static int neighbour(const struct sparse_chol *s, int c, const int at[3], const int off[3])
{
    int q[3];
    for (int d = 0; d < 3; d++) {
        q[d] = at[d] + off[d];
        int n = s->g->n[d];
        if (s->periodic[d])
            q[d] = ((q[d] % n) + n) % n;
        else if (q[d] < -1 || q[d] > n)
            return -1;
    }
    return s->index[c][grid_idx(s->g, q[0], q[1], q[2])];
}

static int same_pattern(const cholmod_sparse *a, const cholmod_sparse *b)
{
    if (!a || !b || a->ncol != b->ncol || a->nzmax < 1)
        return 0;
    const int *ap = a->p, *bp = b->p, *ai = a->i, *bi = b->i;
    for (size_t j = 0; j <= a->ncol; j++)
        if (ap[j] != bp[j])
            return 0;
    for (int q = 0; q < ap[a->ncol]; q++)
        if (ai[q] != bi[q])
            return 0;
    return 1;
}

int sparse_chol_factor(struct sparse_chol *s, operator_fn op, void *ctx, double *probe[3],
                       double *resp[3])
{
    const struct grid *g = s->g;
    size_t nzmax = (size_t)s->n * 14 + 16; /* lower triangle of a <= 27-point stencil */
    cholmod_triplet *T =
        cholmod_allocate_triplet((size_t)s->n, (size_t)s->n, nzmax, -1, CHOLMOD_REAL, &s->cm);
    if (!T)
        return -1;
    int *Ti = T->i, *Tj = T->j;
    double *Tx = T->x;
    size_t nz = 0;
    int *seen = malloc(27 * sizeof(int));
    for (int c = 0; c < 3; c++)
        for (int a0 = 0; a0 < s->period[0]; a0++)
            for (int a1 = 0; a1 < s->period[1]; a1++)
                for (int a2 = 0; a2 < s->period[2]; a2++) {
                    int colour[3] = {a0, a1, a2};
                    for (int m = 0; m < 3; m++)
                        memset(probe[m], 0, g->size * sizeof(double));
                    for (long k = 0; k < s->n; k++) {
                        const int *at = s->pos + 3 * k;
                        if (s->comp[k] == c && at[0] % s->period[0] == a0 &&
                            at[1] % s->period[1] == a1 && at[2] % s->period[2] == a2)
                            probe[c][s->slot[k]] = 1.0;
                    }
                    op(ctx, probe, resp);
                    /* row r holds A(r, col) for the unique probed col near r */
                    for (long r = 0; r < s->n; r++) {
                        const int *at = s->pos + 3 * r;
                        int nseen = 0;
                        for (int ox = -1; ox <= 1; ox++)
                            for (int oy = -1; oy <= 1; oy++)
                                for (int oz = -1; oz <= 1; oz++) {
                                    int off[3] = {ox, oy, oz};
                                    int col = neighbour(s, c, at, off);
                                    if (col < 0 || col > r)
                                        continue;
                                    const int *cp = s->pos + 3 * col;
                                    if (cp[0] % s->period[0] != colour[0] ||
                                        cp[1] % s->period[1] != colour[1] ||
                                        cp[2] % s->period[2] != colour[2])
                                        continue;
                                    int dup = 0;
                                    for (int q = 0; q < nseen; q++)
                                        dup |= seen[q] == col;
                                    if (dup)
                                        continue; /* a periodic image of the same unknown */
                                    seen[nseen++] = col;
                                    double v = resp[s->comp[r]][s->slot[r]];
                                    if (v == 0.0)
                                        continue;
                                    if (nz == nzmax) {
                                        nzmax *= 2;
                                        if (!cholmod_reallocate_triplet(nzmax, T, &s->cm)) {
                                            free(seen);
                                            cholmod_free_triplet(&T, &s->cm);
                                            return -1;
                                        }
                                        Ti = T->i, Tj = T->j, Tx = T->x;
                                    }
                                    Ti[nz] = (int)r;
                                    Tj[nz] = col;
                                    Tx[nz] = v;
                                    nz++;
                                }
                    }
                }
    free(seen);
    T->nnz = nz;
    cholmod_sparse *A = cholmod_triplet_to_sparse(T, nz, &s->cm);
    cholmod_free_triplet(&T, &s->cm);
    if (!A)
        return -1;
    if (!s->L || !same_pattern(A, s->pattern)) {
        cholmod_free_factor(&s->L, &s->cm);
        cholmod_free_sparse(&s->pattern, &s->cm);
        s->L = cholmod_analyze(A, &s->cm);
        if (!s->L) {
            cholmod_free_sparse(&A, &s->cm);
            return -1;
        }
    } else {
        cholmod_free_sparse(&s->pattern, &s->cm);
    }
    s->pattern = A;
    int okf = cholmod_factorize(A, s->L, &s->cm);
    return okf && s->cm.status == CHOLMOD_OK ? 0 : -1;
}

void sparse_chol_solve(struct sparse_chol *s, double *const r[3], double *z[3])
{
    double *b = s->B->x;
    for (long k = 0; k < s->n; k++)
        b[k] = r[s->comp[k]][s->slot[k]];
    cholmod_solve2(CHOLMOD_A, s->L, s->B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm);
    const double *x = s->X->x;
    for (long k = 0; k < s->n; k++)
        z[s->comp[k]][s->slot[k]] = x[k];
}
