/* Tests of the FFT Poisson solver (src/solvers/poisson_fft.c).
 *
 * Two kinds of check:
 *  - manufactured solutions: a smooth exact phi satisfying the continuous
 *    boundary conditions, rhs = its analytic Laplacian at the cell centres;
 *    the max-norm error must fall at second order between n and 2n cells;
 *  - the discrete operator itself: the 7-point Laplacian of the returned phi,
 *    with the ghost values the conditions imply (neumann ghost = interior,
 *    dirichlet ghost = -interior, periodic wrap), must reproduce rhs (minus its
 *    mean when no face is Dirichlet) to round-off, for every combination of
 *    conditions and for tiny, odd and collapsed (n = 1) directions. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "grid/grid.h"
#include "solvers/poisson.h"
#include "test_main.h"
#include "test_poisson_kinds.h"

static const double pi = 3.14159265358979323846;

/* 1D exact profiles on [0, L], each satisfying the conditions of its kind and
 * none an eigenfunction of the discrete operator (so the tests see genuine
 * truncation error, boundary cells included).  PR_ONE: constant (trivial or
 * collapsed direction; fits periodic and neumann). */
enum profile { PR_P = 0, PR_NN, PR_DD, PR_ND, PR_DN, PR_ONE };

static double prof_f(enum profile p, double x, double L)
{
    double u = x / L;
    switch (p) {
    case PR_P: /* periodic */
        return exp(sin(2.0 * pi * u));
    case PR_NN: /* f'(0) = f'(L) = 0 */
        return cos(pi * u) + u * u * (3.0 - 2.0 * u);
    case PR_DD: /* f(0) = f(L) = 0 */
        return sin(pi * u) * exp(u);
    case PR_ND: /* f'(0) = 0, f(L) = 0 */
        return cos(0.5 * pi * u) + 0.5 * (1.0 - u * u) * (1.0 - u * u);
    case PR_DN: /* mirror of PR_ND: f(0) = 0, f'(L) = 0 */
        return prof_f(PR_ND, L - x, L);
    case PR_ONE:
        return 1.0;
    }
    return 0.0;
}

static double prof_f2(enum profile p, double x, double L)
{
    double u = x / L, a;
    switch (p) {
    case PR_P:
        a = 2.0 * pi / L;
        return a * a * (cos(2.0 * pi * u) * cos(2.0 * pi * u) - sin(2.0 * pi * u)) *
               exp(sin(2.0 * pi * u));
    case PR_NN:
        a = pi / L;
        return -a * a * cos(pi * u) + (6.0 - 12.0 * u) / (L * L);
    case PR_DD:
        a = pi / L;
        return exp(u) * ((1.0 / (L * L) - a * a) * sin(pi * u) + 2.0 * a / L * cos(pi * u));
    case PR_ND:
        a = 0.5 * pi / L;
        return -a * a * cos(0.5 * pi * u) + (-2.0 + 6.0 * u * u) / (L * L);
    case PR_DN:
        return prof_f2(PR_ND, L - x, L);
    case PR_ONE:
        return 0.0;
    }
    return 0.0;
}

/* Value of f at the neighbour of cell c in direction d (s = -1 or +1), from the
 * ghost value the boundary condition implies. */
static double neighbour(const struct grid *g, const enum poisson_bc bc[3][2], const double *f,
                        const int c[3], int d, int s)
{
    int q[3] = {c[0], c[1], c[2]};
    q[d] += s;
    double sign = 1.0;
    if (q[d] < 0 || q[d] >= g->n[d]) {
        enum poisson_bc b = bc[d][q[d] < 0 ? 0 : 1];
        if (b == POISSON_PERIODIC) {
            q[d] = q[d] < 0 ? g->n[d] - 1 : 0;
        } else {
            q[d] = c[d];
            if (b == POISSON_DIRICHLET)
                sign = -1.0;
        }
    }
    return sign * f[grid_idx(g, q[0], q[1], q[2])];
}

