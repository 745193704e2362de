/* The checkpoint section of the walls beyond planes (walls.c): saved as they are, checked on
 * load as dem_add_shape_wall checks a new one. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dem/dem_internal.h"

/* Section "wall_shapes" (required: a grainlab without these walls must refuse the file): for each
 * shaped wall, its id, geometry, pose, motion and the load of the last evaluation. */
core_status dem_shapes_save(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    core_status st = ckpt_section_begin(w, "wall_shapes", CKPT_REQUIRED, err);
    if (st)
        return st;
    uint64_t count = 0;
    for (int k = 0; k < s->nwalls; k++)
        count += s->walls[k].shape != NULL;
    ckpt_put_u64(w, count);
    for (int k = 0; k < s->nwalls; k++) {
        const dem_shape *sh = s->walls[k].shape;
        if (!sh)
            continue;
        ckpt_put_i64(w, k);
        ckpt_put_i64(w, (int64_t)sh->kind);
        ckpt_put_f64s(w, sh->v, 3 * sh->nv);
        ckpt_put_u32s(w, sh->e, (sh->kind == DEM_WALL_TRIANGLES ? 3 : 2) * sh->ne);
        const double g[5] = {sh->radius, sh->axis[0], sh->axis[1], sh->axis[2], sh->half};
        ckpt_put_f64s(w, g, 5);
        ckpt_put_u32(w, (uint32_t)sh->inside);
        ckpt_put_u32(w, (uint32_t)sh->spins_in_place);
        ckpt_put_f64(w, sh->reach);
        ckpt_put_f64s(w, sh->center, 3);
        ckpt_put_f64(w, sh->angle);
        ckpt_put_f64s(w, sh->rot, 9);
        ckpt_put_f64s(w, sh->vel, 3);
        ckpt_put_f64s(w, sh->omega, 3);
        ckpt_put_f64s(w, sh->tab, 7 * sh->nt);
        ckpt_put_f64(w, sh->moved);
        ckpt_put_f64s(w, sh->force, 3);
        ckpt_put_f64s(w, sh->torque, 3);
        ckpt_put_u32s(w, sh->cand, sh->ncand);
    }
    return ckpt_section_end(w, err);
}

