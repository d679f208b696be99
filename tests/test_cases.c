/* Every shipped case (each .ini file of cases/), each on a small grid for a few steps,
 * run with its output folder as the command writes it:
 * - continued from a checkpoint, it ends as the uninterrupted run: the
 *   same [result] (but wall_seconds and grid_matrices) and the same files
 *   of its scene and modules (but their wall-time columns), bit for bit; a case that cannot continue (the
 *   heap's tilt search) is refused and says why, and so is a collapse from
 *   a checkpoint without its record (an earlier muflow's);
 * - its summary.ini is an INI file a strict reader takes (no key twice in
 *   a section: Python's configparser, strict);
 * - run_result_value returns every number of its [result] section, and
 *   the forces on a body are named for what they hold;
 * - a fresh run removes every file of it: output_remove_run_files with the
 *   names of scene_output_files leaves its folder empty.
 * Then a run of one scene after another in the same folder leaves none of
 * the first one's files, and the command line's interruption: the resume
 * line for a run that can continue (the collapse), what to do instead for
 * one that cannot (the heap's search, the cylinder's continuation). */
#define _POSIX_C_SOURCE 200809L /* PATH_MAX */
#include <dirent.h>
#include <hdf5.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "app/run.h"
#include "io/checkpoint.h"
#include "io/output.h"
#include "scenes/scene.h"
#include "test_main.h"

#define CASES_DIR "../cases/"
#define PYTHON "/usr/bin/python3"
#define MAX_OV 10

/* A shipped case, small and short: its file, overrides, the step at which
 * the interrupted run stops (max_steps) and its last step (0: the case's
 * max_steps, the run ends steady before it).  stop = 0: it cannot continue
 * from a checkpoint (refused). */
struct shipped {
    const char *tag, *file;
    const char *ov[MAX_OV];
    long stop, end;
};

/* Every case file of cases/ runs: as shipped, stopped at DEFAULT_STOP and
 * continued to DEFAULT_END, unless this table has lines for it (a smaller
 * grid, other bounds, or variants of the case, each with its own tag).  A
 * case file removed from cases/ must leave the table too. */
#define DEFAULT_STOP 5
#define DEFAULT_END 10
static const struct shipped exceptions[] = {
    {"bagnold", "bagnold.ini", {"domain.nz=10"}, 5, 10},
    {"bagnold2", "bagnold2.ini", {"domain.nx=10", "domain.nz=20"}, 5, 10},
    /* the growth study: its record (growth.csv, growth_rate) from the start */
    {"bagnold2_growth",
     "bagnold2.ini",
     {"domain.nx=10", "domain.nz=20", "solver.mode=transient", "bagnold2.start=exact",
      "bagnold2.perturbation=0.01", "solver.dt=1e-4", "solver.end_time=1"},
     9,
     20},
    {"bagnold3d", "bagnold3d.ini", {"domain.nx=8", "domain.ny=8", "domain.nz=8"}, 3, 6},
    {"bedload", "bedload.ini", {NULL}, 5, 10},
    {"bedload_two_fluid", "bedload.ini", {"bedload.model=two_fluid"}, 3, 6},
    {"bingham_cavity", "bingham_cavity.ini", {"domain.nx=16", "domain.nz=16"}, 5, 10},
    {"chute", "chute.ini", {"domain.ny=20"}, 5, 10},
    /* an odd step: the VOF's sweeps alternate their order */
    {"collapse", "collapse.ini", {"domain.nx=40", "domain.nz=12", "domain.ly=0.125"}, 21, 40},
    {"couette", "couette.ini", {NULL}, 3, 0},
    /* steady in 19 steps */
    {"cylinder",
     "cylinder.ini",
     {"domain.nx=20", "domain.nz=60", "rheology.lambda=1e-2", "solver.continuation=1"},
     7,
     0},
    {"cylinder_benchmark", "cylinder_benchmark.ini", {"domain.nx=44", "domain.nz=9"}, 3, 6},
    /* BDF2: the checkpoint carries the velocity and advection a step before */
    {"cylinder_benchmark_bdf2",
     "cylinder_benchmark.ini",
     {"domain.nx=44", "domain.nz=9", "solver.time_scheme=bdf2"},
     3,
     6},
    {"duct_circular", "duct_circular.ini", {NULL}, 5, 10},
    {"duct_circular_two_fluid", "duct_circular.ini", {"duct.model=two_fluid"}, 3, 6},
    {"heap", "heap.ini", {"domain.ny=14", "domain.nz=20", "heap.flow_rate=0", "physics.tilt=0.405"},
     3, 6},
    {"heap_search", "heap.ini", {"domain.ny=14", "domain.nz=20"}, 0, 0},
    /* its record covers the run from the release: not restartable */
    {"slope_release", "slope_release.ini", {"domain.nx=30", "domain.nz=12", "domain.ly=0.005"}, 0,
     20},
};
#define NEXCEPTIONS ((int)(sizeof exceptions / sizeof exceptions[0]))
#define MAX_SHIPPED 64
#define NAME_LEN 64

