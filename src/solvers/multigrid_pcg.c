/* The cycle, and the two solvers built on it: stationary cycles and
 * conjugate gradients preconditioned by one cycle (multigrid_internal.h). */
#include "solvers/multigrid_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

#define PCG_GROWTH 100.0       /* CG stops where its residual exceeds its best this much */
/* the residual's rounding in eps (|b| + |L||x|): a 5-term sum in a plane;
 * a 7-term sum in 3D, where the 3D square column's solves (64 x 64 x 32,
 * density ratio 1e3) stalled at 1.4-2.4 times 10 eps |m| through every
 * restart (docs/numerics/pressure.md) */
#define ROUNDOFF_TERMS_2D 10.0
#define ROUNDOFF_TERMS_3D 40.0

/* Cycle on level l from x = 0 (warm: from the current x): pre-smoothing red
 * then black, post-smoothing black then red (the adjoint order), restriction
 * the scaled transpose of the prolongation, gamma cycles on the next level
 * (1: V, 2: W; the later ones warm), an exact coarsest solve: a symmetric
 * linear map of b. */
/* The gathered level of a decomposed hierarchy (the last kept on the
 * ranks): its right-hand side (and, warm, its unknown) gathered on every
 * rank, the serial multigrid's cycle from there on (the same cycle as an
 * undecomposed hierarchy's from that level), this rank's block taken back. */
static void cycle_from(struct multigrid *mg, int l, int warm);
static void gathered_cycle(struct multigrid *mg, int warm)
{
    struct level *lv = &mg->lev[mg->nlev - 1];
    struct multigrid *sub = mg->sub;
    decomp_gather(lv->dc, &lv->g, lv->b, &mg->gg, mg->gb, mg->gscratch);
    if (warm)
        decomp_gather(lv->dc, &lv->g, lv->x, &mg->gg, mg->gx, mg->gscratch);
    sub->lev[0].b = mg->gb;
    sub->lev[0].x = mg->gx;
    cycle_from(sub, 0, warm);
    decomp_scatter(lv->dc, &mg->gg, mg->gx, &lv->g, lv->x);
}

static void cycle_from(struct multigrid *mg, int l, int warm)
{
    struct level *lv = &mg->lev[l];
    if (mg->sub && l == mg->nlev - 1) {
        gathered_cycle(mg, warm);
        return;
    }
    if (l == mg->nlev - 1) {
        mg_coarse_solve(mg);
        return;
    }
    struct level *lc = &mg->lev[l + 1];
    /* two parallel regions per level and cycle: fork/join costs more than the
     * loops of a small level, and much more on a loaded machine */
    REGION(lv->par, {
        if (!warm)
            mg_zero_interior(lv, lv->x);
        mg_smooth(mg, lv, 0, mg->opt.pre);
        if (mg_halo_wraps(mg, lv))
            mg_halo_fill(mg, lv, lv->x, HALO_OPERATOR);
        mg_residual(lv, lv->x, lv->b, 0.0, lv->r);
        mg_halo_fill(mg, lv, lv->r, HALO_MIRROR);
        mg_restrict_residual(mg, lv, lc);
    });
    const int visits = l + 1 == mg->total_levels - 1 ? 1 : mg->opt.gamma; /* exact there */
    for (int v = 0; v < visits; v++)
        cycle_from(mg, l + 1, v > 0);
    REGION(lv->par, {
        mg_halo_fill(mg, lc, lc->x, HALO_MIRROR);
        mg_prolong_add(lv, lc);
        mg_smooth(mg, lv, 1, mg->opt.post);
    });
}

void multigrid_cycle(struct multigrid *mg, const double *r, double *z)
{
    mg->lev[0].b = r;
    mg->lev[0].x = z;
    cycle_from(mg, 0, 0);
    mg->lev[0].b = NULL;
    mg->lev[0].x = NULL;
}

/* ---- deterministic reductions --------------------------------------------------- */

static int team_size(const struct level *lv)
{
#ifdef _OPENMP
    int t = lv->par ? omp_get_max_threads() : 1;
    return t < MAX_THREADS ? t : MAX_THREADS;
#else
    (void)lv;
    return 1;
#endif
}

/* Per-thread partial sums over a static schedule, added in thread order: the
 * result repeats bit for bit at a given thread count. */
static double sum_partials(const double *part, int nt)
{
    double s = 0.0;
    for (int t = 0; t < nt; t++)
        s += part[t * PAD];
    return s;
}

