/* The multigrid's internals, shared by src/solvers/multigrid*.c only (the
 * interface is multigrid.h; the choices and their measurements are in
 * docs/numerics/multigrid.md).
 *
 * Conventions:
 *  - L phi = sum_faces w_f (phi_nb - phi), w_f = a_f / h_d^2, is negative
 *    semi-definite; the coarsest factorisation and CG work on -L or are
 *    invariant under the sign.
 *  - Each level keeps its own copy of the face coefficients with the boundary
 *    conditions folded in, so that one stencil serves every cell and the
 *    diagonal D = sum_f w_f is computed on the fly (no diagonal array):
 *      Neumann boundary face        a = 0           (no flux)
 *      Dirichlet boundary face      a = 2 a_user    (ghost 0: flux 2a(0-phi)/h^2,
 *                                                    the same as ghost = -phi)
 *      periodic direction of 1 cell a = 0           (the neighbour is the cell itself)
 *      periodic face n              a = face 0
 *    The operator therefore reads ghosts that are 0 on non-periodic
 *    boundaries (HALO_OPERATOR), while the grid transfers read ghosts holding
 *    the value the condition implies (HALO_MIRROR: Neumann mirror, Dirichlet
 *    negated mirror), which is what makes linear prolongation right at walls.
 *  - A cell with D = 0 is dead (identity row): its unknown stays 0, its
 *    residual is 0, transfers skip it.
 *  - Every level is a box of local cells with one ghost layer; ghosts are
 *    filled by mg_halo_fill / mg_halo_faces only, which exchange them across
 *    the rank borders of a decomposed level (lv->dc; grid/decomp.h).  The
 *    red-black colour is that of the global index (lv->parity: the parity
 *    of the block's origin).  A decomposed hierarchy keeps its levels on the
 *    ranks while they halve in place; its last level is gathered on every
 *    rank and cycled by a serial multigrid over the rest (mg->sub), the
 *    coarsest solve included: docs/numerics/decomposition.md.  The other
 *    global operations are the dot products (summed over the ranks).
 *  - The level kernels are orphaned worksharing loops (`omp for`): called by
 *    every thread of a team, or outside any parallel region, where they are
 *    plain loops. */
#ifndef MUFLOW_MULTIGRID_INTERNAL_H
#define MUFLOW_MULTIGRID_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include "grid/decomp.h"
#include "solvers/multigrid.h"
#include "solvers/suitesparse.h"

#define MAX_LEVELS 32
#define MAX_THREADS 256
#define PAD 8 /* doubles between per-thread partial sums (one cache line) */

/* The statements in a parallel region when par, else on the calling thread
 * outside any region: there the orphaned loops' barriers return at once,
 * while a region of one thread pays libgomp's barriers and join, a system
 * call each (docs/numerics/threads-and-platform.md), whatever GOMP_parallel
 * the program binds to. */
#define REGION(par, ...)                                                                        \
    do {                                                                                        \
        if (par) {                                                                              \
            _Pragma("omp parallel") { __VA_ARGS__; }                                            \
        } else {                                                                                \
            __VA_ARGS__;                                                                        \
        }                                                                                       \
    } while (0)

/* REGION for the reductions into per-thread partial sums: a team of exactly
 * nt threads (a local variable of that name), as many as the partials. */
#define REGION_NT(...)                                                                          \
    do {                                                                                        \
        if (nt > 1) {                                                                           \
            _Pragma("omp parallel num_threads(nt)") { __VA_ARGS__; }                            \
        } else {                                                                                \
            __VA_ARGS__;                                                                        \
        }                                                                                       \
    } while (0)

/* HALO_RESULT: the mirror's values in every ghost, the flat direction's
 * too (a solution handed back: its gradient may be taken at once) */
enum halo_kind { HALO_OPERATOR, HALO_MIRROR, HALO_EVEN, HALO_RESULT };

