/* Tests of the case-file reader (src/config/case.c): defaults, a full file,
 * overrides, every class of error, and the round trip through
 * case_write_ini.  Case files are written into a fresh mkdtemp directory. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scenes/scene.h"
#include "test_main.h"
#include "config/case.h"

#define MAX_FILES 16

struct tmp {
    char dir[64];
    char files[MAX_FILES][512];
    int nfiles;
};

static int tmp_setup(void **state)
{
    struct tmp *t = calloc(1, sizeof(*t));
    if (!t)
        return -1;
    snprintf(t->dir, sizeof(t->dir), "/tmp/muflow_case_XXXXXX");
    if (!mkdtemp(t->dir)) {
        free(t);
        return -1;
    }
    *state = t;
    return 0;
}

static int tmp_teardown(void **state)
{
    struct tmp *t = *state;
    for (int i = 0; i < t->nfiles; i++)
        remove(t->files[i]);
    rmdir(t->dir);
    free(t);
    return 0;
}

/* Writes text into dir/name and returns the path (owned by the fixture). */
static const char *put(struct tmp *t, const char *name, const char *text)
{
    assert_true(t->nfiles < MAX_FILES);
    char *path = t->files[t->nfiles], buf[sizeof(t->files[0])];
    snprintf(buf, sizeof(buf), "%s/%.400s", t->dir, name);
    memcpy(path, buf, sizeof(buf));
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
    t->nfiles++;
    return path;
}

/* Field-by-field equality (name included). */
static void assert_case_equal(const struct muflow_case *a, const struct muflow_case *b)
{
    assert_string_equal(a->name, b->name);
    assert_int_equal(a->scene, b->scene);
    for (int d = 0; d < 3; d++) {
        assert_true(a->len[d] == b->len[d]);
        assert_int_equal(a->n[d], b->n[d]);
        assert_int_equal(a->bc.face[d][0], b->bc.face[d][0]);
        assert_int_equal(a->bc.face[d][1], b->bc.face[d][1]);
    }
    assert_true(a->tilt == b->tilt);
    assert_true(a->gravity == b->gravity);
    assert_true(a->density == b->density);
    assert_true(a->confining_pressure == b->confining_pressure);
    assert_int_equal(a->advection, b->advection);
    assert_int_equal(a->rheo.law, b->rheo.law);
    assert_int_equal(a->rheo.reg, b->rheo.reg);
    assert_true(a->rheo.lambda == b->rheo.lambda);
    assert_int_equal(a->rheo.pressure_regularisation, b->rheo.pressure_regularisation);
    assert_true(a->rheo.mu_s == b->rheo.mu_s);
    assert_true(a->rheo.delta_mu == b->rheo.delta_mu);
    assert_true(a->rheo.i0 == b->rheo.i0);
    assert_true(a->rheo.phi == b->rheo.phi);
    assert_true(a->rheo.grain_diameter == b->rheo.grain_diameter);
    assert_true(a->rheo.grain_density == b->rheo.grain_density);
    assert_true(a->rheo.yield_stress == b->rheo.yield_stress);
    assert_true(a->rheo.plastic_viscosity == b->rheo.plastic_viscosity);
    assert_true(a->rheo.viscosity == b->rheo.viscosity);
    assert_int_equal(a->mode, b->mode);
    assert_true(a->tolerance == b->tolerance);
    assert_int_equal(a->max_steps, b->max_steps);
    assert_true(a->end_time == b->end_time);
    assert_true(a->dt == b->dt);
    assert_true(a->dt_max == b->dt_max);
    assert_true(a->cfl == b->cfl);
    assert_int_equal(a->newton, b->newton);
    assert_true(a->linear_tolerance == b->linear_tolerance);
    assert_int_equal(a->max_linear_iterations, b->max_linear_iterations);
    assert_int_equal(a->line_direction, b->line_direction);
    assert_true(a->progress_interval == b->progress_interval);
    assert_string_equal(a->output_dir, b->output_dir);
    assert_int_equal(a->quiet, b->quiet);
}

