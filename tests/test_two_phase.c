/* The two-phase module on the granular layer under air (scene bagnold2,
 * Barker & Rauter 2018, eqs. 6-11) with the interface held flat, steady, on the paper's
 * grid 50 x 100.  Tolerances from the measured errors (cases/bagnold2.ini
 * as shipped, the interface 0.56 of a cell above a face): grains err_rms
 * 1.07e-6 m/s (0.002% of the top velocity 0.0451 m/s), air 4.37e-6 m/s
 * (0.010%) with either mixture law, u at the interface 0.0226678 against
 * 0.0226634 (0.02%).  The bounds are 1e-4 (grains) and 5e-4 (air) of the
 * top velocity, four and five times the measured errors (with the grains'
 * law at the cut links' mean shear rate: 7.17e-6 and 4.68e-5). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "diagnostics/growth.h"
#include "diagnostics/profile.h"
#include "scenes/bagnold2.h"
#include "scenes/scene.h"
#include "solvers/viscous.h"
#include "test_main.h"

#define CASE "../cases/bagnold2.ini"

static void layer_under_air(const char *mixture)
{
    struct muflow_case cs;
    char ov0[64];
    snprintf(ov0, sizeof ov0, "bagnold2.mixture=%s", mixture);
    char *ov[] = {ov0};
    struct run_result r;
    test_run_case(CASE, 1, ov, &cs, &r);
    double top = r.errors.headline_exact;
    double grains = run_result_value(&r, "err_rms_grains"), air = run_result_value(&r, "err_rms_air");
    double ui = run_result_value(&r, "u_interface"), ue = run_result_value(&r, "u_interface_exact");
    print_message("bagnold2 (%s): %s in %ld steps; grains %.3e, air %.3e (u_top %.5f); u_i %.6f "
                  "(%.6f)\n", mixture, run_status_name(r.status), r.steps, grains, air, top, ui, ue);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_true(fabs(top - 0.0450736) < 1e-6); /* the exact top velocity, eq. (9) */
    assert_true(grains <= 1e-4 * top);
    assert_true(fabs(ui / ue - 1.0) <= 1e-3);
    assert_true(air <= 5e-4 * top);
    /* the interface is held: the grains' volume changes only by the rounding
     * of two sums of 5000 cells in different orders (n eps ~ 1e-12) */
    assert_true(fabs(run_result_value(&r, "mass_error")) <= 1e-12);
}

static void test_layer_under_air(void **state)
{
    (void)state;
    layer_under_air("weighted");
    layer_under_air("harmonic");
}

/* The interface anywhere inside a cell: 12 x 24 cells at 25 degrees, the
 * interface on face 13 and 0.3 and 0.7 of a cell above it (the cut link's
 * edge below the interface, and above it), both mixture laws.  Measured:
 * air err_rms 3.65e-5 m/s on the face, 4.29e-5 and 3.67e-5 off it; grains
 * 1.59e-5, 1.51e-5 and 1.67e-5.  Asserted: off the face within twice the
 * on-face error (a grid's error, which moves by tens of per cent with the
 * interface's place in the cell: the profiles' curvature at the nodes
 * changes with it).  The grains' law at the link's mean shear rate and the
 * edge's stress on both phases put 126 % of u_top (0.3) and 4.8 times the
 * on-face error (0.7) into the air. */
