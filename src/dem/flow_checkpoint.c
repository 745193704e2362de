/* The checkpoint section of inserters and outflows (flow.c): their definitions, random streams
 * and counters, checked on load as dem_add_inserter and dem_add_outflow check new ones. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dem/checkpoint_reader.h"
#include "dem/dem_internal.h"
#include "dem/flow_internal.h"

core_status dem_flow_save(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const dem_flow *f = s->flow;
    core_status st = ckpt_section_begin(w, "flow", CKPT_REQUIRED, err);
    if (st)
        return st;
    ckpt_put_f64(w, f->next_tag);
    ckpt_put_f64s(w, s->tag, s->n);
    ckpt_put_u64(w, (uint64_t)f->nins);
    for (int q = 0; q < f->nins; q++) {
        const inserter *in = &f->ins[q];
        const dem_inserter_def *d = &in->def;
        ckpt_put_u32(w, (uint32_t)d->ball);
        ckpt_put_bytes(w, d->lo, sizeof d->lo);
        ckpt_put_bytes(w, d->hi, sizeof d->hi);
        ckpt_put_bytes(w, d->center, sizeof d->center);
        ckpt_put_f64(w, d->extent);
        ckpt_put_f64(w, d->rate);
        ckpt_put_i64(w, d->count);
        ckpt_put_f64(w, d->mass);
        ckpt_put_u32(w, (uint32_t)d->size);
        ckpt_put_f64(w, d->r0);
        ckpt_put_f64(w, d->r1);
        ckpt_put_f64s(w, in->radii, d->size == DEM_SIZE_DISCRETE ? d->nsizes : 0);
        ckpt_put_f64s(w, in->cum, d->size == DEM_SIZE_DISCRETE ? d->nsizes : 0);
        ckpt_put_bytes(w, d->velocity, sizeof d->velocity);
        ckpt_put_f64(w, d->spread);
        ckpt_put_i64(w, d->material);
        ckpt_put_u64(w, d->seed);
        ckpt_put_i64(w, d->every);
        ckpt_put_i64(w, d->attempts);
        ckpt_put_u64s(w, in->rng.s, 4);
        ckpt_put_f64(w, in->t0);
        ckpt_put_i64(w, in->next_step);
        ckpt_put_i64(w, in->c.count);
        ckpt_put_f64(w, in->c.mass);
        ckpt_put_i64(w, in->c.skipped);
        ckpt_put_i64(w, in->c.events);
        ckpt_put_u32(w, (uint32_t)in->done);
    }
    ckpt_put_u64(w, (uint64_t)f->nout);
    for (int o = 0; o < f->nout; o++) {
        const outflow *of = &f->out[o];
        ckpt_put_i64(w, of->def.side);
        ckpt_put_bytes(w, of->def.lo, sizeof of->def.lo);
        ckpt_put_bytes(w, of->def.hi, sizeof of->def.hi);
        ckpt_put_i64(w, of->c.count);
        ckpt_put_f64(w, of->c.mass);
    }
    return ckpt_section_end(w, err);
}

/* An inserter as stored against dem_add_inserter's checks (its region inside the domain, finite
 * values, positive radii the scene's particles can have, a cumulative distribution ending at 1),
 * and its state; NULL, or what is wrong. */
