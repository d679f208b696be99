/* Run output: summary.ini, profile.csv, history.csv in the output folder.
 * Every file is written under a temporary name and renamed when complete, so
 * a file that exists is whole. */
#ifndef MUFLOW_OUTPUT_H
#define MUFLOW_OUTPUT_H

#include <stdio.h>
#include "march.h"
#include "profile.h"

struct run_result {
    enum run_status status;
    long steps;
    double time, wall_seconds, residual, divergence;
    struct scene_errors errors;
    char message[256];
};

/* Creates dir and its parents; returns 0, or -1 with the cause in err. */
int output_make_dir(const char *dir, char *err, size_t errlen);

/* history.csv, row by row. */
struct history {
    FILE *f;
    char path[600], tmp[620];
};
int history_open(struct history *h, const char *dir, char *err, size_t errlen);
void history_row(struct history *h, const struct march_state *st, const struct scene_errors *e);
int history_close(struct history *h, char *err, size_t errlen);

int output_profile(const char *dir, const struct profile *pr, char *err, size_t errlen);
int output_summary(const char *dir, const struct muflow_case *cs, const struct run_result *r,
                   char *err, size_t errlen);

#endif
