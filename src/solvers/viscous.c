/* Matrix-free implicit viscous solve: PCG with probed line blocks, BiCGStab
 * with a probed sparse factorisation, GMRES with algebraic multigrid
 * (viscous.h). */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/mman.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include "solvers/amg_hypre.h"
#include "solvers/fourier_lines.h"
#include "solvers/viscous_gmg.h"
#include "solvers/velocity_mg.h"
#include "solvers/probe_matrix.h"
#include "solvers/sparse_direct.h"
#include "solvers/viscous.h"
#include "solvers/gmres.h"

#define BAND 2               /* nodes reached along a line by the stencil */
#define PROBES (2 * BAND + 1)
/* a block of components with at most this share of the tolerance times the
 * right-hand side's norm is left out of a solve (solve()) */
#define NEGLIGIBLE_SHARE 0.1
#define GMG_RESTART 20       /* flexible GMRES(20) on the multigrid's components */
/* the components the multigrid does not cover are left out below this share
 * of the largest right-hand side solved so far too: round-off (gmg_others) */
#define GMG_ROUNDOFF 1e-12

struct line_blocks {
    int nlines, len;          /* lines of this component and nodes per line */
    int other[2];             /* the two directions across the lines */
    double *band;             /* nlines * len * (BAND+1): GSL symmetric band rows */
    double *probe;            /* nlines * len * PROBES: probed rows, unsymmetrised */
};

/* A preconditioner kept across steps (a factorisation, an AMG hierarchy):
 * it serves up to a limit of further viscous_precondition calls while the
 * Krylov iterations stay within twice those of its first solve plus 2. */
struct kept {
    int age;                     /* viscous_precondition calls since it was built */
    int fresh_iters, last_iters; /* Krylov iterations just after it, and last */
    int force;                   /* 1: the next call rebuilds it (a failed solve) */
};

static int kept_serves(const struct kept *k, int limit)
{
    return !k->force && limit > 0 && k->age < limit && k->last_iters <= 2 * k->fresh_iters + 2;
}

static void kept_built(struct kept *k)
{
    k->age = 0;
    k->fresh_iters = -1;
}

static void kept_solved(struct kept *k, int iterations)
{
    if (k->fresh_iters < 0)
        k->fresh_iters = iterations;
    k->last_iters = iterations;
}

struct viscous_solver {
    const struct grid *g;
    const struct boundary *bc;
    struct box act[3];
    int line_dir;
    struct line_blocks blk[3];
    double *r[3], *z[3], *p[3], *q[3]; /* CG work vectors */
    double *linebuf;                   /* per-thread gather buffer */
    int maxlen, nthreads;
    int failed_blocks;                 /* of the last viscous_precondition */
    double *divbuf;                    /* divergence for the augmentation term */
    struct sparse_direct *direct;      /* NULL: line blocks only */
    int direct_ok;                     /* the factorisation serves this solve */
    double prepare_seconds;            /* factorising the blocks a solve's right-hand side reaches */
    int direct_valid;                  /* the last factorisation succeeded */
    int direct_lagged;                 /* the factors are the lagged viscosity's (direct_factor) */
    int keep_blocks, keep_once;        /* solve() leaves no block out: always, this solve */
    /* the components whose columns the next probing takes and those the
     * current matrix's probing took (bit c; 7: all) */
    int probe_components, probed_components;
    int dropped;                       /* blocks the last solve() left out */
    int direct_reuse;                  /* > 0: it serves up to this many further steps */
    struct kept direct_kept;
    /* full tangent work: strain products, their tangent stresses (allocated
     * with any kind but the line blocks), and the extra BiCGStab vectors
     * (allocated on BiCGStab's first use) */
    double *pn, *pe[3], *Bc, *Be[3], *tmp[3];
    double *r0[3], *v[3], *t[3], *sh[3];
    enum viscous_precond kind;         /* as created */
    /* algebraic multigrid (VISCOUS_AMG) */
    struct probe_matrix *probe;
    struct amg_hypre *amg;
    struct viscous_amg amg_cfg;
    struct csr_matrix amat;            /* the probed matrix */
    double *amg_b, *amg_x;             /* gathered right-hand side and correction */
    int amg_ok;                        /* the last setup succeeded */
    struct kept amg_kept;              /* the hierarchy's reuse (amg_cfg.reuse) */
    int lu_fallback;                   /* viscous_allow_lu_fallback */
    int amg_retired;                   /* the LU took over from the AMG for good */
    struct gmres *gm;                  /* GMRES, its basis in the probed unknowns
                                          (not field triples, three times larger
                                          with their ghosts) */
    struct viscous_precond_info info;
    int direct_pattern, amg_pattern;   /* the pattern_key the probed matrices'
                                          colourings were learnt for (0: none) */
    struct fourier_lines *fourier;     /* VISCOUS_FOURIER */
    int fourier_ok;                    /* its blocks serve this solve */
    int fourier_valid;                 /* they have been built */
    struct viscous_gmg *gmg;           /* VISCOUS_GMG: the covered components' multigrid */
    int gmg_ok;                        /* its hierarchies serve this solve */
    int gmg_lines;                     /* the others' line blocks are built for this operator */
    struct gmres *gmg_gm[2];           /* GMRES on the covered components' unknowns, on all */
    int gmg_mask;                      /* the components of this solve's GMRES (bits): the
                                          multigrid's, and the others unless left out */
    double gmg_scale;                  /* the largest right-hand side solved so far */
    double *gmg_b, *gmg_x;             /* their gathered right-hand side and solution */
    double *flow_gb[2];                /* the flow block's base strains (kernel_flow_gammas),
                                          set by each Newton solve that uses it */
    struct velocity_mg *mg;            /* VISCOUS_MG: the velocity multigrid */
    int mg_ok;                         /* it serves this solve */
    struct gmres *mg_gm;               /* flexible GMRES on every unknown */
    double *mg_b, *mg_x;               /* gathered right-hand side and solution */
};

