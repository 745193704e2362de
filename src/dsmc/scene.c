/* DSMC scenes: definition checks, particles (fill, add), walls, the excluded-volume chi and the
 * paper's validity conditions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "core/memory.h"
#include "dsmc/dsmc_internal.h"

static const char AXIS[3] = {'x', 'y', 'z'};

dsmc_scene_def dsmc_default_scene_def(void)
{
    dsmc_scene_def d;
    memset(&d, 0, sizeof d);
    d.dim = 2;
    for (int k = 0; k < 3; k++) {
        d.hi[k] = 1;
        d.cells[k] = 10;
        d.periodic[k] = true;
    }
    d.restitution = 1;
    d.radius = 1e-3;
    d.density = 2650;
    d.excluded = DSMC_EXCLUDED_FREE_VOLUME;
    d.seed = 1;
    return d;
}

static uint64_t splitmix(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void dsmc_stream(rng *r, uint64_t seed, uint64_t purpose, uint64_t step, uint64_t index)
{
    uint64_t x = seed;
    x = splitmix(&x) ^ purpose;
    x = splitmix(&x) ^ step;
    x = splitmix(&x) ^ index;
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix(&x);
}

core_status dsmc_create(const dsmc_scene_def *def, dsmc_scene **out, core_error *err)
{
    *out = NULL;
    if (def->dim != 2 && def->dim != 3)
        return core_fail(err, CORE_ERR_ARG, "dim must be 2 or 3, got %d", def->dim);
    int D = def->dim;
    if (!(def->radius > 0) || !isfinite(def->radius))
        return core_fail(err, CORE_ERR_ARG, "radius must be positive, got %g", def->radius);
    if (!(def->restitution >= 0 && def->restitution <= 1))
        return core_fail(err, CORE_ERR_ARG, "restitution must be in [0, 1], got %g",
                         def->restitution);
    if (!(def->mass >= 0) || !isfinite(def->mass))
        return core_fail(err, CORE_ERR_ARG, "mass must be positive, got %g", def->mass);
    if (def->mass == 0 && (!(def->density > 0) || !isfinite(def->density)))
        return core_fail(err, CORE_ERR_ARG, "density must be positive, got %g", def->density);
    if (def->packing_limit != 0 && !(def->packing_limit > 0 && def->packing_limit < 1))
        return core_fail(err, CORE_ERR_ARG, "packing_limit must be in (0, 1), got %g",
                         def->packing_limit);
    double ncells = 1;
    for (int k = 0; k < D; k++) {
        if (!isfinite(def->lo[k]) || !isfinite(def->hi[k]) || !(def->hi[k] > def->lo[k]))
            return core_fail(err, CORE_ERR_ARG, "the box's %c extent [%g, %g] is empty", AXIS[k],
                             def->lo[k], def->hi[k]);
        if (def->cells[k] < 1)
            return core_fail(err, CORE_ERR_ARG, "cells along %c must be >= 1, got %d", AXIS[k],
                             def->cells[k]);
        double h = (def->hi[k] - def->lo[k]) / def->cells[k];
        if (h < 2 * def->radius)
            return core_fail(err, CORE_ERR_ARG,
                             "cells along %c are %g m wide, smaller than a particle (diameter %g m); "
                             "use at most %d cells", AXIS[k], h, 2 * def->radius,
                             (int)fmin(floor((def->hi[k] - def->lo[k]) / (2 * def->radius)), 1e9));
        ncells *= def->cells[k];
    }
    {
        /* Per-cell arrays (collision remainders, cell starts, next-in-cell) are allocated here;
         * a calloc beyond the machine may "succeed" on an overcommitting system and kill the
         * process later, so the grid must fit in the machine's memory (core/memory.h). */
        const dsmc_scene *z = NULL;
        const double budget = core_memory_budget();
        double bytes = ncells * (double)(sizeof *z->remainder + sizeof *z->start + sizeof *z->next);
        if (bytes > budget)
            return core_fail(err, CORE_ERR_ARG,
                             "%.4g cells need %.3g bytes, above the limit of %.3g bytes (the machine's memory, or "
                             "GRAINLAB_MEMORY_LIMIT); "
                             "use fewer cells (field 'cells')",
                             ncells, bytes, budget);
    }

    dsmc_scene *s = calloc(1, sizeof *s);
    if (!s)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory");
    s->def = *def;
    s->D = D;
    if (D == 2) {
        s->def.lo[2] = 0;
        s->def.hi[2] = 1;
        s->def.cells[2] = 1;
        s->def.periodic[2] = true;
        s->def.gravity[2] = 0;
    }
    if (s->def.packing_limit == 0)
        s->def.packing_limit = D == 2 ? 0.82 : 0.64;
    double R = def->radius;
    s->mass = def->mass > 0 ? def->mass : def->density * 4.0 / 3.0 * DSMC_PI * R * R * R;
    if (def->mass > 0)
        s->def.density = s->mass / (4.0 / 3.0 * DSMC_PI * R * R * R);
    s->sigma = D == 2 ? 4 * R : 4 * DSMC_PI * R * R;
    s->vpart = D == 2 ? DSMC_PI * R * R : 4.0 / 3.0 * DSMC_PI * R * R * R;
    s->cell_volume = 1;
    for (int k = 0; k < 3; k++) {
        s->h[k] = (s->def.hi[k] - s->def.lo[k]) / s->def.cells[k];
        s->inv_h[k] = 1 / s->h[k];
        if (k < D)
            s->cell_volume *= s->h[k];
    }
    s->ncells = (size_t)ncells;
    /* at most 4096 blocks: the all-gather of per-block sums stays small, and a cut between
     * ranks lands within 1/4096 of the grid of where balance wants it */
    while ((s->ncells + ((size_t)1 << s->blk_shift) - 1) >> s->blk_shift > 4096)
        s->blk_shift++;
    s->nblk = (s->ncells + ((size_t)1 << s->blk_shift) - 1) >> s->blk_shift;
    s->blk_hi = s->nblk;
    s->cell_hi = s->ncells;
    s->remainder = calloc(s->ncells, sizeof *s->remainder);
    s->start = calloc(s->ncells + 1, sizeof *s->start);
    s->next = calloc(s->ncells, sizeof *s->next);
    if (!s->remainder || !s->start || !s->next) {
        dsmc_destroy(s);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu cells", (size_t)ncells);
    }
    for (int k = 0; k < 6; k++)
        s->walls[k] = dsmc_default_wall_def();
    *out = s;
    return CORE_OK;
}

