/* Geometric multigrid for the variable-coefficient cell-centred Poisson problem
 * (see include/solvers/multigrid.h; measurements in docs/design.md, "Multigrid").
 *
 * Conventions inside this file:
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
 *    filled by halo_fill / halo_faces only, which is where a distributed
 *    version would exchange halos.  The red-black colour uses the local index,
 *    which a box decomposition must offset by the box origin.  The only global
 *    operation is coarse_solve (a gather of the coarsest level, as an MPI
 *    version would gather it to one rank), and dot products. */
#include "solvers/multigrid.h"
#include "solvers/suitesparse.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define MAX_LEVELS 32
#define MAX_THREADS 256
#define PAD 8                  /* doubles between per-thread partial sums (one cache line) */
/* Smaller levels run on one thread: fork/join costs more.  16,384 before the
 * short spin count (src/app/main.c), when each region woke a sleeping thread;
 * since, 4,096 runs the heap's 70 x 100 level on two threads too: 140 x 200
 * with gmg in 1.84-1.85 s against 1.93-1.95 s, the column collapse
 * unchanged. */
#define PAR_CELLS 4096
#define ANISO_CELLS 4096       /* above this, coarsen anisotropically rather than stop */
#define PCG_GROWTH 100.0       /* CG stops where its residual exceeds its best this much */
#define ROUNDOFF_TERMS 10.0    /* the residual's rounding, a 7-term sum: in eps (|b| + |L||x|) */

/* The statements in a parallel region when par, else on the calling thread
 * outside any region.  The level loops are orphaned `omp for`s: outside a
 * region they are plain loops and their barriers return at once, while in
 * libgomp's region of one thread (`if (0)`) every barrier and the join are a
 * futex system call, several microseconds each in a virtual machine: 27,000
 * per five steps of the column collapse at 32 cells per H0, whose levels all
 * run on one thread (bench/analysis.md, "Regions of one thread and
 * CHOLMOD's supernodes").  muflow's own GOMP_parallel (gomp_inline.h) now
 * runs such a region inline as well; the macro came first and keeps the
 * multigrid's levels free of the region call whatever GOMP_parallel the
 * program binds to. */
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
                              lines along each line direction (line_factors) */
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
};

static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

void multigrid_default_options(struct multigrid_options *o)
{
    o->pre = 2;
    o->post = 2;
    o->prolong = MG_PROLONG_FLUX;
    o->average = MG_AVERAGE_ARITHMETIC;
    o->coarse_cells = 64;
    o->gamma = 2;
    o->smoother = MG_SMOOTH_POINT;
    o->full_coarsening = 0;
    o->split_finest = 0;
    o->coarse_simplicial = 0;
}

/* ---- halo fills: the only writers of ghost values ------------------------------ */

/* The two ghosts of one grid line along d (see halo_fill). */
static inline void halo_pair(double *f, const struct grid *g, int d, int e1, int e2, int u,
                             int v, int src_lo, int src_hi, double s_lo, double s_hi)
{
    int c[3];
    c[e1] = u;
    c[e2] = v;
    c[d] = 0;
    const ptrdiff_t base = grid_idx(g, c[0], c[1], c[2]), sd = g->stride[d];
    const int n = g->n[d];
    f[base - sd] = s_lo * f[base + (ptrdiff_t)src_lo * sd];
    f[base + (ptrdiff_t)n * sd] = s_hi * f[base + (ptrdiff_t)src_hi * sd];
}

/* Cell field f on level lv (orphaned worksharing: call it from every thread of
 * a team, or outside a parallel region).  Periodic: wrap; otherwise 0
 * (operator), the conditions' value (mirror) or the mirror whatever the
 * condition (even: the transfer weights).  The transfer kinds go direction by
 * direction, each over the ghost-extended range of the directions before it,
 * so edges and corners are filled too (the transfers read them). */
static void halo_fill(const struct multigrid *mg, const struct level *lv, double *f,
                      enum halo_kind kind)
{
    const struct grid *g = &lv->g;
    /* the 7-point operator reads face ghosts only: the three directions then
     * write disjoint ghost sets from interior values and need no barrier
     * between them (one at the end) -- two barriers fewer per half sweep */
    const int faces_only = kind == HALO_OPERATOR;
    for (int d = 0; d < 3; d++) {
        const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
        const int ext1 = e1 < d && !faces_only, ext2 = e2 < d && !faces_only;
        const int lo1 = ext1 ? -1 : 0, hi1 = ext1 ? g->n[e1] + 1 : g->n[e1];
        const int lo2 = ext2 ? -1 : 0, hi2 = ext2 ? g->n[e2] + 1 : g->n[e2];
        const int n = g->n[d];
        /* a periodic direction of one cell has zero coefficients
         * (finish_level_coefficients): the operator reads its ghosts only
         * times 0, and on a 2D cross-section (ny = 1) they are two whole
         * planes, most of a fill's traffic (27 % of the collapse at
         * 320 x 96).  The residual's and the correction's fills skip them
         * too: a direction no level halves has the weight 0 for the ghost
         * in the prolongation and none in the restriction, and a ghost no
         * fill writes keeps a finite value (0 from the allocation, or the
         * last fill's).  The transfer weights' fill (even) and the
         * solution's (result) still write them. */
        if ((kind == HALO_OPERATOR || kind == HALO_MIRROR) && mg->periodic[d] && n == 1)
            continue;
        int src_lo, src_hi;
        double s_lo, s_hi;
        if (mg->periodic[d]) {
            src_lo = n - 1;
            src_hi = 0;
            s_lo = s_hi = 1.0;
        } else {
            src_lo = 0;
            src_hi = n - 1;
            if (kind == HALO_OPERATOR) {
                s_lo = s_hi = 0.0;
            } else if (kind == HALO_EVEN) {
                s_lo = s_hi = 1.0;
            } else {
                s_lo = mg->bc[d][0] == POISSON_DIRICHLET ? -1.0 : 1.0;
                s_hi = mg->bc[d][1] == POISSON_DIRICHLET ? -1.0 : 1.0;
            }
        }
        if (faces_only) {
#pragma omp for collapse(2) schedule(static) nowait
            for (int u = lo1; u < hi1; u++)
                for (int v = lo2; v < hi2; v++)
                    halo_pair(f, g, d, e1, e2, u, v, src_lo, src_hi, s_lo, s_hi);
        } else {
#pragma omp for collapse(2) schedule(static)
            for (int u = lo1; u < hi1; u++)
                for (int v = lo2; v < hi2; v++)
                    halo_pair(f, g, d, e1, e2, u, v, src_lo, src_hi, s_lo, s_hi);
        }
    }
    if (faces_only) {
#pragma omp barrier
    }
}

/* Face array a (normal d) along its normal: a periodic direction's face n is
 * face 0 and face -1 is face n-1; elsewhere the ghost face -1 is unused (0). */
static void halo_faces(const struct multigrid *mg, const struct level *lv, double *a, int d)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const ptrdiff_t sd = g->stride[d];
    const int per = mg->periodic[d];
    for (int u = 0; u < g->n[e1]; u++)
        for (int v = 0; v < g->n[e2]; v++) {
            int c[3];
            c[e1] = u;
            c[e2] = v;
            c[d] = 0;
            const ptrdiff_t base = grid_idx(g, c[0], c[1], c[2]);
            if (per) {
                a[base + (ptrdiff_t)n * sd] = a[base];
                a[base - sd] = a[base + (ptrdiff_t)(n - 1) * sd];
            } else {
                a[base - sd] = 0.0;
            }
        }
}

/* ---- deterministic reductions ---------------------------------------------------- */

static int team_size(const struct level *lv)
{
#ifdef _OPENMP
    int t = lv->par ? omp_get_max_threads() : 1;
    return t < MAX_THREADS ? t : MAX_THREADS;
#else
    (void)lv;
    return 1;
#endif
}

static int thread_id(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* Per-thread partial sums over a static schedule, added in thread order: the
 * result repeats bit for bit at a given thread count. */
static double sum_partials(const double *part, int nt)
{
    double s = 0.0;
    for (int t = 0; t < nt; t++)
        s += part[t * PAD];
    return s;
}

/* The reductions over a level's interior: sum u v over every cell, or over
 * the live cells sum u or sum (u - shift)^2.  One loop for the three, its
 * kind a constant at each inlined call, so that all three keep the same
 * deterministic per-thread partials. */
enum level_sum { SUM_DOT, SUM_LIVE, SUM_LIVE_SQUARES };

static inline __attribute__((always_inline)) double
level_reduce(struct multigrid *mg, const struct level *lv, enum level_sum kind, const double *u,
             const double *v, double shift)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2], nt = team_size(lv);
    const unsigned char *live = lv->live;
    double *part = mg->partial;
    for (int t = 0; t < nt; t++)
        part[t * PAD] = 0.0;
    REGION_NT({
        double s = 0.0;
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++) {
                    if (kind == SUM_DOT) {
                        s += u[row + k] * v[row + k];
                    } else if (kind == SUM_LIVE) {
                        s += live[row + k] ? u[row + k] : 0.0;
                    } else {
                        double w = u[row + k] - shift;
                        s += live[row + k] ? w * w : 0.0;
                    }
                }
            }
        part[thread_id() * PAD] = s;
    });
    return sum_partials(part, nt);
}

/* sum over the interior of u v */
static double dot(struct multigrid *mg, const struct level *lv, const double *u, const double *v)
{
    return level_reduce(mg, lv, SUM_DOT, u, v, 0.0);
}

/* sum of f over the live cells */
static double live_sum(struct multigrid *mg, const struct level *lv, const double *f)
{
    return level_reduce(mg, lv, SUM_LIVE, f, NULL, 0.0);
}

/* sum of (f - shift)^2 over the live cells */
static double live_norm2(struct multigrid *mg, const struct level *lv, const double *f,
                         double shift)
{
    return level_reduce(mg, lv, SUM_LIVE_SQUARES, f, NULL, shift);
}

/* ---- stencil kernels ----------------------------------------------------------- */

