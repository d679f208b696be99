/* Field files, fields.xdmf, checkpoints, restarts and interruption.
 *
 * HDF5 is read back with the HDF5 library directly (not through src/), and
 * compared with the state in memory.  Interruption is made deterministic in
 * process by a run hook that raise()s SIGINT at a chosen step; the command
 * line is interrupted by SIGTERM and SIGKILL while its progress output is held
 * back by a one-page pipe, so it cannot run far past the step it reported.
 * A continued run must reproduce the uninterrupted one bit for bit: the same
 * binary, thread count and FFTW plans (FFTW_ESTIMATE plans the same ones in
 * every process; the checkpoint also carries FFTW's wisdom) give the same
 * floating-point operations in the same order. */
#define _GNU_SOURCE /* popen, symlink */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "io/checkpoint.h"
#include "io/fields_h5.h"
#include "io/h5io.h"
#include "io/output.h"
#include "march/march.h"
#include "app/run.h"
#include "scenes/scene.h"
#include "test_main.h"

/* The cell datasets of a field file of a single-phase run, as
 * docs/user-guide.md and fields_h5.h document them: five scalars and the
 * cell-centred velocity. */
/* The heap scene's own output (scenes/heap.c: files). */
static const char *const scene_files[] = {"heap.csv", NULL};
#define FIELDS_CELL_SCALARS 5
static const char *const fields_cell_scalar_names[FIELDS_CELL_SCALARS] = {
    "pressure", "pressure_regularised", "shear_rate", "inertial_number", "viscosity"};
#define FIELDS_CELL_VECTOR "velocity"

#define CASES_DIR "../cases/"

/* ---------------------------------------------------------------------- */
/* 1. field files hold exactly the fields in memory */

struct key_check {
    hid_t file;
    int checked;
};

static int check_key(void *vctx, const char *section, const char *key, const char *value)
{
    struct key_check *k = vctx;
    char name[128], text[1024];
    snprintf(name, sizeof name, "%s.%s", section, key);
    test_h5_attr_text(k->file, name, text, sizeof text);
    if (strcmp(text, value) != 0)
        print_error("attribute %s = '%s', case has '%s'\n", name, text, value);
    assert_string_equal(text, value);
    k->checked++;
    return 0;
}

static int periodic(const struct march_state *st, int d)
{
    return st->bc.face[d][0] == BC_PERIODIC;
}

