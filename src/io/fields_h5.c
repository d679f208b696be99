/* HDF5 field files (fields_h5.h). */
#include "io/fields_h5.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/h5blocks.h"
#include "io/h5io.h"
#include "platform/comm.h"

void fields_h5_name(long step, char *buf, size_t len)
{
    snprintf(buf, len, "fields_%06ld.h5", step);
}

struct attr_ctx {
    hid_t loc;
    char *err;
    size_t errlen;
};

static int key_attribute(void *vctx, const char *section, const char *key, const char *value)
{
    struct attr_ctx *a = vctx;
    char name[128];
    snprintf(name, sizeof name, "%s.%s", section, key);
    return h5io_attr_write_text(a->loc, name, value, a->err, a->errlen) != 0 ? -1 : 0;
}

int fields_h5_case_attributes(hid_t loc, const struct muflow_case *cs, const struct grid *g,
                              char *err, size_t errlen)
{
    int n[3] = {g->n[0], g->n[1], g->n[2]};
    if (h5io_attr_write_text(loc, "case_name", cs->name, err, errlen) != 0 ||
        h5io_attr_write(loc, "n", H5T_NATIVE_INT, 3, n, err, errlen) != 0 ||
        h5io_attr_write(loc, "len", H5T_NATIVE_DOUBLE, 3, g->len, err, errlen) != 0 ||
        h5io_attr_write(loc, "h", H5T_NATIVE_DOUBLE, 3, g->h, err, errlen) != 0)
        return -1;
    struct attr_ctx a = {loc, err, errlen};
    return case_visit_keys(cs, key_attribute, &a) != 0 ? -1 : 0;
}

/* Number of distinct faces along d (see fields_h5.h). */
static int faces(const struct march_state *st, int d)
{
    return st->g.n[d] + (st->bc.face[d][0] == BC_PERIODIC ? 0 : 1);
}

/* out (x fastest) = cell field f at every cell, through map (NULL: f itself). */
static void gather_cells(const struct grid *g, const double *f, field_map map, const void *ctx,
                         double *out)
{
    size_t m = 0;
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++, m++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                out[m] = map ? map(ctx, f[p], p) : f[p];
            }
}

/* Face values of component c, x fastest, over the first hi_c faces along c
 * (the distinct faces of the grid, or of a rank's block). */
static void gather_faces(const struct grid *g, double *const vel[3], int c, int hi_c,
                         double *out)
{
    int hi[3] = {g->n[0], g->n[1], g->n[2]};
    hi[c] = hi_c;
    size_t m = 0;
    for (int k = 0; k < hi[2]; k++)
        for (int j = 0; j < hi[1]; j++)
            for (int i = 0; i < hi[0]; i++)
                out[m++] = vel[c][grid_idx(g, i, j, k)];
}

/* Cell-centred velocity: mean of the low and high face of each component; the
 * high face of the last cell along a direction wrap[c] (periodic, held whole)
 * is face 0, elsewhere the slot n (a rank's block: the next rank's face 0). */
static void gather_cell_vector(const struct grid *g, double *const vel[3], const int wrap[3],
                               double *out)
{
    size_t m = 0;
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++)
                for (int c = 0; c < 3; c++) {
                    int lo[3] = {i, j, k}, up[3] = {i, j, k};
                    up[c]++;
                    if (up[c] == g->n[c] && wrap[c])
                        up[c] = 0;
                    out[m++] = 0.5 * (vel[c][grid_idx(g, lo[0], lo[1], lo[2])] +
                                      vel[c][grid_idx(g, up[0], up[1], up[2])]);
                }
}

/* The root attributes of a field file of st, the grid's those of g (the
 * global grid of a rank's block). */