/* The runs of the tests, from the folder's case files in name order: each
 * file's lines of the table, or the default line. */
static struct shipped shipped[MAX_SHIPPED];
static int nshipped;
static char default_names[MAX_SHIPPED][2][NAME_LEN]; /* a default line's tag and file */
static int exception_found[NEXCEPTIONS];              /* its file is in cases/ */

static int by_name(const void *a, const void *b)
{
    return strcmp((const char *)a, (const char *)b);
}

static void shipped_list(void)
{
    if (nshipped)
        return;
    static char files[MAX_SHIPPED][NAME_LEN];
    int nfiles = 0;
    DIR *d = opendir(CASES_DIR);
    assert_non_null(d);
    for (struct dirent *e; (e = readdir(d));) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 4, ".ini") != 0)
            continue;
        assert_true(nfiles < MAX_SHIPPED && n < NAME_LEN);
        memcpy(files[nfiles++], e->d_name, n + 1);
    }
    closedir(d);
    qsort(files, (size_t)nfiles, sizeof files[0], by_name);
    for (int f = 0; f < nfiles; f++) {
        int listed = 0;
        for (int x = 0; x < NEXCEPTIONS; x++)
            if (strcmp(exceptions[x].file, files[f]) == 0) {
                assert_true(nshipped < MAX_SHIPPED);
                shipped[nshipped++] = exceptions[x];
                exception_found[x] = listed = 1;
            }
        if (listed)
            continue;
        assert_true(nshipped < MAX_SHIPPED);
        char *tag = default_names[nshipped][0], *file = default_names[nshipped][1];
        memcpy(file, files[f], NAME_LEN);
        snprintf(tag, NAME_LEN, "%.*s", (int)strlen(files[f]) - 4, files[f]);
        shipped[nshipped++] = (struct shipped){tag, file, {NULL}, DEFAULT_STOP, DEFAULT_END};
    }
}

/* The runs of each: a uninterrupted, b stopped at `stop` and continued. */
struct runs {
    char dir[64];
    char a[96], b[96];
    struct muflow_case cs;
    struct run_result ra, rb;
};
static struct runs runs[MAX_SHIPPED];
static int runs_done;

static int count_ov(const struct shipped *s)
{
    int n = 0;
    while (n < MAX_OV && s->ov[n])
        n++;
    return n;
}

/* Loads s's case with its overrides, quiet output into dir, then extra. */
static void load(const struct shipped *s, const char *dir, const char *extra,
                 struct muflow_case *cs)
{
    char path[256], od[128], err[1024];
    char *ov[MAX_OV + 3];
    int n = count_ov(s);
    for (int i = 0; i < n; i++)
        ov[i] = (char *)s->ov[i];
    snprintf(od, sizeof od, "output.dir=%s", dir);
    ov[n++] = od;
    ov[n++] = "output.quiet=on";
    if (extra)
        ov[n++] = (char *)extra;
    snprintf(path, sizeof path, CASES_DIR "%s", s->file);
    int rc = case_load(cs, path, n, ov, err, sizeof err);
    if (rc != 0)
        print_error("%s: %s\n", s->tag, err);
    assert_int_equal(rc, 0);
}

