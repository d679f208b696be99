/* What a physics module keeps between steps beyond its registered fields (a
 * scene's record of the run, a counter that decides the next step), in the
 * checkpoint: the module's save hook puts named arrays of doubles, its load
 * hook gets them back when a run continues (march/module.h).  The checkpoint
 * (io/checkpoint.c) stores them, in the datasets of group
 * modules/<module name>, through the record's store.
 *
 * Every function returns 0 (a count for module_record_count), or -1 with the
 * cause kept in the record: the checkpoint's error names the module and
 * that cause. */
#ifndef MUFLOW_MARCH_MODULE_RECORD_H
#define MUFLOW_MARCH_MODULE_RECORD_H

#include "grid/grid.h"

/* Where a record's arrays live: ctx is the store's (the checkpoint's group);
 * each function returns as the module_record_ function of its name does,
 * the cause in err. */
struct module_record_store {
    int (*put)(void *ctx, const char *name, const double *v, long n, char *err, size_t errlen);
    long (*count)(void *ctx, const char *name, char *err, size_t errlen);
    int (*get)(void *ctx, const char *name, double *v, long n, char *err, size_t errlen);
};

struct module_record {
    const struct module_record_store *store;
    void *ctx;
    char err[512];
};

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
