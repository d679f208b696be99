/* The implicit viscous solve's preconditioners (viscous_internal.h):
 * built for an operator and kept, prepared for a right-hand side, applied,
 * and their fallbacks: to the line blocks when a set-up fails, to the
 * probed LU when a multigrid's GMRES does. */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <gsl/gsl_linalg.h>
#include "solvers/viscous_internal.h"

/* the components the multigrid does not cover are left out below this share
 * of the largest right-hand side solved so far too: round-off (visc_gmg_others) */
#define GMG_ROUNDOFF 1e-12

/* Linear index of node m of line l of component c. */
static inline ptrdiff_t line_node(const struct viscous_solver *s, int c, int l, int m)
{
    const struct line_blocks *b = &s->blk[c];
    const struct box *bx = &s->act[c];
    int idx[3];
    int n0 = bx->hi[b->other[0]] - bx->lo[b->other[0]];
    idx[b->other[0]] = bx->lo[b->other[0]] + l % n0;
    idx[b->other[1]] = bx->lo[b->other[1]] + l / n0;
    idx[s->line_dir] = bx->lo[s->line_dir] + m;
    return grid_idx(s->g, idx[0], idx[1], idx[2]);
}

/* The line blocks' band factors and probes (BAND + 1 + PROBES doubles a
 * node); -1 and none of them when out of memory. */
int visc_line_blocks_alloc(struct viscous_solver *s)
{
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        struct line_blocks *b = &s->blk[c];
        if (b->nlines == 0 || b->band)
            continue;
        size_t nodes = (size_t)b->nlines * (size_t)b->len;
        b->band = malloc(nodes * (BAND + 1) * sizeof(double));
        b->probe = malloc(nodes * PROBES * sizeof(double));
        ok &= b->band && b->probe;
    }
    if (ok)
        return 0;
    for (int c = 0; c < 3; c++) {
        free(s->blk[c].band);
        free(s->blk[c].probe);
        s->blk[c].band = s->blk[c].probe = NULL;
    }
    return -1;
}

/* The sparse factorisation of the operator: the full tangent's (LU), which
 * reaches two nodes (|D| on an edge averages its neighbours' strains), or
 * the symmetric operator's (Cholesky), which reaches one. */
int visc_create_direct(struct viscous_solver *s, int full, char *err, size_t errlen)
{
    int periodic[3];
    bc_periodic_flags(s->bc, periodic);
    return sparse_direct_create(&s->direct, s->g, periodic, s->act, full ? 2 : 1, !full, err,
                                errlen);
}

/* Offset of column m' from row m for probe r: the unique m' = r (mod 5) with
 * |m' - m| <= 2. */
static inline int probe_offset(int r, int m)
{
    int off = ((r - m) % PROBES + PROBES) % PROBES;
    return off > BAND ? off - PROBES : off;
}

static void line_blocks(struct viscous_solver *s, const struct viscous_problem *pb, int skip);

/* What decides the probed matrix's pattern: the full tangent's terms, the
 * augmentation and the open faces' ghosts (the coefficients' values, the
 * mass term and the body, fixed for the solver, do not). */
static int pattern_key(const struct viscous_problem *pb)
{
    return 1 + (pb->b_cell != NULL) + 2 * (pb->augmentation != NULL) + 4 * (pb->open_given != 0);
}

/* The generic coefficients: a fixed pseudo-random sequence, the viscosities
 * and tangent coefficients in [1, 2), the base velocity in [-1, 1). */
