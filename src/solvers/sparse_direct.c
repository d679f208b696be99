/* Probed sparse direct factorisations (sparse_direct.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/sparse_direct.h"
#include "solvers/suitesparse.h"

/* Couplings between velocity components below this share of their
 * diagonals' geometric mean are round-off (csr_drop_component_roundoff). */
#define COMPONENT_ROUNDOFF 1e-12

/* The factors of the velocity components that the matrix couples: one
 * block for a flow that couples them all, two for a flow in a plane (the
 * component across it on its own) or along one direction (its component
 * apart from the two across).  Each block is factorised at the first solve
 * whose right-hand side reaches it (sparse_direct_prepare): a block that
 * no right-hand side reaches is never factorised.  The component across a
 * plane flow (the collapse's, the cavity's) stays 0, so its third of the
 * unknowns costs nothing. */
struct block {
    int ncomp, comp[3];        /* its components, ascending */
    int n;                     /* unknowns */
    struct csr_matrix cur, next; /* by columns: the matrix of the last factorisation, the new one */
    int fresh;                 /* next's pattern differs from cur's: analyse again */
    int factorised;            /* cur's numeric factors are current */
    int dropped;               /* the last sparse_direct_prepare left it out */
    /* symmetric: CHOLMOD, given the lower triangle of P A P' (P the
     * fill-reducing order of its analysis) with a factor analysed in that
     * order: CHOLMOD then factorises what it is given, where with A and P
     * it transposed A twice into new arrays each time */
    cholmod_factor *L;
    int *order;                /* order[k]: the block's unknown in place k of P A P' */
    long *slot;                /* slot[e]: where entry e of cur goes in permuted */
    struct csr_matrix permuted; /* lower triangle of P A P' by columns */
    cholmod_dense *B, *X, *Y, *E;
    /* general: UMFPACK */
    void *symbolic, *numeric;
};

struct sparse_direct {
    struct probe_matrix *pm;   /* numbering, colouring and probing */
    int symmetric;
    long n;                    /* unknowns */
    long first[4];             /* component c's unknowns: first[c] .. first[c + 1] - 1 */
    struct csr_matrix rows;    /* the probed matrix by rows (work) */
    int nblocks;
    struct block blk[3];
    cholmod_common cm;
    double *rhs, *sol;         /* all unknowns, block after block */
    char cause[160];           /* of the last failed factorisation */
};

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

long sparse_direct_unknowns(const struct sparse_direct *s) { return s->n; }

const char *sparse_direct_cause(const struct sparse_direct *s) { return s->cause; }

/* Records why the factorisation (of block b, or NULL: of the matrix) failed;
 * returns -1. */
static int failed(struct sparse_direct *s, const struct block *b, const char *what,
                  const char *why)
{
    char part[64] = "";
    if (b && s->nblocks > 1) {
        static const char axis[3] = {'x', 'y', 'z'};
        int at = snprintf(part, sizeof part, " (velocity component%s", b->ncomp > 1 ? "s" : "");
        for (int q = 0; q < b->ncomp && at < (int)sizeof part - 8; q++)
            at += snprintf(part + at, sizeof part - (size_t)at, "%s%c", q ? " and " : " ",
                           axis[b->comp[q]]);
        snprintf(part + at, sizeof part - (size_t)at, " of %ld unknowns)", s->n);
    }
    snprintf(s->cause, sizeof s->cause, "the probed %s of %ld unknowns%s: %s", what,
             b ? (long)b->n : s->n, part, why);
    return -1;
}

int sparse_direct_probes(const struct sparse_direct *s) { return probe_matrix_probes(s->pm); }

int sparse_direct_probes_for(const struct grid *g, const int periodic[3], int reach)
{
    return probe_matrix_probes_for(g, periodic, reach);
}

int sparse_direct_max_probes(void) { return probe_matrix_max_probes(); }