/* The six face weights w_f = a_f / h_d^2 of cell p (x low, x high, y low,
 * y high, z low, z high) and their sum D plus the cell's mass term, the
 * diagonal of -(L - m).  Without a mass term (lv->m NULL, loop-invariant:
 * the compiler unswitches the loops) D is the face sum alone, to the bit.
 * flat (a constant after inlining; -1: none) is a periodic direction of one
 * cell: its two weights are 0 (finish_level_coefficients), so they are not
 * loaded and are left out of D; zero terms added first change no sum, so D
 * is that of all six terms to the bit. */
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

/* One red-black half sweep of Gauss-Seidel: the cells with (i+j+k) % 2 == colour
 * solve their own row with the neighbours' current values (ghosts filled in
 * HALO_OPERATOR mode before the call).  Dead cells are set to 0. */
static inline __attribute__((always_inline)) void
smooth_colour_body(const struct level *lv, int colour, const int flat)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const double *restrict b = lv->b;
    double *restrict x = lv->x;
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = (i + j + colour) & 1; k < nz; k += 2) {
                const ptrdiff_t p = row + k;
                double S;
                const double D = row_sums(lv, x, p, flat, &S);
                if (lv->km[0])
                    S += mixed_row(lv, x, p);
                x[p] = D > 0.0 ? (S - b[p]) / D : 0.0;
            }
        }
}

static void smooth_colour(const struct level *lv, int colour)
{
#define CALL(flat) smooth_colour_body(lv, colour, flat)
    FLAT_DISPATCH(lv->flat, CALL);
#undef CALL
}

/* The first cell of the line along d through index u along e1, v along e2. */
static inline ptrdiff_t line_start(const struct grid *g, int d, int e1, int e2, int u, int v)
{
    int c[3];
    c[d] = 0;
    c[e1] = u;
    c[e2] = v;
    return grid_idx(g, c[0], c[1], c[2]);
}

/* The forward and backward Thomas passes of m (1 or 2, a constant after
 * inlining) lines of one colour along d from their first cells p0[j], mx[j]
 * their mixed terms (NULL: none).  Two lines go through the passes side by
 * side: each pass is a chain of dependent multiply-adds along its line, and
 * a second, independent chain fills the latency of the first (the backward
 * pass's store-load chain was a third of the cycle's smoothing time).  Every
 * line's arithmetic and order are those of one line alone. */
static inline __attribute__((always_inline)) void
solve_lines(const struct level *lv, int k, int d, int e1, int e2, const int across1,
            const ptrdiff_t p0[2], double *const mx[2], const int m)
{
    const struct grid *g = &lv->g;
    const int n = g->n[d];
    const ptrdiff_t sd = g->stride[d], s1 = g->stride[e1], s2 = g->stride[e2];
    const double h1 = lv->ih2[e1], h2 = lv->ih2[e2], hd = lv->ih2[d];
    const double *restrict b = lv->b, *restrict a1 = lv->a[e1], *restrict a2 = lv->a[e2],
                           *restrict ad = lv->a[d];
    const double *restrict cp = lv->lc[k], *restrict inv = lv->li[k];
    double *restrict x = lv->x;
    double prev[2] = {0.0, 0.0};
    for (int t = 0; t < n; t++)
        for (int j = 0; j < m; j++) {
            const ptrdiff_t p = p0[j] + (ptrdiff_t)t * sd;
            double S = h2 * (a2[p] * x[p - s2] + a2[p + s2] * x[p + s2]) - b[p];
            if (across1)
                S += h1 * (a1[p] * x[p - s1] + a1[p + s1] * x[p + s1]);
            if (mx[0])
                S += mx[j][t];
            prev[j] = x[p] = (S + hd * ad[p] * prev[j]) * inv[p];
        }
    double next[2] = {0.0, 0.0};
    for (int t = n - 1; t >= 0; t--)
        for (int j = 0; j < m; j++) {
            const ptrdiff_t p = p0[j] + (ptrdiff_t)t * sd;
            next[j] = x[p] += cp[p] * next[j];
        }
}

/* One half sweep of zebra line Gauss-Seidel along direction d (the k-th line
 * direction): the lines along d whose index across (the sum of the other
 * two indices) has the parity colour solve their own tridiagonal rows
 * exactly, with the neighbouring lines' current values.  A line smoother is
 * what survives anisotropy along it (the viscous tangent's: the shear
 * direction's coefficient is the tangent, far below the viscosity across
 * it), and alternating the directions covers anisotropy that changes its
 * direction over the domain.  d is not periodic (a cyclic line is not
 * solved here), so the line ends read ghosts of 0 (HALO_OPERATOR).  The
 * Thomas factors (line_factors) are the level's: the forward pass keeps its
 * values in x itself, which the line's own rows do not read.  The lines of
 * a colour go in pairs two apart along e2 (solve_lines); lines of one colour
 * do not read each other, so the pairing changes no result. */
static inline __attribute__((always_inline)) void
smooth_lines_body(const struct level *lv, int k, int d, int colour, const int across1,
                  double *mxbuf, int mxlen)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const int n1 = g->n[e1], n2 = g->n[e2];
    const ptrdiff_t sd = g->stride[d], s2 = g->stride[e2];
    const double *x = lv->x;
    const int pairs = (n2 + 3) / 4; /* of the about n2 / 2 lines of a colour per u */
#pragma omp for collapse(2) schedule(static)
    for (int u = 0; u < n1; u++)
        for (int w = 0; w < pairs; w++) {
            const int v = ((colour - u) & 1) + 4 * w; /* the pair's first line */
            if (v >= n2)
                continue;
            const int m = v + 2 < n2 ? 2 : 1;
            const ptrdiff_t p0[2] = {line_start(g, d, e1, e2, u, v),
                                     line_start(g, d, e1, e2, u, v) + 2 * s2};
            /* the mixed term from the values before the lines' update (their
             * own nodes are overwritten by the forward pass) */
            double *mx[2] = {NULL, NULL};
            if (lv->km[0]) {
                mx[0] = mxbuf + (size_t)thread_id() * (size_t)(2 * mxlen);
                mx[1] = mx[0] + mxlen;
                for (int j = 0; j < m; j++)
                    for (int t = 0; t < n; t++)
                        mx[j][t] = mixed_row(lv, x, p0[j] + (ptrdiff_t)t * sd);
            }
            if (m == 2)
                solve_lines(lv, k, d, e1, e2, across1, p0, mx, 2);
            else
                solve_lines(lv, k, d, e1, e2, across1, p0, mx, 1);
        }
}

/* The first direction across (e1 < e2) is left out where it is a periodic
 * direction of one cell, whose coefficients are 0 (a 2D cross-section:
 * its two ghost planes would be read for nothing, a third of the loads). */
static void smooth_lines(const struct multigrid *mg, const struct level *lv, int k, int d,
                         int colour)
{
    const int e1 = d == 0 ? 1 : 0;
    if (mg->periodic[e1] && lv->g.n[e1] == 1)
        smooth_lines_body(lv, k, d, colour, 0, mg->mxbuf, mg->mxlen);
    else
        smooth_lines_body(lv, k, d, colour, 1, mg->mxbuf, mg->mxlen);
}

/* The Thomas factors of every line along the k-th line direction d of level
 * lv: for the rows -lo x[t-1] + D x[t] - hi x[t+1] (the face weights along
 * d, D the whole diagonal), inv = 1 / (D - lo c'[t-1]) and c' = hi inv;
 * dead cells (D = 0) get 0 for both, which holds them at 0 and cuts the
 * line there.  lo is 0 at t = 0 and hi at t = n - 1: the boundary face's
 * weight stays in D only (ghost 0). */
static void line_factors(const struct level *lv, int k, int d)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const ptrdiff_t sd = g->stride[d];
    double *cp = lv->lc[k], *inv = lv->li[k];
#pragma omp parallel for collapse(2) schedule(static) if (lv->par)
    for (int u = 0; u < g->n[e1]; u++)
        for (int v = 0; v < g->n[e2]; v++) {
            const ptrdiff_t p0 = line_start(g, d, e1, e2, u, v);
            double prev = 0.0;
            for (int t = 0; t < n; t++) {
                const ptrdiff_t p = p0 + (ptrdiff_t)t * sd;
                double w[6];
                const double D = cell_weights(lv, p, -1, w);
                if (!(D > 0.0)) {
                    cp[p] = inv[p] = prev = 0.0;
                    continue;
                }
                const double lo = t > 0 ? w[2 * d] : 0.0, hi = t + 1 < n ? w[2 * d + 1] : 0.0;
                inv[p] = 1.0 / (D - lo * prev);
                prev = cp[p] = hi * inv[p];
            }
        }
}

/* r = (b - shift) - L x on live cells, 0 on dead ones; with b NULL, r = L x
 * (0 on dead cells).  x's ghosts in HALO_OPERATOR mode.  r may not alias x. */
static inline __attribute__((always_inline)) void
residual_body(const struct level *lv, const double *x, const double *b, double shift, double *r,
              const int flat)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const double sign = b ? -1.0 : 1.0;
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                double nb;
                const double D = row_sums(lv, x, p, flat, &nb);
                double Lx = nb - D * x[p];
                if (lv->km[0])
                    Lx += mixed_row(lv, x, p);
                const double bb = b ? b[p] - shift : 0.0;
                r[p] = D > 0.0 ? bb + sign * Lx : 0.0;
            }
        }
}

static void residual(const struct level *lv, const double *x, const double *b, double shift,
                     double *r)
{
#define CALL(flat) residual_body(lv, x, b, shift, r, flat)
    FLAT_DISPATCH(lv->flat, CALL);
#undef CALL
}

/* m = |b - shift| + |L| |x| cell by cell (|L|: the operator with every
 * weight taken positive), 0 on dead cells: the size of the terms whose
 * rounding the residual b - L x carries.  x's ghosts in HALO_OPERATOR mode. */
static void magnitude(const struct level *lv, const double *x, const double *b, double shift,
                      double *m)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const ptrdiff_t sx = g->stride[0], sy = g->stride[1];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                double w[6];
                const double D = cell_weights(lv, p, -1, w);
                const double A = w[0] * fabs(x[p - sx]) + w[1] * fabs(x[p + sx]) +
                                 w[2] * fabs(x[p - sy]) + w[3] * fabs(x[p + sy]) +
                                 w[4] * fabs(x[p - 1]) + w[5] * fabs(x[p + 1]) + D * fabs(x[p]);
                m[p] = D > 0.0 ? fabs(b[p] - shift) + A : 0.0;
            }
        }
}

