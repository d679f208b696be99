/* Debian's serial OpenBLAS under the libraries muflow opens, its kernels
 * named for the CPU (platform/blas.h). */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "platform/blas.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

/* The Makefile passes the multiarch directory of Debian's serial OpenBLAS. */
#ifndef MUFLOW_SERIAL_BLAS_DIR
#define MUFLOW_SERIAL_BLAS_DIR "/usr/lib/x86_64-linux-gnu/openblas-serial"
#endif

static int prepared;

/* OpenBLAS picks its kernels from the CPU's model number and falls back to
 * its oldest x86-64 kernels (Prescott, SSE3) for a model it does not know,
 * as version 0.3.21 does for virtual machines' "Intel Xeon Processor".
 * Naming the core from the CPU's features gives the factorisations' dense
 * blocks the AVX kernels.  A core the user names (OPENBLAS_CORETYPE) is
 * kept; other BLAS ignore the variable.  It must be set before the library
 * is loaded: OpenBLAS reads it once. */
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

/* OpenBLAS itself first (its soname libopenblas.so.0, which the two
 * interface libraries need and would otherwise take from LD_LIBRARY_PATH
 * before their own directory), then both interfaces or neither: a serial
 * BLAS under the system's LAPACK would bring the threaded build back
 * through LAPACK's own dependency.  The handles stay open for the rest of
 * the run. */
static void open_serial_build(void)
{
    const char *choice = getenv("MUFLOW_BLAS");
    if (choice && strcmp(choice, "system") == 0)
        return;
    void *openblas = dlopen(MUFLOW_SERIAL_BLAS_DIR "/libopenblas.so.0", RTLD_NOW | RTLD_GLOBAL);
    if (!openblas)
        return;
    void *blas = dlopen(MUFLOW_SERIAL_BLAS_DIR "/libblas.so.3", RTLD_NOW | RTLD_GLOBAL);
    void *lapack = blas ? dlopen(MUFLOW_SERIAL_BLAS_DIR "/liblapack.so.3", RTLD_NOW | RTLD_GLOBAL)
                        : NULL;
    if (!lapack) {
        if (blas)
            dlclose(blas);
        dlclose(openblas);
    }
}

void blas_prepare(void)
{
    if (prepared)
        return;
    prepared = 1;
    name_blas_core();
    open_serial_build();
}

const char *blas_serial_dir(void)
{
    return MUFLOW_SERIAL_BLAS_DIR;
}
