/* Plane Fourier modes times line blocks (fourier_lines.h). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fftw3.h>
#include "kernels/kernels.h"
#include "platform/fft_ranks.h"
#include "solvers/block_slabs.h"
#include "solvers/fourier_lines.h"
/* last: its macro I would clash with the rheology's parameter names, and
 * FFTW's complex stays double[2] */
#include <complex.h>

/* Nodes reached along a line by the symmetric operator (the per-component
 * tangent and the grad-div term: u of cell m meets w of the faces below and
 * above it).  The line blocks take 2 for the full tangent, which CG never
 * sees; one node less shortens the probes from 5 combs to 3 and the band
 * from 8 to 5. */
#define BAND 1
#define PROBES (2 * BAND + 1)
#define PATTERNS 4               /* plane wavenumbers (0,0), (pi,0), (0,pi), (pi,pi) */
/* unknowns interleaved by line node, (u, v, w) at node m are 3m, 3m+1, 3m+2:
 * a coupling of nodes m and m + BAND lies within this band */
#define KB (3 * BAND + 2)
/* a general block's columns: KB entries above the diagonal, KB below */
#define KW (2 * KB + 1)

typedef double complex cplx;

struct fourier_lines {
    const struct grid *g;
    int L, o[2];                 /* line direction, the two periodic ones across */
    int n[2], half0;             /* cells across (the global grid's); n[0] / 2 + 1 */
    int nl[2], first[2];         /* this rank's lines across and the first's global index */
    long lines[PATTERNS];        /* the lines each pattern's averages count */
    int len[3], lo[3][3];        /* nodes per line (0: none) and box corner per component */
    int maxlen, nu;              /* longest line, unknowns per mode (3 maxlen) */
    long modes;                  /* the real transform's wavenumbers (this rank's) */
    /* sym[((P * 3 + row) * 3 + col) * maxlen * PROBES + m * PROBES + off + BAND]:
     * the plane average of row m's coupling to column node m + off, at the
     * plane wavenumber of pattern P */
    double *sym;
    double *part;                /* nl[1] x maxlen partial sums of the averages */
    /* An open face makes the operator non-symmetric: the increment's fill
     * gives the face's normal component the inner face's (boundary.c), and
     * the edges on the face couple the tangential rows below to it with no
     * row of its own to return the coupling.  Its blocks are then general
     * (a banded LU) and the Krylov method BiCGStab; else Hermitian
     * (a banded Cholesky) for CG. */
    int general;
    int width;                   /* entries a block column keeps: KB + 1, or KW */
    cplx *band;                  /* modes x nu x width: the factors, column-wise */
    /* the spectra, mode-major: mode s's unknowns at spec[s * nu + 3 m + c],
     * as its block numbers them (the transforms write and read them there) */
    fftw_complex *spec;
    fftw_plan fwd[3], bwd[3];    /* per component: every plane of its box at once */
    /* Over ranks (bc->dc; fwd[0], bwd[0] then FFTW's MPI plans of every
     * component): FFTW's 2D transform of nu interleaved values a line, its
     * slabs along across direction o[fa], its output's wavenumbers split
     * along the other, the longer one's half spectrum: the modes, and so the
     * blocks, spread over the ranks.  The lines go from the blocks (box:
     * o[fa] slowest, then o[1 - fa], then the line's nu values) to the slabs
     * and back by one all-to-all each way; spec is then buf's.  aligned:
     * every rank's block of lines is its slab (split along o[fa] alone, as
     * FFTW's blocks), written and read in buf directly, no all-to-all. */
    const struct decomp *dc;
    int fa, aligned;
    struct fft_ranks_slab slab;
    struct block_slabs xs;
    double *buf, *box;
};

static inline int probe_offset(int r, int m)
{
    int off = ((r - m) % PROBES + PROBES) % PROBES;
    return off > BAND ? off - PROBES : off;
}

