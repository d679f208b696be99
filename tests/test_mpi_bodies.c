/* Bodies over ranks in the group mpi (test_mpi.c): a case with a body
 * (physics/obstacle.h) split so that the body straddles rank borders
 * against the same case on one process (every rank runs that too: the
 * test's reference).  Its geometry is each block's from global indices, its
 * forces summed over the ranks; so the same status, steps within 1 and the
 * forces within 1e-8 relative.  Each check reduces over the ranks before
 * asserting (all pass or fail together). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "app/run.h"
#include "platform/comm.h"
#include "test_main.h"
#include "test_util.h"

/* The case split as dims asks (0: MPI's choice) against one process: the
 * same status (want), steps within 1, each of keys within 1e-8 relative
 * (the ranks' sums in MPI's order; the linear solves' round-off on a
 * steady state; a missing line fails). */
static void check_body_on_ranks(const char *file, int n, char *ov[], const int dims[3],
                                const char *const *keys, enum run_status want)
{
    struct muflow_case cs;
    test_load_case(&cs, file, n, ov);
    struct run_result one, all;
    char err[1024] = "";
    const struct run_options alone = {.one_process = 1},
                             split = {.dims = {dims[0], dims[1], dims[2]}};
    int rc = run_case_opts(&cs, &alone, &one, err, sizeof err);
    rc |= run_case_opts(&cs, &split, &all, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    double rel = 0.0;
    for (const char *const *k = keys; *k; k++) {
        const double a = run_result_value(&one, *k), b = run_result_value(&all, *k);
        rel = fmax(rel, isnan(a) || isnan(b) ? INFINITY
                        : a == b             ? 0.0
                                             : fabs(b - a) / fmax(fabs(a), fabs(b)));
    }
    double bad = rc != RUN_OK || one.status != want || all.status != one.status ||
                 labs(all.steps - one.steps) > 1 || !(rel <= 1e-8);
    comm_sum(&bad, 1);
    if (comm_rank() == 0)
        printf("    %s on %d ranks (%d x %d x %d asked): %ld steps (alone %ld), %s %s %.10g "
               "(alone %.10g), within %.1e relative\n",
               cs.name, comm_size(), dims[0], dims[1], dims[2], all.steps, one.steps,
               run_status_name(all.status), keys[0], run_result_value(&all, keys[0]),
               run_result_value(&one, keys[0]), rel);
    assert_true(bad == 0.0);
}

/* Schaefer & Turek's cylinder (cases/cylinder_benchmark.ini) in a channel
 * cut to 0.4 long, h = D/10 (40 x 41), steady in 373 steps alone: split
 * along x the rank border at x = 0.2 runs through the cylinder's centre (4
 * ranks: 0.1, 0.2, 0.3), along z at z = 0.21 (41 cells: 21 + 20), both;
 * the velocity multigrid's held nodes across the borders, the cut links
 * and cut cells' grad-div of the blocks, the surface integral summed over
 * them, the control volume and pressure_drop read on the gathered fields */
void test_cylinder_benchmark_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.lx=0.4", "domain.nx=40"};
    static const char *const keys[] = {"drag_coefficient", "lift_coefficient", "pressure_drop",
                                       "drag_coefficient_control_volume",
                                       "lift_coefficient_control_volume",
                                       "drag_coefficient_reconstructed", NULL};
    const int p = comm_size();
    const int along_x[3] = {p, 1, 1}, along_z[3] = {1, 1, p}, both[3] = {0, 1, 0};
    check_body_on_ranks("../cases/cylinder_benchmark.ini", 2, ov, along_x, keys, STATUS_STEADY);
    check_body_on_ranks("../cases/cylinder_benchmark.ini", 2, ov, along_z, keys, STATUS_STEADY);
    check_body_on_ranks("../cases/cylinder_benchmark.ini", 2, ov, both, keys, STATUS_STEADY);
}

/* The slope release (cases/slope_release.ini: the bed a body of whole
 * cells, two phases, the VOF) at 2.5 mm cells (60 x 24) to t = 0.1 (100
 * steps): the bed crosses every rank border; split along x (x = 0.075;
 * 4 ranks 0.0375 apart), along z (z = 0.03, the bed below the column; 4
 * ranks: 0.015 apart, 0.045 through the column), both; its measures on the
 * gathered fields */
void test_slope_release_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=60", "domain.nz=24", "solver.end_time=0.1",
                  "slope_release.da_cells=200"};
    static const char *const keys[] = {"run_out", "run_out_99", "tail", "kinetic_energy_peak",
                                       "never_yielded_area", NULL};
    const int p = comm_size();
    const int along_x[3] = {p, 1, 1}, along_z[3] = {1, 1, p}, both[3] = {0, 1, 0};
    check_body_on_ranks("../cases/slope_release.ini", 4, ov, along_x, keys, STATUS_FINISHED);
    check_body_on_ranks("../cases/slope_release.ini", 4, ov, along_z, keys, STATUS_FINISHED);
    check_body_on_ranks("../cases/slope_release.ini", 4, ov, both, keys, STATUS_FINISHED);
}
