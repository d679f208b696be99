/* A face density other than the case's, and the projection's coefficient
 * that follows from it (march.h: march_density_changed). */
#include <stdio.h>
#include "march/march.h"
#include "march/step.h"

/* The projection's coefficient; none without a projection (a stretched
 * grid's coupled steps solve the pressure with the velocity). */
static int projection_coefficient(struct march_state *st, double *const beta[3], char *err,
                                  size_t errlen)
{
    return st->pressure_solver ? pressure_set_coefficient(st->pressure_solver, beta, err, errlen)
                               : 0;
}

/* With an embedded body the projection's coefficient is the cut cells'
 * flux form: beta = 0 on the held faces (the velocity correction
 * -beta grad phi leaves them at 0), and the pressure operator
 * div_a(beta grad phi) takes a_f beta with the faces' open shares a_f (the
 * multigrid path: the FFT solver takes a uniform coefficient only). */
static int set_cut_coefficient(struct march_state *st, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    const struct embedded *e = st->embedded;
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++)
            st->beta[c][e->held[c][i]] = 0.0;
    double *coef[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    int rc = -1;
    if (coef[0] && coef[1] && coef[2]) {
        for (int c = 0; c < 3; c++)
            for (size_t p = 0; p < g->size; p++)
                coef[c][p] = st->beta[c][p] * e->share[c][p];
        rc = projection_coefficient(st, coef, err, errlen);
    } else {
        snprintf(err, errlen, "out of memory for the cut cells' projection coefficient");
    }
    for (int c = 0; c < 3; c++)
        field_free(coef[c]);
    return rc;
}

int march_density_changed(struct march_state *st, int uniform, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    /* a body closes faces: the coefficient is never uniform then */
    uniform = uniform && !st->embedded;
    st->density_uniform = uniform;
    hydrostatic_force(st); /* gravity acts on the density of now */
    if (uniform)
        return projection_coefficient(st, NULL, err, errlen);
    if (!st->beta[0]) {
        const struct field_spec sb = {"projection_coefficient", FIELD_FACES, 0},
                                sm = {"mass_faces", FIELD_FACES, 0};
        if (fields_add(&st->fields, &sb, st->beta) < 0 ||
            fields_add(&st->fields, &sm, st->mass_face) < 0) {
            snprintf(err, errlen, "out of memory for the variable density");
            return -1;
        }
    }
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < g->size; p++)
            st->beta[c][p] = st->field.density_faces[c][p] > 0.0
                                 ? st->rho_ref / st->field.density_faces[c][p]
                                 : 0.0;
    if (st->embedded)
        return set_cut_coefficient(st, err, errlen);
    return projection_coefficient(st, st->beta, err, errlen);
}
