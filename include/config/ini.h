/* The generic INI engine under the case files: reads a file through libinih
 * into an ordered list of events (section headers and key = value lines, each
 * with its line number), so that the key table (keys.h, case.h) can apply
 * them in order after a first look at the whole input.  It knows nothing of
 * muflow's keys.
 *
 * The file is fed to inih line by line through our own reader, which
 *   - counts lines (so later errors know where they are),
 *   - rejects lines longer than inih's line buffer instead of letting inih
 *     split them silently, and NUL bytes,
 *   - strips a UTF-8 BOM and leading blanks (so indented keys are keys, never
 *     inih "multi-line continuations" of the previous value).
 * The first error of the file (syntax, long line, NUL, unreadable) ends the
 * list: it is recorded as an event of kind INI_ERROR at its line, so that an
 * error found later by the key table on an earlier line still comes first. */
#ifndef MUFLOW_CONFIG_INI_H
#define MUFLOW_CONFIG_INI_H

#include <stdarg.h>
#include <stddef.h>

#define INI_SHOWN_MAX 160 /* longest value or path quoted in an error message */

enum ini_event_kind { INI_SECTION, INI_KEY, INI_ERROR };

struct ini_event {
    enum ini_event_kind kind;
    int line;            /* 1-based line of the file; 0 for an override */
    char *section;       /* INI_SECTION: its name; INI_KEY: the section it is in */
    char *key, *value;   /* INI_KEY */
    char *message;       /* INI_ERROR: one line, the file named */
    const char *arg;     /* an override's own text ("section.key=value"), else NULL */
};

struct ini_events {
    struct ini_event *ev;
    int count, cap;
};

/* Appends the events of the file at path (shown as `where` in messages).
 * Returns 0, or -1 when memory ran out (message in err).  A file that cannot
 * be opened or read, or whose text is malformed, is not a -1: it ends in an
 * INI_ERROR event. */
int ini_read_file(struct ini_events *out, const char *path, const char *where, char *err,
                  size_t errlen);

/* Appends an override "section.key=value" (split at the first '=' and the
 * first '.' before it, blanks around the parts removed); a malformed one
 * becomes an INI_ERROR event.  Returns 0, or -1 when memory ran out. */
int ini_add_override(struct ini_events *out, const char *arg);

void ini_events_free(struct ini_events *e);

/* Text helpers shared by the key table. */
/* vsnprintf into out, then every control character replaced by '?': a
 * message stays one line whatever the input quoted in it. */
void ini_format_line(char *out, size_t len, const char *fmt, va_list ap);
/* Copy of s for an error message: at most INI_SHOWN_MAX characters, control
 * characters replaced, "..." when cut. */
const char *ini_shown(const char *s, char buf[INI_SHOWN_MAX + 4]);
int ini_equal_nocase(const char *a, const char *b);
int ini_is_blank(int ch);
/* Optimal-string-alignment edit distance; large for long strings. */
int ini_edit_distance(const char *a, const char *b);

#endif