static void interface_in_cell(const char *mixture)
{
    const double dz = 9e-4 / 24.0, at[3] = {0.0, 0.3, 0.7};
    double grains[3], air[3];
    for (int n = 0; n < 3; n++) {
        char h0[64], mix[64];
        snprintf(h0, sizeof h0, "bagnold2.interface_height=%.17g", (13.0 + at[n]) * dz);
        snprintf(mix, sizeof mix, "bagnold2.mixture=%s", mixture);
        char *ov[] = {"domain.nx=12", "domain.nz=24", h0, mix};
        struct muflow_case cs;
        struct run_result r;
        test_run_case(CASE, 4, ov, &cs, &r);
        grains[n] = run_result_value(&r, "err_rms_grains");
        air[n] = run_result_value(&r, "err_rms_air");
        print_message("bagnold2 12 x 24 (%s), interface %.1f of a cell above face 13: %s in %ld "
                      "steps; grains %.3e, air %.3e\n", mixture, at[n],
                      run_status_name(r.status), r.steps, grains[n], air[n]);
        assert_int_equal(r.status, STATUS_STEADY);
    }
    for (int n = 1; n < 3; n++) {
        assert_true(air[n] <= 2.0 * air[0]);
        assert_true(grains[n] <= 2.0 * grains[0]);
    }
}

static void test_interface_in_cell(void **state)
{
    (void)state;
    interface_in_cell("weighted");
    interface_in_cell("harmonic");
}

static void test_bad_input(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"bagnold2.fluid_density=0", "bagnold2.fluid_density"},
        {"bagnold2.fluid_viscosity=-1", "bagnold2.fluid_viscosity"},
        {"bagnold2.mixture=arithmetic", "bagnold2.mixture"},
        {"bagnold2.interface_edges=cells", "bagnold2.interface_edges"},
        {"bagnold2.interface_height=1e-3", "bagnold2.interface_height"},
        {"bagnold2.perturbation=-1e-3", "bagnold2.perturbation"},
        {"bagnold2.start=steady", "bagnold2.start"},
        {"physics.density=1000", "physics.density"},
    };
    test_bad_overrides(CASE, bad, sizeof bad / sizeof bad[0]);
}

/* From rest in time (the lagged viscosity, T carried by the VOF transport
 * in sub-steps) to t = 1 s on the thin grid 2 x 1 x 100 at steps of 2e-3 s:
 * the layer reaches the steady state (measured: grains err_rms 1.07e-6,
 * 0.002% of the top velocity; air 4.37e-6, 0.01%), the
 * grains' volume is kept to the rounding of its sums (measured 7e-14) and
 * T stays in [0, 1]; with a factorisation kept up to 20 steps
 * (solver.preconditioner_reuse), which changes the errors below the printed
 * digits only. */
static void test_transient_from_rest(void **state)
{
    (void)state;
    char *ov[] = {"solver.mode=transient", "solver.end_time=1", "solver.dt=2e-3",
                  "domain.nx=2", "domain.lx=3.6e-5", "solver.preconditioner=cholesky",
                  "solver.preconditioner_reuse=20"};
    struct muflow_case cs;
    char err[512];
    test_load_case(&cs, CASE, 7, ov);
    struct march_state st;
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    assert_int_equal(march_run(&st, NULL, NULL), STATUS_FINISHED);
    struct run_result r;
    memset(&r, 0, sizeof r);
    run_result_from(&st, &r);
    struct profile pr;
    assert_int_equal(scene_profile(&pr, &st), 0);
    scene_profile_errors(&pr, &st, &r.errors);
    profile_free(&pr);
    case_scene(&cs)->results(&st, NULL, &r);
    double top = r.errors.headline_exact;
    double grains = run_result_value(&r, "err_rms_grains"), air = run_result_value(&r, "err_rms_air");
    double mass = run_result_value(&r, "mass_error");
    int t = fields_find(&st.fields, "tracer");
    assert_true(t >= 0);
    double lo = 1.0, hi = 0.0;
    const struct grid *g = &st.g;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++) {
            double v = st.fields.e[t].v[0][grid_idx(g, i, 0, k)];
            lo = fmin(lo, v);
            hi = fmax(hi, v);
        }
    print_message("bagnold2 transient to t = 1: grains %.3e, air %.3e (u_top %.5f), mass %.2e, "
                  "T in [%.3g, 1 + %.2g]\n", grains, air, top, mass, lo, hi - 1.0);
    assert_true(grains <= 1e-4 * top);
    assert_true(air <= 5e-4 * top);
    assert_true(fabs(mass) <= 1e-12);
    assert_true(lo >= -1e-12 && hi <= 1.0 + 1e-12);
    /* the kept factorisation served the last step: the errors above are
     * those of a fresh one every step (the same to the printed digits) */
    struct viscous_precond_info info;
    viscous_precond_info(st.viscous, &info);
    assert_int_equal(info.reused, 1);
    march_destroy(&st);
}

