/* DEM scenes: creation, materials, particles, walls and contact laws, each checked on entry. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/memory.h"
#include "dem/dem_internal.h"

dem_scene_def dem_default_scene_def(void)
{
    dem_scene_def d;
    memset(&d, 0, sizeof d);
    d.dim = 2;
    d.hi[0] = d.hi[1] = d.hi[2] = 1.0;
    return d;
}

dem_material dem_default_material(void)
{
    return (dem_material){.density = 2650, .young = 30e9, .poisson = 0.3, .friction = 0.45,
                          .restitution = 0.5};
}

dem_contact_def dem_default_contact_def(void)
{
    return (dem_contact_def){.normal = DEM_NORMAL_HERTZ,
                             .stiffness = 0,
                             .beta = 1.5,
                             .damping = DEM_DAMPING_NONE,
                             .gamma_n = -1,
                             .damping_time = -1,
                             .restitution = -1,
                             .impact_velocity = 1,
                             .tangential = DEM_TANGENT_NONE,
                             .gamma_t = 0,
                             .kt = -1,
                             .v_r = 1e-3,
                             .exponent = 10,
                             .clip = true,
                             .rolling = false,
                             .rolling_law = DEM_ROLLING_NONE,
                             .rolling_friction = -1,
                             .rolling_stiffness = -1,
                             .rolling_damping = 0,
                             .rolling_rate = 0,
                             .adhesion = -1,
                             .cohesion = DEM_COHESION_NONE,
                             .liquid_volume = 0,
                             .surface_tension = 0,
                             .contact_angle = 0};
}

void dem_invalidate(dem_scene *s, int list)
{
    s->forces_ready = 0;
    s->gear_ready = 0;
    s->prev_ready = 0;
    s->watch_on = 0; /* the energy may change from outside: a new reference */
    if (list)
        s->need_rebuild = 1;
    for (int w = 0; w < s->nwalls; w++) /* laws, materials or masses may have changed */
        s->walls[w].cand_par_ok = 0;
}

core_status dem_alloc_hot(double **a, size_t n, int k, core_error *err)
{
    double *p = core_realloc_staggered(*a, (n ? n : 1) * sizeof *p, k);
    if (!p)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu values", n);
    *a = p;
    return CORE_OK;
}

core_status dem_alloc_array(double **a, size_t n, core_error *err)
{
    double *p = realloc(*a, (n ? n : 1) * sizeof *p);
    if (!p)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu values", n);
    *a = p;
    return CORE_OK;
}

core_status dem_create(const dem_scene_def *def, dem_scene **out, core_error *err)
{
    *out = NULL;
    if (def->dim != 2 && def->dim != 3)
        return core_fail(err, CORE_ERR_ARG, "dim must be 2 or 3, got %d", def->dim);
    for (int d = 0; d < def->dim; d++) {
        if (!isfinite(def->lo[d]) || !isfinite(def->hi[d]) || !(def->hi[d] > def->lo[d]))
            return core_fail(err, CORE_ERR_ARG, "box axis %d: upper %g must exceed lower %g", d + 1,
                             def->hi[d], def->lo[d]);
        if (!isfinite(def->gravity[d]))
            return core_fail(err, CORE_ERR_ARG, "gravity component %d is not finite", d + 1);
    }
    if (!(def->thickness >= 0) || !isfinite(def->thickness))
        return core_fail(err, CORE_ERR_ARG, "thickness must be >= 0, got %g", def->thickness);
    if (!(def->skin >= 0) || !isfinite(def->skin))
        return core_fail(err, CORE_ERR_ARG, "skin must be >= 0, got %g", def->skin);
    dem_scene *s = calloc(1, sizeof *s);
    if (!s)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate a scene");
    s->dim = def->dim;
    for (int d = 0; d < 3; d++) {
        s->lo[d] = d < def->dim ? def->lo[d] : 0;
        s->hi[d] = d < def->dim ? def->hi[d] : 0;
        s->len[d] = s->hi[d] - s->lo[d];
        s->periodic[d] = d < def->dim && def->periodic[d];
        s->gravity[d] = d < def->dim ? def->gravity[d] : 0;
    }
    s->thickness = def->dim == 2 ? def->thickness : 0;
    s->skin_def = def->skin;
    s->contact = dem_default_contact_def();
    s->need_rebuild = 1;
    *out = s;
    return CORE_OK;
}

void dem_destroy(dem_scene *s)
{
    if (!s)
        return;
    dem_domain_free(s);
    dem_clear_boundary(s);
    dem_flow_free(s);
    dem_clumps_free(s);
    for (int d = 0; d < 3; d++) {
        core_free_staggered(s->x[d], DEM_HOT_X + d), core_free_staggered(s->v[d], DEM_HOT_V + d);
        core_free_staggered(s->f[d], DEM_HOT_F + d), core_free_staggered(s->w[d], DEM_HOT_W + d);
        core_free_staggered(s->tq[d], DEM_HOT_TQ + d);
        core_free_staggered(s->x_build[d], DEM_HOT_XB + d);
        free(s->x_ref[d]), free(s->x_prev[d]), free(s->fext[d]);
        for (int k = 0; k < 6; k++)
            free(s->gear[k][d]), free(s->gear_w[k][d]);
    }
    core_free_staggered(s->r, DEM_HOT_R), core_free_staggered(s->m, DEM_HOT_M);
    core_free_staggered(s->inv_m, DEM_HOT_INV_M);
    core_free_staggered(s->inv_inertia, DEM_HOT_INV_I);
    free(s->mat), free(s->flags);
    core_free_staggered(s->angle, DEM_HOT_ANGLE);
    for (int w = 0; w < s->nwalls; w++) {
        for (int d = 0; d < DEM_HIST; d++)
            free(s->walls[w].hist[d]);
        free(s->walls[w].cand), free(s->walls[w].cand_par);
        dem_shape_free(s->walls[w].shape);
    }
    free(s->walls), free(s->mats), free(s->mat_damp);
    dem_free_pairs(&s->pairs);
    free(s->cell_start), free(s->cell_items);
    free(s);
}

