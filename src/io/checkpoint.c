/* Checkpoint files (checkpoint.h). */
#include "io/checkpoint.h"

#include <errno.h>
#include <fftw3.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/fields_h5.h"
#include "io/h5blocks.h"
#include "io/h5io.h"
#include "march/module_record.h"
#include "march/module.h"
#include "platform/comm.h"
#include "platform/fft_ranks.h"

/* The loop state of march_state a restart must recover (march.h). */
enum stype { S_DOUBLE, S_LONG, S_INT };
static const struct {
    const char *name;
    size_t off;
    enum stype type;
    int optional; /* added later: a checkpoint without it keeps march_create's value */
    int count;    /* values (0: one) */
} loop_state[] = {
    {"step", offsetof(struct march_state, step), S_LONG, 0, 0},
    {"time", offsetof(struct march_state, time), S_DOUBLE, 0, 0},
    {"dt", offsetof(struct march_state, dt), S_DOUBLE, 0, 0},
    {"residual0", offsetof(struct march_state, residual0), S_DOUBLE, 0, 0},
    {"force_ref", offsetof(struct march_state, force_ref), S_DOUBLE, 0, 0},
    {"best_residual", offsetof(struct march_state, best_residual), S_DOUBLE, 0, 0},
    {"best_step", offsetof(struct march_state, best_step), S_LONG, 0, 0},
    {"best_time", offsetof(struct march_state, best_time), S_DOUBLE, 0, 0},
    {"mark_time", offsetof(struct march_state, mark_time), S_DOUBLE, 0, 0},
    {"mark_acc0", offsetof(struct march_state, mark_acc[0]), S_DOUBLE, 0, 0},
    {"mark_acc1", offsetof(struct march_state, mark_acc[1]), S_DOUBLE, 0, 0},
    {"mark_acc2", offsetof(struct march_state, mark_acc[2]), S_DOUBLE, 0, 0},
    {"marks", offsetof(struct march_state, marks), S_LONG, 0, 0},
    {"dt_scale", offsetof(struct march_state, dt_scale), S_DOUBLE, 0, 0},
    {"lambda", offsetof(struct march_state, rheo.lambda), S_DOUBLE, 1, 0},
    {"stage_residual0", offsetof(struct march_state, stage_residual0), S_DOUBLE, 1, 0},
    {"picard_stalled", offsetof(struct march_state, picard_stalled), S_INT, 1, 0},
    {"rejected", offsetof(struct march_state, rejected), S_LONG, 0, 0},
    {"wall_seconds", offsetof(struct march_state, wall_seconds), S_DOUBLE, 0, 0},
    {"linear_iterations", offsetof(struct march_state, linear_iterations), S_INT, 0, 0},
    {"forcing", offsetof(struct march_state, forcing), S_DOUBLE, 1, 0},
    {"forcing_rms", offsetof(struct march_state, forcing_rms), S_DOUBLE, 1, 0},
    {"forcing_step", offsetof(struct march_state, forcing_step), S_LONG, 1, 0},
    {"pressure_iterations", offsetof(struct march_state, pressure_iterations), S_LONG, 1, 0},
    {"pressure_unconverged", offsetof(struct march_state, pressure_unconverged), S_LONG, 1, 0},
    {"linear_unconverged", offsetof(struct march_state, linear_unconverged), S_LONG, 1, 0},
    {"grid_matrices", offsetof(struct march_state, grid_matrices), S_LONG, 1, 0},
    {"recent_residual", offsetof(struct march_state, recent_residual), S_DOUBLE, 1, MARCH_RECENT},
    {"peak_residual", offsetof(struct march_state, peak_residual), S_DOUBLE, 1, 0},
    {"sane_velocity", offsetof(struct march_state, sane_velocity), S_DOUBLE, 1, 0},
    {"bdf2_steps", offsetof(struct march_state, bdf2_steps), S_LONG, 1, 0},
};
#define NSTATE ((int)(sizeof loop_state / sizeof loop_state[0]))

