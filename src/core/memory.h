/* How much memory one allocation of a scene may ask for. */
#ifndef GRAINLAB_CORE_MEMORY_H
#define GRAINLAB_CORE_MEMORY_H

/* The machine's physical memory in bytes (sysconf), or GRAINLAB_MEMORY_LIMIT (bytes, e.g. 4e9)
 * when set to a positive number. An allocation larger than this cannot succeed without swapping,
 * and on an overcommitting system a calloc beyond it may "succeed" and kill the process at the
 * first touch, so engines refuse it up front with the numbers in the message. */
double core_memory_budget(void);

#endif
