/* Stretched directions (grid/grid.h, domain.<d>_band):
 * - the band's faces: the box's and the band's ends exact, cells of at most
 *   the band's size inside it, neighbours' sizes within the growth ratio
 *   outside (the fit's scaling only at the band's edge), the ghosts'
 *   widths mirrored or periodic, the centres' distances consistent; two
 *   bands with a gap growing from both; malformed and unordered bands
 *   refused;
 * - a band over the whole box is the uniform grid: the stress divergence,
 *   the strain and the divergence through the stretched loops equal the
 *   uniform ones to round-off on a random field;
 * - the stress divergence weighted by the control volumes is symmetric.
 * The solves on stretched grids: the pipe in the obstacle group. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "grid/grid.h"
#include "kernels/kernels.h"
#include "test_main.h"

static void test_axis_band(void **state)
{
    (void)state;
    char msg[300];
    for (int periodic = 0; periodic < 2; periodic++) {
        struct grid_axis ax;
        /* the granular cylinder's z: 30 long, far 1/4, band [13.5, 16.5] at 1/32 */
        const struct grid_band z = {13.5, 16.5, 1.0 / 32};
        assert_int_equal(grid_axis_build_bands(&ax, 30.0, 0.25, &z, 1, 1.1, periodic, msg, sizeof msg),
                         0);
        int n = ax.n;
        const double *xf = ax.xf + 1, *hc = ax.hc + 1, *hf = ax.hf + 1, *xc = ax.xc + 1;
        assert_true(xf[0] == 0.0 && xf[n] == 30.0);
        int lo = -1, hi = -1;
        for (int i = 0; i <= n; i++) {
            if (xf[i] == 13.5)
                lo = i;
            if (xf[i] == 16.5)
                hi = i;
        }
        assert_true(lo > 0 && hi == lo + 96); /* 3 / (1/32) cells, ends exact */
        for (int i = 0; i < n; i++) {
            assert_true(hc[i] > 0.0 && fabs(hc[i] - (xf[i + 1] - xf[i])) < 1e-14);
            assert_true(hc[i] <= 0.25 * 1.02); /* the far size, up to the fit */
            if (i >= lo && i < hi)
                assert_true(fabs(hc[i] - 1.0 / 32) < 1e-12);
            if (i > 0 && i != lo && i != hi) { /* within a side: the ratio alone */
                double r = hc[i] > hc[i - 1] ? hc[i] / hc[i - 1] : hc[i - 1] / hc[i];
                assert_true(r <= 1.1 * (1 + 1e-12));
            }
        }
        for (int i = 0; i <= n; i++)
            assert_true(fabs(hf[i] - (xc[i] - xc[i - 1])) < 1e-13);
        if (periodic) {
            assert_true(hc[-1] == hc[n - 1] && hc[n] == hc[0]);
        } else {
            assert_true(hc[-1] == hc[0] && hc[n] == hc[n - 1]);
            assert_true(fabs(xc[-1] + xc[0]) < 1e-15); /* the wall half-way */
        }
        grid_axis_free(&ax);
    }
    /* two bands: the gap's cells grow from both, the smaller first */
    struct grid_band two[2];
    assert_int_equal(grid_bands_parse(" 1 2 0.02 ; 6 6.5 0.05", two, 8), 2);
    assert_int_equal(grid_bands_parse("1 2 0.02; 6 6.5", two, 8), -1);
    assert_int_equal(grid_bands_parse("1 2 0.02 6 6.5 0.05", two, 8), -1);
    struct grid_axis ab;
    assert_int_equal(grid_axis_build_bands(&ab, 10.0, 0.5, two, 2, 1.1, 0, msg, sizeof msg), 0);
    {
        int n = ab.n, found = 0;
        const double *xf = ab.xf + 1, *hc = ab.hc + 1;
        assert_true(xf[0] == 0.0 && xf[n] == 10.0);
        int ends[4] = {-1, -1, -1, -1};
        const double at[4] = {1.0, 2.0, 6.0, 6.5};
        for (int i = 0; i <= n; i++)
            for (int e = 0; e < 4; e++)
                if (xf[i] == at[e])
                    ends[e] = i, found++;
        assert_int_equal(found, 4);
        assert_int_equal(ends[1] - ends[0], 50);
        assert_int_equal(ends[3] - ends[2], 10);
        for (int i = 1; i < n; i++) {
            int edge = 0;
            for (int e = 0; e < 4; e++)
                edge |= i == ends[e];
            double r = hc[i] > hc[i - 1] ? hc[i] / hc[i - 1] : hc[i - 1] / hc[i];
            if (!edge)
                assert_true(r <= 1.1 * (1 + 1e-12));
            assert_true(hc[i] <= 0.5 * 1.05);
        }
        grid_axis_free(&ab);
    }
    assert_int_equal(grid_axis_build_bands(&ab, 10.0, 0.5, (struct grid_band[]){{6, 7, 0.1}, {1, 2, 0.1}},
                                           2, 1.1, 0, msg, sizeof msg),
                     -1);
    assert_non_null(strstr(msg, "increasing order"));
    struct grid_axis ax;
    const struct grid_band reversed = {0.5, 0.4, 0.01}, coarse = {0.2, 0.4, 0.2};
    assert_int_equal(grid_axis_build_bands(&ax, 1.0, 0.1, &reversed, 1, 1.1, 0, msg, sizeof msg), -1);
    assert_int_equal(grid_axis_build_bands(&ax, 1.0, 0.1, &coarse, 1, 1.1, 0, msg, sizeof msg), -1);
    assert_non_null(strstr(msg, "must lie in [0, 1]"));
}

