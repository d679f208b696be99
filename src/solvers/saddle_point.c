/* The coupled step's saddle-point solver (saddle_point.h).  UMFPACK takes
 * compressed columns; K's compressed rows are the columns of K^T, so K^T is
 * factorised and solved transposed (UMFPACK_At), which is K x = b.
 *
 * It calls UMFPACK's 64-bit-index interface (umfpack_dl_*): with 32-bit
 * indices the numeric factorisation of the granular cylinder at D/32
 * (1,227,840 unknowns, peak estimate 8.7 GB) stopped as out of memory,
 * since its workspace is counted in 32-bit units.  The pattern's copy the
 * solver keeps anyway (to see when K's pattern changes) is made in the
 * 64-bit indices that interface reads. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/saddle_point.h"
#include "solvers/sparse_direct.h"
#include "solvers/suitesparse.h"

struct saddle_point {
    void *symbolic, *numeric;
    double peak_bytes; /* the symbolic analysis's estimate of the numeric peak */
    /* the rows and columns the symbolic analysis is of, in UMFPACK's
       64-bit indices (no values) */
    long n;
    SuiteSparse_long *rowptr, *col;
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
        suitesparse.umfpack_dl_free_numeric(&s->numeric);
    s->numeric = NULL;
}

static void free_symbolic(struct saddle_point *s)
{
    if (s->symbolic)
        suitesparse.umfpack_dl_free_symbolic(&s->symbolic);
    s->symbolic = NULL;
    free(s->rowptr);
    free(s->col);
    s->rowptr = s->col = NULL;
    s->n = 0;
}

void saddle_point_destroy(struct saddle_point *s)
{
    if (!s)
        return;
    free_numeric(s);
    free_symbolic(s);
    free(s);
}

/* Whether K has the pattern the symbolic analysis was made of. */
static int same_pattern(const struct saddle_point *s, const struct csr_matrix *K)
{
    if (!s->symbolic || s->n != K->n)
        return 0;
    for (int r = 0; r <= K->n; r++)
        if (s->rowptr[r] != K->rowptr[r])
            return 0;
    for (long k = 0; k < csr_nnz(K); k++)
        if (s->col[k] != K->col[k])
            return 0;
    return 1;
}

/* The symbolic analysis of K's pattern: UMFPACK's status (out of memory
 * when the pattern's copy cannot be made). */
static int analyse(struct saddle_point *s, const struct csr_matrix *K)
{
    free_symbolic(s);
    size_t nnz = (size_t)csr_nnz(K);
    s->rowptr = malloc(((size_t)K->n + 1) * sizeof *s->rowptr);
    s->col = malloc((nnz > 0 ? nnz : 1) * sizeof *s->col);
    if (!s->rowptr || !s->col) {
        free_symbolic(s);
        return UMFPACK_ERROR_out_of_memory;
    }
    for (int r = 0; r <= K->n; r++)
        s->rowptr[r] = K->rowptr[r];
    for (size_t k = 0; k < nnz; k++)
        s->col[k] = K->col[k];
    s->n = K->n;
    double control[UMFPACK_CONTROL];
    suitesparse_umfpack_control(control);
    double info[UMFPACK_INFO];
    int status = suitesparse.umfpack_dl_symbolic(s->n, s->n, s->rowptr, s->col, K->val,
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
    return saddle_point_solve_many(s, K, 1, &rhs, &x, err, errlen);
}

int saddle_point_solve_many(struct saddle_point *s, const struct csr_matrix *K, int nrhs,
                            const double *const *rhs, double *const *x, char *err, size_t errlen)
{
    int status = same_pattern(s, K) ? UMFPACK_OK : analyse(s, K);
    if (status != UMFPACK_OK) {
        snprintf(err, errlen, "coupled step's LU (UMFPACK), %d unknowns: %s in its analysis",
                 K->n, suitesparse_umfpack_text(status));
        return -1;
    }
    double control[UMFPACK_CONTROL];
    suitesparse_umfpack_control(control);
    status = suitesparse.umfpack_dl_numeric(s->rowptr, s->col, K->val, s->symbolic, &s->numeric,
                                            control, NULL);
    for (int r = 0; r < nrhs && status == UMFPACK_OK; r++)
        status = suitesparse.umfpack_dl_solve(UMFPACK_At, s->rowptr, s->col, K->val, x[r],
                                              rhs[r], s->numeric, NULL, NULL);
    /* the factors serve this solve only: freed before the next step's
     * matrix is probed, so that the two are never held at once */
    free_numeric(s);
    if (status != UMFPACK_OK) {
        snprintf(err, errlen, "coupled step's LU (UMFPACK), %d unknowns: %s, peak memory "
                              "estimate %.1f GB",
                 K->n, suitesparse_umfpack_text(status), s->peak_bytes / 1e9);
        free_symbolic(s); /* analysed afresh next time */
        return -1;
    }
    return 0;
}

double saddle_point_memory_estimate(long unknowns, int dims)
{
    /* about 320 log2(n) bytes an unknown (the coupled LU on the Bingham
     * cavity: docs/numerics/memory-estimate.md), three times the viscous
     * LU's (sparse_direct_memory_estimate): the pressure rows' zero diagonal
     * keeps UMFPACK from the symmetric ordering's fill. */
    return sparse_fill_bytes(unknowns, dims, 320.0);
}

double saddle_point_matrix_estimate(long unknowns, int dims)
{
    /* the matrices without their factors: the probed velocity block, K and
     * its assembly's entries, about 40 entries a row in 2D (the full
     * tangent's stencil and the pressure columns), 70 in 3D, each held
     * three times at 12-16 bytes */
    return (double)unknowns * (dims == 3 ? 70.0 : 40.0) * 40.0;
}
