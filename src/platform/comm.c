/* The processes of a run (platform/comm.h): libmpi opened on first use,
 * only when mpirun started the program. */
#define _POSIX_C_SOURCE 200809L
#include "platform/comm.h"
#include "platform/dynlib.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The Makefile passes the soname of the -dev package's libmpi.so. */
#ifndef MUFLOW_MPI_LIB
#define MUFLOW_MPI_LIB "libmpi.so.40"
#endif

#define MPI_FUNCTIONS(X)                                                                          \
    X(MPI_Init_thread) X(MPI_Initialized) X(MPI_Finalized) X(MPI_Finalize) X(MPI_Comm_rank)       \
    X(MPI_Comm_size) X(MPI_Allreduce) X(MPI_Barrier) X(MPI_Abort) X(MPI_Dims_create)              \
    X(MPI_Cart_create) X(MPI_Cart_coords) X(MPI_Cart_shift) X(MPI_Comm_free) X(MPI_Irecv)         \
    X(MPI_Isend) X(MPI_Waitall) X(MPI_Allgatherv) X(MPI_Alltoallv)

/* Open MPI's handles are addresses of objects in libmpi (MPI_COMM_WORLD is
 * &ompi_mpi_comm_world): resolved by name like the functions. */
#define MPI_HANDLES(X)                                                                            \
    X(MPI_Comm, comm_world, "ompi_mpi_comm_world") X(MPI_Datatype, type_double, "ompi_mpi_double") \
    X(MPI_Datatype, type_long, "ompi_mpi_long") X(MPI_Op, op_sum, "ompi_mpi_op_sum")              \
    X(MPI_Op, op_max, "ompi_mpi_op_max")

static struct {
    void *lib;
#define POINTER(f) __typeof__(f) *f;
    MPI_FUNCTIONS(POINTER)
#undef POINTER
#define HANDLE(type, name, sym) type name;
    MPI_HANDLES(HANDLE)
#undef HANDLE
} mpi;

static int active; /* MPI initialised by comm_init */
static int world_rank, world_size = 1;
static long reductions; /* MPI_Allreduce calls (comm_reductions) */
static struct comm_traffic traffic;
static struct comm_waits waits;

_Static_assert(sizeof(MPI_Comm) == sizeof(void *), "Open MPI's MPI_Comm, a pointer, expected");

int comm_launched(void)
{
    const char *s = getenv("OMPI_COMM_WORLD_SIZE");
    return s && *s;
}

static int load_mpi(char *err, size_t errlen)
{
    /* global: its plugins see it */
    void *lib = dynlib_open(MUFLOW_MPI_LIB, RTLD_GLOBAL, "mpirun: Open MPI's", "libopenmpi-dev",
                            err, errlen);
    if (!lib)
        return -1;
    const char *missing = NULL;
#define RESOLVE(f) DYNLIB_RESOLVE(lib, mpi, f, missing)
    MPI_FUNCTIONS(RESOLVE)
#undef RESOLVE
#define HANDLE(type, name, sym)                                                                   \
    if (!missing) {                                                                               \
        void *p = dlsym(lib, sym);                                                                \
        if (p)                                                                                    \
            mpi.name = (type)p;                                                                   \
        else                                                                                      \
            missing = sym;                                                                        \
    }
    MPI_HANDLES(HANDLE)
#undef HANDLE
    if (missing) {
        snprintf(err, errlen, "mpirun: %s lacks %s", MUFLOW_MPI_LIB, missing);
        dlclose(lib);
        return -1;
    }
    mpi.lib = lib; /* open for the rest of the run */
    return 0;
}

void comm_finalize(void)
{
    if (!active)
        return;
    int done = 0;
    mpi.MPI_Finalized(&done);
    if (!done)
        mpi.MPI_Finalize();
    active = 0;
}

int comm_require(const char *what, char *err, size_t errlen)
{
    if (!comm_launched()) {
        snprintf(err, errlen, "%s: only under mpirun", what);
        return -1;
    }
    return comm_init(err, errlen);
}

