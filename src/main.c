/* muflow CASE [section.key=value ...]
 * Runs a case file (an INI file under cases/) with command-line overrides of any key.
 * Exit status: 0 steady or finished, 1 diverged, 2 bad input or setup
 * failure, 3 unsteady or stopped. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "analytic.h"
#include "case.h"
#include "run.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: muflow CASE.ini [section.key=value ...]\n"
               "  runs the case to a steady state (solver.mode = steady) or to\n"
               "  solver.end_time (transient); any case key can be overridden, e.g.\n"
               "  muflow cases/bagnold.ini physics.tilt=0.45 domain.nz=80\n"
               "  output: summary.ini, profile.csv, history.csv in output.dir\n");
}

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    static struct muflow_case cs;
    char err[1024];
    if (case_load(&cs, argv[1], argc - 2, argv + 2, err, sizeof err) != 0) {
        fprintf(stderr, "muflow: %s\n", err);
        return 2;
    }
    struct run_result r;
    if (run_case(&cs, 1, &r, err, sizeof err) != 0) {
        fprintf(stderr, "muflow: %s\n", err);
        return 2;
    }
    printf("%s: %s after %ld steps, t = %.6g, wall %.3f s, residual %.3e (%s)\n", cs.name,
           run_status_name(r.status), r.steps, r.time, r.wall_seconds, r.residual, r.message);
    const char *hname = scene_headline_name(cs.scene);
    if (hname && r.errors.valid)
        printf("%s: err_rms %.4e  err_max %.4e  err_rms_paper %.4e  %s %.6g (exact %.6g)\n",
               cs.name, r.errors.err_rms, r.errors.err_max, r.errors.err_rms_paper, hname,
               r.errors.headline, r.errors.headline_exact);
    else if (hname)
        printf("%s: no analytic steady solution for these parameters; %s %.6g\n", cs.name, hname,
               r.errors.headline);
    printf("output: %s\n", cs.output_dir);
    return run_exit_code(r.status);
}
