/* The time loop (see march.h). */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "march/march.h"

/* Steps without a 10% improvement of the best residual after which a steady
 * march is declared unable to reach a steady state. */
#define STALL_STEPS 200
#define STALL_FACTOR 0.9
/* A steady-mode step that multiplies the residual by more than this is
 * rejected and retried with a ten times smaller pseudo-time step: a linearised
 * step far from the solution can overshoot into spurious states. */
#define REJECT_GROWTH 2.0
#define MIN_DT_SCALE 1e-12
/* max |div u| h / max |u| above which a state is not solenoidal to round-off
 * (advance projects it once more). */
#define DIVERGENCE_ROUNDOFF 1e-12
/* Round-off allowance of the residual, in machine epsilons of its terms. */
#define ROUNDOFF_EPS (16.0 * DBL_EPSILON)

const char *run_status_name(enum run_status s)
{
    switch (s) {
    case STATUS_RUNNING: return "running";
    case STATUS_STEADY: return "steady";
    case STATUS_FINISHED: return "finished";
    case STATUS_UNSTEADY: return "unsteady";
    case STATUS_DIVERGED: return "diverged";
    case STATUS_STOPPED: return "stopped";
    }
    return "?";
}

static void copy_fields(const struct grid *g, double *const src[3], double *dst[3])
{
    for (int c = 0; c < 3; c++)
        memcpy(dst[c], src[c], g->size * sizeof(double));
}

static void gravity_vector(const struct muflow_case *cs, double f[3])
{
    double rg = cs->density * cs->gravity;
    f[0] = rg * sin(cs->tilt);
    f[1] = 0.0;
    f[2] = -rg * cos(cs->tilt);
}

/* Hydrostatic pressure of the body force: the pressure whose gradient removes
 * the curl-free part of the force under the walls' no-penetration condition,
 * with p = 0 on free surfaces.  The remaining force drives the flow. */
static int hydrostatic_split(struct march_state *st, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    double f[3];
    gravity_vector(st->cs, f);
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) {
            enum bc_kind k = st->bc.face[d][s];
            pbc[d][s] = k == BC_PERIODIC  ? POISSON_PERIODIC
                        : k == BC_SURFACE ? POISSON_DIRICHLET
                                          : POISSON_NEUMANN;
        }
    /* fluxes of the force through every face; a closed boundary face passes none */
    double **flux = st->delta;
    for (int a = 0; a < 3; a++)
        for (int i = -1; i <= g->n[0]; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    int idx[3] = {i, j, k};
                    int face = idx[a];
                    double v = f[a];
                    if (st->bc.face[a][0] != BC_PERIODIC &&
                        ((face <= 0 && st->bc.face[a][0] != BC_SURFACE) ||
                         (face >= g->n[a] && st->bc.face[a][1] != BC_SURFACE)))
                        v = 0.0;
                    flux[a][grid_idx(g, i, j, k)] = v;
                }
    kernel_divergence(g, flux, st->div);
    struct poisson_fft *ps;
    if (poisson_fft_create(&ps, g, (const enum poisson_bc(*)[2])pbc, err, errlen) != 0)
        return -1;
    poisson_fft_solve(ps, st->div, st->p_hyd);
    poisson_fft_destroy(ps);
    bc_fill_scalar(g, &st->bc, st->p_hyd);
    for (int a = 0; a < 3; a++)
        for (size_t p = 0; p < g->size; p++)
            st->force[a][p] = f[a];
    kernel_gradient_update(g, st->act, st->p_hyd, 1.0, st->force);
    for (int a = 0; a < 3; a++) /* only unknown faces carry a force */
        for (int i = -1; i <= g->n[0]; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++) {
                    const struct box *b = &st->act[a];
                    if (i < b->lo[0] || i >= b->hi[0] || j < b->lo[1] || j >= b->hi[1] ||
                        k < b->lo[2] || k >= b->hi[2])
                        st->force[a][grid_idx(g, i, j, k)] = 0.0;
                }
    return 0;
}