int viscous_line_direction(const struct viscous_solver *s) { return s->line_dir; }

/* The sparse factorisation of the operator: the full tangent's (LU), which
 * reaches two nodes (|D| on an edge averages its neighbours' strains), or
 * the symmetric operator's (Cholesky), which reaches one. */
static int create_direct(struct viscous_solver *s, int full, char *err, size_t errlen)
{
    int periodic[3];
    bc_periodic_flags(s->bc, periodic);
    return sparse_direct_create(&s->direct, s->g, periodic, s->act, full ? 2 : 1, !full, err,
                                errlen);
}

void viscous_allow_lu_fallback(struct viscous_solver *s, int on) { s->lu_fallback = on; }

void viscous_set_reuse(struct viscous_solver *s, int steps)
{
    s->direct_reuse = steps > 0 ? steps : 0;
    s->amg_cfg.reuse = s->direct_reuse;
}

/* CPU seconds of the process (all threads): the timings of viscous_precond_info,
 * which a shared machine does not inflate the way it does wall time. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
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
static int line_blocks_alloc(struct viscous_solver *s)
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

/* BiCGStab's vectors beyond CG's; -1 when out of memory. */
static int bicgstab_alloc(struct viscous_solver *s)
{
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&s->r0[c], &s->v[c], &s->t[c], &s->sh[c]};
        for (size_t m = 0; m < sizeof fs / sizeof fs[0]; m++)
            if (!*fs[m] && !(*fs[m] = field_alloc(s->g)))
                return -1;
    }
    return 0;
}

/* The unknowns of every component's box, in one vector. */
static long box_unknowns(const struct box act[3])
{
    long n = 0;
    for (int c = 0; c < 3; c++)
        if (act[c].hi[0] > act[c].lo[0] && act[c].hi[1] > act[c].lo[1] &&
            act[c].hi[2] > act[c].lo[2])
            n += (long)(act[c].hi[0] - act[c].lo[0]) * (act[c].hi[1] - act[c].lo[1]) *
                 (act[c].hi[2] - act[c].lo[2]);
    return n;
}

/* Between the field triple f and the vector v of every unknown. */
static void box_move(const struct grid *g, const struct box act[3], double *f[3], double *v,
                     int to_vector)
{
    long n = 0;
    for (int c = 0; c < 3; c++) {
        const struct box *b = &act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++) {
                double *row = f[c] + grid_idx(g, i, j, 0);
                for (int k = b->lo[2]; k < b->hi[2]; k++, n++) {
                    if (to_vector)
                        v[n] = row[k];
                    else
                        row[k] = v[n];
                }
            }
    }
}

#define MG_RESTART 30 /* GMRES(30) around the velocity multigrid */

