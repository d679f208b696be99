/* The nonlocal granular fluidity (rheology.law = ngf, physics/ngf.h) on a
 * layered flow down a rough incline (cases/ngf_incline.ini; the grid study is
 * bench/ngf_hstop.py, docs/validation/ngf.md):
 *
 * - the line solver of its fluidity against the screened equation's closed
 *   form, second order;
 * - a layer below its stopping height stops: its velocity is lambda's
 *   creep, proportional to lambda; one above it flows;
 * - the stopping height by bisection on 10 and 20 cells against Kamrin &
 *   Henann's (2015) closed form (pi / 2) A d / sqrt(tan(theta) - mu_s):
 *   within 5%, converging at second order;
 * - a plane Couette flow without gravity (uniform p and mu): the half width
 *   of its wall layers against the closed form of the fluidity equation,
 *   g / g_bulk = 1 - (3/2) sech^2(kappa (z + s0) / 2), kappa = sqrt(mu - mu_s)
 *   / (A d), sech^2(kappa s0 / 2) = 2/3 (g = 0 on the wall): |D| falls to half
 *   its bulk value at 0.9754 / kappa from the wall;
 * - the vertical chute (cases/ngf_chute.ini): the creep length of its plug,
 *   where the fluidity grows by e from the centre, against the Airy closed
 *   form of the linear fluidity equation there (scenes/ngf_chute.c);
 * - planar shear under gravity (cases/ngf_shear.ini): the decay length of the
 *   creeping layer's fluidity at H / 4 against its linear equation with the
 *   measured stress (scenes/ngf_shear.c);
 * - the steady iteration's acceleration: Picard's steady state in a bounded
 *   number of steps, transient steps untouched;
 * - the law's input checks name the key. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "io/output.h"
#include "solvers/line_screened.h"
#include "test_main.h"

#define NGF_CASE "../cases/ngf_incline.ini"
#define MU_S 0.3819
#define NONLOCAL_A 0.48
#define THETA_25 0.4363323129985824

static double h_stop_closed(double theta)
{
    return 0.5 * M_PI * NONLOCAL_A / sqrt(tan(theta) - MU_S);
}

/* -a2 g'' + c g = s on (0, H), g(0) = 0, g'(H) = 0:
 * g = (s / c) (1 - cosh(k (H - z)) / cosh(k H)), k = sqrt(c / a2). */
static double line_error(int n)
{
    enum { NMAX = 80 };
    const double H = 2.0, a2 = 0.2304, c0 = 0.3819, s0 = 1.0, h = H / n;
    double hc[NMAX], hf[NMAX + 1], c[NMAX], s[NMAX], work[NMAX], x[NMAX];
    for (int k = 0; k < n; k++) {
        hc[k] = h;
        c[k] = c0;
        s[k] = s0;
    }
    for (int k = 0; k <= n; k++)
        hf[k] = h;
    struct line_screened L = {n, a2, hc, hf, LINE_ZERO, LINE_NO_FLUX};
    assert_int_equal(line_screened_solve(&L, c, s, work, x), 0);
    double kk = sqrt(c0 / a2), err = 0.0;
    for (int k = 0; k < n; k++) {
        double z = (k + 0.5) * h;
        double exact = s0 / c0 * (1.0 - cosh(kk * (H - z)) / cosh(kk * H));
        err = fmax(err, fabs(x[k] - exact));
    }
    return err;
}

static void test_line_solver(void **state)
{
    (void)state;
    double e1 = line_error(20), e2 = line_error(40), e3 = line_error(80);
    double o1 = log2(e1 / e2), o2 = log2(e2 / e3);
    print_message("ngf line solver: max error %.3e %.3e %.3e, orders %.2f %.2f\n", e1, e2, e3,
                  o1, o2);
    /* cell-centred differences with the wall's mirror ghost: second order */
    assert_true(o1 > 1.9 && o2 > 1.9);
    /* s / c = 2.6: 1.3e-4 relative on 80 cells (measured 3.3e-4 absolute) */
    assert_true(e3 < 5e-4);
}

/* The incline at 25 degrees, H = ratio H_stop, nz cells, steady from rest:
 * the surface velocity. */
