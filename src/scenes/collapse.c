/* Scene "collapse": a rectangular column of grains released on a rough base
 * under air spreads and stops (Lagree, Staron & Popinet 2011; the set-up of
 * their example files; cases/collapse.ini).  Half the column: the symmetry
 * plane at x = 0 (slip), no slip at the base, the flat stress-free top (p = 0
 * there, no flow through it: the closed-top approximation of an open top,
 * harmless at the light phase's density ratio 1e-3), a 2D cross-section.
 * The rheology reads the pressure in the published runs' gauge, the top at
 * -rho_f g lz (collapse.fluid_weight = off), so that the light phase's
 * weight does not press on the grains however tall the box.
 *
 * The two phases are the two_phase module (physics/two_phase.h), T carried
 * by the geometric VOF; the grains' viscosity is the case's mu(I) with the
 * regularised pressure, or its nonlocal fluidity's p / (g + lambda)
 * (rheology.law = ngf: physics/ngf.h, solved on the grains' cells, one
 * process), optionally clipped to [rho d sqrt(g d), eta_max]
 * as in the published runs.  The scene's own module records the measures
 * of scenes/collapse.h at every step and the surface profile h(x) at given
 * times, and holds the dynamic pressure's level at the top at 0 (the
 * projection fixes only its gradient, the rheology needs its value).  The
 * run ends at end_time or when the kinetic energy has fallen below a
 * fraction of its peak: the deposit has come to rest. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/reference.h"
#include "march/module_record.h"
#include "io/output.h"
#include "physics/two_phase.h"
#include "scenes/collapse.h"
#include "scenes/scene.h"
#include "scenes/recorded_drive.h"
#include "scene_common.h"
#include "scenes/two_phase_keys.h"

struct collapse_params {
    double half_width;       /* R0 */
    double height;           /* H0 */
    double fluid_density;
    double fluid_viscosity;
    int viscosity_clip;
    double eta_max;
    double rest_energy;      /* fraction of the peak kinetic energy: at rest */
    double profile_interval; /* time between surface profiles */
    double vof_cfl;
    int fluid_weight;        /* the grains carry the light phase above them */
    int mixture;             /* enum mixture_law */
    int column;              /* enum collapse_column */
};

static const struct choice column_choices[] = {
    {"slab", COLLAPSE_SLAB}, {"square", COLLAPSE_SQUARE}, {NULL, 0}};

