/* Regression test of the fuzz corpus (tests/fuzz/corpus, grown by
 * `make fuzz`): every input found by the fuzzer goes through case_load once
 * more; it must return 0 or 2 (and never crash, which `make check-asan` also
 * checks for memory errors). */
#define _GNU_SOURCE /* memfd_create in fuzz_input.h */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_main.h"
#include "fuzz/fuzz_input.h"

#define CORPUS "fuzz/corpus" /* the runner works in tests/ (test_main.c) */

static void test_corpus(void **state)
{
    (void)state;
    DIR *d = opendir(CORPUS);
    if (!d)
        print_error("cannot open %s in tests/\n", CORPUS);
    assert_non_null(d);
    int files = 0, loaded = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[600];
        snprintf(path, sizeof path, CORPUS "/%s", e->d_name);
        size_t n;
        char *data = test_read_file(path, &n);
        static struct muflow_case cs;
        char err[512];
        int rc = fuzz_case_load((const uint8_t *)data, n, &cs, err, sizeof err);
        if (rc != 0 && rc != 2)
            print_error("%s: case_load returned %d\n", path, rc);
        assert_true(rc == 0 || rc == 2);
        if (rc == 2)
            assert_true(err[0] != '\0' && !strchr(err, '\n'));
        loaded += rc == 0;
        files++;
        free(data);
    }
    closedir(d);
    print_message("fuzz corpus: %d inputs, %d valid cases, %d refused\n", files, loaded,
                  files - loaded);
    assert_true(files > 0);
}

void group_corpus(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corpus),
    };
    RUN_GROUP(t, "corpus", tests);
}