/* A transient run to a steady state (solver.steady_tolerance): from rest on
 * the thin grid at steps of 1e-3 s it stops at t = 0.547 s (measured), on
 * the steady mode's errors (grains 1.072e-6, air 4.373e-6 m/s) to within
 * what the stop's residual of 1e-6 leaves (measured 1.9e-7 and 3.7e-7 m/s
 * from them): asserted to 2e-5 of the top velocity (9e-7 m/s). */
static void test_transient_to_steady(void **state)
{
    (void)state;
    char *ov[] = {"solver.mode=transient", "solver.end_time=5", "solver.dt=1e-3",
                  "solver.steady_tolerance=1e-6", "domain.nx=2", "domain.lx=3.6e-5",
                  "solver.preconditioner_reuse=20"};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(CASE, 7, ov, &cs, &r);
    double grains = run_result_value(&r, "err_rms_grains"), air = run_result_value(&r, "err_rms_air");
    print_message("bagnold2 transient to steady: %s at t = %.4g in %ld steps (%s); grains %.4e, "
                  "air %.4e\n", run_status_name(r.status), r.time, r.steps, r.message, grains, air);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_true(r.time < 5.0);
    double top = r.errors.headline_exact;
    assert_true(fabs(grains - 1.072e-6) < 2e-5 * top);
    assert_true(fabs(air - 4.373e-6) < 2e-5 * top);
}

/* The fit: an exact exponential gives its rate to round-off, the window
 * takes only its samples, and fewer than three samples give NaN. */
static void test_growth_fit(void **state)
{
    (void)state;
    double t[40], a[40];
    for (int m = 0; m < 40; m++) {
        t[m] = 1e-3 * m;
        a[m] = m < 20 ? 1e-3 * exp(-500.0 * t[m]) : 1e-3 * exp(-500.0 * 0.019 + 150.0 * (t[m] - 0.019));
    }
    struct growth_fit f = growth_fit_window(t, a, 40, 0.02, 0.039);
    assert_true(fabs(f.rate - 150.0) < 1e-9 * 150.0);
    assert_int_equal(f.n, 20);
    assert_true(f.r2 > 1.0 - 1e-12);
    f = growth_fit_window(t, a, 40, 0.0, 0.039);
    assert_true(f.rate < 150.0 && f.r2 < 0.9); /* the decay spoils a window taken whole */
    f = growth_fit_window(t, a, 40, 0.0105, 0.0125);
    assert_true(isnan(f.rate));
    /* the scene's window: the second half of the record before saturation
     * (au above a_sat, or above its start when that is larger) */
    double t0, t1;
    bagnold2_growth_window(t, a, 40, 1.0, &t0, &t1);
    assert_true(t0 == 0.5 * t[39] && t1 == t[39]);
    for (int m = 0; m < 40; m++)
        a[m] = 1e-3 * exp(m < 20 ? -100.0 * t[m] : -1.9 + 150.0 * (t[m] - 0.019));
    bagnold2_growth_window(t, a, 40, 1e-6, &t0, &t1);
    assert_true(t1 == t[32] && t0 == 0.5 * t[32]); /* a[0] is first exceeded at t[32] */
    for (int m = 0; m < 40; m++)
        a[m] = 1e-5 * exp(100.0 * t[m]);
    bagnold2_growth_window(t, a, 40, 1e-5 * exp(100.0 * 0.0205), &t0, &t1);
    assert_true(t1 == t[21] && t0 == 0.5 * t[21]);
}