static const char full_ini[] =
    "; a complete case\n"
    "[case]\n"
    "scene = chute\n"
    "\n"
    "[domain]\n"
    "lx = 2.5\n"
    "  ly = 0.5   ; indented, with an inline comment\n"
    "lz = 10\n"
    "nx = 8\n"
    "ny = 1\n"
    "nz = 64\n"
    "[boundary]\n"
    "xlo = periodic\n"
    "xhi = periodic\n"
    "ylo = slip\n"
    "yhi = slip\n"
    "zlo = wall\n"
    "zhi = surface\n"
    "[physics]\n"
    "tilt = 0.4\n"
    "gravity = 9.81\n"
    "density = 1500\n"
    "confining_pressure = 0.25\n"
    "advection = off\n"
    "[rheology]\n"
    "law = mui\n"
    "regularisation = bercovier\n"
    "lambda = 1e-3\n"
    "mu_s = 0.4\n"
    "delta_mu = 0.3\n"
    "i0 = 0.3\n"
    "phi = 0.5\n"
    "grain_diameter = 0.01\n"
    "grain_density = 2500\n"
    "pressure_regularisation = no\n"
    "yield_stress = 1.5\n"
    "plastic_viscosity = 2\n"
    "viscosity = 3\n"
    "[solver]\n"
    "mode = transient\n"
    "tolerance = 1e-9\n"
    "max_steps = 123456\n"
    "end_time = 20\n"
    "dt = 0.001\n"
    "dt_max = 0.1\n"
    "cfl = 0.25\n"
    "newton = false\n"
    "linear_tolerance = 1e-6\n"
    "max_linear_iterations = 77\n"
    "line_direction = z\n"
    "progress_interval = 0\n"
    "[output]\n"
    "dir = results/full run\n"
    "quiet = yes\n";

static void test_defaults(void **state)
{
    (void)state;
    struct muflow_case c, d;
    char err[256] = "x";
    case_defaults(&d);
    assert_string_equal(d.name, "case");
    assert_int_equal(d.scene, scene_find("none"));
    for (int i = 0; i < 3; i++) {
        assert_true(d.len[i] == 1.0);
        assert_int_equal(d.n[i], 1);
        assert_int_equal(d.bc.face[i][0], BC_PERIODIC);
        assert_int_equal(d.bc.face[i][1], BC_PERIODIC);
    }
    assert_true(d.tilt == 0 && d.gravity == 1 && d.density == 1 && d.confining_pressure == 0);
    assert_int_equal(d.advection, 1);
    assert_int_equal(d.rheo.law, LAW_MUI);
    assert_int_equal(d.rheo.reg, REG_MC);
    assert_true(d.rheo.lambda == 1e-4);
    assert_true(d.rheo.mu_s == 0.383 && d.rheo.delta_mu == 0.26 && d.rheo.i0 == 0.279);
    assert_true(d.rheo.phi == 0.6 && d.rheo.grain_diameter == 1);
    assert_true(d.rheo.grain_density == 1 / 0.6);
    assert_int_equal(d.rheo.pressure_regularisation, 1);
    assert_true(d.rheo.yield_stress == 0 && d.rheo.plastic_viscosity == 0);
    assert_true(d.rheo.viscosity == 1);
    assert_int_equal(d.mode, MODE_STEADY);
    assert_true(d.tolerance == 1e-10);
    assert_int_equal(d.max_steps, 10000);
    assert_true(d.end_time == 1 && d.dt == 1e-2 && d.dt_max == 1e12 && d.cfl == 0.5);
    assert_int_equal(d.newton, 1);
    assert_true(d.linear_tolerance == 1e-8);
    assert_int_equal(d.max_linear_iterations, 500);
    assert_int_equal(d.line_direction, -1);
    assert_true(d.progress_interval == 1.0);
    assert_string_equal(d.output_dir, "out/case");
    assert_int_equal(d.quiet, 0);

    /* no file, no overrides: the defaults, valid as they are */
    assert_int_equal(case_load(&c, NULL, 0, NULL, err, sizeof(err)), 0);
    assert_string_equal(err, "");
    assert_case_equal(&c, &d);
}

