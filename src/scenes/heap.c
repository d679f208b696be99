/* Scene "heap": surface flow on a heap between rough side walls (Chauchat
 * & Medale 2014, sec. 4.1; cases/heap.ini), its diagnostics (heap.h) and the tilt search
 * that finds the tilt of a given flow rate (tilt_search.h). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "config/case.h"
#include "diagnostics/profile.h"
#include "io/output.h"
#include "scenes/heap.h"
#include "scenes/scene.h"
#include "scene_common.h"
#include "scenes/tilt_search.h"


/* The whole cross-section's columns: u of column j, layer k, the mean
 * over the x-faces of the periodic x, at t[j * nz + k] (nz the global
 * count).  On ranks each rank's block in place, the sums over x summed
 * over the ranks (a column's other slots are zeros: its own sum to the
 * bit), so every rank holds one process's table.  NULL out of memory.
 * Collective on ranks. */
static double *column_table(const struct march_state *st)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int *lo = st->ranks ? st->ranks->dc.lo : (const int[3]){0, 0, 0};
    const size_t cells = (size_t)G->n[1] * (size_t)G->n[2];
    double *t = calloc(cells, sizeof *t);
    if (!t)
        return NULL;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            double s = 0.0;
            for (int i = 0; i < g->n[0]; i++)
                s += st->field.velocity[0][grid_idx(g, i, j, k)];
            t[(size_t)(lo[1] + j) * G->n[2] + (lo[2] + k)] = s;
        }
    march_sum_array(st, t, (int)cells);
    for (size_t q = 0; q < cells; q++)
        t[q] /= G->n[0];
    return t;
}

static double table_flow_rate(const struct march_state *st, const double *t)
{
    const struct grid *G = march_global_grid(st);
    const struct muflow_case *cs = st->cs;
    double flux = 0.0;
    for (int j = 0; j < G->n[1]; j++)
        for (int k = 0; k < G->n[2]; k++)
            flux += t[(size_t)j * G->n[2] + k];
    flux *= G->h[1] * G->h[2];
    double d = cs->rheo.grain_diameter;
    return flux / G->len[1] / (d * sqrt(cs->gravity * d));
}

double heap_flow_rate(const struct march_state *st)
{
    double *t = column_table(st);
    const double q = t ? table_flow_rate(st, t) : NAN;
    free(t);
    return q;
}

/* Depth below the surface where u of column u (nz layers of height h,
 * the domain lz high) first falls to target, scanning down. */
static double column_depth(const double *u, int nz, double h, double lz, double target)
{
    double above = u[nz - 1];
    if (!(above > target))
        return 0.0;
    for (int k = nz - 2; k >= 0; k--) {
        if (u[k] <= target) {
            double z = (k + 0.5 + (target - u[k]) / (above - u[k])) * h;
            return lz - z;
        }
        above = u[k];
    }
    return lz;
}

void heap_profile_free(struct heap_profile *hp)
{
    free(hp->y);
    free(hp->u_surface);
    free(hp->depth);
    memset(hp, 0, sizeof *hp);
}

int heap_profile_extract(struct heap_profile *hp, const struct march_state *st, double fraction)
{
    memset(hp, 0, sizeof *hp);
    const struct grid *g = march_global_grid(st);
    int n = g->n[1], nz = g->n[2], top = nz - 1;
    if (n < 2 || top < 1)
        return -1;
    double *t = column_table(st);
    hp->n = n;
    hp->y = malloc((size_t)n * sizeof(double));
    hp->u_surface = malloc((size_t)n * sizeof(double));
    hp->depth = malloc((size_t)n * sizeof(double));
    if (!t || !hp->y || !hp->u_surface || !hp->depth) {
        free(t);
        heap_profile_free(hp);
        return -1;
    }
    for (int j = 0; j < n; j++) {
        const double *u = t + (size_t)j * nz;
        hp->y[j] = (j + 0.5) * g->h[1];
        hp->u_surface[j] = profile_zero_slope_end(u[top], u[top - 1]);
        hp->depth[j] = column_depth(u, nz, g->h[2], g->len[2], fraction * hp->u_surface[j]);
    }
    free(t);
    /* the free surface carries no shear stress and the mid-plane is a
     * symmetry plane: both have zero slope */
    hp->u_surface_mid = profile_zero_slope_end(hp->u_surface[n - 1], hp->u_surface[n - 2]);
    hp->depth_mid = profile_zero_slope_end(hp->depth[n - 1], hp->depth[n - 2]);
    return 0;
}

/* ------------------------------------------------------------------------ */
/* The scene: keys, checks, the tilt search as its driver, its outputs. */

