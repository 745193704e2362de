/* DEM checkpoints: the whole scene state in core/checkpoint.h sections, laid out by particle id,
 * so that a run continues bit for bit after a load, in another process or with another thread
 * count. Everything a step reads is stored as it is: the particle arrays, the integrators' state
 * (forces of the last evaluation for velocity Verlet, the Gear derivatives, position Verlet's
 * last displacement, the two-timescales phase), the Verlet list with its per-pair parameters and
 * contact history (keyed by the particle pair i < j, in (i, j) order), the walls with their
 * candidates and histories, the energy watch. Nothing is recomputed on load except tables that
 * are a pure function of stored values (the power table, the list's incidence arrays). This file
 * reads them back; checkpoint_save.c writes them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "core/memory.h"
#include "dem/checkpoint_reader.h"
#include "dem/dem_internal.h"

/* ---- loading -------------------------------------------------------------------------------- */

typedef dem_reader reader;

static void get_into(reader *r, double **a, size_t n, size_t cap)
{
    double *v = get_new(r, n, cap);
    if (v) {
        free(*a);
        *a = v;
    }
}

/* get_into for the step's staggered particle arrays (dem_alloc_hot, number k): the values are
 * read into the staggered block itself. */
static void get_hot(reader *r, double **a, size_t n, size_t cap, int k)
{
    if (!r->st && (r->st = dem_alloc_hot(a, cap, k, r->err)) == CORE_OK)
        r->st = ckpt_get_f64s(&r->sec, *a, n, r->err);
}

static void get_opt_hot(reader *r, double **a, size_t n, size_t cap, int k)
{
    uint32_t present = u32(r);
    if (present > 1)
        bad(r, "bad presence flag");
    if (present && !r->st)
        get_hot(r, a, n, cap, k);
}

static void get_opt(reader *r, double **a, size_t n, size_t cap)
{
    uint32_t present = u32(r);
    if (present > 1)
        bad(r, "bad presence flag");
    if (present && !r->st)
        get_into(r, a, n, cap);
}

static uint32_t *get_u32_new(reader *r, size_t max, size_t *n)
{
    if (r->st)
        return NULL;
    if ((r->st = ckpt_peek_count(&r->sec, max, n, r->err)))
        return NULL;
    uint32_t *a = malloc((*n ? *n : 1) * sizeof *a);
    if (!a) {
        r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return NULL;
    }
    if ((r->st = ckpt_get_u32s(&r->sec, a, *n, r->err))) {
        free(a);
        return NULL;
    }
    return a;
}

static void open_section(reader *r, ckpt_reader *ck, const char *tag)
{
    if (!r->st)
        r->st = ckpt_find(ck, tag, &r->sec, r->err);
}

static void close_section(reader *r)
{
    if (!r->st)
        r->st = ckpt_section_done(&r->sec, r->err);
}

static void read_contact(reader *r, dem_contact_def *c)
{
    /* every value finite: s:contact checks those of the chosen laws only (check_contact) */
    uint32_t normal = u32(r);
    c->stiffness = get_finite(r, "stiffness");
    c->beta = get_finite(r, "beta");
    uint32_t damping = u32(r);
    c->gamma_n = get_finite(r, "gamma_n");
    c->damping_time = get_finite(r, "damping_time");
    c->restitution = get_finite(r, "restitution");
    c->impact_velocity = get_finite(r, "impact_velocity");
    uint32_t tangential = u32(r);
    c->gamma_t = get_finite(r, "gamma_t");
    c->kt = get_finite(r, "kt");
    c->v_r = get_finite(r, "v_r");
    c->exponent = get_finite(r, "exponent");
    c->clip = get_flag(r, "clip");
    c->rolling = get_flag(r, "rolling");
    if (normal >= DEM_NORMAL_COUNT || damping >= DEM_DAMPING_COUNT ||
        tangential >= DEM_TANGENT_COUNT) /* laws.h's lists */
        bad(r, "unknown contact law");
    c->normal = (dem_normal_law)normal;
    c->damping = (dem_damping_law)damping;
    c->tangential = (dem_tangential_law)tangential;
}

static void read_damping(reader *r, dem_scene *s)
{
    s->damp_c = f64(r);
    if (!(s->damp_c >= 0 && s->damp_c < INFINITY))
        bad(r, "bad damping coefficient");
    if (!r->st)
        r->st = ckpt_get_f64s(&r->sec, s->mat_damp, (size_t)s->nmat, r->err);
    for (int k = 0; k < s->nmat && !r->st; k++)
        if (!(s->mat_damp[k] >= 0 && s->mat_damp[k] < INFINITY))
            bad(r, "bad damping coefficient");
}

