/* Tests of the geometric VOF transport (kernels/vof.c, src/physics/vof_transport.c).
 *
 * Every transport test checks after each step that the grain volume sum(T)
 * is that of the start to a relative 1e-13 and that -1e-12 <= T <= 1 + 1e-12.
 * Why 1e-13: the face fluxes cancel exactly in pairs (each face's flux is one
 * double, added to one cell and subtracted from the other) and cells full or
 * empty stay exactly 1 or 0 (their bracket is exactly zero), so the total
 * changes only by the rounding of the updates of cells with 0 < T < 1: about
 * two units of 1.1e-16 per such cell and sweep (the bracket's differences,
 * its product with dt/h, the sum with T; the c_c term of a streamfunction
 * velocity adds its O(eps) divergence inside the same bracket).  Summed
 * without any cancellation, sweeps x cut cells x 2.2e-16 / volume is, for
 * the runs below: disc 400 x 115 / 491 cells = 2.1e-14, sphere 384 x 1,299 /
 * 2,144 = 5.1e-14, Zalesak 1,246 x 197 / 582 = 9.3e-14, vortex 1,024 x 292 /
 * 1,158 = 5.7e-14.  So 1e-13 is the worst case of round-off alone; an O(h) or
 * O(dt) leak would exceed it by orders of magnitude.  The observed drift, with
 * errors of random sign, is below 2e-16.  The sums themselves are compensated
 * (Neumaier) so they do not add their own O(n eps). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/vof.h"
#include "physics/vof_transport.h"
#include "test_main.h"

#define MASS_TOL 1e-13
#define BOUND_TOL 1e-12

/* ---- helpers -------------------------------------------------------------- */

static void make_grid(struct grid *g, int nx, int ny, int nz, double lx, double ly, double lz)
{
    int n[3] = {nx, ny, nz};
    double len[3] = {lx, ly, lz};
    assert_int_equal(grid_init(g, n, len), 0);
}

static struct boundary all_kind(enum bc_kind kind)
{
    struct boundary bc = {0};
    for (int d = 0; d < 3; d++)
        bc.face[d][0] = bc.face[d][1] = kind;
    return bc;
}

/* Compensated sum of T over the interior cells. */
static double total(const struct grid *g, const double *T)
{
    double s = 0.0, c = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                double x = T[grid_idx(g, i, j, k)], t = s + x;
                c += fabs(s) >= fabs(x) ? (s - t) + x : (x - t) + s;
                s = t;
            }
    return s + c;
}

static void bounds(const struct grid *g, const double *T, double *lo, double *hi)
{
    *lo = 1.0;
    *hi = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                double x = T[grid_idx(g, i, j, k)];
                *lo = fmin(*lo, x);
                *hi = fmax(*hi, x);
            }
}

/* L1 difference sum |a - b| over the interior cells (in cells). */
static double l1_diff(const struct grid *g, const double *a, const double *b)
{
    double s = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                s += fabs(a[p] - b[p]);
            }
    return s;
}

/* Cells with 0.01 < T < 0.99: the smeared band around the interface. */
static int band_cells(const struct grid *g, const double *T)
{
    int n = 0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                double x = T[grid_idx(g, i, j, k)];
                n += x > 0.01 && x < 0.99;
            }
    return n;
}

/* A shape by a 1-Lipschitz level set phi (< 0 inside): a cell whose centre
 * is farther from the zero level than its half diagonal is uniform; cut cells
 * are sampled on a regular sub-grid of `sub` points per direction. */
typedef double (*level_set)(const double x[3]);

static void fill_fraction(const struct grid *g, level_set phi, int sub, double *T)
{
    double half_diag = 0.5 * sqrt(g->h[0] * g->h[0] + g->h[1] * g->h[1] + g->h[2] * g->h[2]);
    int ns[3];
    for (int d = 0; d < 3; d++)
        ns[d] = g->n[d] > 1 ? sub : 1;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                int idx[3] = {i, j, k};
                double xc[3];
                for (int d = 0; d < 3; d++)
                    xc[d] = (idx[d] + 0.5) * g->h[d];
                double f = phi(xc), frac;
                if (f > half_diag)
                    frac = 0.0;
                else if (f < -half_diag)
                    frac = 1.0;
                else {
                    int in = 0;
                    for (int a = 0; a < ns[0]; a++)
                        for (int b = 0; b < ns[1]; b++)
                            for (int c = 0; c < ns[2]; c++) {
                                int s[3] = {a, b, c};
                                double x[3];
                                for (int d = 0; d < 3; d++)
                                    x[d] = (idx[d] + (s[d] + 0.5) / ns[d]) * g->h[d];
                                in += phi(x) < 0.0;
                            }
                    frac = (double)in / (ns[0] * ns[1] * ns[2]);
                }
                T[grid_idx(g, i, j, k)] = frac;
            }
}

/* Velocity at time t into vel (interior faces; ghosts filled by the caller). */
typedef void (*velocity_at)(const struct grid *g, double t, double *vel[3]);

/* Face velocity from a streamfunction psi(x, y, t) at the cell corners of
 * the x-y plane: u = -dpsi/dy, v = dpsi/dx as differences along the faces,
 * so the discrete divergence of every cell is zero up to round-off. */
