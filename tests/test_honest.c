/* Honest endings: a run says it has no steady state only when it has none,
 * the automatic preconditioner works on every grid, a run that misses its
 * goal can be continued, a blow-up stops at once with a sane state, memory is
 * estimated before it is allocated, warnings are not hidden by quiet. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "scenes/scene.h"
#include "march/march.h"
#include "app/run.h"
#include "io/checkpoint.h"
#include <omp.h>
#include "test_main.h"

#define CASES_DIR "../cases/"

/* On one thread: the thin profile grids run faster there (about 200 parallel
 * regions a step for a few hundred cells), and the machine is shared. */
static void run_one_thread(const struct muflow_case *cs, int write_output, struct run_result *r)
{
    char err[1024];
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    int rc = run_case(cs, write_output, r, err, sizeof err);
    omp_set_num_threads(threads);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    assert_int_equal(rc, RUN_OK);
}

/* From a small pseudo-time step the march follows the physical start-up of
 * the layer: its residual stays near 4.3e-2 for hundreds of steps while the
 * layer speeds up (200 such steps are not "accelerates").  It must end
 * steady, on the profile of the default run. */
static void test_startup_is_not_a_stall(void **state)
{
    (void)state;
    struct muflow_case cs;
    char *ov[] = {"domain.nz=10", "solver.dt=0.003"};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 2, ov);
    struct run_result r;
    run_one_thread(&cs, 0, &r);
    print_message("bagnold H/10 from dt 0.003: %s after %ld steps: %s\n",
                  run_status_name(r.status), r.steps, r.message);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_true(r.steps > 2 * 200); /* it does pass the old window */
    assert_true(r.errors.err_rms < 2e-3);
}

/* From rest the square duct's residual climbs from 1 to 27 in a few steps
 * and falls back below the start only after hundreds of Picard steps
 * (solver.newton_below = 1e-3 keeps them going), through a plateau near 2.
 * That is progress, not a stall: it was called unsteady at step 206, the
 * best residual being the start's.  It must end steady, on the flow rate of
 * the case's own solve (measured 483 steps; both to all 6 printed digits). */
static void test_climbing_start_is_not_a_stall(void **state)
{
    (void)state;
    char *ov[] = {"domain.ny=60", "domain.nz=120", "output.fields=off",
                  "solver.newton_below=1e-3"};
    struct muflow_case cs, cd;
    test_load_case(&cs, CASES_DIR "duct_square.ini", 4, ov);
    test_load_case(&cd, CASES_DIR "duct_square.ini", 3, ov);
    struct run_result r, d;
    run_one_thread(&cs, 0, &r);
    run_one_thread(&cd, 0, &d);
    print_message("square duct 60 x 120, newton_below 1e-3: %s after %ld steps: %s; "
                  "the case's newton_below: %ld steps\n",
                  run_status_name(r.status), r.steps, r.message, d.steps);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_true(r.steps > 2 * 200); /* it does pass the old window */
    assert_int_equal(d.status, STATUS_STEADY);
    double q = run_result_value(&d, "flow_rate");
    assert_true(fabs(run_result_value(&r, "flow_rate") / q - 1.0) <= 1e-8);
}

/* Papanastasiou at lambda 1e-8: the first Newton steps overshoot, rejections
 * cut dt to ~1e-8, and the march crawls ~250 steps in which the pseudo-time
 * hardly moves before it converges.  That crawl is no stall. */
static void test_cut_steps_are_not_a_stall(void **state)
{
    (void)state;
    struct muflow_case cs;
    char *ov[] = {"domain.ny=240", "rheology.lambda=1e-8",
                  "rheology.regularisation=papanastasiou"};
    test_load_case(&cs, CASES_DIR "chute.ini", 3, ov);
    struct run_result r;
    run_one_thread(&cs, 0, &r);
    print_message("papanastasiou chute b/240, lambda 1e-8: %s after %ld steps: %s\n",
                  run_status_name(r.status), r.steps, r.message);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_true(r.steps > 202);
    assert_true(fabs(r.errors.headline - r.errors.headline_exact) <
                1e-2 * fabs(r.errors.headline_exact));
}

