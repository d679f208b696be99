/* Probed sparse direct factorisations (sparse_direct.h). */
#include <malloc.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <cholmod.h>
#include <umfpack.h>
#include "solvers/sparse_direct.h"

#define MAX_PROBES 600

struct sparse_direct {
    const struct grid *g;
    int periodic[3];
    int period[3];             /* colour period per direction */
    int reach, symmetric;
    long n;                    /* unknowns */
    int *index[3];             /* unknown number of each field slot, or -1 */
    int *comp;                 /* component of unknown k */
    ptrdiff_t *slot;           /* field slot of unknown k */
    int *pos;                  /* i, j, k of unknown k (3 per unknown) */
    cholmod_common cm;
    cholmod_sparse *pattern;   /* the matrix of the last factorisation */
    /* symmetric: CHOLMOD */
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E;
    /* general: UMFPACK */
    void *symbolic, *numeric;
    double *rhs, *sol;
};

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

/* Colours need 2 reach + 1 distinct residues in a row's reach; a periodic
 * direction's period must also divide its cell count, and one of at most
 * 2 reach + 1 cells holds every cell in its own colour. */
static int colour_period(int n, int periodic, int reach)
{
    int p = 2 * reach + 1;
    if (!periodic)
        return p;
    if (n <= p)
        return n;
    for (int q = p; q <= n; q++)
        if (n % q == 0)
            return q;
    return n;
}

long sparse_direct_unknowns(const struct sparse_direct *s) { return s->n; }

int sparse_direct_probes(const struct sparse_direct *s)
{
    return 3 * s->period[0] * s->period[1] * s->period[2];
}

int sparse_direct_probes_for(const struct grid *g, const int periodic[3], int reach)
{
    int p = 3;
    for (int d = 0; d < 3; d++)
        p *= colour_period(g->n[d], periodic[d], reach);
    return p;
}

int sparse_direct_max_probes(void) { return MAX_PROBES; }

