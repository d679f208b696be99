/* SuiteSparse's CHOLMOD and UMFPACK, opened on first use: linked, every run
 * would pay for loading them and their BLAS, LAPACK and METIS
 * (docs/numerics/threads-and-platform.md).  The program opens them with
 * dlopen when the first factorisation is created and calls through the
 * table below. */
#ifndef MUFLOW_PLATFORM_SUITESPARSE_OPEN_H
#define MUFLOW_PLATFORM_SUITESPARSE_OPEN_H

#include <stddef.h>
#include <cholmod.h>
#include <umfpack.h>

#define SUITESPARSE_CHOLMOD_FUNCTIONS(X)                                                          \
    X(cholmod_start) X(cholmod_finish) X(cholmod_allocate_triplet) X(cholmod_free_triplet)        \
    X(cholmod_triplet_to_sparse) X(cholmod_free_sparse) X(cholmod_analyze) X(cholmod_factorize)   \
    X(cholmod_free_factor) X(cholmod_zeros) X(cholmod_free_dense) X(cholmod_solve2)
#define SUITESPARSE_UMFPACK_FUNCTIONS(X)                                                          \
    X(umfpack_di_symbolic) X(umfpack_di_numeric) X(umfpack_di_solve)                              \
    X(umfpack_di_free_symbolic) X(umfpack_di_free_numeric) X(umfpack_di_defaults)                \
    X(umfpack_dl_symbolic) X(umfpack_dl_numeric) X(umfpack_dl_solve)                              \
    X(umfpack_dl_free_symbolic) X(umfpack_dl_free_numeric)

struct suitesparse_api {
#define SUITESPARSE_POINTER(f) __typeof__(f) *f;
    SUITESPARSE_CHOLMOD_FUNCTIONS(SUITESPARSE_POINTER)
    SUITESPARSE_UMFPACK_FUNCTIONS(SUITESPARSE_POINTER)
#undef SUITESPARSE_POINTER
};

/* The functions, valid once suitesparse_load has returned 0. */
extern struct suitesparse_api suitesparse;

/* Opens the libraries (once; later calls return at once).  Returns 0, or -1
 * with the library or symbol that is missing in err. */
int suitesparse_load(char *err, size_t errlen);

#endif
