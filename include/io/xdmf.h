/* fields.xdmf: an XDMF 2 description of the field files (fields_h5.h) as one
 * temporal collection, so ParaView and VisIt open the whole series at once.
 * The mesh is a 3DCoRectMesh (uniform spacing, origin 0) of the cell corners;
 * every cell-centred dataset is an attribute with Center="Cell" (the face
 * velocities live on other grids and stay in the HDF5 files only).  Datasets
 * are referenced as "fields_<step>.h5:/name", relative to the .xdmf file. */
#ifndef MUFLOW_XDMF_H
#define MUFLOW_XDMF_H

#include <stddef.h>
#include "grid/grid.h"
#include "march/fields.h"

/* Writes dir/fields.xdmf (as .tmp, then renamed) for the field files of
 * steps[0..count) at times[0..count), whose cell datasets are the outputs of
 * the registry r.  Returns 0, or -1 with the cause. */
int xdmf_write(const char *dir, const struct grid *g, const struct field_registry *r, int count,
               const long *steps, const double *times, char *err, size_t errlen);

#endif