#define HALF_PI 1.57079632679489661923
#define T struct heap_params
static const struct key heap_keys[] = {
    KEY_DBL(T, "heap", "flow_rate", flow_rate,
            "target flow rate per unit width Q* = Q / (d sqrt(g d)): the tilt is searched over "
            "steady solves (0: one solve at physics.tilt)",
            KEY_GE0),
    KEY_DBLT(T, "heap", "tilt_min", tilt_min, "must be in (0, pi/2) (radians)",
             KEY_HELP("low end of the search's tilt bracket, Q*(tilt_min) < target", "rad", NULL),
             KEY_RANGE(0, HALF_PI, 0, 0)),
    KEY_DBLT(T, "heap", "tilt_max", tilt_max, "must be in (0, pi/2) (radians)",
             KEY_HELP("high end of the search's tilt bracket, Q*(tilt_max) > target", "rad",
                      NULL),
             KEY_RANGE(0, HALF_PI, 0, 0)),
    KEY_DBL(T, "heap", "flow_rate_tolerance", flow_rate_tolerance,
            "the search ends when |Q* / target - 1| is at most this", KEY_RANGE(0, 0.5, 0, 1)),
    KEY_INT(T, "heap", "max_solves", max_solves,
            "steady solves the search may take (the two bracket ends included)",
            KEY_RANGE(2, 1000, 1, 1)),
    KEY_DBL(T, "heap", "depth_fraction", depth_fraction,
            "flowing depth of a column: where its velocity falls to this fraction of its "
            "surface velocity",
            KEY_RANGE(0, 1, 0, 0)),
};
#undef T

static void heap_defaults(void *block)
{
    struct heap_params *h = block;
    h->flow_rate = 0.0;
    h->tilt_min = 0.37; /* just above atan(mu_s) for the default mu_s */
    h->tilt_max = 0.45;
    h->flow_rate_tolerance = 1e-3;
    h->max_solves = 30;
    h->depth_fraction = 0.01;
}

SCENE_PARAMS(heap_block, "heap",
             "Surface flow on a heap between rough side walls (`cases/heap.ini`).  With "
             "`flow_rate > 0` the tilt of that flow rate is found by a bracketing root finder "
             "(Brent) over steady solves, each continued from a previous one; the search needs "
             "`solver.mode = steady`, needs `tilt_min < tilt_max`, and cannot be combined with "
             "`output.checkpoint_every` or `--restart`.  The scene writes `heap.csv` (the "
             "surface velocity and flowing depth of each column).",
             struct heap_params, heap_keys, heap_defaults)

/* The cross-section: periodic along the flow, side wall at y = 0 and
 * symmetry plane at y = ly, static base and free surface in z. */
static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    static const enum bc_kind want[3][2] = {
        {BC_PERIODIC, BC_PERIODIC}, {BC_WALL, BC_SLIP}, {BC_WALL, BC_SURFACE}};
    static const char axis[3] = {'x', 'y', 'z'};
    const struct heap_params *h = params(c);
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] != want[d][side]) {
                snprintf(msg, msglen,
                         "case.scene = heap needs boundary.%c%s = %s (periodic along the flow, "
                         "side wall at y = 0, mid-plane at y = ly, base, free surface), not %s",
                         axis[d], side ? "hi" : "lo", bc_kind_name(want[d][side]),
                         bc_kind_name(c->bc.face[d][side]));
                return 1;
            }
    if (c->rheo.law != LAW_MUI) {
        snprintf(msg, msglen, "case.scene = heap needs rheology.law = mui");
        return 1;
    }
    if (c->n[1] < 2 || c->n[2] < 2) {
        snprintf(msg, msglen, "case.scene = heap needs domain.ny >= 2 and domain.nz >= 2 (got %d, %d)",
                 c->n[1], c->n[2]);
        return 1;
    }
    if (h->flow_rate > 0.0) {
        if (!(h->tilt_min < h->tilt_max)) {
            snprintf(msg, msglen, "heap.tilt_min = %s, heap.tilt_max = %s: the bracket needs "
                                  "heap.tilt_min < heap.tilt_max",
                     num_text(h->tilt_min).s, num_text(h->tilt_max).s);
            return 1;
        }
        if (c->mode != MODE_STEADY || c->checkpoint_every > 0) {
            snprintf(msg, msglen, "heap.flow_rate > 0 (a tilt search over steady solves) needs "
                                  "solver.mode = steady and output.checkpoint_every = 0");
            return 1;
        }
    }
    return 0;
}

static const char *not_restartable(const struct muflow_case *cs)
{
    return params(cs)->flow_rate > 0.0
               ? "a tilt search (heap.flow_rate > 0) cannot continue from a checkpoint: run it "
                 "again, starting from physics.tilt"
               : NULL;
}

struct report_ctx {
    const struct muflow_case *cs;
    double start;
    int verbose;
};

static void report_solve(void *vctx, int solve, double tilt, double flow_rate,
                         const struct march_state *st)
{
    struct report_ctx *r = vctx;
    if (!r->verbose)
        return;
    double target = params(r->cs)->flow_rate;
    printf("heap: solve %2d  tilt %.8f  Q* %-10.6g (target %g, %+.3f%%)  %s after %ld steps  "
           "[%.1f s]\n",
           solve, tilt, flow_rate, target, 100.0 * (flow_rate / target - 1.0),
           run_status_name(st->status), st->step, omp_get_wtime() - r->start);
    fflush(stdout);
}

/* The driver: with heap.flow_rate the tilt by root finding over steady
 * solves (a search that fails or misses the tolerance ends "stopped", or
 * with the failed solve's status, and says why); without it one march. */
