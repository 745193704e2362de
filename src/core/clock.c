/* Monotonic timers. */
#define _POSIX_C_SOURCE 200809L
#include "core/clock.h"

#include <time.h>

static double read(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double clock_wall(void) { return read(CLOCK_MONOTONIC); }
double clock_cpu(void) { return read(CLOCK_PROCESS_CPUTIME_ID); }