/* Line blocks are exact for flows uniform across lines and cheap; a flow that
 * varies in two or more directions gets the sparse Cholesky factorisation
 * while the grid is small enough for it. */
#define CHOLESKY_MAX_UNKNOWNS 400000L

static enum viscous_precond choose_preconditioner(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    switch (cs->preconditioner) {
    case PRECOND_LINE: return VISCOUS_LINE;
    case PRECOND_CHOLESKY: return VISCOUS_CHOLESKY;
    case PRECOND_LU: return VISCOUS_LU;
    case PRECOND_AUTO: break;
    }
    int wide = 0;
    for (int d = 0; d < 3; d++)
        wide += st->g.n[d] > 2;
    long unknowns = 3L * (long)grid_cells(&st->g);
    if (wide < 2 || unknowns > CHOLESKY_MAX_UNKNOWNS)
        return VISCOUS_LINE;
    /* in a flow that varies in two directions the strain components couple
     * through |D|: Newton needs the full tangent, which is not symmetric */
    return cs->newton ? VISCOUS_LU : VISCOUS_CHOLESKY;
}

int march_create(struct march_state *st, const struct muflow_case *cs, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    st->cs = cs;
    st->bc = cs->bc;
    if (grid_init(&st->g, cs->n, cs->len) != 0) {
        snprintf(err, errlen, "grid: invalid cell counts or lengths");
        return -1;
    }
    const struct grid *g = &st->g;
    bc_unknown_boxes(g, &st->bc, st->act);
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        ok &= (st->vel[c] = field_alloc(g)) != NULL;
        ok &= (st->force[c] = field_alloc(g)) != NULL;
        ok &= (st->res[c] = field_alloc(g)) != NULL;
        ok &= (st->delta[c] = field_alloc(g)) != NULL;
        ok &= (st->adv[c] = field_alloc(g)) != NULL;
        ok &= (st->good_vel[c] = field_alloc(g)) != NULL;
        ok &= (st->e2[c] = field_alloc(g)) != NULL;
        ok &= (st->tan_c[c] = field_alloc(g)) != NULL;
        ok &= (st->eta_e[c] = field_alloc(g)) != NULL;
        ok &= (st->tan_e[c] = field_alloc(g)) != NULL;
    }
    double **cells[] = {&st->p_dyn, &st->p_hyd, &st->pressure, &st->shear2, &st->eta,
                        &st->cn2, &st->preg, &st->div, &st->phi, &st->good_p_dyn};
    for (size_t m = 0; m < sizeof cells / sizeof cells[0]; m++)
        ok &= (*cells[m] = field_alloc(g)) != NULL;
    if (!ok) {
        snprintf(err, errlen, "out of memory for a %d x %d x %d grid", g->n[0], g->n[1], g->n[2]);
        march_destroy(st);
        return -1;
    }
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            pbc[d][s] = st->bc.face[d][s] == BC_PERIODIC ? POISSON_PERIODIC : POISSON_NEUMANN;
    enum viscous_precond kind = choose_preconditioner(st);
    st->full_tangent = kind == VISCOUS_LU && cs->newton;
    if (cs->augmentation > 0.0)
        ok &= (st->aug = field_alloc(g)) != NULL;
    if (st->full_tangent) {
        ok &= (st->b_c = field_alloc(g)) != NULL;
        for (int c = 0; c < 3; c++)
            ok &= (st->b_e[c] = field_alloc(g)) != NULL;
        if (!ok) {
            snprintf(err, errlen, "out of memory for the full tangent");
            march_destroy(st);
            return -1;
        }
    }
    if (poisson_fft_create(&st->poisson, g, (const enum poisson_bc(*)[2])pbc, err, errlen) != 0 ||
        viscous_create(&st->viscous, g, &st->bc, st->act, cs->line_direction, kind, err,
                       errlen) != 0 ||
        hydrostatic_split(st, err, errlen) != 0) {
        march_destroy(st);
        return -1;
    }
    st->dt = cs->dt;
    st->best_residual = INFINITY;
    st->dt_scale = 1.0;
    return 0;
}

