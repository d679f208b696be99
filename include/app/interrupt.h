/* SIGINT and SIGTERM during a run.  The handler only records the signal (the
 * one thing a handler may safely do); the run's observer polls it once per
 * step, so the run finishes the step it is in, writes a checkpoint and its
 * outputs, and ends with status "stopped".  The handler is installed with
 * SA_RESETHAND: a second signal while the run is winding down kills the
 * process the usual way. */
#ifndef MUFLOW_INTERRUPT_H
#define MUFLOW_INTERRUPT_H

/* Clears the record and installs the handler for SIGINT and SIGTERM, keeping
 * the previous dispositions; returns 0, or -1 (errno set). */
int interrupt_install(void);

/* Puts the previous dispositions back. */
void interrupt_restore(void);

/* The signal received since interrupt_install, or 0. */
int interrupt_signal(void);

/* "SIGINT", "SIGTERM", or "signal N". */
const char *interrupt_name(int sig);

#endif