static int mg_create(struct viscous_solver *s, char *err, size_t errlen)
{
    if (velocity_mg_create(&s->mg, s->g, s->bc, s->act, NULL, err, errlen) != 0)
        return -1;
    long n = box_unknowns(s->act);
    s->mg_b = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    s->mg_x = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!s->mg_b || !s->mg_x || gmres_create_flexible(&s->mg_gm, n, MG_RESTART) != 0) {
        snprintf(err, errlen, "viscous solver: out of memory for the multigrid's GMRES");
        return -1;
    }
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
        ok &= line_blocks_alloc(s) == 0;
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
                   create_direct(s, kind == VISCOUS_LU, err, errlen) != 0) {
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

static void free_gmres(struct viscous_solver *s)
{
    gmres_destroy(s->gm);
    s->gm = NULL;
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

void viscous_apply(struct viscous_solver *s, const struct viscous_problem *pb, double *v[3],
                   double *out[3])
{
    const struct viscous_work w = {.divbuf = s->divbuf, .pn = s->pn, .Bc = s->Bc,
                                   .pe = {s->pe[0], s->pe[1], s->pe[2]},
                                   .Be = {s->Be[0], s->Be[1], s->Be[2]},
                                   .tmp = {s->tmp[0], s->tmp[1], s->tmp[2]}};
    viscous_operator_eval(s->g, s->bc, s->act, &w, pb, v, out);
}

void viscous_operator_apply(void *ctx, double *v[3], double *out[3])
{
    struct viscous_operator *a = ctx;
    viscous_apply(a->s, a->pb, v, out);
}

static void zero_fields(const struct grid *g, double *f[3])
{
    for (int c = 0; c < 3; c++)
        memset(f[c], 0, g->size * sizeof(double));
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
     * later, larger blocks of the probing and the AMG may not fit (the
     * heap's AMG solve at 140 x 200 peaked at 203-204 MB in five runs of
     * six, where without the learning it took 185-187 MB in nine of ten;
     * mapped, 190-192 in three) */
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
 * friction law can make d tau / d gamma negative in places: the circular
 * duct at 10 x 20 did at step 95).  The factorisation is numeric only when
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
    double t0 = cpu_now();
    s->direct_ok = s->direct_valid =
        sparse_direct_factor(s->direct, viscous_operator_apply, &a, s->p, s->q,
                             probe_mask(s), &s->probed_components) == 0;
    kept_built(&s->direct_kept);
    s->info.setup_seconds = cpu_now() - t0; /* probing included */
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
 * that needs them (gmg_others). */
static int gmg_setup(struct viscous_solver *s, const struct viscous_problem *pb)
{
    double t0 = cpu_now();
    struct viscous_gmg_operator op = {.mass = pb->mass, .augmentation = pb->augmentation};
    for (int a = 0; a < 3; a++) {
        op.A_cell[a] = pb->b_cell && pb->sym_cell[a] ? pb->sym_cell[a] : pb->A_cell[a];
        op.A_edge[a] = pb->b_cell && pb->sym_edge[a] ? pb->sym_edge[a] : pb->A_edge[a];
        op.mass_face[a] = pb->mass_face[a];
        op.b_edge[a] = pb->b_cell ? pb->b_edge[a] : NULL;
    }
    op.base = pb->b_cell ? pb->base : NULL;
    char why[160];
    s->gmg_ok = !pb->embedded && viscous_gmg_setup(s->gmg, &op, why, sizeof why) == 0;
    s->info.setup_seconds = cpu_now() - t0;
    s->info.probe_seconds = 0.0;
    s->info.reused = 0;
    const int first = __builtin_ctz((unsigned)viscous_gmg_components(s->gmg));
    s->info.levels = viscous_gmg_levels(s->gmg, first);
    if (!s->gmg_ok) {
        s->info.kind = VISCOUS_LINE;
        char cause[200];
        snprintf(cause, sizeof cause, "%s",
                 pb->embedded ? "the geometric multigrid of the implicit step: a body's cut cells "
                                "are not in its operator"
                              : why);
        return fall_back(s, pb, cause);
    }
    s->info.kind = VISCOUS_GMG;
    s->gmg_lines = 0; /* built by the first solve that needs them */
    return 0;
}

/* The unknowns' boxes with those of the components outside mask (bits)
 * emptied: the kernels and reductions on them skip those components. */
static void masked_boxes(const struct viscous_solver *s, int mask, struct box out[3])
{
    memcpy(out, s->act, 3 * sizeof *out);
    for (int c = 0; c < 3; c++)
        if (!(mask >> c & 1))
            out[c].hi[0] = out[c].lo[0];
}

/* The components the multigrid does not cover: left out of this solve
 * while their part of the right-hand side is negligible (below a tenth of
 * the tolerance, as the factorisations' blocks are: a flow along a
 * periodic direction carries round-off across it) or round-off (below
 * GMG_ROUNDOFF of the largest right-hand side solved), else in GMRES with
 * their line blocks, built once per operator.  Measured on the heap at
 * 35 x 50: with the two components across the flow in every solve on
 * their line blocks, BiCGStab took 220-440 iterations a step; left out,
 * 23 (docs/design.md).  The round-off test came from the last Newton
 * steps: there the two components' round-off (2.3e-13 at 35 x 50, 8.1e-13
 * at 70 x 100: 1.4e-14 and 2.5e-14 of the largest right-hand sides, 16.5
 * and 33) exceeded a tenth of the tolerance times the right-hand side
 * (9.6e-14), and with their line blocks GMRES stalled at its cap (0.97). */
static void gmg_others(struct viscous_solver *s, const struct viscous_problem *pb,
                       double negligible, double bnorm)
{
    const int covered = viscous_gmg_components(s->gmg), others = 7 & ~covered;
    s->gmg_mask = 7;
    s->gmg_scale = fmax(s->gmg_scale, bnorm);
    if (!others)
        return;
    struct box part[3];
    masked_boxes(s, others, part);
    if (negligible >= 0.0 && sqrt(kernel_dot(s->g, part, s->r, s->r)) <=
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

int viscous_precondition(struct viscous_solver *s, const struct viscous_problem *pb)
{
    s->direct_ok = 0;
    s->fourier_ok = 0;
    s->gmg_ok = 0;
    s->mg_ok = 0;
    if (s->mg) {
        double t0 = cpu_now();
        char why[200];
        s->mg_ok = velocity_mg_setup(s->mg, pb, why, sizeof why) == 0;
        s->info.setup_seconds = cpu_now() - t0;
        s->info.probe_seconds = 0.0;
        s->info.reused = 0;
        s->info.levels = velocity_mg_levels(s->mg);
        s->info.kind = s->mg_ok ? VISCOUS_MG : VISCOUS_LINE;
        return s->mg_ok ? 0 : fall_back(s, pb, why);
    }
    if (s->gmg)
        return gmg_setup(s, pb);
    if (s->fourier) {
        /* kept like a factorisation (solver.preconditioner_reuse): its probes
         * are most of a step once CG needs a few iterations */
        s->fourier_ok = 1;
        if (s->fourier_valid && kept_serves(&s->direct_kept, s->direct_reuse)) {
            s->direct_kept.age++;
            s->info.setup_seconds = 0.0;
            s->info.reused = 1;
            return 0;
        }
        struct viscous_operator a = {s, pb};
        double t0 = cpu_now();
        s->failed_blocks = fourier_lines_setup(s->fourier, viscous_operator_apply, &a, s->p, s->q);
        s->info.setup_seconds = cpu_now() - t0; /* probing included */
        s->info.reused = 0;
        s->fourier_valid = 1;
        kept_built(&s->direct_kept);
        return 0;
    }
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
    if (s->amg && !s->amg_retired) {
        /* the multigrid's matrix: the operator, or its Picard part, with or
         * without the augmentation */
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
        double t0 = cpu_now();
        int probed = probe_matrix_assemble_components(s->probe, viscous_operator_apply, &a, s->p,
                                                      s->q, 0, probe_mask(s), &s->amat,
                                                      &s->probed_components) == 0;
        int ok = probed;
        double t1 = cpu_now();
        s->info.unknowns = s->amat.n;
        s->info.entries = csr_nnz(&s->amat);
        /* hypre copies the matrix: ours is released before its setup */
        ok = ok && amg_hypre_setup(s->amg, &s->amat) == 0; /* built in solve() */
        s->info.probe_seconds = t1 - t0;
        s->info.setup_seconds = cpu_now() - t1;
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
    if (line_blocks_alloc(s) != 0) {
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
static void precondition_apply(struct viscous_solver *s, double *const r[3], double *z[3])
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

/* Preconditioned BiCGStab (van der Vorst) for the non-symmetric full tangent. */
static int bicgstab(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                    double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    if (bicgstab_alloc(s) != 0)
        return -1;
    double **r = s->r, **r0 = s->r0, **p = s->p, **v = s->v, **t = s->t, **ph = s->z,
           **sh = s->sh;
    for (int c = 0; c < 3; c++) {
        memcpy(r0[c], r[c], g->size * sizeof(double));
        memset(p[c], 0, g->size * sizeof(double));
        memset(v[c], 0, g->size * sizeof(double));
    }
    double rho = 1.0, alpha = 1.0, omega = 1.0;
    for (int it = 1; it <= maxit; it++) {
        double rho_new = kernel_dot(g, act, r0, r);
        if (rho_new == 0.0 || !isfinite(rho_new))
            return -1;
        double beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        kernel_axpy(g, act, -omega, v, p);      /* p = r + beta (p - omega v) */
        kernel_lincomb(g, act, 1.0, r, beta, p);
        precondition_apply(s, p, ph);
        viscous_apply(s, pb, ph, v);
        double r0v = kernel_dot(g, act, r0, v);
        if (r0v == 0.0 || !isfinite(r0v))
            return -1;
        alpha = rho / r0v;
        kernel_axpy(g, act, alpha, ph, x);
        kernel_axpy(g, act, -alpha, v, r);      /* r is now s */
        double snorm = sqrt(kernel_dot(g, act, r, r));
        st->iterations = it;
        st->relative_residual = snorm / bnorm;
        if (snorm <= rtol * bnorm)
            return 0;
        precondition_apply(s, r, sh);
        viscous_apply(s, pb, sh, t);
        double tt = kernel_dot(g, act, t, t);
        if (!(tt > 0.0) || !isfinite(tt))
            return -1;
        omega = kernel_dot(g, act, t, r) / tt;
        kernel_axpy(g, act, omega, sh, x);
        kernel_axpy(g, act, -omega, t, r);
        double rnorm = sqrt(kernel_dot(g, act, r, r));
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        if (omega == 0.0)
            return -1;
    }
    return 1;
}

/* GMRES's operator and preconditioner on the probed unknowns: the operator
 * acts on fields, the V-cycle on the gathered vectors. */
struct gmres_ctx {
    struct viscous_solver *s;
    const struct viscous_problem *pb;
};

static void gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    probe_matrix_scatter(s->probe, x, s->z);
    viscous_apply(s, c->pb, s->z, s->q);
    probe_matrix_gather(s->probe, s->q, y);
}

static void gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    amg_hypre_apply(c->s->amg, x, y);
}

/* Restarted GMRES (gmres.h), right-preconditioned by the AMG, from x = 0. */
static int gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                 double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const long n = probe_matrix_unknowns(s->probe);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    probe_matrix_gather(s->probe, rhs, s->amg_b);
    memset(s->amg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->gm, gmres_operator, gmres_precondition, &ctx, s->amg_b, s->amg_x, rtol,
                         maxit, &gs);
    probe_matrix_scatter(s->probe, s->amg_x, x);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

static int solve(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                 double *x[3], double rtol, int maxit, struct viscous_stats *st);

/* The probed LU of the full tangent takes over from a multigrid (named in
 * the cause) whose GMRES ended with rc: the factorisation is created (its
 * probing learns its own pattern) and made by the next
 * viscous_precondition, the fallback counted with its cause.  Returns 0, or
 * -1 (no memory: the multigrid stays, the caller releases nothing). */
static int lu_takes_over(struct viscous_solver *s, const char *multigrid, int rc, int maxit)
{
    char err[160];
    if (!s->direct && create_direct(s, 1, err, sizeof err) != 0)
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
 * GMRES failed (its cap, or a breakdown) on a fresh hierarchy.  Measured: the circular duct
 * at 80 x 160 from rest (38,400 unknowns with a body, where auto took the
 * AMG) reached the cap of 500 and stalled near a residual of 2.5e-2;
 * with the fallback it is steady in 122 steps, the LU alone in 78
 * (docs/design.md, "The circular duct").  The hierarchy is released; the
 * factorisation is made by the next viscous_precondition.  Returns 0, or
 * -1 (no memory: the AMG stays). */
static int retire_amg(struct viscous_solver *s, int rc, int maxit)
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
 * tangent, as the AMG does (retire_amg): its GMRES failed.  Measured
 * before the tangent's cross term entered the cycle: the square duct at
 * 80 x 160 from rest, where the two components across the flow carry a
 * residual of their own during the march (74-247 of a right-hand side of
 * 205-312), stalled with their line blocks at the cap of 500 from step 71
 * and stayed unsteady (0.98 after 285 steps); with the term it is steady
 * in 77 steps without the fallback, which test_amg_gives_way_to_lu keeps
 * exercised.  Returns 0, or -1 (no memory: the multigrid stays). */
static int retire_gmg(struct viscous_solver *s, int rc, int maxit)
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

int viscous_solve(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                  double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    double t0 = cpu_now();
    s->prepare_seconds = 0.0;
    int rc = solve(s, pb, rhs, x, rtol, maxit, st);
    /* kept factors or a kept hierarchy that no longer serve: rebuilt for
     * this operator */
    struct kept *k = s->amg_ok ? &s->amg_kept
                     : s->direct_ok || s->fourier_ok ? &s->direct_kept : NULL;
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
    if (rc != 0 && s->amg_ok && s->lu_fallback && retire_amg(s, rc, maxit) == 0) {
        viscous_precondition(s, pb);
        rc = solve(s, pb, rhs, x, rtol, maxit, st);
    }
    if (rc != 0 && s->gmg_ok && s->lu_fallback && retire_gmg(s, rc, maxit) == 0) {
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
    else if (s->direct_ok || s->fourier_ok)
        kept_solved(&s->direct_kept, st->iterations);
    /* the factorisations done for this right-hand side count as set-up */
    s->info.setup_seconds += s->prepare_seconds;
    s->info.solve_seconds = cpu_now() - t0 - s->prepare_seconds;
    return rc;
}

/* GMRES on the components of the mask s->gmg_mask (the multigrid's, and the
 * others unless they are left out): their unknowns gathered from the boxes
 * act[c] into one vector.  GMRES rather than BiCGStab: in the heap's last
 * Newton steps (dt 1e6, a right-hand side of 3e-6 solved to 1e-8)
 * BiCGStab stalled at its cap of 500 iterations from 35 x 50 to 280 x 400
 * (relative residuals 4.8e-7 to 0.97), where the Cholesky's exact inverse
 * of the same diagonal tangent takes 34; GMRES converges there, also with
 * the two components across the flow in the solve on their line blocks
 * (their round-off 2.4 times the tolerance: docs/design.md, "Geometric
 * multigrid for the implicit step"). */
static long gmg_unknowns(const struct viscous_solver *s, int mask)
{
    long n = 0;
    for (int c = 0; c < 3; c++)
        if (mask >> c & 1)
            n += (long)(s->act[c].hi[0] - s->act[c].lo[0]) *
                 (s->act[c].hi[1] - s->act[c].lo[1]) * (s->act[c].hi[2] - s->act[c].lo[2]);
    return n;
}

static void gmg_move(const struct viscous_solver *s, double *f[3], double *v, int to_vector)
{
    long n = 0;
    for (int c = 0; c < 3; c++) {
        if (!(s->gmg_mask >> c & 1))
            continue;
        const struct box *b = &s->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++) {
                double *row = f[c] + grid_idx(s->g, i, j, 0);
                for (int k = b->lo[2]; k < b->hi[2]; k++, n++) {
                    if (to_vector)
                        v[n] = row[k];
                    else
                        row[k] = v[n];
                }
            }
    }
}

/* The flow component of a cross-section solved alone (the others left
 * out): its column of the operator, kernel_flow_block, in three passes
 * over the cross-section.  Measured on the heap at 140 x 200 (2 threads):
 * 0.4 ms an application against 1.5 ms by viscous_apply, which computes
 * every component's strain products and stresses on the three planes of
 * the field layout. */
static int flow_block_serves(const struct viscous_solver *s, const struct viscous_problem *pb)
{
    const int c = __builtin_ctz((unsigned)s->gmg_mask);
    return s->gmg_mask == 1 << c && s->bc->face[c][0] == BC_PERIODIC && s->g->n[c] == 1 &&
           !pb->embedded && !pb->open_given && !grid_stretched(s->g);
}

/* The operator's rows of the mask's components only: the flow block, or
 * the kernels writing the boxes act[c], which are emptied for the others
 * while it runs (their rows are not gathered; on the heap two thirds of
 * the stress divergence). */
static void gmg_gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    gmg_move(s, s->z, (double *)x, 0); /* the components left out stay 0 */
    if (flow_block_serves(s, c->pb)) {
        const struct viscous_problem *pb = c->pb;
        const int k = __builtin_ctz((unsigned)s->gmg_mask);
        bc_fill_increment_component(s->g, s->bc, s->z, k);
        double *pe[2] = {s->pe[0], s->pe[1]}, *S[2] = {s->tmp[0], s->tmp[1]};
        const double *gb[2] = {s->flow_gb[0], s->flow_gb[1]};
        kernel_flow_block(s->g, k, gb, s->z[k], pb->A_edge,
                          pb->b_cell ? pb->b_edge : NULL, pb->mass_face[k], pb->mass, pe, S,
                          s->q[k]);
        gmg_move(s, s->q, y, 1);
        return;
    }
    struct box kept[3], part[3];
    masked_boxes(s, s->gmg_mask, part);
    memcpy(kept, s->act, sizeof kept);
    memcpy(s->act, part, sizeof part);
    viscous_apply(s, c->pb, s->z, s->q);
    memcpy(s->act, kept, sizeof kept);
    gmg_move(s, s->q, y, 1);
}

static void gmg_gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    gmg_move(c->s, c->s->p, (double *)x, 0);
    precondition_apply(c->s, c->s->p, c->s->q); /* the multigrid, the others' line blocks */
    gmg_move(c->s, c->s->q, y, 1);
}

static int gmg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                     double rtol, int maxit, struct viscous_stats *st)
{
    const int all = s->gmg_mask != viscous_gmg_components(s->gmg);
    const long n = gmg_unknowns(s, s->gmg_mask);
    if (!s->gmg_gm[all]) {
        /* the vectors for every component, the basis for the mask's */
        const long most = gmg_unknowns(s, 7);
        if ((!s->gmg_b && !(s->gmg_b = malloc((size_t)most * sizeof(double)))) ||
            (!s->gmg_x && !(s->gmg_x = malloc((size_t)most * sizeof(double)))) ||
            gmres_create_flexible(&s->gmg_gm[all], n, GMG_RESTART) != 0)
            return -1;
    }
    if (flow_block_serves(s, pb) && pb->b_cell) {
        /* the base strains of the flow block's Newton term, once a solve */
        for (int t = 0; t < 2; t++)
            if (!s->flow_gb[t] && !(s->flow_gb[t] = field_alloc(s->g)))
                return -1;
        kernel_flow_gammas(s->g, __builtin_ctz((unsigned)s->gmg_mask), pb->base, s->flow_gb);
    }
    zero_fields(s->g, s->z);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    gmg_move(s, s->r, s->gmg_b, 1);
    memset(s->gmg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->gmg_gm[all], gmg_gmres_operator, gmg_gmres_precondition, &ctx,
                         s->gmg_b, s->gmg_x, rtol, maxit, &gs);
    gmg_move(s, x, s->gmg_x, 0);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

/* GMRES's operator and preconditioner on every unknown: the operator
 * (the full tangent where pb has it), one multigrid cycle. */
static void mg_gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    box_move(s->g, s->act, s->z, (double *)x, 0);
    viscous_apply(s, c->pb, s->z, s->q);
    box_move(s->g, s->act, s->q, y, 1);
}

static void mg_gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    box_move(s->g, s->act, s->p, (double *)x, 0);
    velocity_mg_cycle(s->mg, s->p, s->q);
    box_move(s->g, s->act, s->q, y, 1);
}

static int mg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                    double rtol, int maxit, struct viscous_stats *st)
{
    const long n = box_unknowns(s->act);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    box_move(s->g, s->act, s->r, s->mg_b, 1);
    memset(s->mg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->mg_gm, mg_gmres_operator, mg_gmres_precondition, &ctx, s->mg_b,
                         s->mg_x, rtol, maxit, &gs);
    box_move(s->g, s->act, x, s->mg_x, 0);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

/* Conjugate gradients preconditioned by one multigrid cycle (a symmetric
 * cycle of a symmetric operator) on the unknowns of the boxes act, from
 * x = 0 with the residual in s->r. */
static int mg_pcg_boxes(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                        double *x[3], double rtol, int maxit, struct viscous_stats *st);

/* A component along a periodic direction of one cell is coupled to no
 * other; with no right-hand side (a flow in a plane: the component across)
 * its solution is 0 and it is left out of the solve. */
static int mg_pcg(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                  double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    struct box kept[3];
    memcpy(kept, s->act, sizeof kept);
    for (int c = 0; c < 3; c++) {
        if (s->bc->face[c][0] != BC_PERIODIC || s->g->n[c] != 1)
            continue;
        struct box one[3];
        masked_boxes(s, 1 << c, one);
        if (kernel_max_abs(s->g, one, s->r) == 0.0)
            s->act[c].hi[0] = s->act[c].lo[0];
    }
    int rc = mg_pcg_boxes(s, pb, bnorm, x, rtol, maxit, st);
    memcpy(s->act, kept, sizeof kept);
    return rc;
}

static int mg_pcg_boxes(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                        double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    velocity_mg_cycle(s->mg, s->r, s->z);
    zero_fields(g, s->p);
    kernel_lincomb(g, act, 1.0, s->z, 0.0, s->p);
    double rz = kernel_dot(g, act, s->r, s->z);
    for (int it = 1; it <= maxit; it++) {
        viscous_apply(s, pb, s->p, s->q);
        double pq = kernel_dot(g, act, s->p, s->q);
        if (!(pq > 0.0) || !isfinite(pq))
            return -1;
        double alpha = rz / pq;
        kernel_axpy(g, act, alpha, s->p, x);
        kernel_axpy(g, act, -alpha, s->q, s->r);
        double rnorm = sqrt(kernel_dot(g, act, s->r, s->r));
        st->iterations = it;
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        velocity_mg_cycle(s->mg, s->r, s->z);
        double rz_new = kernel_dot(g, act, s->r, s->z);
        kernel_lincomb(g, act, 1.0, s->z, rz_new / rz, s->p);
        rz = rz_new;
    }
    return 1;
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
    double bnorm = sqrt(kernel_dot(g, act, s->r, s->r));
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
     * (the heap, the ducts) carries only the state's round-off across it
     * (1e-13 to 1e-10 on the heap, its flow component's 1e-2 to 16), and
     * its factorisation or hierarchy of the two components across was most
     * of the step: leaving them out alone took the heap at 140 x 200 with
     * the LU from 23.7 s to 10.9 s, the same 54 steps and state
     * (docs/design.md, "Blocks left out of a solve").  A solve that
     * fails so is solved again with every block (viscous_solve). */
    double negligible =
        s->keep_blocks || s->keep_once ? -1.0 : NEGLIGIBLE_SHARE * rtol * bnorm;
    s->dropped = 0;
    if ((s->direct_ok || s->amg_ok) && s->probed_components != 7) {
        /* components whose columns the probing left out: while their part
         * of the right-hand side stays negligible their blocks are left out
         * of this solve too; otherwise the whole matrix, probed again */
        const struct probe_matrix *pm =
            s->amg_ok ? s->probe : sparse_direct_probe_matrix(s->direct);
        int missing = 7 & ~s->probed_components;
        if (negligible < 0.0 || probe_matrix_components_norm(pm, s->r, missing) > negligible) {
            struct kept *k = s->amg_ok ? &s->amg_kept : &s->direct_kept;
            s->probe_components = 7;
            k->force = 1;
            viscous_precondition(s, pb);
            k->force = 0;
        }
    }
    if (s->direct_ok) {
        /* the blocks of components this right-hand side reaches */
        double t0 = cpu_now();
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
        s->prepare_seconds += cpu_now() - t0;
    }
    if (s->amg_ok) {
        /* the hierarchies of the blocks this right-hand side reaches */
        double t0 = cpu_now();
        probe_matrix_gather(s->probe, s->r, s->amg_b);
        int failed = amg_hypre_prepare(s->amg, s->amg_b, negligible) != 0;
        s->prepare_seconds += cpu_now() - t0;
        s->info.levels = amg_hypre_levels(s->amg);
        s->info.complexity = amg_hypre_complexity(s->amg);
        s->dropped = amg_hypre_dropped(s->amg);
        if (failed) {
            s->amg_ok = 0;
            s->dropped = 0;
            s->info.kind = VISCOUS_LINE;
            char cause[160];
            snprintf(cause, sizeof cause, "the algebraic multigrid of %ld unknowns: hypre's setup failed",
                     probe_matrix_unknowns(s->probe));
            fall_back(s, pb, cause);
        }
    }
    if (s->mg_ok)
        return pb->b_cell ? mg_gmres(s, pb, x, rtol, maxit, st)
                          : mg_pcg(s, pb, bnorm, x, rtol, maxit, st);
    if (s->gmg_ok)
        gmg_others(s, pb, negligible, bnorm);
    st->failed_blocks = s->failed_blocks;
    st->direct = s->direct_ok;
    if (s->gmg_ok)
        return gmg_gmres(s, pb, x, rtol, maxit, st);
    if (s->amg_ok)
        return s->amg_cfg.bicgstab ? bicgstab(s, pb, bnorm, x, rtol, maxit, st)
                                   : gmres(s, pb, rhs, x, rtol, maxit, st);
    if (pb->b_cell && s->pn) /* the full tangent (viscous_apply uses it) */
        return bicgstab(s, pb, bnorm, x, rtol, maxit, st);
    precondition_apply(s, s->r, s->z);
    zero_fields(g, s->p);
    kernel_lincomb(g, act, 1.0, s->z, 0.0, s->p);
    double rz = kernel_dot(g, act, s->r, s->z);
    for (int it = 1; it <= maxit; it++) {
        viscous_apply(s, pb, s->p, s->q);
        double pq = kernel_dot(g, act, s->p, s->q);
        if (!(pq > 0.0) || !isfinite(pq))
            return -1;
        double alpha = rz / pq;
        kernel_axpy(g, act, alpha, s->p, x);
        kernel_axpy(g, act, -alpha, s->q, s->r);
        double rnorm = sqrt(kernel_dot(g, act, s->r, s->r));
        st->iterations = it;
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        precondition_apply(s, s->r, s->z);
        double rz_new = kernel_dot(g, act, s->r, s->z);
        kernel_lincomb(g, act, 1.0, s->z, rz_new / rz, s->p);
        rz = rz_new;
    }
    return 1;
}

double viscous_memory_estimate(const struct grid *g, enum viscous_precond kind)
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
    if (kind == VISCOUS_LU || kind == VISCOUS_CHOLESKY)
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
        doubles += (2.0 * 12.0 * 4.0 / 3.0 + 4.0) * points +
                   (2.0 * GMG_RESTART + 3.0) * 2.0 * cells;
    /* the velocity multigrid's levels and its GMRES(30)'s flexible bases */
    if (kind == VISCOUS_MG)
        doubles += (2.0 * MG_RESTART + 3.0) * 3.0 * cells;
    return doubles * sizeof(double) +
           (kind == VISCOUS_FOURIER ? fourier_lines_memory_estimate(g) : 0.0) +
           (kind == VISCOUS_MG ? velocity_mg_memory_estimate(g, NULL, NULL) : 0.0);
}
