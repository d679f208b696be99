/* Case files: INI parsing (libinih), command-line overrides, validation,
 * defaults and writing back.  Every key is described once in the table
 * `keys` below; parsing, range checks and case_write_ini all use it.
 *
 * The file is fed to inih line by line through our own reader, which
 *   - counts lines (so handler errors know where they are),
 *   - rejects lines longer than inih's line buffer instead of letting inih
 *     split them silently, and NUL bytes,
 *   - strips a UTF-8 BOM and leading blanks (so indented keys are keys, never
 *     inih "multi-line continuations" of the previous value),
 *   - rejects unknown [section] headers, even ones without keys,
 *   - stops the parse at the first error we detected. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "config/case.h"

#include <errno.h>
#include <ini.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define HALF_PI 1.57079632679489661923
#define MAX_CELLS 500000000.0 /* cap on nx*ny*nz */
#define SHOWN_MAX 160         /* longest value or path quoted in an error message */

enum ktype { K_DOUBLE, K_INT, K_LONG, K_BOOL, K_CHOICE, K_STRING };

struct choice {
    const char *name;
    int value;
};

/* Range of a number: lo/hi with inclusive flags; +-HUGE_VAL for none. */
struct key {
    const char *section;
    const char *name;
    enum ktype type;
    size_t off;
    double lo, hi;
    int lo_incl, hi_incl;
    const struct choice *choices; /* K_CHOICE: terminated by name == NULL */
    const char *range_text;      /* overrides the generated "must be ..." text */
};

static const struct choice scene_choices[] = {
    {"none", SCENE_NONE}, {"bagnold", SCENE_BAGNOLD}, {"chute", SCENE_CHUTE},
    {"bingham_channel", SCENE_BINGHAM_CHANNEL}, {"bingham_cavity", SCENE_BINGHAM_CAVITY},
    {"heap", SCENE_HEAP}, {NULL, 0}};
static const struct choice bc_choices[] = {
    {"periodic", BC_PERIODIC}, {"wall", BC_WALL}, {"slip", BC_SLIP},
    {"surface", BC_SURFACE}, {"lid", BC_LID}, {NULL, 0}};
static const struct choice law_choices[] = {
    {"mui", LAW_MUI}, {"bingham", LAW_BINGHAM}, {"newtonian", LAW_NEWTONIAN}, {NULL, 0}};
static const struct choice reg_choices[] = {
    {"simple", REG_SIMPLE}, {"bercovier", REG_BERCOVIER},
    {"papanastasiou", REG_PAPANASTASIOU}, {"mc", REG_MC}, {NULL, 0}};
static const struct choice mode_choices[] = {
    {"steady", MODE_STEADY}, {"transient", MODE_TRANSIENT}, {NULL, 0}};
