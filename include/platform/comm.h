/* The processes of a run: one, or the ranks of an MPI job.
 *
 * A program started without mpirun is a world of one rank and MPI is never
 * touched (no library loaded, nothing initialised: the serial start-up is
 * unchanged).  Started by Open MPI's mpirun (OMPI_COMM_WORLD_SIZE in the
 * environment), comm_init opens libmpi with dlopen, as hypre and SuiteSparse
 * are opened (docs/numerics/threads-and-platform.md), and initialises it
 * with MPI_THREAD_FUNNELED: only the thread that called comm_init (the
 * master of any OpenMP team) calls MPI.  Everything here is collective over
 * the world unless said otherwise; with one rank every call is the identity. */
#ifndef MUFLOW_PLATFORM_COMM_H
#define MUFLOW_PLATFORM_COMM_H

#include <stddef.h>

/* 0, or -1 with the cause (libmpi missing, MPI_Init failing).  Idempotent;
 * registers comm_finalize at exit when it initialised MPI. */
int comm_init(char *err, size_t errlen);
/* 1 when started by mpirun (whatever the rank count), from the environment
 * alone: callable before comm_init. */
int comm_launched(void);
/* For a library of MPI's (what names it in the message): 0 once libmpi is
 * open in the global scope and MPI initialised; -1 with the cause when not
 * under mpirun or comm_init fails. */
int comm_require(const char *what, char *err, size_t errlen);
int comm_rank(void);
int comm_size(void);
/* MPI_Finalize once (nothing without MPI). */
void comm_finalize(void);
/* Every rank ends here with the status: the message (printed by rank 0
 * only when all ranks call it, by the caller otherwise: pass all = 1 when
 * every rank reaches the call).  With all = 0 MPI_Abort ends the job. */
_Noreturn void comm_exit(int status, int all, const char *msg);

/* Sums and maxima over every rank, in place (n values), the same on every
 * rank; the order of the sum is MPI's, fixed for a given rank count. */
void comm_sum(double *v, int n);
void comm_sum_long(long *v, int n);
void comm_max(double *v, int n);
void comm_barrier(void);
/* The sums and maxima over several ranks done so far (MPI_Allreduce calls:
 * none on one rank). */
long comm_reductions(void);

/* What this process's collectives sent since comm_traffic_reset (or the
 * start), over several ranks only: the sums and maxima (MPI_Allreduce
 * calls) and their values; the all-to-alls, their messages (the other
 * ranks sent a piece) and bytes (those pieces); and the executions of
 * FFTW's MPI plans (fft_ranks_execute), whose own transposes the caller
 * models.  One process-wide tally: the thread that calls MPI writes it. */
struct comm_traffic {
    long reductions, reduced_values;
    long alltoalls, alltoall_messages, alltoall_bytes;
    long fft_executions;
};
void comm_traffic_read(struct comm_traffic *t);
void comm_traffic_reset(void);
/* Wall seconds this process spent in MPI's calls since the start, over
 * several ranks only: halo shifts (comm_cart_shift, the Waitall with its
 * sends), sums and maxima, all-to-alls, and FFTW's MPI executions (their
 * transforms and transposes, fft_ranks_execute); for the benchmarks'
 * shares of a step spent waiting. */
struct comm_waits {
    double shifts, reductions, alltoalls, fft;
};
void comm_waits_read(struct comm_waits *w);
double comm_clock(void); /* seconds of a monotonic clock */
void comm_waits_add_fft(double seconds);
/* One FFTW MPI plan executed (fft_ranks_execute's count). */
void comm_traffic_fft(void);

/* The Cartesian communicator over every rank: dims[d] ranks along d,
 * periodic along d when periodic[d], this rank's coords and its neighbours
 * (nbr[d][0] below, nbr[d][1] above; -1 beyond a non-periodic end, and along
 * a direction of one rank, whose periodic wrap is the rank's own affair). */
struct comm_cart {
    void *comm; /* the MPI_Comm (NULL without MPI) */
    int dims[3], coords[3], periodic[3];
    int rank, size;
    int nbr[3][2];
};

/* The ranks along each direction a Cartesian communicator of the run's
 * ranks would take (dims[d] > 0 fixed, 0 free, splittable[d] 0: 1), as
 * comm_cart_create chooses them, without creating it.  Returns 0, or -1
 * with a message. */
int comm_cart_dims(const int dims[3], const int splittable[3], int out[3], char *err,
                   size_t errlen);
/* dims[d] given (> 0) or 0 for MPI_Dims_create's choice, fixed to 1 along a
 * direction with splittable[d] = 0.  Returns 0, or -1 with a message. */
int comm_cart_create(struct comm_cart *c, const int dims[3], const int periodic[3],
                     const int splittable[3], char *err, size_t errlen);
void comm_cart_free(struct comm_cart *c);

/* Along d: sends count doubles to each neighbour (to_lo to nbr[d][0], to_hi
 * to nbr[d][1]) and receives theirs (from_lo from below, from_hi from
 * above); a side without a neighbour sends and receives nothing. */
void comm_cart_shift(const struct comm_cart *c, int d, const double *to_lo, double *from_lo,
                     const double *to_hi, double *from_hi, int count);
/* Every rank's count doubles (counts[r] from rank r) into all, rank after
 * rank (displs[r] its first). */
void comm_cart_allgather(const struct comm_cart *c, const double *mine, int count, double *all,
                         const int *counts, const int *displs);

/* Every rank's send_counts[r] doubles from send + send_displs[r] to rank r,
 * and rank r's recv_counts[r] doubles into recv + recv_displs[r]. */
void comm_cart_alltoall(const struct comm_cart *c, const double *send, const int *send_counts,
                        const int *send_displs, double *recv, const int *recv_counts,
                        const int *recv_displs);
#endif