int dem_dim(const dem_scene *s) { return s->dim; }

/* ---- materials ------------------------------------------------------------------------------ */
int dem_add_material(dem_scene *s, const dem_material *m, core_error *err)
{
    if (!(m->density > 0) || !isfinite(m->density))
        return core_fail(err, CORE_ERR_ARG, "density must be > 0, got %g", m->density), -1;
    if (!(m->young > 0) || !isfinite(m->young))
        return core_fail(err, CORE_ERR_ARG, "young must be > 0, got %g", m->young), -1;
    if (!(m->poisson >= 0 && m->poisson < 0.5))
        return core_fail(err, CORE_ERR_ARG, "poisson must be in [0, 0.5), got %g", m->poisson), -1;
    if (!(m->friction >= 0) || !isfinite(m->friction))
        return core_fail(err, CORE_ERR_ARG, "friction must be >= 0, got %g", m->friction), -1;
    if (!(m->restitution > 0 && m->restitution <= 1))
        return core_fail(err, CORE_ERR_ARG, "restitution must be in (0, 1], got %g",
                         m->restitution), -1;
    if (!(m->rolling_friction >= 0) || !isfinite(m->rolling_friction))
        return core_fail(err, CORE_ERR_ARG, "rolling_friction must be >= 0, got %g",
                         m->rolling_friction),
               -1;
    if (!(m->adhesion >= 0) || !isfinite(m->adhesion))
        return core_fail(err, CORE_ERR_ARG, "work_of_adhesion must be >= 0, got %g", m->adhesion),
               -1;
    /* the damping its restitution gives under the scene's law (restitution.c) */
    double coef = 0;
    int same = 0;
    while (same < s->nmat && s->mats[same].restitution != m->restitution)
        same++;
    if (same < s->nmat)
        coef = s->mat_damp[same];
    else if (dem_damping_table(&s->contact, m, 1, &coef, err) != CORE_OK)
        return -1;
    if (s->nmat == s->cap_mat) {
        int cap = s->cap_mat ? 2 * s->cap_mat : 4;
        dem_material *p = realloc(s->mats, (size_t)cap * sizeof *p);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate materials"), -1;
        s->mats = p;
        double *q = realloc(s->mat_damp, (size_t)cap * sizeof *q);
        if (!q)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate materials"), -1;
        s->mat_damp = q;
        s->cap_mat = cap;
    }
    s->mats[s->nmat] = *m;
    s->mat_damp[s->nmat] = coef;
    dem_invalidate(s, 1); /* pair parameters depend on materials */
    return s->nmat++;
}

/* ---- contact law ---------------------------------------------------------------------------- */
/* The cohesive laws' values (cohesion.h) and what they compose with. */
static core_status check_cohesion(const dem_contact_def *c, core_error *err)
{
    if ((unsigned)c->cohesion >= DEM_COHESION_COUNT)
        return core_fail(err, CORE_ERR_ARG, "unknown cohesion law %d", (int)c->cohesion);
    if (!(c->adhesion < 0 || isfinite(c->adhesion)))
        return core_fail(err, CORE_ERR_ARG, "work_of_adhesion must be finite, got %g",
                         c->adhesion);
    if (c->cohesion != DEM_COHESION_CAPILLARY)
        return CORE_OK;
    if (c->normal == DEM_NORMAL_JKR || c->normal == DEM_NORMAL_DMT)
        return core_fail(err, CORE_ERR_ARG,
                         "cohesion 'capillary' adds a liquid bridge to the linear, power or hertz "
                         "law; the %s law has its own adhesion: choose one of the two",
                         dem_normal_names[c->normal]);
    if (!(c->liquid_volume > 0) || !isfinite(c->liquid_volume))
        return core_fail(err, CORE_ERR_ARG, "liquid_volume must be > 0, got %g", c->liquid_volume);
    if (!(c->surface_tension >= 0) || !isfinite(c->surface_tension))
        return core_fail(err, CORE_ERR_ARG, "surface_tension must be >= 0, got %g",
                         c->surface_tension);
    if (!(c->contact_angle >= 0 && c->contact_angle < DEM_PI))
        return core_fail(err, CORE_ERR_ARG, "contact_angle must be in [0, pi) rad, got %g",
                         c->contact_angle);
    return CORE_OK;
}