/* Above atan(mu_s + dmu) there is none: still said, in bounded steps. */
static void test_true_acceleration_still_said(void **state)
{
    (void)state;
    struct muflow_case cs;
    char *ov[] = {"domain.nz=10", "physics.tilt=0.6"};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 2, ov);
    struct run_result r;
    run_one_thread(&cs, 0, &r);
    print_message("bagnold tilt 0.6: %s after %ld steps: %s\n", run_status_name(r.status),
                  r.steps, r.message);
    assert_int_equal(r.status, STATUS_UNSTEADY);
    assert_non_null(strstr(r.message, "accelerates"));
    assert_true(r.steps < 2000);
}

/* The automatic preconditioner: a flow bounded in one direction only gets the
 * line blocks, exact for it, whatever the periodic extent (not the LU: 960
 * probes at 16 x 8, 375 probes a step at 15 x 5);
 * two bounded directions keep the sparse factorisation. */
static void test_auto_preconditioner(void **state)
{
    (void)state;
    static const char *sizes[][2] = {{"domain.nx=16", "domain.ny=8"},
                                     {"domain.nx=15", "domain.ny=5"}};
    for (int m = 0; m < 2; m++) {
        struct muflow_case cs;
        char *ov[] = {(char *)sizes[m][0], (char *)sizes[m][1], "domain.nz=10"};
        test_load_case(&cs, CASES_DIR "bagnold.ini", 3, ov);
        struct march_state st;
        test_march_create(&st, &cs, NULL);
        assert_int_equal(st.precond, VISCOUS_LINE);
        march_destroy(&st);
        struct run_result r;
        run_one_thread(&cs, 0, &r);
        print_message("bagnold %s %s nz=10: %s after %ld steps, err_rms %.4e\n", sizes[m][0],
                      sizes[m][1], run_status_name(r.status), r.steps, r.errors.err_rms);
        assert_int_equal(r.status, STATUS_STEADY);
        /* the 1D profile of H/10 (2 x 1 x 10): err_rms 1.9358e-3 */
        assert_true(fabs(r.errors.err_rms - 1.9358e-3) < 1e-6);
    }
    struct muflow_case cs;
    char *ov[] = {"domain.nx=16", "domain.nz=16"};
    test_load_case(&cs, CASES_DIR "bingham_cavity.ini", 2, ov);
    struct march_state st;
    char err[512];
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    assert_int_equal(st.precond, VISCOUS_CHOLESKY);
    march_destroy(&st);
}

/* A steady run that stops at max_steps leaves a checkpoint, and continuing
 * from it with a larger max_steps ends where the uninterrupted run does. */
static void test_max_steps_checkpoint(void **state)
{
    (void)state;
    char err[1024];
    struct test_run_dir dir;
    test_run_dir_make(&dir, "honest_maxsteps");
    struct muflow_case cs, cc;
    char *ov[] = {"solver.max_steps=5", "output.quiet=on", dir.output};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 3, ov);
    struct run_result r;
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_UNSTEADY);
    assert_int_equal(r.steps, 5);
    assert_true(r.checkpointed);
    char ck[300];
    snprintf(ck, sizeof ck, "%s/%s", dir.dir, CHECKPOINT_NAME);
    char *ov2[] = {"solver.max_steps=100"};
    int lrc = checkpoint_load_case(ck, 1, ov2, &cc, err, sizeof err);
    if (lrc != 0)
        print_error("%s\n", err);
    assert_int_equal(lrc, 0);
    struct run_options cont = {.write_output = 1, .restart_from = ck};
    assert_int_equal(run_case_opts(&cc, &cont, &r, err, sizeof err), RUN_OK);
    print_message("max_steps 5, continued: %s after %ld steps, err_rms %.4e\n",
                  run_status_name(r.status), r.steps, r.errors.err_rms);
    assert_int_equal(r.status, STATUS_STEADY);
    assert_int_equal(r.steps, 15);
    assert_true(fabs(r.errors.err_rms - 1.2807e-4) < 5e-9);
    test_run_dir_remove(&dir);
}

