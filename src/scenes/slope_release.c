/* Scene "slope_release": a column of grains released at rest on an incline
 * that bends through a circular arc into a level run-out, under air (the
 * set-up Barker & Rauter 2018, "Two-fluid regularised mu(I)-rheology with
 * OpenFOAM", plan in their sec. 4.1; cases/slope_release.ini).  The bed is
 * the ground below `[obstacle] shapes = slope AC BR THETA R` with
 * `obstacle.boundary = cells`: a cell whose centre lies in the ground is
 * solid, so no cell is cut and the VOF tracer's fluxes are the projection's
 * (the grains' volume is kept to round-off); no slip on the bed.
 *
 * The column is a rectangle in the incline's frame: from arc length s_back
 * down the bed, column_length long and column_height deep normal to it.
 * The two phases and the pressure's gauge are the collapse's (the two_phase
 * module, the top at -rho_f g lz).  Measured every step along the bed's arc
 * length s (from x = 0): the front and the tail (the extreme s of the
 * T = 1/2 contour, its points projected on the bed), the s behind which 99 %
 * of the grains lie, the kinetic energy and the grains' volume; per cell, whether the grains there ever yielded (I
 * above the I where the friction curve reaches mu_s).  At the end the
 * depth-averaged model (diagnostics/depth_averaged.h) runs the same release
 * on the same bed (1D along s, the arc through its local slope), with
 * Pouliquen's friction matched to the case's mu(I) through Bagnold's
 * profile, and both run-outs and times to rest go to the summary. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/depth_averaged.h"
#include "grid/shapes.h"
#include "io/output.h"
#include "physics/two_phase.h"
#include "scenes/scene.h"
#include "scenes/recorded_drive.h"
#include "scene_common.h"
#include "scenes/two_phase_keys.h"
#include "scenes/da_match.h"

struct slope_params {
    double s_back;        /* arc length of the column's back along the bed */
    double column_length; /* along the incline */
    double column_height; /* normal to it */
    double fluid_density;
    double fluid_viscosity;
    double rest_energy;
    double vof_cfl;
    int mixture;
    int da_cells;
};