/* The perturbation (from rest, so the velocity is the perturbation alone):
 * divergence-free cell by cell to round-off, largest velocity the given
 * share of the exact top velocity, nothing in the air, w = 0 at the base
 * and the top; its amplitude measure sees it, the pressure's sees nothing. */
static void test_perturbation(void **state)
{
    (void)state;
    char *ov[] = {"bagnold2.perturbation=1e-3", "domain.nx=12", "domain.nz=40"};
    struct muflow_case cs;
    char err[512];
    test_load_case(&cs, CASE, 3, ov);
    struct march_state st;
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    const struct grid *g = &st.g;
    double umax = 0.0, dmax = 0.0, air = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++) {
            double u0 = st.field.velocity[0][grid_idx(g, i, 0, k)];
            double u1 = st.field.velocity[0][grid_idx(g, (i + 1) % g->n[0], 0, k)];
            double w0 = st.field.velocity[2][grid_idx(g, i, 0, k)],
                   w1 = st.field.velocity[2][grid_idx(g, i, 0, k + 1)];
            umax = fmax(umax, fmax(fabs(u0), fabs(w0)));
            dmax = fmax(dmax, fabs((u1 - u0) / g->h[0] + (w1 - w0) / g->h[2]));
            if ((k + 0.5) * g->h[2] > 5e-4 + g->h[2])
                air = fmax(air, fmax(fabs(u0), fabs(w1)));
            if (k == 0)
                assert_true(w0 == 0.0);
        }
    double top = 0.0450736; /* the exact top velocity at 25 degrees */
    double au, ap;
    bagnold2_amplitudes(&st, &au, &ap);
    print_message("perturbation: max |v| %.6e (1e-3 u_top %.6e), max |div| h / max |v| %.2e, air "
                  "%.1e, amplitudes %.3e %.3e\n", umax, 1e-3 * top, dmax * g->h[2] / umax, air, au,
                  ap);
    assert_true(fabs(umax / (1e-3 * top) - 1.0) < 1e-5);
    assert_true(dmax * g->h[2] / umax < 1e-12);
    assert_true(air == 0.0);
    assert_true(au >= 0.5 * umax && au <= 2.0 * umax);
    assert_true(ap == 0.0);
    march_destroy(&st);
    /* above mu_d no steady flow to start from or to scale by */
    char *bad[] = {"bagnold2.start=exact", "physics.tilt=0.6"};
    assert_int_equal(case_load(&cs, CASE, 2, bad, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "bagnold2.start"));
    assert_non_null(strstr(err, "accelerates"));
    bad[0] = "bagnold2.perturbation=1e-3";
    assert_int_equal(case_load(&cs, CASE, 2, bad, err, sizeof err), 2);
    /* below mu_s the air film over the static grains is the exact state and
     * its top velocity the scale; level, nothing moves: no scale */
    char *film[] = {"bagnold2.start=exact", "physics.tilt=0.3"};
    test_load_case(&cs, CASE, 2, film);
    film[0] = "bagnold2.perturbation=1e-3";
    test_load_case(&cs, CASE, 2, film);
    film[1] = "physics.tilt=0";
    test_case_refused(CASE, 2, film, "bagnold2.perturbation");
}

/* The growth rate of a run from the exact steady solution plus the
 * perturbation (1e-3 of u_top) on nx x nz cells, steps of 1e-4 s to
 * t = 0.04 s; extra: the case's overrides. */
