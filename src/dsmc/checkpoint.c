/* DSMC checkpoints: the state of a gas that a bit-exact continuation needs, as sections of a
 * grainlab checkpoint (core/checkpoint.h), and a strict reader that builds a new scene from them.
 *
 * What is state: the definition (box, cells, periodic axes, gravity, restitution, radius, mass,
 * excluded-volume model, packing limit and the seed), the six walls with their prescribed motion,
 * the time and step count, the run statistics and the collision count, the fractional candidate
 * remainder each cell carries between steps (Eq. 1), and the particles in their array order.
 * The random numbers need no saved generator state: every cell's collisions and every diffuse
 * wall hit draw from a stream seeded by (seed, purpose, step, index) (dsmc_stream), so the seed
 * and the step count reproduce them. The array order is state: particles have no identity beyond
 * their slot and identity (section dsmc.ids: the identity orders each cell's particles and keys a
 * wall hit's stream). Between steps the array is sorted by cell, then identity; the reader checks
 * the cells and re-adds the particles in that order (the sort of dsmc_add then moves none), so the
 * cell offsets are rebuilt exactly. Nothing depends on the thread count or on the number of ranks
 * (a distributed scene is gathered before it is saved). A file without dsmc.ids (written before
 * identities existed) numbers the particles in file order. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dsmc/dsmc_internal.h"

#define TRY(x)                                                                                     \
    do {                                                                                           \
        if ((st = (x)) != CORE_OK)                                                                 \
            goto done;                                                                             \
    } while (0)

static void put_wall(ckpt_writer *w, const dsmc_wall_def *d)
{
    ckpt_put_i64(w, d->kind);
    ckpt_put_f64(w, d->restitution);
    ckpt_put_f64(w, d->temperature);
    ckpt_put_f64(w, d->amplitude);
    ckpt_put_f64(w, d->frequency);
    ckpt_put_f64(w, d->phase);
    for (int k = 0; k < 3; k++)
        ckpt_put_f64(w, d->velocity[k]);
}

core_status dsmc_save(const dsmc_scene *s, const char *path, const char *version, core_error *err)
{
    ckpt_writer *w = NULL;
    core_status st;
    TRY(ckpt_writer_open(&w, path, "dsmc", version, err));

    const dsmc_scene_def *d = &s->def;
    TRY(ckpt_section_begin(w, "dsmc.scene", CKPT_REQUIRED, err));
    ckpt_put_i64(w, d->dim);
    for (int k = 0; k < 3; k++) {
        ckpt_put_f64(w, d->lo[k]);
        ckpt_put_f64(w, d->hi[k]);
        ckpt_put_i64(w, d->cells[k]);
        ckpt_put_i64(w, d->periodic[k]);
        ckpt_put_f64(w, d->gravity[k]);
    }
    ckpt_put_f64(w, d->restitution);
    ckpt_put_f64(w, d->radius);
    ckpt_put_f64(w, d->mass);
    ckpt_put_f64(w, d->density);
    ckpt_put_i64(w, d->excluded);
    ckpt_put_f64(w, d->packing_limit);
    ckpt_put_u64(w, d->seed);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "dsmc.walls", CKPT_REQUIRED, err));
    for (int k = 0; k < 6; k++)
        put_wall(w, &s->walls[k]);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "dsmc.clock", CKPT_REQUIRED, err));
    ckpt_put_f64(w, s->t);
    ckpt_put_i64(w, s->steps);
    ckpt_put_f64(w, s->total_collisions);
    const dsmc_stats *c = &s->stats;
    ckpt_put_i64(w, c->steps);
    const double stats[9] = {c->particle_moves, c->attempts,    c->collisions,
                             c->wall_hits,      c->vmax_raised, c->cells_overpacked,
                             c->time,           c->cpu_s,       c->wall_s};
    for (int k = 0; k < 9; k++)
        ckpt_put_f64(w, stats[k]);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "dsmc.cells", CKPT_REQUIRED, err));
    ckpt_put_f64s(w, s->remainder, s->ncells);
    TRY(ckpt_section_end(w, err));

    /* before the particles, which stay the engine's last section (tests forge values at its end) */
    TRY(ckpt_section_begin(w, "dsmc.ids", CKPT_REQUIRED, err));
    ckpt_put_u64(w, s->next_id);
    ckpt_put_u32s(w, s->id, s->n);
    TRY(ckpt_section_end(w, err));

    TRY(ckpt_section_begin(w, "dsmc.particles", CKPT_REQUIRED, err));
    ckpt_put_u64(w, (uint64_t)s->n);
    for (int k = 0; k < s->D; k++) {
        ckpt_put_f64s(w, s->x[k], s->n);
        ckpt_put_f64s(w, s->v[k], s->n);
    }
    TRY(ckpt_section_end(w, err));


    st = ckpt_writer_commit(w, err);
    w = NULL;
