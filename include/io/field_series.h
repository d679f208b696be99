/* The series of field files a run writes: when the next one is due
 * (output.fields_every steps, output.fields_interval time units, and the end
 * of the run), which were written (for fields.xdmf), and the state a restart
 * needs to continue the same schedule. */
#ifndef MUFLOW_FIELD_SERIES_H
#define MUFLOW_FIELD_SERIES_H

#include <stddef.h>
#include "march/march.h"

struct field_series {
    long *steps;       /* steps of the field files written, increasing */
    double *times;     /* their times */
    int count, cap;
    double next_time;  /* output.fields_interval: the next multiple of it to reach */
};

void field_series_init(struct field_series *s);
void field_series_free(struct field_series *s);

/* 1 when the schedule asks for a field file at st's step (not counting the
 * end of the run). */
int field_series_due(const struct field_series *s, const struct muflow_case *cs,
                     const struct march_state *st);

/* 1 when the field file of st's step has been written. */
int field_series_has(const struct field_series *s, long step);

/* Writes the field file of st into dir, records it (advancing next_time) and
 * rewrites dir/fields.xdmf.  Returns 0, or -1 with the cause. */
int field_series_write(struct field_series *s, const char *dir, const struct march_state *st,
                       char *err, size_t errlen);

/* Records step/time (a restart restores the list); -1 when out of memory. */
int field_series_add(struct field_series *s, long step, double time);

#endif
