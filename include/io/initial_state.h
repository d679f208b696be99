/* A run started from another run's checkpoint on another grid of the same
 * box (solver.initial_state): grid sequencing, a steady solve started from
 * a coarser mesh's solution instead of the scene's state.
 *
 * Every field the registry checkpoints (the velocity, the dynamic pressure,
 * a module's field: march/fields.h) is read from the checkpoint and
 * interpolated, trilinearly between its nodes (faces or cells), to this
 * grid's nodes; a node beyond the checkpoint's last one takes its ghost
 * layer's value; the nodes held in an embedded body are set to rest again.
 * Nothing else of the checkpoint is taken: the march starts
 * at step 0 with its own loop state. */
#ifndef MUFLOW_INITIAL_STATE_H
#define MUFLOW_INITIAL_STATE_H

#include <stddef.h>
#include "march/march.h"

/* path: a checkpoint file or the run folder holding checkpoint.h5.
 * Returns 0, or -1 with one line naming solver.initial_state and the cause
 * in err (a missing file, another box, a field the checkpoint lacks). */
int initial_state_load(const char *path, struct march_state *st, char *err, size_t errlen);

#endif
