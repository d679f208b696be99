/* Scene "bedload": a Newtonian fluid driven by a pressure gradient over a
 * granular bed in a closed channel (walls at z = 0 and z = D, periodic along
 * the flow x), the mixed-fluid model of seeds/002 eq. 13 with the bed held
 * flat (physics/bed.h); cases/bedload.ini.  The driving pressure gradient is
 * the body force: -dp/dx = physics.density * physics.gravity * sin(tilt)
 * (tilt = pi/2 as in bingham_channel), so the weight of the grains in the
 * particle pressure needs a gravity of its own (bedload.gravity).
 *
 * Exact solution (Ouriemi, Aussillous & Guazzelli 2009, as written in the
 * refdata item 4): y = z / D, u = U0 u*(y), U0 = (rho_p - rho_f) g D^2 / eta_f,
 * G = (dp/dx) / ((rho_p - rho_f) g), h = h_p / D, eta = 1 + 5 phi0 / 2,
 * A = G + mu_s phi0 (bed load needs A > 0),
 *   mobile layer  delta = eta (1 - h) [sqrt(1 - G / (eta A)) - 1], h_c = h - delta
 *   fixed bed     y < h_c:       u* = 0
 *   mobile layer  h_c <= y <= h: u* = A / (2 eta) (y - h_c)^2
 *   fluid         y > h:         u* = -G/2 (1 - y)(y - h) + A/(2 eta) delta^2 (1 - y)/(1 - h).
 * Headline: the maximum velocity (in the fluid layer, where d(u*)/dy = 0). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/profile.h"
#include "io/output.h"
#include "physics/bed.h"
#include "physics/bed_two_fluid.h"
#include "scenes/scene.h"
#include "scene_common.h"

struct bedload_params {
    double bed_height;        /* h_p */
    double phi;               /* phi0 */
    double particle_density;  /* rho_p */
    double fluid_density;     /* rho_f */
    double fluid_viscosity;   /* eta_f */
    double mu_s;              /* Coulomb friction */
    double gravity;           /* g in the particle pressure */
    int model;                /* enum bedload_model */
    double grain_diameter;    /* d (two_fluid: the permeability) */
    double kozeny;            /* k_CK (two_fluid) */
};

enum bedload_model { BEDLOAD_MIXED = 0, BEDLOAD_TWO_FLUID };
static const struct choice model_choices[] = {
    {"mixed", BEDLOAD_MIXED}, {"two_fluid", BEDLOAD_TWO_FLUID}, {NULL, 0}};

#define T struct bedload_params
static const struct key bedload_keys[] = {
    KEY_DBL(T, "bedload", "bed_height", bed_height,
            "height h_p of the flat granular bed above the lower wall (inside (0, domain.lz))",
            KEY_GT0),
    KEY_DBL(T, "bedload", "phi", phi, "volume fraction phi0 of the grains in the bed",
            KEY_RANGE(0.0, 1.0, 0, 0)),
    KEY_DBL(T, "bedload", "particle_density", particle_density,
            "density rho_p of the grains (above fluid_density)", KEY_GT0),
    KEY_DBL(T, "bedload", "fluid_density", fluid_density, "density rho_f of the fluid",
            KEY_GT0),
    KEY_DBL(T, "bedload", "fluid_viscosity", fluid_viscosity,
            "viscosity eta_f of the fluid (the bed's is eta_f (1 + 5 phi / 2))", KEY_GT0),
    KEY_DBL(T, "bedload", "mu_s", mu_s,
            "Coulomb friction coefficient of the bed (yield stress mu_s p_p)", KEY_GT0),
    KEY_DBL(T, "bedload", "gravity", gravity,
            "gravity g in the grains' buoyant weight p_p = phi (rho_p - rho_f) g (h_p - z)",
            KEY_GT0),
    KEY_CHO(T, "bedload", "model", model, model_choices,
            "mixed: one mixture velocity (eq. 13); two_fluid: fluid and particle velocities "
            "coupled by Darcy drag (eq. 12)"),
    KEY_DBL(T, "bedload", "grain_diameter", grain_diameter,
            "grain diameter d in the bed's permeability K (two_fluid)", KEY_GT0),
    KEY_DBL(T, "bedload", "kozeny", kozeny,
            "Carman-Kozeny constant k_CK of K = eps^3 d^2 / (k_CK (1 - eps)^2) (two_fluid)",
            KEY_GT0),
};
#undef T