static int state_count(int m) { return loop_state[m].count > 0 ? loop_state[m].count : 1; }

static hid_t native(enum stype t)
{
    return t == S_DOUBLE ? H5T_NATIVE_DOUBLE : t == S_LONG ? H5T_NATIVE_LONG : H5T_NATIVE_INT;
}

void checkpoint_dataset_name(const struct field_spec *spec, int c, char *name, size_t len)
{
    static const char axis[3] = {'x', 'y', 'z'};
    if (field_arrays(spec->where) == 1)
        snprintf(name, len, "%s", spec->name);
    else
        snprintf(name, len, "%s_%c", spec->name, axis[c]);
}

/* The checkpointed fields of the registry (march/fields.h), dataset by
 * dataset, named by checkpoint_dataset_name, each in the layout with every
 * ghost (field_to_full: the files of a compact grid are a full grid's).
 * read: 0 to write them (through w on ranks: each its block), 1 to read
 * them back (on ranks each its block with its ghosts, as written: the
 * neighbours' slots and the images of the domain's ends). */
static int each_dataset(hid_t file, struct h5blocks *w, const struct march_state *st, int read,
                        double *given, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    const struct decomp *dc = st->ranks ? &st->ranks->dc : NULL;
    hsize_t dims[3];
    for (int d = 0; d < 3; d++)
        dims[d] = (hsize_t)g->n[d] + 2;
    double *full = given; /* a buffer of g->padded doubles, or NULL */
    if (!full && (dc || g->size != g->padded) && !(full = malloc(g->padded * sizeof *full))) {
        snprintf(err, errlen, "checkpoint: out of memory for a field");
        return -1;
    }
    const struct field_registry *r = &st->fields;
    int rc = 0;
    for (int i = 0; rc == 0 && i < r->count; i++) {
        const struct field_entry *e = &r->e[i];
        if (!(e->spec.flags & FIELD_CHECKPOINT))
            continue;
        int n = field_arrays(e->spec.where);
        for (int c = 0; rc == 0 && c < n; c++) {
            char name[96];
            checkpoint_dataset_name(&e->spec, c, name, sizeof name);
            /* a field added since the checkpoint was written keeps its start */
            if (read && (e->spec.flags & FIELD_START_OPTIONAL) &&
                H5Lexists(file, name, H5P_DEFAULT) <= 0)
                continue;
            if (dc) {
                rc = read ? h5blocks_read_full_in(file, name, dc, g, e->v[c], full, err, errlen)
                          : h5blocks_put_full(w, name, dc, g, e->v[c], full, err, errlen);
                continue;
            }
            double *buf = full ? full : e->v[c];
            if (!read && full)
                field_to_full(g, e->v[c], full);
            rc = read ? h5io_read(file, name, H5T_NATIVE_DOUBLE, 3, dims, buf, err, errlen)
                      : h5io_write(file, name, H5T_NATIVE_DOUBLE, 3, dims, buf, err, errlen);
            if (rc == 0 && read && full)
                field_from_full(g, full, e->v[c]);
        }
    }
    if (full != given)
        free(full);
    return rc;
}

/* ---- what the modules keep between steps (march/module_record.h) ---- */

/* A record's arrays as the datasets of its module's group (ctx: the hid_t) */
static int record_put(void *ctx, const char *name, const double *v, long n, char *err,
                      size_t errlen)
{
    hsize_t dim = (hsize_t)(n > 0 ? n : 0);
    return h5io_write(*(hid_t *)ctx, name, H5T_NATIVE_DOUBLE, 1, &dim, v, err, errlen);
}

static long record_count(void *ctx, const char *name, char *err, size_t errlen)
{
    hid_t group = *(hid_t *)ctx;
    hsize_t dim;
    if (H5Lexists(group, name, H5P_DEFAULT) <= 0) {
        snprintf(err, errlen, "no dataset %s", name);
        return -1;
    }
    return h5io_dims(group, name, 1, &dim, err, errlen) == 1 ? (long)dim : -1;
}

