/* The coupled step's saddle-point solver (saddle_point.h).  UMFPACK takes
 * compressed columns; K's compressed rows are the columns of K^T, so K^T is
 * factorised and solved transposed (UMFPACK_At), which is K x = b. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/saddle_point.h"
#include "solvers/suitesparse.h"

struct saddle_point {
    void *symbolic, *numeric;
    double peak_bytes; /* the symbolic analysis's estimate of the numeric peak */
    struct csr_matrix pattern; /* the rows and columns the symbolic analysis is of
                                  (no values) */
};

int saddle_point_create(struct saddle_point **out, char *err, size_t errlen)
{
    suitesparse_keep_factor_memory();
    if (suitesparse_load(err, errlen) != 0)
        return -1;
    if (!(*out = calloc(1, sizeof **out))) {
        snprintf(err, errlen, "coupled step: out of memory");
        return -1;
    }
    return 0;
}

static void free_numeric(struct saddle_point *s)
{
    if (s->numeric)
        suitesparse.umfpack_di_free_numeric(&s->numeric);
    s->numeric = NULL;
}

static void free_symbolic(struct saddle_point *s)
{
    if (s->symbolic)
        suitesparse.umfpack_di_free_symbolic(&s->symbolic);
    s->symbolic = NULL;
    csr_free(&s->pattern);
}

void saddle_point_destroy(struct saddle_point *s)
{
    if (!s)
        return;
    free_numeric(s);
    free_symbolic(s);
    free(s);
}

/* UMFPACK's status as words. */
static const char *umfpack_status_text(int status)
{
    switch (status) {
    case UMFPACK_WARNING_singular_matrix:
        return "the matrix is singular";
    case UMFPACK_ERROR_out_of_memory:
        return "out of memory (or beyond its 32-bit indices)";
    case UMFPACK_ERROR_invalid_matrix:
        return "invalid matrix";
    default:
        return "failed";
    }
}

/* The symbolic analysis of K's pattern: UMFPACK's status (out of memory
 * when the pattern's copy cannot be made). */
static int analyse(struct saddle_point *s, const struct csr_matrix *K)
{
    free_symbolic(s);
    size_t nnz = (size_t)csr_nnz(K);
    struct csr_matrix *P = &s->pattern;
    P->rowptr = malloc(((size_t)K->n + 1) * sizeof(int));
    P->col = malloc((nnz > 0 ? nnz : 1) * sizeof(int));
    if (!P->rowptr || !P->col) {
        free_symbolic(s);
        return UMFPACK_ERROR_out_of_memory;
    }
    memcpy(P->rowptr, K->rowptr, ((size_t)K->n + 1) * sizeof(int));
    memcpy(P->col, K->col, nnz * sizeof(int));
    P->n = K->n;
    double control[UMFPACK_CONTROL];
    suitesparse_umfpack_control(control);
    double info[UMFPACK_INFO];
    int status = suitesparse.umfpack_di_symbolic(K->n, K->n, K->rowptr, K->col, K->val,
                                                 &s->symbolic, control, info);
    if (status != UMFPACK_OK) {
        free_symbolic(s);
        return status;
    }
    s->peak_bytes = info[UMFPACK_PEAK_MEMORY_ESTIMATE] * info[UMFPACK_SIZE_OF_UNIT];
    return UMFPACK_OK;
}

int saddle_point_solve(struct saddle_point *s, const struct csr_matrix *K, const double *rhs,
                       double *x, char *err, size_t errlen)
{
    int status = csr_same_pattern(K, &s->pattern) ? UMFPACK_OK : analyse(s, K);
    if (status != UMFPACK_OK) {
        snprintf(err, errlen, "coupled step's LU (UMFPACK), %d unknowns: %s in its analysis",
                 K->n, umfpack_status_text(status));
        return -1;
    }
    double control[UMFPACK_CONTROL];
    suitesparse_umfpack_control(control);
    status = suitesparse.umfpack_di_numeric(K->rowptr, K->col, K->val, s->symbolic, &s->numeric,
                                            control, NULL);
    if (status == UMFPACK_OK)
        status = suitesparse.umfpack_di_solve(UMFPACK_At, K->rowptr, K->col, K->val, x, rhs,
                                              s->numeric, NULL, NULL);
    /* the factors serve this solve only: freed before the next step's
     * matrix is probed, so that the two are never held at once */
    free_numeric(s);
    if (status != UMFPACK_OK) {
        snprintf(err, errlen, "coupled step's LU (UMFPACK), %d unknowns: %s, peak memory "
                              "estimate %.1f GB",
                 K->n, umfpack_status_text(status), s->peak_bytes / 1e9);
        free_symbolic(s); /* analysed afresh next time */
        return -1;
    }
    return 0;
}