static const struct choice dir_choices[] = {
    {"auto", -1}, {"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice axis_choices[] = {{"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice precond_choices[] = {
    {"auto", PRECOND_AUTO}, {"line", PRECOND_LINE}, {"cholesky", PRECOND_CHOLESKY},
    {"lu", PRECOND_LU}, {NULL, 0}};

/* Enum fields are written and read as int through memcpy. */
_Static_assert(sizeof(enum scene) == sizeof(int), "enum size");
_Static_assert(sizeof(enum bc_kind) == sizeof(int), "enum size");
_Static_assert(sizeof(enum rheology_law) == sizeof(int), "enum size");
_Static_assert(sizeof(enum regularisation) == sizeof(int), "enum size");
_Static_assert(sizeof(enum solver_mode) == sizeof(int), "enum size");
_Static_assert(sizeof(enum preconditioner) == sizeof(int), "enum size");

#define OFF(m) offsetof(struct muflow_case, m)
#define NONE_LO (-HUGE_VAL)
#define NONE_HI (HUGE_VAL)
/* number ranges */
#define GT0 0.0, NONE_HI, 0, 0
#define GE0 0.0, NONE_HI, 1, 0
#define RANGE(lo, hi, li, hi_) (lo), (hi), (li), (hi_)
#define NORANGE 0.0, 0.0, 0, 0

#define DBL(s, n, m, r) {s, n, K_DOUBLE, OFF(m), r, NULL, NULL}
#define DBLT(s, n, m, r, t) {s, n, K_DOUBLE, OFF(m), r, NULL, t}
#define INT(s, n, m, r) {s, n, K_INT, OFF(m), r, NULL, NULL}
#define LNG(s, n, m, r) {s, n, K_LONG, OFF(m), r, NULL, NULL}
#define BOOL(s, n, m) {s, n, K_BOOL, OFF(m), NORANGE, NULL, NULL}
#define CHO(s, n, m, ch) {s, n, K_CHOICE, OFF(m), NORANGE, ch, NULL}
#define STR(s, n, m) {s, n, K_STRING, OFF(m), NORANGE, NULL, NULL}

static const struct key keys[] = {
    CHO("case", "scene", scene, scene_choices),
    STR("case", "reference", reference),

    DBL("domain", "lx", len[0], GT0),
    DBL("domain", "ly", len[1], GT0),
    DBL("domain", "lz", len[2], GT0),
    INT("domain", "nx", n[0], RANGE(1, 100000000, 1, 1)),
    INT("domain", "ny", n[1], RANGE(1, 100000000, 1, 1)),
    INT("domain", "nz", n[2], RANGE(1, 100000000, 1, 1)),

    CHO("boundary", "xlo", bc.face[0][0], bc_choices),
    CHO("boundary", "xhi", bc.face[0][1], bc_choices),
    CHO("boundary", "ylo", bc.face[1][0], bc_choices),
    CHO("boundary", "yhi", bc.face[1][1], bc_choices),
    CHO("boundary", "zlo", bc.face[2][0], bc_choices),
    CHO("boundary", "zhi", bc.face[2][1], bc_choices),
    DBL("boundary", "lid_velocity", bc.lid_velocity, RANGE(NONE_LO, NONE_HI, 0, 0)),
    CHO("boundary", "lid_direction", bc.lid_direction, axis_choices),

    DBLT("physics", "tilt", tilt, RANGE(-HALF_PI, HALF_PI, 1, 1), "must be in [-pi/2, pi/2] (radians)"),
    DBL("physics", "gravity", gravity, GE0),
    DBL("physics", "density", density, GT0),
    DBL("physics", "confining_pressure", confining_pressure, GE0),
    BOOL("physics", "advection", advection),

    CHO("rheology", "law", rheo.law, law_choices),
    CHO("rheology", "regularisation", rheo.reg, reg_choices),
    DBL("rheology", "lambda", rheo.lambda, RANGE(0, 1, 0, 1)),
    DBL("rheology", "mu_s", rheo.mu_s, GE0),
    DBL("rheology", "delta_mu", rheo.delta_mu, GE0),
    DBL("rheology", "i0", rheo.i0, GT0),
    DBL("rheology", "phi", rheo.phi, RANGE(0, 1, 0, 1)),
    DBL("rheology", "grain_diameter", rheo.grain_diameter, GT0),
    DBL("rheology", "grain_density", rheo.grain_density, GT0),
    BOOL("rheology", "pressure_regularisation", rheo.pressure_regularisation),
    DBL("rheology", "yield_stress", rheo.yield_stress, GE0),
    DBL("rheology", "plastic_viscosity", rheo.plastic_viscosity, GE0),
    DBL("rheology", "viscosity", rheo.viscosity, GT0),

    CHO("solver", "mode", mode, mode_choices),
    DBL("solver", "tolerance", tolerance, RANGE(0, 1, 0, 0)),
    LNG("solver", "max_steps", max_steps, RANGE(1, 1e9, 1, 1)),
    DBL("solver", "end_time", end_time, GT0),
    DBL("solver", "dt", dt, GT0),
    DBL("solver", "dt_max", dt_max, GT0),
    DBL("solver", "cfl", cfl, RANGE(0, 2, 0, 1)),
    BOOL("solver", "newton", newton),
    DBL("solver", "newton_below", newton_below, RANGE(0, 1, 0, 1)),
    DBL("solver", "linear_tolerance", linear_tolerance, RANGE(0, 1, 0, 0)),
    INT("solver", "max_linear_iterations", max_linear_iterations, RANGE(1, 1e6, 1, 1)),
    CHO("solver", "line_direction", line_direction, dir_choices),
    CHO("solver", "preconditioner", preconditioner, precond_choices),
    DBL("solver", "augmentation", augmentation, GE0),
    DBL("solver", "progress_interval", progress_interval, GE0),

    DBL("heap", "flow_rate", heap.flow_rate, GE0),
    DBLT("heap", "tilt_min", heap.tilt_min, RANGE(0, HALF_PI, 0, 0), "must be in (0, pi/2) (radians)"),
    DBLT("heap", "tilt_max", heap.tilt_max, RANGE(0, HALF_PI, 0, 0), "must be in (0, pi/2) (radians)"),
    DBL("heap", "flow_rate_tolerance", heap.flow_rate_tolerance, RANGE(0, 0.5, 0, 1)),
    INT("heap", "max_solves", heap.max_solves, RANGE(2, 1000, 1, 1)),
    DBL("heap", "depth_fraction", heap.depth_fraction, RANGE(0, 1, 0, 0)),

    STR("output", "dir", output_dir),
    BOOL("output", "quiet", quiet),
    BOOL("output", "fields", fields),
    LNG("output", "fields_every", fields_every, RANGE(0, 1e9, 1, 1)),
    DBL("output", "fields_interval", fields_interval, GE0),
    LNG("output", "checkpoint_every", checkpoint_every, RANGE(0, 1e9, 1, 1)),
};
#define NKEYS ((int)(sizeof(keys) / sizeof(keys[0])))

static const char *const sections[] = {"case", "domain", "boundary", "physics",
                                       "rheology", "solver", "heap", "output"};
#define NSECTIONS ((int)(sizeof(sections) / sizeof(sections[0])))

/* ------------------------------------------------------------------------ */

void case_defaults(struct muflow_case *c)
{
    memset(c, 0, sizeof(*c));
    snprintf(c->name, sizeof(c->name), "case");
    c->scene = SCENE_NONE;
    for (int d = 0; d < 3; d++) {
        c->len[d] = 1.0;
        c->n[d] = 1;
        c->bc.face[d][0] = BC_PERIODIC;
        c->bc.face[d][1] = BC_PERIODIC;
    }
    c->bc.lid_velocity = 1.0;
    c->bc.lid_direction = 0;
    c->tilt = 0.0;
    c->gravity = 1.0;
    c->density = 1.0;
    c->confining_pressure = 0.0;
    c->advection = 1;

    c->rheo.law = LAW_MUI;
    c->rheo.reg = REG_MC;
    c->rheo.lambda = 1e-4;
    c->rheo.pressure_regularisation = 1;
    c->rheo.mu_s = 0.383;
    c->rheo.delta_mu = 0.26;
    c->rheo.i0 = 0.279;
    c->rheo.phi = 0.6;
    c->rheo.grain_diameter = 1.0;
    c->rheo.grain_density = 1.0 / 0.6;
    c->rheo.yield_stress = 0.0;
    c->rheo.plastic_viscosity = 0.0;
    c->rheo.viscosity = 1.0;

    c->mode = MODE_STEADY;
    c->tolerance = 1e-10;
    c->max_steps = 10000;
    c->end_time = 1.0;
    c->dt = 1e-2;
    c->dt_max = 1e12;
    c->cfl = 0.5;
    c->newton = 1;
    c->newton_below = 1.0;
    c->linear_tolerance = 1e-8;
    c->max_linear_iterations = 500;
    c->line_direction = -1;
    c->preconditioner = PRECOND_AUTO;
    c->progress_interval = 1.0;

    c->heap.flow_rate = 0.0;
    c->heap.tilt_min = 0.37;  /* just above atan(mu_s) for the default mu_s */
    c->heap.tilt_max = 0.45;
    c->heap.flow_rate_tolerance = 1e-3;
    c->heap.max_solves = 30;
    c->heap.depth_fraction = 0.01;

    snprintf(c->output_dir, sizeof(c->output_dir), "out/%s", c->name);
    c->quiet = 0;
    c->fields = 1;
    c->fields_every = 0;
    c->fields_interval = 0.0;
    c->checkpoint_every = 0;
}

/* ------------------------------------------------------------------------ */
/* Small string helpers */

static int lower(int ch)
{
    return (ch >= 'A' && ch <= 'Z') ? ch - 'A' + 'a' : ch;
}

static int equal_nocase(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (lower((unsigned char)*a) != lower((unsigned char)*b))
            return 0;
    return *a == *b;
}

static int is_blank(int ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\v' || ch == '\f';
}

/* Copy of s for an error message: at most SHOWN_MAX characters, control
 * characters replaced, "..." when cut. */
static const char *shown(const char *s, char buf[SHOWN_MAX + 4])
{
    size_t i = 0;
    for (; s[i] && i < SHOWN_MAX; i++) {
        unsigned char ch = (unsigned char)s[i];
        buf[i] = (ch < 32 || ch == 127) ? '?' : (char)ch;
    }
    if (s[i]) {
        memcpy(buf + i, "...", 3);
        i += 3;
    }
    buf[i] = '\0';
    return buf;
}

/* Optimal-string-alignment edit distance (insert, delete, substitute,
 * transpose adjacent); large for long strings. */
static int edit_distance(const char *a, const char *b)
{
    enum { M = 64 };
    size_t la = strlen(a), lb = strlen(b);
    if (la >= M || lb >= M)
        return INT_MAX;
    int d[M + 1][M + 1];
    for (size_t i = 0; i <= la; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int cost = a[i - 1] != b[j - 1];
            int v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v)
                v = d[i][j - 1] + 1;
            if (d[i - 1][j - 1] + cost < v)
                v = d[i - 1][j - 1] + cost;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

static int known_section(const char *s)
{
    for (int i = 0; i < NSECTIONS; i++)
        if (strcmp(s, sections[i]) == 0)
            return 1;
    return 0;
}

static const struct key *find_key(const char *section, const char *name)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].name, name) == 0)
            return &keys[i];
    return NULL;
}

