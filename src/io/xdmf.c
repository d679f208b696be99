/* XDMF index of the field files (xdmf.h). */
#include "io/xdmf.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include "io/fields_h5.h"
#include "io/h5io.h"

static void attribute(FILE *f, const char *name, const char *type, const char *dims,
                      const char *file)
{
    fprintf(f,
            "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Cell\">\n"
            "          <DataItem Dimensions=\"%s\" NumberType=\"Float\" Precision=\"8\" "
            "Format=\"HDF\">%s:/%s</DataItem>\n"
            "        </Attribute>\n",
            name, type, dims, file, name);
}

int xdmf_write(const char *dir, const struct grid *g, const struct field_registry *r, int count,
               const long *steps, const double *times, char *err, size_t errlen)
{
    char path[700], tmp[720];
    if (snprintf(path, sizeof path, "%s/fields.xdmf", dir) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        snprintf(err, errlen, "output path too long in %s", dir);
        return -1;
    }
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno));
        return -1;
    }
    /* XDMF lists dimensions slowest first and CoRectMesh origin and spacing in
     * z, y, x order, matching the (z, y, x) arrays of the field files. */
    char nodes[96], cells[96], vec[100];
    snprintf(nodes, sizeof nodes, "%d %d %d", g->n[2] + 1, g->n[1] + 1, g->n[0] + 1);
    snprintf(cells, sizeof cells, "%d %d %d", g->n[2], g->n[1], g->n[0]);
    snprintf(vec, sizeof vec, "%s 3", cells);
    fprintf(f, "<?xml version=\"1.0\" ?>\n"
               "<Xdmf Version=\"2.0\">\n"
               "  <Domain>\n"
               "    <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (int m = 0; m < count; m++) {
        char file[64];
        fields_h5_name(steps[m], file, sizeof file);
        if (grid_stretched(g)) {
            /* a stretched grid: the faces' coordinates per direction, inline */
            fprintf(f,
                    "      <Grid Name=\"step %ld\" GridType=\"Uniform\">\n"
                    "        <Time Value=\"%.17g\"/>\n"
                    "        <Topology TopologyType=\"3DRectMesh\" Dimensions=\"%s\"/>\n"
                    "        <Geometry GeometryType=\"VXVYVZ\">\n",
                    steps[m], times[m], nodes);
            for (int d = 0; d < 3; d++) {
                fprintf(f,
                        "          <DataItem Dimensions=\"%d\" NumberType=\"Float\" "
                        "Precision=\"8\" Format=\"XML\">",
                        g->n[d] + 1);
                for (int i = 0; i <= g->n[d]; i++)
                    fprintf(f, "%s%.17g", i ? " " : "", grid_xf(g, d, i));
                fprintf(f, "</DataItem>\n");
            }
            fprintf(f, "        </Geometry>\n");
        } else
            fprintf(f,
                    "      <Grid Name=\"step %ld\" GridType=\"Uniform\">\n"
                    "        <Time Value=\"%.17g\"/>\n"
                    "        <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"%s\"/>\n"
                    "        <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                    "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
                    "Format=\"XML\">0 0 0</DataItem>\n"
                    "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
                    "Format=\"XML\">%.17g %.17g %.17g</DataItem>\n"
                    "        </Geometry>\n",
                    steps[m], times[m], nodes, g->h[2], g->h[1], g->h[0]);
        /* the registry's outputs: cell scalars first, then the vectors */
        for (int vector = 0; vector < 2; vector++)
            for (int o = 0; o < r->noutputs; o++)
                if ((r->e[r->out[o].source].spec.where == FIELD_FACES) == vector)
                    attribute(f, r->out[o].name, vector ? "Vector" : "Scalar",
                              vector ? vec : cells, file);
        fprintf(f, "      </Grid>\n");
    }
    fprintf(f, "    </Grid>\n"
               "  </Domain>\n"
               "</Xdmf>\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(errno ? errno : EIO));
        remove(tmp);
        return -1;
    }
    return h5io_commit(tmp, path, err, errlen);
}
