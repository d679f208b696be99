/* CHOLMOD's regions on the calling thread, without a team
 * (platform/suitesparse_serial.h). */
#include "platform/suitesparse_serial.h"
#include "platform/gomp_inline.h"

#include <omp.h>

struct suitesparse_serial suitesparse_serial_begin(void)
{
    struct suitesparse_serial saved = {omp_get_max_active_levels(), omp_get_max_threads()};
    omp_set_max_active_levels(0); /* every parallel region inactive: one thread */
    /* and a threaded BLAS asked for its threads is told one (OpenBLAS's
     * OpenMP build forks its own team of omp_get_max_threads() and waits
     * for the members an inactive region never starts: platform/blas.h) */
    omp_set_num_threads(1);
    gomp_inline_enter(); /* and no team at all for CHOLMOD's regions */
    return saved;
}

void suitesparse_serial_end(struct suitesparse_serial saved)
{
    gomp_inline_leave();
    omp_set_num_threads(saved.threads);
    omp_set_max_active_levels(saved.levels);
}