#define T struct slope_params
static const struct key slope_keys[] = {
    KEY_DBL(T, "slope_release", "s_back", s_back,
            KEY_HELP("arc length along the bed from x = 0 to the column's back; the column "
                     "lies on the straight incline",
                     "length", NULL),
            KEY_GE0),
    KEY_DBL(T, "slope_release", "column_length", column_length,
            KEY_HELP("length of the column along the incline: at least a cell", "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "slope_release", "column_height", column_height,
            KEY_HELP("depth of the column normal to the incline: at least a cell, its top "
                     "inside the box",
                     "length", NULL),
            KEY_GT0),
    TWO_PHASE_KEY_FLUID_DENSITY(T, "slope_release"),
    TWO_PHASE_KEY_FLUID_VISCOSITY(T, "slope_release"),
    KEY_DBL(T, "slope_release", "rest_energy", rest_energy,
            "at rest when the kinetic energy falls below this fraction of its peak (both "
            "models); the run then ends; 0: only at solver.end_time",
            KEY_RANGE(0.0, 1.0, 1, 0)),
    TWO_PHASE_KEY_VOF_CFL(T, "slope_release"),
    TWO_PHASE_KEY_MIXTURE(T, "slope_release", ""),
    KEY_INT(T, "slope_release", "da_cells", da_cells,
            "cells of the depth-averaged model along the bed, from x = 0 to the box's end",
            KEY_RANGE(16, 1e6, 1, 1)),
};
#undef T

static void defaults(void *block)
{
    struct slope_params *p = block;
    p->s_back = 0.01;
    p->column_length = 0.02;
    p->column_height = 0.01;
    p->fluid_density = 1.0;
    p->fluid_viscosity = 1.48e-5;
    p->rest_energy = 0.05;
    p->vof_cfl = 0.4;
    p->mixture = MIXTURE_WEIGHTED;
    p->da_cells = 2000;
}

SCENE_PARAMS(slope_block, "slope_release",
             "A column of grains released at rest on an incline bent by a circular arc into a "
             "level run-out, under a light phase (`cases/slope_release.ini`).  The bed is the "
             "one `slope` shape of `[obstacle] shapes` with `obstacle.boundary = cells`; the "
             "grains are the case's `[rheology]` (mu(I)) with `physics.density` their bulk "
             "density.  The scene needs `solver.mode = transient`, no tilt, `xlo` and `xhi` "
             "walls, `zlo = wall`, `zhi = surface` or `open`, periodic y, `domain.ny = 1` and "
             "an unstretched grid.  It writes `slope_release.csv` (every step: t, the front "
             "(the T = 1/2 contour's farthest point) and tail as arc length along the bed, "
             "kinetic energy, grains' volume, the s behind which 99 % of it lies), "
             "`deposit.csv` (the final grains' columns), `depth_averaged.csv` and "
             "`depth_averaged_deposit.csv` (the depth-averaged model on the same bed); the "
             "summary has both run-outs and times to rest, the volume's error and the area "
             "that never yielded.",
             struct slope_params, slope_keys, defaults)

/* ---- the bed: arc length s along the slope shape ---- */

struct bed {
    double ac, br, th, r; /* the shape's */
    double z0;            /* the bed's height at x = 0 */
    double at, bt;        /* the incline's end, where the arc starts */
    double s_arc, s_floor; /* s at the arc's start and at the floor's */
};

static void bed_of(const struct shape *sh, struct bed *b)
{
    b->ac = sh->v[0], b->br = sh->v[1], b->th = sh->v[2], b->r = sh->v[3];
    b->at = b->ac - b->r * sin(b->th);
    b->bt = b->br + b->r * (1.0 - cos(b->th));
    b->z0 = shape_slope_bed(sh, 0.0);
    b->s_arc = b->at / cos(b->th);
    b->s_floor = b->s_arc + b->r * b->th;
}

/* The case's one slope shape, or NULL. */
static const struct shape *slope_shape(const struct muflow_case *c, struct shape_set *set)
{
    case_obstacle_shapes(c, set);
    if (set->n != 1 || set->s[0].kind != SHAPE_SLOPE)
        return NULL;
    return &set->s[0];
}

/* The bed's slope angle at arc length s. */
static double bed_angle(const struct bed *b, double s)
{
    if (s <= b->s_arc)
        return b->th;
    if (s >= b->s_floor)
        return 0.0;
    return b->th - (s - b->s_arc) / b->r;
}

/* The point of the bed at arc length s and its upward normal. */
static void bed_point(const struct bed *b, double s, double x[2], double n[2])
{
    double z = bed_angle(b, s);
    n[0] = sin(z), n[1] = cos(z);
    if (s <= b->s_arc) {
        x[0] = s * cos(b->th), x[1] = b->z0 - s * sin(b->th);
    } else if (s >= b->s_floor) {
        x[0] = b->ac + (s - b->s_floor), x[1] = b->br;
    } else {
        x[0] = b->ac - b->r * n[0], x[1] = b->br + b->r - b->r * n[1];
    }
}

/* The arc length of the bed point nearest (x, z): the nearest of the
 * incline's, the arc's and the floor's. */
static double bed_s(const struct bed *b, double x, double z)
{
    double best = INFINITY, s = 0.0;
    /* the incline: s = projection on its direction, within [0, s_arc] */
    double si = fmin(fmax(x * cos(b->th) - (z - b->z0) * sin(b->th), 0.0), b->s_arc);
    double p[2], n[2];
    bed_point(b, si, p, n);
    double d = hypot(x - p[0], z - p[1]);
    if (d < best)
        best = d, s = si;
    /* the arc: the angle of the point about the centre, clamped */
    double phi = atan2(x - b->ac, (b->br + b->r) - z); /* 0 below the centre, -theta at start */
    double sa = b->s_arc + b->r * (fmin(fmax(phi, -b->th), 0.0) + b->th);
    bed_point(b, sa, p, n);
    d = hypot(x - p[0], z - p[1]);
    if (d < best)
        best = d, s = sa;
    double sf = b->s_floor + fmax(x - b->ac, 0.0);
    bed_point(b, sf, p, n);
    d = hypot(x - p[0], z - p[1]);
    if (d < best)
        s = sf;
    return s;
}

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct slope_params *p = params(c);
    if (c->rheo.law != LAW_MUI || c->mode != MODE_TRANSIENT || c->tilt != 0.0) {
        snprintf(msg, msglen, "case.scene = slope_release needs rheology.law = mui, "
                              "solver.mode = transient and physics.tilt = 0 (the bed's shape "
                              "is the slope)");
        return 1;
    }
    const struct boundary *b = &c->bc;
    if (b->face[0][0] != BC_WALL || b->face[0][1] != BC_WALL || b->face[2][0] != BC_WALL ||
        (b->face[2][1] != BC_SURFACE && b->face[2][1] != BC_OPEN) ||
        b->face[1][0] != BC_PERIODIC || c->n[1] != 1) {
        snprintf(msg, msglen, "case.scene = slope_release needs boundary.xlo = xhi = wall, "
                              "boundary.zlo = wall, boundary.zhi = surface or open, "
                              "boundary.ylo = yhi = periodic and domain.ny = 1");
        return 1;
    }
    struct shape_set set;
    const struct shape *sh = slope_shape(c, &set);
    if (!sh || c->obstacle.plane != 0 || c->obstacle.invert ||
        c->obstacle.boundary != OBSTACLE_CELLS) {
        snprintf(msg, msglen, "case.scene = slope_release needs obstacle.shapes = one 'slope "
                              "AC BR THETA R' (the bed), obstacle.plane = xz, obstacle.invert "
                              "= off and obstacle.boundary = cells (the VOF tracer needs whole "
                              "cells)");
        return 1;
    }
    struct bed bd;
    bed_of(sh, &bd);
    double hx = c->len[0] / c->n[0], hz = c->len[2] / c->n[2];
    if (!(bd.at > 0.0 && bd.ac < c->len[0])) {
        snprintf(msg, msglen, "obstacle.shapes: the slope's arc must start inside the box "
                              "(AC - R sin THETA = %.6g > 0) and meet the floor inside it (AC = "
                              "%.6g < domain.lx = %s)",
                 bd.at, bd.ac, num_text(c->len[0]).s);
        return 1;
    }
    if (!scene_at_least_a_cell(p->column_length, fmax(hx, hz)) ||
        p->s_back + p->column_length > bd.s_arc) {
        snprintf(msg, msglen, "slope_release.column_length = %s with s_back = %s: must be at "
                              "least a cell (%.6g) and end on the straight incline (s_back + "
                              "column_length <= %.6g)",
                 num_text(p->column_length).s, num_text(p->s_back).s, fmax(hx, hz), bd.s_arc);
        return 1;
    }
    /* the column's highest point: its back's top corner */
    double top = bd.z0 - p->s_back * sin(bd.th) + p->column_height * cos(bd.th);
    if (!scene_at_least_a_cell(p->column_height, fmax(hx, hz)) || !(top < c->len[2] - hz)) {
        snprintf(msg, msglen, "slope_release.column_height = %s: must be at least a cell "
                              "(%.6g) and its top (z = %.6g) a cell below domain.lz = %s",
                 num_text(p->column_height).s, fmax(hx, hz), top, num_text(c->len[2]).s);
        return 1;
    }
    return 0;
}

