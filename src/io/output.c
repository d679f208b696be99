/* CSV and INI output of a run (output.h). */
#define _POSIX_C_SOURCE 200809L /* lstat */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <stdarg.h>
#include <unistd.h>
#include "io/checkpoint.h"
#include "io/output.h"

int output_make_dir(const char *dir, char *err, size_t errlen)
{
    char path[600];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path) {
        snprintf(err, errlen, "output.dir = %.100s...: longer than %zu characters", dir,
                 sizeof path - 1);
        return -1;
    }
    for (char *s = path + 1;; s++) {
        int end = *s == '\0';
        if (*s == '/' || end) {
            char keep = *s;
            *s = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST) {
                if (end)
                    snprintf(err, errlen, "output.dir = %s: cannot create the folder: %s", dir,
                             strerror(errno));
                else
                    snprintf(err, errlen, "output.dir = %s: cannot create the folder %s: %s", dir,
                             path, strerror(errno));
                return -1;
            }
            *s = keep;
        }
        if (end)
            break;
    }
    struct stat sb;
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        snprintf(err, errlen, "output.dir = %s: not a folder (a file of that name exists)", dir);
        return -1;
    }
    return 0;
}

/* A name a run writes (output.h), or its temporary name (name.tmp). */
static int is_run_file(const char *name, const char *const *extra)
{
    static const char *const fixed[] = {"fields.xdmf", "history.csv", "profile.csv",
                                        "summary.ini", CHECKPOINT_NAME};
    size_t n = strlen(name);
    if (n > 4 && strcmp(name + n - 4, ".tmp") == 0)
        n -= 4;
    for (size_t f = 0; f < sizeof fixed / sizeof fixed[0]; f++)
        if (strlen(fixed[f]) == n && strncmp(name, fixed[f], n) == 0)
            return 1;
    for (const char *const *x = extra; x && *x; x++)
        if (strlen(*x) == n && strncmp(name, *x, n) == 0)
            return 1;
    /* fields_<step>.h5: six digits or more (fields_h5_name) */
    if (n < sizeof "fields_000000.h5" - 1 || strncmp(name, "fields_", 7) != 0 ||
        strncmp(name + n - 3, ".h5", 3) != 0)
        return 0;
    for (size_t i = 7; i < n - 3; i++)
        if (name[i] < '0' || name[i] > '9')
            return 0;
    return 1;
}

int output_remove_run_files(const char *dir, const char *const *extra, char *err, size_t errlen)
{
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT)
            return 0;
        snprintf(err, errlen, "output.dir = %s: cannot read the folder: %s", dir, strerror(errno));
        return -1;
    }
    int removed = 0;
    struct dirent *e;
    char path[800];
    while ((e = readdir(d))) {
        if (!is_run_file(e->d_name, extra))
            continue;
        struct stat sb;
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path ||
            lstat(path, &sb) != 0 || S_ISDIR(sb.st_mode))
            continue; /* a folder of that name is not the run's */
        if (unlink(path) != 0 && errno != ENOENT) {
            snprintf(err, errlen, "cannot remove %s of an earlier run: %s", path,
                     strerror(errno));
            closedir(d);
            return -1;
        }
        removed++;
    }
    closedir(d);
    return removed;
}

int history_open(struct history *h, const char *dir, const char *error_name, char *err,
                 size_t errlen)
{
    if (output_open(&h->file, dir, "history.csv", err, errlen) != 0)
        return -1;
    fprintf(h->file.f, "step,time,wall_seconds,dt,residual,residual_beyond_roundoff,divergence,"
                  "linear_iterations,rejected_steps,%s\n",
            error_name);
    return 0;
}

/* The rows a continued run keeps: those up to its checkpoint's step. */
static int up_to(long step, void *upto)
{
    return step <= *(const long *)upto;
}

int history_resume(struct history *h, const char *dir, const char *error_name, long upto,
                   char *err, size_t errlen)
{
    FILE *src = output_previous(dir, "history.csv");
    if (history_open(h, dir, error_name, err, errlen) != 0) {
        if (src)
            fclose(src);
        return -1;
    }
    if (!src)
        return 0; /* nothing to continue: the rows before upto are lost */
    output_copy_rows(src, h->file.f, up_to, &upto);
    fclose(src);
    return 0;
}

void history_flush(struct history *h)
{
    if (h->file.f)
        fflush(h->file.f);
}