core_status dem_set_contact(dem_scene *s, const dem_contact_def *c, core_error *err)
{
    if ((unsigned)c->normal >= DEM_NORMAL_COUNT || (unsigned)c->damping >= DEM_DAMPING_COUNT ||
        (unsigned)c->tangential >= DEM_TANGENT_COUNT) /* laws.h's lists */
        return core_fail(err, CORE_ERR_ARG, "unknown contact law (normal %d, damping %d, "
                         "tangential %d)", (int)c->normal, (int)c->damping, (int)c->tangential);
    if (!dem_normal_from_moduli(c->normal)) {
        if (!(c->stiffness > 0) || !isfinite(c->stiffness))
            return core_fail(err, CORE_ERR_ARG, "stiffness must be > 0 for the %s law, got %g",
                             dem_normal_names[c->normal], c->stiffness);
    }
    if (c->normal == DEM_NORMAL_POWER && c->beta != 1 && c->beta != 1.5 && c->beta != 2)
        return core_fail(err, CORE_ERR_ARG, "beta must be 1, 1.5 or 2, got %g", c->beta);
    if (c->damping == DEM_DAMPING_BRILLIANTOV && !dem_normal_hertzian(c->normal))
        return core_fail(err, CORE_ERR_ARG,
                         "brilliantov damping needs the hertz, jkr or dmt normal law (with the %s "
                         "law, damping 'viscous' honours a restitution)",
                         dem_normal_names[c->normal]);
    core_status cst = check_cohesion(c, err);
    if (cst != CORE_OK)
        return cst;
    if (c->damping == DEM_DAMPING_BRILLIANTOV && !(c->damping_time < 0 || isfinite(c->damping_time)))
        return core_fail(err, CORE_ERR_ARG, "damping_time must be finite, got %g", c->damping_time);
    if (c->damping == DEM_DAMPING_VISCOUS && !(c->gamma_n < 0 || isfinite(c->gamma_n)))
        return core_fail(err, CORE_ERR_ARG, "gamma_n must be finite, got %g", c->gamma_n);
    /* A restitution asked of the contact: every law that can honour it does, or it is refused. */
    if (!(c->restitution < 0)) {
        if (!(c->restitution > 0 && c->restitution <= 1))
            return core_fail(err, CORE_ERR_ARG, "restitution must be in (0, 1], got %g",
                             c->restitution);
        if (c->damping == DEM_DAMPING_NONE && c->restitution < 1)
            return core_fail(err, CORE_ERR_ARG,
                             "restitution %g needs damping: damping 'none' rebounds with 1 (choose "
                             "damping 'viscous'%s)",
                             c->restitution, c->normal == DEM_NORMAL_HERTZ ? " or 'brilliantov'" : "");
        if (c->damping == DEM_DAMPING_VISCOUS && c->gamma_n >= 0)
            return core_fail(err, CORE_ERR_ARG,
                             "give gamma_n or restitution, not both (gamma_n is one coefficient "
                             "for every pair, restitution one per pair)");
        if (c->damping == DEM_DAMPING_BRILLIANTOV && c->damping_time >= 0)
            return core_fail(err, CORE_ERR_ARG,
                             "give damping_time or restitution, not both (damping_time is one T "
                             "for every pair, restitution one per pair)");
    }
    if (c->damping != DEM_DAMPING_NONE && !(c->impact_velocity > 0 && isfinite(c->impact_velocity)))
        return core_fail(err, CORE_ERR_ARG, "impact_velocity must be > 0, got %g",
                         c->impact_velocity);
    /* Solved once here; each pair's damping is then a power of its m_eff / k (neighbor.c). */
    double brill_c = 0, damp_c = 0;
    if (c->damping == DEM_DAMPING_BRILLIANTOV && c->restitution > 0) {
        double lambda;
        core_status st = dem_brilliantov_lambda(c->restitution, c->clip, &lambda, err);
        if (st != CORE_OK)
            return st;
        brill_c = lambda * pow(c->impact_velocity, -0.2);
    }
    if (c->damping == DEM_DAMPING_VISCOUS && c->restitution > 0 && c->gamma_n < 0 &&
        (c->clip || dem_law_beta(c) != 1)) {
        core_status st = dem_damping_coefficient(c, c->restitution, &damp_c, err);
        if (st != CORE_OK)
            return st;
    }
    if (c->tangential == DEM_TANGENT_VISCOUS && !(c->gamma_t >= 0 && isfinite(c->gamma_t)))
        return core_fail(err, CORE_ERR_ARG, "gamma_t must be >= 0, got %g", c->gamma_t);
    if (c->tangential == DEM_TANGENT_SPRING && !(c->kt < 0 || (c->kt > 0 && isfinite(c->kt))))
        return core_fail(err, CORE_ERR_ARG, "kt must be > 0, got %g", c->kt);
    if ((unsigned)c->rolling_law >= DEM_ROLLING_COUNT)
        return core_fail(err, CORE_ERR_ARG, "unknown rolling resistance law %d",
                         (int)c->rolling_law);
    if (!(c->rolling_friction < 0 || isfinite(c->rolling_friction)))
        return core_fail(err, CORE_ERR_ARG, "rolling_friction must be finite, got %g",
                         c->rolling_friction);
    if (!(c->rolling_stiffness < 0 || (c->rolling_stiffness > 0 && isfinite(c->rolling_stiffness))))
        return core_fail(err, CORE_ERR_ARG, "rolling_stiffness must be > 0, got %g",
                         c->rolling_stiffness);
    if (!(c->rolling_damping >= 0 && c->rolling_damping <= 1))
        return core_fail(err, CORE_ERR_ARG, "rolling_damping must be in [0, 1], got %g",
                         c->rolling_damping);
    if (!(c->rolling_rate >= 0 && isfinite(c->rolling_rate)))
        return core_fail(err, CORE_ERR_ARG, "rolling_rate must be >= 0, got %g", c->rolling_rate);
    if (c->tangential == DEM_TANGENT_REGULARIZED) {
        if (!(c->v_r > 0) || !isfinite(c->v_r))
            return core_fail(err, CORE_ERR_ARG, "v_r must be > 0, got %g", c->v_r);
        if (!(c->exponent >= 1) || !isfinite(c->exponent))
            return core_fail(err, CORE_ERR_ARG, "exponent must be >= 1, got %g", c->exponent);
    }
    double *mat_damp = NULL; /* the materials' coefficients under the new law */
    if (s->cap_mat > 0) {
        mat_damp = calloc((size_t)s->cap_mat, sizeof *mat_damp);
        if (!mat_damp)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate materials");
        core_status st = dem_damping_table(c, s->mats, s->nmat, mat_damp, err);
        if (st != CORE_OK) {
            free(mat_damp);
            return st;
        }
    }
    int spring_before = dem_tangent_history(s->contact.tangential);
    int bonds_before = dem_bonds(&s->contact);
    int roll_before = s->contact.rolling_law;
    s->contact = *c;
    s->brill_c = brill_c;
    s->damp_c = damp_c;
    free(s->mat_damp);
    s->mat_damp = mat_damp;
    dem_power_init(&s->slip_pow, c->tangential == DEM_TANGENT_REGULARIZED ? 1 / c->exponent : 0);
    if (c->tangential != DEM_TANGENT_NONE || c->rolling || c->rolling_law != DEM_ROLLING_NONE) {
        core_status st = dem_ensure_rotation(s, err);
        if (st != CORE_OK)
            return st;
    }
    if (spring_before != dem_tangent_history(c->tangential)) {
        for (int d = 0; d < 4; d++) { /* history is meaningless under another law */
            free(s->pairs.hist[d]);
            s->pairs.hist[d] = NULL;
            for (int w = 0; w < s->nwalls; w++) {
                free(s->walls[w].hist[d]);
                s->walls[w].hist[d] = NULL;
            }
        }
    }
    if (roll_before != (int)c->rolling_law) /* the same for the rolling history and torques */
        for (int d = 0; d < 3; d++) {
            free(s->pairs.hist[DEM_HIST_ROLL + d]);
            s->pairs.hist[DEM_HIST_ROLL + d] = NULL;
            free(s->pairs.rt[d]);
            s->pairs.rt[d] = NULL;
            for (int w = 0; w < s->nwalls; w++) {
                free(s->walls[w].hist[DEM_HIST_ROLL + d]);
                s->walls[w].hist[DEM_HIST_ROLL + d] = NULL;
            }
        }
    if (bonds_before != dem_bonds(c)) { /* the cohesive contacts that hold */
        free(s->pairs.hist[DEM_HIST_BOND]);
        s->pairs.hist[DEM_HIST_BOND] = NULL;
        for (int w = 0; w < s->nwalls; w++) {
            free(s->walls[w].hist[DEM_HIST_BOND]);
            s->walls[w].hist[DEM_HIST_BOND] = NULL;
        }
    }
    dem_invalidate(s, 1);
    return CORE_OK;
}

