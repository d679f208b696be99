/* Scene "wall_shock": a uniform granular layer fed at the inflow (x = 0)
 * runs down a rough incline under a light fluid (air's density; the case's
 * viscosity: cases/wall_shock.ini) into an impenetrable wall at x = lx; the
 * grains stop against it and a shock travels back up the slope
 * (Barker & Rauter 2018, "Two-fluid regularised mu(I)-rheology with
 * OpenFOAM", sec. 4.3; cases/wall_shock.ini).  The feed, the uniform
 * layer's exact flow and the records are scenes/layer_feed.h's, as in the
 * front scene.
 *
 * Measured at every step, on the column heights h(x) = sum T dz and the
 * grains' fluxes q(x) = sum T u dz: the shock's centre (the steepest rise
 * of h past the feed's FEED_SKIP depths), the upstream depth h1 and speed
 * u1 = q1 / h1 (means over the columns from FEED_SKIP depths past the feed
 * to GAP depths before the centre), the depth h2 and speed u2 = q2 / h2
 * behind (the lines fitted to h and q from GAP depths behind the centre to
 * WALL_SKIP depths from the wall, at the centre: the sharp shock's state
 * behind it, without the few depths over which the resolved shock rises),
 * the shock x_s (where h crosses (h1 + h2) / 2, from upstream) and the
 * static zone (the length from the wall over which every grains' cell,
 * T >= 1/2, moves slower than wall_shock.static_speed u1).
 *
 * The jump conditions of the depth-averaged equations (docs/numerics/
 * depth-averaged.md: h_t + (h u)_x = 0, (h u)_t + (chi h u^2 + g' h^2 /
 * 2)_x = sources, g' = K g cos(zeta), K = 1) across a shock of speed c with
 * the grains at rest behind it (u2 = 0):
 *   mass      c (h2 - h1) = -h1 u1,
 *   momentum  c (0 - h1 u1) = g' h2^2 / 2 - chi h1 u1^2 - g' h1^2 / 2;
 * with r = h2 / h1 and F^2 = u1^2 / (g' h1) they give
 *   2 F^2 (1 + chi (r - 1)) = (r - 1)^2 (r + 1),
 * one root r > 1, and c = -u1 / (r - 1).  Evaluated from the measured h1,
 * u1 (means over the second half of the record), against the measured
 * speed (the slope of x_s(t) over it) and ratio; the mass jump with the
 * measured h2 and u2 as well, c = (h2 u2 - h1 u1) / (h2 - h1), and both
 * jumps with the measured u2 (jump_ratio_moving): the grains behind creep.
 *
 * The grains behind the shock do not stop (u2 = 0.14 u1): on a slope
 * steeper than mu_s a deposit stands only with its surface rising towards
 * the wall, so it must keep filling behind the shock.  The depth-averaged
 * equations themselves, with the friction matched to mu(I) and the same
 * feed and wall (da_shock), show it: their shock is as slow.  Their
 * solution, measured as the scene's columns, is the second reference. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "diagnostics/depth_averaged.h"
#include "io/output.h"
#include "physics/two_phase.h"
#include "scenes/collapse.h"
#include "scenes/layer_feed.h"
#include "scenes/recorded_drive.h"
#include "scenes/scene.h"
#include "scene_common.h"
#include "scenes/two_phase_keys.h"
#include "scenes/da_match.h"

/* the upstream columns start FEED_SKIP depths past the feed and end GAP
 * depths before the shock; behind it the line fitted to h (and to the
 * flux) from GAP depths behind it to WALL_SKIP depths from the wall, at
 * the shock, gives h2 (and q2): the depth-averaged shock's state behind
 * it, without the few depths over which the resolved shock rises */
#define FEED_SKIP 5.0
#define GAP 3.0
#define WALL_SKIP 1.0
/* the box: at least this many depths (the feed's, the upstream columns,
 * the shock and the columns behind it) */