/* A refusal of an engine call made for a stored value (dem_create, dem_add_material, ...),
 * said as the file's: "'PATH' is corrupt (section 'TAG': young must be > 0, got -1)". Returns 1
 * on failure. */
static int relay(reader *r, core_status st)
{
    if (!st || r->st)
        return st != CORE_OK;
    char why[sizeof r->err->msg];
    snprintf(why, sizeof why, "%s", r->err ? r->err->msg : "refused");
    bad(r, why);
    return 1;
}

/* The contact law passes s:contact's checks: they are made on a scratch scene of the same box,
 * so that the loaded scene's state is not touched by them. */
static void check_contact(reader *r, const dem_scene_def *def, const dem_contact_def *c)
{
    dem_scene *scratch = NULL;
    if (relay(r, dem_create(def, &scratch, r->err)))
        return;
    relay(r, dem_set_contact(scratch, c, r->err));
    dem_destroy(scratch);
}

/* The index of the first entry of a that is not finite, or n (a may be NULL: absent). */
static size_t nonfinite(const double *a, size_t n)
{
    for (size_t i = 0; a && i < n; i++)
        if (!isfinite(a[i]))
            return i;
    return n;
}

/* Every particle value against the physics: finite state, positive radius and mass within the
 * box's scales, positions no further than one box length outside the box (a step between the
 * run's checks may leave a grain just outside; far outside, the cell index of a position would
 * overflow), known flags. */
static core_status check_particles(reader *r, const dem_scene *s)
{
    const size_t n = s->n;
    const int D = s->dim;
    char what[96];
    double extent = INFINITY;
    for (int d = 0; d < D; d++) {
        if (!isfinite(s->hi[d] - s->lo[d]))
            return bad_num(r, "box length", s->hi[d] - s->lo[d], "a finite length");
        extent = fmin(extent, s->hi[d] - s->lo[d]);
    }
    double rmax = 0;
    for (size_t i = 0; i < n && !r->st; i++) {
        for (int d = 0; d < D; d++) {
            const double x = s->x[d][i], len = s->hi[d] - s->lo[d];
            if (!(x >= s->lo[d] - len && x <= s->hi[d] + len)) {
                snprintf(what, sizeof what, "particle %zu's %c", i + 1, 'x' + d);
                return bad_num(r, what, x, "a position within a box length of the box");
            }
        }
        if (!(s->r[i] > 0 && s->r[i] <= 0.5 * extent)) {
            snprintf(what, sizeof what, "particle %zu's radius", i + 1);
            return bad_num(r, what, s->r[i], "a positive radius at most half the box");
        }
        rmax = fmax(rmax, s->r[i]);
        if (!(s->m[i] > 0 && isfinite(s->m[i])) || !(s->inv_m[i] >= 0 && isfinite(s->inv_m[i])) ||
            !(s->inv_inertia[i] >= 0 && isfinite(s->inv_inertia[i]))) {
            snprintf(what, sizeof what, "particle %zu's mass", i + 1);
            return bad_num(r, what, s->m[i], "a positive mass with finite inverses");
        }
        /* a speed whose kinetic energy overflows is no grain's (the energy measures sum v^2) */
        double v2 = 0, w2 = 0;
        for (int d = 0; d < 3; d++) {
            v2 += d < D ? s->v[d][i] * s->v[d][i] : 0;
            w2 += s->w[d] ? s->w[d][i] * s->w[d][i] * s->r[i] * s->r[i] : 0;
        }
        if (!isfinite(v2 * s->m[i]) || !isfinite(w2 * s->m[i])) {
            snprintf(what, sizeof what, "particle %zu's speed", i + 1);
            return bad_num(r, what, sqrt(isfinite(v2 * s->m[i]) ? w2 : v2),
                           "a speed whose kinetic energy is finite");
        }
        if (s->flags[i] & ~(DEM_FIXED | DEM_PRESCRIBED)) {
            snprintf(what, sizeof what, "particle %zu's flags", i + 1);
            return bad_int(r, what, s->flags[i], 0, DEM_FIXED | DEM_PRESCRIBED);
        }
    }
    if (!r->st && !(s->r_max >= rmax && s->r_max <= 0.5 * extent))
        return bad_num(r, "largest radius", s->r_max, "the particles' largest radius or more");
    const double *arrays[64]; /* 3 D + 5 x 3 + 1 + 6 (D + 3) at most */
    const char *names[64];
    int na = 0;
    for (int d = 0; d < D; d++) {
        arrays[na] = s->v[d], names[na++] = "velocity";
        arrays[na] = s->f[d], names[na++] = "force";
        arrays[na] = s->x_build[d], names[na++] = "list position";
        arrays[na] = s->fext[d], names[na++] = "external force";
        arrays[na] = s->x_ref[d], names[na++] = "reference position";
        arrays[na] = s->x_prev[d], names[na++] = "previous position";
    }
    for (int d = 0; d < 3; d++) {
        arrays[na] = s->w[d], names[na++] = "angular velocity";
        arrays[na] = s->tq[d], names[na++] = "torque";
    }
    arrays[na] = s->angle, names[na++] = "angle";
    for (int k = 0; k < 6; k++)
        for (int d = 0; d < 3; d++) {
            if (d < D)
                arrays[na] = s->gear[k][d], names[na++] = "Gear derivative";
            arrays[na] = s->gear_w[k][d], names[na++] = "Gear rotation derivative";
        }
    for (int q = 0; q < na && !r->st; q++) {
        size_t i = nonfinite(arrays[q], n);
        if (i < n) {
            snprintf(what, sizeof what, "particle %zu's %s", i + 1, names[q]);
            return bad_num(r, what, arrays[q][i], "a finite number");
        }
    }
    return r->st;
}