void viscous_learn_pattern(struct viscous_solver *s, struct probe_matrix *pm, int *learnt,
                           const struct viscous_problem *pb)
{
    int key = pattern_key(pb);
    if (*learnt == key)
        return;
    *learnt = key; /* also when it fails: the structured colouring serves */
    enum { NFIELDS = 14, BASE = 10 };
    const struct grid *g = s->g;
    /* mapped, not on the heap: freed there, they leave a hole that the
     * later, larger blocks of the probing and the AMG may not fit, which
     * raises the peak memory (docs/numerics/linear-solvers.md, "A learnt
     * colouring") */
    size_t bytes = NFIELDS * g->size * sizeof(double);
    void *block = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    double *f[NFIELDS] = {0};
    int ok = block != MAP_FAILED;
    for (int m = 0; ok && m < NFIELDS; m++)
        f[m] = (double *)block + (size_t)m * g->size;
    if (ok) {
        /* a value per field and node, the same on a node and its periodic
         * images (as the march's ghosts are): random ghosts would couple a
         * direction of one periodic cell, whose derivatives vanish */
        for (int m = 0; m < NFIELDS; m++)
            for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
                for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                    for (int k = -1; k <= g->n[2]; k++) {
                        int t[3] = {i, j, k};
                        unsigned long long x = (unsigned long long)m;
                        for (int d = 0; d < 3; d++) {
                            if (s->bc->face[d][0] == BC_PERIODIC)
                                t[d] = (t[d] % g->n[d] + g->n[d]) % g->n[d];
                            x = x * 0x100000001B3ull + (unsigned long long)(t[d] + 1);
                        }
                        x += 0x9E3779B97F4A7C15ull; /* splitmix64's finaliser */
                        x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
                        x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
                        x ^= x >> 31;
                        double u = (double)(x >> 11) * 0x1.0p-53; /* [0, 1) */
                        f[m][grid_idx(g, i, j, k)] =
                            m >= BASE && m < BASE + 3 ? 2.0 * u - 1.0 : 1.0 + u;
                    }
        struct viscous_problem gen = {.mass = 1.0, .embedded = pb->embedded,
                                      .open_given = pb->open_given};
        for (int a = 0; a < 3; a++) {
            gen.A_cell[a] = f[a];
            gen.A_edge[a] = f[3 + a];
        }
        if (pb->b_cell) {
            gen.b_cell = f[6];
            for (int a = 0; a < 3; a++)
                gen.b_edge[a] = f[7 + a];
            gen.base = &f[BASE];
        }
        if (pb->augmentation)
            gen.augmentation = f[13];
        struct viscous_operator a = {s, &gen};
        probe_matrix_learn(pm, viscous_operator_apply, &a, s->p, s->q);
    }
    if (ok)
        munmap(block, bytes);
}

/* Counts a failed factorisation or AMG setup; the line blocks serve. */
static int fall_back(struct viscous_solver *s, const struct viscous_problem *pb, const char *cause)
{
    s->info.fallbacks++;
    snprintf(s->info.cause, sizeof s->info.cause, "%s", cause);
    line_blocks(s, pb, 0);
    return 1;
}

/* The components whose columns a probing takes: all, or those of the
 * blocks the last solve kept (the others' rows are then the identity's:
 * probe_matrix_assemble_components), while solves keep leaving them out. */
static int probe_mask(const struct viscous_solver *s)
{
    return s->keep_blocks ? 7 : s->probe_components;
}

/* The sparse factors for pb.  A Cholesky with the full tangent factorises a
 * symmetric counterpart while BiCGStab works on the tangent: the diagonal
 * tangent (sym_*), or, once that proved not positive definite
 * (s->direct_lagged), the lagged viscosity that pb's A_* then hold (a bed's
 * friction law can make d tau / d gamma negative in places:
 * docs/numerics/linear-solvers.md, "Failures are told").  The
 * factorisation is numeric only when
 * a right-hand side reaches a block (sparse_direct_prepare), so that is
 * where a failure shows.  Returns 0, or -1 with the cause recorded. */
static int direct_factor(struct viscous_solver *s, const struct viscous_problem *pb)
{
    struct viscous_problem sym = *pb;
    if (pb->b_cell && s->kind == VISCOUS_CHOLESKY) {
        sym.b_cell = NULL;
        sym.base = NULL;
        for (int a = 0; a < 3; a++) {
            sym.b_edge[a] = NULL;
            if (pb->sym_cell[a] && !s->direct_lagged)
                sym.A_cell[a] = pb->sym_cell[a];
            if (pb->sym_edge[a] && !s->direct_lagged)
                sym.A_edge[a] = pb->sym_edge[a];
        }
        pb = &sym;
    }
    viscous_learn_pattern(s, sparse_direct_probe_matrix(s->direct), &s->direct_pattern, pb);
    struct viscous_operator a = {s, pb};
    double t0 = visc_cpu_now();
    s->direct_ok = s->direct_valid =
        sparse_direct_factor(s->direct, viscous_operator_apply, &a, s->p, s->q,
                             probe_mask(s), &s->probed_components) == 0;
    kept_built(&s->direct_kept);
    s->info.grid_matrices++;
    s->info.setup_seconds = visc_cpu_now() - t0; /* probing included */
    s->info.unknowns = sparse_direct_unknowns(s->direct);
    s->info.kind = s->direct_ok ? s->info.kind : VISCOUS_LINE;
    return s->direct_ok ? 0 : -1;
}