#define MIN_LENGTH 20.0
/* a shock: a rise of h between neighbouring columns of at least this many h1 */
#define SEED_RISE 0.01

struct wall_shock_params {
    double depth;
    double fluid_density;
    double fluid_viscosity;
    int mixture;
    double viscosity_floor;
    double vof_cfl;
    double shape_factor;  /* chi of the momentum jump */
    double static_speed;  /* the static zone's speed, in u1 */
    int da_cells;         /* the depth-averaged model's cells per h1 */
};

#define T struct wall_shock_params
static const struct key wall_shock_keys[] = {
    KEY_DBL(T, "wall_shock", "depth", depth,
            KEY_HELP("depth h1 of the uniform layer fed at the inflow and filling the box at "
                     "t = 0: at least two cells, and three cells of air above it",
                     "length", NULL),
            KEY_GT0),
    TWO_PHASE_KEY_FLUID_DENSITY(T, "wall_shock"),
    TWO_PHASE_KEY_FLUID_VISCOSITY(T, "wall_shock"),
    TWO_PHASE_KEY_MIXTURE(T, "wall_shock", ""),
    TWO_PHASE_KEY_VISCOSITY_FLOOR(T, "wall_shock"),
    TWO_PHASE_KEY_VOF_CFL(T, "wall_shock"),
    KEY_DBL(T, "wall_shock", "shape_factor", shape_factor,
            "shape factor chi of the momentum flux chi h u^2 in the jump conditions (5/4: "
            "Bagnold's profile, 1: a plug)",
            KEY_RANGE(1.0, 1.5, 1, 1)),
    KEY_DBL(T, "wall_shock", "static_speed", static_speed,
            "the static zone behind the shock: grains slower than this share of the upstream "
            "mean speed u1",
            KEY_RANGE(0.0, 0.5, 0, 1)),
    KEY_INT(T, "wall_shock", "da_cells", da_cells,
            "cells of the depth-averaged reference per wall_shock.depth (its speed and depth "
            "ratio change by less than 1.2e-3 from 10 to 80)",
            KEY_RANGE(4, 1000, 1, 1)),
};
#undef T

static void defaults(void *block)
{
    struct wall_shock_params *w = block;
    w->depth = 1.43e-3;
    w->fluid_density = 1.0;
    w->fluid_viscosity = 1.48e-5;
    w->mixture = MIXTURE_WEIGHTED;
    w->viscosity_floor = 1.0;
    w->vof_cfl = 0.4;
    w->shape_factor = 1.25;
    w->static_speed = 0.05;
    w->da_cells = 20;
}

SCENE_PARAMS(wall_shock_block, "wall_shock",
             "A uniform granular layer fed at the inflow (x = 0) runs down a rough incline "
             "under a light fluid into a wall at x = `domain.lx`; a shock travels back up the "
             "slope "
             "(Barker & Rauter 2018, sec. 4.3; `cases/wall_shock.ini`).  Its speed and depth "
             "ratio are compared with the jump conditions of the depth-averaged equations "
             "from the measured upstream depth and speed, and with those equations' own "
             "solution of the same problem (Pouliquen's friction matched to mu(I)).  The "
             "scene needs `solver.mode = "
             "transient`, `boundary.xlo = inflow`, `xhi = wall`, `zlo = wall`, `zhi = open`, "
             "periodic y, `domain.ny = 1` and mu_s < tan(physics.tilt) < mu_s + delta_mu.  It "
             "writes `wall_shock.csv` (every step: t, the shock, h1, h2, u1, u2, the "
             "static zone's length) and `heights.csv` (h(x) at the end).",
             struct wall_shock_params, wall_shock_keys, defaults)

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct wall_shock_params *p = params(c);
    if (layer_feed_check(c, "wall_shock", BC_WALL, "wall", msg, msglen))
        return 1;
    double dz = c->len[2] / c->n[2];
    if (!(scene_at_least_a_cell(p->depth, 2.0 * dz) &&
          scene_at_least_a_cell(c->len[2] - p->depth, 3.0 * dz))) {
        snprintf(msg, msglen, "wall_shock.depth = %s: must be in [%.6g, %.6g]: at least two "
                              "cells (domain.lz / domain.nz = %.6g) and three of air above",
                 num_text(p->depth).s, 2.0 * dz, c->len[2] - 3.0 * dz, dz);
        return 1;
    }
    if (!(c->len[0] >= MIN_LENGTH * p->depth)) {
        snprintf(msg, msglen, "domain.lx = %s: must be at least %.6g (%g wall_shock.depth: "
                              "the feed, the upstream columns, the shock and the layer behind "
                              "it)",
                 num_text(c->len[0]).s, MIN_LENGTH * p->depth, MIN_LENGTH);
        return 1;
    }
    return 0;
}

