/* Shared by the test groups: each tests/test_*.c defines one group runner
 * that adds its counts to a tally, and test_main.c prints the closing line;
 * the helpers they share are in test_util.h. */
#ifndef MUFLOW_TEST_MAIN_H
#define MUFLOW_TEST_MAIN_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include "test_util.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

struct test_tally {
    int run;
    int failed;
};

#define RUN_GROUP(tally, name, tests)                                                   \
    do {                                                                                \
        (tally)->run += (int)(sizeof(tests) / sizeof((tests)[0]));                      \
        (tally)->failed += _cmocka_run_group_tests(name, tests,                         \
                                                   sizeof(tests) / sizeof((tests)[0]),  \
                                                   NULL, NULL);                         \
    } while (0)

/* One runner per tests/test_<module>.c */
void group_rheology(struct test_tally *t);
void group_stretched(struct test_tally *t);
void group_poisson(struct test_tally *t);
void group_multigrid(struct test_tally *t);
/* test_multigrid_screened.c, run in group_multigrid */
void test_multigrid_screened(void **state);
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
void group_front(struct test_tally *t);
void group_boundary(struct test_tally *t);
void group_duct(struct test_tally *t);
void group_obstacle(struct test_tally *t);
void group_forces(struct test_tally *t);
void group_velocity_mg(struct test_tally *t);
void group_cases(struct test_tally *t);
void group_depth_averaged(struct test_tally *t);
void group_ngf(struct test_tally *t);
void group_time_scheme(struct test_tally *t);
void group_slope_release(struct test_tally *t);
void group_mpi(struct test_tally *t);
/* the mpi group's checkpoints on ranks (test_mpi_restart.c) */
void test_bagnold_checkpoint_ranks(void **state);
void test_checkpoint_fails_on_ranks(void **state);
void test_collapse_checkpoint_ranks(void **state);
void group_wall_shock(struct test_tally *t);

#endif