static int drive(struct scene_drive *d)
{
    struct march_state *st = d->st;
    struct tilt_search_result *sr = (struct tilt_search_result *)d->data.bytes;
    _Static_assert(sizeof(struct tilt_search_result) <= sizeof d->data.bytes, "drive data");
    memset(sr, 0, sizeof *sr);
    const struct heap_params *h = params(d->cs);
    if (!(h->flow_rate > 0.0)) {
        march_run(st, d->observe, d->observe_ctx);
        return 0;
    }
    struct tilt_search_spec spec = {
        .target = h->flow_rate, .tilt_min = h->tilt_min, .tilt_max = h->tilt_max,
        .tolerance = h->flow_rate_tolerance, .max_solves = h->max_solves,
        .flow_rate = heap_flow_rate};
    struct report_ctx r = {d->cs, omp_get_wtime(), d->verbose};
    tilt_search_run(st, d->cs, &spec, d->observe, d->observe_ctx, report_solve, &r, sr);
    sr->searched = 1;
    st->wall_seconds = omp_get_wtime() - r.start; /* the whole search */
    if (!sr->converged && st->status == STATUS_STEADY)
        st->status = STATUS_STOPPED;
    /* a stop by a signal or a failed output is renamed by the run */
    snprintf(st->message, sizeof st->message, "%s", sr->message);
    return 0;
}

/* A decomposed run's profile for heap.csv: rank 0 writes it alone, after
 * every rank has reduced the columns in results (write may not reduce). */
static struct heap_profile ranks_profile;

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    const struct muflow_case *cs = st->cs;
    const struct heap_params *h = params(cs);
    const struct tilt_search_result *sr = (const struct tilt_search_result *)d->data.bytes;
    struct heap_profile hp;
    int have = heap_profile_extract(&hp, st, h->depth_fraction) == 0;
    heap_profile_free(&ranks_profile);
    double q = heap_flow_rate(st);
    double u_mid = have ? hp.u_surface_mid : NAN, depth_mid = have ? hp.depth_mid : NAN;
    int solves = sr->searched ? sr->solves : 1;
    long steps = sr->searched ? sr->steps : st->step;
    run_result_add(res, "tilt", "%.10g", cs->tilt);
    run_result_add(res, "flow_rate", "%.10g", q);
    if (sr->searched) {
        run_result_add(res, "flow_rate_target", "%.10g", h->flow_rate);
        run_result_add(res, "flow_rate_error", "%.6e", q / h->flow_rate - 1.0);
        run_result_add(res, "search_converged", "%s", sr->converged ? "true" : "false");
        snprintf(res->stop_note, sizeof res->stop_note,
                 "during the tilt search (a search is not restartable); the last solve's tilt "
                 "%.8g can start a new search",
                 cs->tilt);
    }
    run_result_add(res, "solves", "%d", solves);
    run_result_add(res, "steps_total", "%ld", steps);
    run_result_add(res, "u_surface_mid", "%.10g", u_mid);
    run_result_add(res, "depth_mid", "%.10g", depth_mid);
    snprintf(res->scene_line, sizeof res->scene_line,
             "tilt %.8g (%.4f deg)  Q* %.6g  %d solve%s, %ld steps  mid-plane: u_surface %.5g, "
             "flowing depth %.5g",
             cs->tilt, cs->tilt * 180.0 / 3.14159265358979323846, q, solves,
             solves == 1 ? "" : "s", steps, u_mid, depth_mid);
    if (have && st->ranks)
        ranks_profile = hp;
    else if (have)
        heap_profile_free(&hp);
}

/* heap.csv: per column across the channel, y, surface velocity, flowing depth. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    struct heap_profile hp;
    if (st->ranks) { /* the profile results reduced (ranks_profile) */
        if (ranks_profile.n == 0)
            return 0;
        hp = ranks_profile;
        memset(&ranks_profile, 0, sizeof ranks_profile);
    } else if (heap_profile_extract(&hp, st, params(st->cs)->depth_fraction) != 0) {
        return 0;
    }
    struct output_file f;
    int rc = output_open(&f, dir, "heap.csv", err, errlen);
    if (rc == 0) {
        fprintf(f.f, "y,u_surface,flowing_depth\n");
        for (int j = 0; j < hp.n; j++)
            fprintf(f.f, "%.10g,%.12g,%.10g\n", hp.y[j], hp.u_surface[j], hp.depth[j]);
        rc = output_commit(&f, err, errlen);
    }
    heap_profile_free(&hp);
    return rc;
}

static const char *const heap_files[] = {"heap.csv", NULL};

static int along_x(const struct muflow_case *cs)
{
    (void)cs;
    return 1;
}

const struct scene scene_heap = {
    .name = "heap",
    .title = "surface flow on a heap between rough side walls (tilt for a flow rate)",
    .keys = &heap_block,
    .check = check,
    .cross_section_flow = along_x,
    .decomposed = scene_decomposed_always,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .not_restartable = not_restartable,
    .results = results,
    .write = write,
    .files = heap_files,
};