void dsmc_destroy(dsmc_scene *s)
{
    if (!s)
        return;
    for (int k = 0; k < 3; k++) {
        free(s->x[k]);
        free(s->v[k]);
    }
    free(s->cell);
    free(s->id);
    free(s->cuts);
    free(s->remainder);
    free(s->start);
    free(s->next);
    free(s);
}

const dsmc_scene_def *dsmc_def(const dsmc_scene *s) { return &s->def; }
double dsmc_mass(const dsmc_scene *s) { return s->mass; }
double dsmc_cross_section(const dsmc_scene *s) { return s->sigma; }
double dsmc_particle_volume(const dsmc_scene *s) { return s->vpart; }
size_t dsmc_cell_count(const dsmc_scene *s) { return s->ncells; }
size_t dsmc_count(const dsmc_scene *s) { return s->distributed ? s->n_global : s->n; }
double dsmc_time(const dsmc_scene *s) { return s->t; }
long dsmc_steps_done(const dsmc_scene *s) { return s->steps; }
double dsmc_total_collisions(const dsmc_scene *s) { return s->total_collisions; }

double dsmc_volume(const dsmc_scene *s)
{
    return s->cell_volume * (double)s->ncells;
}

void dsmc_cell_size(const dsmc_scene *s, double h[3])
{
    for (int k = 0; k < 3; k++)
        h[k] = k < s->D ? s->h[k] : 0;
}

void dsmc_memory(const dsmc_scene *s, size_t *particle_bytes, size_t *cell_bytes)
{
    *particle_bytes = s->cap * (2 * (size_t)s->D * sizeof(double) + 2 * sizeof(uint32_t));
    *cell_bytes = s->ncells * (sizeof(double) + 2 * sizeof(size_t)) + sizeof(size_t);
}

size_t dsmc_capacity(const dsmc_scene *s)
{
    return (size_t)floor(s->def.packing_limit * dsmc_volume(s) / s->vpart);
}

double dsmc_chi(const dsmc_scene *s, double nu)
{
    switch (s->def.excluded) {
    case DSMC_EXCLUDED_FREE_VOLUME:
        return 1 / (1 - nu / s->def.packing_limit);
    case DSMC_EXCLUDED_ENSKOG:
        if (s->D == 2)
            return (1 - 7 * nu / 16) / ((1 - nu) * (1 - nu));
        return (1 - nu / 2) / ((1 - nu) * (1 - nu) * (1 - nu));
    case DSMC_EXCLUDED_NONE:
    default:
        return 1;
    }
}