/* " (did you mean section.key?)" for a near miss of section.name, or "". */
static void suggest_key(const char *section, const char *name, char *out, size_t outlen)
{
    char full[160];
    out[0] = '\0';
    if (snprintf(full, sizeof(full), "%s.%s", section, name) >= (int)sizeof(full))
        return;
    int best = INT_MAX;
    const struct key *hit = NULL;
    for (int i = 0; i < NKEYS; i++) {
        char cand[96];
        snprintf(cand, sizeof(cand), "%s.%s", keys[i].section, keys[i].name);
        int dist = edit_distance(full, cand);
        if (dist < best) {
            best = dist;
            hit = &keys[i];
        }
    }
    if (best > 2) { /* right key name, wrong (or no) section? */
        hit = NULL;
        for (int i = 0; i < NKEYS && !hit; i++)
            if (strcmp(keys[i].name, name) == 0)
                hit = &keys[i];
    }
    if (hit)
        snprintf(out, outlen, " (did you mean %s.%s?)", hit->section, hit->name);
}

/* Nearest known section within distance 2, or NULL. */
static const char *near_section(const char *s)
{
    int best = 3;
    const char *hit = NULL;
    for (int i = 0; i < NSECTIONS; i++) {
        int dist = edit_distance(s, sections[i]);
        if (dist < best) {
            best = dist;
            hit = sections[i];
        }
    }
    return hit;
}