/* Compares every dataset of dir's field file with st, value for value. */
static void check_fields_file(const char *dir, const struct march_state *st)
{
    const struct grid *g = &st->g;
    char name[64], path[700];
    fields_h5_name(st->step, name, sizeof name);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    hid_t file = test_h5_open(path);

    int n[3];
    double len[3], h[3], time;
    long step;
    test_h5_attr(file, "n", H5T_NATIVE_INT, n);
    test_h5_attr(file, "len", H5T_NATIVE_DOUBLE, len);
    test_h5_attr(file, "h", H5T_NATIVE_DOUBLE, h);
    test_h5_attr(file, "step", H5T_NATIVE_LONG, &step);
    test_h5_attr(file, "time", H5T_NATIVE_DOUBLE, &time);
    for (int d = 0; d < 3; d++) {
        assert_int_equal(n[d], g->n[d]);
        assert_true(len[d] == g->len[d] && h[d] == g->h[d]);
    }
    assert_int_equal(step, st->step);
    assert_true(time == st->time);
    struct key_check kc = {file, 0};
    case_visit_keys(st->cs, check_key, &kc);
    assert_true(kc.checked > 40);

    /* faces: n distinct faces along a periodic direction, n + 1 otherwise */
    static const char *const comp[3] = {"u", "v", "w"};
    for (int c = 0; c < 3; c++) {
        int rank;
        hsize_t dims[4];
        double *a = test_h5_dataset(file, comp[c], NULL, &rank, dims);
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[c] += periodic(st, c) ? 0 : 1;
        assert_int_equal(rank, 3);
        assert_true(dims[0] == (hsize_t)hi[2] && dims[1] == (hsize_t)hi[1] &&
                    dims[2] == (hsize_t)hi[0]);
        size_t m = 0;
        for (int k = 0; k < hi[2]; k++)
            for (int j = 0; j < hi[1]; j++)
                for (int i = 0; i < hi[0]; i++, m++)
                    assert_true(a[m] == st->field.velocity[c][grid_idx(g, i, j, k)]);
        free(a);
    }
    /* cell-centred scalars, from their definitions */
    for (int f = 0; f < FIELDS_CELL_SCALARS; f++) {
        int rank;
        hsize_t dims[4];
        double *a = test_h5_dataset(file, fields_cell_scalar_names[f], NULL, &rank, dims);
        assert_int_equal(rank, 3);
        assert_true(dims[0] == (hsize_t)g->n[2] && dims[1] == (hsize_t)g->n[1] &&
                    dims[2] == (hsize_t)g->n[0]);
        size_t m = 0;
        for (int k = 0; k < g->n[2]; k++)
            for (int j = 0; j < g->n[1]; j++)
                for (int i = 0; i < g->n[0]; i++, m++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    double shear = sqrt(st->field.shear2[p]);
                    double want[FIELDS_CELL_SCALARS] = {
                        st->field.pressure[p], st->field.pressure_regularised[p], shear,
                        rheology_inertial_number(&st->cs->rheo, shear,
                                                 st->field.pressure_regularised[p]),
                        st->field.viscosity[p]};
                    assert_true(a[m] == want[f]);
                }
        free(a);
    }
    /* cell velocity: mean of the two faces, periodic wrap at the high end */
    int rank;
    hsize_t dims[4];
    double *a = test_h5_dataset(file, FIELDS_CELL_VECTOR, NULL, &rank, dims);
    assert_int_equal(rank, 4);
    assert_true(dims[3] == 3);
    size_t m = 0;
    double vmax = 0.0;
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++)
                for (int c = 0; c < 3; c++, m++) {
                    int up[3] = {i, j, k};
                    up[c] = (up[c] + 1 == g->n[c] && periodic(st, c)) ? 0 : up[c] + 1;
                    double want = 0.5 * (st->field.velocity[c][grid_idx(g, i, j, k)] +
                                         st->field.velocity[c][grid_idx(g, up[0], up[1], up[2])]);
                    assert_true(a[m] == want);
                    vmax = fmax(vmax, fabs(a[m]));
                }
    assert_true(vmax > 0.1); /* a flowing state, not zeros compared with zeros */
    free(a);
    H5Fclose(file);
}

