/* A run started from a checkpoint on another grid (initial_state.h). */
#include "io/initial_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "io/checkpoint.h"
#include "kernels/embedded.h"
#include "march/march.h"

/* Relative difference of box lengths taken as the same box (a length
 * written to the case file with 17 digits comes back to the last bit). */
#define SAME_BOX 1e-12

/* The source node below x along direction d and the share of the way to
 * the next, the nodes at (index + off) h (off 0: faces, 1/2: centres) on a
 * uniform direction or at the faces or centres of a stretched one, the
 * index held within the source's slots -1 .. n (its ghost layer at the
 * ends). */
static void bracket(const struct grid *gs, int d, double off, double x, int *i0, double *w)
{
    const int n = gs->n[d];
    if (!gs->axis[d]) {
        double t = fmin(fmax(x / gs->h[d] - off, -1.0), (double)n);
        *i0 = (int)floor(t);
        if (*i0 > n - 1)
            *i0 = n - 1;
        *w = t - *i0;
        return;
    }
    const int faces = off == 0.0;
    if (x <= (faces ? grid_xf(gs, d, -1) : grid_xc(gs, d, -1))) {
        *i0 = -1, *w = 0.0;
        return;
    }
    if (x >= (faces ? grid_xf(gs, d, n) : grid_xc(gs, d, n))) {
        *i0 = n - 1, *w = 1.0;
        return;
    }
    grid_bracket(gs, d, faces, x, i0, w); /* inside: i0 in -1 .. n - 1 */
}

/* The value at x of a source array on grid gs: trilinear between the
 * nodes around x. */
static double sample(const double *src, const struct grid *gs, const double off[3],
                     const double x[3])
{
    int i0[3];
    double w[3];
    for (int d = 0; d < 3; d++)
        bracket(gs, d, off[d], x[d], &i0[d], &w[d]);
    const int *ns = gs->n;
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
 * march fills them again), the nodes of both at their faces or centres; g
 * a block of the whole grid gg whose cell 0 is gg's lo (a rank's; gg = g,
 * lo = 0 on one process): the positions gg's, as one process takes them. */
static void interpolate(const double *src, const struct grid *gs, const double off[3],
                        const struct grid *g, const struct grid *gg, const int lo[3], double *f)
{
    for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const int idx[3] = {i, j, k};
                double x[3];
                for (int d = 0; d < 3; d++) /* off: 0 at faces, 1/2 at centres */
                    x[d] = off[d] == 0.0 ? grid_xf(gg, d, idx[d] + lo[d])
                                         : grid_xc(gg, d, idx[d] + lo[d]);
                f[grid_idx(g, i, j, k)] = sample(src, gs, off, x);
            }
}

/* The source's stretched directions, rebuilt from the keys it was run with
 * (domain.<d>_band, growth, the far count n<d>, a periodic low face) as the
 * march built them.  Returns 0, or -1 with err. */
static int source_axes(const char *file, struct grid *gs, struct grid_axis ax[3], char *err,
                       size_t errlen)
{
    static const char xyz[3] = {'x', 'y', 'z'};
    for (int d = 0; d < 3; d++) {
        char key[48], text[160];
        snprintf(key, sizeof key, "domain.%c_band", xyz[d]);
        struct grid_band b[GRID_BANDS_MAX];
        int nb = checkpoint_read_key(file, key, text, sizeof text) == 0
                     ? grid_bands_parse(text, b, GRID_BANDS_MAX)
                     : 0;
        if (nb <= 0)
            continue; /* uniform (or from before the bands) */
        char nt[48], gt[48], bt[48];
        snprintf(key, sizeof key, "domain.n%c", xyz[d]);
        int okn = checkpoint_read_key(file, key, nt, sizeof nt) == 0;
        int okg = checkpoint_read_key(file, "domain.growth", gt, sizeof gt) == 0;
        snprintf(key, sizeof key, "boundary.%clo", xyz[d]);
        int okb = checkpoint_read_key(file, key, bt, sizeof bt) == 0;
        char why[300] = "its keys domain.n<d>, domain.growth or boundary.<d>lo are missing";
        int bad = !okn || !okg || !okb ||
                  grid_axis_build_bands(&ax[d], gs->len[d], gs->len[d] / atoi(nt), b, nb,
                                        strtod(gt, NULL), strcmp(bt, "periodic") == 0, why,
                                        sizeof why) != 0;
        if (!bad && ax[d].n != gs->n[d]) {
            snprintf(why, sizeof why, "%d cells from its keys, %d in its fields", ax[d].n,
                     gs->n[d]);
            bad = 1;
        }
        if (!bad && grid_set_axis(gs, d, &ax[d]) != 0) {
            snprintf(why, sizeof why, "out of memory");
            bad = 1;
        }
        if (bad) {
            snprintf(err, errlen,
                     "solver.initial_state: %s: its stretched %c direction cannot be rebuilt "
                     "(%s)",
                     file, xyz[d], why);
            return -1;
        }
    }
    return 0;
}

int initial_state_load(const char *path, struct march_state *st, char *err, size_t errlen)
{
    char file[600], cause[800];
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        snprintf(file, sizeof file, "%s/%s", path, CHECKPOINT_NAME);
    else
        snprintf(file, sizeof file, "%s", path);
    /* the box and the positions: the whole grid's (every rank reads the
     * whole source and takes its block's nodes) */
    const struct grid *g = march_global_grid(st);
    int lo[3] = {0, 0, 0};
    for (int d = 0; st->ranks && d < 3; d++)
        lo[d] = st->ranks->dc.lo[d];
    int ns[3];
    double len[3];
    if (checkpoint_read_grid(file, ns, len, cause, sizeof cause) != 0) {
        snprintf(err, errlen, "solver.initial_state: %s", cause);
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        double mine = g->axis[d] ? g->len[d] : g->n[d] * g->h[d];
        if (fabs(len[d] - mine) > SAME_BOX * mine) {
            snprintf(err, errlen,
                     "solver.initial_state: %s holds a box of %g x %g x %g, this case's is "
                     "%g x %g x %g (the same box is needed)",
                     file, len[0], len[1], len[2], g->len[0], g->len[1], g->len[2]);
            return -1;
        }
    }
    struct grid gs;
    struct grid_axis ax[3];
    memset(ax, 0, sizeof ax);
    if (grid_init(&gs, ns, len) != 0) {
        snprintf(err, errlen, "solver.initial_state: %s: not a grid", file);
        return -1;
    }
    if (source_axes(file, &gs, ax, err, errlen) != 0) {
        for (int d = 0; d < 3; d++)
            grid_axis_free(&ax[d]);
        return -1;
    }
    double *src = malloc((size_t)(ns[0] + 2) * (ns[1] + 2) * (ns[2] + 2) * sizeof *src);
    if (!src) {
        snprintf(err, errlen, "solver.initial_state: out of memory for %s", file);
        for (int d = 0; d < 3; d++)
            grid_axis_free(&ax[d]);
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
            interpolate(src, &gs, off, &st->g, g, lo, fe->v[c]);
        }
    }
    free(src);
    for (int d = 0; d < 3; d++)
        grid_axis_free(&ax[d]);
    /* a body's nodes stay at rest (the coarse grid's wall is elsewhere) */
    if (rc == 0 && st->embedded)
        embedded_zero(st->embedded, st->field.velocity);
    return rc;
}