static double steady_surface(double ratio, int nz, const char *lambda, enum run_status *status)
{
    char lz[64], n[32], lam[64];
    snprintf(lz, sizeof lz, "domain.lz=%.17g", ratio * h_stop_closed(THETA_25));
    snprintf(n, sizeof n, "domain.nz=%d", nz);
    snprintf(lam, sizeof lam, "rheology.lambda=%s", lambda);
    char *ov[] = {lz, n, lam, "solver.max_steps=20000"};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(NGF_CASE, 4, ov, &cs, &r);
    *status = r.status;
    return run_result_value(&r, "u_surface");
}

/* Below the stopping height the layer creeps at lambda's scale (eta = p /
 * (g + lambda), g = O(lambda)): u_surface proportional to lambda; above it,
 * it flows at the speed of its weight. */
static void test_stops_and_flows(void **state)
{
    (void)state;
    enum run_status s1, s2, s3;
    double creep8 = steady_surface(0.8, 10, "1e-8", &s1);
    double creep6 = steady_surface(0.8, 10, "1e-6", &s2);
    double flow = steady_surface(1.2, 10, "1e-8", &s3);
    double scale = sqrt(0.8 * h_stop_closed(THETA_25));
    print_message("ngf 0.8 H_stop: u_surface %.4e (lambda 1e-8), %.4e (1e-6), ratio %.4f; "
                  "1.2 H_stop: %.4e\n",
                  creep8, creep6, creep6 / creep8, flow);
    assert_int_equal(s1, STATUS_STEADY);
    assert_int_equal(s2, STATUS_STEADY);
    assert_int_equal(s3, STATUS_STEADY);
    assert_true(creep8 > 0.0 && creep8 < 1e-6 * scale);
    /* linear in lambda while g = O(lambda) << the flowing fluidity */
    assert_true(fabs(creep6 / creep8 / 100.0 - 1.0) < 1e-3);
    assert_true(flow > 1e-2 * scale);
}

/* u_surface after `steps` Picard iterations from rest (transient steps of
 * 1e6, each one an equilibrium of the lagged viscosity). */
static double picard_surface(double H, int nz, int steps)
{
    char lz[64], n[32], m[48];
    snprintf(lz, sizeof lz, "domain.lz=%.17g", H);
    snprintf(n, sizeof n, "domain.nz=%d", nz);
    snprintf(m, sizeof m, "solver.max_steps=%d", steps);
    char *ov[] = {lz, n, m, "rheology.lambda=1e-12", "solver.mode=transient", "solver.dt=1e6",
                  "solver.end_time=1e300"};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(NGF_CASE, 7, ov, &cs, &r);
    return run_result_value(&r, "u_surface");
}

/* The stopping height on nz cells: bisection in H, a layer flowing when its
 * least stable mode grows, u_2M / u_M = r^M + 1 > 2 from rest (the linear
 * Picard iteration at lambda's scale), or when it has reached its flow. */
static double h_stop_bisect(int nz)
{
    double hs = h_stop_closed(THETA_25), lo = 0.8 * hs, hi = 1.2 * hs;
    const int M = 600;
    for (int it = 0; it < 9; it++) {
        double mid = 0.5 * (lo + hi);
        double u1 = picard_surface(mid, nz, M), u2 = picard_surface(mid, nz, 2 * M);
        if (u2 > 1e-4 * sqrt(mid) || u2 > 2.0 * u1)
            hi = mid;
        else
            lo = mid;
    }
    return 0.5 * (lo + hi);
}

static void test_stopping_height(void **state)
{
    (void)state;
    double hs = h_stop_closed(THETA_25);
    double h10 = h_stop_bisect(10), h20 = h_stop_bisect(20);
    double e10 = h10 / hs - 1.0, e20 = h20 / hs - 1.0;
    print_message("ngf H_stop at 25 deg: closed form %.5f, 10 cells %.5f (%+.2f%%), 20 cells "
                  "%.5f (%+.2f%%), order %.2f\n",
                  hs, h10, 100 * e10, h20, 100 * e20, log2(fabs(e10 / e20)));
    /* the brief's 5%; the bisection's own bracket is 0.4 H_stop / 2^9 */
    assert_true(fabs(e10) < 0.05 && fabs(e20) < 0.05);
    /* second order (bench/ngf_hstop.py: 4.2%, 0.84%, 0.18% at 22 degrees) */
    assert_true(fabs(e10 / e20) > 3.0);
}

