/* Measurements on a DEM scene: energies, contacts, the assembly stress, coordination, slip rate
 * at contacts (Padbidri Fig. 2.4) and displacements, plain or relative to an affine field
 * (Padbidri Figs. 2.6-2.7). All read the state of the last force evaluation. */
#include <math.h>
#include <string.h>

#include "core/comm.h"
#include "dem/dem_internal.h"

/* Geometry of pair q now: returns the overlap (<= 0 when apart) and fills n (from j to i). */
static double pair_geometry(const dem_scene *s, size_t i, size_t j, double n[3], double *dist)
{
    double d2 = 0, dx[3] = {0, 0, 0};
    for (int d = 0; d < s->dim; d++) {
        dx[d] = s->x[d][i] - s->x[d][j];
        if (s->periodic[d])
            dx[d] -= s->len[d] * nearbyint(dx[d] / s->len[d]);
        d2 += dx[d] * dx[d];
    }
    *dist = sqrt(d2);
    for (int d = 0; d < 3; d++)
        n[d] = *dist > 0 ? dx[d] / *dist : 0;
    return s->r[i] + s->r[j] - *dist;
}

/* Contacts of particle i with wall w: a plane's one, or a shaped wall's hits (walls.c). */
static int wall_hits(const dem_scene *s, const dem_wall *w, size_t i, dem_wall_hit *hit)
{
    if (w->shape)
        return dem_shape_hits(s, w, i, hit);
    double dist = 0;
    for (int d = 0; d < s->dim; d++)
        dist += (s->x[d][i] - w->point[d]) * w->normal[d];
    if (!(dist < s->r[i]))
        return 0;
    hit->dist = dist;
    for (int d = 0; d < 3; d++) {
        hit->n[d] = d < s->dim ? w->normal[d] : 0;
        hit->point[d] = d < s->dim ? s->x[d][i] - s->r[i] * w->normal[d] : 0;
        hit->vel[d] = d < s->dim ? w->velocity[d] : 0;
    }
    return 1;
}

static double wall_overlap(const dem_scene *s, const dem_wall *w, size_t i)
{
    double dist = 0;
    for (int d = 0; d < s->dim; d++)
        dist += (s->x[d][i] - w->point[d]) * w->normal[d];
    return s->r[i] - dist;
}

/* Energy stored in a tangential spring: |f|^2 / (2 kt), from the stored force and stiffness. */
static double spring_energy(double f2, double kt)
{
    return kt > 0 ? 0.5 * f2 / kt : 0;
}

