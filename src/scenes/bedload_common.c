/* The pieces the bed-load scenes share (scenes/bedload.h): parameters,
 * checks, the exact plane solution, the measured bed top. */
#include <math.h>
#include <stdio.h>
#include "physics/bed_two_fluid.h"
#include "scenes/bedload.h"
#include "scene_common.h"

const struct choice bedload_model_choices[] = {
    {"mixed", BEDLOAD_MIXED}, {"two_fluid", BEDLOAD_TWO_FLUID}, {NULL, 0}};

void bedload_defaults(struct bedload_params *b)
{
    b->bed_height = 0.03225;
    b->phi = 0.6;
    b->particle_density = 1190.0;
    b->fluid_density = 1070.0;
    b->fluid_viscosity = 0.27;
    b->mu_s = 0.32;
    b->gravity = 9.81;
    b->model = BEDLOAD_MIXED;
    b->grain_diameter = 0.065 / 30.0; /* D / d = 30 as in Chauchat & Medale (2010), sec. 3.2 */
    b->kozeny = 180.0;
}

struct bed_params bedload_bed_params(const struct bedload_params *b)
{
    return (struct bed_params){
        .height = b->bed_height,
        .phi = b->phi,
        .fluid_viscosity = b->fluid_viscosity,
        .mu_s = b->mu_s,
        .weight = b->phi * (b->particle_density - b->fluid_density) * b->gravity,
    };
}

struct bedload_exact bedload_exact_of(const struct muflow_case *cs, const struct bedload_params *b)
{
    struct bedload_exact x;
    double drho = b->particle_density - b->fluid_density;
    x.D = cs->len[2];
    x.U0 = drho * b->gravity * x.D * x.D / b->fluid_viscosity;
    /* dp/dx = -(the body force along x) */
    x.G = -cs->density * cs->gravity * sin(cs->tilt) / (drho * b->gravity);
    x.h = b->bed_height / x.D;
    x.eta = 1.0 + 2.5 * b->phi;
    x.A = x.G + b->mu_s * b->phi;
    x.delta = x.eta * (1.0 - x.h) * (sqrt(1.0 - x.G / (x.eta * x.A)) - 1.0);
    x.hc = x.h - x.delta;
    return x;
}

static double ustar(const struct bedload_exact *x, double y)
{
    if (y < x->hc)
        return 0.0;
    double k = x->A / (2.0 * x->eta);
    if (y <= x->h)
        return k * (y - x->hc) * (y - x->hc);
    return -0.5 * x->G * (1.0 - y) * (y - x->h) +
           k * x->delta * x->delta * (1.0 - y) / (1.0 - x->h);
}

double bedload_exact_u(const struct bedload_exact *x, double z)
{
    return x->U0 * ustar(x, z / x->D);
}

double bedload_exact_max(const struct bedload_exact *x)
{
    /* d(u*)/dy = 0 in the fluid layer: -G/2 (1 + h - 2y) = K / (1 - h) */
    double K = x->A / (2.0 * x->eta) * x->delta * x->delta;
    double y = 0.5 * (1.0 + x->h) + K / (x->G * (1.0 - x->h));
    y = fmin(1.0, fmax(x->h, y));
    return x->U0 * ustar(x, y);
}

double bedload_exact_flow_rate(const struct bedload_exact *x)
{
    /* zone II: A/(2 eta) delta^3 / 3; zone I: -G (1-h)^3/12 + A/(2 eta) delta^2 (1 - h) / 2 */
    double k = x->A / (2.0 * x->eta), s = 1.0 - x->h;
    return x->U0 * x->D *
           (k * x->delta * x->delta * x->delta / 3.0 - x->G * s * s * s / 12.0 +
            k * x->delta * x->delta * s / 2.0);
}