/* ------------------------------------------------------------------------ */
/* Loading context and errors */

struct ctx {
    struct muflow_case *c;
    const char *where;      /* file name for messages ("case" without file) */
    FILE *f;
    int line;               /* lines handed to inih so far */
    int failed;
    int err_line;           /* line of our first error (0: not from the file) */
    int io_errno;
    char *err;
    size_t errlen;
    unsigned char set[NKEYS]; /* key given explicitly */
};

/* Records the first error only; the message is one line. */
static void fail(struct ctx *x, const char *fmt, ...)
{
    if (x->failed)
        return;
    x->failed = 1;
    x->err_line = x->line;
    if (!x->err || x->errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(x->err, x->errlen, fmt, ap);
    va_end(ap);
    for (char *p = x->err; *p; p++)
        if ((unsigned char)*p < 32 || (unsigned char)*p == 127)
            *p = '?';
}

static void range_text(const struct key *k, char *out, size_t outlen)
{
    if (k->range_text)
        snprintf(out, outlen, "%s", k->range_text);
    else if (k->hi == HUGE_VAL)
        snprintf(out, outlen, "must be %s %.17g", k->lo_incl ? ">=" : ">", k->lo);
    else
        snprintf(out, outlen, "must be in %c%.17g, %.17g%c", k->lo_incl ? '[' : '(', k->lo,
                 k->hi, k->hi_incl ? ']' : ')');
}

static int in_range(const struct key *k, double v)
{
    if (k->lo_incl ? v < k->lo : v <= k->lo)
        return 0;
    if (k->hi == HUGE_VAL)
        return 1;
    return k->hi_incl ? v <= k->hi : v < k->hi;
}

/* Parses value into key k's field; on error returns a message (static text or
 * written to msg). */
static const char *parse_value(struct muflow_case *c, const struct key *k, const char *value,
                               char *msg, size_t msglen)
{
    char *field = (char *)c + k->off;
    if (value[0] == '\0')
        return "empty value";
    switch (k->type) {
    case K_DOUBLE: {
        char *end;
        errno = 0;
        double v = strtod(value, &end);
        if (end == value || *end != '\0')
            return "not a number";
        if (errno == ERANGE)
            return "out of the range of a double";
        if (!isfinite(v))
            return "not a finite number";
        if (!in_range(k, v)) {
            range_text(k, msg, msglen);
            return msg;
        }
        memcpy(field, &v, sizeof(v));
        return NULL;
    }
    case K_INT:
    case K_LONG: {
        char *end;
        errno = 0;
        long v = strtol(value, &end, 10);
        if (end == value || *end != '\0')
            return "not an integer";
        if (errno == ERANGE || !in_range(k, (double)v)) {
            range_text(k, msg, msglen);
            return msg;
        }
        if (k->type == K_INT) {
            int iv = (int)v; /* the range keeps it within int */
            memcpy(field, &iv, sizeof(iv));
        } else {
            memcpy(field, &v, sizeof(v));
        }
        return NULL;
    }
    case K_BOOL: {
        static const char *const words[8] = {"off", "on", "false", "true", "no", "yes", "0", "1"};
        for (int i = 0; i < 8; i++)
            if (equal_nocase(value, words[i])) {
                int b = i % 2;
                memcpy(field, &b, sizeof(b));
                return NULL;
            }
        return "not a boolean (on|off|true|false|yes|no|1|0)";
    }
    case K_CHOICE: {
        for (const struct choice *ch = k->choices; ch->name; ch++)
            if (equal_nocase(value, ch->name)) {
                memcpy(field, &ch->value, sizeof(int));
                return NULL;
            }
        size_t used = (size_t)snprintf(msg, msglen, "must be one of ");
        for (const struct choice *ch = k->choices; ch->name && used < msglen; ch++)
            used += (size_t)snprintf(msg + used, msglen - used, "%s%s",
                                     ch == k->choices ? "" : "|", ch->name);
        return msg;
    }
    case K_STRING: {
        _Static_assert(sizeof(c->output_dir) == sizeof(c->reference), "string key size");
        size_t size = sizeof(c->output_dir); /* every string key has this size */
        size_t len = strlen(value);
        if (len >= size) {
            snprintf(msg, msglen, "longer than %zu characters", size - 1);
            return msg;
        }
        for (const char *p = value; *p; p++) {
            unsigned char ch = (unsigned char)*p;
            if (ch < 32 || ch == 127)
                return "contains a control character";
            if (ch == ';' && (p == value || is_blank((unsigned char)p[-1])))
                return "contains ';' at the start or after a blank (an INI comment)";
        }
        memcpy(field, value, len + 1);
        return NULL;
    }
    }
    return "internal error: unknown key type";
}

/* One assignment section.name = value, from the file (arg == NULL) or from
 * the override arg.  Returns 1 on success. */
static int assign(struct ctx *x, const char *section, const char *name, const char *value,
                  const char *arg)
{
    char b1[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], b3[SHOWN_MAX + 4], prefix[SHOWN_MAX + 40];
    char hint[160], msg[160];
    if (arg)
        snprintf(prefix, sizeof(prefix), "override %s", shown(arg, b1));
    else
        snprintf(prefix, sizeof(prefix), "%s", shown(x->where, b1));

    const struct key *k = find_key(section, name);
    if (!k) {
        if (!known_section(section)) {
            if (!arg && section[0] == '\0') {
                suggest_key(section, name, hint, sizeof(hint));
                fail(x, "%s: key %s before any [section]%s", prefix, shown(name, b2), hint);
                return 0;
            }
            suggest_key(section, name, hint, sizeof(hint));
            if (!hint[0]) {
                const char *near = near_section(section);
                if (near)
                    snprintf(hint, sizeof(hint), " (did you mean %s?)", near);
            }
            fail(x, "%s: unknown section %s%s", prefix, shown(section, b2), hint);
            return 0;
        }
        suggest_key(section, name, hint, sizeof(hint));
        fail(x, "%s: unknown key %s.%s%s", prefix, section, shown(name, b2), hint);
        return 0;
    }
    const char *why = parse_value(x->c, k, value, msg, sizeof(msg));
    if (why) {
        if (arg)
            fail(x, "%s: %s", prefix, why);
        else
            fail(x, "%s: %s.%s = %s: %s", prefix, section, name, shown(value, b3), why);
        return 0;
    }
    x->set[k - keys] = 1;
    return 1;
}

static int handler(void *user, const char *section, const char *name, const char *value)
{
    struct ctx *x = user;
    if (x->failed)
        return 1; /* the parse stops at the next line anyway */
    if (!value)
        value = "";
    return assign(x, section, name, value, NULL);
}

/* fgets-like reader for inih (see the comment at the top of the file). */
static char *reader(char *buf, int num, void *stream)
{
    struct ctx *x = stream;
    if (x->failed || num < 4)
        return NULL;
    size_t limit = (size_t)num - 3, len = 0;
    int ch, any = 0, too_long = 0, nul = 0;
    errno = 0;
    while ((ch = getc(x->f)) != EOF) {
        any = 1;
        if (ch == '\n')
            break;
        if (ch == '\0')
            nul = 1;
        if (len < limit)
            buf[len++] = (char)ch;
        else
            too_long = 1;
    }
    if (ch == EOF && ferror(x->f)) {
        x->io_errno = errno ? errno : EIO;
        return NULL;
    }
    if (!any)
        return NULL;
    buf[len] = '\0';
    x->line++;
    char b[SHOWN_MAX + 4];
    if (too_long) {
        fail(x, "%s: line %d: longer than %zu characters", shown(x->where, b), x->line, limit);
        buf[0] = '\0';
        return buf;
    }
    if (nul) {
        fail(x, "%s: line %d: contains a NUL byte", shown(x->where, b), x->line);
        buf[0] = '\0';
        return buf;
    }
    size_t skip = 0;
    if (x->line == 1 && len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0)
        skip = 3;
    while (skip < len && is_blank((unsigned char)buf[skip]))
        skip++;
    memmove(buf, buf + skip, len - skip + 1);
    if (buf[0] == '[') {
        char *end = strchr(buf, ']');
        if (end) {
            char name[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], hint[96] = "";
            size_t n = (size_t)(end - buf - 1);
            if (n > SHOWN_MAX)
                n = SHOWN_MAX;
            memcpy(name, buf + 1, n);
            name[n] = '\0';
            if ((size_t)(end - buf - 1) > SHOWN_MAX || !known_section(name)) {
                const char *near = near_section(name);
                if (near && (size_t)(end - buf - 1) <= SHOWN_MAX)
                    snprintf(hint, sizeof(hint), " (did you mean [%s]?)", near);
                fail(x, "%s: unknown section [%s]%s", shown(x->where, b), shown(name, b2), hint);
                buf[0] = '\0';
            }
        }
    }
    return buf;
}

/* ------------------------------------------------------------------------ */
/* Checks that need every key */

static int key_index(const char *section, const char *name)
{
    const struct key *k = find_key(section, name);
    return k ? (int)(k - keys) : -1;
}

/* The heap scene's cross-section: periodic along the flow, side wall at
 * y = 0 and symmetry plane at y = ly, static base and free surface in z. */
static int check_heap(struct ctx *x, const char *where)
{
    const struct muflow_case *c = x->c;
    static const enum bc_kind want[3][2] = {
        {BC_PERIODIC, BC_PERIODIC}, {BC_WALL, BC_SLIP}, {BC_WALL, BC_SURFACE}};
    static const char axis[3] = {'x', 'y', 'z'};
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] != want[d][side]) {
                fail(x,
                     "%s: case.scene = heap needs boundary.%c%s = %s (periodic along the flow, "
                     "side wall at y = 0, mid-plane at y = ly, base, free surface), not %s",
                     where, axis[d], side ? "hi" : "lo", bc_choices[want[d][side]].name,
                     bc_choices[c->bc.face[d][side]].name);
                return 0;
            }
    if (c->rheo.law != LAW_MUI) {
        fail(x, "%s: case.scene = heap needs rheology.law = mui", where);
        return 0;
    }
    if (c->n[1] < 2 || c->n[2] < 2) {
        fail(x, "%s: case.scene = heap needs domain.ny >= 2 and domain.nz >= 2 (got %d, %d)",
             where, c->n[1], c->n[2]);
        return 0;
    }
    if (c->heap.flow_rate > 0.0) {
        if (!(c->heap.tilt_min < c->heap.tilt_max)) {
            fail(x, "%s: heap.tilt_min = %.17g, heap.tilt_max = %.17g: the bracket needs "
                    "tilt_min < tilt_max",
                 where, c->heap.tilt_min, c->heap.tilt_max);
            return 0;
        }
        if (c->mode != MODE_STEADY || c->checkpoint_every > 0) {
            fail(x, "%s: heap.flow_rate > 0 (a tilt search over steady solves) needs "
                    "solver.mode = steady and output.checkpoint_every = 0",
                 where);
            return 0;
        }
    }
    return 1;
}