typedef double (*stream_fn)(double x, double y, double t);

static void velocity_from_stream(const struct grid *g, stream_fn psi, double t, double *vel[3])
{
    const double hx = g->h[0], hy = g->h[1];
    for (int i = 0; i <= g->n[0]; i++)
        for (int j = 0; j <= g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                double c00 = psi(i * hx, j * hy, t);
                if (j < g->n[1])
                    vel[0][p] = -(psi(i * hx, (j + 1) * hy, t) - c00) / hy;
                if (i < g->n[0])
                    vel[1][p] = (psi((i + 1) * hx, j * hy, t) - c00) / hx;
                vel[2][p] = 0.0;
            }
}

struct run_stats {
    long steps;
    double mass_drift; /* max relative change of sum(T) over the steps */
    double t_min, t_max;
};

/* Advects T from 0 to t_end with the largest step whose sweep CFL stays
 * <= target_cfl at the velocity of time 0 (the fields below are largest
 * then), checking mass and bounds after every step. */
static void advect(const struct grid *g, const struct boundary *bc, velocity_at set_velocity,
                   double t_end, double target_cfl, double *T, struct run_stats *st)
{
    double *vel[3];
    for (int d = 0; d < 3; d++)
        vel[d] = field_alloc(g);
    struct vof_transport vt;
    assert_int_equal(vof_transport_init(&vt, g, bc), 0);
    bc_fill_scalar(g, bc, T);

    set_velocity(g, 0.0, vel);
    bc_fill_velocity(g, bc, vel);
    double cfl[3], per_unit_dt = vof_cfl(g, vel, 1.0, cfl);
    long nsteps = (long)ceil(t_end * per_unit_dt / target_cfl);
    while (t_end / nsteps * per_unit_dt > target_cfl)
        nsteps++;
    double dt = t_end / nsteps;

    double mass0 = total(g, T);
    *st = (struct run_stats){.steps = nsteps, .t_min = 1.0, .t_max = 0.0};
    for (long s = 0; s < nsteps; s++) {
        set_velocity(g, (s + 0.5) * dt, vel);
        bc_fill_velocity(g, bc, vel);
        double used;
        assert_int_equal(vof_transport_step(&vt, T, vel, dt, &used), 0);
        assert_true(used <= VOF_CFL_MAX);
        double drift = fabs(total(g, T) - mass0) / mass0, lo, hi;
        bounds(g, T, &lo, &hi);
        st->mass_drift = fmax(st->mass_drift, drift);
        st->t_min = fmin(st->t_min, lo);
        st->t_max = fmax(st->t_max, hi);
        if (drift > MASS_TOL || lo < -BOUND_TOL || hi > 1.0 + BOUND_TOL)
            print_error("step %ld: mass drift %.3e, T in [%.3e, 1 + %.3e]\n", s, drift, lo,
                        hi - 1.0);
        assert_true(drift <= MASS_TOL);
        assert_true(lo >= -BOUND_TOL && hi <= 1.0 + BOUND_TOL);
    }
    vof_transport_free(&vt);
    for (int d = 0; d < 3; d++)
        field_free(vel[d]);
}

/* ---- volume / plane constant ------------------------------------------------ */

/* Independent reference: inclusion-exclusion over the vertices of the unit
 * square or cube, in long double, for normals whose nonzero components are
 * not small (where the formula is well conditioned). */
static double reference_volume(const double m[3], double alpha)
{
    long double prod = 1.0L, v = 0.0L;
    int dim = 0, nz[3];
    for (int c = 0; c < 3; c++)
        if (m[c] != 0.0) {
            nz[dim++] = c;
            prod *= m[c];
        }
    for (int mask = 0; mask < (1 << dim); mask++) {
        long double s = alpha;
        int bits = 0;
        for (int b = 0; b < dim; b++)
            if (mask >> b & 1) {
                s -= m[nz[b]];
                bits++;
            }
        if (s > 0) {
            long double pw = s;
            for (int e = 1; e < dim; e++)
                pw *= s;
            v += (bits % 2 ? -1.0L : 1.0L) * pw;
        }
    }
    long double fact = dim == 3 ? 6.0L : dim == 2 ? 2.0L : 1.0L;
    v /= fact * prod;
    /* negative components: the formula above counts from the vertex where
     * m . xi is lowest only when all are positive; the caller passes those */
    return (double)(v < 0 ? 0 : v > 1 ? 1 : v);
}

static double uniform(double lo, double hi) { return lo + (hi - lo) * (rand() / (double)RAND_MAX); }

static void random_normal(int zero_component, double min_abs, double m[3])
{
    for (int c = 0; c < 3; c++) {
        double a = uniform(min_abs, 1.0);
        m[c] = rand() % 2 ? a : -a;
    }
    if (zero_component >= 0)
        m[zero_component] = 0.0;
}

/* V(alpha(V)) = V to round-off for random normals and volumes, near-empty and
 * near-full cells and interfaces almost aligned with the grid included;
 * alpha(V(alpha)) = alpha where V is strictly between 0 and 1; and V itself
 * against inclusion-exclusion.  zero_component < 0: 3D, else that
 * component is 0 (the 2D relations). */
