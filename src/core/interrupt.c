/* The process-wide interrupt and termination flags. */
#include "core/interrupt.h"

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "core/comm.h"

static volatile sig_atomic_t requested = 0;
static volatile sig_atomic_t terminating = 0;
static char where[160];

void interrupt_request(void) { requested = 1; }
bool interrupt_pending_here(void) { return requested != 0; }

bool interrupt_pending(void)
{
    if (comm_size() == 1)
        return requested != 0;
    /* mpirun forwards SIGTERM to every rank, each at its own moment: the ranks agree, so all of
     * them stop at the same step (and a rank that was not signalled learns the termination). */
    int64_t v[2] = {requested != 0, terminating};
    comm_max_i64(v, 2);
    if (v[1] && !terminating)
        interrupt_terminate((int)v[1]);
    else if (v[0])
        requested = 1;
    return v[0] != 0;
}

void interrupt_clear(void)
{
    if (terminating) /* a termination keeps every later run from starting, and its note */
        return;
    requested = 0;
    where[0] = '\0';
}

void interrupt_terminate(int sig)
{
    terminating = sig;
    requested = 1;
}

int interrupt_terminating(void) { return terminating; }

void interrupt_note(const char *text) { snprintf(where, sizeof where, "%s", text ? text : ""); }
const char *interrupt_where(void) { return where; }
