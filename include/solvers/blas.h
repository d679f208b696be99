#ifndef MUFLOW_SOLVERS_BLAS_H
#define MUFLOW_SOLVERS_BLAS_H

/* The BLAS under the libraries muflow opens with dlopen (SuiteSparse's
 * CHOLMOD and UMFPACK, hypre).  They name only the soname libblas.so.3 and
 * liblapack.so.3, which Debian's alternatives point to whichever BLAS is
 * installed with the highest priority: OpenBLAS's pthread build (100), its
 * OpenMP build (95) or its serial build (90, the one the Makefile
 * installs).
 *
 * - The OpenMP build deadlocks in CHOLMOD's supernodal factorisation: it
 *   forks its own team inside the calls that suitesparse_serial_begin
 *   keeps on one thread and waits for a second thread that never comes
 *   (the column collapse hung at its first step; OpenBLAS 0.3.21).
 * - The pthread build runs its own threads beside muflow's OpenMP threads
 *   and gains nothing on muflow's supernodes: the column collapse at 102.4
 *   cells per H0, 64 steps on 2 threads, 36.3-40.1 s wall and 48.9-53.4 s
 *   CPU against 37.3-37.9 s and 36.3-36.7 s with the serial build.
 *
 * blas_prepare opens the serial build by its path before those libraries
 * are opened, so that their libblas.so.3 and liblapack.so.3 are that one
 * whatever the alternatives say (the dynamic linker reuses a library
 * already loaded under the soname).  Without the serial build, or with
 * MUFLOW_BLAS=system in the environment, the system's choice stays.  It
 * also names OpenBLAS's kernels for the CPU (OPENBLAS_CORETYPE, below).
 * Call it before opening any library that uses BLAS; later calls return at
 * once. */
void blas_prepare(void);

/* The directory of the serial build blas_prepare opens (Debian's
 * /usr/lib/<multiarch>/openblas-serial, from the Makefile). */
const char *blas_serial_dir(void);

#endif
