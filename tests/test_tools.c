/* The tools around the solver, driven as a user would drive them, through the
 * shell: muflow --version, the test runner's command line, `make install`
 * with pkg-config builds of a small program and of examples/minimal.c against
 * the installed library, tools/muflow_plot.py on real runs (every case
 * file's), tools/collapse_movie.py on a run of another scene, README's
 * package and library lists against the Makefile, and README's commands as
 * a user types them.  The runner works in tests/
 * (test_main.c), so the repository is "..". */
#define _DEFAULT_SOURCE /* readlink, realpath */
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "test_main.h"

#define PYTHON "/usr/bin/python3" /* Debian's, with numpy, matplotlib, h5py */

/* ---------------------------------------------------------------------- */
/* helpers */

/* test_sh of cmd with its stderr in *out too. */
static int sh(const char *cmd, char **out)
{
    size_t flen = strlen(cmd) + sizeof "() 2>&1";
    char *full = malloc(flen);
    assert_non_null(full);
    snprintf(full, flen, "(%s) 2>&1", cmd);
    int rc = test_sh(full, out);
    free(full);
    return rc;
}

/* sh() that must exit 0; prints the command and its output otherwise. */
static char *sh_ok(const char *cmd)
{
    char *out;
    int rc = sh(cmd, &out);
    if (rc != 0)
        print_error("`%s` exited %d:\n%s\n", cmd, rc, out);
    assert_int_equal(rc, 0);
    return out;
}

/* This executable's folder (the build folder) and path. */
static void self_paths(char *exe, size_t len, char *dir, size_t dlen)
{
    ssize_t n = readlink("/proc/self/exe", exe, len - 1);
    assert_true(n > 0);
    exe[n] = '\0';
    snprintf(dir, dlen, "%s", exe);
    *strrchr(dir, '/') = '\0';
}

/* The value text of key in the [result] section of dir/summary.ini. */
static void summary_value(const char *dir, const char *key, char *out, size_t len)
{
    char *res = test_summary_result(dir);
    char want[128];
    snprintf(want, sizeof want, "\n%s = ", key);
    char *at = strstr(res, want);
    if (!at)
        print_error("no %s in [result] of %s/summary.ini\n", key, dir);
    assert_non_null(at);
    at += strlen(want);
    size_t n = strcspn(at, "\n");
    assert_true(n < len);
    memcpy(out, at, n);
    out[n] = '\0';
    free(res);
}

/* A PNG file of a plausible size. */
static void check_png(const char *dir, const char *name)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (!test_file_exists(path))
        print_error("%s missing\n", path);
    size_t n;
    char *data = test_read_file(path, &n);
    assert_true(n > 2000);
    assert_memory_equal(data, "\x89PNG\r\n\x1a\n", 8);
    free(data);
}

/* ---------------------------------------------------------------------- */
/* muflow --version */

static void test_version(void **state)
{
    (void)state;
    char bin[PATH_MAX], cmd[PATH_MAX + 64];
    test_muflow_bin(bin, sizeof bin);
    snprintf(cmd, sizeof cmd, "'%s' --version", bin);
    char *out = sh_ok(cmd);
    /* the Makefile's VERSION, the one definition */
    char *version = sh_ok("make -s --no-print-directory -C .. print-version");
    char want[256];
    snprintf(want, sizeof want, "muflow %s", version);
    print_message("%s", out);
    assert_string_equal(out, want);
    assert_true(strlen(version) > 1 && version[0] >= '0' && version[0] <= '9');
    /* without a release tag: the VERSION file */
    char *tag;
    if (sh("cd .. && git describe --tags --match 'v[0-9]*' >/dev/null 2>&1", &tag) != 0) {
        char *file = test_read_file("../VERSION", NULL);
        assert_string_equal(version, file);
        free(file);
    }
    free(tag);
    free(out);
    free(version);
}

/* An unknown option is named, with the usage, exit status 2 (it was taken
 * for a case file: "cannot open"); the options without arguments refuse
 * one (it was ignored); without an extra argument they still work. */