/* Grid index of node m of line (a, b) of component c (a along o[0]). */
static inline ptrdiff_t node(const struct fourier_lines *f, int c, int a, int b, int m)
{
    int idx[3];
    idx[f->o[0]] = f->lo[c][f->o[0]] + a;
    idx[f->o[1]] = f->lo[c][f->o[1]] + b;
    idx[f->L] = f->lo[c][f->L] + m;
    return grid_idx(f->g, idx[0], idx[1], idx[2]);
}

/* The sign of line (a, b) (global indices) in plane pattern P: the wavenumber pi along o[0]
 * for P = 1, 3 and along o[1] for P = 2, 3. */
static inline double pattern(int P, int a, int b)
{
    int x = ((P & 1) ? a : 0) + ((P & 2) ? b : 0);
    return (x & 1) ? -1.0 : 1.0;
}

/* A line whose neighbours across do not alternate in pattern P (the seam of
 * an odd periodic count) is left out of the averages. */
static inline int seam(const struct fourier_lines *f, int P, int a, int b)
{
    return ((P & 1) && (f->n[0] & 1) && (a == 0 || a == f->n[0] - 1)) ||
           ((P & 2) && (f->n[1] & 1) && (b == 0 || b == f->n[1] - 1));
}

double fourier_lines_memory_estimate(const struct grid *g, const struct boundary *bc)
{
    /* the z-lines' case, the largest: n1 (n0/2 + 1) modes of 3 nz unknowns
     * times a block column's complex entries, and the spectra */
    double modes = (double)g->n[1] * (g->n[0] / 2 + 1), nu = 3.0 * g->n[2];
    double width = bc_has_open(bc) ? KW : KB + 1;
    return modes * nu * width * sizeof(cplx) + modes * nu * sizeof(fftw_complex);
}

int fourier_lines_general(const struct fourier_lines *f)
{
    return f->general;
}

void fourier_lines_destroy(struct fourier_lines *f)
{
    if (!f)
        return;
    free(f->sym);
    free(f->part);
    free(f->band);
    for (int c = 0; c < 3; c++) {
        if (f->fwd[c])
            fftw_destroy_plan(f->fwd[c]);
        if (f->bwd[c])
            fftw_destroy_plan(f->bwd[c]);
    }
    if (f->dc) {
        fftw_free(f->buf);
        free(f->box);
        block_slabs_free(&f->xs);
    } else {
        fftw_free(f->spec);
    }
    free(f);
}

/* The serial transforms: every plane of a component's box in one plan,
 * read from the field and written into the modes' vectors where the blocks
 * want them (FFTW's guru strides): no gathering of planes.  Dimensions:
 * o[1], then o[0], whose half spectrum is kept (mode s = k1 half0 + k0);
 * the planes along the lines.  FFTW's own threads (as the pressure's FFT
 * solver takes them); FFTW_UNALIGNED: the fields passed at execution are
 * CG's vectors, not the one planned on.  Returns 0, or -1. */
static int plan_serial(struct fourier_lines *f, double *tmp)
{
    const struct grid *g = f->g;
    int o0 = f->o[0], o1 = f->o[1];
    f->spec = fftw_malloc((size_t)f->modes * f->nu * sizeof(fftw_complex));
    if (!f->spec || fftw_init_threads() == 0)
        return -1;
    /* a padding node (a shorter line) is never transformed: 0 for good */
    memset(f->spec, 0, (size_t)f->modes * f->nu * sizeof(fftw_complex));
    fftw_plan_with_nthreads(grid_cells(g) >= 65536 ? omp_get_max_threads() : 1);
    unsigned flags = FFTW_ESTIMATE | FFTW_UNALIGNED;
    for (int c = 0; c < 3; c++) {
        if (f->len[c] == 0)
            continue;
        fftw_iodim dims[2] = {{f->n[1], (int)g->stride[o1], f->half0 * f->nu},
                              {f->n[0], (int)g->stride[o0], f->nu}};
        fftw_iodim many = {f->len[c], (int)g->stride[f->L], 3};
        double *in = tmp + node(f, c, 0, 0, 0);
        f->fwd[c] = fftw_plan_guru_dft_r2c(2, dims, 1, &many, in, f->spec + c, flags);
        fftw_iodim bdims[2] = {{f->n[1], f->half0 * f->nu, (int)g->stride[o1]},
                               {f->n[0], f->nu, (int)g->stride[o0]}};
        fftw_iodim bmany = {f->len[c], 3, (int)g->stride[f->L]};
        f->bwd[c] = fftw_plan_guru_dft_c2r(2, bdims, 1, &bmany, f->spec + c, in,
                                           flags | FFTW_DESTROY_INPUT);
        if (!f->fwd[c] || !f->bwd[c])
            return -1;
    }
    return 0;
}

