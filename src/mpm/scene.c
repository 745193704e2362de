/* MPM scenes: the grid, materials, grains filled with points, bulk access. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/memory.h"
#include "mpm/mpm_internal.h"

mpm_scene_def mpm_default_scene_def(void)
{
    return (mpm_scene_def){
        .cells = {10, 10},
        .origin = {0, 0},
        .size = {1, 1},
        .periodic = {false, false},
        .gravity = {0, 0},
        .walls = {MPM_WALL_NOSLIP, MPM_WALL_NOSLIP, MPM_WALL_NOSLIP, MPM_WALL_NOSLIP},
        .update = MPM_MUSL,
        .shape = MPM_SHAPE_LINEAR,
        .wall_gap = 0.02,
        .pic = 0};
}

static void *alloc_zero(size_t n, size_t size) { return calloc(n ? n : 1, size); }

/* The arrays a loop walks together at the same index (the point arrays; the nodal arrays, whose
 * grain entries the scatter accumulates into) each start k cache lines into their block, k their
 * number below (STAGGER_*; core_realloc_staggered, src/core/memory.h). Large blocks from malloc
 * all begin at the same offset within a page, so element p of twenty arrays would fall into one
 * set of the 8-way first-level cache. On the MPM bench the stress update's first-level misses
 * went from 13.9 to 3.1 per point (cachegrind) and its time halved; before, its loop took a third
 * longer with its four check arrays than without them. */
enum { STAGGER_POINT = 0, STAGGER_INT = 24, STAGGER_STENCIL = 27, STAGGER_NODE = 30 };

/* 1D shape function of the scene's kind at offset t (in cells) from its node. */
static double shape1(const mpm_scene *s, double t)
{
    t = fabs(t);
    if (s->ns == 9)
        return t < 0.5 ? 0.75 - t * t : (t < 1.5 ? 0.5 * (1.5 - t) * (1.5 - t) : 0);
    return t < 1 ? 1 - t : 0;
}

/* For friction plane k: at every node of the plane, the shape-weighted mean distance from the
 * plane of material filling the whole half-space in front of it, by midpoint quadrature over the
 * node's support (64 x 64 samples). The gap test compares the nodal material's centroid with
 * it. */
static core_status plane_reference(mpm_scene *s, int k, core_error *err)
{
    const mpm_plane *pl = &s->planes[k];
    if (pl->kind != MPM_WALL_FRICTION || !(s->def.wall_gap > 0))
        return CORE_OK;
    if (!s->nmx) {
        s->nmx = alloc_zero(s->nnodes, sizeof(double));
        s->nmy = alloc_zero(s->nnodes, sizeof(double));
    }
    if (!(s->dref[k] = alloc_zero(s->nnodes, sizeof(double))) || !s->nmx || !s->nmy)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the wall gap test");
    const double reach = s->ns == 9 ? 1.5 : 1.0;
    const int M = 64;
    for (int j = 0; j < s->nny; j++)
        for (int i = 0; i < s->nnx; i++) {
            const size_t node = (size_t)j * s->nnx + i;
            if (!(s->nwall[node] & (1u << k)))
                continue;
            const double xi = s->def.origin[0] + (i - s->gl[0]) * s->hx;
            const double yi = s->def.origin[1] + (j - s->gl[1]) * s->hy;
            double w = 0, wd = 0;
            for (int b = 0; b < M; b++) {
                const double ty = -reach + (b + 0.5) * 2 * reach / M;
                const double wy = shape1(s, ty);
                for (int a = 0; a < M; a++) {
                    const double tx = -reach + (a + 0.5) * 2 * reach / M;
                    /* distance out of the body: -(x - point) . n */
                    const double d = -((xi + tx * s->hx - pl->point[0]) * pl->n[0] +
                                       (yi + ty * s->hy - pl->point[1]) * pl->n[1]);
                    if (d <= 0)
                        continue;
                    const double ww = shape1(s, tx) * wy;
                    w += ww;
                    wd += ww * d;
                }
            }
            s->dref[k][node] = w > 0 ? wd / w : 0;
        }
    return CORE_OK;
}