/* ---- the record ---- */

/* VOLUME_SHARE of the grains lie at or behind front99 along the bed: a
 * front that a film thinner than a cell does not move */
#define VOLUME_SHARE 0.99

struct sample {
    double t, front, tail, kinetic, volume, t_min, t_max, front99;
};

struct da_run {
    long n;
    double ds, *h, *m;
    double front, tail, rest_time, peak, volume0, volume, front99;
    struct sample *s; /* t, front, tail, kinetic, volume */
    long ns;
};

struct record {
    struct sample *s;
    long n, cap, last_step;
    double peak, rest_time, volume0;
    unsigned char *solid, *yielded; /* per cell (n[0] n[2]) */
    double *cell_s;                 /* per cell: the arc length of its centre's bed point */
    double *bins, bin_ds;           /* the grains' volume per interval of s */
    long nbins;
    struct bed bed;
    struct da_run da; /* the depth-averaged model's, at step da_step */
    long da_step;
    /* on ranks: the whole grid's T, p and |D|^2 gathered for the measures
     * (whole_fields; T the last gathered, deposit.csv's), decomp_gather's
     * scratch */
    double *whole[3], *scratch;
};

static void destroy(void *state);

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    const struct grid *g = march_global_grid(st); /* the records are the whole grid's */
    struct record *r = calloc(1, sizeof *r);
    size_t nc = (size_t)g->n[0] * g->n[2];
    if (r && st->ranks) {
        int ok = (r->scratch = malloc(decomp_gather_len(&st->ranks->dc) * sizeof(double))) != NULL;
        for (int f = 0; f < 3; f++)
            ok &= (r->whole[f] = field_alloc(g)) != NULL;
        if (!ok) {
            destroy(r);
            r = NULL;
        }
    }
    if (r) {
        r->solid = calloc(2 * nc, 1);
        r->cell_s = malloc(nc * sizeof *r->cell_s);
        r->bin_ds = 0.25 * fmin(g->h[0], g->h[2]);
        r->nbins = (long)(hypot(st->cs->len[0], st->cs->len[2]) * 2.0 / r->bin_ds) + 1;
        r->bins = malloc((size_t)r->nbins * sizeof *r->bins);
    }
    if (!r || !r->solid || !r->cell_s || !r->bins) {
        if (r) {
            free(r->solid);
            free(r->cell_s);
            free(r->bins);
        }
        free(r);
        snprintf(err, errlen, "slope_release: out of memory");
        return -1;
    }
    r->yielded = r->solid + nc;
    r->last_step = -1;
    r->da_step = -1;
    r->rest_time = NAN;
    struct shape_set set;
    const struct shape *sh = slope_shape(st->cs, &set);
    bed_of(sh, &r->bed);
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++) {
            double x[3] = {(i + 0.5) * g->h[0], 0.0, (k + 0.5) * g->h[2]};
            r->solid[(size_t)i * g->n[2] + k] = shape_distance(&set, x) <= 0.0;
            r->cell_s[(size_t)i * g->n[2] + k] = bed_s(&r->bed, x[0], x[2]);
        }
    *state = r;
    return 0;
}

