/* The march of a scene that keeps a record of its steps (the collapse, the
 * slope release, bagnold2's growth, ...): each step taken into the record,
 * until the end, or until the grains come to rest; and the top's pressure
 * gauge of the scenes of grains under a light phase. */
#ifndef MUFLOW_SCENES_RECORDED_DRIVE_H
#define MUFLOW_SCENES_RECORDED_DRIVE_H

#include "scenes/scene.h"

struct recorded_drive {
    /* takes the step into the scene's record: 0, or -1 when out of memory
     * (the run then stops, saying so) */
    int (*record_step)(void *rec, const struct march_state *st);
    /* NULL: no rest; else the last step's kinetic energy, its peak over the
     * run and the peak's time (NaN: not told) */
    void (*energy)(const void *rec, double *kinetic, double *peak, double *peak_time);
    void *rec;
    double rest_fraction;    /* at rest below this share of the peak; 0: never */
    const char *record_name; /* for the message: "the collapse's record" */
    int at_rest;             /* out: the run ended at rest */
};

/* The march of d until its end, its observer's stop or rest: the status
 * `finished` with the rest's message at rest, `stopped` with the cause when
 * the record ran out of memory. */
void recorded_drive_run(struct scene_drive *d, struct recorded_drive *rd);

/* The dynamic pressure's mean over the top layer of cells set to 0: the
 * pressure at the top is the hydrostatic one, 0 on the face (the light
 * phase's weight over half a cell in the top cells), plus the scene's gauge
 * in the pressure the rheology reads.  Over ranks: the top blocks' layer,
 * summed over the ranks (collective). */
void recorded_drive_gauge_top(struct march_state *st);

#endif