static void test_options(void **state)
{
    (void)state;
    char bin[PATH_MAX], cmd[PATH_MAX + 64];
    test_muflow_bin(bin, sizeof bin);
    static const struct {
        const char *args, *want;
    } bad[] = {
        {"--foo", "muflow: unknown option --foo\n"},
        {"-x cases/bagnold.ini", "muflow: unknown option -x\n"},
        {"--version extra", "muflow: --version takes no arguments (got 'extra')\n"},
        {"--list extra more", "muflow: --list takes no arguments (got 'extra' ...)\n"},
        {"--help extra", "muflow: --help takes no arguments (got 'extra')\n"},
        {"-h extra", "muflow: -h takes no arguments (got 'extra')\n"},
    };
    for (size_t m = 0; m < sizeof bad / sizeof bad[0]; m++) {
        snprintf(cmd, sizeof cmd, "'%s' %s", bin, bad[m].args);
        char *out;
        int rc = sh(cmd, &out);
        print_message("muflow %s: exit %d: %s", bad[m].args, rc, out);
        assert_int_equal(rc, 2);
        assert_true(strncmp(out, bad[m].want, strlen(bad[m].want)) == 0);
        assert_non_null(strstr(out, "\nusage: muflow CASE.ini"));
        assert_null(strstr(out, "cannot open"));
        free(out);
    }
    static const char *const good[] = {"--version", "--list", "--help", "-h"};
    for (size_t m = 0; m < sizeof good / sizeof good[0]; m++) {
        snprintf(cmd, sizeof cmd, "'%s' %s >/dev/null", bin, good[m]);
        free(sh_ok(cmd));
    }
}

/* ---------------------------------------------------------------------- */
/* the test runner's command line */

static void test_runner_unknown_group(void **state)
{
    (void)state;
    char exe[PATH_MAX], dir[PATH_MAX], cmd[PATH_MAX + 64];
    self_paths(exe, sizeof exe, dir, sizeof dir);
    snprintf(cmd, sizeof cmd, "'%s' nosuchgroup", exe);
    char *out;
    int rc = sh(cmd, &out);
    print_message("exit %d: %s", rc, out);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(out, "no test group named 'nosuchgroup'"));
    /* the list names every group, in the runner's order */
    const char *list = strstr(out, "groups: rheology poisson ");
    assert_non_null(list);
    static const char *const some[] = {" case ", " scenes ", " io ", " corpus ", " tools"};
    for (size_t i = 0; i < sizeof some / sizeof some[0]; i++)
        assert_non_null(strstr(list, some[i]));
    assert_null(strstr(out, " passed"));
    free(out);
    /* a known group beside an unknown one: nothing runs */
    snprintf(cmd, sizeof cmd, "'%s' corpus corpsu", exe);
    rc = sh(cmd, &out);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(out, "'corpsu'"));
    assert_null(strstr(out, "fuzz corpus"));
    free(out);
}

/* The corpus group (files relative to tests/) from the repository root and
 * from an unrelated folder. */
static void test_runner_any_folder(void **state)
{
    (void)state;
    char exe[PATH_MAX], dir[PATH_MAX], cmd[PATH_MAX + 64];
    self_paths(exe, sizeof exe, dir, sizeof dir);
    const char *from[] = {"..", "/tmp"};
    for (int m = 0; m < 2; m++) {
        snprintf(cmd, sizeof cmd, "cd %s && '%s' corpus", from[m], exe);
        char *out = sh_ok(cmd);
        assert_non_null(strstr(out, "fuzz corpus: "));
        assert_non_null(strstr(out, "tests: 1 passed, 0 failed"));
        free(out);
    }
}

/* ---------------------------------------------------------------------- */
/* make install into a DESTDIR, a program built against it with pkg-config */

static const char prog[] =
    "#include <stdio.h>\n"
    "#include \"app/run.h\"\n"
    "int main(int argc, char **argv)\n"
    "{\n"
    "    static struct muflow_case cs;\n"
    "    char err[512];\n"
    "    run_init();\n"
    "    if (argc < 2 || case_load(&cs, argv[1], 0, NULL, err, sizeof err) != 0)\n"
    "        return fprintf(stderr, \"%s\\n\", argc < 2 ? \"usage: prog CASE\" : err), 1;\n"
    "    printf(\"%s %d %d %d\\n\", cs.name, cs.n[0], cs.n[1], cs.n[2]);\n"
    "    return 0;\n"
    "}\n";