/* ---- the jump conditions ---- */

/* r = h2 / h1 of the shock to rest: the root r > 1 of
 * (r - 1)^2 (r + 1) = 2 F^2 (1 + chi (r - 1)) (bisection: the left side
 * less the right is negative at r = 1 and grows as r^3) */
static double jump_ratio(double froude2, double chi)
{
    double lo = 1.0, hi = 2.0;
    while ((hi - 1.0) * (hi - 1.0) * (hi + 1.0) < 2.0 * froude2 * (1.0 + chi * (hi - 1.0)))
        hi *= 2.0;
    for (int it = 0; it < 200; it++) {
        double r = 0.5 * (lo + hi);
        if ((r - 1.0) * (r - 1.0) * (r + 1.0) < 2.0 * froude2 * (1.0 + chi * (r - 1.0)))
            lo = r;
        else
            hi = r;
    }
    return 0.5 * (lo + hi);
}

/* r = h2 / h1 of the shock with the grains behind it moving at u2 = w u1:
 * mass c (h2 - h1) = h2 u2 - h1 u1 and momentum c (h2 u2 - h1 u1) =
 * chi (h2 u2^2 - h1 u1^2) + g' (h2^2 - h1^2) / 2 give, with c / u1 =
 * (r w - 1) / (r - 1), the root r > 1 of
 *   (r^2 - 1) (r - 1) = 2 F^2 ((r w - 1)^2 - chi (r w^2 - 1) (r - 1))
 * (the left side less the right: -2 F^2 (1 - w)^2 at r = 1, growing as
 * r^3); w = 0 is jump_ratio's. */
static double jump_residual_moving(double r, double froude2, double chi, double w)
{
    return (r * r - 1.0) * (r - 1.0) -
           2.0 * froude2 * ((r * w - 1.0) * (r * w - 1.0) - chi * (r * w * w - 1.0) * (r - 1.0));
}

static double jump_ratio_moving(double froude2, double chi, double w)
{
    double lo = 1.0, hi = 2.0;
    while (jump_residual_moving(hi, froude2, chi, w) < 0.0)
        hi *= 2.0;
    for (int it = 0; it < 200; it++) {
        double r = 0.5 * (lo + hi);
        if (jump_residual_moving(r, froude2, chi, w) < 0.0)
            lo = r;
        else
            hi = r;
    }
    return 0.5 * (lo + hi);
}

/* ---- the record ---- */

enum { S_T, S_SHOCK, S_H1, S_H2, S_U1, S_U2, S_STATIC, NSERIES };
static const char *const series_names[NSERIES] = {"t", "x_shock", "h1", "h2", "u1", "u2",
                                                  "static_length"};

