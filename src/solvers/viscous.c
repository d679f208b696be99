/* Matrix-free implicit viscous solve (viscous.h): the solver object, its
 * settings, the solve and its retries; the preconditioners are built in
 * viscous_precond.c, the Krylov loops run in viscous_krylov.c, the operator
 * is applied in viscous_apply.c (viscous_internal.h). */
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <gsl/gsl_errno.h>
#include "solvers/viscous_internal.h"

/* a block of components with at most this share of the tolerance times the
 * right-hand side's norm is left out of a solve (solve()) */
#define NEGLIGIBLE_SHARE 0.1
#define MG_RESTART 30 /* GMRES(30) around the velocity multigrid */

int viscous_line_direction(const struct viscous_solver *s) { return s->line_dir; }

void viscous_allow_lu_fallback(struct viscous_solver *s, int on) { s->lu_fallback = on; }

void viscous_set_reuse(struct viscous_solver *s, int steps)
{
    s->direct_reuse = steps > 0 ? steps : 0;
    s->amg_cfg.reuse = s->direct_reuse;
}

void viscous_renew(struct viscous_solver *s)
{
    /* past any limit: kept_serves refuses it, the next build resets it */
    s->direct_kept.age = s->amg_kept.age = INT_MAX;
}

static int pick_line_direction(const struct grid *g, const struct boundary *bc, int wanted)
{
    if (wanted >= 0)
        return bc->face[wanted][0] == BC_PERIODIC ? -1 : wanted;
    int best = -1;
    for (int d = 2; d >= 0; d--) /* ties go to z, the usual wall-normal direction */
        if (bc->face[d][0] != BC_PERIODIC && (best < 0 || g->n[d] > g->n[best]))
            best = d;
    return best;
}

static int mg_create(struct viscous_solver *s, char *err, size_t errlen)
{
    if (velocity_mg_create(&s->mg, s->g, s->bc, s->act, NULL, err, errlen) != 0)
        return -1;
    long n = visc_box_unknowns(s->act);
    s->mg_b = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    s->mg_x = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!s->mg_b || !s->mg_x || gmres_create_flexible(&s->mg_gm, n, MG_RESTART) != 0) {
        snprintf(err, errlen, "viscous solver: out of memory for the multigrid's GMRES");
        return -1;
    }
    gmres_set_decomp(s->mg_gm, s->bc->dc); /* its dots over the ranks */
    return 0;
}