static struct growth_fit illposed_run(const char *const *extra, int nextra, int nx, int nz)
{
    char gx[32], gz[32];
    snprintf(gx, sizeof gx, "domain.nx=%d", nx);
    snprintf(gz, sizeof gz, "domain.nz=%d", nz);
    char *ov[16] = {"solver.mode=transient", "bagnold2.start=exact", "bagnold2.perturbation=1e-3",
                    "solver.dt=1e-4", "solver.end_time=0.04", "solver.max_steps=100000", gx, gz};
    int n = 8;
    for (int m = 0; m < nextra; m++)
        ov[n++] = (char *)extra[m];
    struct muflow_case cs;
    struct run_result r;
    test_run_case(CASE, n, ov, &cs, &r);
    assert_int_equal(r.status, STATUS_FINISHED);
    struct growth_fit f;
    f.rate = run_result_value(&r, "growth_rate");
    f.r2 = run_result_value(&r, "growth_fit_r2");
    print_message("  %d x %d: growth_rate %.1f 1/s (pressure %.1f), r2 %.4f, amplitude %.2e -> "
                  "%.2e\n", nx, nz, f.rate, run_result_value(&r, "growth_rate_pressure"), f.r2,
                  run_result_value(&r, "amplitude_start"), run_result_value(&r, "amplitude_end"));
    return f;
}

/* Barker & Rauter (2018), sec. 3.1: at 32 degrees with Table 1 (the case's jop curve;
 * tan 32 = 0.625 below mu_d = 0.643, I = 3.72 above the well-posed band's
 * I_2^N = 0.846) the uniform flow is unstable, and the finer grid grows
 * faster.  Measured (dt 1e-4): 72 1/s on 12 x 40, 111 on 16 x 64; 10 x 20
 * decays (-34); the rate rises with resolution and as dt falls
 * (docs/validation/bagnold2.md).  Bounds: > 20 1/s (r2 > 0.9: an
 * exponential), and the finer at least 1.2 times the coarser. */
static void test_illposed_table1(void **state)
{
    (void)state;
    const char *tilt[] = {"physics.tilt=0.55850536063818546"};
    print_message("Table 1, 32 degrees, jop:\n");
    struct growth_fit c = illposed_run(tilt, 1, 12, 40), f = illposed_run(tilt, 1, 16, 64);
    assert_true(c.rate > 20.0 && c.r2 > 0.9);
    assert_true(f.rate > 1.2 * c.rate && f.r2 > 0.9);
}

/* Barker & Rauter (2018), sec. 3.2: at 28.5 degrees with Table 2 the jop curve grows
 * (I = 0.99 above I_2^N = 0.280) and the Barker & Gray curve (alpha 1.9,
 * mu_inf 0.05; I = 0.405 below its regularised bound 16.99) decays.
 * Measured on 12 x 40: jop 85 1/s, barker_gray -83 1/s.  Bounds: jop
 * > 20 1/s, barker_gray < -20 1/s. */
static void test_illposed_table2(void **state)
{
    (void)state;
    const char *jop[] = {"physics.tilt=0.49741883681838395", "rheology.mu_s=0.342",
                         "rheology.delta_mu=0.215", "rheology.i0=0.069",
                         "rheology.grain_diameter=1.43e-4"};
    const char *bg[] = {"physics.tilt=0.49741883681838395", "rheology.mu_s=0.342",
                        "rheology.delta_mu=0.215", "rheology.i0=0.069",
                        "rheology.grain_diameter=1.43e-4", "rheology.curve=barker_gray",
                        "rheology.alpha=1.9", "rheology.mu_inf=0.05"};
    print_message("Table 2, 28.5 degrees, jop:\n");
    struct growth_fit j = illposed_run(jop, 5, 12, 40);
    print_message("Table 2, 28.5 degrees, barker_gray:\n");
    struct growth_fit b = illposed_run(bg, 8, 12, 40);
    assert_true(j.rate > 20.0 && j.r2 > 0.9);
    assert_true(b.rate < -20.0);
}

/* ---- the exact solution off the design point (src/scenes/bagnold2.c) ---- */

/* cases/bagnold2.ini: L, h0, rho_f, eta_f, g, and the grains' curve */
#define B2_L 9e-4
#define B2_H0 5e-4
#define B2_RHO_F 1.0
#define B2_ETA_F 1.48e-5
#define B2_G 9.81

/* The exact profile written out here from the derivation, independently of
 * the scene's code: the grains' Bagnold profile at I = mu^-1(|tan tilt|)
 * (0 below mu_s), the fluid's film on top of it, the sign of the tilt. */
