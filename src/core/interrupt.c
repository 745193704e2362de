/* The process-wide interrupt and termination flags. */
#include "core/interrupt.h"

#include <signal.h>
#include <stdio.h>

static volatile sig_atomic_t requested = 0;
static volatile sig_atomic_t terminating = 0;
static char where[160];

void interrupt_request(void) { requested = 1; }
bool interrupt_pending(void) { return requested != 0; }

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