static void test_install(void **state)
{
    (void)state;
    char root[PATH_MAX], exe[PATH_MAX], bdir[PATH_MAX], tmp[64], cmd[3 * PATH_MAX];
    assert_non_null(realpath("..", root));
    self_paths(exe, sizeof exe, bdir, sizeof bdir);
    /* BUILD of this executable, relative to the repository when inside it */
    size_t rl = strlen(root);
    const char *build = strncmp(bdir, root, rl) == 0 && bdir[rl] == '/' ? bdir + rl + 1 : bdir;
    test_tmp_make(tmp, sizeof tmp, "tools_install");
    char dest[128];
    snprintf(dest, sizeof dest, "%s/stage", tmp);

    snprintf(cmd, sizeof cmd, "make -s --no-print-directory -C '%s' BUILD='%s' DESTDIR='%s' "
                              "PREFIX=/usr/local install", root, build, dest);
    free(sh_ok(cmd));
    const char *files[] = {"bin/muflow", "lib/libmuflow.a", "lib/pkgconfig/muflow.pc",
                           "include/muflow/config/case.h", "include/muflow/io/output.h",
                           "include/muflow/kernels/rheology.h"};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        char path[700];
        snprintf(path, sizeof path, "%s/usr/local/%s", dest, files[f]);
        if (!test_file_exists(path))
            print_error("%s not installed\n", path);
        assert_true(test_file_exists(path));
    }
    /* every header of include/ */
    snprintf(cmd, sizeof cmd, "cd '%s/include' && for h in */*.h; do "
                              "cmp \"$h\" '%s/usr/local/include/muflow/'\"$h\" || exit 1; done",
             root, dest);
    free(sh_ok(cmd));
    /* the installed command runs and has the build's version */
    snprintf(cmd, sizeof cmd, "'%s/usr/local/bin/muflow' --version", dest);
    char *ver = sh_ok(cmd);
    assert_true(strncmp(ver, "muflow ", 7) == 0);

    /* muflow.pc names /usr/local (PREFIX, not DESTDIR): pkg-config is pointed
     * at the staged tree by redefining prefix */
    char pcpath[256];
    snprintf(pcpath, sizeof pcpath, "%s/usr/local/lib/pkgconfig/muflow.pc", dest);
    char *pc = test_read_file(pcpath, NULL);
    print_message("%s", pc);
    assert_non_null(strstr(pc, "prefix=/usr/local\n"));
    char vline[160];
    snprintf(vline, sizeof vline, "Version: %.*s", (int)strcspn(ver + 7, "\n") + 1, ver + 7);
    assert_non_null(strstr(pc, vline));
    free(pc);
    free(ver);
    snprintf(cmd, sizeof cmd, "%s/prog.c", tmp);
    FILE *f = fopen(cmd, "w");
    assert_non_null(f);
    fputs(prog, f);
    fclose(f);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && export PKG_CONFIG_PATH='%s/usr/local/lib/pkgconfig' && "
             "flags=$(pkg-config --define-variable=prefix='%s/usr/local' --cflags --libs muflow) "
             "&& echo \"$flags\" && ${CC:-cc} -std=c11 -Wall -Wextra -Werror prog.c -o prog $flags "
             "&& ./prog '%s/cases/bagnold.ini'",
             tmp, dest, dest, root);
    char *out = sh_ok(cmd);
    print_message("%s", out);
    assert_non_null(strstr(out, "-fopenmp"));
    assert_non_null(strstr(out, "-lmuflow"));
    assert_non_null(strstr(out, "\nbagnold 2 1 40\n")); /* cases/bagnold.ini's grid */
    free(out);

    /* examples/minimal.c, the documented example, built the way its comment
     * says: its status, steps and err_rms are the installed command's
     * summary.ini lines for the same case and overrides (its comment's
     * numbers, bagnold at H/10: 15 steps, err_rms 1.935774e-03) */
    int cmd_len = snprintf(cmd, sizeof cmd,
             "cd '%s' && export PKG_CONFIG_PATH='%s/usr/local/lib/pkgconfig' && "
             "${CC:-cc} -std=c11 -Wall -Wextra -Werror '%s/examples/minimal.c' -o minimal "
             "$(pkg-config --define-variable=prefix='%s/usr/local' --cflags --libs muflow) "
             "&& ./minimal '%s/cases/bagnold.ini' domain.nz=10 && "
             "'%s/usr/local/bin/muflow' '%s/cases/bagnold.ini' domain.nz=10 output.quiet=on "
             "output.fields=off output.dir=cli >/dev/null && "
             "grep -E '^(status|steps|err_rms) = ' cli/summary.ini",
             tmp, dest, root, dest, root, dest, root);
    assert_true(cmd_len > 0 && (size_t)cmd_len < sizeof cmd); /* the paths fit */
    out = sh_ok(cmd);
    print_message("%s", out);
    const char *want = "status = steady\nsteps = 15\nerr_rms = 1.935774e-03\n";
    assert_true(strncmp(out, want, strlen(want)) == 0);        /* the example */
    assert_string_equal(out + strlen(want), want);             /* the command's summary */
    free(out);
    /* and its usage line and status without a case */
    snprintf(cmd, sizeof cmd, "cd '%s' && ./minimal", tmp);
    assert_int_equal(sh(cmd, &out), 2);
    assert_non_null(strstr(out, "usage: minimal CASE.ini"));
    free(out);

    /* make uninstall leaves none of the files */
    snprintf(cmd, sizeof cmd, "make -s --no-print-directory -C '%s' BUILD='%s' DESTDIR='%s' "
                              "PREFIX=/usr/local uninstall", root, build, dest);
    free(sh_ok(cmd));
    snprintf(cmd, sizeof cmd, "test -z \"$(find '%s' -type f)\"", dest);
    free(sh_ok(cmd));

    /* the same build installed with another PREFIX, then the first again:
     * each muflow.pc names the PREFIX (and LIBDIR) of its own make command */
    static const struct {
        const char *prefix, *libdir, *want_prefix, *want_libdir;
    } again[] = {
        {"/opt/muflow", "", "prefix=/opt/muflow\n", "libdir=${prefix}/lib\n"},
        {"/opt/muflow", "/opt/lib64", "prefix=/opt/muflow\n", "libdir=/opt/lib64\n"},
        {"/usr/local", "", "prefix=/usr/local\n", "libdir=${prefix}/lib\n"},
    };
    for (size_t m = 0; m < sizeof again / sizeof again[0]; m++) {
        char libdir[64] = "", pcdir[300];
        if (again[m].libdir[0])
            snprintf(libdir, sizeof libdir, "LIBDIR=%s", again[m].libdir);
        snprintf(cmd, sizeof cmd, "make -s --no-print-directory -C '%s' BUILD='%s' DESTDIR='%s' "
                                  "PREFIX=%s %s install", root, build, dest, again[m].prefix, libdir);
        free(sh_ok(cmd));
        snprintf(pcdir, sizeof pcdir, "%s%s%s/pkgconfig/muflow.pc", dest,
                 again[m].libdir[0] ? "" : again[m].prefix,
                 again[m].libdir[0] ? again[m].libdir : "/lib");
        pc = test_read_file(pcdir, NULL);
        print_message("PREFIX=%s %s: %s", again[m].prefix, libdir, pc);
        assert_non_null(strstr(pc, again[m].want_prefix));
        assert_non_null(strstr(pc, again[m].want_libdir));
        free(pc);
        snprintf(cmd, sizeof cmd, "make -s --no-print-directory -C '%s' BUILD='%s' DESTDIR='%s' "
                                  "PREFIX=%s %s uninstall", root, build, dest, again[m].prefix,
                 libdir);
        free(sh_ok(cmd));
    }
    snprintf(cmd, sizeof cmd, "test -z \"$(find '%s' -type f)\"", dest);
    free(sh_ok(cmd));
    test_tmp_remove(tmp);
}