static double b2_exact(double tilt, double z)
{
    const double mu_s = 0.383, mu_2 = 0.643, i0 = 0.279, d = 1e-4, rho_s = 2500.0,
                 rho_g = 1500.0;
    double t = fabs(tan(tilt)), I = t > mu_s ? i0 * (t - mu_s) / (mu_2 - t) : 0.0;
    double q0 = rho_g * B2_H0 + B2_RHO_F * (B2_L - B2_H0);
    double zg = fmin(z, B2_H0), q = rho_g * (B2_H0 - zg) + B2_RHO_F * (B2_L - B2_H0);
    double u = 2.0 * I / (3.0 * d * rho_g) * sqrt(B2_G * cos(tilt) / rho_s) *
               (pow(q0, 1.5) - pow(q, 1.5));
    if (tilt < 0.0)
        u = -u;
    if (z > B2_H0)
        u += B2_RHO_F * B2_G * sin(tilt) / (2.0 * B2_ETA_F) *
             ((B2_L - B2_H0) * (B2_L - B2_H0) - (B2_L - z) * (B2_L - z));
    return u;
}

/* Runs the case with the overrides on 4 x 1 x 100 (the flow is uniform
 * along x) and returns its status, its profile in pr (caller frees) and
 * its errors in r. */
static enum run_status b2_run(int n, char **ov, struct profile *pr, struct run_result *r)
{
    struct muflow_case cs;
    char err[512];
    char *all[8] = {"domain.nx=4"};
    for (int m = 0; m < n; m++)
        all[m + 1] = ov[m];
    test_load_case(&cs, CASE, n + 1, all);
    struct march_state st;
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    enum run_status status = march_run(&st, NULL, NULL);
    memset(r, 0, sizeof *r);
    run_result_from(&st, r);
    assert_int_equal(scene_profile(pr, &st), 0);
    scene_profile_errors(pr, &st, &r->errors);
    case_scene(&cs)->results(&st, NULL, r);
    march_destroy(&st);
    return status;
}

/* Below the yield angle (tan 0.2 = 0.203 < mu_s = 0.383) the grains are at
 * rest and the air a film driven by gravity over the static bed, u_top =
 * rho_f g sin(tilt) (L - h0)^2 / (2 eta_f) = 0.0105348 m/s.  The run ends
 * steady (its residual stalls at 4e-9 at the base of the plug, round-off of
 * the plug's viscosity mu p / lambda, which must not end it unsteady) on the
 * film: measured air err_rms 1.72e-6 (0.016% of u_top, the cell the
 * interface cuts), the grains' creep 1.8e-10.  Bounds: the exact top to
 * round-off, the air to 5e-4 of u_top (3x), the grains to 1e-7 of it. */
static void test_below_yield_film(void **state)
{
    (void)state;
    char *ov[] = {"physics.tilt=0.2"};
    struct profile pr;
    struct run_result r;
    enum run_status status = b2_run(1, ov, &pr, &r);
    double top = b2_exact(0.2, B2_L);
    double h = B2_L / 100, air2 = 0.0, grains = 0.0;
    int nair = 0;
    for (int l = 0; l < pr.n; l++) {
        double z = pr.coord[l], e = pr.velocity[l] - b2_exact(0.2, z);
        if (z < B2_H0 - h)
            grains = fmax(grains, fabs(pr.velocity[l]));
        else if (z > B2_H0 + h) {
            air2 += e * e;
            nair++;
        }
    }
    double air = sqrt(air2 / nair);
    print_message("bagnold2 tilt 0.2: %s in %ld steps (%s); u_top exact %.7g (film %.7g), air "
                  "err_rms %.3e, grains max |u| %.2e\n", run_status_name(status), r.steps,
                  r.message, r.errors.headline_exact, top, air, grains);
    profile_free(&pr);
    assert_int_equal(status, STATUS_STEADY);
    assert_true(fabs(top / 0.0105348 - 1.0) < 1e-5);
    assert_true(fabs(r.errors.headline_exact - top) <= 1e-12 * top);
    assert_true(air <= 5e-4 * top);
    assert_true(grains <= 1e-7 * top);
    assert_true(r.errors.err_rms <= 5e-4 * top);
}

