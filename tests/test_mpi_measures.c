/* The scenes whose measures cross rank borders (the fed layers' columns
 * along x, bagnold2's rows along x, the duct's mid-plane columns) split over
 * the ranks in each direction their grid allows, against one process, in
 * the group mpi (test_mpi.c): the same status, steps within 1, the listed
 * [result] lines within 1e-8 relative (check_scene_lines, test_mpi.h).
 * On one rank both runs are one process's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "app/run.h"
#include "scenes/scene.h"
#include "platform/comm.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* 20 x 15 cells to the shipped end (379 steps alone): the shock at 0.052,
 * past the border at x = lx / 2 of a split in two; the speed's fit has too
 * few rows with a shock at this grid (NaN in both: not listed); each split
 * alone (379 steps on the ranks take minutes on a loaded machine) */
void test_wall_shock_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=20", "domain.nz=15"};
    static const char *const keys[] = {"x_shock",      "h1",         "u1",
                                       "depth_ratio",  "u2_over_u1", "static_length",
                                       "shock_speed_mass", "fit_rows", NULL};
    const struct scene_lines s = {.file = "../cases/wall_shock.ini", .n = 2, .ov = ov,
                                  .keys = keys, .want = STATUS_FINISHED};
    const int splits[2][3] = {{comm_size(), 1, 1}, {1, 1, comm_size()}}; /* x, z */
    check_scene_splits(&s, 2, splits);
}

/* 100 x 10 cells to t = 0.05: the tip (0.086) and x_half past the border
 * at x = lx / 2 of a split in two, the layer behind the front on both
 * sides of it; the bed's layer on the lowest blocks along z */
void test_front_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=100", "domain.nz=10", "domain.ly=2.145e-4", "solver.end_time=0.05"};
    static const char *const keys[] = {"x_tip",          "x_half",          "front_speed",
                                       "h_err_rms",      "h_err_max",       "h_behind_error",
                                       "profile_err_rms", "precursor_flux", "h_err_max_nose",
                                       "h_err_rms_depth_averaged", NULL};
    const struct scene_lines s = {.file = "../cases/front.ini", .n = 4, .ov = ov, .keys = keys,
                                  .want = STATUS_FINISHED};
    const int splits[2][3] = {{comm_size(), 1, 1}, {1, 1, comm_size()}}; /* x, z */
    check_scene_splits(&s, 2, splits);
}

/* The shipped front as it is (250 x 15 to t = 0.6, 1,339 steps): one
 * process's run, then split along x and along z, the [result] lines within
 * 1e-8 relative, steps within 1, and every implicit solve converged in
 * every run (linear_unconverged 0).  The open faces make the operator
 * non-symmetric: under CG one solve (step 1018) stopped at its cap, at
 * 2.5e-8 alone and 4e-4 on two ranks, and front_speed ended 1.3e-7 apart;
 * the flexible GMRES converges it (viscous.c).  The group's longest test
 * (40 s a run on one thread): under `mpirun -np 2` only, alone once for
 * both splits (on 4 ranks along z one measure ends 2.2e-7 apart:
 * docs/numerics/decomposition.md). */
void test_front_shipped_on_ranks(void **state)
{
    (void)state;
    if (comm_size() != 2)
        skip();
    static const char *const keys[] = {
        "front_speed", "x_tip", "x_half", "uniform_speed", "front_speed_depth_averaged",
        "h_err_rms", "h_err_max", "h_err_rms_body", "h_err_max_body", "h_behind_error",
        "nose_offset", "profile_err_rms", "precursor_flux", "h_err_max_nose",
        "h_err_rms_depth_averaged", "h_err_max_body_depth_averaged",
        "h_err_max_nose_depth_averaged", "depth_averaged_nose_err_max", NULL};
    struct muflow_case cs;
    char *ov[] = {"output.quiet=on"};
    test_load_case(&cs, "../cases/front.ini", 1, ov);
    const int p = comm_size();
    struct run_result one, all;
    char err[1024] = "";
    const struct run_options alone = {.one_process = 1};
    int rc = run_case_opts(&cs, &alone, &one, err, sizeof err);
    double bad = rc != RUN_OK || one.status != STATUS_FINISHED || one.linear_unconverged != 0;
    for (int a = 0; a < 3; a += 2) { /* x, then z */
        struct run_options split = {.dims = {1, 1, 1}};
        split.dims[a] = p;
        int rs = run_case_opts(&cs, &split, &all, err, sizeof err);
        double rel = 0.0;
        const char *worst = keys[0];
        for (const char *const *k = keys; *k; k++) {
            const double u = run_result_value(&one, *k), v = run_result_value(&all, *k);
            const double e = isnan(u) || isnan(v) ? INFINITY
                             : u == v             ? 0.0
                                                  : fabs(v - u) / fmax(fabs(u), fabs(v));
            if (e > rel) {
                rel = e;
                worst = *k;
            }
        }
        bad += rs != RUN_OK || all.status != one.status || labs(all.steps - one.steps) > 1 ||
               all.linear_unconverged != 0 || !(rel <= 1e-8);
        if (comm_rank() == 0)
            printf("    front (shipped) on %d ranks along %c: %ld steps (alone %ld), "
                   "front_speed %.10g (alone %.10g), results within %.1e relative, "
                   "the most %s %.10g (alone %.10g), unconverged solves %ld (alone %ld)\n",
                   p, "xyz"[a], all.steps, one.steps, run_result_value(&all, "front_speed"),
                   run_result_value(&one, "front_speed"), rel, worst,
                   run_result_value(&all, worst), run_result_value(&one, worst),
                   all.linear_unconverged, one.linear_unconverged);
    }
    if (rc != RUN_OK)
        print_error("%s\n", err);
    comm_sum(&bad, 1);
    assert_true(bad == 0.0);
}