static void zero_interior(const struct level *lv, double *f)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            double *row = f + grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                row[k] = 0.0;
        }
}

/* ---- grid transfers ------------------------------------------------------------ */

/* c->b = R f->r with R = P^T / 2^(halved directions): coarse cell I gathers
 * from the fine cells 2I-1 .. 2I+2 of each halved direction with the weight
 * each of them gives I in the prolongation (1 - w for its parent, w for its
 * neighbour); the division by 2 per direction makes a constant residual
 * restrict to itself, the scaling of the rediscretised coarse operator.
 * f->r's ghosts are in HALO_MIRROR mode and the weights' in HALO_EVEN: a fine
 * ghost then carries the condition's sign and its mirror cell's weight, which
 * is exactly the transpose of the prolongation reading a coarse ghost. */
static inline __attribute__((always_inline)) void
restrict_residual_body(const struct multigrid *mg, const struct level *f, struct level *c,
                       const int flat)
{
    const struct grid *gf = &f->g, *gc = &c->g;
    int off[3][4], par[3][4], cnt[3], m[3];
    double scale = 1.0;
    for (int d = 0; d < 3; d++) {
        if (c->coarse[d] && mg->opt.prolong == MG_PROLONG_CONSTANT) {
            /* w = 0: only the two children, the neighbours' weight is 0 */
            off[d][0] = 0, off[d][1] = 1;
            par[d][0] = par[d][1] = 1;
            cnt[d] = 2;
            m[d] = 2;
            scale *= 0.5;
        } else if (c->coarse[d]) {
            static const int o[4] = {-1, 0, 1, 2}, pa[4] = {0, 1, 1, 0};
            for (int t = 0; t < 4; t++)
                off[d][t] = o[t], par[d][t] = pa[t];
            cnt[d] = 4;
            m[d] = 2;
            scale *= 0.5;
        } else {
            off[d][0] = 0;
            par[d][0] = 1;
            cnt[d] = 1;
            m[d] = 1;
        }
    }
    const double *restrict r = f->r;
    const double *restrict wx = f->pw[0], *restrict wy = f->pw[1], *restrict wz = f->pw[2];
    /* the weight of a fine cell towards I along d is A + B w: (1, -1) for its
     * parent, (0, 1) for its neighbour (branch-free inner loop) */
    double A[3][4], B[3][4];
    for (int d = 0; d < 3; d++)
        for (int t = 0; t < cnt[d]; t++) {
            A[d][t] = par[d][t] ? 1.0 : 0.0;
            B[d][t] = par[d][t] ? -1.0 : 1.0;
        }
    double *restrict b = c->bbuf;
    const unsigned char *live = c->live;
    const int nx = gc->n[0], ny = gc->n[1], nz = gc->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int I = 0; I < nx; I++)
        for (int J = 0; J < ny; J++) {
            double *restrict brow = b + grid_idx(gc, I, J, 0);
            for (int K = 0; K < nz; K++)
                brow[K] = 0.0;
            for (int p = 0; p < cnt[0]; p++) {
                const int fi = m[0] * I + off[0][p];
                for (int q = 0; q < cnt[1]; q++) {
                    const int fj = m[1] * J + off[1][q];
                    const ptrdiff_t base = grid_idx(gf, fi, fj, 0);
                    const double ax = A[0][p], bx = B[0][p], ay = A[1][q], by = B[1][q];
                    for (int t = 0; t < cnt[2]; t++) {
                        const double az = A[2][t], bz = B[2][t];
                        const int o = off[2][t], mz = m[2];
                        /* along the flat direction (never halved) the weight
                         * is 1 - 0: left out, the same product to the bit (x
                         * and y; a flat z takes the general product) */
                        for (int K = 0; K < nz; K++) {
                            const ptrdiff_t pf = base + mz * K + o;
                            if (flat == 0)
                                brow[K] += (ay + by * wy[pf]) * (az + bz * wz[pf]) * r[pf];
                            else if (flat == 1)
                                brow[K] += (ax + bx * wx[pf]) * (az + bz * wz[pf]) * r[pf];
                            else
                                brow[K] += (ax + bx * wx[pf]) * (ay + by * wy[pf]) *
                                           (az + bz * wz[pf]) * r[pf];
                        }
                    }
                }
            }
            const unsigned char *lrow = live + grid_idx(gc, I, J, 0);
            for (int K = 0; K < nz; K++)
                brow[K] = lrow[K] ? scale * brow[K] : 0.0;
        }
}

static void restrict_residual(const struct multigrid *mg, const struct level *f,
                              struct level *c)
{
#define CALL(flat) restrict_residual_body(mg, f, c, flat)
    FLAT_DISPATCH(f->flat, CALL);
#undef CALL
}

/* f->x += P c->x on live fine cells; c->x's ghosts in HALO_MIRROR mode.
 * Along f's flat direction (a constant after inlining, -1: none; never
 * halved) the weight of the neighbouring coarse line is 0, and its terms
 * are left out: (1 - 0) a + 0 b is a to the bit (x and y; a flat z takes
 * the general sum). */
static inline __attribute__((always_inline)) void
prolong_add_body(const struct level *f, const struct level *c, const int flat)
{
    const struct grid *gf = &f->g, *gc = &c->g;
    const int nx = gf->n[0], ny = gf->n[1], nz = gf->n[2];
    const int *restrict ix = f->pi[0], *restrict iy = f->pi[1], *restrict iz = f->pi[2];
    const double *wx = f->pw[0], *wy = f->pw[1], *wz = f->pw[2];
    const double *restrict e = c->x;
    double *restrict x = f->x;
    const unsigned char *live = f->live;
    const ptrdiff_t csx = gc->stride[0], csy = gc->stride[1];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(gf, i, j, 0);
            /* the four coarse lines this fine line interpolates from */
            const ptrdiff_t x0 = (ptrdiff_t)(ix[2 * i] + 1) * csx, x1 = (ptrdiff_t)(ix[2 * i + 1] + 1) * csx;
            const ptrdiff_t y0 = (ptrdiff_t)(iy[2 * j] + 1) * csy, y1 = (ptrdiff_t)(iy[2 * j + 1] + 1) * csy;
            const ptrdiff_t l00 = x0 + y0, l01 = x0 + y1, l10 = x1 + y0, l11 = x1 + y1;
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                if (!live[p])
                    continue;
                const ptrdiff_t k0 = iz[2 * k] + 1, k1 = iz[2 * k + 1] + 1;
                const double uz = wz[p];
                const double z0 = 1.0 - uz, z1 = uz;
                double v;
                if (flat == 0) {
                    const double uy = wy[p];
                    v = (1.0 - uy) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                        uy * (z0 * e[l01 + k0] + z1 * e[l01 + k1]);
                } else if (flat == 1) {
                    const double ux = wx[p];
                    v = (1.0 - ux) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                        ux * (z0 * e[l10 + k0] + z1 * e[l10 + k1]);
                } else {
                    const double ux = wx[p], uy = wy[p];
                    v = (1.0 - ux) * ((1.0 - uy) * (z0 * e[l00 + k0] + z1 * e[l00 + k1]) +
                                      uy * (z0 * e[l01 + k0] + z1 * e[l01 + k1])) +
                        ux * ((1.0 - uy) * (z0 * e[l10 + k0] + z1 * e[l10 + k1]) +
                              uy * (z0 * e[l11 + k0] + z1 * e[l11 + k1]));
                }
                x[p] += v;
            }
        }
}

static void prolong_add(const struct level *f, const struct level *c)
{
#define CALL(flat) prolong_add_body(f, c, flat)
    FLAT_DISPATCH(f->flat, CALL);
#undef CALL
}

/* Prolongation weights of fine level f for the directions c halves.  Linear:
 * w = 1/4 (the fine centre is a quarter of a coarse cell from its parent's
 * centre).  Constant: 0.  Flux (operator-dependent, after Alcouffe, Brandt,
 * Dendy and Painter, SIAM J. Sci. Stat. Comput. 2 (1981) 430): the value a
 * flux-continuous 1D profile along the cell's own grid line takes, i.e. w is
 * the fraction of the series resistance between the two coarse centres that
 * lies between the parent's centre and the fine centre.  The coarse centres
 * sit on the fine faces inside the coarse cells; each half fine cell is
 * charged to the coefficient of the fine face it touches:
 *   own side  R_a = 1/2 / a(face between parent centre and cell)
 *   far side  R_b = 1 / a(face the coarse face is) + 1/2 / a(neighbour's inner face)
 * (uniform a: 1/4, the linear weight; a jump on the coarse face: the kink of
 * the error is reproduced).  A blocked face makes its side infinitely
 * resistant.  Next to a non-periodic boundary the neighbour is the mirror
 * ghost and the linear weight is kept.  Computed at set-up; the periodic wrap
 * reads the faces by index modulo n (a box decomposition would need the
 * neighbour's faces at set-up). */