static void test_empty_file(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c, d;
    char err[256];
    const char *path = put(t, "empty.ini", "; nothing but a comment\n\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    case_defaults(&d);
    snprintf(d.name, sizeof(d.name), "empty");
    snprintf(d.output_dir, sizeof(d.output_dir), "out/empty");
    assert_case_equal(&c, &d);
}

static void test_full_file(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[256];
    const char *path = put(t, "full.ini", full_ini);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    assert_string_equal(c.name, "full");
    assert_int_equal(c.scene, scene_find("chute"));
    assert_true(c.len[0] == 2.5 && c.len[1] == 0.5 && c.len[2] == 10);
    assert_int_equal(c.n[0], 8);
    assert_int_equal(c.n[1], 1);
    assert_int_equal(c.n[2], 64);
    assert_int_equal(c.bc.face[0][0], BC_PERIODIC);
    assert_int_equal(c.bc.face[0][1], BC_PERIODIC);
    assert_int_equal(c.bc.face[1][0], BC_SLIP);
    assert_int_equal(c.bc.face[1][1], BC_SLIP);
    assert_int_equal(c.bc.face[2][0], BC_WALL);
    assert_int_equal(c.bc.face[2][1], BC_SURFACE);
    assert_true(c.tilt == 0.4 && c.gravity == 9.81 && c.density == 1500);
    assert_true(c.confining_pressure == 0.25);
    assert_int_equal(c.advection, 0);
    assert_int_equal(c.rheo.law, LAW_MUI);
    assert_int_equal(c.rheo.reg, REG_BERCOVIER);
    assert_true(c.rheo.lambda == 1e-3 && c.rheo.mu_s == 0.4 && c.rheo.delta_mu == 0.3);
    assert_true(c.rheo.i0 == 0.3 && c.rheo.phi == 0.5 && c.rheo.grain_diameter == 0.01);
    assert_true(c.rheo.grain_density == 2500);
    assert_int_equal(c.rheo.pressure_regularisation, 0);
    assert_true(c.rheo.yield_stress == 1.5 && c.rheo.plastic_viscosity == 2);
    assert_true(c.rheo.viscosity == 3);
    assert_int_equal(c.mode, MODE_TRANSIENT);
    assert_true(c.tolerance == 1e-9);
    assert_int_equal(c.max_steps, 123456);
    assert_true(c.end_time == 20 && c.dt == 0.001 && c.dt_max == 0.1 && c.cfl == 0.25);
    assert_int_equal(c.newton, 0);
    assert_true(c.linear_tolerance == 1e-6);
    assert_int_equal(c.max_linear_iterations, 77);
    assert_int_equal(c.line_direction, 2);
    assert_true(c.progress_interval == 0);
    assert_string_equal(c.output_dir, "results/full run");
    assert_int_equal(c.quiet, 1);
}

static void test_name_and_default_dir(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[256];
    const char *p1 = put(t, "my.case.ini", "[domain]\nnx = 2\n");
    assert_int_equal(case_load(&c, p1, 0, NULL, err, sizeof(err)), 0);
    assert_string_equal(c.name, "my.case");
    assert_string_equal(c.output_dir, "out/my.case");

    const char *p2 = put(t, "noext", "[domain]\nnx = 2\n");
    assert_int_equal(case_load(&c, p2, 0, NULL, err, sizeof(err)), 0);
    assert_string_equal(c.name, "noext");
    assert_string_equal(c.output_dir, "out/noext");
}

/* BOM, CRLF line ends, name: value, case-insensitive words, all booleans. */
static void test_syntax_variants(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[256];
    const char *path = put(t, "variants.ini",
                           "\xEF\xBB\xBF[physics]\r\n"
                           "advection: False\r\n"
                           "\t[boundary]\r\n"
                           "\tzlo = WALL\r\n"
                           "\tzhi = Slip\r\n"
                           "# hash comment\n"
                           "[solver]\n"
                           "newton = 0\n"
                           "line_direction = Y\n"
                           "[output]\n"
                           "quiet = ON\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    assert_int_equal(c.advection, 0);
    assert_int_equal(c.bc.face[2][0], BC_WALL);
    assert_int_equal(c.bc.face[2][1], BC_SLIP);
    assert_int_equal(c.newton, 0);
    assert_int_equal(c.line_direction, 1);
    assert_int_equal(c.quiet, 1);

    static const char *const words[] = {"on", "off", "true", "false", "yes", "no", "1", "0"};
    for (int i = 0; i < 8; i++) {
        char ov[64];
        char *ovs[1] = {ov};
        snprintf(ov, sizeof(ov), "output.quiet = %s", words[i]);
        assert_int_equal(case_load(&c, NULL, 1, ovs, err, sizeof(err)), 0);
        assert_int_equal(c.quiet, i % 2 == 0);
    }
}

static void test_overrides(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[256];
    const char *path = put(t, "ov.ini",
                           "[domain]\nnz = 16\nnz = 32\n" /* duplicate: last wins */
                           "[rheology]\nphi = 0.5\nlambda = 0.01\n"
                           "[output]\ndir = from_file\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    assert_int_equal(c.n[2], 32);
    assert_true(c.rheo.grain_density == 1 / 0.5);
    assert_string_equal(c.output_dir, "from_file");

    char *ovs[] = {"domain.nz=128", "rheology.lambda = 0.5", "rheology.phi=0.8",
                   "output.dir=elsewhere", "domain.nx=4", "domain.nx=5",
                   "case.scene=bagnold"};
    assert_int_equal(case_load(&c, path, 7, ovs, err, sizeof(err)), 0);
    assert_int_equal(c.n[2], 128);
    assert_int_equal(c.n[0], 5);
    assert_true(c.rheo.lambda == 0.5);
    assert_true(c.rheo.phi == 0.8);
    assert_true(c.rheo.grain_density == 1 / 0.8); /* follows phi: not given explicitly */
    assert_string_equal(c.output_dir, "elsewhere");
    assert_int_equal(c.scene, scene_find("bagnold"));

    /* explicit grain_density is kept when phi changes */
    char *ovs2[] = {"rheology.grain_density=2650", "rheology.phi=0.55"};
    assert_int_equal(case_load(&c, path, 2, ovs2, err, sizeof(err)), 0);
    assert_true(c.rheo.grain_density == 2650);
    assert_true(c.rheo.phi == 0.55);

    /* overrides alone, without a file */
    char *ovs3[] = {"boundary.zlo=wall", "boundary.zhi=surface"};
    assert_int_equal(case_load(&c, NULL, 2, ovs3, err, sizeof(err)), 0);
    assert_int_equal(c.bc.face[2][0], BC_WALL);
    assert_int_equal(c.bc.face[2][1], BC_SURFACE);
}

struct bad {
    const char *ini;          /* file contents, or NULL for no file */
    const char *ov;           /* one override, or NULL */
    const char *expect[3];    /* substrings the error must contain */
};

static const struct bad bad_cases[] = {
    {"[rheology]\nlamda = 1e-3\n", NULL,
     {"unknown key rheology.lamda (did you mean rheology.lambda?)"}},
    {"[domian]\nnx = 4\n", NULL, {"unknown section [domian]", "did you mean [domain]?"}},
    {"[domain]\nnx = 4\n[outputs]\n", NULL, {"unknown section [outputs]"}},
    {"[fluid]\nrho = 1\n", NULL, {"unknown section [fluid]"}},
    {"[physics]\nlambda = 0.1\n", NULL, {"physics.lambda", "did you mean rheology.lambda?"}},
    {"lx = 2\n", NULL, {"lx", "before any [section]", "did you mean domain.lx?"}},
    {"[domain]\nnz = abc\n", NULL, {"domain.nz = abc: not an integer"}},
    {NULL, "domain.nz=abc", {"override domain.nz=abc: not an integer"}},
    {"[domain]\nnx = 4.5\n", NULL, {"domain.nx = 4.5: not an integer"}},
    {"[domain]\nnx = 4 # cells\n", NULL, {"domain.nx", "not an integer"}},
    {"[domain]\nlx = 1.0x\n", NULL, {"domain.lx = 1.0x: not a number"}},
    {"[domain]\nlx = nan\n", NULL, {"domain.lx = nan", "not a finite number"}},
    {"[domain]\nlx = inf\n", NULL, {"domain.lx = inf", "not a finite number"}},
    {"[domain]\nlx = 1e999\n", NULL, {"domain.lx = 1e999", "range"}},
    {"[domain]\nlx =\n", NULL, {"domain.lx", "empty value"}},
    {"[domain]\nnx = 99999999999999999999999\n", NULL, {"domain.nx", "must be in [1, 100000000]"}},
    {"[rheology]\nlambda = -1\n", NULL, {"rheology.lambda = -1: must be in (0, 1]"}},
    {NULL, "rheology.lambda=0", {"override rheology.lambda=0: must be in (0, 1]"}},
    {"[rheology]\nphi = 1.5\n", NULL, {"rheology.phi = 1.5: must be in (0, 1]"}},
    {"[domain]\nnz = 0\n", NULL, {"domain.nz = 0: must be in [1, 100000000]"}},
    {"[domain]\nly = -2\n", NULL, {"domain.ly = -2: must be > 0"}},
    {"[physics]\ntilt = 2\n", NULL, {"physics.tilt = 2", "pi/2"}},
    {"[physics]\ngravity = -1\n", NULL, {"physics.gravity = -1: must be >= 0"}},
    {"[solver]\ntolerance = 1\n", NULL, {"solver.tolerance = 1: must be in (0, 1)"}},
    {"[solver]\ncfl = 2.5\n", NULL, {"solver.cfl = 2.5: must be in (0, 2]"}},
    {"[solver]\nmax_steps = 0\n", NULL, {"solver.max_steps = 0", "[1, 1000000000]"}},
    {"[solver]\nmax_linear_iterations = 2000000\n", NULL, {"solver.max_linear_iterations"}},
    {"[solver]\nprogress_interval = -1\n", NULL, {"solver.progress_interval"}},
    {"[solver]\nmode = implicit\n", NULL, {"solver.mode = implicit", "steady|transient"}},
    {NULL, "boundary.xlo=open", {"override boundary.xlo=open", "periodic|wall|slip|surface"}},
    {NULL, "physics.advection=maybe", {"override physics.advection=maybe", "boolean"}},
    {"[boundary]\nzlo = wall\n", NULL, {"boundary.zlo", "boundary.zhi", "periodic"}},
    {NULL, "boundary.yhi=slip", {"boundary.ylo", "boundary.yhi"}},
    {"[solver]\ndt = 0.1\ndt_max = 0.01\n", NULL, {"solver.dt_max", "solver.dt"}},
    {"[domain]\nnx = 1000\nny = 1000\nnz = 1000\n", NULL, {"domain", "nx*ny*nz"}},
    {"[rheology]\nlaw = bingham\n", NULL, {"bingham", "plastic_viscosity", "yield_stress"}},
    {"[domain]\nnx\n", NULL, {"line 2", "syntax error"}},
    {"[domain\nnx = 1\n", NULL, {"line 1", "syntax error"}},
    {NULL, "solver.max_step=3", {"override solver.max_step=3",
                                 "unknown key solver.max_step (did you mean solver.max_steps?)"}},
    {NULL, "domian.nx=3", {"unknown section domian", "did you mean domain.nx?"}},
    {NULL, "nodot=3", {"override nodot=3", "expected section.key=value"}},
    {NULL, "domain.nx", {"override domain.nx", "expected section.key=value"}},
    {NULL, "output.dir=", {"override output.dir=", "empty value"}},
    {NULL, "output.dir=a\nb", {"override output.dir=a?b", "control character"}},
    {NULL, "output.dir=a ; b", {"';'"}},
    /* the first error is reported */
    {"[domain]\nnx = 0\nny = x\n", NULL, {"domain.nx = 0"}},
    {"[domain]\nnx = 2\nbad line\nny = x\n", NULL, {"line 3", "syntax error"}},
};

static void test_errors(void **state)
{
    struct tmp *t = *state;
    for (size_t i = 0; i < sizeof(bad_cases) / sizeof(bad_cases[0]); i++) {
        const struct bad *b = &bad_cases[i];
        struct muflow_case c;
        char err[512] = "";
        char name[32];
        const char *path = NULL;
        if (b->ini) {
            snprintf(name, sizeof(name), "bad%02zu.ini", i);
            /* reuse one fixture slot per case so the file list stays short */
            path = put(t, name, b->ini);
        }
        char *ovs[1] = {(char *)b->ov};
        int rc = case_load(&c, path, b->ov ? 1 : 0, ovs, err, sizeof(err));
        if (rc != 2)
            print_error("case %zu: rc %d, err \"%s\"\n", i, rc, err);
        assert_int_equal(rc, 2);
        assert_null(strchr(err, '\n'));
        if (path && strncmp(err, "override", 8) != 0)
            assert_non_null(strstr(err, path));
        for (int j = 0; j < 3 && b->expect[j]; j++) {
            if (!strstr(err, b->expect[j]))
                print_error("case %zu: \"%s\" lacks \"%s\"\n", i, err, b->expect[j]);
            assert_non_null(strstr(err, b->expect[j]));
        }
        if (path) { /* free the slot */
            remove(path);
            t->nfiles--;
        }
    }
}

static void test_file_errors(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c, d;
    char err[512], path[128];

    snprintf(path, sizeof(path), "%s/missing.ini", t->dir);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, path));
    assert_non_null(strstr(err, strerror(ENOENT)));
    case_defaults(&d); /* a failed load leaves the defaults */
    assert_case_equal(&c, &d);

    /* a directory is not a case file */
    assert_int_equal(case_load(&c, t->dir, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, t->dir));
    assert_non_null(strstr(err, strerror(EISDIR)));

    /* a tiny err buffer is still terminated; NULL err is tolerated */
    char small[8];
    assert_int_equal(case_load(&c, path, 0, NULL, small, sizeof(small)), 2);
    assert_true(strlen(small) < sizeof(small));
    assert_int_equal(case_load(&c, path, 0, NULL, NULL, 0), 2);
}

/* Very long lines, names and values never overflow anything. */
static void test_hostile(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[512];
    size_t big = 100000;
    char *text = malloc(big + 64);
    assert_non_null(text);

    /* a very long value line */
    int n = snprintf(text, big, "[output]\ndir = ");
    memset(text + n, 'a', big - (size_t)n - 2);
    text[big - 2] = '\n';
    text[big - 1] = '\0';
    const char *path = put(t, "long.ini", text);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "line 2"));
    assert_non_null(strstr(err, "longer than"));

    /* a very long section name and key name on short-enough lines */
    char line[400];
    memset(line, 'k', 150);
    line[150] = '\0';
    snprintf(text, big, "[%s]\nx = 1\n", line);
    path = put(t, "longsec.ini", text);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "unknown section"));
    snprintf(text, big, "[domain]\n%s = 1\n", line);
    path = put(t, "longkey.ini", text);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "unknown key"));

    /* a NUL byte inside a line */
    char nulpath[128];
    snprintf(nulpath, sizeof(nulpath), "%s/nul.ini", t->dir);
    FILE *f = fopen(nulpath, "wb");
    assert_non_null(f);
    fwrite("[domain]\nnx = 4\0 junk\n", 1, 22, f);
    fclose(f);
    assert_int_equal(case_load(&c, nulpath, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "NUL"));
    remove(nulpath);

    /* overrides: huge value, huge key, output.dir of 511 (ok) and 512 (error) */
    char *ov = malloc(big);
    assert_non_null(ov);
    char *ovs[1] = {ov};
    n = snprintf(ov, big, "domain.lx=");
    memset(ov + n, '7', big - (size_t)n - 1);
    ov[big - 1] = '\0';
    assert_int_equal(case_load(&c, NULL, 1, ovs, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "range"));
    memset(ov, 'q', big - 3);
    memcpy(ov + 1000, ".", 1);
    memcpy(ov + big - 3, "=1", 3);
    assert_int_equal(case_load(&c, NULL, 1, ovs, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "unknown section"));
    assert_true(strlen(err) < 600);

    n = snprintf(ov, big, "output.dir=");
    memset(ov + n, 'd', 511);
    ov[n + 511] = '\0';
    assert_int_equal(case_load(&c, NULL, 1, ovs, err, sizeof(err)), 0);
    assert_int_equal(strlen(c.output_dir), 511);
    ov[n + 511] = 'd';
    ov[n + 512] = '\0';
    assert_int_equal(case_load(&c, NULL, 1, ovs, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "output.dir"));
    assert_non_null(strstr(err, "longer than 511"));

    /* a file name too long for c->name */
    char longname[200];
    memset(longname, 'n', 140);
    memcpy(longname + 140, ".ini", 5);
    path = put(t, longname, "");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "name"));
    free(ov);
    free(text);
}

