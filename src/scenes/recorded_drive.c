/* The march with a record of its steps, until the end or rest
 * (include/scenes/recorded_drive.h). */
#include "scenes/recorded_drive.h"

#include <math.h>
#include <stdio.h>
#include "march/march.h"

struct observe_ctx {
    struct scene_drive *d;
    struct recorded_drive *rd;
    int failed;
};

static int observe(void *vctx, const struct march_state *st)
{
    struct observe_ctx *c = vctx;
    struct recorded_drive *rd = c->rd;
    int stop = c->d->observe ? c->d->observe(c->d->observe_ctx, st) : 0;
    if (rd->record_step(rd->rec, st) != 0) {
        c->failed = 1;
        return 1;
    }
    if (!rd->energy)
        return stop;
    double kinetic, peak, peak_time;
    rd->energy(rd->rec, &kinetic, &peak, &peak_time);
    if (!stop && st->status == STATUS_RUNNING && st->step > 0 && rd->rest_fraction > 0.0 &&
        peak > 0.0 && kinetic < rd->rest_fraction * peak) {
        rd->at_rest = 1;
        return 1;
    }
    return stop;
}

void recorded_drive_run(struct scene_drive *d, struct recorded_drive *rd)
{
    struct march_state *st = d->st;
    struct observe_ctx c = {.d = d, .rd = rd};
    rd->at_rest = 0;
    march_run(st, observe, &c);
    if (c.failed) {
        rd->at_rest = 0;
        st->status = STATUS_STOPPED;
        snprintf(st->message, sizeof st->message, "out of memory for %s at step %ld",
                 rd->record_name, st->step);
    } else if (rd->at_rest && st->status == STATUS_STOPPED) {
        double kinetic, peak, peak_time;
        rd->energy(rd->rec, &kinetic, &peak, &peak_time);
        st->status = STATUS_FINISHED;
        int n = snprintf(st->message, sizeof st->message,
                         "the grains came to rest at t = %.6g: kinetic energy %.3e below %g of "
                         "its peak %.3e",
                         st->time, kinetic, rd->rest_fraction, peak);
        if (!isnan(peak_time) && n > 0 && (size_t)n < sizeof st->message)
            snprintf(st->message + n, sizeof st->message - (size_t)n, " (t = %.4g)", peak_time);
    }
}

void recorded_drive_gauge_top(struct march_state *st)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    int k = g->n[2] - 1;
    /* the top layer: the ranks' blocks at the top along z */
    int top = !st->ranks || st->ranks->dc.lo[2] + g->n[2] == G->n[2];
    double s = 0.0;
    for (int i = 0; i < g->n[0] && top; i++)
        for (int j = 0; j < g->n[1]; j++)
            s += st->field.p_dyn[grid_idx(g, i, j, k)];
    s = march_sum(st, s) / ((double)G->n[0] * G->n[1]);
    for (size_t p = 0; p < g->size; p++)
        st->field.p_dyn[p] -= s;
}