/* The README's commands: a run, then `muflow --restart DIR` and
 * `muflow --restart DIR solver.max_steps=20000`. */
static void test_readme_restart_commands(void **state)
{
    (void)state;
    char bin[4096], dir[128], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "honest_readme");
    snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 '%s' ../cases/bagnold.ini output.dir=%s", bin, dir);
    assert_int_equal(test_sh(cmd, &out), 0);
    assert_non_null(strstr(out, "steady after 15 steps"));
    free(out);
    const char *extra[] = {"", " solver.max_steps=20000"};
    for (int m = 0; m < 2; m++) {
        snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 '%s' --restart %s%s", bin, dir, extra[m]);
        int rc = test_sh(cmd, &out);
        print_message("muflow --restart DIR%s: exit %d\n", extra[m], rc);
        assert_int_equal(rc, 0);
        assert_non_null(strstr(out, "continuing from"));
        assert_non_null(strstr(out, "steady after 15 steps"));
        assert_non_null(strstr(out, "err_rms 1.2807e-04"));
        free(out);
    }
    test_tmp_remove(dir);
}

/* An unstable explicit advection (cfl 2, Newtonian cavity at 32 x 32): the
 * run stops as the state blows up, names step, time and reason, keeps the
 * last state below the threshold (psi_max of a cavity flow, not 4.5e74 after
 * 2095 steps) and writes one history row per step. */
static void test_blowup_stops_early(void **state)
{
    (void)state;
    struct test_run_dir dir;
    test_run_dir_make(&dir, "honest_blowup");
    struct muflow_case cs;
    char *ov[] = {"domain.nx=32", "domain.nz=32", "rheology.law=newtonian",
                  "rheology.viscosity=1e-5", "physics.advection=on", "solver.mode=transient",
                  "solver.end_time=20", "solver.cfl=2", "solver.dt=1", "output.quiet=on",
                  "output.fields=off", dir.output};
    test_load_case(&cs, CASES_DIR "bingham_cavity.ini", 12, ov);
    struct run_result r;
    run_one_thread(&cs, 1, &r);
    print_message("cavity cfl 2: %s after %ld steps, t = %g, psi_max %.4g: %s\n",
                  run_status_name(r.status), r.steps, r.time, r.errors.headline, r.message);
    assert_int_equal(r.status, STATUS_DIVERGED);
    assert_true(r.steps < 100);
    assert_non_null(strstr(r.message, "blows up at step"));
    assert_non_null(strstr(r.message, ", t = "));
    assert_true(r.residual <= 1e3);
    assert_true(r.errors.headline > 0.0 && r.errors.headline < 0.2); /* Vola Bn 0: 0.0996 */
    char *h = test_read_in(dir.dir, "history.csv");
    long last = -1, rows = 0;
    for (char *line = strchr(h, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
        long step = strtol(line + 1, NULL, 10);
        assert_true(step > last); /* increasing: no duplicates */
        last = step;
        rows++;
    }
    free(h);
    assert_int_equal(last, r.steps);
    assert_int_equal(rows, r.steps + 1);
    test_run_dir_remove(&dir);
}

/* The memory estimate: refused before allocating when it exceeds what is
 * available (one line naming the grid keys, the estimate and the memory,
 * exit 2, nothing written), printed in the header otherwise. */
static void test_memory_estimate(void **state)
{
    (void)state;
    char bin[4096], dir[128], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "honest_memory");
    /* 100 MB available, a 100 x 100 x 50 grid needs about 370 MB */
    snprintf(cmd, sizeof cmd,
             "MUFLOW_AVAILABLE_MEMORY=100000000 '%s' ../cases/bagnold.ini domain.nx=100 "
             "domain.ny=100 domain.nz=50 output.dir=%s/run 2>&1",
             bin, dir);
    out = test_sh_refused(cmd, "domain.nx x domain.ny x domain.nz = 100 x 100 x 50");
    assert_non_null(strstr(out, "needs about"));
    assert_non_null(strstr(out, "100 MB of memory available"));
    free(out);
    char run_dir[200];
    snprintf(run_dir, sizeof run_dir, "%s/run", dir);
    assert_int_not_equal(access(run_dir, F_OK), 0); /* nothing written */
    /* the coupled step's own LU counts: the cavity at 128 x 128 peaks at
     * 384 MB (estimate 389 MB; the viscous LU's model would say 130 MB and
     * let the run start) */
    snprintf(cmd, sizeof cmd,
             "MUFLOW_AVAILABLE_MEMORY=300000000 '%s' ../cases/bingham_cavity.ini "
             "solver.coupled=on solver.augmentation=0 solver.preconditioner=lu "
             "domain.nx=128 domain.nz=128 "
             "output.dir=%s/run 2>&1",
             bin, dir);
    free(test_sh_refused(cmd, "needs about"));
    assert_int_not_equal(access(run_dir, F_OK), 0);
    /* fits: the estimate is in the header line */
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 MUFLOW_AVAILABLE_MEMORY=100000000 '%s' ../cases/bagnold.ini "
             "domain.nz=10 output.dir=%s/run",
             bin, dir);
    assert_int_equal(test_sh(cmd, &out), 0);
    const char *m = strstr(out, "memory ~");
    assert_non_null(m);
    assert_true(m < strchr(out, '\n'));
    free(out);
    test_tmp_remove(dir);
}

