/* The field registry: every field array of a march is declared once, with
 * where it lives and what the run does with it, and everything that loops
 * over fields (the rejected-step save/restore, the checkpoint, the field
 * files and their XDMF index) loops over the registry.  A physics module
 * registers its own fields (a volume fraction, a solid fraction) in its
 * create hook and they are saved, checkpointed and written with no change
 * to any I/O file.
 *
 * Arrays are whole grid arrays with their ghost layers (grid.h): one for a
 * cell field, three for faces (component c on the faces normal to c), edges
 * (plane c) or a cell triple (one cell array per direction). */
#ifndef MUFLOW_MARCH_FIELDS_H
#define MUFLOW_MARCH_FIELDS_H

#include <stddef.h>
#include "grid/grid.h"

#define FIELDS_MAX 64

enum field_where { FIELD_CELLS = 0, FIELD_FACES, FIELD_EDGES, FIELD_CELLS3 };

enum field_flags {
    FIELD_CHECKPOINT = 1, /* in the checkpoint: a continued run needs it */
    FIELD_SAVED = 2,      /* saved before a step, restored when the step is rejected */
    FIELD_START_OPTIONAL = 4, /* a start from a state without it (solver.initial_state,
                                 a restart) keeps march_create's value */
};

struct field_spec {
    const char *name;  /* checkpoint dataset: name, or name_x, name_y, name_z */
    enum field_where where;
    unsigned flags;
};

struct field_entry {
    struct field_spec spec;
    double *v[3];      /* v[0] only for FIELD_CELLS */
    double *saved[3];  /* FIELD_SAVED: the copy of the last accepted state */
};

/* What the field files hold: cell scalars (a cell field, optionally through
 * a map of each value, e.g. |D| from |D|^2) and face fields (their face
 * values and the cell-centred vector).  In the order of registration. */
typedef double (*field_map)(const void *ctx, double value, ptrdiff_t p);
struct field_output {
    const char *name;          /* dataset; for faces the cell-centred vector */
    const char *components[3]; /* faces: the datasets of the face values */
    int source;                /* registry index */
    field_map map;             /* NULL: the value itself */
    const void *ctx;
};

struct field_registry {
    const struct grid *g;
    int count, noutputs;
    struct field_entry e[FIELDS_MAX];
    struct field_output out[FIELDS_MAX];
};

static inline int field_arrays(enum field_where w) { return w == FIELD_CELLS ? 1 : 3; }

void fields_init(struct field_registry *r, const struct grid *g);
/* Allocates the field's zeroed arrays into v (one or three pointers) and
 * returns its index, or -1 (out of memory or a full registry). */
int fields_add(struct field_registry *r, const struct field_spec *s, double **v);
/* Declares an output of field `source` (see struct field_output); 0 or -1. */
int fields_output(struct field_registry *r, const struct field_output *o);
/* A cell field that the field files hold under its own name (a module's
 * tracer): fields_add and fields_output in one; 0 or -1. */
int fields_add_written(struct field_registry *r, const char *name, unsigned flags, double **v);
int fields_find(const struct field_registry *r, const char *name);
void fields_save(struct field_registry *r);
void fields_restore(struct field_registry *r);
/* Moves every FIELD_SAVED field to saved + alpha (current - saved): a
 * shorter step along the last one (the steady march's line search). */
void fields_blend(struct field_registry *r, double alpha);
/* A copy of the FIELD_CHECKPOINT fields, the state a run starts from (a
 * continuation's steady states, march/fields.c). */
struct field_snapshot {
    int n;
    double *a[3 * FIELDS_MAX];
};
/* Copies the fields into s (allocating its arrays the first time); 0, or
 * -1 out of memory. */
int fields_snapshot_take(struct field_snapshot *s, const struct field_registry *r);
/* The fields = s + w (s - older): the secant step beyond s (older NULL or
 * w = 0: s itself). */
void fields_snapshot_put(const struct field_snapshot *s, const struct field_snapshot *older,
                         double w, struct field_registry *r);
void fields_snapshot_free(struct field_snapshot *s);
void fields_free(struct field_registry *r);

#endif