static int record_get(void *ctx, const char *name, double *v, long n, char *err, size_t errlen)
{
    hsize_t dim = (hsize_t)(n > 0 ? n : 0);
    return h5io_read(*(hid_t *)ctx, name, H5T_NATIVE_DOUBLE, 1, &dim, v, err, errlen);
}

static const struct module_record_store group_store = {record_put, record_count, record_get};

#define MODULES_GROUP "modules"

/* Group name under loc: created (create 1) or opened; -1 when it cannot be
 * (opening: it is not there). */
static hid_t group_at(hid_t loc, const char *name, int create)
{
    if (create)
        return H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    return H5Lexists(loc, name, H5P_DEFAULT) > 0 ? H5Gopen2(loc, name, H5P_DEFAULT) : -1;
}

/* Each module's save hook, with its group modules/<name>. */
static int modules_save(hid_t file, const struct march_state *st, char *err, size_t errlen)
{
    hid_t top = -1;
    int rc = 0;
    for (int i = 0; rc == 0 && i < st->nmodules; i++) {
        const struct module *m = st->modules[i];
        if (!m->save)
            continue;
        if (top < 0 && (top = group_at(file, MODULES_GROUP, 1)) < 0) {
            h5io_error(err, errlen, "cannot create the group " MODULES_GROUP);
            return -1;
        }
        hid_t group = group_at(top, m->name, 1);
        struct module_record rec = {.store = &group_store, .ctx = &group, .err = ""};
        if (group < 0) {
            h5io_error(err, errlen, "cannot create a module's group");
            rc = -1;
            break;
        }
        if ((rc = m->save(st, st->module_state[i], &rec)) != 0)
            snprintf(err, errlen, "module %s: %s", m->name, rec.err[0] ? rec.err : "failed");
        H5Gclose(group);
    }
    if (top >= 0)
        H5Gclose(top);
    return rc;
}

/* Each module's load hook, with the group its save filled. */
static int modules_load(hid_t file, struct march_state *st, char *err, size_t errlen)
{
    hid_t top = -1;
    int rc = 0;
    for (int i = 0; rc == 0 && i < st->nmodules; i++) {
        const struct module *m = st->modules[i];
        if (!m->load)
            continue;
        hid_t group = -1;
        struct module_record rec = {.store = &group_store, .ctx = &group, .err = ""};
        if (top < 0)
            top = group_at(file, MODULES_GROUP, 0);
        if (top >= 0)
            group = group_at(top, m->name, 0);
        /* a checkpoint of an earlier muflow holds none: the module goes on
         * without (load with NULL) or refuses */
        if (group < 0) {
            if ((rc = m->load(st, st->module_state[i], NULL)) != 0)
                snprintf(err, errlen, "it holds no state of the physics module %s (written by "
                                      "an earlier muflow, which could not continue this case)",
                         m->name);
            continue;
        }
        if ((rc = m->load(st, st->module_state[i], &rec)) != 0)
            snprintf(err, errlen, "module %s: %s", m->name, rec.err[0] ? rec.err : "failed");
        H5Gclose(group);
    }
    if (top >= 0)
        H5Gclose(top);
    return rc;
}

static int write_wisdom(hid_t file, char *err, size_t errlen)
{
    /* the wisdom's header names the threaded planner: a run that made no
     * FFT plan (a stretched grid's) must still export it threaded, or the
     * restart's import (after fftw_init_threads) rejects it */
    if (!fftw_init_threads()) {
        snprintf(err, errlen, "fftw_init_threads failed");
        return -1;
    }
    char *w = fftw_export_wisdom_to_string();
    if (!w) {
        snprintf(err, errlen, "cannot export FFTW wisdom");
        return -1;
    }
    hsize_t n = strlen(w);
    int rc = h5io_write(file, "fftw_wisdom", H5T_NATIVE_CHAR, 1, &n, w, err, errlen);
    free(w);
    return rc;
}