static void destroy(void *state)
{
    struct record *r = state;
    if (r) {
        free(r->s);
        free(r->solid);
        free(r->cell_s);
        free(r->bins);
        free(r->da.h);
        free(r->da.s);
        for (int f = 0; f < 3; f++)
            field_free(r->whole[f]);
        free(r->scratch);
    }
    free(r);
}

/* The dynamic pressure's mean over the top layer of cells set to 0 (the
 * collapse's: the top is at the gauge's pressure). */
static void end_step(struct march_state *st, void *state, double dt)
{
    (void)state;
    (void)dt;
    recorded_drive_gauge_top(st);
}

static const struct module slope_module = {
    .name = "slope_release",
    .create = create,
    .end_step = end_step,
    .destroy = destroy,
};

static struct record *record_of(const struct march_state *st)
{
    return march_module_state(st, &slope_module);
}

static const double *tracer(const struct march_state *st)
{
    int t = fields_find(&st->fields, "tracer");
    return t >= 0 ? st->fields.e[t].v[0] : NULL;
}

/* The whole grid's T, and with all its pressure and |D|^2 (*pr, *sh): the
 * march's own on one process, on ranks every block gathered into r->whole
 * (collective).  NULL without a tracer. */
static const double *whole_fields(struct record *r, const struct march_state *st, int all,
                                  const double **pr, const double **sh)
{
    const double *f[3] = {tracer(st), st->field.pressure_regularised, st->field.shear2};
    if (!f[0])
        return NULL;
    for (int q = 0; st->ranks && q < (all ? 3 : 1); q++) {
        decomp_gather(&st->ranks->dc, &st->g, f[q], &st->ranks->global, r->whole[q],
                      r->scratch);
        f[q] = r->whole[q];
    }
    if (all) {
        *pr = f[1];
        *sh = f[2];
    }
    return f[0];
}

/* The front's and tail's candidates: where T crosses 1/2 between two fluid
 * cells (a solid neighbour is the bed, not the grains' edge), along x and
 * along z, the crossing projected on the bed. */
static void crossings(const struct record *r, const struct grid *g, const double *T,
                      double *front, double *tail)
{
    const int nz = g->n[2];
    for (int d = 0; d < 3; d += 2)
        for (int i = 0; i + (d == 0) < g->n[0]; i++)
            for (int k = 0; k + (d == 2) < nz; k++) {
                int i1 = i + (d == 0), k1 = k + (d == 2);
                if (r->solid[(size_t)i * nz + k] || r->solid[(size_t)i1 * nz + k1])
                    continue;
                double a = T[grid_idx(g, i, 0, k)], b = T[grid_idx(g, i1, 0, k1)];
                if ((a >= 0.5) == (b >= 0.5))
                    continue;
                double w = (a - 0.5) / (a - b);
                double x = (i + 0.5 + (d == 0) * w) * g->h[0];
                double z = (k + 0.5 + (d == 2) * w) * g->h[2];
                double s = bed_s(&r->bed, x, z);
                *front = fmax(*front, s);
                *tail = fmin(*tail, s);
            }
}

