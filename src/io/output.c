/* CSV and INI output of a run (output.h). */
#define _POSIX_C_SOURCE 200809L /* getline */
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
#include "scenes/scene.h"
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

/* Opens dir/name.tmp for writing; fills the final and temporary paths. */
static FILE *open_tmp(const char *dir, const char *name, char *path, size_t plen, char *tmp,
                      size_t tlen, char *err, size_t errlen)
{
    if (snprintf(path, plen, "%s/%s", dir, name) >= (int)plen ||
        snprintf(tmp, tlen, "%s/%s.tmp", dir, name) >= (int)tlen) {
        snprintf(err, errlen, "output path too long in %s", dir);
        return NULL;
    }
    FILE *f = fopen(tmp, "w");
    if (!f)
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno));
    return f;
}

/* Closes f and renames tmp to path; on any failure removes tmp. */
static int close_rename(FILE *f, const char *tmp, const char *path, char *err, size_t errlen)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno ? errno : EIO));
        remove(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

int history_open(struct history *h, const char *dir, const char *error_name, char *err,
                 size_t errlen)
{
    h->f = open_tmp(dir, "history.csv", h->path, sizeof h->path, h->tmp, sizeof h->tmp, err,
                    errlen);
    if (!h->f)
        return -1;
    fprintf(h->f, "step,time,wall_seconds,dt,residual,residual_beyond_roundoff,divergence,"
                  "linear_iterations,rejected_steps,%s\n",
            error_name);
    return 0;
}

int history_resume(struct history *h, const char *dir, const char *error_name, long upto,
                   char *err, size_t errlen)
{
    char path[600], tmp[620];
    snprintf(path, sizeof path, "%s/history.csv", dir);
    snprintf(tmp, sizeof tmp, "%s/history.csv.tmp", dir);
    FILE *src = fopen(tmp, "r");
    if (src)
        remove(tmp); /* still read through src; history_open makes a new one */
    else
        src = fopen(path, "r");
    if (history_open(h, dir, error_name, err, errlen) != 0) {
        if (src)
            fclose(src);
        return -1;
    }
    if (!src)
        return 0; /* nothing to continue: the rows before upto are lost */
    char *line = NULL;
    size_t cap = 0;
    int first = 1;
    while (getline(&line, &cap, src) > 0) {
        if (first) { /* the header, already written */
            first = 0;
            continue;
        }
        char *end;
        long step = strtol(line, &end, 10);
        if (end != line && *end == ',' && step <= upto)
            fputs(line, h->f);
    }
    free(line);
    fclose(src);
    return 0;
}

void history_flush(struct history *h)
{
    if (h->f)
        fflush(h->f);
}

void history_row(struct history *h, const struct march_state *st, const struct scene_errors *e)
{
    if (!h->f)
        return;
    fprintf(h->f, "%ld,%.10g,%.6g,%.6g,%.6e,%.6e,%.6e,%d,%ld,%.6e\n", st->step, st->time,
            st->wall_seconds, st->dt, st->residual, st->residual_excess, st->divergence,
            st->linear_iterations, st->rejected, e->err_rms);
}

int history_close(struct history *h, char *err, size_t errlen)
{
    if (!h->f)
        return 0;
    int rc = close_rename(h->f, h->tmp, h->path, err, errlen);
    h->f = NULL;
    return rc;
}

int output_profile(const char *dir, const struct profile *pr, char *err, size_t errlen)
{
    char path[600], tmp[620];
    FILE *f = open_tmp(dir, "profile.csv", path, sizeof path, tmp, sizeof tmp, err, errlen);
    if (!f)
        return -1;
    const char *ax = pr->axis == 0 ? "x" : pr->axis == 1 ? "y" : "z";
    const char *vc = pr->component == 0 ? "u" : pr->component == 1 ? "v" : "w";
    fprintf(f, "%s,%s,pressure,shear_rate,inertial_number,viscosity,%s_%s\n", ax, vc, vc,
            pr->exact_name ? pr->exact_name : "exact");
    for (int l = 0; l < pr->n; l++)
        fprintf(f, "%.10g,%.12g,%.10g,%.10g,%.10g,%.10g,%.12g\n", pr->coord[l], pr->velocity[l],
                pr->pressure[l], pr->shear_rate[l], pr->inertial[l], pr->viscosity[l],
                pr->exact[l]);
    return close_rename(f, tmp, path, err, errlen);
}

int output_open(struct output_file *o, const char *dir, const char *name, char *err,
                size_t errlen)
{
    o->f = open_tmp(dir, name, o->path, sizeof o->path, o->tmp, sizeof o->tmp, err, errlen);
    return o->f ? 0 : -1;
}

int output_commit(struct output_file *o, char *err, size_t errlen)
{
    int rc = close_rename(o->f, o->tmp, o->path, err, errlen);
    o->f = NULL;
    return rc;
}

void run_result_add(struct run_result *r, const char *key, const char *fmt, ...)
{
    if (r->nvalues >= RESULT_VALUES_MAX)
        return;
    struct result_value *v = &r->values[r->nvalues++];
    snprintf(v->key, sizeof v->key, "%s", key);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->text, sizeof v->text, fmt, ap);
    va_end(ap);
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
    NUMBER_LINE("time", "%.10g", r->time);
    NUMBER_LINE("wall_seconds", "%.6g", r->wall_seconds);
    NUMBER_LINE("residual", "%.6e", r->residual);
    NUMBER_LINE("divergence", "%.6e", r->divergence);
    const struct scene *sc = r->scene;
    if (sc && sc->headline_name) {
        /* err_midline and psi_max_reference for the cavity: its comparison
         * is a published curve, not an exact solution, and it has no
         * per-layer err_rms_paper */
        NUMBER_LINE(scene_error_name(sc), "%.6e", r->errors.err_rms);
        NUMBER_LINE("err_max", "%.6e", r->errors.err_max);
        if (!sc->no_err_rms_paper)
            NUMBER_LINE("err_rms_paper", "%.6e", r->errors.err_rms_paper);
        NUMBER_LINE(sc->headline_name, "%.10g", r->errors.headline);
        snprintf(key, sizeof key, "%s_%s", sc->headline_name, scene_solution_name(sc));
        NUMBER_LINE(key, "%.10g", r->errors.headline_exact);
    }
    for (int i = 0; i < r->nvalues; i++) {
        char *end;
        double v = strtod(r->values[i].text, &end);
        line(ctx, r->values[i].key, r->values[i].text, end != r->values[i].text ? v : NAN);
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
    char path[600], tmp[620];
    FILE *f = open_tmp(dir, "summary.ini", path, sizeof path, tmp, sizeof tmp, err, errlen);
    if (!f)
        return -1;
    fprintf(f, "; muflow run summary: the result, then every case key as used\n[result]\n");
    run_result_lines(r, print_line, f);
    fprintf(f, "\n");
    case_write_ini(cs, f);
    return close_rename(f, tmp, path, err, errlen);
}
