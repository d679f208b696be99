/* Numbers as case files write them (num_text.h). */
#include "platform/num_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct num_text num_text(double v)
{
    struct num_text t;
    num_format(v, t.s, sizeof t.s);
    return t;
}

/* The fewest significant digits (at most 17) that round-trip, written in
 * plain decimal unless scientific notation is at least two characters
 * shorter.  Both forms carry the same digits, so either reads back to v. */
void num_format(double v, char *out, size_t outlen)
{
    char sci[40];
    int prec = 1;
    for (; prec <= 17; prec++) {
        snprintf(sci, sizeof sci, "%.*e", prec - 1, v);
        if (strtod(sci, NULL) == v)
            break;
    }
    if (prec > 17) /* unreachable for a finite double */
        prec = 17;
    snprintf(sci, sizeof sci, "%.*e", prec - 1, v);
    /* sci is [-]d[.ddd]e(+|-)XX: the digits and the decimal exponent */
    char digits[24];
    int nd = 0, neg = sci[0] == '-';
    const char *p = sci + neg;
    for (; *p && *p != 'e'; p++)
        if (*p >= '0' && *p <= '9' && nd < (int)sizeof digits - 1)
            digits[nd++] = *p;
    digits[nd] = '\0';
    int exp10 = *p == 'e' ? atoi(p + 1) : 0;
    while (nd > 1 && digits[nd - 1] == '0') /* %.*e pads with zeros (v = 0) */
        digits[--nd] = '\0';
    if (!isfinite(v) || nd == 0) {
        snprintf(out, outlen, "%s", sci);
        return;
    }
    /* the plain form: digits with the point moved by exp10 */
    char plain[400];
    size_t n = 0;
    if (neg)
        plain[n++] = '-';
    if (exp10 < 0) {
        plain[n++] = '0';
        plain[n++] = '.';
        for (int i = 0; i < -exp10 - 1 && n < sizeof plain - 32; i++)
            plain[n++] = '0';
        for (int i = 0; i < nd; i++)
            plain[n++] = digits[i];
    } else {
        for (int i = 0; i <= exp10 && n < sizeof plain - 32; i++)
            plain[n++] = i < nd ? digits[i] : '0';
        if (nd > exp10 + 1) {
            plain[n++] = '.';
            for (int i = exp10 + 1; i < nd; i++)
                plain[n++] = digits[i];
        }
    }
    plain[n] = '\0';
    /* scientific: %.*e with the trailing zeros of the mantissa removed */
    char shortsci[40];
    snprintf(shortsci, sizeof shortsci, "%.*e", nd - 1, v);
    const char *best = strlen(plain) <= strlen(shortsci) + 1 ? plain : shortsci;
    if (strtod(best, NULL) != v) /* cannot happen: the same digits */
        best = sci;
    snprintf(out, outlen, "%s", best);
}