/* Whether the factors of the diagonal tangent can give way to those of the
 * lagged viscosity (direct_factor) */
static int can_lag(const struct viscous_solver *s, const struct viscous_problem *pb)
{
    return s->kind == VISCOUS_CHOLESKY && pb->b_cell && !s->direct_lagged &&
           (pb->sym_cell[0] || pb->sym_cell[1] || pb->sym_cell[2]);
}

/* The multigrid of the covered components on the symmetric operator's
 * coefficients (the diagonal tangent with Newton's full tangent, as the
 * Cholesky takes); the others' line blocks are built by the first solve
 * that needs them (visc_gmg_others). */
static int gmg_setup(struct viscous_solver *s, const struct viscous_problem *pb)
{
    double t0 = visc_cpu_now();
    struct viscous_gmg_operator op = {.mass = pb->mass, .augmentation = pb->augmentation,
                                      .embedded = pb->embedded};
    for (int a = 0; a < 3; a++) {
        op.A_cell[a] = pb->b_cell && pb->sym_cell[a] ? pb->sym_cell[a] : pb->A_cell[a];
        op.A_edge[a] = pb->b_cell && pb->sym_edge[a] ? pb->sym_edge[a] : pb->A_edge[a];
        op.mass_face[a] = pb->mass_face[a];
        op.b_edge[a] = pb->b_cell ? pb->b_edge[a] : NULL;
    }
    op.base = pb->b_cell ? pb->base : NULL;
    char why[160];
    s->gmg_ok = viscous_gmg_setup(s->gmg, &op, why, sizeof why) == 0;
    s->info.setup_seconds = visc_cpu_now() - t0;
    s->info.probe_seconds = 0.0;
    s->info.reused = 0;
    const int first = __builtin_ctz((unsigned)viscous_gmg_components(s->gmg));
    s->info.levels = viscous_gmg_levels(s->gmg, first);
    if (!s->gmg_ok) {
        s->info.kind = VISCOUS_LINE;
        return fall_back(s, pb, why);
    }
    s->info.kind = VISCOUS_GMG;
    s->gmg_lines = 0; /* built by the first solve that needs them */
    return 0;
}

/* The components the multigrid does not cover: left out of this solve
 * while their part of the right-hand side is negligible (below a tenth of
 * the tolerance, as the factorisations' blocks are: a flow along a
 * periodic direction carries round-off across it) or round-off (below
 * GMG_ROUNDOFF of the largest right-hand side solved: in the last Newton
 * steps their round-off exceeds a tenth of the tolerance), else in GMRES
 * with their line blocks, built once per operator; in every solve they
 * multiply the iterations (docs/numerics/multigrid.md, "The implicit
 * step's geometric multigrid"). */
void visc_gmg_others(struct viscous_solver *s, const struct viscous_problem *pb,
                     double negligible, double bnorm)
{
    const int covered = viscous_gmg_components(s->gmg), others = 7 & ~covered;
    s->gmg_mask = 7;
    s->gmg_scale = fmax(s->gmg_scale, bnorm);
    if (!others)
        return;
    struct box part[3];
    masked_boxes(s, others, part);
    if (negligible >= 0.0 && sqrt(visc_dot(s, part, s->r, s->r)) <=
                                 fmax(negligible, GMG_ROUNDOFF * s->gmg_scale)) {
        s->gmg_mask = covered;
        s->dropped = 1;
        return;
    }
    if (!s->gmg_lines) {
        line_blocks(s, pb, covered);
        s->gmg_lines = 1;
    }
}

/* The velocity multigrid for pb, kept like a factorisation
 * (solver.preconditioner_reuse): at a fixed dt a Newtonian fluid's operator
 * does not change, and the set-up (the levels' stencils, line factors and
 * coarsest factorisation) was most of a step that CG ends in two
 * iterations (docs/numerics/velocity-multigrid.md). */