int sparse_direct_create(struct sparse_direct **out, const struct grid *g, const int periodic[3],
                         const struct box act[3], int reach, int symmetric, char *err,
                         size_t errlen)
{
    /* UMFPACK and CHOLMOD allocate and free their factor workspace at every
     * factorisation.  With glibc's defaults, blocks that large come from fresh
     * mmap pages that the kernel zero-fills each time: a third of a Newton
     * step on a 70 x 100 cross-section.  A top pad keeps that much freed
     * memory in the heap, so the next factorisation reuses the same pages. */
    mallopt(M_TOP_PAD, 256 << 20);
    struct sparse_direct *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "sparse factorisation: out of memory");
        return -1;
    }
    s->g = g;
    s->reach = reach;
    s->symmetric = symmetric;
    for (int d = 0; d < 3; d++) {
        s->periodic[d] = periodic[d];
        s->period[d] = colour_period(g->n[d], periodic[d], reach);
    }
    if (sparse_direct_probes(s) > MAX_PROBES) {
        snprintf(err, errlen,
                 "sparse factorisation: %d probes needed (periodic cell counts without a small "
                 "divisor); use solver.preconditioner = line",
                 sparse_direct_probes(s));
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
    s->rhs = malloc((size_t)s->n * sizeof(double));
    s->sol = malloc((size_t)s->n * sizeof(double));
    ok &= s->comp && s->slot && s->pos && s->rhs && s->sol;
    cholmod_start(&s->cm);
    s->cm.error_handler = quiet_handler;
    s->cm.print = 0;
    if (ok && symmetric)
        ok = (s->B = cholmod_zeros((size_t)s->n, 1, CHOLMOD_REAL, &s->cm)) != NULL;
    if (!ok) {
        sparse_direct_destroy(s);
        snprintf(err, errlen, "sparse factorisation: out of memory");
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
    *out = s;
    return 0;
}

void sparse_direct_destroy(struct sparse_direct *s)
{
    if (!s)
        return;
    for (int c = 0; c < 3; c++)
        free(s->index[c]);
    free(s->comp);
    free(s->slot);
    free(s->pos);
    free(s->rhs);
    free(s->sol);
    if (s->symbolic)
        umfpack_di_free_symbolic(&s->symbolic);
    if (s->numeric)
        umfpack_di_free_numeric(&s->numeric);
    cholmod_free_factor(&s->L, &s->cm);
    cholmod_free_sparse(&s->pattern, &s->cm);
    cholmod_free_dense(&s->B, &s->cm);
    cholmod_free_dense(&s->X, &s->cm);
    cholmod_free_dense(&s->Y, &s->cm);
    cholmod_free_dense(&s->E, &s->cm);
    cholmod_finish(&s->cm);
    free(s);
}

/* The unknown of component c probed with colour `colour` that row r's stencil
 * reaches, or -1: per direction the offset within +-reach with the right
 * residue is unique (a short periodic direction holds one cell per colour). */
static int probed_column(const struct sparse_direct *s, int c, const int at[3],
                         const int colour[3])
{
    int q[3];
    for (int d = 0; d < 3; d++) {
        int n = s->g->n[d], P = s->period[d];
        if (s->periodic[d] && P == n) {
            q[d] = colour[d];
            continue;
        }
        int off = ((colour[d] - at[d]) % P + P) % P;
        if (off > s->reach)
            off -= P;
        if (off < -s->reach || off > s->reach)
            return -1;
        q[d] = at[d] + off;
        if (s->periodic[d])
            q[d] = ((q[d] % n) + n) % n;
        else if (q[d] < -1 || q[d] > n)
            return -1;
    }
    return s->index[c][grid_idx(s->g, q[0], q[1], q[2])];
}

static int same_pattern(const cholmod_sparse *a, const cholmod_sparse *b)
{
    if (!a || !b || a->ncol != b->ncol)
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

/* Probes the operator into a triplet matrix (lower triangle if symmetric). */
static cholmod_sparse *assemble(struct sparse_direct *s, operator_fn op, void *ctx,
                                double *probe[3], double *resp[3])
{
    const struct grid *g = s->g;
    size_t nzmax = (size_t)s->n * (s->symmetric ? 16 : 40) + 16;
    cholmod_triplet *T = cholmod_allocate_triplet((size_t)s->n, (size_t)s->n, nzmax,
                                                  s->symmetric ? -1 : 0, CHOLMOD_REAL, &s->cm);
    if (!T)
        return NULL;
    size_t nz = 0;
    for (int c = 0; c < 3; c++)
        for (int a0 = 0; a0 < s->period[0]; a0++)
            for (int a1 = 0; a1 < s->period[1]; a1++)
                for (int a2 = 0; a2 < s->period[2]; a2++) {
                    int colour[3] = {a0, a1, a2};
                    for (int m = 0; m < 3; m++)
                        memset(probe[m], 0, g->size * sizeof(double));
                    int any = 0;
                    for (long k = 0; k < s->n; k++) {
                        const int *at = s->pos + 3 * k;
                        if (s->comp[k] == c && at[0] % s->period[0] == a0 &&
                            at[1] % s->period[1] == a1 && at[2] % s->period[2] == a2) {
                            probe[c][s->slot[k]] = 1.0;
                            any = 1;
                        }
                    }
                    if (!any)
                        continue;
                    op(ctx, probe, resp);
                    for (long r = 0; r < s->n; r++) {
                        int col = probed_column(s, c, s->pos + 3 * r, colour);
                        if (col < 0 || (s->symmetric && col > r))
                            continue;
                        double v = resp[s->comp[r]][s->slot[r]];
                        if (v == 0.0)
                            continue;
                        if (nz == nzmax) {
                            nzmax *= 2;
                            if (!cholmod_reallocate_triplet(nzmax, T, &s->cm)) {
                                cholmod_free_triplet(&T, &s->cm);
                                return NULL;
                            }
                        }
                        ((int *)T->i)[nz] = (int)r;
                        ((int *)T->j)[nz] = col;
                        ((double *)T->x)[nz] = v;
                        nz++;
                    }
                }
    T->nnz = nz;
    cholmod_sparse *A = cholmod_triplet_to_sparse(T, nz, &s->cm);
    cholmod_free_triplet(&T, &s->cm);
    return A;
}

int sparse_direct_factor(struct sparse_direct *s, operator_fn op, void *ctx, double *probe[3],
                         double *resp[3])
{
    cholmod_sparse *A = assemble(s, op, ctx, probe, resp);
    if (!A)
        return -1;
    int fresh = !same_pattern(A, s->pattern);
    cholmod_free_sparse(&s->pattern, &s->cm);
    s->pattern = A;
    if (s->symmetric) {
        if (fresh || !s->L) {
            cholmod_free_factor(&s->L, &s->cm);
            if (!(s->L = cholmod_analyze(A, &s->cm)))
                return -1;
        }
        int okf = cholmod_factorize(A, s->L, &s->cm);
        return okf && s->cm.status == CHOLMOD_OK ? 0 : -1;
    }
    const int *Ap = A->p, *Ai = A->i;
    const double *Ax = A->x;
    if (fresh || !s->symbolic) {
        if (s->symbolic)
            umfpack_di_free_symbolic(&s->symbolic);
        if (umfpack_di_symbolic((int)s->n, (int)s->n, Ap, Ai, Ax, &s->symbolic, NULL, NULL) !=
            UMFPACK_OK)
            return -1;
    }
    if (s->numeric)
        umfpack_di_free_numeric(&s->numeric);
    return umfpack_di_numeric(Ap, Ai, Ax, s->symbolic, &s->numeric, NULL, NULL) == UMFPACK_OK
               ? 0
               : -1;
}

void sparse_direct_solve(struct sparse_direct *s, double *const r[3], double *z[3])
{
    double *b = s->symmetric ? s->B->x : s->rhs;
    for (long k = 0; k < s->n; k++)
        b[k] = r[s->comp[k]][s->slot[k]];
    const double *x = s->sol;
    if (s->symmetric) {
        cholmod_solve2(CHOLMOD_A, s->L, s->B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm);
        x = s->X->x;
    } else {
        const cholmod_sparse *A = s->pattern;
        umfpack_di_solve(UMFPACK_A, A->p, A->i, A->x, s->sol, s->rhs, s->numeric, NULL, NULL);
    }
    for (long k = 0; k < s->n; k++)
        z[s->comp[k]][s->slot[k]] = x[k];
}

double sparse_direct_memory_estimate(long unknowns, int dims)
{
    /* Measured (peak RSS less the fields, UMFPACK's LU of the full tangent on
     * the Bingham cavity): 1,260 bytes an unknown at 64 x 64 (12,288
     * unknowns), 1,550 at 128 x 128 (49,152): about 100 log2(n) bytes, the
     * n log n fill of nested dissection on a 2D grid.  In 3D the fill grows
     * like n^(4/3) (not measured: the same constant times n^(1/3)). */
    double n = (double)(unknowns > 2 ? unknowns : 2);
    double per = 100.0 * log2(n);
    if (dims >= 3)
        per = 100.0 * cbrt(n) * 8.0;
    return n * per;
}