/* The transforms over the ranks (struct fourier_lines: dc).  Every rank
 * alike: 0, or -1 with the cause in err.  Collective. */
static int plan_ranks(struct fourier_lines *f, char *err, size_t errlen)
{
    const struct decomp *dc = f->dc;
    const int unopened = fft_ranks_open(err, errlen) != 0;
    if (decomp_max(dc, unopened) != 0.0) {
        if (!unopened)
            snprintf(err, errlen, "viscous solver: FFTW's MPI transforms failed on another rank");
        return -1;
    }
    /* The slabs along the one direction across the blocks are split along,
     * when one is (and the other holds more than one line: FFTW plans no
     * real transform of one point): the lines stay on their rank (2 ranks
     * on 128 x 128 lines: half of them sent each way per apply otherwise).
     * Else B, whose half spectrum is kept, the longer: more modes to spread. */
    const int split0 = dc->cart->dims[f->o[0]] > 1, split1 = dc->cart->dims[f->o[1]] > 1;
    const int one = split0 != split1 && f->n[0] > 1 && f->n[1] > 1;
    const int fa = f->fa = one ? split1 : f->n[1] > f->n[0] ? 0 : 1, fb = 1 - fa;
    const int n[2] = {f->n[fa], f->n[fb]};
    fft_ranks_plane_slab(dc->cart, n, f->nu, &f->slab);
    const int mine = f->slab.x0 == f->first[fa] && f->slab.nx == f->nl[fa] && f->nl[fb] == n[1];
    f->aligned = decomp_max(dc, !mine) == 0.0;
    f->modes = (long)f->slab.ny * n[0];
    const int lo[3] = {f->first[fa], f->first[fb], 0}, nl[3] = {f->nl[fa], f->nl[fb], f->nu},
              ng[3] = {n[0], n[1], f->nu};
    const size_t box = (size_t)nl[0] * nl[1] * f->nu;
    f->buf = fftw_malloc((size_t)(f->slab.len > 0 ? f->slab.len : 1) * sizeof(double));
    int failed = !f->buf;
    if (!f->aligned) { /* every rank alike: block_slabs_init is collective */
        f->box = malloc((box ? box : 1) * sizeof(double));
        failed |= !f->box || block_slabs_init(&f->xs, dc->cart, lo, nl, ng, f->slab.x0,
                                              f->slab.nx, 2 * (n[1] / 2 + 1)) != 0;
    }
    if (decomp_max(dc, failed) != 0.0) {
        snprintf(err, errlen, "viscous solver: out of memory for the Fourier line blocks' slabs");
        return -1;
    }
    f->spec = (fftw_complex *)f->buf;
    fftw_plan_with_nthreads(grid_cells(f->g) >= 65536 ? omp_get_max_threads() : 1);
    f->fwd[0] = fft_ranks_plane_plan(dc->cart, n, f->nu, f->buf, 0, FFTW_ESTIMATE);
    f->bwd[0] = fft_ranks_plane_plan(dc->cart, n, f->nu, f->buf, 1, FFTW_ESTIMATE);
    if (decomp_max(dc, !f->fwd[0] || !f->bwd[0]) != 0.0) {
        snprintf(err, errlen, "viscous solver: FFTW's MPI planning failed for %d x %d lines",
                 n[0], n[1]);
        return -1;
    }
    return 0;
}

