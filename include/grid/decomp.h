/* A box decomposition of the grid over the ranks of a Cartesian
 * communicator (platform/comm.h); docs/numerics/decomposition.md.
 *
 * The global grid of n_global cells per direction is cut into dims[d]
 * blocks along d, as even as can be (the first n % dims blocks one cell
 * more); a rank holds its block as an ordinary struct grid of its local n
 * with one ghost layer (grid.h), so kernels and solvers loop over local
 * boxes as before.  lo[d] is the global index of local cell 0.
 *
 * Faces: a rank owns the faces 0 .. n - 1 of direction d (the low faces of
 * its cells); the face n on a rank border is the low face of the next
 * rank's cell 0, held in the high ghost slot and filled by the exchange,
 * exactly as a periodic direction's face n is face 0's image.  At the
 * domain's high end (not periodic) face n is the last rank's own.  So a
 * face array of normal d exchanges along d like a cell array: the ghost
 * slot n takes the neighbour's slot 0, the ghost -1 its slot n - 1.
 *
 * border[d][s]: side s of direction d is a rank border (ghosts from the
 * exchange); otherwise the domain's boundary, or a periodic direction held
 * by one rank (its wrap is local, as without decomposition).  A compact
 * direction (grid.h) is never split. */
#ifndef MUFLOW_GRID_DECOMP_H
#define MUFLOW_GRID_DECOMP_H

#include "grid/grid.h"
#include "platform/comm.h"

#define DECOMP_MAX_SPLIT 64 /* ranks along one direction */

struct decomp {
    const struct comm_cart *cart; /* not owned */
    int n_global[3];
    int lo[3], n[3];              /* this rank's block */
    /* block c along d: global cells start[d][c] .. start[d][c + 1] - 1 */
    int start[3][DECOMP_MAX_SPLIT + 1];
    int border[3][2];
    double *buf;                  /* exchange planes (shared by coarsened copies) */
    size_t buflen;                /* doubles */
    int owns_buf;
};

/* The block of this rank.  Returns 0, or -1 with a message (a direction
 * split into more blocks than cells, too many ranks along one). */
int decomp_create(struct decomp *dc, const struct comm_cart *cart, const int n_global[3],
                  char *err, size_t errlen);
void decomp_free(struct decomp *dc);

/* The decomposition of the grid halved along the directions halve[d]: each
 * block halved in place, so that a coarse cell's children are on its rank.
 * Returns 0, or -1 (nothing set) when some block along a halved direction
 * starts at an odd cell or holds an odd count.  coarse shares fine's buffer. */
int decomp_coarsen(const struct decomp *fine, const int halve[3], struct decomp *coarse);

/* v summed (maximised) over the ranks of dc; v itself when dc is NULL (one
 * process holds the grid).  Collective. */
double decomp_sum(const struct decomp *dc, double v);
double decomp_max(const struct decomp *dc, double v);
/* The n values of v summed over the ranks of dc, in place (nothing when dc
 * is NULL). */
void decomp_sum_array(const struct decomp *dc, double *v, int n);
/* The n values of v maximised over the ranks of dc, in place (nothing when
 * dc is NULL); no NaN among them (MPI's maximum of a NaN is undefined). */
void decomp_max_array(const struct decomp *dc, double *v, int n);

/* 1 when some side is a rank border. */
int decomp_split(const struct decomp *dc);

/* The local grid of a global grid gg (uniform): dc's n cells, gg's spacing
 * to the bit.  Returns 0, or -1 as grid_init. */
int decomp_local_grid(const struct decomp *dc, const struct grid *gg, struct grid *g);

/* The ghost slots along d of field f (local grid g) from the neighbours
 * across the rank borders, over every slot of the other two directions
 * (ghosts included: a fill direction after direction, each after the
 * boundary fills of those before, gets edges and corners right).  Only the
 * thread that initialised MPI calls it. */
void decomp_exchange(const struct decomp *dc, const struct grid *g, double *f, int d);

/* The transpose of decomp_exchange along d: the ghost slots of f across
 * the rank borders added to the neighbours' slots they image (ghost -1 to
 * the low neighbour's n - 1, ghost n to the high one's 0), then zeroed.  A
 * sum scattered into ghosts (a restriction's) lands on its owners; direction
 * after direction, the corners' too.  Only the thread that initialised MPI
 * calls it. */
void decomp_exchange_add(const struct decomp *dc, const struct grid *g, double *f, int d);

/* What this rank sent since decomp_traffic_reset (or the start): the
 * exchanges that crossed a rank border, their messages (one per border
 * side) and bytes (the ghost-extended plane, (n_e1 + 2)(n_e2 + 2) doubles),
 * the gathers and their bytes (this rank's block sent, the other ranks'
 * received).  Counted past the early return of a rank without borders:
 * nothing counted, nothing spent, without mpirun.  One process-wide tally
 * (the thread that calls MPI is the only writer). */
struct decomp_traffic {
    long exchanges, messages, bytes;
    long gathers, gather_sent, gather_received;
};
void decomp_traffic_read(struct decomp_traffic *t);
/* Resets this tally and the collectives' (comm_traffic_reset). */
void decomp_traffic_reset(void);
/* The collectives' tally (platform/comm.h: comm_traffic_read), for the
 * layers above the grid's. */
void decomp_collectives_read(struct comm_traffic *t);

/* Every rank's block of f (local grid g), cells and the ghost slots on the
 * domain's boundary, into global (the global grid gg's layout), on every
 * rank; scratch holds the ranks' whole arrays (decomp_gather_len doubles). */
void decomp_gather(const struct decomp *dc, const struct grid *g, const double *f,
                   const struct grid *gg, double *global, double *scratch);
size_t decomp_gather_len(const struct decomp *dc);

/* The local slots of this rank's block in a global field (the inverse of
 * gather for the cells; ghosts left alone). */
void decomp_scatter(const struct decomp *dc, const struct grid *gg, const double *global,
                    const struct grid *g, double *f);

#endif
