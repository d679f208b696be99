/* The smallest program on the muflow library: loads a case file with
 * command-line overrides, runs it in memory and prints how it ended and
 * its error against the exact solution.
 *
 *   cc -std=c11 minimal.c -o minimal $(pkg-config --cflags --libs muflow)
 *   ./minimal cases/bagnold.ini domain.nz=10
 *
 * prints
 *
 *   status = steady
 *   steps = 15
 *   err_rms = 1.935774e-03
 *
 * (after `make install`; in the source tree `make build/minimal` builds it
 * against build/libmuflow.a). */
#include <stdio.h>
#include "app/run.h"     /* run_init, run_case, run_exit_code; includes config/case.h */

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: minimal CASE.ini [section.key=value ...]\n");
        return 2;
    }
    /* The scenes and the checks the case reader needs, once. */
    run_init();
    /* The case: every key of the file, then the overrides in order, checked
     * as the muflow command checks them (one line naming the key on error). */
    struct muflow_case cs;
    char err[1024];
    if (case_load(&cs, argv[1], argc - 2, argv + 2, err, sizeof err) != 0) {
        fprintf(stderr, "minimal: %s\n", err);
        return 2;
    }
    /* Run it to its end: 0 writes nothing (1 writes output.dir as the
     * command does: summary.ini, profile.csv, checkpoint.h5, ...).  The
     * result is a plain value: nothing to free. */
    struct run_result r;
    if (run_case(&cs, 0, &r, err, sizeof err) != RUN_OK) {
        fprintf(stderr, "minimal: %s\n", err);
        return 2;
    }
    /* Any line of summary.ini's [result] section by its name (NaN when the
     * run has none: a scene without an exact solution has no err_rms). */
    printf("status = %s\n", run_status_name(r.status));
    printf("steps = %ld\n", r.steps);
    printf("err_rms = %.6e\n", run_result_value(&r, "err_rms"));
    return run_exit_code(r.status); /* the command's: 0 steady or finished */
}
