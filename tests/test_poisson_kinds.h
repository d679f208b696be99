/* The condition pairs along one direction that the Poisson solvers' tests
 * (test_poisson.c, test_multigrid.c) combine, three at a time
 * (test_util.c). */
#ifndef MUFLOW_TEST_POISSON_KINDS_H
#define MUFLOW_TEST_POISSON_KINDS_H

#include "solvers/poisson.h"

enum kind { K_P = 0, K_NN, K_DD, K_ND, K_DN, NKIND };
extern const enum poisson_bc kind_bc[NKIND][2];
extern const char *const kind_name[NKIND];

/* The t-th of the NTRIPLES triples of kinds (x, y, z): z fastest. */
#define NTRIPLES (NKIND * NKIND * NKIND)
void kind_triple(int t, enum kind k[3]);

/* The conditions of the three directions' kinds. */
void make_bc(const enum kind k[3], enum poisson_bc bc[3][2]);

/* No Dirichlet face: the solution is defined up to a constant. */
int is_singular(const enum poisson_bc bc[3][2]);

#endif