struct record {
    struct layer_record base; /* the columns S_*, the inflow's layer (the hook's context) */
    /* the domain's column heights and grains' fluxes (nx each, q = h + nx)
     * of the last state recorded, every rank's alike (rank 0 writes h);
     * the columns moving (1) or still (0), work */
    double *h, *q, *moving;
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct record *r = calloc(1, sizeof *r);
    const int nx = march_global_grid(st)->n[0];
    if (r)
        r->h = malloc(3 * (size_t)nx * sizeof *r->h);
    if (!r || !r->h) {
        free(r);
        snprintf(err, errlen, "wall_shock: out of memory");
        return -1;
    }
    const struct wall_shock_params *p = params(st->cs);
    r->q = r->h + nx;
    r->moving = r->q + nx;
    layer_series_init(&r->base.s, NSERIES, series_names);
    r->base.feed = (struct layer_feed){st->cs, p->depth, p->fluid_density, p->fluid_viscosity};
    *state = r;
    return 0;
}

static void destroy(void *state)
{
    struct record *r = state;
    if (r) {
        layer_series_free(&r->base.s);
        free(r->h);
    }
    free(r);
}

static const struct module wall_shock_module = {
    .name = "wall_shock",
    .create = create,
    .end_step = layer_record_end_step,
    .save = layer_record_save,
    .load = layer_record_load,
    .destroy = destroy,
};

static struct record *record_of(const struct march_state *st)
{
    return march_module_state(st, &wall_shock_module);
}

/* ---- the measures of one state ---- */

struct shock_state {
    double x_shock, h1, h2, u1, u2, static_length;
};

/* The first x, from upstream (from column i0 on), where h reaches level;
 * linear between the centres; NAN if none does. */
static double crossing_from_upstream(const double *h, int n, int i0, double dx, double level)
{
    for (int i = i0 + 1; i < n; i++)
        if (h[i] >= level && h[i - 1] < level)
            return (i - 0.5) * dx + dx * (level - h[i - 1]) / (h[i] - h[i - 1]);
    return NAN;
}

/* The mean of h over the columns whose centres lie in [a, b) */
static double mean_over(const double *h, int n, double dx, double a, double b)
{
    double s = 0.0;
    int m = 0;
    for (int i = 0; i < n; i++) {
        double x = (i + 0.5) * dx;
        if (x >= a && x < b) {
            s += h[i];
            m++;
        }
    }
    return m ? s / m : NAN;
}

/* The least-squares line through h over the columns whose centres lie in
 * [a, b), at x0; NAN with fewer than three columns. */
static double line_at(const double *h, int n, double dx, double a, double b, double x0)
{
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    int m = 0;
    for (int i = 0; i < n; i++) {
        double x = (i + 0.5) * dx - x0;
        if (x + x0 >= a && x + x0 < b) {
            sx += x;
            sy += h[i];
            sxx += x * x;
            sxy += x * h[i];
            m++;
        }
    }
    double den = m * sxx - sx * sx;
    return m >= 3 && den > 0.0 ? (sxx * sy - sx * sxy) / den : NAN;
}

/* The grains' velocity at cell (i, k): the mean of its two faces' */
static double cell_u(const struct march_state *st, int i, int k)
{
    const struct grid *g = &st->g;
    return 0.5 * (st->field.velocity[0][grid_idx(g, i, 0, k)] +
                  st->field.velocity[0][grid_idx(g, i + 1, 0, k)]);
}

/* The shock, h1, u1, h2, u2 of the column heights h and fluxes q (n
 * columns of width dx ending at the wall, depth d fed): the scene's and the
 * depth-averaged model's alike; no static zone. */
static void measure_columns(const double *h, const double *q, int n, double dx, double d,
                            struct shock_state *s)
{
    double lx = n * dx, behind_end = lx - WALL_SKIP * d;
    int i0 = (int)(FEED_SKIP * d / dx);
    /* the shock's centre: the steepest rise of h past the feed's columns;
     * h1 the mean upstream of it, h2 the line behind it at it; the shock
     * where h crosses (h1 + h2) / 2 */
    int steep = -1;
    for (int i = i0; i + 1 < n; i++) {
        double rise = h[i + 1] - h[i];
        if (rise > SEED_RISE * d && (steep < 0 || rise > h[steep + 1] - h[steep]))
            steep = i;
    }
    double x = NAN, h1 = NAN, h2 = NAN;
    if (steep >= 0) {
        double xc = (steep + 1.0) * dx;
        h1 = mean_over(h, n, dx, FEED_SKIP * d, xc - GAP * d);
        h2 = line_at(h, n, dx, xc + GAP * d, behind_end, xc);
        if (isfinite(h1) && isfinite(h2) && h2 > h1)
            x = crossing_from_upstream(h, n, i0, dx, 0.5 * (h1 + h2));
    }
    *s = (struct shock_state){.x_shock = x, .h1 = h1, .h2 = h2, .u1 = NAN, .u2 = NAN};
    if (isfinite(x)) {
        s->u1 = mean_over(q, n, dx, FEED_SKIP * d, x - GAP * d) / h1;
        s->u2 = line_at(q, n, dx, x + GAP * d, behind_end, x) / h2;
    }
}