static int mg_setup(struct viscous_solver *s, const struct viscous_problem *pb)
{
    if (s->mg_valid && kept_serves(&s->direct_kept, s->direct_reuse)) {
        s->direct_kept.age++;
        s->mg_ok = 1;
        s->info.probe_seconds = s->info.setup_seconds = 0.0;
        s->info.reused = 1;
        return 0;
    }
    double t0 = visc_cpu_now();
    char why[200];
    s->mg_ok = s->mg_valid = velocity_mg_setup(s->mg, pb, why, sizeof why) == 0;
    kept_built(&s->direct_kept);
    s->info.setup_seconds = visc_cpu_now() - t0;
    s->info.probe_seconds = 0.0;
    s->info.reused = 0;
    s->info.levels = velocity_mg_levels(s->mg);
    s->info.kind = s->mg_ok ? VISCOUS_MG : VISCOUS_LINE;
    return s->mg_ok ? 0 : fall_back(s, pb, why);
}

/* The Fourier blocks for pb, kept like a factorisation
 * (solver.preconditioner_reuse): their probes are most of a step once CG
 * needs a few iterations. */
static int fourier_setup(struct viscous_solver *s, const struct viscous_problem *pb)
{
    s->fourier_ok = 1;
    if (s->fourier_valid && kept_serves(&s->direct_kept, s->direct_reuse)) {
        s->direct_kept.age++;
        s->info.setup_seconds = 0.0;
        s->info.reused = 1;
        return 0;
    }
    struct viscous_operator a = {s, pb};
    double t0 = visc_cpu_now();
    s->failed_blocks = fourier_lines_setup(s->fourier, viscous_operator_apply, &a, s->p, s->q);
    s->info.setup_seconds = visc_cpu_now() - t0; /* probing included */
    s->info.reused = 0;
    s->fourier_valid = 1;
    kept_built(&s->direct_kept);
    return 0;
}

/* A new AMG hierarchy on the multigrid's matrix: the operator, or its
 * Picard part, with or without the augmentation. */
static int amg_setup(struct viscous_solver *s, const struct viscous_problem *pb)
{
    struct viscous_problem q = *pb;
    if (s->amg_cfg.picard)
        q.b_cell = NULL;
    if (s->amg_cfg.drop_augmentation)
        q.augmentation = NULL;
    struct viscous_operator a = {s, &q};
    /* the old hierarchy is no use now: freed before the probing's
     * triplets and rows are allocated, not after (the peak memory held
     * both) */
    amg_hypre_release(s->amg);
    viscous_learn_pattern(s, s->probe, &s->amg_pattern, &q);
    double t0 = visc_cpu_now();
    int probed = probe_matrix_assemble_components(s->probe, viscous_operator_apply, &a, s->p,
                                                  s->q, 0, probe_mask(s), &s->amat,
                                                  &s->probed_components) == 0;
    int ok = probed;
    s->info.grid_matrices += probed;
    double t1 = visc_cpu_now();
    s->info.unknowns = s->amat.n;
    s->info.entries = csr_nnz(&s->amat);
    /* hypre copies the matrix: ours is released before its setup */
    ok = ok && amg_hypre_setup(s->amg, &s->amat) == 0; /* built in amg_prepare */
    s->info.probe_seconds = t1 - t0;
    s->info.setup_seconds = visc_cpu_now() - t1;
    s->info.levels = ok ? amg_hypre_levels(s->amg) : 0;
    s->info.complexity = ok ? amg_hypre_complexity(s->amg) : 0.0;
    s->info.blocks = ok ? amg_hypre_blocks(s->amg) : 0;
    s->info.kind = ok ? VISCOUS_AMG : VISCOUS_LINE;
    s->amg_ok = ok;
    kept_built(&s->amg_kept);
    if (ok)
        return 0;
    char cause[160];
    snprintf(cause, sizeof cause, "the algebraic multigrid of %ld unknowns: %s",
             probe_matrix_unknowns(s->probe),
             probed ? "hypre's setup failed" : "out of memory probing the matrix");
    return fall_back(s, pb, cause);
}