int viscous_create(struct viscous_solver **out, const struct grid *g, const struct boundary *bc,
                   const struct box act[3], int line_dir, enum viscous_precond kind, char *err,
                   size_t errlen)
{
    int L = pick_line_direction(g, bc, line_dir);
    if (L < 0) {
        snprintf(err, errlen, "viscous solver: the preconditioner lines need a non-periodic "
                              "direction (solver.line_direction)");
        return -1;
    }
    struct viscous_solver *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "viscous solver: out of memory");
        return -1;
    }
    gsl_set_error_handler_off(); /* a non-SPD block is handled, not fatal */
    s->probe_components = s->probed_components = s->info.probed_components = 7;
    s->g = g;
    s->bc = bc;
    s->line_dir = L;
    memcpy(s->act, act, sizeof s->act);
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        struct line_blocks *b = &s->blk[c];
        b->other[0] = (L + 1) % 3;
        b->other[1] = (L + 2) % 3;
        b->len = act[c].hi[L] - act[c].lo[L];
        b->nlines = (act[c].hi[b->other[0]] - act[c].lo[b->other[0]]) *
                    (act[c].hi[b->other[1]] - act[c].lo[b->other[1]]);
        if (b->len <= 0 || b->nlines <= 0) {
            b->len = b->nlines = 0;
            continue;
        }
        if (b->len > s->maxlen)
            s->maxlen = b->len;
    }
    /* the line blocks are the preconditioner of VISCOUS_LINE; of the other
     * kinds only the fallback of a failed set-up, allocated then */
    if (kind == VISCOUS_LINE)
        ok &= visc_line_blocks_alloc(s) == 0;
    for (int c = 0; c < 3; c++) {
        s->r[c] = field_alloc(g);
        s->z[c] = field_alloc(g);
        s->p[c] = field_alloc(g);
        s->q[c] = field_alloc(g);
        ok &= s->r[c] && s->z[c] && s->p[c] && s->q[c];
    }
    s->nthreads = omp_get_max_threads();
    s->linebuf = malloc((size_t)s->nthreads * (size_t)(s->maxlen > 0 ? s->maxlen : 1) *
                        sizeof(double));
    s->divbuf = field_alloc(g);
    ok &= s->linebuf != NULL && s->divbuf != NULL;
    if (!ok) {
        viscous_destroy(s);
        snprintf(err, errlen, "viscous solver: out of memory");
        return -1;
    }
    s->kind = s->info.kind = kind;
    if (kind == VISCOUS_MG && mg_create(s, err, errlen) != 0) {
        viscous_destroy(s);
        return -1;
    }
    if (kind == VISCOUS_GMG &&
        viscous_gmg_create(&s->gmg, g, bc, act, err, errlen) != 0) {
        viscous_destroy(s);
        return -1;
    }
    if (kind == VISCOUS_FOURIER) {
        if (fourier_lines_create(&s->fourier, g, bc, act, L, err, errlen) != 0) {
            viscous_destroy(s);
            return -1;
        }
    } else if (kind != VISCOUS_LINE) {
        if (kind == VISCOUS_AMG) {
            viscous_amg_defaults(&s->amg_cfg);
            if (viscous_set_amg(s, &s->amg_cfg, err, errlen) != 0) {
                viscous_destroy(s);
                return -1;
            }
        } else if (kind != VISCOUS_GMG && kind != VISCOUS_MG &&
                   visc_create_direct(s, kind == VISCOUS_LU, err, errlen) != 0) {
            viscous_destroy(s);
            return -1;
        }
        ok &= (s->pn = field_alloc(g)) != NULL && (s->Bc = field_alloc(g)) != NULL;
        /* BiCGStab's own vectors (r0, v, t, sh) on first use: the AMG's
         * GMRES and the symmetric operator's CG do without them */
        for (int c = 0; c < 3; c++) {
            double **fs[] = {&s->pe[c], &s->Be[c], &s->tmp[c]};
            for (size_t m = 0; m < sizeof fs / sizeof fs[0]; m++)
                ok &= (*fs[m] = field_alloc(g)) != NULL;
        }
        if (!ok) {
            viscous_destroy(s);
            snprintf(err, errlen, "viscous solver: out of memory");
            return -1;
        }
    }
    *out = s;
    return 0;
}

void viscous_amg_defaults(struct viscous_amg *c)
{
    amg_options_default(&c->amg);
    c->bicgstab = 0;
    c->restart = 20;
    c->picard = 0;
    c->drop_augmentation = 0;
    c->reuse = 0;
}

int viscous_amg_parse(struct viscous_amg *c, const char *spec, char *err, size_t errlen)
{
    if (!spec)
        return 0;
    char buf[512], rest[512] = "";
    snprintf(buf, sizeof buf, "%s", spec);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        if (strncmp(tok, "krylov=", 7) == 0) {
            if (strcmp(tok + 7, "gmres") != 0 && strcmp(tok + 7, "bicgstab") != 0) {
                snprintf(err, errlen, "amg option %s: gmres or bicgstab", tok);
                return -1;
            }
            c->bicgstab = strcmp(tok + 7, "bicgstab") == 0;
        } else if (strncmp(tok, "restart=", 8) == 0) {
            c->restart = atoi(tok + 8);
            if (c->restart < 1) {
                snprintf(err, errlen, "amg option %s: at least 1", tok);
                return -1;
            }
        } else if (strncmp(tok, "picard=", 7) == 0) {
            c->picard = atoi(tok + 7) != 0;
        } else if (strncmp(tok, "reuse=", 6) == 0) {
            c->reuse = atoi(tok + 6);
        } else if (strncmp(tok, "aug=", 4) == 0) {
            c->drop_augmentation = atoi(tok + 4) == 0;
        } else {
            size_t l = strlen(rest);
            snprintf(rest + l, sizeof rest - l, "%s%s", l ? "," : "", tok);
        }
    }
    return amg_options_parse(&c->amg, rest, err, errlen);
}