static void finish(struct ctx *x)
{
    struct muflow_case *c = x->c;
    char b[SHOWN_MAX + 4];
    const char *where = shown(x->where, b);
    static const char axis[3] = {'x', 'y', 'z'};

    if (!x->set[key_index("rheology", "grain_density")])
        c->rheo.grain_density = 1.0 / c->rheo.phi; /* phi in (0, 1]: finite */

    for (int d = 0; d < 3; d++) {
        int lo = c->bc.face[d][0] == BC_PERIODIC, hi = c->bc.face[d][1] == BC_PERIODIC;
        if (lo != hi) {
            fail(x,
                 "%s: boundary.%clo = %s, boundary.%chi = %s: periodic must be on both faces of "
                 "%c or on neither",
                 where, axis[d], bc_choices[c->bc.face[d][0]].name, axis[d],
                 bc_choices[c->bc.face[d][1]].name, axis[d]);
            return;
        }
    }

    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] == BC_LID && c->bc.lid_direction == d) {
                fail(x, "%s: boundary.%c%s = lid, boundary.lid_direction = %c: a lid moves in its "
                        "own plane, the direction must differ from %c",
                     where, axis[d], side ? "hi" : "lo", axis[d], axis[d]);
                return;
            }

    if (c->scene == SCENE_HEAP && !check_heap(x, where))
        return;

    double cells = (double)c->n[0] * (double)c->n[1] * (double)c->n[2];
    if (cells > MAX_CELLS) {
        fail(x, "%s: domain nx*ny*nz = %d*%d*%d = %.17g cells: must be <= %.17g", where, c->n[0],
             c->n[1], c->n[2], cells, MAX_CELLS);
        return;
    }

    if (c->dt_max < c->dt) {
        fail(x, "%s: solver.dt_max = %.17g < solver.dt = %.17g: dt_max must be >= dt", where,
             c->dt_max, c->dt);
        return;
    }

    if (c->rheo.law == LAW_NEWTONIAN && !(c->rheo.viscosity > 0)) {
        fail(x, "%s: rheology.law = newtonian needs rheology.viscosity > 0", where);
        return;
    }
    if (c->rheo.law == LAW_BINGHAM &&
        !(c->rheo.plastic_viscosity > 0 || c->rheo.yield_stress > 0)) {
        fail(x,
             "%s: rheology.law = bingham needs rheology.plastic_viscosity > 0 or "
             "rheology.yield_stress > 0",
             where);
        return;
    }

    if (!x->set[key_index("output", "dir")]) {
        /* "out/<name>", checked like an explicit output.dir (name < 128) */
        char dir[sizeof(c->name) + 8], msg[160], b2[SHOWN_MAX + 4];
        snprintf(dir, sizeof(dir), "out/%s", c->name);
        const char *why = parse_value(c, &keys[key_index("output", "dir")], dir, msg, sizeof(msg));
        if (why)
            fail(x, "%s: default output.dir = %s: %s; set output.dir", where, shown(dir, b2), why);
    }
}