void dem_measure_energy(dem_scene *s, dem_energy *e)
{
    const int D = s->dim;
    memset(e, 0, sizeof *e);
    /* Distributed (the run's energy watch): each rank its owned particles and their pairs as
     * first particle, then a sum over ranks, the same on every rank. */
    const unsigned char *gh = s->ghost;
    for (size_t i = 0; i < s->n; i++) {
        if ((s->flags[i] & DEM_FIXED) || (gh && gh[i]) || dem_is_member(s, i))
            continue; /* a clump's members: its body's energies below */
        double v2 = 0, gx = 0;
        for (int d = 0; d < D; d++) {
            v2 += s->v[d][i] * s->v[d][i];
            gx += s->gravity[d] * s->x[d][i];
        }
        e->kinetic += 0.5 * s->m[i] * v2;
        if (!(s->flags[i] & DEM_PRESCRIBED))
            e->potential -= s->m[i] * gx;
        if (s->rot && s->inv_inertia[i] > 0) {
            double w2 = 0;
            for (int d = (D == 2 ? 2 : 0); d < 3; d++)
                w2 += s->w[d][i] * s->w[d][i];
            e->rotational += 0.5 * w2 / s->inv_inertia[i];
        }
    }
    if (s->clumps) {
        double kin, rot, pot;
        dem_clumps_energy(s, &kin, &rot, &pot);
        e->kinetic += kin, e->rotational += rot, e->potential += pot;
    }
    if (s->need_rebuild || !s->pairs.start)
        dem_build_pairs(s, NULL);
    const dem_pairs *p = &s->pairs;
    for (size_t q = 0; q < p->n; q++) {
        if (gh && gh[p->i[q]])
            continue;
        double n[3], dist;
        double delta = pair_geometry(s, p->i[q], p->j[q], n, &dist);
        if (delta <= 0)
            continue;
        e->elastic += dem_elastic_energy(&s->contact, p->k[q], delta);
        if (p->hist[0]) {
            double f2 = 0;
            for (int d = 0; d < D; d++)
                f2 += p->hist[d][q] * p->hist[d][q];
            e->elastic += spring_energy(f2, p->hist[3][q]);
        }
    }
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        for (size_t i = 0; i < s->n; i++) {
            if (wl->shape && !(gh && gh[i])) {
                dem_wall_hit hit[DEM_WALL_MAXHIT];
                const int nh = dem_shape_hits(s, wl, i, hit);
                for (int h = 0; h < nh; h++) {
                    double k, gamma, mu;
                    dem_wall_parameters(s, wl, i, &k, &gamma, &mu);
                    e->elastic += dem_elastic_energy(&s->contact, k, s->r[i] - hit[h].dist);
                    if (wl->hist[0] && h == 0) {
                        double f2 = 0;
                        for (int d = 0; d < D; d++)
                            f2 += wl->hist[d][i] * wl->hist[d][i];
                        e->elastic += spring_energy(f2, wl->hist[3][i]);
                    }
                }
                continue;
            }
            double delta = wall_overlap(s, wl, i);
            if (delta <= 0 || (gh && gh[i]))
                continue;
            double k, gamma, mu;
            dem_wall_parameters(s, wl, i, &k, &gamma, &mu);
            e->elastic += dem_elastic_energy(&s->contact, k, delta);
            if (wl->hist[0]) {
                double f2 = 0;
                for (int d = 0; d < D; d++)
                    f2 += wl->hist[d][i] * wl->hist[d][i];
                e->elastic += spring_energy(f2, wl->hist[3][i]);
            }
        }
    }
    if (s->dom) {
        double v[4] = {e->kinetic, e->rotational, e->elastic, e->potential};
        comm_sum_double(v, 4);
        e->kinetic = v[0], e->rotational = v[1], e->elastic = v[2], e->potential = v[3];
    }
    e->total = e->kinetic + e->rotational + e->elastic + e->potential;
}

/* |slip| of particle i's contact point on wall wl. */
static double wall_slip(const dem_scene *s, const dem_wall_hit *hit, size_t i)
{
    const int D = s->dim;
    const double *n = hit->n;
    double vr[3] = {0, 0, 0}, vn = 0;
    for (int d = 0; d < D; d++) {
        vr[d] = s->v[d][i] - hit->vel[d];
        vn += vr[d] * n[d];
    }
    if (D == 2)
        return fabs(-vr[0] * n[1] + vr[1] * n[0] - (s->rot ? s->r[i] * s->w[2][i] : 0));
    double om[3] = {0, 0, 0}, sl2 = 0;
    for (int d = 0; s->rot && d < 3; d++)
        om[d] = s->r[i] * s->w[d][i];
    double oxn[3] = {om[1] * n[2] - om[2] * n[1], om[2] * n[0] - om[0] * n[2],
                     om[0] * n[1] - om[1] * n[0]};
    for (int d = 0; d < 3; d++) {
        double sd = vr[d] - vn * n[d] - oxn[d];
        sl2 += sd * sd;
    }
    return sqrt(sl2);
}

/* The tangential laws (laws.h's DEM_TANGENT_LAWS): the force a wall contact carries now, without
 * advancing the spring history. */
#define WALL_TANGENTIAL_ARGS                                                                       \
    const dem_scene *s, const dem_wall *wl, const dem_wall_hit *hit, int first, size_t i,          \
        double fn, double k, double mu, double delta
static double wall_tangential_none(WALL_TANGENTIAL_ARGS)
{
    (void)s, (void)wl, (void)hit, (void)first, (void)i, (void)fn, (void)k, (void)mu, (void)delta;
    return 0;
}

static double wall_tangential_viscous(WALL_TANGENTIAL_ARGS)
{
    (void)wl, (void)first, (void)fn, (void)k, (void)mu, (void)delta;
    return s->contact.gamma_t * wall_slip(s, hit, i);
}

static double wall_tangential_coulomb_regularized(WALL_TANGENTIAL_ARGS)
{
    (void)wl, (void)first, (void)k, (void)delta;
    const dem_contact_def *c = &s->contact;
    double x = wall_slip(s, hit, i) / c->v_r;
    return x >= 1 ? mu * fn : mu * fn * pow(x, 1 / c->exponent);
}