const dem_contact_def *dem_contact(const dem_scene *s) { return &s->contact; }

/* ---- particles ------------------------------------------------------------------------------ */
static core_status grow(dem_scene *s, size_t need, core_error *err)
{
    if (need <= s->cap)
        return CORE_OK;
    size_t cap = s->cap ? s->cap : 64;
    while (cap < need)
        cap *= 2;
    core_status st = CORE_OK;
    for (int d = 0; d < s->dim && st == CORE_OK; d++) {
        st = dem_alloc_hot(&s->x[d], cap, DEM_HOT_X + d, err);
        if (st == CORE_OK)
            st = dem_alloc_hot(&s->v[d], cap, DEM_HOT_V + d, err);
        if (st == CORE_OK)
            st = dem_alloc_hot(&s->f[d], cap, DEM_HOT_F + d, err);
        if (st == CORE_OK)
            st = dem_alloc_hot(&s->x_build[d], cap, DEM_HOT_XB + d, err);
        if (st == CORE_OK && s->x_ref[d])
            st = dem_alloc_array(&s->x_ref[d], cap, err);
        if (st == CORE_OK && s->x_prev[d])
            st = dem_alloc_array(&s->x_prev[d], cap, err);
        if (st == CORE_OK && s->fext[d]) {
            st = dem_alloc_array(&s->fext[d], cap, err);
            if (st == CORE_OK)
                memset(s->fext[d] + s->cap, 0, (cap - s->cap) * sizeof(double));
        }
        for (int k = 0; k < 6 && st == CORE_OK; k++) {
            if (st == CORE_OK && s->gear[k][d])
                st = dem_alloc_array(&s->gear[k][d], cap, err);
        }
    }
    for (int d = 0; d < 3 && st == CORE_OK; d++) {
        if (s->w[d])
            st = dem_alloc_hot(&s->w[d], cap, DEM_HOT_W + d, err);
        if (st == CORE_OK && s->tq[d])
            st = dem_alloc_hot(&s->tq[d], cap, DEM_HOT_TQ + d, err);
        for (int k = 0; k < 6 && st == CORE_OK; k++)
            if (s->gear_w[k][d])
                st = dem_alloc_array(&s->gear_w[k][d], cap, err);
        for (int w = 0; w < s->nwalls && st == CORE_OK; w++)
            for (int k = d; k < DEM_HIST; k += 3) /* components d (tangential, rolling), [3]
                                                   * once (with d = 0), [7] (with d = 1) */
                if (s->walls[w].hist[k] && (k != 3 || d == 0)) {
                    st = dem_alloc_array(&s->walls[w].hist[k], cap, err);
                    if (st == CORE_OK)
                        memset(s->walls[w].hist[k] + s->cap, 0, (cap - s->cap) * sizeof(double));
                }
    }
    if (st == CORE_OK && s->angle)
        st = dem_alloc_hot(&s->angle, cap, DEM_HOT_ANGLE, err);
    if (st == CORE_OK && s->tag)
        st = dem_alloc_array(&s->tag, cap, err);
    if (st == CORE_OK)
        st = dem_alloc_hot(&s->r, cap, DEM_HOT_R, err);
    if (st == CORE_OK)
        st = dem_alloc_hot(&s->m, cap, DEM_HOT_M, err);
    if (st == CORE_OK)
        st = dem_alloc_hot(&s->inv_m, cap, DEM_HOT_INV_M, err);
    if (st == CORE_OK)
        st = dem_alloc_hot(&s->inv_inertia, cap, DEM_HOT_INV_I, err);
    if (st != CORE_OK)
        return st;
    int *mat = realloc(s->mat, cap * sizeof *mat);
    if (mat)
        s->mat = mat;
    unsigned char *fl = realloc(s->flags, cap);
    if (fl)
        s->flags = fl;
    if (!mat || !fl)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu particles", cap);
    if (s->clumps && (st = dem_clumps_grow(s, s->cap, cap, err)))
        return st;
    s->cap = cap;
    return CORE_OK;
}