/* c->name: base name of path without directory and a trailing ".ini". */
static int set_name(struct ctx *x, const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    if (len >= sizeof(x->c->name)) {
        char b[SHOWN_MAX + 4];
        fail(x, "%s: case name longer than %zu characters", shown(path, b),
             sizeof(x->c->name) - 1);
        return 0;
    }
    memcpy(x->c->name, base, len);
    x->c->name[len] = '\0';
    return 1;
}

static int load_file(struct ctx *x, const char *path)
{
    char b[SHOWN_MAX + 4];
    x->f = fopen(path, "r");
    if (!x->f) {
        fail(x, "%s: cannot open: %s", shown(path[0] ? path : "(empty file name)", b),
             strerror(errno));
        return 0;
    }
    errno = 0;
    int ret = ini_parse_stream(reader, x, handler, x);
    if (x->io_errno && !x->failed) {
        x->line = 0;
        fail(x, "%s: cannot read: %s", shown(path, b), strerror(x->io_errno));
    }
    fclose(x->f);
    x->f = NULL;
    if (ret > 0 && (!x->failed || ret < x->err_line)) {
        x->failed = 0; /* a syntax error comes first */
        x->line = ret;
        fail(x, "%s: line %d: syntax error (expected [section] or key = value)", shown(path, b),
             ret);
    } else if (ret < 0 && !x->failed) {
        fail(x, "%s: cannot parse (inih error %d)", shown(path, b), ret);
    }
    return !x->failed;
}