static double wall_tangential_spring(WALL_TANGENTIAL_ARGS)
{
    (void)hit;
    /* the stored force (already capped at mu f_n) */
    if (!wl->hist[0] || !first) /* further hits of a shaped wall carry no history */
        return 0;
    double f2 = 0;
    for (int d = 0; d < s->dim; d++)
        f2 += wl->hist[d][i] * wl->hist[d][i];
    (void)k, (void)delta;
    return fmin(sqrt(f2), mu * fn);
}

static double wall_tangential(WALL_TANGENTIAL_ARGS)
{
    switch (s->contact.tangential) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_TANGENT_##ID:                                                                         \
        return wall_tangential_##name(s, wl, hit, first, i, fn, k, mu, delta);
        DEM_TANGENT_LAWS(LAW_, _)
#undef LAW_
    default:
        return 0;
    }
}
#undef WALL_TANGENTIAL_ARGS

void dem_each_contact(dem_scene *s, void (*visit)(const dem_contact_info *c, void *ctx),
                      void *ctx)
{
    const int D = s->dim;
    if (s->need_rebuild || !s->pairs.start)
        dem_build_pairs(s, NULL);
    const dem_pairs *p = &s->pairs;
    for (size_t q = 0; q < p->n; q++) {
        dem_contact_info c;
        double dist;
        c.overlap = pair_geometry(s, p->i[q], p->j[q], c.normal, &dist);
        if (c.overlap <= 0)
            continue;
        c.i = p->i[q];
        c.j = p->j[q];
        double fn = 0, f2 = 0;
        for (int d = 0; d < D; d++) {
            fn += p->f[d][q] * c.normal[d];
            f2 += p->f[d][q] * p->f[d][q];
        }
        c.fn = fn;
        c.ft = sqrt(fmax(0, f2 - fn * fn));
        for (int d = 0; d < 3; d++)
            c.force[d] = d < D ? p->f[d][q] : 0;
        for (int d = 0; d < 3; d++)
            c.point[d] = d < D ? s->x[d][c.i] - (s->r[c.i] - 0.5 * c.overlap) * c.normal[d] : 0;
        visit(&c, ctx);
    }
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        for (size_t i = 0; i < s->n; i++) {
            dem_wall_hit hit[DEM_WALL_MAXHIT];
            const int nh = wall_hits(s, wl, i, hit);
            for (int h = 0; h < nh; h++) {
                double delta = s->r[i] - hit[h].dist;
                dem_contact_info c = {.i = (long)i, .j = -(long)w - 1, .overlap = delta};
                double k, gamma, mu, vn = 0;
                dem_wall_parameters(s, wl, i, &k, &gamma, &mu);
                for (int d = 0; d < 3; d++) {
                    c.normal[d] = hit[h].n[d];
                    c.point[d] = hit[h].point[d];
                }
                for (int d = 0; d < D; d++)
                    vn += (s->v[d][i] - hit[h].vel[d]) * hit[h].n[d];
                c.fn = dem_normal_force(&s->contact, k, gamma, delta, -vn);
                c.ft = wall_tangential(s, wl, &hit[h], h == 0, i, c.fn, k, mu, delta);
                for (int d = 0; d < D; d++)
                    c.force[d] = c.fn * hit[h].n[d];
                visit(&c, ctx);
            }
        }
    }
}

long dem_measure_stress(dem_scene *s, double volume, double sigma[3][3])
{
    const int D = s->dim;
    memset(sigma, 0, 9 * sizeof(double));
    if (!(volume > 0)) {
        volume = 1;
        for (int d = 0; d < D; d++)
            volume *= s->len[d];
    }
    if (s->need_rebuild || !s->pairs.start)
        dem_build_pairs(s, NULL);
    const dem_pairs *p = &s->pairs;
    long count = 0;
    for (size_t q = 0; q < p->n; q++) {
        double n[3], dist;
        if (pair_geometry(s, p->i[q], p->j[q], n, &dist) <= 0)
            continue;
        count++;
        /* branch vector from j to i times the force on i */
        for (int a = 0; a < D; a++)
            for (int b = 0; b < D; b++)
                sigma[a][b] += dist * n[a] * p->f[b][q];
    }
    for (int a = 0; a < D; a++)
        for (int b = 0; b < D; b++)
            sigma[a][b] /= volume;
    return count;
}