/* The Couette flow between a wall and a lid at 1.5, H = 40 d, p = 1 without
 * gravity, on nz cells: the measured half width over the closed form's,
 * minus 1.  mu = mu_s + b I of the bulk's shear rate (its local law). */
static double wall_layer_error(int nz)
{
    struct test_run_dir dir;
    test_run_dir_make(&dir, "ngf_couette");
    char n[32];
    snprintf(n, sizeof n, "domain.nz=%d", nz);
    /* at the case's tolerance 1e-10 the march stopped after 43 steps with the
     * two wall layers still unequal (on 80 cells); 1e-15 takes 142 */
    char *ov[] = {dir.output, n, "physics.tilt=0", "physics.gravity=0",
                  "physics.confining_pressure=1", "boundary.zhi=lid", "boundary.lid_velocity=1.5",
                  "domain.lz=40", "solver.tolerance=1e-15", "solver.max_steps=5000",
                  "output.fields=off", "output.quiet=on"};
    struct muflow_case cs;
    struct run_result r;
    test_load_case(&cs, NGF_CASE, 12, ov);
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_STEADY);
    char header[256];
    int rows, cols;
    double *v = test_read_csv_numbers(dir.dir, "profile.csv", header, sizeof header, &rows, &cols);
    int cz = test_csv_column(header, "z"), cd = test_csv_column(header, "shear_rate");
    assert_true(rows == nz && cz >= 0 && cd >= 0);
    double bulk = 0.5 * (v[(nz / 2 - 1) * cols + cd] + v[(nz / 2) * cols + cd]);
    double z_half = NAN;
    for (int k = 1; k < nz / 2 && isnan(z_half); k++) {
        double d0 = v[(k - 1) * cols + cd], d1 = v[k * cols + cd];
        double z0 = v[(k - 1) * cols + cz], z1 = v[k * cols + cz];
        if (d1 >= 0.5 * bulk)
            z_half = z0 + (0.5 * bulk - d0) * (z1 - z0) / (d1 - d0);
    }
    free(v);
    test_run_dir_remove(&dir);
    double inertial = bulk * sqrt(cs.rheo.grain_density / 1.0) * cs.rheo.grain_diameter;
    double kappa =
        sqrt(cs.rheo.nonlocal_b * inertial) / (cs.rheo.nonlocal_a * cs.rheo.grain_diameter);
    /* sech^2 = 1/3 at kappa (z + s0) / 2 = acosh(sqrt 3), sech^2 = 2/3 at z = 0 */
    double exact = 2.0 * (acosh(sqrt(3.0)) - acosh(sqrt(1.5))) / kappa;
    print_message("ngf Couette on %d cells: |D| bulk %.6f, kappa %.5f, half width %.5f, closed "
                  "form %.5f (%+.3f%%)\n",
                  nz, bulk, kappa, z_half, exact, 100.0 * (z_half / exact - 1.0));
    return z_half / exact - 1.0;
}

/* The wall layers' width: 4.8%, 0.73%, 0.077% on 40, 80, 160 cells (h = 1,
 * 1/2, 1/4 d, the layer's half width 2.04 d). */
static void test_couette_wall_layer(void **state)
{
    (void)state;
    double e80 = wall_layer_error(80), e160 = wall_layer_error(160);
    assert_true(fabs(e80) < 0.02 && fabs(e160) < 0.005);
    assert_true(fabs(e80 / e160) > 4.0);
}

/* The shipped layer (H = 10 d, 25 degrees) from rest on 160 cells: its
 * first steps only creep (g = 0 at the start: max |u| 3.6e-6) and its
 * residual passes the sane bound while the fluidity develops; the growth
 * to the flow (0.94) is not a blow-up.  Steady, and u_surface within 0.5 %
 * of the 40 cells' (measured: 0.93652 and 0.93732, 0.086 %). */
static void test_fine_layer_from_rest(void **state)
{
    (void)state;
    char *coarse[] = {"domain.nz=40"}, *fine[] = {"domain.nz=160"};
    struct muflow_case cs;
    struct run_result r40, r160;
    test_run_case(NGF_CASE, 1, coarse, &cs, &r40);
    test_run_case(NGF_CASE, 1, fine, &cs, &r160);
    double u40 = run_result_value(&r40, "u_surface"), u160 = run_result_value(&r160, "u_surface");
    print_message("ngf incline from rest: 40 cells %s, u_surface %.6f; 160 cells %s, %.6f: %s\n",
                  run_status_name(r40.status), u40, run_status_name(r160.status), u160,
                  r160.message);
    assert_int_equal(r40.status, STATUS_STEADY);
    assert_int_equal(r160.status, STATUS_STEADY);
    assert_true(fabs(u160 - u40) < 5e-3 * u40);
}