int sparse_direct_create(struct sparse_direct **out, const struct grid *g, const int periodic[3],
                         const struct box act[3], int reach, int symmetric, char *err,
                         size_t errlen)
{
    suitesparse_keep_factor_memory();
    if (suitesparse_load(err, errlen) != 0)
        return -1;
    struct sparse_direct *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "sparse factorisation: out of memory");
        return -1;
    }
    s->symmetric = symmetric;
    if (probe_matrix_create(&s->pm, g, periodic, act, reach, err, errlen) != 0) {
        free(s);
        return -1;
    }
    s->n = probe_matrix_unknowns(s->pm);
    const int *comp = probe_matrix_components(s->pm);
    for (int c = 0, k = 0; c <= 3; c++) { /* the unknowns come component by component */
        while (k < s->n && comp[k] < c)
            k++;
        s->first[c] = k;
    }
    s->rhs = malloc(((size_t)s->n + 1) * sizeof(double));
    s->sol = malloc(((size_t)s->n + 1) * sizeof(double));
    suitesparse_cholmod_start(&s->cm);
    s->cm.error_handler = quiet_handler;
    s->cm.print = 0;
    if (!s->rhs || !s->sol) {
        sparse_direct_destroy(s);
        snprintf(err, errlen, "sparse factorisation: out of memory");
        return -1;
    }
    *out = s;
    return 0;
}

static void free_block(struct sparse_direct *s, struct block *b)
{
    csr_free(&b->cur);
    csr_free(&b->next);
    csr_free(&b->permuted);
    free(b->order);
    free(b->slot);
    if (b->symbolic)
        suitesparse.umfpack_di_free_symbolic(&b->symbolic);
    if (b->numeric)
        suitesparse.umfpack_di_free_numeric(&b->numeric);
    suitesparse.cholmod_free_factor(&b->L, &s->cm);
    suitesparse.cholmod_free_dense(&b->B, &s->cm);
    suitesparse.cholmod_free_dense(&b->X, &s->cm);
    suitesparse.cholmod_free_dense(&b->Y, &s->cm);
    suitesparse.cholmod_free_dense(&b->E, &s->cm);
    memset(b, 0, sizeof *b);
}

void sparse_direct_destroy(struct sparse_direct *s)
{
    if (!s)
        return;
    probe_matrix_destroy(s->pm);
    csr_free(&s->rows);
    free(s->rhs);
    free(s->sol);
    for (int k = 0; k < 3; k++)
        free_block(s, &s->blk[k]);
    suitesparse.cholmod_finish(&s->cm);
    free(s);
}

/* A CHOLMOD view of compressed columns (lower triangle), not owned by CHOLMOD. */
static cholmod_sparse cholmod_view(const struct csr_matrix *A)
{
    cholmod_sparse v = {
        .nrow = (size_t)A->n, .ncol = (size_t)A->n, .nzmax = (size_t)csr_nnz(A),
        .p = A->rowptr, .i = A->col, .x = A->val, .stype = -1, .itype = CHOLMOD_INT,
        .xtype = CHOLMOD_REAL, .dtype = CHOLMOD_DOUBLE, .sorted = 1, .packed = 1};
    return v;
}

/* The blocks of components that M couples (entries between components
 * that csr_drop_component_roundoff kept); the blocks are kept while their
 * components stay the same. */
static void split_blocks(struct sparse_direct *s, const struct csr_matrix *M)
{
    const int *comp = probe_matrix_components(s->pm);
    int group[3];
    csr_component_groups(M, comp, group);
    struct block want[3];
    int nb = 0;
    for (int gi = 0; gi < 3; gi++) {
        struct block b = {0};
        for (int c = 0; c < 3; c++)
            if (group[c] == gi && s->first[c + 1] > s->first[c]) {
                b.comp[b.ncomp++] = c;
                b.n += (int)(s->first[c + 1] - s->first[c]);
            }
        if (b.ncomp > 0)
            want[nb++] = b;
    }
    int same = nb == s->nblocks;
    for (int k = 0; same && k < nb; k++)
        same = want[k].ncomp == s->blk[k].ncomp &&
               memcmp(want[k].comp, s->blk[k].comp, sizeof want[k].comp) == 0;
    if (!same) {
        for (int k = 0; k < 3; k++)
            free_block(s, &s->blk[k]);
        for (int k = 0; k < nb; k++)
            s->blk[k] = want[k];
        s->nblocks = nb;
    }
}

/* Block b's part of M (its rows and columns, numbered within the block: its
 * components' unknowns one after the other) by columns into b->next: M's
 * transpose restricted to the block. */