static void transfer_weights(const struct multigrid *mg, struct level *f, const struct level *c)
{
    const struct grid *g = &f->g;
    for (int d = 0; d < 3; d++) {
        double *w = f->pw[d];
        if (!c->coarse[d])
            continue; /* stays 0 */
        const int n = g->n[d], per = mg->periodic[d];
        const ptrdiff_t sd = g->stride[d];
#pragma omp parallel for collapse(2) schedule(static) if (f->par)
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    const int cc[3] = {i, j, k};
                    const int t = cc[d];
                    const ptrdiff_t p = grid_idx(g, i, j, k);
                    const ptrdiff_t p0 = p - (ptrdiff_t)t * sd; /* cell 0 of this line */
                    double val;
                    if (mg->opt.prolong == MG_PROLONG_CONSTANT) {
                        val = 0.0;
                    } else {
                        int own, cross, far, outside;
                        if (t & 1) {
                            own = t, cross = t + 1, far = t + 2;
                            outside = t + 1 >= n;
                        } else {
                            own = t + 1, cross = t, far = t - 1;
                            outside = t == 0;
                        }
                        if (mg->opt.prolong == MG_PROLONG_LINEAR || (outside && !per)) {
                            val = 0.25;
                        } else {
                            /* faces by index: periodic faces wrap modulo n
                             * (the indices lie in -1 .. n + 1: one shift is
                             * the modulo, without its divisions) */
                            if (per) {
                                own = own < 0 ? own + n : own >= n ? own - n : own;
                                cross = cross < 0 ? cross + n : cross >= n ? cross - n : cross;
                                far = far < 0 ? far + n : far >= n ? far - n : far;
                            }
                            const double ao = f->a[d][p0 + (ptrdiff_t)own * sd];
                            const double ac = f->a[d][p0 + (ptrdiff_t)cross * sd];
                            const double af = f->a[d][p0 + (ptrdiff_t)far * sd];
                            const int ra_inf = !(ao > 0.0), rb_inf = !(ac > 0.0) || !(af > 0.0);
                            if (ra_inf)
                                val = rb_inf ? 0.0 : 1.0;
                            else if (rb_inf)
                                val = 0.0;
                            else {
                                const double ra = 0.5 / ao, rb = 1.0 / ac + 0.5 / af;
                                val = ra / (ra + rb);
                            }
                        }
                    }
                    w[p] = val;
                }
        (void)c;
        halo_fill(mg, f, w, HALO_EVEN);
    }
}

/* ---- coefficients -------------------------------------------------------------- */

/* 1 / (1/4 a1^-1 + 1/2 a0^-1 + 1/4 a2^-1): the series resistance between two
 * coarse centres, which sit on the fine faces either side of the coarse face;
 * a blocked face on the path blocks it. */
static double harmonic3(double a1, double a0, double a2)
{
    if (!(a1 > 0.0 && a0 > 0.0 && a2 > 0.0))
        return 0.0;
    return 1.0 / (0.25 / a1 + 0.5 / a0 + 0.25 / a2);
}

/* The coarse face cc of direction d from the fine face array fa: the mean
 * across it of the fine faces it coincides with, each replaced by harmonic3
 * of the three fine faces along the normal when harmonic. */
static inline double coarse_face_mean(const struct level *f, const struct level *c, int d,
                                      const double *fa, const int cc[3], int harmonic)
{
    const struct grid *gf = &f->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
    const int n1 = c->coarse[e1] ? 2 : 1, n2 = c->coarse[e2] ? 2 : 1;
    const ptrdiff_t sd = gf->stride[d];
    double s = 0.0;
    for (int p = 0; p < n1; p++)
        for (int q = 0; q < n2; q++) {
            int fc[3];
            fc[d] = c->coarse[d] ? 2 * cc[d] : cc[d];
            fc[e1] = n1 * cc[e1] + p;
            fc[e2] = n2 * cc[e2] + q;
            const ptrdiff_t pf = grid_idx(gf, fc[0], fc[1], fc[2]);
            s += harmonic ? harmonic3(fa[pf - sd], fa[pf], fa[pf + sd]) : fa[pf];
        }
    return s * (1.0 / (n1 * n2));
}

/* Coarse face coefficients of c from the fine level f: for each coarse face,
 * the mean across the face of the fine lines' values, each line's value being
 * harmonic3 of the three fine faces along the normal (harmonic mode, interior
 * faces of a halved direction) or the coincident fine face (otherwise, and on
 * boundary faces, whose folded-in conditions are linear in a). */
static void coarsen_coefficients(const struct multigrid *mg, const struct level *f,
                                 struct level *c)
{
    const struct grid *gc = &c->g;
    for (int d = 0; d < 3; d++) {
        const int nc = gc->n[d], per = mg->periodic[d];
        int hi[3] = {gc->n[0], gc->n[1], gc->n[2]};
        hi[d] = per ? nc : nc + 1;
        const double *fa = f->a[d];
        double *ca = c->a[d];
        const int harmonic = mg->opt.average == MG_AVERAGE_HARMONIC && c->coarse[d];
#pragma omp parallel for collapse(2) schedule(static) if (c->par)
        for (int I = 0; I < hi[0]; I++)
            for (int J = 0; J < hi[1]; J++)
                for (int K = 0; K < hi[2]; K++) {
                    const int cc[3] = {I, J, K};
                    const int boundary = !per && (cc[d] == 0 || cc[d] == nc);
                    ca[grid_idx(gc, I, J, K)] = coarse_face_mean(f, c, d, fa, cc,
                                                                 harmonic && !boundary);
                }
    }
}

/* Per-level fix-ups once a[] is filled: a periodic direction of one cell
 * couples a cell to itself (no flux: a = 0), face halos, the live mask. */
static void finish_level_coefficients(const struct multigrid *mg, struct level *lv)
{
    const struct grid *g = &lv->g;
    for (int d = 0; d < 3; d++) {
        if (mg->periodic[d] && g->n[d] == 1)
            for (size_t p = 0; p < g->size; p++)
                lv->a[d][p] = 0.0;
        halo_faces(mg, lv, lv->a[d], d);
    }
    const ptrdiff_t sx = g->stride[0], sy = g->stride[1];
    memset(lv->live, 0, g->size); /* ghosts: dead */
#pragma omp parallel for collapse(2) schedule(static) if (lv->par)
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const ptrdiff_t p = grid_idx(g, i, j, k);
                const double D = lv->a[0][p] + lv->a[0][p + sx] + lv->a[1][p] + lv->a[1][p + sy] +
                                 lv->a[2][p] + lv->a[2][p + 1] + (lv->m ? lv->m[p] : 0.0);
                lv->live[p] = D > 0.0;
            }
}

/* ---- the coarsest level: CHOLMOD ----------------------------------------------- */

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

/* Neighbour slot of cell (c) across its face (d, side s = -1/+1) inside the
 * level, wrapping periodic directions; -1 across a non-periodic boundary. */
static ptrdiff_t neighbour_slot(const struct multigrid *mg, const struct grid *g, const int c[3],
                                int d, int s)
{
    int q[3] = {c[0], c[1], c[2]};
    q[d] += s;
    if (q[d] < 0 || q[d] >= g->n[d]) {
        if (!mg->periodic[d])
            return -1;
        q[d] = q[d] < 0 ? g->n[d] - 1 : 0;
    }
    return grid_idx(g, q[0], q[1], q[2]);
}

/* Coupling coefficient w of cell c's face (d, s). */
static double face_weight(const struct level *lv, const int c[3], int d, int s)
{
    const struct grid *g = &lv->g;
    ptrdiff_t p = grid_idx(g, c[0], c[1], c[2]);
    return lv->ih2[d] * lv->a[d][s < 0 ? p : p + g->stride[d]];
}

/* Assembles -L of the coarsest level on its live cells (cs->A) and, when
 * its pattern is new, analyses it; coarse_numeric factorises it.  The
 * analysis (the AMD or METIS ordering) stays on the caller's thread: only
 * the numeric factorisation may run beside other work (multigrid.h,
 * multigrid_finish_operator).  Each connected component of live cells
 * that no Dirichlet face holds is singular (constants): its first cell is
 * pinned to 0 (identity row and column), which leaves the other rows a
 * nonsingular M-matrix and, for a compatible right-hand side, the same
 * solution up to that component's constant. */