done:
    ckpt_writer_abort(w);
    return st;
}

/* ---- reading ------------------------------------------------------------------------------ */
typedef struct reader {
    ckpt_section sec;
    core_error *err;
    const char *path;
} reader;

static core_status corrupt(const reader *rd, const char *what)
{
    return core_fail(rd->err, CORE_ERR_ARG, "'%s' is a corrupt dsmc checkpoint: %s", rd->path,
                     what);
}

/* A refusal of an engine call made for stored values (dsmc_create, dsmc_set_wall, ...), said as
 * the file's: "'PATH' is a corrupt dsmc checkpoint: radius must be positive, got -1". */
static core_status named(const reader *rd, core_status st)
{
    return ckpt_blame_file(rd->err, st, rd->path, "dsmc");
}

/* The grid against the file, before the grid is sized by the definition's cells: dsmc.cells
 * holds one remainder per cell. */
static core_status check_cells(ckpt_reader *r, reader *rd, const dsmc_scene_def *d)
{
    ckpt_section c;
    core_status st = ckpt_find(r, "dsmc.cells", &c, rd->err);
    uint64_t n = 0;
    if (st || (st = ckpt_get_u64(&c, &n, rd->err)))
        return st;
    double cells = 1;
    for (int k = 0; k < d->dim; k++)
        cells *= d->cells[k];
    if (cells != (double)n) {
        char what[200];
        snprintf(what, sizeof what,
                 "cells %d x %d x %d make %.17g cells, but section 'dsmc.cells' holds %llu",
                 d->cells[0], d->cells[1], d->dim == 3 ? d->cells[2] : 1, cells,
                 (unsigned long long)n);
        return corrupt(rd, what);
    }
    return CORE_OK;
}

static core_status get_int(reader *rd, long lo, long hi, const char *what, long *out)
{
    return ckpt_get_int_in(&rd->sec, lo, hi, what, out, rd->err);
}

static core_status get_num(reader *rd, const char *what, double *out)
{
    return ckpt_get_finite(&rd->sec, what, out, rd->err);
}