int viscous_set_amg(struct viscous_solver *s, const struct viscous_amg *c, char *err,
                    size_t errlen)
{
    if (s->kind != VISCOUS_AMG) {
        snprintf(err, errlen, "viscous solver: not an amg preconditioner");
        return -1;
    }
    s->amg_cfg = *c;
    amg_hypre_destroy(s->amg);
    s->amg = NULL;
    s->amg_ok = 0;
    /* the full tangent reaches two nodes, the Picard operator one: 75 or 27
     * probes on a 2D grid */
    probe_matrix_destroy(s->probe);
    s->probe = NULL;
    int periodic[3];
    bc_periodic_flags(s->bc, periodic);
    if (probe_matrix_create(&s->probe, s->g, periodic, s->act, c->picard ? 1 : 2, err, errlen) !=
        0)
        return -1;
    long n = probe_matrix_unknowns(s->probe);
    if (!s->amg_b) {
        s->amg_b = malloc((size_t)n * sizeof(double));
        s->amg_x = malloc((size_t)n * sizeof(double));
    }
    free_gmres(s);
    int m = c->restart;
    if (!s->amg_b || !s->amg_x || gmres_create(&s->gm, n, m) != 0) {
        snprintf(err, errlen, "viscous solver: out of memory for GMRES(%d)", m);
        return -1;
    }
    return amg_hypre_create(&s->amg, (int)n, probe_matrix_components(s->probe), &c->amg, err,
                            errlen);
}

const char *viscous_precond_name(enum viscous_precond kind)
{
    static const char *const names[] = {"line", "cholesky", "lu", "amg", "fourier", "gmg",
                                        "multigrid"};
    return (int)kind >= 0 && kind <= VISCOUS_MG ? names[kind] : "?";
}

void viscous_precond_info(const struct viscous_solver *s, struct viscous_precond_info *info)
{
    *info = s->info;
}

void viscous_keep_blocks(struct viscous_solver *s, int on) { s->keep_blocks = on != 0; }

void viscous_destroy(struct viscous_solver *s)
{
    if (!s)
        return;
    for (int c = 0; c < 3; c++) {
        free(s->blk[c].band);
        free(s->blk[c].probe);
        field_free(s->r[c]);
        field_free(s->z[c]);
        field_free(s->p[c]);
        field_free(s->q[c]);
    }
    free(s->linebuf);
    field_free(s->divbuf);
    fourier_lines_destroy(s->fourier);
    viscous_gmg_destroy(s->gmg);
    velocity_mg_destroy(s->mg);
    gmres_destroy(s->mg_gm);
    free(s->mg_b);
    free(s->mg_x);
    gmres_destroy(s->gmg_gm[0]);
    gmres_destroy(s->gmg_gm[1]);
    free(s->gmg_b);
    free(s->gmg_x);
    field_free(s->flow_gb[0]);
    field_free(s->flow_gb[1]);
    sparse_direct_destroy(s->direct);
    amg_hypre_destroy(s->amg);
    probe_matrix_destroy(s->probe);
    csr_free(&s->amat);
    free(s->amg_b);
    free(s->amg_x);
    free_gmres(s);
    field_free(s->pn);
    field_free(s->Bc);
    for (int c = 0; c < 3; c++) {
        double *fs[] = {s->pe[c], s->Be[c], s->tmp[c], s->r0[c], s->v[c], s->t[c], s->sh[c]};
        for (size_t m = 0; m < sizeof fs / sizeof fs[0]; m++)
            field_free(fs[m]);
    }
    free(s);
}