/* ---- particles ------------------------------------------------------------------------------- */
int dsmc_resize(dsmc_scene *s, size_t cap)
{
    if (cap < s->n)
        cap = s->n;
    if (cap == 0)
        cap = 1;
    /* each array keeps its old contents on failure; the capacity is the smallest of them */
    int bad = 0;
    for (int k = 0; k < s->D; k++) {
        double *a = realloc(s->x[k], cap * sizeof(double));
        bad |= !a;
        s->x[k] = a ? a : s->x[k];
        a = realloc(s->v[k], cap * sizeof(double));
        bad |= !a;
        s->v[k] = a ? a : s->v[k];
    }
    uint32_t *c = realloc(s->cell, cap * sizeof *c);
    bad |= !c;
    s->cell = c ? c : s->cell;
    c = realloc(s->id, cap * sizeof *c);
    bad |= !c;
    s->id = c ? c : s->id;
    if (bad)
        return -1;
    s->cap = cap;
    return 0;
}

core_status dsmc_reserve(dsmc_scene *s, size_t n, core_error *err)
{
    if (n <= s->cap)
        return CORE_OK;
    size_t cap = 2 * s->cap > n ? 2 * s->cap : n; /* exact on a first fill */
    if (dsmc_resize(s, cap) && dsmc_resize(s, n))
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu particles", n);
    return CORE_OK;
}

static core_status check_room(const dsmc_scene *s, size_t n, const char *what, core_error *err)
{
    /* Positions, velocities (3 + 3 doubles), a cell index and an identity per particle, within
     * the same budget as the cell grid, for the same reason (overcommitted allocations). */
    const double budget = core_memory_budget(), per = 6 * sizeof(double) + 2 * sizeof(uint32_t);
    if (((double)s->n + (double)n) * per > budget)
        return core_fail(err, CORE_ERR_ARG,
                         "%s %zu particles: %zu particles need %.3g bytes, above the limit of "
                         "%.3g bytes (the machine's memory, or GRAINLAB_MEMORY_LIMIT) (field 'n')",
                         what, n, s->n + n, ((double)s->n + (double)n) * per, budget);
    if ((double)s->next_id + (double)n > 4294967296.0)
        return core_fail(err, CORE_ERR_ARG,
                         "%s %zu particles: a scene numbers at most 2^32 particles over its life "
                         "(%.0f numbered already)", what, n, (double)s->next_id);
    size_t cap = dsmc_capacity(s);
    if (n > cap || s->n + n > cap)
        return core_fail(err, CORE_ERR_ARG,
                         "%s %zu particles: the box holds at most %zu at the packing limit "
                         "nu_rcp = %g (%zu already in; packing fraction would be %.3g)",
                         what, n, cap, s->def.packing_limit, s->n,
                         (double)(s->n + n) * s->vpart / dsmc_volume(s));
    return CORE_OK;
}

static void after_add(dsmc_scene *s, size_t first)
{
    for (size_t i = first; i < s->n; i++) {
        s->cell[i] = dsmc_cell_of(s, s->x[0][i], s->x[1][i], s->D == 3 ? s->x[2][i] : 0);
        s->id[i] = (uint32_t)s->next_id++;
    }
    dsmc_sort(s);
}

dsmc_fill_def dsmc_default_fill_def(void)
{
    dsmc_fill_def f;
    memset(&f, 0, sizeof f);
    f.seed = 1;
    return f;
}