void march_destroy(struct march_state *st)
{
    for (int c = 0; c < 3; c++) {
        field_free(st->vel[c]);
        field_free(st->force[c]);
        field_free(st->res[c]);
        field_free(st->delta[c]);
        field_free(st->adv[c]);
        field_free(st->good_vel[c]);
        field_free(st->e2[c]);
        field_free(st->tan_c[c]);
        field_free(st->eta_e[c]);
        field_free(st->tan_e[c]);
        field_free(st->b_e[c]);
    }
    field_free(st->b_c);
    field_free(st->aug);
    double *cells[] = {st->p_dyn, st->p_hyd, st->pressure, st->shear2, st->eta,
                       st->cn2, st->preg, st->div, st->phi, st->good_p_dyn};
    for (size_t m = 0; m < sizeof cells / sizeof cells[0]; m++)
        field_free(cells[m]);
    if (st->poisson)
        poisson_fft_destroy(st->poisson);
    viscous_destroy(st->viscous);
    memset(st, 0, sizeof *st);
}

int march_reforce(struct march_state *st, char *err, size_t errlen)
{
    if (hydrostatic_split(st, err, errlen) != 0)
        return -1;
    st->force_ref = 0.0; /* rho g may have changed */
    st->step = 0;
    st->time = 0.0;
    st->dt = st->cs->dt;
    /* residual0 is kept: it sets the pseudo-time step dt = dt0 r0 / r, and the
     * first residual of a continued solve is already small, so resetting it
     * would hold dt near dt0 and march through the physical transient (a heap
     * solve from the previous tilt: 150-250 steps instead of 15-40 from rest) */
    st->rejected = 0;
    st->best_residual = INFINITY;
    st->best_step = 0;
    st->dt_scale = 1.0;
    st->wall_seconds = 0.0;
    st->status = STATUS_RUNNING;
    st->message[0] = '\0';
    return 0;
}

static double force_scale(const struct march_state *st)
{
    return st->force_ref > 0.0 ? st->force_ref : 1.0;
}

static double min_spacing(const struct grid *g)
{
    double h = g->h[0];
    for (int d = 1; d < 3; d++)
        if (g->n[d] > 1 && g->h[d] < h)
            h = g->h[d];
    return h;
}

/* Viscosity at the current state and the steady momentum residual
 *   R = f - grad p_dyn + div(eta gamma(u)) - rho div(u u). */
