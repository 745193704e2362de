/* Walls beyond planes: segments and polylines (2D), triangle meshes (3D), circles and cylinders,
 * moving as rigid bodies. This file holds their geometry (closest point, normal, the surface's
 * velocity at the contact point), their motion and candidates (their checkpoint section:
 * walls_checkpoint.c); the force law stays in the wall kernel (forces_dim.inc), which calls
 * dem_shape_hits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "dem/dem_internal.h"

dem_shape_def dem_default_shape_def(void)
{
    return (dem_shape_def){.kind = DEM_WALL_SEGMENTS, .inside = 1, .friction = -1, .material = -1};
}

/* ---- frames ---------------------------------------------------------------------------------- */
static void rot_from_angle(dem_shape *sh)
{
    const double c = cos(sh->angle), s = sin(sh->angle);
    const double r[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    memcpy(sh->rot, r, sizeof r);
}

static void to_body(const dem_shape *sh, const double *x, double *pb)
{
    const double d[3] = {x[0] - sh->center[0], x[1] - sh->center[1], x[2] - sh->center[2]};
    for (int a = 0; a < 3; a++) /* R^T d */
        pb[a] = sh->rot[a] * d[0] + sh->rot[3 + a] * d[1] + sh->rot[6 + a] * d[2];
}

static void to_world_vec(const dem_shape *sh, const double *vb, double *vw)
{
    for (int a = 0; a < 3; a++)
        vw[a] = sh->rot[3 * a] * vb[0] + sh->rot[3 * a + 1] * vb[1] + sh->rot[3 * a + 2] * vb[2];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* ---- closest points (body frame) --------------------------------------------------------------
 * A raw hit: the element, what its closest point is (FACE: inside the segment or triangle;
 * VERTEX fa; EDGE fa-fb), the distance and the point. */
enum { FEAT_FACE, FEAT_VERTEX, FEAT_EDGE };
typedef struct raw_hit {
    uint32_t elem, fa, fb;
    int feat;
    double dist, q[3];
} raw_hit;

/* The closest point is vertex i (at v), or on the edge i-j (from a at i to b at j) at a + t (b -
 * a). */
static inline void at_vertex(raw_hit *h, uint32_t i, const double *v)
{
    h->feat = FEAT_VERTEX, h->fa = i;
    memcpy(h->q, v, sizeof h->q);
}
static inline void at_edge(raw_hit *h, uint32_t i, uint32_t j, const double *a, const double *b,
                           double t)
{
    h->feat = FEAT_EDGE, h->fa = i, h->fb = j;
    for (int d = 0; d < 3; d++)
        h->q[d] = a[d] + t * (b[d] - a[d]);
}

static void seg_closest(const dem_shape *sh, uint32_t k, const double *p, raw_hit *h)
{
    const uint32_t ia = sh->e[2 * k], ib = sh->e[2 * k + 1];
    const double *a = sh->v + 3 * ia, *b = sh->v + 3 * ib;
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    const double t = dot3(ap, ab) / dot3(ab, ab);
    h->elem = k;
    if (t <= 0) /* the end points exactly, so that two segments agree on a shared vertex */
        at_vertex(h, ia, a);
    else if (t >= 1)
        at_vertex(h, ib, b);
    else {
        h->feat = FEAT_FACE;
        for (int d = 0; d < 3; d++)
            h->q[d] = a[d] + t * ab[d];
    }
}

/* Ericson, Real-Time Collision Detection Sec. 5.1.5: the Voronoi regions of the triangle. */
static void tri_closest(const dem_shape *sh, uint32_t k, const double *p, raw_hit *h)
{
    const uint32_t ia = sh->e[3 * k], ib = sh->e[3 * k + 1], ic = sh->e[3 * k + 2];
    const double *a = sh->v + 3 * ia, *b = sh->v + 3 * ib, *c = sh->v + 3 * ic;
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int d = 0; d < 3; d++) {
        ab[d] = b[d] - a[d], ac[d] = c[d] - a[d];
        ap[d] = p[d] - a[d], bp[d] = p[d] - b[d], cp[d] = p[d] - c[d];
    }
    h->elem = k;
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        at_vertex(h, ia, a);
        return;
    }
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        at_vertex(h, ib, b);
        return;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        at_edge(h, ia, ib, a, b, d1 / (d1 - d3));
        return;
    }
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        at_vertex(h, ic, c);
        return;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        at_edge(h, ia, ic, a, c, d2 / (d2 - d6));
        return;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        at_edge(h, ib, ic, b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
        return;
    }
    const double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    h->feat = FEAT_FACE;
    for (int d = 0; d < 3; d++)
        h->q[d] = a[d] + ab[d] * v + ac[d] * w;
}