/* 10 x 20 cells steady (the shipped Fourier line blocks: the periodic x
 * split, z lines whole) and the growth of a perturbation over 20 steps
 * (its amplitudes: rows along x summed over the ranks, the faces' maxima) */
void test_bagnold2_on_ranks(void **state)
{
    (void)state;
    const int along_x[3] = {comm_size(), 1, 1};
    char *ov[] = {"domain.nx=10", "domain.nz=20"};
    static const char *const keys[] = {"u_top", "err_rms", "err_rms_grains", "err_rms_air",
                                       "u_interface", NULL};
    const struct scene_lines steady = {.file = "../cases/bagnold2.ini", .n = 2, .ov = ov,
                                       .keys = keys, .want = STATUS_STEADY};
    check_scene_lines(&steady, along_x);
    char *grow[] = {"domain.nx=10",         "domain.nz=20",         "solver.mode=transient",
                    "bagnold2.start=exact", "bagnold2.perturbation=0.01", "solver.dt=1e-4",
                    "solver.end_time=0.002"};
    static const char *const amplitudes[] = {"amplitude_start", "amplitude_end", "growth_rate",
                                             "u_top", NULL};
    const struct scene_lines growth = {.file = "../cases/bagnold2.ini", .n = 7, .ov = grow,
                                       .keys = amplitudes, .want = STATUS_FINISHED};
    check_scene_lines(&growth, along_x);
}

/* The shipped 20 x 40 half cross-section (66 steps alone) split across y,
 * along z (the bed's heights the domain's: split at z = 0.0325 in two,
 * 0.01625 in four, the bed's top at 0.03225) and both: the flow rate, area
 * and mid-plane over the ranks */
void test_duct_square_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"output.quiet=on"};
    static const char *const keys[] = {"u_max",         "diff_plane",  "flow_rate",
                                       "area",          "mean_velocity", "u_max_midplane",
                                       "mobile_layer_midplane", NULL};
    const struct scene_lines s = {.file = "../cases/duct_square.ini", .n = 1, .ov = ov,
                                  .keys = keys, .want = STATUS_STEADY};
    const int p = comm_size();
    const int splits[3][3] = {{1, p, 1}, {1, 1, p}, {1, 0, 0}}; /* y, z, both */
    check_scene_splits(&s, 3, splits);
}

/* The implicit solves' iterations of a run, summed over its observations
 * (run_hook; the last step's each time). */
static void count_iterations(void *ctx, const struct march_state *st)
{
    *(long *)ctx += st->linear_iterations;
}

/* The circular duct's implicit solves on the ranks as dims asks: auto's
 * gmg (the velocity multigrid does not converge on it), and its iterations
 * over the run within one a step of one process's, which a gathered
 * cross-section without the body's folded nodes and links misses (the
 * answers alike: the solves converge all the same).  Collective. */
static void check_duct_circular_gmg(const struct muflow_case *cs, const int dims[3])
{
    long one = 0, all = 0, steps[2] = {0, 0};
    struct run_result r;
    char err[1024] = "";
    const struct run_options alone = {.one_process = 1, .hook = count_iterations,
                                      .hook_ctx = &one},
                             split = {.dims = {dims[0], dims[1], dims[2]},
                                      .hook = count_iterations, .hook_ctx = &all};
    int rc = run_case_opts(cs, &alone, &r, err, sizeof err);
    steps[0] = r.steps;
    rc |= run_case_opts(cs, &split, &r, err, sizeof err);
    steps[1] = r.steps;
    struct march_state st;
    struct march_setup su;
    scene_march_setup(cs, NULL, &su);
    su.decompose = 1; /* as a run on the ranks (run.c) */
    for (int d = 0; d < 3; d++)
        su.dims[d] = dims[d];
    rc |= march_create(&st, cs, &su, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    const int gmg = rc == RUN_OK && st.precond == VISCOUS_GMG;
    if (rc == RUN_OK)
        march_destroy(&st);
    double bad = !gmg || labs(all - one) > steps[0] || labs(steps[1] - steps[0]) > 1;
    comm_sum(&bad, 1);
    if (comm_rank() == 0)
        printf("    %s on %d ranks (%d x %d x %d asked): %s, %ld implicit iterations in %ld "
               "steps (alone %ld in %ld)\n", cs->name, comm_size(), dims[0], dims[1], dims[2],
               gmg ? "gmg" : "not gmg", all, steps[1], one, steps[0]);
    assert_true(bad == 0.0);
}

/* The circular duct (the shipped 20 x 40 half cross-section, 78 steps
 * alone): auto's gmg on the ranks too (the velocity multigrid does not
 * converge on it), its cross-section gathered with the body's held nodes and
 * cut links; split across y, along z (rank borders through the wall's cut
 * cells) and both: the flow rate over the faces' open shares and the open
 * area over the ranks, the mid-plane */
void test_duct_circular_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"output.quiet=on"};
    struct muflow_case cs;
    test_load_case(&cs, "../cases/duct_circular.ini", 1, ov);
    const int p = comm_size();
    const int splits[3][3] = {{1, p, 1}, {1, 1, p}, {1, 0, 0}}; /* y, z, both */
    int dims[3][3];
    for (int t = 0, n = test_splits(3, splits, dims); t < n; t++)
        check_duct_circular_gmg(&cs, dims[t]);
    static const char *const keys[] = {"u_max",         "diff_plane",  "flow_rate",
                                       "area",          "mean_velocity", "u_max_midplane",
                                       "mobile_layer_midplane", NULL};
    const struct scene_lines s = {.file = "../cases/duct_circular.ini", .n = 1, .ov = ov,
                                  .keys = keys, .want = STATUS_STEADY};
    check_scene_splits(&s, 3, splits);
}