static void fields_of(const char *file, int n, char *ov[])
{
    struct muflow_case cs;
    test_load_case(&cs, file, n, ov);
    struct march_state st;
    char err[1024], dir[64];
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    march_run(&st, NULL, NULL);
    assert_int_equal(st.status, STATUS_STEADY);
    test_tmp_make(dir, sizeof dir, "io_fields");
    int rc = fields_h5_write(dir, &st, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    check_fields_file(dir, &st);
    march_destroy(&st);
    test_tmp_remove(dir);
}

static void test_fields_match_memory(void **state)
{
    (void)state;
    char *bag[] = {"domain.nz=10"};
    fields_of(CASES_DIR "bagnold.ini", 1, bag);   /* z: wall / surface, x, y periodic */
    char *chute[] = {"domain.ny=10", "domain.nx=3"}; /* y: walls, x periodic with 3 faces */
    fields_of(CASES_DIR "chute.ini", 2, chute);
}

/* ---------------------------------------------------------------------- */
/* 2. fields.xdmf: well-formed, its datasets exist with its dimensions */

static int count_of(const char *text, const char *what)
{
    int n = 0;
    for (const char *p = strstr(text, what); p; p = strstr(p + 1, what))
        n++;
    return n;
}

/* Checks every HDF dataset reference of dir/fields.xdmf; returns the steps of
 * its grids (at most max) and their number. */
static int check_xdmf(const char *dir, long *steps, int max)
{
    char path[700], cmd[800];
    snprintf(path, sizeof path, "%s/fields.xdmf", dir);
    snprintf(cmd, sizeof cmd, "xmllint --noout '%s'", path);
    int st = system(cmd);
    if (st != 0)
        print_error("%s failed (status %d; xmllint comes with libxml2-utils, make deps)\n", cmd,
                    st);
    assert_int_equal(st, 0);
    char *text = test_read_file(path, NULL);
    int grids = 0;
    for (const char *p = strstr(text, "<Grid Name=\"step "); p;
         p = strstr(p + 1, "<Grid Name=\"step ")) {
        assert_true(grids < max);
        steps[grids++] = strtol(p + strlen("<Grid Name=\"step "), NULL, 10);
    }
    assert_int_equal(count_of(text, "<Time Value="), grids);
    /* every <DataItem Dimensions="..." ... Format="HDF">file:/name</DataItem> */
    int refs = 0;
    for (const char *p = strstr(text, "Format=\"HDF\">"); p; p = strstr(p + 1, "Format=\"HDF\">")) {
        const char *item = p;
        while (item > text && strncmp(item, "<DataItem", 9) != 0)
            item--;
        const char *dq = strstr(item, "Dimensions=\"");
        assert_true(dq && dq < p);
        long want[4];
        int wrank = 0;
        char *q = (char *)dq + strlen("Dimensions=\"");
        while (*q != '"') {
            assert_true(wrank < 4);
            want[wrank++] = strtol(q, &q, 10);
            while (*q == ' ')
                q++;
        }
        const char *ref = p + strlen("Format=\"HDF\">");
        const char *colon = strstr(ref, ":/"), *end = strstr(ref, "</DataItem>");
        assert_true(colon && end && colon < end);
        char h5[700], set[128];
        snprintf(h5, sizeof h5, "%s/%.*s", dir, (int)(colon - ref), ref);
        snprintf(set, sizeof set, "%.*s", (int)(end - colon - 2), colon + 2);
        hid_t file = test_h5_open(h5);
        int rank;
        hsize_t dims[4];
        double *a = test_h5_dataset(file, set, NULL, &rank, dims);
        free(a);
        assert_int_equal(rank, wrank);
        for (int d = 0; d < rank; d++)
            assert_int_equal((long)dims[d], want[d]);
        /* the grid's time is the file's */
        const char *grid = item;
        while (grid > text && strncmp(grid, "<Time Value=\"", 13) != 0)
            grid--;
        double t, tf;
        assert_int_equal(sscanf(grid, "<Time Value=\"%lf\"", &t), 1);
        test_h5_attr(file, "time", H5T_NATIVE_DOUBLE, &tf);
        assert_true(t == tf);
        H5Fclose(file);
        refs++;
    }
    assert_int_equal(refs, grids * (FIELDS_CELL_SCALARS + 1));
    free(text);
    return grids;
}

static void test_xdmf_series(void **state)
{
    (void)state;
    char dir[64], o[700];
    test_tmp_make(dir, sizeof dir, "io_xdmf");
    /* by steps: 0, 20, 40 and the end (bagnold H/10 from dt 0.1: 53 steps) */
    snprintf(o, sizeof o, "output.dir=%s/steps", dir);
    char *ov1[] = {"domain.nz=10", "solver.dt=0.1", "output.fields_every=20", "output.quiet=on",
                   o};
    struct muflow_case cs;
    test_load_case(&cs, CASES_DIR "bagnold.ini", 5, ov1);
    struct run_result r;
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_STEADY);
    long steps[64];
    snprintf(o, sizeof o, "%s/steps", dir);
    int n = check_xdmf(o, steps, 64);
    long want1[] = {0, 20, 40, r.steps};
    assert_true(r.steps > 40);
    assert_int_equal(n, 4);
    for (int m = 0; m < n; m++)
        assert_int_equal(steps[m], want1[m]);

    /* by time: a transient start-up with dt 0.01 to t = 0.05, a file every 0.02:
     * t = 0, 0.02, 0.04 (steps 0, 2, 4; 2 x 0.01 must count as 0.02) and the end */
    snprintf(o, sizeof o, "output.dir=%s/time", dir);
    char *ov2[] = {"domain.nz=10", "solver.mode=transient", "solver.dt=0.01",
                   "solver.end_time=0.05", "output.fields_interval=0.02", "output.quiet=on", o};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 7, ov2);
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_FINISHED);
    snprintf(o, sizeof o, "%s/time", dir);
    n = check_xdmf(o, steps, 64);
    long want2[] = {0, 2, 4, 5};
    assert_int_equal(n, 4);
    for (int m = 0; m < n; m++)
        assert_int_equal(steps[m], want2[m]);

    /* output.fields = off: none */
    snprintf(o, sizeof o, "output.dir=%s/none", dir);
    char *ov3[] = {"domain.nz=10", "output.fields=off", "output.quiet=on", o};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 4, ov3);
    test_run_loaded(&cs, 1, &r);
    snprintf(o, sizeof o, "%s/none/fields.xdmf", dir);
    assert_false(test_file_exists(o));
    test_tmp_remove(dir);
}