int fourier_lines_create(struct fourier_lines **out, const struct grid *g,
                         const struct boundary *bc, const struct box act[3], int line_dir,
                         char *err, size_t errlen)
{
    int o0 = (line_dir + 1) % 3, o1 = (line_dir + 2) % 3;
    if (bc->face[o0][0] != BC_PERIODIC || bc->face[o1][0] != BC_PERIODIC) {
        snprintf(err, errlen, "viscous solver: solver.preconditioner = fourier needs the two "
                              "directions across the lines periodic");
        return -1;
    }
    struct fourier_lines *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, errlen, "viscous solver: out of memory");
        return -1;
    }
    f->g = g;
    f->dc = bc->dc;
    f->L = line_dir;
    f->o[0] = o0;
    f->o[1] = o1;
    for (int e = 0; e < 2; e++) {
        f->nl[e] = g->n[f->o[e]];
        f->n[e] = f->dc ? f->dc->n_global[f->o[e]] : f->nl[e];
        f->first[e] = f->dc ? f->dc->lo[f->o[e]] : 0;
    }
    f->half0 = f->n[0] / 2 + 1;
    f->modes = (long)f->n[1] * f->half0;
    f->general = bc_has_open(bc);
    f->width = f->general ? KW : KB + 1;
    for (int c = 0; c < 3; c++) {
        for (int d = 0; d < 3; d++)
            f->lo[c][d] = act[c].lo[d];
        f->len[c] = act[c].hi[line_dir] - act[c].lo[line_dir];
        /* a periodic direction's box spans it (the rank's share) whole */
        if (f->len[c] < 0 || act[c].hi[o0] - act[c].lo[o0] != f->nl[0] ||
            act[c].hi[o1] - act[c].lo[o1] != f->nl[1])
            f->len[c] = 0;
        if (f->len[c] > f->maxlen)
            f->maxlen = f->len[c];
    }
    for (int P = 0; P < PATTERNS; P++)
        for (int b = 0; b < f->n[1]; b++)
            for (int a = 0; a < f->n[0]; a++)
                f->lines[P] += !seam(f, P, a, b);
    int ml = f->maxlen > 0 ? f->maxlen : 1;
    f->nu = 3 * ml;
    double *tmp = field_alloc(g); /* a field to plan on */
    int ok = tmp != NULL;
    if (f->dc && ok) {
        if (plan_ranks(f, err, errlen) != 0) {
            field_free(tmp);
            fourier_lines_destroy(f);
            return -1;
        }
    } else if (ok) {
        ok = plan_serial(f, tmp) == 0;
    }
    field_free(tmp);
    f->sym = malloc((size_t)PATTERNS * 9 * ml * PROBES * sizeof(double));
    f->band = malloc((size_t)(f->modes > 0 ? f->modes : 1) * f->nu * f->width * sizeof(cplx));
    f->part = malloc((size_t)(f->nl[1] > 0 ? f->nl[1] : 1) * ml * sizeof(double));
    ok = ok && f->sym && f->band && f->part;
    if (f->dc ? decomp_max(f->dc, !ok) != 0.0 : !ok) {
        fourier_lines_destroy(f);
        snprintf(err, errlen, "viscous solver: out of memory for the Fourier line blocks");
        return -1;
    }
    *out = f;
    return 0;
}

static double *sym_at(const struct fourier_lines *f, int P, int row, int col)
{
    return f->sym + (size_t)((P * 3 + row) * 3 + col) * f->maxlen * PROBES;
}

/* sym of pattern P, row component row, column component col from the
 * response q of comb r: each row node's coupling averaged over the lines.
 * The lines are summed a plane row b at a time (contiguous along the lines
 * when they run along z), each row into its own partial sum, then the
 * partial sums in order: the same bits on any number of threads.  Over
 * ranks, each rank's share of the average (its lines' sum over all the
 * lines' count), summed over the ranks once every probe is in. */