/* The cylinder's (circle's) closest surface point: signed distance (negative: the centre is on
 * the wrong side), normal towards the particle, all in the body frame. */
static double cyl_closest(const dem_shape *sh, int D, const double *p, double *q, double *n)
{
    double s = 0, rho[3] = {p[0], p[1], D == 3 ? p[2] : 0};
    if (D == 3) {
        s = dot3(p, sh->axis);
        for (int d = 0; d < 3; d++)
            rho[d] -= s * sh->axis[d];
    }
    double len = sqrt(dot3(rho, rho)), u[3];
    if (len > 0) {
        for (int d = 0; d < 3; d++)
            u[d] = rho[d] / len;
    } else { /* on the axis: any radial direction */
        const double *a = sh->axis;
        double t[3] = {D == 3 && fabs(a[0]) > 0.9 ? 0 : 1, D == 3 && fabs(a[0]) > 0.9 ? 1 : 0, 0};
        double ta = D == 3 ? dot3(t, a) : 0, tl = 0;
        for (int d = 0; d < 3; d++)
            t[d] -= ta * (D == 3 ? a[d] : 0), tl += t[d] * t[d];
        for (int d = 0; d < 3; d++)
            u[d] = t[d] / sqrt(tl);
    }
    if (D == 2 || fabs(s) <= sh->half) {
        for (int d = 0; d < 3; d++) {
            q[d] = (D == 3 ? s * sh->axis[d] : 0) + sh->radius * u[d];
            n[d] = sh->inside ? -u[d] : u[d];
        }
        return sh->inside ? sh->radius - len : len - sh->radius;
    }
    /* beyond an open end: the rim, from either side */
    const double e = s > 0 ? sh->half : -sh->half;
    double diff[3];
    for (int d = 0; d < 3; d++) {
        q[d] = e * sh->axis[d] + sh->radius * u[d];
        diff[d] = p[d] - q[d];
    }
    double dist = sqrt(dot3(diff, diff));
    for (int d = 0; d < 3; d++)
        n[d] = dist > 0 ? diff[d] / dist : u[d];
    return dist;
}

static int elem_has(const dem_shape *sh, uint32_t k, uint32_t v)
{
    const int m = sh->kind == DEM_WALL_TRIANGLES ? 3 : 2;
    for (int a = 0; a < m; a++)
        if (sh->e[(size_t)m * k + (size_t)a] == v)
            return 1;
    return 0;
}

/* Element k contains hit h's feature (its vertex, or both ends of its edge). */
static int has_feature(const dem_shape *sh, uint32_t k, const raw_hit *h)
{
    return elem_has(sh, k, h->fa) && (h->feat != FEAT_EDGE || elem_has(sh, k, h->fb));
}

enum { RAW_MAX = 32 };

/* The closest-feature rule (dem.h): hits sorted by (distance, element); an end point, vertex or
 * edge hit is dropped when a kept hit's element contains that feature; a face hit is always kept
 * and removes a kept vertex/edge hit of its own element's features that is no closer (up to
 * rounding: the two points are then the same). */
static int select_hits(const dem_shape *sh, raw_hit *raw, int nraw, int *keep)
{
    for (int a = 1; a < nraw; a++) /* insertion sort: few hits */
        for (int b = a;
             b > 0 && (raw[b].dist < raw[b - 1].dist ||
                       (raw[b].dist == raw[b - 1].dist && raw[b].elem < raw[b - 1].elem));
             b--) {
            raw_hit t = raw[b];
            raw[b] = raw[b - 1];
            raw[b - 1] = t;
        }
    int nk = 0;
    for (int a = 0; a < nraw; a++) {
        const raw_hit *x = &raw[a];
        if (x->feat != FEAT_FACE) {
            int drop = 0;
            for (int b = 0; b < nk && !drop; b++)
                drop = has_feature(sh, raw[keep[b]].elem, x);
            if (!drop)
                keep[nk++] = a;
        } else {
            int m = 0;
            for (int b = 0; b < nk; b++) {
                const raw_hit *y = &raw[keep[b]];
                int sliver = y->feat != FEAT_FACE && has_feature(sh, x->elem, y) &&
                             y->dist >= x->dist * (1 - 1e-9);
                if (!sliver)
                    keep[m++] = keep[b];
            }
            nk = m;
            keep[nk++] = a;
        }
    }
    return nk;
}