/* ---------------------------------------------------------------------- */
/* 3. interrupted and continued runs equal uninterrupted ones bit for bit */

struct stop_at {
    long step;
    int sig;
    int raised;
};

static void raise_at(void *vctx, const struct march_state *st)
{
    struct stop_at *s = vctx;
    if (st->step == s->step && st->status == STATUS_RUNNING && !s->raised) {
        s->raised = 1;
        raise(s->sig); /* the handler runs before raise returns */
    }
}

/* Each step once, in order, 0 .. last. */
static void history_continuous(const char *dir, long last)
{
    char *h = test_read_csv_without_wall(dir, "history.csv");
    long expect = 0;
    for (char *line = strchr(h, '\n') + 1; *line; line = strchr(line, '\n') + 1) {
        assert_int_equal(strtol(line, NULL, 10), expect);
        expect++;
    }
    assert_int_equal(expect - 1, last);
    free(h);
}

static void interrupt_and_continue(const char *file, int n, char **ov, long stop, int tag)
{
    char dir[64], oa[700], ob[700], err[1024];
    test_tmp_make(dir, sizeof dir, "io_restart");
    snprintf(oa, sizeof oa, "output.dir=%s/a", dir);
    snprintf(ob, sizeof ob, "output.dir=%s/b", dir);
    char *all[16];
    assert_true(n + 3 <= 16); /* its overrides, quiet, output.dir, one output key */
    for (int m = 0; m < n; m++)
        all[m] = ov[m];
    all[n] = "output.quiet=on";

    /* a: uninterrupted */
    struct muflow_case ca, cb, cc;
    all[n + 1] = oa;
    test_load_case(&ca, file, n + 2, all);
    struct run_result ra, rb, rc;
    test_run_loaded(&ca, 1, &ra);
    print_message("%s: uninterrupted %s after %ld steps\n", ca.name, run_status_name(ra.status),
                  ra.steps);
    assert_true(ra.status == STATUS_STEADY || ra.status == STATUS_FINISHED);
    assert_true(ra.steps > stop + 2);

    /* b: SIGINT at step `stop`, written to checkpoint, then continued */
    all[n + 1] = ob;
    all[n + 2] = tag ? "output.checkpoint_every=5" : "output.fields_every=7";
    test_load_case(&cb, file, n + 3, all);
    struct stop_at s = {stop, SIGINT, 0};
    struct run_options opt = {.write_output = 1, .hook = raise_at, .hook_ctx = &s};
    assert_int_equal(run_case_opts(&cb, &opt, &rb, err, sizeof err), RUN_OK);
    assert_int_equal(rb.status, STATUS_STOPPED);
    assert_int_equal(rb.steps, stop);
    assert_int_equal(rb.signal, SIGINT);
    assert_true(rb.checkpointed);
    assert_int_equal(run_exit_code(rb.status), 3);
    char want[128];
    snprintf(want, sizeof want, "interrupted by SIGINT at step %ld", stop);
    assert_string_equal(rb.message, want);
    char *res = test_summary_result(ob + strlen("output.dir="));
    assert_non_null(strstr(res, "status = stopped"));
    free(res);

    char ck[800];
    snprintf(ck, sizeof ck, "%s/%s", ob + strlen("output.dir="), CHECKPOINT_NAME);
    int lrc = checkpoint_load_case(ck, 0, NULL, &cc, err, sizeof err);
    if (lrc != 0)
        print_error("%s\n", err);
    assert_int_equal(lrc, 0);
    assert_string_equal(cc.name, cb.name);
    assert_string_equal(cc.output_dir, cb.output_dir);
    struct run_options cont = {.write_output = 1, .restart_from = ck};
    int rrc = run_case_opts(&cc, &cont, &rc, err, sizeof err);
    if (rrc != 0)
        print_error("%s\n", err);
    assert_int_equal(rrc, RUN_OK);
    print_message("%s: stopped at step %ld, continued to %s after %ld steps\n", ca.name, stop,
                  run_status_name(rc.status), rc.steps);
    assert_int_equal(rc.status, ra.status);
    assert_int_equal(rc.steps, ra.steps);

    const char *da = oa + strlen("output.dir="), *db = ob + strlen("output.dir=");
    test_same_fields(da, db, ra.steps);
    char *x = test_summary_result(da), *y = test_summary_result(db);
    assert_string_equal(x, y);
    free(x);
    free(y);
    x = test_read_csv_without_wall(da, "history.csv");
    y = test_read_csv_without_wall(db, "history.csv");
    assert_string_equal(x, y);
    free(x);
    free(y);
    history_continuous(db, ra.steps);
    test_tmp_remove(dir);
}