#define T struct collapse_params
static const struct key collapse_keys[] = {
    KEY_DBL(T, "collapse", "half_width", half_width,
            KEY_HELP("half-width R0 of the column (the axis at x = 0): at least a cell, "
                     "domain.lx / domain.nx, and below domain.lx",
                     "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "collapse", "height", height,
            KEY_HELP("height H0 of the column: at least a cell, domain.lz / domain.nz, and "
                     "below domain.lz",
                     "length", NULL),
            KEY_GT0),
    TWO_PHASE_KEY_FLUID_DENSITY(T, "collapse"),
    TWO_PHASE_KEY_FLUID_VISCOSITY(T, "collapse"),
    KEY_BOOL(T, "collapse", "viscosity_clip", viscosity_clip,
             "clip the granular viscosity to [rho d sqrt(g d), eta_max] before mixing (the "
             "published runs)"),
    KEY_DBL(T, "collapse", "eta_max", eta_max,
            KEY_HELP("upper bound of the viscosity clip", "pressure time", NULL), KEY_GT0),
    KEY_DBL(T, "collapse", "rest_energy", rest_energy,
            "the run ends (finished, at rest) when the kinetic energy falls below this "
            "fraction of its peak; 0: only at solver.end_time",
            KEY_RANGE(0.0, 1.0, 1, 0)),
    KEY_DBL(T, "collapse", "profile_interval", profile_interval,
            KEY_HELP("time between the surface profiles h(x) of surface.csv", "time", NULL),
            KEY_GT0),
    TWO_PHASE_KEY_VOF_CFL(T, "collapse"),
    KEY_BOOL(T, "collapse", "fluid_weight", fluid_weight,
             "the grains carry the light phase's weight above them up to the top (p = 0 "
             "there; the front then depends on domain.lz); off: the rheology's pressure is "
             "taken with the top at -rho_f g lz, p = -rho_f g z in the light phase at rest, "
             "as in the published runs"),
    TWO_PHASE_KEY_MIXTURE(T, "collapse", "; the published Gerris runs' is harmonic; weighted holds the shipped case's front closer to the reference (docs/validation/collapse.md)"),
    KEY_CHO(T, "collapse", "column", column, column_choices,
            "slab: the column x <= R0, uniform in y (a 2D cross-section: periodic y, "
            "domain.ny = 1); square: the column x <= R0 and y <= R0, a quarter of a square "
            "column with the symmetry planes x = 0 and y = 0 (boundary.ylo = slip, yhi not "
            "periodic, domain.ny >= 1); x_front is then the front along the row at y = 0"),
};
#undef T

/* a = 0.5 of the published runs (units H0 = g = rho = 1) */
static void defaults(void *block)
{
    struct collapse_params *c = block;
    c->half_width = 2.0;
    c->height = 1.0;
    c->fluid_density = 1e-3;
    c->fluid_viscosity = 1e-4;
    c->viscosity_clip = 0;
    c->eta_max = 10.0;
    c->rest_energy = 1e-4;
    c->profile_interval = 1.0;
    c->vof_cfl = 0.4;
    c->fluid_weight = 0;
    c->mixture = MIXTURE_WEIGHTED;
    c->column = COLLAPSE_SLAB;
}


SCENE_PARAMS(collapse_block, "collapse",
             "A rectangular column of grains released on a rough base under a light phase, half "
             "the column with the symmetry plane at x = 0 (Lagree, Staron & Popinet 2011; "
             "`cases/collapse.ini`).  The grains are the case's `[rheology]` (mu(I), or `law = "
             "ngf` on one process) with `physics.density` their density; the scene needs "
             "`solver.mode = transient`, `boundary.xlo = slip`, `xhi` not periodic, `zlo = wall`, "
             "`zhi = surface` or `open`, periodic y and `domain.ny = 1` (`collapse.column = "
             "square`: a quarter of a square column in 3D, `ylo = slip`).  It writes "
             "`collapse.csv` (every step: t, x_front, h_axis, kinetic energy, grains' volume, "
             "extremes of T; square: then y_front and the diagonal's front) and `surface.csv` "
             "(h(x) at the profile times and at the end; square: along y = 0); with "
             "`case.reference` it compares x_front and h_axis with the reference's datasets of the "
             "same aspect ratio H0/R0.",
             struct collapse_params, collapse_keys, defaults)

/* The case's column is the quarter of a square one (collapse.column). */
static int is_square(const struct muflow_case *cs)
{
    return params(cs)->column == COLLAPSE_SQUARE;
}

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct collapse_params *p = params(c);
    if (c->rheo.law != LAW_MUI && c->rheo.law != LAW_NGF) {
        snprintf(msg, msglen, "case.scene = collapse needs rheology.law = mui or ngf");
        return 1;
    }
    if (c->mode != MODE_TRANSIENT) {
        snprintf(msg, msglen, "case.scene = collapse needs solver.mode = transient");
        return 1;
    }
    const struct boundary *b = &c->bc;
    int square = p->column == COLLAPSE_SQUARE;
    if (b->face[0][0] != BC_SLIP || b->face[0][1] == BC_PERIODIC || b->face[2][0] != BC_WALL ||
        (b->face[2][1] != BC_SURFACE && b->face[2][1] != BC_OPEN)) {
        snprintf(msg, msglen, "case.scene = collapse needs boundary.xlo = slip (the axis), "
                              "boundary.xhi not periodic, boundary.zlo = wall, boundary.zhi = "
                              "surface or open");
        return 1;
    }
    if (!square && (b->face[1][0] != BC_PERIODIC || c->n[1] != 1)) {
        snprintf(msg, msglen, "collapse.column = slab needs boundary.ylo = boundary.yhi = "
                              "periodic and domain.ny = 1 (a 3D column: collapse.column = "
                              "square)");
        return 1;
    }
    if (square && (b->face[1][0] != BC_SLIP || b->face[1][1] == BC_PERIODIC)) {
        snprintf(msg, msglen, "collapse.column = square needs boundary.ylo = slip (the "
                              "symmetry plane y = 0) and boundary.yhi not periodic");
        return 1;
    }
    /* the column inside the box, and at least a cell across each way (a
     * thinner one is a fraction of a cell's mixture: it ends "finished"
     * with x_front 0) */
    static const char *const name[3] = {"half_width", "half_width", "height"},
                             *const len_key[3] = {"lx", "ly", "lz"},
                             *const n_key[3] = {"nx", "ny", "nz"};
    const double size[3] = {p->half_width, p->half_width, p->height};
    for (int d = 0; d < 3; d++) {
        if (d == 1 && !square) /* a slab fills y */
            continue;
        double h = c->len[d] / c->n[d];
        if (!(scene_at_least_a_cell(size[d], h) && size[d] < c->len[d])) {
            snprintf(msg, msglen, "collapse.%s = %s: must be in [%.6g, %s): at least a cell "
                                  "(domain.%s / domain.%s = %s / %d = %.6g) and inside "
                                  "domain.%s = %s",
                     name[d], num_text(size[d]).s, h, num_text(c->len[d]).s, len_key[d], n_key[d],
                     num_text(c->len[d]).s, c->n[d], h, len_key[d], num_text(c->len[d]).s);
            return 1;
        }
    }
    return 0;
}

