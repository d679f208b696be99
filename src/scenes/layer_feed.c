/* The uniform layer fed at the inflow of a two-phase incline, its feed
 * column, crossings and time series (scenes/layer_feed.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "kernels/rheology.h"
#include "scenes/layer_feed.h"
#include "platform/num_text.h"
#include "scene_common.h"

double layer_uniform_i(const struct muflow_case *cs)
{
    return rheology_i_of_mu(&cs->rheo, tan(cs->tilt));
}

double layer_uniform_u(const struct layer_feed *lf, double h, double z)
{
    const struct muflow_case *cs = lf->cs;
    const struct rheology *r = &cs->rheo;
    double L = cs->len[2], rf = lf->fluid_density, rg = cs->density, rs = r->grain_density;
    double gc = cs->gravity * cos(cs->tilt), gs = cs->gravity * sin(cs->tilt);
    double k = (2.0 * layer_uniform_i(cs) / (3.0 * r->grain_diameter * rg)) * sqrt(gc / rs);
    double zz = fmin(fmax(z, 0.0), h);
    double P0 = rg * h + rf * (L - h), Pz = rg * (h - zz) + rf * (L - h);
    double u = k * (P0 * sqrt(P0) - Pz * sqrt(Pz));
    if (z > h)
        u += (rf * gs / (2.0 * lf->fluid_viscosity)) * ((L - h) * (L - h) - (L - z) * (L - z));
    return u;
}

/* Gauss-Legendre, 8 points on the smooth profile */
double layer_uniform_mean(const struct layer_feed *lf, double h)
{
    static const double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                0.9602898564975363};
    static const double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                0.1012285362903763};
    double s = 0.0;
    for (int m = 0; m < 4; m++)
        s += w[m] * (layer_uniform_u(lf, h, 0.5 * h * (1.0 - x[m])) +
                     layer_uniform_u(lf, h, 0.5 * h * (1.0 + x[m])));
    return 0.5 * s;
}

double layer_fraction(double h, int k, double dz)
{
    return fmin(1.0, fmax(0.0, (h - k * dz) / dz));
}

/* The inflow's normal velocity at the face centre x: the uniform layer's */
static double inflow_shape(const void *ctx, int d, const double x[3])
{
    const struct layer_feed *lf = ctx;
    return d == 0 ? layer_uniform_u(lf, lf->depth, x[2]) : 0.0;
}

double *layer_feed_configure(struct march_state *st, const struct layer_feed *lf, int mixture,
                             double floor, int bed_pressure, double vof_cfl, char *err,
                             size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    double d = cs->rheo.grain_diameter;
    const struct two_phase_params tp = {
        .fluid_density = lf->fluid_density,
        .fluid_viscosity = lf->fluid_viscosity,
        .mixture = (enum mixture_law)mixture,
        .transported = 1,
        .eta_min = floor * cs->density * d * sqrt(cs->gravity * d),
        .eta_max = floor > 0.0 ? HUGE_VAL : 0.0,
        .step_cfl = vof_cfl,
        .bed_pressure = bed_pressure,
    };
    double *T = two_phase_configure(st, &tp, err, errlen);
    if (!T)
        return NULL;
    st->bc.inflow_shape = inflow_shape;
    st->bc.inflow_ctx = lf;
    return T;
}

void layer_feed_hold(struct march_state *st, const struct layer_feed *lf)
{
    int t = fields_find(&st->fields, "tracer");
    /* the feed is the domain's first column: the first block's along x */
    if (t < 0 || scene_block_lo(st, 0) != 0)
        return;
    double *T = st->fields.e[t].v[0];
    const struct grid *g = &st->g;
    const int k0 = scene_block_lo(st, 2); /* the block's first layer */
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++)
            T[grid_idx(g, 0, j, k)] = layer_fraction(lf->depth, k0 + k, g->h[2]);
}

void layer_columns(const struct march_state *st, const double *T, double *h, int flux)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int n = G->n[0], lo = scene_block_lo(st, 0);
    double *q = h + n;
    for (int i = 0; i < (flux ? 2 * n : n); i++)
        h[i] = 0.0;
    /* this rank's part of its columns, at their global index */
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                h[lo + i] += T[p];
                if (flux)
                    q[lo + i] += T[p] * (0.5 * (st->field.velocity[0][p] +
                                                st->field.velocity[0][p + g->stride[0]])) *
                                 g->h[2];
            }
    if (st->ranks)
        march_sum_array(st, h, flux ? 2 * n : n);
    for (int i = 0; i < n; i++)
        h[i] = h[i] * G->h[2] / G->n[1];
}

double layer_crossing(const double *h, int n, double dx, double level)
{
    for (int i = n - 1; i >= 0; i--) {
        if (h[i] < level)
            continue;
        double xc = (i + 0.5) * dx;
        if (i == n - 1)
            return xc;
        return xc + dx * (h[i] - level) / (h[i] - h[i + 1]);
    }
    return 0.0;
}

/* ---- the time series ---- */