static int solve(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                 double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    zero_fields(g, x);
    zero_fields(g, s->z);
    for (int c = 0; c < 3; c++)
        memcpy(s->r[c], rhs[c], g->size * sizeof(double));
    double bnorm = sqrt(visc_dot(s, act, s->r, s->r));
    st->iterations = 0;
    st->relative_residual = 0.0;
    if (bnorm == 0.0) {
        st->failed_blocks = s->failed_blocks;
        st->direct = s->direct_ok;
        return 0;
    }
    if (!isfinite(bnorm))
        return -1;
    /* A block of velocity components (sparse_direct, amg_hypre: those the
     * matrix does not couple) whose part of the right-hand side is below a
     * tenth of the tolerance is left out: its correction is 0 and its
     * residual stays, within the tolerance.  A flow along one direction
     * (the heap, the ducts) carries only the state's round-off across it,
     * and the factorisation or hierarchy of the two components across was
     * most of the step (docs/numerics/linear-solvers.md, "Blocks left
     * out").  A solve that fails so is solved again with every block
     * (viscous_solve). */
    double negligible =
        s->keep_blocks || s->keep_once ? -1.0 : NEGLIGIBLE_SHARE * rtol * bnorm;
    s->dropped = 0;
    visc_prepare(s, pb, negligible);
    /* An open face makes the Picard operator non-symmetric too: its normal
     * component's increment copies the inner face's, and the shear at the
     * face takes that copy's tangential gradient, a coupling with no
     * transpose (the front: (u, Av) and (v, Au) of random fields 1e-5 to
     * 3e-4 apart, the cycle's 2e-2).  CG then stalls on some steps (the
     * front's step 1018 at its cap of 500, 2.5e-8 alone, 4e-4 on two ranks);
     * the flexible GMRES converges them (that step in 24 iterations) */
    if (s->mg_ok)
        return pb->b_cell || bc_has_open(s->bc) ? visc_mg_gmres(s, pb, x, rtol, maxit, st)
                                                : visc_mg_pcg(s, pb, bnorm, x, rtol, maxit, st);
    if (s->gmg_ok)
        visc_gmg_others(s, pb, negligible, bnorm);
    st->failed_blocks = s->failed_blocks;
    st->direct = s->direct_ok;
    if (s->gmg_ok)
        return visc_gmg_gmres(s, pb, x, rtol, maxit, st);
    if (s->amg_ok)
        return s->amg_cfg.bicgstab ? visc_bicgstab(s, pb, bnorm, x, rtol, maxit, st)
                                   : visc_gmres(s, pb, rhs, x, rtol, maxit, st);
    /* the full tangent (viscous_apply uses it), or an open face's
     * non-symmetric operator on the Fourier blocks */
    if ((pb->b_cell && s->pn) || (s->fourier_ok && fourier_lines_general(s->fourier)))
        return visc_bicgstab(s, pb, bnorm, x, rtol, maxit, st);
    return visc_pcg(s, pb, bnorm, x, rtol, maxit, st);
}

int viscous_solve(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                  double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    double t0 = visc_cpu_now();
    s->prepare_seconds = 0.0;
    int rc = solve(s, pb, rhs, x, rtol, maxit, st);
    /* kept factors or a kept hierarchy that no longer serve: rebuilt for
     * this operator */
    struct kept *k = s->amg_ok ? &s->amg_kept
                     : s->direct_ok || s->fourier_ok || s->mg_ok ? &s->direct_kept : NULL;
    if (rc != 0 && k && k->age > 0) {
        k->force = 1;
        viscous_precondition(s, pb);
        k->force = 0;
        rc = solve(s, pb, rhs, x, rtol, maxit, st);
    }
    if (rc != 0 && s->dropped) {
        /* a block left out that the solve needed after all */
        s->keep_once = 1;
        rc = solve(s, pb, rhs, x, rtol, maxit, st);
        s->keep_once = 0;
    }
    if (rc != 0 && s->amg_ok && s->lu_fallback && visc_retire_amg(s, rc, maxit) == 0) {
        viscous_precondition(s, pb);
        rc = solve(s, pb, rhs, x, rtol, maxit, st);
    }
    if (rc != 0 && s->gmg_ok && s->lu_fallback && visc_retire_gmg(s, rc, maxit) == 0) {
        viscous_precondition(s, pb);
        rc = solve(s, pb, rhs, x, rtol, maxit, st);
    }
    s->info.dropped_blocks = s->dropped;
    s->info.probed_components = s->probed_components;
    /* the next probing leaves out the components of the blocks this solve
     * left out (a solve that failed: none) */
    int out = 0;
    if (rc == 0 && s->dropped)
        out = s->amg_ok ? amg_hypre_dropped_components(s->amg)
                        : s->direct_ok ? sparse_direct_dropped_components(s->direct) : 0;
    s->probe_components = 7 & ~out;
    if (s->amg_ok)
        kept_solved(&s->amg_kept, st->iterations);
    else if (s->direct_ok || s->fourier_ok || s->mg_ok)
        kept_solved(&s->direct_kept, st->iterations);
    /* the factorisations done for this right-hand side count as set-up */
    s->info.setup_seconds += s->prepare_seconds;
    s->info.solve_seconds = visc_cpu_now() - t0 - s->prepare_seconds;
    return rc;
}