static double discrete_lap(const struct grid *g, const enum poisson_bc bc[3][2], const double *f,
                           int i, int j, int k)
{
    const int c[3] = {i, j, k};
    double centre = f[grid_idx(g, i, j, k)], sum = 0.0;
    for (int d = 0; d < 3; d++)
        sum += (neighbour(g, bc, f, c, d, -1) - 2.0 * centre + neighbour(g, bc, f, c, d, +1)) /
               (g->h[d] * g->h[d]);
    return sum;
}

static double interior_mean(const struct grid *g, const double *f)
{
    double s = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                s += f[grid_idx(g, i, j, k)];
    return s / (double)grid_cells(g);
}

/* max |lap_h(phi) - (rhs - mean)| / max |rhs - mean| over the interior. */
static double relative_residual(const struct grid *g, const enum poisson_bc bc[3][2],
                                const double *rhs, const double *phi)
{
    double mean = is_singular(bc) ? interior_mean(g, rhs) : 0.0;
    double rmax = 0.0, emax = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                double r = rhs[grid_idx(g, i, j, k)] - mean;
                rmax = fmax(rmax, fabs(r));
                emax = fmax(emax, fabs(discrete_lap(g, bc, phi, i, j, k) - r));
            }
    return rmax > 0.0 ? emax / rmax : emax;
}

struct mms_result {
    double err;   /* max |phi - exact| / max |exact| (means removed if singular) */
    double resid; /* relative residual of the discrete equation */
};

/* Solves the manufactured problem phi = fx(x) fy(y) fz(z) on an n grid. */
static struct mms_result run_mms(const int n[3], const double len[3], const enum kind k[3],
                                 const enum profile p[3])
{
    struct grid g;
    assert_int_equal(grid_init(&g, n, len), 0);
    enum poisson_bc bc[3][2];
    make_bc(k, bc);
    double *rhs = field_alloc(&g), *phi = field_alloc(&g), *ex = field_alloc(&g);
    assert_non_null(rhs);
    assert_non_null(phi);
    assert_non_null(ex);

    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int l = 0; l < n[2]; l++) {
                double x = (i + 0.5) * g.h[0], y = (j + 0.5) * g.h[1], z = (l + 0.5) * g.h[2];
                double fx = prof_f(p[0], x, len[0]), fy = prof_f(p[1], y, len[1]),
                       fz = prof_f(p[2], z, len[2]);
                ptrdiff_t m = grid_idx(&g, i, j, l);
                ex[m] = fx * fy * fz;
                rhs[m] = prof_f2(p[0], x, len[0]) * fy * fz + fx * prof_f2(p[1], y, len[1]) * fz +
                         fx * fy * prof_f2(p[2], z, len[2]);
            }

    struct poisson_fft *ps = NULL;
    char err[256] = "";
    int rc = poisson_fft_create(&ps, &g, bc, err, sizeof(err));
    if (rc != 0)
        fail_msg("poisson_fft_create: %s", err);
    poisson_fft_solve(ps, rhs, phi);

    int singular = is_singular(bc);
    double mphi = 0.0, mex = 0.0;
    if (singular) {
        mphi = interior_mean(&g, phi);
        mex = interior_mean(&g, ex);
        assert_true(fabs(mphi) < 1e-12 * (1.0 + fabs(mex)));
    }
    double emax = 0.0, xmax = 0.0;
    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int l = 0; l < n[2]; l++) {
                ptrdiff_t m = grid_idx(&g, i, j, l);
                emax = fmax(emax, fabs((phi[m] - mphi) - (ex[m] - mex)));
                xmax = fmax(xmax, fabs(ex[m] - mex));
            }
    struct mms_result res = {emax / xmax, relative_residual(&g, bc, rhs, phi)};

    poisson_fft_destroy(ps);
    field_free(rhs);
    field_free(phi);
    field_free(ex);
    return res;
}

/* Runs at n and 2n; asserts second order, the fine-grid error bound and the
 * discrete residual of both solves. */