/* What one process writes: the case, the loop state (rank 0's on ranks:
 * every rank holds the same), the modules' records, the field files'
 * schedule and FFTW's wisdom; arrays: 1 to write the arrays too (one
 * process), 0 when the ranks wrote them. */
static int write_contents(hid_t file, const struct march_state *st, const struct field_series *fs,
                          int arrays, char *err, size_t errlen)
{
    int threads = omp_get_max_threads(), ranks = st->ranks ? st->ranks->cart.size : 1;
    if (h5io_attr_write_text(file, "format", CHECKPOINT_FORMAT, err, errlen) != 0 ||
        fields_h5_case_attributes(file, st->cs, march_global_grid(st), err, errlen) != 0 ||
        h5io_attr_write(file, "omp_threads", H5T_NATIVE_INT, 1, &threads, err, errlen) != 0 ||
        h5io_attr_write(file, "mpi_ranks", H5T_NATIVE_INT, 1, &ranks, err, errlen) != 0)
        return -1;
    for (int m = 0; m < NSTATE; m++)
        if (h5io_attr_write(file, loop_state[m].name, native(loop_state[m].type),
                            state_count(m), (const char *)st + loop_state[m].off, err,
                            errlen) != 0)
            return -1;
    if ((arrays && each_dataset(file, NULL, st, 0, NULL, err, errlen) != 0) ||
        modules_save(file, st, err, errlen) != 0)
        return -1;
    hsize_t n = (hsize_t)fs->count;
    if (h5io_attr_write(file, "fields_count", H5T_NATIVE_INT, 1, &fs->count, err, errlen) != 0 ||
        h5io_attr_write(file, "fields_next_time", H5T_NATIVE_DOUBLE, 1, &fs->next_time, err,
                        errlen) != 0 ||
        (n > 0 && (h5io_write(file, "fields_steps", H5T_NATIVE_LONG, 1, &n, fs->steps, err,
                              errlen) != 0 ||
                   h5io_write(file, "fields_times", H5T_NATIVE_DOUBLE, 1, &n, fs->times, err,
                              errlen) != 0)))
        return -1;
    return write_wisdom(file, err, errlen);
}

struct checkpoint_ctx {
    const struct march_state *st;
    const struct field_series *fs;
    int arrays;
};

static int checkpoint_contents(hid_t file, void *vctx, char *err, size_t errlen)
{
    const struct checkpoint_ctx *ctx = vctx;
    return write_contents(file, ctx->st, ctx->fs, ctx->arrays, err, errlen);
}

/* A decomposed run's checkpoint: every rank its block of each array (with
 * the ghosts at the domain's ends) into one file, then rank 0 the rest
 * (h5blocks.h); every rank returns the same status. */
static int write_on_ranks(const char *path, const struct march_state *st,
                          const struct field_series *fs, char *err, size_t errlen)
{
    double *buf = malloc(st->g.padded * sizeof *buf);
    if (march_max(st, !buf) != 0.0) { /* before the ranks' first collective call */
        snprintf(err, errlen, "cannot write checkpoint %s: out of memory", path);
        free(buf);
        return -1;
    }
    struct h5blocks w;
    struct checkpoint_ctx ctx = {st, fs, 0};
    int rc = h5blocks_create(&w, &st->ranks->cart, path, err, errlen);
    if (rc == 0 && (rc = each_dataset(-1, &w, st, 0, buf, err, errlen)) == 0)
        rc = h5blocks_finish(&w, "checkpoint", checkpoint_contents, &ctx, err, errlen);
    free(buf);
    return rc;
}

int checkpoint_write(const char *dir, const struct march_state *st,
                     const struct field_series *fs, char *err, size_t errlen)
{
    char path[700], tmp[720];
    if (snprintf(path, sizeof path, "%s/%s", dir, CHECKPOINT_NAME) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        snprintf(err, errlen, "checkpoint path too long in %s", dir);
        return -1;
    }
    if (st->ranks)
        return write_on_ranks(path, st, fs, err, errlen);
    struct checkpoint_ctx ctx = {st, fs, 1};
    return h5io_write_file(tmp, path, "checkpoint", checkpoint_contents, &ctx, err, errlen);
}

