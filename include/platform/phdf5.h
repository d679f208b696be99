/* Parallel HDF5 (Debian's Open MPI flavour) for the ranks of an mpirun.
 *
 * muflow links the serial HDF5; the parallel one, its own build of the same
 * version (libhdf5_openmpi.so.103, needing libmpi), is opened with dlopen
 * under mpirun only, once comm_init has opened libmpi: a run without mpirun
 * loads neither (docs/numerics/decomposition.md).  Both libraries export
 * the same names, under their own symbol versions (HDF5_SERIAL_1.x,
 * HDF5_MPI_1.x): each binds its calls and global ids (H5T_NATIVE_DOUBLE_g
 * ...) to itself, and the program's calls, linked against the serial
 * library, go to it.  The parallel library's handles (hid_t) are its own:
 * never passed to the serial one, nor back. */
#ifndef MUFLOW_PLATFORM_PHDF5_H
#define MUFLOW_PLATFORM_PHDF5_H

#include <hdf5.h>
#include <stddef.h>

/* The calls the ranks' writer makes, typed from the serial headers (the
 * same version's prototypes), and the two MPI-IO settings the serial
 * headers lack. */
struct phdf5 {
#define PHDF5_POINTER(f) __typeof__(f) *f;
#define PHDF5_FUNCTIONS(X)                                                                        \
    X(H5open) X(H5Eset_auto2) X(H5Pcreate) X(H5Pclose) X(H5Fcreate) X(H5Fclose) X(H5Screate_simple) \
    X(H5Sselect_hyperslab) X(H5Sclose) X(H5Dcreate2) X(H5Dwrite) X(H5Dclose)
    PHDF5_FUNCTIONS(PHDF5_POINTER)
    herr_t (*H5Pset_fapl_mpio)(hid_t fapl, void *comm, void *info);
    herr_t (*H5Pset_dxpl_mpio)(hid_t dxpl, int collective);
    hid_t native_double, file_access, dataset_xfer; /* its H5T_NATIVE_DOUBLE ... */
    void *info_null;                                /* MPI_INFO_NULL */
    void *comm_world;                               /* MPI_COMM_WORLD */
};

/* The parallel library, opened and initialised on the first call; NULL
 * with the cause in err (not under mpirun, the library missing). */
const struct phdf5 *phdf5_open(char *err, size_t errlen);

#endif
