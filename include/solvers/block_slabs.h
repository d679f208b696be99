/* The blocks <-> slabs all-to-all of FFTW's MPI transforms (platform/
 * fft_ranks.h): a global array of n[0] x n[1] x n[2] values (n[2] fastest)
 * held by the ranks as boxes (any split of the three directions), moved to
 * slabs of whole n[1] x n[2] planes along n[0] (FFTW's input) in one
 * all-to-all, and back.  Each box's range along n[0] meets a run of slabs
 * in rank order, so a box packed n[0] slowest sends one contiguous piece to
 * each rank.  The slab's rows may be padded (the in-place real transform's
 * 2 (n/2 + 1)): its element (a, b, c) sits at ((a - a0) rows + b) n[2] + c.
 * The pressure's FFT and the plane Fourier line blocks share it. */
#ifndef MUFLOW_SOLVERS_BLOCK_SLABS_H
#define MUFLOW_SOLVERS_BLOCK_SLABS_H
#include "platform/comm.h"

struct block_slabs {
    const struct comm_cart *cart; /* not owned */
    int ranks;
    int n2;                       /* the slab's values per (a, b): n[2] */
    long rows;                    /* the slab's b rows per a (n[1] or padded) */
    long a0;                      /* the slab's first a */
    double *pieces;               /* the received pieces, rank after rank */
    /* per rank: sends and displacements, receives and displacements, and
     * each received piece's b0, b count, a0, c0 and c count */
    int *counts;
};

/* This rank's box lo[d] .. lo[d] + n[d] - 1 of the global sizes n_global,
 * its slab a0 .. a0 + na - 1 of rows rows.  Returns 0, or -1 when out of
 * memory (on this rank: the caller makes it every rank's).  Collective. */
int block_slabs_init(struct block_slabs *x, const struct comm_cart *cart, const int lo[3],
                     const int n[3], const int n_global[3], long a0, long na, long rows);
void block_slabs_free(struct block_slabs *x);

/* The box (packed n[0] slowest, n[2] fastest) into the slab, and back (the
 * slab left as it was).  Collective. */
void block_slabs_to_slab(struct block_slabs *x, const double *box, double *slab);
void block_slabs_to_boxes(struct block_slabs *x, double *slab, double *box);
#endif