/* The reductions over a level's interior: sum u v over every cell, or over
 * the live cells sum u or sum (u - shift)^2.  One loop for the three, its
 * kind a constant at each inlined call, so that all three keep the same
 * deterministic per-thread partials. */
enum level_sum { SUM_DOT, SUM_LIVE, SUM_LIVE_SQUARES };

static inline __attribute__((always_inline)) double
level_reduce(struct multigrid *mg, const struct level *lv, enum level_sum kind, const double *u,
             const double *v, double shift)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2], nt = team_size(lv);
    const unsigned char *live = lv->live;
    double *part = mg->partial;
    for (int t = 0; t < nt; t++)
        part[t * PAD] = 0.0;
    REGION_NT({
        double s = 0.0;
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++) {
                    if (kind == SUM_DOT) {
                        s += u[row + k] * v[row + k];
                    } else if (kind == SUM_LIVE) {
                        s += live[row + k] ? u[row + k] : 0.0;
                    } else {
                        double w = u[row + k] - shift;
                        s += live[row + k] ? w * w : 0.0;
                    }
                }
            }
        part[thread_id() * PAD] = s;
    });
    double sum = sum_partials(part, nt);
    if (lv->dc)
        comm_sum(&sum, 1);
    return sum;
}

/* sum over the interior of u v */
static double dot(struct multigrid *mg, const struct level *lv, const double *u, const double *v)
{
    return level_reduce(mg, lv, SUM_DOT, u, v, 0.0);
}

/* sum of f over the live cells */
static double live_sum(struct multigrid *mg, const struct level *lv, const double *f)
{
    return level_reduce(mg, lv, SUM_LIVE, f, NULL, 0.0);
}

/* sum of (f - shift)^2 over the live cells */
static double live_norm2(struct multigrid *mg, const struct level *lv, const double *f,
                         double shift)
{
    return level_reduce(mg, lv, SUM_LIVE_SQUARES, f, NULL, shift);
}

/* ---- the solvers ---------------------------------------------------------------- */

/* r = rhs - shift - L phi (phi's ghosts filled here) */
static void fine_residual(struct multigrid *mg, double *phi, const double *rhs, double shift,
                          double *r)
{
    REGION(mg->lev[0].par, {
        mg_halo_fill(mg, &mg->lev[0], phi, HALO_OPERATOR);
        mg_residual(&mg->lev[0], phi, rhs, shift, r);
    });
}

static int singular(const struct multigrid *mg)
{
    if (mg->lev[0].m)
        return 0; /* a mass term: a component without mass or Dirichlet face is pinned
                     (mg_coarse_assemble) */
    for (int d = 0; d < 3; d++)
        if (mg->bc[d][0] == POISSON_DIRICHLET || mg->bc[d][1] == POISSON_DIRICHLET)
            return 0;
    return 1;
}

/* Mean of rhs over the live cells for a singular problem (else 0). */
static double rhs_shift(struct multigrid *mg, const double *rhs)
{
    if (!singular(mg) || mg->live == 0)
        return 0.0;
    return live_sum(mg, &mg->lev[0], rhs) / (double)mg->live;
}

/* phi: dead cells 0, zero mean over the live cells when singular, ghosts
 * holding the conditions' values. */
static void finish_phi(struct multigrid *mg, double *phi)
{
    struct level *l0 = &mg->lev[0];
    const double m = singular(mg) && mg->live ? live_sum(mg, l0, phi) / (double)mg->live : 0.0;
    const struct grid *g = &l0->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const unsigned char *live = l0->live;
    REGION(l0->par, {
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++)
                    phi[row + k] = live[row + k] ? phi[row + k] - m : 0.0;
            }
        mg_halo_fill(mg, l0, phi, HALO_RESULT);
    });
}

static void stats_init(struct multigrid_stats *st, double res0)
{
    memset(st, 0, sizeof(*st));
    st->res0 = res0;
    st->rel = 1.0;
    st->rate = 0.0;
}

static void stats_step(struct multigrid_stats *st, double rel)
{
    if (st->cycles < MULTIGRID_HISTORY) {
        st->history[st->cycles] = rel;
        st->reduction[st->cycles] = st->rel > 0.0 ? rel / st->rel : 0.0;
    }
    st->cycles++;
    st->rel = rel;
}

static int stats_end(struct multigrid_stats *st, double rtol, struct multigrid_stats *out)
{
    st->converged = st->rel <= rtol || st->roundoff;
    st->rate = st->cycles > 0 && st->rel > 0.0 ? pow(st->rel, 1.0 / st->cycles) : 0.0;
    if (!isfinite(st->rel))
        st->rate = INFINITY; /* diverged */
    if (out)
        *out = *st;
    return st->converged ? 0 : 1;
}

