/* Reading a DEM checkpoint section with a sticky status: after the first failure every read is
 * a no-op returning 0, and the caller checks r->st once (checkpoint.c, and flow_checkpoint.c for
 * its own section). bad() names the file and the section. */
#ifndef GRAINLAB_DEM_CHECKPOINT_READER_H
#define GRAINLAB_DEM_CHECKPOINT_READER_H

#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

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

/* A value that cannot be: "'PATH' is corrupt (section 'TAG': WHAT = V is outside [LO, HI])". */
static inline core_status bad_int(dem_reader *r, const char *what, long long v, long long lo,
                                  long long hi)
{
    if (!r->st)
        r->st = core_fail(r->err, CORE_ERR_IO,
                          "'%s' is corrupt (section '%s': %s = %lld is outside [%lld, %lld])",
                          ckpt_reader_path(r->sec.r), r->sec.tag, what, v, lo, hi);
    return r->st;
}

/* "'PATH' is corrupt (section 'TAG': WHAT = V, WANT expected)" */
static inline core_status bad_num(dem_reader *r, const char *what, double v, const char *want)
{
    if (!r->st)
        r->st =
            core_fail(r->err, CORE_ERR_IO, "'%s' is corrupt (section '%s': %s = %g, %s expected)",
                      ckpt_reader_path(r->sec.r), r->sec.tag, what, v, want);
    return r->st;
}

/* An int64 in [lo, hi]. */
static inline long long get_int_in(dem_reader *r, const char *what, long long lo, long long hi)
{
    int64_t v = i64(r);
    if (!r->st && (v < lo || v > hi)) {
        bad_int(r, what, v, lo, hi);
        return lo;
    }
    return v;
}

/* A step counter or count of a run: [0, CKPT_COUNTER_MAX]. */
static inline long get_counter(dem_reader *r, const char *what)
{
    return (long)get_int_in(r, what, 0, CKPT_COUNTER_MAX);
}

/* A uint32 flag: 0 or 1. */
static inline int get_flag(dem_reader *r, const char *what)
{
    uint32_t v = u32(r);
    if (!r->st && v > 1) {
        bad_int(r, what, v, 0, 1);
        return 0;
    }
    return (int)v;
}

/* A double in [lo, hi] (so finite when both are). */
static inline double get_num_in(dem_reader *r, const char *what, double lo, double hi)
{
    double v = f64(r);
    if (!r->st && !(v >= lo && v <= hi)) {
        char want[96];
        snprintf(want, sizeof want, "a number in [%g, %g]", lo, hi);
        bad_num(r, what, v, want);
        return 0;
    }
    return v;
}

/* A finite double. */
static inline double get_finite(dem_reader *r, const char *what)
{
    return get_num_in(r, what, -DBL_MAX, DBL_MAX);
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
