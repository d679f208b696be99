/* Shared by the test groups: each tests/test_*.c defines one group runner
 * that adds its counts to a tally, and test_main.c prints the closing line. */
#ifndef MUFLOW_TEST_MAIN_H
#define MUFLOW_TEST_MAIN_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

struct test_tally {
    int run;
    int failed;
};

/* Deterministic pseudo-random numbers in [-1, 1) (a linear congruential
 * step; the tests' fields and coefficients). */
static inline double rand_pm1(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 4503599627370496.0 - 1.0; /* 2^53 / 2 */
}

#define RUN_GROUP(tally, name, tests)                                                   \
    do {                                                                                \
        (tally)->run += (int)(sizeof(tests) / sizeof((tests)[0]));                      \
        (tally)->failed += _cmocka_run_group_tests(name, tests,                         \
                                                   sizeof(tests) / sizeof((tests)[0]),  \
                                                   NULL, NULL);                         \
    } while (0)

/* Whole file, NUL-terminated; its length (without the NUL) in *len when len
 * is not NULL; fails the test when it cannot be read (caller frees). */
char *test_read_file(const char *path, size_t *len);

/* Each bad[i][0], one override of the case file case_path, is refused:
 * case_load returns 2 with a one-line message containing bad[i][1] (the
 * key it names). */
void test_bad_overrides(const char *case_path, const char *const bad[][2], size_t n);

/* A fresh folder under /tmp for a test's runs (mkdtemp, named after name),
 * with the overrides that write a run there and start another from it;
 * test_run_dir_remove deletes it and what the runs wrote. */
struct test_run_dir {
    char dir[64];
    char output[96];        /* output.dir=DIR */
    char initial_state[112]; /* solver.initial_state=DIR */
};
void test_run_dir_make(struct test_run_dir *d, const char *name);
void test_run_dir_remove(const struct test_run_dir *d);

/* Loads the case file with its n overrides and runs it to its end without
 * writing output (run_case with write_output 0), failing the test with the
 * message if either fails. */
struct muflow_case;
struct run_result;
void test_run_case(const char *file, int n, char *ov[], struct muflow_case *cs,
                   struct run_result *r);

/* One runner per tests/test_<module>.c */
void group_rheology(struct test_tally *t);
void group_stretched(struct test_tally *t);
void group_poisson(struct test_tally *t);
void group_multigrid(struct test_tally *t);
void group_case(struct test_tally *t);
void group_architecture(struct test_tally *t);
void group_viscous(struct test_tally *t);
void group_amg(struct test_tally *t);
void group_scenes(struct test_tally *t);
void group_bingham(struct test_tally *t);
void group_heap(struct test_tally *t);
void group_io(struct test_tally *t);
void group_corpus(struct test_tally *t);
void group_vof(struct test_tally *t);
void group_tools(struct test_tally *t);
void group_repro(struct test_tally *t);
void group_two_phase(struct test_tally *t);
void group_outputs(struct test_tally *t);
void group_honest(struct test_tally *t);
void group_bedload(struct test_tally *t);
void group_collapse(struct test_tally *t);
void group_boundary(struct test_tally *t);
void group_duct(struct test_tally *t);
void group_obstacle(struct test_tally *t);
void group_velocity_mg(struct test_tally *t);
void group_cases(struct test_tally *t);

#endif