/* ---------------------------------------------------------------------- */
/* tools/muflow_plot.py */

static int python_ready(void)
{
    return sh(PYTHON " -c 'import numpy, matplotlib, h5py'", NULL) == 0;
}

static void test_plot(void **state)
{
    (void)state;
    if (!python_ready())
        print_error(PYTHON " lacks numpy, matplotlib or h5py: make deps installs "
                           "python3-matplotlib python3-h5py\n");
    assert_true(python_ready());
    char bin[PATH_MAX], tmp[64], cmd[4096], bag[128], none[128], png[160];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(tmp, sizeof tmp, "tools_plot");
    snprintf(bag, sizeof bag, "%s/bagnold", tmp);
    snprintf(none, sizeof none, "%s/none", tmp);

    /* bagnold: summary with err_rms and u_surface, profile, history, fields */
    assert_true(snprintf(cmd, sizeof cmd, "'%s' ../cases/bagnold.ini domain.nz=10 output.quiet=on "
                                          "output.dir='%s'", bin, bag) < (int)sizeof cmd);
    free(sh_ok(cmd));
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/muflow_plot.py '%s'", bag);
    char *out = sh_ok(cmd);
    print_message("%s", out);
    char want[512], v[128], x[128];
    const char *keys[] = {"status", "steps", "err_rms"};
    for (int k = 0; k < 3; k++) {
        summary_value(bag, keys[k], v, sizeof v);
        snprintf(want, sizeof want, "%s = %s\n", keys[k], v);
        if (!strstr(out, want))
            print_error("muflow_plot.py did not print '%s'\n", want);
        assert_non_null(strstr(out, want));
    }
    summary_value(bag, "u_surface", v, sizeof v);
    summary_value(bag, "u_surface_exact", x, sizeof x);
    snprintf(want, sizeof want, "u_surface = %s (exact %s)\n", v, x);
    assert_non_null(strstr(out, want));
    assert_non_null(strstr(out, "status = steady\n")); /* the values themselves */
    free(out);
    check_png(bag, "compare.png");
    check_png(bag, "history.png");
    check_png(bag, "field_velocity.png");
    /* other cell fields (log colours: eta spans decades) into another folder,
     * one by its alias */
    snprintf(png, sizeof png, "%s/viscosity", tmp);
    snprintf(cmd, sizeof cmd,
             PYTHON " ../tools/muflow_plot.py '%s' --field viscosity --field p --out '%s'", bag,
             png);
    free(sh_ok(cmd));
    check_png(png, "field_viscosity.png");
    check_png(png, "field_pressure.png");
    /* a field the files do not have: exit 2, the ones they have listed, nothing drawn */
    snprintf(png, sizeof png, "%s/nosuch", tmp);
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/muflow_plot.py '%s' --field tracer --out '%s'",
             bag, png);
    assert_int_equal(sh(cmd, &out), 2);
    print_message("%s", out);
    assert_non_null(strstr(out, "no field 'tracer'"));
    assert_non_null(strstr(out, "it has: inertial_number, pressure, "));
    assert_non_null(strstr(out, " velocity, viscosity"));
    assert_null(strstr(out, "Traceback"));
    assert_false(test_file_exists(png));
    free(out);

    /* no scene (no profile.csv, no error, no headline) and no field files,
     * plots into --out: only the history, and no failure */
    assert_true(snprintf(cmd, sizeof cmd, "'%s' ../cases/bagnold.ini case.scene=none domain.nz=10 "
                                          "output.fields=off output.quiet=on output.dir='%s'",
                         bin, none) < (int)sizeof cmd);
    free(sh_ok(cmd));
    snprintf(png, sizeof png, "%s/png", none);
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/muflow_plot.py '%s' --out '%s' --field viscosity",
             none, png);
    out = sh_ok(cmd);
    print_message("%s", out);
    summary_value(none, "steps", v, sizeof v);
    snprintf(want, sizeof want, "steps = %s\n", v);
    assert_non_null(strstr(out, want));
    assert_null(strstr(out, "err_rms"));
    assert_non_null(strstr(out, "scene 'none' has no comparison"));
    assert_non_null(strstr(out, "no fields_*.h5"));
    check_png(png, "history.png");
    snprintf(want, sizeof want, "%s/compare.png", png);
    assert_false(test_file_exists(want));
    snprintf(want, sizeof want, "%s/field_viscosity.png", png);
    assert_false(test_file_exists(want));
    free(out);

    /* a folder without muflow output: exit status 1 */
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/muflow_plot.py '%s'", png);
    assert_int_equal(sh(cmd, NULL), 1);
    test_tmp_remove(tmp);
}

