/* forces.csv (physics/forces_file.h), on the Schaefer-Turek cylinder
 * (cases/cylinder_benchmark.ini, its D/10 grid) for a few dozen steps of
 * its transient start:
 * - the file: its header, a row per step, the steps in order, the time
 *   rising to the summary's, the coefficients 2 F / (rho U^2 D) of the
 *   forces, and the last row the summary's drag_force, lift_force,
 *   drag_coefficient, lift_coefficient and pressure_drop bit for bit;
 * - output.forces_every = 4: the sampled steps and the final one;
 * - a run stopped and continued (--restart's path) writes the
 *   uninterrupted run's file byte for byte, every step and every 4, also
 *   from a forces.csv.tmp that holds rows past the checkpoint (a run that
 *   died after it): no row twice, none missing;
 * - output.forces_every = 0, and a case without a body in a flow (the
 *   circular duct's wall), write none; a fresh run removes an earlier one.
 * The steady run's record, C_D(t) settling at the 2D-1 value, is checked
 * on the obstacle group's D/10 run (test_cylinder_coarse). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "io/checkpoint.h"
#include "io/output.h"
#include "test_main.h"

#define CASE "../cases/cylinder_benchmark.ini"
#define STEPS 30
#define STOP 13

/* cylinder_benchmark.ini into dir (quiet), with up to three more overrides. */
static void load(struct muflow_case *cs, const char *dir, const char *a, const char *b,
                 const char *c)
{
    char od[128];
    snprintf(od, sizeof od, "output.dir=%s", dir);
    char *ov[5] = {od, "output.quiet=on"};
    int n = 2;
    const char *more[3] = {a, b, c};
    for (int i = 0; i < 3; i++)
        if (more[i])
            ov[n++] = (char *)more[i];
    test_load_case(cs, CASE, n, ov);
}