#define NGF_CHUTE_CASE "../cases/ngf_chute.ini"

/* The steady run of file on nz cells: its measure name against the
 * reference the scene computes (name_exact), relative error returned. */
static double steady_error(const char *file, int nz, const char *name)
{
    char n[32], key[64];
    snprintf(n, sizeof n, "domain.nz=%d", nz);
    char *ov[] = {n};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(file, 1, ov, &cs, &r);
    assert_int_equal(r.status, STATUS_STEADY);
    snprintf(key, sizeof key, "%s_error", name);
    double e = run_result_value(&r, key);
    snprintf(key, sizeof key, "%s_exact", name);
    print_message("%s on %d cells: %s %.6f, reference %.6f (%+.3f%%)\n", cs.name, nz, name,
                  run_result_value(&r, name), run_result_value(&r, key), 100.0 * e);
    return e;
}

/* The chute's creep length over 40 d against the closed form's (1.31468 d):
 * measured +12.3%, +2.72%, +0.62%, +0.17% on 40, 80, 160, 320 cells (h = 1,
 * 1/2, 1/4, 1/8 d against a creep length of 1.31 d): second order.  The
 * shipped 80 cells within 5%, 160 within 1.5%, the error falling more than
 * 3 times. */
static void test_chute_creep_length(void **state)
{
    (void)state;
    double e80 = steady_error(NGF_CHUTE_CASE, 80, "creep_length"),
           e160 = steady_error(NGF_CHUTE_CASE, 160, "creep_length");
    assert_true(fabs(e80) < 0.05 && fabs(e160) < 0.015);
    assert_true(fabs(e80 / e160) > 3.0);
    char *tilted[] = {"physics.tilt=1.5"};
    test_case_refused(NGF_CHUTE_CASE, 1, tilted, "physics.tilt");
    char *lid[] = {"boundary.zhi=lid"};
    test_case_refused(NGF_CHUTE_CASE, 1, lid, "boundary.zhi");
}

#define NGF_SHEAR_CASE "../cases/ngf_shear.ini"

/* The sheared layer's run on nz cells under the confining pressure p_c: the
 * decay length's errors against its linear equation and against the
 * cooperativity length xi. */
static void shear_errors(int nz, double p_c, double *e_equation, double *e_xi)
{
    char n[32], p[64];
    snprintf(n, sizeof n, "domain.nz=%d", nz);
    snprintf(p, sizeof p, "physics.confining_pressure=%g", p_c);
    char *ov[] = {n, p};
    struct muflow_case cs;
    struct run_result r;
    test_run_case(NGF_SHEAR_CASE, 2, ov, &cs, &r);
    assert_int_equal(r.status, STATUS_STEADY);
    *e_equation = run_result_value(&r, "decay_length_error");
    *e_xi = run_result_value(&r, "decay_length_xi_error");
    print_message("ngf_shear on %d cells, p_c %g: decay length %.6f, its linear equation's %.6f "
                  "(%+.3f%%), xi %.6f (%+.3f%%); the velocity's %.6f (%+.3f%% of xi)\n",
                  nz, p_c, run_result_value(&r, "decay_length"),
                  run_result_value(&r, "decay_length_exact"), 100.0 * *e_equation,
                  run_result_value(&r, "decay_length_xi_exact"), 100.0 * *e_xi,
                  run_result_value(&r, "velocity_decay_length"),
                  100.0 * run_result_value(&r, "velocity_decay_length_error"));
}