/* Walls and the pair list: finite, unit normals, flags 0 or 1, a servo as s:wall_servo makes
 * it, the pairs' parameters >= 0. */
static core_status check_walls_pairs(reader *r, const dem_scene *s)
{
    char what[96];
    for (int k = 0; k < s->nwalls && !r->st; k++) {
        const dem_wall *w = &s->walls[k];
        const double v[16] = {
            w->point[0],       w->point[1],    w->point[2],       w->velocity[0],
            w->velocity[1],    w->velocity[2], w->normal[0],      w->normal[1],
            w->normal[2],      w->friction,    w->point_build[0], w->point_build[1],
            w->point_build[2], w->fn,          w->servo_force,    w->servo_rate};
        snprintf(what, sizeof what, "wall %d's point, velocity, normal or friction", k + 1);
        if (nonfinite(v, 16) < 16)
            return bad_num(r, what, v[nonfinite(v, 16)], "finite values");
        const double len = sqrt(v[6] * v[6] + v[7] * v[7] + v[8] * v[8]);
        snprintf(what, sizeof what, "wall %d's normal length", k + 1);
        if (!w->shape && !(fabs(len - 1) < 1e-9))
            return bad_num(r, what, len, "1");
        snprintf(what, sizeof what, "wall %d's active and servo flags", k + 1);
        if (w->active != 0 && w->active != 1)
            return bad_int(r, what, w->active, 0, 1);
        if (w->servo != 0 && w->servo != 1)
            return bad_int(r, what, w->servo, 0, 1);
        snprintf(what, sizeof what, "wall %d's servo mass", k + 1);
        if (!(w->servo_mass >= 0 && isfinite(w->servo_mass)) || w->servo != (w->servo_mass > 0) ||
            !(w->servo_force >= 0) || !(w->servo_rate >= 0))
            return bad_num(r, what, w->servo_mass, "a servo with mass > 0, force and rate >= 0");
        for (int d = 0; d < DEM_HIST; d++) {
            size_t i = nonfinite(w->hist[d], s->n);
            snprintf(what, sizeof what, "wall %d's contact history of particle %zu", k + 1, i + 1);
            if (i < s->n)
                return bad_num(r, what, w->hist[d][i], "a finite number");
        }
    }
    const dem_pairs *p = &s->pairs;
    const double *pa[3 + 6 + DEM_HIST] = {p->k, p->gamma, p->mu};
    static const char *const law[3] = {"stiffness", "damping", "friction"};
    int na = 3;
    for (int d = 0; d < 3; d++)
        pa[na++] = p->f[d], pa[na++] = p->c[d];
    for (int d = 0; d < DEM_HIST; d++)
        pa[na++] = p->hist[d];
    for (int q = 0; q < na && !r->st; q++) {
        size_t i = nonfinite(pa[q], p->n);
        if (i < p->n) {
            snprintf(what, sizeof what, "pair %zu's %s", i + 1,
                     q < 3   ? law[q]
                     : q < 9 ? "force"
                             : "contact history");
            return bad_num(r, what, pa[q][i], "a finite number");
        }
        for (size_t j = 0; q < 3 && j < p->n; j++)
            if (!(pa[q][j] >= 0)) {
                snprintf(what, sizeof what, "pair %zu's %s", j + 1, law[q]);
                return bad_num(r, what, pa[q][j], "a number >= 0");
            }
    }
    return r->st;
}

