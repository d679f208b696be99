/* muflow's settings for CHOLMOD and UMFPACK (see suitesparse.h). */
#include "solvers/suitesparse.h"

#include <limits.h>
#include <malloc.h>

void suitesparse_umfpack_control(double control[UMFPACK_CONTROL])
{
    suitesparse.umfpack_di_defaults(control);
    control[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
}

void suitesparse_keep_factor_memory(void)
{
#ifdef __GLIBC__
    mallopt(M_TOP_PAD, 256 << 20);
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, INT_MAX);
#endif
}

void suitesparse_cholmod_start(cholmod_common *cm) { suitesparse.cholmod_start(cm); }

const char *suitesparse_umfpack_text(int status)
{
    switch (status) {
    case UMFPACK_WARNING_singular_matrix:
        return "the matrix is singular";
    case UMFPACK_ERROR_out_of_memory:
        return "out of memory";
    case UMFPACK_ERROR_invalid_matrix:
        return "invalid matrix";
    default:
        return "failed";
    }
}

const char *suitesparse_cholmod_text(int status)
{
    switch (status) {
    case CHOLMOD_NOT_POSDEF:
        return "the matrix is not positive definite";
    case CHOLMOD_OUT_OF_MEMORY:
        return "out of memory";
    case CHOLMOD_TOO_LARGE:
        return "the problem is too large";
    case CHOLMOD_INVALID:
        return "invalid matrix";
    default:
        return "failed";
    }
}
