/* The architecture's promises, each with a real use:
 * - a scene that lives in its own file (src/scenes/couette.c, one registry
 *   line, cases/couette.ini) runs to its exact profile at second order;
 * - a physics module registers an extra field that is checkpointed,
 *   continued and written to the field files with no change to any I/O
 *   file: a restarted run ends bit for bit where the uninterrupted one does;
 * - the variable-coefficient path (a face density that is not uniform) gives
 *   the same flow as the uniform one when the density is in fact uniform,
 *   through the multigrid projection instead of the FFT one;
 * - the layers (docs/architecture.md) are one-way: every include and every
 *   use of another file's definitions goes down their order, and no source
 *   files use each other (tests/include_layers.py). */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "io/checkpoint.h"
#include "io/fields_h5.h"
#include "march/step.h"
#include "scenes/scene.h"
#include "test_main.h"

#define COUETTE "../cases/couette.ini"

/* Couette-Poiseuille at nz = 10, 20, 40: steady, second order (the parabola
 * meets the wall condition ghost = -interior, an O(h^2) approximation; the
 * linear part is exact), the mid-height velocity U/2 + G H^2 / (8 mu) = 1.5. */
static void test_couette_scene(void **state)
{
    (void)state;
    assert_true(scene_find("couette") >= 0);
    static const int nz[] = {10, 20, 40};
    double err[3];
    for (int m = 0; m < 3; m++) {
        char o[32];
        snprintf(o, sizeof o, "domain.nz=%d", nz[m]);
        char *ov[] = {o};
        struct muflow_case cs;
        struct run_result r;
        test_run_case(COUETTE, 1, ov, &cs, &r);
        print_message("couette nz %d: %s in %ld steps, err_rms %.3e, u_mid %.6f (exact %.6f)\n",
                      nz[m], run_status_name(r.status), r.steps, r.errors.err_rms,
                      r.errors.headline, r.errors.headline_exact);
        assert_int_equal(r.status, STATUS_STEADY);
        assert_true(fabs(r.errors.headline_exact - 1.5) < 1e-12);
        err[m] = r.errors.err_rms;
    }
    double order = log2(err[0] / err[2]) / 2.0;
    print_message("couette RMS order: %.3f\n", order);
    /* a second-order scheme; 0.1 below 2 for the pre-asymptotic coarse grid */
    assert_true(order > 1.9 && order < 2.1);
}

/* A module with a field of its own: a tracer that integrates the flow
 * speed over time in every cell (d tracer / dt = |u| at the cell's low x
 * face), checkpointed, restored on rejected steps and written out. */
struct tracer_state {
    double *tracer;
};

static int tracer_create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct tracer_state *t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    *state = t;
    if (fields_add_written(&st->fields, "tracer", FIELD_CHECKPOINT | FIELD_SAVED, &t->tracer) !=
        0) {
        snprintf(err, errlen, "cannot register the tracer");
        return -1;
    }
    return 0;
}

static int tracer_transport(struct march_state *st, void *state, double dt)
{
    struct tracer_state *t = state;
    const struct grid *g = &st->g;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                t->tracer[p] += dt * fabs(st->field.velocity[0][p]) * (1.0 + k);
            }
    return 0;
}

static void tracer_destroy(void *state) { free(state); }

static const struct module tracer_module = {
    .name = "tracer",
    .create = tracer_create,
    .transport = tracer_transport,
    .destroy = tracer_destroy,
};
static const struct module *const extra_modules[] = {&tracer_module, NULL};

static void run_couette(const char *dir, const char *steps, const char *restart_from,
                        struct run_result *r)
{
    char o1[600], o2[64];
    snprintf(o1, sizeof o1, "output.dir=%s", dir);
    snprintf(o2, sizeof o2, "solver.max_steps=%s", steps);
    char *ov[] = {"solver.mode=transient", "solver.end_time=100", "solver.dt=0.002",
                  "output.quiet=on", o1, o2};
    struct muflow_case cs;
    char err[512];
    if (restart_from) {
        char *ov2[] = {o1, o2};
        int rc = checkpoint_load_case(restart_from, 2, ov2, &cs, err, sizeof err);
        if (rc)
            print_error("%s\n", err);
        assert_int_equal(rc, 0);
    } else {
        test_load_case(&cs, COUETTE, 6, ov);
    }
    struct run_options opt = {.write_output = 1, .restart_from = restart_from,
                              .modules = extra_modules};
    int rc = run_case_opts(&cs, &opt, r, err, sizeof err);
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
}