/* ---- the record: measures at every step, profiles at given times ---- */

struct record {
    struct collapse_sample *s;
    long n, cap;
    long last_step;          /* the step of the last sample (-1: none) */
    double peak;             /* largest kinetic energy so far, and when */
    double peak_time;
    double volume0;
    int nx;                  /* profiles: times and nx heights each (the whole grid's) */
    double *ptime, *ph;
    long np, pcap;
    double next_profile;
    double *h_last;          /* on ranks: h(x) at the last sample (rank 0 writes it) */
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct record *r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, errlen, "collapse: out of memory");
        return -1;
    }
    r->last_step = -1;
    r->nx = march_global_grid(st)->n[0];
    *state = r;
    if (st->ranks && !(r->h_last = calloc((size_t)r->nx, sizeof *r->h_last))) {
        snprintf(err, errlen, "collapse: out of memory");
        return -1;
    }
    return 0;
}

static void destroy(void *state)
{
    struct record *r = state;
    if (r) {
        free(r->s);
        free(r->ptime);
        free(r->ph);
        free(r->h_last);
    }
    free(r);
}

/* The dynamic pressure's mean over the top layer of cells set to 0: the
 * pressure at the top is the hydrostatic one, 0 on the face (the light
 * phase's weight over half a cell in the top cells), plus the scene's
 * gauge (setup) in the pressure the rheology reads. */
static void end_step(struct march_state *st, void *state, double dt)
{
    (void)state;
    (void)dt;
    recorded_drive_gauge_top(st);
}

static int grow(void **a, long *cap, long need, size_t each)
{
    if (need <= *cap)
        return 0;
    long c = *cap ? 2 * *cap : 1024;
    while (c < need)
        c *= 2;
    void *b = realloc(*a, (size_t)c * each);
    if (!b)
        return -1;
    *a = b;
    *cap = c;
    return 0;
}

/* The record in the checkpoint: a continued run's collapse.csv,
 * surface.csv and results are the uninterrupted run's.  One array per
 * measure of the samples, the profiles' times and heights, and the
 * scalars that decide the next sample and profile and the rest. */
#define SAMPLE_FIELDS 9
static const char *const sample_names[SAMPLE_FIELDS] = {
    "t",          "x_front",    "h_axis",  "kinetic_energy", "grains_volume",
    "tracer_min", "tracer_max", "y_front", "diagonal_front"};