/* The list's per-particle index arrays from the stored (i, j) order. */
static core_status index_pairs(dem_pairs *p, core_error *err)
{
    const size_t np = p->np;
    p->start = calloc(np + 1, sizeof *p->start);
    p->jstart = calloc(np + 1, sizeof *p->jstart);
    p->jpair = malloc((p->n ? p->n : 1) * sizeof *p->jpair);
    size_t *fill = malloc((np ? np : 1) * sizeof *fill);
    if (!p->start || !p->jstart || !p->jpair || !fill) {
        free(fill);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    }
    for (size_t q = 0; q < p->n; q++) {
        p->start[p->i[q] + 1]++;
        p->jstart[p->j[q] + 1]++;
    }
    for (size_t i = 0; i < np; i++) {
        p->start[i + 1] += p->start[i];
        p->jstart[i + 1] += p->jstart[i];
    }
    if (np > 0)
        memcpy(fill, p->jstart, np * sizeof *fill);
    for (size_t q = 0; q < p->n; q++)
        p->jpair[fill[p->j[q]]++] = (uint32_t)q;
    free(fill);
    return CORE_OK;
}

static void read_pairs(reader *r, dem_scene *s)
{
    dem_pairs *p = &s->pairs;
    uint32_t built = u32(r);
    p->np = (size_t)u64(r);
    if (built > 1 || p->np > s->n)
        bad(r, "bad list header");
    size_t ni = 0, nj = 0;
    p->i = get_u32_new(r, SIZE_MAX / 16, &ni);
    p->j = get_u32_new(r, SIZE_MAX / 16, &nj);
    if (r->st)
        return;
    if (ni != nj) {
        bad(r, "pair arrays differ in length");
        return;
    }
    p->n = p->cap = ni;
    /* (i, j) must be strictly increasing with i < j < np: the list order the steps rely on. */
    for (size_t q = 0; q < p->n; q++) {
        int ok = p->i[q] < p->j[q] && p->j[q] < p->np;
        if (q > 0)
            ok = ok && (p->i[q - 1] < p->i[q] || (p->i[q - 1] == p->i[q] && p->j[q - 1] < p->j[q]));
        if (!ok) {
            bad(r, "pair list out of order");
            return;
        }
    }
    get_into(r, &p->k, p->n, p->n);
    get_into(r, &p->gamma, p->n, p->n);
    get_into(r, &p->mu, p->n, p->n);
    for (int d = 0; d < 3; d++) {
        get_opt(r, &p->f[d], p->n, p->n);
        get_opt(r, &p->c[d], p->n, p->n);
    }
    for (int d = 0; d < 4; d++)
        get_opt(r, &p->hist[d], p->n, p->n);
    if (!r->st && built)
        r->st = index_pairs(p, r->err);
}

static void read_rolling(reader *r, dem_scene *s)
{
    dem_contact_def *c = &s->contact;
    uint32_t law = u32(r);
    if (law >= DEM_ROLLING_COUNT)
        bad(r, "unknown rolling law");
    c->rolling_law = (dem_rolling_law)law;
    c->rolling_friction = f64(r);
    c->rolling_stiffness = f64(r);
    c->rolling_damping = f64(r);
    c->rolling_rate = f64(r);
    if (u64(r) != (uint64_t)s->nmat)
        bad(r, "material count");
    for (int k = 0; k < s->nmat && !r->st; k++) {
        s->mats[k].rolling_friction = get_num_in(r, "a material's rolling friction", 0, DBL_MAX);
    }
    dem_pairs *p = &s->pairs;
    for (int d = 0; d < 3; d++)
        get_opt(r, &p->hist[DEM_HIST_ROLL + d], p->n, p->n);
    if (u64(r) != (uint64_t)s->nwalls)
        bad(r, "wall count");
    const size_t n = s->n;
    for (int k = 0; k < s->nwalls && !r->st; k++)
        for (int d = 0; d < 3; d++)
            get_opt(r, &s->walls[k].hist[DEM_HIST_ROLL + d], n, n ? n : 1);
    /* the torques are scratch of each evaluation: allocated as the list build does */
    for (int d = s->dim == 2 ? 2 : 0; d < 3 && !r->st && c->rolling_law && p->start; d++) {
        free(p->rt[d]);
        if (!(p->rt[d] = calloc(p->n ? p->n : 1, sizeof(double))))
            r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    }
}

