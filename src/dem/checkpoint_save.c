/* DEM checkpoints, the writing side: the sections checkpoint.c reads back (its header says what
 * they hold and why). */
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dem/dem_internal.h"

/* An array that may be absent: a presence flag, then the values. */
static void put_opt(ckpt_writer *w, const double *a, size_t n)
{
    ckpt_put_u32(w, a != NULL);
    if (a)
        ckpt_put_f64s(w, a, n);
}

static void put_i32s(ckpt_writer *w, const int *a, size_t n)
{
    ckpt_put_u64(w, n);
    for (size_t k = 0; k < n; k++)
        ckpt_put_i64(w, a[k]);
}

static core_status end(ckpt_writer *w, core_error *err) { return ckpt_section_end(w, err); }

static void put_contact(ckpt_writer *w, const dem_contact_def *c)
{
    ckpt_put_u32(w, (uint32_t)c->normal);
    ckpt_put_f64(w, c->stiffness);
    ckpt_put_f64(w, c->beta);
    ckpt_put_u32(w, (uint32_t)c->damping);
    ckpt_put_f64(w, c->gamma_n);
    ckpt_put_f64(w, c->damping_time);
    ckpt_put_f64(w, c->restitution);
    ckpt_put_f64(w, c->impact_velocity);
    ckpt_put_u32(w, (uint32_t)c->tangential);
    ckpt_put_f64(w, c->gamma_t);
    ckpt_put_f64(w, c->kt);
    ckpt_put_f64(w, c->v_r);
    ckpt_put_f64(w, c->exponent);
    ckpt_put_u32(w, c->clip);
    ckpt_put_u32(w, c->rolling);
}

/* Rolling resistance (rolling.inc) has its own section, written only by a scene that uses it (a
 * rolling law, or a material with a rolling friction): a file without it loads as before, and a
 * grainlab without rolling resistance refuses a file with it by the section's name. It holds the
 * law, the materials' mu_r, and the rolling spring's history of the pairs and walls. */
static int uses_rolling(const dem_scene *s)
{
    int used = s->contact.rolling_law != DEM_ROLLING_NONE;
    for (int k = 0; k < s->nmat; k++)
        used |= s->mats[k].rolling_friction != 0;
    return used;
}

static core_status write_rolling(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    core_status st;
    if ((st = ckpt_section_begin(w, "rolling", CKPT_REQUIRED, err)))
        return st;
    const dem_contact_def *c = &s->contact;
    ckpt_put_u32(w, (uint32_t)c->rolling_law);
    ckpt_put_f64(w, c->rolling_friction);
    ckpt_put_f64(w, c->rolling_stiffness);
    ckpt_put_f64(w, c->rolling_damping);
    ckpt_put_f64(w, c->rolling_rate);
    ckpt_put_u64(w, (uint64_t)s->nmat);
    for (int k = 0; k < s->nmat; k++)
        ckpt_put_f64(w, s->mats[k].rolling_friction);
    for (int d = 0; d < 3; d++)
        put_opt(w, s->pairs.hist[DEM_HIST_ROLL + d], s->pairs.n);
    ckpt_put_u64(w, (uint64_t)s->nwalls);
    for (int k = 0; k < s->nwalls; k++)
        for (int d = 0; d < 3; d++)
            put_opt(w, s->walls[k].hist[DEM_HIST_ROLL + d], s->n);
    return end(w, err);
}

/* Cohesion (cohesion.h) has its own section too, written only by a scene that uses it (a JKR or
 * DMT law, a liquid bridge, or a material with a work of adhesion): the contact's values, the
 * materials' work of adhesion, and which pairs' and planes' cohesive contacts hold. */
static int uses_cohesion(const dem_scene *s)
{
    int used = dem_cohesive(&s->contact);
    for (int k = 0; k < s->nmat; k++)
        used |= s->mats[k].adhesion != 0;
    return used;
}

static core_status write_cohesion(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    core_status st;
    if ((st = ckpt_section_begin(w, "cohesion", CKPT_REQUIRED, err)))
        return st;
    const dem_contact_def *c = &s->contact;
    ckpt_put_f64(w, c->adhesion);
    ckpt_put_u32(w, (uint32_t)c->cohesion);
    ckpt_put_f64(w, c->liquid_volume);
    ckpt_put_f64(w, c->surface_tension);
    ckpt_put_f64(w, c->contact_angle);
    ckpt_put_u64(w, (uint64_t)s->nmat);
    for (int k = 0; k < s->nmat; k++)
        ckpt_put_f64(w, s->mats[k].adhesion);
    put_opt(w, s->pairs.hist[DEM_HIST_BOND], s->pairs.n);
    ckpt_put_u64(w, (uint64_t)s->nwalls);
    for (int k = 0; k < s->nwalls; k++)
        put_opt(w, s->walls[k].hist[DEM_HIST_BOND], s->n);
    return end(w, err);
}

