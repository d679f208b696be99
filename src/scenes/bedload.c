/* Scene "bedload": a Newtonian fluid driven by a pressure gradient over a
 * granular bed in a closed channel (walls at z = 0 and z = D, periodic along
 * the flow x), the mixed-fluid model of Chauchat & Medale (2010), eq. 13, with the bed held
 * flat (physics/bed.h); cases/bedload.ini.  The driving pressure gradient is
 * the body force: -dp/dx = physics.density * physics.gravity * sin(tilt)
 * (tilt = pi/2 as in bingham_channel), so the weight of the grains in the
 * particle pressure needs a gravity of its own (bedload.gravity).
 *
 * Exact solution: Ouriemi, Aussillous & Guazzelli (2009), in
 * scenes/bedload.h (shared with the duct scene).
 * Headline: the maximum velocity (in the fluid layer, where d(u*)/dy = 0). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/profile.h"
#include "io/output.h"
#include "physics/bed.h"
#include "physics/bed_two_fluid.h"
#include "scenes/bedload.h"
#include "scenes/scene.h"
#include "scene_common.h"

#define T struct bedload_params
static const struct key bedload_keys[] = {
    BEDLOAD_KEYS(T, "bedload"),
    KEY_CHO(T, "bedload", "model", model, bedload_model_choices,
            KEY_HELP("mixed: one mixture velocity (eq. 13); two_fluid: fluid and particle "
                     "velocities coupled by Darcy drag (eq. 12)",
                     NULL,
                     "`mixed`: one mixture velocity, the bed's viscosity plus the Coulomb "
                     "friction (Chauchat & Medale 2010, eq. 13; `src/physics/bed.c`); "
                     "`two_fluid`: the mixture velocity u^m and the particle velocity u^p, "
                     "coupled by the Darcy drag (eq. 12; `src/physics/bed_two_fluid.c`; "
                     "plane flow only, periodic x and y, `solver.mode = steady`)")),
    KEY_DBL(T, "bedload", "grain_diameter", grain_diameter,
            KEY_HELP("grain diameter d in the bed's permeability K (two_fluid)", "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "bedload", "kozeny", kozeny,
            "Carman-Kozeny constant k_CK of K = eps^3 d^2 / (k_CK (1 - eps)^2) (two_fluid)",
            KEY_GT0),
};
#undef T

/* Set A: the parameters of SedFoam's bed-load tutorial for the solution of
 * Ouriemi, Aussillous & Guazzelli (2009) */
static void defaults(void *block) { bedload_defaults(block); }

SCENE_PARAMS(bedload_block, "bedload",
             "A Newtonian fluid over a granular bed in a closed channel (Ouriemi, Aussillous & "
             "Guazzelli 2009; `cases/bedload.ini`).  The bed module sets every viscosity: "
             "`rheology.law` must be `newtonian` (a placeholder, its `viscosity` unused), and "
             "`rheology.regularisation` and `lambda` regularise the bed friction's 1/|D|.  The "
             "driving pressure gradient is the body force, -dp/dx = `physics.density` "
             "`physics.gravity` sin(`physics.tilt`) (tilt = pi/2).  A case without bed load (A = "
             "G + mu_s phi <= 0, or the mobile layer outside (0, h_p]) is refused.  The defaults "
             "are set A of SedFoam's bed-load tutorial, in SI units.",
             struct bedload_params, bedload_keys, defaults)

static struct bedload_exact exact_of(const struct muflow_case *cs)
{
    return bedload_exact_of(cs, params(cs));
}

static double bedload_u(const struct muflow_case *cs, double z)
{
    struct bedload_exact x = exact_of(cs);
    return bedload_exact_u(&x, z);
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
        snprintf(msg, msglen, "case.scene = bedload needs boundary.xlo = boundary.xhi = periodic, "
                              "boundary.zlo = wall and boundary.zhi = wall");
        return 1;
    }
    if (b->model == BEDLOAD_TWO_FLUID && c->bc.face[1][0] != BC_PERIODIC) {
        snprintf(msg, msglen, "bedload.model = two_fluid solves the plane flow u(z) only: it "
                              "needs periodic y (boundary.ylo = boundary.yhi = periodic)");
        return 1;
    }
    return bedload_check_params(c, b, "bedload", msg, msglen);
}

static int setup(struct march_state *st, char *err, size_t errlen)
{
    return bedload_configure(st, params(st->cs), err, errlen);
}

/* The measured mobile layer: h_p less the measured top of the fixed bed
 * (scenes/bedload.h). */
static double measured_bed_top(const struct profile *pr, const double *u)
{
    double umax = 0.0;
    for (int l = 0; l < pr->n; l++)
        umax = fmax(umax, pr->velocity[l]);
    return bedload_bed_top(pr->n, pr->coord, u, umax);
}

static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    struct bedload_exact x = exact_of(st->cs);
    profile_errors_default(pr, bedload_exact_max(&x), e);
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
    if (scene_profile(&pr, st) != 0)
        return;
    struct bedload_exact x = exact_of(cs);
    double hp = params(cs)->bed_height;
    /* two_fluid: the grains' mobile layer, from u^p where the layer's centre
     * is in the bed.  u^m runs ahead of u^p by the Darcy slip there, which
     * moves the zero of sqrt(u^m) down: on u^m the layer came out too thick
     * (docs/numerics/bed-models.md) */
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
    /* per unit width: the midpoint rule over the layers, and the exact integral */
    double q = 0.0;
    for (int l = 0; l < pr.n; l++)
        q += pr.velocity[l] * st->g.h[2];
    double q_exact = bedload_exact_flow_rate(&x);
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
    if (scene_profile(&pr, st) != 0)
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

/* the mixed model over ranks (its bed module per cell, the profile's
 * results summed over them); the two-fluid model's line solves hold whole
 * planes of one process */
static int decomposed(const struct muflow_case *cs)
{
    return params(cs)->model == BEDLOAD_MIXED;
}

/* both models' modules: setup configures the one of bedload.model, the other idles */
static const struct module *const bedload_modules[] = {&bed_module, &two_fluid_module, NULL};

const struct scene scene_bedload = {
    .name = "bedload",
    .title = "Poiseuille flow over a granular bed, mixed- or two-fluid model (Ouriemi et al. 2009)",
    .keys = &bedload_block,
    .modules = bedload_modules,
    .check = check,
    .setup = setup,
    .decomposed = decomposed,
    .not_decomposed = "bedload.model = two_fluid",
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_max",
    .errors = errors,
    .results = results,
    .write = write,
    .files = bedload_files,
};