/* The s at which the cumulated volume of n intervals of width ds from 0
 * reaches share of the whole, linear inside an interval. */
static double volume_front(const double *v, long n, double ds, double share)
{
    double total = 0.0, sum = 0.0;
    for (long i = 0; i < n; i++)
        total += v[i];
    for (long i = 0; i < n; i++) {
        if (v[i] > 0.0 && sum + v[i] >= share * total)
            return (i + (share * total - sum) / v[i]) * ds;
        sum += v[i];
    }
    return n * ds;
}

static void measure(struct record *r, const struct march_state *st, struct sample *s)
{
    const struct grid *g = march_global_grid(st);
    const double *pres = NULL, *shear2 = NULL, *T = whole_fields(r, st, 1, &pres, &shear2);
    s->t = st->time;
    s->front = -INFINITY;
    s->tail = INFINITY;
    crossings(r, g, T, &s->front, &s->tail);
    s->t_min = INFINITY;
    s->t_max = -INFINITY;
    double vol = 0.0;
    for (long b = 0; b < r->nbins; b++)
        r->bins[b] = 0.0;
    /* yielded: grains (T >= 1/2) whose I passed the I where the curve
     * reaches mu_s (0 for the jop curve: any motion) */
    const struct rheology *rh = &st->cs->rheo;
    double i_s = rh->curve == CURVE_BARKER_GRAY ? rh->a_minus * exp(-rh->alpha / (rh->mu_s * rh->mu_s))
                                                : 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++) {
            ptrdiff_t p = grid_idx(g, i, 0, k);
            double t = T[p];
            vol += t;
            long b = (long)(r->cell_s[(size_t)i * g->n[2] + k] / r->bin_ds);
            r->bins[b < 0 ? 0 : b >= r->nbins ? r->nbins - 1 : b] += t;
            s->t_min = fmin(s->t_min, t);
            s->t_max = fmax(s->t_max, t);
            double pr = pres[p];
            if (t >= 0.5 && pr > 0.0 &&
                sqrt(shear2[p]) * rh->grain_diameter * sqrt(rh->grain_density / pr) >
                    i_s)
                r->yielded[(size_t)i * g->n[2] + k] = 1;
        }
    s->volume = vol * g->h[0] * g->h[2];
    s->front99 = volume_front(r->bins, r->nbins, r->bin_ds, VOLUME_SHARE);
    double ke = 0.0;
    for (int c = 0; c < 3; c += 2) { /* this block's faces, summed over the ranks */
        const struct box *b = &st->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int k = b->lo[2]; k < b->hi[2]; k++) {
                ptrdiff_t p = grid_idx(&st->g, i, 0, k);
                ke += 0.5 * st->field.density_faces[c][p] * st->field.velocity[c][p] *
                      st->field.velocity[c][p];
            }
    }
    s->kinetic = (st->ranks ? march_sum(st, ke) : ke) * g->h[0] * g->h[2];
}

static int record_step(void *rec, const struct march_state *st)
{
    struct record *r = rec;
    if (!tracer(st) || st->step == r->last_step)
        return 0;
    if (r->n == r->cap) {
        long c = r->cap ? 2 * r->cap : 1024;
        struct sample *s = realloc(r->s, (size_t)c * sizeof *s);
        if (!s)
            return -1;
        r->s = s;
        r->cap = c;
    }
    struct sample *s = &r->s[r->n++];
    measure(r, st, s);
    r->last_step = st->step;
    if (r->n == 1)
        r->volume0 = s->volume;
    r->peak = fmax(r->peak, s->kinetic);
    return 0;
}

/* ---- the driver: the march until end_time or rest ---- */

static void energy(const void *rec, double *kinetic, double *peak, double *peak_time)
{
    const struct record *r = rec;
    *kinetic = r->n > 0 ? r->s[r->n - 1].kinetic : NAN;
    *peak = r->peak;
    *peak_time = NAN;
}

