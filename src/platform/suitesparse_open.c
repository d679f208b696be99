/* CHOLMOD and UMFPACK opened with dlopen on first use, by the sonames the
 * Makefile finds (platform/suitesparse_open.h). */
#include "platform/suitesparse_open.h"
#include "platform/blas.h"
#include "platform/dynlib.h"

#include <stdio.h>

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
    return dynlib_open(name, RTLD_LOCAL, "sparse factorisation needs SuiteSparse's",
                       "libsuitesparse-dev", err, errlen);
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