int viscous_precondition(struct viscous_solver *s, const struct viscous_problem *pb)
{
    s->direct_ok = 0;
    s->fourier_ok = 0;
    s->gmg_ok = 0;
    s->mg_ok = 0;
    if (s->mg)
        return mg_setup(s, pb);
    if (s->gmg)
        return gmg_setup(s, pb);
    if (s->fourier)
        return fourier_setup(s, pb);
    if (s->amg && s->amg_ok && kept_serves(&s->amg_kept, s->amg_cfg.reuse)) {
        /* the hierarchy of an earlier operator still serves: GMRES works on
         * the current one, so only the iteration count can suffer */
        s->amg_kept.age++;
        s->info.probe_seconds = s->info.setup_seconds = 0.0;
        s->info.reused = 1;
        return 0;
    }
    s->amg_ok = 0;
    s->info.reused = 0;
    if (s->amg && !s->amg_retired)
        return amg_setup(s, pb);
    if (s->direct && s->direct_valid && kept_serves(&s->direct_kept, s->direct_reuse)) {
        /* the factors of an earlier operator precondition the current one:
         * the Krylov method works on the current operator, so the solution
         * is the same to the linear tolerance and only the iterations grow */
        s->direct_kept.age++;
        s->direct_ok = 1;
        s->info.probe_seconds = s->info.setup_seconds = 0.0;
        s->info.reused = 1;
        return 0;
    }
    if (s->direct) {
        s->direct_lagged = 0;
        if (direct_factor(s, pb) == 0)
            return 0;
        return fall_back(s, pb, sparse_direct_cause(s->direct));
    }
    line_blocks(s, pb, 0);
    return 0;
}

/* skip: components (bits) left without blocks */
static void line_blocks(struct viscous_solver *s, const struct viscous_problem *pb, int skip)
{
    const struct grid *g = s->g;
    int L = s->line_dir;
    s->failed_blocks = 0;
    if (visc_line_blocks_alloc(s) != 0) {
        /* no memory for the blocks: every line unpreconditioned (z = r) */
        for (int c = 0; c < 3; c++)
            s->failed_blocks += s->blk[c].nlines;
        return;
    }
    for (int c = 0; c < 3; c++) {
        struct line_blocks *b = &s->blk[c];
        if (b->nlines == 0 || (skip >> c & 1))
            continue;
        for (int r = 0; r < PROBES; r++) {
            zero_fields(g, s->p);
            const struct box *bx = &s->act[c];
            for (int i = bx->lo[0]; i < bx->hi[0]; i++)
                for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                    for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                        int idx[3] = {i, j, k};
                        if ((idx[L] - bx->lo[L]) % PROBES == r)
                            s->p[c][grid_idx(g, i, j, k)] = 1.0;
                    }
            viscous_apply(s, pb, s->p, s->q);
#pragma omp parallel for schedule(static) if (kernel_parallel(s->g))
            for (int l = 0; l < b->nlines; l++)
                for (int m = 0; m < b->len; m++) {
                    int off = probe_offset(r, m);
                    if (m + off < 0 || m + off >= b->len)
                        continue;
                    b->probe[((size_t)l * b->len + m) * PROBES + off + BAND] =
                        s->q[c][line_node(s, c, l, m)];
                }
        }
        int failed = 0;
#pragma omp parallel for schedule(static) reduction(+ : failed) if (kernel_parallel(s->g))
        for (int l = 0; l < b->nlines; l++) {
            const double *pr = b->probe + (size_t)l * b->len * PROBES;
            double *band = b->band + (size_t)l * b->len * (BAND + 1);
            /* GSL symmetric band storage: row j holds A(j, j), A(j+1, j), A(j+2, j);
             * the probed block is symmetrised. */
            for (int j = 0; j < b->len; j++)
                for (int o = 0; o <= BAND; o++) {
                    double a = 0.0;
                    if (j + o < b->len)
                        a = 0.5 * (pr[(size_t)(j + o) * PROBES + BAND - o] +
                                   pr[(size_t)j * PROBES + BAND + o]);
                    band[j * (BAND + 1) + o] = a;
                }
            gsl_matrix_view mv = gsl_matrix_view_array(band, (size_t)b->len, BAND + 1);
            if (gsl_linalg_cholesky_band_decomp(&mv.matrix) != GSL_SUCCESS) {
                /* not positive definite: fall back to the mass-shifted diagonal */
                failed++;
                for (int j = 0; j < b->len; j++) {
                    double d = pr[(size_t)j * PROBES + BAND];
                    band[j * (BAND + 1)] = sqrt(d > pb->mass ? d : pb->mass);
                    band[j * (BAND + 1) + 1] = band[j * (BAND + 1) + 2] = 0.0;
                }
            }
        }
        s->failed_blocks += failed;
    }
}