int comm_init(char *err, size_t errlen)
{
    if (active || !comm_launched())
        return 0;
    if (!mpi.lib && load_mpi(err, errlen) != 0)
        return -1;
    int init = 0, provided = MPI_THREAD_SINGLE;
    mpi.MPI_Initialized(&init);
    if (!init && mpi.MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        snprintf(err, errlen, "mpirun: MPI_Init_thread failed");
        return -1;
    }
    mpi.MPI_Comm_rank(mpi.comm_world, &world_rank);
    mpi.MPI_Comm_size(mpi.comm_world, &world_size);
    active = 1;
    atexit(comm_finalize);
    return 0;
}

int comm_rank(void)
{
    return world_rank;
}

int comm_size(void)
{
    return world_size;
}

_Noreturn void comm_exit(int status, int all, const char *msg)
{
    if (msg && (!all || world_rank == 0)) {
        fprintf(stderr, "%s\n", msg);
        fflush(stderr);
    }
    if (active && !all)
        mpi.MPI_Abort(mpi.comm_world, status);
    fflush(stdout);
    comm_finalize();
    exit(status);
}

void comm_sum(double *v, int n)
{
    if (active && world_size > 1) {
        reductions++;
        traffic.reductions++;
        traffic.reduced_values += n;
        const double t0 = comm_clock();
        mpi.MPI_Allreduce(MPI_IN_PLACE, v, n, mpi.type_double, mpi.op_sum, mpi.comm_world);
        waits.reductions += comm_clock() - t0;
    }
}

void comm_sum_long(long *v, int n)
{
    if (active && world_size > 1) {
        reductions++;
        traffic.reductions++;
        traffic.reduced_values += n;
        const double t0 = comm_clock();
        mpi.MPI_Allreduce(MPI_IN_PLACE, v, n, mpi.type_long, mpi.op_sum, mpi.comm_world);
        waits.reductions += comm_clock() - t0;
    }
}

void comm_max(double *v, int n)
{
    if (active && world_size > 1) {
        reductions++;
        traffic.reductions++;
        traffic.reduced_values += n;
        const double t0 = comm_clock();
        mpi.MPI_Allreduce(MPI_IN_PLACE, v, n, mpi.type_double, mpi.op_max, mpi.comm_world);
        waits.reductions += comm_clock() - t0;
    }
}

long comm_reductions(void)
{
    return reductions;
}

void comm_traffic_read(struct comm_traffic *t)
{
    *t = traffic;
}

void comm_traffic_reset(void)
{
    memset(&traffic, 0, sizeof traffic);
}

