/* Probing a matrix-free operator into a sparse matrix (probe_matrix.h). */
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/probe_matrix.h"

#define MAX_PROBES 600

struct probe_matrix {
    const struct grid *g;
    int periodic[3];
    int period[3];             /* colour period per direction */
    int reach;
    long n;                    /* unknowns */
    int *index[3];             /* unknown number of each field slot, or -1 */
    int *comp;                 /* component of unknown k */
    ptrdiff_t *slot;           /* field slot of unknown k */
    int *pos;                  /* i, j, k of unknown k (3 per unknown) */
    /* the unknowns each probe sets, by probe: members[start[q] .. start[q+1]) */
    long *start, *members;
    /* an assembly's entries, column by column as the probes find them:
     * the rows and values (trow, tval; tcap allocated), and the columns
     * in their order of appearance, column gcol[m] holding the entries
     * gstart[m] .. gstart[m + 1] (a column's entries all come from its
     * probe, together) */
    int *trow;
    double *tval;
    size_t tcap;
    int *gcol;
    size_t *gstart;
};

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

int probe_matrix_probes_for(const struct grid *g, const int periodic[3], int reach)
{
    int p = 3;
    for (int d = 0; d < 3; d++)
        p *= colour_period(g->n[d], periodic[d], reach);
    return p;
}

int probe_matrix_max_probes(void) { return MAX_PROBES; }

long probe_matrix_unknowns(const struct probe_matrix *pm) { return pm->n; }

int probe_matrix_probes(const struct probe_matrix *pm)
{
    return 3 * pm->period[0] * pm->period[1] * pm->period[2];
}

const int *probe_matrix_components(const struct probe_matrix *pm) { return pm->comp; }

/* The probe that sets unknown u: its component and its position's residues
 * (the order of probe_matrix_assemble's loops). */
static int probe_of(const struct probe_matrix *pm, long u)
{
    const int *at = pm->pos + 3 * u;
    return ((pm->comp[u] * pm->period[0] + at[0] % pm->period[0]) * pm->period[1] +
            at[1] % pm->period[1]) * pm->period[2] + at[2] % pm->period[2];
}

