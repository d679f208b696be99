/* Two-phase mixture properties (two_phase.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels/vof.h"
#include "physics/two_phase.h"
#include "physics/vof_transport.h"

/* Sub-steps of the transport keep each sweep's CFL number below this
 * (VOF_CFL_MAX with a margin for the rounding of the ratio). */
#define TRANSPORT_CFL 0.45
/* A change of T below this in every cell leaves the density as it was (its
 * relative effect on the mixture density is below 1e-12 / 1500). */
#define TRACER_UNCHANGED 1e-12

struct two_phase {
    struct two_phase_params p;
    double *T;
    int configured;
    int transported;        /* T moves with the flow (else it is held) */
    struct vof_transport vt;
    int vt_ready;
    double *before;         /* T at the start of the transport stage */
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct two_phase *tp = calloc(1, sizeof *tp);
    if (!tp) {
        snprintf(err, errlen, "two phases: out of memory");
        return -1;
    }
    *state = tp;
    if (fields_add_written(&st->fields, "tracer", FIELD_CHECKPOINT | FIELD_SAVED, &tp->T) != 0) {
        snprintf(err, errlen, "two phases: out of memory for the tracer");
        return -1;
    }
    return 0;
}

static void destroy(void *state)
{
    struct two_phase *tp = state;
    if (tp && tp->vt_ready)
        vof_transport_free(&tp->vt);
    if (tp)
        field_free(tp->before);
    free(state);
}

double *two_phase_configure(struct march_state *st, const struct two_phase_params *p, char *err,
                            size_t errlen)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    if (!tp) {
        snprintf(err, errlen, "two phases: the module is not switched on");
        return NULL;
    }
    tp->p = *p;
    tp->configured = 1;
    tp->transported = p->transported;
    if (tp->transported && !tp->vt_ready) {
        if (vof_transport_init(&tp->vt, &st->g, &st->bc) != 0 ||
            !(tp->before = field_alloc(&st->g))) {
            snprintf(err, errlen, "two phases: out of memory for the transport");
            return NULL;
        }
        tp->vt_ready = 1;
    }
    return tp->T;
}

int two_phase_tracer_changed(struct march_state *st, char *err, size_t errlen)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    const struct grid *g = &st->g;
    const double rg = st->cs->density, rf = tp->p.fluid_density;
    bc_fill_scalar(g, &st->bc, tp->T);
    const ptrdiff_t *o = g->stride;
    /* the face between cells p - o_c and p: the mean of their densities
     * (ghost cells mirror the boundary cells, so a wall face gets its cell's) */
    for (int c = 0; c < 3; c++)
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j <= g->n[1]; j++)
                for (int k = 0; k <= g->n[2]; k++) {
                    ptrdiff_t q = grid_idx(g, i, j, k);
                    double t = 0.5 * (tp->T[q] + tp->T[q - o[c]]);
                    st->rho_face[c][q] = t * rg + (1.0 - t) * rf;
                }
    return march_density_changed(st, 0, err, errlen);
}

double two_phase_volume(const struct march_state *st)
{
    const struct two_phase *tp = march_module_state(st, &two_phase_module);
    return kernel_sum(&st->g, tp->T);
}

/* The mixture of the granular viscosity eta_g and the fluid's at fraction
 * t, and its derivative with respect to eta_g (for the tangents). */
static inline double mix(const struct two_phase *tp, double rg, double t, double eta_g,
                         double *deta)
{
    double ef = tp->p.fluid_viscosity, rf = tp->p.fluid_density;
    if (tp->p.mixture == MIXTURE_HARMONIC) {
        double eta = 1.0 / (t / eta_g + (1.0 - t) / ef);
        *deta = t > 0.0 ? eta * eta * t / (eta_g * eta_g) : 0.0;
        return eta;
    }
    double w = t * rg / (t * rg + (1.0 - t) * rf);
    *deta = w;
    return w * eta_g + (1.0 - w) * ef;
}

/* The granular viscosity within the clip (when there is one); *clipped
 * says whether it was cut (its derivatives then vanish). */
static inline double clip(const struct two_phase *tp, double eta_g, int *clipped)
{
    *clipped = 0;
    if (!(tp->p.eta_max > 0.0))
        return eta_g;
    double e = fmin(fmax(eta_g, tp->p.eta_min), tp->p.eta_max);
    *clipped = e != eta_g;
    return e;
}