int bedload_check_params(const struct muflow_case *c, const struct bedload_params *b,
                         const char *section, char *msg, size_t msglen)
{
    if (b->model == BEDLOAD_TWO_FLUID && c->mode != MODE_STEADY) {
        snprintf(msg, msglen, "%s.model = two_fluid needs solver.mode = steady (the grains' "
                              "pseudo-time mass is not their inertia)",
                 section);
        return 1;
    }
    if (b->model == BEDLOAD_TWO_FLUID && c->n[2] < 3) {
        snprintf(msg, msglen, "%s.model = two_fluid needs domain.nz >= 3", section);
        return 1;
    }
    /* the bed and the fluid above it are layers of the grid: each at least
     * a cell thick (a thinner one is a fraction of a cell's mixture) */
    double lz = c->len[2], dz = lz / c->n[2];
    if (!scene_layer_fits(b->bed_height, lz, dz)) {
        snprintf(msg, msglen, "%s.bed_height = %s: the bed and the fluid above it must each be "
                              "at least a cell thick (domain.lz / domain.nz = %s / %d = %.6g): "
                              "%s.bed_height must be in [%.6g, %.6g]",
                 section, num_text(b->bed_height).s, num_text(lz).s, c->n[2], dz, section, dz,
                 lz - dz);
        return 1;
    }
    if (!(b->particle_density > b->fluid_density)) {
        snprintf(msg, msglen, "%s.particle_density = %s: must exceed "
                              "%s.fluid_density = %s (a bed that does not sink)",
                 section, num_text(b->particle_density).s, section,
                 num_text(b->fluid_density).s);
        return 1;
    }
    struct bedload_exact x = bedload_exact_of(c, b);
    double drive = c->density * c->gravity * sin(c->tilt);
    if (!(x.G < 0.0)) {
        snprintf(msg, msglen, "physics.density * physics.gravity * sin(physics.tilt) = %s * %s * "
                              "sin(%s) = %s: must be > 0 (the pressure gradient that drives the "
                              "flow along +x)",
                 num_text(c->density).s, num_text(c->gravity).s, num_text(c->tilt).s,
                 num_text(drive).s);
        return 1;
    }
    /* every key in G and A, with its value: any of them can be the one to change */
    char keys[600];
    snprintf(keys, sizeof keys, "physics.density = %s, physics.gravity = %s, physics.tilt = %s, "
                                "%s.particle_density = %s, %s.fluid_density = %s, "
                                "%s.gravity = %s, %s.mu_s = %s, %s.phi = %s",
             num_text(c->density).s, num_text(c->gravity).s, num_text(c->tilt).s, section,
             num_text(b->particle_density).s, section, num_text(b->fluid_density).s, section,
             num_text(b->gravity).s, section, num_text(b->mu_s).s, section, num_text(b->phi).s);
    if (!(x.A > 0.0)) {
        snprintf(msg, msglen, "no bed load: the friction cannot hold the bed against the "
                              "pressure gradient, A = G + mu_s phi = %.6g <= 0 with G = "
                              "-rho g sin(tilt) / ((rho_p - rho_f) g_p) = %.6g (%s)",
                 x.A, x.G, keys);
        return 1;
    }
    if (!(x.delta > 0.0 && x.delta <= x.h)) {
        snprintf(msg, msglen, "%s.bed_height = %s: no bed load for these parameters, the "
                              "mobile layer delta = %.6g D is outside (0, h_p / D = %.6g] "
                              "(D = domain.lz = %s; delta follows from G = %.6g and A = %.6g: %s)",
                 section, num_text(b->bed_height).s, x.delta, x.h, num_text(lz).s, x.G, x.A,
                 keys);
        return 1;
    }
    return 0;
}

int bedload_configure(struct march_state *st, const struct bedload_params *b, char *err,
                      size_t errlen)
{
    const struct bed_params bp = bedload_bed_params(b);
    if (b->model == BEDLOAD_TWO_FLUID) {
        const struct two_fluid_params tp = {
            .bed = bp, .grain_diameter = b->grain_diameter, .kozeny = b->kozeny};
        return two_fluid_configure(st, &tp, err, errlen);
    }
    return bed_configure(st, &bp, err, errlen);
}

/* The fixed bed creeps at ~lambda D (1e-8 m/s at lambda 1e-6), far below
 * the threshold; a plain threshold crossing would sit
 * sqrt(2 eta frac u*_max / A) D above h_c (6% of delta for set A at 1e-3). */
double bedload_bed_top(int n, const double *z, const double *u, double umax)
{
    for (int l = 0; l < n - 1; l++)
        if (u[l] > BEDLOAD_MOBILE_FRACTION * umax) {
            if (l == 0)
                return 0.0;
            double s0 = sqrt(fmax(u[l], 0.0)), s1 = sqrt(fmax(u[l + 1], 0.0));
            if (!(s1 > s0))
                return z[l];
            return z[l] - s0 * (z[l + 1] - z[l]) / (s1 - s0);
        }
    return NAN;
}
