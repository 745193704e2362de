/* How much memory one allocation of a scene may ask for, and allocations staggered so that the
 * arrays a loop walks together do not share a cache set. */
#ifndef GRAINLAB_CORE_MEMORY_H
#define GRAINLAB_CORE_MEMORY_H

#include <stddef.h>

/* The machine's physical memory in bytes (sysconf), or GRAINLAB_MEMORY_LIMIT (bytes, e.g. 4e9)
 * when set to a positive number. An allocation larger than this cannot succeed without swapping,
 * and on an overcommitting system a calloc beyond it may "succeed" and kill the process at the
 * first touch, so engines refuse it up front with the numbers in the message. */
double core_memory_budget(void);

/* Arrays that one loop walks together at the same index, each starting k cache lines into its
 * block (k: the array's number among them, any int >= 0). Large blocks from malloc come from
 * mmap and all begin at the same offset within a page, so element i of a dozen such arrays falls
 * into one set of the 8-way first-level cache, and a load 4 KiB from a pending store waits for it
 * (the DEM kick-drift over 13 arrays, the MPM stress update over 20: 13 % and 40 % of their
 * time). realloc semantics (contents kept, NULL on failure with cur untouched); the block must be
 * freed by core_free_staggered with the same k, never by free. */
void *core_realloc_staggered(void *cur, size_t bytes, int k);
void core_free_staggered(void *cur, int k);

#endif
