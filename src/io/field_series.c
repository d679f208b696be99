/* Schedule and index of the field files (field_series.h). */
#include "io/field_series.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "io/fields_h5.h"
#include "io/xdmf.h"
#include "platform/comm.h"

/* Times are sums of steps: 10 steps of 0.01 reach 0.09999999999999999, which
 * must count as having reached 0.1.  A relative slack far above the rounding
 * of such sums and far below any step anyone would take. */
#define TIME_SLACK 1e-9

void field_series_init(struct field_series *s)
{
    s->steps = NULL;
    s->times = NULL;
    s->count = s->cap = 0;
    s->next_time = 0.0;
}

void field_series_free(struct field_series *s)
{
    free(s->steps);
    free(s->times);
    field_series_init(s);
}

int field_series_due(const struct field_series *s, const struct muflow_case *cs,
                     const struct march_state *st)
{
    if (!cs->fields)
        return 0;
    if (cs->fields_every > 0 && st->step % cs->fields_every == 0)
        return 1;
    return cs->fields_interval > 0.0 &&
           st->time >= s->next_time - TIME_SLACK * cs->fields_interval;
}

int field_series_has(const struct field_series *s, long step)
{
    return s->count > 0 && s->steps[s->count - 1] == step;
}

int field_series_add(struct field_series *s, long step, double time)
{
    if (field_series_has(s, step)) { /* rewritten: same step, same state */
        s->times[s->count - 1] = time;
        return 0;
    }
    if (s->count == s->cap) {
        int cap = s->cap ? 2 * s->cap : 16;
        long *steps = realloc(s->steps, (size_t)cap * sizeof *steps);
        if (!steps)
            return -1;
        s->steps = steps;
        double *times = realloc(s->times, (size_t)cap * sizeof *times);
        if (!times)
            return -1;
        s->times = times;
        s->cap = cap;
    }
    s->steps[s->count] = step;
    s->times[s->count] = time;
    s->count++;
    return 0;
}

int field_series_write(struct field_series *s, const char *dir, const struct march_state *st,
                       char *err, size_t errlen)
{
    /* a decomposed run's ranks write their blocks of one file together */
    if ((st->ranks ? fields_h5_write_decomposed(dir, st, &st->ranks->global, &st->ranks->dc, err,
                                                errlen)
                   : fields_h5_write(dir, st, err, errlen)) != 0)
        return -1;
    if (field_series_add(s, st->step, st->time) != 0) {
        snprintf(err, errlen, "out of memory for the list of field files");
        return -1;
    }
    double T = st->cs->fields_interval;
    if (T > 0.0)
        s->next_time = (floor(st->time / T + TIME_SLACK) + 1.0) * T;
    if (st->ranks && comm_rank() != 0)
        return 0;
    return xdmf_write(dir, march_global_grid(st), &st->fields, s->count, s->steps, s->times, err,
                      errlen);
}