/* A negative tilt is the mirror image: the profile at -0.4 is minus the one
 * at +0.4 (to the round-off of the march: 4e-14 measured), and so is
 * the exact solution (tan 0.4 = 0.423 just above mu_s: the grains flow).
 * Measured: err_rms 1.13e-5 at either sign (0.038% of |u_top| 0.0294); an
 * exact solution not mirrored (0 at -0.4) is 1.6e-2 off. */
static void test_negative_tilt_mirror(void **state)
{
    (void)state;
    char *up[] = {"physics.tilt=0.4"}, *down[] = {"physics.tilt=-0.4"};
    struct profile pu, pd;
    struct run_result ru, rd;
    assert_int_equal(b2_run(1, up, &pu, &ru), STATUS_STEADY);
    assert_int_equal(b2_run(1, down, &pd, &rd), STATUS_STEADY);
    double top = b2_exact(0.4, B2_L), mirror = 0.0;
    for (int l = 0; l < pu.n; l++)
        mirror = fmax(mirror, fabs(pu.velocity[l] + pd.velocity[l]));
    print_message("bagnold2 tilt -0.4: u_top %.7g exact %.7g (+0.4: %.7g, %.7g); err_rms %.3e "
                  "(+0.4: %.3e); max |u(+) + u(-)| %.1e\n", rd.errors.headline,
                  rd.errors.headline_exact, ru.errors.headline, ru.errors.headline_exact,
                  rd.errors.err_rms, ru.errors.err_rms, mirror);
    profile_free(&pu);
    profile_free(&pd);
    assert_true(fabs(ru.errors.headline_exact - top) <= 1e-12 * top);
    assert_true(rd.errors.headline_exact == -ru.errors.headline_exact);
    assert_true(mirror <= 1e-10 * top); /* measured 4e-14 */
    assert_true(fabs(rd.errors.err_rms - ru.errors.err_rms) <= 1e-9 * top);
    assert_true(rd.errors.err_rms <= 1e-3 * top);
}

/* Where no exact solution exists the reference is NaN and the run says
 * why: above mu_s + delta_mu (the layer accelerates), walls across y, a
 * confining pressure in flowing grains (not in static ones: the film stays
 * exact). */
static void test_no_exact_said(void **state)
{
    (void)state;
    /* walls across y: the Cholesky (the case's Fourier blocks need y periodic) */
    static const char *const cases[][4] = {
        {"physics.tilt=0.6", "domain.nx=4", "solver.preconditioner=fourier", "accelerates"},
        {"boundary.ylo=wall", "boundary.yhi=wall", "solver.preconditioner=cholesky", "across y"},
        {"physics.confining_pressure=10", "domain.nx=4", "solver.preconditioner=fourier",
         "confining_pressure"},
    };
    for (size_t m = 0; m < sizeof cases / sizeof cases[0]; m++) {
        struct muflow_case cs;
        char err[512];
        char *ov[] = {(char *)cases[m][0], (char *)cases[m][1], (char *)cases[m][2]};
        test_load_case(&cs, CASE, 3, ov);
        assert_true(isnan(scene_exact_at(&cs, B2_L)));
        struct march_state st;
        assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
        struct run_result r;
        memset(&r, 0, sizeof r);
        case_scene(&cs)->results(&st, NULL, &r);
        march_destroy(&st);
        const char *why = NULL;
        for (int v = 0; v < r.values.n; v++)
            if (strcmp(r.values.v[v].key, "no_exact_solution") == 0)
                why = r.values.v[v].text;
        print_message("%s: %s | %s\n", cases[m][0], why ? why : "(none)", r.scene_line);
        assert_non_null(why);
        assert_non_null(strstr(r.scene_line, "no exact solution"));
        assert_non_null(strstr(r.scene_line, cases[m][3]));
    }
    struct muflow_case cs;
    char *ov[] = {"physics.tilt=0.2", "physics.confining_pressure=10"};
    test_load_case(&cs, CASE, 2, ov);
    assert_true(fabs(scene_exact_at(&cs, B2_L) - b2_exact(0.2, B2_L)) <= 1e-12 * 0.0105);
}