/* Raw hits of body-frame point p within `reach` of the surface (the RAW_MAX closest). */
static int raw_hits(const dem_shape *sh, const double *p, double reach, raw_hit *raw)
{
    int nraw = 0;
    for (uint32_t k = 0; k < sh->ne; k++) {
        raw_hit h;
        if (sh->kind == DEM_WALL_SEGMENTS)
            seg_closest(sh, k, p, &h);
        else
            tri_closest(sh, k, p, &h);
        const double dq[3] = {p[0] - h.q[0], p[1] - h.q[1], p[2] - h.q[2]};
        h.dist = sqrt(dot3(dq, dq));
        if (!(h.dist < reach))
            continue;
        if (nraw < RAW_MAX) {
            raw[nraw++] = h;
        } else { /* full: replace the farthest */
            int far = 0;
            for (int a = 1; a < nraw; a++)
                far = raw[a].dist > raw[far].dist ? a : far;
            if (h.dist < raw[far].dist)
                raw[far] = h;
        }
    }
    return nraw;
}

/* The element's own normal, for a centre exactly on it (then the run stops: it tunnelled). */
static void elem_normal(const dem_shape *sh, uint32_t k, double *n)
{
    if (sh->kind == DEM_WALL_SEGMENTS) {
        const double *a = sh->v + 3 * sh->e[2 * k], *b = sh->v + 3 * sh->e[2 * k + 1];
        double t[2] = {b[0] - a[0], b[1] - a[1]}, l = hypot(t[0], t[1]);
        n[0] = -t[1] / l, n[1] = t[0] / l, n[2] = 0;
        return;
    }
    const double *a = sh->v + 3 * sh->e[3 * k], *b = sh->v + 3 * sh->e[3 * k + 1],
                 *c = sh->v + 3 * sh->e[3 * k + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
           w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    double l = sqrt(dot3(x, x));
    for (int d = 0; d < 3; d++)
        n[d] = x[d] / l;
}

/* Fills a world-frame hit from a body-frame point q and normal n. */
static void finish_hit(const dem_scene *s, const dem_shape *sh, double dist, const double *qb,
                       const double *nb, dem_wall_hit *h)
{
    double q[3], n[3];
    to_world_vec(sh, qb, q);
    to_world_vec(sh, nb, n);
    h->dist = dist;
    for (int d = 0; d < 3; d++) {
        h->n[d] = d < s->dim ? n[d] : 0;
        h->point[d] = d < s->dim ? q[d] + sh->center[d] : 0;
    }
    /* the surface's velocity at the point: v + omega x r (2D: omega along z) */
    const double *w = sh->omega;
    const double r[3] = {q[0], q[1], s->dim == 3 ? q[2] : 0};
    const double wxr[3] = {w[1] * r[2] - w[2] * r[1], w[2] * r[0] - w[0] * r[2],
                           w[0] * r[1] - w[1] * r[0]};
    for (int d = 0; d < 3; d++)
        h->vel[d] = d < s->dim ? sh->vel[d] + wxr[d] : 0;
}

int dem_shape_hits(const dem_scene *s, const dem_wall *wl, size_t i, dem_wall_hit *hit)
{
    const dem_shape *sh = wl->shape;
    const double ri = s->r[i];
    const double x[3] = {s->x[0][i], s->x[1][i], s->dim == 3 ? s->x[2][i] : 0};
    double p[3];
    to_body(sh, x, p);
    if (sh->kind == DEM_WALL_CYLINDER) {
        double q[3], n[3];
        double dist = cyl_closest(sh, s->dim, p, q, n);
        if (!(dist < ri))
            return 0;
        finish_hit(s, sh, dist, q, n, hit);
        return 1;
    }
    raw_hit raw[RAW_MAX];
    int keep[RAW_MAX];
    const int nraw = raw_hits(sh, p, ri, raw);
    if (nraw == 0)
        return 0;
    int nk = select_hits(sh, raw, nraw, keep);
    if (nk > DEM_WALL_MAXHIT)
        nk = DEM_WALL_MAXHIT; /* keep is in the order of distance */
    for (int a = 0; a < nk; a++) {
        const raw_hit *h = &raw[keep[a]];
        double n[3];
        if (h->dist > 0) {
            for (int d = 0; d < 3; d++)
                n[d] = (p[d] - h->q[d]) / h->dist;
        } else {
            elem_normal(sh, h->elem, n);
        }
        finish_hit(s, sh, h->dist, h->q, n, &hit[a]);
    }
    return nk;
}

double dem_shape_distance(const dem_scene *s, const dem_wall *wl, const double *x)
{
    const dem_shape *sh = wl->shape;
    const double xx[3] = {x[0], x[1], s->dim == 3 ? x[2] : 0};
    double p[3];
    to_body(sh, xx, p);
    if (sh->kind == DEM_WALL_CYLINDER) {
        double q[3], n[3];
        return cyl_closest(sh, s->dim, p, q, n);
    }
    double best = INFINITY;
    for (uint32_t k = 0; k < sh->ne; k++) {
        raw_hit h;
        if (sh->kind == DEM_WALL_SEGMENTS)
            seg_closest(sh, k, p, &h);
        else
            tri_closest(sh, k, p, &h);
        const double dq[3] = {p[0] - h.q[0], p[1] - h.q[1], p[2] - h.q[2]};
        best = fmin(best, sqrt(dot3(dq, dq)));
    }
    return best;
}

core_status dem_shape_candidates(dem_scene *s, dem_wall *wl, core_error *err)
{
    dem_shape *sh = wl->shape;
    const int D = s->dim;
    sh->ncand = 0;
    wl->ncand = 0;
    wl->cand_par_ok = 0;
    for (size_t i = 0; i < s->n; i++) {
        const double x[3] = {s->x[0][i], s->x[1][i], D == 3 ? s->x[2][i] : 0};
        const double lim = s->r[i] + s->skin;
        double c2 = 0;
        for (int d = 0; d < D; d++)
            c2 += (x[d] - sh->center[d]) * (x[d] - sh->center[d]);
        /* outside the bounding sphere: no test of every element (a cylinder's is unbounded) */
        if (sh->kind != DEM_WALL_CYLINDER && sqrt(c2) > sh->reach + lim)
            continue;
        if (!(dem_shape_distance(s, wl, x) < lim))
            continue;
        if (sh->ncand == sh->cap_cand) {
            size_t cap = sh->cap_cand ? 2 * sh->cap_cand : 256;
            uint32_t *c = realloc(sh->cand, cap * sizeof *c);
            double *l = realloc(sh->cload, DEM_SHAPE_LOAD * cap * sizeof *l);
            if (c)
                sh->cand = c;
            if (l)
                sh->cload = l;
            if (!c || !l)
                return core_fail(err, CORE_ERR_NOMEM, "cannot allocate wall candidates");
            sh->cap_cand = cap;
        }
        sh->cand[sh->ncand++] = (uint32_t)i;
    }
    for (int d = 0; d < 3; d++)
        wl->point_build[d] = wl->point[d];
    sh->moved = 0;
    return CORE_OK;
}

int dem_shapes_moved(const dem_scene *s)
{
    for (int w = 0; w < s->nwalls; w++)
        if (s->walls[w].active && s->walls[w].shape && s->walls[w].shape->moved > 0.5 * s->skin)
            return 1;
    return 0;
}

/* ---- motion ---------------------------------------------------------------------------------- */
void dem_shape_sample(dem_shape *sh, double t)
{
    if (sh->nt == 0)
        return;
    const double *tab = sh->tab;
    const size_t nt = sh->nt;
    const double *row;
    double mix[7];
    if (t <= tab[0]) {
        row = tab;
    } else if (t >= tab[7 * (nt - 1)]) {
        row = tab + 7 * (nt - 1);
    } else {
        size_t lo = 0, hi = nt - 1; /* tab[7 lo] <= t < tab[7 hi] */
        while (hi - lo > 1) {
            size_t mid = (lo + hi) / 2;
            if (tab[7 * mid] <= t)
                lo = mid;
            else
                hi = mid;
        }
        const double *a = tab + 7 * lo, *b = tab + 7 * hi;
        const double u = (t - a[0]) / (b[0] - a[0]);
        for (int k = 1; k < 7; k++)
            mix[k] = a[k] + u * (b[k] - a[k]);
        row = mix;
    }
    for (int d = 0; d < 3; d++) {
        sh->vel[d] = row[1 + d];
        sh->omega[d] = row[4 + d];
    }
}

/* x <- exp([w]) x for the rotation matrix (Rodrigues), w = omega dt. */
static void turn3(double *rot, const double *w)
{
    const double th = sqrt(dot3(w, w));
    if (!(th > 0))
        return;
    const double k[3] = {w[0] / th, w[1] / th, w[2] / th}, c = cos(th), sn = sin(th);
    const double K[9] = {0, -k[2], k[1], k[2], 0, -k[0], -k[1], k[0], 0};
    double R[9], out[9];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double k2 = 0;
            for (int m = 0; m < 3; m++)
                k2 += K[3 * a + m] * K[3 * m + b];
            R[3 * a + b] = (a == b) + sn * K[3 * a + b] + (1 - c) * k2;
        }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            out[3 * a + b] =
                R[3 * a] * rot[b] + R[3 * a + 1] * rot[3 + b] + R[3 * a + 2] * rot[6 + b];
    memcpy(rot, out, sizeof out);
}