static void test_interrupt_restart_bagnold(void **state)
{
    (void)state;
    /* from dt 0.01 the pseudo-time march takes ~400 steps */
    char *ov[] = {"domain.nz=10", "solver.dt=0.01"};
    interrupt_and_continue(CASES_DIR "bagnold.ini", 2, ov, 150, 1);
}

static void test_interrupt_restart_chute(void **state)
{
    (void)state;
    char *ov[] = {"domain.ny=20"};
    interrupt_and_continue(CASES_DIR "chute.ini", 1, ov, 8, 0);
}

static void test_interrupt_restart_transient(void **state)
{
    (void)state;
    /* time-accurate: the end time, not a residual, ends it */
    char *ov[] = {"domain.nz=10", "solver.mode=transient", "solver.dt=0.01",
                  "solver.end_time=0.4"};
    interrupt_and_continue(CASES_DIR "bagnold.ini", 4, ov, 17, 1);
}

static void test_interrupt_restart_no_gravity(void **state)
{
    (void)state;
    /* Couette start-up under a lid without gravity: residuals are relative to
     * the first one, which the continued run must not take from its own start */
    char *ov[] = {"case.scene=none", "domain.nz=10", "physics.gravity=0",
                  "boundary.zhi=lid", "rheology.law=newtonian", "solver.mode=transient",
                  "solver.dt=0.01", "solver.end_time=0.3"};
    interrupt_and_continue(CASES_DIR "bagnold.ini", 8, ov, 12, 0);
}

/* ---------------------------------------------------------------------- */
/* 4. the command line: SIGTERM, SIGKILL after periodic checkpoints, --restart */