static void evaluate_residual(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    bc_fill_velocity(g, &st->bc, st->vel);
    kernel_strain(g, st->vel, st->cn2, st->e2);
    bc_fill_scalar(g, &st->bc, st->cn2);
    for (size_t p = 0; p < g->size; p++)
        st->pressure[p] = cs->confining_pressure + st->p_hyd[p] + st->p_dyn[p];
    bc_fill_scalar_linear(g, &st->bc, st->pressure);
    kernel_viscosity_cells(g, &cs->rheo, st->vel, st->cn2, st->e2, st->pressure, st->eta,
                           cs->newton ? st->tan_c : NULL, st->shear2, st->preg, st->b_c);
    kernel_viscosity_edges(g, &cs->rheo, st->cn2, st->e2, st->pressure, st->eta_e,
                           cs->newton ? st->tan_e : NULL, st->full_tangent ? st->b_e : NULL);
    bc_fill_scalar(g, &st->bc, st->eta);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->tan_c[a]);
    const double *eta_cell[3] = {st->eta, st->eta, st->eta};
    kernel_stress_divergence(g, st->act, eta_cell, (const double *const *)st->eta_e, st->vel,
                             st->res);
    kernel_axpy(g, st->act, 1.0, st->force, st->res);
    bc_fill_scalar(g, &st->bc, st->p_dyn);
    kernel_gradient_update(g, st->act, st->p_dyn, 1.0, st->res);
    if (cs->advection) {
        kernel_advection(g, st->act, st->vel, st->adv);
        kernel_axpy(g, st->act, cs->density, st->adv, st->res);
    }
    if (st->aug) {
        /* The grad-div augmentation r = kappa max(eta) of the implicit
         * operator.  It enters the operator and the Uzawa update only, not
         * this residual: u is solenoidal to round-off after each projection,
         * where grad(r div u) would be that round-off times r.  One r for the
         * whole field, not kappa eta per cell: the Uzawa update contracts the
         * pressure error by 1/(1 + r s) for each eigenvalue s of the Schur
         * complement div A^-1 grad, and s can be as small as 1/max(eta) in any
         * cell (a pressure mode in a yielded layer is resisted by the plug
         * beside it).  With r = kappa eta_cell a Vola Bn = 1000 cavity
         * contracted by 0.994 per step; with r = kappa max(eta) by < 1/kappa. */
        double r = cs->augmentation * kernel_max_abs_cells(g, st->eta);
        for (size_t p = 0; p < g->size; p++)
            st->aug[p] = r;
    }
    if (st->force_ref == 0.0) {
        double rg = cs->density * cs->gravity;
        st->force_ref = rg > 0.0 ? rg : kernel_max_abs(g, st->act, st->res);
    }
    double scale = force_scale(st);
    st->residual = kernel_max_abs(g, st->act, st->res) / scale;
    kernel_stress_magnitude(g, st->act, eta_cell, (const double *const *)st->eta_e, st->vel,
                            st->delta);
    st->residual_excess = kernel_residual_excess(g, st->act, st->res, st->delta, st->force,
                                                 ROUNDOFF_EPS) / scale;
    kernel_divergence(g, st->vel, st->div);
    double umax = kernel_max_abs(g, st->act, st->vel);
    double dmax = kernel_max_abs_cells(g, st->div);
    st->divergence = umax > 0.0 ? dmax * min_spacing(g) / umax : dmax;
}

double march_mean_acceleration(const struct march_state *st)
{
    /* mean residual per unit mass of the component the body force drives */
    double f[3];
    gravity_vector(st->cs, f);
    int a = fabs(f[0]) >= fabs(f[2]) ? 0 : 2;
    if (st->bc.face[a][0] != BC_PERIODIC)
        a = a == 0 ? 2 : 0;
    const struct grid *g = &st->g;
    const struct box *b = &st->act[a];
    double s = 0.0;
    long n = 0;
    for (int i = b->lo[0]; i < b->hi[0]; i++)
        for (int j = b->lo[1]; j < b->hi[1]; j++)
            for (int k = b->lo[2]; k < b->hi[2]; k++, n++)
                s += st->res[a][grid_idx(g, i, j, k)];
    return n > 0 ? s / n / st->cs->density : 0.0;
}

/* The implicit operator at the current state: mass + linearised stress. */
static struct viscous_problem implicit_problem(const struct march_state *st, double mass)
{
    const struct muflow_case *cs = st->cs;
    struct viscous_problem pb = {.mass = mass, .augmentation = st->aug};
    /* Newton's basin shrinks with lambda: far from the solution the lagged
     * (Picard) viscosity is the robust step, the tangent the fast one near it */
    int tangent = cs->newton &&
                  (cs->newton_below >= 1.0 || st->residual <= cs->newton_below * st->residual0);
    int diagonal = tangent && !st->full_tangent;
    for (int a = 0; a < 3; a++) {
        pb.A_cell[a] = diagonal ? st->tan_c[a] : st->eta;
        pb.A_edge[a] = diagonal ? st->tan_e[a] : st->eta_e[a];
    }
    if (tangent && st->full_tangent) {
        pb.b_cell = st->b_c;
        for (int a = 0; a < 3; a++)
            pb.b_edge[a] = st->b_e[a];
        pb.base = st->vel;
    }
    return pb;
}

void march_evaluate(struct march_state *st) { evaluate_residual(st); }

void march_apply_tangent(struct march_state *st, double *v[3], double *out[3])
{
    struct viscous_problem pb = implicit_problem(st, 0.0);
    viscous_apply(st->viscous, &pb, v, out);
}

