/* The velocity multigrid's internals, shared by src/solvers/velocity_mg*.c
 * only (the interface is velocity_mg.h; docs/numerics/velocity-multigrid.md). */
#ifndef MUFLOW_SOLVERS_VELOCITY_MG_INTERNAL_H
#define MUFLOW_SOLVERS_VELOCITY_MG_INTERNAL_H

#include "grid/decomp.h"
#include "kernels/embedded.h"
#include "kernels/patch_smoother.h"
#include "kernels/viscous_stencil.h"
#include "solvers/sparse_direct.h"
#include "solvers/velocity_mg.h"
#include "solvers/viscous_operator.h"

#define MAX_LEVELS 24
/* A decomposed hierarchy keeps a level on the ranks while the global level
 * above it has more cells than this, the pressure multigrid's threshold
 * (multigrid_internal.h: MG_GATHER_CELLS); the last kept is gathered. */
#define GATHER_CELLS 4096

struct mg_level {
    struct grid g;
    struct boundary bc;          /* the case's conditions, dc this level's blocks */
    struct decomp dc;            /* this level's blocks (decomposed hierarchy) */
    int split;                   /* some side of this rank's block is a rank border */
    int f[3];                    /* halved from the finer level along d: 2, else 1 */
    int periodic[3];
    struct box act[3];
    int lines[3], nlines;        /* the line directions: bounded, two cells or more */
    /* coefficients this level owns (the finest reads the caller's) */
    double *A_cell[3], *A_edge[3], *mass_face[3], *aug;
    struct viscous_problem pb;   /* the symmetric operator of this level */
    /* a body's held nodes: the caller's on the finest level, else carried down */
    struct embedded emb;
    unsigned char *held[3];      /* 1 at a held node (NULL: no body) */
    struct viscous_work work;
    struct own_stencil st[3];
    double *x[3], *b[3], *r[3], *d[3];
    struct line_factors lf[3][3]; /* per component, per line direction */
    double *pw[3][3];            /* the prolongation's weights to the next coarser level,
                                    per component and direction (kernel_prolong_weights) */
    struct sparse_direct *direct; /* the coarsest level's factorisation */
    /* the edge patches' factors per plane normal (kernels/patch_smoother.h),
     * with the augmentation; NULL: the plane carries none */
    double *patch[3];
    int patch_on;
};

/* The gathered level of a decomposed hierarchy: the global grid of the last
 * level kept on the ranks, its coefficients, right-hand side and solution
 * gathered on every rank, and the serial hierarchy that cycles it. */
struct gathered {
    struct grid gg;
    struct boundary bc;          /* the case's, no decomposition */
    double *A_cell[3], *A_edge[3], *mass_face[3];
    double *aug;                 /* the grad-div augmentation's (NULL: none yet) */
    double *b[3], *x[3];
    double *scratch;             /* decomp_gather's */
    struct embedded emb;         /* a body's held nodes on the whole level (no cut cells) */
    struct velocity_mg *serial;
};

struct velocity_mg {
    const struct boundary *bc;
    struct velocity_mg_options opt;
    struct gathered *gath;       /* NULL: one process holds the grid */
    double *edge0[3];            /* decomposed: the finest edges, ghosts exchanged */
    int nlevels;
    struct mg_level lv[MAX_LEVELS];
    int nthreads;
    int has_body;
    /* the components this cycle leaves out (bit c): a component along a
     * periodic direction of one cell is coupled to no other (every
     * derivative along it vanishes), and when its part of the right-hand
     * side is 0 so is its solution (a flow in a plane: the component across) */
    int skip;
};

static inline size_t vmg_box_size(const struct box *b)
{
    size_t s = 1;
    for (int d = 0; d < 3; d++)
        s *= (size_t)(b->hi[d] > b->lo[d] ? b->hi[d] - b->lo[d] : 0);
    return s;
}

/* The ghosts of a level's field across its rank borders, every direction
 * (nothing on one process). */
static inline void vmg_exchange_ghosts(const struct mg_level *lv, double *f)
{
    for (int d = 0; lv->split && d < 3; d++)
        if (bc_split(&lv->bc, d))
            decomp_exchange(&lv->dc, &lv->g, f, d);
}

/* Level l's held masks and, below the finest, its held lists, from level
 * l - 1's (the finest: the body's e); on ranks the ghosts' too.  Returns 0,
 * or -1 when out of memory (velocity_mg_body.c). */
int vmg_carry_body(struct velocity_mg *m, int l, const struct embedded *e);

/* The gathered level's held list from the last decomposed level lv's
 * masks.  Returns 0, or -1 when out of memory (velocity_mg_body.c). */
int vmg_gathered_body(struct velocity_mg *m, const struct mg_level *lv);

#endif