static void test_cli_signals(void **state)
{
    (void)state;
    char bin[PATH_MAX], dir[64], oa[700], ob[700], oc[700], out[1 << 16];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "io_cli");
    snprintf(oa, sizeof oa, "output.dir=%s/a", dir);
    snprintf(ob, sizeof ob, "output.dir=%s/b", dir);
    snprintf(oc, sizeof oc, "output.dir=%s/c", dir);
    const char *da = oa + 11, *db = ob + 11, *dc = oc + 11;
    char *a[] = {bin, CASES_DIR "bagnold.ini", "domain.nz=10", "solver.dt=0.03",
                 "solver.progress_interval=0", "output.checkpoint_every=25", oa, NULL};
    int st = test_cli(a, NULL, 0, out, sizeof out);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    long steps = 0;
    assert_non_null(strstr(out, "steady after"));
    steps = strtol(strstr(out, "steady after") + 13, NULL, 10);
    /* the child runs at most ~40 steps ahead of the line we act on */
    assert_true(steps > 120);

    /* SIGTERM at step 60 or a little later: exit status 3, a checkpoint */
    char *b[] = {bin, CASES_DIR "bagnold.ini", "domain.nz=10", "solver.dt=0.03",
                 "solver.progress_interval=0", "output.checkpoint_every=25", ob, NULL};
    st = test_cli(b, "step     60 ", SIGTERM, out, sizeof out);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 3);
    assert_non_null(strstr(out, "interrupted by SIGTERM at step"));
    assert_non_null(strstr(out, "resume with: muflow --restart"));
    char ck[800];
    snprintf(ck, sizeof ck, "%s/%s", db, CHECKPOINT_NAME);
    assert_true(test_file_exists(ck));
    char *rb[] = {bin, "--restart", (char *)db, NULL};
    st = test_cli(rb, NULL, 0, out, sizeof out);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    assert_non_null(strstr(out, "continuing from"));

    /* SIGKILL at step 70 or a little later: no outputs, but the last periodic
     * checkpoint (step 50 or later) and the rows of history.csv.tmp up to it */
    char *c[] = {bin, CASES_DIR "bagnold.ini", "domain.nz=10", "solver.dt=0.03",
                 "solver.progress_interval=0", "output.checkpoint_every=25", oc, NULL};
    st = test_cli(c, "step     70 ", SIGKILL, out, sizeof out);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    char *rc[] = {bin, "--restart", (char *)dc, NULL};
    st = test_cli(rc, NULL, 0, out, sizeof out);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    const char *at = strstr(out, "continuing from");
    assert_non_null(at);
    long from = strtol(strstr(at, "at step ") + 8, NULL, 10);
    print_message("killed at step 70 or a little later, continued from step %ld\n", from);
    assert_true(from >= 50 && from % 25 == 0); /* a periodic checkpoint */

    /* The reference run a is a separate process: with FFTW_ESTIMATE it plans
     * the same transforms as b and c (docs/numerics/reproducibility.md), so the
     * fields match bit for bit, and so does the summary. */
    char *x = test_summary_result(da);
    for (int m = 0; m < 2; m++) {
        const char *d = m ? dc : db;
        char *y = test_summary_result(d);
        assert_string_equal(x, y);
        free(y);
        test_same_fields(da, d, steps);
        history_continuous(d, steps);
    }
    free(x);
    test_tmp_remove(dir);
}

/* ---------------------------------------------------------------------- */
/* 5. a checkpoint that cannot be written */

static void test_checkpoint_write_fails(void **state)
{
    (void)state;
    if (!test_file_exists("/dev/full")) {
        print_message("no /dev/full here\n");
        skip();
    }
    char bin[PATH_MAX], dir[64], od[700], out[1 << 16];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "io_full");
    snprintf(od, sizeof od, "output.dir=%s", dir);
    /* a transient run stopped by max_steps leaves a checkpoint of step 10 */
    char *a[] = {bin, CASES_DIR "bagnold.ini", "domain.nz=10", "solver.mode=transient",
                 "solver.dt=0.01", "solver.end_time=1", "solver.max_steps=10", od, NULL};
    int st = test_cli(a, NULL, 0, out, sizeof out);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 3);
    char ck[800], tmp[820];
    snprintf(ck, sizeof ck, "%s/%s", dir, CHECKPOINT_NAME);
    snprintf(tmp, sizeof tmp, "%s.tmp", ck);
    char *before = test_read_file(ck, NULL);
    struct stat sb;
    assert_int_equal(stat(ck, &sb), 0);
    off_t size = sb.st_size;

    /* the next checkpoint goes to a full device */
    assert_int_equal(symlink("/dev/full", tmp), 0);
    char errpath[800];
    snprintf(errpath, sizeof errpath, "%s/stderr", dir);
    int saved = dup(2);
    int efd = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(efd >= 0 && saved >= 0);
    dup2(efd, 2);
    char *b[] = {bin, "--restart", dir, "solver.max_steps=30", "output.checkpoint_every=5",
                 NULL};
    st = test_cli(b, NULL, 0, out, sizeof out);
    dup2(saved, 2);
    close(saved);
    close(efd);
    char *msg = test_read_file(errpath, NULL);
    print_message("exit %d: %s", WIFEXITED(st) ? WEXITSTATUS(st) : -1, msg);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 4);
    assert_non_null(strstr(msg, "checkpoint"));
    assert_non_null(strstr(msg, "No space left on device"));
    /* the run stopped at the failed checkpoint, step 15, and says so */
    char *res = test_summary_result(dir);
    assert_non_null(strstr(res, "status = stopped"));
    assert_non_null(strstr(res, "output failed at step 15"));
    free(res);
    /* the previous checkpoint, untouched */
    assert_int_equal(stat(ck, &sb), 0);
    assert_int_equal(sb.st_size, size);
    char *after = test_read_file(ck, NULL);
    assert_memory_equal(before, after, (size_t)size);
    assert_false(test_file_exists(tmp));
    free(before);
    free(after);
    free(msg);

    /* a folder that is a regular file: the cause is named, nothing written */
    struct muflow_case cs;
    char *ov[] = {"domain.nz=10"};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 1, ov);
    struct march_state ms;
    char err[1024], notdir[800];
    assert_int_equal(scene_march_create(&ms, &cs, NULL, err, sizeof err), 0);
    struct field_series fs;
    field_series_init(&fs);
    snprintf(notdir, sizeof notdir, "%s/stderr", dir);
    assert_int_equal(checkpoint_write(notdir, &ms, &fs, err, sizeof err), -1);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "Not a directory"));
    march_destroy(&ms);
    test_tmp_remove(dir);
}

