/* A body in the velocity multigrid (velocity_mg_internal.h): its held
 * nodes carried down the levels, across rank borders and to the gathered
 * level of a decomposed hierarchy. */
#include "solvers/velocity_mg_internal.h"
#include "kernels/kernels.h"
#include "kernels/mac_transfer.h"

#include <stdlib.h>
#include <string.h>

/* The held masks and coarse held lists of level l (from level l - 1's). */
int vmg_carry_body(struct velocity_mg *m, int l, const struct embedded *e)
{
    struct mg_level *lv = &m->lv[l];
    const struct grid *g = &lv->g;
    if (l == 0) {
        for (int c = 0; c < 3; c++) {
            if (!lv->held[c] && !(lv->held[c] = calloc(g->size, 1)))
                return -1;
            memset(lv->held[c], 0, g->size);
            for (long i = 0; i < e->nheld[c]; i++)
                lv->held[c][e->held[c][i]] = 1;
        }
        return 0;
    }
    const struct mg_level *fl = &m->lv[l - 1];
    double *coarse = lv->d[1]; /* work: this level's d is free here */
    double *fmask = malloc(fl->g.size * sizeof(double));
    if (!fmask)
        return -1;
    int ok = 1;
    for (int c = 0; c < 3 && ok; c++) {
        for (size_t p = 0; p < fl->g.size; p++)
            fmask[p] = fl->held[c][p];
        kernel_coarsen_faces(&fl->g, g, lv->f, c, fmask, coarse);
        if (!lv->held[c] && !(lv->held[c] = calloc(g->size, 1))) {
            ok = 0;
            break;
        }
        memset(lv->held[c], 0, g->size);
        long n = 0;
        const struct box *b = &lv->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    coarse[p] = coarse[p] >= 0.5;
                    lv->held[c][p] = (unsigned char)coarse[p];
                    n += lv->held[c][p];
                }
        if (lv->split) { /* the neighbours' held nodes in the ghosts, read as 0 */
            for (size_t p = 0; p < g->size; p++)
                coarse[p] = lv->held[c][p];
            vmg_exchange_ghosts(lv, coarse);
            for (size_t p = 0; p < g->size; p++)
                if (!lv->held[c][p] && coarse[p] != 0.0) {
                    lv->held[c][p] = 1;
                    n++;
                }
        }
        free(lv->emb.held[c]);
        free(lv->emb.saved[c]);
        lv->emb.held[c] = malloc((size_t)(n > 0 ? n : 1) * sizeof(ptrdiff_t));
        lv->emb.saved[c] = malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
        if (!lv->emb.held[c] || !lv->emb.saved[c]) {
            ok = 0;
            break;
        }
        lv->emb.nheld[c] = 0;
        for (size_t p = 0; p < g->size; p++)
            if (lv->held[c][p])
                lv->emb.held[c][lv->emb.nheld[c]++] = (ptrdiff_t)p;
        memset(coarse, 0, g->size * sizeof(double));
    }
    free(fmask);
    return ok ? 0 : -1;
}

/* The gathered level's held nodes: the last decomposed level's (lv), every
 * rank's gathered, listed on the whole level (a staircase, as every level
 * below the finest).  Returns 0, or -1 when out of memory. */
int vmg_gathered_body(struct velocity_mg *m, const struct mg_level *lv)
{
    struct gathered *gt = m->gath;
    const struct grid *gg = &gt->gg;
    double *mask = lv->r[0], *whole = gt->x[0]; /* free between cycles */
    struct box act[3];
    bc_unknown_boxes(gg, &gt->bc, act);
    for (int c = 0; c < 3; c++) {
        for (size_t p = 0; p < lv->g.size; p++)
            mask[p] = lv->held[c][p];
        decomp_gather(&lv->dc, &lv->g, mask, gg, whole, gt->scratch);
        free(gt->emb.held[c]);
        free(gt->emb.saved[c]);
        long n = 0;
        const struct box *b = &act[c];
        gt->emb.held[c] = malloc((size_t)vmg_box_size(b) * sizeof(ptrdiff_t) + sizeof(ptrdiff_t));
        gt->emb.saved[c] = malloc((size_t)vmg_box_size(b) * sizeof(double) + sizeof(double));
        if (!gt->emb.held[c] || !gt->emb.saved[c])
            return -1;
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++)
                    if (whole[grid_idx(gg, i, j, k)] != 0.0)
                        gt->emb.held[c][n++] = grid_idx(gg, i, j, k);
        gt->emb.nheld[c] = n;
    }
    memset(mask, 0, lv->g.size * sizeof(double));
    memset(whole, 0, gg->size * sizeof(double));
    return 0;
}