static void round_trips(int zero_component)
{
    static const double special[] = {0.0, 1e-300, 1e-14, 1e-9, 0.5, 1.0 - 1e-9, 1.0 - 1e-14, 1.0};
    double worst_v = 0.0, worst_a = 0.0, worst_ref = 0.0;
    for (int trial = 0; trial < 20000; trial++) {
        double m[3];
        random_normal(zero_component, trial % 4 == 3 ? 0.0 : 0.05, m);
        if (trial % 8 == 7) /* nearly grid-aligned: one tiny component */
            m[(zero_component + 1 + trial % 2) % 3] *= 1e-9;
        if (trial % 16 == 15)
            m[(zero_component + 2) % 3] *= 1e-12;
        double v = trial < 8 ? special[trial] : uniform(0.0, 1.0);
        double a = vof_plane_alpha(m, v), back = vof_plane_volume(m, a);
        worst_v = fmax(worst_v, fabs(back - v));
        /* alpha within the range where V is invertible */
        double lo = 0.0, hi = 0.0;
        for (int c = 0; c < 3; c++) {
            lo += fmin(m[c], 0.0);
            hi += fmax(m[c], 0.0);
        }
        double al = uniform(lo, hi), vv = vof_plane_volume(m, al);
        if (vv > 1e-6 && vv < 1.0 - 1e-6) {
            double aa = vof_plane_alpha(m, vv);
            worst_a = fmax(worst_a, fabs(aa - al) / (hi - lo));
        }
        /* reference with positive components only (mirror xi -> 1 - xi) */
        double mp[3], shift = 0.0;
        int small = 0;
        for (int c = 0; c < 3; c++) {
            mp[c] = fabs(m[c]);
            if (m[c] < 0.0)
                shift -= m[c];
            small |= mp[c] != 0.0 && mp[c] < 0.04 * (hi - lo);
        }
        if (!small)
            worst_ref = fmax(worst_ref, fabs(reference_volume(mp, al + shift) - vv));
    }
    print_message("%s: |V(alpha(V)) - V| <= %.1e, |alpha(V(alpha)) - alpha| <= %.1e of the range, "
                  "|V - inclusion-exclusion| <= %.1e\n",
                  zero_component < 0 ? "3D" : "2D", worst_v, worst_a, worst_ref);
    assert_true(worst_v <= 4e-15);
    assert_true(worst_a <= 1e-9); /* V is flat (quadratic or cubic) at its ends */
    assert_true(worst_ref <= 1e-12);
}

static void test_round_trip_2d(void **state)
{
    (void)state;
    srand(7);
    for (int c = 0; c < 3; c++)
        round_trips(c);
}

static void test_round_trip_3d(void **state)
{
    (void)state;
    srand(11);
    round_trips(-1);
}

/* A slab of the cell: the geometric face value of T.  The half-cell slabs
 * of a cell add up to its volume, and a cell cut by the plane xi_x = 0.3
 * gives exactly 0 or 1 in slabs on either side. */
static void test_slab_fraction(void **state)
{
    (void)state;
    srand(3);
    for (int trial = 0; trial < 2000; trial++) {
        double m[3];
        random_normal(trial % 4 - 1, 0.0, m);
        double t = uniform(0.0, 1.0), a = vof_plane_alpha(m, t);
        for (int d = 0; d < 3; d++) {
            double w = uniform(0.0, 1.0);
            double lower = vof_slab_fraction(m, a, t, d, 0.0, w);
            double upper = vof_slab_fraction(m, a, t, d, w, 1.0 - w);
            assert_true(fabs(w * lower + (1.0 - w) * upper - t) <= 1e-14);
            assert_true(lower >= 0.0 && lower <= 1.0 && upper >= 0.0 && upper <= 1.0);
        }
    }
    double m[3] = {1.0, 0.0, 0.0};
    double a = vof_plane_alpha(m, 0.3);
    assert_true(fabs(a - 0.3) <= 1e-15);
    assert_true(vof_slab_fraction(m, a, 0.3, 0, 0.0, 0.25) == 1.0);
    assert_true(vof_slab_fraction(m, a, 0.3, 0, 0.5, 0.5) == 0.0);
    double none[3] = {0.0, 0.0, 0.0};
    assert_true(vof_slab_fraction(none, 0.0, 0.7, 1, 0.2, 0.5) == 0.7);
}

/* ---- reconstruction ---------------------------------------------------------- */

/* Exact fractions of a random plane through the centre cell of a 3 x 3 x 3
 * block (ghosts included, so the stencil sees the plane everywhere); the MYC
 * normal of the centre cell against the plane's.  Measured with the rule of
 * myc_normal: mean L1 error 4e-4 (2D) and 2e-3 (3D), where Youngs alone gives
 * 1.4e-2 and 2.2e-2 and the best centred column 9e-4 and 3.9e-3; the
 * opposite choice between them would give 1.4e-2 and 2.3e-2.  The plane
 * constant must give the cell its volume back. */