/* Every case file of cases/ on a small grid or a short time (a second or
 * two each), then tools/muflow_plot.py on all the runs in one process: exit
 * 0, each run's compare.png (the scene against its reference, the reference
 * named on the line that writes it), history.png (a transient's, by
 * solver.mode, without a residual; the channel's body: its C_D and C_L
 * from forces.csv), field_velocity.png, the axes in SI
 * units exactly for the SI cases, no [result] key printed twice; and
 * tools/collapse_movie.py on a run that is not a collapse: exit 2 and one
 * line.
 *
 * The cases are the folder's.  The table names what the tool must draw for
 * the shipped ones, with the overrides that make them small; a case not in
 * it runs as shipped (it must be short), and its run says what to expect:
 * with a profile.csv, a compare.png against the file's exact column, or
 * "muflow alone" without one; the axes in SI units when a gravity of the
 * case is Earth's. */
struct small_case {
    const char *name, *overrides;
    const char *against; /* what the "wrote .../compare.png (...)" line names */
    int si;              /* the case is in SI units (-1: as its summary says) */
};
static const struct small_case small_cases[] = {
    {"bagnold", "domain.nz=10", "against Bagnold's profile (Chauchat & Medale 2014", 0},
    {"bagnold2", "domain.nx=4 domain.nz=20", "(Barker & Rauter 2018", 1},
    {"bagnold3d",
     "domain.nx=4 domain.ny=4 domain.nz=8 domain.lx=3.5 domain.ly=3.5 output.fields=on",
     "against Bagnold's profile", 0},
    {"bedload", "domain.nz=20", "(Ouriemi, Aussillous & Guazzelli 2009)", 1},
    {"bingham_cavity", "domain.nx=16 domain.nz=16", "against Vola et al. 2003, vola2003_cavity.csv",
     0},
    {"bingham_channel", "domain.nz=20", "against the Bingham plug-flow profile", 0},
    {"chute", "domain.ny=20", "(Chauchat & Medale 2014, eq. 27)", 0},
    {"collapse", "domain.nx=40 domain.nz=12 solver.end_time=1",
     "against Lagree et al. 2011, lagree2011_collapse.csv", 0},
    {"couette", "", "against u = U z/H + G z (H - z) / (2 mu)", 0},
    {"cylinder", "domain.nx=10 domain.nz=30 cylinder.forcing=1.2",
     "no published drag: muflow alone", 0},
    {"cylinder_benchmark", "domain.nx=44 domain.nz=9 solver.end_time=1",
     "against Schaefer & Turek (1996), test 2D-1", 0},
    {"duct_circular", "domain.ny=10 domain.nz=20", "against the plane channel's exact profile", 1},
    {"duct_square", "domain.ny=10 domain.nz=20", "against the plane channel's exact profile", 1},
    {"front", "domain.nx=50 domain.nz=6 domain.ly=3.575e-4 solver.end_time=0.01", NULL, 1},
    {"heap", "domain.ny=14 domain.nz=20", "no experimental profiles: muflow alone", 0},
    {"slope_release", "domain.nx=30 domain.nz=12 domain.ly=0.005 solver.end_time=0.02", NULL, 1},
};
#define SMALL_CASES (sizeof small_cases / sizeof small_cases[0])
#define MAX_CASES 64
#define CASE_NAME 64

