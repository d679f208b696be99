/* Runs one case from start to output: the pipeline
 * case -> march (grid, fields, solvers) -> time loop -> diagnostics -> output,
 * with field files, checkpoints, restarts and clean interruption. */
#ifndef MUFLOW_RUN_H
#define MUFLOW_RUN_H

#include "config/case.h"
#include "march/march.h"
#include "io/output.h"

/* Hands the case reader (config, the bottom layer) what the layers above
 * it know: the scenes of the registry and the checks that need the solvers,
 * the friction curve and the march (config/case_registry.h).  Once, before
 * the first case_load or case_defaults; later calls change nothing. */
void run_init(void);

/* What run_case_opts returns (PETSc-like: 0 or a negative code, cause in err). */
enum run_error {
    RUN_OK = 0,
    RUN_ERR_SETUP = -1,   /* the run could not start (nothing marched) */
    RUN_ERR_OUTPUT = -2,  /* the run took place, an output or checkpoint could not be
                             written (the others were still attempted) */
};

/* Called at every observation of the march (after the residual evaluation,
 * before the step), before anything else; for tests. */
typedef void (*run_hook)(void *ctx, const struct march_state *st);

struct run_options {
    /* 0: in memory only (tests, benchmarks).  1: the output folder (history,
     * field files, checkpoints, profile, summary), progress lines unless
     * cs->quiet, and SIGINT / SIGTERM stop the run cleanly (interrupt.h). */
    int write_output;
    /* A checkpoint file to continue from (checkpoint.h), or NULL.  The case
     * must be the checkpoint's (checkpoint_load_case), with any overrides. */
    const char *restart_from;
    run_hook hook;
    void *hook_ctx;
    /* physics modules beside the scene's (NULL-terminated), or NULL: a
     * program that embeds muflow adds its own (march/module.h) */
    const struct module *const *modules;
    /* 1: this process runs the case alone, also under mpirun with several
     * ranks (a test's reference); 0: a run under mpirun is split over its
     * ranks (march_setup.decompose) */
    int one_process;
    /* the ranks along each direction (march_setup.dims; 0: MPI's choice) */
    int dims[3];
};

/* Returns RUN_OK when the run took place (whatever its status), else an
 * enum run_error with the cause in err.  A run stopped by a signal, by
 * max_steps in transient mode or by a failed checkpoint ends with status
 * STATUS_STOPPED.  With write_output, every run but one whose checkpoint
 * failed (or whose scene cannot continue, the heap search) writes a
 * checkpoint of its final state (res->checkpointed). */
int run_case_opts(const struct muflow_case *cs, const struct run_options *opt,
                  struct run_result *res, char *err, size_t errlen);

/* run_case_opts without restart or hook. */
int run_case(const struct muflow_case *cs, int write_output, struct run_result *res, char *err,
             size_t errlen);

/* The result fields a finished march determines: the scene, status, steps,
 * time, wall seconds, residual, divergence and message (not the scene
 * errors). */
void run_result_from(const struct march_state *st, struct run_result *res);

/* Exit status of the command for a run's status. */
int run_exit_code(enum run_status s);

#endif