static void average_rows(struct fourier_lines *f, int P, int row, int col, int r, const double *q)
{
    int n0 = f->nl[0], n1 = f->nl[1], lr = f->len[row], ml = f->maxlen;
    double *part = f->part;
#pragma omp parallel for schedule(static) if (kernel_parallel(f->g))
    for (int b = 0; b < n1; b++) {
        double *pb = part + (size_t)b * ml;
        for (int m = 0; m < lr; m++)
            pb[m] = 0.0;
        for (int a = 0; a < n0; a++) {
            int ga = a + f->first[0], gb = b + f->first[1];
            if (seam(f, P, ga, gb))
                continue;
            double sg = pattern(P, ga, gb);
            for (int m = 0; m < lr; m++)
                pb[m] += q[node(f, row, a, b, m)] * sg;
        }
    }
    long total = f->lines[P];
    double *S = sym_at(f, P, row, col);
    for (int m = 0; m < lr; m++) {
        int off = probe_offset(r, m);
        if (m + off < 0 || m + off >= f->len[col])
            continue;
        double s = 0.0;
        for (int b = 0; b < n1; b++)
            s += part[(size_t)b * ml + m];
        S[(size_t)m * PROBES + off + BAND] = total ? s / total : 0.0;
    }
}

/* Probes column component c with every pattern and comb: sym of each row
 * component. */
static void probe_column(struct fourier_lines *f, int c, operator_fn op, void *ctx, double *p[3],
                         double *q[3])
{
    const struct grid *g = f->g;
    int n0 = f->nl[0], n1 = f->nl[1];
    for (int P = 0; P < PATTERNS; P++) {
        /* one cell across: the wavenumber pi does not exist there; the
         * pattern without it serves (the symbol is then read at 0 only) */
        int Q = P;
        if (f->n[0] == 1)
            Q &= ~1;
        if (f->n[1] == 1)
            Q &= ~2;
        if (Q != P) {
            for (int row = 0; row < 3; row++)
                memcpy(sym_at(f, P, row, c), sym_at(f, Q, row, c),
                       (size_t)f->maxlen * PROBES * sizeof(double));
            continue;
        }
        for (int row = 0; row < 3; row++)
            memset(sym_at(f, P, row, c), 0, (size_t)f->maxlen * PROBES * sizeof(double));
        for (int r = 0; r < PROBES; r++) {
            for (int d = 0; d < 3; d++)
                memset(p[d], 0, g->size * sizeof(double));
            for (int b = 0; b < n1; b++)
                for (int a = 0; a < n0; a++)
                    for (int m = r; m < f->len[c]; m += PROBES)
                        p[c][node(f, c, a, b, m)] =
                            pattern(P, a + f->first[0], b + f->first[1]);
            op(ctx, p, q);
            for (int row = 0; row < 3; row++)
                average_rows(f, P, row, c, r, q[row]);
        }
    }
}

/* The phase of a unit offset across, along the grid direction D, between a
 * row of component row and a column of component col: the same component
 * couples both neighbours alike (cos t); a component normal to D sits on
 * the faces, the others at the centres, so a face row meets the centres at
 * offsets 0 and -1 (e^-it), a centre row the faces at 0 and +1 (e^it), and
 * two centred ones only at offset 0. */
static cplx phase(int D, int row, int col, double t)
{
    if (row == col)
        return cos(t);
    if (D == row)
        return cexp(-I * t);
    if (D == col)
        return cexp(I * t);
    return 1.0;
}

/* The weights of the four measured plane wavenumbers in the symbol at
 * (t0, t1) of each component pair: w[(row * 3 + col) * PATTERNS + P] (exact
 * for couplings to nearest neighbours across, which is what a
 * symmetric-gradient stencil has: per direction the two measurements give
 * the two offsets' coefficients). */
static void mode_weights(const struct fourier_lines *f, double t0, double t1, cplx *w)
{
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++) {
            cplx p0 = phase(f->o[0], row, col, t0), p1 = phase(f->o[1], row, col, t1);
            cplx a[2] = {0.5 * (1.0 + p0), 0.5 * (1.0 - p0)}, b[2] = {0.5 * (1.0 + p1), 0.5 * (1.0 - p1)};
            for (int P = 0; P < PATTERNS; P++)
                w[(row * 3 + col) * PATTERNS + P] = a[P & 1] * b[P >> 1];
        }
}

