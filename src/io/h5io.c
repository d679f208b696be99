/* HDF5 helpers (h5io.h). */
#define _POSIX_C_SOURCE 200809L /* fsync, open */
#include "io/h5io.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void h5io_init(void)
{
    static int done;
    if (!done) {
        H5open();
        H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
        done = 1;
    }
}

struct innermost {
    char func[64];
    char desc[400];
    int found;
};

static herr_t take_innermost(unsigned n, const H5E_error2_t *e, void *vctx)
{
    struct innermost *in = vctx;
    (void)n;
    snprintf(in->func, sizeof in->func, "%s", e->func_name ? e->func_name : "?");
    snprintf(in->desc, sizeof in->desc, "%s", e->desc ? e->desc : "");
    in->found = 1;
    return 1; /* the first entry walking upward is the innermost: stop */
}

void h5io_error(char *err, size_t errlen, const char *what)
{
    struct innermost in = {.found = 0};
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_innermost, &in);
    if (!in.found) {
        snprintf(err, errlen, "%s: unknown HDF5 error", what);
        return;
    }
    /* The file drivers append the system's message as "error message = '...'"
     * to a long description with times and offsets: keep the head and that. */
    const char *sys = strstr(in.desc, "error message = '");
    if (sys) {
        sys += strlen("error message = '");
        const char *end = strchr(sys, '\'');
        int slen = end ? (int)(end - sys) : (int)strlen(sys);
        const char *comma = strpbrk(in.desc, ",:");
        int hlen = comma ? (int)(comma - in.desc) : (int)strlen(in.desc);
        snprintf(err, errlen, "%s: %.*s: %.*s (HDF5 %s)", what, hlen, in.desc, slen, sys,
                 in.func);
    } else {
        snprintf(err, errlen, "%s: %s (HDF5 %s)", what, in.desc, in.func);
    }
}

static void fail_at(char *err, size_t errlen, const char *kind, const char *name, const char *op)
{
    char what[300];
    snprintf(what, sizeof what, "%s %s: %s", kind, name, op);
    h5io_error(err, errlen, what);
}

int h5io_write(hid_t loc, const char *name, hid_t type, int rank, const hsize_t *dims,
               const void *data, char *err, size_t errlen)
{
    hid_t space = H5Screate_simple(rank, dims, NULL);
    if (space < 0) {
        fail_at(err, errlen, "dataset", name, "cannot create its dataspace");
        return -1;
    }
    hid_t set = H5Dcreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (set < 0) {
        fail_at(err, errlen, "dataset", name, "cannot create");
        H5Sclose(space);
        return -1;
    }
    int rc = 0;
    hssize_t count = H5Sget_simple_extent_npoints(space);
    if (count > 0 && H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        fail_at(err, errlen, "dataset", name, "cannot write");
        rc = -1;
    }
    if (H5Dclose(set) < 0 && rc == 0) {
        fail_at(err, errlen, "dataset", name, "cannot close");
        rc = -1;
    }
    H5Sclose(space);
    return rc;
}

int h5io_dims(hid_t loc, const char *name, int maxrank, hsize_t *dims, char *err, size_t errlen)
{
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) {
        snprintf(err, errlen, "dataset %s: missing", name);
        return -1;
    }
    hid_t set = H5Dopen2(loc, name, H5P_DEFAULT);
    if (set < 0) {
        fail_at(err, errlen, "dataset", name, "cannot open");
        return -1;
    }
    hid_t space = H5Dget_space(set);
    int rank = space < 0 ? -1 : H5Sget_simple_extent_ndims(space);
    if (rank < 0) {
        fail_at(err, errlen, "dataset", name, "cannot read its shape");
    } else if (rank > maxrank) {
        snprintf(err, errlen, "dataset %s: rank %d, expected at most %d", name, rank, maxrank);
        rank = -1;
    } else {
        H5Sget_simple_extent_dims(space, dims, NULL);
    }
    if (space >= 0)
        H5Sclose(space);
    H5Dclose(set);
    return rank;
}

