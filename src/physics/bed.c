/* The granular bed of the mixed-fluid model (bed.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "kernels/kernels.h"
#include "physics/bed.h"

struct bed {
    struct bed_params p;
    int configured;
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    (void)st;
    struct bed *b = calloc(1, sizeof *b);
    if (!b) {
        snprintf(err, errlen, "bed: out of memory");
        return -1;
    }
    *state = b;
    return 0;
}

static void destroy(void *state) { free(state); }

int bed_configure(struct march_state *st, const struct bed_params *p, char *err, size_t errlen)
{
    struct bed *b = march_module_state(st, &bed_module);
    if (!b) {
        snprintf(err, errlen, "bed: the module is not switched on");
        return -1;
    }
    b->p = *p;
    b->configured = 1;
    return 0;
}

void bed_point(const struct bed_params *p, double z, double dz, double *t, double *pp)
{
    double lo = z - 0.5 * dz, hi = z + 0.5 * dz, h = p->height;
    if (h >= hi) {
        *t = 1.0;
        *pp = p->weight * (h - z); /* linear: the mean is the centre value */
    } else if (h <= lo) {
        *t = 0.0;
        *pp = 0.0;
    } else {
        /* the bed ends inside: the mean of weight (h - z') over [lo, h] */
        *t = (h - lo) / dz;
        *pp = 0.5 * p->weight * (h - lo);
    }
}

/* eta and its slope d eta / d|D| at one stress location.  Where the bed
 * ends inside the control volume the bed's part (eta_e plus its friction)
 * and the fluid's are taken in series, 1/eta = t/eta_bed + (1 - t)/eta_f:
 * the shear stress is continuous across the bed's top, so the velocity
 * jump over the volume is the sum of the two parts' strains.  The
 * arithmetic mean made the whole fluid profile first-order wrong
 * (docs/numerics/bed-models.md). */
double bed_viscosity(const struct bed_params *p, const struct rheology *r, double z, double dz,
                     double shear, double *deta)
{
    double t, pp, f, df;
    bed_point(p, z, dz, &t, &pp);
    if (t <= 0.0) {
        *deta = 0.0;
        return p->fluid_viscosity;
    }
    double eb = p->fluid_viscosity * (1.0 + 2.5 * p->phi), deb = 0.0;
    if (pp > 0.0) {
        rheology_yield_kernel(r->reg, shear, r->lambda, &f, &df);
        eb += p->mu_s * pp * f;
        deb = p->mu_s * pp * df;
    }
    if (t >= 1.0) {
        *deta = deb;
        return eb;
    }
    double eta = 1.0 / (t / eb + (1.0 - t) / p->fluid_viscosity);
    *deta = eta * eta * t / (eb * eb) * deb;
    return eta;
}

void bed_fill_viscosities(const struct grid *g, bed_law law, const void *ctx,
                          const double *shear2, const double *cn2, double *const e2[3],
                          double *const vel[3], const struct bed_viscosity_out *out)
{
    const ptrdiff_t *o = g->stride;
    const double dz = g->h[2];
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double D = shear2 ? sqrt(shear2[q]) : 0.0, de;
                double eta = law(ctx, (out->k0 + k + 0.5) * dz, dz, D, &de);
                out->eta_c[q] = eta;
                if (out->b_c)
                    out->b_c[q] = D > 0.0 ? de / (2.0 * D) : 0.0;
                if (out->tan_c[0])
                    for (int a = 0; a < 3; a++) {
                        double gn = 2.0 * (vel[a][q + o[a]] - vel[a][q]) / g->h[a];
                        out->tan_c[a][q] = D > 0.0 ? eta + de * gn * gn / (2.0 * D) : eta;
                    }
            }
    for (int c = 0; c < 3; c++) {
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    double own = cn2 ? e2[c][e] : 0.0;
                    double D = cn2 ? sqrt(kernel_edge_shear2(g, cn2, e2, c, e)) : 0.0, de;
                    double z = c == 2 ? (out->k0 + k + 0.5) * dz : (out->k0 + k) * dz;
                    double eta = law(ctx, z, dz, D, &de);
                    out->eta_e[c][e] = eta;
                    if (out->tan_e[c])
                        out->tan_e[c][e] = D > 0.0 ? eta + de * own / D : eta;
                    if (out->b_e[c])
                        out->b_e[c][e] = D > 0.0 ? de / (2.0 * D) : 0.0;
                }
    }
}

struct bed_law_ctx {
    const struct bed_params *p;
    const struct rheology *r;
};

static double mixture_law(const void *ctx, double z, double dz, double shear, double *deta)
{
    const struct bed_law_ctx *l = ctx;
    return bed_viscosity(l->p, l->r, z, dz, shear, deta);
}

static void properties(struct march_state *st, void *state)
{
    struct bed *bd = state;
    if (!bd->configured)
        return;
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    const struct bed_law_ctx l = {&bd->p, &cs->rheo};
    /* cells: |D| is the core's shear2; the tangent coefficients are those of
     * kernel_viscosity_cells with this law's eta and slope */
    struct bed_viscosity_out out = {.eta_c = st->field.viscosity, .b_c = st->b_c,
                                    .k0 = st->ranks ? st->ranks->dc.lo[2] : 0};
    for (int a = 0; a < 3; a++) {
        out.tan_c[a] = cs->newton ? st->field.tangent_cells[a] : NULL;
        out.eta_e[a] = st->field.viscosity_edges[a];
        out.tan_e[a] = cs->newton ? st->field.tangent_edges[a] : NULL;
        out.b_e[a] = st->b_e[a];
    }
    bed_fill_viscosities(g, mixture_law, &l, st->field.shear2, st->field.strain_normal2,
                         st->field.strain_shear2, st->field.velocity, &out);
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);
}

const struct module bed_module = {
    .name = "bed",
    .create = create,
    .properties = properties,
    .destroy = destroy,
    .decomposed = 1, /* per cell, by the height z of the domain */
};