static int coarse_assemble(struct multigrid *mg, char *err, size_t errlen)
{
    struct coarse_direct *cs = &mg->cs;
    suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
    struct level *lv = &mg->lev[mg->nlev - 1];
    const struct grid *g = &lv->g;
    long n = 0;
    for (size_t p = 0; p < g->size; p++)
        cs->row[p] = -1;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                if (lv->live[p]) {
                    cs->slot[n] = p;
                    cs->row[p] = (int)n++;
                }
            }
    cs->n = n;
    if (n == 0)
        return 0;
    /* components by breadth-first search; pin the first cell of floating ones */
    for (long r = 0; r < n; r++)
        cs->pinned[r] = 2; /* unvisited */
    for (long r0 = 0; r0 < n; r0++) {
        if (cs->pinned[r0] != 2)
            continue;
        long head = 0, tail = 0;
        int held = 0; /* a Dirichlet face or a mass term holds the component */
        cs->queue[tail++] = (int)r0;
        cs->pinned[r0] = 0;
        while (head < tail) {
            long r = cs->queue[head++];
            ptrdiff_t p = cs->slot[r];
            int c[3];
            c[0] = (int)(p / g->stride[0]) - 1;
            c[1] = (int)((p % g->stride[0]) / g->stride[1]) - 1;
            c[2] = (int)(p % g->stride[1]) - 1;
            if (lv->m && lv->m[p] > 0.0)
                held = 1;
            for (int d = 0; d < 3; d++)
                for (int s = -1; s <= 1; s += 2) {
                    double w = face_weight(lv, c, d, s);
                    if (!(w > 0.0))
                        continue;
                    ptrdiff_t q = neighbour_slot(mg, g, c, d, s);
                    if (q < 0) {
                        held = 1; /* a non-periodic boundary face with a > 0: Dirichlet */
                        continue;
                    }
                    int rq = cs->row[q];
                    if (rq >= 0 && cs->pinned[rq] == 2) {
                        cs->pinned[rq] = 0;
                        cs->queue[tail++] = rq;
                    }
                }
        }
        if (!held)
            cs->pinned[r0] = 1;
    }
    /* upper triangle of -L (stype 1); duplicates (two periodic faces between the
     * same pair of cells) are summed by the conversion */
    size_t nzmax = (size_t)n * 4;
    cholmod_triplet *T = suitesparse.cholmod_allocate_triplet((size_t)n, (size_t)n, nzmax, 1, CHOLMOD_REAL,
                                                  &cs->cm);
    if (!T) {
        set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    int *Ti = T->i, *Tj = T->j;
    double *Tx = T->x;
    size_t nz = 0;
    for (long r = 0; r < n; r++) {
        ptrdiff_t p = cs->slot[r];
        int c[3];
        c[0] = (int)(p / g->stride[0]) - 1;
        c[1] = (int)((p % g->stride[0]) / g->stride[1]) - 1;
        c[2] = (int)(p % g->stride[1]) - 1;
        double D = 0.0;
        for (int d = 0; d < 3; d++)
            for (int s = -1; s <= 1; s += 2) {
                double w = face_weight(lv, c, d, s);
                D += w;
                if (s < 0 || !(w > 0.0))
                    continue;
                ptrdiff_t q = neighbour_slot(mg, g, c, d, s);
                if (q < 0)
                    continue;
                int rq = cs->row[q];
                if (rq < 0 || cs->pinned[r] || cs->pinned[rq])
                    continue;
                Ti[nz] = (int)(r < rq ? r : rq);
                Tj[nz] = (int)(r < rq ? rq : r);
                Tx[nz] = -w;
                nz++;
            }
        if (lv->m)
            D += lv->m[p];
        Ti[nz] = Tj[nz] = (int)r;
        Tx[nz] = cs->pinned[r] ? 1.0 : D;
        nz++;
    }
    T->nnz = nz;
    cholmod_sparse *A = suitesparse.cholmod_triplet_to_sparse(T, nz, &cs->cm);
    suitesparse.cholmod_free_triplet(&T, &cs->cm);
    if (!A) {
        set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    /* The analysis (the fill-reducing ordering, the supernodes) depends on
     * the pattern only, which a new density on the same cells keeps: a
     * coarsest level as large as a whole small grid (pressure.c) is
     * refactorised every step, and analysing it afresh cost as much again. */
    size_t len = (size_t)n + 1 + (size_t)((const int *)A->p)[n];
    int same = cs->L && cs->pattern && cs->pattern_len == len &&
               memcmp(cs->pattern, A->p, ((size_t)n + 1) * sizeof(int)) == 0 &&
               memcmp(cs->pattern + n + 1, A->i, (len - (size_t)n - 1) * sizeof(int)) == 0;
    if (!same) {
        /* and the solves' workspace is set up again after the factorisation */
        suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
        suitesparse.cholmod_free_factor(&cs->L, &cs->cm);
        cs->L = suitesparse.cholmod_analyze(A, &cs->cm);
        free(cs->pattern);
        cs->pattern_len = 0;
        if ((cs->pattern = malloc(len * sizeof(int)))) {
            memcpy(cs->pattern, A->p, ((size_t)n + 1) * sizeof(int));
            memcpy(cs->pattern + n + 1, A->i, (len - (size_t)n - 1) * sizeof(int));
            cs->pattern_len = len;
        }
    }
    cs->A = A;
    if (!cs->L) {
        set_err(err, errlen, "multigrid: the coarsest level's analysis failed (status %d)",
                cs->cm.status);
        return -1;
    }
    return 0;
}

/* The numeric factorisation of what coarse_assemble left in cs->A, and the
 * solves' workspace. */
static int coarse_numeric(struct multigrid *mg, char *err, size_t errlen)
{
    struct coarse_direct *cs = &mg->cs;
    if (cs->n == 0)
        return 0;
    const size_t n = (size_t)cs->n;
    struct suitesparse_serial serial = suitesparse_serial_begin();
    int ok = cs->A && cs->L && suitesparse.cholmod_factorize(cs->A, cs->L, &cs->cm) &&
             cs->cm.status == CHOLMOD_OK;
    suitesparse_serial_end(serial);
    suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
    if (!ok) {
        set_err(err, errlen, "multigrid: the coarsest factorisation failed (status %d)",
                cs->cm.status);
        return -1;
    }
    if (cs->B && cs->X)
        return 0; /* the solves' workspace is the right size already (the pattern's) */
    suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
    cs->B = suitesparse.cholmod_zeros(n, 1, CHOLMOD_REAL, &cs->cm);
    if (!cs->B) {
        set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    /* one solve here lets cholmod_solve2 allocate its workspace (X, Y, E) now */
    serial = suitesparse_serial_begin();
    suitesparse.cholmod_solve2(CHOLMOD_A, cs->L, cs->B, NULL, &cs->X, NULL, &cs->Y, &cs->E, &cs->cm);
    suitesparse_serial_end(serial);
    if (!cs->X) {
        set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    return 0;
}

/* x = L^-1 b on the coarsest level: gather, solve, scatter (a distributed
 * version gathers the coarsest box to one rank here; nowhere else). */
static void coarse_solve(struct multigrid *mg)
{
    struct coarse_direct *cs = &mg->cs;
    struct level *lv = &mg->lev[mg->nlev - 1];
    zero_interior(lv, lv->x);
    if (cs->n == 0)
        return;
    double *B = cs->B->x;
    for (long r = 0; r < cs->n; r++)
        B[r] = cs->pinned[r] ? 0.0 : -lv->b[cs->slot[r]];
    struct suitesparse_serial serial = suitesparse_serial_begin();
    suitesparse.cholmod_solve2(CHOLMOD_A, cs->L, cs->B, NULL, &cs->X, NULL, &cs->Y, &cs->E, &cs->cm);
    suitesparse_serial_end(serial);
    const double *X = cs->X->x;
    for (long r = 0; r < cs->n; r++)
        lv->x[cs->slot[r]] = X[r];
}

/* ---- hierarchy ----------------------------------------------------------------- */

/* Which directions of g to halve: the even ones (never a direction of one
 * cell) whose spacing is within 1.5 of the finest spacing, so that the point
 * smoother never faces an anisotropy beyond 2.25 (1.5^2) that coarsening made;
 * when none qualifies and the level is still large, any even direction (the
 * coarsest solve must stay small).  With full, every even direction: the
 * line smoother takes the anisotropy, and halving one direction of two
 * leaves a W-cycle's second level half as large as the first, visited
 * twice (the heap at 140 x 200, cells of 0.5 x 0.25: the same GMRES
 * iterations of the implicit step, 479 against 478, in 0.79 of the time).
 * Returns how many were chosen. */
static int choose_halving(const struct grid *g, long coarse_cells, int full, int halve[3])
{
    long cells = (long)grid_cells(g);
    halve[0] = halve[1] = halve[2] = 0;
    if (cells <= coarse_cells)
        return 0;
    double hmin = INFINITY;
    for (int d = 0; d < 3; d++)
        if (g->n[d] > 1 && g->h[d] < hmin)
            hmin = g->h[d];
    int count = 0;
    for (int d = 0; d < 3; d++) {
        halve[d] = g->n[d] >= 2 && g->n[d] % 2 == 0 &&
                   (full || g->h[d] <= 1.5 * hmin * (1.0 + 1e-12));
        count += halve[d];
    }
    if (count == 0 && cells > ANISO_CELLS)
        for (int d = 0; d < 3; d++) {
            halve[d] = g->n[d] >= 2 && g->n[d] % 2 == 0;
            count += halve[d];
        }
    return count;
}

static void level_free(struct level *lv, int owns_xb)
{
    field_free(lv->mbuf);
    for (int k = 0; k < 3; k++) {
        field_free(lv->lc[k]);
        field_free(lv->li[k]);
    }
    for (int d = 0; d < 3; d++) {
        field_free(lv->a[d]);
        free(lv->pi[d]);
        field_free(lv->pw[d]);
    }
    free(lv->live);
    field_free(lv->kbuf[0]);
    field_free(lv->kbuf[1]);
    field_free(lv->r);
    field_free(lv->bbuf);
    if (owns_xb)
        field_free(lv->x);
}

void multigrid_destroy(struct multigrid *mg)
{
    if (!mg)
        return;
    for (int l = 0; l < mg->nlev; l++)
        level_free(&mg->lev[l], l > 0);
    free(mg->mxbuf);
    struct coarse_direct *cs = &mg->cs;
    if (cs->started) {
        suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
        suitesparse.cholmod_free_factor(&cs->L, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->X, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->Y, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->E, &cs->cm);
        suitesparse.cholmod_finish(&cs->cm);
    }
    free(cs->slot);
    free(cs->row);
    free(cs->pinned);
    free(cs->queue);
    free(cs->pattern);
    field_free(mg->wr);
    field_free(mg->wz);
    field_free(mg->wp);
    field_free(mg->wq);
    field_free(mg->wbest);
    free(mg);
}

/* Prolongation tables of fine level f from coarse level c (see struct level). */
static int build_prolongation(struct level *f, const struct level *c)
{
    for (int d = 0; d < 3; d++) {
        const int n = f->g.n[d];
        f->pi[d] = malloc(2 * (size_t)n * sizeof(int));
        if (!f->pi[d])
            return -1;
        for (int i = 0; i < n; i++) {
            int *ci = f->pi[d] + 2 * i;
            if (!c->coarse[d]) {
                ci[0] = ci[1] = i;
            } else {
                ci[0] = i / 2;
                ci[1] = (i & 1) ? i / 2 + 1 : i / 2 - 1;
            }
        }
        /* a direction not halved has w = 0 (field_alloc zeroes), kept as an
         * array so that the transfer loops have no branches */
        if (!(f->pw[d] = field_alloc(&f->g)))
            return -1;
    }
    return 0;
}

double multigrid_memory_estimate(const struct grid *g, const struct multigrid_options *opt)
{
    struct multigrid_options o;
    if (opt)
        o = *opt;
    else
        multigrid_default_options(&o);
    /* the levels as multigrid_create builds them */
    struct grid lev[MAX_LEVELS];
    lev[0] = *g;
    int nlev = 1;
    while (nlev < MAX_LEVELS) {
        int halve[3], n[3];
        if (choose_halving(&lev[nlev - 1], o.coarse_cells, o.full_coarsening, halve) == 0)
            break;
        for (int d = 0; d < 3; d++)
            n[d] = halve[d] ? lev[nlev - 1].n[d] / 2 : lev[nlev - 1].n[d];
        if (grid_init(&lev[nlev], n, lev[nlev - 1].len) != 0)
            break;
        nlev++;
    }
    int lines = 0;
    for (int d = 0; d < 3; d++)
        lines += o.smoother == MG_SMOOTH_LINES && g->n[d] > 1;
    double bytes = 0.0;
    for (int l = 0; l < nlev; l++) {
        double points = (double)lev[l].size;
        /* a[3] and r; x and b below the finest; the prolongation's weights
         * above the coarsest; the line factors on all but the coarsest */
        double arrays = 4.0 + (l > 0 ? 2.0 : 0.0) + (l < nlev - 1 ? 3.0 + 2.0 * lines : 0.0);
        bytes += (arrays * sizeof(double) + 1.0) * points; /* and live */
    }
    bytes += 5.0 * (double)g->size * sizeof(double); /* the Krylov work arrays */
    double coarse = (double)grid_cells(&lev[nlev - 1]);
    bytes += (double)lev[nlev - 1].size * (sizeof(ptrdiff_t) + 2.0 * sizeof(int) + 1.0);
    bytes += coarse * (4.0 * log2(coarse + 1.0) + 10.0) * (sizeof(double) + sizeof(int));
    return bytes;
}

int multigrid_create(struct multigrid **out, const struct grid *g, const enum poisson_bc bc[3][2],
                     const struct multigrid_options *opt, char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || !g || !bc) {
        set_err(err, errlen, "multigrid: missing argument");
        return -1;
    }
    if (suitesparse_load(err, errlen) != 0) /* the coarsest level's factorisation */
        return -1;
    for (int d = 0; d < 3; d++) {
        if (g->n[d] < 1 || !(g->h[d] > 0.0) || !isfinite(g->h[d])) {
            set_err(err, errlen, "multigrid: invalid grid in direction %c", "xyz"[d]);
            return -1;
        }
        for (int s = 0; s < 2; s++)
            if ((int)bc[d][s] < (int)POISSON_PERIODIC || (int)bc[d][s] > (int)POISSON_DIRICHLET) {
                set_err(err, errlen, "multigrid: invalid condition %d in direction %c",
                        (int)bc[d][s], "xyz"[d]);
                return -1;
            }
        if ((bc[d][0] == POISSON_PERIODIC) != (bc[d][1] == POISSON_PERIODIC)) {
            set_err(err, errlen, "multigrid: periodic must be on both faces of direction %c",
                    "xyz"[d]);
            return -1;
        }
    }
    if ((size_t)grid_cells(g) >= (size_t)INT32_MAX) {
        set_err(err, errlen, "multigrid: grid too large");
        return -1;
    }
    struct multigrid *mg = calloc(1, sizeof(*mg));
    if (!mg) {
        set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    if (opt)
        mg->opt = *opt;
    else
        multigrid_default_options(&mg->opt);
    if (mg->opt.gamma < 1 || mg->opt.gamma > 2) {
        free(mg);
        set_err(err, errlen, "multigrid: gamma must be 1 (V-cycle) or 2 (W-cycle)");
        return -1;
    }
    if (mg->opt.pre < 0 || mg->opt.post < 0 || mg->opt.pre + mg->opt.post < 1) {
        free(mg);
        set_err(err, errlen, "multigrid: need at least one smoothing sweep");
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        mg->bc[d][0] = bc[d][0];
        mg->bc[d][1] = bc[d][1];
        mg->periodic[d] = bc[d][0] == POISSON_PERIODIC;
    }

    /* the levels */
    mg->lev[0].g = *g;
    mg->nlev = 1;
    while (mg->nlev < MAX_LEVELS) {
        const struct grid *gf = &mg->lev[mg->nlev - 1].g;
        int halve[3];
        if (choose_halving(gf, mg->opt.coarse_cells, mg->opt.full_coarsening, halve) == 0)
            break;
        int n[3];
        for (int d = 0; d < 3; d++)
            n[d] = halve[d] ? gf->n[d] / 2 : gf->n[d];
        struct level *lc = &mg->lev[mg->nlev];
        if (grid_init(&lc->g, n, gf->len) != 0)
            break;
        for (int d = 0; d < 3; d++)
            lc->coarse[d] = halve[d];
        mg->nlev++;
    }
    int ok = 1;
    for (int l = 0; l < mg->nlev && ok; l++) {
        struct level *lv = &mg->lev[l];
        lv->par = grid_cells(&lv->g) >= PAR_CELLS;
        lv->flat = -1;
        for (int d = 2; d >= 0; d--)
            if (mg->periodic[d] && lv->g.n[d] == 1)
                lv->flat = d;
        for (int d = 0; d < 3; d++) {
            lv->ih2[d] = 1.0 / (lv->g.h[d] * lv->g.h[d]);
            ok &= (lv->a[d] = field_alloc(&lv->g)) != NULL;
        }
        ok &= (lv->live = calloc(lv->g.size, 1)) != NULL;
        ok &= (lv->r = field_alloc(&lv->g)) != NULL;
        if (l > 0) {
            ok &= (lv->x = field_alloc(&lv->g)) != NULL;
            ok &= (lv->bbuf = field_alloc(&lv->g)) != NULL;
            lv->b = lv->bbuf;
            if (ok)
                ok &= build_prolongation(&mg->lev[l - 1], lv) == 0;
        }
    }
    if (ok && mg->opt.smoother == MG_SMOOTH_LINES) {
        /* lines along every direction that is not periodic and has cells to
         * couple; none (a periodic box): the point smoother */
        for (int d = 0; d < 3; d++)
            if (!mg->periodic[d] && g->n[d] > 1)
                mg->line_dirs[mg->nline_dirs++] = d;
        /* the coarsest level is solved, not smoothed: no factors there */
        for (int l = 0; l < mg->nlev - 1 && ok; l++)
            for (int k = 0; k < mg->nline_dirs; k++)
                ok &= (mg->lev[l].lc[k] = field_alloc(&mg->lev[l].g)) != NULL &&
                      (mg->lev[l].li[k] = field_alloc(&mg->lev[l].g)) != NULL;
    }
    ok = ok && (mg->wr = field_alloc(g)) && (mg->wz = field_alloc(g)) && (mg->wp = field_alloc(g)) &&
         (mg->wq = field_alloc(g)) && (mg->wbest = field_alloc(g));
    struct coarse_direct *cs = &mg->cs;
    const size_t csize = mg->lev[mg->nlev - 1].g.size;
    if (ok) {
        cs->slot = malloc(csize * sizeof(ptrdiff_t));
        cs->row = malloc(csize * sizeof(int));
        cs->pinned = malloc(csize);
        cs->queue = malloc(csize * sizeof(int));
        ok = cs->slot && cs->row && cs->pinned && cs->queue;
    }
    if (ok) {
        suitesparse_cholmod_start(&cs->cm);
        cs->started = 1;
        cs->cm.error_handler = quiet_handler;
        cs->cm.print = 0;
        if (mg->opt.coarse_simplicial)
            cs->cm.supernodal = CHOLMOD_SIMPLICIAL;
    }
    if (!ok) {
        multigrid_destroy(mg);
        set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    *out = mg;
    return 0;
}

/* The mass term of every level: level 0's copied from mass (>= 0 and finite
 * on the interior), each coarser one the mean of its children, the scaling
 * of the restriction (a constant residual restricts to itself), so the
 * coarse operator stays the rediscretised L - m.  mass NULL: none. */
static int set_mass(struct multigrid *mg, const double *mass, char *err, size_t errlen)
{
    for (int l = 0; l < mg->nlev; l++) {
        struct level *lv = &mg->lev[l];
        lv->m = NULL;
        if (mass && !lv->mbuf && !(lv->mbuf = field_alloc(&lv->g))) {
            set_err(err, errlen, "multigrid: out of memory (mass term)");
            return -1;
        }
    }
    if (!mass)
        return 0;
    const struct grid *g = &mg->lev[0].g;
    double *m0 = mg->lev[0].mbuf;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const ptrdiff_t p = grid_idx(g, i, j, k);
                if (!(mass[p] >= 0.0) || !isfinite(mass[p])) {
                    set_err(err, errlen, "multigrid: mass term %g in cell (%d,%d,%d)", mass[p], i,
                            j, k);
                    return -1;
                }
                m0[p] = mass[p];
            }
    for (int l = 1; l < mg->nlev; l++) {
        const struct level *f = &mg->lev[l - 1];
        struct level *c = &mg->lev[l];
        const int n0 = c->coarse[0] ? 2 : 1, n1 = c->coarse[1] ? 2 : 1, n2 = c->coarse[2] ? 2 : 1;
        const double inv = 1.0 / (n0 * n1 * n2);
        for (int I = 0; I < c->g.n[0]; I++)
            for (int J = 0; J < c->g.n[1]; J++)
                for (int K = 0; K < c->g.n[2]; K++) {
                    double sum = 0.0;
                    for (int a = 0; a < n0; a++)
                        for (int b = 0; b < n1; b++)
                            for (int q = 0; q < n2; q++)
                                sum += f->mbuf[grid_idx(&f->g, n0 * I + a, n1 * J + b, n2 * K + q)];
                    c->mbuf[grid_idx(&c->g, I, J, K)] = sum * inv;
                }
    }
    for (int l = 0; l < mg->nlev; l++)
        mg->lev[l].m = mg->lev[l].mbuf;
    return 0;
}

/* Face array km of direction d on level c from level f: the mean of the
 * fine faces each coarse face coincides with (boundary faces 0). */
static void coarsen_mixed(const struct level *f, struct level *c, int t)
{
    const int d = c->md[t];
    const struct grid *gc = &c->g;
    double *ck = c->kbuf[t];
    for (int I = 0; I < gc->n[0]; I++)
        for (int J = 0; J < gc->n[1]; J++)
            for (int K = 0; K < gc->n[2]; K++) {
                const int cc[3] = {I, J, K};
                ck[grid_idx(gc, I, J, K)] = cc[d] == 0 ? 0.0 : coarse_face_mean(f, c, d,
                                                                              f->km[t], cc, 0);
            }
}

int multigrid_set_mixed(struct multigrid *mg, int d1, int d2, const double *k1, const double *k2,
                        char *err, size_t errlen)
{
    for (int l = 0; l < mg->nlev; l++)
        mg->lev[l].km[0] = mg->lev[l].km[1] = NULL;
    if (!k1 || !k2)
        return 0;
    const struct grid *g = &mg->lev[0].g;
    if (d1 == d2 || d1 < 0 || d1 > 2 || d2 < 0 || d2 > 2 || mg->periodic[d1] ||
        mg->periodic[d2]) {
        set_err(err, errlen, "multigrid: the mixed term needs two bounded directions");
        return -1;
    }
    const int md[2] = {d1, d2};
    int longest = 0;
    for (int d = 0; d < 3; d++)
        longest = g->n[d] > longest ? g->n[d] : longest;
#ifdef _OPENMP
    const int nt = omp_get_max_threads();
#else
    const int nt = 1;
#endif
    if (!mg->mxbuf) {
        mg->mxlen = longest;
        if (!(mg->mxbuf = malloc(2 * (size_t)longest * (size_t)nt * sizeof(double)))) {
            set_err(err, errlen, "multigrid: out of memory (mixed term)");
            return -1;
        }
    }
    for (int l = 0; l < mg->nlev; l++) {
        struct level *lv = &mg->lev[l];
        for (int t = 0; t < 2; t++) {
            lv->md[t] = md[t];
            if (!lv->kbuf[t] && !(lv->kbuf[t] = field_alloc(&lv->g))) {
                set_err(err, errlen, "multigrid: out of memory (mixed term)");
                return -1;
            }
        }
    }
    struct level *l0 = &mg->lev[0];
    for (int t = 0; t < 2; t++) {
        const double *src = t ? k2 : k1;
        const int d = md[t], n = g->n[d];
        for (size_t p = 0; p < g->size; p++)
            l0->kbuf[t][p] = 0.0;
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    const int c[3] = {i, j, k};
                    const ptrdiff_t p = grid_idx(g, i, j, k);
                    if (c[d] == 0 || c[d] == n)
                        continue;
                    if (!isfinite(src[p])) {
                        set_err(err, errlen, "multigrid: mixed coefficient %g on face (%d,%d,%d)",
                                src[p], i, j, k);
                        return -1;
                    }
                    l0->kbuf[t][p] = src[p];
                }
        l0->km[t] = l0->kbuf[t];
    }
    for (int l = 1; l < mg->nlev; l++)
        for (int t = 0; t < 2; t++) {
            struct level *c = &mg->lev[l];
            c->km[t] = c->kbuf[t];
            coarsen_mixed(&mg->lev[l - 1], c, t);
        }
    return 0;
}

int multigrid_set_coefficients(struct multigrid *mg, double *const a[3], char *err,
                               size_t errlen)
{
    return multigrid_set_operator(mg, a, NULL, err, errlen);
}

int multigrid_set_operator(struct multigrid *mg, double *const a[3], const double *mass,
                           char *err, size_t errlen)
{
    if (multigrid_set_operator_deferred(mg, a, mass, err, errlen) != 0)
        return -1;
    return multigrid_finish_operator(mg, err, errlen);
}

int multigrid_set_operator_deferred(struct multigrid *mg, double *const a[3], const double *mass,
                                    char *err, size_t errlen)
{
    struct level *l0 = &mg->lev[0];
    const struct grid *g = &l0->g;
    mg->ready = 0;
    mg->pending = 0;
    if (set_mass(mg, mass, err, errlen) != 0)
        return -1;
    for (int d = 0; d < 3; d++) {
        const int n = g->n[d], per = mg->periodic[d];
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[d] = per ? n : n + 1; /* the faces read: a periodic direction's face n is face 0 */
        const double *src = a[d];
        double *dst = l0->a[d];
        long bad = -1;
#pragma omp parallel for collapse(2) schedule(static) if (l0->par) reduction(max : bad)
        for (int i = 0; i < hi[0]; i++)
            for (int j = 0; j < hi[1]; j++)
                for (int k = 0; k < hi[2]; k++) {
                    const int c[3] = {i, j, k}, t = c[d];
                    const ptrdiff_t p = grid_idx(g, i, j, k);
                    const int boundary = !per && (t == 0 || t == n);
                    double val = src[p];
                    if (boundary && mg->bc[d][t == 0 ? 0 : 1] == POISSON_NEUMANN)
                        val = 0.0; /* not read */
                    else if (!(val >= 0.0) || !isfinite(val))
                        bad = p > bad ? p : bad;
                    else if (boundary)
                        val *= 2.0; /* Dirichlet: half a cell from the centre to the face */
                    dst[p] = val;
                }
        if (bad >= 0) {
            const int i = (int)(bad / g->stride[0]) - 1;
            const int j = (int)((bad % g->stride[0]) / g->stride[1]) - 1;
            const int k = (int)(bad % g->stride[1]) - 1;
            set_err(err, errlen, "multigrid: coefficient %g on face (%d,%d,%d) of direction %c",
                    src[bad], i, j, k, "xyz"[d]);
            return -1;
        }
    }
    finish_level_coefficients(mg, l0);
    for (int l = 1; l < mg->nlev; l++) {
        coarsen_coefficients(mg, &mg->lev[l - 1], &mg->lev[l]);
        finish_level_coefficients(mg, &mg->lev[l]);
        transfer_weights(mg, &mg->lev[l - 1], &mg->lev[l]);
    }
    long live = 0;
#pragma omp parallel for schedule(static) if (l0->par) reduction(+ : live)
    for (size_t p = 0; p < g->size; p++)
        live += l0->live[p];
    mg->live = live;
    if (coarse_assemble(mg, err, errlen) != 0)
        return -1;
    mg->pending = 1;
    return 0;
}

int multigrid_finish_operator(struct multigrid *mg, char *err, size_t errlen)
{
    if (!mg->pending)
        return 0;
    mg->pending = 0;
    if (coarse_numeric(mg, err, errlen) != 0)
        return -1;
    if (mg->opt.smoother == MG_SMOOTH_LINES)
        for (int l = 0; l < mg->nlev - 1; l++)
            for (int k = 0; k < mg->nline_dirs; k++)
                line_factors(&mg->lev[l], k, mg->line_dirs[k]);
    mg->ready = 1;
    return 0;
}

int multigrid_pending(const struct multigrid *mg)
{
    return mg->pending;
}

/* ---- cycles and solvers -------------------------------------------------------- */

/* Whether the operator's halo of level lv changes as its interior does: a
 * periodic direction of two or more cells wraps values around; every other
 * ghost the operator reads is 0 (HALO_OPERATOR), and the smoothers write
 * interior cells only, so once filled it stays filled. */
static int halo_wraps(const struct multigrid *mg, const struct level *lv)
{
    for (int d = 0; d < 3; d++)
        if (mg->periodic[d] && lv->g.n[d] > 1)
            return 1;
    return 0;
}

/* Called by every thread of a team (or outside any parallel region): the
 * kernels are orphaned worksharing loops, whose implicit barriers order the
 * half sweeps and their halo fills.  The halo is filled before each half
 * sweep where it wraps, else once (a line-smoothed cross-section: three
 * fills of four saved, 9 % of a cycle's instructions). */
static void smooth(const struct multigrid *mg, const struct level *lv, int first_colour,
                   int sweeps)
{
    const int wraps = halo_wraps(mg, lv);
    if (!wraps)
        halo_fill(mg, lv, lv->x, HALO_OPERATOR);
    if (mg->opt.smoother == MG_SMOOTH_LINES && mg->nline_dirs > 0) {
        /* the post-smoother (first_colour 1) runs the pre-smoother's half
         * sweeps in reverse order: its adjoint, so the cycle stays symmetric */
        const int nd = mg->nline_dirs;
        /* split_finest: the finest level's pre-smoother takes the lines
         * of direction 1, its post-smoother those of direction 0 */
        const int only = mg->opt.split_finest && nd == 2 && lv == &mg->lev[0]
                             ? (first_colour ? 0 : 1)
                             : -1;
        for (int s = 0; s < sweeps; s++)
            for (int q = 0; q < 2 * nd; q++) {
                const int k = first_colour ? 2 * nd - 1 - q : q;
                if (only >= 0 && k / 2 != only)
                    continue;
                if (wraps)
                    halo_fill(mg, lv, lv->x, HALO_OPERATOR);
                smooth_lines(mg, lv, k / 2, mg->line_dirs[k / 2], k & 1);
            }
        return;
    }
    for (int s = 0; s < sweeps; s++)
        for (int c = 0; c < 2; c++) {
            if (wraps)
                halo_fill(mg, lv, lv->x, HALO_OPERATOR);
            smooth_colour(lv, first_colour ^ c);
        }
}

/* Cycle on level l from x = 0 (warm: from the current x): pre-smoothing red
 * then black, post-smoothing black then red (the adjoint order), restriction
 * the scaled transpose of the prolongation, gamma cycles on the next level
 * (1: V, 2: W; the later ones warm), an exact coarsest solve: a symmetric
 * linear map of b. */
static void cycle_from(struct multigrid *mg, int l, int warm)
{
    struct level *lv = &mg->lev[l];
    if (l == mg->nlev - 1) {
        coarse_solve(mg);
        return;
    }
    struct level *lc = &mg->lev[l + 1];
    /* two parallel regions per level and cycle: fork/join costs more than the
     * loops of a small level, and much more on a loaded machine */
    REGION(lv->par, {
        if (!warm)
            zero_interior(lv, lv->x);
        smooth(mg, lv, 0, mg->opt.pre);
        if (halo_wraps(mg, lv))
            halo_fill(mg, lv, lv->x, HALO_OPERATOR);
        residual(lv, lv->x, lv->b, 0.0, lv->r);
        halo_fill(mg, lv, lv->r, HALO_MIRROR);
        restrict_residual(mg, lv, lc);
    });
    const int visits = l + 1 == mg->nlev - 1 ? 1 : mg->opt.gamma; /* exact there */
    for (int v = 0; v < visits; v++)
        cycle_from(mg, l + 1, v > 0);
    REGION(lv->par, {
        halo_fill(mg, lc, lc->x, HALO_MIRROR);
        prolong_add(lv, lc);
        smooth(mg, lv, 1, mg->opt.post);
    });
}

void multigrid_cycle(struct multigrid *mg, const double *r, double *z)
{
    mg->lev[0].b = r;
    mg->lev[0].x = z;
    cycle_from(mg, 0, 0);
    mg->lev[0].b = NULL;
    mg->lev[0].x = NULL;
}

void multigrid_apply(struct multigrid *mg, double *x, double *y)
{
    REGION(mg->lev[0].par, {
        halo_fill(mg, &mg->lev[0], x, HALO_OPERATOR);
        residual(&mg->lev[0], x, NULL, 0.0, y);
    });
}

/* r = rhs - shift - L phi (phi's ghosts filled here) */
static void fine_residual(struct multigrid *mg, double *phi, const double *rhs, double shift,
                          double *r)
{
    REGION(mg->lev[0].par, {
        halo_fill(mg, &mg->lev[0], phi, HALO_OPERATOR);
        residual(&mg->lev[0], phi, rhs, shift, r);
    });
}

static int singular(const struct multigrid *mg)
{
    if (mg->lev[0].m)
        return 0; /* a mass term: a component without mass or Dirichlet face is pinned
                     (coarse_assemble) */
    for (int d = 0; d < 3; d++)
        if (mg->bc[d][0] == POISSON_DIRICHLET || mg->bc[d][1] == POISSON_DIRICHLET)
            return 0;
    return 1;
}

/* Mean of rhs over the live cells for a singular problem (else 0). */
static double rhs_shift(struct multigrid *mg, const double *rhs)
{
    if (!singular(mg) || mg->live == 0)
        return 0.0;
    return live_sum(mg, &mg->lev[0], rhs) / (double)mg->live;
}

/* phi: dead cells 0, zero mean over the live cells when singular, ghosts
 * holding the conditions' values. */
static void finish_phi(struct multigrid *mg, double *phi)
{
    struct level *l0 = &mg->lev[0];
    const double m = singular(mg) && mg->live ? live_sum(mg, l0, phi) / (double)mg->live : 0.0;
    const struct grid *g = &l0->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const unsigned char *live = l0->live;
    REGION(l0->par, {
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++)
                    phi[row + k] = live[row + k] ? phi[row + k] - m : 0.0;
            }
        halo_fill(mg, l0, phi, HALO_RESULT);
    });
}