static void check_convergence(const char *label, const int n[3], const double len[3],
                              const enum kind k[3], const enum profile p[3], double bound)
{
    int n2[3] = {2 * n[0], 2 * n[1], 2 * n[2]};
    for (int d = 0; d < 3; d++)
        if (n[d] == 1)
            n2[d] = 1; /* collapsed directions stay collapsed */
    struct mms_result r1 = run_mms(n, len, k, p), r2 = run_mms(n2, len, k, p);
    double order = log2(r1.err / r2.err);
    printf("    %-28s n=(%d,%d,%d) err %.3e -> %.3e  order %.3f  resid %.1e %.1e\n", label,
           n[0], n[1], n[2], r1.err, r2.err, order, r1.resid, r2.resid);
    assert_true(r1.resid < 1e-10);
    assert_true(r2.resid < 1e-10);
    assert_true(order >= 1.9);
    assert_true(r2.err < bound);
}

static const double test_len[3] = {2.0, 1.0, 1.5};

/* Kind K along direction d, periodic (with a periodic profile) along the others. */
static void one_direction(enum kind kd)
{
    static const enum profile prof_of[NKIND] = {PR_P, PR_NN, PR_DD, PR_ND, PR_DN};
    for (int d = 0; d < 3; d++) {
        enum kind k[3] = {K_P, K_P, K_P};
        enum profile p[3] = {PR_P, PR_P, PR_P};
        int n[3] = {16, 16, 16};
        n[(d + 2) % 3] = 16;
        n[(d + 1) % 3] = 24;
        n[d] = 16;
        k[d] = kd;
        p[d] = prof_of[kd];
        char label[64];
        snprintf(label, sizeof(label), "%s along %c", kind_name[kd], "xyz"[d]);
        check_convergence(label, n, test_len, k, p, 1e-2);
    }
}

static void test_periodic(void **state)
{
    (void)state;
    one_direction(K_P);
}

static void test_neumann(void **state)
{
    (void)state;
    one_direction(K_NN);
}

static void test_dirichlet(void **state)
{
    (void)state;
    one_direction(K_DD);
}

static void test_neumann_dirichlet(void **state)
{
    (void)state;
    one_direction(K_ND);
}

static void test_dirichlet_neumann(void **state)
{
    (void)state;
    one_direction(K_DN);
}

/* Inclined layer: periodic x and y, neumann bed / dirichlet surface in z. */
static void test_inclined_layer(void **state)
{
    (void)state;
    const int n[3] = {16, 16, 24};
    const enum kind k[3] = {K_P, K_P, K_ND};
    const enum profile p[3] = {PR_P, PR_P, PR_ND};
    check_convergence("inclined P,P,ND", n, test_len, k, p, 1e-2);
}

/* Chute: periodic x, neumann side walls in y, periodic z. */
static void test_chute(void **state)
{
    (void)state;
    const int n[3] = {24, 16, 12};
    const double len[3] = {3.0, 1.0, 0.5}; /* long in the flow direction */
    const enum kind k[3] = {K_P, K_NN, K_P};
    const enum profile p[3] = {PR_P, PR_NN, PR_P};
    check_convergence("chute P,NN,P", n, len, k, p, 1e-2);
}

/* No periodic direction: three different non-periodic pairs. */
static void test_walls(void **state)
{
    (void)state;
    const int n[3] = {16, 16, 24};
    const enum kind k1[3] = {K_NN, K_DD, K_DN};
    const enum profile p1[3] = {PR_NN, PR_DD, PR_DN};
    check_convergence("walls NN,DD,DN", n, test_len, k1, p1, 1e-2);
    const enum kind k2[3] = {K_DN, K_NN, K_ND};
    const enum profile p2[3] = {PR_DN, PR_NN, PR_ND};
    check_convergence("walls DN,NN,ND", n, test_len, k2, p2, 1e-2);
}

/* Collapsed directions (n = 1): periodic or neumann with a constant profile. */
static void test_collapsed(void **state)
{
    (void)state;
    const int n1[3] = {1, 1, 16};
    const enum kind k1[3] = {K_P, K_NN, K_ND};
    const enum profile p1[3] = {PR_ONE, PR_ONE, PR_ND};
    check_convergence("collapsed x,y; z ND", n1, test_len, k1, p1, 1e-2);
    const int n2[3] = {1, 16, 16};
    const enum kind k2[3] = {K_P, K_NN, K_P};
    const enum profile p2[3] = {PR_ONE, PR_NN, PR_P};
    check_convergence("collapsed x; chute y,z", n2, test_len, k2, p2, 1e-2);
    const int n3[3] = {16, 16, 1};
    const enum kind k3[3] = {K_P, K_DD, K_NN};
    const enum profile p3[3] = {PR_P, PR_DD, PR_ONE};
    check_convergence("collapsed z (neumann)", n3, test_len, k3, p3, 1e-2);
}