core_status dsmc_fill(dsmc_scene *s, const dsmc_fill_def *f, core_error *err)
{
    int D = s->D;
    if (s->distributed)
        return core_fail(err, CORE_ERR_STATE, "the scene is distributed: dsmc_gather first");
    if (f->temperature < 0 || f->speed < 0 || !isfinite(f->temperature) || !isfinite(f->speed))
        return core_fail(err, CORE_ERR_ARG, "temperature and speed must be finite and >= 0");
    if (f->temperature > 0 && f->speed > 0)
        return core_fail(err, CORE_ERR_ARG, "give temperature or speed, not both");
    double lo[3], hi[3];
    bool whole = true;
    for (int k = 0; k < D; k++)
        whole = whole && f->lo[k] == f->hi[k];
    for (int k = 0; k < D; k++) {
        lo[k] = whole ? s->def.lo[k] : f->lo[k];
        hi[k] = whole ? s->def.hi[k] : f->hi[k];
        if (!(hi[k] > lo[k]) || lo[k] < s->def.lo[k] || hi[k] > s->def.hi[k])
            return core_fail(err, CORE_ERR_ARG,
                             "the region's %c extent [%g, %g] must be non-empty and inside the box "
                             "[%g, %g]", AXIS[k], lo[k], hi[k], s->def.lo[k], s->def.hi[k]);
    }
    core_status st = check_room(s, f->n, "cannot add", err);
    if (st)
        return st;
    /* The region alone must not be overpacked either. */
    double vol = 1;
    for (int k = 0; k < D; k++)
        vol *= hi[k] - lo[k];
    if ((double)f->n * s->vpart > s->def.packing_limit * vol)
        return core_fail(err, CORE_ERR_ARG,
                         "cannot add %zu particles: the region holds at most %.0f at the packing "
                         "limit nu_rcp = %g (packing fraction would be %.3g)", f->n,
                         floor(s->def.packing_limit * vol / s->vpart), s->def.packing_limit,
                         (double)f->n * s->vpart / vol);
    if ((st = dsmc_reserve(s, s->n + f->n, err)))
        return st;
    rng r;
    rng_seed(&r, f->seed, 0);
    double sd = sqrt(f->temperature / s->mass);
    size_t first = s->n;
    for (size_t i = first; i < first + f->n; i++) {
        for (int k = 0; k < D; k++)
            s->x[k][i] = lo[k] + (hi[k] - lo[k]) * rng_uniform(&r);
        double v[3] = {0, 0, 0};
        if (f->speed > 0) { /* a uniform direction: a normal vector, normalised */
            double q = 0;
            do {
                q = 0;
                for (int k = 0; k < D; k++) {
                    v[k] = rng_normal(&r);
                    q += v[k] * v[k];
                }
            } while (q < 1e-12);
            q = f->speed / sqrt(q);
            for (int k = 0; k < D; k++)
                v[k] *= q;
        } else {
            for (int k = 0; k < D; k++)
                v[k] = sd * rng_normal(&r);
        }
        for (int k = 0; k < D; k++)
            s->v[k][i] = v[k] + f->velocity[k];
    }
    s->n += f->n;
    after_add(s, first);
    return CORE_OK;
}

core_status dsmc_add(dsmc_scene *s, size_t n, const double *x, const double *y, const double *z,
                     const double *vx, const double *vy, const double *vz, core_error *err)
{
    const double *p[3] = {x, y, z}, *v[3] = {vx, vy, vz};
    if (s->distributed)
        return core_fail(err, CORE_ERR_STATE, "the scene is distributed: dsmc_gather first");
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < s->D; k++) {
            if (!isfinite(p[k][i]) || !isfinite(v[k][i]))
                return core_fail(err, CORE_ERR_ARG, "particle %zu: non-finite position or "
                                 "velocity", i + 1);
            if (p[k][i] < s->def.lo[k] || p[k][i] > s->def.hi[k])
                return core_fail(err, CORE_ERR_ARG, "particle %zu: %c = %g is outside the box "
                                 "[%g, %g]", i + 1, AXIS[k], p[k][i], s->def.lo[k], s->def.hi[k]);
        }
    core_status st = check_room(s, n, "cannot add", err);
    if (st || (st = dsmc_reserve(s, s->n + n, err)))
        return st;
    size_t first = s->n;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < s->D; k++) {
            s->x[k][first + i] = p[k][i];
            s->v[k][first + i] = v[k][i];
        }
    s->n += n;
    after_add(s, first);
    return CORE_OK;
}

void dsmc_get_particles(const dsmc_scene *s, dsmc_particles *p)
{
    for (int k = 0; k < 3; k++) {
        p->x[k] = k < s->D ? s->x[k] : NULL;
        p->v[k] = k < s->D ? s->v[k] : NULL;
    }
    p->cell = s->cell;
    p->id = s->id;
}

/* ---- walls ----------------------------------------------------------------------------------- */
dsmc_wall_def dsmc_default_wall_def(void)
{
    dsmc_wall_def w;
    memset(&w, 0, sizeof w);
    w.kind = DSMC_WALL_SPECULAR;
    w.restitution = 1;
    return w;
}

