/* The bedload scene: Poiseuille flow over a granular bed, mixed-fluid model
 * (physics/bed.h), against the exact solution of Ouriemi, Aussillous &
 * Guazzelli (2009).  Tolerances from the measured study
 * (docs/validation/bedload.md), lambda 1e-6, bercovier:
 *   set A nz = 20: err_rms 3.065e-4 m/s (0.54% of u_max 0.0567), mobile layer
 *                  0.0119286 m against 0.0120997 (0.053 cells);
 *   set A nz = 40: err_rms 7.698e-5 (order 1.99 from nz = 20);
 *   set B nz = 40: err_rms 3.392e-4 (sedFoam's check accepts 1e-3), mobile
 *                  layer 0.0081276 against 0.0084289 (0.20 cells, the worst
 *                  of the eight runs of both sets).
 * The measured mobile layer is within 0.25 cells of the exact one on every
 * grid of the study, so that is the bound; err_rms bounds are the measured
 * values plus 15%. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "app/run.h"
#include "physics/bed.h"
#include "test_main.h"

#define CASE "../cases/bedload.ini"

static void run(int nov, char **ov, struct run_result *r, double *dz)
{
    struct muflow_case cs;
    test_run_case(CASE, nov, ov, &cs, r);
    *dz = cs.len[2] / cs.n[2];
    print_message("bedload: %s in %ld steps, err_rms %.4e, mobile layer %.7g (exact %.7g), "
                  "flow rate %.6g (exact %.6g)\n",
                  run_status_name(r->status), r->steps, r->errors.err_rms,
                  run_result_value(r, "mobile_layer"), run_result_value(r, "mobile_layer_exact"),
                  run_result_value(r, "flow_rate"), run_result_value(r, "flow_rate_exact"));
    assert_int_equal(r->status, STATUS_STEADY);
}

static void test_set_a(void **state)
{
    (void)state;
    struct run_result r20, r40;
    double dz20, dz40;
    char *o20[] = {"domain.nz=20", "output.fields=off"};
    char *o40[] = {"domain.nz=40", "output.fields=off"};
    run(2, o20, &r20, &dz20);
    run(2, o40, &r40, &dz40);
    /* Ouriemi et al.'s (2009) exact mobile layer for set A: delta = 0.186149 D */
    assert_true(fabs(run_result_value(&r20, "mobile_layer_exact") / (0.186149 * 0.065) - 1.0) <
                1e-5);
    assert_true(fabs(r20.errors.headline_exact - 0.0567236) < 2e-6); /* table max 0.0567236 */
    assert_true(r20.errors.err_rms <= 3.5e-4);
    assert_true(r40.errors.err_rms <= 9e-5);
    /* second order (measured 1.99) */
    assert_true(log(r20.errors.err_rms / r40.errors.err_rms) / log(2.0) >= 1.8);
    double m = run_result_value(&r20, "mobile_layer"), me = run_result_value(&r20, "mobile_layer_exact");
    assert_true(fabs(m - me) <= 0.25 * dz20);
    /* the flow rate: midpoint sum against the exact integral (measured 1.2%) */
    assert_true(fabs(run_result_value(&r20, "flow_rate") / run_result_value(&r20, "flow_rate_exact") -
                     1.0) <= 0.015);
}

static void test_set_b(void **state)
{
    (void)state;
    struct run_result r;
    double dz;
    char *ov[] = {"domain.nz=40",
                  "output.fields=off",
                  "domain.lz=0.06",
                  "physics.gravity=80",
                  "bedload.bed_height=0.045825",
                  "bedload.phi=0.595",
                  "bedload.particle_density=1050",
                  "bedload.fluid_density=950",
                  "bedload.fluid_viscosity=0.0199975",
                  "bedload.mu_s=0.24"};
    run((int)(sizeof ov / sizeof ov[0]), ov, &r, &dz);
    double me = run_result_value(&r, "mobile_layer_exact");
    assert_true(fabs(me / (0.140482 * 0.06) - 1.0) < 1e-5); /* set B (SedFoam's test) */
    assert_true(r.errors.err_rms <= 4e-4);
    assert_true(fabs(run_result_value(&r, "mobile_layer") - me) <= 0.25 * dz);
}