static void reconstruct_planes(int thin)
{
    struct grid g;
    make_grid(&g, 3, thin ? 1 : 3, 3, 3.0, thin ? 1.0 : 3.0, 3.0);
    double *T = field_alloc(&g), *normal[3], *alpha = field_alloc(&g);
    for (int d = 0; d < 3; d++)
        normal[d] = field_alloc(&g);
    double sum_err = 0.0, max_err = 0.0, max_volume = 0.0;
    int trials = 0;
    for (int trial = 0; trial < 4000; trial++) {
        double n[3] = {uniform(-1.0, 1.0), thin ? 0.0 : uniform(-1.0, 1.0), uniform(-1.0, 1.0)};
        double s = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
        for (int c = 0; c < 3; c++)
            n[c] /= s;
        /* the plane n . x = level in index units, x = 0 at the centre cell's low corner */
        double level = 0.5 * (n[0] + n[1] + n[2]) + uniform(-0.25, 0.25);
        for (int i = -1; i <= g.n[0]; i++)
            for (int j = -1; j <= g.n[1]; j++)
                for (int k = -1; k <= g.n[2]; k++) {
                    double off[3] = {i - 1, thin ? 0 : j - 1, k - 1};
                    T[grid_idx(&g, i, j, k)] =
                        vof_plane_volume(n, level - (n[0] * off[0] + n[1] * off[1] + n[2] * off[2]));
                }
        ptrdiff_t centre = grid_idx(&g, 1, thin ? 0 : 1, 1);
        if (T[centre] < 1e-3 || T[centre] > 1.0 - 1e-3)
            continue;
        vof_reconstruct(&g, T, normal, alpha);
        double m[3] = {normal[0][centre], normal[1][centre], normal[2][centre]}, err = 0.0;
        for (int c = 0; c < 3; c++)
            err += fabs(m[c] - n[c]);
        if (thin)
            assert_true(m[1] == 0.0);
        sum_err += err;
        max_err = fmax(max_err, err);
        max_volume = fmax(max_volume, fabs(vof_plane_volume(m, alpha[centre]) - T[centre]));
        trials++;
    }
    print_message("MYC normals of planes (%s): L1 error mean %.1e, max %.1e over %d cells; "
                  "volume of the reconstructed plane off by <= %.1e\n",
                  thin ? "3 x 1 x 3" : "3 x 3 x 3", sum_err / trials, max_err, trials, max_volume);
    assert_true(sum_err / trials < (thin ? 1e-3 : 5e-3));
    assert_true(max_err < (thin ? 0.02 : 0.04));
    assert_true(max_volume <= 1e-15);
    field_free(T);
    field_free(alpha);
    for (int d = 0; d < 3; d++)
        field_free(normal[d]);
}

static void test_reconstruct_planes(void **state)
{
    (void)state;
    srand(13);
    reconstruct_planes(1);
    reconstruct_planes(0);
}

/* ---- the CFL limit -------------------------------------------------------- */

static void test_cfl(void **state)
{
    (void)state;
    struct grid g;
    make_grid(&g, 8, 1, 16, 2.0, 0.25, 1.0); /* h = 0.25, 0.25, 0.0625 */
    struct boundary bc = all_kind(BC_PERIODIC);
    double *vel[3], *T = field_alloc(&g);
    for (int d = 0; d < 3; d++)
        vel[d] = field_alloc(&g);
    for (int i = 0; i < g.n[0]; i++)
        for (int k = 0; k < g.n[2]; k++) {
            ptrdiff_t p = grid_idx(&g, i, 0, k);
            vel[0][p] = i == 3 ? -2.0 : 0.5;
            vel[1][p] = 100.0; /* one cell along y: never swept */
            vel[2][p] = k == 5 ? 0.75 : -0.25;
            T[p] = k < 8 ? 1.0 : 0.0;
        }
    bc_fill_velocity(&g, &bc, vel);
    double cfl[3];
    double largest = vof_cfl(&g, vel, 0.05, cfl);
    assert_true(fabs(cfl[0] - 2.0 * 0.05 / 0.25) <= 1e-15);
    assert_true(cfl[1] == 0.0);
    assert_true(fabs(cfl[2] - 0.75 * 0.05 / 0.0625) <= 1e-15);
    assert_true(largest == fmax(cfl[0], cfl[2]));

    /* beyond VOF_CFL_MAX the step is refused and T untouched */
    struct vof_transport vt;
    assert_int_equal(vof_transport_init(&vt, &g, &bc), 0);
    double *before = field_alloc(&g), used;
    memcpy(before, T, g.size * sizeof *T);
    assert_int_equal(vof_transport_step(&vt, T, vel, 0.1, &used), -1);
    assert_true(fabs(used - 0.75 * 0.1 / 0.0625) <= 1e-15);
    assert_true(memcmp(before, T, g.size * sizeof *T) == 0);
    assert_int_equal(vof_transport_step(&vt, T, vel, 0.04, &used), 0);
    assert_true(used <= VOF_CFL_MAX);
    vof_transport_free(&vt);
    field_free(before);
    field_free(T);
    for (int d = 0; d < 3; d++)
        field_free(vel[d]);
}

/* Inflow through a non-periodic face: the driver mirrors the interface of the
 * first cell into the ghost (like the zero-gradient T), so the slab entering
 * across face 0 is the mirror image of the first cell's slab next to that
 * face: the same face value of T. */
