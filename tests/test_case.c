/* Tests of the case-file reader (src/config/case*.c): defaults, a full file,
 * overrides, every class of error, and the round trip through
 * case_write_ini.  Case files are written into a fresh mkdtemp directory. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/run.h"
#include "scenes/scene.h"
#include "test_main.h"
#include "config/case.h"
#include "config/case_registry.h"
#include "config/keys.h"

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
    assert_int_equal(a->rheo.curve, b->rheo.curve);
    assert_true(a->rheo.alpha == b->rheo.alpha);
    assert_true(a->rheo.mu_inf == b->rheo.mu_inf);
    /* derived when loaded, from the keys: the same keys give the same values */
    assert_true(a->rheo.i1n == b->rheo.i1n);
    assert_true(a->rheo.a_minus == b->rheo.a_minus);
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
    "curve = jop\n"
    "alpha = 1.5\n"
    "mu_inf = 0.1\n"
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

    /* no file, no overrides: the defaults, which are not a case muflow can
     * run (every face periodic leaves the implicit solve no direction) */
    assert_int_equal(case_load(&c, NULL, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "sets no key"));
    /* with one non-periodic direction they load as they are */
    char *walls[] = {"boundary.zlo=wall", "boundary.zhi=surface"};
    assert_int_equal(case_load(&c, NULL, 2, walls, err, sizeof(err)), 0);
    assert_string_equal(err, "");
    d.bc.face[2][0] = BC_WALL;
    d.bc.face[2][1] = BC_SURFACE;
    assert_case_equal(&c, &d);
}

/* An empty case (no key at all) is refused with a message that says what
 * is missing, not with the solver's complaint about solver.line_direction;
 * overrides can complete it. */
static void test_empty_file(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c, d;
    char err[1024];
    static const char *const texts[] = {"", "; nothing but a comment\n\n", "[domain]\n[case]\n"};
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "empty%d.ini", i);
        const char *path = put(t, name, texts[i]);
        assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
        static const char *const want[] = {"sets no key", "case.scene", "bagnold",
                                           "periodic on every face", "boundary.*",
                                           "muflow --list"};
        for (size_t w = 0; w < sizeof want / sizeof want[0]; w++) {
            if (!strstr(err, want[w]))
                print_error("\"%s\" lacks \"%s\"\n", err, want[w]);
            assert_non_null(strstr(err, want[w]));
        }
        assert_non_null(strstr(err, path));
        assert_null(strchr(err, '\n'));
        assert_null(strstr(err, "line_direction"));
    }

    /* completed by overrides: the defaults with those faces */
    const char *path = put(t, "empty.ini", "; nothing but a comment\n\n");
    char *walls[] = {"boundary.zlo=wall", "boundary.zhi=surface"};
    assert_int_equal(case_load(&c, path, 2, walls, err, sizeof(err)), 0);
    case_defaults(&d);
    snprintf(d.name, sizeof(d.name), "empty");
    snprintf(d.output_dir, sizeof(d.output_dir), "out/empty");
    d.bc.face[2][0] = BC_WALL;
    d.bc.face[2][1] = BC_SURFACE;
    assert_case_equal(&c, &d);

    /* keys, but every face periodic: said so */
    path = put(t, "periodic.ini", "[case]\nscene = bagnold\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 2);
    assert_non_null(strstr(err, path));
    assert_non_null(strstr(err, "every boundary face is periodic"));
    char *quiet[] = {"output.quiet=on"};
    assert_int_equal(case_load(&c, path, 1, quiet, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "every boundary face is periodic"));

    /* preconditioner lines along a periodic direction */
    char *lines[] = {"boundary.zlo=wall", "boundary.zhi=surface", "solver.line_direction=x"};
    assert_int_equal(case_load(&c, NULL, 3, lines, err, sizeof(err)), 2);
    assert_non_null(strstr(err, "solver.line_direction = x: x is periodic"));
    lines[2] = "solver.line_direction=z";
    assert_int_equal(case_load(&c, NULL, 3, lines, err, sizeof(err)), 0);
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
    assert_int_equal(c.rheo.curve, CURVE_JOP);
    assert_true(c.rheo.alpha == 1.5 && c.rheo.mu_inf == 0.1);
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
    const char *p1 = put(t, "my.case.ini", "[domain]\nnx = 2\n[boundary]\nzlo = wall\nzhi = wall\n");
    assert_int_equal(case_load(&c, p1, 0, NULL, err, sizeof(err)), 0);
    assert_string_equal(c.name, "my.case");
    assert_string_equal(c.output_dir, "out/my.case");

    const char *p2 = put(t, "noext", "[domain]\nnx = 2\n[boundary]\nzlo = wall\nzhi = wall\n");
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
                           "line_direction = Z\n"
                           "[output]\n"
                           "quiet = ON\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    assert_int_equal(c.advection, 0);
    assert_int_equal(c.bc.face[2][0], BC_WALL);
    assert_int_equal(c.bc.face[2][1], BC_SLIP);
    assert_int_equal(c.newton, 0);
    assert_int_equal(c.line_direction, 2);
    assert_int_equal(c.quiet, 1);

    static const char *const words[] = {"on", "off", "true", "false", "yes", "no", "1", "0"};
    for (int i = 0; i < 8; i++) {
        char ov[64];
        char *ovs[3] = {ov, "boundary.zlo=wall", "boundary.zhi=wall"};
        snprintf(ov, sizeof(ov), "output.quiet = %s", words[i]);
        assert_int_equal(case_load(&c, NULL, 3, ovs, err, sizeof(err)), 0);
        assert_int_equal(c.quiet, i % 2 == 0);
    }
}