static double inertia_factor(const dem_scene *s)
{
    return (s->dim == 2 && s->thickness > 0) ? 0.5 : 0.4; /* cylinder : sphere */
}

core_status dem_ensure_rotation(dem_scene *s, core_error *err)
{
    if (s->rot)
        return CORE_OK;
    size_t cap = s->cap ? s->cap : 1;
    int d0 = s->dim == 2 ? 2 : 0;
    for (int d = d0; d < 3; d++) {
        if (dem_alloc_hot(&s->w[d], cap, DEM_HOT_W + d, err) || dem_alloc_hot(&s->tq[d], cap, DEM_HOT_TQ + d, err))
            return err ? err->status : CORE_ERR_NOMEM;
        memset(s->w[d], 0, cap * sizeof(double));
        memset(s->tq[d], 0, cap * sizeof(double));
    }
    if (s->dim == 2) {
        if (dem_alloc_hot(&s->angle, cap, DEM_HOT_ANGLE, err))
            return err ? err->status : CORE_ERR_NOMEM;
        memset(s->angle, 0, cap * sizeof(double));
    }
    s->rot = 1;
    dem_invalidate(s, 1);
    return CORE_OK;
}

long dem_add_particle(dem_scene *s, const dem_particle_def *p, core_error *err)
{
    const int D = s->dim;
    if (!(p->radius > 0) || !isfinite(p->radius))
        return core_fail(err, CORE_ERR_ARG, "radius must be > 0, got %g", p->radius), -1;
    if (p->material < 0 || p->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "unknown material %d", p->material), -1;
    if (s->n >= UINT32_MAX - 1)
        return core_fail(err, CORE_ERR_ARG, "too many particles"), -1;
    for (int d = 0; d < D; d++) {
        if (!isfinite(p->x[d]) || !isfinite(p->v[d]))
            return core_fail(err, CORE_ERR_ARG, "position and velocity must be finite"), -1;
        if (p->x[d] < s->lo[d] || p->x[d] > s->hi[d])
            return core_fail(err, CORE_ERR_ARG,
                             "position %g on axis %d is outside the box [%g, %g] (field 'pos')",
                             p->x[d], d + 1, s->lo[d], s->hi[d]),
                   -1;
    }
    /* Sizes against the box: a grain wider than the box is no grain of this scene, and a grain
     * so small that its contact overlaps (~1e-4 r) drown in the rounding of its coordinates
     * (2.2e-16 |x|) gives forces from noise. At r >= 1e-9 max|x| such an overlap still spans
     * about 450 ulps of the coordinate. */
    double extent = INFINITY, reach = 0;
    for (int d = 0; d < D; d++) {
        extent = fmin(extent, s->hi[d] - s->lo[d]);
        reach = fmax(reach, fmax(fabs(s->lo[d]), fabs(s->hi[d])));
    }
    if (p->radius > 0.5 * extent)
        return core_fail(err, CORE_ERR_ARG,
                         "radius %g is larger than half the box's smallest extent %g (field "
                         "'radius')",
                         p->radius, 0.5 * extent),
               -1;
    if (p->radius < 1e-9 * reach)
        return core_fail(err, CORE_ERR_ARG,
                         "radius %g is below 1e-9 of the largest box coordinate %g: its contacts "
                         "would be lost in the rounding of its position (field 'radius')",
                         p->radius, reach),
               -1;
    for (int d = 0; d < 3; d++)
        if (!isfinite(p->omega[d]))
            return core_fail(err, CORE_ERR_ARG, "angular velocity must be finite"), -1;
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        double dist = 0;
        if (wl->shape)
            dist = dem_shape_distance(s, wl, p->x);
        else
            for (int d = 0; d < D; d++)
                dist += (p->x[d] - wl->point[d]) * wl->normal[d];
        if (dist < p->radius * (1 - 1e-9)) /* touching is fine, up to rounding */
            return core_fail(err, CORE_ERR_ARG,
                             "particle at pos (%g, %g%s) overlaps wall %d: its centre is %g from "
                             "the wall, less than its radius %g",
                             p->x[0], p->x[1], D == 3 ? ", ..." : "", w + 1, dist, p->radius), -1;
    }
    core_status st = grow(s, s->n + 1, err);
    if (st != CORE_OK)
        return -1;
    size_t i = s->n;
    const dem_material *mat = &s->mats[p->material];
    double r = p->radius, vol;
    if (D == 2 && s->thickness > 0)
        vol = DEM_PI * r * r * s->thickness;
    else
        vol = 4.0 / 3.0 * DEM_PI * r * r * r;
    double m = mat->density * vol;
    for (int d = 0; d < D; d++) {
        s->x[d][i] = p->x[d];
        s->v[d][i] = (p->flags & DEM_FIXED) ? 0 : p->v[d];
        s->f[d][i] = 0;
        s->x_build[d][i] = p->x[d];
        if (s->x_ref[d])
            s->x_ref[d][i] = p->x[d];
        if (s->x_prev[d])
            s->x_prev[d][i] = 0; /* re-initialised from v before the next position-Verlet step */
    }
    for (int d = 0; d < 3; d++) {
        if (s->w[d])
            s->w[d][i] = (p->flags & DEM_FIXED) ? 0 : p->omega[d];
        if (s->tq[d])
            s->tq[d][i] = 0;
    }
    for (int w = 0; w < s->nwalls; w++)
        for (int k = 0; k < DEM_HIST; k++)
            if (s->walls[w].hist[k])
                s->walls[w].hist[k][i] = 0;
    if (s->angle)
        s->angle[i] = 0;
    s->r[i] = r;
    s->m[i] = m;
    s->inv_m[i] = (p->flags & (DEM_FIXED | DEM_PRESCRIBED)) ? 0 : 1 / m;
    s->inv_inertia[i] = (p->flags & (DEM_FIXED | DEM_PRESCRIBED))
                            ? 0
                            : 1 / (inertia_factor(s) * m * r * r);
    s->mat[i] = p->material;
    s->flags[i] = (unsigned char)p->flags;
    if (r > s->r_max)
        s->r_max = r;
    if (s->tag)
        dem_flow_tag_new(s, i);
    s->n++;
    dem_invalidate(s, 1);
    return (long)i;
}

