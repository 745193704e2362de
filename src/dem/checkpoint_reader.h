/* Reading a DEM checkpoint section with a sticky status: after the first failure every read is
 * a no-op returning 0, and the caller checks r->st once (checkpoint.c, and flow.c for its own
 * section). bad() names the file and the section. */
#ifndef GRAINLAB_DEM_CHECKPOINT_READER_H
#define GRAINLAB_DEM_CHECKPOINT_READER_H

#include <stddef.h>
#include <stdint.h>

#include "core/checkpoint.h"
#include "core/error.h"

typedef struct dem_reader {
    ckpt_section sec;
    core_error *err;
    core_status st; /* sticky: the first failure */
} dem_reader;

static inline uint32_t u32(dem_reader *r)
{
    uint32_t v = 0;
    if (!r->st)
        r->st = ckpt_get_u32(&r->sec, &v, r->err);
    return v;
}

static inline uint64_t u64(dem_reader *r)
{
    uint64_t v = 0;
    if (!r->st)
        r->st = ckpt_get_u64(&r->sec, &v, r->err);
    return v;
}

static inline int64_t i64(dem_reader *r)
{
    int64_t v = 0;
    if (!r->st)
        r->st = ckpt_get_i64(&r->sec, &v, r->err);
    return v;
}

static inline double f64(dem_reader *r)
{
    double v = 0;
    if (!r->st)
        r->st = ckpt_get_f64(&r->sec, &v, r->err);
    return v;
}

static inline void bytes(dem_reader *r, void *out, size_t len)
{
    if (!r->st)
        r->st = ckpt_get_bytes(&r->sec, out, len, r->err);
}

static inline void bad(dem_reader *r, const char *what)
{
    if (!r->st)
        r->st = core_fail(r->err, CORE_ERR_IO, "'%s' is corrupt (section '%s': %s)",
                          ckpt_reader_path(r->sec.r), r->sec.tag, what);
}

/* n values into a new array of cap >= n entries. */
static inline double *get_new(dem_reader *r, size_t n, size_t cap)
{
    if (r->st)
        return NULL;
    double *a;
    r->st = ckpt_get_new_f64s(&r->sec, n, cap, &a, r->err);
    return a;
}

#endif