/* Every size check comes before the work the grid costs: the body's
 * geometry on the grid (a plane of flags and a queue, 5 bytes a cell,
 * twice) would take the cylinder benchmark at 40000 x 8000 cells a minute
 * and 1.5 GB, the circular duct at 20000 x 40000 half a minute and 790 MB,
 * before a later check refused them.  Two checks, neither a timing:
 * - case_load refuses the first from the case alone, before march_create
 *   (not only march_create's estimate);
 * - from the command line, under an address space of 1 GB, far below what
 *   the geometry needs and far above what muflow's start needs, both are
 *   refused with the size message (exit 2), not "out of memory checking
 *   the shapes": no allocation of the grid's size came before the check. */
static void test_size_before_geometry(void **state)
{
    (void)state;
    struct muflow_case cs;
    char err[1024];
    char *big[] = {"domain.nx=40000", "domain.nz=8000"};
    setenv("MUFLOW_AVAILABLE_MEMORY", "16000000000", 1); /* any machine: 16 GB */
    int rc = case_load(&cs, "../cases/cylinder_benchmark.ini", 2, big, err, sizeof err);
    unsetenv("MUFLOW_AVAILABLE_MEMORY");
    print_message("case_load: %d: %s\n", rc, err);
    assert_int_equal(rc, 2);
    assert_true(strncmp(err, "override domain.nx=40000, override domain.nz=8000: domain.nx x "
                             "domain.ny x domain.nz = 40000 x 1 x 8000: the run needs about ",
                        120) == 0);
    assert_non_null(strstr(err, "more than the 16.0 GB of memory available"));

    char bin[4096], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    static const struct {
        const char *args, *want;
    } runs[] = {
        {"../cases/cylinder_benchmark.ini domain.nx=40000 domain.nz=8000",
         "domain.nx x domain.ny x domain.nz = 40000 x 1 x 8000: the run needs about "},
        {"../cases/duct_circular.ini domain.ny=20000 domain.nz=40000",
         "domain.nx * domain.ny * domain.nz = 1 * 20000 * 40000 = 800000000 cells: must be <= "
         "500000000"},
    };
    for (size_t m = 0; m < sizeof runs / sizeof runs[0]; m++) {
        snprintf(cmd, sizeof cmd,
                 "ulimit -v 1000000 && '%s' %s output.dir=/tmp/muflow_honest_never 2>&1", bin,
                 runs[m].args);
        out = test_sh_refused(cmd, runs[m].want);
        assert_null(strstr(out, "out of memory"));
        free(out);
    }
    assert_int_not_equal(access("/tmp/muflow_honest_never", F_OK), 0);
}

/* An output folder that cannot be made names the key (it said "cannot
 * create output folder /proc/x"): exit 2, one line. */
