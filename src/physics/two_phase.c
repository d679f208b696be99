/* Two-phase mixture properties (two_phase.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "physics/two_phase.h"

struct two_phase {
    struct two_phase_params p;
    double *T;
    int configured;
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

static void destroy(void *state) { free(state); }

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

/* eta (and the tangent A, the full tangent's b) of one stress location:
 * A = eta + eta_g' x (its derivative part), which scales with d eta / d eta_g. */
static inline void mix_point(const struct two_phase *tp, double rg, double t, double *eta,
                             double *tan, double *b)
{
    double d, eg = *eta;
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
                double eg = st->eta[q], d;
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

const struct module two_phase_module = {
    .name = "two_phase",
    .create = create,
    .properties = properties,
    .destroy = destroy,
};