static int take_block(struct sparse_direct *s, struct block *b, const struct csr_matrix *M)
{
    long offset[3] = {0, 0, 0}; /* block index = unknown + offset[c] (c its component) */
    size_t nz = 0;
    for (int q = 0, at = 0; q < b->ncomp; q++) {
        int c = b->comp[q];
        offset[c] = at - s->first[c];
        at += (int)(s->first[c + 1] - s->first[c]);
        nz += (size_t)(M->rowptr[s->first[c + 1]] - M->rowptr[s->first[c]]);
    }
    struct csr_matrix *T = &b->next;
    if (csr_reserve(T, b->n, nz) != 0)
        return -1;
    const int *comp = probe_matrix_components(s->pm);
    memset(T->rowptr, 0, ((size_t)b->n + 1) * sizeof(int));
    for (int q = 0; q < b->ncomp; q++) { /* the block's entries of each column */
        int c = b->comp[q];
        for (int e = M->rowptr[s->first[c]]; e < M->rowptr[s->first[c + 1]]; e++)
            T->rowptr[M->col[e] + offset[comp[M->col[e]]] + 1]++;
    }
    for (int r = 0; r < b->n; r++)
        T->rowptr[r + 1] += T->rowptr[r];
    for (int q = 0; q < b->ncomp; q++) { /* rows ascending: the columns come out sorted */
        int c = b->comp[q];
        for (long k = s->first[c]; k < s->first[c + 1]; k++)
            for (int e = M->rowptr[k]; e < M->rowptr[k + 1]; e++) {
                int at = T->rowptr[M->col[e] + offset[comp[M->col[e]]]]++;
                T->col[at] = (int)(k + offset[c]);
                T->val[at] = M->val[e];
            }
    }
    for (int r = b->n; r > 0; r--)
        T->rowptr[r] = T->rowptr[r - 1];
    T->rowptr[0] = 0;
    b->fresh = !csr_same_pattern(&b->next, &b->cur);
    struct csr_matrix t = b->cur;
    b->cur = b->next;
    b->next = t;
    b->factorised = 0;
    return 0;
}

int sparse_direct_factor(struct sparse_direct *s, operator_fn op, void *ctx, double *probe[3],
                         double *resp[3], int components, int *probed)
{
    /* by rows (the lower triangle if symmetric), transposed into columns */
    if (probe_matrix_assemble_components(s->pm, op, ctx, probe, resp, s->symmetric, components,
                                         &s->rows, probed) != 0)
        return failed(s, NULL, "matrix", "out of memory");
    /* the factors of a flow along one direction then hold its component and
     * the two across it apart: about half the time, less memory, the same
     * steps (docs/numerics/linear-solvers.md, "Blocks left out"); the Krylov
     * method keeps the dropped round-off in the operator */
    csr_drop_component_roundoff(&s->rows, probe_matrix_components(s->pm),
                                COMPONENT_ROUNDOFF);
    split_blocks(s, &s->rows);
    for (int k = 0; k < s->nblocks; k++)
        if (take_block(s, &s->blk[k], &s->rows) != 0)
            return failed(s, NULL, "matrix", "out of memory");
    return 0;
}

/* Analyses block b's current matrix A for CHOLMOD: its fill-reducing order
 * P (CHOLMOD's choice, postordered, as cholmod_analyze gives it for A), the
 * pattern of P A P''s lower triangle with the place of each of A's entries
 * in it, and the factor of P A P' in its own order (natural, not
 * postordered again: P is).  The factor's supernodes and operations are
 * those of A's factor with P.  Returns 0 or -1 (the cause recorded). */
