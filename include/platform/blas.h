/* The BLAS under the libraries muflow opens with dlopen (CHOLMOD, UMFPACK,
 * hypre): they name only libblas.so.3 and liblapack.so.3, which Debian's
 * alternatives may point to OpenBLAS's OpenMP build (it deadlocks in
 * CHOLMOD's one-thread section) or its pthread build (its threads compete
 * with muflow's for no speed): docs/numerics/threads-and-platform.md. */
#ifndef MUFLOW_PLATFORM_BLAS_H
#define MUFLOW_PLATFORM_BLAS_H

/* Opens Debian's serial OpenBLAS by its path before those libraries are
 * opened, so that their libblas.so.3 and liblapack.so.3 are that one
 * whatever the alternatives say (the dynamic linker reuses a library
 * already loaded under the soname).  Without the serial build, or with
 * MUFLOW_BLAS=system in the environment, the system's choice stays.  It
 * also names OpenBLAS's kernels for the CPU (OPENBLAS_CORETYPE, blas.c).
 * Call it before opening any library that uses BLAS; later calls return at
 * once. */
void blas_prepare(void);

/* The directory of the serial build blas_prepare opens (Debian's
 * /usr/lib/<multiarch>/openblas-serial, from the Makefile). */
const char *blas_serial_dir(void);

#endif