static void run(const struct muflow_case *cs, const char *restart_from, struct run_result *r)
{
    char err[1024];
    struct run_options opt = {.write_output = 1, .restart_from = restart_from};
    int rc = run_case_opts(cs, &opt, r, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    assert_int_equal(rc, RUN_OK);
}

/* The run into dir stopped at `stop` steps and continued from its
 * checkpoint to `end`; tail (or NULL): lines appended to its forces.csv,
 * renamed forces.csv.tmp, before the continuation (a run that died after
 * its checkpoint). */
static void stopped_and_continued(const char *dir, const char *every, long stop, long end,
                                  const char *tail, struct run_result *r)
{
    char s[64], e[64], ck[200], err[1024];
    snprintf(s, sizeof s, "solver.max_steps=%ld", stop);
    snprintf(e, sizeof e, "solver.max_steps=%ld", end);
    struct muflow_case cs;
    load(&cs, dir, s, every, NULL);
    run(&cs, NULL, r);
    assert_int_equal(r->steps, stop);
    if (tail) {
        char path[200], tmp[210];
        snprintf(path, sizeof path, "%s/forces.csv", dir);
        snprintf(tmp, sizeof tmp, "%s.tmp", path);
        assert_int_equal(rename(path, tmp), 0);
        FILE *f = fopen(tmp, "a");
        assert_non_null(f);
        fputs(tail, f);
        fclose(f);
    }
    snprintf(ck, sizeof ck, "%s/%s", dir, CHECKPOINT_NAME);
    char *more[] = {e};
    assert_int_equal(checkpoint_load_case(ck, 1, more, &cs, err, sizeof err), 0);
    run(&cs, ck, r);
    assert_int_equal(r->steps, end);
}

/* The file of a run of `steps` steps sampled every `every`: its header,
 * its steps, the time rising to the summary's, the coefficients of the
 * forces, the last row the summary's numbers. */
static void check_file(const char *dir, const struct run_result *r, long every)
{
    char header[512];
    int rows, cols;
    double *v = test_read_csv_numbers(dir, "forces.csv", header, sizeof header, &rows, &cols);
    assert_string_equal(header, "step,time,drag_force,lift_force,drag_coefficient,"
                                "lift_coefficient,pressure_drop");
    long want = r->steps / every + 1 + (r->steps % every != 0);
    assert_int_equal(rows, want);
    for (int i = 0; i < rows; i++) {
        double step = v[(size_t)i * cols], t = v[(size_t)i * cols + 1];
        assert_true(step == (i + 1 < rows ? (double)(i * every) : (double)r->steps));
        if (i > 0)
            assert_true(t > v[(size_t)(i - 1) * cols + 1]);
        /* C = 2 F / (rho U^2 D): rho 1, U 2/3 of the peak 0.3, D 0.1 (to the
         * file's 10 digits) */
        for (int k = 0; k < 2; k++) {
            double F = v[(size_t)i * cols + 2 + k], C = v[(size_t)i * cols + 4 + k];
            assert_true(fabs(C - F / (0.5 * 0.2 * 0.2 * 0.1)) <= 1e-9 * fabs(C) + 1e-300);
        }
    }
    const double *last = v + (size_t)(rows - 1) * cols;
    char t[32]; /* the summary's time, as both files write it */
    snprintf(t, sizeof t, "%.10g", r->time);
    assert_true(last[1] == strtod(t, NULL));
    const char *names[] = {"drag_force", "lift_force", "drag_coefficient", "lift_coefficient",
                           "pressure_drop"};
    for (int k = 0; k < 5; k++) {
        double s = run_result_value(r, names[k]);
        if (last[2 + k] != s)
            print_error("forces.csv's last %s %.17g, the summary's %.17g\n", names[k],
                        last[2 + k], s);
        assert_true(last[2 + k] == s);
    }
    print_message("forces.csv: %d rows to step %ld, t %g: C_D %.6f, C_L %.6f, Delta p %.6f\n",
                  rows, r->steps, last[1], last[4], last[5], last[6]);
    free(v);
}

static void assert_same_file(const char *a, const char *b, const char *name)
{
    char *x = test_read_in(a, name), *y = test_read_in(b, name);
    if (strcmp(x, y) != 0)
        print_error("%s differs:\n%s\n---\n%s\n", name, x, y);
    assert_string_equal(x, y);
    free(x);
    free(y);
}

/* Every step, and every 4: the file, and the continued run's the same. */
static void test_forces_file(void **state)
{
    (void)state;
    char base[64], a[96], b[96], a4[96], b4[96];
    test_tmp_make(base, sizeof base, "forces");
    snprintf(a, sizeof a, "%s/a", base);
    snprintf(b, sizeof b, "%s/b", base);
    snprintf(a4, sizeof a4, "%s/a4", base);
    snprintf(b4, sizeof b4, "%s/b4", base);
    char end[64];
    snprintf(end, sizeof end, "solver.max_steps=%d", STEPS);
    struct muflow_case cs;
    struct run_result ra, rb, ra4, rb4;
    load(&cs, a, end, NULL, NULL);
    run(&cs, NULL, &ra);
    assert_int_equal(ra.steps, STEPS);
    check_file(a, &ra, 1);
    load(&cs, a4, end, "output.forces_every=4", NULL);
    run(&cs, NULL, &ra4);
    check_file(a4, &ra4, 4);
    assert_true(run_result_value(&ra4, "drag_force") == run_result_value(&ra, "drag_force"));
    /* stopped at STOP, its forces.csv.tmp holding two rows past it that a
     * run dying after its checkpoint had written */
    stopped_and_continued(b, NULL, STOP, STEPS, "14,0.28,1,1,1,1,1\n15,0.3,1,1,1,1,1\n", &rb);
    check_file(b, &rb, 1);
    assert_same_file(a, b, "forces.csv");
    /* the stopped run's last row (step 13, no sample of 4) is not the
     * uninterrupted run's */
    stopped_and_continued(b4, "output.forces_every=4", STOP, STEPS, NULL, &rb4);
    check_file(b4, &rb4, 4);
    assert_same_file(a4, b4, "forces.csv");
    test_tmp_remove(base);
}

/* No file: output.forces_every = 0 (an earlier run's removed), and a
 * case whose shapes are a wall around the fluid (obstacle.invert). */
static void test_forces_none(void **state)
{
    (void)state;
    char dir[64], path[128];
    test_tmp_make(dir, sizeof dir, "forces_none");
    snprintf(path, sizeof path, "%s/forces.csv", dir);
    struct muflow_case cs;
    struct run_result r;
    load(&cs, dir, "solver.max_steps=2", NULL, NULL);
    run(&cs, NULL, &r);
    assert_true(test_file_exists(path));
    load(&cs, dir, "solver.max_steps=2", "output.forces_every=0", NULL);
    run(&cs, NULL, &r);
    assert_false(test_file_exists(path));
    load(&cs, dir, "solver.max_steps=2", NULL, NULL);
    run(&cs, NULL, &r);
    assert_true(test_file_exists(path));
    char od[96];
    snprintf(od, sizeof od, "output.dir=%s", dir);
    char *ov[] = {od, "output.quiet=on", "solver.max_steps=2"};
    test_load_case(&cs, "../cases/duct_circular.ini", 3, ov);
    run(&cs, NULL, &r);
    assert_true(cs.forces_every == 1);
    assert_false(test_file_exists(path));
    test_tmp_remove(dir);
}

void group_forces(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_forces_file),
        cmocka_unit_test(test_forces_none),
    };
    RUN_GROUP(t, "forces", tests);
}