static int by_name(const void *a, const void *b)
{
    return strcmp((const char *)a, (const char *)b);
}

/* The case files of cases/ (without ".ini"), in name order; each line of
 * the table must name one. */
static size_t case_files(char names[][CASE_NAME], size_t max)
{
    DIR *d = opendir("../cases");
    assert_non_null(d);
    size_t files = 0;
    for (struct dirent *e; (e = readdir(d));) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 4, ".ini") != 0)
            continue;
        assert_true(files < max && n - 4 < CASE_NAME);
        memcpy(names[files], e->d_name, n - 4);
        names[files++][n - 4] = '\0';
    }
    closedir(d);
    qsort(names, files, CASE_NAME, by_name);
    for (size_t c = 0; c < SMALL_CASES; c++) {
        size_t f = 0;
        while (f < files && strcmp(names[f], small_cases[c].name) != 0)
            f++;
        if (f == files)
            print_error("test_plot_cases names %s, which is not in cases/\n",
                        small_cases[c].name);
        assert_true(f < files);
    }
    return files;
}

/* The value text of key in section of dir/summary.ini, or "" without it. */
static void summary_key(const char *dir, const char *section, const char *key, char *out,
                        size_t len)
{
    char *s = test_read_in(dir, "summary.ini"), head[96], want[96];
    snprintf(head, sizeof head, "\n[%s]\n", section);
    snprintf(want, sizeof want, "\n%s = ", key);
    const char *at = strstr(s, head), *end = at ? strstr(at + 1, "\n[") : NULL;
    at = at ? strstr(at + 1, want) : NULL;
    out[0] = '\0';
    if (at && (!end || at < end))
        snprintf(out, len, "%.*s", (int)strcspn(at + strlen(want), "\n"), at + strlen(want));
    free(s);
}

/* The case of run dir is in SI units: a gravity of it is Earth's. */
static int summary_si(const char *dir)
{
    char *s = test_read_in(dir, "summary.ini");
    int si = 0;
    for (const char *at = strstr(s, "\ngravity = "); at; at = strstr(at + 1, "\ngravity = "))
        si |= fabs(strtod(at + strlen("\ngravity = "), NULL) - 9.81) < 0.02;
    free(s);
    return si;
}

/* What the compare.png line of a case outside the table names: "against"
 * when its profile.csv has an exact (or reference, or plane channel)
 * column, "muflow alone" when it has none; NULL without a profile.csv (a
 * scene the tool knows may draw one from other files). */
static const char *generic_against(const char *dir, char *buf, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/profile.csv", dir);
    if (!test_file_exists(path))
        return NULL;
    char *t = test_read_file(path, NULL);
    t[strcspn(t, "\r\n")] = '\0';
    snprintf(buf, len, "no exact profile: muflow alone");
    static const char *const suffix[] = {"_exact", "_reference", "_plane"};
    for (char *col = strtok(t, ","); col; col = strtok(NULL, ",")) {
        size_t n = strlen(col);
        for (int k = 0; k < 3; k++)
            if (n > strlen(suffix[k]) && strcmp(col + n - strlen(suffix[k]), suffix[k]) == 0)
                snprintf(buf, len, "against ");
    }
    free(t);
    return buf;
}