static int root_attributes(hid_t file, const struct march_state *st, const struct grid *g,
                           char *err, size_t errlen)
{
    long step = st->step;
    if (h5io_attr_write_text(file, "format", FIELDS_FORMAT, err, errlen) != 0 ||
        h5io_attr_write(file, "step", H5T_NATIVE_LONG, 1, &step, err, errlen) != 0 ||
        h5io_attr_write(file, "time", H5T_NATIVE_DOUBLE, 1, &st->time, err, errlen) != 0 ||
        h5io_attr_write(file, "dt", H5T_NATIVE_DOUBLE, 1, &st->dt, err, errlen) != 0 ||
        h5io_attr_write_text(file, "status", run_status_name(st->status), err, errlen) != 0 ||
        fields_h5_case_attributes(file, st->cs, g, err, errlen) != 0)
        return -1;
    return 0;
}

static int write_contents(hid_t file, const struct march_state *st, double *buf, char *err,
                          size_t errlen)
{
    const struct grid *g = &st->g;
    if (root_attributes(file, st, g, err, errlen) != 0)
        return -1;
    if (grid_stretched(g)) { /* the faces' coordinates, n + 1 per direction (h is NaN) */
        static const char *const names[3] = {"x_faces", "y_faces", "z_faces"};
        for (int d = 0; d < 3; d++) {
            hsize_t nf = (hsize_t)g->n[d] + 1;
            for (int i = 0; i <= g->n[d]; i++)
                buf[i] = grid_xf(g, d, i);
            if (h5io_write(file, names[d], H5T_NATIVE_DOUBLE, 1, &nf, buf, err, errlen) != 0)
                return -1;
        }
    }
    /* the registry's outputs (march/fields.h): face fields as their face
     * values and the cell-centred vector, cell fields through their maps */
    const struct field_registry *r = &st->fields;
    hsize_t cdims[4] = {(hsize_t)g->n[2], (hsize_t)g->n[1], (hsize_t)g->n[0], 3};
    int wrap[3];
    for (int c = 0; c < 3; c++)
        wrap[c] = st->bc.face[c][0] == BC_PERIODIC;
    for (int o = 0; o < r->noutputs; o++) {
        const struct field_output *out = &r->out[o];
        const struct field_entry *e = &r->e[out->source];
        if (e->spec.where == FIELD_FACES) {
            for (int c = 0; c < 3; c++) {
                hsize_t dims[3] = {(hsize_t)g->n[2], (hsize_t)g->n[1], (hsize_t)g->n[0]};
                dims[2 - c] = (hsize_t)faces(st, c);
                gather_faces(g, e->v, c, faces(st, c), buf);
                if (h5io_write(file, out->components[c], H5T_NATIVE_DOUBLE, 3, dims, buf, err,
                               errlen) != 0)
                    return -1;
            }
            gather_cell_vector(g, e->v, wrap, buf);
            if (h5io_write(file, out->name, H5T_NATIVE_DOUBLE, 4, cdims, buf, err, errlen) != 0)
                return -1;
        } else {
            gather_cells(g, e->v[0], out->map, out->ctx, buf);
            if (h5io_write(file, out->name, H5T_NATIVE_DOUBLE, 3, cdims, buf, err, errlen) != 0)
                return -1;
        }
    }
    return 0;
}

struct fields_ctx {
    const struct march_state *st;
    double *buf; /* room for the largest array */
};

static int fields_contents(hid_t file, void *vctx, char *err, size_t errlen)
{
    const struct fields_ctx *ctx = vctx;
    return write_contents(file, ctx->st, ctx->buf, err, errlen);
}

int fields_h5_write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    char name[64], path[700], tmp[720];
    fields_h5_name(st->step, name, sizeof name);
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        snprintf(err, errlen, "output path too long in %s", dir);
        return -1;
    }
    const struct grid *g = &st->g;
    /* the largest array: the cell velocity or one face component */
    size_t cells = grid_cells(g), most = 3 * cells;
    for (int c = 0; c < 3; c++) {
        size_t f = cells / (size_t)g->n[c] * (size_t)faces(st, c);
        if (f > most)
            most = f;
    }
    double *buf = malloc(most * sizeof(double));
    if (!buf) {
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        return -1;
    }
    struct fields_ctx ctx = {st, buf};
    int rc = h5io_write_file(tmp, path, "", fields_contents, &ctx, err, errlen);
    free(buf);
    return rc;
}