int probe_matrix_create(struct probe_matrix **out, const struct grid *g, const int periodic[3],
                        const struct box act[3], int reach, char *err, size_t errlen)
{
    struct probe_matrix *pm = calloc(1, sizeof *pm);
    if (!pm) {
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    pm->g = g;
    pm->reach = reach;
    for (int d = 0; d < 3; d++) {
        pm->periodic[d] = periodic[d];
        pm->period[d] = colour_period(g->n[d], periodic[d], reach);
    }
    if (probe_matrix_probes(pm) > MAX_PROBES) {
        snprintf(err, errlen,
                 "probed matrix: %d probes needed (periodic cell counts without a small "
                 "divisor); use solver.preconditioner = line",
                 probe_matrix_probes(pm));
        free(pm);
        return -1;
    }
    for (int c = 0; c < 3; c++) {
        const struct box *b = &act[c];
        pm->n += (long)(b->hi[0] - b->lo[0]) * (b->hi[1] - b->lo[1]) * (b->hi[2] - b->lo[2]);
    }
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        pm->index[c] = malloc(g->size * sizeof(int));
        ok &= pm->index[c] != NULL;
    }
    pm->comp = malloc((size_t)pm->n * sizeof(int));
    pm->slot = malloc((size_t)pm->n * sizeof(ptrdiff_t));
    pm->pos = malloc((size_t)pm->n * 3 * sizeof(int));
    ok &= pm->comp && pm->slot && pm->pos;
    if (!ok) {
        probe_matrix_destroy(pm);
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    long k = 0;
    for (int c = 0; c < 3; c++) {
        for (size_t p = 0; p < g->size; p++)
            pm->index[c][p] = -1;
        const struct box *b = &act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int kk = b->lo[2]; kk < b->hi[2]; kk++, k++) {
                    ptrdiff_t p = grid_idx(g, i, j, kk);
                    pm->index[c][p] = (int)k;
                    pm->comp[k] = c;
                    pm->slot[k] = p;
                    pm->pos[3 * k] = i;
                    pm->pos[3 * k + 1] = j;
                    pm->pos[3 * k + 2] = kk;
                }
    }
    /* the probes' members by a counting sort of the unknowns on their probe */
    int nprobes = probe_matrix_probes(pm);
    pm->start = calloc((size_t)nprobes + 1, sizeof(long));
    pm->members = malloc((size_t)(pm->n > 0 ? pm->n : 1) * sizeof(long));
    if (!pm->start || !pm->members) {
        probe_matrix_destroy(pm);
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    for (long u = 0; u < pm->n; u++)
        pm->start[probe_of(pm, u) + 1]++;
    for (int q = 0; q < nprobes; q++)
        pm->start[q + 1] += pm->start[q];
    for (long u = 0; u < pm->n; u++)
        pm->members[pm->start[probe_of(pm, u)]++] = u;
    for (int q = nprobes; q > 0; q--)
        pm->start[q] = pm->start[q - 1];
    pm->start[0] = 0;
    *out = pm;
    return 0;
}

void probe_matrix_destroy(struct probe_matrix *pm)
{
    if (!pm)
        return;
    for (int c = 0; c < 3; c++)
        free(pm->index[c]);
    free(pm->comp);
    free(pm->slot);
    free(pm->pos);
    free(pm->start);
    free(pm->members);
    free(pm->trow);
    free(pm->tval);
    free(pm->gcol);
    free(pm->gstart);
    free(pm);
}


static int grow_triplets(struct probe_matrix *pm, size_t cap)
{
    int *r = realloc(pm->trow, cap * sizeof(int));
    if (r)
        pm->trow = r;
    double *v = realloc(pm->tval, cap * sizeof(double));
    if (v)
        pm->tval = v;
    if (!r || !v)
        return -1;
    pm->tcap = cap;
    return 0;
}

static void free_entries(struct probe_matrix *pm)
{
    free(pm->trow);
    free(pm->tval);
    free(pm->gcol);
    free(pm->gstart);
    pm->trow = pm->gcol = NULL;
    pm->tval = NULL;
    pm->gstart = NULL;
    pm->tcap = 0;
}

int csr_reserve(struct csr_matrix *A, int n, size_t nz)
{
    if (A->n != n || !A->rowptr) {
        int *rp = realloc(A->rowptr, ((size_t)n + 1) * sizeof(int));
        if (!rp)
            return -1;
        A->rowptr = rp;
        A->n = n;
    }
    if (nz > A->cap || !A->col) {
        size_t cap = nz > 0 ? nz : 1;
        int *c = realloc(A->col, cap * sizeof(int));
        if (c)
            A->col = c;
        double *v = realloc(A->val, cap * sizeof(double));
        if (v)
            A->val = v;
        if (!c || !v)
            return -1;
        A->cap = cap;
    }
    return 0;
}

int probe_matrix_assemble(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                          double *resp[3], int lower, struct csr_matrix *A)
{
    const struct grid *g = pm->g;
    if (!pm->tcap && grow_triplets(pm, (size_t)pm->n * (lower ? 16 : 40) + 16) != 0)
        return -1;
    if (!pm->gcol) {
        pm->gcol = malloc(((size_t)pm->n + 1) * sizeof(int));
        pm->gstart = malloc(((size_t)pm->n + 1) * sizeof(size_t));
        if (!pm->gcol || !pm->gstart) {
            free_entries(pm);
            return -1;
        }
    }
    size_t nz = 0, ng = 0;
    const int nprobes = probe_matrix_probes(pm);
    for (int q = 0; q < nprobes; q++) {
        if (pm->start[q] == pm->start[q + 1])
            continue;
        for (int m = 0; m < 3; m++)
            memset(probe[m], 0, g->size * sizeof(double));
        for (long a = pm->start[q]; a < pm->start[q + 1]; a++) {
            long u = pm->members[a];
            probe[pm->comp[u]][pm->slot[u]] = 1.0;
        }
        op(ctx, probe, resp);
        /* the rows each probed column reaches: the unknowns of any component
         * within reach of its position (every position of a periodic direction
         * that is its own colour period and no longer than the stencil); no
         * other column of the probe is within reach of them, so the response
         * there is this column's entry */
        for (long a = pm->start[q]; a < pm->start[q + 1]; a++) {
            long col = pm->members[a];
            const int *at = pm->pos + 3 * col;
            pm->gcol[ng] = (int)col;
            pm->gstart[ng++] = nz;
            int lo[3], hi[3];
            for (int d = 0; d < 3; d++) {
                int n = g->n[d];
                if (pm->periodic[d] && pm->period[d] == n && n <= 2 * pm->reach + 1) {
                    lo[d] = 0;
                    hi[d] = n - 1;
                } else {
                    lo[d] = at[d] - pm->reach;
                    hi[d] = at[d] + pm->reach;
                    if (!pm->periodic[d]) { /* the ghost layer's unknowns: none, index -1 */
                        lo[d] = lo[d] < -1 ? -1 : lo[d];
                        hi[d] = hi[d] > n ? n : hi[d];
                    }
                }
            }
            for (int t0 = lo[0]; t0 <= hi[0]; t0++)
                for (int t1 = lo[1]; t1 <= hi[1]; t1++)
                    for (int t2 = lo[2]; t2 <= hi[2]; t2++) {
                        int t[3] = {t0, t1, t2};
                        for (int d = 0; d < 3; d++)
                            if (pm->periodic[d])
                                t[d] = (t[d] % g->n[d] + g->n[d]) % g->n[d];
                        ptrdiff_t p = grid_idx(g, t[0], t[1], t[2]);
                        for (int m = 0; m < 3; m++) {
                            int r = pm->index[m][p];
                            if (r < 0 || (lower && col > r))
                                continue;
                            double v = resp[m][p];
                            if (v == 0.0)
                                continue;
                            if (nz == pm->tcap && grow_triplets(pm, 2 * pm->tcap) != 0) {
                                free_entries(pm);
                                return -1;
                            }
                            pm->trow[nz] = r;
                            pm->tval[nz] = v;
                            nz++;
                        }
                    }
        }
    }
    pm->gstart[ng] = nz;
    /* rows by counting sort (stable), then columns ascending within a row;
     * every (row, column) comes from exactly one probe.  Each entry's row
     * becomes its place in the rows; the values move there, then the
     * columns, each array allocated when the one before is freed: at most
     * 20 bytes an entry at once (the triplets and a separate matrix held
     * 28, and the peak memory of an AMG step was there) */
    int n = (int)pm->n;
    int *rp = realloc(A->rowptr, ((size_t)n + 1) * sizeof(int));
    if (!rp) {
        free_entries(pm);
        return -1;
    }
    A->rowptr = rp;
    A->n = n;
    free(A->col);
    free(A->val);
    A->col = NULL;
    A->val = NULL;
    A->cap = 0;
    memset(rp, 0, ((size_t)n + 1) * sizeof(int));
    for (size_t q = 0; q < nz; q++)
        rp[pm->trow[q] + 1]++;
    for (int r = 0; r < n; r++)
        rp[r + 1] += rp[r];
    for (size_t q = 0; q < nz; q++)
        pm->trow[q] = rp[pm->trow[q]]++; /* the entry's place */
    for (int r = n; r > 0; r--)
        rp[r] = rp[r - 1];
    rp[0] = 0;
    size_t cap = nz > 0 ? nz : 1;
    A->val = malloc(cap * sizeof(double));
    if (!A->val) {
        free_entries(pm);
        return -1;
    }
    for (size_t q = 0; q < nz; q++)
        A->val[pm->trow[q]] = pm->tval[q];
    free(pm->tval);
    pm->tval = NULL;
    A->col = malloc(cap * sizeof(int));
    if (!A->col) {
        free_entries(pm);
        return -1;
    }
    for (size_t m = 0; m < ng; m++)
        for (size_t q = pm->gstart[m]; q < pm->gstart[m + 1]; q++)
            A->col[pm->trow[q]] = pm->gcol[m];
    A->cap = cap;
    /* the entries are as large as the matrix: not kept between assemblies */
    free_entries(pm);
    for (int r = 0; r < n; r++)
        for (int a = A->rowptr[r] + 1; a < A->rowptr[r + 1]; a++) {
            int cc = A->col[a];
            double vv = A->val[a];
            int b = a - 1;
            for (; b >= A->rowptr[r] && A->col[b] > cc; b--) {
                A->col[b + 1] = A->col[b];
                A->val[b + 1] = A->val[b];
            }
            A->col[b + 1] = cc;
            A->val[b + 1] = vv;
        }
    return 0;
}

void probe_matrix_gather(const struct probe_matrix *pm, double *const r[3], double *b)
{
    for (long k = 0; k < pm->n; k++)
        b[k] = r[pm->comp[k]][pm->slot[k]];
}

void probe_matrix_scatter(const struct probe_matrix *pm, const double *x, double *z[3])
{
    for (long k = 0; k < pm->n; k++)
        z[pm->comp[k]][pm->slot[k]] = x[k];
}

int csr_transpose(const struct csr_matrix *A, struct csr_matrix *T)
{
    int n = A->n;
    size_t nz = (size_t)csr_nnz(A);
    if (csr_reserve(T, n, nz) != 0)
        return -1;
    memset(T->rowptr, 0, ((size_t)n + 1) * sizeof(int));
    for (size_t q = 0; q < nz; q++)
        T->rowptr[A->col[q] + 1]++;
    for (int r = 0; r < n; r++)
        T->rowptr[r + 1] += T->rowptr[r];
    for (int r = 0; r < n; r++) /* rows ascending: T's columns come out sorted */
        for (int a = A->rowptr[r]; a < A->rowptr[r + 1]; a++) {
            int at = T->rowptr[A->col[a]]++;
            T->col[at] = r;
            T->val[at] = A->val[a];
        }
    for (int r = n; r > 0; r--)
        T->rowptr[r] = T->rowptr[r - 1];
    T->rowptr[0] = 0;
    return 0;
}

int csr_same_pattern(const struct csr_matrix *A, const struct csr_matrix *B)
{
    if (!A->rowptr || !B->rowptr || A->n != B->n)
        return 0;
    if (memcmp(A->rowptr, B->rowptr, ((size_t)A->n + 1) * sizeof(int)) != 0)
        return 0;
    return memcmp(A->col, B->col, (size_t)csr_nnz(A) * sizeof(int)) == 0;
}

long csr_drop_component_roundoff(struct csr_matrix *M, const int *comp, double rel)
{
    /* the diagonals first: rows are rewritten in place below */
    double *diag = malloc(((size_t)M->n + 1) * sizeof(double));
    if (!diag)
        return 0; /* nothing dropped: the matrix stays as it is */
    for (int r = 0; r < M->n; r++) {
        diag[r] = 0.0;
        for (int e = M->rowptr[r]; e < M->rowptr[r + 1]; e++)
            if (M->col[e] == r)
                diag[r] = fabs(M->val[e]);
    }
    int w = 0;
    long dropped = 0;
    for (int r = 0; r < M->n; r++) {
        int e0 = M->rowptr[r], e1 = M->rowptr[r + 1];
        M->rowptr[r] = w;
        for (int e = e0; e < e1; e++) {
            int c = M->col[e];
            if (comp[c] != comp[r] && fabs(M->val[e]) <= rel * sqrt(diag[r] * diag[c])) {
                dropped++;
                continue;
            }
            M->col[w] = c;
            M->val[w++] = M->val[e];
        }
    }
    M->rowptr[M->n] = w;
    free(diag);
    return dropped;
}

void csr_free(struct csr_matrix *A)
{
    free(A->rowptr);
    free(A->col);
    free(A->val);
    memset(A, 0, sizeof *A);
}