static void run_with(const struct muflow_case *cs, const char *restart_from, struct run_result *r,
                     const char *tag)
{
    char err[1024];
    struct run_options opt = {.write_output = 1, .restart_from = restart_from};
    int rc = run_case_opts(cs, &opt, r, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s: %s\n", tag, err);
    assert_int_equal(rc, RUN_OK);
}

/* The index of the shipped case tag. */
static int shipped_index(const char *tag)
{
    shipped_list();
    int i = 0;
    while (i < nshipped && strcmp(shipped[i].tag, tag) != 0)
        i++;
    assert_true(i < nshipped);
    return i;
}

/* Runs every shipped case once (a and b), for the tests below. */
static void shipped_runs(void)
{
    if (runs_done)
        return;
    shipped_list();
    for (int i = 0; i < nshipped; i++) {
        const struct shipped *s = &shipped[i];
        struct runs *w = &runs[i];
        char tag[32];
        snprintf(tag, sizeof tag, "cases_%.20s", s->tag);
        test_tmp_make(w->dir, sizeof w->dir, tag);
        char dir[sizeof w->dir]; /* a copy: the compiler cannot tell w->a from w->dir */
        memcpy(dir, w->dir, sizeof dir);
        snprintf(w->a, sizeof w->a, "%.63s/a", dir);
        snprintf(w->b, sizeof w->b, "%.63s/b", dir);
        char end[64], stop[64];
        load(s, w->a, NULL, &w->cs);
        snprintf(end, sizeof end, "solver.max_steps=%ld", s->end ? s->end : w->cs.max_steps);
        load(s, w->a, end, &w->cs);
        run_with(&w->cs, NULL, &w->ra, s->tag);
        print_message("%s: %s after %ld steps\n", s->tag, run_status_name(w->ra.status),
                      w->ra.steps);
        if (s->stop == 0)
            continue;
        if (w->ra.steps <= s->stop)
            print_error("%s ends after %ld steps, not after its stop at %ld: its case file "
                        "needs a line in tests/test_cases.c's table\n",
                        s->tag, w->ra.steps, s->stop);
        assert_true(w->ra.steps > s->stop);
        struct muflow_case cb;
        snprintf(stop, sizeof stop, "solver.max_steps=%ld", s->stop);
        load(s, w->b, stop, &cb);
        struct run_result r;
        run_with(&cb, NULL, &r, s->tag);
        assert_int_equal(r.steps, s->stop);
        assert_true(r.checkpointed && r.restartable);
        char ck[200], err[1024];
        snprintf(ck, sizeof ck, "%s/%s", w->b, CHECKPOINT_NAME);
        char *more[] = {end};
        assert_int_equal(checkpoint_load_case(ck, 1, more, &cb, err, sizeof err), 0);
        run_with(&cb, ck, &w->rb, s->tag);
    }
    runs_done = 1;
}

static int teardown(void **state)
{
    (void)state;
    for (int i = 0; runs_done && i < nshipped; i++) {
        char cmd[128];
        snprintf(cmd, sizeof cmd, "rm -rf '%.63s'", runs[i].dir);
        if (strncmp(runs[i].dir, "/tmp/muflow_cases_", 18) == 0 && system(cmd) != 0)
            return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------------- */
/* the tests */

/* Every case file of cases/ runs (the list is the folder's), every line of
 * the table names a case file of it, and every scene of the registry (but
 * none) is in some case. */
static void test_every_case_listed(void **state)
{
    (void)state;
    shipped_list();
    int files = 0;
    for (int i = 0; i < nshipped; i++) {
        char path[256];
        snprintf(path, sizeof path, CASES_DIR "%s", shipped[i].file);
        assert_true(test_file_exists(path));
        files += i == 0 || strcmp(shipped[i].file, shipped[i - 1].file) != 0;
    }
    for (int x = 0; x < NEXCEPTIONS; x++) {
        if (!exception_found[x])
            print_error("tests/test_cases.c's table names %s, which is not in cases/\n",
                        exceptions[x].file);
        assert_true(exception_found[x]);
    }
    print_message("%d case files, %d runs (%d lines of the table)\n", files, nshipped,
                  NEXCEPTIONS);
    assert_true(files > 1 && nshipped >= files);
    for (int k = 0; k < scene_count(); k++) {
        const char *name = scene_at(k)->name;
        int used = strcmp(name, "none") == 0;
        for (int i = 0; i < nshipped && !used; i++) {
            struct muflow_case cs;
            load(&shipped[i], "/tmp/unused", NULL, &cs);
            used = case_scene(&cs) == scene_at(k);
        }
        if (!used)
            print_error("scene %s has no case in cases/\n", name);
        assert_true(used);
    }
}

/* Every case file's first step on its own grid (auto's choice depends on
 * it) probes no matrix of the grid's unknowns (summary.ini: grid_matrices),
 * but for the two that docs/numerics/linear-solvers.md says still
 * factorise: the cavity's Newton (the Cholesky of the diagonal tangent)
 * and the granular cylinder's coupled LU.  They are asserted to, so the
 * page's table stays true: one that stops factorising leaves the list.
 * Likewise the projection's whole-grid factorisation (pressure_matrices:
 * a 2D grid of at most 32,768 cells with a variable density or a body,
 * docs/numerics/pressure.md) in the cases the same table lists.
 * bagnold3d names its preconditioner (fourier), so its grid is cut to 16 x
 * 16 x 32 (8 s a step as shipped). */
static int on_list(const char *file, const char *const *list, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (strcmp(file, list[k]) == 0)
            return 1;
    return 0;
}

static void test_shipped_matrix_free(void **state)
{
    (void)state;
    static const char *const factorising[] = {"bingham_cavity.ini", "cylinder.ini"};
    static const char *const pressure_factorising[] = {
        "bagnold2.ini",      "collapse.ini", "cylinder.ini",      "cylinder_benchmark.ini",
        "duct_circular.ini", "front.ini",    "slope_release.ini", "wall_shock.ini"};
    shipped_list();
    for (int i = 0; i < nshipped; i++) {
        if (i > 0 && strcmp(shipped[i].file, shipped[i - 1].file) == 0)
            continue;
        char path[256];
        snprintf(path, sizeof path, CASES_DIR "%s", shipped[i].file);
        char *ov[] = {"solver.max_steps=1", "output.fields=off", "domain.nx=16", "domain.ny=16",
                      "domain.nz=32"};
        int cut = strcmp(shipped[i].file, "bagnold3d.ini") == 0;
        struct muflow_case cs;
        struct run_result r;
        test_run_case(path, cut ? 5 : 2, ov, &cs, &r);
        const int listed =
            on_list(shipped[i].file, factorising, sizeof factorising / sizeof factorising[0]);
        const int pressure_listed =
            on_list(shipped[i].file, pressure_factorising,
                    sizeof pressure_factorising / sizeof pressure_factorising[0]);
        print_message("%-24s %ld grid matrices in its first step%s, the pressure's %ld%s\n",
                      shipped[i].file, r.grid_matrices, listed ? " (listed as factorising)" : "",
                      r.pressure_matrices, pressure_listed ? " (listed)" : "");
        assert_true(r.steps >= 1);
        if (listed)
            assert_true(r.grid_matrices > 0);
        else
            assert_int_equal(r.grid_matrices, 0);
        if (pressure_listed)
            assert_true(r.pressure_matrices > 0);
        else
            assert_int_equal(r.pressure_matrices, 0);
    }
}

/* Stopped at max_steps and continued (--restart's path, run_case_opts with
 * restart_from and a larger max_steps): the uninterrupted run's [result]
 * and its scene's and modules' files, bit for bit (same binary, thread
 * count and process). */
static void test_continued_as_uninterrupted(void **state)
{
    (void)state;
    shipped_runs();
    for (int i = 0; i < nshipped; i++) {
        const struct shipped *s = &shipped[i];
        struct runs *w = &runs[i];
        if (s->stop == 0) {
            /* refused, with the reason */
            char ck[200], err[1024];
            snprintf(ck, sizeof ck, "%s/%s", w->a, CHECKPOINT_NAME);
            struct muflow_case cc;
            assert_int_equal(checkpoint_load_case(ck, 0, NULL, &cc, err, sizeof err), 0);
            struct run_options opt = {.write_output = 1, .restart_from = ck};
            struct run_result r;
            assert_int_equal(run_case_opts(&cc, &opt, &r, err, sizeof err), RUN_ERR_SETUP);
            print_message("%s: --restart refused: %s\n", s->tag, err);
            assert_non_null(strstr(err, "cannot continue from a checkpoint"));
            assert_false(w->ra.restartable);
            continue;
        }
        char *x = test_summary_result(w->a), *y = test_summary_result(w->b);
        if (strcmp(x, y) != 0)
            print_error("%s: the continued run's [result]\n%s\nthe uninterrupted one's\n%s\n",
                        s->tag, y, x);
        assert_string_equal(x, y);
        free(x);
        free(y);
        /* the scene's and its modules' own files (forces.csv: a body's) */
        const char *files[SCENE_OUTPUT_FILES_MAX];
        assert_true(scene_output_files(files, SCENE_OUTPUT_FILES_MAX, NULL) > 0);
        for (const char *const *f = files; *f; f++) {
            char path[256];
            snprintf(path, sizeof path, "%s/%s", w->a, *f);
            if (access(path, F_OK) != 0)
                continue; /* not written by this run (growth.csv of a steady one) */
            char *fa = test_read_csv_without_wall(w->a, *f);
            char *fb = test_read_csv_without_wall(w->b, *f);
            if (strcmp(fa, fb) != 0)
                print_error("%s: %s differs after the continuation\n", s->tag, *f);
            assert_string_equal(fa, fb);
            free(fa);
            free(fb);
        }
        print_message("%s: stopped at step %ld, continued to %ld: the same [result] and files\n",
                      s->tag, s->stop, w->rb.steps);
    }
}

/* Python's configparser, strict (a key twice in a section, or a section
 * twice, is an error), reads every case's summary.ini. */
static void test_summary_strict_ini(void **state)
{
    (void)state;
    shipped_runs();
    for (int i = 0; i < nshipped; i++) {
        char cmd[512];
        snprintf(cmd, sizeof cmd,
                 PYTHON " -c 'import configparser, sys\n"
                        "c = configparser.ConfigParser(strict=True, interpolation=None)\n"
                        "c.read(sys.argv[1])\n"
                        "print(len(c[\"result\"]), len(c[\"case\"]))' '%s/summary.ini' 2>&1",
                 runs[i].a);
        char *out;
        int rc = test_sh(cmd, &out);
        print_message("%s: summary.ini: %s", shipped[i].tag, out);
        assert_int_equal(rc, 0);
        free(out);
    }
}

/* run_result_value of every [result] line: its number (as written, to the
 * line's digits), or NaN for a text (status, message). */
static void test_result_values(void **state)
{
    (void)state;
    shipped_runs();
    for (int i = 0; i < nshipped; i++) {
        char *s = test_read_in(runs[i].a, "summary.ini");
        char *line = strstr(s, "[result]\n");
        assert_non_null(line);
        int lines = 0;
        for (line = strchr(line, '\n') + 1; *line && *line != '\n'; line = strchr(line, '\n') + 1) {
            char key[64], text[256];
            assert_int_equal(sscanf(line, "%63s = %255[^\n]", key, text), 2);
            char *end;
            double t = strtod(text, &end);
            double v = run_result_value(&runs[i].ra, key);
            int number = end != text && (*end == '\0' || *end == ' ');
            if (!number ? !isnan(v)
                        : isnan(t) ? !isnan(v) : !(fabs(v - t) <= 5e-6 * fabs(t)))
                print_error("%s: %s = %s, run_result_value %.17g\n", shipped[i].tag, key, text,
                            v);
            if (!number)
                assert_true(isnan(v));
            else if (isnan(t))
                assert_true(isnan(v));
            else
                assert_true(fabs(v - t) <= 5e-6 * fabs(t));
            lines++;
        }
        print_message("%s: %d lines of [result] read back\n", shipped[i].tag, lines);
        free(s);
    }
    /* the names the README's "Outputs" promises, read on bagnold's run */
    const struct run_result *b = &runs[shipped_index("bagnold")].ra;
    assert_true(run_result_value(b, "err_rms") > 0.0);
    assert_true(run_result_value(b, "err_max") >= run_result_value(b, "err_rms"));
    assert_true(fabs(run_result_value(b, "u_surface_exact") - 1.5913872) < 1e-6);
    assert_true(run_result_value(b, "steps") == (double)b->steps);
}

/* The forces are named for what they hold: drag_force along the flow
 * (positive downstream), lift_force across it; the cylinder's drag and
 * drag_surface are its drag_force_control_volume and drag_force (the flow
 * along -z, across the symmetry plane nothing); a duct's wall, no body in
 * a flow, has no force lines. */
static void test_summary_force_names(void **state)
{
    (void)state;
    shipped_runs();
    const struct run_result *c = &runs[shipped_index("cylinder")].ra;
    assert_int_equal(c->status, STATUS_STEADY);
    double drag = run_result_value(c, "drag_force");
    print_message("cylinder: drag_force %.10g (drag_surface %.10g), control volume %.10g (drag "
                  "%.10g), lift_force %g\n",
                  drag, run_result_value(c, "drag_surface"),
                  run_result_value(c, "drag_force_control_volume"), run_result_value(c, "drag"),
                  run_result_value(c, "lift_force"));
    assert_true(drag > 0.0);
    assert_true(drag == run_result_value(c, "drag_surface"));
    assert_true(run_result_value(c, "drag_force_control_volume") == run_result_value(c, "drag"));
    assert_true(run_result_value(c, "lift_force") == 0.0);
    assert_true(run_result_value(c, "lift_force_control_volume") == 0.0);
    /* the flow along +x */
    const struct run_result *b = &runs[shipped_index("cylinder_benchmark")].ra;
    assert_true(run_result_value(b, "drag_force") > 0.0);
    assert_true(run_result_value(b, "drag_coefficient") > 0.0);
    const char *ducts[] = {"duct_circular", "duct_circular_two_fluid"};
    for (int m = 0; m < 2; m++) {
        const struct run_result *d = &runs[shipped_index(ducts[m])].ra;
        for (int i = 0; i < d->values.n; i++)
            if (strstr(d->values.v[i].key, "force"))
                print_error("%s: %s = %s\n", ducts[m], d->values.v[i].key, d->values.v[i].text);
        assert_true(isnan(run_result_value(d, "drag_force")));
        assert_true(isnan(run_result_value(d, "lift_force")));
        assert_true(run_result_value(d, "mean_velocity") > 0.0); /* the duct's: Q / area */
    }
}

/* A checkpoint without the modules' state (as an earlier muflow wrote
 * them): bagnold2's steady run goes on (its density from today's T), the
 * collapse, whose record covers the run from the start, is refused and
 * says why. */
static void test_checkpoint_without_module_state(void **state)
{
    (void)state;
    shipped_runs();
    const char *tags[] = {"bagnold2", "collapse"};
    for (int m = 0; m < 2; m++) {
        const struct runs *w = &runs[shipped_index(tags[m])];
        char ck[200], old[200], cmd[512], err[1024];
        snprintf(ck, sizeof ck, "%.95s/%s", w->b, CHECKPOINT_NAME);
        snprintf(old, sizeof old, "%.63s/earlier.h5", w->dir);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", ck, old);
        assert_int_equal(system(cmd), 0);
        hid_t f = H5Fopen(old, H5F_ACC_RDWR, H5P_DEFAULT);
        assert_true(f >= 0);
        assert_true(H5Ldelete(f, "modules", H5P_DEFAULT) >= 0);
        H5Fclose(f);
        struct muflow_case cs;
        assert_int_equal(checkpoint_load_case(old, 0, NULL, &cs, err, sizeof err), 0);
        struct run_options opt = {.write_output = 0, .restart_from = old};
        struct run_result r;
        int rc = run_case_opts(&cs, &opt, &r, err, sizeof err);
        print_message("%s from a checkpoint without its modules' state: %s\n", tags[m],
                      rc == RUN_OK ? run_status_name(r.status) : err);
        if (m == 0) {
            assert_int_equal(rc, RUN_OK);
        } else {
            assert_int_equal(rc, RUN_ERR_SETUP);
            assert_non_null(strstr(err, "no state of the physics module collapse"));
        }
    }
}

/* The names of every file a run writes: after any case's run, removing
 * them leaves its folder empty but for a file of the user's. */
static void test_run_files_cover_every_case(void **state)
{
    (void)state;
    shipped_runs();
    const char *names[SCENE_OUTPUT_FILES_MAX];
    assert_true(scene_output_files(names, SCENE_OUTPUT_FILES_MAX, NULL) > 0);
    for (int i = 0; i < nshipped; i++) {
        char copy[96], keep[160], err[512], cmd[256];
        snprintf(copy, sizeof copy, "%.63s/c", runs[i].dir); /* the other tests keep a */
        snprintf(cmd, sizeof cmd, "cp -r '%s' '%s'", runs[i].a, copy);
        assert_int_equal(system(cmd), 0);
        snprintf(keep, sizeof keep, "%s/notes.txt", copy);
        FILE *f = fopen(keep, "w");
        assert_non_null(f);
        fclose(f);
        int removed = output_remove_run_files(copy, names, err, sizeof err);
        assert_true(removed > 0);
        DIR *d = opendir(copy);
        assert_non_null(d);
        struct dirent *e;
        int left = 0;
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
                strcmp(e->d_name, "notes.txt")) {
                print_error("%s: %s is left\n", shipped[i].tag, e->d_name);
                left++;
            }
        closedir(d);
        print_message("%s: %d files removed\n", shipped[i].tag, removed);
        assert_int_equal(left, 0);
        assert_int_equal(access(keep, F_OK), 0);
    }
}

/* A run of scene b into the folder of a run of scene a: none of a's files
 * is left (duct_circular's midplane.csv and obstacle_surface.csv under a
 * collapse, the collapse's collapse.csv and surface.csv under bagnold),
 * a file of the user's is. */
static void one_after_another(const char *a_tag, const char *b_tag, const char *const gone[])
{
    const struct shipped *a = &shipped[shipped_index(a_tag)], *b = &shipped[shipped_index(b_tag)];
    char dir[64];
    test_tmp_make(dir, sizeof dir, "cases_after");
    struct muflow_case cs;
    struct run_result r;
    load(a, dir, "solver.max_steps=3", &cs);
    run_with(&cs, NULL, &r, a->tag);
    char path[256];
    for (int m = 0; gone[m]; m++) {
        snprintf(path, sizeof path, "%s/%s", dir, gone[m]);
        assert_int_equal(access(path, F_OK), 0); /* written by a */
    }
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fclose(f);
    load(b, dir, "solver.max_steps=3", &cs);
    run_with(&cs, NULL, &r, b->tag);
    for (int m = 0; gone[m]; m++) {
        snprintf(path, sizeof path, "%s/%s", dir, gone[m]);
        if (access(path, F_OK) == 0)
            print_error("%s after %s: %s is left\n", b->tag, a->tag, gone[m]);
        assert_int_not_equal(access(path, F_OK), 0);
    }
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    assert_int_equal(access(path, F_OK), 0);
    test_tmp_remove(dir);
}

static void test_one_scene_after_another(void **state)
{
    (void)state;
    const char *const duct[] = {"midplane.csv", "obstacle_surface.csv", NULL};
    const char *const collapse[] = {"collapse.csv", "surface.csv", NULL};
    const char *const heap[] = {"heap.csv", NULL};
    one_after_another("duct_circular", "collapse", duct);
    one_after_another("collapse", "bagnold", collapse);
    one_after_another("heap", "bedload", heap);
}

/* ---------------------------------------------------------------------- */
/* the command line, interrupted */

/* muflow with args, SIGINT once a line containing `when` has been read
 * (NULL: none); its exit status, its stdout in out. */
static int run_cli(char *const args[], const char *when, char *out, size_t len)
{
    int st = test_cli(args, when, when ? SIGINT : 0, out, len);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

/* The collapse, interrupted: "resume with: muflow --restart DIR", and that
 * command ends with the uninterrupted run's collapse.csv and surface.csv. */
static void test_cli_collapse_resumes(void **state)
{
    (void)state;
    char bin[PATH_MAX], dir[64], oa[128], ob[128], out[1 << 16];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "cases_cli");
    snprintf(oa, sizeof oa, "output.dir=%s/a", dir);
    snprintf(ob, sizeof ob, "output.dir=%s/b", dir);
    char *a[] = {bin, CASES_DIR "collapse.ini", "domain.nx=40", "domain.nz=12",
                 "domain.ly=0.125", "solver.end_time=1.5", "collapse.profile_interval=0.5",
                 "solver.progress_interval=0", oa, NULL};
    assert_int_equal(run_cli(a, NULL, out, sizeof out), 0);
    char *b[] = {bin, CASES_DIR "collapse.ini", "domain.nx=40", "domain.nz=12",
                 "domain.ly=0.125", "solver.end_time=1.5", "collapse.profile_interval=0.5",
                 "solver.progress_interval=0", ob, NULL};
    assert_int_equal(run_cli(b, "step     41 ", out, sizeof out), 3);
    const char *resume = strstr(out, "resume with: muflow --restart ");
    if (!resume)
        print_error("%s", out);
    assert_non_null(resume);
    char *rb[] = {bin, "--restart", ob + strlen("output.dir="), NULL};
    assert_int_equal(run_cli(rb, NULL, out, sizeof out), 0);
    assert_non_null(strstr(out, "finished after 150 steps"));
    const char *files[] = {"collapse.csv", "surface.csv"};
    for (int m = 0; m < 2; m++) {
        char *x = test_read_in(oa + strlen("output.dir="), files[m]);
        char *y = test_read_in(ob + strlen("output.dir="), files[m]);
        assert_string_equal(x, y);
        free(x);
        free(y);
    }
    test_tmp_remove(dir);
}

/* muflow with args, interrupted once a line containing `when` has been
 * read: exit status 3, no resume line (--restart would refuse it), the
 * interruption during `during` and what to do instead (`instead`). */
static void interrupted_without_resume(char *const args[], const char *when, const char *during,
                                       const char *instead)
{
    char out[1 << 16], said[128];
    assert_int_equal(run_cli(args, when, out, sizeof out), 3);
    const char *why = strstr(out, "muflow: interrupted");
    print_message("%s", why ? why : out);
    assert_null(strstr(out, "resume with"));
    snprintf(said, sizeof said, "muflow: interrupted by SIGINT during %s", during);
    assert_non_null(strstr(out, said));
    assert_non_null(strstr(out, instead));
}

/* The heap's tilt search and the cylinder's continuation, interrupted: no
 * resume line (--restart would refuse them), what to do instead. */
static void test_cli_search_interrupted(void **state)
{
    (void)state;
    char bin[PATH_MAX], dir[64], od[128], out[1 << 16];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "cases_cli");
    snprintf(od, sizeof od, "output.dir=%s/heap", dir);
    char *heap[] = {bin, CASES_DIR "heap.ini", "domain.ny=14", "domain.nz=20",
                    "solver.progress_interval=0", od, NULL};
    interrupted_without_resume(heap, "step      3 ", "the tilt search", "can start a new search");
    char *rh[] = {bin, "--restart", od + strlen("output.dir="), NULL};
    assert_int_equal(run_cli(rh, NULL, out, sizeof out), 2);

    snprintf(od, sizeof od, "output.dir=%s/cylinder", dir);
    char *cyl[] = {bin, CASES_DIR "cylinder.ini", "domain.nx=20", "domain.nz=60",
                   "rheology.lambda=1e-2", "solver.continuation=1", "cylinder.forcing_end=1.4",
                   "solver.progress_interval=0", od, NULL};
    interrupted_without_resume(cyl, "cylinder: F 1 ", "the continuation", "solver.initial_state");
    test_tmp_remove(dir);
}

void group_cases(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_case_listed),
        cmocka_unit_test(test_shipped_matrix_free),
        cmocka_unit_test(test_continued_as_uninterrupted),
        cmocka_unit_test(test_summary_strict_ini),
        cmocka_unit_test(test_result_values),
        cmocka_unit_test(test_summary_force_names),
        cmocka_unit_test(test_checkpoint_without_module_state),
        cmocka_unit_test(test_run_files_cover_every_case),
        cmocka_unit_test(test_one_scene_after_another),
        cmocka_unit_test(test_cli_collapse_resumes),
        cmocka_unit_test(test_cli_search_interrupted),
    };
    t->run += (int)(sizeof tests / sizeof tests[0]);
    t->failed += _cmocka_run_group_tests("cases", tests, sizeof tests / sizeof tests[0], NULL,
                                         teardown);
}
