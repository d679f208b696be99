/* Test runner: runs every group (or those named on the command line) and
 * ends with one closing line "tests: N passed, M failed". */
#include <stdio.h>
#include <string.h>
#include "test_main.h"

static const struct {
    const char *name;
    void (*run)(struct test_tally *);
} groups[] = {
    {"rheology", group_rheology},
    {"poisson", group_poisson},
    {"case", group_case},
    {"viscous", group_viscous},
    {"scenes", group_scenes},
    {"bingham", group_bingham},
    {"heap", group_heap},
    {"io", group_io},
    {"corpus", group_corpus},
};

int main(int argc, char **argv)
{
    struct test_tally tally = {0, 0};
    for (size_t g = 0; g < sizeof(groups) / sizeof(groups[0]); g++) {
        int wanted = argc < 2;
        for (int a = 1; a < argc; a++)
            wanted |= strcmp(argv[a], groups[g].name) == 0;
        if (wanted)
            groups[g].run(&tally);
    }
    printf("tests: %d passed, %d failed\n", tally.run - tally.failed, tally.failed);
    return tally.failed != 0;
}