/* x += z on the interior */
static void add_to(const struct level *lv, double *x, const double *z)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                x[row + k] += z[row + k];
        }
}

/* What both solves start with: no coefficients (-1 into *rc), or the
 * shifted rhs's norm; a zero rhs is solved by phi = 0 (its result into
 * *rc).  Returns 1 when *rc is the solve's answer, 0 to go on. */
static int solve_begin(struct multigrid *mg, const double *rhs, double *phi, double rtol,
                       struct multigrid_stats *stats, struct multigrid_stats *st,
                       double *shift, double *res0, int *rc)
{
    if (!mg->ready) { /* no (valid) coefficients */
        if (stats)
            memset(stats, 0, sizeof(*stats));
        *rc = -1;
        return 1;
    }
    struct level *l0 = &mg->lev[0];
    *shift = rhs_shift(mg, rhs);
    *res0 = sqrt(live_norm2(mg, l0, rhs, *shift));
    stats_init(st, *res0);
    if (!(*res0 > 0.0)) {
        REGION(l0->par, mg_zero_interior(l0, phi));
        st->rel = 0.0;
        finish_phi(mg, phi);
        *rc = stats_end(st, rtol, stats);
        return 1;
    }
    return 0;
}

int multigrid_solve(struct multigrid *mg, const double *rhs, double *phi, double rtol,
                    int max_cycles, struct multigrid_stats *stats)
{
    struct level *l0 = &mg->lev[0];
    struct multigrid_stats st;
    double shift, res0;
    int rc;
    if (solve_begin(mg, rhs, phi, rtol, stats, &st, &shift, &res0, &rc))
        return rc;
    fine_residual(mg, phi, rhs, shift, mg->wr);
    st.rel = sqrt(dot(mg, l0, mg->wr, mg->wr)) / res0;
    while (st.rel > rtol && st.cycles < max_cycles) {
        multigrid_cycle(mg, mg->wr, mg->wz);
        REGION(l0->par, add_to(l0, phi, mg->wz));
        fine_residual(mg, phi, rhs, shift, mg->wr);
        stats_step(&st, sqrt(dot(mg, l0, mg->wr, mg->wr)) / res0);
    }
    finish_phi(mg, phi);
    return stats_end(&st, rtol, stats);
}

/* x += alpha p, r -= alpha q; returns r.r */
static double cg_update(struct multigrid *mg, const struct level *lv, double alpha, double *x,
                        const double *p, double *r, const double *q)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2], nt = team_size(lv);
    double *part = mg->partial;
    for (int t = 0; t < nt; t++)
        part[t * PAD] = 0.0;
    REGION_NT({
        double s = 0.0;
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++) {
                    x[row + k] += alpha * p[row + k];
                    double rv = r[row + k] - alpha * q[row + k];
                    r[row + k] = rv;
                    s += rv * rv;
                }
            }
        part[thread_id() * PAD] = s;
    });
    double sum = sum_partials(part, nt);
    if (lv->dc)
        comm_sum(&sum, 1);
    return sum;
}

/* p = z + beta p */
static void cg_direction(const struct level *lv, double beta, double *p, const double *z)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                p[row + k] = z[row + k] + beta * p[row + k];
        }
}

