/* Creating and destroying a march (march.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "march_internal.h"

#include "march/step.h"
#include "solvers/sparse_direct.h"

/* The projection's condition on a face: the pressure vanishes on an open
 * face (Dirichlet), its normal gradient on every closed or prescribed one. */
static enum poisson_bc projection_bc(enum bc_kind k)
{
    return k == BC_PERIODIC ? POISSON_PERIODIC : k == BC_OPEN ? POISSON_DIRICHLET : POISSON_NEUMANN;
}

/* The setup's modules, in order. */
static int add_modules(struct march_state *st, const struct march_setup *su, char *err,
                       size_t errlen)
{
    for (int l = 0; l < 3; l++)
        for (const struct module *const *m = su->modules[l]; m && *m; m++) {
            if (st->nmodules == MODULES_MAX) {
                snprintf(err, errlen, "more than %d physics modules", MODULES_MAX);
                return -1;
            }
            /* the coupled step solves the velocity and pressure of one
             * density and one velocity field (module.h: coupled_ok) */
            if (st->cs->coupled && !(*m)->coupled_ok) {
                snprintf(err, errlen, "solver.coupled = on: the physics module '%s' of this "
                                      "scene is not supported by the coupled step yet",
                         (*m)->name);
                return -1;
            }
            /* its own unknowns would miss BDF2's terms (stage_time_scheme.c) */
            if (st->cs->time_scheme == TIME_BDF2 && (*m)->implicit && !(*m)->implicit_steady) {
                snprintf(err, errlen, "solver.time_scheme = bdf2: the physics module '%s' of "
                                      "this scene solves the step itself, with Euler's step only "
                                      "(set solver.time_scheme = euler)",
                         (*m)->name);
                return -1;
            }
            int i = st->nmodules++;
            st->modules[i] = *m;
            if ((*m)->create && (*m)->create(st, &st->module_state[i], err, errlen) != 0)
                return -1;
        }
    return 0;
}

/* What runs over several ranks besides the scene's consent (scene.h:
 * decomposed): one message naming the first option that does not, and what
 * does. */
#define RANKS_RUN "solver.coupled = off, or on with the LU and no open face, " \
                  "physics.advection_scheme = centred or upwind, the " \
                  "physics modules that run decomposed (the scenes', the nonlocal fluidity's, " \
                  "a body's), uniform spacing, the line, fourier or multigrid preconditioner " \
                  "(solver.preconditioner = auto, line, fourier or multigrid)"

static int ranks_refused(const struct muflow_case *cs, const char *what, char *err, size_t errlen)
{
    snprintf(err, errlen, "%s on %d MPI ranks: %s does not run decomposed (what does: %s)",
             cs->name, comm_size(), what, RANKS_RUN);
    return -1;
}

/* The first module of the case (not the scene's own: its consent covers
 * them) that does not run decomposed (module.h), or NULL. */
static const struct module *module_not_decomposed(const struct march_setup *su)
{
    for (int l = 1; l < 3; l++)
        for (const struct module *const *m = su->modules[l]; m && *m; m++)
            if (!(*m)->decomposed)
                return *m;
    return NULL;
}

static int march_ranks_refusal(const struct muflow_case *cs, const struct march_setup *su,
                               char *err, size_t errlen)
{
    const struct module *m = module_not_decomposed(su);
    char module[120] = "";
    if (m)
        snprintf(module, sizeof module, "the physics module '%s'", m->name);
    /* vanleer's and quick's second upwind node is a ghost beyond the one
     * layer at a rank border (first order there, not at one process) */
    const int upwind2 = cs->advection && (cs->advection_scheme == ADVECTION_VANLEER ||
                                          cs->advection_scheme == ADVECTION_QUICK);
    /* the coupled step gathers its matrix onto every rank and factorises it
     * there (coupled_view.h): the LU's, without open faces' unknowns */
    const int coupled_lu = cs->preconditioner == PRECOND_AUTO || cs->preconditioner == PRECOND_LU;
    const char *what = cs->coupled && !coupled_lu
                           ? "solver.coupled = on with solver.preconditioner = amg or multigrid"
                       : cs->coupled && bc_has_open(&cs->bc)
                           ? "solver.coupled = on with an open face"
                       : upwind2               ? "physics.advection_scheme = vanleer or quick"
                       : m                     ? module
                                               : NULL;
    return what ? ranks_refused(cs, what, err, errlen) : 0;
}

/* A run over several ranks (comm.h): the Cartesian communicator over the
 * periodic directions (a line across walls or a surface, the line blocks'
 * (never periodic: case_checks.c) and the profile's, stays whole on a
 * rank), and the bounded ones under the velocity multigrid (its lines cut
 * at rank borders), this rank's block, its local grid as st->g, not
 * compact (the decomposed multigrid takes no compact grid), and the fills'
 * decomposition; *kind the implicit step's preconditioner, chosen on the
 * whole grid (precond_policy.c), refused unless decomposed (before the
 * split, which it decides).  What runs so is march_ranks_refusal's. */
