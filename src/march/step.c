/* The step's stages in order (step.h): the one place that says what a step
 * does, and where the physics modules come in. */
#include "march/step.h"
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
 * arrays only.  One after the other, on a small 2D grid whose pressure is
 * the whole grid's factorisation, they are both serial (CHOLMOD runs on one
 * thread, suitesparse.h) and the second core sat idle: the pressure's
 * factorisation is a sixth of the column collapse's run at 25.6 cells per
 * H0 (docs/numerics/pressure.md).  A POSIX thread takes it, outside
 * any OpenMP team, so that the implicit stage's regions run as they do
 * alone, with one thread fewer meanwhile (on 256 x 80, where the kernels
 * are parallel, that is still 0.87 of the time).  Where the pressure is
 * the multigrid's cycles the factorisation is its small coarsest level:
 * it follows the implicit stage, which keeps every thread. */
static int implicit_beside_pressure(struct march_state *st, double dt)
{
    struct pressure_solver *ps = st->pressure_solver;
    if (!ps || !pressure_pending(ps))
        return stage_implicit(st, dt);
    struct pressure_job job = {.ps = ps};
    pthread_t worker;
    const int threads = omp_get_max_threads();
    const int beside = threads > 1 && pressure_direct(ps) &&
                       pthread_create(&worker, NULL, pressure_job_run, &job) == 0;
    if (beside)
        omp_set_num_threads(threads - 1);
    int rc = stage_implicit(st, dt);
    if (beside) {
        omp_set_num_threads(threads);
        pthread_join(worker, NULL);
    } else if (rc == 0) {
        pressure_job_run(&job);
    }
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
    /* the mass term's and the projection's dt: dt / a0 of the time scheme */
    double dt_mass = stage_time_scheme(st, dt);
    if (implicit_beside_pressure(st, dt_mass) != 0)
        return -1;
    if (st->cs->coupled)
        stage_coupled_update(st);
    else
        stage_projection(st, dt_mass);
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->transport &&
            st->modules[m]->transport(st, st->module_state[m], dt) != 0)
            return -1;
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->end_step)
            st->modules[m]->end_step(st, st->module_state[m], dt);
    return 0;
}