static void test_output_dir_named(void **state)
{
    (void)state;
    char bin[4096], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    static const char *const want[][2] = {
        {"/proc/x", "muflow: output.dir = /proc/x: cannot create the folder: "},
        {"/proc/x/y", "muflow: output.dir = /proc/x/y: cannot create the folder /proc/x: "},
        {"/dev/null", "muflow: output.dir = /dev/null: not a folder"},
    };
    for (size_t m = 0; m < sizeof want / sizeof want[0]; m++) {
        snprintf(cmd, sizeof cmd, "'%s' ../cases/bagnold.ini domain.nz=10 output.dir=%s 2>&1", bin,
                 want[m][0]);
        out = test_sh_refused(cmd, want[m][1]);
        assert_true(strncmp(out, want[m][1], strlen(want[m][1])) == 0);
        free(out);
    }
}

/* A restart with another thread count warns on stderr even when quiet (a
 * restart inherits the checkpoint's output.quiet). */
static void test_warning_not_quiet(void **state)
{
    (void)state;
    char bin[4096], dir[128], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "honest_warn");
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 '%s' ../cases/bagnold.ini domain.nz=10 solver.max_steps=3 "
             "output.quiet=on output.dir=%s 2>&1",
             bin, dir);
    assert_int_equal(test_sh(cmd, NULL), 3); /* max_steps: unsteady */
    snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=2 '%s' --restart %s solver.max_steps=100 2>&1 >/dev/null", bin, dir);
    int rc = test_sh(cmd, &out);
    print_message("restart on 2 threads, quiet: exit %d, stderr: %s", rc, out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "warning: the checkpoint was written with 1 threads, this run has 2"));
    free(out);
    test_tmp_remove(dir);
}

/* An implicit solve stopped at solver.max_linear_iterations is taken (the
 * step goes on with the iterate) but told: one warning line with the cap
 * and the residual, and the count in summary.ini.  The column collapse on
 * a coarse grid with the line blocks and a cap of 2 iterations (they need
 * hundreds there); the same run with the default cap and preconditioner
 * (the Cholesky, one iteration) counts none and says nothing. */
static void test_linear_cap_told(void **state)
{
    (void)state;
    char bin[4096], dir[128], cmd[5000], *out;
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "honest_linear");
    for (int capped = 1; capped >= 0; capped--) {
        snprintf(cmd, sizeof cmd,
                 "OMP_NUM_THREADS=1 '%s' ../cases/collapse.ini domain.nx=40 domain.nz=12 "
                 "domain.ly=0.125 solver.end_time=0.05 output.fields=off output.quiet=on %s "
                 "output.dir=%s 2>&1 >/dev/null",
                 bin, capped ? "solver.preconditioner=line solver.max_linear_iterations=2" : "",
                 dir);
        int rc = test_sh(cmd, &out);
        print_message("%s: exit %d, stderr: %s\n", capped ? "capped" : "default", rc, out);
        assert_int_equal(rc, 0);
        char *sum = test_read_in(dir, "summary.ini");
        const char *k = strstr(sum, "\nlinear_unconverged = ");
        assert_non_null(k);
        long n = strtol(k + strlen("\nlinear_unconverged = "), NULL, 10);
        const char *w = strstr(out, "warning: step 1: the implicit viscous solve stopped at "
                                    "solver.max_linear_iterations = 2 with a relative residual of");
        if (capped) {
            assert_true(n >= 1);
            assert_non_null(w);
        } else {
            assert_int_equal(n, 0);
            assert_null(strstr(out, "implicit viscous solve stopped"));
        }
        free(sum);
        free(out);
    }
    test_tmp_remove(dir);
}

/* A steady march whose velocity grows by orders of magnitude (bagnold2
 * below mu_s at 4 x 100, lambda 1e-9 by stages from 1e-6: the stiffer
 * plug of the last stage raises the residual to 69 with the film still
 * right, then the velocity from the film's 0.0105 m/s to 20 m/s at step 50;
 * lambda 1e-8 reaches the film, steady in 40 steps) ends diverged at once,
 * names the step and the velocity,
 * and keeps (and checkpoints) the state before: its velocity within 1000
 * times the film's. */