/* The shock's measures of the domain's columns h, q (layer_columns) and
 * the static zone: the columns from the wall whose grains all stand still,
 * each rank's part of a column moving or not (into moving[nx]), the ranks'
 * largest.  Collective. */
static void measure_state(const struct march_state *st, const double *T, const double *h,
                          const double *q, double *moving, struct shock_state *s)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const struct wall_shock_params *p = params(st->cs);
    int n = G->n[0], i0 = scene_block_lo(st, 0);
    measure_columns(h, q, n, G->h[0], p->depth, s);
    double slow = p->static_speed * (isfinite(s->u1) ? s->u1 : 0.0);
    for (int i = 0; i < n; i++)
        moving[i] = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = 0; k < g->n[2] && !moving[i0 + i]; k++)
            moving[i0 + i] = T[grid_idx(g, i, 0, k)] >= 0.5 && fabs(cell_u(st, i, k)) >= slow;
    if (st->ranks)
        march_max_array(st, moving, n);
    int still = 0;
    for (int i = n - 1; i >= 0 && !moving[i]; i--)
        still++;
    s->static_length = still * G->h[0];
}

static int record_step(void *rec, const struct march_state *st)
{
    struct record *r = rec;
    const double *T = collapse_tracer(st);
    if (!T)
        return 0;
    /* this state's columns on every rank (the write's, rank 0's) */
    struct shock_state s;
    layer_columns(st, T, r->h, 1);
    measure_state(st, T, r->h, r->q, r->moving, &s);
    int rc = layer_series_row(&r->base.s, st->step);
    if (rc != 0)
        return rc > 0 ? 0 : -1;
    double **v = r->base.s.v;
    long n = r->base.s.n - 1;
    v[S_T][n] = st->time;
    v[S_SHOCK][n] = s.x_shock;
    v[S_H1][n] = s.h1;
    v[S_H2][n] = s.h2;
    v[S_U1][n] = s.u1;
    v[S_U2][n] = s.u2;
    v[S_STATIC][n] = s.static_length;
    return 0;
}

/* ---- the driver ---- */

static int drive(struct scene_drive *d)
{
    struct recorded_drive rd = {.record_step = record_step,
                                .rec = record_of(d->st),
                                .record_name = "the wall shock's record"};
    recorded_drive_run(d, &rd);
    return 0;
}

/* ---- the measures at the end ---- */

struct shock_measures {
    double speed;            /* upslope speed of x_shock: -slope over the second half */
    double h1, h2, u1, u2;   /* means over the second half */
    double froude;           /* u1 / sqrt(g' h1) */
    double ratio, ratio_exact;  /* h2 / h1 measured, from the jump conditions */
    double speed_exact;      /* -c of the jump conditions from h1, u1 */
    double speed_mass;       /* -c of the mass jump with the measured h2, u2 */
    double ratio_moving, speed_moving; /* the jump conditions from h1, u1 and the measured u2 */
    double static_length;    /* at the end */
    int rows;                /* the rows of the second half with a shock */
};