static core_status read_def(reader *rd, dsmc_scene_def *d)
{
    core_status st;
    long v;
    *d = dsmc_default_scene_def();
    TRY(get_int(rd, 2, 3, "dim", &v));
    d->dim = (int)v;
    for (int k = 0; k < 3; k++) {
        TRY(get_num(rd, "box", &d->lo[k]));
        TRY(get_num(rd, "box", &d->hi[k]));
        TRY(get_int(rd, 1, INT_MAX, "cells", &v));
        d->cells[k] = (int)v;
        TRY(get_int(rd, 0, 1, "periodic", &v));
        d->periodic[k] = v != 0;
        TRY(get_num(rd, "gravity", &d->gravity[k]));
    }
    TRY(get_num(rd, "restitution", &d->restitution));
    TRY(get_num(rd, "radius", &d->radius));
    TRY(get_num(rd, "mass", &d->mass));
    TRY(get_num(rd, "density", &d->density));
    TRY(get_int(rd, DSMC_EXCLUDED_NONE, DSMC_EXCLUDED_ENSKOG, "excluded volume", &v));
    d->excluded = (dsmc_excluded)v;
    TRY(get_num(rd, "packing limit", &d->packing_limit));
    TRY(ckpt_get_u64(&rd->sec, &d->seed, rd->err));
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_walls(reader *rd, dsmc_scene *s)
{
    core_status st;
    for (int side = 0; side < 6; side++) {
        dsmc_wall_def w = dsmc_default_wall_def();
        long kind;
        TRY(get_int(rd, DSMC_WALL_SPECULAR, DSMC_WALL_DIFFUSE, "wall kind", &kind));
        w.kind = (dsmc_wall_kind)kind;
        TRY(get_num(rd, "wall restitution", &w.restitution));
        TRY(get_num(rd, "wall temperature", &w.temperature));
        TRY(get_num(rd, "wall amplitude", &w.amplitude));
        TRY(get_num(rd, "wall frequency", &w.frequency));
        TRY(get_num(rd, "wall phase", &w.phase));
        for (int k = 0; k < 3; k++)
            TRY(get_num(rd, "wall velocity", &w.velocity[k]));
        if (side < 2 * s->D && !s->def.periodic[side / 2]) {
            /* a wall of the box: the same checks as s:wall, which keeps it as given */
            const double vn = w.velocity[side / 2];
            TRY(named(rd, dsmc_set_wall(s, side, &w, rd->err)));
            if (vn != 0)
                TRY(corrupt(rd, "a wall has a normal velocity"));
        } else {
            s->walls[side] = w; /* never used: a periodic side, or z in 2D */
        }
    }
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_clock(reader *rd, dsmc_scene *s)
{
    core_status st;
    long v;
    TRY(get_num(rd, "time", &s->t));
    TRY(get_int(rd, 0, CKPT_COUNTER_MAX, "steps", &v));
    s->steps = v;
    TRY(get_num(rd, "collisions", &s->total_collisions));
    dsmc_stats *c = &s->stats;
    TRY(get_int(rd, 0, CKPT_COUNTER_MAX, "stats steps", &v));
    c->steps = v;
    double *stats[9] = {&c->particle_moves, &c->attempts,    &c->collisions,
                        &c->wall_hits,      &c->vmax_raised, &c->cells_overpacked,
                        &c->time,           &c->cpu_s,       &c->wall_s};
    for (int k = 0; k < 9; k++)
        TRY(get_num(rd, "statistics", stats[k]));
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_cells(reader *rd, dsmc_scene *s)
{
    core_status st;
    TRY(ckpt_get_f64s(&rd->sec, s->remainder, s->ncells, rd->err));
    for (size_t c = 0; c < s->ncells; c++)
        if (!(s->remainder[c] >= 0 && s->remainder[c] < 1))
            TRY(corrupt(rd, "a cell's candidate remainder is outside [0, 1)"));
    st = ckpt_section_done(&rd->sec, rd->err);
done:
    return st;
}

static core_status read_particles(reader *rd, dsmc_scene *s)
{
    core_status st;
    uint64_t n64;
    double *a[6] = {NULL, NULL, NULL, NULL, NULL, NULL};
    TRY(ckpt_get_u64(&rd->sec, &n64, rd->err));
    const int D = s->D;
    if (n64 > rd->sec.size / (2 * (uint64_t)D * sizeof(double)) || n64 > dsmc_capacity(s))
        TRY(corrupt(rd, "the particle count does not fit the file or the box"));
    const size_t n = (size_t)n64;
    for (int k = 0; k < 2 * D; k++)
        if (!(a[k] = malloc((n ? n : 1) * sizeof(double))))
            TRY(core_fail(rd->err, CORE_ERR_NOMEM, "out of memory for %zu particles", n));
    for (int k = 0; k < D; k++) {
        TRY(ckpt_get_f64s(&rd->sec, a[k], n, rd->err));
        TRY(ckpt_get_f64s(&rd->sec, a[D + k], n, rd->err));
    }
    TRY(ckpt_section_done(&rd->sec, rd->err));
    /* between steps the particles are sorted by cell; re-adding them in that order keeps it */
    uint32_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        double v2 = 0;
        for (int k = 0; k < D; k++) {
            if (!isfinite(a[k][i]) || !isfinite(a[D + k][i]) || a[k][i] < s->def.lo[k] ||
                a[k][i] > s->def.hi[k])
                TRY(corrupt(rd, "a particle is outside the box or not finite"));
            v2 += a[D + k][i] * a[D + k][i];
        }
        if (!isfinite(v2 * s->mass))
            TRY(corrupt(rd, "a particle's kinetic energy is not finite"));
        const uint32_t c = dsmc_cell_of(s, a[0][i], a[1][i], D == 3 ? a[2][i] : 0);
        if (c < prev)
            TRY(corrupt(rd, "the particles are not in cell order"));
        prev = c;
    }
    if (n)
        TRY(named(rd, dsmc_add(s, n, a[0], a[1], D == 3 ? a[2] : NULL, a[D], a[D + 1],
                               D == 3 ? a[D + 2] : NULL, rd->err)));
done:
    for (int k = 0; k < 6; k++)
        free(a[k]);
    return st;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static core_status read_ids(reader *rd, dsmc_scene *s)
{
    core_status st;
    uint64_t next;
    uint32_t *sorted = NULL;
    TRY(ckpt_get_u64(&rd->sec, &next, rd->err));
    if (next < s->n || next > 4294967296ULL)
        TRY(corrupt(rd, "the next identity is out of range"));
    TRY(ckpt_get_u32s(&rd->sec, s->id, s->n, rd->err));
    TRY(ckpt_section_done(&rd->sec, rd->err));
    if (!(sorted = malloc((s->n ? s->n : 1) * sizeof *sorted)))
        TRY(core_fail(rd->err, CORE_ERR_NOMEM, "out of memory for %zu particles", s->n));
    if (s->n)
        memcpy(sorted, s->id, s->n * sizeof *sorted);
    qsort(sorted, s->n, sizeof *sorted, cmp_u32);
    for (size_t i = 0; i < s->n; i++)
        if (sorted[i] >= next || (i > 0 && sorted[i] == sorted[i - 1]))
            TRY(corrupt(rd, "particle identities repeat or exceed the next identity"));
    s->next_id = next;
    dsmc_sort(s); /* each cell in identity order, as it was saved */
done:
    free(sorted);
    return st;
}

static core_status read_scene(ckpt_reader *r, reader *rd, dsmc_scene **out)
{
    core_status st;
    dsmc_scene *s = NULL;
    dsmc_scene_def def;
    TRY(ckpt_find(r, "dsmc.scene", &rd->sec, rd->err));
    TRY(read_def(rd, &def));
    TRY(check_cells(r, rd, &def));
    TRY(named(rd, dsmc_create(&def, &s, rd->err)));
    TRY(ckpt_find(r, "dsmc.walls", &rd->sec, rd->err));
    TRY(read_walls(rd, s));
    TRY(ckpt_find(r, "dsmc.particles", &rd->sec, rd->err));
    TRY(read_particles(rd, s));
    if (ckpt_has(r, "dsmc.ids")) {
        TRY(ckpt_find(r, "dsmc.ids", &rd->sec, rd->err));
        TRY(read_ids(rd, s));
    }
    /* after the particles: dsmc_add leaves the remainders and the clock alone, but read them
     * last all the same so that nothing can overwrite them */
    TRY(ckpt_find(r, "dsmc.cells", &rd->sec, rd->err));
    TRY(read_cells(rd, s));
    TRY(ckpt_find(r, "dsmc.clock", &rd->sec, rd->err));
    TRY(read_clock(rd, s));
    TRY(ckpt_reader_finish(r, rd->err));
    *out = s;
    s = NULL;
done:
    dsmc_destroy(s);
    return st;
}

core_status dsmc_load(const char *path, dsmc_scene **out, core_error *err)
{
    *out = NULL;
    ckpt_reader *r = NULL;
    core_status st = ckpt_reader_open(&r, path, "dsmc", err);
    if (st)
        return st;
    reader rd = {.err = err, .path = ckpt_reader_path(r)};
    st = read_scene(r, &rd, out);
    ckpt_reader_close(r);
    return st;
}
