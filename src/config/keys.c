/* Parsing and writing one key of a key table (keys.h). */
#include "config/keys.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "config/ini.h"

/* A bound of a number key: integers in full (100000000, not 1e+08). */
static struct num_text bound_text(const struct key *k, double v)
{
    struct num_text t;
    if (k->type == K_DOUBLE)
        return num_text(v);
    snprintf(t.s, sizeof t.s, "%.0f", v);
    return t;
}

void key_range_text(const struct key *k, char *out, size_t outlen)
{
    if (k->range_text)
        snprintf(out, outlen, "%s", k->range_text);
    else if (k->hi == HUGE_VAL)
        snprintf(out, outlen, "must be %s %s", k->lo_incl ? ">=" : ">", bound_text(k, k->lo).s);
    else
        snprintf(out, outlen, "must be in %c%s, %s%c", k->lo_incl ? '[' : '(',
                 bound_text(k, k->lo).s, bound_text(k, k->hi).s, k->hi_incl ? ']' : ')');
}

void key_allowed_text(const struct key *k, char *out, size_t outlen)
{
    switch (k->type) {
    case K_DOUBLE:
    case K_INT:
    case K_LONG: {
        const char *kind = k->type == K_DOUBLE ? "real" : "integer";
        if (!k->range_text && k->lo == -HUGE_VAL && k->hi == HUGE_VAL) {
            snprintf(out, outlen, "%s", kind);
            return;
        }
        char range[160];
        if (k->range_text)
            snprintf(range, sizeof range, "%s", k->range_text);
        else
            key_range_text(k, range, sizeof range);
        /* "must be > 0" -> "real > 0", "must be in [1, 2]" -> "integer in [1, 2]" */
        if (strncmp(range, "must be ", 8) == 0)
            snprintf(out, outlen, "%s %s", kind, range + 8);
        else
            snprintf(out, outlen, "%s: %s", kind, range);
        return;
    }
    case K_BOOL:
        snprintf(out, outlen, "on|off");
        return;
    case K_CHOICE: {
        size_t used = 0;
        out[0] = '\0';
        for (const struct choice *ch = k->choices; ch->name && used < outlen; ch++)
            used += (size_t)snprintf(out + used, outlen - used, "%s%s",
                                     ch == k->choices ? "" : "|", ch->name);
        return;
    }
    case K_STRING:
        snprintf(out, outlen, "text of at most %zu characters", k->size - 1);
        return;
    }
    snprintf(out, outlen, "?");
}

void key_default_text(const void *base, const struct key *k, char *out, size_t outlen)
{
    if (k->default_text)
        snprintf(out, outlen, "%s", k->default_text);
    else
        key_text(base, k, out, outlen);
}

void key_write_help(const void *base, const struct key *k, FILE *out)
{
    char def[600], allowed[600];
    key_default_text(base, k, def, sizeof def);
    if (!def[0])
        snprintf(def, sizeof def, "(not set)");
    key_allowed_text(k, allowed, sizeof allowed);
    fprintf(out, "  %s.%s = %s  (%s)\n      %s", k->section, k->name, def, allowed,
            k->help ? k->help : "");
    if (k->units)
        fprintf(out, " (%s)", k->units);
    fputc('\n', out);
}

static int in_range(const struct key *k, double v)
{
    if (k->lo_incl ? v < k->lo : v <= k->lo)
        return 0;
    if (k->hi == HUGE_VAL)
        return 1;
    return k->hi_incl ? v <= k->hi : v < k->hi;
}

/* A plain decimal number: [+-] digits [. digits] [(e|E) [+-] digits], at
 * least one digit in the mantissa.  strtod also reads hexadecimal floats
 * (0x1p-2), "inf", "infinity" and "nan(...)": none of them is a case-file
 * number. */
static int is_decimal(const char *s)
{
    int digits = 0;
    if (*s == '+' || *s == '-')
        s++;
    for (; *s >= '0' && *s <= '9'; s++)
        digits++;
    if (*s == '.')
        for (s++; *s >= '0' && *s <= '9'; s++)
            digits++;
    if (!digits)
        return 0;
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            s++;
        if (!(*s >= '0' && *s <= '9'))
            return 0;
        while (*s >= '0' && *s <= '9')
            s++;
    }
    return *s == '\0';
}

const char *key_parse(void *base, const struct key *k, const char *value, char *msg,
                      size_t msglen)
{
    char *field = (char *)base + k->off;
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
        if (!is_decimal(value))
            return "not a decimal number (hexadecimal and other forms are not accepted)";
        if (!in_range(k, v)) {
            key_range_text(k, msg, msglen);
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
            key_range_text(k, msg, msglen);
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
            if (ini_equal_nocase(value, words[i])) {
                int b = i % 2;
                memcpy(field, &b, sizeof(b));
                return NULL;
            }
        return "not a boolean (on|off|true|false|yes|no|1|0)";
    }
    case K_CHOICE: {
        for (const struct choice *ch = k->choices; ch->name; ch++)
            if (ini_equal_nocase(value, ch->name)) {
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
        size_t len = strlen(value);
        if (len >= k->size) {
            snprintf(msg, msglen, "longer than %zu characters", k->size - 1);
            return msg;
        }
        for (const char *p = value; *p; p++) {
            unsigned char ch = (unsigned char)*p;
            if (ch < 32 || ch == 127)
                return "contains a control character";
            if (ch == ';' && (p == value || ini_is_blank((unsigned char)p[-1])))
                return "contains ';' at the start or after a blank (an INI comment)";
        }
        memcpy(field, value, len + 1);
        return NULL;
    }
    }
    return "internal error: unknown key type";
}

void key_text(const void *base, const struct key *k, char *val, size_t len)
{
    const char *field = (const char *)base + k->off;
    switch (k->type) {
    case K_DOUBLE: {
        double v;
        memcpy(&v, field, sizeof(v));
        num_format(v, val, len);
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
        snprintf(val, len, "%.*s", (int)(k->size - 1), field);
        return;
    }
    snprintf(val, len, "?");
}