/* gmg's hierarchies a grid slot (viscous_memory_estimate) */
#define GMG_HIERARCHY_DOUBLES (2.0 * 12.0 * 4.0 / 3.0 + 4.0)

double viscous_gmg_gathered_estimate(const struct grid *gg, const struct grid *g)
{
    /* the hierarchies on the whole cross-section, not the block's, and at
     * most 16 gathered arrays of the operator, the right-hand side, the
     * cycle and the gather's buffer (the ranks' blocks, about one field) */
    return ((GMG_HIERARCHY_DOUBLES + 16.0 + 3.0) * (double)gg->size -
            GMG_HIERARCHY_DOUBLES * (double)g->size) *
           sizeof(double);
}

double viscous_memory_estimate(const struct grid *g, const struct boundary *bc,
                               enum viscous_precond kind)
{
    /* as viscous_create allocates: per component r, z, p, q and the
     * divergence buffer; the line blocks' band and probes (BAND + 1 +
     * PROBES doubles a node) with VISCOUS_LINE; with any other kind pn, Bc
     * and three per component (and the factorisation,
     * sparse_direct_memory_estimate), and BiCGStab's four more per
     * component where the full tangent takes them (LU, Cholesky; a fallback to the
     * line blocks, or BiCGStab around the AMG, is not counted) */
    double cells = (double)grid_cells(g), points = (double)g->size;
    double doubles = (3.0 * 4.0 + 1.0) * points;
    if (kind == VISCOUS_LINE)
        doubles += 3.0 * cells * (BAND + 1 + PROBES);
    else
        doubles += (2.0 + 3.0 * 3.0) * points;
    if (kind == VISCOUS_LU || kind == VISCOUS_CHOLESKY ||
        (kind == VISCOUS_FOURIER && bc_has_open(bc))) /* general Fourier blocks */
        doubles += 3.0 * 4.0 * points;
    /* the AMG's GMRES(20) basis (21 vectors of the unknowns, about three a
     * cell) and its gathered right-hand side and correction (hypre's share:
     * amg_hypre_memory_estimate) */
    if (kind == VISCOUS_AMG)
        doubles += (21.0 + 2.0) * 3.0 * cells;
    /* the geometric multigrid: per covered component (at most two) and
     * level (4/3 of the finest in 2D) the coefficients, mass, Thomas
     * factors and cycle arrays (about 12 fields), the set-up's four, and
     * the flexible GMRES(20)'s two bases of the covered unknowns */
    if (kind == VISCOUS_GMG)
        doubles += GMG_HIERARCHY_DOUBLES * points + (2.0 * GMG_RESTART + 3.0) * 2.0 * cells;
    /* the velocity multigrid's levels and its GMRES(30)'s flexible bases */
    if (kind == VISCOUS_MG)
        doubles += (2.0 * MG_RESTART + 3.0) * 3.0 * cells;
    return doubles * sizeof(double) +
           (kind == VISCOUS_FOURIER ? fourier_lines_memory_estimate(g, bc) : 0.0) +
           (kind == VISCOUS_MG ? velocity_mg_memory_estimate(g, NULL, NULL) : 0.0);
}

struct velocity_mg *viscous_velocity_mg(struct viscous_solver *s) { return s->mg; }