static void measure(const struct muflow_case *cs, const struct layer_series *s,
                    struct shock_measures *m)
{
    double t0 = 0.5 * (s->v[S_T][0] + s->v[S_T][s->n - 1]);
    *m = (struct shock_measures){.speed = -layer_series_slope(s, S_T, S_SHOCK, t0)};
    double a[4] = {0.0, 0.0, 0.0, 0.0};
    for (long i = 0; i < s->n; i++)
        if (s->v[S_T][i] >= t0 && isfinite(s->v[S_SHOCK][i]) && isfinite(s->v[S_H2][i]) &&
            isfinite(s->v[S_U1][i]) && isfinite(s->v[S_U2][i])) {
            a[0] += s->v[S_H1][i];
            a[1] += s->v[S_H2][i];
            a[2] += s->v[S_U1][i];
            a[3] += s->v[S_U2][i];
            m->rows++;
        }
    m->h1 = m->rows ? a[0] / m->rows : NAN;
    m->h2 = m->rows ? a[1] / m->rows : NAN;
    m->u1 = m->rows ? a[2] / m->rows : NAN;
    m->u2 = m->rows ? a[3] / m->rows : NAN;
    double gp = cs->gravity * cos(cs->tilt);
    m->froude = m->u1 / sqrt(gp * m->h1);
    m->ratio = m->h2 / m->h1;
    m->ratio_exact = jump_ratio(m->froude * m->froude, params(cs)->shape_factor);
    m->speed_exact = m->u1 / (m->ratio_exact - 1.0);
    m->speed_mass = (m->h1 * m->u1 - m->h2 * m->u2) / (m->h2 - m->h1);
    double w = m->u2 / m->u1;
    m->ratio_moving = jump_ratio_moving(m->froude * m->froude, params(cs)->shape_factor, w);
    m->speed_moving = m->u1 * (1.0 - m->ratio_moving * w) / (m->ratio_moving - 1.0);
    m->static_length = s->v[S_STATIC][s->n - 1];
}

/* ---- the depth-averaged equations on the same problem ---- */

/* the depth-averaged model's records over the run */
#define DA_ROWS 400

/* the uniform flow of depth h fed at the inflow */
struct da_feed {
    double h, u;
};

static void da_feed_state(void *ctx, double x, double t, double *h, double *u)
{
    (void)x;
    (void)t;
    const struct da_feed *f = ctx;
    *h = f->h;
    *u = f->u;
}

/* The depth-averaged equations (docs/numerics/depth-averaged.md) on the
 * scene's problem: the uniform flow of depth h1 (its speed where the
 * friction balances gravity, mu_b = tan zeta) over [0, lx] at t = 0, fed at
 * x = 0, a wall at lx; recorded DA_ROWS times over the run and measured as
 * the scene's columns (measure_columns, measure).  Its friction and
 * pressure gradient act behind the shock as they do in the 2D flow, so its
 * u2 is not set to 0.  -1 if the model cannot be set up. */