int h5io_read(hid_t loc, const char *name, hid_t memtype, int rank, const hsize_t *dims,
              void *data, char *err, size_t errlen)
{
    hsize_t have[8];
    if (rank > 8)
        return -1;
    int r = h5io_dims(loc, name, 8, have, err, errlen);
    if (r < 0)
        return -1;
    int same = r == rank;
    for (int d = 0; same && d < rank; d++)
        same = have[d] == dims[d];
    if (!same) {
        char a[128] = "", b[128] = "";
        for (int d = 0; d < r; d++)
            snprintf(a + strlen(a), sizeof a - strlen(a), "%s%llu", d ? " x " : "",
                     (unsigned long long)have[d]);
        for (int d = 0; d < rank; d++)
            snprintf(b + strlen(b), sizeof b - strlen(b), "%s%llu", d ? " x " : "",
                     (unsigned long long)dims[d]);
        snprintf(err, errlen, "dataset %s: shape %s, expected %s", name, a, b);
        return -1;
    }
    hid_t set = H5Dopen2(loc, name, H5P_DEFAULT);
    if (set < 0) {
        fail_at(err, errlen, "dataset", name, "cannot open");
        return -1;
    }
    int rc = 0;
    size_t count = 1;
    for (int d = 0; d < rank; d++)
        count *= dims[d];
    if (count > 0 && H5Dread(set, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        fail_at(err, errlen, "dataset", name, "cannot read");
        rc = -1;
    }
    H5Dclose(set);
    return rc;
}

int h5io_attr_write(hid_t loc, const char *name, hid_t type, int n, const void *data, char *err,
                    size_t errlen)
{
    hsize_t dim = (hsize_t)n;
    hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &dim, NULL);
    if (space < 0) {
        fail_at(err, errlen, "attribute", name, "cannot create its dataspace");
        return -1;
    }
    hid_t at = H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    int rc = 0;
    if (at < 0) {
        fail_at(err, errlen, "attribute", name, "cannot create");
        rc = -1;
    } else {
        if (H5Awrite(at, type, data) < 0) {
            fail_at(err, errlen, "attribute", name, "cannot write");
            rc = -1;
        }
        H5Aclose(at);
    }
    H5Sclose(space);
    return rc;
}

/* The attribute name of loc, or -1 (missing, or cannot be opened). */
static hid_t open_attribute(hid_t loc, const char *name, char *err, size_t errlen)
{
    if (H5Aexists(loc, name) <= 0) {
        snprintf(err, errlen, "attribute %s: missing", name);
        return -1;
    }
    hid_t at = H5Aopen(loc, name, H5P_DEFAULT);
    if (at < 0)
        fail_at(err, errlen, "attribute", name, "cannot open");
    return at;
}

int h5io_attr_read(hid_t loc, const char *name, hid_t memtype, int n, void *data, char *err,
                   size_t errlen)
{
    hid_t at = open_attribute(loc, name, err, errlen);
    if (at < 0)
        return -1;
    int rc = 0;
    hid_t space = H5Aget_space(at);
    hssize_t count = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
    if (count != n) {
        snprintf(err, errlen, "attribute %s: %lld values, expected %d", name, (long long)count, n);
        rc = -1;
    } else if (H5Aread(at, memtype, data) < 0) {
        fail_at(err, errlen, "attribute", name, "cannot read");
        rc = -1;
    }
    if (space >= 0)
        H5Sclose(space);
    H5Aclose(at);
    return rc;
}

int h5io_attr_write_text(hid_t loc, const char *name, const char *text, char *err,
                         size_t errlen)
{
    /* fixed-length, NUL-terminated: read by every HDF5 tool and h5py as str */
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type < 0 || H5Tset_size(type, strlen(text) + 1) < 0 ||
        H5Tset_strpad(type, H5T_STR_NULLTERM) < 0) {
        fail_at(err, errlen, "attribute", name, "cannot make its string type");
        if (type >= 0)
            H5Tclose(type);
        return -1;
    }
    int rc = h5io_attr_write(loc, name, type, 1, text, err, errlen);
    H5Tclose(type);
    return rc;
}

/* Text of the open attribute at into text[len]. */
static int read_text(hid_t at, const char *name, char *text, size_t len, char *err,
                     size_t errlen)
{
    hid_t ftype = H5Aget_type(at);
    if (ftype < 0) {
        fail_at(err, errlen, "attribute", name, "cannot read its type");
        return -1;
    }
    int rc = 0;
    if (H5Tget_class(ftype) != H5T_STRING || H5Tis_variable_str(ftype) > 0) {
        snprintf(err, errlen, "attribute %s: not a fixed-length text", name);
        rc = -1;
    } else {
        size_t size = H5Tget_size(ftype);
        if (size + 1 > len) {
            snprintf(err, errlen, "attribute %s: text of %zu bytes, at most %zu allowed", name,
                     size, len - 1);
            rc = -1;
        } else {
            hid_t mtype = H5Tcopy(H5T_C_S1);
            H5Tset_size(mtype, size + 1);
            H5Tset_strpad(mtype, H5T_STR_NULLTERM);
            if (H5Aread(at, mtype, text) < 0) {
                fail_at(err, errlen, "attribute", name, "cannot read");
                rc = -1;
            }
            text[size] = '\0';
            H5Tclose(mtype);
        }
    }
    H5Tclose(ftype);
    return rc;
}