static int split_over_ranks(struct march_state *st, const struct muflow_case *cs,
                            const struct march_setup *su, enum viscous_precond *kind, char *err,
                            size_t errlen)
{
    struct march_ranks *rk = st->ranks = calloc(1, sizeof *rk);
    if (!rk) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int periodic[3], splittable[3], dims[3] = {su->dims[0], su->dims[1], su->dims[2]};
    bc_periodic_flags(&cs->bc, periodic);
    if (grid_init(&rk->global, cs->n, cs->len) != 0) {
        snprintf(err, errlen, "grid: invalid cell counts or lengths");
        return -1;
    }
    *kind = march_choose_preconditioner(cs, su, &rk->global, -1);
    /* gmg gathers its cross-section on every rank (viscous_gmg.c), a body's
     * held nodes and cut links with it */
    const int gmg = *kind == VISCOUS_GMG;
    if (*kind != VISCOUS_LINE && *kind != VISCOUS_FOURIER && *kind != VISCOUS_MG && !gmg &&
        !cs->coupled) { /* the coupled step's solver is its own (coupled_view.h) */
        char what[120];
        snprintf(what, sizeof what,
                 cs->preconditioner == PRECOND_AUTO ? "the implicit step's %s preconditioner"
                                                    : "solver.preconditioner = %s",
                 viscous_precond_name(*kind));
        return ranks_refused(cs, what, err, errlen);
    }
    /* the velocity multigrid cuts its lines at rank borders, gmg gathers
     * its cross-section, so does the coupled step its whole grid: a bounded
     * direction splits too */
    const int bounded = *kind == VISCOUS_MG || gmg || cs->coupled;
    for (int d = 0; d < 3; d++)
        splittable[d] = (periodic[d] || bounded) && cs->n[d] > 1;
    char why[300];
    if (comm_cart_create(&rk->cart, dims, periodic, splittable, why, sizeof why) != 0 ||
        decomp_create(&rk->dc, &rk->cart, cs->n, why, sizeof why) != 0) {
        snprintf(err, errlen, "%s on %d MPI ranks: %s (only the periodic directions are split, "
                              "and with solver.preconditioner = multigrid or gmg the bounded ones, "
                              "each into at most its cells)", cs->name, comm_size(), why);
        return -1;
    }
    if (decomp_local_grid(&rk->dc, &rk->global, &st->g) != 0) {
        snprintf(err, errlen, "grid: invalid cell counts or lengths");
        return -1;
    }
    st->bc.dc = &rk->dc;
    return 0;
}

