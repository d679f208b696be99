/* A depth-averaged reference model of a shallow granular layer along a slope
 * (one dimension, x down the slope): the equations of Gray & Edwards (2014),
 * "A depth-averaged mu(I)-rheology for shallow granular free-surface flows",
 *
 *   h_t + (h u)_x = 0
 *   (h u)_t + (chi h u^2 + K g cos(zeta) h^2 / 2)_x
 *       = (h^2 / 2) (K g cos(zeta))_x + g h sin(zeta)
 *         - mu_b(h, u) g cos(zeta) h sgn(u) + (nu h^{3/2} u_x)_x
 *
 * with a Coulomb (mu_b = tan delta) or Pouliquen (mu_b = mu1 + (mu2 - mu1) /
 * (1 + beta h / (L Fr)), Fr = |u| / sqrt(g cos(zeta) h)) basal friction, on a
 * bed whose slope zeta(x) is given per cell.  Finite volumes: MUSCL edges of h
 * and u, an HLL or Rusanov flux, two-stage SSP Runge-Kutta, the friction as a
 * projection that stops a cell exactly; faces between two cells that friction
 * holds at rest pass no mass, and nothing flows out of a holding cell into a
 * moving one (docs/numerics/depth-averaged.md).  No I/O; the arrays the
 * solver needs come with da_create and go with da_free. */
#ifndef MUFLOW_DIAGNOSTICS_DEPTH_AVERAGED_H
#define MUFLOW_DIAGNOSTICS_DEPTH_AVERAGED_H

enum da_friction_law {
    DA_COULOMB,   /* mu_b = mu */
    DA_POULIQUEN, /* mu_b(h, Fr) of Pouliquen & Forterre (2002), Gray & Edwards (2014) */
};

enum da_flux { DA_FLUX_HLL, DA_FLUX_RUSANOV };

enum da_limiter {
    DA_LIMITER_MC,     /* monotonised central: second order */
    DA_LIMITER_MINMOD, /* second order, more diffusive */
    DA_LIMITER_NONE,   /* piecewise constant: first order */
};

struct da_params {
    double g;   /* gravity */
    double K;   /* earth-pressure coefficient (1) */
    double chi; /* shape factor of the momentum flux: 1 (plug), 5/4 (Bagnold) */
    enum da_friction_law law;
    double mu;                /* DA_COULOMB: tan(delta) */
    double mu1, mu2, beta, L; /* DA_POULIQUEN: tan(zeta_1), tan(zeta_2), beta, L */
    double nu;                /* coefficient of (nu h^{3/2} u_x)_x; 0: none */
    enum da_flux flux;
    enum da_limiter limiter;
    double cfl;   /* Courant number of da_max_dt, <= 1/2 for positivity */
    double h_dry; /* depths at or below it carry no velocity */
};

/* A struct da_params with g = 1, K = 1, chi = 1, Coulomb mu = 0, no
 * viscosity, HLL, MC, cfl = 0.45, h_dry = 1e-12. */
struct da_params da_params_default(void);

enum da_bc_kind {
    DA_BC_OPEN,  /* zero gradient of h and u */
    DA_BC_WALL,  /* impermeable: the mirror state */
    DA_BC_GIVEN, /* h and u of the ghost cells from a function of x and t */
};

typedef void (*da_ghost_fn)(void *ctx, double x, double t, double *h, double *u);

struct da_bc {
    enum da_bc_kind kind;
    da_ghost_fn ghost; /* DA_BC_GIVEN */
    void *ctx;
};

struct da_solver;

/* n cells of width dx from x0; zeta: the bed's slope angle (radians) at each
 * cell centre, n values (copied).  NULL when a parameter is out of range or
 * memory runs out; err (if not NULL, err_len > 0) then says which. */
struct da_solver *da_create(long n, double x0, double dx, const double *zeta,
                            const struct da_params *p, struct da_bc left, struct da_bc right,
                            char *err, int err_len);
void da_free(struct da_solver *s);

/* The stable time step of the state (h, m = h u): cfl dx over the fastest
 * wave (edge states included), bounded by the viscous term's limit; INFINITY
 * for a state with nothing to move. */
double da_max_dt(const struct da_solver *s, const double *h, const double *m);

/* One SSP-RK2 step of dt from time t, in place.  Returns 0, or -1 when the
 * state is not finite (then h and m hold what the step made of it). */
int da_step(struct da_solver *s, double *h, double *m, double t, double dt);

/* Steps from t0 to t1 (the last step shortened to land on t1) at da_max_dt.
 * Returns the number of steps, or -1 as da_step. */
long da_advance(struct da_solver *s, double *h, double *m, double t0, double t1);

/* The basal friction coefficient at depth h and speed |u| on a bed of
 * cos(zeta) = cos_zeta: mu, or Pouliquen's mu1 at rest rising to mu2. */
double da_basal_friction(const struct da_params *p, double cos_zeta, double h, double speed);

/* Gray & Edwards' (2014) depth-averaged viscosity of their Pouliquen law on a
 * uniform slope zeta: nu = (2/9) (L sqrt(g) / beta) (sin zeta / sqrt(cos
 * zeta)) (mu2 - tan zeta) / (tan zeta - mu1); NaN outside mu1 < tan zeta <
 * mu2. */
double da_gray_edwards_nu(const struct da_params *p, double zeta);

#endif