/* The three velocity components, viscosities at cells and edges: random. */
struct fields {
    double *v[3], *out[3], *ref[3], *Ac, *Ae[3], *div, *divref, *cn, *cnref, *e2[3], *e2ref[3];
};

static void fields_make(const struct grid *g, struct fields *f)
{
    srand(7);
    for (int c = 0; c < 3; c++) {
        f->v[c] = field_alloc(g);
        f->out[c] = field_alloc(g);
        f->ref[c] = field_alloc(g);
        f->Ae[c] = field_alloc(g);
        f->e2[c] = field_alloc(g);
        f->e2ref[c] = field_alloc(g);
        for (size_t p = 0; p < g->size; p++) {
            f->v[c][p] = rand() / (double)RAND_MAX - 0.5;
            f->Ae[c][p] = 0.5 + rand() / (double)RAND_MAX;
        }
    }
    f->Ac = field_alloc(g);
    f->div = field_alloc(g);
    f->divref = field_alloc(g);
    f->cn = field_alloc(g);
    f->cnref = field_alloc(g);
    for (size_t p = 0; p < g->size; p++)
        f->Ac[p] = 0.5 + rand() / (double)RAND_MAX;
}

static void fields_free(struct fields *f)
{
    for (int c = 0; c < 3; c++) {
        field_free(f->v[c]);
        field_free(f->out[c]);
        field_free(f->ref[c]);
        field_free(f->Ae[c]);
        field_free(f->e2[c]);
        field_free(f->e2ref[c]);
    }
    field_free(f->Ac);
    field_free(f->div);
    field_free(f->divref);
    field_free(f->cn);
    field_free(f->cnref);
}

static void all_faces(const struct grid *g, struct box act[3])
{
    for (int c = 0; c < 3; c++)
        for (int d = 0; d < 3; d++) {
            act[c].lo[d] = 0;
            act[c].hi[d] = g->n[d];
        }
}

static void test_full_band_is_uniform(void **state)
{
    (void)state;
    const int n[3] = {6, 5, 7};
    const double len[3] = {1.2, 1.0, 1.4};
    struct grid gu, gs;
    assert_int_equal(grid_init(&gu, n, len), 0);
    assert_int_equal(grid_init(&gs, n, len), 0);
    struct grid_axis ax[3];
    char msg[300];
    for (int d = 0; d < 3; d++) {
        assert_int_equal(grid_axis_build_bands(&ax[d], len[d], len[d] / n[d],
                                               &(struct grid_band){0.0, len[d], len[d] / n[d]}, 1,
                                               1.1, d == 1, msg, sizeof msg),
                         0);
        assert_int_equal(ax[d].n, n[d]);
        assert_int_equal(grid_set_axis(&gs, d, &ax[d]), 0);
    }
    assert_true(grid_stretched(&gs) && !grid_stretched(&gu));
    struct fields f;
    fields_make(&gu, &f);
    struct box act[3];
    all_faces(&gu, act);
    const double *Acell[3] = {f.Ac, f.Ac, f.Ac};
    const double *Aedge[3] = {f.Ae[0], f.Ae[1], f.Ae[2]};
    double worst = 0.0;
    for (int magnitude = 0; magnitude < 2; magnitude++) {
        if (magnitude) {
            kernel_stress_magnitude(&gu, act, Acell, Aedge, f.v, f.ref);
            kernel_stress_magnitude(&gs, act, Acell, Aedge, f.v, f.out);
        } else {
            kernel_stress_divergence(&gu, act, Acell, Aedge, f.v, f.ref);
            kernel_stress_divergence(&gs, act, Acell, Aedge, f.v, f.out);
        }
        for (int c = 0; c < 3; c++)
            for (size_t p = 0; p < gu.size; p++)
                worst = fmax(worst, fabs(f.out[c][p] - f.ref[c][p]) / (1.0 + fabs(f.ref[c][p])));
    }
    kernel_divergence(&gu, f.v, f.divref);
    kernel_divergence(&gs, f.v, f.div);
    kernel_strain(&gu, f.v, f.cnref, f.e2ref);
    kernel_strain(&gs, f.v, f.cn, f.e2);
    for (size_t p = 0; p < gu.size; p++) {
        worst = fmax(worst, fabs(f.div[p] - f.divref[p]) / (1.0 + fabs(f.divref[p])));
        worst = fmax(worst, fabs(f.cn[p] - f.cnref[p]) / (1.0 + fabs(f.cnref[p])));
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(f.e2[c][p] - f.e2ref[c][p]) / (1.0 + fabs(f.e2ref[c][p])));
    }
    print_message("full band against uniform: largest relative difference %.2e\n", worst);
    assert_true(worst < 1e-12);
    fields_free(&f);
    for (int d = 0; d < 3; d++)
        grid_axis_free(&ax[d]);
}

