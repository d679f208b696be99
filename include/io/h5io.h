/* Small HDF5 helpers shared by the field files and the checkpoints.
 *
 * Every function returns 0 on success and -1 on failure with the cause in err:
 * for a failing HDF5 call, the innermost entry of HDF5's error stack (where the
 * error was detected, e.g. "file write failed: No space left on device"),
 * because the outer entries only repeat which API call failed.  HDF5's own
 * printing of the stack to stderr is switched off by h5io_init(). */
#ifndef MUFLOW_H5IO_H
#define MUFLOW_H5IO_H

#include <hdf5.h>
#include <stddef.h>

/* Switches off HDF5's automatic error printing (muflow reports errors itself).
 * Idempotent; call before any other HDF5 call. */
void h5io_init(void);

/* err = what + ": " + the innermost HDF5 error (or "unknown HDF5 error").
 * Call right after the failing HDF5 call: the next call clears the stack. */
void h5io_error(char *err, size_t errlen, const char *what);

/* Datasets of rank dims (C order, last index fastest). */
int h5io_write(hid_t loc, const char *name, hid_t type, int rank, const hsize_t *dims,
               const void *data, char *err, size_t errlen);
/* Reads a dataset whose shape must be exactly rank/dims. */
int h5io_read(hid_t loc, const char *name, hid_t memtype, int rank, const hsize_t *dims,
              void *data, char *err, size_t errlen);
/* Rank and dims (up to maxrank) of a dataset; -1 when it is missing. */
int h5io_dims(hid_t loc, const char *name, int maxrank, hsize_t *dims, char *err, size_t errlen);

/* Attributes: n values of type (n = 1: a scalar), or a text. */
int h5io_attr_write(hid_t loc, const char *name, hid_t type, int n, const void *data, char *err,
                    size_t errlen);
int h5io_attr_read(hid_t loc, const char *name, hid_t memtype, int n, void *data, char *err,
                   size_t errlen);
int h5io_attr_write_text(hid_t loc, const char *name, const char *text, char *err,
                         size_t errlen);
/* Fails when the text does not fit len (never truncated). */
int h5io_attr_read_text(hid_t loc, const char *name, char *text, size_t len, char *err,
                        size_t errlen);

/* Calls visit(ctx, name, text) for every text attribute of loc, in name order;
 * stops at the first non-zero return of visit and returns it (or -1 when an
 * attribute cannot be read, cause in err). */
int h5io_attr_each_text(hid_t loc, int (*visit)(void *ctx, const char *name, const char *text),
                        void *ctx, char *err, size_t errlen);

/* Writes a whole HDF5 file: creates tmp, calls contents(file, ctx, ...) to
 * fill it, closes it (a full disk may only show there) and commits it to path
 * (h5io_commit).  On failure tmp is removed and err says "cannot write
 * <label> <tmp>: <cause>" (label e.g. "checkpoint", or "" for none); a failed
 * commit gives "cannot write <label>: <cause>" (just the cause without label). */
typedef int (*h5io_contents)(hid_t file, void *ctx, char *err, size_t errlen);
int h5io_write_file(const char *tmp, const char *path, const char *label, h5io_contents contents,
                    void *ctx, char *err, size_t errlen);

/* Makes the closed file tmp durable and gives it its final name: fsync(tmp),
 * rename(tmp, path), fsync of the folder.  After a crash path is either the
 * old file or the new one, whole.  On failure tmp is removed. */
int h5io_commit(const char *tmp, const char *path, char *err, size_t errlen);

#endif
