/* SuiteSparse's CHOLMOD and UMFPACK as muflow's sparse factorisations
 * (sparse_direct.c, the multigrid's coarsest level, the coupled solvers)
 * use them: the libraries opened on first use and run on one thread
 * (platform/), and muflow's settings for them (docs/numerics/
 * threads-and-platform.md, "The sparse factorisations' libraries"). */
#ifndef MUFLOW_SUITESPARSE_H
#define MUFLOW_SUITESPARSE_H

#include "platform/suitesparse_open.h"
#include "platform/suitesparse_serial.h"

/* UMFPACK's controls for muflow's matrices: its defaults, with the METIS
 * ordering instead of AMD/COLAMD (half the flops on the coupled step's
 * saddle-point matrices). */
void suitesparse_umfpack_control(double control[UMFPACK_CONTROL]);

/* glibc's heap keeps the factorisations' memory for the next one.
 * UMFPACK and CHOLMOD allocate and free their factors at every
 * factorisation; glibc maps any block above its mmap threshold afresh, and
 * the kernel faults in and zero-fills its pages each time.  A top pad of
 * 256 MB keeps the smaller blocks, and with no mmap and no trim the larger
 * ones stay too.  Called by the LU, Cholesky and coupled solvers; the AMG
 * keeps its own setting (amg_hypre.c). */
void suitesparse_keep_factor_memory(void);

/* cholmod_start with muflow's settings, which are CHOLMOD's defaults: with
 * its regions inline (platform/gomp_inline.h) the defaults' supernodes were
 * the fastest measured (docs/numerics/threads-and-platform.md). */
void suitesparse_cholmod_start(cholmod_common *cm);

/* A failed factorisation's status as words (UMFPACK's return value,
 * CHOLMOD's cholmod_common status). */
const char *suitesparse_umfpack_text(int status);
const char *suitesparse_cholmod_text(int status);

#endif