static void test_velocity_blowup_diverges(void **state)
{
    (void)state;
    char err[512];
    struct test_run_dir dir;
    test_run_dir_make(&dir, "honest_vblowup");
    struct muflow_case cs;
    char *ov[] = {"domain.nx=4", "physics.tilt=0.2", "rheology.lambda=1e-9",
                  "solver.continuation=100", "output.quiet=on", "output.fields=off", dir.output};
    test_load_case(&cs, CASES_DIR "bagnold2.ini", 7, ov);
    struct run_result r;
    run_one_thread(&cs, 1, &r);
    print_message("bagnold2 tilt 0.2, lambda 1e-9 by stages: %s after %ld steps: %s\n",
                  run_status_name(r.status), r.steps, r.message);
    assert_int_equal(r.status, STATUS_DIVERGED);
    assert_non_null(strstr(r.message, "blows up at step"));
    assert_non_null(strstr(r.message, "max |u|"));
    assert_true(r.steps < 200);
    assert_int_equal(r.checkpointed, 1);
    /* the checkpoint holds the kept state: finite, within the bound */
    char path[300];
    snprintf(path, sizeof path, "%s/%s", dir.dir, CHECKPOINT_NAME);
    int n[3] = {4, 1, 100};
    size_t size = (size_t)(n[0] + 2) * (n[1] + 2) * (n[2] + 2);
    double *u = malloc(size * sizeof *u), umax = 0.0;
    assert_non_null(u);
    assert_int_equal(checkpoint_read_dataset(path, "velocity_x", n, u, err, sizeof err), 0);
    for (size_t p = 0; p < size; p++) {
        assert_true(isfinite(u[p]));
        umax = fmax(umax, fabs(u[p]));
    }
    free(u);
    print_message("kept state: max |u| %.3e\n", umax);
    assert_true(umax > 0.0 && umax <= 1e3 * 0.0105348);
    test_run_dir_remove(&dir);
}

/* A CFL step that collapses (a layer under g = 1e12 reaches |u| ~ 4e10 in
 * its first step: end_time 1 would take ~1e11 steps) stops the run at once
 * with the step, the time and the reason, keeping the state before. */
static void test_dt_collapse_stops(void **state)
{
    (void)state;
    struct muflow_case cs;
    char *ov[] = {"domain.nz=10", "rheology.law=newtonian", "physics.advection=on",
                  "solver.mode=transient", "solver.end_time=1", "solver.dt=0.1",
                  "physics.gravity=1e12"};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 7, ov);
    struct run_result r;
    run_one_thread(&cs, 0, &r);
    print_message("g = 1e12: %s after %ld steps, t = %g: %s\n", run_status_name(r.status),
                  r.steps, r.time, r.message);
    assert_int_equal(r.status, STATUS_DIVERGED);
    assert_non_null(strstr(r.message, "the time step collapses at step 1, t = 0.1"));
    assert_int_equal(r.steps, 0);
    assert_true(r.time == 0.0);
}

void group_honest(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_startup_is_not_a_stall),
        cmocka_unit_test(test_cut_steps_are_not_a_stall),
        cmocka_unit_test(test_climbing_start_is_not_a_stall),
        cmocka_unit_test(test_true_acceleration_still_said),
        cmocka_unit_test(test_auto_preconditioner),
        cmocka_unit_test(test_max_steps_checkpoint),
        cmocka_unit_test(test_readme_restart_commands),
        cmocka_unit_test(test_blowup_stops_early),
        cmocka_unit_test(test_dt_collapse_stops),
        cmocka_unit_test(test_velocity_blowup_diverges),
        cmocka_unit_test(test_memory_estimate),
        cmocka_unit_test(test_size_before_geometry),
        cmocka_unit_test(test_output_dir_named),
        cmocka_unit_test(test_warning_not_quiet),
        cmocka_unit_test(test_linear_cap_told),
    };
    RUN_GROUP(t, "honest", tests);
}