static void read_cohesion(reader *r, dem_scene *s)
{
    dem_contact_def *c = &s->contact;
    c->adhesion = get_finite(r, "work_of_adhesion");
    uint32_t law = u32(r);
    if (law >= DEM_COHESION_COUNT)
        bad(r, "unknown cohesion law");
    c->cohesion = (dem_cohesion_law)law;
    c->liquid_volume = get_finite(r, "liquid_volume");
    c->surface_tension = get_finite(r, "surface_tension");
    c->contact_angle = get_finite(r, "contact_angle");
    if (u64(r) != (uint64_t)s->nmat)
        bad(r, "material count");
    for (int k = 0; k < s->nmat && !r->st; k++)
        s->mats[k].adhesion = get_num_in(r, "a material's work of adhesion", 0, DBL_MAX);
    get_opt(r, &s->pairs.hist[DEM_HIST_BOND], s->pairs.n, s->pairs.n);
    if (u64(r) != (uint64_t)s->nwalls)
        bad(r, "wall count");
    const size_t n = s->n;
    for (int k = 0; k < s->nwalls && !r->st; k++)
        get_opt(r, &s->walls[k].hist[DEM_HIST_BOND], n, n ? n : 1);
}

/* A file that passed the checksum but was not written by dem_save (forged, or a bug) must not
 * make a step read arrays that are not there: the kernels allocate their state in whole sets,
 * and a list in use covers every particle. Returns what is wrong, or NULL. */
static const char *inconsistent(const dem_scene *s, int gear_ready, int prev_ready,
                                int need_rebuild)
{
    const int D = s->dim, d0 = D == 2 ? 2 : 0;
    if (gear_ready && !s->gear[0][0])
        return "Gear state marked ready but absent";
    for (int k = 0; k < 6 && s->gear[0][0]; k++)
        for (int d = d0; s->rot && d < 3; d++)
            if (!s->gear_w[k][d])
                return "Gear rotation state missing";
    if (prev_ready && !s->x_prev[0])
        return "position Verlet state marked ready but absent";
    for (int w = 0; w < s->nwalls; w++)
        for (int d = 1; d < 4; d++)
            if ((d < D || d == 3) && !s->walls[w].hist[d] != !s->walls[w].hist[0])
                return "incomplete wall history";
    for (int w = 0; w < s->nwalls; w++)
        for (int d = 1; d < 3; d++)
            if ((D == 3) &&
                !s->walls[w].hist[DEM_HIST_ROLL + d] != !s->walls[w].hist[DEM_HIST_ROLL])
                return "incomplete wall rolling history";
    const dem_pairs *p = &s->pairs;
    if (!need_rebuild) {
        if (!p->start || p->np != s->n)
            return "the pair list in use does not cover every particle";
        for (int d = 0; d < 3 && p->n > 0; d++) { /* an empty list allocates nothing */
            if (d < D && !p->f[d])
                return "pair forces missing";
            if (s->rot && (D == 3 || d == 2) && !p->c[d])
                return "pair torques missing";
            if (dem_tangent_history(s->contact.tangential) && d < D && !p->hist[d])
                return "contact history missing";
        }
        if (dem_tangent_history(s->contact.tangential) && p->n > 0 && !p->hist[3])
            return "contact history missing";
        for (int d = 0; d < dem_rolling_slots(s) && p->n > 0; d++)
            if (!p->hist[DEM_HIST_ROLL + d])
                return "rolling history missing";
        if (s->contact.rolling_law && !p->rt[2])
            return "rolling torques missing";
        if (dem_bonds(&s->contact) && p->n > 0 && !p->hist[DEM_HIST_BOND])
            return "cohesion history missing";
    }
    return NULL;
}

/* The section "materials": each through dem_add_material's checks. */
static void read_materials(reader *r, ckpt_reader *ck, dem_scene *s)
{
    open_section(r, ck, "materials");
    uint64_t nmat = u64(r);
    if (nmat > (uint64_t)r->sec.size / 48)
        bad(r, "bad material count");
    if (r->st)
        return;
    s->mats = calloc(nmat ? nmat : 1, sizeof *s->mats);
    if (!s->mats) {
        r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return;
    }
    s->mat_damp = calloc(nmat ? nmat : 1, sizeof *s->mat_damp);
    if (!s->mat_damp) {
        r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return;
    }
    s->cap_mat = (int)(nmat ? nmat : 1);
    for (int k = 0; k < (int)nmat && !r->st; k++) {
        double v[5];
        if ((r->st = ckpt_get_f64s(&r->sec, v, 5, r->err)))
            break;
        /* the checks of s:add_material; rolling friction, adhesion: their own sections */
        const dem_material m = {v[0], v[1], v[2], v[3], v[4], 0, 0};
        if (relay(r, dem_add_material(s, &m, r->err) < 0 ? CORE_ERR_ARG : CORE_OK))
            break;
    }
    close_section(r);
}

