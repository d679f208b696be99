/* forces.csv: the forces on the case's bodies through a run, a row per
 * sampled step (output.forces_every) and one for the final state, whose
 * numbers are the summary's (obstacle_force_lines of obstacle_forces_surface:
 * step, time, then drag_force, lift_force and, where the case defines them,
 * drag_coefficient, lift_coefficient and pressure_drop; force_<axis>
 * without a flow in the body's plane).  Written row by row under the
 * temporary name and renamed at the end (platform/output_file.h), as
 * history.csv is.  A case without a body in a flow (no shapes,
 * obstacle.invert), or output.forces_every = 0, writes none. */
#ifndef MUFLOW_PHYSICS_FORCES_FILE_H
#define MUFLOW_PHYSICS_FORCES_FILE_H

#include <stddef.h>
#include "march/march.h"
#include "platform/output_file.h"

#define FORCES_FILE_NAME "forces.csv"

struct forces_file {
    struct output_file file; /* file.f NULL: no file */
    long every;              /* output.forces_every */
    long last_step;          /* the step of the last row (-1: none) */
    int collective;          /* on ranks: every rank computes each row (the
                                forces sum the blocks), rank 0 writes it */
};

/* Opens dir/forces.csv for the march st (created, its state set; the
 * columns follow its case).  resume >= 0: the run continues from a
 * checkpoint of that step, and the file starts with the previous file's
 * rows up to it (forces.csv.tmp when a run died before renaming it, else
 * forces.csv) that the uninterrupted run has too: every row before it, the
 * row of that step when it is a sampled one.  Returns 0 (also when it
 * writes no file), or -1 with the cause in err. */
int forces_file_open(struct forces_file *ff, const struct march_state *st, const char *dir,
                     long resume, char *err, size_t errlen);
/* The other ranks' part of rank 0's file (no file): the same rows'
 * forces, which sum over the blocks. */
void forces_file_follow(struct forces_file *ff, const struct march_state *st);

/* The row of an evaluated state st: every `every` steps, and the state the
 * march ends on (status not running); once per step.  On ranks every rank
 * calls it. */
void forces_file_row(struct forces_file *ff, const struct march_state *st);
/* Pushes the rows so far to the temporary file (before a checkpoint). */
void forces_file_flush(struct forces_file *ff);
/* Renames the file to forces.csv; 0, or -1 with the cause in err. */
int forces_file_close(struct forces_file *ff, char *err, size_t errlen);

#endif
