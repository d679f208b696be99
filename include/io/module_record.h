/* What a physics module keeps between steps beyond its registered fields (a
 * scene's record of the run, a counter that decides the next step), in the
 * checkpoint: the module's save hook puts named arrays of doubles, its load
 * hook gets them back when a run continues (march/module.h).  In the file,
 * the datasets of group modules/<module name>.
 *
 * Every function returns 0 (a count for module_record_count), or -1 with the
 * cause kept in the record: the checkpoint's error names the module and
 * that cause. */
#ifndef MUFLOW_IO_MODULE_RECORD_H
#define MUFLOW_IO_MODULE_RECORD_H

#include "grid/grid.h"

struct module_record;

/* Stores the n values of v (n >= 0) under name. */
int module_record_put(struct module_record *r, const char *name, const double *v, long n);
/* The number of values stored under name, or -1 when there is none. */
long module_record_count(struct module_record *r, const char *name);
/* Reads the n values stored under name into v; their count must be n. */
int module_record_get(struct module_record *r, const char *name, double *v, long n);
/* A field array of g under name, stored in the layout with every ghost
 * (g->padded values, as the checkpoint's fields: grid.h), and read back. */
int module_record_put_field(struct module_record *r, const char *name, const struct grid *g,
                            const double *f);
int module_record_get_field(struct module_record *r, const char *name, const struct grid *g,
                            double *f);
/* Sets the cause (printf-like) and returns -1: for a hook's own failure
 * (out of memory, a stored value that does not fit this run). */
int module_record_fail(struct module_record *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

#endif
