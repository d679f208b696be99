/* What a run tells its user, from the command line (build/muflow): the
 * names on the terminal and in summary.ini follow the scene (an exact
 * solution, or published reference data as for the Bingham cavity), and
 * profile.csv's comparison column holds no value the data do not have.
 * Small runs only (16 x 16 cavity, bagnold at nz = 10). */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/reference.h"
#include "test_main.h"

#define CAVITY "../cases/bingham_cavity.ini"
#define VOLA "../cases/data/vola2003_cavity.csv"

/* Runs build/muflow with args into a fresh folder; returns its stdout (the
 * caller frees) and the folder in dir. */
static char *run_muflow(const char *args, char *dir, size_t dirlen)
{
    snprintf(dir, dirlen, "/tmp/muflow_outputs_XXXXXX");
    assert_non_null(mkdtemp(dir));
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "../build/muflow %s output.dir=%s output.fields=off output.quiet=on", args, dir);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t cap = 1 << 14, len = 0, got;
    char *out = malloc(cap);
    assert_non_null(out);
    while ((got = fread(out + len, 1, cap - 1 - len, p)) > 0)
        len += got;
    out[len] = '\0';
    int rc = pclose(p);
    if (rc != 0)
        print_error("%s: status %d\n%s", cmd, rc, out);
    assert_int_equal(rc, 0);
    return out;
}

static char *read_in(const char *dir, const char *name)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return test_read_file(path, NULL);
}