/* The section "particles": n particles' arrays, the optional ones in whole sets. */
static void read_particles(reader *r, ckpt_reader *ck, dem_scene *s, size_t n)
{
    const int D = s->dim, d0 = D == 2 ? 2 : 0;
    open_section(r, ck, "particles");
    if (r->st)
        return;
    const size_t cap = n ? n : 1;
    s->n = n;
    s->cap = cap;
    for (int d = 0; d < D; d++) {
        get_hot(r, &s->x[d], n, cap, DEM_HOT_X + d);
        get_hot(r, &s->v[d], n, cap, DEM_HOT_V + d);
        get_hot(r, &s->f[d], n, cap, DEM_HOT_F + d);
        get_hot(r, &s->x_build[d], n, cap, DEM_HOT_XB + d);
    }
    get_hot(r, &s->r, n, cap, DEM_HOT_R);
    get_hot(r, &s->m, n, cap, DEM_HOT_M);
    get_hot(r, &s->inv_m, n, cap, DEM_HOT_INV_M);
    get_hot(r, &s->inv_inertia, n, cap, DEM_HOT_INV_I);
    s->mat = malloc(cap * sizeof *s->mat);
    s->flags = malloc(cap);
    if (!s->mat || !s->flags) {
        r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return;
    }
    if (u64(r) != n)
        bad(r, "material array length");
    for (size_t i = 0; i < n && !r->st; i++) {
        int64_t m = i64(r);
        if (m < 0 || m >= s->nmat)
            bad(r, "unknown material");
        s->mat[i] = (int)m;
    }
    if (u64(r) != n)
        bad(r, "flag array length");
    bytes(r, s->flags, n);
    for (int d = d0; d < 3; d++) {
        get_opt_hot(r, &s->w[d], n, cap, DEM_HOT_W + d);
        get_opt_hot(r, &s->tq[d], n, cap, DEM_HOT_TQ + d);
    }
    get_opt_hot(r, &s->angle, n, cap, DEM_HOT_ANGLE);
    for (int d = 0; d < D; d++) {
        get_opt(r, &s->fext[d], n, cap);
        get_opt(r, &s->x_ref[d], n, cap);
        get_opt(r, &s->x_prev[d], n, cap);
    }
    for (int k = 0; k < 6; k++) {
        for (int d = 0; d < D; d++)
            get_opt(r, &s->gear[k][d], n, cap);
        for (int d = d0; d < 3; d++)
            get_opt(r, &s->gear_w[k][d], n, cap);
    }
    close_section(r);
    if (r->st)
        return;
    /* Optional arrays come in whole sets, as the kernels allocate them. */
    int rot_ok = s->rot ? s->w[d0] && s->tq[d0] && (D == 3 || s->angle) : !s->w[d0] && !s->angle;
    for (int d = d0 + 1; d < 3; d++)
        rot_ok = rot_ok && !s->w[d] == !s->w[d0] && !s->tq[d] == !s->tq[d0];
    for (int d = 1; d < D; d++)
        rot_ok = rot_ok && !s->fext[d] == !s->fext[0] && !s->x_ref[d] == !s->x_ref[0] &&
                 !s->x_prev[d] == !s->x_prev[0];
    for (int k = 0; k < 6; k++)
        for (int d = 0; d < D; d++)
            rot_ok = rot_ok && !s->gear[k][d] == !s->gear[0][0];
    if (!rot_ok)
        bad(r, "incomplete set of optional arrays");
}

