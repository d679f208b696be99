/* HDF5 files written by the ranks together, each its block (a hyperslab)
 * of every global dataset, with parallel HDF5 (platform/phdf5.h) under
 * mpirun and the serial library otherwise; read back by any rank count.
 * docs/numerics/decomposition.md.
 *
 * A file holds the datasets the serial writers would write, in the same
 * shapes and order (C order, last index fastest), and their attributes,
 * written by rank 0 with the serial library once the ranks' file is closed
 * (h5io, fields_h5: the same code writes them as without ranks).  Like
 * every output it is written as path.tmp and renamed when whole.
 *
 * Every call but h5blocks_read is collective over the ranks of the cart
 * given to h5blocks_create, and every rank returns the same status: a
 * failure on one rank fails the file on all (err names the cause on the
 * rank that met it, "another rank failed" on the others). */
#ifndef MUFLOW_IO_H5BLOCKS_H
#define MUFLOW_IO_H5BLOCKS_H

#include <hdf5.h>
#include <stddef.h>
#include "grid/decomp.h"
#include "io/h5io.h"
#include "platform/phdf5.h"

/* A rank's box of a global dataset of rank 1 .. 4. */
struct h5box {
    int rank;
    hsize_t global[4], start[4], count[4];
};

struct h5blocks {
    const struct phdf5 *p; /* NULL: the serial library (one rank) */
    hid_t file, dxpl;
    char tmp[1100], path[1100];
};

/* Opens path.tmp for writing on every rank of cart (cart->comm NULL: one
 * rank, serial HDF5). */
int h5blocks_create(struct h5blocks *w, const struct comm_cart *cart, const char *path,
                    char *err, size_t errlen);
/* Creates dataset name of box->global doubles and writes this rank's box
 * of it from data (box->count doubles, C order).  On failure the file is
 * closed and removed (no h5blocks_finish). */
int h5blocks_put(struct h5blocks *w, const char *name, const struct h5box *box,
                 const double *data, char *err, size_t errlen);
/* Closes the file, adds the attributes (rank 0, serial HDF5: attributes may
 * be NULL) and commits it to path (h5io_commit); label as h5io_write_file. */
int h5blocks_finish(struct h5blocks *w, const char *label, h5io_contents attributes,
                    void *ctx, char *err, size_t errlen);

/* Reads the box of dataset name of the file at path into data (serial
 * HDF5, on one rank: any rank count may have written the file). */
int h5blocks_read(const char *path, const char *name, const struct h5box *box, double *data,
                  char *err, size_t errlen);

/* ---- whole grid arrays, ghosts included (the checkpoint's layout) ---------------- */

/* The global dataset of a field with every ghost, (N0 + 2) x (N1 + 2) x (N2 + 2),
 * and this rank's part of it: its cells, and the ghost layer where its
 * block ends at the domain's end (face N of a face field there, a
 * periodic direction's images): box, and the local slots it starts at. */
void h5blocks_full_box(const struct decomp *dc, struct h5box *box, int first[3]);
/* Packs (or unpacks, pack = 0) the box of local field f (grid g, slots
 * first .. first + count - 1) to or from buf, C order. */
void h5blocks_full_copy(const struct grid *g, const int first[3], const struct h5box *box,
                        double *f, double *buf, int pack);
/* Writes field f (local grid g, its ghosts filled: the exchange, the
 * boundary) as dataset name of the global array with every ghost; buf
 * holds g->size doubles. */
int h5blocks_put_full(struct h5blocks *w, const char *name, const struct decomp *dc,
                      const struct grid *g, const double *f, double *buf, char *err,
                      size_t errlen);
/* Reads every slot of local field f, ghosts included (the neighbours' cells
 * and faces there), from such a dataset written on any rank count; buf
 * holds g->size doubles. */
int h5blocks_read_full(const char *path, const char *name, const struct decomp *dc,
                       const struct grid *g, double *f, double *buf, char *err, size_t errlen);
/* The same from a file open for reading (serial HDF5: a checkpoint). */
int h5blocks_read_full_in(hid_t file, const char *name, const struct decomp *dc,
                          const struct grid *g, double *f, double *buf, char *err,
                          size_t errlen);

#endif
