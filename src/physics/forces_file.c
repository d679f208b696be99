/* forces.csv, row by row (forces_file.h). */
#include "physics/forces_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "physics/obstacle_forces.h"

/* The rows of the previous file that the uninterrupted run has too: those
 * before step resume, and its own row when it is a sampled step (a final
 * row of a run stopped between samples is not one). */
struct kept_rows {
    long resume, every;
};
static int kept(long step, void *ctx)
{
    const struct kept_rows *k = ctx;
    return step < k->resume || (step == k->resume && step % k->every == 0);
}

int forces_file_open(struct forces_file *ff, const struct march_state *st, const char *dir,
                     long resume, char *err, size_t errlen)
{
    memset(ff, 0, sizeof *ff);
    ff->last_step = -1;
    ff->every = st->cs->forces_every;
    if (ff->every <= 0 || !case_obstacle_active(st->cs) || st->cs->obstacle.invert)
        return 0; /* no body in a flow */
    struct obstacle_forces f;
    struct obstacle_force_lines l;
    ff->collective = st->ranks != NULL;
    obstacle_forces_scales(st, &f); /* the columns: the scales decide the coefficients' */
    obstacle_force_lines(st, &f, &l);
    FILE *src = resume >= 0 ? output_previous(dir, FORCES_FILE_NAME) : NULL;
    if (output_open(&ff->file, dir, FORCES_FILE_NAME, err, errlen) != 0) {
        if (src)
            fclose(src);
        return -1;
    }
    fprintf(ff->file.f, "step,time");
    for (int i = 0; i < l.n; i++)
        fprintf(ff->file.f, ",%s", l.name[i]);
    fprintf(ff->file.f, "\n");
    if (src) {
        struct kept_rows k = {resume, ff->every};
        long last = output_copy_rows(src, ff->file.f, kept, &k);
        if (last >= 0)
            ff->last_step = last;
        fclose(src);
    }
    return 0;
}

void forces_file_follow(struct forces_file *ff, const struct march_state *st)
{
    memset(ff, 0, sizeof *ff);
    ff->last_step = -1;
    ff->every = st->cs->forces_every;
    ff->collective = st->ranks && ff->every > 0 && case_obstacle_active(st->cs) &&
                     !st->cs->obstacle.invert;
}

void forces_file_row(struct forces_file *ff, const struct march_state *st)
{
    if (ff->collective) {
        /* on ranks the forces sum every block: each rank on the same steps,
         * whether or not rank 0 has the row already */
        if (st->step % ff->every != 0 && st->status == STATUS_RUNNING)
            return;
    } else if (!ff->file.f || st->step == ff->last_step ||
               (st->step % ff->every != 0 && st->status == STATUS_RUNNING)) {
        return;
    }
    struct obstacle_forces f;
    struct obstacle_force_lines l;
    obstacle_forces_surface(st, &f);
    obstacle_force_lines(st, &f, &l);
    if (!ff->file.f || st->step == ff->last_step)
        return;
    fprintf(ff->file.f, "%ld,%.10g", st->step, st->time);
    for (int i = 0; i < l.n; i++)
        fprintf(ff->file.f, ",%.10g", l.value[i]);
    fprintf(ff->file.f, "\n");
    ff->last_step = st->step;
}

void forces_file_flush(struct forces_file *ff)
{
    if (ff->file.f)
        fflush(ff->file.f);
}

int forces_file_close(struct forces_file *ff, char *err, size_t errlen)
{
    if (!ff->file.f)
        return 0;
    int rc = output_commit(&ff->file, err, errlen);
    ff->file.f = NULL;
    return rc;
}