void history_row(struct history *h, const struct march_state *st, const struct scene_errors *e)
{
    if (!h->file.f)
        return;
    fprintf(h->file.f, "%ld,%.10g,%.6g,%.6g,%.6e,%.6e,%.6e,%d,%ld,%.6e\n", st->step, st->time,
            st->wall_seconds, st->dt, st->residual, st->residual_excess, st->divergence,
            st->linear_iterations, st->rejected, e->err_rms);
}

int history_close(struct history *h, char *err, size_t errlen)
{
    if (!h->file.f)
        return 0;
    return output_commit(&h->file, err, errlen);
}

void run_result_add(struct run_result *r, const char *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    result_values_vadd(&r->values, key, fmt, ap);
    va_end(ap);
}

void run_result_add_compared(struct run_result *r, const char *name, double value,
                             double reference)
{
    char key[96];
    run_result_add(r, name, "%.10g", value);
    snprintf(key, sizeof key, "%s_exact", name);
    run_result_add(r, key, "%.10g", reference);
    snprintf(key, sizeof key, "%s_error", name);
    run_result_add(r, key, "%.6e", value / reference - 1.0);
}

/* A number's line: its text as the summary writes it, its value exact. */
#define NUMBER_LINE(key, fmt, v)                                                   \
    do {                                                                           \
        snprintf(text, sizeof text, fmt, v);                                       \
        line(ctx, key, text, (double)(v));                                         \
    } while (0)

void run_result_lines(const struct run_result *r, result_line_fn line, void *ctx)
{
    char text[64], key[96];
    line(ctx, "status", run_status_name(r->status), NAN);
    line(ctx, "message", r->message, NAN);
    NUMBER_LINE("steps", "%ld", r->steps);
    NUMBER_LINE("rejected_steps", "%ld", r->rejected_steps);
    NUMBER_LINE("pressure_iterations", "%ld", r->pressure_iterations);
    NUMBER_LINE("pressure_unconverged", "%ld", r->pressure_unconverged);
    NUMBER_LINE("linear_unconverged", "%ld", r->linear_unconverged);
    NUMBER_LINE("preconditioner_fallbacks", "%ld", r->preconditioner_fallbacks);
    NUMBER_LINE("grid_matrices", "%ld", r->grid_matrices);
    NUMBER_LINE("pressure_matrices", "%ld", r->pressure_matrices);
    NUMBER_LINE("time", "%.10g", r->time);
    NUMBER_LINE("wall_seconds", "%.6g", r->wall_seconds);
    NUMBER_LINE("residual", "%.6e", r->residual);
    NUMBER_LINE("divergence", "%.6e", r->divergence);
    const struct result_names *nm = &r->names;
    if (nm->headline) {
        /* err_midline and psi_max_reference for the cavity: its comparison
         * is a published curve, not an exact solution, and it has no
         * per-layer err_rms_paper */
        NUMBER_LINE(nm->error, "%.6e", r->errors.err_rms);
        NUMBER_LINE("err_max", "%.6e", r->errors.err_max);
        if (!nm->no_err_rms_paper)
            NUMBER_LINE("err_rms_paper", "%.6e", r->errors.err_rms_paper);
        NUMBER_LINE(nm->headline, "%.10g", r->errors.headline);
        snprintf(key, sizeof key, "%s_%s", nm->headline, nm->solution);
        NUMBER_LINE(key, "%.10g", r->errors.headline_exact);
    }
    for (int i = 0; i < r->values.n; i++) {
        const struct result_value *rv = &r->values.v[i];
        char *end;
        double v = strtod(rv->text, &end);
        line(ctx, rv->key, rv->text, end != rv->text ? v : NAN);
    }
}

struct value_search {
    const char *key;
    double value;
    int found;
};

static void take_value(void *vctx, const char *key, const char *text, double value)
{
    (void)text;
    struct value_search *s = vctx;
    if (!s->found && strcmp(key, s->key) == 0) {
        s->value = value;
        s->found = 1;
    }
}

double run_result_value(const struct run_result *r, const char *key)
{
    struct value_search s = {key, NAN, 0};
    run_result_lines(r, take_value, &s);
    return s.value;
}

static void print_line(void *vctx, const char *key, const char *text, double value)
{
    (void)value;
    fprintf(vctx, "%s = %s\n", key, text);
}

int output_summary(const char *dir, const struct muflow_case *cs, const struct run_result *r,
                   char *err, size_t errlen)
{
    struct output_file o;
    if (output_open(&o, dir, "summary.ini", err, errlen) != 0)
        return -1;
    FILE *f = o.f;
    fprintf(f, "; muflow run summary: the result, then every case key as used\n[result]\n");
    run_result_lines(r, print_line, f);
    fprintf(f, "\n");
    case_write_ini(cs, f);
    return output_commit(&o, err, errlen);
}
