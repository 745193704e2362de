/* Ctrl-C and SIGTERM reach the kernels as a flag: the CLI's signal handlers set it, engines poll it
 * between steps and stop with CORE_ERR_INTERRUPTED, leaving their state intact. SIGTERM (a batch
 * scheduler's time limit) also marks the process as terminating: the CLI then ends it instead of
 * returning to the prompt. */
#ifndef GRAINLAB_CORE_INTERRUPT_H
#define GRAINLAB_CORE_INTERRUPT_H

#include <stdbool.h>

/* Async-signal-safe. interrupt_clear() does nothing once the process is terminating. */
void interrupt_request(void);
/* Whether a stop was requested. In a distributed run (comm_size() > 1) this is a collective
 * call, the ranks' flags or-ed (not async-signal-safe then): engines call it at the same points
 * on every rank, between steps, so that all ranks stop at the same step. */
bool interrupt_pending(void);
/* This process's own flag, never collective (async-signal-safe): for code that may run on some
 * ranks only, such as an error path. */
bool interrupt_pending_here(void);
void interrupt_clear(void);

/* Async-signal-safe: sets the interrupt flag and records that the process must end with `sig`. */
void interrupt_terminate(int sig);
/* The signal the process is ending on (SIGTERM), or 0. */
int interrupt_terminating(void);

/* Where the work stood when it was interrupted, for the closing message: "step 4000 of 100000 of
 * 'dem run'". Runs record it when they stop on the flag; interrupt_clear() forgets it (unless
 * terminating). */
void interrupt_note(const char *where);
const char *interrupt_where(void);

#endif
