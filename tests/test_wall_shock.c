/* The shock from a wall (scene wall_shock, cases/wall_shock.ini) on the
 * coarse grid of the grid study: its depth ratio and speed against the
 * jump conditions of the depth-averaged equations from the measured
 * upstream depth and speed, and its speed against those equations' own
 * solution of the problem; then bad input. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "app/run.h"
#include "test_main.h"

#define CASE "../cases/wall_shock.ini"

/* The grid study (docs/validation/wall_shock.md), 0.45 s on 40 x 30,
 * 80 x 60 and 160 x 120 cells, measured (F = 1.47-1.48):
 *   h2 / h1 against the jump conditions (u2 = 0)  +0.45 %, -3.32 %, -3.80 %
 *   the speed against them (u2 = 0)               -36.0 %, -33.3 %, -31.8 %
 *   the speed against the mass jump with the measured u2
 *                                                 +7.8 %, +4.0 %, +4.9 %
 *   the speed against the jumps (mass and momentum) with the measured u2
 *                                                 -12.7 %, -8.6 %, -6.8 %
 *     (order 0.7, Richardson's limit 0.0853 m/s: -3.4 % of them)
 *   u2 / u1 behind the shock                      0.136, 0.137, 0.137
 *   the speed against the depth-averaged equations' solution (0.07537 m/s,
 *   independent of the grid)                      +2.6 %, +6.8 %, +9.3 %
 * The grains behind the shock do not stop: the deposit's surface rises at
 * 0.10 towards the wall, less than the (tan zeta - mu_s) / K = 0.17 that
 * holds grains at rest, and they creep into the wall at u2 = 0.14 u1; the
 * mass jump with u2 = 0 then overestimates the speed by a third.  The test
 * runs the coarse grid: the ratio within the 5 % the comparison claims; the
 * speed against the mass jump with the measured u2 within 10 % (the coarse
 * grid's 7.8 % and a margin); against u2 = 0 inside (-40 %, -28 %), the
 * study's band and about 4 % either side, so that a shock that stopped the
 * grains behind it (or lost them) fails; u2 / u1 inside (0.08, 0.2).  The
 * depth-averaged equations' own solution, measured the same way, is as far
 * from their jump conditions (-37.0 %, u2 = 0.18 u1; within 3e-4 from 10 to
 * 40 cells per h1): it must lie in the same bands; the 2D speed within 5 %
 * of it on the coarse grid (its 2.6 % and a margin; the finer grids' 6.8
 * and 9.3 % are the table's).  With its own u2 in the jumps that solution
 * meets them to 0.16 % (speed) and 0.12 % (ratio), 0.27 % at most from 5
 * to 80 cells per h1: the measure of the state behind the shock is the
 * jumps'; asserted within 0.5 %.  The 2D speed against the jumps with its
 * u2 within 15 % on the coarse grid (its 12.7 % and a margin). */
#define COARSE_GRID "domain.nx=40", "domain.nz=30"
#define RATIO_TOL 0.05
#define MASS_TOL 0.10
#define SPEED_LO -0.40
#define SPEED_HI -0.28
#define U2_LO 0.08
#define U2_HI 0.2
#define DA_SPEED_TOL 0.05
#define DA_JUMP_U2_TOL 0.005
#define JUMP_U2_TOL 0.15

static void test_coarse_shock(void **state)
{
    (void)state;
    char *ov[] = {COARSE_GRID};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(CASE, (int)(sizeof ov / sizeof ov[0]), ov, &cs, &r);
    double ratio = run_result_value(&r, "depth_ratio_error");
    double speed = run_result_value(&r, "shock_speed_error");
    double mass = run_result_value(&r, "shock_speed_mass_error");
    double u2 = run_result_value(&r, "u2_over_u1"), fr = run_result_value(&r, "froude");
    print_message("wall shock: F %.3f, h2/h1 error %+.3e, speed error %+.3e (mass jump with "
                  "u2: %+.3e), u2/u1 %.3e\n", fr, ratio, speed, mass, u2);
    assert_int_equal(r.status, STATUS_FINISHED);
    assert_true(fr > 1.0);
    assert_true(fabs(ratio) < RATIO_TOL);
    assert_true(fabs(mass) < MASS_TOL);
    assert_true(speed > SPEED_LO && speed < SPEED_HI);
    assert_true(u2 > U2_LO && u2 < U2_HI);
    double da = run_result_value(&r, "shock_speed_depth_averaged_error");
    double da_jump = run_result_value(&r, "shock_speed_depth_averaged_jump_error");
    double da_u2 = run_result_value(&r, "u2_over_u1_depth_averaged");
    print_message("wall shock: speed against the depth-averaged solution %+.3e; that solution "
                  "against the jumps %+.3e, its u2/u1 %.3e\n", da, da_jump, da_u2);
    assert_true(fabs(da) < DA_SPEED_TOL);
    assert_true(da_jump > SPEED_LO && da_jump < SPEED_HI);
    assert_true(da_u2 > U2_LO && da_u2 < U2_HI);
    double u2_speed = run_result_value(&r, "shock_speed_u2_error");
    double da_u2_speed = run_result_value(&r, "speed_depth_averaged_jump_u2_error");
    double da_u2_ratio = run_result_value(&r, "ratio_depth_averaged_jump_u2_error");
    print_message("wall shock: the jumps with the measured u2: speed %+.3e (depth-averaged "
                  "solution %+.3e, ratio %+.3e)\n", u2_speed, da_u2_speed, da_u2_ratio);
    assert_true(fabs(u2_speed) < JUMP_U2_TOL);
    assert_true(fabs(da_u2_speed) < DA_JUMP_U2_TOL && fabs(da_u2_ratio) < DA_JUMP_U2_TOL);
    /* matrix-free by default: no grid-sized matrix probed or factorised */
    assert_true(run_result_value(&r, "grid_matrices") == 0.0);
}

static void test_bad_input(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"physics.tilt=0.3", "physics.tilt"},
        {"physics.tilt=0.6", "physics.tilt"},
        {"wall_shock.depth=1e-4", "wall_shock.depth"},
        {"wall_shock.depth=0.0165", "wall_shock.depth"},
        {"wall_shock.depth=-1", "wall_shock.depth"},
        {"wall_shock.shape_factor=2", "wall_shock.shape_factor"},
        {"wall_shock.static_speed=0", "wall_shock.static_speed"},
        {"wall_shock.da_cells=2", "wall_shock.da_cells"},
        {"wall_shock.vof_cfl=0.6", "wall_shock.vof_cfl"},
        {"wall_shock.viscosity_floor=-1", "wall_shock.viscosity_floor"},
        {"wall_shock.mixture=mean", "wall_shock.mixture"},
        {"domain.lx=0.05", "domain.lx"},
        {"physics.density=2500", "physics.density"},
        {"solver.mode=steady", "solver.mode"},
        {"boundary.xhi=open", "boundary.xhi"},
        {"boundary.zlo=slip", "boundary.zlo"},
    };
    test_bad_overrides(CASE, bad, sizeof bad / sizeof bad[0]);
}

void group_wall_shock(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_coarse_shock),
    };
    RUN_GROUP(t, "wall_shock", tests);
}