/* Every combination of conditions on small, odd, even and n = 1 grids with a
 * random rhs: the discrete equation must hold to round-off. */
static void test_discrete_all_kinds(void **state)
{
    (void)state;
    static const int sizes[][3] = {{1, 1, 1}, {1, 2, 3}, {5, 1, 4}, {7, 6, 1}, {3, 8, 5}};
    unsigned long long seed = 12345;
    double worst = 0.0;
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); s++)
        for (int t = 0; t < NTRIPLES; t++) {
            enum kind k[3];
            kind_triple(t, k);
            enum poisson_bc bc[3][2];
            make_bc(k, bc);
            struct grid g;
            assert_int_equal(grid_init(&g, sizes[s], test_len), 0);
            double *rhs = field_alloc(&g), *phi = field_alloc(&g);
            assert_non_null(rhs);
            assert_non_null(phi);
            for (int i = 0; i < g.n[0]; i++)
                for (int j = 0; j < g.n[1]; j++)
                    for (int l = 0; l < g.n[2]; l++)
                        rhs[grid_idx(&g, i, j, l)] = rand_pm1(&seed);
            struct poisson_fft *ps = NULL;
            char err[256] = "";
            if (poisson_fft_create(&ps, &g, bc, err, sizeof(err)) != 0)
                fail_msg("create %s,%s,%s: %s", kind_name[k[0]], kind_name[k[1]],
                         kind_name[k[2]], err);
            poisson_fft_solve(ps, rhs, phi);
            double r = relative_residual(&g, bc, rhs, phi);
            if (!(r < 1e-10))
                fail_msg("residual %.3e for %s,%s,%s on %dx%dx%d", r, kind_name[k[0]],
                         kind_name[k[1]], kind_name[k[2]], g.n[0], g.n[1], g.n[2]);
            worst = fmax(worst, r);
            if (is_singular(bc))
                assert_true(fabs(interior_mean(&g, phi)) < 1e-12);
            poisson_fft_destroy(ps);
            field_free(rhs);
            field_free(phi);
        }
    printf("    all 125 condition triples x 5 small grids: worst residual %.1e\n", worst);
}

/* phi may alias rhs; phi's ghosts are left alone; repeated solves agree. */
static void test_alias_ghosts_repeat(void **state)
{
    (void)state;
    const int n[3] = {6, 5, 7};
    struct grid g;
    assert_int_equal(grid_init(&g, n, test_len), 0);
    const enum kind k[3] = {K_P, K_DN, K_NN};
    enum poisson_bc bc[3][2];
    make_bc(k, bc);
    double *rhs = field_alloc(&g), *phi = field_alloc(&g), *inplace = field_alloc(&g);
    assert_non_null(rhs);
    assert_non_null(phi);
    assert_non_null(inplace);
    unsigned long long seed = 99;
    for (size_t m = 0; m < g.size; m++)
        phi[m] = 777.0; /* ghosts must keep this */
    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int l = 0; l < n[2]; l++)
                rhs[grid_idx(&g, i, j, l)] = rand_pm1(&seed);
    memcpy(inplace, rhs, g.size * sizeof(double));

    struct poisson_fft *ps = NULL;
    char err[256] = "";
    assert_int_equal(poisson_fft_create(&ps, &g, bc, err, sizeof(err)), 0);
    poisson_fft_solve(ps, rhs, phi);
    poisson_fft_solve(ps, inplace, inplace);
    for (int i = -1; i <= n[0]; i++)
        for (int j = -1; j <= n[1]; j++)
            for (int l = -1; l <= n[2]; l++) {
                ptrdiff_t m = grid_idx(&g, i, j, l);
                int interior = i >= 0 && i < n[0] && j >= 0 && j < n[1] && l >= 0 && l < n[2];
                if (interior)
                    assert_true(fabs(inplace[m] - phi[m]) <= 1e-14 * (1.0 + fabs(phi[m])));
                else
                    assert_true(phi[m] == 777.0 && inplace[m] == rhs[m]);
            }
    /* a second solve with the same plan gives the same answer */
    memcpy(inplace, phi, g.size * sizeof(double));
    poisson_fft_solve(ps, rhs, phi);
    assert_memory_equal(inplace, phi, g.size * sizeof(double));
    poisson_fft_destroy(ps);
    field_free(rhs);
    field_free(phi);
    field_free(inplace);
}