static void shape_move(dem_scene *s, dem_wall *wl, double dt)
{
    dem_shape *sh = wl->shape;
    const int D = s->dim;
    /* the midpoint rate: exact for a motion linear in time within the step */
    dem_shape_sample(sh, s->time + 0.5 * dt);
    double v2 = 0, wturn[3] = {0, 0, 0};
    for (int d = 0; d < D; d++) {
        sh->center[d] += dt * sh->vel[d];
        v2 += sh->vel[d] * sh->vel[d];
    }
    if (D == 2) {
        sh->angle += dt * sh->omega[2];
        rot_from_angle(sh);
        wturn[2] = sh->omega[2];
    } else {
        const double w[3] = {dt * sh->omega[0], dt * sh->omega[1], dt * sh->omega[2]};
        turn3(sh->rot, w);
        memcpy(wturn, sh->omega, sizeof wturn);
    }
    double turn = sqrt(dot3(wturn, wturn));
    if (sh->spins_in_place) { /* only a tilt of the axis moves the surface */
        double a[3], wa;
        to_world_vec(sh, sh->axis, a);
        wa = D == 2 ? turn : dot3(wturn, a);
        turn = sqrt(fmax(0, turn * turn - wa * wa));
    }
    sh->moved += dt * (sqrt(v2) + (turn > 0 ? turn * sh->reach : 0));
    dem_shape_sample(sh, s->time + dt);
    for (int d = 0; d < 3; d++)
        wl->point[d] = sh->center[d];
}

