/* Ctrl-C reaches the kernels as a flag: the CLI's signal handler sets it, engines poll it between
 * steps and stop with CORE_ERR_INTERRUPTED, leaving their state intact. */
#ifndef GRAINLAB_CORE_INTERRUPT_H
#define GRAINLAB_CORE_INTERRUPT_H

#include <stdbool.h>

/* Async-signal-safe. */
void interrupt_request(void);
bool interrupt_pending(void);
void interrupt_clear(void);

#endif
