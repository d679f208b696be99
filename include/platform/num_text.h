/* Numbers as case files, summaries and messages write them: the shortest
 * text that reads back as exactly the same double.  The C library offers
 * only a fixed precision (%g rounds, %.17g shows noise digits such as
 * 0.10000000000000001), so the text is searched for here.  Every layer
 * writes numbers this way, so it sits at the bottom with no muflow
 * include. */
#ifndef MUFLOW_PLATFORM_NUM_TEXT_H
#define MUFLOW_PLATFORM_NUM_TEXT_H

#include <stddef.h>

/* The shortest text that reads back as exactly v: plain decimal (70, 0.25,
 * 0.0001, 123456) unless scientific notation (1e+12, 1e-08) is at least two
 * characters shorter; into out (outlen bytes, cut like snprintf). */
void num_format(double v, char *out, size_t outlen);

/* num_format as a value, for messages:
 * snprintf(msg, len, "... = %s", num_text(v).s).  The array lives to the end
 * of the full expression that calls num_text (C11 6.2.4p8). */
struct num_text {
    char s[32];
};
struct num_text num_text(double v);

#endif