static void test_overrides(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[256];
    const char *path = put(t, "ov.ini",
                           "[boundary]\nzlo = wall\nzhi = surface\n"
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

    /* the Barker & Gray curve's derived values, from the final keys (the
     * BG2017_glass set of Barker & Gray 2017: I_1^N 0.0039718, A_minus 15642) */
    char *ovs_bg[] = {"rheology.curve=barker_gray", "rheology.mu_s=0.342",
                      "rheology.delta_mu=0.215", "rheology.i0=0.069"};
    assert_int_equal(case_load(&c, path, 4, ovs_bg, err, sizeof(err)), 0);
    assert_int_equal(c.rheo.curve, CURVE_BARKER_GRAY);
    assert_true(c.rheo.alpha == 1.9 && c.rheo.mu_inf == 0.05);
    assert_true(fabs(c.rheo.i1n - 0.0039718) < 0.5e-7);
    assert_true(fabs(c.rheo.a_minus - 15642) < 0.5);
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof(err)), 0);
    assert_true(c.rheo.curve == CURVE_JOP && c.rheo.i1n == 0.0 && c.rheo.a_minus == 0.0);

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
    {NULL, "boundary.xlo=outlet", {"override boundary.xlo=outlet", "periodic|wall|slip|surface|lid|open|inflow"}},
    {NULL, "physics.advection=maybe", {"override physics.advection=maybe", "boolean"}},
    {"[boundary]\nzlo = wall\n", NULL, {"boundary.zlo", "boundary.zhi", "periodic"}},
    {NULL, "boundary.yhi=slip", {"boundary.ylo", "boundary.yhi"}},
    {"[solver]\ndt = 0.1\ndt_max = 0.01\n", NULL, {"solver.dt_max", "solver.dt"}},
    {"[domain]\nnx = 1000\nny = 1000\nnz = 1000\n", NULL,
     {"domain.nx * domain.ny * domain.nz = 1000 * 1000 * 1000", "must be <= 500000000"}},
    /* stretched directions: three numbers, inside the box, finer than the far
     * cells, and only with the coupled steady step */
    {"[domain]\nnx = 8\nx_band = 0.2 0.5\n", NULL, {"domain.x_band = '0.2 0.5'", "triples 'lo hi h'"}},
    {"[domain]\nnx = 8\nx_band = 0.2 1.5 0.01\n", NULL,
     {"domain.x_band = '0.2 1.5 0.01'", "must lie in [0, 1]"}},
    {"[domain]\nnx = 8\nx_band = 0.2 0.5 0.5\n", NULL, {"domain.x_band", "(0, 0.125]"}},
    {"[domain]\nny = 1\ny_band = 0.2 0.5 0.01\n", NULL, {"domain.y_band", "domain.ny >= 2"}},
    {"[domain]\nnz = 8\nz_band = 0.2 0.5 0.01\n", NULL,
     {"domain.z_band = '0.2 0.5 0.01' needs", "solver.coupled = on"}},
    {NULL, "domain.growth=2", {"override domain.growth=2", "must be in (1, 1.5]"}},
    /* the implicit step's geometric multigrid: a periodic direction, no coupled step */
    {"[boundary]\nxlo = wall\nxhi = wall\nylo = wall\nyhi = wall\nzlo = wall\nzhi = surface\n"
     "[solver]\npreconditioner = gmg\n",
     NULL, {"solver.preconditioner = gmg needs a periodic direction"}},
    {"[solver]\nmode = steady\ncoupled = on\npreconditioner = gmg\n", NULL,
     {"solver.coupled = on with solver.preconditioner = gmg"}},
    {"[domain]\nnx = 4\nny = 1\n[boundary]\nzlo = wall\nzhi = surface\n[solver]\npreconditioner = gmg\n",
     NULL, {"solver.preconditioner = gmg needs every periodic direction to be one cell across"}},
    {"[rheology]\nlaw = bingham\n", NULL, {"bingham", "plastic_viscosity", "yield_stress"}},
    /* the Barker & Gray curve: alpha in (0, 2), and a jop curve with a well-posed band */
    {NULL, "rheology.alpha=2", {"override rheology.alpha=2", "must be in (0, 2)"}},
    {"[rheology]\ncurve = barker_gray\nmu_s = 2\ndelta_mu = 0.1\n", NULL,
     {"rheology.curve = barker_gray", "rheology.mu_s = 2, rheology.delta_mu = 0.1",
      "rheology.i0"}},
    {"[rheology]\ncurve = barker_gray\ndelta_mu = 0\n", NULL,
     {"rheology.mu_s", "rheology.delta_mu = 0", "no well-posed I_1^N"}},
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
    /* numbers are decimal: strtod's other forms are refused, the key named */
    {"[physics]\ntilt = 0x1p-2\n", NULL, {"physics.tilt = 0x1p-2", "not a decimal number"}},
    {NULL, "physics.tilt=0x1p-2", {"override physics.tilt=0x1p-2", "not a decimal number"}},
    {NULL, "domain.lx=0X10", {"override domain.lx=0X10", "not a decimal number"}},
    {NULL, "domain.lx=-0x1.8p1", {"override domain.lx=-0x1.8p1", "not a decimal number"}},
    {NULL, "boundary.lid_velocity=0x.8", {"boundary.lid_velocity=0x.8", "not a decimal number"}},
    {"[domain]\nlx = infinity\n", NULL, {"domain.lx = infinity", "not a finite number"}},
    {NULL, "boundary.lid_velocity=-INF", {"boundary.lid_velocity=-INF", "not a finite number"}},
    {NULL, "boundary.lid_velocity=nan(1)", {"boundary.lid_velocity=nan(1)", "not a finite number"}},
    {"[domain]\nlx = 1e\n", NULL, {"domain.lx = 1e", "not a"}},
    {"[domain]\nlx = .\n", NULL, {"domain.lx = .", "not a number"}},
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