/* Entry (i, j) of the mode's block (weights w), i = 3 m_i + c_i; 0 outside
 * the stencil, 1 on the diagonal of a padding node (a component with a
 * shorter line). */
static cplx entry(const struct fourier_lines *f, const cplx *w, int i, int j)
{
    int mi = i / 3, ci = i % 3, mj = j / 3, cj = j % 3, off = mj - mi;
    if (mi >= f->len[ci] || mj >= f->len[cj])
        return i == j ? 1.0 : 0.0;
    if (off < -BAND || off > BAND)
        return 0.0;
    const cplx *wp = w + (ci * 3 + cj) * PATTERNS;
    size_t at = (size_t)mi * PROBES + off + BAND;
    cplx s = 0.0;
    for (int P = 0; P < PATTERNS; P++)
        s += sym_at(f, P, ci, cj)[at] * wp[P];
    return s;
}

/* Hermitian banded Cholesky in place: band[j * (KB + 1) + o] = A(j + o, j)
 * becomes L(j + o, j), but for the diagonal, which holds 1 / L(j, j).  Returns 0, or -1 when A is not positive definite. */
static int cholesky(cplx *band, int n)
{
    for (int j = 0; j < n; j++) {
        cplx *cj = band + (size_t)j * (KB + 1);
        double d = creal(cj[0]);
        for (int k = j - KB > 0 ? j - KB : 0; k < j; k++) {
            cplx l = band[(size_t)k * (KB + 1) + (j - k)];
            d -= creal(l * conj(l));
        }
        if (!(d > 0.0))
            return -1;
        double inv = 1.0 / sqrt(d);
        cj[0] = inv; /* the reciprocal: the solves multiply by a real */
        for (int i = j + 1; i < n && i <= j + KB; i++) {
            cplx s = cj[i - j];
            for (int k = i - KB > 0 ? i - KB : 0; k < j; k++)
                s -= band[(size_t)k * (KB + 1) + (i - k)] * conj(band[(size_t)k * (KB + 1) + (j - k)]);
            cj[i - j] = s * inv;
        }
    }
    return 0;
}

/* Banded LU without pivoting in place: band[j * KW + KB + i - j] = A(i, j)
 * for |i - j| <= KB becomes L (below the diagonal, unit diagonal implied)
 * and U, but for the diagonal, which holds 1 / U(j, j).  No pivoting: a
 * block whose Hermitian part is positive definite (the viscous operator's,
 * the open face's coupling aside) has nonsingular leading blocks.  Returns
 * 0, or -1 at a zero or non-finite pivot. */
static int banded_lu(cplx *band, int n)
{
#define AT(i, j) band[(size_t)(j) * KW + KB + (i) - (j)]
    for (int k = 0; k < n; k++) {
        cplx piv = AT(k, k);
        if (!(cabs(piv) > 0.0) || !isfinite(cabs(piv)))
            return -1;
        cplx inv = 1.0 / piv;
        int last = k + KB < n - 1 ? k + KB : n - 1;
        for (int i = k + 1; i <= last; i++) {
            cplx l = AT(i, k) * inv;
            AT(i, k) = l;
            for (int j = k + 1; j <= last; j++)
                AT(i, j) -= l * AT(k, j);
        }
        AT(k, k) = inv;
    }
    return 0;
}

/* x = (L U)^-1 x. */
static void banded_lu_solve(const cplx *band, int n, cplx *x)
{
    for (int k = 0; k < n; k++) {
        int last = k + KB < n - 1 ? k + KB : n - 1;
        for (int i = k + 1; i <= last; i++)
            x[i] -= AT(i, k) * x[k];
    }
    for (int k = n - 1; k >= 0; k--) {
        int last = k + KB < n - 1 ? k + KB : n - 1;
        cplx s = x[k];
        for (int j = k + 1; j <= last; j++)
            s -= AT(k, j) * x[j];
        x[k] = s * AT(k, k);
    }
#undef AT
}