static int analyse_permuted(struct sparse_direct *s, struct block *b)
{
    const struct csr_matrix *A = &b->cur;
    const int n = A->n;
    const long nz = csr_nnz(A);
    suitesparse.cholmod_free_factor(&b->L, &s->cm);
    cholmod_sparse v = cholmod_view(A);
    cholmod_factor *L0 = suitesparse.cholmod_analyze(&v, &s->cm);
    if (!L0)
        return failed(s, b, "Cholesky factorisation (CHOLMOD)",
                      suitesparse_cholmod_text(s->cm.status));
    int *order = realloc(b->order, ((size_t)n + 1) * sizeof(int));
    if (order)
        b->order = order;
    long *slot = realloc(b->slot, ((size_t)nz + 1) * sizeof(long));
    if (slot)
        b->slot = slot;
    int *place = malloc(((size_t)n + 1) * sizeof(int)); /* place[i]: unknown i's k */
    int ok = order && slot && place;
    const char *why = "out of memory";
    if (ok) {
        memcpy(order, L0->Perm, (size_t)n * sizeof(int));
        for (int k = 0; k < n; k++)
            place[order[k]] = k;
        ok = csr_permute_lower(A, place, n, &b->permuted, slot) == 0;
    }
    if (ok) {
        /* the factor of P A P' in its own order */
        cholmod_sparse pv = cholmod_view(&b->permuted);
        int nmethods = s->cm.nmethods, ordering = s->cm.method[0].ordering,
            postorder = s->cm.postorder;
        s->cm.nmethods = 1;
        s->cm.method[0].ordering = CHOLMOD_NATURAL;
        s->cm.postorder = 0;
        b->L = suitesparse.cholmod_analyze(&pv, &s->cm);
        s->cm.nmethods = nmethods;
        s->cm.method[0].ordering = ordering;
        s->cm.postorder = postorder;
        ok = b->L && b->L->ordering == CHOLMOD_NATURAL;
        why = !b->L ? suitesparse_cholmod_text(s->cm.status)
                    : "the permuted matrix's analysis is not in its own order";
    }
    suitesparse.cholmod_free_factor(&L0, &s->cm);
    free(place);
    if (!ok)
        suitesparse.cholmod_free_factor(&b->L, &s->cm);
    return ok ? 0 : failed(s, b, "Cholesky factorisation (CHOLMOD)", why);
}

/* Numeric factors of block b's current matrix (its symbolic analysis again
 * when its pattern changed).  Returns 0 or -1 (the cause recorded). */
static int factorise_block(struct sparse_direct *s, struct block *b)
{
    const struct csr_matrix *A = &b->cur;
    if (s->symmetric) {
        if ((b->fresh || !b->L) && analyse_permuted(s, b) != 0)
            return -1;
        if (!b->B && !(b->B = suitesparse.cholmod_zeros((size_t)b->n, 1, CHOLMOD_REAL, &s->cm)))
            return failed(s, b, "Cholesky factorisation (CHOLMOD)", "out of memory");
        const long nz = csr_nnz(A);
        for (long e = 0; e < nz; e++)
            b->permuted.val[b->slot[e]] = A->val[e];
        cholmod_sparse v = cholmod_view(&b->permuted);
        struct suitesparse_serial serial = suitesparse_serial_begin();
        int okf = suitesparse.cholmod_factorize(&v, b->L, &s->cm);
        suitesparse_serial_end(serial);
        if (!okf || s->cm.status != CHOLMOD_OK)
            return failed(s, b, "Cholesky factorisation (CHOLMOD)",
                          suitesparse_cholmod_text(okf ? s->cm.status : CHOLMOD_INVALID));
    } else {
        double control[UMFPACK_CONTROL];
        suitesparse_umfpack_control(control);
        if (b->fresh || !b->symbolic) {
            if (b->symbolic)
                suitesparse.umfpack_di_free_symbolic(&b->symbolic);
            int status = suitesparse.umfpack_di_symbolic(A->n, A->n, A->rowptr, A->col, A->val,
                                                         &b->symbolic, control, NULL);
            if (status != UMFPACK_OK)
                return failed(s, b, "LU factorisation (UMFPACK)", suitesparse_umfpack_text(status));
        }
        if (b->numeric)
            suitesparse.umfpack_di_free_numeric(&b->numeric);
        int status = suitesparse.umfpack_di_numeric(A->rowptr, A->col, A->val, b->symbolic,
                                                    &b->numeric, control, NULL);
        if (status != UMFPACK_OK)
            return failed(s, b, "LU factorisation (UMFPACK)", suitesparse_umfpack_text(status));
    }
    b->fresh = 0;
    b->factorised = 1;
    return 0;
}

/* Block b's part of the unknowns' vector v (all unknowns by component) is
 * at v + (its offset in the blocks' order); copied between the two orders. */