size_t dem_count(const dem_scene *s) { return dem_domain_count(s); }
const double *dem_positions(const dem_scene *s, int d) { return s->x[d]; }
const double *dem_velocities(const dem_scene *s, int d) { return s->v[d]; }
const double *dem_angular_velocities(const dem_scene *s, int d) { return s->w[d]; }
const double *dem_radii(const dem_scene *s) { return s->r; }
const double *dem_angles(const dem_scene *s) { return s->angle; }
const int *dem_particle_materials(const dem_scene *s) { return s->mat; }
const double *dem_masses(const dem_scene *s) { return s->m; }
double dem_time(const dem_scene *s) { return s->time; }
long dem_steps_done(const dem_scene *s) { return s->steps; }
long dem_force_evaluations(const dem_scene *s) { return s->force_evals; }

core_status dem_set_velocity(dem_scene *s, size_t i, const double v[3], core_error *err)
{
    if (i >= s->n)
        return core_fail(err, CORE_ERR_ARG, "no particle %zu (the scene has %zu)", i + 1, s->n);
    for (int d = 0; d < s->dim; d++)
        if (!isfinite(v[d]))
            return core_fail(err, CORE_ERR_ARG, "velocity must be finite");
    if (s->flags[i] & DEM_FIXED)
        return core_fail(err, CORE_ERR_STATE, "particle %zu is fixed", i + 1);
    if (dem_is_member(s, i))
        return core_fail(err, CORE_ERR_STATE,
                         "particle %zu is a member of clump %ld: it moves with its clump", i + 1,
                         (long)s->clumps->body[i] + 1);
    for (int d = 0; d < s->dim; d++)
        s->v[d][i] = v[d];
    dem_invalidate(s, 0);
    return CORE_OK;
}

core_status dem_scale_mass(dem_scene *s, double factor, core_error *err)
{
    if (!(factor > 0) || !isfinite(factor))
        return core_fail(err, CORE_ERR_ARG, "mass scale factor must be > 0, got %g", factor);
    for (size_t i = 0; i < s->n; i++) {
        s->m[i] *= factor;
        s->inv_m[i] /= factor;
        s->inv_inertia[i] /= factor;
    }
    for (int k = 0; k < s->nmat; k++)
        s->mats[k].density *= factor;
    for (size_t k = 0; k < dem_clump_count(s); k++) { /* the same spin, a heavier body */
        dem_body *b = &s->clumps->b[k];
        b->mass *= factor;
        for (int d = 0; d < 3; d++)
            b->moment[d] *= factor, b->L[d] *= factor;
    }
    dem_invalidate(s, 1); /* damping coefficients depend on masses */
    return CORE_OK;
}

