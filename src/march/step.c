/* The step's stages in order (step.h): the one place that says what a step
 * does, and where the physics modules come in. */
#include "march/step.h"
#include "kernels/kernels.h"
#include "solvers/pressure.h"

#include <omp.h>
#include <pthread.h>
#include <stdio.h>

void step_evaluate(struct march_state *st)
{
    stage_properties(st);
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->properties)
            st->modules[m]->properties(st, st->module_state[m]);
    stage_residual(st);
}

struct pressure_job {
    struct pressure_solver *ps;
    int rc;
    char why[200];
};

static void *pressure_job_run(void *arg)
{
    struct pressure_job *job = arg;
    job->rc = pressure_finish(job->ps, job->why, sizeof job->why);
    return NULL;
}

/* Stage 3, and beside it the projection's factorisation that the last
 * transport left due (a new density: pressure_set_coefficient).  The two
 * share nothing: the factorisation reads the pressure multigrid's own
 * arrays only.  On a small 2D grid both are serial (CHOLMOD runs on one
 * thread, suitesparse.h; the kernels below kernel_parallel's size), and
 * one after the other they left the second core idle: the pressure's
 * factorisation is a sixth of the column collapse's run at 25.6 cells per
 * H0 (docs/design.md, "Column collapse").  A POSIX thread takes it, outside
 * any OpenMP team, so the implicit stage's regions run as they do alone.
 * Where the kernels are parallel the two would contend for the cores: the
 * factorisation follows the implicit stage there, as on one thread. */
static int implicit_beside_pressure(struct march_state *st, double dt)
{
    struct pressure_solver *ps = st->pressure_solver;
    if (!ps || !pressure_pending(ps))
        return stage_implicit(st, dt);
    struct pressure_job job = {.ps = ps};
    pthread_t worker;
    const int beside = omp_get_max_threads() > 1 && !kernel_parallel(&st->g) &&
                       pthread_create(&worker, NULL, pressure_job_run, &job) == 0;
    int rc = stage_implicit(st, dt);
    if (beside)
        pthread_join(worker, NULL);
    else if (rc == 0)
        pressure_job_run(&job);
    if (rc != 0)
        return -1;
    if (job.rc != 0) {
        snprintf(st->step_error, sizeof st->step_error, "the projection's factorisation: %.120s",
                 job.why);
        return -1;
    }
    return 0;
}

int step_advance(struct march_state *st, double dt)
{
    if (implicit_beside_pressure(st, dt) != 0)
        return -1;
    if (st->cs->coupled)
        stage_coupled_update(st);
    else
        stage_projection(st, dt);
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->transport &&
            st->modules[m]->transport(st, st->module_state[m], dt) != 0)
            return -1;
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->end_step)
            st->modules[m]->end_step(st, st->module_state[m], dt);
    return 0;
}