static void test_module_field_restart(void **state)
{
    (void)state;
    char base[64];
    test_tmp_make(base, sizeof base, "arch");
    char a[600], b[600], c[600], ck[700], fa[700], fb[700];
    snprintf(a, sizeof a, "%s/first", base);
    snprintf(b, sizeof b, "%s/continued", base);
    snprintf(c, sizeof c, "%s/whole", base);
    struct run_result r;
    run_couette(a, "6", NULL, &r);
    assert_int_equal(r.status, STATUS_STOPPED); /* max_steps in transient mode: a checkpoint */
    assert_true(r.checkpointed);
    snprintf(ck, sizeof ck, "%s/%s", a, CHECKPOINT_NAME);
    size_t n;
    double *stored = test_h5_file_dataset(ck, "tracer", &n); /* the module's field is in it */
    double sum = 0.0;
    for (size_t i = 0; i < n; i++)
        sum += stored[i];
    assert_true(sum > 0.0);
    free(stored);
    run_couette(b, "12", ck, &r);
    assert_int_equal(r.status, STATUS_STOPPED);
    assert_int_equal(r.steps, 12);
    run_couette(c, "12", NULL, &r);
    assert_int_equal(r.steps, 12);
    char name[64];
    fields_h5_name(12, name, sizeof name);
    snprintf(fb, sizeof fb, "%s/%s", b, name);
    snprintf(fa, sizeof fa, "%s/%s", c, name);
    size_t nb, nc;
    double *tb = test_h5_file_dataset(fb, "tracer", &nb);
    double *tc = test_h5_file_dataset(fa, "tracer", &nc);
    assert_int_equal(nb, nc);
    double most = 0.0;
    for (size_t i = 0; i < nb; i++) {
        assert_true(tb[i] == tc[i]); /* bit for bit */
        most = fmax(most, tb[i]);
    }
    print_message("module field 'tracer': checkpointed, continued from step 6 to 12 bit for "
                  "bit (max %.6g)\n", most);
    free(tb);
    free(tc);
    test_tmp_remove(base);
}

/* A module that makes the density "variable" without changing its value:
 * the multigrid projection and the face-density mass term must give the
 * uniform path's flow (to the solvers' tolerances). */
static void test_variable_coefficients(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=8", "domain.nz=16", "solver.mode=transient", "solver.end_time=0.05",
                  "solver.dt=0.005", "physics.advection=on"};
    struct muflow_case cs;
    test_load_case(&cs, COUETTE, 6, ov);
    struct march_state u, v;
    char err[512];
    assert_int_equal(scene_march_create(&u, &cs, NULL, err, sizeof err), 0);
    test_march_create(&v, &cs, test_variable_density);
    assert_true(u.density_uniform && !v.density_uniform);
    /* a perturbation that is not a steady flow: w varies along x */
    for (struct march_state *s = &u; s; s = s == &u ? &v : NULL)
        for (int i = 0; i < s->g.n[0]; i++)
            for (int k = 1; k < s->g.n[2]; k++)
                s->field.velocity[2][grid_idx(&s->g, i, 0, k)] =
                    0.1 * sin(2.0 * M_PI * (i + 0.5) / 8);
    assert_int_equal(march_run(&u, NULL, NULL), STATUS_FINISHED);
    assert_int_equal(march_run(&v, NULL, NULL), STATUS_FINISHED);
    double size, diff = test_velocity_difference(&u, &v, &size);
    print_message("uniform density by the FFT and by the multigrid path: max |du| %.2e of %.3f\n",
                  diff, size);
    /* the multigrid-CG projection is solved to a relative residual of 1e-12 */
    assert_true(diff <= 1e-9 * size);
    march_destroy(&u);
    march_destroy(&v);
}

/* A scene's own section: known to its cases only, written back (between
 * [solver] and [output]) and read back to the same values. */
static void test_scene_section(void **state)
{
    (void)state;
    struct muflow_case cs;
    char err[512];
    char *bad[] = {"heap.flow_rate=40"};
    assert_int_equal(case_load(&cs, "../cases/bagnold.ini", 1, bad, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "unknown section heap"));
    assert_non_null(strstr(err, "case.scene = heap"));
    char *ok[] = {"heap.flow_rate=14.9", "heap.max_solves=7"};
    test_load_case(&cs, "../cases/heap.ini", 2, ok);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    case_write_ini(&cs, f);
    fclose(f);
    const char *heap = strstr(buf, "[heap]\nflow_rate = 14.9\n");
    assert_non_null(heap);
    assert_true(strstr(buf, "[solver]") < heap && heap < strstr(buf, "[output]"));
    assert_non_null(strstr(heap, "max_solves = 7\n"));
    free(buf);
    /* the scene chosen by an override makes its section known to the file
     * and the overrides before it */
    char *late[] = {"heap.max_solves=9", "case.scene=heap"};
    assert_int_equal(case_load(&cs, "../cases/couette.ini", 2, late, err, sizeof err), 2);
    assert_non_null(strstr(err, "case.scene = heap needs")); /* couette's boundaries */
}

/* tests/include_layers.py on the tree: exit 0 and its one line; else every
 * upward include or use and every cycle, one line each. */
static void test_include_layers(void **state)
{
    (void)state;
    char *out;
    int rc = test_sh("/usr/bin/python3 include_layers.py .. 2>&1", &out);
    if (rc != 0)
        print_error("include_layers.py exited %d:\n%s", rc, out);
    else
        print_message("%s", out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "no cycle"));
    free(out);
}

void group_architecture(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_include_layers),
        cmocka_unit_test(test_scene_section),
        cmocka_unit_test(test_couette_scene),
        cmocka_unit_test(test_module_field_restart),
        cmocka_unit_test(test_variable_coefficients),
    };
    RUN_GROUP(t, "architecture", tests);
}