/* The bed's viscosity: its three parts, and its slope (the module's Newton
 * tangents) against central differences, for every regularisation, in the
 * bed, in a volume the bed's top cuts and above it. */
static void test_viscosity(void **state)
{
    (void)state;
    const struct bed_params p = {.height = 0.03, .phi = 0.6, .fluid_viscosity = 0.27,
                                 .mu_s = 0.32, .weight = 0.6 * 120.0 * 9.81};
    const double dz = 0.002, eta_e = 0.27 * 2.5;
    double t, pp;
    bed_point(&p, 0.01, dz, &t, &pp);
    assert_true(t == 1.0 && fabs(pp - p.weight * 0.02) <= 1e-12 * pp);
    bed_point(&p, 0.0305, dz, &t, &pp); /* the volume [0.0295, 0.0315] */
    assert_true(fabs(t - 0.25) < 1e-12 && fabs(pp - p.weight * 0.00025) <= 1e-9 * pp);
    bed_point(&p, 0.032, dz, &t, &pp);
    assert_true(t == 0.0 && pp == 0.0);
    const enum regularisation regs[] = {REG_SIMPLE, REG_BERCOVIER, REG_PAPANASTASIOU, REG_MC};
    const double zs[] = {0.01, 0.0295, 0.0305, 0.05};
    const double shears[] = {1e-7, 1e-6, 3e-6, 1e-3, 2.0};
    for (int ir = 0; ir < 4; ir++) {
        struct rheology r = {.law = LAW_NEWTONIAN, .reg = regs[ir], .lambda = 1e-6};
        for (int iz = 0; iz < 4; iz++)
            for (int is = 0; is < 5; is++) {
                double D = shears[is], d, dp, dm, f, df;
                double eta = bed_viscosity(&p, &r, zs[iz], dz, D, &d);
                bed_point(&p, zs[iz], dz, &t, &pp);
                rheology_yield_kernel(r.reg, D, r.lambda, &f, &df);
                double eb = eta_e + p.mu_s * pp * f;
                double want = t >= 1.0 ? eb
                              : t <= 0.0 ? 0.27
                                         : 1.0 / (t / eb + (1.0 - t) / 0.27);
                assert_true(fabs(eta / want - 1.0) <= 1e-13);
                double hs = 1e-5 * D;
                double ep = bed_viscosity(&p, &r, zs[iz], dz, D + hs, &dp);
                double em = bed_viscosity(&p, &r, zs[iz], dz, D - hs, &dm);
                double fd = (ep - em) / (2.0 * hs);
                if (t <= 0.0)
                    assert_true(d == 0.0);
                else /* truncation, plus the rounding of eta over 2 hs */
                    assert_true(fabs(fd - d) <= 1e-6 * fabs(d) + 100.0 * DBL_EPSILON * eta / hs);
            }
    }
}

/* The two-fluid model (bedload.model = two_fluid, physics/bed_two_fluid.h),
 * set A, lambda 1e-6.  Measured (docs/validation/bedload.md):
 *   nz = 20: err_rms 3.568e-4 (u^m), err_rms_particles 5.72e-5 (u^p in the
 *            bed), mobile layer (of the grains, from u^p) 0.0119213 m
 *            against 0.0120997 (0.055 cells), 11 steps;
 *   nz = 40: err_rms 8.575e-5 (order 2.06), err_rms_particles 1.93e-6,
 *            mobile layer 0.0120847 (0.009 cells), 15 steps.
 * The slip u^m - u^p in the mobile layer is the Darcy velocity that carries
 * the grains' friction gradient, mu_s phi (rho_p - rho_f) g K / eta_f =
 * 3.881e-6 m/s, on every grid; in the fixed bed u^m is the Darcy seepage
 * f K / eta_f = 1.72e-6 m/s.  Bounds: the measured values plus 15%, the
 * mobile layer within 0.25 cells as for the mixed model. */