static double *sample_field(struct collapse_sample *s, int f)
{
    double *const at[SAMPLE_FIELDS] = {&s->t,     &s->x_front, &s->h_axis,
                                       &s->kinetic, &s->volume, &s->t_min,
                                       &s->t_max, &s->y_front, &s->d_front};
    return at[f];
}

/* The measures a column records: the square's two fronts besides. */
static int sample_fields(const struct muflow_case *cs)
{
    return is_square(cs) ? SAMPLE_FIELDS : SAMPLE_FIELDS - 2;
}
enum { SC_LAST_STEP, SC_PEAK, SC_PEAK_TIME, SC_VOLUME0, SC_NEXT_PROFILE, SC_NX, SCALARS };

static int save(const struct march_state *st, void *state, struct module_record *rec)
{
    struct record *r = state;
    int nf = sample_fields(st->cs);
    double scalars[SCALARS] = {(double)r->last_step, r->peak, r->peak_time, r->volume0,
                               r->next_profile, r->nx};
    double *v = malloc((size_t)(r->n > 0 ? r->n : 1) * sizeof *v);
    if (!v)
        return module_record_fail(rec, "out of memory for the record");
    int rc = module_record_put(rec, "scalars", scalars, SCALARS);
    for (int f = 0; rc == 0 && f < nf; f++) {
        for (long m = 0; m < r->n; m++)
            v[m] = *sample_field(&r->s[m], f);
        rc = module_record_put(rec, sample_names[f], v, r->n);
    }
    free(v);
    if (rc == 0)
        rc = module_record_put(rec, "profile_times", r->ptime, r->np);
    if (rc == 0)
        rc = module_record_put(rec, "profile_heights", r->ph, r->np * r->nx);
    return rc;
}

static int load(struct march_state *st, void *state, struct module_record *rec)
{
    struct record *r = state;
    int nf = sample_fields(st->cs);
    double scalars[SCALARS];
    if (!rec) /* the record covers the run from the initial column */
        return -1;
    if (module_record_get(rec, "scalars", scalars, SCALARS) != 0)
        return -1;
    if ((int)scalars[SC_NX] != r->nx)
        return module_record_fail(rec, "its profiles have %d columns, the grid %d",
                                  (int)scalars[SC_NX], r->nx);
    long n = module_record_count(rec, "t"), np = module_record_count(rec, "profile_times");
    if (n < 0 || np < 0)
        return -1;
    long cap = r->cap, pc = r->pcap, hc = r->pcap;
    double *v = malloc((size_t)(n > 0 ? n : 1) * sizeof *v);
    if (!v || grow((void **)&r->s, &cap, n, sizeof *r->s) != 0 ||
        grow((void **)&r->ptime, &pc, np, sizeof(double)) != 0 ||
        grow((void **)&r->ph, &hc, np, (size_t)r->nx * sizeof(double)) != 0) {
        free(v);
        return module_record_fail(rec, "out of memory for the record");
    }
    r->cap = cap;
    r->pcap = pc;
    int rc = 0;
    for (int f = 0; rc == 0 && f < nf; f++) {
        rc = module_record_get(rec, sample_names[f], v, n);
        for (long m = 0; rc == 0 && m < n; m++)
            *sample_field(&r->s[m], f) = v[m];
    }
    free(v);
    if (rc == 0)
        rc = module_record_get(rec, "profile_times", r->ptime, np);
    if (rc == 0)
        rc = module_record_get(rec, "profile_heights", r->ph, np * r->nx);
    if (rc != 0)
        return -1;
    r->n = n;
    r->np = np;
    r->last_step = (long)scalars[SC_LAST_STEP];
    r->peak = scalars[SC_PEAK];
    r->peak_time = scalars[SC_PEAK_TIME];
    r->volume0 = scalars[SC_VOLUME0];
    r->next_profile = scalars[SC_NEXT_PROFILE];
    return 0;
}

static const struct module collapse_module = {
    .name = "collapse",
    .create = create,
    .end_step = end_step,
    .save = save,
    .load = load,
    .destroy = destroy,
};