/* ---- walls ---------------------------------------------------------------------------------- */
int dem_add_wall(dem_scene *s, const dem_wall_def *w, core_error *err)
{
    const int D = s->dim;
    double nn = 0;
    for (int d = 0; d < D; d++) {
        if (!isfinite(w->point[d]) || !isfinite(w->normal[d]) || !isfinite(w->velocity[d]))
            return core_fail(err, CORE_ERR_ARG, "point, normal and velocity must be finite"), -1;
        nn += w->normal[d] * w->normal[d];
    }
    if (!(nn > 1e-24))
        return core_fail(err, CORE_ERR_ARG, "normal must not be zero"), -1;
    if (w->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "unknown material %d", w->material), -1;
    if (!isfinite(w->friction))
        return core_fail(err, CORE_ERR_ARG, "friction must be finite"), -1;
    dem_wall wl = {.active = 1, .friction = w->friction, .material = w->material};
    for (int d = 0; d < D; d++) {
        wl.point[d] = w->point[d];
        wl.normal[d] = w->normal[d] / sqrt(nn);
        wl.velocity[d] = w->velocity[d];
    }
    for (size_t i = 0; i < s->n; i++) {
        double dist = 0;
        for (int d = 0; d < D; d++)
            dist += (s->x[d][i] - wl.point[d]) * wl.normal[d];
        if (dist < s->r[i] * (1 - 1e-9))
            return core_fail(err, CORE_ERR_ARG,
                             "wall would overlap particle %zu (distance %g, radius %g)", i + 1,
                             dist, s->r[i]), -1;
    }
    for (int k = 0; k < s->nwalls; k++) {
        const dem_wall *o = &s->walls[k];
        if (!o->active || o->shape)
            continue;
        double dot = 0, off = 0;
        for (int d = 0; d < D; d++) {
            dot += o->normal[d] * wl.normal[d];
            off += (wl.point[d] - o->point[d]) * o->normal[d];
        }
        if (dot < -1 + 1e-12 && off <= 0) /* facing walls that leave no room between them */
            return core_fail(err, CORE_ERR_ARG, "wall overlaps wall %d (they face each other "
                             "with no space between)", k + 1), -1;
    }
    if (s->nwalls == s->cap_walls) {
        int cap = s->cap_walls ? 2 * s->cap_walls : 8;
        dem_wall *p = realloc(s->walls, (size_t)cap * sizeof *p);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate walls"), -1;
        s->walls = p;
        s->cap_walls = cap;
    }
    s->walls[s->nwalls] = wl;
    dem_invalidate(s, 1); /* the wall's candidate particles come with the next list build */
    return s->nwalls++;
}

static core_status check_wall(const dem_scene *s, int id, core_error *err)
{
    if (id < 0 || id >= s->nwalls || !s->walls[id].active)
        return core_fail(err, CORE_ERR_ARG, "no wall %d", id + 1);
    return CORE_OK;
}

core_status dem_remove_wall(dem_scene *s, int id, core_error *err)
{
    core_status st = check_wall(s, id, err);
    if (st == CORE_OK) {
        s->walls[id].active = 0;
        for (int d = 0; d < DEM_HIST; d++) {
            free(s->walls[id].hist[d]);
            s->walls[id].hist[d] = NULL;
        }
        dem_invalidate(s, 0);
    }
    return st;
}

core_status dem_set_wall_velocity(dem_scene *s, int id, const double v[3], core_error *err)
{
    core_status st = check_wall(s, id, err);
    if (st != CORE_OK)
        return st;
    dem_shape *sh = s->walls[id].shape;
    if (sh && sh->nt)
        return core_fail(err, CORE_ERR_ARG, "wall %d moves by its motion table", id + 1);
    for (int d = 0; d < s->dim; d++) {
        if (!isfinite(v[d]))
            return core_fail(err, CORE_ERR_ARG, "wall velocity must be finite");
    }
    for (int d = 0; d < s->dim; d++) /* a shaped wall's own (its plane velocity stays 0) */
        *(sh ? &sh->vel[d] : &s->walls[id].velocity[d]) = v[d];
    dem_invalidate(s, 0); /* damping and friction see the wall's velocity */
    return CORE_OK;
}

int dem_wall_count(const dem_scene *s) { return s->nwalls; }

core_status dem_wall_geometry(const dem_scene *s, int id, double point[3], double normal[3],
                              int *active, core_error *err)
{
    if (id < 0 || id >= s->nwalls)
        return core_fail(err, CORE_ERR_ARG, "no wall %d", id + 1);
    for (int d = 0; d < 3; d++) {
        point[d] = s->walls[id].point[d];
        normal[d] = s->walls[id].normal[d];
    }
    *active = s->walls[id].active && !s->walls[id].shape; /* planes only: see dem_wall_outline */
    return CORE_OK;
}

core_status dem_wall_force(const dem_scene *s, int id, double *fn, core_error *err)
{
    if (id < 0 || id >= s->nwalls || !s->walls[id].active)
        return core_fail(err, CORE_ERR_ARG, "no wall %d", id + 1);
    *fn = s->walls[id].fn;
    return CORE_OK;
}

core_status dem_wall_servo(dem_scene *s, int id, double force, double mass, double rate,
                           core_error *err)
{
    core_status st = check_wall(s, id, err);
    if (st != CORE_OK)
        return st;
    if (!isfinite(force) || force < 0)
        return core_fail(err, CORE_ERR_ARG, "servo force must be >= 0, got %g", force);
    if (!isfinite(mass) || mass < 0)
        return core_fail(err, CORE_ERR_ARG, "servo mass must be >= 0, got %g", mass);
    if (!isfinite(rate) || rate < 0)
        return core_fail(err, CORE_ERR_ARG, "servo rate must be >= 0, got %g", rate);
    dem_wall *wl = &s->walls[id];
    if (wl->shape)
        return core_fail(err, CORE_ERR_ARG, "wall %d is not a plane: a servo moves planes only",
                         id + 1);
    wl->servo = mass > 0;
    wl->servo_force = force;
    wl->servo_mass = mass;
    wl->servo_rate = rate;
    return CORE_OK;
}