struct level {
    struct grid g;
    int coarse[3];         /* this level halves direction d of the finer one */
    double ih2[3];         /* 1 / h_d^2 */
    double *a[3];          /* face coefficients, conditions folded in (see top) */
    double *m;             /* cell mass term m >= 0 of L - m (NULL: none; mbuf) */
    double *mbuf;          /* its storage, allocated on the first mass set */
    double *lc[3], *li[3]; /* MG_SMOOTH_LINES: Thomas factors c' and 1 / pivot of the
                              lines along each line direction (mg_line_factors) */
    unsigned char *live;   /* D > 0 */
    double *x;             /* unknown (level 0: the caller's array, set per call) */
    const double *b;       /* right-hand side (level 0: the caller's array) */
    double *bbuf;          /* owned storage of b on coarse levels */
    double *r;             /* residual, restricted to the next level */
    /* prolongation from level l+1 into this level: along d, fine cell i takes
     * (1 - w) of its parent pi[d][2i] and w of the coarse neighbour
     * pi[d][2i+1] nearer to it (a ghost, -1 or nc, at the ends), w = pw[d] at
     * the cell (0 along a direction not halved) */
    int *pi[3];
    double *pw[3];
    int par;               /* run the loops of this level with OpenMP */
    int flat;              /* a periodic direction of one cell (0 coefficients: its
                              terms are left out of the row sums), -1: none */
    /* the mixed-derivative term (multigrid_set_mixed) of directions md[0],
     * md[1]: km[t] on the faces of md[t], the coefficient of the mean
     * gradient along the other direction there; NULL: none (kbuf holds it) */
    const double *km[2];
    double *kbuf[2];
    int md[2];
    const struct decomp *dc; /* this level's block (NULL: the whole grid) */
    int parity;            /* (i + j + k) of local cell 0 in the global grid, mod 2 */
};

struct coarse_direct {
    cholmod_common cm;
    int started;
    cholmod_sparse *A;     /* assembled and analysed, its numeric factorisation due */
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E;
    long n;                /* rows (live cells of the coarsest level) */
    ptrdiff_t *slot;       /* field slot of row k (sized for every cell) */
    int *row;              /* row of a field slot, -1 for dead cells and ghosts */
    unsigned char *pinned; /* row k is fixed to 0 (one per floating component) */
    int *queue;            /* breadth-first search of the components */
    int *pattern;          /* the analysed matrix's column starts and rows: a
                              matrix of the same pattern keeps L's analysis */
    size_t pattern_len;
};

struct multigrid {
    struct multigrid_options opt;
    enum poisson_bc bc[3][2];
    int periodic[3];
    int nlev;
    struct level lev[MAX_LEVELS];
    struct coarse_direct cs;
    double *wr, *wz, *wp, *wq;     /* fine-level work arrays of the solvers */
    double *wbest;                 /* multigrid_pcg: the iterate of the least residual */
    long live;                     /* live cells of level 0 */
    int line_dirs[3], nline_dirs;  /* MG_SMOOTH_LINES: the directions of its lines */
    int ready;                     /* coefficients set */
    int pending;                   /* set, the coarsest factorisation (and the line
                                      factors) still to do: multigrid_finish_operator */
    double *mxbuf;                 /* the lines' mixed terms, two lines per thread
                                      (multigrid_set_mixed) */
    int mxlen;                     /* the longest line */
    double partial[MAX_THREADS * PAD];
    /* decomposed (multigrid_create_decomposed): each level's block, the
     * serial multigrid of the gathered last level (its global grid gg, its
     * unknown, right-hand side and the gather's buffer), and the levels of
     * the whole hierarchy, sub's included; serial: dlev unused, sub NULL,
     * total_levels = nlev */
    struct decomp dlev[MAX_LEVELS];
    struct multigrid *sub;
    struct grid gg;
    double *gx, *gb, *gscratch;
    int total_levels;
};

/* 1 when side s of direction d of level lv is the domain's boundary (not
 * periodic, not a rank border). */
static inline int mg_physical_side(const struct multigrid *mg, const struct level *lv, int d,
                                   int s)
{
    return !mg->periodic[d] && !(lv->dc && lv->dc->border[d][s]);
}

/* 1 when direction d of level lv is periodic and one cell across the whole
 * level (its coefficients 0, its ghosts the cell itself): the global count
 * on a decomposed level, whose blocks may hold one cell of a longer
 * periodic direction, coupled to the neighbours across the rank borders. */
static inline int mg_periodic_flat(const struct multigrid *mg, const struct level *lv, int d)
{
    return mg->periodic[d] && (lv->dc ? lv->dc->n_global[d] : lv->g.n[d]) == 1;
}

/* The faces of direction d a level holds: 0 .. n - 1, and n when the high
 * side is the domain's boundary. */
static inline int mg_faces_held(const struct multigrid *mg, const struct level *lv, int d)
{
    return mg_physical_side(mg, lv, d, 1) ? lv->g.n[d] + 1 : lv->g.n[d];
}

/* ---- the stencil, inlined into every kernel that reads it ----------------------- */