static int drive(struct scene_drive *d)
{
    struct march_state *st = d->st;
    struct recorded_drive rd = {.record_step = record_step,
                            .energy = energy,
                            .rec = record_of(st),
                            .rest_fraction = params(st->cs)->rest_energy,
                            .record_name = "the slope's record"};
    recorded_drive_run(d, &rd);
    if (rd.at_rest)
        record_of(st)->rest_time = st->time;
    return 0;
}

static const char *not_restartable(const struct muflow_case *cs)
{
    (void)cs;
    return "a slope release cannot continue from a checkpoint (its record of the front, the "
           "tail and where the grains yielded covers the run from the release): run it again";
}

/* ---- the depth-averaged model on the same bed ---- */


/* The extremes of the cells deeper than a grain, and the layer's kinetic
 * energy per unit density. */
static void da_measure(struct da_run *a, double d, double t, struct sample *s)
{
    s->t = t;
    s->front = -INFINITY;
    s->tail = INFINITY;
    s->kinetic = s->volume = 0.0;
    s->front99 = volume_front(a->h, a->n, a->ds, VOLUME_SHARE);
    for (long i = 0; i < a->n; i++) {
        s->volume += a->h[i] * a->ds;
        if (a->h[i] > 1e-12)
            s->kinetic += 0.5 * a->m[i] * a->m[i] / a->h[i] * a->ds;
        if (a->h[i] > d) {
            s->front = fmax(s->front, (i + 1) * a->ds);
            s->tail = fmin(s->tail, i * a->ds);
        }
    }
}

static int da_run(const struct march_state *st, struct da_run *a, char *err, size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    const struct slope_params *p = params(cs);
    const struct record *r = record_of(st);
    const struct bed *b = &r->bed;
    memset(a, 0, sizeof *a);
    a->n = p->da_cells;
    a->ds = (b->s_floor + (cs->len[0] - b->ac)) / a->n;
    double *zeta = malloc((size_t)a->n * sizeof *zeta);
    a->h = calloc(2 * (size_t)a->n, sizeof *a->h);
    a->m = a->h ? a->h + a->n : NULL;
    if (!zeta || !a->h) {
        free(zeta);
        snprintf(err, errlen, "depth-averaged model: out of memory");
        return -1;
    }
    for (long i = 0; i < a->n; i++) {
        double s = (i + 0.5) * a->ds;
        zeta[i] = bed_angle(b, s);
        /* the column: the cells' share of [s_back, s_back + length] */
        double lo = fmax(i * a->ds, p->s_back), hi = fmin((i + 1) * a->ds, p->s_back + p->column_length);
        a->h[i] = hi > lo ? p->column_height * (hi - lo) / a->ds : 0.0;
    }
    struct da_params dp = da_params_matched(cs);
    struct da_bc wall = {.kind = DA_BC_WALL};
    char why[256];
    struct da_solver *so = da_create(a->n, 0.0, a->ds, zeta, &dp, wall, wall, why, sizeof why);
    free(zeta);
    if (!so) {
        snprintf(err, errlen, "%s", why);
        return -1;
    }
    /* samples every 1/1000 of the end time, to the 2D run's end time or rest */
    double t = 0.0, every = cs->end_time / 1000.0;
    long cap = 1002;
    a->s = malloc((size_t)cap * sizeof *a->s);
    if (!a->s) {
        da_free(so);
        snprintf(err, errlen, "depth-averaged model: out of memory");
        return -1;
    }
    a->rest_time = NAN;
    da_measure(a, cs->rheo.grain_diameter, t, &a->s[a->ns++]);
    a->volume0 = a->s[0].volume;
    int rc = 0;
    while (t < cs->end_time * (1.0 - 1e-12) && a->ns < cap) {
        if (da_advance(so, a->h, a->m, t, t + every) < 0) {
            snprintf(err, errlen, "depth-averaged model: the state is not finite at t = %g", t);
            rc = -1;
            break;
        }
        t += every;
        struct sample *s = &a->s[a->ns++];
        da_measure(a, cs->rheo.grain_diameter, t, s);
        a->peak = fmax(a->peak, s->kinetic);
        if (p->rest_energy > 0.0 && s->kinetic < p->rest_energy * a->peak) {
            a->rest_time = t;
            break;
        }
    }
    da_free(so);
    const struct sample *e = &a->s[a->ns - 1];
    a->front = e->front, a->tail = e->tail, a->volume = e->volume, a->front99 = e->front99;
    return rc;
}