/* ---------------------------------------------------------------------- */
/* 6. restarting from something that is not a usable checkpoint */

static void test_restart_bad_checkpoint(void **state)
{
    (void)state;
    char dir[64], path[700], err[1024];
    test_tmp_make(dir, sizeof dir, "io_bad");
    struct muflow_case cs;
    snprintf(path, sizeof path, "%s/%s", dir, CHECKPOINT_NAME);
    assert_int_equal(checkpoint_load_case(path, 0, NULL, &cs, err, sizeof err), 2);
    assert_non_null(strstr(err, "No such file or directory"));
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("not HDF5\n", f);
    fclose(f);
    assert_int_equal(checkpoint_load_case(path, 0, NULL, &cs, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "cannot open checkpoint"));

    /* a real checkpoint, continued on a different grid: refused */
    char od[700];
    snprintf(od, sizeof od, "output.dir=%s", dir);
    char *ov[] = {"domain.nz=10", "solver.mode=transient", "solver.dt=0.01",
                  "solver.max_steps=3", "output.quiet=on", od};
    test_load_case(&cs, CASES_DIR "bagnold.ini", 6, ov);
    struct run_result r;
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_STOPPED);
    char *bad[] = {"domain.nz=12"};
    assert_int_equal(checkpoint_load_case(path, 1, bad, &cs, err, sizeof err), 0);
    struct run_options opt = {.write_output = 0, .restart_from = path};
    assert_int_equal(run_case_opts(&cs, &opt, &r, err, sizeof err), RUN_ERR_SETUP);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "grid"));
    /* a bad override is blamed on the override */
    char *typo[] = {"solver.max_step=4"};
    assert_int_equal(checkpoint_load_case(path, 1, typo, &cs, err, sizeof err), 2);
    assert_non_null(strstr(err, "override solver.max_step=4"));
    test_tmp_remove(dir);
}

/* ---------------------------------------------------------------------- */
/* 7. a reused output folder: the earlier run's files go, nothing else */

static void touch(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("x\n", f);
    fclose(f);
}

/* The sorted names in dir (without . and ..), one line each. */
static void list_dir(const char *dir, char *out, size_t len)
{
    char cmd[800];
    snprintf(cmd, sizeof cmd, "LC_ALL=C ls -A '%s'", dir);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, len - 1, p);
    out[n] = '\0';
    assert_int_equal(pclose(p), 0);
}

