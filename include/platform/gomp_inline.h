/* Parallel regions run inline on the calling thread: a region of one thread
 * still ends in libgomp's barrier, a system call, and CHOLMOD opens several
 * per supernode (docs/numerics/threads-and-platform.md). */
#ifndef MUFLOW_PLATFORM_GOMP_INLINE_H
#define MUFLOW_PLATFORM_GOMP_INLINE_H

/* muflow's executables define GOMP_parallel, the entry of every `omp
 * parallel` that GCC compiles, and export it (the Makefile's
 * --export-dynamic-symbol), so that the libraries opened later bind to it.
 * Between enter and leave, on the thread that entered, it calls the
 * region's body directly (an orphaned region of one thread: the body's `omp
 * for` loops and barriers are plain loops and no-ops); a region asked for
 * one thread (GCC passes num_threads 1 for a false `if` clause) runs inline
 * everywhere; any other goes to libgomp's.  The depth is per thread: only
 * the regions the entering thread opens run inline.  Calls nest. */
void gomp_inline_enter(void);
void gomp_inline_leave(void);

/* The regions this thread has run inline so far (the tests check that
 * CHOLMOD's reach them: that CHOLMOD binds to the executable's
 * GOMP_parallel and that the one-thread section enters the inline mode). */
long gomp_inline_count(void);

#endif
