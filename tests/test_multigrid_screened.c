/* The multigrid's screening term (group multigrid; multigrid.h:
 * multigrid_set_operator's cell term m): div(a grad phi) - c phi = rhs, the
 * nonlocal fluidity's equation (physics/ngf.h), with a and c varying over
 * the domain.
 *
 *  - manufactured solutions phi = X(x) Z(z) on the unit square for periodic,
 *    wall (zero flux) and Dirichlet conditions, a = 1 + sin(2 pi x) cos(2 pi
 *    z) / 2 on the faces, c = 4 + 3 cos(2 pi x) sin(pi z) >= 1 at the
 *    centres: the error at the centres falls at second order over 16^2,
 *    32^2, 64^2;
 *  - PCG iterations per solve bounded as the grid refines (to 128^2);
 *  - all faces zero-flux: with c > 0 the problem is not singular, and the
 *    solution's mean (X = 1 + cos(pi x) has mean 1 per direction) is
 *    returned, not removed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid/grid.h"
#include "solvers/multigrid.h"
#include "test_main.h"
#include "test_poisson_kinds.h"

static const double pi = 3.14159265358979323846;

/* One direction's factor of phi and its first two derivatives, for the
 * direction's conditions: periodic, zero flux at both ends, zero at both. */
static double factor(enum kind k, double x, double *d1, double *d2)
{
    switch (k) {
    case K_P:
        *d1 = 2.0 * pi * cos(2.0 * pi * x + 0.3);
        *d2 = -4.0 * pi * pi * sin(2.0 * pi * x + 0.3);
        return sin(2.0 * pi * x + 0.3);
    case K_NN:
        *d1 = -pi * sin(pi * x);
        *d2 = -pi * pi * cos(pi * x);
        return 1.0 + cos(pi * x);
    default: /* K_DD */
        *d1 = pi * cos(pi * x);
        *d2 = -pi * pi * sin(pi * x);
        return sin(pi * x);
    }
}

static double coef_a(double x, double z, double *ax, double *az)
{
    *ax = pi * cos(2.0 * pi * x) * cos(2.0 * pi * z);
    *az = -pi * sin(2.0 * pi * x) * sin(2.0 * pi * z);
    return 1.0 + 0.5 * sin(2.0 * pi * x) * cos(2.0 * pi * z);
}

static double coef_c(double x, double z)
{
    return 4.0 + 3.0 * cos(2.0 * pi * x) * sin(pi * z);
}

/* Solves the manufactured problem of kinds kx (x) and kz (z) on n^2 cells;
 * returns the max error at the centres, *iters the PCG iterations to a
 * relative residual of 1e-10 from zero. */
static double screened_mms(int n, enum kind kx, enum kind kz, int *iters)
{
    struct grid g;
    const int nn[3] = {n, 1, n};
    const double len[3] = {1.0, 1.0 / n, 1.0};
    assert_int_equal(grid_init(&g, nn, len), 0);
    const enum kind k[3] = {kx, K_P, kz};
    enum poisson_bc bc[3][2];
    make_bc(k, bc);
    double *a[3], *c = field_alloc(&g), *rhs = field_alloc(&g), *phi = field_alloc(&g);
    assert_true(c && rhs && phi);
    for (int d = 0; d < 3; d++) {
        a[d] = field_alloc(&g);
        assert_non_null(a[d]);
    }
    const double h = 1.0 / n;
    double ax, az;
    for (int i = 0; i <= n; i++)
        for (int l = 0; l <= n; l++) {
            ptrdiff_t m = grid_idx(&g, i, 0, l);
            a[0][m] = coef_a(i * h, (l + 0.5) * h, &ax, &az);
            a[1][m] = 1.0;
            a[2][m] = coef_a((i + 0.5) * h, l * h, &ax, &az);
        }
    for (int i = 0; i < n; i++)
        for (int l = 0; l < n; l++) {
            double x = (i + 0.5) * h, z = (l + 0.5) * h, x1, x2, z1, z2;
            double X = factor(kx, x, &x1, &x2), Z = factor(kz, z, &z1, &z2);
            double A = coef_a(x, z, &ax, &az);
            ptrdiff_t m = grid_idx(&g, i, 0, l);
            c[m] = coef_c(x, z);
            rhs[m] = A * (x2 * Z + X * z2) + ax * x1 * Z + az * X * z1 - c[m] * X * Z;
        }
    struct multigrid *mg = NULL;
    char err[256] = "";
    if (multigrid_create(&mg, &g, bc, NULL, err, sizeof err) != 0 ||
        multigrid_set_operator(mg, a, c, err, sizeof err) != 0)
        fail_msg("multigrid: %s", err);
    struct multigrid_stats st;
    assert_int_equal(multigrid_pcg(mg, rhs, phi, 1e-10, 100, &st), 0);
    *iters = st.cycles;
    double e = 0.0, x1, x2, z1, z2;
    for (int i = 0; i < n; i++)
        for (int l = 0; l < n; l++) {
            double ex = factor(kx, (i + 0.5) * h, &x1, &x2) * factor(kz, (l + 0.5) * h, &z1, &z2);
            e = fmax(e, fabs(phi[grid_idx(&g, i, 0, l)] - ex));
        }
    multigrid_destroy(mg);
    for (int d = 0; d < 3; d++)
        field_free(a[d]);
    field_free(c);
    field_free(rhs);
    field_free(phi);
    return e;
}

/* Measured: errors 1.26e-2, 3.14e-3, 7.86e-4 (periodic x, Dirichlet z) to
 * 9.64e-3, 2.42e-3, 6.05e-4 (all zero flux), orders 1.98 .. 2.01; 6 .. 8
 * PCG iterations on every grid.  Second order: each halving of h divides
 * the error by more than 3.5; the finest error below 2e-3 (C h^2 with C
 * <= 6.2 measured, phi of unit amplitude); the iterations grow by at most
 * 2 from 16^2 to 128^2 and stay <= 12.  A mean removed (the singular
 * treatment) would leave an error of 1 in the all-zero-flux problem. */
void test_multigrid_screened(void **state)
{
    (void)state;
    static const enum kind cases[][2] = {{K_P, K_DD}, {K_NN, K_DD}, {K_DD, K_NN}, {K_NN, K_NN},
                                         {K_P, K_NN}};
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        enum kind kx = cases[t][0], kz = cases[t][1];
        double e[3];
        int it[4];
        for (int r = 0; r < 3; r++)
            e[r] = screened_mms(16 << r, kx, kz, &it[r]);
        (void)screened_mms(128, kx, kz, &it[3]);
        print_message("screened multigrid x %s z %s: error %.3e %.3e %.3e (orders %.2f %.2f), "
                      "PCG iterations %d %d %d %d\n",
                      kind_name[kx], kind_name[kz], e[0], e[1], e[2], log2(e[0] / e[1]),
                      log2(e[1] / e[2]), it[0], it[1], it[2], it[3]);
        assert_true(e[0] / e[1] > 3.5 && e[1] / e[2] > 3.5);
        assert_true(e[2] < 2e-3);
        assert_true(it[3] <= it[0] + 2 && it[3] <= 12);
    }
}
