/* The operator of the implicit step applied with the solver's work arrays,
 * and the CPU clock the solver's statistics read: what the solve, its Krylov
 * loops and its preconditioners all call, kept apart so that none of those
 * files depends on another's (viscous_internal.h). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <time.h>
#include "solvers/viscous_internal.h"

double visc_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void viscous_apply(struct viscous_solver *s, const struct viscous_problem *pb, double *v[3],
                   double *out[3])
{
    const struct viscous_work w = {.divbuf = s->divbuf, .pn = s->pn, .Bc = s->Bc,
                                   .pe = {s->pe[0], s->pe[1], s->pe[2]},
                                   .Be = {s->Be[0], s->Be[1], s->Be[2]},
                                   .tmp = {s->tmp[0], s->tmp[1], s->tmp[2]}};
    viscous_operator_eval(s->g, s->bc, s->act, &w, pb, v, out);
}

void viscous_operator_apply(void *ctx, double *v[3], double *out[3])
{
    struct viscous_operator *a = ctx;
    viscous_apply(a->s, a->pb, v, out);
}
