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

struct sparse_direct {
    struct probe_matrix *pm;   /* numbering, colouring and probing */
    int symmetric;
    long n;                    /* unknowns */
    struct csr_matrix rows;    /* the probed matrix by rows (work) */
    struct csr_matrix cur, next; /* by columns: the last factorised one, the new one */
    cholmod_common cm;
    /* symmetric: CHOLMOD */
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E;
    /* general: UMFPACK */
    void *symbolic, *numeric;
    double *rhs, *sol;
    char cause[160];           /* of the last failed factorisation */
};

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

long sparse_direct_unknowns(const struct sparse_direct *s) { return s->n; }

const char *sparse_direct_cause(const struct sparse_direct *s) { return s->cause; }

/* Records why the factorisation failed; returns -1. */
static int failed(struct sparse_direct *s, const char *what, const char *why)
{
    snprintf(s->cause, sizeof s->cause, "the probed %s of %ld unknowns: %s", what, s->n, why);
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
    s->rhs = malloc((size_t)s->n * sizeof(double));
    s->sol = malloc((size_t)s->n * sizeof(double));
    int ok = s->rhs && s->sol;
    suitesparse_cholmod_start(&s->cm);
    s->cm.error_handler = quiet_handler;
    s->cm.print = 0;
    if (ok && symmetric)
        ok = (s->B = suitesparse.cholmod_zeros((size_t)s->n, 1, CHOLMOD_REAL, &s->cm)) != NULL;
    if (!ok) {
        sparse_direct_destroy(s);
        snprintf(err, errlen, "sparse factorisation: out of memory");
        return -1;
    }
    *out = s;
    return 0;
}

void sparse_direct_destroy(struct sparse_direct *s)
{
    if (!s)
        return;
    probe_matrix_destroy(s->pm);
    csr_free(&s->rows);
    csr_free(&s->cur);
    csr_free(&s->next);
    free(s->rhs);
    free(s->sol);
    if (s->symbolic)
        suitesparse.umfpack_di_free_symbolic(&s->symbolic);
    if (s->numeric)
        suitesparse.umfpack_di_free_numeric(&s->numeric);
    suitesparse.cholmod_free_factor(&s->L, &s->cm);
    suitesparse.cholmod_free_dense(&s->B, &s->cm);
    suitesparse.cholmod_free_dense(&s->X, &s->cm);
    suitesparse.cholmod_free_dense(&s->Y, &s->cm);
    suitesparse.cholmod_free_dense(&s->E, &s->cm);
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

int sparse_direct_factor(struct sparse_direct *s, operator_fn op, void *ctx, double *probe[3],
                         double *resp[3])
{
    /* by rows (the lower triangle if symmetric), transposed into columns */
    if (probe_matrix_assemble(s->pm, op, ctx, probe, resp, s->symmetric, &s->rows) != 0)
        return failed(s, "matrix", "out of memory");
    /* the factors of a flow along one direction then hold its component and
     * the two across it apart: the heap at 140 x 200 factorised in half the
     * time and 60 % of the memory, the same steps (docs/design.md); the
     * Krylov method keeps the dropped round-off in the operator */
    csr_drop_component_roundoff(&s->rows, probe_matrix_components(s->pm),
                                COMPONENT_ROUNDOFF);
    if (csr_transpose(&s->rows, &s->next) != 0)
        return failed(s, "matrix", "out of memory");
    int fresh = !csr_same_pattern(&s->next, &s->cur);
    struct csr_matrix t = s->cur;
    s->cur = s->next;
    s->next = t;
    const struct csr_matrix *A = &s->cur;
    if (s->symmetric) {
        cholmod_sparse v = cholmod_view(A);
        if (fresh || !s->L) {
            suitesparse.cholmod_free_factor(&s->L, &s->cm);
            if (!(s->L = suitesparse.cholmod_analyze(&v, &s->cm)))
                return failed(s, "Cholesky factorisation (CHOLMOD)",
                              suitesparse_cholmod_text(s->cm.status));
        }
        int serial = suitesparse_serial_begin();
        int okf = suitesparse.cholmod_factorize(&v, s->L, &s->cm);
        suitesparse_serial_end(serial);
        if (!okf || s->cm.status != CHOLMOD_OK)
            return failed(s, "Cholesky factorisation (CHOLMOD)",
                          suitesparse_cholmod_text(okf ? s->cm.status : CHOLMOD_INVALID));
        return 0;
    }
    double control[UMFPACK_CONTROL];
    suitesparse_umfpack_control(control);
    if (fresh || !s->symbolic) {
        if (s->symbolic)
            suitesparse.umfpack_di_free_symbolic(&s->symbolic);
        int status = suitesparse.umfpack_di_symbolic(A->n, A->n, A->rowptr, A->col, A->val,
                                                     &s->symbolic, control, NULL);
        if (status != UMFPACK_OK)
            return failed(s, "LU factorisation (UMFPACK)", suitesparse_umfpack_text(status));
    }
    if (s->numeric)
        suitesparse.umfpack_di_free_numeric(&s->numeric);
    int status = suitesparse.umfpack_di_numeric(A->rowptr, A->col, A->val, s->symbolic,
                                                &s->numeric, control, NULL);
    if (status != UMFPACK_OK)
        return failed(s, "LU factorisation (UMFPACK)", suitesparse_umfpack_text(status));
    return 0;
}

void sparse_direct_solve(struct sparse_direct *s, double *const r[3], double *z[3])
{
    double *b = s->symmetric ? s->B->x : s->rhs;
    probe_matrix_gather(s->pm, r, b);
    const double *x = s->sol;
    if (s->symmetric) {
        int serial = suitesparse_serial_begin();
        suitesparse.cholmod_solve2(CHOLMOD_A, s->L, s->B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm);
        suitesparse_serial_end(serial);
        x = s->X->x;
    } else {
        const struct csr_matrix *A = &s->cur;
        suitesparse.umfpack_di_solve(UMFPACK_A, A->rowptr, A->col, A->val, s->sol, s->rhs, s->numeric, NULL,
                         NULL);
    }
    probe_matrix_scatter(s->pm, x, z);
}

struct probe_matrix *sparse_direct_probe_matrix(struct sparse_direct *s) { return s->pm; }

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