static void test_remove_run_files(void **state)
{
    (void)state;
    char dir[64], od[700], err[1024], path[800];
    test_tmp_make(dir, sizeof dir, "io_stale");
    /* an earlier run: stopped by max_steps, field files every 5 steps and a checkpoint */
    snprintf(od, sizeof od, "output.dir=%s", dir);
    char *ov[] = {"domain.nz=10", "solver.mode=transient", "solver.dt=0.01",
                  "solver.max_steps=10", "output.fields_every=5", "output.quiet=on", od};
    struct muflow_case cs;
    test_load_case(&cs, CASES_DIR "bagnold.ini", 7, ov);
    struct run_result r;
    test_run_loaded(&cs, 1, &r);
    assert_int_equal(r.status, STATUS_STOPPED);
    const char *written[] = {"fields_000000.h5", "fields_000005.h5", "fields_000010.h5",
                             "fields.xdmf", "history.csv", "profile.csv", "summary.ini",
                             CHECKPOINT_NAME};
    for (size_t m = 0; m < sizeof written / sizeof written[0]; m++) {
        snprintf(path, sizeof path, "%s/%s", dir, written[m]);
        assert_true(test_file_exists(path));
    }
    /* what a killed run or the heap scene leaves, and a long step number */
    const char *more[] = {"heap.csv", "heap.csv.tmp", "fields_000015.h5.tmp",
                          "fields_1234567.h5", "fields.xdmf.tmp", "history.csv.tmp",
                          "profile.csv.tmp", "summary.ini.tmp", CHECKPOINT_NAME ".tmp"};
    for (size_t m = 0; m < sizeof more / sizeof more[0]; m++)
        touch(dir, more[m]);
    /* not the run's: kept */
    const char *keep[] = {"notes.txt", "fields_abc.h5", "fields_12345.h5", "fields_000001.h5.bak",
                          "summary.ini.orig", "history.csv~", "field.png", "Summary.ini",
                          "xfields_000001.h5", "fields_000001.h5.tmp.tmp"};
    for (size_t m = 0; m < sizeof keep / sizeof keep[0]; m++)
        touch(dir, keep[m]);
    snprintf(path, sizeof path, "%s/fields_000002.h5", dir); /* a folder of a run file's name */
    assert_int_equal(mkdir(path, 0777), 0);
    touch(path, "inside");
    snprintf(path, sizeof path, "%s/plots", dir);
    assert_int_equal(mkdir(path, 0777), 0);
    touch(path, "summary.ini");

    int removed = output_remove_run_files(dir, scene_files, err, sizeof err);
    if (removed < 0)
        print_error("%s\n", err);
    assert_int_equal(removed, (int)(sizeof written / sizeof written[0] +
                                    sizeof more / sizeof more[0]));
    char names[4096];
    list_dir(dir, names, sizeof names);
    print_message("left:\n%s", names);
    assert_string_equal(names, "Summary.ini\nfield.png\nfields_000001.h5.bak\n"
                               "fields_000001.h5.tmp.tmp\nfields_000002.h5\nfields_12345.h5\n"
                               "fields_abc.h5\nhistory.csv~\nnotes.txt\nplots\n"
                               "summary.ini.orig\nxfields_000001.h5\n");
    snprintf(path, sizeof path, "%s/plots/summary.ini", dir); /* not recursive */
    assert_true(test_file_exists(path));
    snprintf(path, sizeof path, "%s/fields_000002.h5/inside", dir);
    assert_true(test_file_exists(path));
    assert_int_equal(output_remove_run_files(dir, scene_files, err, sizeof err), 0); /* again: nothing */

    /* a folder that does not exist yet: nothing to do */
    snprintf(path, sizeof path, "%s/new", dir);
    assert_int_equal(output_remove_run_files(path, scene_files, err, sizeof err), 0);
    /* a file where the folder should be: the cause is named */
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    assert_int_equal(output_remove_run_files(path, scene_files, err, sizeof err), -1);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "Not a directory"));
    test_tmp_remove(dir);
}

void group_io(struct test_tally *t)
{
    h5io_init(); /* the failures above are expected: no HDF5 stack dumps */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fields_match_memory),
        cmocka_unit_test(test_xdmf_series),
        cmocka_unit_test(test_interrupt_restart_bagnold),
        cmocka_unit_test(test_interrupt_restart_chute),
        cmocka_unit_test(test_interrupt_restart_transient),
        cmocka_unit_test(test_interrupt_restart_no_gravity),
        cmocka_unit_test(test_cli_signals),
        cmocka_unit_test(test_checkpoint_write_fails),
        cmocka_unit_test(test_restart_bad_checkpoint),
        cmocka_unit_test(test_remove_run_files),
    };
    RUN_GROUP(t, "io", tests);
}