static void test_mirror_inflow(void **state)
{
    (void)state;
    struct grid g;
    make_grid(&g, 8, 8, 1, 1.0, 1.0, 0.125);
    struct boundary bc = all_kind(BC_SLIP);
    bc.face[2][0] = bc.face[2][1] = BC_PERIODIC;
    double *T = field_alloc(&g), *alpha = field_alloc(&g), *normal[3], *vel[3];
    for (int d = 0; d < 3; d++) {
        normal[d] = field_alloc(&g);
        vel[d] = field_alloc(&g);
    }
    const double n[3] = {0.8, 0.2, 0.0}, level = 1.0; /* cuts cells 1-4 of column 0 */
    for (int i = 0; i < g.n[0]; i++)
        for (int j = 0; j < g.n[1]; j++)
            T[grid_idx(&g, i, j, 0)] = vof_plane_volume(n, level - (n[0] * i + n[1] * j));
    bc_fill_scalar(&g, &bc, T);
    vof_reconstruct(&g, T, normal, alpha);
    const double dt = 0.01, width = 0.4, u_in = width * g.h[0] / dt;
    for (int j = 0; j < g.n[1]; j++)
        vel[0][grid_idx(&g, 0, j, 0)] = u_in;
    struct vof_transport vt;
    assert_int_equal(vof_transport_init(&vt, &g, &bc), 0);
    assert_int_equal(vof_transport_step(&vt, T, vel, dt, NULL), 0);
    int cut = 0;
    for (int j = 0; j < g.n[1]; j++) {
        ptrdiff_t p = grid_idx(&g, 0, j, 0);
        double m[3] = {normal[0][p], normal[1][p], normal[2][p]};
        double face_t = vof_slab_fraction(m, alpha[p], T[p], 0, 0.0, width);
        cut += face_t > 0.0 && face_t < 1.0;
        assert_true(fabs(vt.flux[0][p] - u_in * face_t) <= 1e-15 * u_in);
    }
    assert_true(cut >= 2); /* the interface does cross the inflow face */
    vof_transport_free(&vt);
    field_free(T);
    field_free(alpha);
    for (int d = 0; d < 3; d++) {
        field_free(normal[d]);
        field_free(vel[d]);
    }
}

/* ---- translations in periodic boxes ----------------------------------------- */

/* A disc of radius 0.25 at (0.5, 1.0) in the x-z plane of a thin grid
 * 50 x 1 x 100 (h = 0.02), moved by u = (1, 5, 1): y has one cell, so its
 * velocity (CFL 2.5 were it swept) must be ignored.  After t = 2 the disc is
 * back (two periods in x, one in z). */
static double disc_xz(const double x[3])
{
    return hypot(x[0] - 0.5, x[2] - 1.0) - 0.25;
}

static void translate_xz(const struct grid *g, double t, double *vel[3])
{
    (void)t;
    for (size_t q = 0; q < g->size; q++) {
        vel[0][q] = 1.0;
        vel[1][q] = 5.0;
        vel[2][q] = 1.0;
    }
}

static void test_translate_disc_thin(void **state)
{
    (void)state;
    struct grid g;
    make_grid(&g, 50, 1, 100, 1.0, 0.02, 2.0);
    struct boundary bc = all_kind(BC_PERIODIC);
    double *T = field_alloc(&g), *T0 = field_alloc(&g);
    fill_fraction(&g, disc_xz, 32, T);
    memcpy(T0, T, g.size * sizeof *T);

    /* one step by hand: the exposed fluxes reproduce the change of T */
    {
        double *vel[3], *prev = field_alloc(&g);
        for (int d = 0; d < 3; d++)
            vel[d] = field_alloc(&g);
        translate_xz(&g, 0.0, vel);
        struct vof_transport vt;
        assert_int_equal(vof_transport_init(&vt, &g, &bc), 0);
        memcpy(prev, T, g.size * sizeof *T);
        double dt = 0.009;
        assert_int_equal(vof_transport_step(&vt, T, vel, dt, NULL), 0);
        assert_int_equal(vt.nsweeps, 2);
        assert_true(vt.cfl[1] == 0.0);
        double worst = 0.0, worst_normal_y = 0.0;
        for (int i = 0; i < g.n[0]; i++)
            for (int k = 0; k < g.n[2]; k++) {
                ptrdiff_t p = grid_idx(&g, i, 0, k);
                double change = 0.0;
                for (int d = 0; d < 3; d += 2)
                    change -= dt / g.h[d] * (vt.flux[d][p + g.stride[d]] - vt.flux[d][p]);
                worst = fmax(worst, fabs(T[p] - prev[p] - change));
                worst_normal_y = fmax(worst_normal_y, fabs(vt.normal[1][p]));
            }
        assert_true(worst <= 1e-15);
        assert_true(worst_normal_y == 0.0);
        vof_transport_free(&vt);
        memcpy(T, T0, g.size * sizeof *T);
        field_free(prev);
        for (int d = 0; d < 3; d++)
            field_free(vel[d]);
    }

    struct run_stats st;
    advect(&g, &bc, translate_xz, 2.0, VOF_CFL_MAX, T, &st);
    double err = l1_diff(&g, T, T0) / total(&g, T0);
    print_message("disc (50 x 1 x 100, R = 12.5 h) after one period, %ld steps: L1 shape error "
                  "%.3e of its area, mass drift %.1e, T in [%.1e, 1 + %.1e], band %d cells\n",
                  st.steps, err, st.mass_drift, st.t_min, st.t_max - 1.0, band_cells(&g, T));
    assert_true(err < 0.02);
    field_free(T);
    field_free(T0);
}