static void test_two_fluid(void **state)
{
    (void)state;
    struct run_result r20, r40;
    double dz20, dz40;
    char *o20[] = {"domain.nz=20", "output.fields=off", "bedload.model=two_fluid"};
    char *o40[] = {"domain.nz=40", "output.fields=off", "bedload.model=two_fluid"};
    run(3, o20, &r20, &dz20);
    run(3, o40, &r40, &dz40);
    print_message("two_fluid: err_rms_particles %.4e / %.4e, slip %.6e, particle residual %.2e\n",
                  run_result_value(&r20, "err_rms_particles"),
                  run_result_value(&r40, "err_rms_particles"), run_result_value(&r40, "slip_max"),
                  run_result_value(&r40, "particle_residual"));
    assert_true(r20.errors.err_rms <= 4.1e-4);
    assert_true(r40.errors.err_rms <= 9.9e-5);
    assert_true(log(r20.errors.err_rms / r40.errors.err_rms) / log(2.0) >= 1.8);
    assert_true(run_result_value(&r20, "err_rms_particles") <= 6.6e-5);
    assert_true(run_result_value(&r40, "err_rms_particles") <= 2.2e-6);
    for (int g = 0; g < 2; g++) {
        const struct run_result *r = g ? &r40 : &r20;
        double dz = g ? dz40 : dz20;
        double m = run_result_value(r, "mobile_layer"), me = run_result_value(r, "mobile_layer_exact");
        assert_true(fabs(m - me) <= 0.25 * dz);
        /* the slip: mu_s phi (rho_p - rho_f) g / beta, beta = eta_f k_CK phi^2 /
         * ((1 - phi)^3 d^2) with d = 0.065 / 30 */
        double d = 0.065 / 30.0, beta = 0.27 * 180.0 * 0.36 / (0.064 * d * d);
        double slip = 0.32 * 0.6 * 120.0 * 9.81 / beta;
        assert_true(fabs(run_result_value(r, "slip_max") / slip - 1.0) <= 1e-6);
        assert_true(fabs(run_result_value(r, "drag_coefficient") / beta - 1.0) <= 1e-9);
        assert_true(run_result_value(r, "particle_residual") <= 1e-10);
        assert_true(r->steps <= 30);
    }
}

static void test_bad_input(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"bedload.bed_height=0.07", "bedload.bed_height"},
        {"bedload.bed_height=0", "bedload.bed_height"},
        {"bedload.phi=1", "bedload.phi"},
        {"bedload.phi=0", "bedload.phi"},
        {"bedload.particle_density=-1", "bedload.particle_density"},
        {"bedload.particle_density=1000", "bedload.particle_density"},
        {"bedload.fluid_density=0", "bedload.fluid_density"},
        {"bedload.fluid_viscosity=0", "bedload.fluid_viscosity"},
        {"bedload.mu_s=-0.3", "bedload.mu_s"},
        {"bedload.gravity=0", "bedload.gravity"},
        {"bedload.mu_s=0.1", "A = G + mu_s phi"},          /* no bed load: A <= 0 */
        {"bedload.bed_height=0.005", "mobile layer delta"}, /* delta > h_p */
        {"physics.tilt=-1.5707963267948966", "physics.tilt"},
        {"rheology.law=bingham", "rheology.law = newtonian"},
        {"bedload.model=three", "bedload.model"},
        {"bedload.kozeny=0", "bedload.kozeny"},
        {"bedload.kozeny=-180", "bedload.kozeny"},
        {"bedload.grain_diameter=0", "bedload.grain_diameter"},
        {"bedload.phi=1.5", "bedload.phi"},
        {"bedload.phi=-0.1", "bedload.phi"},
        {"bedload.bed_height=-0.01", "bedload.bed_height"},
        {"bedload.bed_height=0.065", "bedload.bed_height"},
    };
    test_bad_overrides(CASE, bad, sizeof bad / sizeof bad[0]);
    /* the two-fluid model solves the plane flow only */
    char *ov[] = {"bedload.model=two_fluid", "boundary.ylo=wall", "boundary.yhi=wall"};
    test_case_refused(CASE, 3, ov, "bedload.model = two_fluid");
    /* and the steady state only */
    char *ot[] = {"bedload.model=two_fluid", "solver.mode=transient", "solver.end_time=1"};
    test_case_refused(CASE, 3, ot, "bedload.model = two_fluid");
}

void group_bedload(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_viscosity),
        cmocka_unit_test(test_set_a),
        cmocka_unit_test(test_set_b),
        cmocka_unit_test(test_two_fluid),
        cmocka_unit_test(test_bad_input),
    };
    RUN_GROUP(t, "bedload", tests);
}