core_status dsmc_set_wall(dsmc_scene *s, int side, const dsmc_wall_def *w, core_error *err)
{
    static const char *const names[6] = {"x low", "x high", "y low", "y high", "z low", "z high"};
    if (side < 0 || side >= 2 * s->D)
        return core_fail(err, CORE_ERR_ARG, "side %d does not exist in %dD", side, s->D);
    int axis = side / 2;
    if (s->def.periodic[axis])
        return core_fail(err, CORE_ERR_ARG, "the %s side is on a periodic axis (no walls there)",
                         names[side]);
    if (!(w->restitution >= 0 && w->restitution <= 1))
        return core_fail(err, CORE_ERR_ARG, "wall restitution must be in [0, 1], got %g",
                         w->restitution);
    if (w->kind == DSMC_WALL_DIFFUSE && (!(w->temperature > 0) || !isfinite(w->temperature)))
        return core_fail(err, CORE_ERR_ARG, "a diffuse wall needs a positive temperature, got %g",
                         w->temperature);
    if (!(w->amplitude >= 0) || !isfinite(w->amplitude) || !(w->frequency >= 0) ||
        !isfinite(w->frequency) || !isfinite(w->phase))
        return core_fail(err, CORE_ERR_ARG, "amplitude and frequency must be finite and >= 0");
    double span = s->def.hi[axis] - s->def.lo[axis];
    if (2 * w->amplitude >= 0.5 * span)
        return core_fail(err, CORE_ERR_ARG,
                         "the wall's stroke 2 x amplitude = %g m takes more than half the box "
                         "(%g m along %c)", 2 * w->amplitude, span, AXIS[axis]);
    for (int k = 0; k < 3; k++)
        if (!isfinite(w->velocity[k]))
            return core_fail(err, CORE_ERR_ARG, "wall velocity must be finite");
    s->walls[side] = *w;
    s->walls[side].velocity[axis] = 0; /* only tangential components count */
    return CORE_OK;
}

const dsmc_wall_def *dsmc_wall(const dsmc_scene *s, int side) { return &s->walls[side]; }

void dsmc_wall_motion(const dsmc_scene *s, int side, double t, double *pos, double *vel)
{
    const dsmc_wall_def *w = &s->walls[side];
    int axis = side / 2;
    double sign = side % 2 == 0 ? 1 : -1;
    double base = side % 2 == 0 ? s->def.lo[axis] : s->def.hi[axis];
    if (w->amplitude == 0) {
        *pos = base;
        *vel = 0;
        return;
    }
    double om = 2 * DSMC_PI * w->frequency, ph = om * t + w->phase;
    *pos = base + sign * w->amplitude * (1 + sin(ph));
    *vel = sign * w->amplitude * om * cos(ph);
}

/* ---- validity (paper Sec. 4, conditions i-iii) ---------------------------------------------- */
core_status dsmc_check_validity(const dsmc_scene *s, double dt, dsmc_validity *out,
                                core_error *err)
{
    memset(out, 0, sizeof *out);
    size_t N = dsmc_count(s);
    if (N < 2)
        return core_fail(err, CORE_ERR_STATE, "the scene has %zu particles (2 or more needed)", N);
    /* an integer sum: the same on any number of ranks */
    int64_t sum2 = 0;
    for (size_t c = s->cell_lo; c < s->cell_hi; c++) {
        int64_t nc = (int64_t)(s->start[c + 1] - s->start[c]);
        sum2 += nc * (nc - 1);
    }
    if (s->distributed)
        comm_sum_i64(&sum2, 1);
    double n = (double)sum2 / ((double)N * s->cell_volume);
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    double sd = 2 * s->def.radius;
    out->density = n;
    out->packing = n * s->vpart;
    out->chi = dsmc_chi(s, fmin(out->packing, 0.99 * s->def.packing_limit));
    double omega;
    if (s->D == 2) {
        out->mean_free_path = 1 / (2 * sqrt(2.0) * n * sd * out->chi);
        omega = 2 * sqrt(DSMC_PI) * out->chi * n * sd * sqrt(m.t_over_m);
    } else {
        out->mean_free_path = 1 / (sqrt(2.0) * DSMC_PI * n * sd * sd * out->chi);
        omega = 4 * sqrt(DSMC_PI) * out->chi * n * sd * sd * sqrt(m.t_over_m);
    }
    double side = INFINITY, cell = 0;
    for (int k = 0; k < s->D; k++) {
        side = fmin(side, s->def.hi[k] - s->def.lo[k]);
        cell = fmax(cell, s->h[k]);
    }
    out->knudsen = out->mean_free_path / side;
    out->cell_size = cell;
    out->collision_time = omega > 0 ? 1 / omega : INFINITY;
    out->dt = dt;
    out->collisional = out->knudsen < 1;
    out->cells_ok = out->mean_free_path > cell;
    out->dt_ok = out->collision_time > dt;
    return CORE_OK;
}