int h5io_attr_read_text(hid_t loc, const char *name, char *text, size_t len, char *err,
                        size_t errlen)
{
    hid_t at = open_attribute(loc, name, err, errlen);
    if (at < 0)
        return -1;
    int rc = read_text(at, name, text, len, err, errlen);
    H5Aclose(at);
    return rc;
}

int h5io_attr_each_text(hid_t loc, int (*visit)(void *ctx, const char *name, const char *text),
                        void *ctx, char *err, size_t errlen)
{
    H5O_info_t info;
    if (H5Oget_info2(loc, &info, H5O_INFO_NUM_ATTRS) < 0) {
        h5io_error(err, errlen, "cannot count attributes");
        return -1;
    }
    for (hsize_t i = 0; i < info.num_attrs; i++) {
        hid_t at = H5Aopen_by_idx(loc, ".", H5_INDEX_NAME, H5_ITER_INC, i, H5P_DEFAULT,
                                  H5P_DEFAULT);
        if (at < 0) {
            h5io_error(err, errlen, "cannot open an attribute");
            return -1;
        }
        char name[256];
        if (H5Aget_name(at, sizeof name, name) < 0) {
            h5io_error(err, errlen, "cannot read an attribute's name");
            H5Aclose(at);
            return -1;
        }
        hid_t type = H5Aget_type(at);
        int is_text = type >= 0 && H5Tget_class(type) == H5T_STRING;
        if (type >= 0)
            H5Tclose(type);
        int rc = 0;
        if (is_text) {
            size_t cap = 4096;
            char *text = malloc(cap);
            if (!text) {
                snprintf(err, errlen, "attribute %s: out of memory", name);
                rc = -1;
            } else if (read_text(at, name, text, cap, err, errlen) != 0) {
                rc = -1;
            } else {
                rc = visit(ctx, name, text);
            }
            free(text);
        }
        H5Aclose(at);
        if (rc)
            return rc;
    }
    return 0;
}

int h5io_write_file(const char *tmp, const char *path, const char *label, h5io_contents contents,
                    void *ctx, char *err, size_t errlen)
{
    h5io_init();
    char cause[600];
    hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    int rc = 0;
    if (file < 0) {
        h5io_error(cause, sizeof cause, "cannot create");
        rc = -1;
    } else {
        rc = contents(file, ctx, cause, sizeof cause);
        /* closing flushes the metadata: a full disk may only show here */
        if (H5Fclose(file) < 0 && rc == 0) {
            h5io_error(cause, sizeof cause, "cannot close");
            rc = -1;
        }
    }
    if (rc != 0) {
        snprintf(err, errlen, "cannot write %s%s%s: %s", label, *label ? " " : "", tmp, cause);
        remove(tmp);
        return -1;
    }
    if (h5io_commit(tmp, path, cause, sizeof cause) != 0) {
        if (*label)
            snprintf(err, errlen, "cannot write %s: %s", label, cause);
        else
            snprintf(err, errlen, "%s", cause);
        return -1;
    }
    return 0;
}

int h5io_commit(const char *tmp, const char *path, char *err, size_t errlen)
{
    int fd = open(tmp, O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) {
        snprintf(err, errlen, "cannot sync %s: %s", tmp, strerror(errno));
        if (fd >= 0)
            close(fd);
        remove(tmp);
        return -1;
    }
    close(fd);
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        remove(tmp);
        return -1;
    }
    /* the rename itself is durable once the folder is synced */
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash)
        *(slash == dir ? slash + 1 : slash) = '\0';
    else
        snprintf(dir, sizeof dir, ".");
    int dfd = open(dir, O_RDONLY);
    if (dfd >= 0) {
        fsync(dfd); /* best effort: some file systems refuse fsync on folders */
        close(dfd);
    }
    return 0;
}