/* Opens a checkpoint for reading and checks its format. */
static hid_t open_checkpoint(const char *path, char *err, size_t errlen)
{
    h5io_init();
    FILE *probe = fopen(path, "rb"); /* the system's reason, not HDF5's paraphrase */
    if (!probe) {
        snprintf(err, errlen, "cannot open checkpoint %s: %s", path, strerror(errno));
        return -1;
    }
    fclose(probe);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    char cause[600], format[64];
    if (file < 0) {
        h5io_error(cause, sizeof cause, "not an HDF5 file");
        snprintf(err, errlen, "cannot open checkpoint %s: %s", path, cause);
        return -1;
    }
    if (h5io_attr_read_text(file, "format", format, sizeof format, cause, sizeof cause) != 0 ||
        strcmp(format, CHECKPOINT_FORMAT) != 0) {
        snprintf(err, errlen, "checkpoint %s: not a muflow checkpoint (format attribute: %s)",
                 path, format[0] && strcmp(format, CHECKPOINT_FORMAT) ? format : cause);
        H5Fclose(file);
        return -1;
    }
    return file;
}

/* The stored keys as "section.key=value" strings. */
struct stored {
    char **items;
    int count, cap;
};

static int collect_key(void *vctx, const char *name, const char *text)
{
    struct stored *s = vctx;
    if (!strchr(name, '.'))
        return 0; /* not a case key (format, case_name) */
    if (!text[0])
        return 0; /* an empty text key at its default: "key=" would be refused */
    if (s->count == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        char **items = realloc(s->items, (size_t)cap * sizeof *items);
        if (!items)
            return 1;
        s->items = items;
        s->cap = cap;
    }
    size_t len = strlen(name) + strlen(text) + 2;
    char *item = malloc(len);
    if (!item)
        return 1; /* out of memory */
    snprintf(item, len, "%s=%s", name, text);
    s->items[s->count++] = item;
    return 0;
}

int checkpoint_load_case(const char *path, int noverrides, char *const overrides[],
                         struct muflow_case *cs, char *err, size_t errlen)
{
    hid_t file = open_checkpoint(path, err, errlen);
    if (file < 0)
        return 2;
    struct stored s = {NULL, 0, 0};
    char cause[600], name[sizeof cs->name];
    int rc = h5io_attr_each_text(file, collect_key, &s, cause, sizeof cause);
    if (rc == 1)
        snprintf(cause, sizeof cause, "out of memory");
    if (rc == 0)
        rc = h5io_attr_read_text(file, "case_name", name, sizeof name, cause, sizeof cause);
    H5Fclose(file);
    if (rc != 0) {
        snprintf(err, errlen, "checkpoint %s: %s", path, cause);
        rc = 2;
        goto done;
    }
    /* the stored case alone first, so a bad stored key is blamed on the file */
    if (case_load(cs, NULL, s.count, s.items, cause, sizeof cause) != 0) {
        snprintf(err, errlen, "checkpoint %s: stored case: %s", path, cause);
        rc = 2;
        goto done;
    }
    char **all = malloc((size_t)(s.count + noverrides + 1) * sizeof *all);
    if (!all) {
        snprintf(err, errlen, "checkpoint %s: out of memory", path);
        rc = 2;
        goto done;
    }
    memcpy(all, s.items, (size_t)s.count * sizeof *all);
    for (int i = 0; i < noverrides; i++)
        all[s.count + i] = overrides[i];
    rc = case_load(cs, NULL, s.count + noverrides, all, err, errlen);
    free(all);
    if (rc == 0)
        snprintf(cs->name, sizeof cs->name, "%s", name);
done:
    for (int i = 0; i < s.count; i++)
        free(s.items[i]);
    free(s.items);
    return rc;
}