static void stats_init(struct multigrid_stats *st, double res0)
{
    memset(st, 0, sizeof(*st));
    st->res0 = res0;
    st->rel = 1.0;
    st->rate = 0.0;
}

static void stats_step(struct multigrid_stats *st, double rel)
{
    if (st->cycles < MULTIGRID_HISTORY) {
        st->history[st->cycles] = rel;
        st->reduction[st->cycles] = st->rel > 0.0 ? rel / st->rel : 0.0;
    }
    st->cycles++;
    st->rel = rel;
}

static int stats_end(struct multigrid_stats *st, double rtol, struct multigrid_stats *out)
{
    st->converged = st->rel <= rtol || st->roundoff;
    st->rate = st->cycles > 0 && st->rel > 0.0 ? pow(st->rel, 1.0 / st->cycles) : 0.0;
    if (!isfinite(st->rel))
        st->rate = INFINITY; /* diverged */
    if (out)
        *out = *st;
    return st->converged ? 0 : 1;
}

/* x += z on the interior */
static void add_to(const struct level *lv, double *x, const double *z)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                x[row + k] += z[row + k];
        }
}

/* What both solves start with: no coefficients (-1 into *rc), or the
 * shifted rhs's norm; a zero rhs is solved by phi = 0 (its result into
 * *rc).  Returns 1 when *rc is the solve's answer, 0 to go on. */
