/* Reproducibility across processes, and the thread policy of the command.
 *
 * docs/numerics/reproducibility.md: the same binary, input, thread count
 * and machine give the same bits.  Within one process that follows from
 * fixed-order reductions (kernels/vector.c) and static schedules; across
 * processes it also needs the same FFTW plans, which FFTW_ESTIMATE gives
 * (FFTW_MEASURE times candidate plans and may choose another one in each
 * process).  So the same
 * case is run by two separate build/muflow processes and their summaries
 * ([result] without wall_seconds) and field files (every dataset, read with
 * the HDF5 library) are compared bit for bit: the thin bagnold grid (one
 * thread below the kernels' size threshold) to its steady state, and a small
 * 3D grid at 2 threads (kernels, reductions and transforms threaded) for a
 * few steps.
 *
 * The run-time defaults: muflow re-executes itself with a short spin count
 * (GOMP_SPINCOUNT=1000) unless the user set OMP_WAIT_POLICY or GOMP_SPINCOUNT
 * or runs one thread (sleeping at once instead when the machine is busy at
 * start: MUFLOW_MACHINE_LOAD stands for the load average), and with malloc's
 * huge pages (GLIBC_TUNABLES) unless the user set that (src/app/main.c);
 * libgomp's OMP_DISPLAY_ENV=verbose prints the spin count each image uses,
 * one block per image. */
#define _POSIX_C_SOURCE 200809L /* PATH_MAX */
#include <limits.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_main.h"

#define CASES_DIR "../cases/"

/* The step count of a summary's [result]. */
static long steps_of(const char *result)
{
    const char *s = strstr(result, "\nsteps = ");
    assert_non_null(s);
    return strtol(s + 9, NULL, 10);
}

/* Runs `threads` muflow case + overrides into dir/a and dir/b and compares. */
static void two_processes(const char *threads, const char *ovr, int expect_status)
{
    char bin[PATH_MAX], dir[64], cmd[2 * PATH_MAX + 1024], out[2][700];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "repro");
    for (int m = 0; m < 2; m++) {
        snprintf(out[m], sizeof out[m], "%s/%c", dir, 'a' + m);
        snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=%s '%s' %s output.dir='%s' output.quiet=on 2>&1",
                 threads, bin, ovr, out[m]);
        char *text;
        int st = test_sh(cmd, &text);
        if (st != expect_status)
            print_error("%s\n-> status %d\n%s\n", cmd, st, text);
        assert_int_equal(st, expect_status);
        free(text);
    }
    char *ra = test_summary_result(out[0]), *rb = test_summary_result(out[1]);
    print_message("%s threads, %s:\n%s", threads, ovr, ra);
    assert_string_equal(ra, rb);
    test_same_fields(out[0], out[1], steps_of(ra));
    free(ra);
    free(rb);
    test_tmp_remove(dir);
}

/* bagnold as shipped: 2 x 1 x 40, steady after 15 steps. */
static void test_two_processes_bagnold(void **state)
{
    (void)state;
    two_processes("2", CASES_DIR "bagnold.ini", 0);
}

/* 32 x 32 x 40 cells (48,552 slots, above KERNEL_PARALLEL_MIN): the threaded
 * path, 4 steps of the steady march (stopped by max_steps: status 3). */
static void test_two_processes_3d(void **state)
{
    (void)state;
    two_processes("2",
                  CASES_DIR "bagnold.ini domain.nx=32 domain.ny=32 domain.lx=11.2 "
                            "domain.ly=11.2 solver.preconditioner=line solver.max_steps=4",
                  3);
}

/* The column collapse on 128 x 40 cells to t = 1 (100 steps): the
 * projection's factorisation on a second thread beside each implicit step
 * (march/step.c).  A version whose OpenMP settings leaked between the two
 * threads gave histories that differed in the last bits from step 5 to 24
 * in three runs of five; with such a leak put back on purpose this test
 * failed in three runs of four (a race: it cannot fail every time). */
static void test_two_processes_collapse(void **state)
{
    (void)state;
    two_processes("2",
                  CASES_DIR "collapse.ini domain.nx=128 domain.nz=40 domain.ly=0.0390625 "
                            "domain.lz=1.5625 collapse.viscosity_clip=on "
                            "physics.advection_scheme=vanleer solver.end_time=1",
                  0);
}

/* The last "GOMP_SPINCOUNT = 'N'" libgomp prints (one block per image). */
static long last_spincount(const char *text, int *blocks)
{
    long v = -1;
    *blocks = 0;
    for (const char *s = strstr(text, "GOMP_SPINCOUNT = '"); s;
         s = strstr(s + 1, "GOMP_SPINCOUNT = '")) {
        v = strtol(s + 18, NULL, 10);
        (*blocks)++;
    }
    return v;
}

#define LARGE "domain.nx=32 domain.ny=32 domain.nz=32 domain.lx=14 domain.ly=14"

/* The last "OMP_NUM_THREADS = 'N'" libgomp prints: the image that runs. */
static long last_threads(const char *text)
{
    long v = -1;
    for (const char *s = strstr(text, "OMP_NUM_THREADS = '"); s;
         s = strstr(s + 1, "OMP_NUM_THREADS = '"))
        v = strtol(s + 19, NULL, 10);
    return v;
}

/* On a busy machine (MUFLOW_MACHINE_LOAD standing for the load average) a
 * steady march on a grid below the kernels' threshold runs on one thread when the user left
 * the count to OpenMP, keeps the user's count otherwise, and a larger grid
 * keeps its threads, which sleep at once. */