/* The wisdom of a run on ranks names FFTW's MPI solvers (fftw_mpi_...) and
 * its header the planner's set of solvers with them: FFTW takes it only once
 * its MPI part is initialised, done first under mpirun.  One process (no
 * mpirun) cannot take it at all, nor needs it: its plans are FFTW_ESTIMATE's
 * (poisson_fft.c), and a continuation on another rank count is not bit for
 * bit anyway (the sums' order); it plans afresh. */
static int import_wisdom(const char *w, char *cause, size_t causelen)
{
    if (strstr(w, "(fftw_mpi_")) {
        if (!comm_launched())
            return 0;
        if (fft_ranks_open(cause, causelen) != 0)
            return -1;
    }
    if (!fftw_import_wisdom_from_string(w)) {
        snprintf(cause, causelen, "FFTW rejects the stored wisdom");
        return -1;
    }
    return 0;
}

int checkpoint_import_wisdom(const char *path, char *err, size_t errlen)
{
    hid_t file = open_checkpoint(path, err, errlen);
    if (file < 0)
        return -1;
    char cause[600];
    hsize_t n;
    int rc = h5io_dims(file, "fftw_wisdom", 1, &n, cause, sizeof cause) == 1 ? 0 : -1;
    char *w = rc == 0 ? malloc(n + 1) : NULL;
    if (rc == 0 && !w) {
        snprintf(cause, sizeof cause, "out of memory");
        rc = -1;
    }
    if (rc == 0)
        rc = h5io_read(file, "fftw_wisdom", H5T_NATIVE_CHAR, 1, &n, w, cause, sizeof cause);
    H5Fclose(file);
    if (rc == 0) {
        w[n] = '\0';
        /* the wisdom names the threaded solvers, known to FFTW only once its
         * threads are initialised (idempotent; poisson_fft does it too) */
        if (!fftw_init_threads()) {
            snprintf(cause, sizeof cause, "fftw_init_threads failed");
            rc = -1;
        } else {
            rc = import_wisdom(w, cause, sizeof cause);
        }
    }
    free(w);
    if (rc != 0)
        snprintf(err, errlen, "checkpoint %s: %s", path, cause);
    return rc;
}

static int read_contents(hid_t file, struct march_state *st, struct field_series *fs,
                         int writer[2], char *err, size_t errlen)
{
    const struct grid *g = march_global_grid(st);
    int n[3];
    if (h5io_attr_read(file, "n", H5T_NATIVE_INT, 3, n, err, errlen) != 0)
        return -1;
    if (n[0] != g->n[0] || n[1] != g->n[1] || n[2] != g->n[2]) {
        snprintf(err, errlen, "its grid is %d x %d x %d cells, the case's %d x %d x %d", n[0],
                 n[1], n[2], g->n[0], g->n[1], g->n[2]);
        return -1;
    }
    if (h5io_attr_read(file, "omp_threads", H5T_NATIVE_INT, 1, &writer[0], err, errlen) != 0)
        return -1;
    writer[1] = 1; /* written before decomposed runs wrote checkpoints: one process */
    if (H5Aexists(file, "mpi_ranks") > 0 &&
        h5io_attr_read(file, "mpi_ranks", H5T_NATIVE_INT, 1, &writer[1], err, errlen) != 0)
        return -1;
    for (int m = 0; m < NSTATE; m++)
        if (!(loop_state[m].optional && H5Aexists(file, loop_state[m].name) <= 0) &&
            h5io_attr_read(file, loop_state[m].name, native(loop_state[m].type), state_count(m),
                           (char *)st + loop_state[m].off, err, errlen) != 0)
            return -1;
    if (each_dataset(file, NULL, st, 1, NULL, err, errlen) != 0 ||
        modules_load(file, st, err, errlen) != 0)
        return -1;
    int count;
    double next_time;
    if (h5io_attr_read(file, "fields_count", H5T_NATIVE_INT, 1, &count, err, errlen) != 0 ||
        h5io_attr_read(file, "fields_next_time", H5T_NATIVE_DOUBLE, 1, &next_time, err,
                       errlen) != 0)
        return -1;
    field_series_free(fs);
    fs->next_time = next_time;
    if (count <= 0)
        return 0;
    hsize_t nf = (hsize_t)count;
    long *steps = malloc(nf * sizeof *steps);
    double *times = malloc(nf * sizeof *times);
    int rc = steps && times ? 0 : -1;
    if (rc != 0)
        snprintf(err, errlen, "out of memory");
    if (rc == 0)
        rc = h5io_read(file, "fields_steps", H5T_NATIVE_LONG, 1, &nf, steps, err, errlen);
    if (rc == 0)
        rc = h5io_read(file, "fields_times", H5T_NATIVE_DOUBLE, 1, &nf, times, err, errlen);
    for (int m = 0; rc == 0 && m < count; m++)
        if (field_series_add(fs, steps[m], times[m]) != 0) {
            snprintf(err, errlen, "out of memory");
            rc = -1;
        }
    free(steps);
    free(times);
    return rc;
}