/* z = M^-1 r: the factorisation, or line by line. */
void visc_precondition_apply(struct viscous_solver *s, double *const r[3], double *z[3])
{
    if (s->direct_ok) {
        sparse_direct_solve(s->direct, r, z);
        return;
    }
    if (s->fourier_ok) {
        fourier_lines_apply(s->fourier, r, z);
        return;
    }
    if (s->amg_ok) {
        probe_matrix_gather(s->probe, r, s->amg_b);
        amg_hypre_apply(s->amg, s->amg_b, s->amg_x);
        probe_matrix_scatter(s->probe, s->amg_x, z);
        return;
    }
    int skip = 0;
    if (s->gmg_ok) { /* the multigrid's components, and those left out of the solve */
        viscous_gmg_apply(s->gmg, r, z);
        skip = viscous_gmg_components(s->gmg) | (7 & ~s->gmg_mask);
    }
    for (int c = 0; c < 3; c++) {
        struct line_blocks *b = &s->blk[c];
        if (b->nlines == 0 || (skip >> c & 1))
            continue;
        if (!b->band) { /* line_blocks could not allocate them */
            memcpy(z[c], r[c], s->g->size * sizeof(double));
            continue;
        }
#pragma omp parallel for schedule(static) if (kernel_parallel(s->g))
        for (int l = 0; l < b->nlines; l++) {
            double *buf = s->linebuf + (size_t)omp_get_thread_num() * s->maxlen;
            for (int m = 0; m < b->len; m++)
                buf[m] = r[c][line_node(s, c, l, m)];
            gsl_matrix_view mv =
                gsl_matrix_view_array(b->band + (size_t)l * b->len * (BAND + 1), (size_t)b->len,
                                      BAND + 1);
            gsl_vector_view xv = gsl_vector_view_array(buf, (size_t)b->len);
            gsl_linalg_cholesky_band_svx(&mv.matrix, &xv.vector);
            for (int m = 0; m < b->len; m++)
                z[c][line_node(s, c, l, m)] = buf[m];
        }
    }
}

/* The components whose columns the probing left out: while their part of
 * the right-hand side stays negligible their blocks are left out of this
 * solve too; otherwise the whole matrix, probed again. */
static void probe_all_if_reached(struct viscous_solver *s, const struct viscous_problem *pb,
                                 double negligible)
{
    const struct probe_matrix *pm = s->amg_ok ? s->probe : sparse_direct_probe_matrix(s->direct);
    int missing = 7 & ~s->probed_components;
    if (negligible < 0.0 || probe_matrix_components_norm(pm, s->r, missing) > negligible) {
        struct kept *k = s->amg_ok ? &s->amg_kept : &s->direct_kept;
        s->probe_components = 7;
        k->force = 1;
        viscous_precondition(s, pb);
        k->force = 0;
    }
}

/* The sparse factors of the blocks of components this right-hand side
 * reaches; a failed Cholesky of the diagonal tangent tries the lagged
 * viscosity's, then the line blocks serve. */
static void direct_prepare(struct viscous_solver *s, const struct viscous_problem *pb,
                           double negligible)
{
    double t0 = visc_cpu_now();
    int failed = sparse_direct_prepare(s->direct, s->r, negligible) != 0;
    if (failed && can_lag(s, pb)) {
        s->direct_lagged = 1;
        s->info.lagged_factors++;
        failed = direct_factor(s, pb) != 0 ||
                 sparse_direct_prepare(s->direct, s->r, negligible) != 0;
    }
    s->dropped = failed ? 0 : sparse_direct_dropped(s->direct);
    if (failed) {
        s->direct_ok = s->direct_valid = 0;
        s->info.kind = VISCOUS_LINE;
        fall_back(s, pb, sparse_direct_cause(s->direct));
    }
    s->prepare_seconds += visc_cpu_now() - t0;
}

