/* Test runner: runs every group (or those named on the command line) and
 * ends with one closing line "tests: N passed, M failed". */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_main.h"

char *test_read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        print_error("cannot open %s: %s\n", path, strerror(errno));
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    if (len)
        *len = (size_t)n;
    return s;
}

static const struct {
    const char *name;
    void (*run)(struct test_tally *);
} groups[] = {
    {"rheology", group_rheology},
    {"poisson", group_poisson},
    {"case", group_case},
    {"viscous", group_viscous},
    {"amg", group_amg},
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