/* The scene definition's values, and a grid whose creation fields fit in memory. */
static core_status check_scene_def(const mpm_scene_def *def, core_error *err)
{
    for (int d = 0; d < 2; d++) {
        if (def->cells[d] < 1 || def->cells[d] > 1 << 20)
            return core_fail(err, CORE_ERR_ARG, "cells[%d] must be in [1, 1048576], got %d", d + 1,
                             def->cells[d]);
        if (!(def->size[d] > 0) || !isfinite(def->size[d]))
            return core_fail(err, CORE_ERR_ARG, "size[%d] must be > 0, got %g", d + 1,
                             def->size[d]);
        if (!isfinite(def->origin[d]) || !isfinite(def->gravity[d]))
            return core_fail(err, CORE_ERR_ARG, "origin and gravity must be finite");
        if (def->periodic[d] && def->cells[d] < 3)
            return core_fail(err, CORE_ERR_ARG, "a periodic axis needs at least 3 cells, got %d",
                             def->cells[d]);
    }
    for (int k = 0; k < 4; k++) {
        if (!(def->wall_mu[k] >= 0) || !isfinite(def->wall_mu[k]))
            return core_fail(err, CORE_ERR_ARG, "wall friction must be finite and >= 0, got %g",
                             def->wall_mu[k]);
        if (!isfinite(def->wall_velocity[k][0]) || !isfinite(def->wall_velocity[k][1]))
            return core_fail(err, CORE_ERR_ARG, "wall velocities must be finite");
        if ((unsigned)def->walls[k] > MPM_WALL_FRICTION)
            return core_fail(err, CORE_ERR_ARG, "unknown wall kind %d", (int)def->walls[k]);
    }
    if ((unsigned)def->update > MPM_USF)
        return core_fail(err, CORE_ERR_ARG, "unknown update order %d", (int)def->update);
    if (!(def->wall_gap >= 0) || !isfinite(def->wall_gap))
        return core_fail(err, CORE_ERR_ARG, "wall_gap must be finite and >= 0, got %g",
                         def->wall_gap);
    if (def->shape != MPM_SHAPE_LINEAR && def->shape != MPM_SHAPE_BSPLINE)
        return core_fail(err, CORE_ERR_ARG, "unknown shape functions %d", (int)def->shape);
    if (!(def->pic >= 0 && def->pic <= 1))
        return core_fail(err, CORE_ERR_ARG, "pic must be in [0, 1], got %g", def->pic);
    {
        /* The grid at creation holds 9 doubles and 2 bytes per node, and frictional contact adds
         * per-grain fields later. Calloc of a huge grid may "succeed" on an overcommitting
         * system and kill the process at the first step, so a grid whose creation fields do not
         * fit in the machine's memory (core/memory.h) is refused here, with the numbers. */
        const double budget = core_memory_budget();
        double nodes = (def->cells[0] + 3.0) * (def->cells[1] + 3.0);
        double bytes = nodes * (9 * sizeof(double) + 2);
        if (bytes > budget)
            return core_fail(
                err, CORE_ERR_ARG,
                "cells %d x %d need %.3g bytes of grid fields, above the limit of "
                "%.3g bytes (the machine's memory, or GRAINLAB_MEMORY_LIMIT); use fewer cells "
                "(field 'cells')",
                def->cells[0], def->cells[1], bytes, budget);
    }
    return CORE_OK;
}

/* The grid's edges as planes 0-3 (n into the wall); their nodes are the boundary rows and
 * columns and the ghost layers beyond them, on axes that are not periodic. */