/* After the planes' motion, which passes over these walls (their own velocity stays 0). */
void dem_shapes_move(dem_scene *s, double dt)
{
    for (int w = 0; w < s->nwalls; w++)
        if (s->walls[w].shape)
            shape_move(s, &s->walls[w], dt);
}

int dem_shapes_driven(const dem_scene *s)
{
    for (int w = 0; w < s->nwalls; w++) {
        const dem_shape *sh = s->walls[w].shape;
        if (!sh || !s->walls[w].active)
            continue;
        if (sh->nt > 0)
            return 1;
        for (int d = 0; d < 3; d++)
            if (sh->vel[d] != 0 || sh->omega[d] != 0)
                return 1;
    }
    return 0;
}

void dem_shape_free(dem_shape *sh)
{
    if (!sh)
        return;
    free(sh->v), free(sh->e), free(sh->tab), free(sh->cload), free(sh->cand);
    free(sh);
}

/* ---- creation -------------------------------------------------------------------------------- */
/* Vertex id of point p among the first nv (equal coordinates: the same vertex), or a new one. */
static uint32_t vertex_id(double *v, size_t *nv, const double *p)
{
    for (size_t k = 0; k < *nv; k++)
        if (v[3 * k] == p[0] && v[3 * k + 1] == p[1] && v[3 * k + 2] == p[2])
            return (uint32_t)k;
    memcpy(v + 3 * *nv, p, 3 * sizeof *p);
    return (uint32_t)(*nv)++;
}

/* A triangle given twice would push twice: refused (sorted corner ids, compared after a sort). */
static int cmp_tri(const void *pa, const void *pb)
{
    const uint32_t *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k] ? -1 : 1;
    return a[3] < b[3] ? -1 : a[3] > b[3];
}

static core_status unique_triangles(const dem_shape *sh, core_error *err)
{
    uint32_t(*t)[4] = malloc((sh->ne ? sh->ne : 1) * sizeof *t);
    if (!t)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the wall's triangles");
    for (size_t k = 0; k < sh->ne; k++) {
        uint32_t a = sh->e[3 * k], b = sh->e[3 * k + 1], c = sh->e[3 * k + 2], x;
        if (a > b)
            x = a, a = b, b = x;
        if (b > c)
            x = b, b = c, c = x;
        if (a > b)
            x = a, a = b, b = x;
        t[k][0] = a, t[k][1] = b, t[k][2] = c, t[k][3] = (uint32_t)k;
    }
    qsort(t, sh->ne, sizeof *t, cmp_tri);
    core_status st = CORE_OK;
    for (size_t k = 1; k < sh->ne && !st; k++)
        if (t[k][0] == t[k - 1][0] && t[k][1] == t[k - 1][1] && t[k][2] == t[k - 1][2])
            st = core_fail(err, CORE_ERR_ARG, "triangle %u repeats triangle %u (field 'triangles')",
                           (unsigned)t[k][3] + 1, (unsigned)t[k - 1][3] + 1);
    free(t);
    return st;
}

