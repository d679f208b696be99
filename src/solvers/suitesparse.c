/* CHOLMOD and UMFPACK opened on first use (see suitesparse.h). */
#include "solvers/suitesparse.h"
#include "solvers/blas.h"
#include "solvers/dynlib.h"
#include "solvers/gomp_inline.h"

#include <omp.h>
#include <limits.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The Makefile passes the libraries' sonames; these are Debian's. */
#ifndef MUFLOW_CHOLMOD_LIB
#define MUFLOW_CHOLMOD_LIB "libcholmod.so.3"
#endif
#ifndef MUFLOW_UMFPACK_LIB
#define MUFLOW_UMFPACK_LIB "libumfpack.so.5"
#endif

struct suitesparse_api suitesparse;
static int loaded;

static void *open_library(const char *name, char *err, size_t errlen)
{
    void *lib = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char *why = dlerror();
        snprintf(err, errlen,
                 "sparse factorisation needs SuiteSparse's %s (Debian: libsuitesparse-dev): %s",
                 name, why ? why : "not found");
    }
    return lib;
}

struct suitesparse_serial suitesparse_serial_begin(void)
{
    struct suitesparse_serial saved = {omp_get_max_active_levels(), omp_get_max_threads()};
    omp_set_max_active_levels(0); /* every parallel region inactive: one thread */
    /* and a threaded BLAS asked for its threads is told one (OpenBLAS's
     * OpenMP build forks its own team of omp_get_max_threads() and waits
     * for the members an inactive region never starts: blas.h) */
    omp_set_num_threads(1);
    gomp_inline_enter(); /* and no team at all for CHOLMOD's regions */
    return saved;
}

void suitesparse_serial_end(struct suitesparse_serial saved)
{
    gomp_inline_leave();
    omp_set_num_threads(saved.threads);
    omp_set_max_active_levels(saved.levels);
}

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

int suitesparse_load(char *err, size_t errlen)
{
    if (loaded)
        return 0;
    blas_prepare();
    void *cholmod = open_library(MUFLOW_CHOLMOD_LIB, err, errlen);
    if (!cholmod)
        return -1;
    void *umfpack = open_library(MUFLOW_UMFPACK_LIB, err, errlen);
    if (!umfpack) {
        dlclose(cholmod);
        return -1;
    }
    struct suitesparse_api api;
    const char *missing = NULL;
#define RESOLVE_CHOLMOD(f) DYNLIB_RESOLVE(cholmod, api, f, missing)
#define RESOLVE_UMFPACK(f) DYNLIB_RESOLVE(umfpack, api, f, missing)
    SUITESPARSE_CHOLMOD_FUNCTIONS(RESOLVE_CHOLMOD)
    SUITESPARSE_UMFPACK_FUNCTIONS(RESOLVE_UMFPACK)
#undef RESOLVE_CHOLMOD
#undef RESOLVE_UMFPACK
    if (missing) {
        snprintf(err, errlen, "sparse factorisation: SuiteSparse's libraries lack %s", missing);
        dlclose(umfpack);
        dlclose(cholmod);
        return -1;
    }
    suitesparse = api; /* the libraries stay open for the rest of the run */
    loaded = 1;
    return 0;
}
