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
#include "test_mpi.h"
#include "test_util.h"

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
    const struct scene_lines s = {.file = "../cases/cylinder_benchmark.ini", .n = 2, .ov = ov,
                                  .keys = keys, .want = STATUS_STEADY};
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}}; /* x, z, both */
    check_scene_splits(&s, 3, splits);
}

/* The granular cylinder (cases/cylinder.ini: mu(I), the coupled Newton
 * step with the viscosity's pressure columns, gathered onto every rank and
 * factorised there) in a box of 5 x 10 D at D/2 (10 x 20) driven by F = 3,
 * so that it flows (U 1.37) and is steady in 104 steps alone: split along
 * x (the symmetry plane's block beside the wall's), along z (the border
 * through the cylinder's centre at z = 5 on 2 ranks), both */
void test_cylinder_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.lx=5", "domain.nx=10", "domain.lz=10", "domain.nz=20",
                  "obstacle.shapes=circle 0 5 0.5", "cylinder.forcing=3"};
    static const char *const keys[] = {"flow_rate", "drag", "drag_surface", "froude", NULL};
    const struct scene_lines s = {.file = "../cases/cylinder.ini", .n = 6, .ov = ov,
                                  .keys = keys, .want = STATUS_STEADY};
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}}; /* x, z, both */
    check_scene_splits(&s, 3, splits);
}

/* The cylinder's continuation in the mean velocity (cylinder.velocity_end:
 * the flow-rate module's border, its mean summed over the ranks) at D/2
 * (20 x 60, lambda 1e-2), 3 solves to U = 2 at F 1.20555 alone, split
 * along z (the rank border through the cylinder's centre on 2 ranks): F,
 * U and the drag within 1e-8.  With the mean of a rank's block alone the
 * continuation went to F < 0 and 3,000 unsteady steps a solve. */
void test_cylinder_velocity_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"rheology.lambda=1e-2",        "solver.continuation=1",
                  "domain.nx=20",                "domain.nz=60",
                  "cylinder.forcing_end=1.15",   "cylinder.forcing_step=0.15",
                  "cylinder.velocity_end=2",     "cylinder.velocity_ratio=2"};
    static const char *const keys[] = {"forcing", "mean_velocity", "drag", NULL};
    const struct scene_lines s = {.file = "../cases/cylinder.ini", .n = 8, .ov = ov,
                                  .keys = keys, .want = STATUS_STEADY};
    const int along_z[3] = {1, 1, comm_size()};
    check_scene_lines(&s, along_z);
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
    const struct scene_lines s = {.file = "../cases/slope_release.ini", .n = 4, .ov = ov,
                                  .keys = keys, .want = STATUS_FINISHED};
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}}; /* x, z, both */
    check_scene_splits(&s, 3, splits);
}