/* "section.key=value": splits at the first '=' and the first '.' before it,
 * with blanks around the parts removed. */
static int apply_override(struct ctx *x, const char *arg)
{
    char b[SHOWN_MAX + 4];
    const char *eq = strchr(arg, '=');
    const char *dot = NULL;
    if (eq)
        for (const char *p = arg; p < eq; p++)
            if (*p == '.' && !dot)
                dot = p;
    if (!eq || !dot) {
        fail(x, "override %s: expected section.key=value", shown(arg, b));
        return 0;
    }
    size_t len = strlen(arg);
    char *copy = malloc(len + 1);
    if (!copy) {
        fail(x, "override %s: out of memory", shown(arg, b));
        return 0;
    }
    memcpy(copy, arg, len + 1);
    char *section = copy, *name = copy + (dot - arg) + 1, *value = copy + (eq - arg) + 1;
    copy[dot - arg] = '\0';
    copy[eq - arg] = '\0';
    char *parts[3] = {section, name, value};
    for (int i = 0; i < 3; i++) {
        char *s = parts[i];
        while (*s && is_blank((unsigned char)*s))
            s++;
        char *e = s + strlen(s);
        while (e > s && is_blank((unsigned char)e[-1]))
            *--e = '\0';
        parts[i] = s;
    }
    int ok = assign(x, parts[0], parts[1], parts[2], arg);
    free(copy);
    return ok;
}

/* case.reference relative to the case file's folder, made absolute so that a
 * summary or checkpoint that repeats the key finds the same file. */
