/* Monotonic wall-clock and process CPU-time readings, in seconds. */
#ifndef GRAINLAB_CORE_CLOCK_H
#define GRAINLAB_CORE_CLOCK_H

/* Seconds on a monotonic clock (CLOCK_MONOTONIC); only differences mean anything. */
double clock_wall(void);

/* CPU seconds used by the process, all threads (CLOCK_PROCESS_CPUTIME_ID). */
double clock_cpu(void);

#endif