/* ---- the ranks' blocks ------------------------------------------------------------ */

struct block_attributes {
    const struct march_state *st;
    const struct grid *gg;
};

static int block_attributes(hid_t file, void *vctx, char *err, size_t errlen)
{
    const struct block_attributes *a = vctx;
    return root_attributes(file, a->st, a->gg, err, errlen);
}

/* The (z, y, x[, 3]) box of this rank's cells (face c: faces along c, the
 * last rank's face N too unless periodic) in a field file's dataset. */
static void file_box(const struct decomp *dc, const struct march_state *st, int face, int vec,
                     struct h5box *box)
{
    box->rank = vec ? 4 : 3;
    for (int d = 0; d < 3; d++) {
        const int periodic = st->bc.face[d][0] == BC_PERIODIC;
        const int at_hi = dc->cart->coords[d] == dc->cart->dims[d] - 1;
        const int extra = d == face && !periodic;
        box->global[2 - d] = (hsize_t)(dc->n_global[d] + extra);
        box->start[2 - d] = (hsize_t)dc->lo[d];
        box->count[2 - d] = (hsize_t)(dc->n[d] + (extra && at_hi));
    }
    box->global[3] = box->count[3] = 3;
    box->start[3] = 0;
}

static int write_blocks(struct h5blocks *w, const struct march_state *st,
                        const struct decomp *dc, double *buf, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    int wrap[3];
    for (int c = 0; c < 3; c++)
        wrap[c] = st->bc.face[c][0] == BC_PERIODIC && dc->cart->dims[c] == 1;
    const struct field_registry *r = &st->fields;
    struct h5box box;
    for (int o = 0; o < r->noutputs; o++) {
        const struct field_output *out = &r->out[o];
        const struct field_entry *e = &r->e[out->source];
        if (e->spec.where == FIELD_FACES) {
            for (int c = 0; c < 3; c++) {
                file_box(dc, st, c, 0, &box);
                gather_faces(g, e->v, c, (int)box.count[2 - c], buf);
                if (h5blocks_put(w, out->components[c], &box, buf, err, errlen) != 0)
                    return -1;
            }
            gather_cell_vector(g, e->v, wrap, buf);
            file_box(dc, st, -1, 1, &box);
        } else {
            gather_cells(g, e->v[0], out->map, out->ctx, buf);
            file_box(dc, st, -1, 0, &box);
        }
        if (h5blocks_put(w, out->name, &box, buf, err, errlen) != 0)
            return -1;
    }
    return 0;
}

int fields_h5_write_decomposed(const char *dir, const struct march_state *st,
                               const struct grid *gg, const struct decomp *dc, char *err,
                               size_t errlen)
{
    char name[64], path[700];
    fields_h5_name(st->step, name, sizeof name);
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) {
        snprintf(err, errlen, "output path too long in %s", dir);
        return -1;
    }
    if (grid_stretched(gg)) {
        snprintf(err, errlen, "cannot write %s: a stretched grid is not decomposed", path);
        return -1;
    }
    const struct grid *g = &st->g;
    /* the cell velocity or one face component of the block (one more plane) */
    size_t most = 0;
    for (int c = 0; c < 3; c++) {
        size_t f = grid_cells(g) / (size_t)g->n[c] * (size_t)(g->n[c] + 1);
        most = f > most ? f : most;
    }
    most = 3 * grid_cells(g) > most ? 3 * grid_cells(g) : most;
    double *buf = malloc(most * sizeof(double));
    double lacking = !buf;
    comm_max(&lacking, 1);
    if (lacking != 0.0) {
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        free(buf);
        return -1;
    }
    struct h5blocks w;
    int rc = h5blocks_create(&w, dc->cart, path, err, errlen);
    if (rc == 0 && (rc = write_blocks(&w, st, dc, buf, err, errlen)) == 0) {
        struct block_attributes a = {st, gg};
        rc = h5blocks_finish(&w, "", block_attributes, &a, err, errlen);
    }
    free(buf);
    return rc;
}
