/* HDF5 files of the ranks' blocks (h5blocks.h). */
#include "io/h5blocks.h"

#include <stdio.h>
#include <string.h>
#include "platform/comm.h"

/* Every rank's rc, agreed: the failure of any rank is every rank's (the
 * others' err says so). */
static int agree(int rc, char *err, size_t errlen)
{
    double failed = rc != 0;
    comm_max(&failed, 1);
    if (failed != 0.0 && rc == 0)
        snprintf(err, errlen, "another rank failed");
    return failed != 0.0 ? -1 : 0;
}

/* Closes what is open; 0, or -1 (the close failed: a full disk may only
 * show here). */
static int close_file(struct h5blocks *w)
{
    const struct phdf5 *p = w->p;
    int rc = 0;
    if (w->dxpl >= 0)
        p->H5Pclose(w->dxpl);
    if (w->file >= 0)
        rc = (p ? p->H5Fclose(w->file) : H5Fclose(w->file)) < 0 ? -1 : 0;
    w->file = w->dxpl = -1;
    return rc;
}

/* Abandons the file on every rank: closed, removed by rank 0. */
static void abandon(struct h5blocks *w)
{
    close_file(w);
    if (comm_rank() == 0)
        remove(w->tmp);
}

int h5blocks_create(struct h5blocks *w, const struct comm_cart *cart, const char *path,
                    char *err, size_t errlen)
{
    memset(w, 0, sizeof *w);
    w->file = w->dxpl = -1;
    h5io_init();
    if (snprintf(w->path, sizeof w->path, "%s", path) >= (int)sizeof w->path ||
        snprintf(w->tmp, sizeof w->tmp, "%s.tmp", path) >= (int)sizeof w->tmp) {
        snprintf(err, errlen, "output path too long: %s", path);
        return -1; /* the same path on every rank: the same answer */
    }
    int rc = 0;
    if (cart->comm) {
        if (!(w->p = phdf5_open(err, errlen)))
            rc = -1;
    }
    const struct phdf5 *p = w->p;
    if (rc == 0 && p) {
        /* MPI-IO over every rank (the cart's, in the same order), collective
         * transfers.  Not the Cartesian communicator itself: Open MPI 4.1's
         * OMPIO then groups its aggregators by the topology and, measured,
         * sometimes writes a block of one dataset over another's
         * (docs/numerics/decomposition.md). */
        hid_t fapl = p->H5Pcreate(p->file_access);
        if (fapl < 0 || p->H5Pset_fapl_mpio(fapl, p->comm_world, p->info_null) < 0 ||
            (w->file = p->H5Fcreate(w->tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl)) < 0 ||
            (w->dxpl = p->H5Pcreate(p->dataset_xfer)) < 0 ||
            p->H5Pset_dxpl_mpio(w->dxpl, 1 /* H5FD_MPIO_COLLECTIVE */) < 0) {
            snprintf(err, errlen, "cannot create %s with parallel HDF5", w->tmp);
            rc = -1;
        }
        if (fapl >= 0)
            p->H5Pclose(fapl);
    } else if (rc == 0 && (w->file = H5Fcreate(w->tmp, H5F_ACC_TRUNC, H5P_DEFAULT,
                                               H5P_DEFAULT)) < 0) {
        h5io_error(err, errlen, "cannot create");
        rc = -1;
    }
    if (agree(rc, err, errlen) != 0) {
        abandon(w);
        return -1;
    }
    return 0;
}