static const char *bad_inserter(const dem_scene *s, const inserter *in)
{
    const dem_inserter_def *d = &in->def;
    const int D = s->dim;
    double lo[3], hi[3];
    if (d->ball > 1 || (d->ball && !(d->extent > 0 && isfinite(d->extent))) ||
        !dem_finite_n(d->lo, D) || !dem_finite_n(d->hi, D) || !dem_finite_n(d->center, D) ||
        dem_inserter_region(s, d, lo, hi, NULL))
        return "its region is not a finite region inside the domain";
    if (!dem_finite_n(d->velocity, D) || !(d->spread >= 0 && isfinite(d->spread)) ||
        !(d->rate >= 0 && isfinite(d->rate)) || !(d->mass >= 0 && isfinite(d->mass)) ||
        d->count > CKPT_COUNTER_MAX)
        return "its velocity, spread, rate, count or mass";
    if (d->every < 1 || d->every > CKPT_COUNTER_MAX || d->attempts < 1)
        return "its schedule (every, attempts)";
    if (d->size == DEM_SIZE_DISCRETE) {
        for (size_t k = 0; k < d->nsizes; k++)
            if (!(in->radii[k] > 0 && isfinite(in->radii[k])) ||
                !(in->cum[k] > (k ? in->cum[k - 1] : 0) && in->cum[k] <= 1))
                return "its size distribution";
        if (in->cum[d->nsizes - 1] != 1)
            return "its size distribution";
    } else if (!(d->r0 > 0 && isfinite(d->r0)) ||
               (d->size == DEM_SIZE_UNIFORM && !(d->r1 >= d->r0 && isfinite(d->r1)))) {
        return "its radii";
    }
    double extent = INFINITY, reach = 0;
    for (int a = 0; a < D; a++) {
        extent = fmin(extent, s->hi[a] - s->lo[a]);
        reach = fmax(reach, fmax(fabs(s->lo[a]), fabs(s->hi[a])));
    }
    if (dem_inserter_rmax(d) > 0.5 * extent || dem_inserter_rmin(d) < 1e-9 * reach)
        return "its radii (against the box)";
    if (!isfinite(in->t0) || in->next_step < 0 || in->next_step > CKPT_COUNTER_MAX ||
        in->c.count < 0 || in->c.count > CKPT_COUNTER_MAX || in->c.skipped < 0 ||
        in->c.skipped > CKPT_COUNTER_MAX || in->c.events < 0 || in->c.events > CKPT_COUNTER_MAX ||
        !(in->c.mass >= 0 && isfinite(in->c.mass)) || in->done > 1)
        return "its state (time, next step, counters)";
    return NULL;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Tags are distinct whole numbers in [0, next_tag), next_tag <= 2^53; NULL, or what is wrong. */
static const char *bad_tags(const dem_scene *s, double next_tag, core_error *err, int *nomem)
{
    if (!(next_tag >= 0 && next_tag <= (double)CKPT_COUNTER_MAX && next_tag == floor(next_tag)))
        return "the next tag is not a whole number in [0, 2^53]";
    for (size_t i = 0; i < s->n; i++)
        if (!(s->tag[i] >= 0 && s->tag[i] < next_tag && s->tag[i] == floor(s->tag[i])))
            return "a particle's tag is not a whole number below the next tag";
    double *t = malloc((s->n ? s->n : 1) * sizeof *t);
    if (!t) {
        *nomem = 1;
        core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return NULL;
    }
    if (s->n)
        memcpy(t, s->tag, s->n * sizeof *t);
    qsort(t, s->n, sizeof *t, cmp_double);
    const char *why = NULL;
    for (size_t i = 1; i < s->n && !why; i++)
        if (t[i] == t[i - 1])
            why = "two particles have the same tag";
    free(t);
    return why;
}

core_status dem_flow_load(dem_scene *s, dem_reader *r)
{
    core_error *err = r->err;
    if ((r->st = dem_flow_on(s, err)))
        return r->st;
    dem_flow *f = s->flow;
    f->next_tag = f64(r);
    double *tag = get_new(r, s->n, s->cap);
    if (tag) {
        free(s->tag);
        s->tag = tag;
        int nomem = 0;
        const char *why = bad_tags(s, f->next_tag, err, &nomem);
        if (nomem)
            return r->st = CORE_ERR_NOMEM;
        if (why)
            bad(r, why);
    }
    uint64_t nins = u64(r);
    if (nins > r->sec.size / 64)
        bad(r, "bad inserter count");
    if (!r->st && nins > 0) {
        f->ins = calloc(nins, sizeof *f->ins);
        if (!f->ins)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        f->cap_ins = (int)nins;
    }
    for (uint64_t q = 0; q < nins && !r->st; q++) {
        inserter *in = &f->ins[f->nins++];
        dem_inserter_def *d = &in->def;
        d->ball = get_flag(r, "an inserter's ball flag");
        bytes(r, d->lo, sizeof d->lo);
        bytes(r, d->hi, sizeof d->hi);
        bytes(r, d->center, sizeof d->center);
        d->extent = f64(r);
        d->rate = f64(r);
        d->count = (long)get_int_in(r, "an inserter's count", LONG_MIN, CKPT_COUNTER_MAX);
        d->mass = f64(r);
        uint32_t size = u32(r);
        if (size > DEM_SIZE_DISCRETE)
            bad(r, "unknown size distribution");
        d->size = (dem_size_law)size;
        d->r0 = f64(r);
        d->r1 = f64(r);
        size_t nr = 0;
        if (!r->st)
            r->st = ckpt_peek_count(&r->sec, r->sec.size / 8, &nr, err);
        in->radii = get_new(r, nr, nr);
        in->cum = get_new(r, nr, nr);
        d->nsizes = nr;
        d->radii = in->radii;
        if (!r->st && (d->size == DEM_SIZE_DISCRETE) != (nr > 0))
            bad(r, "size distribution");
        bytes(r, d->velocity, sizeof d->velocity);
        d->spread = f64(r);
        int64_t mat = i64(r);
        if (mat < 0 || mat >= s->nmat)
            bad(r, "unknown material");
        d->material = (int)mat;
        d->seed = u64(r);
        d->every = (long)get_int_in(r, "an inserter's interval", 1, CKPT_COUNTER_MAX);
        d->attempts = (int)get_int_in(r, "an inserter's attempts", 1, INT_MAX);
        if (!r->st)
            r->st = ckpt_get_u64s(&r->sec, in->rng.s, 4, err);
        in->t0 = f64(r);
        in->next_step = (long)i64(r);
        in->c.count = (long)i64(r);
        in->c.mass = f64(r);
        in->c.skipped = (long)i64(r);
        in->c.events = (long)i64(r);
        in->done = (int)u32(r);
        const char *why = r->st ? NULL : bad_inserter(s, in);
        if (why) {
            char what[128];
            snprintf(what, sizeof what, "inserter %d: %s", f->nins, why);
            bad(r, what);
        }
    }
    uint64_t nout = u64(r);
    if (nout > r->sec.size / 16)
        bad(r, "bad outflow count");
    if (!r->st && nout > 0) {
        f->out = calloc(nout, sizeof *f->out);
        if (!f->out)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        f->cap_out = (int)nout;
    }
    for (uint64_t o = 0; o < nout && !r->st; o++) {
        outflow *of = &f->out[f->nout++];
        int64_t side = i64(r);
        if (side < -1 || side >= 2 * s->dim)
            bad(r, "unknown side");
        of->def.side = (int)side;
        bytes(r, of->def.lo, sizeof of->def.lo);
        bytes(r, of->def.hi, sizeof of->def.hi);
        of->c.count = get_counter(r, "an outflow's count");
        of->c.mass = get_num_in(r, "an outflow's mass", 0, DBL_MAX);
        if (!r->st && (!dem_finite_n(of->def.lo, s->dim) || !dem_finite_n(of->def.hi, s->dim)))
            bad(r, "an outflow's box is not finite");
    }
    return r->st;
}
