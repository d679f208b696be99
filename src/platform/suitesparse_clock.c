/* SuiteSparse's clock, stopped: CHOLMOD reads it around every BLAS call of
 * its supernodal factorisation for timing statistics muflow never reads.
 * The program exports this SuiteSparse_time (the Makefile), which CHOLMOD's
 * calls find before libsuitesparseconfig's; the statistics read 0 and
 * nothing else in the libraries muflow opens depends on the clock. */
#include <SuiteSparse_config.h>

double SuiteSparse_time(void)
{
    return 0.0;
}