static void to_blocks(const struct sparse_direct *s, const double *v, double *out, int back)
{
    long at = 0;
    for (int k = 0; k < s->nblocks; k++)
        for (int q = 0; q < s->blk[k].ncomp; q++) {
            int c = s->blk[k].comp[q];
            size_t len = (size_t)(s->first[c + 1] - s->first[c]);
            if (back)
                memcpy(out + s->first[c], v + at, len * sizeof(double));
            else
                memcpy(out + at, v + s->first[c], len * sizeof(double));
            at += (long)len;
        }
}

static int reaches(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] != 0.0)
            return 1;
    return 0;
}

int sparse_direct_prepare(struct sparse_direct *s, double *const r[3], double negligible)
{
    probe_matrix_gather(s->pm, r, s->sol);
    to_blocks(s, s->sol, s->rhs, 0);
    long at = 0;
    for (int k = 0; k < s->nblocks; k++) {
        struct block *b = &s->blk[k];
        b->dropped = s->nblocks > 1 && csr_vector_norm(s->rhs + at, b->n) <= negligible;
        if (!b->dropped && !b->factorised && reaches(s->rhs + at, b->n) &&
            factorise_block(s, b) != 0)
            return -1;
        at += b->n;
    }
    return 0;
}

int sparse_direct_dropped(const struct sparse_direct *s)
{
    int n = 0;
    for (int k = 0; k < s->nblocks; k++)
        n += s->blk[k].dropped;
    return n;
}

int sparse_direct_dropped_components(const struct sparse_direct *s)
{
    int m = 0;
    for (int k = 0; k < s->nblocks; k++)
        for (int q = 0; s->blk[k].dropped && q < s->blk[k].ncomp; q++)
            m |= 1 << s->blk[k].comp[q];
    return m;
}

void sparse_direct_solve(struct sparse_direct *s, double *const r[3], double *z[3])
{
    probe_matrix_gather(s->pm, r, s->sol);
    to_blocks(s, s->sol, s->rhs, 0);
    long at = 0;
    for (int k = 0; k < s->nblocks; k++) {
        struct block *b = &s->blk[k];
        double *rb = s->rhs + at, *xb = s->sol + at;
        at += b->n;
        if (b->dropped || (!b->factorised && (!reaches(rb, b->n) || factorise_block(s, b) != 0))) {
            /* left out, or no right-hand side has reached it (or its
             * factorisation failed: the Krylov method then does not
             * converge) */
            memset(xb, 0, (size_t)b->n * sizeof(double));
            continue;
        }
        if (s->symmetric) {
            double *in = b->B->x; /* in P A P''s order */
            for (int k = 0; k < b->n; k++)
                in[k] = rb[b->order[k]];
            struct suitesparse_serial serial = suitesparse_serial_begin();
            suitesparse.cholmod_solve2(CHOLMOD_A, b->L, b->B, NULL, &b->X, NULL, &b->Y, &b->E,
                                       &s->cm);
            suitesparse_serial_end(serial);
            const double *out = b->X->x;
            for (int k = 0; k < b->n; k++)
                xb[b->order[k]] = out[k];
        } else {
            const struct csr_matrix *A = &b->cur;
            suitesparse.umfpack_di_solve(UMFPACK_A, A->rowptr, A->col, A->val, xb, rb, b->numeric,
                                         NULL, NULL);
        }
    }
    to_blocks(s, s->sol, s->rhs, 1);
    probe_matrix_scatter(s->pm, s->rhs, z);
}

struct probe_matrix *sparse_direct_probe_matrix(struct sparse_direct *s) { return s->pm; }

double sparse_fill_bytes(long unknowns, int dims, double c)
{
    /* the n log n fill of nested dissection on a 2D grid; in 3D it grows
     * like n^(4/3) (not measured: the same constant times n^(1/3)) */
    double n = (double)(unknowns > 2 ? unknowns : 2);
    double per = c * log2(n);
    if (dims >= 3)
        per = c * cbrt(n) * 8.0;
    return n * per;
}

double sparse_direct_memory_estimate(long unknowns, int dims)
{
    /* about 100 log2(n) bytes an unknown: the peak less the fields of
     * UMFPACK's LU of the full tangent on the Bingham cavity
     * (docs/numerics/memory-estimate.md) */
    return sparse_fill_bytes(unknowns, dims, 100.0);
}