/* h(x) of surface.csv: averaged over y (slab; over the ranks, collective),
 * along the row next to y = 0 (square). */
static void surface_heights(const struct march_state *st, const double *T, double *h)
{
    if (is_square(st->cs))
        collapse_row_heights(&st->g, T, 0, h);
    else if (st->ranks)
        collapse_heights_ranks(st, T, h);
    else
        collapse_heights(&st->g, T, h);
}

/* Adds the state's sample (once per step) and a profile when one is due. */
static int record_step(void *rec, const struct march_state *st)
{
    struct record *r = rec;
    const double *T = collapse_tracer(st);
    if (!T || st->step == r->last_step)
        return 0;
    long scap = r->cap;
    if (grow((void **)&r->s, &scap, r->n + 1, sizeof *r->s) != 0)
        return -1;
    r->cap = scap;
    struct collapse_sample *s = &r->s[r->n++];
    collapse_measure(st, T, is_square(st->cs), s);
    r->last_step = st->step;
    if (r->h_last) /* every rank at every sample: the final deposit's, for rank 0 */
        surface_heights(st, T, r->h_last);
    if (r->n == 1)
        r->volume0 = s->volume;
    if (s->kinetic > r->peak) {
        r->peak = s->kinetic;
        r->peak_time = s->t;
    }
    if (s->t >= r->next_profile * (1.0 - 1e-12)) {
        long pc = r->pcap, hc = r->pcap;
        if (grow((void **)&r->ptime, &pc, r->np + 1, sizeof(double)) != 0 ||
            grow((void **)&r->ph, &hc, r->np + 1, (size_t)r->nx * sizeof(double)) != 0)
            return -1;
        r->pcap = pc;
        r->ptime[r->np] = s->t;
        if (r->h_last)
            memcpy(r->ph + (size_t)r->np * r->nx, r->h_last, (size_t)r->nx * sizeof *r->h_last);
        else
            surface_heights(st, T, r->ph + (size_t)r->np * r->nx);
        r->np++;
        double every = params(st->cs)->profile_interval;
        while (r->next_profile <= s->t * (1.0 + 1e-12))
            r->next_profile += every;
    }
    return 0;
}

static struct record *record_of(const struct march_state *st)
{
    return march_module_state(st, &collapse_module);
}

/* ---- the driver: the march, recorded, until end_time or rest ---- */

static void energy(const void *rec, double *kinetic, double *peak, double *peak_time)
{
    const struct record *r = rec;
    *kinetic = r->n > 0 ? r->s[r->n - 1].kinetic : NAN;
    *peak = r->peak;
    *peak_time = r->peak_time;
}

static int drive(struct scene_drive *d)
{
    struct march_state *st = d->st;
    struct recorded_drive rd = {.record_step = record_step,
                            .energy = energy,
                            .rec = record_of(st),
                            .rest_fraction = params(st->cs)->rest_energy,
                            .record_name = "the collapse's record"};
    recorded_drive_run(d, &rd);
    return 0;
}

/* ---- results and files ---- */

/* A time the run reached to the rounding of its sum of steps (the end
 * time, 4, is reached as 3.9999999999999996). */
#define RECORD_TIME_EPS 1e-9

/* Field `which` of the record (0 x_front, 1 h_axis) at time t, linear
 * between samples; NaN outside the record. */
static double record_at(const struct record *r, int which, double t)
{
    for (long m = 1; m < r->n; m++)
        if (r->s[m].t >= t - RECORD_TIME_EPS) {
            const struct collapse_sample *a = &r->s[m - 1], *b = &r->s[m];
            double va = which ? a->h_axis : a->x_front, vb = which ? b->h_axis : b->x_front;
            double w = b->t > a->t ? fmin(1.0, (t - a->t) / (b->t - a->t)) : 1.0;
            return va + w * (vb - va);
        }
    return r->n > 0 && fabs(r->s[0].t - t) < 1e-12 ? (which ? r->s[0].h_axis : r->s[0].x_front)
                                                    : NAN;
}

/* The largest |measure - reference| over the reference times the run
 * reached, and their count. */