static int solve_begin(struct multigrid *mg, const double *rhs, double *phi, double rtol,
                       struct multigrid_stats *stats, struct multigrid_stats *st,
                       double *shift, double *res0, int *rc)
{
    if (!mg->ready) { /* no (valid) coefficients */
        if (stats)
            memset(stats, 0, sizeof(*stats));
        *rc = -1;
        return 1;
    }
    struct level *l0 = &mg->lev[0];
    *shift = rhs_shift(mg, rhs);
    *res0 = sqrt(live_norm2(mg, l0, rhs, *shift));
    stats_init(st, *res0);
    if (!(*res0 > 0.0)) {
        REGION(l0->par, zero_interior(l0, phi));
        st->rel = 0.0;
        finish_phi(mg, phi);
        *rc = stats_end(st, rtol, stats);
        return 1;
    }
    return 0;
}

int multigrid_solve(struct multigrid *mg, const double *rhs, double *phi, double rtol,
                    int max_cycles, struct multigrid_stats *stats)
{
    struct level *l0 = &mg->lev[0];
    struct multigrid_stats st;
    double shift, res0;
    int rc;
    if (solve_begin(mg, rhs, phi, rtol, stats, &st, &shift, &res0, &rc))
        return rc;
    fine_residual(mg, phi, rhs, shift, mg->wr);
    st.rel = sqrt(dot(mg, l0, mg->wr, mg->wr)) / res0;
    while (st.rel > rtol && st.cycles < max_cycles) {
        multigrid_cycle(mg, mg->wr, mg->wz);
        REGION(l0->par, add_to(l0, phi, mg->wz));
        fine_residual(mg, phi, rhs, shift, mg->wr);
        stats_step(&st, sqrt(dot(mg, l0, mg->wr, mg->wr)) / res0);
    }
    finish_phi(mg, phi);
    return stats_end(&st, rtol, stats);
}