void dem_measure_coordination(dem_scene *s, double *z_all, double *z_no_rattlers)
{
    if (s->need_rebuild || !s->pairs.start)
        dem_build_pairs(s, NULL);
    const dem_pairs *p = &s->pairs;
    long total = 0, kept = 0, kept_particles = 0;
    for (size_t i = 0; i < s->n; i++) {
        long z = 0;
        double n[3], dist;
        for (size_t q = p->start[i]; q < p->start[i + 1]; q++)
            z += pair_geometry(s, i, p->j[q], n, &dist) > 0;
        for (size_t e = p->jstart[i]; e < p->jstart[i + 1]; e++)
            z += pair_geometry(s, p->i[p->jpair[e]], i, n, &dist) > 0;
        for (int w = 0; w < s->nwalls; w++) {
            dem_wall_hit hit[DEM_WALL_MAXHIT];
            z += s->walls[w].active ? wall_hits(s, &s->walls[w], i, hit) : 0;
        }
        total += z;
        if (z >= 2) {
            kept += z;
            kept_particles++;
        }
    }
    *z_all = s->n ? (double)total / (double)s->n : 0;
    *z_no_rattlers = kept_particles ? (double)kept / (double)kept_particles : 0;
}

double dem_measure_slip(dem_scene *s)
{
    const int D = s->dim;
    if (s->need_rebuild || !s->pairs.start)
        dem_build_pairs(s, NULL);
    const dem_pairs *p = &s->pairs;
    double sum = 0;
    long count = 0;
    for (size_t q = 0; q < p->n; q++) {
        const size_t i = p->i[q], j = p->j[q];
        double n[3], dist;
        if (pair_geometry(s, i, j, n, &dist) <= 0)
            continue;
        double vr[3] = {0, 0, 0}, vn = 0;
        for (int d = 0; d < D; d++) {
            vr[d] = s->v[d][i] - s->v[d][j];
            vn += vr[d] * n[d];
        }
        double slip;
        if (D == 2) {
            double w = s->rot ? s->r[i] * s->w[2][i] + s->r[j] * s->w[2][j] : 0;
            slip = fabs(-vr[0] * n[1] + vr[1] * n[0] - w);
        } else {
            double om[3] = {0, 0, 0}, s2 = 0;
            for (int d = 0; s->rot && d < 3; d++)
                om[d] = s->r[i] * s->w[d][i] + s->r[j] * s->w[d][j];
            double oxn[3] = {om[1] * n[2] - om[2] * n[1], om[2] * n[0] - om[0] * n[2],
                             om[0] * n[1] - om[1] * n[0]};
            for (int d = 0; d < 3; d++) {
                double sd = vr[d] - vn * n[d] - oxn[d];
                s2 += sd * sd;
            }
            slip = sqrt(s2);
        }
        sum += slip;
        count++;
    }
    return count ? sum / (double)count : 0;
}

core_status dem_set_reference(dem_scene *s, core_error *err)
{
    for (int d = 0; d < s->dim; d++) {
        if (!s->x_ref[d] && dem_alloc_array(&s->x_ref[d], s->cap ? s->cap : 1, err))
            return err->status;
        memcpy(s->x_ref[d], s->x[d], s->n * sizeof(double));
    }
    return CORE_OK;
}

core_status dem_measure_displacement(const dem_scene *s, const double grad_u[3][3],
                                     const double center[3], double *out[3], core_error *err)
{
    const int D = s->dim;
    if (!s->x_ref[0])
        return core_fail(err, CORE_ERR_STATE, "no reference state: call set_reference first");
    for (size_t i = 0; i < s->n; i++)
        for (int a = 0; a < D; a++) {
            double u = s->x[a][i] - s->x_ref[a][i];
            if (grad_u)
                for (int b = 0; b < D; b++)
                    u -= grad_u[a][b] * (s->x_ref[b][i] - (center ? center[b] : 0));
            out[a][i] = u;
        }
    return CORE_OK;
}

/* ---- contacts with the walls' friction (coarse-graining) ------------------------------------ */
typedef struct pairs_only {
    void (*visit)(const dem_contact_info *c, void *ctx);
    void *ctx;
} pairs_only;

static void visit_pair(const dem_contact_info *c, void *ctx)
{
    const pairs_only *p = ctx;
    if (c->j >= 0)
        p->visit(c, p->ctx);
}

