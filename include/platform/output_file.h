/* A file written under a temporary name and renamed when complete, so that a
 * file that exists is whole (every output of a run: io/output.h, and the
 * modules' and scenes' own files). */
#ifndef MUFLOW_PLATFORM_OUTPUT_FILE_H
#define MUFLOW_PLATFORM_OUTPUT_FILE_H

#include <stddef.h>
#include <stdio.h>

struct output_file {
    FILE *f;
    char path[600], tmp[620];
};
/* Opens dir/name.tmp; returns 0, or -1 with the cause in err. */
int output_open(struct output_file *o, const char *dir, const char *name, char *err,
                size_t errlen);
/* Closes and renames it (removing the temporary on failure). */
int output_commit(struct output_file *o, char *err, size_t errlen);
/* The file a previous run left as dir/name, to read the rows a continued
 * run keeps: its temporary (a run that died before renaming it; the name is
 * removed, the stream still reads it) if there is one, else dir/name; NULL
 * when neither opens. */
FILE *output_previous(const char *dir, const char *name);
/* Copies to dst the data rows of the CSV file src (its header line skipped)
 * whose first column, a step, keep(step, ctx) accepts; returns the last step
 * copied, or -1.  A continued run keeps the rows of its record this way. */
long output_copy_rows(FILE *src, FILE *dst, int (*keep)(long step, void *ctx), void *ctx);

#endif