/* x += alpha p, r -= alpha q; returns r.r */
static double cg_update(struct multigrid *mg, const struct level *lv, double alpha, double *x,
                        const double *p, double *r, const double *q)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2], nt = team_size(lv);
    double *part = mg->partial;
    for (int t = 0; t < nt; t++)
        part[t * PAD] = 0.0;
    REGION_NT({
        double s = 0.0;
        _Pragma("omp for collapse(2) schedule(static)")
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++) {
                const ptrdiff_t row = grid_idx(g, i, j, 0);
                for (int k = 0; k < nz; k++) {
                    x[row + k] += alpha * p[row + k];
                    double rv = r[row + k] - alpha * q[row + k];
                    r[row + k] = rv;
                    s += rv * rv;
                }
            }
        part[thread_id() * PAD] = s;
    });
    return sum_partials(part, nt);
}

/* p = z + beta p */
static void cg_direction(const struct level *lv, double beta, double *p, const double *z)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                p[row + k] = z[row + k] + beta * p[row + k];
        }
}

int multigrid_pcg(struct multigrid *mg, const double *rhs, double *phi, double rtol, int max_iter,
                  struct multigrid_stats *stats)
{
    struct level *l0 = &mg->lev[0];
    struct multigrid_stats st;
    double shift, res0;
    int rc;
    if (solve_begin(mg, rhs, phi, rtol, stats, &st, &shift, &res0, &rc))
        return rc;
    double *r = mg->wr, *z = mg->wz, *p = mg->wp, *q = mg->wq;
    fine_residual(mg, phi, rhs, shift, r);
    st.rel = sqrt(dot(mg, l0, r, r)) / res0;
    if (st.rel > rtol && st.rel < 1e3 * rtol) {
        /* close to the tolerance from a previous iterate (a restart): within
         * what the residual's own rounding allows, CG can do no better */
        REGION(l0->par, magnitude(l0, phi, rhs, shift, q));
        const double floor = ROUNDOFF_TERMS * DBL_EPSILON * sqrt(dot(mg, l0, q, q));
        if (st.rel * res0 <= floor) {
            finish_phi(mg, phi);
            st.roundoff = 1;
            return stats_end(&st, rtol, stats);
        }
    }
    if (st.rel > rtol) {
        multigrid_cycle(mg, r, z);
        REGION(l0->par, cg_direction(l0, 0.0, p, z));
        double rz = dot(mg, l0, r, z);
        double best = st.rel;
        memcpy(mg->wbest, phi, l0->g.size * sizeof(double));
        /* L and the cycle are both negative definite on the live cells: CG's
         * iterates are those of the positive problem (-L, -V) */
        while (st.cycles < max_iter && rz != 0.0) {
            multigrid_apply(mg, p, q);
            const double pq = dot(mg, l0, p, q);
            if (pq == 0.0)
                break;
            const double alpha = rz / pq;
            const double rr = cg_update(mg, l0, alpha, phi, p, r, q);
            stats_step(&st, sqrt(rr) / res0);
            if (st.rel <= rtol)
                break;
            /* At the round-off of the operator (a relative residual of about
             * 1e-12 with the coefficient contrast 1e3 of the column
             * collapse) the recursive residual stops falling and then grows
             * by orders of magnitude: measured there, 1.5e-12 after 10
             * iterations, 1e-5 twenty later, and the cap of 500 with
             * nothing gained, four restarts in a row.  Stopped where it has
             * grown well above its best, it returns the iterate of its best
             * residual, from which the caller restarts with a fresh one. */
            if (st.rel < best) {
                best = st.rel;
                memcpy(mg->wbest, phi, l0->g.size * sizeof(double));
            } else if (st.rel > PCG_GROWTH * best) {
                memcpy(phi, mg->wbest, l0->g.size * sizeof(double));
                st.rel = best;
                break;
            }
            multigrid_cycle(mg, r, z);
            const double rz_new = dot(mg, l0, r, z);
            REGION(l0->par, cg_direction(l0, rz_new / rz, p, z));
            rz = rz_new;
        }
    }
    finish_phi(mg, phi);
    return stats_end(&st, rtol, stats);
}

/* ---- information --------------------------------------------------------------- */

int multigrid_levels(const struct multigrid *mg)
{
    return mg->nlev;
}

void multigrid_level_size(const struct multigrid *mg, int l, int n[3])
{
    for (int d = 0; d < 3; d++)
        n[d] = mg->lev[l].g.n[d];
}

size_t multigrid_bytes(const struct multigrid *mg)
{
    size_t b = 0;
    for (int l = 0; l < mg->nlev; l++) {
        const struct level *lv = &mg->lev[l];
        size_t f = lv->g.size * sizeof(double);
        b += 4 * f + lv->g.size; /* a[3], r, live */
        if (lv->mbuf)
            b += f;
        for (int k = 0; k < mg->nline_dirs; k++)
            b += lv->lc[k] ? 2 * f : 0;
        if (l > 0)
            b += 2 * f; /* x, b */
        for (int d = 0; d < 3; d++)
            b += 2 * (size_t)lv->g.n[d] * sizeof(int) + (lv->pw[d] ? f : 0); /* pw: not on the coarsest */
    }
    b += 4 * mg->lev[0].g.size * sizeof(double); /* solver work arrays */
    const size_t cs = mg->lev[mg->nlev - 1].g.size;
    b += cs * (sizeof(ptrdiff_t) + 2 * sizeof(int) + 1);
    if (mg->cs.started)
        b += mg->cs.cm.memory_inuse;
    return b;
}
