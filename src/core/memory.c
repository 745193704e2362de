/* The memory budget of one allocation, and arrays staggered in their blocks (see memory.h). */
#include "core/memory.h"

#include <stdlib.h>
#include <unistd.h>

static size_t stagger(int k) { return (size_t)(k % 64) * 64; }

void *core_realloc_staggered(void *cur, size_t bytes, int k)
{
    char *base = cur ? (char *)cur - stagger(k) : NULL;
    char *p = realloc(base, (bytes ? bytes : 1) + stagger(k));
    return p ? p + stagger(k) : NULL;
}

void core_free_staggered(void *cur, int k)
{
    if (cur)
        free((char *)cur - stagger(k));
}

double core_memory_budget(void)
{
    const char *env = getenv("GRAINLAB_MEMORY_LIMIT");
    if (env && *env) {
        char *end = NULL;
        double v = strtod(env, &end);
        if (end && *end == '\0' && v > 0)
            return v;
    }
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && size > 0)
        return (double)pages * (double)size;
    return 8.0 * 1024 * 1024 * 1024; /* unknown: a conservative 8 GiB */
}