/* One implicit step of size dt from the current state (residual evaluated). */
static int advance(struct march_state *st, double dt)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    struct viscous_problem pb = implicit_problem(st, cs->density / dt);
    viscous_precondition(st->viscous, &pb);
    struct viscous_stats vs;
    int rc = viscous_solve(st->viscous, &pb, st->res, st->delta, cs->linear_tolerance,
                           cs->max_linear_iterations, &vs);
    st->linear_iterations = vs.iterations;
    if (rc < 0)
        return -1;
    /* u is solenoidal to round-off after the last projection, so
     * div u* = div u + div delta is div delta but for that round-off.  The
     * pressure updates are taken from div delta alone: the Uzawa update
     * -r div u* and the projection's (rho/dt) lap^-1 div u* would carry u's
     * round-off times r (large) or rho/dt (large once a rejected step cut dt:
     * a Newton step at dt 1e-9 then raised the residual whatever its
     * length).  The projection u = u* - grad lap^-1 div delta keeps div u at
     * round-off; a state whose own divergence is above it (not one this
     * march produced) gets a second projection. */
    bc_fill_velocity_homogeneous(g, &st->bc, st->delta);
    kernel_divergence(g, st->delta, st->phi);
    if (st->aug) /* augmented-Lagrangian (Uzawa) update p -= r div u* */
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    st->p_dyn[p] -= st->aug[p] * st->phi[p];
                }
    kernel_axpy(g, st->act, 1.0, st->delta, st->vel);
    poisson_fft_solve(st->poisson, st->phi, st->phi);
    bc_fill_scalar(g, &st->bc, st->phi);
    kernel_gradient_update(g, st->act, st->phi, 1.0, st->vel);
    bc_fill_velocity(g, &st->bc, st->vel);
    if (st->divergence > DIVERGENCE_ROUNDOFF) {
        kernel_divergence(g, st->vel, st->div);
        poisson_fft_solve(st->poisson, st->div, st->div);
        bc_fill_scalar(g, &st->bc, st->div);
        kernel_gradient_update(g, st->act, st->div, 1.0, st->vel);
    }
    /* incremental pressure correction (rho/dt) lap^-1 div delta; with large
     * dt it is small and the Uzawa update carries the pressure */
    double scale = cs->density / dt;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                st->p_dyn[p] += scale * st->phi[p];
            }
    return 0;
}

static void save_good(struct march_state *st)
{
    copy_fields(&st->g, st->vel, st->good_vel);
    memcpy(st->good_p_dyn, st->p_dyn, st->g.size * sizeof(double));
}

static void restore_good(struct march_state *st)
{
    copy_fields(&st->g, st->good_vel, st->vel);
    memcpy(st->p_dyn, st->good_p_dyn, st->g.size * sizeof(double));
    evaluate_residual(st);
}

static double choose_dt(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double dt;
    if (cs->mode == MODE_STEADY) {
        /* switched evolution relaxation: the step grows as the residual falls */
        dt = st->residual > 0.0 ? cs->dt * st->residual0 / st->residual : cs->dt_max;
        if (dt > cs->dt_max)
            dt = cs->dt_max;
        if (dt < cs->dt)
            dt = cs->dt;
    } else {
        dt = cs->dt;
        if (st->time + dt > cs->end_time)
            dt = cs->end_time - st->time;
    }
    if (cs->advection) {
        double umax = kernel_max_abs(&st->g, st->act, st->vel);
        if (umax > 0.0) {
            double lim = cs->cfl * min_spacing(&st->g) / umax;
            if (dt > lim)
                dt = lim;
        }
    }
    return dt;
}

