/* SuiteSparse's CHOLMOD and UMFPACK, opened on first use.
 *
 * The sparse factorisations (sparse_direct.c, the multigrid's coarsest
 * level) are the only users.  Linking them would make every run pay for
 * loading them and their BLAS/LAPACK (over half of the dynamic loader's
 * relocations, a third of a small case's whole-process time), so the
 * program opens the libraries with dlopen when the first factorisation is
 * created and calls through the table below. */
#ifndef MUFLOW_SUITESPARSE_H
#define MUFLOW_SUITESPARSE_H

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

/* UMFPACK's controls for muflow's matrices: its defaults, with the METIS
 * ordering instead of AMD/COLAMD.  On the coupled step's saddle-point
 * matrix of the granular cylinder (40 x 120 cells, 19,080 unknowns) METIS
 * halves the factorisation's flops (7.2e8 against 1.6e9) and its time
 * (docs/design.md, "The sparse factorisations' ordering and BLAS"). */
void suitesparse_umfpack_control(double control[UMFPACK_CONTROL]);

/* glibc's heap keeps the factorisations' memory for the next one.
 * UMFPACK and CHOLMOD allocate and free their factors at every
 * factorisation; glibc maps any block above its mmap threshold (at most
 * 32 MB) afresh, and the kernel faults in and zero-fills its pages each
 * time.  A top pad of 256 MB kept the smaller blocks (a third of a Newton
 * step on a 70 x 100 cross-section); with no mmap and no trim the larger
 * ones stay too: the LU's whole solve of the heap at 140 x 200 took 107 s,
 * 27 of them in the kernel, and now 60 s, its peak 557 -> 533 MB (1 thread;
 * docs/design.md, "The factors' memory").  Called by the LU, Cholesky and
 * coupled solvers; the AMG keeps its own setting (amg_hypre.c). */
void suitesparse_keep_factor_memory(void);

/* cholmod_start with muflow's settings, which are CHOLMOD's defaults.  The
 * supernodes were once amalgamated more (nrelax 32, 96, 256 columns and
 * zrelax 0.9, 0.2, 0.1 instead of 4, 16, 48 and 0.8, 0.1, 0.05): each
 * supernode cost five OpenMP regions, whose joins were system calls.  Since
 * the regions of a one-thread section run inline (gomp_inline.c) the
 * defaults' fewer flops win: the column collapse's implicit solves at 128 x
 * 40 cells took 2.10-2.20 s instead of 2.89-2.94 s to t = 4, at 256 x 80
 * 3.32 s instead of 4.63 s to t = 1, and the heap's steady solve at 70 x 100
 * (cholesky) 4.3-4.4 s instead of 5.6-5.7 s, peak memory 50 instead of
 * 64 MB (2 threads; docs/design.md, "The sparse factorisations' ordering
 * and BLAS"). */
void suitesparse_cholmod_start(cholmod_common *cm);

/* CHOLMOD's own OpenMP loops run on the calling thread between these two:
 * Debian's CHOLMOD opens a parallel region per supernode (some 5,000 per
 * factorisation of a 160 x 48 cross-section), and their forks and joins
 * cost more than the loops (bench/analysis.md, "CHOLMOD's OpenMP loops").
 * The dense work is BLAS's either way; a threaded BLAS is told one thread
 * too.  Returns what _end restores. */
struct suitesparse_serial {
    int levels;  /* omp_get_max_active_levels() before */
    int threads; /* omp_get_max_threads() before */
};
struct suitesparse_serial suitesparse_serial_begin(void);
void suitesparse_serial_end(struct suitesparse_serial saved);

/* Opens the libraries (once; later calls return at once).  Returns 0, or -1
 * with the library or symbol that is missing in err. */
int suitesparse_load(char *err, size_t errlen);

/* A failed factorisation's status as words (UMFPACK's return value,
 * CHOLMOD's cholmod_common status). */
const char *suitesparse_umfpack_text(int status);
const char *suitesparse_cholmod_text(int status);

#endif