/* x = (L L^H)^-1 x. */
static void cholesky_solve(const cplx *band, int n, cplx *x)
{
    for (int j = 0; j < n; j++) { /* L y = x, column by column */
        const cplx *cj = band + (size_t)j * (KB + 1);
        x[j] *= creal(cj[0]);
        for (int i = j + 1; i < n && i <= j + KB; i++)
            x[i] -= cj[i - j] * x[j];
    }
    for (int j = n - 1; j >= 0; j--) { /* L^H x = y */
        const cplx *cj = band + (size_t)j * (KB + 1);
        cplx s = x[j];
        for (int i = j + 1; i < n && i <= j + KB; i++)
            s -= conj(cj[i - j]) * x[i];
        x[j] = s * creal(cj[0]);
    }
}

/* The block of a mode (weights w): its lower band made Hermitian (as the
 * line blocks are made symmetric) and factorised by Cholesky.  Returns 0,
 * or -1 when it is not positive definite. */
static int factor_hermitian(const struct fourier_lines *f, const cplx *w, cplx *band)
{
    int nu = f->nu;
    for (int j = 0; j < nu; j++)
        for (int o = 0; o <= KB; o++) {
            int i = j + o;
            band[(size_t)j * (KB + 1) + o] =
                i < nu ? 0.5 * (entry(f, w, i, j) + conj(entry(f, w, j, i))) : 0.0;
        }
    return cholesky(band, nu);
}

/* The whole band of a mode's block, as probed, factorised by the banded LU. */
static int factor_general(const struct fourier_lines *f, const cplx *w, cplx *band)
{
    int nu = f->nu;
    for (int j = 0; j < nu; j++)
        for (int o = -KB; o <= KB; o++) {
            int i = j + o;
            band[(size_t)j * KW + KB + o] = i >= 0 && i < nu ? entry(f, w, i, j) : 0.0;
        }
    return banded_lu(band, nu);
}

/* The wavenumbers across, k[e] along o[e], of this rank's mode s. */
static void mode_wavenumbers(const struct fourier_lines *f, long s, int k[2])
{
    if (!f->dc) {
        k[0] = (int)(s % f->half0);
        k[1] = (int)(s / f->half0);
        return;
    }
    int na = f->n[f->fa]; /* FFTW's output: o[1 - fa]'s wavenumbers slowest */
    k[f->fa] = (int)(s % na);
    k[1 - f->fa] = (int)(f->slab.y0 + s / na);
}

int fourier_lines_setup(struct fourier_lines *f, operator_fn op, void *ctx, double *p[3],
                        double *q[3])
{
    if (f->maxlen == 0)
        return 0;
    for (int c = 0; c < 3; c++)
        if (f->len[c] > 0)
            probe_column(f, c, op, ctx, p, q);
        else
            for (int P = 0; P < PATTERNS; P++)
                for (int row = 0; row < 3; row++)
                    memset(sym_at(f, P, row, c), 0, (size_t)f->maxlen * PROBES * sizeof(double));
    if (f->dc) /* each rank's shares of the averages */
        decomp_sum_array(f->dc, f->sym, PATTERNS * 9 * f->maxlen * PROBES);
    const double pi = 3.14159265358979323846;
    int failed = 0, nu = f->nu;
#pragma omp parallel for schedule(static) reduction(+ : failed) if (kernel_parallel(f->g))
    for (long s = 0; s < f->modes; s++) {
        int k[2];
        mode_wavenumbers(f, s, k);
        double t0 = 2.0 * pi * k[0] / f->n[0], t1 = 2.0 * pi * k[1] / f->n[1];
        cplx *band = f->band + (size_t)s * nu * f->width;
        cplx w[9 * PATTERNS];
        mode_weights(f, t0, t1, w);
        if (f->general ? factor_general(f, w, band) : factor_hermitian(f, w, band)) {
            /* singular, or not positive definite: the block's diagonal */
            failed++;
            for (int j = 0; j < nu; j++) {
                double d = creal(entry(f, w, j, j));
                d = d > 0.0 ? d : 1.0;
                cplx *col = band + (size_t)j * f->width;
                for (int o = 0; o < f->width; o++)
                    col[o] = 0.0;
                col[f->general ? KB : 0] = f->general ? 1.0 / d : 1.0 / sqrt(d);
            }
        }
    }
    return f->dc ? (int)decomp_sum(f->dc, failed) : failed;
}