/* Sets status and message when the run must end with the current state. */
static void check_end(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    if (!isfinite(st->residual) || !isfinite(st->divergence)) {
        long bad = st->step;
        restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "non-finite values at step %ld; the last finite state is kept", bad);
    } else if (cs->mode == MODE_STEADY && st->residual_excess <= cs->tolerance &&
               st->divergence <= cs->tolerance) {
        st->status = STATUS_STEADY;
        if (st->residual > cs->tolerance)
            snprintf(st->message, sizeof st->message,
                     "residual %.3e is round-off of its terms: beyond it %.1e <= tolerance %.1e",
                     st->residual, st->residual_excess, cs->tolerance);
        else
            snprintf(st->message, sizeof st->message, "residual %.3e <= tolerance %.1e",
                     st->residual, cs->tolerance);
    } else if (cs->mode == MODE_TRANSIENT && st->time >= cs->end_time * (1.0 - 1e-12)) {
        st->status = STATUS_FINISHED;
        snprintf(st->message, sizeof st->message, "end time %g reached", cs->end_time);
    } else if (st->step >= cs->max_steps) {
        st->status = cs->mode == MODE_STEADY ? STATUS_UNSTEADY : STATUS_STOPPED;
        snprintf(st->message, sizeof st->message, "no %s after max_steps = %ld (residual %.3e)",
                 cs->mode == MODE_STEADY ? "steady state" : "end time", cs->max_steps,
                 st->residual);
    } else if (cs->mode == MODE_STEADY && st->step - st->best_step > STALL_STEPS) {
        st->status = STATUS_UNSTEADY;
        double acc = march_mean_acceleration(st);
        if (fabs(acc) > 0.1 * st->residual * force_scale(st) / cs->density)
            snprintf(st->message, sizeof st->message,
                     "no steady state: the layer accelerates (mean acceleration %.3e; "
                     "residual %.3e, no progress in %d steps)",
                     acc, st->residual, STALL_STEPS);
        else
            snprintf(st->message, sizeof st->message,
                     "no steady state: the residual stalls at %.3e for %d steps", st->residual,
                     STALL_STEPS);
    }
}

enum run_status march_run(struct march_state *st, march_observer obs, void *ctx)
{
    const struct muflow_case *cs = st->cs;
    double t0 = omp_get_wtime() - st->wall_seconds; /* a restart keeps counting */
    st->status = STATUS_RUNNING;
    save_good(st);
    evaluate_residual(st);
    if (st->step == 0 && st->residual0 == 0.0) /* march_reforce keeps it: below */
        st->residual0 = st->residual;
    for (;;) {
        st->wall_seconds = omp_get_wtime() - t0;
        check_end(st);
        if (obs && obs(ctx, st) && st->status == STATUS_RUNNING) {
            st->status = STATUS_STOPPED;
            snprintf(st->message, sizeof st->message, "stopped at step %ld", st->step);
        }
        if (st->status != STATUS_RUNNING)
            break;
        save_good(st);
        if (st->residual < STALL_FACTOR * st->best_residual) {
            st->best_residual = st->residual;
            st->best_step = st->step;
        }
        double accepted_residual = st->residual, dt;
        for (;;) {
            dt = choose_dt(st) * st->dt_scale;
            int broke = advance(st, dt) != 0;
            if (!broke)
                evaluate_residual(st);
            int bad = broke || !isfinite(st->residual) ||
                      (cs->mode == MODE_STEADY && st->residual > REJECT_GROWTH * accepted_residual);
            if (!bad || cs->mode != MODE_STEADY || st->dt_scale < MIN_DT_SCALE) {
                if (broke) { /* nothing usable: end with the last finite state */
                    restore_good(st);
                    st->status = STATUS_DIVERGED;
                    snprintf(st->message, sizeof st->message,
                             "the implicit viscous solve broke down at step %ld; the last "
                             "finite state is kept", st->step);
                }
                break;
            }
            restore_good(st);
            st->dt_scale *= 0.1;
            st->rejected++;
        }
        if (st->status == STATUS_DIVERGED) {
            st->wall_seconds = omp_get_wtime() - t0;
            if (obs)
                obs(ctx, st);
            break;
        }
        st->dt_scale = fmin(1.0, 2.0 * st->dt_scale);
        st->dt = dt;
        st->time += dt;
        st->step++;
    }
    st->wall_seconds = omp_get_wtime() - t0;
    return st->status;
}