int h5blocks_put(struct h5blocks *w, const char *name, const struct h5box *box,
                 const double *data, char *err, size_t errlen)
{
    const struct phdf5 *p = w->p;
    hsize_t points = 1;
    for (int d = 0; d < box->rank; d++)
        points *= box->count[d];
    hid_t fspace = -1, mspace = -1, set = -1;
    int rc = 0;
    if (p) {
        if ((fspace = p->H5Screate_simple(box->rank, box->global, NULL)) < 0 ||
            (mspace = p->H5Screate_simple(box->rank, box->count, NULL)) < 0 ||
            (set = p->H5Dcreate2(w->file, name, p->native_double, fspace, H5P_DEFAULT,
                                 H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
            p->H5Sselect_hyperslab(fspace, H5S_SELECT_SET, box->start, NULL, box->count,
                                   NULL) < 0 ||
            /* collective: every rank writes, an empty box too */
            p->H5Dwrite(set, p->native_double, mspace, fspace, w->dxpl, data) < 0) {
            snprintf(err, errlen, "dataset %s: cannot write with parallel HDF5", name);
            rc = -1;
        }
        if (set >= 0 && p->H5Dclose(set) < 0 && rc == 0) {
            snprintf(err, errlen, "dataset %s: cannot close", name);
            rc = -1;
        }
        if (mspace >= 0)
            p->H5Sclose(mspace);
        if (fspace >= 0)
            p->H5Sclose(fspace);
    } else {
        if ((fspace = H5Screate_simple(box->rank, box->global, NULL)) < 0 ||
            (mspace = H5Screate_simple(box->rank, box->count, NULL)) < 0 ||
            (set = H5Dcreate2(w->file, name, H5T_NATIVE_DOUBLE, fspace, H5P_DEFAULT,
                              H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
            H5Sselect_hyperslab(fspace, H5S_SELECT_SET, box->start, NULL, box->count,
                                NULL) < 0 ||
            (points > 0 &&
             H5Dwrite(set, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, data) < 0)) {
            char what[200];
            snprintf(what, sizeof what, "dataset %s: cannot write", name);
            h5io_error(err, errlen, what);
            rc = -1;
        }
        if (set >= 0 && H5Dclose(set) < 0 && rc == 0) {
            h5io_error(err, errlen, "cannot close a dataset");
            rc = -1;
        }
        if (mspace >= 0)
            H5Sclose(mspace);
        if (fspace >= 0)
            H5Sclose(fspace);
    }
    if (agree(rc, err, errlen) != 0) {
        abandon(w);
        return -1;
    }
    return 0;
}

int h5blocks_finish(struct h5blocks *w, const char *label, h5io_contents attributes,
                    void *ctx, char *err, size_t errlen)
{
    char cause[600] = "";
    int rc = close_file(w);
    if (rc != 0)
        snprintf(cause, sizeof cause, "cannot close");
    rc = agree(rc, cause, sizeof cause);
    const int root = comm_rank() == 0;
    if (rc == 0 && root && attributes) {
        /* the ranks' file closed: rank 0 alone adds what the serial writers add */
        hid_t file = H5Fopen(w->tmp, H5F_ACC_RDWR, H5P_DEFAULT);
        if (file < 0) {
            h5io_error(cause, sizeof cause, "cannot reopen");
            rc = -1;
        } else {
            rc = attributes(file, ctx, cause, sizeof cause);
            if (H5Fclose(file) < 0 && rc == 0) {
                h5io_error(cause, sizeof cause, "cannot close");
                rc = -1;
            }
        }
    }
    if (rc == 0 && root && h5io_commit(w->tmp, w->path, cause, sizeof cause) != 0)
        rc = -2; /* tmp removed by the commit, whose message names it */
    if (rc == -1 && root)
        remove(w->tmp);
    if (rc == -1)
        snprintf(err, errlen, "cannot write %s%s%s: %s", label, *label ? " " : "", w->tmp,
                 cause);
    else if (rc == -2)
        snprintf(err, errlen, "%s%s%s", label, *label ? ": " : "", cause);
    /* the file is whole on disk (or gone) before any rank returns */
    return agree(rc, err, errlen);
}

/* The box of dataset name of an open file (serial HDF5); where names the
 * file in the messages. */
static int read_box(hid_t file, const char *where, const char *name, const struct h5box *box,
                    double *data, char *err, size_t errlen)
{
    hsize_t dims[4];
    int rank = h5io_dims(file, name, 4, dims, err, errlen), rc = rank < 0 ? -1 : 0;
    for (int d = 0; rc == 0 && d < box->rank; d++)
        if (rank != box->rank || dims[d] != box->global[d]) {
            snprintf(err, errlen, "dataset %s%s%s: not of the grid's shape", name,
                     *where ? " of " : "", where);
            rc = -1;
        }
    hid_t set = rc == 0 ? H5Dopen2(file, name, H5P_DEFAULT) : -1;
    hid_t fspace = set >= 0 ? H5Dget_space(set) : -1;
    hid_t mspace = fspace >= 0 ? H5Screate_simple(box->rank, box->count, NULL) : -1;
    if (rc == 0 && (mspace < 0 ||
                    H5Sselect_hyperslab(fspace, H5S_SELECT_SET, box->start, NULL, box->count,
                                        NULL) < 0 ||
                    H5Dread(set, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, data) < 0)) {
        char what[200];
        snprintf(what, sizeof what, "dataset %s: cannot read", name);
        h5io_error(err, errlen, what);
        rc = -1;
    }
    if (mspace >= 0)
        H5Sclose(mspace);
    if (fspace >= 0)
        H5Sclose(fspace);
    if (set >= 0)
        H5Dclose(set);
    return rc;
}

int h5blocks_read(const char *path, const char *name, const struct h5box *box, double *data,
                  char *err, size_t errlen)
{
    h5io_init();
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) {
        char what[1200];
        snprintf(what, sizeof what, "cannot open %s", path);
        h5io_error(err, errlen, what);
        return -1;
    }
    int rc = read_box(file, path, name, box, data, err, errlen);
    H5Fclose(file);
    return rc;
}

/* ---- whole grid arrays, ghosts included ------------------------------------------- */

void h5blocks_full_box(const struct decomp *dc, struct h5box *box, int first[3])
{
    const struct comm_cart *cart = dc->cart;
    box->rank = 3;
    for (int d = 0; d < 3; d++) {
        const int at_lo = cart->coords[d] == 0, at_hi = cart->coords[d] == cart->dims[d] - 1;
        first[d] = at_lo ? -1 : 0;
        box->global[d] = (hsize_t)dc->n_global[d] + 2;
        box->start[d] = (hsize_t)(dc->lo[d] + first[d] + 1); /* slot -1 is the file's 0 */
        box->count[d] = (hsize_t)(dc->n[d] + at_lo + at_hi);
    }
}

void h5blocks_full_copy(const struct grid *g, const int first[3], const struct h5box *box,
                        double *f, double *buf, int pack)
{
    size_t q = 0;
    for (hsize_t i = 0; i < box->count[0]; i++)
        for (hsize_t j = 0; j < box->count[1]; j++)
            for (hsize_t k = 0; k < box->count[2]; k++, q++) {
                const ptrdiff_t p = grid_idx(g, first[0] + (int)i, first[1] + (int)j,
                                             first[2] + (int)k);
                if (pack)
                    buf[q] = f[p];
                else
                    f[p] = buf[q];
            }
}

int h5blocks_put_full(struct h5blocks *w, const char *name, const struct decomp *dc,
                      const struct grid *g, const double *f, double *buf, char *err,
                      size_t errlen)
{
    struct h5box box;
    int first[3];
    h5blocks_full_box(dc, &box, first);
    h5blocks_full_copy(g, first, &box, (double *)f, buf, 1);
    return h5blocks_put(w, name, &box, buf, err, errlen);
}

/* Every local slot of the rank's block: global slots lo - 1 .. lo + n. */
static void local_box(const struct decomp *dc, struct h5box *box)
{
    box->rank = 3;
    for (int d = 0; d < 3; d++) {
        box->global[d] = (hsize_t)dc->n_global[d] + 2;
        box->start[d] = (hsize_t)dc->lo[d];
        box->count[d] = (hsize_t)dc->n[d] + 2;
    }
}

int h5blocks_read_full(const char *path, const char *name, const struct decomp *dc,
                       const struct grid *g, double *f, double *buf, char *err, size_t errlen)
{
    struct h5box box;
    const int first[3] = {-1, -1, -1};
    local_box(dc, &box);
    if (h5blocks_read(path, name, &box, buf, err, errlen) != 0)
        return -1;
    h5blocks_full_copy(g, first, &box, f, buf, 0);
    return 0;
}

int h5blocks_read_full_in(hid_t file, const char *name, const struct decomp *dc,
                          const struct grid *g, double *f, double *buf, char *err,
                          size_t errlen)
{
    struct h5box box;
    const int first[3] = {-1, -1, -1};
    local_box(dc, &box);
    if (read_box(file, "", name, &box, buf, err, errlen) != 0)
        return -1;
    h5blocks_full_copy(g, first, &box, f, buf, 0);
    return 0;
}
