/* CHOLMOD on the calling thread: Debian's CHOLMOD opens a parallel region
 * per supernode, whose forks and joins cost more than their loops, and a
 * threaded BLAS would fork a team of its own inside
 * (docs/numerics/threads-and-platform.md). */
#ifndef MUFLOW_PLATFORM_SUITESPARSE_SERIAL_H
#define MUFLOW_PLATFORM_SUITESPARSE_SERIAL_H

/* Between begin and end, CHOLMOD's own OpenMP loops run on the calling
 * thread (inline: platform/gomp_inline.h) and a threaded BLAS is told one
 * thread.  The dense work is BLAS's either way.  begin returns what end
 * restores. */
struct suitesparse_serial {
    int levels;  /* omp_get_max_active_levels() before */
    int threads; /* omp_get_max_threads() before */
};
struct suitesparse_serial suitesparse_serial_begin(void);
void suitesparse_serial_end(struct suitesparse_serial saved);

#endif