/* The part of the plot tool's output about run dir (from its "== dir (" line
 * to the next run's), copied. */
static char *run_block(const char *out, const char *dir)
{
    char head[300];
    snprintf(head, sizeof head, "== %s (", dir);
    const char *at = strstr(out, head);
    if (!at)
        print_error("muflow_plot.py said nothing about %s\n", dir);
    assert_non_null(at);
    char *s = strdup(at);
    assert_non_null(s);
    char *end = strstr(s + 1, "\n== ");
    if (end)
        end[1] = '\0';
    return s;
}

/* Fails when two lines of block start with the same "key = ". */
static void keys_once(const char *block, const char *name)
{
    for (const char *l = block; *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : l + strlen(l)) {
        size_t k = strspn(l, "abcdefghijklmnopqrstuvwxyz0123456789_");
        if (k == 0 || strncmp(l + k, " = ", 3) != 0)
            continue;
        for (const char *m = strchr(l, '\n'); m; m = strchr(m + 1, '\n'))
            if (strncmp(m + 1, l, k + 3) == 0) {
                print_error("%s: muflow_plot.py printed %.*s twice\n", name, (int)k, l);
                fail();
            }
    }
}

static void test_plot_cases(void **state)
{
    (void)state;
    assert_true(python_ready());
    char bin[PATH_MAX], tmp[64], cmd[4096], dir[256], path[512];
    test_muflow_bin(bin, sizeof bin);
    /* every case file has its run: its line of the table, or as shipped */
    static char names[MAX_CASES][CASE_NAME];
    size_t files = case_files(names, MAX_CASES);
    assert_true(files >= SMALL_CASES);
    struct small_case cases[MAX_CASES];
    for (size_t f = 0; f < files; f++) {
        cases[f] = (struct small_case){names[f], "", NULL, -1};
        for (size_t c = 0; c < SMALL_CASES; c++)
            if (strcmp(small_cases[c].name, names[f]) == 0)
                cases[f] = small_cases[c];
    }

    test_tmp_make(tmp, sizeof tmp, "tools_cases");
    for (size_t c = 0; c < files; c++) {
        assert_true(snprintf(cmd, sizeof cmd, "'%s' ../cases/%s.ini %s output.quiet=on "
                                              "output.dir='%s/runs/%s'",
                             bin, cases[c].name, cases[c].overrides, tmp,
                             cases[c].name) < (int)sizeof cmd);
        free(sh_ok(cmd));
    }
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/muflow_plot.py '%s'/runs/* --out '%s/png'", tmp,
             tmp);
    char *out; /* sh, not sh_ok: gcc 12 takes run_block's pointers for ones into sh_ok's frame */
    int rc = sh(cmd, &out);
    print_message("%s", out);
    assert_int_equal(rc, 0);
    assert_null(strstr(out, "Traceback"));
    for (size_t c = 0; c < files; c++) {
        const char *name = cases[c].name;
        char run[256], generic[64], mode[32];
        snprintf(run, sizeof run, "%s/runs/%s", tmp, name);
        char *block = run_block(out, run);
        const char *against = cases[c].against ? cases[c].against
                                               : generic_against(run, generic, sizeof generic);
        snprintf(dir, sizeof dir, "%s/png/%s", tmp, name);
        snprintf(path, sizeof path, "%s/compare.png (", dir);
        const char *line = strstr(block, path);
        if (against || line) {
            check_png(dir, "compare.png");
            assert_non_null(line);
        } else {
            assert_non_null(strstr(block, "has no comparison to draw"));
        }
        if (against) {
            const char *what = strstr(line, against);
            if (!what || what > strchr(line, '\n'))
                print_error("%s: compare.png not %s\n", name, against);
            assert_true(what && what < strchr(line, '\n'));
        }
        check_png(dir, "history.png");
        check_png(dir, "field_velocity.png");
        /* a transient history: the time step, no residual */
        snprintf(path, sizeof path, "%s/history.png (", dir);
        const char *hist = strstr(block, path);
        assert_non_null(hist);
        summary_key(run, "solver", "mode", mode, sizeof mode);
        assert_true(!strcmp(mode, "transient") || !strcmp(mode, "steady"));
        int transient = !strcmp(mode, "transient");
        if (!strcmp(name, "collapse") || !strcmp(name, "cylinder_benchmark"))
            assert_true(transient);
        if (transient) {
            assert_true(strncmp(hist + strlen(path), "dt", 2) == 0);
            assert_null(strstr(hist, "residual"));
        } else {
            assert_true(strncmp(hist + strlen(path), "residual", 8) == 0);
        }
        if (!strcmp(name, "collapse"))
            assert_non_null(strstr(hist, "(dt, kinetic energy against t)"));
        if (!strcmp(name, "cylinder_benchmark")) /* forces.csv's series */
            assert_non_null(strstr(hist, "(dt, drag coefficient, lift coefficient against t)"));
        int si = strstr(block, "\naxes in SI units\n") != NULL;
        int want_si = cases[c].si >= 0 ? cases[c].si : summary_si(run);
        if (si != want_si)
            print_error("%s: axes %sin SI units\n", name, si ? "" : "not ");
        assert_int_equal(si, want_si);
        keys_once(block, name);
        free(block);
    }
    free(out);

    /* the collapse's pictures of another scene's run: one line, exit 2 */
    snprintf(cmd, sizeof cmd, PYTHON " ../tools/collapse_movie.py '%s/runs/bagnold'", tmp);
    char *movie;
    assert_int_equal(sh(cmd, &movie), 2);
    print_message("%s", movie);
    assert_true(strncmp(movie, "collapse_movie: ", 16) == 0);
    assert_non_null(strstr(movie, "not a column collapse (case.scene = bagnold)"));
    assert_int_equal(strchr(movie, '\n') - movie + 1, (long)strlen(movie)); /* one line */
    free(movie);
    test_tmp_remove(tmp);
}