/* Damping solved from a restitution (restitution.c) has its own section, written only by a
 * scene whose law uses it: the coefficients of s:contact's restitution and of each material, as
 * they were solved (a file without it, from a scene whose law needs it, is refused). */
int dem_checkpoint_damping(const dem_contact_def *c)
{
    return dem_damping_solved(c) ||
           (c->damping == DEM_DAMPING_VISCOUS && c->restitution > 0 && c->gamma_n < 0 &&
            (c->clip || dem_law_beta(c) != 1));
}

static core_status write_damping(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    core_status st;
    if ((st = ckpt_section_begin(w, "damping", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_f64(w, s->damp_c);
    static const double none = 0; /* a scene without materials may have no table */
    ckpt_put_f64s(w, s->nmat > 0 ? s->mat_damp : &none, (size_t)s->nmat); /* count, values */
    return end(w, err);
}

/* Particles by id: every per-particle array the steps read. */
static core_status write_particles(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const size_t n = s->n;
    const int D = s->dim, d0 = D == 2 ? 2 : 0;
    core_status st;
    if ((st = ckpt_section_begin(w, "particles", CKPT_REQUIRED, err)))
        return st;
    for (int d = 0; d < D; d++) {
        ckpt_put_f64s(w, s->x[d], n);
        ckpt_put_f64s(w, s->v[d], n);
        ckpt_put_f64s(w, s->f[d], n);
        ckpt_put_f64s(w, s->x_build[d], n);
    }
    ckpt_put_f64s(w, s->r, n);
    ckpt_put_f64s(w, s->m, n);
    ckpt_put_f64s(w, s->inv_m, n);
    ckpt_put_f64s(w, s->inv_inertia, n);
    put_i32s(w, s->mat, n);
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, s->flags, n);
    for (int d = d0; d < 3; d++) {
        put_opt(w, s->w[d], n);
        put_opt(w, s->tq[d], n);
    }
    put_opt(w, s->angle, n);
    for (int d = 0; d < D; d++) {
        put_opt(w, s->fext[d], n);
        put_opt(w, s->x_ref[d], n);
        put_opt(w, s->x_prev[d], n);
    }
    for (int k = 0; k < 6; k++) {
        for (int d = 0; d < D; d++)
            put_opt(w, s->gear[k][d], n);
        for (int d = d0; d < 3; d++)
            put_opt(w, s->gear_w[k][d], n);
    }
    return end(w, err);
}

/* The walls as planes (a wall beyond planes adds its shape: dem_shapes_save). */
static core_status write_walls(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const size_t n = s->n;
    core_status st;
    if ((st = ckpt_section_begin(w, "walls", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_u64(w, (uint64_t)s->nwalls);
    for (int k = 0; k < s->nwalls; k++) {
        const dem_wall *wl = &s->walls[k];
        ckpt_put_u32(w, (uint32_t)wl->active);
        ckpt_put_bytes(w, wl->point, sizeof wl->point);
        ckpt_put_bytes(w, wl->normal, sizeof wl->normal);
        ckpt_put_bytes(w, wl->velocity, sizeof wl->velocity);
        ckpt_put_f64(w, wl->friction);
        ckpt_put_i64(w, wl->material);
        ckpt_put_bytes(w, wl->point_build, sizeof wl->point_build);
        ckpt_put_f64(w, wl->fn);
        ckpt_put_u32(w, (uint32_t)wl->servo);
        ckpt_put_f64(w, wl->servo_force);
        ckpt_put_f64(w, wl->servo_mass);
        ckpt_put_f64(w, wl->servo_rate);
        for (int d = 0; d < 4; d++)
            put_opt(w, wl->hist[d], n);
        ckpt_put_u32s(w, wl->cand, wl->ncand);
    }
    return end(w, err);
}

static core_status write_scene(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const size_t n = s->n;
    const int D = s->dim;
    core_status st;
    if ((st = ckpt_section_begin(w, "scene", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_u32(w, (uint32_t)D);
    ckpt_put_bytes(w, s->lo, sizeof s->lo);
    ckpt_put_bytes(w, s->hi, sizeof s->hi);
    for (int d = 0; d < 3; d++)
        ckpt_put_u32(w, s->periodic[d]);
    ckpt_put_bytes(w, s->gravity, sizeof s->gravity);
    ckpt_put_f64(w, s->thickness);
    ckpt_put_f64(w, s->drag);
    ckpt_put_f64(w, s->skin_def);
    ckpt_put_f64(w, s->skin);
    ckpt_put_f64(w, s->r_max);
    ckpt_put_u64(w, n);
    ckpt_put_u32(w, (uint32_t)s->rot);
    ckpt_put_f64(w, s->time);
    ckpt_put_i64(w, s->steps);
    ckpt_put_i64(w, s->force_evals);
    ckpt_put_i64(w, s->last_integrator);
    ckpt_put_i64(w, s->tt_phase);
    ckpt_put_u32(w, (uint32_t)s->gear_ready);
    ckpt_put_u32(w, (uint32_t)s->prev_ready);
    ckpt_put_u32(w, (uint32_t)s->forces_ready);
    ckpt_put_u32(w, (uint32_t)s->suspect);
    ckpt_put_u32(w, (uint32_t)s->need_rebuild);
    ckpt_put_f64(w, s->gear_dt);
    ckpt_put_f64(w, s->prev_dt);
    ckpt_put_u32(w, (uint32_t)s->watch_on);
    ckpt_put_i64(w, s->watch_next);
    ckpt_put_i64(w, s->watch_min_step);
    ckpt_put_f64(w, s->watch_min);
    ckpt_put_f64(w, s->watch_min_t);
    ckpt_put_f64(w, s->watch_scale);
    ckpt_put_f64(w, s->brill_c);
    if ((st = end(w, err)))
        return st;

    if ((st = ckpt_section_begin(w, "contact", CKPT_REQUIRED, err)))
        return st;
    put_contact(w, &s->contact);
    if ((st = end(w, err)))
        return st;

    if ((st = ckpt_section_begin(w, "materials", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_u64(w, (uint64_t)s->nmat);
    for (int k = 0; k < s->nmat; k++) {
        const dem_material *m = &s->mats[k];
        const double v[5] = {m->density, m->young, m->poisson, m->friction, m->restitution};
        ckpt_put_f64s(w, v, 5);
    }
    if ((st = end(w, err)))
        return st;

    if ((st = write_particles(s, w, err)) || (st = write_walls(s, w, err)))
        return st;
    int shaped = 0; /* walls beyond planes: their own section, absent from a scene without them */
    for (int k = 0; k < s->nwalls; k++)
        shaped |= s->walls[k].shape != NULL;
    if (shaped && (st = dem_shapes_save(s, w, err)))
        return st;

    /* The Verlet list as built, with what each pair carries between steps. */
    const dem_pairs *p = &s->pairs;
    if ((st = ckpt_section_begin(w, "pairs", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_u32(w, p->start != NULL);
    ckpt_put_u64(w, p->np);
    ckpt_put_u32s(w, p->i, p->n);
    ckpt_put_u32s(w, p->j, p->n);
    ckpt_put_f64s(w, p->k, p->n);
    ckpt_put_f64s(w, p->gamma, p->n);
    ckpt_put_f64s(w, p->mu, p->n);
    for (int d = 0; d < 3; d++) {
        put_opt(w, p->f[d], p->n);
        put_opt(w, p->c[d], p->n);
    }
    for (int d = 0; d < 4; d++)
        put_opt(w, p->hist[d], p->n);
    if ((st = end(w, err)))
        return st;
    if (uses_rolling(s) && (st = write_rolling(s, w, err)))
        return st;
    if (uses_cohesion(s) && (st = write_cohesion(s, w, err)))
        return st;
    if (dem_checkpoint_damping(&s->contact) && (st = write_damping(s, w, err)))
        return st;
    if (s->bnd && (st = dem_boundary_save(s, w, err)))
        return st;
    if (s->flow && (st = dem_flow_save(s, w, err)))
        return st;
    return dem_clump_count(s) ? dem_clumps_save(s, w, err) : CORE_OK;
}

core_status dem_save(const dem_scene *s, const char *path, const char *version, core_error *err)
{
    ckpt_writer *w;
    core_status st = ckpt_writer_open(&w, path, "dem", version, err);
    if (st)
        return st;
    if ((st = write_scene(s, w, err))) {
        ckpt_writer_abort(w);
        return st;
    }
    return ckpt_writer_commit(w, err);
}
