/* One fuzz input -> one case_load call, shared by the libFuzzer target
 * (fuzz_case.c) and the corpus regression test (tests/test_corpus.c).
 *
 * Input format: the case file's bytes, optionally followed by the separator
 * "\n----\n" and command-line overrides, one per line:
 *     [domain]\nnx = 4\n----\ndomain.ny=3\nsolver.dt=1e-3
 * The file part may hold anything (NUL bytes, long lines, invalid UTF-8);
 * an override ends at its newline or at a NUL byte, as argv strings do.
 * The file is handed to case_load through a memfd under /proc/self/fd, so
 * nothing touches the disk. */
#ifndef MUFLOW_FUZZ_INPUT_H
#define MUFLOW_FUZZ_INPUT_H

#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* memfd_create; must precede every system header */
#endif
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>
#include "app/run.h"
#include "config/case.h"

#define FUZZ_SEPARATOR "\n----\n"
#define FUZZ_MAX_OVERRIDES 64

/* The memfd that carries the file part (created once per process). */
static int fuzz_memfd(void)
{
    static int fd = -1;
    if (fd < 0)
        fd = memfd_create("case.ini", 0);
    return fd;
}

/* Splits data and calls case_load; returns its result (0 or 2), or -1 when
 * the input could not be staged (out of memory, no memfd). */
static int fuzz_case_load(const uint8_t *data, size_t size, struct muflow_case *cs, char *err,
                          size_t errlen)
{
    size_t file_len = size, sep = strlen(FUZZ_SEPARATOR);
    for (size_t i = 0; i + sep <= size; i++)
        if (memcmp(data + i, FUZZ_SEPARATOR, sep) == 0) {
            file_len = i;
            break;
        }
    int fd = fuzz_memfd();
    if (fd < 0 || ftruncate(fd, 0) != 0 ||
        (file_len > 0 && pwrite(fd, data, file_len, 0) != (ssize_t)file_len))
        return -1;
    char *over[FUZZ_MAX_OVERRIDES];
    int n = 0;
    char *text = NULL;
    if (file_len < size) {
        size_t rest = size - file_len - sep;
        text = malloc(rest + 1);
        if (!text)
            return -1;
        memcpy(text, data + file_len + sep, rest);
        text[rest] = '\0';
        for (char *line = text; n < FUZZ_MAX_OVERRIDES;) {
            char *nl = strchr(line, '\n');
            if (nl)
                *nl = '\0';
            over[n++] = line; /* a NUL inside ends the string like an argv entry */
            if (!nl)
                break;
            line = nl + 1;
        }
    }
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    run_init(); /* the scenes case_load reads case.scene against */
    int rc = case_load(cs, path, n, over, err, errlen);
    free(text);
    return rc;
}

#endif