int multigrid_pcg(struct multigrid *mg, const double *rhs, double *phi, double rtol, int max_iter,
                  struct multigrid_stats *stats)
{
    struct level *l0 = &mg->lev[0];
    struct multigrid_stats st;
    double shift, res0;
    int rc;
    if (solve_begin(mg, rhs, phi, rtol, stats, &st, &shift, &res0, &rc))
        return rc;
    double *r = mg->wr, *z = mg->wz, *p = mg->wp, *q = mg->wq;
    fine_residual(mg, phi, rhs, shift, r);
    st.rel = sqrt(dot(mg, l0, r, r)) / res0;
    if (st.rel > rtol && st.rel < 1e3 * rtol) {
        /* close to the tolerance from a previous iterate (a restart): within
         * what the residual's own rounding allows, CG can do no better */
        REGION(l0->par, mg_magnitude(l0, phi, rhs, shift, q));
        const int solid = (l0->g.n[0] > 1) + (l0->g.n[1] > 1) + (l0->g.n[2] > 1) == 3;
        const double terms = solid ? ROUNDOFF_TERMS_3D : ROUNDOFF_TERMS_2D;
        const double floor = terms * DBL_EPSILON * sqrt(dot(mg, l0, q, q));
        if (st.rel * res0 <= floor) {
            finish_phi(mg, phi);
            st.roundoff = 1;
            return stats_end(&st, rtol, stats);
        }
    }
    if (st.rel > rtol) {
        multigrid_cycle(mg, r, z);
        REGION(l0->par, cg_direction(l0, 0.0, p, z));
        double rz = dot(mg, l0, r, z);
        double best = st.rel;
        memcpy(mg->wbest, phi, l0->g.size * sizeof(double));
        /* L and the cycle are both negative definite on the live cells: CG's
         * iterates are those of the positive problem (-L, -V) */
        while (st.cycles < max_iter && rz != 0.0) {
            multigrid_apply(mg, p, q);
            const double pq = dot(mg, l0, p, q);
            if (pq == 0.0)
                break;
            const double alpha = rz / pq;
            const double rr = cg_update(mg, l0, alpha, phi, p, r, q);
            stats_step(&st, sqrt(rr) / res0);
            if (st.rel <= rtol)
                break;
            /* At the round-off of the operator the recursive residual
             * stops falling and then grows by orders of magnitude
             * (docs/numerics/multigrid.md).  Stopped where it has grown well
             * above its best, it returns the iterate of its best residual,
             * from which the caller restarts with a fresh one. */
            if (st.rel < best) {
                best = st.rel;
                memcpy(mg->wbest, phi, l0->g.size * sizeof(double));
            } else if (st.rel > PCG_GROWTH * best) {
                memcpy(phi, mg->wbest, l0->g.size * sizeof(double));
                st.rel = best;
                break;
            }
            multigrid_cycle(mg, r, z);
            const double rz_new = dot(mg, l0, r, z);
            REGION(l0->par, cg_direction(l0, rz_new / rz, p, z));
            rz = rz_new;
        }
    }
    finish_phi(mg, phi);
    return stats_end(&st, rtol, stats);
}

/* ---- the traffic's model (multigrid.h) -------------------------------------------- */

/* One halo fill of level l (decomp_exchange's planes, direction after direction). */
static void fill_traffic(const struct level *lv, long times, struct decomp_traffic *t)
{
    const struct grid *g = &lv->g;
    for (int d = 0; d < 3; d++) {
        const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
        const long sides = lv->dc->border[d][0] + lv->dc->border[d][1];
        if (sides == 0)
            continue;
        const long plane = (long)(g->n[e1] + 2) * (g->n[e2] + 2);
        t->exchanges += times;
        t->messages += times * sides;
        t->bytes += times * sides * plane * (long)sizeof(double);
    }
}

static void gather_traffic(const struct multigrid *mg, long times, struct decomp_traffic *t)
{
    const struct level *lv = &mg->lev[mg->nlev - 1];
    const long all = (long)decomp_gather_len(lv->dc), own = (long)lv->g.size;
    if (all == own)
        return; /* one rank */
    t->gathers += times;
    t->gather_sent += times * own * (long)sizeof(double);
    t->gather_received += times * (all - own) * (long)sizeof(double);
}

void multigrid_traffic_model(const struct multigrid *mg, int iterations,
                             struct decomp_traffic *cycle, struct decomp_traffic *solve,
                             long *reductions)
{
    memset(cycle, 0, sizeof *cycle);
    const int last = mg->nlev - 1; /* the gathered level */
    const long fills = 2L * (mg->opt.pre + mg->opt.post) + 2;
    long visits = 1, above = 1; /* of level l; of the level above the gathered one */
    for (int l = 0; l < last; l++) {
        fill_traffic(&mg->lev[l], visits * fills, cycle);
        fill_traffic(&mg->lev[l + 1], visits, cycle); /* the correction's fill */
        above = visits;
        visits *= l + 1 == mg->total_levels - 1 ? 1 : mg->opt.gamma;
    }
    gather_traffic(mg, visits, cycle);                 /* b at every visit */
    gather_traffic(mg, last > 0 ? visits - above : 0, cycle); /* x at the warm ones */
    *solve = *cycle;
    struct decomp_traffic *s = solve;
    const long it = iterations;
    s->exchanges *= it;
    s->messages *= it;
    s->bytes *= it;
    s->gathers *= it;
    s->gather_sent *= it;
    s->gather_received *= it;
    fill_traffic(&mg->lev[0], it + 2, s); /* the first residual, L p, the result */
    /* |b|, r.r, r.z, per iteration p.q, r.r and (not after the last) r.z;
     * a singular problem's mean of b and of phi */
    *reductions = 3 * it + 2 + (singular(mg) ? 2 : 0);
}