/* A sphere of radius 0.25 (8 cells) in a periodic 32^3 box, u = (1, 0.5,
 * 0.5) for t = 2: two periods in x, one in y and z. */
static double sphere(const double x[3])
{
    return sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5) +
                (x[2] - 0.5) * (x[2] - 0.5)) - 0.25;
}

static void translate_3d(const struct grid *g, double t, double *vel[3])
{
    (void)t;
    for (size_t q = 0; q < g->size; q++) {
        vel[0][q] = 1.0;
        vel[1][q] = 0.5;
        vel[2][q] = 0.5;
    }
}

static void test_translate_sphere(void **state)
{
    (void)state;
    struct grid g;
    make_grid(&g, 32, 32, 32, 1.0, 1.0, 1.0);
    struct boundary bc = all_kind(BC_PERIODIC);
    double *T = field_alloc(&g), *T0 = field_alloc(&g);
    fill_fraction(&g, sphere, 10, T);
    memcpy(T0, T, g.size * sizeof *T);
    struct run_stats st;
    advect(&g, &bc, translate_3d, 2.0, VOF_CFL_MAX, T, &st);
    double err = l1_diff(&g, T, T0) / total(&g, T0);
    print_message("sphere (32^3, R = 8 h) after one period, %ld steps: L1 shape error %.3e of "
                  "its volume, mass drift %.1e, T in [%.1e, 1 + %.1e]\n",
                  st.steps, err, st.mass_drift, st.t_min, st.t_max - 1.0);
    assert_true(err < 0.05);
    field_free(T);
    field_free(T0);
}

/* ---- rotation and shear ----------------------------------------------------- */

/* Zalesak's slotted disc: radius 0.15 at (0.5, 0.75), slot 0.05 wide up to
 * y = 0.85, one revolution about (0.5, 0.5) in unit time, 100 x 100 x 1. */
static double slotted_disc(const double x[3])
{
    double disc = hypot(x[0] - 0.5, x[1] - 0.75) - 0.15;
    double slot = fmax(fabs(x[0] - 0.5) - 0.025, x[1] - 0.85);
    return fmax(disc, -slot);
}

static double rotation_stream(double x, double y, double t)
{
    (void)t;
    return M_PI * ((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)); /* omega = 2 pi */
}

static void rotate(const struct grid *g, double t, double *vel[3])
{
    velocity_from_stream(g, rotation_stream, t, vel);
}

/* Its perimeter, for the interface band width: the circle minus the arc
 * under the slot's mouth, plus the slot's two sides and its end. */
static double slotted_perimeter(void)
{
    double r = 0.15, half = 0.025;
    double mouth_arc = 2.0 * r * asin(half / r);
    double side = 0.85 - (0.75 - sqrt(r * r - half * half));
    return 2.0 * M_PI * r - mouth_arc + 2.0 * side + 2.0 * half;
}

static void test_zalesak(void **state)
{
    (void)state;
    struct grid g;
    make_grid(&g, 100, 100, 1, 1.0, 1.0, 0.01);
    struct boundary bc = all_kind(BC_SLIP);
    bc.face[2][0] = bc.face[2][1] = BC_PERIODIC;
    double *T = field_alloc(&g), *T0 = field_alloc(&g);
    fill_fraction(&g, slotted_disc, 32, T);
    memcpy(T0, T, g.size * sizeof *T);
    struct run_stats st;
    advect(&g, &bc, rotate, 1.0, VOF_CFL_MAX, T, &st);
    double err = l1_diff(&g, T, T0);
    double width = band_cells(&g, T) / (slotted_perimeter() / g.h[0]);
    print_message("Zalesak (100 x 100, %ld steps): L1 shape error %.3e cells = %.3e of the area, "
                  "band %.2f cells across, mass drift %.1e, T in [%.1e, 1 + %.1e]\n",
                  st.steps, err, err / total(&g, T0), width, st.mass_drift, st.t_min,
                  st.t_max - 1.0);
    assert_true(err / total(&g, T0) < 0.03);
    assert_true(width < 2.0);
    field_free(T);
    field_free(T0);
}

/* LeVeque's single vortex: psi = sin^2(pi x) sin^2(pi y) cos(pi t / period) / pi
 * stretches a disc of radius 0.15 at (0.5, 0.75) into a filament and brings
 * it back at t = period. */
static const double vortex_period = 2.0;

static double vortex_stream(double x, double y, double t)
{
    double sx = sin(M_PI * x), sy = sin(M_PI * y);
    return sx * sx * sy * sy * cos(M_PI * t / vortex_period) / M_PI;
}

static void vortex(const struct grid *g, double t, double *vel[3])
{
    velocity_from_stream(g, vortex_stream, t, vel);
}

