/* A run started from a checkpoint on another grid (initial_state.h). */
#include "io/initial_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "io/checkpoint.h"
#include "kernels/embedded.h"

/* Relative difference of box lengths taken as the same box (a length
 * written to the case file with 17 digits comes back to the last bit). */
#define SAME_BOX 1e-12

/* The value at x of a source array on grid ns with spacing hs, its nodes at
 * (index + off[d]) hs[d]: trilinear between the nodes around x, the index
 * held within the source's slots -1 .. ns (its ghost layer at the ends). */
static double sample(const double *src, const int ns[3], const double hs[3], const double off[3],
                     const double x[3])
{
    int i0[3];
    double w[3];
    for (int d = 0; d < 3; d++) {
        double t = fmin(fmax(x[d] / hs[d] - off[d], -1.0), (double)ns[d]);
        i0[d] = (int)floor(t);
        if (i0[d] > ns[d] - 1)
            i0[d] = ns[d] - 1;
        w[d] = t - i0[d];
    }
    const ptrdiff_t s0 = (ptrdiff_t)(ns[1] + 2) * (ns[2] + 2), s1 = ns[2] + 2;
    double v = 0.0;
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int c = 0; c < 2; c++) {
                double wt = (a ? w[0] : 1.0 - w[0]) * (b ? w[1] : 1.0 - w[1]) *
                            (c ? w[2] : 1.0 - w[2]);
                if (wt == 0.0)
                    continue;
                v += wt * src[(ptrdiff_t)(i0[0] + a + 1) * s0 + (ptrdiff_t)(i0[1] + b + 1) * s1 +
                              (i0[2] + c + 1)];
            }
    return v;
}

/* Interpolates the source array into f on every slot of g (ghosts too: the
 * march fills them again), the nodes of both at (index + off) h. */
static void interpolate(const double *src, const int ns[3], const double hs[3],
                        const double off[3], const struct grid *g, double *f)
{
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const int idx[3] = {i, j, k};
                double x[3];
                for (int d = 0; d < 3; d++)
                    x[d] = (idx[d] + off[d]) * g->h[d];
                f[grid_idx(g, i, j, k)] = sample(src, ns, hs, off, x);
            }
}

int initial_state_load(const char *path, struct march_state *st, char *err, size_t errlen)
{
    char file[600], cause[800];
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        snprintf(file, sizeof file, "%s/%s", path, CHECKPOINT_NAME);
    else
        snprintf(file, sizeof file, "%s", path);
    const struct grid *g = &st->g;
    int ns[3];
    double len[3], hs[3];
    if (checkpoint_read_grid(file, ns, len, cause, sizeof cause) != 0) {
        snprintf(err, errlen, "solver.initial_state: %s", cause);
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        double mine = g->n[d] * g->h[d];
        if (fabs(len[d] - mine) > SAME_BOX * mine) {
            snprintf(err, errlen,
                     "solver.initial_state: %s holds a box of %g x %g x %g, this case's is "
                     "%g x %g x %g (the same box is needed)",
                     file, len[0], len[1], len[2], g->n[0] * g->h[0], g->n[1] * g->h[1],
                     g->n[2] * g->h[2]);
            return -1;
        }
        hs[d] = len[d] / ns[d];
    }
    double *src = malloc((size_t)(ns[0] + 2) * (ns[1] + 2) * (ns[2] + 2) * sizeof *src);
    if (!src) {
        snprintf(err, errlen, "solver.initial_state: out of memory for %s", file);
        return -1;
    }
    const struct field_registry *r = &st->fields;
    int rc = 0;
    for (int e = 0; rc == 0 && e < r->count; e++) {
        const struct field_entry *fe = &r->e[e];
        if (!(fe->spec.flags & FIELD_CHECKPOINT))
            continue;
        if (fe->spec.where != FIELD_CELLS && fe->spec.where != FIELD_FACES) {
            snprintf(err, errlen, "solver.initial_state: the field %s is neither on cells nor "
                                  "on faces", fe->spec.name);
            rc = -1;
            break;
        }
        int n = field_arrays(fe->spec.where);
        for (int c = 0; rc == 0 && c < n; c++) {
            char name[96];
            checkpoint_dataset_name(&fe->spec, c, name, sizeof name);
            if ((fe->spec.flags & FIELD_START_OPTIONAL) && checkpoint_has_dataset(file, name) == 0)
                break;
            if (checkpoint_read_dataset(file, name, ns, src, cause, sizeof cause) != 0) {
                snprintf(err, errlen, "solver.initial_state: %s", cause);
                rc = -1;
                break;
            }
            /* cells at the centres; component c of the faces on the faces
             * normal to c */
            double off[3];
            for (int d = 0; d < 3; d++)
                off[d] = fe->spec.where == FIELD_FACES && d == c ? 0.0 : 0.5;
            interpolate(src, ns, hs, off, g, fe->v[c]);
        }
    }
    free(src);
    /* a body's nodes stay at rest (the coarse grid's wall is elsewhere) */
    if (rc == 0 && st->embedded)
        embedded_zero(st->embedded, st->vel);
    return rc;
}