/* The section "walls": planes (their spring history and candidates among the n particles). */
static void read_walls(reader *r, ckpt_reader *ck, dem_scene *s, size_t n)
{
    const size_t cap = n ? n : 1;
    open_section(r, ck, "walls");
    uint64_t nw = u64(r);
    if (nw > (uint64_t)r->sec.size / 64)
        bad(r, "bad wall count");
    if (r->st)
        return;
    s->walls = calloc(nw ? nw : 1, sizeof *s->walls);
    if (!s->walls) {
        r->st = core_fail(r->err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
        return;
    }
    s->cap_walls = (int)(nw ? nw : 1);
    for (uint64_t k = 0; k < nw && !r->st; k++) {
        dem_wall *wl = &s->walls[s->nwalls++];
        wl->active = (int)u32(r);
        bytes(r, wl->point, sizeof wl->point);
        bytes(r, wl->normal, sizeof wl->normal);
        bytes(r, wl->velocity, sizeof wl->velocity);
        wl->friction = f64(r);
        int64_t mat = i64(r);
        if (mat < -1 || mat >= s->nmat)
            bad(r, "unknown wall material");
        wl->material = (int)mat;
        bytes(r, wl->point_build, sizeof wl->point_build);
        wl->fn = f64(r);
        wl->servo = (int)u32(r);
        wl->servo_force = f64(r);
        wl->servo_mass = f64(r);
        wl->servo_rate = f64(r);
        for (int d = 0; d < 4; d++)
            get_opt(r, &wl->hist[d], n, cap);
        wl->cand = get_u32_new(r, n, &wl->ncand);
        wl->cap_cand = wl->ncand;
        for (size_t c = 0; c < wl->ncand && !r->st; c++)
            if (wl->cand[c] >= n)
                bad(r, "wall candidate out of range");
    }
    close_section(r);
}

/* The sections a scene writes only when it uses their feature, each read when present. */
static void read_optional(reader *r, ckpt_reader *ck, dem_scene *s, const dem_scene_def *def,
                          const dem_boundary_restorer *restorer)
{
    if (!r->st && ckpt_has(ck, "rolling")) {
        open_section(r, ck, "rolling");
        read_rolling(r, s);
        if (!r->st)
            check_contact(r, def, &s->contact);
        close_section(r);
    }
    if (!r->st && ckpt_has(ck, "cohesion")) {
        open_section(r, ck, "cohesion");
        read_cohesion(r, s);
        if (!r->st)
            check_contact(r, def, &s->contact);
        close_section(r);
    }
    if (!r->st && ckpt_has(ck, "damping")) {
        open_section(r, ck, "damping");
        read_damping(r, s);
        close_section(r);
    } else if (!r->st && dem_checkpoint_damping(&s->contact)) {
        r->st = core_fail(r->err, CORE_ERR_IO,
                          "'%s' has no section 'damping', which its contact law (%s damping from "
                          "a restitution) needs: a file from a grainlab whose damping of this "
                          "law did not honour the restitution cannot continue; build the scene "
                          "again",
                          ckpt_reader_path(ck),
                          s->contact.damping == DEM_DAMPING_VISCOUS ? "viscous" : "brilliantov");
    }
    if (!r->st && ckpt_has(ck, "boundary")) {
        open_section(r, ck, "boundary");
        if (!r->st)
            r->st = dem_boundary_load(s, &r->sec, r->err);
    }
    if (!r->st && ckpt_has(ck, "boundary_update")) {
        open_section(r, ck, "boundary_update");
        if (!r->st)
            r->st = dem_boundary_load_update(s, &r->sec, restorer, r->err);
    }
    if (!r->st && ckpt_has(ck, "flow")) { /* inserters and outflows (flow.c) */
        open_section(r, ck, "flow");
        if (!r->st)
            r->st = dem_flow_load(s, r);
        close_section(r);
    }
    if (!r->st && ckpt_has(ck, "clumps")) { /* rigid bodies (clump_checkpoint.c) */
        open_section(r, ck, "clumps");
        if (!r->st)
            dem_clumps_load(s, r);
        close_section(r);
    }
}

static void read_all(reader *r, ckpt_reader *ck, const dem_boundary_restorer *restorer,
                     dem_scene **out)
{
    dem_scene_def def = dem_default_scene_def();
    open_section(r, ck, "scene");
    uint32_t dim = u32(r);
    if (dim != 2 && dim != 3)
        bad(r, "dimension not 2 or 3");
    def.dim = (int)dim;
    bytes(r, def.lo, sizeof def.lo);
    bytes(r, def.hi, sizeof def.hi);
    for (int d = 0; d < 3; d++)
        def.periodic[d] = u32(r) != 0;
    bytes(r, def.gravity, sizeof def.gravity);
    def.thickness = f64(r);
    double drag = get_num_in(r, "drag", 0, DBL_MAX);
    def.skin = f64(r);
    if (r->st)
        return;
    if (relay(r, dem_create(&def, out, r->err)))
        return;
    dem_scene *s = *out;
    s->drag = drag;
    s->skin = get_num_in(r, "skin", 0, DBL_MAX);
    s->r_max = get_num_in(r, "largest radius", 0, DBL_MAX);
    const uint64_t n64 = u64(r);
    if (!r->st && n64 >= UINT32_MAX - 1)
        bad_int(r, "particle count", (long long)n64, 0, UINT32_MAX - 2);
    const size_t n = (size_t)n64;
    s->rot = get_flag(r, "rotation");
    s->time = get_finite(r, "time");
    s->steps = get_counter(r, "steps");
    s->force_evals = get_counter(r, "force evaluations");
    s->last_integrator = (int)get_int_in(r, "last integrator", 0, DEM_TWO_TIMESCALES);
    s->tt_phase = get_counter(r, "two-timescales phase");
    /* set at the end: restoring the boundary goes through calls that reset them */
    const int gear_ready = get_flag(r, "gear_ready"), prev_ready = get_flag(r, "prev_ready");
    const int forces_ready = get_flag(r, "forces_ready");
    s->suspect = get_flag(r, "suspect");
    const int need_rebuild = get_flag(r, "need_rebuild");
    s->gear_dt = get_num_in(r, "Gear dt", 0, DBL_MAX);
    s->prev_dt = get_num_in(r, "position Verlet dt", 0, DBL_MAX);
    const int watch_on = get_flag(r, "energy watch");
    s->watch_next = get_counter(r, "energy watch step");
    s->watch_min_step = get_counter(r, "energy watch minimum step");
    s->watch_min = f64(r);
    s->watch_min_t = f64(r);
    s->watch_scale = f64(r);
    if (watch_on && !r->st &&
        !(isfinite(s->watch_min) && isfinite(s->watch_min_t) && s->watch_scale >= 0 &&
          isfinite(s->watch_scale)))
        bad(r, "the energy watch's reference is not finite");
    s->brill_c = get_num_in(r, "Brilliantov coefficient", 0, DBL_MAX);
    close_section(r);

    open_section(r, ck, "contact");
    read_contact(r, &s->contact);
    if (!r->st)
        check_contact(r, &def, &s->contact);
    close_section(r);
    if (r->st)
        return;
    dem_power_init(&s->slip_pow,
                   s->contact.tangential == DEM_TANGENT_REGULARIZED ? 1 / s->contact.exponent : 0);

    read_materials(r, ck, s);
    if (r->st)
        return;

    read_particles(r, ck, s, n);
    if (r->st)
        return;

    read_walls(r, ck, s, n);
    if (r->st)
        return;
    if (!r->st && ckpt_has(ck, "wall_shapes")) {
        open_section(r, ck, "wall_shapes");
        if (!r->st)
            r->st = dem_shapes_load(s, &r->sec, r->err);
    }

    open_section(r, ck, "pairs");
    read_pairs(r, s);
    close_section(r);
    read_optional(r, ck, s, &def, restorer);
    if (!r->st) { /* values, named by the section that holds them */
        r->sec.tag = "particles";
        check_particles(r, s);
        r->sec.tag = "walls";
        check_walls_pairs(r, s);
    }
    const char *wrong = r->st ? NULL : inconsistent(s, gear_ready, prev_ready, need_rebuild);
    if (wrong)
        r->st = core_fail(r->err, CORE_ERR_IO, "'%s' is corrupt (inconsistent state: %s)",
                          ckpt_reader_path(ck), wrong);
    s->gear_ready = gear_ready;
    s->prev_ready = prev_ready;
    s->forces_ready = forces_ready;
    s->need_rebuild = need_rebuild;
    s->watch_on = watch_on;
    if (!r->st)
        r->st = ckpt_reader_finish(ck, r->err);
}

core_status dem_load(const char *path, dem_scene **out, core_error *err)
{
    return dem_load_with(path, NULL, out, err);
}

core_status dem_load_with(const char *path, const dem_boundary_restorer *restorer, dem_scene **out,
                          core_error *err)
{
    *out = NULL;
    ckpt_reader *ck;
    core_status st = ckpt_reader_open(&ck, path, "dem", err);
    if (st)
        return st;
    reader r = {.err = err, .st = CORE_OK};
    dem_scene *s = NULL;
    read_all(&r, ck, restorer, &s);
    ckpt_reader_close(ck);
    if (r.st) { /* nothing half-loaded reaches the caller */
        dem_destroy(s);
        return r.st;
    }
    *out = s;
    return CORE_OK;
}