/* The sheared layer's decay length at H / 4 over 20 d against its linear
 * equation's (1.2923 d with the 80 cells' stress): measured +5.57%, +1.42%,
 * +0.35%, +0.080% on 40, 80, 160, 320 cells (h = 1/2 .. 1/16 d against a
 * decay length of 1.29 d): second order.  40 cells within 10%, the shipped
 * 80 within 2.5%, the error falling more than 3 times.
 * Against the published width of a creeping zone, the cooperativity length
 * xi = A d / sqrt(mu_s - mu) of Kamrin & Koval 2012 and Henann & Kamrin 2013
 * at the mu of H / 4 (1.3224 d): +3.15%, -0.89%, -1.93%, -2.19%, -2.26% on
 * 40 .. 640 cells, the grids' error above (second order) on the model's own
 * -2.3% (mu grows towards the band: the WKB term xi' / 2 makes it -2.45%).
 * Bounds: 40 cells within 5% (the grid's +5.6% on the -2.3%), 80 within
 * 2% (+1.4% on it), 640 cells' -2.26% inside both; the target is 10%.
 * Across mu, 80 cells under p_c 12 and 40 (mu 0.144 and 0.327 at H / 4, xi
 * 0.98 and 2.04 d): +0.21% and -4.81%; on 320 cells -0.73% and -6.25%, the
 * WKB term's -0.87% and -6.31%.  Bounds 2% (under p_c 12) and 10%. */
static void test_shear_decay_length(void **state)
{
    (void)state;
    double e40, e80, x40, x80, e_lo, x_lo, e_hi, x_hi;
    shear_errors(40, 20.0, &e40, &x40);
    shear_errors(80, 20.0, &e80, &x80);
    assert_true(fabs(e40) < 0.10 && fabs(e80) < 0.025);
    assert_true(fabs(e40 / e80) > 3.0);
    assert_true(fabs(x40) < 0.05 && fabs(x80) < 0.02);
    shear_errors(80, 12.0, &e_lo, &x_lo);
    shear_errors(80, 40.0, &e_hi, &x_hi);
    assert_true(fabs(e_lo) < 0.025 && fabs(e_hi) < 0.025);
    assert_true(fabs(x_lo) < 0.02 && fabs(x_hi) < 0.10);
    char *tilted[] = {"physics.tilt=0.1"};
    test_case_refused(NGF_SHEAR_CASE, 1, tilted, "physics.tilt");
    char *light[] = {"physics.confining_pressure=10"};
    test_case_refused(NGF_SHEAR_CASE, 1, light, "physics.confining_pressure");
}

/* The box's multigrid (rheology.fluidity_solver = multigrid) on the three
 * layered cases against the z lines: the lateral part of lap(g) is zero on
 * a flow uniform along x, so both solve the same equation, the multigrid to
 * a relative residual of 1e-12.  Its round-off along x (the red-black
 * sweeps of two periodic columns) leaves a divergence of 1e-15 that the
 * lines' identical columns do not, and the march stops at that round-off
 * (residual 1e-7 .. 1e-5, not the lines' 1e-9 .. 1e-6).  Measured relative
 * differences: u_surface 3.5e-12, u_centre 5.9e-12, u_mid 8.7e-10, the
 * creep and decay lengths 0 in their 10 digits; bound 1e-7, above the
 * largest a hundredfold (the stalls' residuals differ by up to 14 times). */
static void test_fluidity_multigrid(void **state)
{
    (void)state;
    static const struct {
        const char *file, *names[2];
    } cases[] = {{NGF_CASE, {"u_surface", NULL}},
                 {NGF_CHUTE_CASE, {"u_centre", "creep_length"}},
                 {NGF_SHEAR_CASE, {"u_mid", "decay_length"}}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char *lines[] = {"rheology.fluidity_solver=lines"};
        char *box[] = {"rheology.fluidity_solver=multigrid"};
        struct muflow_case cs;
        struct run_result rl, rm;
        test_run_case(cases[c].file, 1, lines, &cs, &rl);
        test_run_case(cases[c].file, 1, box, &cs, &rm);
        assert_int_equal(rl.status, STATUS_STEADY);
        assert_int_equal(rm.status, STATUS_STEADY);
        for (int v = 0; v < 2 && cases[c].names[v]; v++) {
            double l = run_result_value(&rl, cases[c].names[v]);
            double m = run_result_value(&rm, cases[c].names[v]);
            print_message("ngf fluidity by multigrid, %s: %s %.12g (lines %.12g, %.2e relative)\n",
                          cases[c].file, cases[c].names[v], m, l, fabs(m / l - 1.0));
            assert_true(fabs(m / l - 1.0) < 1e-7);
        }
    }
    /* walls along x: the lines refuse them, the multigrid (auto) takes them */
    char *walls_lines[] = {"boundary.xlo=wall", "boundary.xhi=wall",
                           "rheology.fluidity_solver=lines"};
    test_case_refused(NGF_CASE, 3, walls_lines, "rheology.fluidity_solver");
    char *banded[] = {"rheology.fluidity_solver=multigrid", "domain.z_band=0 1 0.05"};
    test_case_refused(NGF_CASE, 2, banded, "domain.z_band");
}

