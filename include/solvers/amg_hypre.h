/* Algebraic multigrid (hypre's BoomerAMG) on a probed matrix, as a
 * preconditioner: one V-cycle from zero per application.
 *
 * The matrix comes from probe_matrix.h (compressed rows); BoomerAMG is set
 * up on it afresh at each amg_hypre_setup.  Serial: hypre runs on one MPI
 * rank (MPI_COMM_SELF); MPI is initialised on first use if the program did
 * not (and finalised at exit).  This file and amg_hypre.c are the only
 * places that know about hypre or MPI.  The program does not link them:
 * hypre's shared library (and with it OpenMPI) is opened on first use
 * (dlopen), so runs without the AMG do not pay for loading them. */
#ifndef MUFLOW_AMG_HYPRE_H
#define MUFLOW_AMG_HYPRE_H

#include <stddef.h>
#include "solvers/probe_matrix.h"

/* BoomerAMG settings (hypre's numeric codes, named in amg_options_parse). */
struct amg_options {
    int coarsen;        /* 10 HMIS, 8 PMIS, 6 Falgout */
    int interp;         /* 6 ext+i, 0 classical, 13 FF1, 14 extended */
    double theta;       /* strong threshold */
    int relax;          /* 8 l1 symmetric Gauss-Seidel, 6 hybrid symmetric GS,
                           3 hybrid GS (forward down, backward up), 18 l1 Jacobi */
    int sweeps;         /* smoothing sweeps per level after the coarse
                           correction (and on the coarsest level) */
    int pre_sweeps;     /* before the restriction: 0, a V(0,1) cycle, by
                           default (less time than V(1,1) on the heap's
                           steady solves: docs/numerics/multigrid.md) */
    int systems;        /* 1: the three velocity components coarsened and
                           interpolated apart (unknown-based systems AMG) */
    int agg_levels;     /* levels of aggressive coarsening */
    int pmax;           /* interpolation entries per row (0: no limit) */
    double max_row_sum; /* weak-coupling row-sum test (1: off) */
    int print;          /* hypre's setup statistics on stdout */
};

/* HMIS, ext+i (4 entries per row), theta 0.5, l1 symmetric Gauss-Seidel,
 * one sweep after the coarse correction and none before, systems on. */
void amg_options_default(struct amg_options *o);

/* Overrides from a comma-separated list of key=value: coarsen=hmis|pmis|
 * falgout|N, interp=ext+i|classical|ff1|ext|N, theta=X, relax=l1gs|hgs|hsgs|
 * l1jacobi|N, sweeps=N, pre=N, systems=0|1, agg=N, pmax=N, rowsum=X, print=0|1.
 * Returns 0, or -1 with a message for an unknown key or value. */
int amg_options_parse(struct amg_options *o, const char *spec, char *err, size_t errlen);

/* "HMIS ext+i(4) theta 0.5 l1gs V(0,1) systems" */
void amg_options_describe(const struct amg_options *o, char *buf, size_t len);

struct amg_hypre;

/* Opens hypre's library if not yet open: 1 when it is there, else 0 with a
 * one-line message naming solver.preconditioner = amg.  (The environment
 * variable MUFLOW_HYPRE_LIB names another file to open.) */
int amg_hypre_available(char *err, size_t errlen);

/* For n unknowns; dof_func[k] the velocity component of unknown k (copied,
 * used with systems).  Returns 0, or -1 with a message (a missing library:
 * amg_hypre_available's). */
int amg_hypre_create(struct amg_hypre **out, int n, const int *dof_func,
                     const struct amg_options *o, char *err, size_t errlen);
void amg_hypre_destroy(struct amg_hypre *a);

/* Takes A for the multigrid, copied into hypre's matrix and then released
 * (csr_free: the peak memory holds one copy less); the hierarchies are
 * built when a right-hand side first reaches their blocks
 * (amg_hypre_prepare, or amg_hypre_apply).  Returns 0, or -1 when hypre
 * reports an error. */
int amg_hypre_setup(struct amg_hypre *a, struct csr_matrix *A);

/* Builds the hierarchies of the blocks that b reaches and that are not
 * built yet: call it with the right-hand side before a Krylov solve.  Of two
 * or more blocks, one whose part of b has a norm of at most negligible
 * (< 0: none) is left out: amg_hypre_apply gives it 0 until the next
 * prepare (a flow along one direction: the components across it carry only
 * the state's round-off).  Returns 0, or -1 when hypre reports an error. */
int amg_hypre_prepare(struct amg_hypre *a, const double *b, double negligible);

/* Frees the last hierarchy and hypre's copy of its matrix (amg_hypre_setup
 * builds new ones): before the next matrix is probed, so that the two are
 * never held at once. */
void amg_hypre_release(struct amg_hypre *a);

/* x = one V-cycle applied to b (from x = 0); a block left out by the last
 * amg_hypre_prepare, or whose set-up failed, gives 0, and one that b
 * reaches for the first time is built first. */
void amg_hypre_apply(struct amg_hypre *a, const double *b, double *x);

/* Diagonal blocks of the last set-up's matrix, each its own hierarchy: runs
 * of velocity components that no entry above round-off (1e-12 of the
 * diagonals) couples to the others, 1 to 3.  Their set-ups and V-cycles run
 * side by side on the OpenMP threads, one a block (hypre has no threads of
 * its own); the Krylov method keeps the whole operator. */
int amg_hypre_blocks(const struct amg_hypre *a);

/* Blocks the last amg_hypre_prepare left out, and their components (bit
 * c). */
int amg_hypre_dropped(const struct amg_hypre *a);
int amg_hypre_dropped_components(const struct amg_hypre *a);

/* Bytes hypre takes for a hierarchy of this many unknowns (with the default
 * options, the full tangent on a 2D grid), its library and MPI included: a
 * model fitted to measured peaks for the run's memory estimate
 * (docs/numerics/memory-estimate.md). */
double amg_hypre_memory_estimate(long unknowns);

/* Levels and operator complexity (sum of the levels' entries over A's) of the
 * hierarchies built since the last setup. */
int amg_hypre_levels(const struct amg_hypre *a);
double amg_hypre_complexity(const struct amg_hypre *a);

#endif