/* eta (and the tangent A, the full tangent's b) of one stress location:
 * A = eta + eta_g' x (its derivative part), which scales with d eta / d eta_g. */
static inline void mix_point(const struct two_phase *tp, double rg, double t, double *eta,
                             double *tan, double *b)
{
    int cut;
    double d, eg = clip(tp, *eta, &cut);
    if (cut) {
        if (tan)
            *tan = eg;
        if (b)
            *b = 0.0;
    }
    double m = mix(tp, rg, t, eg, &d);
    if (tan)
        *tan = m + d * (*tan - eg);
    if (b)
        *b *= d;
    *eta = m;
}

static void properties(struct march_state *st, void *state)
{
    struct two_phase *tp = state;
    if (!tp->configured)
        return;
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    const double rg = cs->density;
    bc_fill_scalar(g, &st->bc, tp->T);
    const ptrdiff_t *o = g->stride;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                int cut;
                double eg = clip(tp, st->eta[q], &cut), d;
                if (cut) {
                    if (cs->newton)
                        for (int a = 0; a < 3; a++)
                            st->tan_c[a][q] = eg;
                    if (st->b_c)
                        st->b_c[q] = 0.0;
                }
                double m = mix(tp, rg, tp->T[q], eg, &d);
                if (cs->newton)
                    for (int a = 0; a < 3; a++)
                        st->tan_c[a][q] = m + d * (st->tan_c[a][q] - eg);
                if (st->b_c)
                    st->b_c[q] *= d;
                st->eta[q] = m;
            }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    const double *T = tp->T;
                    double t = 0.25 * (T[e] + T[e - o[a]] + T[e - o[b]] + T[e - o[a] - o[b]]);
                    mix_point(tp, rg, t, &st->eta_e[c][e], cs->newton ? &st->tan_e[c][e] : NULL,
                              st->b_e[c] ? &st->b_e[c][e] : NULL);
                }
    }
    bc_fill_scalar(g, &st->bc, st->eta);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->tan_c[a]);
}

/* The transport stage: T carried by the projected velocity over the step,
 * geometric VOF (physics/vof_transport.h), in as many equal sub-steps as the
 * sweeps' CFL limit needs, so that the implicit step's dt is not bound by
 * it; then the mixture density follows T. */
static void transport(struct march_state *st, void *state, double dt)
{
    struct two_phase *tp = state;
    if (!tp->configured || !tp->transported)
        return;
    double cfl[3];
    long n = (long)ceil(vof_cfl(&st->g, st->vel, dt, cfl) / TRANSPORT_CFL);
    if (n < 1)
        n = 1;
    bc_fill_velocity(&st->g, &st->bc, st->vel);
    memcpy(tp->before, tp->T, st->g.size * sizeof(double));
    for (long m = 0; m < n; m++)
        vof_transport_step(&tp->vt, tp->T, st->vel, dt / (double)n, NULL);
    /* the density (and the multigrid's coefficients, rebuilt with a
     * factorisation of its coarsest level) only when T moved: a flat layer
     * sheared along itself keeps T to round-off */
    double moved = 0.0;
    const struct grid *g = &st->g;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                moved = fmax(moved, fabs(tp->T[q] - tp->before[q]));
            }
    if (moved > TRACER_UNCHANGED) {
        char err[256];
        two_phase_tracer_changed(st, err, sizeof err);
    }
}

/* The VOF limit of the step: step_cfl h_d / max |u_d| over the swept
 * directions, at the velocity the step starts from. */
static double max_dt(const struct march_state *st, void *state)
{
    struct two_phase *tp = state;
    if (!tp->configured || !tp->transported || !(tp->p.step_cfl > 0.0))
        return INFINITY;
    double cfl[3];
    double c = vof_cfl(&st->g, st->vel, 1.0, cfl);
    return c > 0.0 ? fmin(tp->p.step_cfl, VOF_CFL_MAX) / c : INFINITY;
}

const struct module two_phase_module = {
    .name = "two_phase",
    .create = create,
    .properties = properties,
    .transport = transport,
    .max_dt = max_dt,
    .destroy = destroy,
};