static inline int thread_id(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* The six face weights w_f = a_f / h_d^2 of cell p (x low, x high, y low,
 * y high, z low, z high) and their sum D plus the cell's mass term, the
 * diagonal of -(L - m).  Without a mass term (lv->m NULL, loop-invariant:
 * the compiler unswitches the loops) D is the face sum alone, to the bit.
 * flat (a constant after inlining; -1: none) is a periodic direction of one
 * cell: its two weights are 0 (multigrid_levels.c), so they are not loaded
 * and are left out of D; zero terms added first change no sum, so D is that
 * of all six terms to the bit. */
static inline __attribute__((always_inline)) double
cell_weights(const struct level *lv, ptrdiff_t p, const int flat, double w[6])
{
    const ptrdiff_t s[3] = {lv->g.stride[0], lv->g.stride[1], 1};
    for (int d = 0; d < 3; d++) {
        w[2 * d] = d == flat ? 0.0 : lv->ih2[d] * lv->a[d][p];
        w[2 * d + 1] = d == flat ? 0.0 : lv->ih2[d] * lv->a[d][p + s[d]];
    }
    const double D = flat == 0   ? w[2] + w[3] + w[4] + w[5]
                     : flat == 1 ? w[0] + w[1] + w[4] + w[5]
                     : flat == 2 ? w[0] + w[1] + w[2] + w[3]
                                 : w[0] + w[1] + w[2] + w[3] + w[4] + w[5];
    return lv->m ? D + lv->m[p] : D;
}

/* cell_weights, and the weighted sum nb of the six neighbours of x, the
 * flat direction's left out (on a 2D cross-section its neighbours are two
 * whole ghost planes, read only times 0): the same sum to the bit. */
static inline __attribute__((always_inline)) double
row_sums(const struct level *lv, const double *x, ptrdiff_t p, const int flat, double *nb)
{
    const ptrdiff_t s[3] = {lv->g.stride[0], lv->g.stride[1], 1};
    double w[6];
    const double D = cell_weights(lv, p, flat, w);
    *nb = flat == 0   ? w[2] * x[p - s[1]] + w[3] * x[p + s[1]] + w[4] * x[p - 1] + w[5] * x[p + 1]
          : flat == 1 ? w[0] * x[p - s[0]] + w[1] * x[p + s[0]] + w[4] * x[p - 1] + w[5] * x[p + 1]
          : flat == 2 ? w[0] * x[p - s[0]] + w[1] * x[p + s[0]] + w[2] * x[p - s[1]] + w[3] * x[p + s[1]]
                      : w[0] * x[p - s[0]] + w[1] * x[p + s[0]] + w[2] * x[p - s[1]] +
                            w[3] * x[p + s[1]] + w[4] * x[p - 1] + w[5] * x[p + 1];
    return D;
}

/* Runs CALL(flat) with a level's flat direction as a constant (-1: none),
 * so that its kernel is instantiated with the terms of that direction left
 * out (cell_weights). */
#define FLAT_DISPATCH(flat, CALL)                                                               \
    do {                                                                                        \
        switch (flat) {                                                                         \
        case 0: CALL(0); break;                                                                 \
        case 1: CALL(1); break;                                                                 \
        case 2: CALL(2); break;                                                                 \
        default: CALL(-1); break;                                                               \
        }                                                                                       \
    } while (0)

/* The mixed-derivative term's part of (L x)_p: along each of the two
 * directions, the difference of the fluxes km (mean gradient across) on the
 * cell's two faces; the mean gradient across a face is that of the four
 * faces of the other direction around it.  km is 0 on boundary faces, so
 * no corner ghost is read with a weight. */
static inline __attribute__((always_inline)) double mixed_row(const struct level *lv,
                                                              const double *x, ptrdiff_t p)
{
    const ptrdiff_t s1 = lv->g.stride[lv->md[0]], s2 = lv->g.stride[lv->md[1]];
    const double *k1 = lv->km[0], *k2 = lv->km[1];
    const double q = 0.25 / (lv->g.h[lv->md[0]] * lv->g.h[lv->md[1]]);
    const double d2 = x[p + s2] - x[p - s2], d1 = x[p + s1] - x[p - s1];
    const double f1 = k1[p + s1] * (d2 + x[p + s1 + s2] - x[p + s1 - s2]) -
                      k1[p] * (d2 + x[p - s1 + s2] - x[p - s1 - s2]);
    const double f2 = k2[p + s2] * (d1 + x[p + s2 + s1] - x[p + s2 - s1]) -
                      k2[p] * (d1 + x[p - s2 + s1] - x[p - s2 - s1]);
    return q * (f1 + f2);
}

/* err = the formatted message (err NULL or errlen 0: nothing); here, not
 * in multigrid.c, because the parts multigrid.c calls use it too. */
__attribute__((format(printf, 3, 4))) static inline void mg_set_err(char *err, size_t errlen,
                                                                    const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

/* ---- multigrid_levels.c: the hierarchy and its coefficients --------------------- */

/* The levels of grid g (mg's options and conditions set) with their arrays,
 * the prolongation tables and the line smoother's factors.  Returns 0, or
 * -1 out of memory (mg_level_free releases what was allocated). */
/* Which directions the level below g halves (halve[d] = 1); 0 when none. */
int mg_choose_halving(const struct grid *g, long coarse_cells, int full, int halve[3]);
int mg_build_levels(struct multigrid *mg, const struct grid *g);
/* The levels kept on the ranks of a decomposed grid (mg_build_levels_decomposed
 * in multigrid_levels.c): gathered at the first global level of at most
 * this many cells, or where a block no longer halves in place. */
#define MG_GATHER_CELLS 4096
int mg_build_levels_decomposed(struct multigrid *mg, const struct grid *gglobal,
                               const struct decomp *dc);
void mg_level_free(struct level *lv, int owns_xb);
/* The mass term of every level (mass NULL: none). */
int mg_set_mass(struct multigrid *mg, const double *mass, char *err, size_t errlen);
/* Level 0's face coefficients from a[] (checked), every coarser level's,
 * the transfer weights and the live cells. */
int mg_set_faces(struct multigrid *mg, double *const a[3], char *err, size_t errlen);
/* mg_set_faces after level 0's folded coefficients are in place (a gathered
 * level): the coarser levels, the weights and the live cells. */
void mg_coarsen_faces(struct multigrid *mg);
/* The mass of the levels below 0 from level 0's mbuf, and the pointers. */
void mg_coarsen_mass(struct multigrid *mg);

/* ---- multigrid_operator.c: ghosts and the operator on a level ------------------- */

/* Cell field f on level lv: its ghosts as kind says (orphaned worksharing). */
void mg_halo_fill(const struct multigrid *mg, const struct level *lv, double *f,
                  enum halo_kind kind);
/* Face array a of normal d along its normal (periodic wrap, else 0). */
void mg_halo_faces(const struct multigrid *mg, const struct level *lv, double *a, int d);
/* r = (b - shift) - L x on live cells, 0 on dead ones; with b NULL, r = L x.
 * x's ghosts in HALO_OPERATOR mode; r may not alias x. */
void mg_residual(const struct level *lv, const double *x, const double *b, double shift,
                 double *r);
/* m = |b - shift| + |L| |x| cell by cell, 0 on dead cells. */
void mg_magnitude(const struct level *lv, const double *x, const double *b, double shift,
                  double *m);
void mg_zero_interior(const struct level *lv, double *f);

/* ---- multigrid_smooth.c --------------------------------------------------------- */

/* Whether the operator's halo of lv changes as its interior does. */
int mg_halo_wraps(const struct multigrid *mg, const struct level *lv);
/* sweeps smoothing sweeps on lv->x: first_colour 0 the pre-smoother, 1 its
 * adjoint (the post-smoother).  Orphaned worksharing. */
void mg_smooth(const struct multigrid *mg, const struct level *lv, int first_colour, int sweeps);
/* The Thomas factors of the lines along the k-th line direction d. */
void mg_line_factors(const struct level *lv, int k, int d);

/* ---- multigrid_transfer.c ------------------------------------------------------- */

/* Prolongation tables of fine level f from coarse level c (struct level). */
int mg_build_prolongation(struct level *f, const struct level *c);
/* The prolongation weights of f towards c, from f's coefficients. */
void mg_transfer_weights(const struct multigrid *mg, struct level *f, const struct level *c);
/* c->b = R f->r (orphaned worksharing; f->r's ghosts in HALO_MIRROR mode). */
void mg_restrict_residual(const struct multigrid *mg, const struct level *f, struct level *c);
/* f->x += P c->x on live fine cells (orphaned; c->x's ghosts in HALO_MIRROR). */
void mg_prolong_add(const struct level *f, const struct level *c);

/* ---- multigrid_coarse.c: the coarsest level, by CHOLMOD ------------------------- */

/* Its arrays and CHOLMOD's common block.  Returns 0, or -1 out of memory. */
int mg_coarse_start(struct multigrid *mg);
void mg_coarse_free(struct multigrid *mg);
/* The matrix assembled (and analysed when its pattern is new), then its
 * numeric factorisation: each returns 0, or -1 with a message. */
int mg_coarse_assemble(struct multigrid *mg, char *err, size_t errlen);
int mg_coarse_numeric(struct multigrid *mg, char *err, size_t errlen);
/* x = L^-1 b on the coarsest level. */
void mg_coarse_solve(struct multigrid *mg);
size_t mg_coarse_bytes(const struct multigrid *mg);

#endif
