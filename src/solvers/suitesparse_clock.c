/* SuiteSparse's clock, stopped.
 *
 * Debian's CHOLMOD (SuiteSparse 5.12) reads the clock around every BLAS
 * call of its supernodal factorisation, for timing statistics in its
 * common block that muflow never reads: SuiteSparse_time, a
 * clock_gettime each, was 3.5 % of the main thread's time in the column
 * collapse at 25.6 and at 51.2 cells per H0 (perf, 2 threads).  The
 * program exports this SuiteSparse_time (the Makefile's
 * --export-dynamic-symbol), which CHOLMOD's calls find before
 * libsuitesparseconfig's, and it returns 0: the statistics read 0, and
 * nothing else in the libraries muflow opens depends on the clock
 * (test_one_thread_section, group viscous; docs/design.md, "The sparse
 * factorisations' ordering and BLAS"). */
#include <SuiteSparse_config.h>

double SuiteSparse_time(void)
{
    return 0.0;
}