core_status dem_shapes_load(dem_scene *s, ckpt_section *sec, core_error *err)
{
    uint64_t count;
    core_status st = ckpt_get_u64(sec, &count, err);
    for (uint64_t c = 0; c < count && !st; c++) {
        long id, kind;
        if ((st = ckpt_get_int_in(sec, 0, s->nwalls - 1, "wall id", &id, err)) ||
            (st = ckpt_get_int_in(sec, DEM_WALL_SEGMENTS, DEM_WALL_CYLINDER, "wall kind", &kind,
                                  err)))
            break;
        dem_wall *wl = &s->walls[id];
        if (wl->shape) {
            st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (wall %ld has two shapes)",
                           ckpt_reader_path(sec->r), id + 1);
            break;
        }
        dem_shape *sh = wl->shape = calloc(1, sizeof *sh);
        if (!sh) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
            break;
        }
        sh->kind = (dem_wall_kind)kind;
        const size_t per = sh->kind == DEM_WALL_TRIANGLES ? 3 : 2;
        size_t n;
        if ((st = ckpt_peek_count(sec, (size_t)3 << 24, &n, err)))
            break;
        if (n % 3) {
            st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (vertex array)",
                           ckpt_reader_path(sec->r));
            break;
        }
        sh->nv = n / 3;
        if (!(sh->v = malloc((n ? n : 1) * sizeof *sh->v))) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
            break;
        }
        if ((st = ckpt_get_f64s(sec, sh->v, n, err)))
            break;
        if ((st = ckpt_peek_count(sec, (size_t)3 << 24, &n, err)))
            break;
        if (n % per) {
            st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (element array)",
                           ckpt_reader_path(sec->r));
            break;
        }
        sh->ne = n / per;
        if (!(sh->e = malloc((n ? n : 1) * sizeof *sh->e))) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
            break;
        }
        if ((st = ckpt_get_u32s(sec, sh->e, n, err)))
            break;
        for (size_t k = 0; k < n; k++)
            if (sh->e[k] >= sh->nv) {
                st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (vertex id out of range)",
                               ckpt_reader_path(sec->r));
                break;
            }
        if (st)
            break;
        double g[5];
        uint32_t inside, spins;
        if ((st = ckpt_get_f64s(sec, g, 5, err)) || (st = ckpt_get_u32(sec, &inside, err)) ||
            (st = ckpt_get_u32(sec, &spins, err)) || (st = ckpt_get_f64(sec, &sh->reach, err)) ||
            (st = ckpt_get_f64s(sec, sh->center, 3, err)) ||
            (st = ckpt_get_f64(sec, &sh->angle, err)) ||
            (st = ckpt_get_f64s(sec, sh->rot, 9, err)) ||
            (st = ckpt_get_f64s(sec, sh->vel, 3, err)) ||
            (st = ckpt_get_f64s(sec, sh->omega, 3, err)))
            break;
        sh->radius = g[0], sh->axis[0] = g[1], sh->axis[1] = g[2], sh->axis[2] = g[3];
        sh->half = g[4];
        sh->inside = inside != 0, sh->spins_in_place = spins != 0;
        if ((st = ckpt_peek_count(sec, (size_t)7 << 24, &n, err)))
            break;
        if (n % 7) {
            st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (motion table)",
                           ckpt_reader_path(sec->r));
            break;
        }
        sh->nt = n / 7;
        if (!(sh->tab = malloc((n ? n : 1) * sizeof *sh->tab))) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
            break;
        }
        if ((st = ckpt_get_f64s(sec, sh->tab, n, err)) ||
            (st = ckpt_get_f64(sec, &sh->moved, err)) ||
            (st = ckpt_get_f64s(sec, sh->force, 3, err)) ||
            (st = ckpt_get_f64s(sec, sh->torque, 3, err)))
            break;
        if (sh->kind == DEM_WALL_CYLINDER ? !(sh->radius > 0) : sh->ne == 0) {
            st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (wall geometry)",
                           ckpt_reader_path(sec->r));
            break;
        }
        /* every value finite, the motion's times increasing (as dem_add_shape checks them) */
        const double scalars[] = {sh->radius,  sh->axis[0], sh->axis[1],
                                  sh->axis[2], sh->angle,   sh->moved};
        int ok = dem_finite_n(sh->v, 3 * sh->nv) && dem_finite_n(scalars, 6) &&
                 dem_finite_n(sh->center, 3) && dem_finite_n(sh->rot, 9) &&
                 dem_finite_n(sh->vel, 3) && dem_finite_n(sh->omega, 3) &&
                 dem_finite_n(sh->tab, 7 * sh->nt) && dem_finite_n(sh->force, 3) &&
                 dem_finite_n(sh->torque, 3) && inside <= 1 && spins <= 1 && sh->half >= 0 &&
                 sh->reach >= 0; /* infinite for an endless cylinder */
        for (size_t k = 1; ok && k < sh->nt; k++)
            ok = sh->tab[7 * k] > sh->tab[7 * (k - 1)];
        if (!ok) {
            st = core_fail(err, CORE_ERR_IO,
                           "'%s' is corrupt (section '%s': wall %ld's geometry, pose or motion "
                           "holds a value that is not finite, or motion times that do not "
                           "increase)",
                           ckpt_reader_path(sec->r), sec->tag, id + 1);
            break;
        }
        if ((st = ckpt_peek_count(sec, s->n, &n, err)))
            break;
        sh->cand = malloc((n ? n : 1) * sizeof *sh->cand);
        sh->cload = malloc(DEM_SHAPE_LOAD * (n ? n : 1) * sizeof *sh->cload);
        sh->cap_cand = n ? n : 1;
        if (!sh->cand || !sh->cload) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
            break;
        }
        if ((st = ckpt_get_u32s(sec, sh->cand, n, err)))
            break;
        sh->ncand = n;
        for (size_t k = 0; k < n && !st; k++)
            if (sh->cand[k] >= s->n)
                st = core_fail(err, CORE_ERR_IO, "'%s' is corrupt (wall candidate out of range)",
                               ckpt_reader_path(sec->r));
        s->nshaped++;
    }
    return st ? st : ckpt_section_done(sec, err);
}
