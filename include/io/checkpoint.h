/* Checkpoints: everything a run needs to continue exactly as if it had not
 * stopped, in one HDF5 file DIR/checkpoint.h5:
 *   - every case key as a text attribute "section.key" and the case name, so a
 *     restart needs no case file;
 *   - the loop state of struct march_state (step, time, dt, residual0,
 *     best_residual, best_step, dt_scale, rejected, wall_seconds, ...);
 *   - every field the registry marks FIELD_CHECKPOINT (march/fields.h: the
 *     velocity, the dynamic pressure, a module's tracer), whole arrays with
 *     their ghost layers, in the memory layout of grid.h;
 *   - what each physics module keeps between steps beyond its fields (its
 *     save hook, march/module.h; group modules/<name>): a scene's record of
 *     the run (the collapse's x_front(t) and profiles, bagnold2's growth),
 *     the two phases' face densities and the VOF's sweep order;
 *   - the schedule of field files (field_series.h);
 *   - FFTW's wisdom: the transform algorithms FFTW_MEASURE chose, so the
 *     restarted run plans the same ones and rounds the same way.
 * The file is written as checkpoint.h5.tmp, synced and renamed: a failed
 * write leaves the previous checkpoint as it was.  A decomposed run's ranks
 * write it together, the same file (h5blocks.h: each rank its block of the
 * arrays; rank 0 the rest, which every rank holds alike). */
#ifndef MUFLOW_CHECKPOINT_H
#define MUFLOW_CHECKPOINT_H

#include <stddef.h>
#include "io/field_series.h"
#include "march/march.h"

#define CHECKPOINT_NAME "checkpoint.h5"
#define CHECKPOINT_FORMAT "muflow checkpoint 1"

/* Writes dir/checkpoint.h5 (collective on ranks: every rank the same
 * status).  Returns 0, or -1 with the cause in err. */
int checkpoint_write(const char *dir, const struct march_state *st,
                     const struct field_series *fs, char *err, size_t errlen);

/* The case stored in the checkpoint at path, then the overrides in order
 * (as case_load).  Returns 0, or 2 with the cause in err. */
int checkpoint_load_case(const char *path, int noverrides, char *const overrides[],
                         struct muflow_case *cs, char *err, size_t errlen);

/* Imports the checkpoint's FFTW wisdom; call before march_create.  Returns 0,
 * or -1 with the cause. */
int checkpoint_import_wisdom(const char *path, char *err, size_t errlen);

/* Loads the fields, the loop state and the field-file schedule into st and fs.
 * st must come from march_create for the checkpoint's grid (a different grid
 * is an error); on ranks each reads its block, ghosts included, of the file
 * any rank count wrote.  writer[0] receives the OpenMP thread count and
 * writer[1] the MPI rank count of the run that wrote it (other counts
 * continue, but not bit for bit).  Returns 0, or -1 with the cause. */
int checkpoint_read_state(const char *path, struct march_state *st, struct field_series *fs,
                          int writer[2], char *err, size_t errlen);

/* The dataset name of array c of a checkpointed field: its name for a
 * cell field, name_x, _y, _z for the three arrays of the others. */
void checkpoint_dataset_name(const struct field_spec *spec, int c, char *name, size_t len);

/* The grid (cells per direction) and the box lengths of the checkpoint at
 * path.  Returns 0, or -1 with the cause in err. */
int checkpoint_read_grid(const char *path, int n[3], double len[3], char *err, size_t errlen);

/* The case key `key` ("domain.x_band") as the checkpoint stored it, into
 * text; 0, or -1 when the file cannot be read or has no such key. */
int checkpoint_read_key(const char *path, const char *key, char *text, size_t len);
/* 1 when the checkpoint has the dataset, 0 when not, -1 when the file is
 * not a readable checkpoint. */
int checkpoint_has_dataset(const char *path, const char *name);
/* Its dataset `name` (a checkpointed field's array, each_dataset's names:
 * checkpoint_dataset_name) on its grid n: (n[0]+2)(n[1]+2)(n[2]+2) doubles in
 * the layout of grid.h into buf.  Returns 0, or -1 with the cause in err. */
int checkpoint_read_dataset(const char *path, const char *name, const int n[3], double *buf,
                            char *err, size_t errlen);

#endif
