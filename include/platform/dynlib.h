/* Shared libraries opened on first use (amg_hypre.c, comm.c, phdf5.c,
 * fft_ranks.c, suitesparse_open.c): they are not linked, so that runs that
 * need none start without them (docs/numerics/threads-and-platform.md);
 * each symbol is resolved into a pointer typed from the library's own
 * prototype. */
#ifndef MUFLOW_PLATFORM_DYNLIB_H
#define MUFLOW_PLATFORM_DYNLIB_H

#include <dlfcn.h>
#include <stdio.h>

/* dlopen(soname, RTLD_NOW | scope) (scope: RTLD_LOCAL, or RTLD_GLOBAL for a
 * library whose plugins or dependants must see its names); NULL with the
 * message "what soname (Debian: package): why" when it cannot be opened. */
static inline void *dynlib_open(const char *soname, int scope, const char *what,
                                const char *package, char *err, size_t errlen)
{
    void *lib = dlopen(soname, RTLD_NOW | scope);
    if (!lib) {
        const char *why = dlerror();
        snprintf(err, errlen, "%s %s (Debian: %s): %s", what, soname, package,
                 why ? why : "not found");
    }
    return lib;
}

/* table.f = the symbol f of lib, unless an earlier symbol was missing
 * (missing: NULL, or the first name not found, which this sets). */
#define DYNLIB_RESOLVE(lib, table, f, missing)                                                    \
    if (!(missing)) {                                                                             \
        void *dynlib_sym_ = dlsym((lib), #f);                                                     \
        if (dynlib_sym_)                                                                          \
            (table).f = (__typeof__((table).f))dynlib_sym_;                                       \
        else                                                                                      \
            (missing) = #f;                                                                       \
    }

#endif