static int da_shock(const struct muflow_case *cs, struct shock_measures *m)
{
    static const char *const names[NSERIES] = {"t", "x_shock", "h1", "h2", "u1", "u2", "static"};
    const struct wall_shock_params *wp = params(cs);
    struct da_params p = da_params_matched(cs);
    p.chi = params(cs)->shape_factor; /* the jump conditions' */
    double zeta = cs->tilt, d = wp->depth;
    /* mu_b = tan zeta: 1 + beta h / (L Fr) = (mu2 - mu1) / (tan zeta - mu1) */
    double fr = p.beta * d / (p.L * ((p.mu2 - p.mu1) / (tan(zeta) - p.mu1) - 1.0));
    struct da_feed feed = {d, fr * sqrt(cs->gravity * cos(zeta) * d)};
    int n = (int)ceil(wp->da_cells * cs->len[0] / d);
    double dx = cs->len[0] / n;
    double *buf = malloc(3 * (size_t)n * sizeof *buf);
    struct layer_series s;
    layer_series_init(&s, NSERIES, names);
    if (!buf || layer_series_reserve(&s, DA_ROWS + 1) != 0) {
        free(buf);
        layer_series_free(&s);
        return -1;
    }
    double *h = buf, *q = buf + n, *zetas = buf + 2 * (size_t)n;
    for (int i = 0; i < n; i++) {
        zetas[i] = zeta;
        h[i] = feed.h;
        q[i] = feed.h * feed.u;
    }
    struct da_bc in = {.kind = DA_BC_GIVEN, .ghost = da_feed_state, .ctx = &feed};
    struct da_bc wall = {.kind = DA_BC_WALL};
    struct da_solver *so = da_create(n, 0.0, dx, zetas, &p, in, wall, NULL, 0);
    int rc = so ? 0 : -1;
    /* rows from t = 0 to the end, as the scene's record */
    double t = 0.0;
    for (long row = 0; rc == 0 && row <= DA_ROWS; row++) {
        double t1 = cs->end_time * row / DA_ROWS;
        if (row > 0 && da_advance(so, h, q, t, t1) < 0)
            rc = -1;
        t = t1;
        struct shock_state e;
        measure_columns(h, q, n, dx, d, &e);
        layer_series_row(&s, row);
        long k = s.n - 1;
        s.v[S_T][k] = t;
        s.v[S_SHOCK][k] = e.x_shock;
        s.v[S_H1][k] = e.h1;
        s.v[S_H2][k] = e.h2;
        s.v[S_U1][k] = e.u1;
        s.v[S_U2][k] = e.u2;
        s.v[S_STATIC][k] = NAN;
    }
    if (rc == 0)
        measure(cs, &s, m);
    da_free(so);
    free(buf);
    layer_series_free(&s);
    return rc;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct record *r = record_of(st);
    if (!r || r->base.s.n == 0)
        return;
    struct shock_measures m;
    measure(st->cs, &r->base.s, &m);
    double d0 = params(st->cs)->depth;
    run_result_add_compared(res, "shock_speed", m.speed, m.speed_exact);
    run_result_add(res, "shock_speed_mass", "%.10g", m.speed_mass);
    run_result_add(res, "shock_speed_mass_error", "%.6e", m.speed / m.speed_mass - 1.0);
    run_result_add_compared(res, "depth_ratio", m.ratio, m.ratio_exact);
    run_result_add_compared(res, "shock_speed_u2", m.speed, m.speed_moving);
    run_result_add_compared(res, "depth_ratio_u2", m.ratio, m.ratio_moving);
    run_result_add(res, "froude", "%.10g", m.froude);
    run_result_add(res, "h1", "%.10g", m.h1);
    run_result_add(res, "u1", "%.10g", m.u1);
    run_result_add(res, "u2_over_u1", "%.6e", m.u2 / m.u1);
    run_result_add(res, "uniform_speed", "%.10g", layer_uniform_mean(&r->base.feed, d0));
    run_result_add(res, "x_shock", "%.10g", r->base.s.v[S_SHOCK][r->base.s.n - 1]);
    run_result_add(res, "static_length", "%.10g", m.static_length / d0);
    run_result_add(res, "fit_rows", "%d", m.rows);
    /* the depth-averaged equations' own solution of the problem */
    struct shock_measures a;
    if (da_shock(st->cs, &a) == 0) {
        run_result_add(res, "shock_speed_depth_averaged", "%.10g", a.speed);
        run_result_add(res, "shock_speed_depth_averaged_error", "%.6e", m.speed / a.speed - 1.0);
        run_result_add(res, "depth_ratio_depth_averaged", "%.10g", a.ratio);
        run_result_add(res, "depth_ratio_depth_averaged_error", "%.6e", m.ratio / a.ratio - 1.0);
        run_result_add(res, "u2_over_u1_depth_averaged", "%.6e", a.u2 / a.u1);
        run_result_add(res, "shock_speed_depth_averaged_jump_error", "%.6e",
                       a.speed / a.speed_exact - 1.0);
        run_result_add(res, "speed_depth_averaged_jump_u2_error", "%.6e",
                       a.speed / a.speed_moving - 1.0);
        run_result_add(res, "ratio_depth_averaged_jump_u2_error", "%.6e",
                       a.ratio / a.ratio_moving - 1.0);
    }
    snprintf(res->scene_line, sizeof res->scene_line,
             "shock speed %.6g (jumps %.6g, %+.2f %%; mass with h2, u2 %.6g)  h2/h1 %.4f (jumps "
             "%.4f, %+.2f %%)  F %.3f  static zone %.1f h1",
             m.speed, m.speed_exact, 100.0 * (m.speed / m.speed_exact - 1.0), m.speed_mass,
             m.ratio, m.ratio_exact, 100.0 * (m.ratio / m.ratio_exact - 1.0), m.froude,
             m.static_length / d0);
}