/* Set A of the refdata (the sedFoam tutorial's parameters) */
static void defaults(void *block)
{
    struct bedload_params *b = block;
    b->bed_height = 0.03225;
    b->phi = 0.6;
    b->particle_density = 1190.0;
    b->fluid_density = 1070.0;
    b->fluid_viscosity = 0.27;
    b->mu_s = 0.32;
    b->gravity = 9.81;
    b->model = BEDLOAD_MIXED;
    b->grain_diameter = 0.065 / 30.0; /* D / d = 30 as in the seed's test */
    b->kozeny = 180.0;
}

static const struct key_block bedload_block = {
    .section = "bedload",
    .keys = bedload_keys,
    .nkeys = (int)(sizeof bedload_keys / sizeof bedload_keys[0]),
    .size = sizeof(struct bedload_params),
    .defaults = defaults,
};

static const struct bedload_params *params(const struct muflow_case *cs)
{
    return case_scene_params(cs);
}

/* The dimensionless solution's constants. */
struct bedload_exact {
    double D, U0, G, h, eta, A, delta, hc;
};

static struct bedload_exact exact_of(const struct muflow_case *cs)
{
    const struct bedload_params *b = params(cs);
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

static double bedload_u(const struct muflow_case *cs, double z)
{
    struct bedload_exact x = exact_of(cs);
    return x.U0 * ustar(&x, z / x.D);
}

POINTWISE_PROFILE(exact_profile, bedload_u)

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct bedload_params *b = params(c);
    if (c->rheo.law != LAW_NEWTONIAN) {
        snprintf(msg, msglen, "case.scene = bedload needs rheology.law = newtonian (the bed module "
                              "sets every viscosity; rheology.regularisation and lambda are its "
                              "friction's)");
        return 1;
    }
    if (c->bc.face[0][0] != BC_PERIODIC || c->bc.face[2][0] != BC_WALL ||
        c->bc.face[2][1] != BC_WALL) {
        snprintf(msg, msglen, "case.scene = bedload needs periodic x, boundary.zlo = wall and "
                              "boundary.zhi = wall");
        return 1;
    }
    if (b->model == BEDLOAD_TWO_FLUID && c->bc.face[1][0] != BC_PERIODIC) {
        snprintf(msg, msglen, "bedload.model = two_fluid solves the plane flow u(z) only: it "
                              "needs periodic y (boundary.ylo = boundary.yhi = periodic)");
        return 1;
    }
    if (b->model == BEDLOAD_TWO_FLUID && c->mode != MODE_STEADY) {
        snprintf(msg, msglen, "bedload.model = two_fluid needs solver.mode = steady (the grains' "
                              "pseudo-time mass is not their inertia)");
        return 1;
    }
    if (b->model == BEDLOAD_TWO_FLUID && c->n[2] < 3) {
        snprintf(msg, msglen, "bedload.model = two_fluid needs domain.nz >= 3");
        return 1;
    }
    if (!(b->bed_height < c->len[2])) {
        snprintf(msg, msglen, "bedload.bed_height = %.17g: must be inside the channel, below "
                              "domain.lz = %.17g",
                 b->bed_height, c->len[2]);
        return 1;
    }
    if (!(b->particle_density > b->fluid_density)) {
        snprintf(msg, msglen, "bedload.particle_density = %.17g: must exceed "
                              "bedload.fluid_density = %.17g (a bed that does not sink)",
                 b->particle_density, b->fluid_density);
        return 1;
    }
    struct bedload_exact x = exact_of(c);
    if (!(x.G < 0.0)) {
        snprintf(msg, msglen, "physics.tilt = %.17g: the pressure gradient must drive the flow "
                              "along +x (physics.density * gravity * sin(tilt) > 0; G = %.6g)",
                 c->tilt, x.G);
        return 1;
    }
    if (!(x.A > 0.0)) {
        snprintf(msg, msglen, "bedload.mu_s = %.17g: no bed load, A = G + mu_s phi = %.6g <= 0 "
                              "(G = %.6g: the friction cannot hold the bed against the pressure "
                              "gradient)",
                 b->mu_s, x.A, x.G);
        return 1;
    }
    if (!(x.delta > 0.0 && x.delta <= x.h)) {
        snprintf(msg, msglen, "bedload.bed_height = %.17g: no bed load for these parameters, the "
                              "mobile layer delta = %.6g D is outside (0, h_p / D = %.6g]",
                 b->bed_height, x.delta, x.h);
        return 1;
    }
    return 0;
}

