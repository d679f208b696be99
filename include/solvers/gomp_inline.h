#ifndef MUFLOW_SOLVERS_GOMP_INLINE_H
#define MUFLOW_SOLVERS_GOMP_INLINE_H

/* Parallel regions run inline on the calling thread between enter and leave.
 *
 * CHOLMOD (Debian's, built with GCC's OpenMP) opens parallel regions in its
 * supernodal factorisation, several per supernode, and muflow runs it on one
 * thread (suitesparse_serial_begin: its loops are too short to share).  An
 * inactive region still costs libgomp a team and a barrier whose release is
 * a futex system call, microseconds in a virtual machine: 201,794 futex
 * calls in the first 100 steps of the column collapse at 25.6 cells per H0,
 * 2,000 a step.  muflow's executables define GOMP_parallel, the entry of
 * every `omp parallel` that GCC compiles, and export it (the Makefile's
 * --export-dynamic-symbol), so that the libraries opened later bind to it:
 * between enter and leave, on the thread that entered, it calls the
 * region's body directly (an orphaned region of one thread: the body's
 * `omp for` loops and barriers are plain loops and no-ops, as in multigrid.c's
 * REGION); elsewhere it passes the call to libgomp's.  The same run then
 * makes 25,694 futex calls (docs/design.md, "The sparse factorisations'
 * ordering and BLAS").
 *
 * The depth is per thread: only the regions the entering thread opens run
 * inline.  Calls nest.
 *
 * A region asked for one thread (GCC passes num_threads 1 for a false `if`
 * clause: the kernels' `if (kernel_parallel(g))` on small grids) runs inline
 * everywhere: the same 100 steps then make one futex call instead of
 * 25,694. */
void gomp_inline_enter(void);
void gomp_inline_leave(void);

/* The regions this thread has run inline so far (the tests check that
 * CHOLMOD's reach them: that CHOLMOD binds to the executable's
 * GOMP_parallel and that the one-thread section enters the inline mode). */
long gomp_inline_count(void);

#endif