static core_status build_geometry(const dem_scene *s, const dem_shape_def *def, dem_shape *sh,
                                  core_error *err)
{
    const int D = s->dim;
    if (def->kind == DEM_WALL_CYLINDER) {
        if (!(def->radius > 0) || !isfinite(def->radius))
            return core_fail(err, CORE_ERR_ARG, "radius must be > 0, got %g", def->radius);
        sh->radius = def->radius;
        sh->inside = def->inside != 0;
        sh->half = INFINITY;
        sh->axis[2] = 1;
        if (D == 3) {
            double l = sqrt(dot3(def->axis, def->axis));
            if (!(l > 1e-12) || !dem_finite_n(def->axis, 3))
                return core_fail(err, CORE_ERR_ARG, "axis must be a finite non-zero vector");
            for (int d = 0; d < 3; d++)
                sh->axis[d] = def->axis[d] / l;
            if (!(def->length >= 0) || !isfinite(def->length))
                return core_fail(err, CORE_ERR_ARG, "length must be >= 0, got %g", def->length);
            if (def->length > 0)
                sh->half = 0.5 * def->length;
        }
        sh->reach = D == 2 ? def->radius : hypot(def->radius, sh->half);
        sh->spins_in_place = 1;
        return CORE_OK;
    }
    const int seg = def->kind == DEM_WALL_SEGMENTS;
    if (seg ? D != 2 : D != 3)
        return core_fail(err, CORE_ERR_ARG, "%s walls are %s only", seg ? "segment" : "triangle",
                         seg ? "2D" : "3D");
    const size_t n = def->n, npts = seg ? n : 3 * n;
    if (seg ? n < 2 : n < 1)
        return core_fail(err, CORE_ERR_ARG, "%s",
                         seg ? "a polyline needs at least 2 points (field 'points')"
                             : "a mesh needs at least 1 triangle (field 'triangles')");
    if (seg && def->closed && n < 3)
        return core_fail(err, CORE_ERR_ARG,
                         "a closed polyline needs at least 3 points (field 'closed')");
    if (npts > (size_t)1 << 24)
        return core_fail(err, CORE_ERR_ARG, "too many points (%zu)", npts);
    if (!dem_finite_n(def->points, 3 * npts))
        return core_fail(err, CORE_ERR_ARG, "points must be finite");
    double c[3] = {0, 0, 0};
    for (size_t k = 0; k < npts; k++)
        for (int d = 0; d < D; d++)
            c[d] += def->points[3 * k + d] / (double)npts;
    if (def->has_center)
        memcpy(c, def->center, sizeof c);
    if (D == 2)
        c[2] = 0;
    memcpy(sh->center, c, sizeof c);
    sh->v = malloc(3 * npts * sizeof *sh->v);
    sh->ne = seg ? (def->closed ? n : n - 1) : n;
    sh->e = malloc((seg ? 2 : 3) * sh->ne * sizeof *sh->e);
    uint32_t *ids = malloc(npts * sizeof *ids);
    if (!sh->v || !sh->e || !ids) {
        free(ids);
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the wall's vertices");
    }
    for (size_t k = 0; k < npts; k++) {
        double p[3] = {0, 0, 0};
        for (int d = 0; d < D; d++)
            p[d] = def->points[3 * k + d] - c[d];
        ids[k] = vertex_id(sh->v, &sh->nv, p);
    }
    core_status st = CORE_OK;
    for (size_t k = 0; k < sh->ne && !st; k++) {
        if (seg) {
            sh->e[2 * k] = ids[k], sh->e[2 * k + 1] = ids[(k + 1) % n];
            if (sh->e[2 * k] == sh->e[2 * k + 1])
                st = core_fail(err, CORE_ERR_ARG,
                               "segment %zu has no length (points %zu and %zu "
                               "are equal, field 'points')",
                               k + 1, k + 1, (k + 1) % n + 1);
        } else {
            for (int a = 0; a < 3; a++)
                sh->e[3 * k + (size_t)a] = ids[3 * k + (size_t)a];
            double x[3];
            const double *a = sh->v + 3 * sh->e[3 * k], *b = sh->v + 3 * sh->e[3 * k + 1],
                         *cc = sh->v + 3 * sh->e[3 * k + 2];
            double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double w[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
            x[0] = u[1] * w[2] - u[2] * w[1], x[1] = u[2] * w[0] - u[0] * w[2];
            x[2] = u[0] * w[1] - u[1] * w[0];
            if (!(dot3(x, x) > 1e-24 * dot3(u, u) * dot3(w, w)))
                st = core_fail(err, CORE_ERR_ARG,
                               "triangle %zu is degenerate (no area, field 'triangles')", k + 1);
        }
    }
    free(ids);
    if (!st && !seg)
        st = unique_triangles(sh, err);
    for (size_t k = 0; k < sh->nv; k++)
        sh->reach = fmax(sh->reach, sqrt(dot3(sh->v + 3 * k, sh->v + 3 * k)));
    return st;
}

int dem_add_shape_wall(dem_scene *s, const dem_shape_def *def, core_error *err)
{
    const int D = s->dim;
    if (def->kind != DEM_WALL_SEGMENTS && def->kind != DEM_WALL_TRIANGLES &&
        def->kind != DEM_WALL_CYLINDER)
        return core_fail(err, CORE_ERR_ARG, "unknown wall kind %d", (int)def->kind), -1;
    if (def->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "unknown material %d", def->material), -1;
    if (!isfinite(def->friction))
        return core_fail(err, CORE_ERR_ARG, "friction must be finite"), -1;
    if (!dem_finite_n(def->center, 3) || !dem_finite_n(def->velocity, 3) ||
        !dem_finite_n(def->omega, 3))
        return core_fail(err, CORE_ERR_ARG, "center, velocity and omega must be finite"), -1;
    if (def->nmotion > 0) {
        if (!dem_finite_n(def->motion, 7 * def->nmotion))
            return core_fail(err, CORE_ERR_ARG, "the motion table must be finite"), -1;
        for (size_t k = 1; k < def->nmotion; k++)
            if (!(def->motion[7 * k] > def->motion[7 * (k - 1)]))
                return core_fail(err, CORE_ERR_ARG,
                                 "motion times must increase (row %zu: %g "
                                 "after %g, field 'motion')",
                                 k + 1, def->motion[7 * k], def->motion[7 * (k - 1)]),
                       -1;
    }
    dem_shape *sh = calloc(1, sizeof *sh);
    if (!sh)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate a wall"), -1;
    sh->kind = def->kind;
    memcpy(sh->center, def->center, sizeof sh->center);
    if (D == 2)
        sh->center[2] = 0;
    rot_from_angle(sh); /* the identity */
    core_status st = build_geometry(s, def, sh, err);
    if (!st && def->nmotion > 0) {
        sh->tab = malloc(7 * def->nmotion * sizeof *sh->tab);
        if (!sh->tab)
            st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate the motion table");
        else
            memcpy(sh->tab, def->motion, 7 * def->nmotion * sizeof *sh->tab);
        sh->nt = def->nmotion;
    }
    if (st) {
        dem_shape_free(sh);
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        sh->vel[d] = d < D ? def->velocity[d] : 0;
        sh->omega[d] = D == 3 || d == 2 ? def->omega[d] : 0;
    }
    if (sh->nt) { /* zero the unused components of the table, as of the constants */
        for (size_t k = 0; k < sh->nt; k++)
            for (int d = 0; d < 3; d++) {
                if (d >= D)
                    sh->tab[7 * k + 1 + d] = 0;
                if (D == 2 && d < 2)
                    sh->tab[7 * k + 4 + d] = 0;
            }
        dem_shape_sample(sh, s->time);
    }
    /* the planes' fields: the centre as its point, no velocity (the planes' motion, which
     * passes over this wall, must not move it: dem_shapes_move does) */
    dem_wall wl = {.active = 1, .friction = def->friction, .material = def->material, .shape = sh};
    for (int d = 0; d < 3; d++)
        wl.point[d] = wl.point_build[d] = sh->center[d];
    for (size_t i = 0; i < s->n; i++) {
        const double x[3] = {s->x[0][i], s->x[1][i], D == 3 ? s->x[2][i] : 0};
        double dist = dem_shape_distance(s, &wl, x);
        if (dist < s->r[i] * (1 - 1e-9)) {
            dem_shape_free(sh);
            return core_fail(err, CORE_ERR_ARG,
                             "wall would overlap particle %zu (distance %g, radius %g)", i + 1,
                             dist, s->r[i]),
                   -1;
        }
    }
    if (s->nwalls == s->cap_walls) {
        int cap = s->cap_walls ? 2 * s->cap_walls : 8;
        dem_wall *p = realloc(s->walls, (size_t)cap * sizeof *p);
        if (!p) {
            dem_shape_free(sh);
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate walls"), -1;
        }
        s->walls = p;
        s->cap_walls = cap;
    }
    s->walls[s->nwalls] = wl;
    s->nshaped++;
    dem_invalidate(s, 1);
    return s->nwalls++;
}

dem_wall_kind dem_wall_kind_of(const dem_scene *s, int id)
{
    if (id < 0 || id >= s->nwalls || !s->walls[id].shape)
        return DEM_WALL_PLANE;
    return s->walls[id].shape->kind;
}

core_status dem_wall_load(const dem_scene *s, int id, double force[3], double torque[3],
                          core_error *err)
{
    if (id < 0 || id >= s->nwalls || !s->walls[id].active)
        return core_fail(err, CORE_ERR_ARG, "no wall %d", id + 1);
    const dem_wall *wl = &s->walls[id];
    for (int d = 0; d < 3; d++) {
        force[d] = wl->shape ? wl->shape->force[d] : -wl->fn * wl->normal[d];
        torque[d] = wl->shape ? wl->shape->torque[d] : 0;
    }
    return CORE_OK;
}

int dem_wall_outline(const dem_scene *s, int id, int segments, int *nv, double *pts, size_t *npts)
{
    *npts = 0;
    if (id < 0 || id >= s->nwalls || !s->walls[id].active || !s->walls[id].shape)
        return 0;
    const dem_shape *sh = s->walls[id].shape;
    const int D = s->dim;
    int strips = 0;
    size_t q = 0;
#define EMIT(pb)                                                                                   \
    do {                                                                                           \
        if (pts) {                                                                                 \
            double w_[3];                                                                          \
            to_world_vec(sh, (pb), w_);                                                            \
            for (int d_ = 0; d_ < 3; d_++)                                                         \
                pts[3 * q + (size_t)d_] = d_ < D ? w_[d_] + sh->center[d_] : 0;                    \
        }                                                                                          \
        q++;                                                                                       \
    } while (0)
    if (sh->kind == DEM_WALL_SEGMENTS) { /* one strip: the polyline, closed by repeating p0 */
        const size_t n = sh->ne + 1;
        for (size_t k = 0; k < n; k++)
            EMIT(sh->v + 3 * sh->e[2 * (k < sh->ne ? k : k - 1) + (k < sh->ne ? 0 : 1)]);
        if (nv)
            nv[strips] = (int)n;
        strips++;
    } else if (sh->kind == DEM_WALL_TRIANGLES) {
        for (size_t k = 0; k < sh->ne; k++) {
            for (int a = 0; a < 3; a++)
                EMIT(sh->v + 3 * sh->e[3 * k + (size_t)a]);
            if (nv)
                nv[strips] = 3;
            strips++;
        }
    } else {
        /* a circle (2D); a cylinder: the two rims (a finite length) or rims at +-reach of the
         * box's size for an infinite one */
        double half = sh->half;
        if (!isfinite(half)) {
            double lo[3], hi[3], g[3];
            dem_box(s, lo, hi, g);
            half = 0;
            for (int d = 0; d < D; d++)
                half = fmax(half, hi[d] - lo[d]);
        }
        double u[3], w[3];
        const double *a = sh->axis;
        u[0] = fabs(a[0]) > 0.9 ? 0 : 1, u[1] = fabs(a[0]) > 0.9 ? 1 : 0, u[2] = 0;
        double ua = dot3(u, a), ul = 0;
        for (int d = 0; d < 3; d++)
            u[d] -= ua * a[d], ul += u[d] * u[d];
        for (int d = 0; d < 3; d++)
            u[d] /= sqrt(ul);
        w[0] = a[1] * u[2] - a[2] * u[1], w[1] = a[2] * u[0] - a[0] * u[2];
        w[2] = a[0] * u[1] - a[1] * u[0];
        for (int rim = 0; rim < (D == 2 ? 1 : 2); rim++) {
            const double e = D == 2 ? 0 : (rim ? half : -half);
            for (int k = 0; k <= segments; k++) {
                const double t = 2 * DEM_PI * k / segments;
                double pb[3];
                for (int d = 0; d < 3; d++)
                    pb[d] = D == 2 ? (d == 0   ? sh->radius * cos(t)
                                      : d == 1 ? sh->radius * sin(t)
                                               : 0)
                                   : e * a[d] + sh->radius * (cos(t) * u[d] + sin(t) * w[d]);
                EMIT(pb);
            }
            if (nv)
                nv[strips] = segments + 1;
            strips++;
        }
    }
#undef EMIT
    *npts = q;
    return strips;
}