/* The depth-averaged run of the results and files: once per final state,
 * kept in the record. */
static const struct da_run *da_result(const struct march_state *st)
{
    struct record *r = record_of(st);
    if (r->da_step == st->step)
        return r->da.s ? &r->da : NULL;
    free(r->da.h);
    free(r->da.s);
    char err[256];
    if (da_run(st, &r->da, err, sizeof err) != 0) {
        free(r->da.h);
        free(r->da.s);
        memset(&r->da, 0, sizeof r->da);
    }
    r->da_step = st->step;
    return r->da.s ? &r->da : NULL;
}

/* ---- results and files ---- */

/* The area of the final deposit (T >= 1/2) that never yielded. */
static double never_yielded(struct record *r, const struct march_state *st)
{
    const struct grid *g = march_global_grid(st);
    const double *T = whole_fields(r, st, 0, NULL, NULL); /* deposit.csv's on ranks too */
    double a = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++)
            if (T[grid_idx(g, i, 0, k)] >= 0.5 && !r->yielded[(size_t)i * g->n[2] + k])
                a += g->h[0] * g->h[2];
    return a;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    struct record *r = record_of(st);
    if (!r || r->n == 0)
        return;
    const struct sample *s = &r->s[r->n - 1];
    double lo = INFINITY, hi = -INFINITY;
    for (long m = 0; m < r->n; m++) {
        lo = fmin(lo, r->s[m].t_min);
        hi = fmax(hi, r->s[m].t_max);
    }
    double vol_err = s->volume / r->volume0 - 1.0;
    run_result_add(res, "run_out", "%.10g", s->front);
    run_result_add(res, "run_out_99", "%.10g", s->front99);
    run_result_add(res, "tail", "%.10g", s->tail);
    run_result_add(res, "time_to_rest", "%.10g", r->rest_time);
    run_result_add(res, "volume_error", "%.6e", vol_err);
    run_result_add(res, "never_yielded_area", "%.10g", never_yielded(r, st));
    run_result_add(res, "kinetic_energy_peak", "%.6e", r->peak);
    run_result_add(res, "tracer_min", "%.6e", lo);
    run_result_add(res, "tracer_max_minus_1", "%.6e", hi - 1.0);
    const struct da_run *a = da_result(st);
    if (a) {
        run_result_add(res, "da_run_out", "%.10g", a->front);
        run_result_add(res, "da_run_out_99", "%.10g", a->front99);
        run_result_add(res, "da_tail", "%.10g", a->tail);
        run_result_add(res, "da_time_to_rest", "%.10g", a->rest_time);
        run_result_add(res, "da_volume_error", "%.6e", a->volume / a->volume0 - 1.0);
    }
    snprintf(res->scene_line, sizeof res->scene_line,
             "run-out %.5g (depth-averaged %.5g), at rest t = %.4g (%.4g), volume error %.2e",
             s->front, a ? a->front : NAN, r->rest_time, a ? a->rest_time : NAN, vol_err);
}

static int write_samples(const char *dir, const char *name, const struct sample *s, long n,
                         char *err, size_t errlen)
{
    struct output_file f;
    if (output_open(&f, dir, name, err, errlen) != 0)
        return -1;
    fprintf(f.f, "t,s_front,s_tail,kinetic_energy,grains_volume,s_front_99\n");
    for (long m = 0; m < n; m++)
        fprintf(f.f, "%.10g,%.10g,%.10g,%.10e,%.16e,%.10g\n", s[m].t, s[m].front, s[m].tail,
                s[m].kinetic, s[m].volume, s[m].front99);
    return output_commit(&f, err, errlen);
}