/* The tangential force vector of a wall contact now, as wall_tangential gives its length: the
 * spring's stored force (capped at mu f_n), or the viscous or regularised law against the slip
 * of the contact point (2D: along t = (-n_y, n_x)). */
static void wall_tangential_vector(const dem_scene *s, const dem_wall *wl, const dem_wall_hit *hit,
                                   int first, size_t i, double ft, double out[3])
{
    const int D = s->dim;
    const double *n = hit->n;
    double vr[3] = {0, 0, 0}, vn = 0, sl[3] = {0, 0, 0}, t[3] = {-n[1], n[0], 0};
    for (int d = 0; d < 3; d++)
        out[d] = 0;
    for (int d = 0; d < D; d++) {
        vr[d] = s->v[d][i] - hit->vel[d];
        vn += vr[d] * n[d];
    }
    if (D == 2) {
        sl[0] = -vr[0] * n[1] + vr[1] * n[0] - (s->rot ? s->r[i] * s->w[2][i] : 0);
    } else {
        double om[3] = {0, 0, 0};
        for (int d = 0; s->rot && d < 3; d++)
            om[d] = s->r[i] * s->w[d][i];
        const double oxn[3] = {om[1] * n[2] - om[2] * n[1], om[2] * n[0] - om[0] * n[2],
                               om[0] * n[1] - om[1] * n[0]};
        for (int d = 0; d < 3; d++)
            sl[d] = vr[d] - vn * n[d] - oxn[d];
    }
    if (s->contact.tangential == DEM_TANGENT_SPRING) {
        if (!wl->hist[0] || !first)
            return;
        if (D == 2) {
            const double f = fmax(-ft, fmin(ft, wl->hist[0][i]));
            for (int d = 0; d < 2; d++)
                out[d] = f * t[d];
            return;
        }
        double h2 = 0;
        for (int d = 0; d < 3; d++)
            h2 += wl->hist[d][i] * wl->hist[d][i];
        const double scale = h2 > 0 ? ft / sqrt(h2) : 0;
        for (int d = 0; d < 3; d++)
            out[d] = scale * wl->hist[d][i];
        return;
    }
    double s2 = 0;
    for (int d = 0; d < (D == 2 ? 1 : 3); d++)
        s2 += sl[d] * sl[d];
    if (!(s2 > 0))
        return;
    const double k = -ft / sqrt(s2); /* against the slip, of length ft */
    if (D == 2)
        for (int d = 0; d < 2; d++)
            out[d] = k * sl[0] * t[d];
    else
        for (int d = 0; d < 3; d++)
            out[d] = k * sl[d];
}

void dem_each_contact_full(dem_scene *s, void (*visit)(const dem_contact_info *c, void *ctx),
                           void *ctx)
{
    const int D = s->dim;
    pairs_only po = {visit, ctx};
    dem_each_contact(s, visit_pair, &po);
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        for (size_t i = 0; i < s->n; i++) {
            dem_wall_hit hit[DEM_WALL_MAXHIT];
            const int nh = wall_hits(s, wl, i, hit);
            for (int h = 0; h < nh; h++) {
                double delta = s->r[i] - hit[h].dist;
                dem_contact_info c = {.i = (long)i, .j = -(long)w - 1, .overlap = delta};
                double k, gamma, mu, vn = 0, ftv[3];
                dem_wall_parameters(s, wl, i, &k, &gamma, &mu);
                for (int d = 0; d < 3; d++) {
                    c.normal[d] = hit[h].n[d];
                    c.point[d] = hit[h].point[d];
                }
                for (int d = 0; d < D; d++)
                    vn += (s->v[d][i] - hit[h].vel[d]) * hit[h].n[d];
                c.fn = dem_normal_force(&s->contact, k, gamma, delta, -vn);
                c.ft = wall_tangential(s, wl, &hit[h], h == 0, i, c.fn, k, mu, delta);
                wall_tangential_vector(s, wl, &hit[h], h == 0, i, c.ft, ftv);
                for (int d = 0; d < D; d++)
                    c.force[d] = c.fn * hit[h].n[d] + ftv[d];
                visit(&c, ctx);
            }
        }
    }
}

void dem_periodic(const dem_scene *s, bool periodic[3])
{
    for (int d = 0; d < 3; d++)
        periodic[d] = s->periodic[d];
}
