/* The scenes whose measures cross rank borders (the fed layers' columns
 * along x, bagnold2's rows along x, the duct's mid-plane columns) split over
 * the ranks in each direction their grid allows, against one process, in
 * the group mpi (test_mpi.c): the same status, steps within 1, the listed
 * [result] lines within 1e-8 relative (check_scene_lines_on_ranks).  On
 * one rank both runs are one process's. */
#include <stdio.h>
#include "app/run.h"
#include "platform/comm.h"
#include "test_main.h"
#include "test_util.h"

void check_scene_lines_on_ranks(const char *file, int n, char *ov[], const int dims[3],
                                const char *const *keys, enum run_status want);

/* Each split of the ranks a case is checked on: along a (and b) alone, and
 * with both set MPI's choice over both on four ranks or more (on two it is
 * one of them). */
static void check_splits(const char *file, int n, char *ov[], int a, int b, int both_too,
                         const char *const *keys, enum run_status want)
{
    const int p = comm_size();
    int along_a[3] = {1, 1, 1}, along_b[3] = {1, 1, 1}, both[3] = {1, 1, 1};
    along_a[a] = along_b[b] = p;
    both[a] = both[b] = 0;
    check_scene_lines_on_ranks(file, n, ov, along_a, keys, want);
    if (p > 1)
        check_scene_lines_on_ranks(file, n, ov, along_b, keys, want);
    if (both_too && p >= 4)
        check_scene_lines_on_ranks(file, n, ov, both, keys, want);
}

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
    check_splits("../cases/wall_shock.ini", 2, ov, 0, 2, 0, keys, STATUS_FINISHED);
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
    check_splits("../cases/front.ini", 4, ov, 0, 2, 0, keys, STATUS_FINISHED);
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
    check_scene_lines_on_ranks("../cases/bagnold2.ini", 2, ov, along_x, keys, STATUS_STEADY);
    char *grow[] = {"domain.nx=10",         "domain.nz=20",         "solver.mode=transient",
                    "bagnold2.start=exact", "bagnold2.perturbation=0.01", "solver.dt=1e-4",
                    "solver.end_time=0.002"};
    static const char *const amplitudes[] = {"amplitude_start", "amplitude_end", "growth_rate",
                                             "u_top", NULL};
    check_scene_lines_on_ranks("../cases/bagnold2.ini", 7, grow, along_x, amplitudes,
                               STATUS_FINISHED);
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
    check_splits("../cases/duct_square.ini", 1, ov, 1, 2, 1, keys, STATUS_STEADY);
}