static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct bedload_params *b = params(st->cs);
    const struct bed_params bp = {
        .height = b->bed_height,
        .phi = b->phi,
        .fluid_viscosity = b->fluid_viscosity,
        .mu_s = b->mu_s,
        .weight = b->phi * (b->particle_density - b->fluid_density) * b->gravity,
    };
    if (b->model == BEDLOAD_TWO_FLUID) {
        const struct two_fluid_params tp = {
            .bed = bp, .grain_diameter = b->grain_diameter, .kozeny = b->kozeny};
        return two_fluid_configure(st, &tp, err, errlen);
    }
    return bed_configure(st, &bp, err, errlen);
}

/* The measured mobile layer: the first layer from the bottom where u rises
 * above this fraction of the maximum, then the zero of the straight line
 * through sqrt(u) of it and the layer above.  The exact profile is
 * quadratic in the mobile layer, u ~ (z - z_c)^2, so sqrt(u) is linear and
 * the zero is z_c itself; a plain threshold crossing would sit
 * sqrt(2 eta frac u*_max / A) D above it (6% of delta for set A at 1e-3).
 * The fixed bed creeps at ~lambda D (1e-8 m/s at lambda 1e-6), far below. */
#define MOBILE_FRACTION 1e-3

static double measured_bed_top(const struct profile *pr, const double *u)
{
    double umax = 0.0;
    for (int l = 0; l < pr->n; l++)
        umax = fmax(umax, pr->velocity[l]);
    for (int l = 0; l < pr->n - 1; l++)
        if (u[l] > MOBILE_FRACTION * umax) {
            if (l == 0)
                return 0.0;
            double s0 = sqrt(fmax(u[l], 0.0)), s1 = sqrt(fmax(u[l + 1], 0.0));
            if (!(s1 > s0))
                return pr->coord[l];
            return pr->coord[l] - s0 * (pr->coord[l + 1] - pr->coord[l]) / (s1 - s0);
        }
    return NAN;
}

static double exact_max(const struct bedload_exact *x)
{
    /* d(u*)/dy = 0 in the fluid layer: -G/2 (1 + h - 2y) = K / (1 - h) */
    double K = x->A / (2.0 * x->eta) * x->delta * x->delta;
    double y = 0.5 * (1.0 + x->h) + K / (x->G * (1.0 - x->h));
    y = fmin(1.0, fmax(x->h, y));
    return x->U0 * ustar(x, y);
}