static double reference_error(const struct muflow_case *cs, const struct record *r,
                              const char *dataset, int which, int *count)
{
    *count = 0;
    if (!cs->reference[0] || is_square(cs)) /* the references are slabs' */
        return NAN;
    const struct collapse_params *p = params(cs);
    struct curve c;
    char err[256];
    if (reference_curve(cs->reference, dataset, p->height / p->half_width, &c, err,
                        sizeof err) != 0)
        return NAN;
    double e = 0.0;
    for (int m = 0; m < c.n; m++) {
        double v = record_at(r, which, c.x[m]);
        if (isnan(v))
            continue;
        e = fmax(e, fabs(v - c.y[m]));
        (*count)++;
    }
    curve_free(&c);
    return *count ? e : NAN;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct record *r = record_of(st);
    if (!r || r->n == 0)
        return;
    const struct collapse_sample *s = &r->s[r->n - 1];
    double lo = INFINITY, hi = -INFINITY;
    for (long m = 0; m < r->n; m++) {
        lo = fmin(lo, r->s[m].t_min);
        hi = fmax(hi, r->s[m].t_max);
    }
    double mass = s->volume / r->volume0 - 1.0;
    run_result_add(res, "x_front", "%.10g", s->x_front);
    run_result_add(res, "h_axis", "%.10g", s->h_axis);
    run_result_add(res, "kinetic_energy", "%.6e", s->kinetic);
    run_result_add(res, "kinetic_energy_peak", "%.6e", r->peak);
    run_result_add(res, "mass_error", "%.6e", mass);
    run_result_add(res, "tracer_min", "%.6e", lo);
    run_result_add(res, "tracer_max_minus_1", "%.6e", hi - 1.0);
    int nx, nh;
    double ex = reference_error(st->cs, r, "x_front", 0, &nx);
    double eh = reference_error(st->cs, r, "h_axis", 1, &nh);
    if (is_square(st->cs)) {
        run_result_add(res, "y_front", "%.10g", s->y_front);
        run_result_add(res, "diagonal_front", "%.10g", s->d_front);
    }
    if (nx > 0)
        run_result_add(res, "x_front_err_max", "%.6e", ex);
    if (nh > 0)
        run_result_add(res, "h_axis_err_max", "%.6e", eh);
    int n = snprintf(res->scene_line, sizeof res->scene_line,
                     "x_front %.4f  h_axis %.4f  mass error %.2e  T in [%.2g, 1%+.2g]",
                     s->x_front, s->h_axis, mass, lo, hi - 1.0);
    if (nx > 0 && n > 0 && (size_t)n < sizeof res->scene_line)
        snprintf(res->scene_line + n, sizeof res->scene_line - (size_t)n,
                 "  |x_front - reference| <= %.3f at %d times", ex, nx);
}

/* collapse.csv: the measures at every step; surface.csv: h(x) at the
 * profile times and at the end.  Also during the run (write_running), each
 * file replaced whole: the record so far, without the final profile. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    const struct record *r = record_of(st);
    const double *T = collapse_tracer(st);
    if (!r || !T)
        return 0;
    struct output_file f;
    if (output_open(&f, dir, "collapse.csv", err, errlen) != 0)
        return -1;
    int square = is_square(st->cs);
    fprintf(f.f, "t,x_front,h_axis,kinetic_energy,grains_volume,tracer_min,tracer_max%s\n",
            square ? ",y_front,diagonal_front" : "");
    for (long m = 0; m < r->n; m++) {
        const struct collapse_sample *s = &r->s[m];
        fprintf(f.f, "%.10g,%.10g,%.10g,%.10e,%.16e,%.6e,%.16e", s->t, s->x_front, s->h_axis,
                s->kinetic, s->volume, s->t_min, s->t_max);
        if (square)
            fprintf(f.f, ",%.10g,%.10g", s->y_front, s->d_front);
        fputc('\n', f.f);
    }
    if (output_commit(&f, err, errlen) != 0)
        return -1;
    if (output_open(&f, dir, "surface.csv", err, errlen) != 0)
        return -1;
    const struct grid *g = march_global_grid(st);
    double *h = malloc((size_t)g->n[0] * sizeof *h);
    if (!h) {
        fclose(f.f);
        snprintf(err, errlen, "surface.csv: out of memory");
        return -1;
    }
    /* rank 0 alone: the heights every rank reduced at the last sample */
    if (r->h_last)
        memcpy(h, r->h_last, (size_t)g->n[0] * sizeof *h);
    else
        surface_heights(st, T, h);
    fprintf(f.f, "t,final,x,h\n");
    for (long m = 0; m < r->np; m++)
        for (int i = 0; i < r->nx; i++)
            fprintf(f.f, "%.10g,0,%.10g,%.10g\n", r->ptime[m], (i + 0.5) * g->h[0],
                    r->ph[(size_t)m * r->nx + i]);
    if (st->status != STATUS_RUNNING) /* the final deposit: once the run has ended */
        for (int i = 0; i < g->n[0]; i++)
            fprintf(f.f, "%.10g,1,%.10g,%.10g\n", st->time, (i + 0.5) * g->h[0], h[i]);
    free(h);
    return output_commit(&f, err, errlen);
}

