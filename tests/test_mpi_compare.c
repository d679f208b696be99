/* The group mpi's comparisons of a run on the ranks with one process's
 * (test_mpi.h): the splits a check runs on, each once, and a scene's
 * [result] lines against the same case run alone. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "app/run.h"
#include "platform/comm.h"
#include "test_main.h"
#include "test_mpi.h"

/* The ranks along each direction that MPI gives dims (run.c's too: the
 * directions a test splits are free there). */
static void resolve(const int dims[3], int got[3])
{
    const int split[3] = {1, 1, 1};
    char err[256] = "";
    const int rc = comm_cart_dims(dims, split, got, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
}

int test_splits(int n, const int ask[][3], int dims[][3])
{
    assert_true(n <= TEST_SPLITS_MAX);
    int count = 0, got[TEST_SPLITS_MAX][3];
    for (int s = 0; s < n; s++) {
        resolve(ask[s], got[count]);
        int seen = 0;
        for (int t = 0; t < count; t++)
            seen |= got[t][0] == got[count][0] && got[t][1] == got[count][1] &&
                    got[t][2] == got[count][2];
        if (seen)
            continue; /* the same blocks: the same computation again */
        for (int d = 0; d < 3; d++)
            dims[count][d] = ask[s][d];
        count++;
    }
    return count;
}

void check_scene_on_ranks(const char *file, int n, char *ov[], double tol, enum run_status want)
{
    struct muflow_case cs;
    test_load_case(&cs, file, n, ov);
    struct run_result one, all;
    char err[1024] = "";
    const struct run_options alone = {.one_process = 1}, split = {0};
    int rc = run_case_opts(&cs, &alone, &one, err, sizeof err);
    rc |= run_case_opts(&cs, &split, &all, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    const double a[4] = {one.errors.err_rms, one.errors.err_max, one.errors.err_rms_paper,
                         one.errors.headline},
                 b[4] = {all.errors.err_rms, all.errors.err_max, all.errors.err_rms_paper,
                         all.errors.headline};
    double rel = isnan(a[3]) ? INFINITY : 0.0;
    for (int v = 0; v < 4; v++)
        rel = isnan(a[v]) != isnan(b[v]) ? INFINITY
                                          : fmax(rel, fabs(b[v] - a[v]) / fabs(a[v]));
    const double exact = one.errors.headline_exact;
    const int near_exact = isnan(tol) ? isnan(exact)
                                      : fabs(one.errors.headline - exact) <= tol * fabs(exact);
    double bad = rc != RUN_OK || one.status != want || all.status != one.status ||
                 labs(all.steps - one.steps) > 1 || !(rel <= 1e-8) || !near_exact;
    comm_sum(&bad, 1);
    if (comm_rank() == 0)
        printf("    %s on %d ranks: %ld steps (alone %ld), %s %.10g (alone %.10g, exact %.10g), "
               "errors and headline within %.1e relative\n",
               cs.name, comm_size(), all.steps, one.steps, run_status_name(all.status),
               b[3], a[3], exact, rel);
    assert_true(bad == 0.0);
}

/* s's case split as dims asks against one's run of it (rc_one what that
 * run returned), as check_scene_lines says. */
static void compare_lines(const struct scene_lines *s, const struct muflow_case *cs,
                          const struct run_result *one, int rc_one, const int dims[3])
{
    struct run_result all;
    char err[1024] = "";
    const struct run_options split = {.dims = {dims[0], dims[1], dims[2]}};
    const int rc = rc_one | run_case_opts(cs, &split, &all, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    double rel = 0.0;
    for (const char *const *k = s->keys; *k; k++) {
        const double a = run_result_value(one, *k), b = run_result_value(&all, *k);
        rel = fmax(rel, isnan(a) || isnan(b) ? INFINITY
                        : a == b             ? 0.0
                                             : fabs(b - a) / fmax(fabs(a), fabs(b)));
    }
    /* a count of steps (the heap's tilt search: its solves' steps summed)
     * moves by a step as a run's steps do, the ranks' sums in MPI's order
     * ending a solve a step apart: within 1, as the steps, where 1e-8 of a
     * count would ask for the same count */
    const double counted = s->count ? fabs(run_result_value(&all, s->count) -
                                           run_result_value(one, s->count))
                                    : 0.0;
    const double m1 = run_result_value(one, "mass_error"),
                 m2 = run_result_value(&all, "mass_error");
    const double mass = isnan(m1) && isnan(m2) ? 0.0 : fabs(m2 - m1); /* none: 0 */
    double bad = rc != RUN_OK || one->status != s->want || all.status != one->status ||
                 labs(all.steps - one->steps) > 1 || !(rel <= 1e-8) || !(counted <= 1.0) ||
                 !(mass <= 1e-13);
    comm_sum(&bad, 1);
    if (comm_rank() == 0) {
        printf("    %s on %d ranks (%d x %d x %d asked): %ld steps (alone %ld), %s %s %.10g "
               "(alone %.10g), results within %.1e relative, mass_error within %.1e",
               cs->name, comm_size(), dims[0], dims[1], dims[2], all.steps, one->steps,
               run_status_name(all.status), s->keys[0], run_result_value(&all, s->keys[0]),
               run_result_value(one, s->keys[0]), rel, mass);
        if (s->count)
            printf(", %s %g (alone %g)", s->count, run_result_value(&all, s->count),
                   run_result_value(one, s->count));
        printf("\n");
    }
    assert_true(bad == 0.0);
}

/* One process's run of s's case (every rank's reference) into one, cs the
 * case loaded; what run_case_opts returned. */
static int run_alone(const struct scene_lines *s, struct muflow_case *cs, struct run_result *one)
{
    test_load_case(cs, s->file, s->n, s->ov);
    char err[1024] = "";
    const struct run_options alone = {.one_process = 1};
    const int rc = run_case_opts(cs, &alone, one, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    return rc;
}

void check_scene_lines(const struct scene_lines *s, const int dims[3])
{
    struct muflow_case cs;
    struct run_result one;
    const int rc = run_alone(s, &cs, &one);
    compare_lines(s, &cs, &one, rc, dims);
}

void check_scene_splits(const struct scene_lines *s, int n, const int ask[][3])
{
    int dims[TEST_SPLITS_MAX][3];
    const int splits = test_splits(n, ask, dims);
    struct muflow_case cs;
    struct run_result one;
    const int rc = run_alone(s, &cs, &one);
    for (int t = 0; t < splits; t++)
        compare_lines(s, &cs, &one, rc, dims[t]);
}
