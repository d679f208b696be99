/* Field files: the state of a run at one time, in HDF5, for analysis and
 * visualisation (fields.xdmf, see xdmf.h, lets ParaView open a series).
 *
 * File dir/fields_<step, 6 digits or more>.h5, written as .tmp and renamed.
 * The datasets are the outputs the field registry declares (march/fields.h),
 * the core ones below and any a physics module adds.
 * Every array is stored x fastest, i.e. with dimensions (z, y, x), the order
 * of VTK and XDMF, so a[k][j][i] is cell / face (i, j, k):
 *   u, v, w      velocity components on their faces: u (nz, ny, nxf), v (nz, nyf, nx),
 *                w (nzf, ny, nx).  Along a periodic direction there are n distinct
 *                faces (face n is face 0), so nxf = nx; otherwise nxf = nx + 1 with the
 *                boundary faces 0 and nx included.  Face i is at x = i hx.
 *   pressure                total pressure (confining + hydrostatic + dynamic)
 *   pressure_regularised    the pressure that enters mu(I)
 *   shear_rate              |D| = sqrt(0.5 gamma:gamma)
 *   inertial_number         I from |D| and the regularised pressure
 *   viscosity               cell viscosity eta
 *   velocity                (nz, ny, nx, 3): the cell-centred velocity, the mean of
 *                           the two faces of each component (for visualisation)
 * all cell-centred, cell (i, j, k) centred at ((i + 1/2) hx, ...).
 * Root attributes: format, case_name, step, time, dt, status, n (nx ny nz),
 * len (lx ly lz), h (hx hy hz), and one text attribute "section.key" per case
 * key with its value as the summary writes it. */
#ifndef MUFLOW_FIELDS_H5_H
#define MUFLOW_FIELDS_H5_H

#include <hdf5.h>
#include <stddef.h>
#include "grid/decomp.h"
#include "march/march.h"

#define FIELDS_FORMAT "muflow fields 1"

/* "fields_000042.h5" for step 42. */
void fields_h5_name(long step, char *buf, size_t len);

/* Writes dir/fields_<step>.h5 for the current state of st (residual evaluated,
 * so pressure, |D|, viscosity belong to the velocity).  Returns 0, or -1 with
 * the cause in err (the temporary file removed, an older file of that name
 * untouched). */
int fields_h5_write(const char *dir, const struct march_state *st, char *err, size_t errlen);

/* The same file written by the ranks of dc together (h5blocks.h), each
 * its block of every dataset: st is a rank's march (st->g its block of
 * the global grid gg, ghosts filled: the next rank's face 0 in slot n).
 * Collective; every rank returns the same status.  Not for a stretched
 * grid. */
int fields_h5_write_decomposed(const char *dir, const struct march_state *st,
                               const struct grid *gg, const struct decomp *dc, char *err,
                               size_t errlen);

/* Writes the grid attributes and one text attribute per case key on loc
 * (shared with the checkpoints). */
int fields_h5_case_attributes(hid_t loc, const struct muflow_case *cs, const struct grid *g,
                              char *err, size_t errlen);

#endif
