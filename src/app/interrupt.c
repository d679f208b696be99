/* Signal handling of a run (interrupt.h). */
#define _POSIX_C_SOURCE 200809L /* sigaction */
#include "app/interrupt.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

static volatile sig_atomic_t received;
static struct sigaction previous[2];
static int installed;
static const int signals[2] = {SIGINT, SIGTERM};

static void on_signal(int sig)
{
    received = sig;
}

int interrupt_install(void)
{
    received = 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART; /* blocking I/O resumes after the flag is set */
    for (int m = 0; m < 2; m++)
        if (sigaction(signals[m], &sa, &previous[m]) != 0) {
            for (int k = 0; k < m; k++)
                sigaction(signals[k], &previous[k], NULL);
            return -1;
        }
    installed = 1;
    return 0;
}

void interrupt_restore(void)
{
    if (!installed)
        return;
    for (int m = 0; m < 2; m++)
        sigaction(signals[m], &previous[m], NULL);
    installed = 0;
}

int interrupt_signal(void)
{
    return received;
}

const char *interrupt_name(int sig)
{
    static char buf[32];
    if (sig == SIGINT)
        return "SIGINT";
    if (sig == SIGTERM)
        return "SIGTERM";
    snprintf(buf, sizeof buf, "signal %d", sig);
    return buf;
}