/* A check that needs several keys names what set them: the command line's
 * overrides among the keys its message names ("override a=1: ..."), else
 * the file; values as the case files write them (the shortest text that
 * reads back, never 0.00089999999999999998 for 0.0009). */
static void test_check_origin(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[1024];
    /* an override: it is named, the case file is not */
    char *wide[] = {"collapse.half_width=10"};
    assert_int_equal(case_load(&c, "../cases/collapse.ini", 1, wide, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_true(strncmp(err, "override collapse.half_width=10: collapse.half_width = 10", 57) == 0);
    assert_null(strstr(err, "cases/collapse.ini"));
    /* the same value from a file: the file is named */
    const char *path = put(t, "wide.ini",
                           "[case]\nscene = collapse\n[domain]\nlx = 5\nlz = 1.5\nnx = 160\n"
                           "nz = 48\n[boundary]\nxlo = slip\nxhi = wall\nzlo = wall\n"
                           "zhi = surface\n[rheology]\nlaw = mui\n[solver]\nmode = transient\n"
                           "[collapse]\nhalf_width = 10\n");
    assert_int_equal(case_load(&c, path, 0, NULL, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_true(strncmp(err, path, strlen(path)) == 0);
    assert_non_null(strstr(err, ": collapse.half_width = 10: "));
    assert_null(strstr(err, "override"));
    /* every override among the keys named, in the keys' order */
    char *dt[] = {"solver.dt=0.0009", "solver.dt_max=0.0001", "solver.tolerance=1e-9"};
    assert_int_equal(case_load(&c, "../cases/bagnold.ini", 3, dt, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_string_equal(err, "override solver.dt=0.0009, override solver.dt_max=0.0001: "
                             "solver.dt_max = 0.0001 < solver.dt = 0.0009: dt_max must be >= dt");
    /* bed load with a gravity the friction cannot hold: physics.gravity
     * is blamed (the condition's every key and value is named), not the
     * bed's friction coefficient of the file */
    char *g[] = {"physics.gravity=1e6"};
    assert_int_equal(case_load(&c, "../cases/bedload.ini", 1, g, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_true(strncmp(err, "override physics.gravity=1e6: ", 30) == 0);
    assert_non_null(strstr(err, "physics.gravity = 1e+06"));
    assert_non_null(strstr(err, "bedload.mu_s = 0.32"));
    assert_null(strstr(err, "0.32000000000000001"));
    /* no value in 17 digits: the memory refusal's keys, the cells' count */
    char *big[] = {"domain.ny=20000", "domain.nz=40000"};
    assert_int_equal(case_load(&c, "../cases/duct_circular.ini", 2, big, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_string_equal(err, "override domain.ny=20000, override domain.nz=40000: domain.nx * "
                             "domain.ny * domain.nz = 1 * 20000 * 40000 = 800000000 cells: must "
                             "be <= 500000000");
}

/* A length the scene needs resolved thinner than a cell is refused, naming
 * the key, its value, the cell size and the allowed range (a column of
 * 0.001 ran to "finished" with x_front 0, a grain layer of a ninth of a
 * cell was accepted), and a body thinner than a cell too. */
static void test_thinner_than_a_cell(void **state)
{
    (void)state;
    static const struct {
        const char *file, *ov, *want[3];
    } thin[] = {
        {"../cases/collapse.ini", "collapse.height=0.001",
         {"override collapse.height=0.001: collapse.height = 0.001: must be in [0.03125, 1.5)",
          "domain.lz / domain.nz = 1.5 / 48 = 0.03125"}},
        {"../cases/collapse.ini", "collapse.half_width=0.01",
         {"collapse.half_width = 0.01: must be in [0.03125, 5)"}},
        {"../cases/bagnold2.ini", "bagnold2.interface_height=1e-6",
         {"override bagnold2.interface_height=1e-6: bagnold2.interface_height = 1e-06",
          "(domain.lz / domain.nz = 0.0009 / 100 = 9e-06)", "must be in [9e-06, 0.000891]"}},
        {"../cases/bagnold2.ini", "bagnold2.interface_height=0.000895",
         {"must be in [9e-06, 0.000891]"}},
        {"../cases/bedload.ini", "bedload.bed_height=0.001",
         {"bedload.bed_height = 0.001", "0.065 / 40 = 0.001625", "[0.001625, 0.063375]"}},
        {"../cases/duct_square.ini", "duct.bed_height=0.064",
         {"duct.bed_height = 0.064", "[0.001625, 0.063375]"}},
        {"../cases/cylinder_benchmark.ini", "obstacle.shapes=circle 0.2 0.2 0.004",
         {"shape 1 spans 0.008 along x, thinner than a cell (domain.lx / domain.nx = 0.01)"}},
    };
    for (size_t m = 0; m < sizeof thin / sizeof thin[0]; m++) {
        struct muflow_case c;
        char err[1024];
        char *ov[] = {(char *)thin[m].ov};
        assert_int_equal(case_load(&c, thin[m].file, 1, ov, err, sizeof err), 2);
        print_message("%s\n", err);
        for (int k = 0; k < 3 && thin[m].want[k]; k++) {
            if (!strstr(err, thin[m].want[k]))
                print_error("lacks \"%s\"\n", thin[m].want[k]);
            assert_non_null(strstr(err, thin[m].want[k]));
        }
    }
    /* one cell is enough (the bound the message prints is accepted) */
    static const char *const one_cell[][2] = {
        {"../cases/collapse.ini", "collapse.height=0.03125"},
        {"../cases/bagnold2.ini", "bagnold2.interface_height=9e-6"},
        {"../cases/bedload.ini", "bedload.bed_height=0.063375"},
    };
    for (size_t m = 0; m < sizeof one_cell / sizeof one_cell[0]; m++) {
        struct muflow_case c;
        char err[1024];
        char *ov[] = {(char *)one_cell[m][1], "bedload.mu_s=10"};
        int rc = case_load(&c, one_cell[m][0], m == 2 ? 2 : 1, ov, err, sizeof err);
        if (rc != 0 && strstr(err, "cell"))
            print_error("%s: %s\n", one_cell[m][1], err);
        assert_false(rc != 0 && strstr(err, "cell"));
    }
}

/* The fluid the body leaves must be one region, or regions that each
 * reach a face where the pressure is fixed: the circular duct with
 * obstacle.invert = off keeps two corners outside the circle, closed off by
 * walls (it ran to "hydrostatic pressure solve: relative residual 4.00e+00
 * after 10 multigrid-CG iterations"); refused at load, naming
 * obstacle.invert.  Two discs of fluid in a channel whose open end is away
 * from both likewise; one disc alone loads (it is solved up to its
 * pressure's level), and so do the shipped cases with bodies. */
static void test_enclosed_fluid(void **state)
{
    (void)state;
    struct muflow_case c;
    char err[1024];
    char *off[] = {"obstacle.invert=off"};
    assert_int_equal(case_load(&c, "../cases/duct_circular.ini", 1, off, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_true(strncmp(err, "override obstacle.invert=off: ", 30) == 0);
    assert_non_null(strstr(err, "obstacle.invert = off"));
    assert_non_null(strstr(err, "splits the fluid into 2 regions"));
    char *two[] = {"obstacle.invert=on", "boundary.xlo=wall",
                   "obstacle.shapes=circle 0.2 0.2 0.05; circle 1 0.2 0.05"};
    assert_int_equal(case_load(&c, "../cases/cylinder_benchmark.ini", 3, two, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_non_null(strstr(err, "obstacle.invert = on"));
    assert_non_null(strstr(err, "2 regions on this grid, 2 of them closed off"));
    assert_non_null(strstr(err, "(boundary.xhi = open)"));
    int rc = case_load(&c, "../cases/cylinder_benchmark.ini", 2, two, err, sizeof err);
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    static const char *const fine[] = {"../cases/duct_circular.ini", "../cases/duct_square.ini",
                                       "../cases/cylinder.ini", "../cases/cylinder_benchmark.ini"};
    for (size_t m = 0; m < sizeof fine / sizeof fine[0]; m++) {
        rc = case_load(&c, fine[m], 0, NULL, err, sizeof err);
        if (rc)
            print_error("%s: %s\n", fine[m], err);
        assert_int_equal(rc, 0);
    }
}

/* Every plain decimal form is a number. */
static void test_decimal_forms(void **state)
{
    (void)state;
    struct muflow_case c;
    char err[512];
    char *ovs[] = {"boundary.zlo=wall", "boundary.zhi=wall", "domain.lx=1.",
                   "domain.ly=.5",       "domain.lz=+2",       "physics.tilt=-1E-1",
                   "boundary.lid_velocity=-0", "physics.gravity=9.81e+0",
                   "rheology.lambda=00.001"};
    int rc = case_load(&c, NULL, (int)(sizeof ovs / sizeof ovs[0]), ovs, err, sizeof err);
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_true(c.len[0] == 1.0 && c.len[1] == 0.5 && c.len[2] == 2.0);
    assert_true(c.tilt == -0.1 && c.gravity == 9.81 && c.rheo.lambda == 0.001);
    assert_true(c.bc.lid_velocity == 0.0 && signbit(c.bc.lid_velocity));
}

static void collect_warning(void *ctx, const char *line)
{
    char **buf = ctx;
    size_t old = *buf ? strlen(*buf) : 0, add = strlen(line);
    char *p = realloc(*buf, old + add + 2);
    assert_non_null(p);
    memcpy(p + old, line, add);
    p[old + add] = '\n';
    p[old + add + 1] = '\0';
    *buf = p;
}

static int count_lines(const char *s)
{
    int n = 0;
    for (; s && *s; s++)
        n += *s == '\n';
    return n;
}

/* A key or section given twice in the file is warned about (one line naming
 * the file, the key and both lines); the later value is used.  Overrides
 * replace file values without a warning. */
static void test_duplicates(void **state)
{
    struct tmp *t = *state;
    struct muflow_case c;
    char err[512];
    char *w = NULL;
    const char *path = put(t, "dup.ini",
                           "[case]\n"
                           "scene = bagnold\n"
                           "[boundary]\n"
                           "zlo = wall\n"
                           "zhi = surface\n"
                           "[case]\n"
                           "scene = chute\n");
    int rc = case_load_warn(&c, path, 0, NULL, collect_warning, &w, err, sizeof err);
    assert_int_equal(rc, 0);
    assert_int_equal(c.scene, scene_find("chute")); /* the later line */
    assert_non_null(w);
    print_message("%s", w);
    assert_int_equal(count_lines(w), 2);
    char *key = strstr(w, "case.scene");
    assert_non_null(key);
    const char *want[] = {path, "line 2 (bagnold)", "line 7 (chute)", "the later replaces the earlier"};
    char *end = strchr(key, '\n');
    *end = '\0';
    const char *start = key;
    while (start > w && start[-1] != '\n')
        start--;
    for (int i = 0; i < 4; i++)
        assert_non_null(strstr(start, want[i]));
    *end = '\n';
    assert_non_null(strstr(w, "section [case] given twice: line 1 and line 6"));
    free(w);
    w = NULL;

    /* the silent loader reads the same case */
    struct muflow_case d;
    assert_int_equal(case_load(&d, path, 0, NULL, err, sizeof err), 0);
    assert_case_equal(&c, &d);

    /* overrides, even repeated, replace without a warning; a key three
     * times in the file gives two warnings; a scene's own key too */
    path = put(t, "dup3.ini",
               "[boundary]\nzlo = wall\nzhi = wall\n"
               "[domain]\nnx = 2\nnx = 3\nnx = 4\n");
    char *ovs[] = {"domain.nx=5", "domain.nx=6", "boundary.zhi=surface"};
    rc = case_load_warn(&c, path, 3, ovs, collect_warning, &w, err, sizeof err);
    assert_int_equal(rc, 0);
    assert_int_equal(c.n[0], 6);
    assert_int_equal(count_lines(w), 2);
    assert_non_null(strstr(w, "domain.nx given twice: line 5 (2) and line 6 (3)"));
    assert_non_null(strstr(w, "domain.nx given twice: line 6 (3) and line 7 (4)"));
    free(w);
    w = NULL;
    rc = case_load_warn(&c, path, 0, NULL, NULL, NULL, err, sizeof err); /* no callback */
    assert_int_equal(rc, 0);

    path = put(t, "dupheap.ini",
               "[case]\nscene = heap\n"
               "[domain]\nny = 2\nnz = 2\n"
               "[boundary]\nylo = wall\nyhi = slip\nzlo = wall\nzhi = surface\n"
               "[heap]\nflow_rate = 1\ndepth_fraction = 0.1\nflow_rate = 2\n");
    rc = case_load_warn(&c, path, 0, NULL, collect_warning, &w, err, sizeof err);
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal(count_lines(w), 1);
    assert_non_null(strstr(w, "heap.flow_rate given twice: line 12 (1) and line 14 (2)"));
    free(w);
    w = NULL;

    /* no duplicates, no warnings */
    path = put(t, "nodup.ini", "[boundary]\nzlo = wall\nzhi = wall\n[domain]\nnx = 2\n");
    rc = case_load_warn(&c, path, 1, ovs, collect_warning, &w, err, sizeof err);
    assert_int_equal(rc, 0);
    assert_null(w);
}

/* Numbers are written with the fewest digits that read back exactly, in
 * plain decimal unless scientific notation is at least two characters
 * shorter. */
static void test_number_text(void **state)
{
    (void)state;
    struct holder {
        double v;
    };
    const struct key k =
        KEY_DBL(struct holder, "s", "v", v, "a number", KEY_RANGE(KEY_NONE_LO, KEY_NONE_HI, 0, 0));
    static const struct {
        double v;
        const char *text;
    } cases[] = {
        {70, "70"},         {10, "10"},           {1, "1"},
        {0.015625, "0.015625"}, {1e-4, "0.0001"}, {0.0025, "0.0025"},
        {123456, "123456"}, {100000, "100000"},   {1e6, "1e+06"},
        {1e12, "1e+12"},    {1e-5, "1e-05"},      {1e-8, "1e-08"},
        {-1.5707963267948966, "-1.5707963267948966"}, {0.1, "0.1"},
        {1.0 / 3.0, "0.3333333333333333"}, {1.7976931348623157e308, "1.7976931348623157e+308"},
        {123456789012.0, "123456789012"}, {7.0710678118654755, "7.0710678118654755"},
        {0.0, "0"},         {-2.5, "-2.5"},       {1e-300, "1e-300"},
    };
    char text[64];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        struct holder h = {cases[i].v};
        key_text(&h, &k, text, sizeof text);
        if (strcmp(text, cases[i].text) != 0)
            print_error("%.17g written as %s, not %s\n", cases[i].v, text, cases[i].text);
        assert_string_equal(text, cases[i].text);
    }
    /* random doubles: the text reads back exactly (through the key parser),
     * and has no more significant digits than needed */
    unsigned long long x = 88172645463325252ULL;
    for (int i = 0; i < 200000; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        struct holder h, back = {0};
        memcpy(&h.v, &x, sizeof h.v);
        if (!isnormal(h.v))
            continue;
        key_text(&h, &k, text, sizeof text);
        char msg[160];
        const char *why = key_parse(&back, &k, text, msg, sizeof msg);
        if (why || back.v != h.v)
            print_error("%.17g -> %s -> %s\n", h.v, text, why ? why : "another value");
        assert_null(why);
        assert_true(back.v == h.v);
        int digits = 0;
        for (const char *p = text; *p && *p != 'e'; p++)
            digits += *p >= '0' && *p <= '9';
        char shortest[40];
        for (int prec = 1; prec <= 17; prec++) {
            snprintf(shortest, sizeof shortest, "%.*e", prec - 1, h.v);
            if (strtod(shortest, NULL) == h.v) {
                /* plain forms add at most the leading zeros of 0.000ddd */
                assert_true(digits <= prec + 4 || strchr(text, 'e') == NULL);
                if (strchr(text, 'e'))
                    assert_true(digits == prec);
                break;
            }
        }
    }
}

/* Every key of the tables (core and each scene's section). */
struct key_ref {
    const char *section, *name, *help;
};

static int all_keys(struct key_ref *out, int cap)
{
    int n = 0;
    for (int i = 0; i < case_key_count() && n < cap; i++, n++)
        out[n] = (struct key_ref){case_key_at(i)->section, case_key_at(i)->name,
                                  case_key_at(i)->help};
    for (int sc = 0; sc < scene_count(); sc++) {
        const struct key_block *kb = scene_at(sc)->keys;
        for (int j = 0; kb && j < kb->nkeys && n < cap; j++, n++)
            out[n] = (struct key_ref){kb->keys[j].section, kb->keys[j].name, kb->keys[j].help};
    }
    assert_true(n < cap);
    return n;
}

/* Each key has a one-line help text. */
static void test_key_help(void **state)
{
    (void)state;
    struct key_ref k[256];
    int n = all_keys(k, 256);
    assert_true(n > 50);
    assert_null(case_key_at(case_key_count()));
    for (int i = 0; i < n; i++) {
        if (!k[i].help || !k[i].help[0])
            print_error("%s.%s has no help text\n", k[i].section, k[i].name);
        assert_non_null(k[i].help);
        assert_true(k[i].help[0] != '\0');
        assert_null(strchr(k[i].help, '\n'));
    }
}

/* docs/case_keys.md is what the key tables generate (muflow --list=markdown,
 * `make case-keys`), byte for byte: it cannot drift from the tables. */
static void test_docs_generated(void **state)
{
    (void)state;
    size_t n_doc;
    char *doc = test_read_file("../docs/case_keys.md", &n_doc);
    char *gen = NULL;
    size_t n_gen = 0;
    FILE *f = open_memstream(&gen, &n_gen);
    assert_non_null(f);
    case_write_key_markdown(f);
    assert_int_equal(fclose(f), 0);
    size_t i = 0;
    while (i < n_doc && i < n_gen && doc[i] == gen[i])
        i++;
    if (i < n_doc || i < n_gen) {
        size_t line = 1;
        for (size_t j = 0; j < i; j++)
            line += gen[j] == '\n';
        print_error("docs/case_keys.md differs from the key tables from line %zu on: run "
                    "`make case-keys`\n", line);
    }
    assert_true(i == n_doc && i == n_gen);
    free(gen);
    free(doc);
}

/* docs/case_keys.md names every key the tables have, each in its section's
 * table, and no key they do not have. */
static void test_docs_name_every_key(void **state)
{
    (void)state;
    char *doc = test_read_file("../docs/case_keys.md", NULL);
    struct key_ref k[256];
    int n = all_keys(k, 256);
    int found[256] = {0};
    char section[64] = "";
    int documented = 0;
    for (char *line = doc; line && *line;) {
        char *end = strchr(line, '\n');
        if (end)
            *end = '\0';
        if (sscanf(line, "### `[%63[^]]", section) == 1) {
            /* the section of the tables that follow */
        } else if (strncmp(line, "| `", 3) == 0 && section[0]) {
            /* the first cell: `a`, `b`, ... */
            char *cell_end = strstr(line + 1, " |");
            assert_non_null(cell_end);
            *cell_end = '\0';
            for (char *q = strchr(line, '`'); q; q = strchr(q, '`')) {
                char *close = strchr(q + 1, '`');
                assert_non_null(close);
                *close = '\0';
                int hit = 0;
                for (int i = 0; i < n; i++)
                    if (strcmp(k[i].section, section) == 0 && strcmp(k[i].name, q + 1) == 0)
                        found[i] = hit = 1;
                if (!hit)
                    print_error("docs/case_keys.md documents %s.%s, which no key table has\n",
                                section, q + 1);
                assert_true(hit);
                documented++;
                q = close + 1;
            }
        }
        line = end ? end + 1 : NULL;
    }
    for (int i = 0; i < n; i++) {
        if (!found[i])
            print_error("docs/case_keys.md does not document %s.%s\n", k[i].section, k[i].name);
        assert_true(found[i]);
    }
    assert_int_equal(documented, n);
    free(doc);
}

/* The keys of each section come in the order docs/case_keys.md lists them
 * (summary.ini writes them in the key table's order). */
struct order_ctx {
    char keys[256][64];
    int n;
};

static int collect_order(void *vctx, const char *section, const char *key, const char *value)
{
    (void)value;
    struct order_ctx *o = vctx;
    if (o->n < 256)
        snprintf(o->keys[o->n++], 64, "%s.%s", section, key);
    return 0;
}

static void test_docs_key_order(void **state)
{
    (void)state;
    char *doc = test_read_file("../docs/case_keys.md", NULL);
    struct order_ctx documented = {.n = 0};
    char section[64] = "";
    for (char *line = doc; line && *line;) {
        char *end = strchr(line, '\n');
        if (end)
            *end = '\0';
        if (sscanf(line, "### `[%63[^]]", section) == 1) {
        } else if (section[0] && strncmp(line, "| `", 3) == 0) {
            /* the first column: one key or several, each in backticks */
            char *bar = strchr(line + 1, '|');
            for (char *p = line + 1; bar && p < bar;) {
                char *open = strchr(p, '`');
                if (!open || open > bar)
                    break;
                char *close = strchr(open + 1, '`');
                if (!close || close > bar)
                    break;
                if (documented.n < 256) {
                    int w = snprintf(documented.keys[documented.n], 64, "%s.%.*s", section,
                                     (int)(close - open - 1), open + 1);
                    assert_true(w > 0 && w < 64); /* a key that fits */
                    documented.n++;
                }
                p = close + 1;
            }
        }
        line = end ? end + 1 : NULL;
    }
    free(doc);
    /* every scene's keys: the core ones and its own section */
    for (int sc = 0; sc < scene_count(); sc++) {
        struct muflow_case c;
        case_defaults(&c);
        case_set_scene(&c, sc);
        struct order_ctx written = {.n = 0};
        case_visit_keys(&c, collect_order, &written);
        int at = 0; /* position in the documented list */
        for (int i = 0; i < written.n; i++) {
            int found = -1;
            for (int j = 0; j < documented.n && found < 0; j++)
                if (strcmp(documented.keys[j], written.keys[i]) == 0)
                    found = j;
            if (found < at)
                print_error("%s is written before a key that docs/case_keys.md lists "
                            "before it\n", written.keys[i]);
            assert_true(found >= at);
            at = found;
        }
    }
}

/* muflow --list: every scene with its title, every key with its default
 * (as key_text writes the defaults), allowed values and help. */
static void test_list_command(void **state)
{
    (void)state;
    char *out;
    assert_int_equal(test_sh("../build/muflow --list", &out), 0);
    for (int sc = 0; sc < scene_count(); sc++) {
        char line[256];
        snprintf(line, sizeof line, "  %-16s %s\n", scene_at(sc)->name, scene_at(sc)->title);
        assert_non_null(strstr(out, line));
    }
    static struct muflow_case d;
    for (int sc = 0; sc < scene_count(); sc++) {
        case_defaults(&d);
        case_set_scene(&d, sc);
        const struct key_block *kb = scene_at(sc)->keys;
        int nk = sc == 0 ? case_key_count() : kb ? kb->nkeys : 0;
        for (int i = 0; i < nk; i++) {
            const struct key *k = sc == 0 ? case_key_at(i) : &kb->keys[i];
            const void *base = sc == 0 ? (const void *)&d : case_scene_params(&d);
            char def[600], allowed[600], want[1600];
            if (k->default_text)
                snprintf(def, sizeof def, "%s", k->default_text);
            else
                key_text(base, k, def, sizeof def);
            if (!def[0])
                snprintf(def, sizeof def, "(not set)");
            key_allowed_text(k, allowed, sizeof allowed);
            snprintf(want, sizeof want, "  %s.%s = %s  (%s)\n      %s%s%s%s\n", k->section,
                     k->name, def, allowed, k->help, k->units ? " (" : "",
                     k->units ? k->units : "", k->units ? ")" : "");
            if (!strstr(out, want))
                print_error("--list lacks \"%s\"\n", want);
            assert_non_null(strstr(out, want));
        }
    }
    /* spot checks against the documented values */
    assert_non_null(strstr(out, "  domain.nx = 1  (integer in [1, 100000000])\n"));
    assert_non_null(strstr(out, "  rheology.lambda = 0.0001  (real in (0, 1])\n"));
    assert_non_null(strstr(out, "  heap.max_solves = 30  (integer in [2, 1000])\n"));
    assert_non_null(strstr(out, "  rheology.grain_density = 1/phi  (real > 0)\n"));
    assert_non_null(strstr(out, "  output.dir = out/<case name>"));
    assert_non_null(strstr(out, "[heap]  (only with case.scene = heap)"));
    free(out);
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
    char *ovw[3] = {ov, "boundary.zlo=wall", "boundary.zhi=wall"};
    assert_int_equal(case_load(&c, NULL, 3, ovw, err, sizeof(err)), 0);
    assert_int_equal(strlen(c.output_dir), 511);
    ov[n + 511] = 'd';
    ov[n + 512] = '\0';
    assert_int_equal(case_load(&c, NULL, 3, ovw, err, sizeof(err)), 2);
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
    c.bc.face[2][0] = BC_WALL; /* a runnable case: one non-periodic direction */
    c.bc.face[2][1] = BC_SURFACE;
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

    /* the Barker & Gray curve: keys written back, derived values the same */
    char *ovs_bg[] = {"boundary.zlo=wall", "boundary.zhi=surface", "rheology.curve=barker_gray",
                      "rheology.alpha=1.25", "rheology.mu_inf=0.125"};
    rc = case_load(&c, NULL, 5, ovs_bg, err, sizeof(err));
    if (rc)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_true(c.rheo.i1n > 0.0 && c.rheo.a_minus > c.rheo.i1n);
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
            for (int d = 0; d < 3; d++) /* lines along any direction */
                c.bc.face[d][0] = c.bc.face[d][1] = BC_WALL;
            round_trip(t, &c);
        }
}

static void test_write_format(void **state)
{
    (void)state;
    struct muflow_case c;
    case_defaults(&c);
    c.len[1] = 70;
    c.rheo.yield_stress = 10;
    c.rheo.plastic_viscosity = 0.0025;
    c.dt = 1e-5;
    c.end_time = 123456;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    case_write_ini(&c, f);
    fclose(f);
    static const char *const want[] = {
        "ly = 70\n", "yield_stress = 10\n", "plastic_viscosity = 0.0025\n", "dt = 1e-05\n",
        "end_time = 123456\n",
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

/* ---------------------------------------------------------------------- */
/* The case reader knows the layers above it only by what they register
 * (config/case_registry.h): a scene list of its own and checks that record
 * their calls stand in for muflow's here, and run_init restores those. */

struct fake_block {
    double width;
};

static const struct key fake_keys[] = {
    KEY_DBL(struct fake_block, "fake", "width", width, "a width", KEY_GT0),
};

static void fake_defaults(void *block) { ((struct fake_block *)block)->width = 2.0; }

static int fake_block_check(const struct muflow_case *cs, const void *block, char *msg,
                            size_t msglen)
{
    (void)cs;
    if (((const struct fake_block *)block)->width > 5.0) {
        snprintf(msg, msglen, "fake.width = %g: must be at most 5 for this scene",
                 ((const struct fake_block *)block)->width);
        return 1;
    }
    return 0;
}

static const struct key_block fake_block_keys = {
    .section = "fake", .keys = fake_keys, .nkeys = 1, .size = sizeof(struct fake_block),
    .defaults = fake_defaults, .check = fake_block_check};

static int fake_scene_check(const struct muflow_case *cs, char *msg, size_t msglen)
{
    if (cs->bc.face[2][0] != BC_WALL) {
        snprintf(msg, msglen, "case.scene = fake needs boundary.zlo = wall");
        return 1;
    }
    return 0;
}

static int fake_calls[3]; /* preconditioner, rheology curve, memory */

static int fake_preconditioner(const struct muflow_case *cs, char *msg, size_t msglen)
{
    fake_calls[0]++;
    if (cs->preconditioner == PRECOND_GMG) {
        snprintf(msg, msglen, "solver.preconditioner = gmg: refused by the fake solver");
        return 1;
    }
    return 0;
}

static int fake_curve(struct rheology *r, char *msg, size_t msglen)
{
    (void)msg, (void)msglen;
    fake_calls[1]++;
    r->i1n = 0.125; /* what the hook derives reaches the loaded case */
    return 0;
}

static int fake_memory(const struct muflow_case *cs, char *msg, size_t msglen)
{
    fake_calls[2]++;
    if (cs->n[0] > 1000) {
        snprintf(msg, msglen, "domain.nx = %d: more than the fake machine holds", cs->n[0]);
        return 1;
    }
    return 0;
}

static int restore_registry(void **state)
{
    (void)state;
    run_init();
    return 0;
}

static int load_with(struct muflow_case *cs, char *err, size_t errlen, int n, ...)
{
    char *ov[8];
    va_list ap;
    va_start(ap, n);
    for (int i = 0; i < n; i++)
        ov[i] = va_arg(ap, char *);
    va_end(ap);
    return case_load(cs, NULL, n, ov, err, errlen);
}

static void test_registered_layers(void **state)
{
    (void)state;
    static const struct case_scene_info scenes[] = {
        {.name = "none", .title = "no scene"},
        {.name = "fake", .title = "a scene of this test", .keys = &fake_block_keys,
         .check = fake_scene_check},
    };
    static const struct case_checks checks = {fake_preconditioner, fake_curve, fake_memory};
    assert_int_equal(case_register_scenes(scenes, 2), 0);
    case_register_checks(&checks);
    static struct muflow_case cs;
    char err[512];

    /* the registered scene, its block's defaults and keys, every hook once */
    memset(fake_calls, 0, sizeof fake_calls);
    assert_int_equal(load_with(&cs, err, sizeof err, 3, "case.scene=fake", "boundary.zlo=wall",
                               "boundary.zhi=wall"),
                     0);
    assert_int_equal(cs.scene, 1);
    assert_true(((const struct fake_block *)case_scene_params(&cs))->width == 2.0);
    assert_true(cs.rheo.i1n == 0.125);
    for (int i = 0; i < 3; i++)
        assert_int_equal(fake_calls[i], 1);
    assert_int_equal(load_with(&cs, err, sizeof err, 4, "case.scene=fake", "boundary.zlo=wall",
                               "boundary.zhi=wall", "fake.width=4.5"),
                     0);
    assert_true(((const struct fake_block *)case_scene_params(&cs))->width == 4.5);

    /* refusals: the scene's and the hooks', each named after the override
     * that set the key it names, as the reader's own */
    static const struct {
        const char *ov[4];
        const char *want;
    } bad[] = {
        {{"case.scene=heap", "boundary.zlo=wall", "boundary.zhi=wall", "domain.nx=1"},
         "override case.scene=heap: must be one of none|fake"},
        {{"case.scene=fake", "boundary.zlo=slip", "boundary.zhi=wall", "domain.nx=1"},
         "override case.scene=fake, override boundary.zlo=slip: case.scene = fake needs "
         "boundary.zlo = wall"},
        {{"case.scene=fake", "boundary.zlo=wall", "boundary.zhi=wall", "fake.width=6"},
         "override fake.width=6: fake.width = 6: must be at most 5 for this scene"},
        {{"case.scene=fake", "boundary.zlo=wall", "boundary.zhi=wall",
          "solver.preconditioner=gmg"},
         "override solver.preconditioner=gmg: solver.preconditioner = gmg: refused by the fake "
         "solver"},
        {{"case.scene=fake", "boundary.zlo=wall", "boundary.zhi=wall", "domain.nx=2000"},
         "override domain.nx=2000: domain.nx = 2000: more than the fake machine holds"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(load_with(&cs, err, sizeof err, 4, bad[i].ov[0], bad[i].ov[1],
                                   bad[i].ov[2], bad[i].ov[3]),
                         2);
        print_message("%s\n", err);
        assert_string_equal(err, bad[i].want);
    }

    /* no scenes: every case refused, saying what the program must do */
    assert_int_equal(case_register_scenes(scenes, CASE_SCENES_MAX + 1), -1);
    assert_int_equal(case_register_scenes(scenes, 0), 0);
    assert_int_equal(load_with(&cs, err, sizeof err, 2, "boundary.zlo=wall", "boundary.zhi=wall"),
                     2);
    print_message("%s\n", err);
    assert_string_equal(err, "case: no scenes are registered: a program calls run_init() "
                             "(app/run.h) before loading a case");
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
        cmocka_unit_test(test_decimal_forms),
        cmocka_unit_test_setup_teardown(test_check_origin, tmp_setup, tmp_teardown),
        cmocka_unit_test(test_thinner_than_a_cell),
        cmocka_unit_test(test_enclosed_fluid),
        cmocka_unit_test_setup_teardown(test_duplicates, tmp_setup, tmp_teardown),
        cmocka_unit_test(test_number_text),
        cmocka_unit_test(test_key_help),
        cmocka_unit_test(test_docs_generated),
        cmocka_unit_test(test_docs_name_every_key),
        cmocka_unit_test(test_list_command),
        cmocka_unit_test_setup_teardown(test_file_errors, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_hostile, tmp_setup, tmp_teardown),
        cmocka_unit_test_setup_teardown(test_round_trip, tmp_setup, tmp_teardown),
        cmocka_unit_test(test_write_format),
        cmocka_unit_test(test_docs_key_order),
        cmocka_unit_test_teardown(test_registered_layers, restore_registry),
    };
    RUN_GROUP(t, "case", tests);
}