/* lambda 1e-8 from rest: the whole layer starts as a plug of viscosity
 * mu p / lambda ~ 2e8 Pa s.  With the face densities of the cells' means
 * the hydrostatic pressure left a force at the interface: as the plug
 * yielded, the round-off grew into a flow across x whose interface pressure
 * the projection's correction (rho / dt) phi could not relax at large
 * pseudo-time steps (the residual stalled at 6.8e-4 in the z-momentum at
 * the interface, 16 x 100).  With the faces' sub-cell shares it is steady in
 * 10 steps on lambda 1e-6's profile (err_rms 3.0098e-6 both).  The run must
 * end steady on that profile, or say that it stalls there and is no
 * round-off; by stages (solver.continuation = 100) it is steady too. */
static void test_small_lambda(void **state)
{
    (void)state;
    char *ref_ov[] = {"domain.nx=16"}, *ov[] = {"domain.nx=16", "rheology.lambda=1e-8"},
         *st_ov[] = {"domain.nx=16", "rheology.lambda=1e-8", "solver.continuation=100"};
    struct muflow_case cs;
    struct run_result ref, r, rs;
    test_run_case(CASE, 1, ref_ov, &cs, &ref);
    test_run_case(CASE, 2, ov, &cs, &r);
    test_run_case(CASE, 3, st_ov, &cs, &rs);
    print_message("bagnold2 16 x 100, lambda 1e-8: %s in %ld steps: %s; err_rms %.4e (1e-6: "
                  "%.4e; by stages: %s in %ld steps, %.4e)\n", run_status_name(r.status),
                  r.steps, r.message, r.errors.err_rms, ref.errors.err_rms,
                  run_status_name(rs.status), rs.steps, rs.errors.err_rms);
    assert_int_equal(ref.status, STATUS_STEADY);
    assert_true(fabs(r.errors.err_rms / ref.errors.err_rms - 1.0) < 1e-3);
    if (r.status != STATUS_STEADY) {
        assert_int_equal(r.status, STATUS_UNSTEADY);
        const char *at = strstr(r.message, "beyond the round-off its velocities carry, largest in "
                                           "the z-momentum at (");
        assert_non_null(at);
        double x, y, z;
        assert_int_equal(sscanf(strchr(at, '(') + 1, "%lf, %lf, %lf", &x, &y, &z), 3);
        assert_true(fabs(z - B2_H0) <= 2.0 * B2_L / 100); /* at the interface */
        assert_true(strtod(strstr(r.message, "stalls at ") + 10, NULL) > 1e-6);
    }
    assert_int_equal(rs.status, STATUS_STEADY);
    assert_true(fabs(rs.errors.err_rms / ref.errors.err_rms - 1.0) < 1e-3);
}

void group_two_phase(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layer_under_air),
        cmocka_unit_test(test_interface_in_cell),
        cmocka_unit_test(test_transient_to_steady),
        cmocka_unit_test(test_transient_from_rest),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_growth_fit),
        cmocka_unit_test(test_perturbation),
        cmocka_unit_test(test_illposed_table1),
        cmocka_unit_test(test_illposed_table2),
        cmocka_unit_test(test_below_yield_film),
        cmocka_unit_test(test_negative_tilt_mirror),
        cmocka_unit_test(test_no_exact_said),
        cmocka_unit_test(test_small_lambda),
    };
    RUN_GROUP(t, "two_phase", tests);
}