double comm_clock(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void comm_waits_read(struct comm_waits *w)
{
    *w = waits;
}

void comm_waits_add_fft(double seconds)
{
    waits.fft += seconds;
}

void comm_traffic_fft(void)
{
    if (active && world_size > 1)
        traffic.fft_executions++;
}

void comm_barrier(void)
{
    if (active && world_size > 1)
        mpi.MPI_Barrier(mpi.comm_world);
}

/* ---- the Cartesian communicator --------------------------------------------------- */

int comm_cart_dims(const int dims[3], const int splittable[3], int out[3], char *err,
                   size_t errlen)
{
    long given = 1;
    for (int d = 0; d < 3; d++) {
        out[d] = !splittable[d] ? 1 : dims[d] > 0 ? dims[d] : 0;
        if (out[d] > 0)
            given *= out[d];
    }
    if (world_size == 1 || !active) {
        if (given != 1) {
            snprintf(err, errlen, "decomposition: %ld ranks asked, the run has 1", given);
            return -1;
        }
        out[0] = out[1] = out[2] = 1;
        return 0;
    }
    /* every direction fixed: MPI_Dims_create aborts the job unless they
     * multiply to the ranks */
    const int free_dims = (out[0] == 0) + (out[1] == 0) + (out[2] == 0);
    if (world_size % given != 0 || (free_dims == 0 && given != world_size) ||
        mpi.MPI_Dims_create(world_size, 3, out) != MPI_SUCCESS) {
        snprintf(err, errlen, "decomposition: %d ranks cannot be split as asked (%d x %d x %d)",
                 world_size, dims[0], dims[1], dims[2]);
        return -1;
    }
    return 0;
}

int comm_cart_create(struct comm_cart *c, const int dims[3], const int periodic[3],
                     const int splittable[3], char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->size = world_size;
    int d3[3], per[3];
    for (int d = 0; d < 3; d++) {
        per[d] = periodic[d] != 0;
        c->periodic[d] = per[d];
        c->nbr[d][0] = c->nbr[d][1] = -1;
        c->dims[d] = 1;
    }
    if (comm_cart_dims(dims, splittable, d3, err, errlen) != 0)
        return -1;
    if (world_size == 1 || !active)
        return 0;
    MPI_Comm cart;
    if (mpi.MPI_Cart_create(mpi.comm_world, 3, d3, per, 0, &cart) != MPI_SUCCESS) {
        snprintf(err, errlen, "decomposition: MPI_Cart_create failed");
        return -1;
    }
    c->comm = (void *)cart;
    mpi.MPI_Comm_rank(cart, &c->rank);
    mpi.MPI_Cart_coords(cart, c->rank, 3, c->coords);
    for (int d = 0; d < 3; d++) {
        c->dims[d] = d3[d];
        if (d3[d] > 1) {
            mpi.MPI_Cart_shift(cart, d, 1, &c->nbr[d][0], &c->nbr[d][1]);
            for (int s = 0; s < 2; s++)
                if (c->nbr[d][s] == MPI_PROC_NULL)
                    c->nbr[d][s] = -1;
        }
    }
    return 0;
}

void comm_cart_free(struct comm_cart *c)
{
    if (c->comm) {
        MPI_Comm cart = (MPI_Comm)c->comm;
        mpi.MPI_Comm_free(&cart);
    }
    c->comm = NULL;
}

void comm_cart_shift(const struct comm_cart *c, int d, const double *to_lo, double *from_lo,
                     const double *to_hi, double *from_hi, int count)
{
    if (!c->comm)
        return;
    MPI_Comm cart = (MPI_Comm)c->comm;
    const int lo = c->nbr[d][0], hi = c->nbr[d][1];
    /* both ways at once: my top plane up (tag 2d), my bottom plane down (2d + 1);
     * with two ranks along a periodic d both neighbours are the same rank,
     * and the tags keep the planes apart */
    const double t0 = comm_clock();
    MPI_Request req[4];
    int nreq = 0;
    if (lo >= 0)
        mpi.MPI_Irecv(from_lo, count, mpi.type_double, lo, 2 * d, cart, &req[nreq++]);
    if (hi >= 0)
        mpi.MPI_Irecv(from_hi, count, mpi.type_double, hi, 2 * d + 1, cart, &req[nreq++]);
    if (hi >= 0)
        mpi.MPI_Isend(to_hi, count, mpi.type_double, hi, 2 * d, cart, &req[nreq++]);
    if (lo >= 0)
        mpi.MPI_Isend(to_lo, count, mpi.type_double, lo, 2 * d + 1, cart, &req[nreq++]);
    mpi.MPI_Waitall(nreq, req, MPI_STATUSES_IGNORE);
    waits.shifts += comm_clock() - t0;
}

void comm_cart_allgather(const struct comm_cart *c, const double *mine, int count, double *all,
                         const int *counts, const int *displs)
{
    if (!c->comm) {
        memcpy(all + displs[0], mine, (size_t)count * sizeof(double));
        return;
    }
    mpi.MPI_Allgatherv(mine, count, mpi.type_double, all, counts, displs, mpi.type_double,
                       (MPI_Comm)c->comm);
}

void comm_cart_alltoall(const struct comm_cart *c, const double *send, const int *send_counts,
                        const int *send_displs, double *recv, const int *recv_counts,
                        const int *recv_displs)
{
    if (!c->comm) {
        memcpy(recv + recv_displs[0], send + send_displs[0],
               (size_t)send_counts[0] * sizeof(double));
        return;
    }
    traffic.alltoalls++;
    for (int r = 0; r < c->size; r++)
        if (r != c->rank && send_counts[r] > 0) {
            traffic.alltoall_messages++;
            traffic.alltoall_bytes += (long)send_counts[r] * (long)sizeof(double);
        }
    const double t0 = comm_clock();
    mpi.MPI_Alltoallv(send, send_counts, send_displs, mpi.type_double, recv, recv_counts,
                      recv_displs, mpi.type_double, (MPI_Comm)c->comm);
    waits.alltoalls += comm_clock() - t0;
}
