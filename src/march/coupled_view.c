/* The whole grid as the coupled step sees it: st's own on one process, the
 * gathered global grid over ranks (coupled_view.h). */
#include <stdlib.h>
#include <string.h>
#include "grid/decomp.h"
#include "march/coupled_view.h"
#include "march/march.h"
#include "solvers/viscous.h"

void coupled_view_destroy(struct coupled_view *v)
{
    if (!v)
        return;
    for (int k = 0; k < 3; k++) {
        field_free(v->own_share[k]);
        field_free(v->whole[k]);
        field_free(v->in[k]);
        field_free(v->out[k]);
    }
    free(v->scratch);
    free(v);
}

struct coupled_view *coupled_view_create(struct march_state *st)
{
    struct coupled_view *v = calloc(1, sizeof *v);
    if (!v)
        return NULL;
    v->st = st;
    bc_periodic_flags(&st->bc, v->periodic);
    if (!st->ranks) {
        v->g = &st->g;
        memcpy(v->act, st->act, sizeof v->act);
        for (int k = 0; k < 3; k++)
            v->share[k] = st->embedded ? st->embedded->share[k] : NULL;
        return v;
    }
    const struct decomp *dc = &st->ranks->dc;
    v->gathered = 1;
    v->g = &st->ranks->global;
    for (int d = 0; d < 3; d++)
        v->lo[d] = dc->lo[d];
    struct boundary whole_bc = st->bc; /* the domain's faces, no rank border */
    whole_bc.dc = NULL;
    bc_unknown_boxes(v->g, &whole_bc, v->act);
    if (!(v->scratch = malloc(decomp_gather_len(dc) * sizeof *v->scratch)))
        goto fail;
    for (int k = 0; k < 3; k++)
        if (!(v->whole[k] = field_alloc(v->g)) || !(v->in[k] = field_alloc(&st->g)) ||
            !(v->out[k] = field_alloc(&st->g)))
            goto fail;
    if (st->embedded)
        for (int k = 0; k < 3; k++) {
            if (!(v->own_share[k] = field_alloc(v->g)))
                goto fail;
            v->share[k] = coupled_view_whole(v, st->embedded->share[k], v->own_share[k]);
        }
    return v;
fail:
    coupled_view_destroy(v);
    return NULL;
}

const double *coupled_view_whole(struct coupled_view *v, const double *f, double *buf)
{
    if (!v->gathered)
        return f;
    decomp_gather(&v->st->ranks->dc, &v->st->g, f, v->g, buf, v->scratch);
    return buf;
}

void coupled_view_part(const struct coupled_view *v, const double *whole, double *f)
{
    if (v->gathered)
        decomp_scatter(&v->st->ranks->dc, v->g, whole, &v->st->g, f);
}

double *coupled_view_field(const struct coupled_view *v)
{
    return v->gathered ? field_alloc(v->g) : NULL;
}

ptrdiff_t coupled_view_slot(const struct coupled_view *v, ptrdiff_t p)
{
    if (!v->gathered)
        return p;
    int idx[3];
    grid_slot_index(&v->st->g, p, idx);
    return grid_idx(v->g, idx[0] + v->lo[0], idx[1] + v->lo[1], idx[2] + v->lo[2]);
}

/* The probe on st's block, the operator there, its response gathered:
 * every rank holds every column's response. */
static void gathered_apply(void *ctx, double *in[3], double *out[3])
{
    struct coupled_view *v = ctx;
    struct march_state *st = v->st;
    for (int k = 0; k < 3; k++) {
        memset(v->in[k], 0, st->g.size * sizeof(double));
        memset(v->out[k], 0, st->g.size * sizeof(double));
        coupled_view_part(v, in[k], v->in[k]);
    }
    viscous_operator_apply(&v->op, v->in, v->out);
    for (int k = 0; k < 3; k++)
        coupled_view_whole(v, v->out[k], out[k]);
}

void coupled_view_operator(struct coupled_view *v, const struct viscous_problem *pb,
                           operator_fn *op, void **ctx)
{
    v->op = (struct viscous_operator){v->st->viscous, pb};
    *op = v->gathered ? gathered_apply : viscous_operator_apply;
    *ctx = v->gathered ? (void *)v : (void *)&v->op;
}
