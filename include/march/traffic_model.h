/* One step's traffic over the ranks by its model (docs/numerics/
 * decomposition.md), for the configuration of bagnold3d: a steady or
 * transient march of uniform density (the pressure's FFT over the ranks),
 * the Fourier line blocks' CG, Newton's symmetric tangent or Picard, the
 * grad-div augmentation or none, no module, body, open face or coupled
 * step.  A step is what march_run records in st->step_halo and
 * st->step_collectives: the advance (implicit stage, projection) and the
 * evaluation after it.  Its events are counted by the caller: the CG
 * iterations (each one operator apply and one of the blocks), the blocks'
 * set-ups (each probing the operator with every comb and pattern) and the
 * projection's solves. */
#ifndef MUFLOW_MARCH_TRAFFIC_MODEL_H
#define MUFLOW_MARCH_TRAFFIC_MODEL_H

#include "march/march.h"

struct step_events {
    long iterations, setups, pressure_solves;
};

/* What this rank sends in a step by the model: halo (decomp_traffic_read's
 * terms), the collectives (comm_traffic's: sums, all-to-alls and their
 * messages and bytes, FFTW's MPI executions) and the bytes and messages of
 * FFTW's own transposes (one global transpose an execution, FFTW's default
 * blocks), which no tally of muflow's sees. */
struct step_traffic {
    struct decomp_traffic halo;
    struct comm_traffic coll;
    long fft_messages, fft_bytes;
};

/* 0, or -1 when st is not a configuration the model covers (one process
 * among them). */
int march_step_traffic_model(const struct march_state *st, const struct step_events *ev,
                             struct step_traffic *m);

#endif