static void test_busy_threads(void **state)
{
    (void)state;
    if (omp_get_num_procs() < 2)
        skip();
    char bin[PATH_MAX], cmd[PATH_MAX + 512];
    test_muflow_bin(bin, sizeof bin);
    char dir[64];
    test_tmp_make(dir, sizeof dir, "busy");
    struct {
        const char *env, *grid;
        long threads, spin;
    } cases[] = {
        {"MUFLOW_MACHINE_LOAD=64", "domain.nx=60 domain.nz=60", 1, -1},
        /* a transient step keeps its threads, asleep */
        {"MUFLOW_MACHINE_LOAD=64", "domain.nx=60 domain.nz=60 solver.mode=transient", 2, 0},
        {"MUFLOW_MACHINE_LOAD=0", "domain.nx=60 domain.nz=60", 2, 1000},
        {"MUFLOW_MACHINE_LOAD=64 OMP_NUM_THREADS=2", "domain.nx=60 domain.nz=60", 2, 0},
        {"MUFLOW_MACHINE_LOAD=64", LARGE, 2, 0},
        {"MUFLOW_MACHINE_LOAD=64", "", 1, -1}, /* the thin grid too */
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        snprintf(cmd, sizeof cmd,
                 "env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u GLIBC_TUNABLES -u OMP_NUM_THREADS "
                 "OMP_DISPLAY_ENV=verbose %s '%s' ../cases/bagnold.ini %s solver.max_steps=1 "
                 "output.fields=off output.dir=%s 2>&1",
                 cases[c].env, bin, cases[c].grid, dir);
        char *text;
        int st = test_sh(cmd, &text);
        int blocks;
        long spin = last_spincount(text, &blocks), threads = last_threads(text);
        print_message("%s %s: OMP_NUM_THREADS %ld, GOMP_SPINCOUNT %ld\n", cases[c].env,
                      cases[c].grid, threads, spin);
        assert_true(st == 0 || st == 3);
        /* the thin grid is set to one thread in the running image (the
         * run's header says so), the others by the environment */
        if (!cases[c].grid[0])
            assert_non_null(strstr(text, ", 1 thread,"));
        else if (omp_get_num_procs() == 2 || cases[c].threads == 1)
            assert_int_equal(threads, cases[c].threads);
        if (cases[c].spin >= 0)
            assert_int_equal(spin, cases[c].spin);
        free(text);
    }
    test_tmp_remove(dir);
}

static void test_wait_policy(void **state)
{
    (void)state;
    char bin[PATH_MAX], cmd[PATH_MAX + 512];
    test_muflow_bin(bin, sizeof bin);
    char dir[64];
    test_tmp_make(dir, sizeof dir, "policy");
    struct {
        const char *env;
        long spin;  /* expected spin count of the image that runs, -1: any above 0 */
        int blocks; /* images started: 2 when muflow re-executes itself */
        const char *grid;
    } cases[] = {
        /* a 32^3 grid opens parallel regions: no policy set, short spinning
         * on an idle machine, sleeping at once (passive: 0) on a busy one */
        {"OMP_NUM_THREADS=2 MUFLOW_MACHINE_LOAD=0", 1000, 2, LARGE},
        {"OMP_NUM_THREADS=2 MUFLOW_MACHINE_LOAD=64", 0, 2, LARGE},
        /* the user's choices are kept; the huge pages alone still re-execute */
        {"OMP_NUM_THREADS=2 OMP_WAIT_POLICY=active", -1, 2, LARGE},
        {"OMP_NUM_THREADS=2 GOMP_SPINCOUNT=5000 MUFLOW_MACHINE_LOAD=64", 5000, 2, LARGE},
        {"OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive", 0, 2, LARGE},
        /* both set by the user (an empty GLIBC_TUNABLES too): no re-exec */
        {"OMP_NUM_THREADS=2 GOMP_SPINCOUNT=5000 GLIBC_TUNABLES=", 5000, 1, LARGE},
        {"OMP_NUM_THREADS=1", -1, 2, LARGE},       /* one thread: libgomp's own count */
        {"OMP_NUM_THREADS=1 GLIBC_TUNABLES=", -1, 1, LARGE},
        {"OMP_NUM_THREADS=2", -1, 1, ""},          /* 2 x 1 x 40: no re-exec */
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        snprintf(cmd, sizeof cmd,
                 "env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u GLIBC_TUNABLES OMP_DISPLAY_ENV=verbose %s '%s' "
                 "../cases/bagnold.ini %s solver.max_steps=1 output.fields=off output.quiet=on "
                 "output.dir=%s 2>&1",
                 cases[c].env, bin, cases[c].grid, dir);
        int blocks;
        char *text;
        int st = test_sh(cmd, &text);
        long spin = last_spincount(text, &blocks);
        print_message("%s %s: GOMP_SPINCOUNT %ld, %d image(s)\n", cases[c].env, cases[c].grid,
                      spin, blocks);
        assert_true(st == 0 || st == 3); /* steady, or stopped at max_steps */
        assert_non_null(strstr(text, "bagnold: "));
        assert_int_equal(blocks, cases[c].blocks);
        if (cases[c].spin >= 0)
            assert_int_equal(spin, cases[c].spin);
        else
            assert_true(spin > 0);
        free(text);
    }
    test_tmp_remove(dir);
}

void group_repro(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wait_policy),
        cmocka_unit_test(test_busy_threads),
        cmocka_unit_test(test_two_processes_bagnold),
        cmocka_unit_test(test_two_processes_3d),
        cmocka_unit_test(test_two_processes_collapse),
    };
    RUN_GROUP(t, "repro", tests);
}
