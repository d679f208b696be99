/* muflow's own GOMP_parallel: regions of one thread run inline instead of
 * paying libgomp's barrier (platform/gomp_inline.h). */
#define _GNU_SOURCE /* RTLD_NEXT */
#include "platform/gomp_inline.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

typedef void (*region_body)(void *);
typedef void (*gomp_parallel_entry)(region_body, void *, unsigned, unsigned);

/* GOMP_parallel is libgomp's ABI (GCC 4.9 and later): GCC compiles
 * `#pragma omp parallel` into an outlined body and this call. */
void GOMP_parallel(region_body body, void *data, unsigned num_threads, unsigned flags);

static _Thread_local int inline_depth;
static _Thread_local long inline_count;

void gomp_inline_enter(void)
{
    inline_depth++;
}

void gomp_inline_leave(void)
{
    inline_depth--;
}

static gomp_parallel_entry libgomp_entry(void)
{
    static gomp_parallel_entry next; /* every thread finds the same one */
    gomp_parallel_entry f = __atomic_load_n(&next, __ATOMIC_ACQUIRE);
    if (!f) {
        f = (gomp_parallel_entry)dlsym(RTLD_NEXT, "GOMP_parallel");
        if (!f) {
            /* nothing can run a region of several threads without it */
            fprintf(stderr, "muflow: libgomp's GOMP_parallel not found: %s\n", dlerror());
            abort();
        }
        __atomic_store_n(&next, f, __ATOMIC_RELEASE);
    }
    return f;
}

void GOMP_parallel(region_body body, void *data, unsigned num_threads, unsigned flags)
{
    /* num_threads 1 is also what GCC passes for a false `if` clause (the
     * kernels' `if (kernel_parallel(g))` on small grids): a team of one,
     * whose body runs the same way called directly */
    if (inline_depth > 0 || num_threads == 1) {
        inline_count++;
        body(data);
        return;
    }
    libgomp_entry()(body, data, num_threads, flags);
}

long gomp_inline_count(void)
{
    return inline_count;
}
