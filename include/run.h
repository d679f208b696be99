/* Runs one case from start to output: the pipeline
 * case -> march (grid, fields, solvers) -> time loop -> diagnostics -> output. */
#ifndef MUFLOW_RUN_H
#define MUFLOW_RUN_H

#include "case.h"
#include "output.h"

/* write_output: 0 runs in memory only (tests, benchmarks); 1 writes the output
 * folder and prints progress unless cs->quiet.  Returns 0 when the run took
 * place (whatever its status), -1 when it could not start or its output could
 * not be written (cause in err). */
int run_case(const struct muflow_case *cs, int write_output, struct run_result *res, char *err,
             size_t errlen);

/* Exit status of the command for a run's status. */
int run_exit_code(enum run_status s);

#endif