/* load(write(c)) == c */
static void round_trip(struct tmp *t, const struct muflow_case *c)
{
    struct muflow_case back;
    char err[512], path[256];
    /* same base name, so the name comes back too */
    snprintf(path, sizeof(path), "%s/rt", t->dir);
    assert_int_equal(mkdir(path, 0700), 0);
    snprintf(path, sizeof(path), "%s/rt/%s.ini", t->dir, c->name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    case_write_ini(c, f);
    assert_int_equal(fclose(f), 0);
    int rc = case_load(&back, path, 0, NULL, err, sizeof(err));
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    remove(path);
    snprintf(path, sizeof(path), "%s/rt", t->dir);
    rmdir(path);
    assert_case_equal(&back, c);
}

static void test_round_trip(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[512];

    case_defaults(&c);
    round_trip(t, &c);

    const char *path = put(t, "full.ini", full_ini);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    round_trip(t, &c);

    /* awkward doubles, every enum value */
    char *ovs[] = {"domain.lx=0.1",        "domain.ly=0.3333333333333333",
                   "domain.lz=1e-300",      "physics.tilt=-1.5707963267948966",
                   "rheology.lambda=1e-16", "rheology.phi=0.7",
                   "rheology.law=newtonian", "rheology.regularisation=papanastasiou",
                   "solver.dt=1e-7",        "solver.dt_max=1.7976931348623157e308",
                   "solver.line_direction=auto", "boundary.xlo=surface",
                   "boundary.xhi=wall",     "output.dir=a dir/with:colon=and;semi"};
    int nov = (int)(sizeof(ovs) / sizeof(ovs[0]));
    int rc = case_load(&c, path, nov, ovs, err, sizeof(err));
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_string_equal(c.output_dir, "a dir/with:colon=and;semi");
    assert_true(c.rheo.grain_density == 2500); /* explicit in the file */
    round_trip(t, &c);

    for (int law = 0; law < 3; law++)
        for (int reg = 0; reg < 4; reg++) {
            case_defaults(&c);
            c.rheo.law = (enum rheology_law)law;
            c.rheo.reg = (enum regularisation)reg;
            c.rheo.yield_stress = 0.5;
            case_set_scene(&c, law % 3);
            c.mode = (enum solver_mode)(reg % 2);
            c.line_direction = reg - 1;
            c.rheo.grain_density = 1.0 / 3.0;
            round_trip(t, &c);
        }
}

static void test_write_format(void **state)
{
    (void)state;
    struct muflow_case c;
    case_defaults(&c);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    case_write_ini(&c, f);
    fclose(f);
    static const char *const want[] = {
        "[case]\nscene = none\n", "[domain]\nlx = 1\n", "nz = 1\n",
        "[boundary]\nxlo = periodic\n", "[physics]\ntilt = 0\n", "advection = on\n",
        "[rheology]\nlaw = mui\nregularisation = mc\nlambda = 0.0001\n",
        "mu_s = 0.383\n", "[solver]\nmode = steady\n", "line_direction = auto\n",
        "dt_max = 1e+12\n", "[output]\ndir = out/case\nquiet = off\n"};
    for (size_t i = 0; i < sizeof(want) / sizeof(want[0]); i++) {
        if (!strstr(buf, want[i]))
            print_error("missing \"%s\" in:\n%s", want[i], buf);
        assert_non_null(strstr(buf, want[i]));
    }
    /* sections in order */
    const char *order[] = {"[case]", "[domain]", "[boundary]", "[physics]",
                           "[rheology]", "[solver]", "[output]"};
    for (int i = 1; i < 7; i++)
        assert_true(strstr(buf, order[i - 1]) < strstr(buf, order[i]));
    free(buf);
}

void group_case(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test_setup_teardown(test_empty_file, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_full_file, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_name_and_default_dir, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_syntax_variants, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_overrides, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_errors, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_file_errors, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_hostile, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_round_trip, tmp_setup, tmp_teardown),
        cmocka_unit_test(test_write_format),
    };
    RUN_GROUP(t, "case", tests);
}