static void edge_planes(mpm_scene *s)
{
    const mpm_scene_def *def = &s->def;
    static const double normals[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    for (int k = 0; k < 4; k++) {
        mpm_plane *pl = &s->planes[k];
        pl->kind = def->periodic[k / 2] ? MPM_WALL_NONE : def->walls[k];
        pl->n[0] = normals[k][0];
        pl->n[1] = normals[k][1];
        pl->v[0] = def->wall_velocity[k][0];
        pl->v[1] = def->wall_velocity[k][1];
        pl->mu = def->wall_mu[k];
    }
    s->nplanes = 4;
    for (int j = 0; j < s->nny; j++)
        for (int i = 0; i < s->nnx; i++) {
            unsigned char w = 0;
            int gi = i - s->gl[0], gj = j - s->gl[1];
            if (!def->periodic[0] && gi <= 0 && s->planes[MPM_LEFT].kind != MPM_WALL_NONE)
                w |= 1u << MPM_LEFT;
            if (!def->periodic[0] && gi >= def->cells[0] &&
                s->planes[MPM_RIGHT].kind != MPM_WALL_NONE)
                w |= 1u << MPM_RIGHT;
            if (!def->periodic[1] && gj <= 0 && s->planes[MPM_BOTTOM].kind != MPM_WALL_NONE)
                w |= 1u << MPM_BOTTOM;
            if (!def->periodic[1] && gj >= def->cells[1] &&
                s->planes[MPM_TOP].kind != MPM_WALL_NONE)
                w |= 1u << MPM_TOP;
            s->nwall[(size_t)j * s->nnx + i] = w;
        }
}

core_status mpm_create(const mpm_scene_def *def, mpm_scene **out, core_error *err)
{
    *out = NULL;
    core_status st = check_scene_def(def, err);
    if (st)
        return st;
    mpm_scene *s = calloc(1, sizeof *s);
    if (!s)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the scene");
    s->def = *def;
    s->hx = def->size[0] / def->cells[0];
    s->hy = def->size[1] / def->cells[1];
    s->inv_hx = 1 / s->hx;
    s->inv_hy = 1 / s->hy;
    s->ns = def->shape == MPM_SHAPE_BSPLINE ? 9 : 4;
    for (int a = 0; a < 2; a++)
        s->gl[a] = def->shape == MPM_SHAPE_BSPLINE && !def->periodic[a] ? 1 : 0;
    s->nnx = def->cells[0] + (def->periodic[0] ? 0 : 1 + 2 * s->gl[0]);
    s->nny = def->cells[1] + (def->periodic[1] ? 0 : 1 + 2 * s->gl[1]);
    s->nnodes = (size_t)s->nnx * (size_t)s->nny;
    double **fields[] = {&s->nm,  &s->npx, &s->npy, &s->nfx, &s->nfy,
                         &s->nvx, &s->nvy, &s->nax, &s->nay};
    for (size_t k = 0; k < sizeof fields / sizeof *fields; k++) {
        const size_t bytes = (s->nnodes ? s->nnodes : 1) * sizeof(double);
        if (!(*fields[k] = core_realloc_staggered(NULL, bytes, STAGGER_NODE + (int)k))) {
            mpm_destroy(s);
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu grid nodes", s->nnodes);
        }
        memset(*fields[k], 0, bytes);
    }
    if (!(s->nwall = alloc_zero(s->nnodes, 1)) || !(s->nwin = alloc_zero(s->nnodes, 1))) {
        mpm_destroy(s);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu grid nodes", s->nnodes);
    }
    edge_planes(s);
    s->opt = mpm_default_contact_options();
    for (int k = 0; k < 4; k++)
        s->slack[k / 2][k % 2] =
            s->planes[k].kind == MPM_WALL_NONE ? 0 : 0.25 * (k / 2 ? s->hy : s->hx);
    for (int k = 0; k < 4; k++) {
        /* the grid edge's plane passes through the edge */
        s->planes[k].point[0] = def->origin[0] + (k == MPM_RIGHT ? def->size[0] : 0);
        s->planes[k].point[1] = def->origin[1] + (k == MPM_TOP ? def->size[1] : 0);
        if ((st = plane_reference(s, k, err))) {
            mpm_destroy(s);
            return st;
        }
    }
    s->contact = MPM_CONTACT_NOSLIP;
    *out = s;
    return CORE_OK;
}

static double **point_doubles(mpm_scene *s, int k)
{
    double **list[] = {&s->x,     &s->y,     &s->vx,     &s->vy,     &s->m,      &s->v0,
                       &s->F[0],  &s->F[1],  &s->F[2],   &s->F[3],   &s->be[0],  &s->be[1],
                       &s->be[2], &s->be[3], &s->sig[0], &s->sig[1], &s->sig[2], &s->sig[3],
                       &s->eps_p, &s->ux,    &s->uy,     &s->lzz,    NULL};
    return list[k];
}

void mpm_destroy(mpm_scene *s)
{
    if (!s)
        return;
    double *fields[] = {s->nm, s->npx, s->npy, s->nfx, s->nfy, s->nvx, s->nvy, s->nax, s->nay};
    for (size_t k = 0; k < sizeof fields / sizeof *fields; k++)
        core_free_staggered(fields[k], STAGGER_NODE + (int)k);
    double *stencil[] = {s->sw, s->sgx, s->sgy};
    for (int k = 0; k < 3; k++)
        core_free_staggered(stencil[k], STAGGER_STENCIL + k);
    for (int k = 0; point_doubles(s, k); k++)
        core_free_staggered(*point_doubles(s, k), STAGGER_POINT + k);
    free(s->rate);
    free(s->nwall);
    free(s->nwin);
    free(s->nmx);
    free(s->nmy);
    for (int k = 0; k < 4 + MPM_MAX_PLANES; k++)
        free(s->dref[k]);
    free(s->gpres);
    free(s->pv);
    free(s->nforce);
    free(s->pwin);
    free(s->pvol);
    free(s->pnode);
    free(s->pgrain);
    free(s->pin);
    free(s->pnx);
    free(s->pny);
    free(s->ngr);
    free(s->nhead);
    free(s->pnext);
    free(s->pshared);
    free(s->sv);
    core_free_staggered(s->grain, STAGGER_INT);
    core_free_staggered(s->mat, STAGGER_INT + 1);
    core_free_staggered(s->sn, STAGGER_INT + 2);
    free(s->mats);
    free(s->gstart);
    free(s->gcount);
    free(s->gdef);
    mpm_step_free(s->step);
    free(s);
}

const mpm_scene_def *mpm_def(const mpm_scene *s) { return &s->def; }

void mpm_cell_size(const mpm_scene *s, double h[2])
{
    h[0] = s->hx;
    h[1] = s->hy;
}

/* The point rates of the continuum models, for cap points (zero), once. */
static core_status reserve_rate(mpm_scene *s, core_error *err)
{
    double *r = realloc(s->rate, (s->cap ? s->cap : 1) * sizeof *r);
    if (!r)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", s->cap);
    if (!s->rate)
        memset(r, 0, (s->cap ? s->cap : 1) * sizeof *r);
    s->rate = r;
    return CORE_OK;
}

int mpm_add_material(mpm_scene *s, const mpm_material *m, core_error *err)
{
    if (mpm_check_material(m, err))
        return -1;
    if ((m->model == MPM_DRUCKER_PRAGER || m->model == MPM_MU_I) && !s->rate &&
        reserve_rate(s, err))
        return -1;
    if (s->nmat == s->matcap) {
        int cap = s->matcap ? 2 * s->matcap : 4;
        mpm_material *p = realloc(s->mats, (size_t)cap * sizeof *p);
        if (!p) {
            core_fail(err, CORE_ERR_NOMEM, "out of memory for materials");
            return -1;
        }
        s->mats = p;
        s->matcap = cap;
    }
    s->mats[s->nmat] = *m;
    mpm_material_prepare(&s->mats[s->nmat]);
    return s->nmat++;
}

/* Grows the point arrays (and the stencil) to hold n points. Allocation happens here, when grains
 * are added, never in the step loop. */
static core_status reserve_points(mpm_scene *s, size_t n, core_error *err)
{
    if (n <= s->cap)
        return CORE_OK;
    size_t cap = s->cap ? s->cap : 1024;
    while (cap < n)
        cap *= 2;
    for (int k = 0; point_doubles(s, k); k++) {
        double **a = point_doubles(s, k);
        double *p = core_realloc_staggered(*a, cap * sizeof(double), STAGGER_POINT + k);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", cap);
        *a = p;
    }
    int **ints[] = {&s->grain, &s->mat};
    for (int k = 0; k < 2; k++) {
        int *p = core_realloc_staggered(*ints[k], cap * sizeof(int), STAGGER_INT + k);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", cap);
        *ints[k] = p;
    }
    int *sn = core_realloc_staggered(s->sn, cap * MPM_STENCIL * sizeof(int), STAGGER_INT + 2);
    if (!sn)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", cap);
    s->sn = sn;
    double **st[] = {&s->sw, &s->sgx, &s->sgy};
    for (int k = 0; k < 3; k++) {
        double *p =
            core_realloc_staggered(*st[k], cap * MPM_STENCIL * sizeof(double), STAGGER_STENCIL + k);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", cap);
        *st[k] = p;
    }
    const size_t old = s->cap;
    s->cap = cap;
    if (s->rate) {
        core_status rs = reserve_rate(s, err);
        if (rs)
            return rs;
        memset(s->rate + old, 0, (cap - old) * sizeof *s->rate);
    }
    return CORE_OK;
}

mpm_grain_def mpm_default_grain_def(void)
{
    return (mpm_grain_def){
        .shape = MPM_DISK, .radius = 0, .material = 0, .points_per_cell = 2, .clip = false};
}

static bool inside(const mpm_grain_def *g, double x, double y)
{
    if (g->shape == MPM_DISK) {
        double dx = x - g->center[0], dy = y - g->center[1];
        return dx * dx + dy * dy <= g->radius * g->radius;
    }
    if (g->shape == MPM_POLYGON) { /* crossing number */
        bool in = false;
        const double *v = g->vertices;
        for (int i = 0, j = g->nvertices - 1; i < g->nvertices; j = i++) {
            const double xi = v[2 * i], yi = v[2 * i + 1], xj = v[2 * j], yj = v[2 * j + 1];
            if ((yi > y) != (yj > y) && x < xi + (y - yi) * (xj - xi) / (yj - yi))
                in = !in;
        }
        return in;
    }
    return x >= g->lo[0] && x <= g->hi[0] && y >= g->lo[1] && y <= g->hi[1];
}

/* The grain's material, points per cell and shape, and its bounding box [lo, hi]: inside the
 * grid on an axis that is not periodic (unless clipped), shorter than a periodic axis. */
static core_status grain_bounds(const mpm_scene *s, const mpm_grain_def *g, double lo[2],
                                double hi[2], core_error *err)
{
    const mpm_scene_def *d = &s->def;
    if (g->material < 0 || g->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "material index %d is not in the scene", g->material);
    if (g->points_per_cell < 1 || g->points_per_cell > 64)
        return core_fail(err, CORE_ERR_ARG, "points per cell must be in [1, 64], got %d",
                         g->points_per_cell);
    if (g->shape == MPM_POLYGON) {
        if (g->nvertices < 3 || !g->vertices)
            return core_fail(err, CORE_ERR_ARG, "a polygon needs at least 3 vertices, got %d",
                             g->nvertices);
        double area = 0;
        lo[0] = lo[1] = INFINITY;
        hi[0] = hi[1] = -INFINITY;
        for (int i = 0, j = g->nvertices - 1; i < g->nvertices; j = i++) {
            const double *v = g->vertices;
            if (!isfinite(v[2 * i]) || !isfinite(v[2 * i + 1]))
                return core_fail(err, CORE_ERR_ARG, "vertex %d of the polygon is not finite",
                                 i + 1);
            area += v[2 * j] * v[2 * i + 1] - v[2 * i] * v[2 * j + 1];
            for (int a = 0; a < 2; a++) {
                lo[a] = fmin(lo[a], v[2 * i + a]);
                hi[a] = fmax(hi[a], v[2 * i + a]);
            }
        }
        if (!(fabs(area) > 0))
            return core_fail(err, CORE_ERR_ARG, "the polygon has zero area (collinear vertices)");
    } else if (g->shape == MPM_DISK) {
        if (!(g->radius > 0) || !isfinite(g->radius))
            return core_fail(err, CORE_ERR_ARG, "radius must be > 0, got %g", g->radius);
        for (int a = 0; a < 2; a++) {
            lo[a] = g->center[a] - g->radius;
            hi[a] = g->center[a] + g->radius;
        }
    } else {
        for (int a = 0; a < 2; a++) {
            if (!(g->hi[a] > g->lo[a]))
                return core_fail(err, CORE_ERR_ARG,
                                 "the rectangle's upper corner must be above the "
                                 "lower one on every axis");
            lo[a] = g->lo[a];
            hi[a] = g->hi[a];
        }
    }
    static const char *const axis[2] = {"x", "y"};
    for (int a = 0; a < 2; a++) {
        double glo = d->origin[a], ghi = d->origin[a] + d->size[a];
        if (d->periodic[a] && hi[a] - lo[a] >= d->size[a])
            return core_fail(err, CORE_ERR_ARG,
                             "the shape spans %g in %s, not less than the periodic "
                             "length %g",
                             hi[a] - lo[a], axis[a], d->size[a]);
        if (!d->periodic[a] && !g->clip && (lo[a] < glo || hi[a] > ghi))
            return core_fail(err, CORE_ERR_ARG,
                             "the shape spans [%g, %g] in %s, outside the grid [%g, %g]", lo[a],
                             hi[a], axis[a], glo, ghi);
    }
    return CORE_OK;
}

/* The sub-cells of size dx x dy whose centres may hold the grain's points: [i0, i1] x [j0, j1]
 * over the bounding box [lo, hi], within the grid if clipped. */
typedef struct {
    double dx, dy;
    long i0, i1, j0, j1;
} grain_cells;

static grain_cells cells_of(const mpm_scene *s, const mpm_grain_def *g, const double lo[2],
                            const double hi[2])
{
    const mpm_scene_def *d = &s->def;
    /* Points at the centres of n x n sub-cells of every grid cell, kept when inside the shape. */
    const int n = g->points_per_cell;
    const double dx = s->hx / n, dy = s->hy / n;
    long i0 = (long)floor((lo[0] - d->origin[0]) / dx),
         i1 = (long)ceil((hi[0] - d->origin[0]) / dx);
    long j0 = (long)floor((lo[1] - d->origin[1]) / dy),
         j1 = (long)ceil((hi[1] - d->origin[1]) / dy);
    if (g->clip) { /* sub-cells inside the grid only, on axes that are not periodic */
        const long n0[2] = {(long)n * d->cells[0] - 1, (long)n * d->cells[1] - 1};
        if (!d->periodic[0]) {
            i0 = i0 < 0 ? 0 : i0;
            i1 = i1 > n0[0] ? n0[0] : i1;
        }
        if (!d->periodic[1]) {
            j0 = j0 < 0 ? 0 : j0;
            j1 = j1 > n0[1] ? n0[1] : j1;
        }
    }
    return (grain_cells){dx, dy, i0, i1, j0, j1};
}

/* Room for one more grain. */
static core_status grow_grains(mpm_scene *s, core_error *err)
{
    if (s->ngrains < s->gcap)
        return CORE_OK;
    size_t cap = s->gcap ? 2 * s->gcap : 16;
    size_t *a = realloc(s->gstart, cap * sizeof *a);
    if (!a)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for grains");
    s->gstart = a;
    size_t *b = realloc(s->gcount, cap * sizeof *b);
    if (!b)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for grains");
    s->gcount = b;
    mpm_grain_def *gd = realloc(s->gdef, cap * sizeof *gd);
    if (!gd)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for grains");
    s->gdef = gd;
    if (s->gpres) {
        int *c = realloc(s->gpres, cap * sizeof *c);
        if (!c)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for grains");
        s->gpres = c;
    }
    s->gcap = cap;
    return CORE_OK;
}

/* The grain's points at the centres of its sub-cells inside the shape, from point np on, at
 * rest in their reference state but for a rigid motion about their centroid (cx, cy); returns
 * a point's mass. */
static double fill_grain(mpm_scene *s, const mpm_grain_def *g, const grain_cells *b, double cx,
                         double cy)
{
    const mpm_scene_def *d = &s->def;
    const double dx = b->dx, dy = b->dy;
    const mpm_material *mat = &s->mats[g->material];
    const double vol = dx * dy, mass = mat->density * vol;
    size_t p = s->np;
    for (long j = b->j0; j <= b->j1; j++)
        for (long i = b->i0; i <= b->i1; i++) {
            double x = d->origin[0] + (i + 0.5) * dx, y = d->origin[1] + (j + 0.5) * dy;
            if (!inside(g, x, y))
                continue;
            /* rigid initial motion about the point centroid */
            s->vx[p] = g->velocity[0] - g->omega * (y - cy);
            s->vy[p] = g->velocity[1] + g->omega * (x - cx);
            for (int a = 0; a < 2; a++) {
                double L = d->size[a], o = d->origin[a];
                double *c = a ? &y : &x;
                if (d->periodic[a])
                    *c -= L * floor((*c - o) / L);
            }
            s->x[p] = x;
            s->y[p] = y;
            s->m[p] = mass;
            s->v0[p] = vol;
            s->F[0][p] = s->F[3][p] = 1;
            s->F[1][p] = s->F[2][p] = 0;
            s->be[0][p] = s->be[2][p] = s->be[3][p] = 1;
            s->be[1][p] = 0;
            for (int k = 0; k < 4; k++)
                s->sig[k][p] = 0;
            s->eps_p[p] = 0;
            if (s->rate)
                s->rate[p] = 0;
            s->ux[p] = s->uy[p] = 0;
            s->grain[p] = (int)s->ngrains;
            s->mat[p] = g->material;
            p++;
        }
    return mass;
}

long mpm_add_grain(mpm_scene *s, const mpm_grain_def *g, core_error *err)
{
    const mpm_scene_def *d = &s->def;
    double lo[2], hi[2];
    if (grain_bounds(s, g, lo, hi, err))
        return -1;
    const grain_cells b = cells_of(s, g, lo, hi);
    const double dx = b.dx, dy = b.dy;
    const int n = g->points_per_cell;
    size_t count = 0;
    double cx = 0, cy = 0;
    for (long j = b.j0; j <= b.j1; j++)
        for (long i = b.i0; i <= b.i1; i++) {
            double x = d->origin[0] + (i + 0.5) * dx, y = d->origin[1] + (j + 0.5) * dy;
            if (inside(g, x, y)) {
                count++;
                cx += x;
                cy += y;
            }
        }
    if (count == 0) {
        core_fail(err, CORE_ERR_ARG,
                  "the shape holds no point at %d points per cell (cell %g x %g): "
                  "make it larger or use more points per cell",
                  n, s->hx, s->hy);
        return -1;
    }
    cx /= (double)count;
    cy /= (double)count;
    if (reserve_points(s, s->np + count, err))
        return -1;
    if (grow_grains(s, err))
        return -1;
    if (s->gpres)
        s->gpres[s->ngrains] = -1;
    const double mass = fill_grain(s, g, &b, cx, cy);
    s->gdef[s->ngrains] = *g;
    if (g->shape == MPM_POLYGON) { /* keep the bounding box, not the caller's vertices */
        s->gdef[s->ngrains].shape = MPM_RECT;
        for (int a = 0; a < 2; a++) {
            s->gdef[s->ngrains].lo[a] = lo[a];
            s->gdef[s->ngrains].hi[a] = hi[a];
        }
        s->gdef[s->ngrains].vertices = NULL;
    }
    s->gstart[s->ngrains] = s->np;
    s->gcount[s->ngrains] = count;
    s->np += count;
    s->lzz_ok = false;
    /* Nodes lighter than 1e-12 of the lightest point take no acceleration (no division blow-up). */
    if (s->m_min == 0 || 1e-12 * mass < s->m_min)
        s->m_min = 1e-12 * mass;
    return (long)s->ngrains++;
}

size_t mpm_grain_count(const mpm_scene *s) { return s->ngrains; }
size_t mpm_point_count(const mpm_scene *s) { return s->np; }

core_status mpm_set_contact(mpm_scene *s, mpm_contact_model model, core_error *err)
{
    if (model == MPM_CONTACT_FRICTION)
        return core_fail(err, CORE_ERR_ARG,
                         "contact model 'friction' needs a friction "
                         "coefficient: use mpm_set_friction(scene, mu)");
    if (model != MPM_CONTACT_NOSLIP)
        return core_fail(err, CORE_ERR_ARG, "unknown contact model %d", (int)model);
    s->contact = model;
    return CORE_OK;
}

core_status mpm_set_friction(mpm_scene *s, double mu, core_error *err)
{
    if (!(mu >= 0) || !isfinite(mu))
        return core_fail(err, CORE_ERR_ARG, "mu must be a finite number >= 0, got %g", mu);
    s->contact = MPM_CONTACT_FRICTION;
    s->mu = mu;
    return CORE_OK;
}

mpm_contact_model mpm_contact(const mpm_scene *s) { return s->contact; }
double mpm_friction(const mpm_scene *s) { return s->contact == MPM_CONTACT_FRICTION ? s->mu : 0; }

/* realloc that keeps *a on failure. */
#define GROW(a, n)                                                                                 \
    do {                                                                                           \
        void *grown_ = realloc((a), ((n) ? (n) : 1) * sizeof *(a));                                \
        if (!grown_)                                                                               \
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact field entries",   \
                             (size_t)(n));                                                         \
        (a) = grown_;                                                                              \
    } while (0)

/* GROW for the staggered arrays (number k). */
#define GROW_STAGGERED(a, n, k)                                                                    \
    do {                                                                                           \
        void *grown_ = core_realloc_staggered((a), ((n) ? (n) : 1) * sizeof *(a), (k));            \
        if (!grown_)                                                                               \
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact field entries",   \
                             (size_t)(n));                                                         \
        (a) = grown_;                                                                              \
    } while (0)

core_status mpm_contact_reserve(mpm_scene *s, core_error *err)
{
    const size_t need = (size_t)s->ns * s->np, nn = s->nnodes;
    if (need + nn > (size_t)INT_MAX)
        return core_fail(err, CORE_ERR_NOMEM, "%zu points are too many for the contact fields",
                         s->np);
    if (!s->nhead) {
        GROW(s->ngr, nn);
        GROW(s->nhead, nn);
    }
    if (need <= s->paircap && s->sv)
        return CORE_OK;
    GROW_STAGGERED(s->nm, nn + need, STAGGER_NODE + 0);
    GROW_STAGGERED(s->npx, nn + need, STAGGER_NODE + 1);
    GROW_STAGGERED(s->npy, nn + need, STAGGER_NODE + 2);
    GROW_STAGGERED(s->nfx, nn + need, STAGGER_NODE + 3);
    GROW_STAGGERED(s->nfy, nn + need, STAGGER_NODE + 4);
    GROW_STAGGERED(s->nvx, nn + need, STAGGER_NODE + 5);
    GROW_STAGGERED(s->nvy, nn + need, STAGGER_NODE + 6);
    GROW_STAGGERED(s->nax, nn + need, STAGGER_NODE + 7);
    GROW_STAGGERED(s->nay, nn + need, STAGGER_NODE + 8);
    GROW(s->pnode, need);
    GROW(s->pgrain, need);
    GROW(s->pin, need);
    GROW(s->pwin, need);
    GROW(s->pvol, need);
    GROW(s->pnx, need);
    GROW(s->pny, need);
    GROW(s->pnext, need);
    GROW(s->pshared, need);
    GROW(s->sv, need);
    s->paircap = need;
    return CORE_OK;
}

void mpm_get_points(const mpm_scene *s, mpm_points *p)
{
    p->x = s->x;
    p->y = s->y;
    p->vx = s->vx;
    p->vy = s->vy;
    p->mass = s->m;
    p->volume0 = s->v0;
    for (int k = 0; k < 4; k++) {
        p->F[k] = s->F[k];
        p->sigma[k] = s->sig[k];
    }
    p->eps_p = s->eps_p;
    p->ux = s->ux;
    p->uy = s->uy;
    p->grain = s->grain;
    p->material = s->mat;
    p->rate = s->rate;
}

double mpm_time(const mpm_scene *s) { return s->time; }
long mpm_steps_done(const mpm_scene *s) { return s->steps; }

core_status mpm_set_velocities(mpm_scene *s, const double *vx, const double *vy, core_error *err)
{
    for (size_t p = 0; p < s->np; p++)
        if (!isfinite(vx[p]) || !isfinite(vy[p]))
            return core_fail(err, CORE_ERR_ARG, "velocity of point %zu is not finite", p + 1);
    memcpy(s->vx, vx, s->np * sizeof(double));
    memcpy(s->vy, vy, s->np * sizeof(double));
    return CORE_OK;
}

mpm_contact_options mpm_default_contact_options(void)
{
    return (mpm_contact_options){
        .normals = MPM_NORMALS_AVERAGED, .separation = 0, .strain_cap = 0, .conserve = true};
}

core_status mpm_set_contact_options(mpm_scene *s, const mpm_contact_options *o, core_error *err)
{
    if ((unsigned)o->normals > MPM_NORMALS_LINEAR)
        return core_fail(err, CORE_ERR_ARG, "unknown normals %d", (int)o->normals);
    if (!(o->separation >= 0 && o->separation <= 1))
        return core_fail(err, CORE_ERR_ARG, "separation must be in [0, 1], got %g", o->separation);
    if (!(o->strain_cap >= 0) || !isfinite(o->strain_cap))
        return core_fail(err, CORE_ERR_ARG, "strain_cap must be finite and >= 0, got %g",
                         o->strain_cap);
    s->opt = *o;
    return CORE_OK;
}

mpm_contact_options mpm_get_contact_options(const mpm_scene *s) { return s->opt; }

core_status mpm_prescribe(mpm_scene *s, size_t grain, const double v[2], core_error *err)
{
    if (grain >= s->ngrains)
        return core_fail(err, CORE_ERR_ARG, "grain %zu does not exist (the scene has %zu)",
                         grain + 1, s->ngrains);
    if (!isfinite(v[0]) || !isfinite(v[1]))
        return core_fail(err, CORE_ERR_ARG, "the prescribed velocity must be finite");
    if (!s->gpres) {
        if (!(s->gpres = malloc((s->gcap ? s->gcap : 1) * sizeof *s->gpres)) ||
            !(s->nforce = calloc(s->nnodes, sizeof *s->nforce)))
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for prescribed grains");
        for (size_t g = 0; g < s->ngrains; g++)
            s->gpres[g] = -1;
    }
    int k = s->gpres[grain];
    if (k < 0) {
        double(*pv)[2] = realloc(s->pv, (size_t)(s->npres + 1) * sizeof *pv);
        if (!pv)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for prescribed grains");
        s->pv = pv;
        k = s->gpres[grain] = s->npres++;
    }
    s->pv[k][0] = v[0];
    s->pv[k][1] = v[1];
    for (size_t p = s->gstart[grain]; p < s->gstart[grain] + s->gcount[grain]; p++) {
        s->vx[p] = v[0];
        s->vy[p] = v[1];
    }
    return CORE_OK;
}

core_status mpm_add_plane(mpm_scene *s, const mpm_plane_def *d, core_error *err)
{
    if (s->nplanes >= 4 + MPM_MAX_PLANES)
        return core_fail(err, CORE_ERR_ARG, "at most %d planes", MPM_MAX_PLANES);
    double len = hypot(d->normal[0], d->normal[1]);
    if (!(len > 0) || !isfinite(len))
        return core_fail(err, CORE_ERR_ARG, "the plane's normal must be a non-zero finite vector");
    if (d->kind != MPM_WALL_NOSLIP && d->kind != MPM_WALL_SLIP && d->kind != MPM_WALL_FRICTION)
        return core_fail(err, CORE_ERR_ARG, "a plane is noslip, slip or friction");
    if (!(d->mu >= 0) || !isfinite(d->mu))
        return core_fail(err, CORE_ERR_ARG, "the plane's mu must be finite and >= 0, got %g",
                         d->mu);
    for (int a = 0; a < 2; a++)
        if (!isfinite(d->point[a]) || !isfinite(d->velocity[a]))
            return core_fail(err, CORE_ERR_ARG, "the plane's point and velocity must be finite");
    mpm_plane pl = {.kind = d->kind, .mu = d->mu};
    for (int a = 0; a < 2; a++) {
        pl.n[a] = -d->normal[a] / len;
        pl.v[a] = d->velocity[a];
        pl.point[a] = d->point[a];
    }
    return mpm_install_plane(s, &pl, err);
}

core_status mpm_hydrostatic(mpm_scene *s, size_t grain, core_error *err)
{
    if (grain >= s->ngrains)
        return core_fail(err, CORE_ERR_ARG, "grain %zu does not exist (the scene has %zu)",
                         grain + 1, s->ngrains);
    const double gx = s->def.gravity[0], gy = s->def.gravity[1];
    const size_t p0 = s->gstart[grain], p1 = p0 + s->gcount[grain];
    double top = INFINITY;
    for (size_t p = p0; p < p1; p++)
        top = fmin(top, gx * s->x[p] + gy * s->y[p]);
    for (size_t p = p0; p < p1; p++) {
        const mpm_material *m = &s->mats[s->mat[p]];
        const double pres = m->density * (gx * s->x[p] + gy * s->y[p] - top);
        /* In-plane isotropic stretch lambda (F = lambda I in plane, 1 out of plane): the Hencky
         * law gives sigma_xx = sigma_yy = (2K + 2G/3) ln(lambda) / lambda^2; solve for -pres by
         * Newton from lambda = 1. */
        const double c = 2 * m->bulk + 2 * m->shear / 3;
        double l = 0; /* ln lambda */
        for (int it = 0; it < 50; it++) {
            double f = c * l * exp(-2 * l) + pres, df = c * exp(-2 * l) * (1 - 2 * l);
            double dl = f / df;
            l -= dl;
            if (fabs(dl) < 1e-15)
                break;
        }
        const double lam = exp(l);
        double f[4] = {lam, 0, 0, lam}, be[4] = {1, 0, 1, 1}, eps = 0, sig[4];
        if (!mpm_material_update(m, f, be, &eps, lam * lam, sig))
            return core_fail(err, CORE_ERR_ARG, "the hydrostatic pressure %g Pa inverts a point",
                             pres);
        s->F[0][p] = s->F[3][p] = lam;
        s->F[1][p] = s->F[2][p] = 0;
        for (int k = 0; k < 4; k++) {
            s->be[k][p] = be[k];
            s->sig[k][p] = sig[k];
        }
        s->eps_p[p] = eps;
        s->lzz_ok = false;
    }
    return CORE_OK;
}

static void bounds(const mpm_grain_def *g, double lo[2], double hi[2])
{
    for (int a = 0; a < 2; a++) {
        lo[a] = g->shape == MPM_DISK ? g->center[a] - g->radius : g->lo[a];
        hi[a] = g->shape == MPM_DISK ? g->center[a] + g->radius : g->hi[a];
    }
}

double mpm_grain_overlap(const mpm_scene *s, size_t id, size_t *other)
{
    double best = 0;
    *other = 0;
    if (id >= s->ngrains)
        return 0;
    const mpm_grain_def *a = &s->gdef[id];
    for (size_t k = 0; k < id; k++) {
        const mpm_grain_def *b = &s->gdef[k];
        double depth;
        if (a->shape == MPM_DISK && b->shape == MPM_DISK) {
            double d2 = 0;
            for (int ax = 0; ax < 2; ax++) {
                double d = a->center[ax] - b->center[ax];
                if (s->def.periodic[ax])
                    d -= s->def.size[ax] * floor(d / s->def.size[ax] + 0.5);
                d2 += d * d;
            }
            depth = a->radius + b->radius - sqrt(d2);
        } else {
            double alo[2], ahi[2], blo[2], bhi[2];
            bounds(a, alo, ahi);
            bounds(b, blo, bhi);
            depth = INFINITY;
            for (int ax = 0; ax < 2; ax++) {
                double shift = 0;
                if (s->def.periodic[ax]) {
                    double L = s->def.size[ax], d = 0.5 * (alo[ax] + ahi[ax] - blo[ax] - bhi[ax]);
                    shift = L * floor(d / L + 0.5);
                }
                double w = fmin(ahi[ax], bhi[ax] + shift) - fmax(alo[ax], blo[ax] + shift);
                depth = fmin(depth, w);
            }
        }
        if (depth > best) {
            best = depth;
            *other = k;
        }
    }
    return best;
}

/* ---- for checkpoints (src/mpm/checkpoint.c) ------------------------------------------------ */
core_status mpm_reserve_points(mpm_scene *s, size_t n, core_error *err)
{
    return reserve_points(s, n, err);
}

core_status mpm_install_plane(mpm_scene *s, const mpm_plane *p, core_error *err)
{
    if (s->nplanes >= 4 + MPM_MAX_PLANES)
        return core_fail(err, CORE_ERR_ARG, "at most %d planes", MPM_MAX_PLANES);
    const int k = s->nplanes++;
    mpm_plane *pl = &s->planes[k];
    *pl = *p;
    for (int j = 0; j < s->nny; j++)
        for (int i = 0; i < s->nnx; i++) {
            double x = s->def.origin[0] + (i - s->gl[0]) * s->hx;
            double y = s->def.origin[1] + (j - s->gl[1]) * s->hy;
            /* inside the body: (x - point) . normal_out <= 0, i.e. . n >= 0 */
            if ((x - pl->point[0]) * pl->n[0] + (y - pl->point[1]) * pl->n[1] >= 0)
                s->nwall[(size_t)j * s->nnx + i] |= (unsigned char)(1u << k);
        }
    return plane_reference(s, k, err);
}