/* The hierarchies of the blocks this right-hand side reaches; the line
 * blocks serve when their setup fails. */
static void amg_prepare(struct viscous_solver *s, const struct viscous_problem *pb,
                        double negligible)
{
    double t0 = visc_cpu_now();
    probe_matrix_gather(s->probe, s->r, s->amg_b);
    int failed = amg_hypre_prepare(s->amg, s->amg_b, negligible) != 0;
    s->prepare_seconds += visc_cpu_now() - t0;
    s->info.levels = amg_hypre_levels(s->amg);
    s->info.complexity = amg_hypre_complexity(s->amg);
    s->dropped = amg_hypre_dropped(s->amg);
    if (failed) {
        s->amg_ok = 0;
        s->dropped = 0;
        s->info.kind = VISCOUS_LINE;
        char cause[160];
        snprintf(cause, sizeof cause,
                 "the algebraic multigrid of %ld unknowns: hypre's setup failed",
                 probe_matrix_unknowns(s->probe));
        fall_back(s, pb, cause);
    }
}

void visc_prepare(struct viscous_solver *s, const struct viscous_problem *pb, double negligible)
{
    if ((s->direct_ok || s->amg_ok) && s->probed_components != 7)
        probe_all_if_reached(s, pb, negligible);
    if (s->direct_ok)
        direct_prepare(s, pb, negligible);
    if (s->amg_ok)
        amg_prepare(s, pb, negligible);
}

/* The probed LU of the full tangent takes over from a multigrid (named in
 * the cause) whose GMRES ended with rc: the factorisation is created (its
 * probing learns its own pattern) and made by the next
 * viscous_precondition, the fallback counted with its cause.  Returns 0, or
 * -1 (no memory: the multigrid stays, the caller releases nothing). */
static int lu_takes_over(struct viscous_solver *s, const char *multigrid, int rc, int maxit)
{
    char err[160];
    if (!s->direct && visc_create_direct(s, 1, err, sizeof err) != 0)
        return -1;
    s->probe_components = 7;
    s->info.kind = VISCOUS_LU;
    s->info.fallbacks++;
    if (rc == 1)
        snprintf(s->info.cause, sizeof s->info.cause,
                 "the %s's GMRES reached its cap of %d iterations", multigrid, maxit);
    else
        snprintf(s->info.cause, sizeof s->info.cause, "the %s's GMRES broke down", multigrid);
    return 0;
}

/* The AMG gives way to the probed sparse LU of the same full tangent: its
 * GMRES failed (its cap, or a breakdown) on a fresh hierarchy, where the LU
 * converges (docs/numerics/linear-solvers.md, "Failures are told").  The
 * hierarchy is released; the factorisation is made by the next
 * viscous_precondition.  Returns 0, or -1 (no memory: the AMG stays). */
int visc_retire_amg(struct viscous_solver *s, int rc, int maxit)
{
    if (lu_takes_over(s, "algebraic multigrid", rc, maxit) != 0)
        return -1;
    amg_hypre_release(s->amg);
    csr_free(&s->amat);
    free_gmres(s);
    s->amg_ok = 0;
    s->amg_retired = 1;
    return 0;
}

/* The geometric multigrid gives way to the probed LU of the same full
 * tangent, as the AMG does (visc_retire_amg): its GMRES failed (where the
 * components across the flow carry a residual of their own: their line
 * blocks can stall it; docs/numerics/linear-solvers.md, "Failures are
 * told").  Returns 0, or -1 (no memory: the multigrid stays). */
int visc_retire_gmg(struct viscous_solver *s, int rc, int maxit)
{
    if (lu_takes_over(s, "geometric multigrid", rc, maxit) != 0)
        return -1;
    viscous_gmg_destroy(s->gmg);
    s->gmg = NULL;
    s->gmg_ok = 0;
    for (int k = 0; k < 2; k++) {
        gmres_destroy(s->gmg_gm[k]);
        s->gmg_gm[k] = NULL;
    }
    return 0;
}