/* ---------------------------------------------------------------------- */
/* README against the Makefile */

/* The text of README's section "## title" (to the next "## "). */
static char *readme_section(const char *readme, const char *title)
{
    char head[128];
    snprintf(head, sizeof head, "\n## %s\n", title);
    const char *at = strstr(readme, head);
    if (!at)
        print_error("README.md has no section '## %s'\n", title);
    assert_non_null(at);
    at += strlen(head);
    const char *end = strstr(at, "\n## ");
    size_t n = end ? (size_t)(end - at) : strlen(at);
    char *s = malloc(n + 1);
    assert_non_null(s);
    memcpy(s, at, n);
    s[n] = '\0';
    return s;
}

/* word in text between blanks, backticks, line ends or punctuation. */
static int has_word(const char *text, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = strstr(text, word); p; p = strstr(p + 1, word)) {
        char before = p == text ? ' ' : p[-1], after = p[n];
        if (strchr(" `\n(", before) && strchr(" `\n),.;", after))
            return 1;
    }
    return 0;
}

static void test_readme_packages(void **state)
{
    (void)state;
    char *readme = test_read_file("../README.md", NULL);
    char *pkgs = sh_ok("make -s --no-print-directory -C .. print-deb-pkgs");
    char *two = readme_section(readme, "Two commands");
    int n = 0;
    for (char *w = strtok(pkgs, " \n"); w; w = strtok(NULL, " \n"), n++) {
        if (!has_word(two, w))
            print_error("README's \"Two commands\" does not name %s of DEB_PKGS\n", w);
        assert_true(has_word(two, w));
    }
    assert_true(n >= 10);
    char *libs = readme_section(readme, "Libraries");
    const char *names[] = {"FFTW", "GSL", "libinih", "cmocka", "HDF5", "SuiteSparse", "UMFPACK",
                           "CHOLMOD", "OpenBLAS"};
    for (size_t m = 0; m < sizeof names / sizeof names[0]; m++) {
        if (!strstr(libs, names[m]))
            print_error("README's \"Libraries\" does not name %s\n", names[m]);
        assert_non_null(strstr(libs, names[m]));
    }
    free(libs);
    free(two);
    free(pkgs);
    free(readme);
}

/* Every command of README's code blocks: the make targets exist, the case
 * files exist, every override is a key muflow --list knows, and the cheap
 * ones run as written, in order, from a scratch folder
 * (tests/readme_commands.py). */
static void test_readme_commands(void **state)
{
    (void)state;
    char bin[PATH_MAX], cmd[PATH_MAX + 128];
    test_muflow_bin(bin, sizeof bin);
    snprintf(cmd, sizeof cmd, PYTHON " readme_commands.py .. '%s'", bin);
    char *out = sh_ok(cmd);
    printf("    %s", out);
    free(out);
}

void group_tools(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version),
        cmocka_unit_test(test_options),
        cmocka_unit_test(test_runner_unknown_group),
        cmocka_unit_test(test_runner_any_folder),
        cmocka_unit_test(test_install),
        cmocka_unit_test(test_plot),
        cmocka_unit_test(test_plot_cases),
        cmocka_unit_test(test_readme_packages),
        cmocka_unit_test(test_readme_commands),
    };
    RUN_GROUP(t, "tools", tests);
}
