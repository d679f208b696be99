/* The implicit viscous solver's internals, shared by viscous.c (the solver
 * object, its settings, the solve and its retries), viscous_precond.c
 * (building, choosing and applying the preconditioners, their fallbacks)
 * and viscous_krylov.c (the Krylov loops) only; the interface is
 * viscous.h, the choices and their measurements are in
 * docs/numerics/linear-solvers.md. */
#ifndef MUFLOW_VISCOUS_INTERNAL_H
#define MUFLOW_VISCOUS_INTERNAL_H

#include <string.h>
#include "solvers/amg_hypre.h"
#include "solvers/fourier_lines.h"
#include "solvers/gmres.h"
#include "solvers/probe_matrix.h"
#include "solvers/sparse_direct.h"
#include "solvers/velocity_mg.h"
#include "solvers/viscous.h"
#include "solvers/viscous_gmg.h"

#define BAND 2               /* nodes reached along a line by the stencil */
#define PROBES (2 * BAND + 1)
#define GMG_RESTART 20       /* flexible GMRES(20) on the multigrid's components */

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

static inline int kept_serves(const struct kept *k, int limit)
{
    return !k->force && limit > 0 && k->age < limit && k->last_iters <= 2 * k->fresh_iters + 2;
}

static inline void kept_built(struct kept *k)
{
    k->age = 0;
    k->fresh_iters = -1;
}

static inline void kept_solved(struct kept *k, int iterations)
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
    int mg_valid;                      /* its last set-up succeeded (kept: direct_kept) */
    struct gmres *mg_gm;               /* flexible GMRES on every unknown */
    double *mg_b, *mg_x;               /* gathered right-hand side and solution */
};

/* CPU seconds of the process (all threads): the timings of viscous_precond_info,
 * which a shared machine does not inflate the way it does wall time. */
double visc_cpu_now(void);

static inline void zero_fields(const struct grid *g, double *f[3])
{
    for (int c = 0; c < 3; c++)
        memset(f[c], 0, g->size * sizeof(double));
}

/* The unknowns' boxes with those of the components outside mask (bits)
 * emptied: the kernels and reductions on them skip those components. */
static inline void masked_boxes(const struct viscous_solver *s, int mask, struct box out[3])
{
    memcpy(out, s->act, 3 * sizeof *out);
    for (int c = 0; c < 3; c++)
        if (!(mask >> c & 1))
            out[c].hi[0] = out[c].lo[0];
}

static inline void free_gmres(struct viscous_solver *s)
{
    gmres_destroy(s->gm);
    s->gm = NULL;
}

/* viscous_precond.c */
/* The probed sparse factorisation: the full tangent's LU (full), or the
 * symmetric operator's Cholesky. */
int visc_create_direct(struct viscous_solver *s, int full, char *err, size_t errlen);
/* The line blocks' storage; -1 when out of memory. */
int visc_line_blocks_alloc(struct viscous_solver *s);
/* The preconditioner for this solve's right-hand side s->r: the matrix
 * probed again if s->r reaches components its probing left out, the
 * factorisations or hierarchies of the blocks s->r reaches (those below
 * negligible left out, s->dropped; negligible < 0: none); a failure leaves
 * the line blocks. */
void visc_prepare(struct viscous_solver *s, const struct viscous_problem *pb, double negligible);
/* The components the geometric multigrid does not cover: left out of this
 * solve (s->gmg_mask) or given their line blocks. */
void visc_gmg_others(struct viscous_solver *s, const struct viscous_problem *pb,
                     double negligible, double bnorm);
/* z = M^-1 r. */
void visc_precondition_apply(struct viscous_solver *s, double *const r[3], double *z[3]);
/* The probed LU takes over for good from the AMG or the geometric
 * multigrid whose GMRES ended with rc; 0, or -1 when out of memory. */
int visc_retire_amg(struct viscous_solver *s, int rc, int maxit);
int visc_retire_gmg(struct viscous_solver *s, int rc, int maxit);

/* viscous_krylov.c: from x = 0 with the residual in s->r (bnorm its norm);
 * 0 when converged, 1 at maxit, -1 on a breakdown */
int visc_pcg(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
             double *x[3], double rtol, int maxit, struct viscous_stats *st);
int visc_bicgstab(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                  double *x[3], double rtol, int maxit, struct viscous_stats *st);
int visc_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
               double *x[3], double rtol, int maxit, struct viscous_stats *st);
int visc_gmg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                   double rtol, int maxit, struct viscous_stats *st);
int visc_mg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                  double rtol, int maxit, struct viscous_stats *st);
int visc_mg_pcg(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                double *x[3], double rtol, int maxit, struct viscous_stats *st);
long visc_box_unknowns(const struct box act[3]);

/* A dot product and a maximum over the unknowns of every rank (the grid's
 * decomposition, bc->dc; one process: the kernels' own). */
static inline double visc_dot(const struct viscous_solver *s, const struct box act[3],
                              double *const a[3], double *const b[3])
{
    return decomp_sum(s->bc->dc, kernel_dot(s->g, act, a, b));
}
static inline double visc_max_abs(const struct viscous_solver *s, const struct box act[3],
                                  double *const a[3])
{
    return decomp_max(s->bc->dc, kernel_max_abs(s->g, act, a));
}

#endif
