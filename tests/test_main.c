/* Test runner: runs every group (or those named on the command line) and
 * ends with one closing line "tests: N passed, M failed".  A name that is no
 * group is an error (exit status 2, the groups listed) before anything runs.
 * The tests read their files relative to tests/ (../cases, fuzz/corpus), so
 * the runner first moves there: it stays when started in tests/, else it
 * looks for the repository from its own executable's folder upwards. */
#define _DEFAULT_SOURCE /* readlink */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "app/run.h" /* run_init */
#include "platform/comm.h"
#include "test_main.h"

static const struct {
    const char *name;
    void (*run)(struct test_tally *);
} groups[] = {
    {"rheology", group_rheology},
    {"poisson", group_poisson},
    {"multigrid", group_multigrid},
    {"case", group_case},
    {"architecture", group_architecture},
    {"viscous", group_viscous},
    {"amg", group_amg},
    {"scenes", group_scenes},
    {"bingham", group_bingham},
    {"heap", group_heap},
    {"io", group_io},
    {"corpus", group_corpus},
    {"vof", group_vof},
    {"tools", group_tools},
    {"repro", group_repro},
    {"two_phase", group_two_phase},
    {"outputs", group_outputs},
    {"honest", group_honest},
    {"bedload", group_bedload},
    {"collapse", group_collapse},
    {"front", group_front},
    {"boundary", group_boundary},
    {"duct", group_duct},
    {"obstacle", group_obstacle},
    {"forces", group_forces},
    {"stretched", group_stretched},
    {"cases", group_cases},
    {"velocity_mg", group_velocity_mg},
    {"depth_averaged", group_depth_averaged},
    {"ngf", group_ngf},
    {"time_scheme", group_time_scheme},
    {"slope_release", group_slope_release},
    {"mpi", group_mpi},
    {"wall_shock", group_wall_shock},
};
#define NGROUPS (sizeof(groups) / sizeof(groups[0]))

static int is_dir(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
}

/* dir is the tests/ folder of a muflow tree: it holds fuzz/corpus beside ../cases */
static int is_tests_dir(const char *dir)
{
    char a[PATH_MAX + 32], b[PATH_MAX + 32];
    snprintf(a, sizeof a, "%s/fuzz/corpus", dir);
    snprintf(b, sizeof b, "%s/../cases", dir);
    return is_dir(a) && is_dir(b);
}

/* Moves to the tests/ folder: the current one, or tests/ of the first folder
 * above this executable that has one.  Returns 0, or -1 when there is none. */
static int enter_tests_dir(void)
{
    if (is_tests_dir("."))
        return 0;
    char dir[PATH_MAX], tests[PATH_MAX + 8];
    ssize_t n = readlink("/proc/self/exe", dir, sizeof dir - 1);
    if (n <= 0)
        return -1;
    dir[n] = '\0';
    for (char *slash = strrchr(dir, '/'); slash; slash = strrchr(dir, '/')) {
        *slash = '\0'; /* one folder up */
        snprintf(tests, sizeof tests, "%s/tests", slash == dir ? "" : dir);
        if (is_tests_dir(tests))
            return chdir(tests);
        if (slash == dir)
            break;
    }
    return -1;
}

static void list_groups(FILE *f)
{
    fprintf(f, "groups:");
    for (size_t g = 0; g < NGROUPS; g++)
        fprintf(f, " %s", groups[g].name);
    fprintf(f, "\n");
}

int main(int argc, char **argv)
{
    struct test_tally tally = {0, 0};
    int unknown = 0;
    run_init();
    /* MUFLOW_TEST_FILTER=test_pipe*: only the tests whose names match */
    const char *filter = getenv("MUFLOW_TEST_FILTER");
    if (filter && *filter)
        cmocka_set_test_filter(filter);
    for (int a = 1; a < argc; a++) {
        size_t g = 0;
        while (g < NGROUPS && strcmp(argv[a], groups[g].name) != 0)
            g++;
        if (g == NGROUPS) {
            fprintf(stderr, "muflow_tests: no test group named '%s'\n", argv[a]);
            unknown = 1;
        }
    }
    /* under mpirun only the mpi group: the others would run once per rank
     * over the same files */
    char err[256] = "";
    if (comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "muflow_tests: %s\n", err);
        return 2;
    }
    if (comm_launched() && (argc != 2 || strcmp(argv[1], "mpi") != 0))
        comm_exit(2, 1, "muflow_tests: under mpirun only the group mpi runs (muflow_tests mpi)");
    if (comm_rank() != 0 && !freopen("/dev/null", "w", stdout))
        return 2; /* the ranks' results are reduced: rank 0 prints them */
    if (unknown) {
        fprintf(stderr, "usage: muflow_tests [group ...] (all groups without one; "
                        "MUFLOW_TEST_FILTER=pattern runs the matching tests only)\n");
        list_groups(stderr);
        return 2;
    }
    if (enter_tests_dir() != 0) {
        fprintf(stderr, "muflow_tests: cannot find the tests/ folder (fuzz/corpus beside "
                        "../cases) here or above this executable\n");
        return 2;
    }
    for (size_t g = 0; g < NGROUPS; g++) {
        int wanted = argc < 2;
        for (int a = 1; a < argc; a++)
            wanted |= strcmp(argv[a], groups[g].name) == 0;
        if (wanted)
            groups[g].run(&tally);
    }
    if (filter && *filter) /* the groups' counts include the tests the filter skipped */
        printf("tests: only those matching '%s': %d failed\n", filter, tally.failed);
    else
        printf("tests: %d passed, %d failed\n", tally.run - tally.failed, tally.failed);
    return tally.failed != 0;
}