/* slope_release.csv and depth_averaged.csv: the records; deposit.csv: each
 * column's bed (its lowest fluid cell's base) and the grains' depth above
 * it; depth_averaged_deposit.csv: the model's final h(s) and the bed. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    const struct record *r = record_of(st);
    /* on ranks (rank 0 alone writes) the T results() gathered */
    const double *T = !r ? NULL : st->ranks ? r->whole[0] : tracer(st);
    if (!r || !T)
        return 0;
    if (write_samples(dir, "slope_release.csv", r->s, r->n, err, errlen) != 0)
        return -1;
    const struct grid *g = march_global_grid(st);
    struct output_file f;
    if (output_open(&f, dir, "deposit.csv", err, errlen) != 0)
        return -1;
    fprintf(f.f, "x,z_bed,depth\n");
    for (int i = 0; i < g->n[0]; i++) {
        int k0 = 0;
        double h = 0.0;
        while (k0 < g->n[2] && r->solid[(size_t)i * g->n[2] + k0])
            k0++;
        for (int k = k0; k < g->n[2]; k++)
            h += T[grid_idx(g, i, 0, k)] * g->h[2];
        fprintf(f.f, "%.10g,%.10g,%.10g\n", (i + 0.5) * g->h[0], k0 * g->h[2], h);
    }
    if (output_commit(&f, err, errlen) != 0)
        return -1;
    const struct da_run *a = da_result(st);
    if (!a)
        return 0;
    if (write_samples(dir, "depth_averaged.csv", a->s, a->ns, err, errlen) != 0)
        return -1;
    if (output_open(&f, dir, "depth_averaged_deposit.csv", err, errlen) != 0)
        return -1;
    fprintf(f.f, "s,x_bed,z_bed,nx,nz,h\n");
    for (long i = 0; i < a->n; i++) {
        double x[2], n[2];
        bed_point(&r->bed, (i + 0.5) * a->ds, x, n);
        fprintf(f.f, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", (i + 0.5) * a->ds, x[0], x[1],
                n[0], n[1], a->h[i]);
    }
    return output_commit(&f, err, errlen);
}

/* ---- set-up ---- */

/* The share of the fluid cell (i, k) inside the column: 8 x 8 points, each
 * in it when its arc length along the incline is within the column and its
 * height above the incline's line at most column_height (below the line,
 * down to the cell's staircase, is grains too). */
#define COLUMN_SAMPLES 8
static double column_fraction(const struct bed *b, const struct slope_params *p,
                              const struct grid *g, int i, int k)
{
    int in = 0;
    for (int a = 0; a < COLUMN_SAMPLES; a++)
        for (int c = 0; c < COLUMN_SAMPLES; c++) {
            double x = (i + (a + 0.5) / COLUMN_SAMPLES) * g->h[0];
            double z = (k + (c + 0.5) / COLUMN_SAMPLES) * g->h[2];
            double s = x * cos(b->th) - (z - b->z0) * sin(b->th);
            double eta = x * sin(b->th) + (z - b->z0) * cos(b->th);
            in += s >= p->s_back && s <= p->s_back + p->column_length && eta <= p->column_height;
        }
    return (double)in / (COLUMN_SAMPLES * COLUMN_SAMPLES);
}

static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    const struct slope_params *p = params(cs);
    const struct two_phase_params tp = {
        .fluid_density = p->fluid_density,
        .fluid_viscosity = p->fluid_viscosity,
        .mixture = (enum mixture_law)p->mixture,
        .transported = 1,
        .step_cfl = p->vof_cfl,
    };
    double *T = two_phase_configure(st, &tp, err, errlen);
    if (!T)
        return -1;
    /* the collapse's gauge: the light phase's weight presses on no grains */
    st->pressure_gauge = -p->fluid_density * cs->gravity * cs->len[2];
    const struct record *r = record_of(st);
    const struct grid *g = &st->g;
    const int *lo = st->ranks ? st->ranks->dc.lo : (const int[3]){0, 0, 0};
    const int nz = march_global_grid(st)->n[2];
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2]; k++) {
            const int I = lo[0] + i, K = lo[2] + k; /* the whole grid's cell */
            T[grid_idx(g, i, 0, k)] =
                r->solid[(size_t)I * nz + K] ? 0.0 : column_fraction(&r->bed, p, g, I, K);
        }
    return two_phase_tracer_changed(st, err, errlen);
}

static const struct module *const slope_modules[] = {&two_phase_module, &slope_module, NULL};
static const char *const slope_files[] = {"slope_release.csv", "deposit.csv",
                                          "depth_averaged.csv", "depth_averaged_deposit.csv",
                                          NULL};

const struct scene scene_slope_release = {
    .name = "slope_release",
    .title = "granular column released on an incline bent into a level run-out, under air, "
             "beside the depth-averaged model",
    .keys = &slope_block,
    .modules = slope_modules,
    .check = check,
    .setup = setup,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .not_restartable = not_restartable,
    .results = results,
    .write = write,
    .files = slope_files,
    .decomposed = scene_decomposed_always, /* its measures on the gathered fields */
};