void layer_series_init(struct layer_series *s, int ncol, const char *const *names)
{
    *s = (struct layer_series){.ncol = ncol, .names = names, .last_step = -1};
}

void layer_series_free(struct layer_series *s)
{
    for (int m = 0; m < s->ncol; m++)
        free(s->v[m]);
}

int layer_series_reserve(struct layer_series *s, long need)
{
    if (need <= s->cap)
        return 0;
    long c = s->cap ? 2 * s->cap : 1024;
    while (c < need)
        c *= 2;
    for (int m = 0; m < s->ncol; m++) {
        double *b = realloc(s->v[m], (size_t)c * sizeof *b);
        if (!b)
            return -1;
        s->v[m] = b;
    }
    s->cap = c;
    return 0;
}

int layer_series_row(struct layer_series *s, long step)
{
    if (step == s->last_step)
        return 1;
    if (layer_series_reserve(s, s->n + 1) != 0)
        return -1;
    s->n++;
    s->last_step = step;
    return 0;
}

int layer_series_save(const struct layer_series *s, struct module_record *rec)
{
    double last = (double)s->last_step;
    int rc = module_record_put(rec, "last_step", &last, 1);
    for (int m = 0; rc == 0 && m < s->ncol; m++)
        rc = module_record_put(rec, s->names[m], s->v[m], s->n);
    return rc;
}

int layer_series_load(struct layer_series *s, struct module_record *rec)
{
    double last;
    if (!rec)
        return -1;
    long n = module_record_count(rec, s->names[0]);
    if (n < 0 || module_record_get(rec, "last_step", &last, 1) != 0)
        return -1;
    if (layer_series_reserve(s, n > 0 ? n : 1) != 0)
        return module_record_fail(rec, "out of memory for the record");
    for (int m = 0; m < s->ncol; m++)
        if (module_record_get(rec, s->names[m], s->v[m], n) != 0)
            return -1;
    s->n = n;
    s->last_step = (long)last;
    return 0;
}

double layer_series_slope(const struct layer_series *s, int x, int y, double x0)
{
    if (s->n < 4)
        return NAN;
    double st = 0.0, sx = 0.0, stt = 0.0, stx = 0.0;
    long m = 0;
    for (long i = 0; i < s->n; i++) {
        double t = s->v[x][i], v = s->v[y][i];
        if (t < x0)
            continue;
        st += t;
        sx += v;
        stt += t * t;
        stx += t * v;
        m++;
    }
    double den = m * stt - st * st;
    return m >= 2 && den > 0.0 ? (m * stx - st * sx) / den : NAN;
}

int layer_feed_check(const struct muflow_case *c, const char *scene, enum bc_kind xhi,
                     const char *xhi_name,
                     char *msg, size_t msglen)
{
    const struct boundary *b = &c->bc;
    if (c->rheo.law != LAW_MUI || c->mode != MODE_TRANSIENT) {
        snprintf(msg, msglen, "case.scene = %s needs rheology.law = mui and solver.mode = "
                              "transient",
                 scene);
        return 1;
    }
    if (b->face[0][0] != BC_INFLOW || b->face[0][1] != xhi || b->face[2][0] != BC_WALL ||
        b->face[2][1] != BC_OPEN || b->face[1][0] != BC_PERIODIC || c->n[1] != 1) {
        snprintf(msg, msglen, "case.scene = %s needs boundary.xlo = inflow, boundary.xhi = %s, "
                              "boundary.zlo = wall, boundary.zhi = open, boundary.ylo = "
                              "boundary.yhi = periodic and domain.ny = 1",
                 scene, xhi_name);
        return 1;
    }
    double t = tan(c->tilt), lo = c->rheo.mu_s, hi = c->rheo.mu_s + c->rheo.delta_mu;
    if (!(t > lo && t < hi)) {
        snprintf(msg, msglen, "physics.tilt = %s: tan(physics.tilt) = %.6g must be in "
                              "(rheology.mu_s, rheology.mu_s + rheology.delta_mu) = (%.6g, %.6g): "
                              "a uniform flow that neither stops nor accelerates",
                 num_text(c->tilt).s, t, lo, hi);
        return 1;
    }
    double rg = c->rheo.phi * c->rheo.grain_density;
    if (fabs(c->density - rg) > 1e-12 * rg) {
        snprintf(msg, msglen, "physics.density = %s: the grains' bulk density must be "
                              "rheology.phi * rheology.grain_density = %.10g",
                 num_text(c->density).s, rg);
        return 1;
    }
    return 0;
}

void layer_record_end_step(struct march_state *st, void *state, double dt)
{
    (void)dt;
    layer_feed_hold(st, &((struct layer_record *)state)->feed);
}

int layer_record_save(const struct march_state *st, void *state, struct module_record *rec)
{
    (void)st;
    return layer_series_save(&((struct layer_record *)state)->s, rec);
}

int layer_record_load(struct march_state *st, void *state, struct module_record *rec)
{
    (void)st;
    return layer_series_load(&((struct layer_record *)state)->s, rec);
}