core_status dem_wall_point(const dem_scene *s, int id, double p[3], core_error *err)
{
    core_status st = check_wall(s, id, err);
    for (int d = 0; st == CORE_OK && d < 3; d++)
        p[d] = s->walls[id].point[d];
    return st;
}

core_status dem_scale_stiffness(dem_scene *s, double factor, core_error *err)
{
    if (!(factor > 0) || !isfinite(factor))
        return core_fail(err, CORE_ERR_ARG, "stiffness scale factor must be > 0, got %g", factor);
    for (int k = 0; k < s->nmat; k++)
        s->mats[k].young *= factor;
    s->contact.stiffness *= factor;
    if (s->contact.kt > 0)
        s->contact.kt *= factor;
    dem_invalidate(s, 1); /* pair stiffness and damping are cached in the list */
    return CORE_OK;
}

core_status dem_set_gravity(dem_scene *s, const double g[3], core_error *err)
{
    for (int d = 0; d < 3; d++) {
        if (!isfinite(g[d]) || fabs(g[d]) > 1e100)
            return core_fail(err, CORE_ERR_ARG,
                             "gravity component %d must be finite and at most 1e100 in magnitude, "
                             "got %g", d + 1, g[d]);
        if (d >= s->dim && g[d] != 0)
            return core_fail(err, CORE_ERR_ARG, "gravity component %d must be 0 in %dD, got %g",
                             d + 1, s->dim, g[d]);
    }
    for (int d = 0; d < 3; d++)
        s->gravity[d] = g[d];
    dem_invalidate(s, 0);
    return CORE_OK;
}

core_status dem_set_drag(dem_scene *s, double rate, core_error *err)
{
    if (!(rate >= 0) || !isfinite(rate))
        return core_fail(err, CORE_ERR_ARG, "drag rate must be >= 0, got %g", rate);
    s->drag = rate;
    dem_invalidate(s, 0);
    return CORE_OK;
}

double dem_drag(const dem_scene *s) { return s->drag; }

void dem_box(const dem_scene *s, double lo[3], double hi[3], double gravity[3])
{
    for (int d = 0; d < 3; d++) {
        lo[d] = s->lo[d];
        hi[d] = s->hi[d];
        gravity[d] = s->gravity[d];
    }
}

core_status dem_set_external_force(dem_scene *s, size_t i, const double f[3], core_error *err)
{
    if (i >= s->n)
        return core_fail(err, CORE_ERR_ARG, "no particle %zu (the scene has %zu)", i + 1, s->n);
    for (int d = 0; d < s->dim; d++)
        if (!isfinite(f[d]))
            return core_fail(err, CORE_ERR_ARG, "force on particle %zu is not finite", i + 1);
    if (!s->fext[0])
        for (int d = 0; d < s->dim; d++) {
            if (dem_alloc_array(&s->fext[d], s->cap, err))
                return err->status;
            memset(s->fext[d], 0, s->cap * sizeof(double));
        }
    /* The external force enters the total linearly: adjust the stored total rather than
     * re-evaluating every contact before the next step. */
    for (int d = 0; d < s->dim; d++) {
        if (s->forces_ready)
            s->f[d][i] += f[d] - s->fext[d][i];
        s->fext[d][i] = f[d];
    }
    s->gear_ready = s->prev_ready = 0;
    return CORE_OK;
}

void dem_clear_external_forces(dem_scene *s)
{
    for (int d = 0; d < 3; d++) {
        if (s->fext[d] && s->forces_ready)
            for (size_t i = 0; i < s->n; i++)
                s->f[d][i] -= s->fext[d][i];
        free(s->fext[d]);
        s->fext[d] = NULL;
    }
    s->gear_ready = s->prev_ready = 0;
}

core_status dem_quasistatic(const dem_scene *s, double pressure, double strain_rate, double *phi,
                            double *psi, core_error *err)
{
    if (s->n == 0)
        return core_fail(err, CORE_ERR_STATE, "the scene has no particles: add some first");
    if (!(pressure > 0) || !isfinite(pressure))
        return core_fail(err, CORE_ERR_ARG, "pressure must be > 0, got %g", pressure);
    if (!(strain_rate > 0) || !isfinite(strain_rate))
        return core_fail(err, CORE_ERR_ARG, "strain_rate must be > 0, got %g", strain_rate);
    double m = 0, r = 0, N = (double)s->n;
    for (size_t i = 0; i < s->n; i++) {
        m += s->m[i];
        r += s->r[i];
    }
    m /= N;
    r /= N;
    if (s->dim == 3) { /* Eq. 2.13, 2.14 */
        *phi = m * strain_rate * strain_rate * pow(N, 2.0 / 3.0) / (4 * pressure * r);
        *psi = pow(N, -1.0 / 3.0);
    } else { /* Eq. 2.B1 */
        *phi = m * strain_rate * strain_rate * N / (2 * pressure * r);
        *psi = 1 / sqrt(2 * N);
    }
    return CORE_OK;
}
