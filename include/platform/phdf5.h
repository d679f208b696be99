/* Parallel HDF5 (Debian's Open MPI flavour) for the ranks of an mpirun.
 *
 * muflow links the serial HDF5; the parallel one, its own build of the same
 * version (libhdf5_openmpi.so.103, needing libmpi), is opened with dlopen
 * under mpirun only, once comm_init has opened libmpi: a run without mpirun
 * loads neither (docs/numerics/decomposition.md).  Both libraries export
 * the same names, and the parallel one reaches its own global ids (the
 * native types, the property classes: H5T_NATIVE_DOUBLE_g ...) through
 * its GOT: RTLD_DEEPBIND binds them to its own copies, not the serial
 * library's.  Its handles (hid_t) are the parallel library's: never
 * passed to the serial one, nor back.  Not under AddressSanitizer, which
 * refuses RTLD_DEEPBIND (check-asan runs no mpirun). */
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
};

/* The parallel library, opened and initialised on the first call; NULL
 * with the cause in err (not under mpirun, the library missing). */
const struct phdf5 *phdf5_open(char *err, size_t errlen);

#endif
