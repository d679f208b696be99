/* Key tables: one declaration per case key drives parsing, range checks,
 * writing back and the checkpoint.  A table describes the members of one
 * struct (by offset): the core case (case.h) or the parameter block of a
 * scene or physics module, which lives in the case's own storage (so a case
 * stays a plain value that can be copied). */
#ifndef MUFLOW_CONFIG_KEYS_H
#define MUFLOW_CONFIG_KEYS_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include "platform/num_text.h" /* num_text: numbers as key_text writes them */

enum ktype { K_DOUBLE, K_INT, K_LONG, K_BOOL, K_CHOICE, K_STRING };

struct choice {
    const char *name;
    int value;
};

/* Range of a number: lo/hi with inclusive flags; +-HUGE_VAL for none.
 * help, units and doc are what muflow --list and docs/case_keys.md (muflow
 * --list=markdown) print: the tables are the only description of a key. */
struct key {
    const char *section;
    const char *name;
    enum ktype type;
    size_t off;                   /* of the member in the table's struct */
    double lo, hi;
    int lo_incl, hi_incl;
    const struct choice *choices; /* K_CHOICE: terminated by name == NULL */
    const char *range_text;       /* overrides the generated "must be ..." text */
    size_t size;                  /* K_STRING: bytes of the member */
    const char *help;             /* one line: what the key means (muflow --list) */
    const char *default_text;     /* the default as --list shows it when it is not
                                     the defaults' value (1/phi, out/<case name>) */
    const char *units;            /* "length", "rad", ...; NULL: dimensionless */
    const char *doc;              /* the full meaning in docs/case_keys.md (one
                                     Markdown paragraph, no line breaks); NULL: help.
                                     Consecutive keys of the same doc, units, allowed
                                     values and default share one row there. */
};

#define KEY_NONE_LO (-HUGE_VAL)
#define KEY_NONE_HI (HUGE_VAL)
/* number ranges */
#define KEY_GT0 0.0, KEY_NONE_HI, 0, 0
#define KEY_GE0 0.0, KEY_NONE_HI, 1, 0
#define KEY_RANGE(lo, hi, li, hi_) (lo), (hi), (li), (hi_)
#define KEY_NORANGE 0.0, 0.0, 0, 0

/* A help argument h of the macros below: either a plain string, or
 * KEY_HELP(help, units, doc), which also sets the key's units and doc
 * (either may be NULL).  Its expansion has commas, so it is deferred by one
 * scan (KEY_EMPTY): a macro that hands h on to one of the macros below (the
 * tables' own shorthands) still sees it as one argument. */
#define KEY_EMPTY()
#define KEY_HELP(h_, u_, d_) KEY_HELP_ KEY_EMPTY()(h_, u_, d_)
#define KEY_HELP_(h_, u_, d_) h_, .units = u_, .doc = d_

/* Table entries for the members m of struct T, each with its help h.
 * (the range, four numbers, comes last: macros hand it on as several arguments) */
#define KEY_DBL(T, s, n, m, h, ...) \
    {.section = s, .name = n, .type = K_DOUBLE, .off = offsetof(T, m), __VA_ARGS__, .help = h}
#define KEY_DBLT(T, s, n, m, t, h, ...)                                                      \
    {.section = s, .name = n, .type = K_DOUBLE, .off = offsetof(T, m), __VA_ARGS__,          \
     .range_text = t, .help = h}
#define KEY_INT(T, s, n, m, h, ...) \
    {.section = s, .name = n, .type = K_INT, .off = offsetof(T, m), __VA_ARGS__, .help = h}
#define KEY_LNG(T, s, n, m, h, ...) \
    {.section = s, .name = n, .type = K_LONG, .off = offsetof(T, m), __VA_ARGS__, .help = h}
#define KEY_BOOL(T, s, n, m, h) \
    {.section = s, .name = n, .type = K_BOOL, .off = offsetof(T, m), .help = h}
#define KEY_CHO(T, s, n, m, ch, h) \
    {.section = s, .name = n, .type = K_CHOICE, .off = offsetof(T, m), .choices = ch, .help = h}
#define KEY_STR(T, s, n, m, h)                                                               \
    {.section = s, .name = n, .type = K_STRING, .off = offsetof(T, m),                       \
     .size = sizeof(((T *)0)->m), .help = h}

/* The case keys of a scene or physics module: one INI section, its keys
 * (offsets into the block), the block's size, its defaults, and a check
 * that needs every key (returns 0, or non-zero with one line in msg, which
 * the caller prefixes with the file's name). */
struct muflow_case;
struct key_block {
    const char *section;
    const char *intro;            /* Markdown before the section's table in
                                     docs/case_keys.md: what the section is for */
    const struct key *keys;
    int nkeys;
    size_t size;
    void (*defaults)(void *block);
    int (*check)(const struct muflow_case *cs, const void *block, char *msg, size_t msglen);
};

/* Parses value into key k's member of base; returns NULL, or a message
 * (static text or written to msg). */
const char *key_parse(void *base, const struct key *k, const char *value, char *msg,
                      size_t msglen);

/* The value of key k in base as case files and summaries write it: doubles
 * as the shortest text that reads back to the same value. */
void key_text(const void *base, const struct key *k, char *val, size_t len);

/* "must be ..." for a number key. */
void key_range_text(const struct key *k, char *out, size_t outlen);

/* What the key accepts, for muflow --list: "real > 0", "integer in [1, 1000]",
 * "on|off", "a|b|c", "text of at most 511 characters". */
void key_allowed_text(const struct key *k, char *out, size_t outlen);

/* Writes one key for muflow --list: "section.key = default  (allowed)" and
 * its help (with its units) on the next line; the default read from base (a
 * block holding the defaults), or the key's default_text. */
void key_write_help(const void *base, const struct key *k, FILE *out);

/* The default as --list and docs/case_keys.md show it: default_text, or the
 * value in base; "" for an unset string. */
void key_default_text(const void *base, const struct key *k, char *out, size_t outlen);

#endif