static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    struct bedload_exact x = exact_of(st->cs);
    profile_errors_default(pr, exact_max(&x), e);
    double m = 0.0;
    for (int l = 0; l < pr->n; l++)
        m = fmax(m, pr->velocity[l]);
    e->headline = m;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct muflow_case *cs = st->cs;
    struct profile pr;
    if (profile_extract(&pr, st) != 0)
        return;
    struct bedload_exact x = exact_of(cs);
    double hp = params(cs)->bed_height;
    /* two_fluid: the grains' mobile layer, from u^p where the layer's centre
     * is in the bed.  u^m runs ahead of u^p by the Darcy slip there (3.9e-6
     * m/s for set A, 7% of the threshold), which moved the zero of sqrt(u^m)
     * 5e-5 m down: measured on u^m the layer came out 0.3% thicker on the
     * finest grids (docs/design.md) */
    double *ub = malloc((size_t)pr.n * sizeof *ub);
    if (!ub) {
        profile_free(&pr);
        return;
    }
    for (int l = 0; l < pr.n; l++)
        ub[l] = pr.velocity[l];
    if (params(cs)->model == BEDLOAD_TWO_FLUID && pr.n == st->g.n[2] &&
        two_fluid_particle_profile(st, ub, NULL) == 0)
        for (int l = 0; l < pr.n; l++)
            if (!(pr.coord[l] < hp) || !isfinite(ub[l]))
                ub[l] = pr.velocity[l];
    double mobile = hp - measured_bed_top(&pr, ub), mobile_exact = x.delta * x.D;
    free(ub);
    /* per unit width: the midpoint rule over the layers, and the integral of
     * the exact profile (zone II: A/(2 eta) delta^3 / 3; zone I: -G (1-h)^3/12
     * + A/(2 eta) delta^2 (1 - h) / 2) */
    double q = 0.0;
    for (int l = 0; l < pr.n; l++)
        q += pr.velocity[l] * st->g.h[2];
    double k = x.A / (2.0 * x.eta), s = 1.0 - x.h;
    double q_exact = x.U0 * x.D *
                     (k * x.delta * x.delta * x.delta / 3.0 - x.G * s * s * s / 12.0 +
                      k * x.delta * x.delta * s / 2.0);
    if (params(cs)->model == BEDLOAD_TWO_FLUID) {
        /* u^p in the bed (layers whose centre is below h_p) against the exact
         * profile, which has u^p = u^f there; the largest |u^m - u^p| */
        double *up = malloc((size_t)pr.n * sizeof *up), slip = 0.0, s2 = 0.0, emax = 0.0;
        int n = 0;
        if (up && pr.n == st->g.n[2] && two_fluid_particle_profile(st, up, &slip) == 0) {
            for (int l = 0; l < pr.n; l++)
                if (pr.coord[l] < hp && isfinite(up[l])) {
                    double e = up[l] - bedload_u(cs, pr.coord[l]);
                    s2 += e * e;
                    emax = fmax(emax, fabs(e));
                    n++;
                }
            run_result_add(res, "err_rms_particles", "%.10g", n > 0 ? sqrt(s2 / n) : NAN);
            run_result_add(res, "err_max_particles", "%.10g", n > 0 ? emax : NAN);
            run_result_add(res, "slip_max", "%.10g", slip);
            run_result_add(res, "particle_residual", "%.10g", two_fluid_particle_residual(st));
            struct two_fluid_params tp = {.bed = {.phi = params(cs)->phi,
                                                  .fluid_viscosity = params(cs)->fluid_viscosity},
                                          .grain_diameter = params(cs)->grain_diameter,
                                          .kozeny = params(cs)->kozeny};
            run_result_add(res, "drag_coefficient", "%.10g", two_fluid_drag(&tp));
        }
        free(up);
    }
    run_result_add(res, "mobile_layer", "%.10g", mobile);
    run_result_add(res, "mobile_layer_exact", "%.10g", mobile_exact);
    run_result_add(res, "flow_rate", "%.10g", q);
    run_result_add(res, "flow_rate_exact", "%.10g", q_exact);
    snprintf(res->scene_line, sizeof res->scene_line,
             "mobile layer %.6g m (exact %.6g), flow rate %.6g m^2/s (exact %.6g)", mobile,
             mobile_exact, q, q_exact);
    profile_free(&pr);
}

/* two_fluid: particles.csv, per layer z, the mixture velocity u^m (the
 * profile's), the particles' u^p and the fluid's u^f = (u^m - phi u^p) /
 * (1 - phi) where the layer's centre is in the bed (empty above), and the
 * exact profile. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    if (params(cs)->model != BEDLOAD_TWO_FLUID)
        return 0;
    struct profile pr;
    if (profile_extract(&pr, st) != 0)
        return 0;
    double *up = malloc((size_t)pr.n * sizeof *up);
    int rc = 0;
    if (up && pr.n == st->g.n[2] && two_fluid_particle_profile(st, up, NULL) == 0) {
        struct output_file f;
        rc = output_open(&f, dir, "particles.csv", err, errlen);
        if (rc == 0) {
            double phi = params(cs)->phi, hp = params(cs)->bed_height;
            fprintf(f.f, "z,u_mixture,u_particles,u_fluid,u_exact\n");
            for (int l = 0; l < pr.n; l++) {
                double z = pr.coord[l], um = pr.velocity[l];
                fprintf(f.f, "%.10g,%.12g,", z, um);
                if (z < hp && isfinite(up[l]))
                    fprintf(f.f, "%.12g,%.12g,", up[l], (um - phi * up[l]) / (1.0 - phi));
                else
                    fprintf(f.f, ",%.12g,", um);
                fprintf(f.f, "%.12g\n", bedload_u(cs, z));
            }
            rc = output_commit(&f, err, errlen);
        }
    }
    free(up);
    profile_free(&pr);
    return rc;
}

static const char *const bedload_files[] = {"particles.csv", NULL};

/* both models' modules: setup configures the one of bedload.model, the other idles */
static const struct module *const bedload_modules[] = {&bed_module, &two_fluid_module, NULL};

const struct scene scene_bedload = {
    .name = "bedload",
    .title = "Poiseuille flow over a granular bed, mixed- or two-fluid model (Ouriemi et al. 2009)",
    .keys = &bedload_block,
    .modules = bedload_modules,
    .check = check,
    .setup = setup,
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_max",
    .errors = errors,
    .results = results,
    .write = write,
    .files = bedload_files,
};