/* The steady iteration's acceleration (rheology.fluidity_anderson, physics/
 * fluidity_anderson.h) against the plain Picard iteration (depth 0) on the
 * three shipped cases: the same steady state, each case's headline and
 * measures within 1e-7 relative (the criterion stops both within their
 * tolerance 1e-10 .. 1e-12, or where the residual stalls at its round-off,
 * 6e-7 and 1.2e-6 on the shear; measured: u_surface 2.5e-11, u_centre 3.8e-13,
 * u_mid 2.1e-10 relative, the creep and decay lengths 0 in their 10 digits),
 * and in a bounded number of steps (measured 47, 50, 40 against Picard's
 * 252, 189, 108; bounds 60, 60, 50, and less than half of Picard's).  A transient run is not accelerated:
 * 30 steps of 1e6 alike to the bit. */
static void test_accelerated_steady(void **state)
{
    (void)state;
    static const struct {
        const char *file, *names[2];
        long max_steps;
    } cases[] = {{NGF_CASE, {"u_surface", NULL}, 60},
                 {NGF_CHUTE_CASE, {"u_centre", "creep_length"}, 60},
                 {NGF_SHEAR_CASE, {"u_mid", "decay_length"}, 50}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char *plain[] = {"rheology.fluidity_anderson=0"};
        struct muflow_case cs;
        struct run_result rp, ra;
        test_run_case(cases[c].file, 1, plain, &cs, &rp);
        test_run_case(cases[c].file, 0, NULL, &cs, &ra);
        assert_int_equal(rp.status, STATUS_STEADY);
        assert_int_equal(ra.status, STATUS_STEADY);
        print_message("ngf accelerated, %s: %ld steps (Picard %ld)\n", cases[c].file, ra.steps,
                      rp.steps);
        assert_true(ra.steps <= cases[c].max_steps && 2 * ra.steps < rp.steps);
        for (int v = 0; v < 2 && cases[c].names[v]; v++) {
            double p = run_result_value(&rp, cases[c].names[v]);
            double a = run_result_value(&ra, cases[c].names[v]);
            print_message("    %s %.12g (Picard %.12g, %.2e relative)\n", cases[c].names[v], a, p,
                          fabs(a / p - 1.0));
            assert_true(fabs(a / p - 1.0) < 1e-7);
        }
    }
    char *t0[] = {"rheology.fluidity_anderson=0", "solver.mode=transient", "solver.dt=1e6",
                  "solver.end_time=1e300", "solver.max_steps=30"};
    char *t5[] = {"rheology.fluidity_anderson=5", "solver.mode=transient", "solver.dt=1e6",
                  "solver.end_time=1e300", "solver.max_steps=30"};
    struct muflow_case cs;
    struct run_result r0, r5;
    test_run_case(NGF_CASE, 5, t0, &cs, &r0);
    test_run_case(NGF_CASE, 5, t5, &cs, &r5);
    assert_true(run_result_value(&r0, "u_surface") == run_result_value(&r5, "u_surface"));
}

static void test_bad_input(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {"rheology.lambda=0", "rheology.lambda"},
        {"rheology.nonlocal_a=0", "rheology.nonlocal_a"},
        {"rheology.nonlocal_b=-1", "rheology.nonlocal_b"},
        {"solver.coupled=on", "solver.coupled"},
        {"rheology.fluidity_anderson=9", "rheology.fluidity_anderson"},
    };
    test_bad_overrides(NGF_CASE, bad, sizeof bad / sizeof bad[0]);
}

void group_ngf(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_line_solver),
        cmocka_unit_test(test_stops_and_flows),
        cmocka_unit_test(test_stopping_height),
        cmocka_unit_test(test_couette_wall_layer),
        cmocka_unit_test(test_fine_layer_from_rest),
        cmocka_unit_test(test_chute_creep_length),
        cmocka_unit_test(test_shear_decay_length),
        cmocka_unit_test(test_fluidity_multigrid),
        cmocka_unit_test(test_accelerated_steady),
    };
    RUN_GROUP(t, "ngf", tests);
}
