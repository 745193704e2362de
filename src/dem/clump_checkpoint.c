/* The checkpoint section of clumps (clump.c), written only by a scene that has them: each body's
 * members (first, count), pose, momenta and mass properties, and each member's offset in its
 * body's principal frame. Which clump a particle belongs to follows from the bodies' member
 * ranges. Checked on load against what dem_add_clump makes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dem/checkpoint_reader.h"
#include "dem/dem_internal.h"

core_status dem_clumps_save(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const dem_clumps *c = s->clumps;
    core_status st = ckpt_section_begin(w, "clumps", CKPT_REQUIRED, err);
    if (st)
        return st;
    ckpt_put_u64(w, (uint64_t)c->n);
    for (size_t k = 0; k < c->n; k++) {
        const dem_body *b = &c->b[k];
        ckpt_put_u64(w, (uint64_t)b->first);
        ckpt_put_u64(w, (uint64_t)b->count);
        ckpt_put_f64(w, b->mass);
        ckpt_put_f64s(w, b->moment, 3);
        ckpt_put_f64s(w, b->x, 3);
        ckpt_put_f64s(w, b->v, 3);
        ckpt_put_f64s(w, b->q, 4);
        ckpt_put_f64(w, b->angle);
        ckpt_put_f64s(w, b->L, 3);
        ckpt_put_f64s(w, b->omega, 3);
    }
    ckpt_put_f64s(w, c->off, 3 * s->n);
    return ckpt_section_end(w, err);
}

/* Body k's values against what dem_add_clump and the steps make: members in order after the
 * bodies before it, within the particles; positive mass and moments; a finite state whose kinetic
 * energy is finite; the centre within a box length of the box; a unit quaternion in 3D. */
static core_status check_body(dem_reader *r, const dem_scene *s, size_t k, size_t after)
{
    const dem_body *b = &s->clumps->b[k];
    char what[96];
    snprintf(what, sizeof what, "clump %zu's first member", k + 1);
    if (b->first < after || b->first >= s->n)
        return bad_int(r, what, (long long)b->first + 1, (long long)after + 1, (long long)s->n);
    snprintf(what, sizeof what, "clump %zu's member count", k + 1);
    const size_t left = s->n - b->first;
    const size_t most = left < DEM_CLUMP_MAX_MEMBERS ? left : DEM_CLUMP_MAX_MEMBERS;
    if (b->count < 1 || b->count > most)
        return bad_int(r, what, (long long)b->count, 1, (long long)most);
    snprintf(what, sizeof what, "clump %zu's mass", k + 1);
    if (!(b->mass > 0 && isfinite(b->mass)))
        return bad_num(r, what, b->mass, "a positive mass");
    snprintf(what, sizeof what, "clump %zu's moment of inertia", k + 1);
    for (int d = s->dim == 2 ? 2 : 0; d < 3; d++)
        if (!(b->moment[d] > 0 && isfinite(b->moment[d])))
            return bad_num(r, what, b->moment[d], "a positive moment");
    const double v[19] = {b->x[0], b->x[1], b->x[2], b->v[0], b->v[1], b->v[2], b->q[0],
                          b->q[1], b->q[2], b->q[3], b->angle, b->L[0], b->L[1], b->L[2],
                          b->omega[0], b->omega[1], b->omega[2], b->moment[0], b->moment[1]};
    snprintf(what, sizeof what, "clump %zu's state", k + 1);
    for (size_t q = 0; q < 19; q++)
        if (!isfinite(v[q]))
            return bad_num(r, what, v[q], "finite values");
    double e = 0;
    for (int d = 0; d < 3; d++)
        e += b->mass * b->v[d] * b->v[d] + b->omega[d] * b->L[d];
    snprintf(what, sizeof what, "clump %zu's kinetic energy", k + 1);
    if (!isfinite(e))
        return bad_num(r, what, e, "a finite energy");
    for (int d = 0; d < s->dim; d++) {
        const double len = s->hi[d] - s->lo[d];
        snprintf(what, sizeof what, "clump %zu's %c", k + 1, 'x' + d);
        if (!(b->x[d] >= s->lo[d] - len && b->x[d] <= s->hi[d] + len))
            return bad_num(r, what, b->x[d], "a position within a box length of the box");
    }
    if (s->dim == 3) {
        const double n2 = b->q[0] * b->q[0] + b->q[1] * b->q[1] + b->q[2] * b->q[2] +
                          b->q[3] * b->q[3];
        snprintf(what, sizeof what, "clump %zu's orientation |q|^2", k + 1);
        if (!(fabs(n2 - 1) < 1e-9))
            return bad_num(r, what, n2, "1 (a unit quaternion)");
    }
    return CORE_OK;
}

/* The members: each particle of a body marked as its member, with an offset no longer than the
 * box (a member lies within its body); no member fixed, prescribed or of no body in between. */
static core_status mark_members(dem_reader *r, dem_scene *s)
{
    dem_clumps *c = s->clumps;
    char what[96];
    double extent = 0;
    for (int d = 0; d < s->dim; d++)
        extent += (s->hi[d] - s->lo[d]) * (s->hi[d] - s->lo[d]);
    extent = sqrt(extent);
    for (size_t k = 0; k < c->n; k++) {
        const dem_body *b = &c->b[k];
        for (size_t i = b->first; i < b->first + b->count; i++) {
            c->body[i] = (int32_t)k;
            const double *o = c->off + 3 * i;
            const double len = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
            snprintf(what, sizeof what, "member %zu's offset in clump %zu", i + 1, k + 1);
            if (!(len <= extent) || (s->dim == 2 && o[2] != 0))
                return bad_num(r, what, len, "a finite offset within the box's diagonal");
            snprintf(what, sizeof what, "member %zu of clump %zu's flags", i + 1, k + 1);
            if (s->flags[i])
                return bad_int(r, what, s->flags[i], 0, 0);
        }
    }
    return CORE_OK;
}

core_status dem_clumps_load(dem_scene *s, dem_reader *r)
{
    uint64_t nb = u64(r);
    if (!r->st && nb > s->n)
        return bad_int(r, "clump count", (long long)nb, 0, (long long)s->n);
    if (r->st)
        return r->st;
    dem_clumps_free(s);
    s->clumps = calloc(1, sizeof *s->clumps);
    if (!s->clumps || dem_clumps_grow(s, 0, s->cap, r->err))
        return r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    dem_clumps *c = s->clumps;
    c->b = calloc(nb ? nb : 1, sizeof *c->b);
    if (!c->b)
        return r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    c->cap = nb ? nb : 1;
    size_t after = 0;
    for (size_t k = 0; k < nb && !r->st; k++) {
        dem_body *b = &c->b[k];
        uint64_t first = u64(r), count = u64(r);
        b->first = first < s->n ? (size_t)first : s->n;
        b->count = count <= DEM_CLUMP_MAX_MEMBERS ? (size_t)count : DEM_CLUMP_MAX_MEMBERS + 1;
        b->mass = f64(r);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->moment, 3, r->err);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->x, 3, r->err);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->v, 3, r->err);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->q, 4, r->err);
        b->angle = f64(r);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->L, 3, r->err);
        if (!r->st)
            r->st = ckpt_get_f64s(&r->sec, b->omega, 3, r->err);
        c->n = k + 1;
        if (!r->st && check_body(r, s, k, after))
            return r->st;
        after = b->first + b->count;
    }
    if (!r->st)
        r->st = ckpt_get_f64s(&r->sec, c->off, 3 * s->n, r->err);
    if (!r->st)
        mark_members(r, s);
    return r->st;
}