static double vortex_disc(const double x[3])
{
    return hypot(x[0] - 0.5, x[1] - 0.75) - 0.15;
}

static double vortex_error(int n, struct run_stats *st)
{
    struct grid g;
    make_grid(&g, n, n, 1, 1.0, 1.0, 1.0 / n);
    struct boundary bc = all_kind(BC_SLIP);
    bc.face[2][0] = bc.face[2][1] = BC_PERIODIC;
    double *T = field_alloc(&g), *T0 = field_alloc(&g);
    fill_fraction(&g, vortex_disc, 32, T);
    memcpy(T0, T, g.size * sizeof *T);
    advect(&g, &bc, vortex, vortex_period, VOF_CFL_MAX, T, st);
    double err = l1_diff(&g, T, T0) * g.h[0] * g.h[1]; /* area */
    field_free(T);
    field_free(T0);
    return err;
}

static void test_single_vortex(void **state)
{
    (void)state;
    struct run_stats coarse, fine;
    double e_coarse = vortex_error(64, &coarse), e_fine = vortex_error(128, &fine);
    double order = log2(e_coarse / e_fine);
    print_message("single vortex, period %.0f: L1 area error %.3e (64^2, %ld steps), %.3e "
                  "(128^2, %ld steps), observed order %.2f; mass drift %.1e, %.1e\n",
                  vortex_period, e_coarse, coarse.steps, e_fine, fine.steps, order,
                  coarse.mass_drift, fine.mass_drift);
    assert_true(e_fine < e_coarse);
    assert_true(order > 1.5);
}

/* ---- the algebraic comparison ------------------------------------------------ */

/* Algebraic VOF on the same Zalesak rotation and time step, unsplit (the
 * divergence-free flux form needs no split correction):
 *  - first-order upwind, the bounded scheme an algebraic VOF starts from;
 *  - with interface compression as interFoam does it: a high-order flux
 *    (centred T plus the compressive flux u_r T (1 - T), u_r = |u| n_f along
 *    the face normal of grad T, each factor upwinded with respect to u_r),
 *    limited towards upwind by flux-corrected transport (Zalesak 1979, J.
 *    Comput. Phys. 31), which is what MULES does, so that T stays in [0, 1]
 *    and within the local extrema of the old and upwind fields.
 * Both are conservative to round-off (one flux per face); what differs from
 * PLIC is how wide the interface gets. */
struct algebraic_work {
    double *low[2], *anti[2]; /* upwind flux and high-order minus upwind, per face */
    double *t_low;            /* T after the upwind fluxes alone */
    double *r_plus, *r_minus; /* Zalesak's fractions of the antidiffusion allowed */
};

static int face_exists(const struct grid *g, int d, int i, int j)
{
    return d == 0 ? j < g->n[1] : i < g->n[0];
}

static void algebraic_step(const struct grid *g, const struct boundary *bc,
                           double *const vel[3], double dt, int compress, double *T,
                           struct algebraic_work *w)
{
    const ptrdiff_t *o = g->stride;
    bc_fill_scalar(g, bc, T);
    for (int d = 0; d < 2; d++) {
        int e = 1 - d;
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j <= g->n[1]; j++) {
                if (!face_exists(g, d, i, j))
                    continue;
                ptrdiff_t p = grid_idx(g, i, j, 0), left = p - o[d];
                double u = vel[d][p];
                double low = u * (u > 0.0 ? T[left] : T[p]), high = low;
                if (compress) {
                    double grad_d = (T[p] - T[left]) / g->h[d];
                    double grad_e = 0.25 * (T[p + o[e]] - T[p - o[e]] + T[left + o[e]] -
                                            T[left - o[e]]) / g->h[e];
                    double n_d = grad_d / (hypot(grad_d, grad_e) + 1e-8 / g->h[d]);
                    double u_r = fabs(u) * n_d;
                    double compression = u_r > 0.0 ? u_r * T[left] * (1.0 - T[p])
                                                   : u_r * T[p] * (1.0 - T[left]);
                    high = u * 0.5 * (T[left] + T[p]) + compression;
                }
                w->low[d][p] = low;
                w->anti[d][p] = high - low;
            }
    }
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++) {
            ptrdiff_t p = grid_idx(g, i, j, 0);
            double net = 0.0;
            for (int d = 0; d < 2; d++)
                net -= dt / g->h[d] * (w->low[d][p + o[d]] - w->low[d][p]);
            w->t_low[p] = T[p] + net;
        }
    if (!compress) {
        for (size_t q = 0; q < g->size; q++)
            T[q] = w->t_low[q];
        return;
    }
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++) {
            ptrdiff_t p = grid_idx(g, i, j, 0);
            double hi = fmax(T[p], w->t_low[p]), lo = fmin(T[p], w->t_low[p]);
            for (int d = 0; d < 2; d++)
                for (int side = -1; side <= 1; side += 2) {
                    int idx[2] = {i, j};
                    idx[d] += side;
                    if (idx[d] < 0 || idx[d] >= g->n[d])
                        continue;
                    ptrdiff_t q = p + side * o[d];
                    hi = fmax(hi, fmax(T[q], w->t_low[q]));
                    lo = fmin(lo, fmin(T[q], w->t_low[q]));
                }
            hi = fmin(hi, 1.0);
            lo = fmax(lo, 0.0);
            double in = 0.0, out = 0.0;
            for (int d = 0; d < 2; d++) {
                double r = dt / g->h[d], a_low = w->anti[d][p], a_high = w->anti[d][p + o[d]];
                in += r * (fmax(a_low, 0.0) - fmin(a_high, 0.0));
                out += r * (fmax(a_high, 0.0) - fmin(a_low, 0.0));
            }
            w->r_plus[p] = in > 0.0 ? fmin(1.0, (hi - w->t_low[p]) / in) : 0.0;
            w->r_minus[p] = out > 0.0 ? fmin(1.0, (w->t_low[p] - lo) / out) : 0.0;
        }
    for (int d = 0; d < 2; d++)
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j <= g->n[1]; j++) {
                if (!face_exists(g, d, i, j))
                    continue;
                ptrdiff_t p = grid_idx(g, i, j, 0), left = p - o[d];
                int idx[2] = {i, j};
                if (idx[d] == 0 || idx[d] == g->n[d]) { /* closed boundary */
                    w->anti[d][p] = 0.0;
                    continue;
                }
                double a = w->anti[d][p];
                double c = a > 0.0 ? fmin(w->r_plus[p], w->r_minus[left])
                                   : fmin(w->r_plus[left], w->r_minus[p]);
                w->anti[d][p] = c * a;
            }
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++) {
            ptrdiff_t p = grid_idx(g, i, j, 0);
            double net = 0.0;
            for (int d = 0; d < 2; d++)
                net -= dt / g->h[d] * (w->anti[d][p + o[d]] - w->anti[d][p]);
            T[p] = w->t_low[p] + net;
        }
}