int march_create(struct march_state *st, const struct muflow_case *cs,
                 const struct march_setup *su, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    st->cs = cs;
    st->bc = cs->bc;
    st->rheo = cs->rheo;
    if (cs->mode == MODE_STEADY)
        st->rheo.lambda *= cs->continuation;
    int wraps[3];
    bc_periodic_flags(&cs->bc, wraps);
    enum viscous_precond kind;
    if (su->decompose && comm_size() > 1) {
        if (march_ranks_refusal(cs, su, err, errlen) != 0 ||
            split_over_ranks(st, cs, su, &kind, err, errlen) != 0) {
            march_destroy(st);
            return -1;
        }
    } else if (grid_init_compact(&st->g, cs->n, cs->len, wraps) != 0) {
        snprintf(err, errlen, "grid: invalid cell counts or lengths");
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        char why[300];
        int r = case_axis(cs, d, &st->axes[d], why, sizeof why);
        if (r > 0 && grid_set_axis(&st->g, d, &st->axes[d]) != 0) {
            snprintf(why, sizeof why, "the field would not fit in memory");
            r = -1;
        }
        if (r < 0) {
            snprintf(err, errlen, "domain.%c_band: %s", "xyz"[d],
                     why[0] ? why : "not 'lo hi h' triples separated by ';'");
            march_destroy(st);
            return -1;
        }
    }
    const struct grid *g = &st->g;
    if (st->ranks && grid_stretched(g)) {
        ranks_refused(cs, "a domain.<d>_band (a stretched grid)", err, errlen);
        march_destroy(st);
        return -1;
    }
    fields_init(&st->fields, g);
    bc_unknown_boxes(g, &st->bc, st->act);
    /* refuse before allocating what the machine does not have (case_load
     * refuses it first, from the case alone) */
    double avail = march_available_memory();
    /* on ranks the kind split_over_ranks chose on the whole grid, this
     * rank's block's memory */
    st->memory_estimate = st->ranks ? march_memory_estimate(cs, su, g, kind)
                                    : march_plan(cs, su, g, -1, avail, &kind);
    if (st->ranks && kind == VISCOUS_GMG) /* its cross-section whole on every rank */
        st->memory_estimate += viscous_gmg_gathered_estimate(&st->ranks->global, g);
    if (st->ranks && cs->coupled) /* its whole grid's matrix on every rank */
        st->memory_estimate += march_coupled_gathered_estimate(&st->ranks->global);
    st->precond = kind;
    if (avail > 0.0 && st->memory_estimate > avail) {
        march_memory_refusal(err, errlen, g, kind, st->memory_estimate, avail);
        march_destroy(st);
        return -1;
    }
    if (march_register_fields(st) != 0) {
        snprintf(err, errlen, "out of memory for a %d x %d x %d grid", g->n[0], g->n[1], g->n[2]);
        march_destroy(st);
        return -1;
    }
    /* one density everywhere until a module says otherwise */
    st->rho_ref = cs->density;
    st->density_uniform = 1;
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < g->size; p++)
            st->field.density_faces[c][p] = cs->density;
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            pbc[d][s] = projection_bc(st->bc.face[d][s]);
    /* the probed LU and the AMG both take the full (non-symmetric) tangent,
     * and so does the coupled step whatever the preconditioner named; the
     * Cholesky factorises the diagonal tangent and BiCGStab solves the full
     * one with it (docs/numerics/implicit-step-and-newton.md) */
    st->full_tangent = (kind == VISCOUS_LU || kind == VISCOUS_AMG || kind == VISCOUS_CHOLESKY ||
                        kind == VISCOUS_GMG || kind == VISCOUS_MG ||
                        cs->coupled) && cs->newton;
    int ok = 1;
    if (cs->augmentation > 0.0) {
        const struct field_spec s = {"augmentation", FIELD_CELLS, 0};
        ok &= fields_add(&st->fields, &s, &st->aug) >= 0;
    }
    if (st->full_tangent) {
        const struct field_spec sc = {"tangent_b_cells", FIELD_CELLS, 0},
                                se = {"tangent_b_edges", FIELD_EDGES, 0};
        ok &= fields_add(&st->fields, &sc, &st->b_c) >= 0 &&
              fields_add(&st->fields, &se, st->b_e) >= 0;
    }
    if (!ok) {
        snprintf(err, errlen, "out of memory for the full tangent");
        march_destroy(st);
        return -1;
    }
    /* a stretched grid's steps are the coupled ones (case_checks.c): no projection */
    const enum poisson_bc(*pb)[2] = (const enum poisson_bc(*)[2])pbc;
    if ((!grid_stretched(g) &&
         march_pressure_create(st, &st->pressure_solver, pb, err, errlen) != 0) ||
        viscous_create(&st->viscous, g, &st->bc, st->act, cs->line_direction, kind, err,
                       errlen) != 0 ||
        add_modules(st, su, err, errlen) != 0 || (su->setup && su->setup(st, err, errlen) != 0) ||
        hydrostatic_split(st, err, errlen) != 0) {
        march_destroy(st);
        return -1;
    }
    viscous_set_reuse(st->viscous, cs->preconditioner_reuse);
    /* an AMG or a geometric multigrid whose GMRES fails gives way to the LU
     * where that fits: the factorisation's limits, and the run with the LU
     * in the memory the machine had at the start */
    int periodic[3];
    bc_periodic_flags(&st->bc, periodic);
    viscous_allow_lu_fallback(st->viscous,
                              (kind == VISCOUS_AMG || kind == VISCOUS_GMG) &&
                                  3L * (long)grid_cells(g) <= FACTOR_MAX_UNKNOWNS &&
                                  sparse_direct_probes_for(g, periodic, 2) <=
                                      sparse_direct_max_probes() &&
                                  !(avail > 0.0 &&
                                    march_memory_estimate(cs, su, g, VISCOUS_LU) > avail));
    st->dt = cs->dt;
    march_forget_progress(st);
    st->dt_scale = 1.0;
    return 0;
}

void march_destroy(struct march_state *st)
{
    for (int i = st->nmodules - 1; i >= 0; i--)
        if (st->modules[i]->destroy)
            st->modules[i]->destroy(st->module_state[i]);
    fields_free(&st->fields);
    pressure_destroy(st->pressure_solver);
    viscous_destroy(st->viscous);
    stage_coupled_destroy(st->coupled);
    for (int d = 0; d < 3; d++)
        grid_axis_free(&st->axes[d]);
    if (st->ranks) {
        decomp_free(&st->ranks->dc);
        comm_cart_free(&st->ranks->cart);
        free(st->ranks);
    }
    memset(st, 0, sizeof *st);
}
