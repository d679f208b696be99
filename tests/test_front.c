/* The granular front fed by a uniform layer (scene front, cases/front.ini)
 * on the coarse grid of the grid study: the front speed against the
 * uniform layer's mean speed, h(x) in the front's frame against the
 * depth-averaged travelling front of Pouliquen (1999), the profile behind
 * against Bagnold's; then bad input. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "app/run.h"
#include "test_main.h"

#define CASE "../cases/front.ini"

/* The grid study (make bench-front; docs/validation/front.md), 0.6 s on
 * 166 x 10, 250 x 15 and 400 x 24 cells, measured: front speed -0.65 %,
 * -0.89 %, -1.01 % against mass conservation across the front; h(x) against
 * Pouliquen's front, in % of h_inf over the front's length, rms 1.48, 1.55,
 * 1.46, over its body (exact h >= h_inf / 4) max 4.33, 4.59, 1.90; the
 * nose (the last 3 h_inf) steeper than the closed form, max 8.28, 8.35,
 * 8.82 on every grid (the precursor meets it near the critical Froude
 * number: the momentum flux the closed form leaves out); the profile
 * behind 1.95 %, 0.34 %, 0.32 % of the surface speed.  The test runs the
 * coarse grid against the claims (speed within 2 %, h's rms within 2 %,
 * the body within 5 %), the nose and the profile within the coarse grid's
 * own errors plus about a fifth (regression bounds; their grid independence
 * is the study's).  The precursor (0.67 of the bottom cell) flows as one
 * velocity node half a cell above the no-slip bed at the bed's exact
 * (Bagnold) shear rate: its flux is h_p gamma_b dz / 2, dz / (0.8 h_p)
 * times its uniform flow's 0.4 gamma_b h_p^2 (measured 0.992 and 0.990 of
 * that on 166 x 10 and 250 x 15); the bed's pressure extrapolated linearly
 * across the grains' surface gave it 7.6 times its flux on 250 x 15.
 * The depth-averaged front over the precursor (chi = 5/4, the same feed,
 * precursor and start, front.da_cells = 20; 10 and 80 within 2e-4 of
 * h_inf) differs from the closed form by 6.1 % of h_inf over the nose: the
 * momentum flux and the precursor the closed form leaves out (5.8 % at
 * 0.3 s: both fronts from the same start, compared at the same time); its
 * precursor started at 0.5 or 1.86 times its uniform flux (the 2D runs
 * carry 0.87-1.86) relaxes to it within milliseconds: the same nose to
 * 1e-6 h_inf.  The 2D nose
 * is further from it (12.9 % on 166 x 10) than from the closed form (8.3 %):
 * its steeper nose is not theirs.  Asserted: the model's nose within 10 %
 * of the closed form, the 2D nose nearer the closed form than the model. */
#define COARSE_GRID "domain.nx=166", "domain.nz=10", "domain.ly=2.145e-4"
#define SPEED_TOL 0.02
#define H_RMS_TOL 0.02
#define BODY_MAX_TOL 0.05
#define H_MAX_TOL 0.10
#define PROFILE_TOL 0.023
#define PRECURSOR_TOL 0.05
#define DA_NOSE_TOL 0.10
/* h_p: front.precursor times front.depth in cases/front.ini */
#define PRECURSOR_DEPTH (0.1 * 1.43e-3)

static void test_coarse_front(void **state)
{
    (void)state;
    char *ov[] = {COARSE_GRID};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(CASE, (int)(sizeof ov / sizeof ov[0]), ov, &cs, &r);
    double speed = run_result_value(&r, "front_speed_error");
    double rms = run_result_value(&r, "h_err_rms"), mx = run_result_value(&r, "h_err_max");
    double prof = run_result_value(&r, "profile_err_rms");
    double body = run_result_value(&r, "h_err_max_body");
    double dz = cs.len[2] / cs.n[2];
    double flux = run_result_value(&r, "precursor_flux") /
                  (run_result_value(&r, "precursor_flux_exact") * dz / (0.8 * PRECURSOR_DEPTH));
    print_message("front speed error %+.3e, h rms %.3e max %.3e (body %.3e), profile rms "
                  "%.3e, precursor flux %.4f of one node's\n", speed, rms, mx, body, prof, flux);
    assert_int_equal(r.status, STATUS_FINISHED);
    assert_true(fabs(speed) < SPEED_TOL);
    assert_true(rms < H_RMS_TOL);
    assert_true(mx < H_MAX_TOL);
    assert_true(body < BODY_MAX_TOL);
    assert_true(prof < PROFILE_TOL);
    assert_true(fabs(flux - 1.0) < PRECURSOR_TOL);
    double nose = run_result_value(&r, "h_err_max_nose");
    double nose_da = run_result_value(&r, "h_err_max_nose_depth_averaged");
    double da_model = run_result_value(&r, "depth_averaged_nose_err_max");
    print_message("nose max %.3e against the closed form, %.3e against the depth-averaged "
                  "front over the precursor (that front against the closed form %.3e)\n",
                  nose, nose_da, da_model);
    assert_true(da_model < DA_NOSE_TOL);
    assert_true(nose < nose_da);
    /* matrix-free by default: no grid-sized matrix probed or factorised */
    assert_true(run_result_value(&r, "grid_matrices") == 0.0);
}

static void test_bad_input(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"physics.tilt=0.3", "physics.tilt"},
        {"physics.tilt=0.6", "physics.tilt"},
        {"rheology.mu_inf=0.05", "rheology.mu_inf"},
        {"front.depth=1e-4", "front.depth"},
        {"front.depth=2.1e-3", "front.depth"},
        {"front.tip=0.2", "front.tip"},
        {"front.depth=-1", "front.depth"},
        {"front.vof_cfl=0.6", "front.vof_cfl"},
        {"front.precursor=0.5", "front.precursor"},
        {"front.viscosity_floor=-1", "front.viscosity_floor"},
        {"front.da_cells=2", "front.da_cells"},
        {"front.mixture=mean", "front.mixture"},
        {"physics.density=2500", "physics.density"},
        {"solver.mode=steady", "solver.mode"},
        {"boundary.xlo=wall", "boundary.xlo"},
        {"boundary.zhi=surface", "boundary.zhi"},
    };
    test_bad_overrides(CASE, bad, sizeof bad / sizeof bad[0]);
}

void group_front(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_coarse_front),
    };
    RUN_GROUP(t, "front", tests);
}