static void compare_algebraic(int compress)
{
    struct grid g;
    make_grid(&g, 100, 100, 1, 1.0, 1.0, 0.01);
    struct boundary bc = all_kind(BC_SLIP);
    bc.face[2][0] = bc.face[2][1] = BC_PERIODIC;
    double *T = field_alloc(&g), *T0 = field_alloc(&g), *vel[3];
    struct algebraic_work w;
    for (int d = 0; d < 3; d++)
        vel[d] = field_alloc(&g);
    for (int d = 0; d < 2; d++) {
        w.low[d] = field_alloc(&g);
        w.anti[d] = field_alloc(&g);
    }
    w.t_low = field_alloc(&g);
    w.r_plus = field_alloc(&g);
    w.r_minus = field_alloc(&g);
    fill_fraction(&g, slotted_disc, 32, T);
    memcpy(T0, T, g.size * sizeof *T);
    rotate(&g, 0.0, vel);
    bc_fill_velocity(&g, &bc, vel);
    double cfl[3];
    long nsteps = (long)ceil(vof_cfl(&g, vel, 1.0, cfl) / VOF_CFL_MAX);
    double dt = 1.0 / nsteps, mass0 = total(&g, T), drift = 0.0, lo = 0.0, hi = 1.0;
    for (long s = 0; s < nsteps; s++) {
        algebraic_step(&g, &bc, vel, dt, compress, T, &w);
        drift = fmax(drift, fabs(total(&g, T) - mass0) / mass0);
        double a, b;
        bounds(&g, T, &a, &b);
        lo = fmin(lo, a);
        hi = fmax(hi, b);
    }
    double err = l1_diff(&g, T, T0), width = band_cells(&g, T) / (slotted_perimeter() / g.h[0]);
    print_message("Zalesak, %s (%ld steps): L1 shape error %.3e cells = %.3e of the area, band "
                  "%.2f cells across, mass drift %.1e, T in [%.1e, 1 + %.1e]\n",
                  compress ? "upwind + FCT-limited compression" : "first-order upwind", nsteps,
                  err, err / mass0, width, drift, lo, hi - 1.0);
    assert_true(drift <= MASS_TOL);
    assert_true(lo >= -BOUND_TOL && hi <= 1.0 + BOUND_TOL);
    assert_true(width > 2.0); /* PLIC: 1.04 */
    field_free(T);
    field_free(T0);
    for (int d = 0; d < 3; d++)
        field_free(vel[d]);
    for (int d = 0; d < 2; d++) {
        field_free(w.low[d]);
        field_free(w.anti[d]);
    }
    field_free(w.t_low);
    field_free(w.r_plus);
    field_free(w.r_minus);
}

static void test_compare_algebraic(void **state)
{
    (void)state;
    compare_algebraic(0);
    compare_algebraic(1);
}

void group_vof(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_2d),
        cmocka_unit_test(test_round_trip_3d),
        cmocka_unit_test(test_slab_fraction),
        cmocka_unit_test(test_reconstruct_planes),
        cmocka_unit_test(test_cfl),
        cmocka_unit_test(test_mirror_inflow),
        cmocka_unit_test(test_translate_disc_thin),
        cmocka_unit_test(test_translate_sphere),
        cmocka_unit_test(test_zalesak),
        cmocka_unit_test(test_single_vortex),
        cmocka_unit_test(test_compare_algebraic),
    };
    RUN_GROUP(t, "vof", tests);
}