static void resolve_reference(struct ctx *x, const char *path)
{
    struct muflow_case *c = x->c;
    char joined[2 * sizeof(c->reference)], real[PATH_MAX], b[SHOWN_MAX + 4], b2[SHOWN_MAX + 4];
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (c->reference[0] != '/' && slash)
        snprintf(joined, sizeof joined, "%.*s/%s", (int)(slash - path), path, c->reference);
    else
        snprintf(joined, sizeof joined, "%s", c->reference);
    if (!realpath(joined, real)) {
        fail(x, "%s: case.reference = %s: %s", shown(x->where, b), shown(joined, b2),
             strerror(errno));
        return;
    }
    if (strlen(real) >= sizeof(c->reference)) {
        fail(x, "%s: case.reference: path longer than %zu characters", shown(x->where, b),
             sizeof(c->reference) - 1);
        return;
    }
    snprintf(c->reference, sizeof(c->reference), "%s", real);
}

int case_load(struct muflow_case *c, const char *path, int noverrides,
              char *const overrides[], char *err, size_t errlen)
{
    struct muflow_case work;
    struct ctx x;
    memset(&x, 0, sizeof(x));
    case_defaults(c);
    case_defaults(&work);
    x.c = &work;
    x.where = path ? path : "case";
    x.err = err;
    x.errlen = errlen;
    if (err && errlen)
        err[0] = '\0';

    if (path && set_name(&x, path))
        load_file(&x, path);
    x.line = 0;
    for (int i = 0; i < noverrides && !x.failed; i++) {
        if (!overrides || !overrides[i]) {
            fail(&x, "override %d: missing", i + 1);
            break;
        }
        apply_override(&x, overrides[i]);
    }
    if (!x.failed)
        finish(&x);
    if (!x.failed && work.reference[0])
        resolve_reference(&x, path);
    if (x.failed)
        return 2;
    *c = work;
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Writing */

/* Shortest %.*g that reads back as exactly v (at most 17 digits). */
static void format_double(double v, char *out, size_t outlen)
{
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(out, outlen, "%.*g", prec, v);
        if (strtod(out, NULL) == v)
            return;
    }
    snprintf(out, outlen, "%.17g", v);
}

/* The value of key k in c as case_write_ini writes it. */
static void key_text(const struct muflow_case *c, const struct key *k, char *val, size_t len)
{
    const char *field = (const char *)c + k->off;
    switch (k->type) {
    case K_DOUBLE: {
        double v;
        memcpy(&v, field, sizeof(v));
        format_double(v, val, len);
        return;
    }
    case K_INT:
    case K_BOOL:
    case K_CHOICE: {
        int v;
        memcpy(&v, field, sizeof(v));
        if (k->type == K_BOOL) {
            snprintf(val, len, "%s", v ? "on" : "off");
            return;
        }
        if (k->type == K_CHOICE)
            for (const struct choice *ch = k->choices; ch->name; ch++)
                if (ch->value == v) {
                    snprintf(val, len, "%s", ch->name);
                    return;
                }
        snprintf(val, len, "%d", v);
        return;
    }
    case K_LONG: {
        long v;
        memcpy(&v, field, sizeof(v));
        snprintf(val, len, "%ld", v);
        return;
    }
    case K_STRING:
        snprintf(val, len, "%.*s", (int)(sizeof(c->output_dir) - 1), field);
        return;
    }
    snprintf(val, len, "?");
}

int case_visit_keys(const struct muflow_case *c,
                    int (*visit)(void *ctx, const char *section, const char *key,
                                 const char *value),
                    void *ctx)
{
    char val[sizeof(c->output_dir) + 8];
    for (int i = 0; i < NKEYS; i++) {
        key_text(c, &keys[i], val, sizeof(val));
        int rc = visit(ctx, keys[i].section, keys[i].name, val);
        if (rc)
            return rc;
    }
    return 0;
}

void case_write_ini(const struct muflow_case *c, FILE *out)
{
    char b[SHOWN_MAX + 4];
    const char *section = NULL;
    fprintf(out, "; muflow case: %s\n", shown(c->name, b));
    for (int i = 0; i < NKEYS; i++) {
        const struct key *k = &keys[i];
        if (!section || strcmp(section, k->section) != 0) {
            fprintf(out, "%s[%s]\n", section ? "\n" : "", k->section);
            section = k->section;
        }
        char val[sizeof(c->output_dir) + 8];
        key_text(c, k, val, sizeof(val));
        if (val[0] == '\0') /* an unset string key (no reference): its default */
            fprintf(out, "; %s is not set\n", k->name);
        else
            fprintf(out, "%s = %s\n", k->name, val);
    }
}