/* wall_shock.csv: the record; heights.csv: h(x) at the end */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    const struct record *r = record_of(st);
    if (!r || r->base.s.n == 0)
        return 0;
    const struct layer_series *s = &r->base.s;
    struct output_file o;
    if (output_open(&o, dir, "wall_shock.csv", err, errlen) != 0)
        return -1;
    fprintf(o.f, "t,x_shock,h1,h2,u1,u2,static_length\n");
    for (long m = 0; m < s->n; m++)
        fprintf(o.f, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", s->v[S_T][m],
                s->v[S_SHOCK][m], s->v[S_H1][m], s->v[S_H2][m], s->v[S_U1][m], s->v[S_U2][m],
                s->v[S_STATIC][m]);
    if (output_commit(&o, err, errlen) != 0)
        return -1;
    if (output_open(&o, dir, "heights.csv", err, errlen) != 0)
        return -1;
    fprintf(o.f, "x,h\n");
    const struct grid *G = march_global_grid(st);
    for (int i = 0; i < G->n[0]; i++)
        fprintf(o.f, "%.10g,%.10g\n", (i + 0.5) * G->h[0], r->h[i]);
    return output_commit(&o, err, errlen);
}

/* ---- set-up: the uniform layer over the whole bed ---- */

static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct wall_shock_params *p = params(st->cs);
    struct record *r = record_of(st);
    double *T = layer_feed_configure(st, &r->base.feed, p->mixture, p->viscosity_floor, 0,
                                     p->vof_cfl, err, errlen);
    if (!T)
        return -1;
    const struct grid *g = &st->g;
    /* this rank's block: its first global cells, the domain's cells along x */
    const int i0 = scene_block_lo(st, 0), k0 = scene_block_lo(st, 2);
    const int nx = march_global_grid(st)->n[0];
    for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
            for (int k = 0; k < g->n[2]; k++) {
                /* the wall's face at rest; the rest the uniform flow */
                double u = i0 + i >= nx ? 0.0 : layer_uniform_u(&r->base.feed, p->depth,
                                                               (k0 + k + 0.5) * g->h[2]);
                st->field.velocity[0][grid_idx(g, i, j, k)] = u;
                if (i >= 0 && i < g->n[0])
                    T[grid_idx(g, i, j, k)] = layer_fraction(p->depth, k0 + k, g->h[2]);
            }
    return two_phase_tracer_changed(st, err, errlen);
}

static const struct module *const wall_shock_modules[] = {&two_phase_module, &wall_shock_module,
                                                          NULL};
static const char *const wall_shock_files[] = {"wall_shock.csv", "heights.csv", NULL};

const struct scene scene_wall_shock = {
    .name = "wall_shock",
    .title = "a granular layer fed down an incline under a light fluid stops against a wall: "
             "the shock up the slope against the depth-averaged jump conditions (Barker & "
             "Rauter 2018)",
    .keys = &wall_shock_block,
    .modules = wall_shock_modules,
    .check = check,
    .setup = setup,
    .decomposed = scene_decomposed_always,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .results = results,
    .write = write,
    .files = wall_shock_files,
    .write_running = 1,
};