/* ---- set-up ---- */

static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    const struct collapse_params *p = params(cs);
    double d = cs->rheo.grain_diameter;
    const struct two_phase_params tp = {
        .fluid_density = p->fluid_density,
        .fluid_viscosity = p->fluid_viscosity,
        .mixture = (enum mixture_law)p->mixture,
        .transported = 1,
        .eta_min = p->viscosity_clip ? cs->density * d * sqrt(cs->gravity * d) : 0.0,
        .eta_max = p->viscosity_clip ? p->eta_max : 0.0,
        .step_cfl = p->vof_cfl,
    };
    double *T = two_phase_configure(st, &tp, err, errlen);
    if (!T)
        return -1;
    /* The published runs set the pressure at the top to -rho_f g L (their
     * box's height), so that p = -rho_f g z in the light phase at rest and
     * the grains' pressure is their own weight (less rho_f g h, a
     * thousandth): the light phase above them, however tall the box, adds
     * no friction.  With p = 0 at the top it adds rho_f g (lz - h), which
     * at the thin front, whose own pressure is a few hundredths, made the
     * front depend on the box's height; with the gauge it does not
     * (docs/numerics/two-phase-and-vof.md, "What the collapse needed"). */
    st->pressure_gauge = p->fluid_weight ? 0.0 : -p->fluid_density * cs->gravity * cs->len[2];
    const struct grid *g = &st->g;
    const int *lo = st->ranks ? st->ranks->dc.lo : (const int[3]){0, 0, 0};
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                T[grid_idx(g, i, j, k)] =
                    collapse_rectangle_fraction((lo[0] + i) * g->h[0], g->h[0],
                                                (lo[2] + k) * g->h[2], g->h[2], p->half_width,
                                                p->height) *
                    (p->column == COLLAPSE_SQUARE
                         ? collapse_rectangle_fraction(j * g->h[1], g->h[1], 0.0, 1.0,
                                                       p->half_width, 1.0)
                         : 1.0);
    return two_phase_tracer_changed(st, err, errlen);
}

/* A slab runs over ranks (its measures reduced: collapse_measure.c); the
 * square's lines along y and the diagonal do not. */
static int decomposed(const struct muflow_case *cs)
{
    return !is_square(cs);
}

static const struct module *const collapse_modules[] = {&two_phase_module, &collapse_module,
                                                        NULL};
static const char *const collapse_files[] = {"collapse.csv", "surface.csv", NULL};

const struct scene scene_collapse = {
    .name = "collapse",
    .title = "granular column collapse under air, two phases (Lagree, Staron & Popinet 2011)",
    .keys = &collapse_block,
    .modules = collapse_modules,
    .check = check,
    .setup = setup,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .results = results,
    .write = write,
    .files = collapse_files,
    .write_running = 1,
    .decomposed = decomposed,
    .not_decomposed = "collapse.column = square",
};
