/* CHOLMOD and UMFPACK opened on first use (see suitesparse.h). */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "solvers/suitesparse.h"
#include "solvers/dynlib.h"

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

int suitesparse_serial_begin(void)
{
    int saved = omp_get_max_active_levels();
    omp_set_max_active_levels(0); /* every parallel region inactive: one thread */
    return saved;
}

void suitesparse_serial_end(int saved)
{
    omp_set_max_active_levels(saved);
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

void suitesparse_cholmod_start(cholmod_common *cm)
{
    suitesparse.cholmod_start(cm);
    const size_t nrelax[3] = {32, 96, 256};
    const double zrelax[3] = {0.9, 0.2, 0.1};
    for (int k = 0; k < 3; k++) {
        cm->nrelax[k] = nrelax[k];
        cm->zrelax[k] = zrelax[k];
    }
}

/* OpenBLAS (the BLAS under SuiteSparse on Debian) picks its kernels from the
 * CPU's model number and falls back to its oldest x86-64 kernels (Prescott,
 * SSE3) for a model it does not know, as version 0.3.21 does for virtual
 * machines' "Intel Xeon Processor".  Naming the core from the CPU's
 * features gives the factorisations' dense blocks the AVX kernels: the
 * coupled step's factorisation takes 0.26 s instead of 0.34 s.  A core the
 * user names (OPENBLAS_CORETYPE) is kept; other BLAS ignore the variable.
 * It must be set before the library is loaded: OpenBLAS reads it once. */
static void name_blas_core(void)
{
    if (getenv("OPENBLAS_CORETYPE"))
        return;
#if defined(__x86_64__) && defined(__GNUC__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
        setenv("OPENBLAS_CORETYPE", "SkylakeX", 0);
    else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        setenv("OPENBLAS_CORETYPE", "Haswell", 0);
#endif
}

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
    name_blas_core();
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