/* Over ranks: this rank's lines of r into FFTW's slabs by way of the box,
 * every component's nodes interleaved as a mode's vector (a padding node
 * 0), and back from them into z. */
static void lines_to_slabs(struct fourier_lines *f, double *const r[3])
{
    const int fa = f->fa, na = f->nl[fa], nb = f->nl[1 - fa], nu = f->nu;
    /* aligned: the slab's rows of 2 (n_b / 2 + 1) lines, FFTW's padding */
    double *to = f->aligned ? f->buf : f->box;
    const size_t rows = f->aligned ? 2 * (size_t)(f->n[1 - fa] / 2 + 1) : (size_t)nb;
    const ptrdiff_t stride = f->g->stride[f->L];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(f->g))
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++) {
            double *x = to + ((size_t)i * rows + j) * nu;
            int a = fa ? j : i, b = fa ? i : j; /* along o[0], o[1] */
            for (int c = 0; c < 3; c++) {
                /* a line's nodes one stride apart: no index per node */
                const double *line = r[c] + node(f, c, a, b, 0);
                int m = 0;
                for (; m < f->len[c]; m++)
                    x[3 * m + c] = line[m * stride];
                for (; m < nu / 3; m++)
                    x[3 * m + c] = 0.0;
            }
        }
    if (!f->aligned)
        block_slabs_to_slab(&f->xs, f->box, f->buf);
}

static void slabs_to_lines(struct fourier_lines *f, double *z[3])
{
    const int fa = f->fa, na = f->nl[fa], nb = f->nl[1 - fa], nu = f->nu;
    const double *from = f->aligned ? f->buf : f->box;
    const size_t rows = f->aligned ? 2 * (size_t)(f->n[1 - fa] / 2 + 1) : (size_t)nb;
    const ptrdiff_t stride = f->g->stride[f->L];
    if (!f->aligned)
        block_slabs_to_boxes(&f->xs, f->buf, f->box);
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(f->g))
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++) {
            const double *x = from + ((size_t)i * rows + j) * nu;
            int a = fa ? j : i, b = fa ? i : j;
            for (int c = 0; c < 3; c++) {
                double *line = z[c] + node(f, c, a, b, 0);
                for (int m = 0; m < f->len[c]; m++)
                    line[m * stride] = x[3 * m + c];
            }
        }
}

void fourier_lines_apply(struct fourier_lines *f, double *const r[3], double *z[3])
{
    const struct grid *g = f->g;
    int nu = f->nu;
    if (f->maxlen == 0)
        return;
    if (f->dc) {
        lines_to_slabs(f, r);
        fft_ranks_execute(f->fwd[0]);
    } else {
        for (int c = 0; c < 3; c++)
            if (f->len[c] > 0)
                fftw_execute_dft_r2c(f->fwd[c], r[c] + node(f, c, 0, 0, 0), f->spec + c);
    }
    /* each mode's vector is contiguous; the inverse transform's 1 / (n0 n1)
     * is taken here */
    double norm = 1.0 / ((double)f->n[0] * f->n[1]);
    cplx *spec = (cplx *)f->spec; /* fftw_complex is double[2], laid out as C's complex */
#pragma omp parallel for schedule(static) if (kernel_parallel(g))
    for (long s = 0; s < f->modes; s++) {
        cplx *x = spec + (size_t)s * nu;
        const cplx *band = f->band + (size_t)s * nu * f->width;
        if (f->general)
            banded_lu_solve(band, nu, x);
        else
            cholesky_solve(band, nu, x);
        for (int i = 0; i < nu; i++)
            x[i] *= norm;
    }
    if (f->dc) {
        fft_ranks_execute(f->bwd[0]);
        slabs_to_lines(f, z);
        return;
    }
    for (int c = 0; c < 3; c++)
        if (f->len[c] > 0)
            fftw_execute_dft_c2r(f->bwd[c], f->spec + c, z[c] + node(f, c, 0, 0, 0));
}