static void test_errors(void **state)
{
    (void)state;
    const int n[3] = {4, 4, 4};
    struct grid g;
    assert_int_equal(grid_init(&g, n, test_len), 0);
    enum poisson_bc bc[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                {POISSON_PERIODIC, POISSON_NEUMANN},
                                {POISSON_NEUMANN, POISSON_DIRICHLET}};
    static char dummy;
    struct poisson_fft *ps = (struct poisson_fft *)(void *)&dummy; /* must be reset to NULL */
    char err[256] = "";
    assert_int_equal(poisson_fft_create(&ps, &g, bc, err, sizeof(err)), -1);
    assert_null(ps);
    assert_string_equal(err, "poisson: periodic must be on both faces of direction y");
    bc[1][0] = POISSON_DIRICHLET;
    bc[2][1] = POISSON_PERIODIC;
    assert_int_equal(poisson_fft_create(&ps, &g, bc, err, sizeof(err)), -1);
    assert_string_equal(err, "poisson: periodic must be on both faces of direction z");
    bc[2][1] = POISSON_NEUMANN;
    assert_int_equal(poisson_fft_create(&ps, &g, bc, NULL, 0), 0); /* err may be NULL */
    poisson_fft_destroy(ps);
    poisson_fft_destroy(NULL);

    /* grid.c */
    const int bad_n[3] = {4, 0, 4};
    const double bad_len[3] = {1.0, 1.0, -1.0};
    assert_int_equal(grid_init(&g, bad_n, test_len), -1);
    assert_int_equal(grid_init(&g, n, bad_len), -1);
}

static void test_grid_layout(void **state)
{
    (void)state;
    const int n[3] = {3, 4, 5};
    struct grid g;
    assert_int_equal(grid_init(&g, n, test_len), 0);
    assert_int_equal(g.ext[0], 5);
    assert_int_equal(g.ext[1], 6);
    assert_int_equal(g.ext[2], 7);
    assert_int_equal(g.stride[2], 1);
    assert_int_equal(g.stride[1], 7);
    assert_int_equal(g.stride[0], 42);
    assert_int_equal(g.size, 210);
    assert_int_equal(grid_cells(&g), 60);
    assert_true(fabs(g.h[0] - 2.0 / 3.0) < 1e-15 && fabs(g.h[2] - 0.3) < 1e-15);
    assert_int_equal(grid_idx(&g, -1, -1, -1), 0);
    assert_int_equal(grid_idx(&g, 3, 4, 5), 209);
    double *f = field_alloc(&g);
    assert_non_null(f);
    assert_int_equal((uintptr_t)f % 64, 0);
    for (size_t m = 0; m < g.size; m++)
        assert_true(f[m] == 0.0);
    field_free(f);
}

void group_poisson(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_layout),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_periodic),
        cmocka_unit_test(test_neumann),
        cmocka_unit_test(test_dirichlet),
        cmocka_unit_test(test_neumann_dirichlet),
        cmocka_unit_test(test_dirichlet_neumann),
        cmocka_unit_test(test_inclined_layer),
        cmocka_unit_test(test_chute),
        cmocka_unit_test(test_walls),
        cmocka_unit_test(test_collapsed),
        cmocka_unit_test(test_discrete_all_kinds),
        cmocka_unit_test(test_alias_ghosts_repeat),
    };
    RUN_GROUP(t, "poisson", tests);
}