int checkpoint_read_state(const char *path, struct march_state *st, struct field_series *fs,
                          int writer[2], char *err, size_t errlen)
{
    hid_t file = open_checkpoint(path, err, errlen);
    if (file < 0)
        return -1;
    char cause[600];
    int rc = read_contents(file, st, fs, writer, cause, sizeof cause);
    H5Fclose(file);
    if (rc != 0)
        snprintf(err, errlen, "checkpoint %s: %s", path, cause);
    return rc;
}

int checkpoint_read_grid(const char *path, int n[3], double len[3], char *err, size_t errlen)
{
    hid_t file = open_checkpoint(path, err, errlen);
    if (file < 0)
        return -1;
    static const char *const keys[3] = {"domain.lx", "domain.ly", "domain.lz"};
    char cause[600], text[64];
    int rc = h5io_attr_read(file, "n", H5T_NATIVE_INT, 3, n, cause, sizeof cause);
    for (int d = 0; rc == 0 && d < 3; d++) {
        rc = h5io_attr_read_text(file, keys[d], text, sizeof text, cause, sizeof cause);
        char *end = text;
        if (rc == 0)
            len[d] = strtod(text, &end);
        if (rc == 0 && (end == text || !(len[d] > 0.0))) {
            snprintf(cause, sizeof cause, "%s = '%s' is not a length", keys[d], text);
            rc = -1;
        }
    }
    H5Fclose(file);
    if (rc != 0)
        snprintf(err, errlen, "checkpoint %s: %s", path, cause);
    return rc;
}

int checkpoint_read_key(const char *path, const char *key, char *text, size_t len)
{
    char err[600];
    hid_t file = open_checkpoint(path, err, sizeof err);
    if (file < 0)
        return -1;
    /* a checkpoint from before a key was added has no such attribute */
    int rc = H5Aexists(file, key) > 0 &&
                     h5io_attr_read_text(file, key, text, len, err, sizeof err) == 0
                 ? 0
                 : -1;
    H5Fclose(file);
    return rc;
}

int checkpoint_has_dataset(const char *path, const char *name)
{
    char err[600];
    hid_t file = open_checkpoint(path, err, sizeof err);
    if (file < 0)
        return -1;
    int has = H5Lexists(file, name, H5P_DEFAULT) > 0;
    H5Fclose(file);
    return has;
}

int checkpoint_read_dataset(const char *path, const char *name, const int n[3], double *buf,
                            char *err, size_t errlen)
{
    hid_t file = open_checkpoint(path, err, errlen);
    if (file < 0)
        return -1;
    hsize_t dims[3];
    for (int d = 0; d < 3; d++)
        dims[d] = (hsize_t)n[d] + 2;
    char cause[600];
    int rc = h5io_read(file, name, H5T_NATIVE_DOUBLE, 3, dims, buf, cause, sizeof cause);
    H5Fclose(file);
    if (rc != 0)
        snprintf(err, errlen, "checkpoint %s: %s", path, cause);
    return rc;
}