static void remove_dir(const char *dir)
{
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

/* The [result] section of a summary (up to the case keys). */
static void cut_result(char *summary)
{
    char *keys = strstr(summary, "\n; muflow case");
    assert_non_null(keys);
    *keys = '\0';
}

/* The line of text that contains what. */
static const char *line_with(const char *text, const char *what)
{
    const char *hit = strstr(text, what);
    if (!hit)
        print_error("no line with \"%s\" in:\n%s", what, text);
    assert_non_null(hit);
    while (hit > text && hit[-1] != '\n')
        hit--;
    return hit;
}

/* The cavity at Vola's Bn = 1 (yield_stress 1/sqrt(2)): terminal and summary
 * say err_midline and reference, profile.csv's u_reference is Vola's curve
 * between its first and last point and nan outside (next to the walls). */
static void test_cavity_reference_names(void **state)
{
    (void)state;
    char dir[64];
    char *out = run_muflow(CAVITY " domain.nx=16 domain.nz=16 "
                           "rheology.yield_stress=0.70710678118654752",
                           dir, sizeof dir);
    print_message("%s", out);
    const char *line = line_with(out, "psi_max");
    char *nl = strchr(line, '\n');
    assert_non_null(nl);
    *nl = '\0';
    assert_non_null(strstr(line, "err_midline "));
    assert_non_null(strstr(line, "(reference "));
    assert_null(strstr(line, "err_rms"));
    assert_null(strstr(line, "exact"));
    free(out);

    char *summary = read_in(dir, "summary.ini");
    cut_result(summary);
    assert_non_null(strstr(summary, "\nerr_midline = "));
    assert_non_null(strstr(summary, "\npsi_max = "));
    assert_non_null(strstr(summary, "\npsi_max_reference = 0.0898"));
    assert_null(strstr(summary, "exact"));
    assert_null(strstr(summary, "err_rms"));
    assert_null(strstr(summary, "nan"));
    assert_null(strstr(summary, "_note"));
    free(summary);

    struct curve mid;
    char err[256];
    assert_int_equal(reference_curve(VOLA, "midline", 1.0, &mid, err, sizeof err), 0);
    assert_true(mid.n > 10);
    char *csv = read_in(dir, "profile.csv");
    assert_int_equal(strncmp(csv, "z,u,pressure,shear_rate,inertial_number,viscosity,u_reference\n",
                             62), 0);
    int rows = 0, inside = 0;
    for (char *row = strchr(csv, '\n') + 1; *row; rows++) {
        char *end = strchr(row, '\n');
        assert_non_null(end);
        *end = '\0';
        double z = strtod(row, NULL);
        const char *last = strrchr(row, ',') + 1;
        int in_range = z >= mid.x[0] && z <= mid.x[mid.n - 1];
        if (in_range) {
            double ref = strtod(last, NULL);
            assert_true(fabs(ref - curve_at(&mid, z)) <= 1e-10);
            inside++;
        } else {
            if (strcmp(last, "nan") != 0)
                print_error("z = %g outside [%g, %g]: u_reference %s\n", z, mid.x[0],
                            mid.x[mid.n - 1], last);
            assert_string_equal(last, "nan");
        }
        row = end + 1;
    }
    assert_int_equal(rows, 16);
    assert_int_equal(inside, 14); /* the cells next to the walls lie outside the data */
    free(csv);
    curve_free(&mid);
    /* and so does the history's error column */
    char *hist = read_in(dir, "history.csv");
    assert_non_null(strstr(hist, ",rejected_steps,err_midline\n"));
    free(hist);
    remove_dir(dir);
}

/* yield_stress = 1 is Vola's Bn = 1.414, for which the data have no
 * mid-line: the terminal says so (no reference profile, the Bn named), not
 * "no analytic steady solution"; psi_max still has the fig. 2a value. */
static void test_cavity_no_reference_profile(void **state)
{
    (void)state;
    char dir[64];
    char *out = run_muflow(CAVITY " domain.nx=16 domain.nz=16 rheology.yield_stress=1", dir,
                           sizeof dir);
    print_message("%s", out);
    const char *line = line_with(out, "psi_max");
    assert_non_null(strstr(line, "no reference profile for these parameters (Bn = 1.41421"));
    assert_non_null(strstr(line, "vola2003_cavity.csv"));
    assert_non_null(strstr(line, "(reference 0.08"));
    assert_null(strstr(out, "analytic"));
    /* why, on the terminal and in the summary: the same words */
    const char *why = line_with(out, "bingham_cavity: no mid-line reference: ");
    assert_non_null(strstr(why, "Bn 1.41421 has no profile in the data (Bn 0, 1, 10, 100, 1000)"));
    char *summary = read_in(dir, "summary.ini");
    cut_result(summary);
    assert_non_null(strstr(summary, "\nerr_midline = nan\n"));
    assert_non_null(strstr(summary, "\npsi_max_reference = 0.08"));
    assert_non_null(strstr(summary, "\nmidline_reference_note = Bn 1.41421 has no profile in the "
                                    "data (Bn 0, 1, 10, 100, 1000)\n"));
    assert_null(strstr(summary, "psi_max_reference_note"));
    assert_null(strstr(summary, "err_rms_paper"));
    free(summary);
    free(out);
    char *csv = read_in(dir, "profile.csv");
    int values = 0;
    for (const char *p = strchr(csv, '\n'); p; p = strchr(p + 1, '\n'))
        values += p[1] != '\0';
    assert_int_equal(values, 16);
    for (const char *p = strchr(csv, '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
        const char *end = strchr(p + 1, '\n');
        const char *last = end - 3;
        assert_int_equal(strncmp(last, "nan", 3), 0); /* no data: no value */
    }
    free(csv);
    remove_dir(dir);
}

/* Where the published data do not cover the parameters the reference is
 * nan, never an extrapolation, and the terminal and the summary say why in
 * the same words.  Vola's Bn = 10^4 (yield_stress 7071): fig. 2a's psi_max
 * ends at Bn 982.103, and extrapolated past it the reference was -4.19e-4
 * (negative, for a largest |psi|), printed beside "no reference data for
 * these parameters"; the mid-lines are at five Bn only.  Bn = 0 lies before
 * the curve's first point (0.1). */
static void test_cavity_outside_data(void **state)
{
    (void)state;
    static const struct {
        const char *yield, *bn, *midline;
    } outside[] = {
        {"7071", "9999.9", "Bn 9999.9 has no profile in the data (Bn 0, 1, 10, 100, 1000)"},
        {"0", "0", NULL},
    };
    for (size_t m = 0; m < sizeof outside / sizeof outside[0]; m++) {
        char dir[64], args[160], note[200];
        snprintf(args, sizeof args, CAVITY " domain.nx=16 domain.nz=16 rheology.yield_stress=%s",
                 outside[m].yield);
        char *out = run_muflow(args, dir, sizeof dir);
        print_message("%s", out);
        assert_null(strstr(out, "(reference "));
        const char *headline = line_with(out, "psi_max ");
        assert_true(headline == strstr(out, "bingham_cavity: no reference data for these") ||
                    strstr(headline, "(no reference value)") != NULL);
        snprintf(note, sizeof note, "Bn %s outside the data's 0.1 to 982.103 (Vola's convention; "
                                    "not extrapolated)", outside[m].bn);
        const char *why = line_with(out, "bingham_cavity: no psi_max reference: ");
        assert_non_null(strstr(why, note));
        char *summary = read_in(dir, "summary.ini");
        cut_result(summary);
        assert_non_null(strstr(summary, "\npsi_max_reference = nan\n"));
        char want[300];
        snprintf(want, sizeof want, "\npsi_max_reference_note = %s\n", note);
        assert_non_null(strstr(summary, want));
        if (outside[m].midline) {
            assert_non_null(strstr(why, outside[m].midline));
            snprintf(want, sizeof want, "\nmidline_reference_note = %s\n", outside[m].midline);
            assert_non_null(strstr(summary, want));
        } else {
            assert_null(strstr(summary, "midline_reference_note"));
        }
        free(summary);
        free(out);
        remove_dir(dir);
    }
}

/* A scene with an exact solution keeps its names: err_rms, err_rms_paper,
 * u_surface (exact ...), u_surface_exact, u_exact. */
static void test_exact_scene_names(void **state)
{
    (void)state;
    char dir[64];
    char *out = run_muflow("../cases/bagnold.ini domain.nz=10", dir, sizeof dir);
    const char *line = line_with(out, "u_surface");
    assert_int_equal(strncmp(line, "bagnold: err_rms ", 17), 0);
    assert_non_null(strstr(line, "err_rms_paper "));
    assert_non_null(strstr(line, "(exact 1.59"));
    free(out);
    char *summary = read_in(dir, "summary.ini");
    cut_result(summary);
    assert_non_null(strstr(summary, "\nerr_rms = "));
    assert_non_null(strstr(summary, "\nerr_rms_paper = "));
    assert_non_null(strstr(summary, "\nu_surface_exact = 1.59"));
    assert_null(strstr(summary, "reference"));
    free(summary);
    char *csv = read_in(dir, "profile.csv");
    assert_int_equal(strncmp(csv, "z,u,pressure,shear_rate,inertial_number,viscosity,u_exact\n",
                             58), 0);
    free(csv);
    remove_dir(dir);
}

void group_outputs(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cavity_reference_names),
        cmocka_unit_test(test_cavity_no_reference_profile),
        cmocka_unit_test(test_cavity_outside_data),
        cmocka_unit_test(test_exact_scene_names),
    };
    RUN_GROUP(t, "outputs", tests);
}