/* Weighted by the nodes' control volumes, the stress divergence is
 * symmetric: <w, V div tau(u)> = <u, V div tau(w)> for fields that vanish
 * outside the unknowns (each flux between two nodes enters both rows with
 * the same coefficient, the shear's cross terms included).  A difference
 * divided by a wrong distance anywhere (a cell's width for the centres'
 * distance) breaks it.  All three directions stretched, bands of different
 * sizes; the viscosities random.  (A truncation-error test would not do: at
 * a fixed growth ratio r the growing cells' truncation error of a second
 * derivative is O(r - 1), not O(h); the solution's error still falls as h^2,
 * as the pipe in the obstacle group measures.) */
static double weighted_dot(const struct grid *g, const struct box act[3], double *const a[3],
                           double *const b[3])
{
    double s = 0.0;
    for (int c = 0; c < 3; c++)
        for (int i = act[c].lo[0]; i < act[c].hi[0]; i++)
            for (int j = act[c].lo[1]; j < act[c].hi[1]; j++)
                for (int k = act[c].lo[2]; k < act[c].hi[2]; k++) {
                    const int idx[3] = {i, j, k};
                    double vol = 1.0;
                    for (int d = 0; d < 3; d++)
                        vol *= grid_node_width(g, c, d, idx[d]);
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    s += vol * a[c][p] * b[c][p];
                }
    return s;
}

static void test_stretched_symmetric(void **state)
{
    (void)state;
    const int n[3] = {8, 6, 10};
    const double len[3] = {2.0, 1.0, 3.0};
    const double band[3][3] = {{0.5, 1.0, 0.05}, {0.2, 0.4, 0.04}, {1.0, 1.5, 0.06}};
    struct grid g;
    assert_int_equal(grid_init(&g, n, len), 0);
    struct grid_axis ax[3];
    char msg[300];
    for (int d = 0; d < 3; d++) {
        assert_int_equal(grid_axis_build_bands(&ax[d], len[d], len[d] / n[d],
                                               &(struct grid_band){band[d][0], band[d][1], band[d][2]},
                                               1, 1.2, 0, msg, sizeof msg),
                         0);
        assert_int_equal(grid_set_axis(&g, d, &ax[d]), 0);
    }
    struct fields u, w;
    fields_make(&g, &u);
    fields_make(&g, &w);
    /* the unknowns: interior faces along c, every cell across */
    struct box act[3];
    for (int c = 0; c < 3; c++)
        for (int d = 0; d < 3; d++) {
            act[c].lo[d] = d == c ? 1 : 0;
            act[c].hi[d] = g.n[d];
        }
    srand(11);
    for (int c = 0; c < 3; c++)
        for (int i = -1; i <= g.n[0]; i++)
            for (int j = -1; j <= g.n[1]; j++)
                for (int k = -1; k <= g.n[2]; k++) {
                    const int idx[3] = {i, j, k};
                    int in = 1;
                    for (int d = 0; d < 3; d++)
                        in &= idx[d] >= act[c].lo[d] && idx[d] < act[c].hi[d];
                    ptrdiff_t p = grid_idx(&g, i, j, k);
                    u.v[c][p] = in ? rand() / (double)RAND_MAX - 0.5 : 0.0;
                    w.v[c][p] = in ? rand() / (double)RAND_MAX - 0.5 : 0.0;
                }
    const double *Acell[3] = {u.Ac, u.Ac, u.Ac};
    const double *Aedge[3] = {u.Ae[0], u.Ae[1], u.Ae[2]};
    kernel_stress_divergence(&g, act, Acell, Aedge, u.v, u.out);
    kernel_stress_divergence(&g, act, Acell, Aedge, w.v, w.out);
    double wu = weighted_dot(&g, act, w.v, u.out), uw = weighted_dot(&g, act, u.v, w.out);
    double size = sqrt(weighted_dot(&g, act, u.out, u.out) * weighted_dot(&g, act, w.v, w.v));
    print_message("stretched stress divergence: <w, V L u> %.15g, <u, V L w> %.15g (relative "
                  "difference %.2e)\n",
                  wu, uw, fabs(wu - uw) / size);
    assert_true(fabs(wu - uw) < 1e-12 * size);
    assert_true(fabs(wu) > 1e-3 * size); /* not a trivially vanishing pair */
    fields_free(&u);
    fields_free(&w);
    for (int d = 0; d < 3; d++)
        grid_axis_free(&ax[d]);
}

void group_stretched(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_axis_band),
        cmocka_unit_test(test_full_band_is_uniform),
        cmocka_unit_test(test_stretched_symmetric),
    };
    RUN_GROUP(t, "stretched", tests);
}
