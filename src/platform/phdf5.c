/* Parallel HDF5 opened under mpirun (platform/phdf5.h). */
#include "platform/phdf5.h"
#include "platform/comm.h"
#include "platform/dynlib.h"

#include <stdio.h>

/* The Makefile passes the soname of libhdf5-openmpi-dev's libhdf5.so. */
#ifndef MUFLOW_PHDF5_LIB
#define MUFLOW_PHDF5_LIB "libhdf5_openmpi.so.103"
#endif

static struct phdf5 api;
static int opened;

/* The hid_t the library keeps in its global name (valid after H5open). */
static int global_id(void *lib, const char *name, hid_t *id)
{
    const hid_t *p = dlsym(lib, name);
    if (!p)
        return -1;
    *id = *p;
    return 0;
}

const struct phdf5 *phdf5_open(char *err, size_t errlen)
{
    if (opened)
        return &api;
    if (comm_require("parallel HDF5", err, errlen) != 0) /* libmpi first, in the global scope */
        return NULL;
    /* local: its names stay out of the global scope (the serial library's) */
    void *lib = dynlib_open(MUFLOW_PHDF5_LIB, RTLD_LOCAL, "parallel HDF5", "libhdf5-openmpi-dev",
                            err, errlen);
    if (!lib)
        return NULL;
    struct phdf5 t = {0};
    const char *missing = NULL;
#define RESOLVE(f) DYNLIB_RESOLVE(lib, t, f, missing)
    PHDF5_FUNCTIONS(RESOLVE)
    RESOLVE(H5Pset_fapl_mpio)
    RESOLVE(H5Pset_dxpl_mpio)
#undef RESOLVE
    /* MPI_INFO_NULL, MPI_COMM_WORLD: Open MPI's objects of those names
     * (libmpi, its dependency) */
    if (!missing && !(t.info_null = dlsym(lib, "ompi_mpi_info_null")))
        missing = "ompi_mpi_info_null";
    if (!missing && !(t.comm_world = dlsym(lib, "ompi_mpi_comm_world")))
        missing = "ompi_mpi_comm_world";
    if (!missing && t.H5open() < 0)
        missing = "H5open";
    if (!missing && global_id(lib, "H5T_NATIVE_DOUBLE_g", &t.native_double) != 0)
        missing = "H5T_NATIVE_DOUBLE_g";
    if (!missing && global_id(lib, "H5P_CLS_FILE_ACCESS_ID_g", &t.file_access) != 0)
        missing = "H5P_CLS_FILE_ACCESS_ID_g";
    if (!missing && global_id(lib, "H5P_CLS_DATASET_XFER_ID_g", &t.dataset_xfer) != 0)
        missing = "H5P_CLS_DATASET_XFER_ID_g";
    if (missing) {
        snprintf(err, errlen, "parallel HDF5 %s lacks %s", MUFLOW_PHDF5_LIB, missing);
        dlclose(lib);
        return NULL;
    }
    t.H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the writer reports its errors */
    api = t;
    opened = 1; /* open for the rest of the run */
    return &api;
}
