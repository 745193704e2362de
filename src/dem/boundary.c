/* Boundary conditions of the biaxial laboratory (Padbidri Ch. 3): pressure as tractions on a
 * boundary edge loop (direct pressure, Fig. 2.2), the penalty force of the minimal boundary
 * conditions (Eqs. 3.2-3.5), membrane springs and particles tied to the plates. Applied after
 * the contact forces of every evaluation; the edges are rebuilt by a caller-supplied update
 * every `every` steps. Costs nothing when a scene has no boundary. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/checkpoint.h"
#include "core/clock.h"
#include "dem/dem_internal.h"

struct dem_boundary {
    dem_boundary_def def;
    int has_def;
    /* edges a -> b and their endpoints as node numbers */
    size_t ne, cap_e;
    long *a, *b;
    unsigned char *loaded;
    size_t *ea, *eb;
    int closed;
    /* distinct particles on the edges, their g_a (Eq. 3.3) */
    size_t nn, cap_n;
    long *node;
    double *gx, *gy;
    long *map; /* particle -> node, -1 (cap_map entries) */
    size_t cap_map;
    /* springs and ties */
    size_t ns, cap_s;
    long *si, *sj;
    double *sk, *srest;
    size_t nt, cap_t;
    long *ti;
    int *tw, *ta;
    size_t nspin;      /* prescribed spins (few: a linear search is fine) */
    long spin_i[8];
    double spin_w[8];
    /* bookkeeping */
    long last_update;
    long updates;
    double update_s, apply_s;
    double pen_sum[2], pen_max, pres_max, stiffness;
    double eint[4]; /* integral of the rate error (tau > 0) */
};

dem_boundary_def dem_default_boundary_def(void)
{
    dem_boundary_def d;
    memset(&d, 0, sizeof d);
    d.every = 250;
    d.mask[0] = d.mask[1] = d.mask[2] = d.mask[3] = 1;
    return d;
}

double dem_thickness(const dem_scene *s) { return s->thickness; }

static core_status grow(void **p, size_t *cap, size_t need, size_t size, core_error *err)
{
    if (need <= *cap)
        return CORE_OK;
    size_t c = *cap ? *cap : 16;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * size);
    if (!q)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu boundary entries", need);
    *p = q;
    *cap = c;
    return CORE_OK;
}

static core_status ensure(dem_scene *s, core_error *err)
{
    if (s->dim != 2)
        return core_fail(err, CORE_ERR_ARG, "boundary conditions are 2D only (this scene is 3D)");
    if (!s->bnd) {
        s->bnd = calloc(1, sizeof *s->bnd);
        if (!s->bnd)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for the boundary");
        s->bnd->def = dem_default_boundary_def();
        s->bnd->last_update = s->steps;
    }
    return CORE_OK;
}

void dem_clear_boundary(dem_scene *s)
{
    dem_boundary *b = s->bnd;
    if (!b)
        return;
    if (b->has_def && b->def.free_ctx)
        b->def.free_ctx(b->def.ctx);
    free(b->a);
    free(b->b);
    free(b->loaded);
    free(b->ea);
    free(b->eb);
    free(b->node);
    free(b->gx);
    free(b->gy);
    free(b->map);
    free(b->si);
    free(b->sj);
    free(b->sk);
    free(b->srest);
    free(b->ti);
    free(b->tw);
    free(b->ta);
    free(b);
    s->bnd = NULL;
    dem_invalidate(s, 0);
}

core_status dem_set_boundary(dem_scene *s, const dem_boundary_def *def, core_error *err)
{
    if (!(def->pressure >= 0) || !isfinite(def->pressure))
        return core_fail(err, CORE_ERR_ARG, "pressure must be >= 0 (Pa), got %g", def->pressure);
    if (!(def->depth > 0) || !isfinite(def->depth))
        return core_fail(err, CORE_ERR_ARG, "depth must be > 0 (m), got %g", def->depth);
    if (def->every < 0)
        return core_fail(err, CORE_ERR_ARG, "every must be >= 0 steps, got %ld", def->every);
    if (!(def->penalty >= 0) || !isfinite(def->penalty))
        return core_fail(err, CORE_ERR_ARG, "penalty K must be >= 0, got %g", def->penalty);
    if (!(def->tau >= 0) || !isfinite(def->tau))
        return core_fail(err, CORE_ERR_ARG, "tau must be >= 0 (s), got %g", def->tau);
    for (int q = 0; q < 4; q++)
        if (!isfinite(def->target[q]) || !(def->mask[q] >= 0) || !isfinite(def->mask[q]))
            return core_fail(err, CORE_ERR_ARG, "target and mask must be finite (mask >= 0)");
    if (!def->gradient && (def->target[1] != def->target[2] || def->mask[1] != def->mask[2]))
        return core_fail(err, CORE_ERR_ARG, "a strain-rate target and its mask must be symmetric "
                         "(xy = yx); use gradient = true for a velocity-gradient target");
    core_status st = ensure(s, err);
    if (st)
        return st;
    dem_boundary *b = s->bnd;
    if (b->has_def && b->def.free_ctx && b->def.ctx != def->ctx)
        b->def.free_ctx(b->def.ctx);
    b->def = *def;
    b->has_def = 1;
    memset(b->eint, 0, sizeof b->eint);
    b->last_update = s->steps;
    dem_invalidate(s, 0);
    return CORE_OK;
}

core_status dem_set_boundary_edges(dem_scene *s, size_t n, const long *a, const long *bb,
                                   const unsigned char *loaded, int closed, core_error *err)
{
    core_status st = ensure(s, err);
    if (st)
        return st;
    dem_boundary *b = s->bnd;
    for (size_t k = 0; k < n; k++)
        if (a[k] < 0 || (size_t)a[k] >= s->n || bb[k] < 0 || (size_t)bb[k] >= s->n || a[k] == bb[k])
            return core_fail(err, CORE_ERR_ARG, "edge %zu joins particles %ld and %ld: ids must be "
                             "distinct and in [1, %zu]", k + 1, a[k] + 1, bb[k] + 1, s->n);
    if (closed)
        for (size_t k = 0; k < n; k++)
            if (bb[k] != a[(k + 1) % n])
                return core_fail(err, CORE_ERR_ARG, "a closed boundary needs the edges in loop "
                                 "order (edge %zu ends at %ld, the next starts at %ld)", k + 1,
                                 bb[k] + 1, a[(k + 1) % n] + 1);
    if ((st = grow((void **)&b->a, &b->cap_e, n, sizeof *b->a, err)))
        return st;
    size_t cap = b->cap_e;
    b->cap_e = 0; /* the other per-edge arrays follow the same capacity */
    void **arrs[4] = {(void **)&b->b, (void **)&b->loaded, (void **)&b->ea, (void **)&b->eb};
    size_t sizes[4] = {sizeof *b->b, 1, sizeof *b->ea, sizeof *b->eb};
    for (int q = 0; q < 4; q++) {
        void *p = realloc(*arrs[q], cap * sizes[q]);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu edges", n);
        *arrs[q] = p;
    }
    b->cap_e = cap;
    size_t mc = b->cap_map;
    if (mc < s->n) {
        long *m = realloc(b->map, s->n * sizeof *m);
        if (!m)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for the boundary map");
        for (size_t i = mc; i < s->n; i++)
            m[i] = -1;
        b->map = m;
        b->cap_map = s->n;
    }
    for (size_t k = 0; k < b->nn; k++) /* forget the old nodes */
        b->map[b->node[k]] = -1;
    b->nn = 0;
    for (size_t k = 0; k < n; k++) {
        long ends[2] = {a[k], bb[k]};
        for (int q = 0; q < 2; q++) {
            long p = ends[q];
            if (b->map[p] < 0) {
                if ((st = grow((void **)&b->node, &b->cap_n, b->nn + 1, sizeof *b->node, err)))
                    return st;
                b->map[p] = (long)b->nn;
                b->node[b->nn++] = p;
            }
        }
        b->a[k] = a[k];
        b->b[k] = bb[k];
        b->loaded[k] = loaded ? loaded[k] != 0 : 1;
        b->ea[k] = (size_t)b->map[a[k]];
        b->eb[k] = (size_t)b->map[bb[k]];
    }
    double *gx = realloc(b->gx, (b->cap_n ? b->cap_n : 1) * sizeof *gx);
    if (gx)
        b->gx = gx;
    double *gy = realloc(b->gy, (b->cap_n ? b->cap_n : 1) * sizeof *gy);
    if (gy)
        b->gy = gy;
    if (!gx || !gy)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu boundary nodes", b->nn);
    b->ne = n;
    b->closed = closed && n >= 3;
    return CORE_OK;
}

core_status dem_update_boundary(dem_scene *s, core_error *err)
{
    dem_boundary *b = s->bnd;
    b->last_update = s->steps;
    if (!b->has_def || !b->def.update)
        return CORE_OK;
    double t0 = clock_cpu(); /* CPU time: shares stay meaningful on a loaded machine */
    core_status st = b->def.update(b->def.ctx, s, err);
    b->update_s += clock_cpu() - t0;
    b->updates++;
    return st;
}

core_status dem_boundary_due(dem_scene *s, core_error *err)
{
    dem_boundary *b = s->bnd;
    if (b->has_def && b->def.update && b->def.every > 0 && s->steps - b->last_update >= b->def.every)
        return dem_update_boundary(s, err);
    return CORE_OK;
}

core_status dem_add_springs(dem_scene *s, size_t n, const long *i, const long *j, double k,
                            const double *rest, core_error *err)
{
    if (!(k > 0) || !isfinite(k))
        return core_fail(err, CORE_ERR_ARG, "spring stiffness must be > 0 (N/m), got %g", k);
    for (size_t q = 0; q < n; q++)
        if (i[q] < 0 || (size_t)i[q] >= s->n || j[q] < 0 || (size_t)j[q] >= s->n || i[q] == j[q])
            return core_fail(err, CORE_ERR_ARG, "spring %zu joins particles %ld and %ld: ids must "
                             "be distinct and in [1, %zu]", q + 1, i[q] + 1, j[q] + 1, s->n);
        else if (rest && !(rest[q] >= 0))
            return core_fail(err, CORE_ERR_ARG, "spring %zu: rest length must be >= 0, got %g",
                             q + 1, rest[q]);
    core_status st = ensure(s, err);
    if (st)
        return st;
    dem_boundary *b = s->bnd;
    size_t need = b->ns + n, cap = b->cap_s;
    if ((st = grow((void **)&b->si, &cap, need, sizeof *b->si, err)))
        return st;
    void **arrs[3] = {(void **)&b->sj, (void **)&b->sk, (void **)&b->srest};
    for (int q = 0; q < 3; q++) {
        void *p = realloc(*arrs[q], cap * sizeof(double));
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu springs", need);
        *arrs[q] = p;
    }
    b->cap_s = cap;
    for (size_t q = 0; q < n; q++) {
        size_t m = b->ns + q;
        b->si[m] = i[q];
        b->sj[m] = j[q];
        b->sk[m] = k;
        b->srest[m] = rest ? rest[q]
                           : hypot(s->x[0][j[q]] - s->x[0][i[q]], s->x[1][j[q]] - s->x[1][i[q]]);
    }
    b->ns = need;
    dem_invalidate(s, 0);
    return CORE_OK;
}

/* Appends a tie (particle i held to wall's motion along axis) to the boundary's arrays. */
static core_status push_tie(dem_boundary *b, long i, int wall, int axis, core_error *err)
{
    size_t cap = b->cap_t;
    core_status st = grow((void **)&b->ti, &cap, b->nt + 1, sizeof *b->ti, err);
    if (st)
        return st;
    int *tw = realloc(b->tw, cap * sizeof *tw);
    if (tw)
        b->tw = tw;
    int *ta = realloc(b->ta, cap * sizeof *ta);
    if (ta)
        b->ta = ta;
    if (!tw || !ta)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the ties");
    b->cap_t = cap;
    b->ti[b->nt] = i;
    b->tw[b->nt] = wall;
    b->ta[b->nt] = axis;
    b->nt++;
    return CORE_OK;
}

core_status dem_tie_to_wall(dem_scene *s, size_t i, int wall, int axis, core_error *err)
{
    if (i >= s->n)
        return core_fail(err, CORE_ERR_ARG, "particle %zu does not exist (1..%zu)", i + 1, s->n);
    if (wall < 0 || wall >= s->nwalls || !s->walls[wall].active)
        return core_fail(err, CORE_ERR_ARG, "wall %d does not exist", wall + 1);
    if (s->walls[wall].shape)
        return core_fail(err, CORE_ERR_ARG, "wall %d is not a plane: ties follow planes only",
                         wall + 1);
    if (axis < 0 || axis >= s->dim)
        return core_fail(err, CORE_ERR_ARG, "axis must be 1..%d, got %d", s->dim, axis + 1);
    core_status st = ensure(s, err);
    if (st)
        return st;
    if ((st = push_tie(s->bnd, (long)i, wall, axis, err)))
        return st;
    s->v[axis][i] = s->walls[wall].velocity[axis];
    dem_invalidate(s, 0);
    return CORE_OK;
}

core_status dem_set_spin(dem_scene *s, size_t i, double omega, core_error *err)
{
    if (i >= s->n)
        return core_fail(err, CORE_ERR_ARG, "particle %zu does not exist (1..%zu)", i + 1, s->n);
    if (!isfinite(omega))
        return core_fail(err, CORE_ERR_ARG, "omega must be finite, got %g", omega);
    if (!s->rot)
        return core_fail(err, CORE_ERR_STATE, "the scene has no rotations: set a tangential law "
                         "(or rolling = true) first");
    core_status st = ensure(s, err);
    if (st)
        return st;
    dem_boundary *b = s->bnd;
    size_t k = 0;
    while (k < b->nspin && b->spin_i[k] != (long)i)
        k++;
    if (k == b->nspin) {
        if (b->nspin == sizeof b->spin_i / sizeof b->spin_i[0])
            return core_fail(err, CORE_ERR_ARG, "at most %zu particles can have a prescribed spin",
                             sizeof b->spin_i / sizeof b->spin_i[0]);
        b->spin_i[b->nspin++] = (long)i;
    }
    b->spin_w[k] = omega;
    s->w[2][i] = omega;
    return CORE_OK;
}

/* g_a (Eq. 3.3: half the outward L n of each edge at a) and the enclosed area. */
static double node_vectors(dem_boundary *b, const double *x, const double *y)
{
    double V = 0;
    for (size_t k = 0; k < b->nn; k++)
        b->gx[k] = b->gy[k] = 0;
    for (size_t k = 0; k < b->ne; k++) {
        long a = b->a[k], c = b->b[k];
        double hx = 0.5 * (y[c] - y[a]), hy = -0.5 * (x[c] - x[a]);
        b->gx[b->ea[k]] += hx;
        b->gy[b->ea[k]] += hy;
        b->gx[b->eb[k]] += hx;
        b->gy[b->eb[k]] += hy;
        V += 0.5 * (x[a] * y[c] - x[c] * y[a]);
    }
    return V;
}

static void coarse_gradient(const dem_boundary *b, const double *vx, const double *vy, double V,
                            double H[4])
{
    double h[4] = {0, 0, 0, 0};
    for (size_t k = 0; k < b->nn; k++) {
        long p = b->node[k];
        h[0] += vx[p] * b->gx[k];
        h[1] += vx[p] * b->gy[k];
        h[2] += vy[p] * b->gx[k];
        h[3] += vy[p] * b->gy[k];
    }
    for (int q = 0; q < 4; q++)
        H[q] = h[q] / V;
}

core_status dem_boundary_apply(dem_scene *s, double dt, core_error *err)
{
    dem_boundary *b = s->bnd;
    double t0 = clock_cpu();
    const double *x = s->x[0], *y = s->x[1];
    double *fx = s->f[0], *fy = s->f[1];
    for (size_t q = 0; q < b->ns; q++) { /* membrane springs */
        long i = b->si[q], j = b->sj[q];
        double dx = x[j] - x[i], dy = y[j] - y[i], d = hypot(dx, dy);
        if (!(d > 0))
            continue;
        double f = b->sk[q] * (d - b->srest[q]) / d;
        fx[i] += f * dx;
        fy[i] += f * dy;
        fx[j] -= f * dx;
        fy[j] -= f * dy;
    }
    b->pen_sum[0] = b->pen_sum[1] = b->pen_max = b->pres_max = 0;
    if (b->ne > 0 && b->has_def) {
        double V = node_vectors(b, x, y);
        const double P = b->def.pressure * b->def.depth;
        if (P > 0)
            for (size_t k = 0; k < b->ne; k++) {
                if (!b->loaded[k])
                    continue;
                long a = b->a[k], c = b->b[k];
                double hx = 0.5 * (y[c] - y[a]), hy = -0.5 * (x[c] - x[a]);
                fx[a] -= P * hx;
                fy[a] -= P * hy;
                fx[c] -= P * hx;
                fy[c] -= P * hy;
                b->pres_max = fmax(b->pres_max, hx * hx + hy * hy); /* squared; root below */
            }
        b->pres_max = P * sqrt(b->pres_max);
        if (b->closed && b->def.penalty > 0) {
            if (!(V > 0))
                return core_fail(err, CORE_ERR_UNSTABLE, "the boundary loop encloses area %g <= 0 "
                                 "at step %ld: the assembly turned inside out", V, s->steps + 1);
            double H[4], d[4], W[4];
            coarse_gradient(b, s->v[0], s->v[1], V, H);
            if (b->def.gradient) {
                for (int q = 0; q < 4; q++)
                    d[q] = H[q] - b->def.target[q];
            } else {
                double off = 0.5 * (H[1] + H[2]);
                d[0] = H[0] - b->def.target[0];
                d[1] = d[2] = off - b->def.target[1];
                d[3] = H[3] - b->def.target[3];
            }
            if (b->def.tau > 0)
                for (int q = 0; q < 4; q++) {
                    b->eint[q] += d[q] * dt;
                    d[q] += b->eint[q] / b->def.tau;
                }
            for (int q = 0; q < 4; q++)
                W[q] = b->def.mask[q] * d[q];
            const double KV = b->def.penalty / V;
            double g2 = 0, mmin = INFINITY;
            for (size_t k = 0; k < b->nn; k++) {
                long p = b->node[k];
                double gx = b->gx[k], gy = b->gy[k];
                /* Eq. 3.5: F_a = -(K/V) W g_a */
                double Fx = -KV * (W[0] * gx + W[1] * gy), Fy = -KV * (W[2] * gx + W[3] * gy);
                fx[p] += Fx;
                fy[p] += Fy;
                b->pen_sum[0] += Fx;
                b->pen_sum[1] += Fy;
                b->pen_max = fmax(b->pen_max, Fx * Fx + Fy * Fy); /* squared; root below */
                g2 += gx * gx + gy * gy;
                if (s->inv_m[p] > 0)
                    mmin = fmin(mmin, s->m[p]);
            }
            b->pen_max = sqrt(b->pen_max);
            /* The penalty acts as a dashpot on the boundary's collective motion with rate
             * K sum|g|^2 / (V^2 m): explicit steps need rate * dt < 2; refuse beyond 1. */
            b->stiffness = isfinite(mmin) ? b->def.penalty * g2 / (V * V * mmin) : 0;
            if (b->stiffness * dt > 1)
                return core_fail(err, CORE_ERR_UNSTABLE,
                                 "the minimal-boundary penalty K = %g is too stiff for dt = %g s "
                                 "(rate K sum|g|^2/(V^2 m) = %g 1/s, times dt = %.3g > 1); lower K "
                                 "below %g or the step", b->def.penalty, dt, b->stiffness,
                                 b->stiffness * dt, b->def.penalty / (b->stiffness * dt));
        }
    }
    for (size_t q = 0; q < b->nt; q++) { /* ties: that component follows the wall */
        long i = b->ti[q];
        int ax = b->ta[q];
        dem_wall *wl = &s->walls[b->tw[q]];
        s->v[ax][i] = wl->velocity[ax];
        /* the wall holds the tied particle, so it carries that force too (a servo sees it) */
        wl->fn -= s->f[ax][i] * wl->normal[ax];
        s->f[ax][i] = 0;
    }
    for (size_t q = 0; q < b->nspin; q++) { /* prescribed spins */
        s->w[2][b->spin_i[q]] = b->spin_w[q];
        s->tq[2][b->spin_i[q]] = 0;
    }
    b->apply_s += clock_cpu() - t0;
    return CORE_OK;
}

core_status dem_boundary_info_get(dem_scene *s, dem_boundary_info *o, core_error *err)
{
    memset(o, 0, sizeof *o);
    dem_boundary *b = s->bnd;
    if (!b)
        return core_fail(err, CORE_ERR_STATE, "the scene has no boundary (set one with boundary{})");
    o->edges = b->ne;
    for (size_t k = 0; k < b->ne; k++)
        o->loaded += b->loaded[k];
    o->nodes = b->nn;
    o->closed = b->closed;
    if (b->closed) {
        double V = node_vectors(b, s->x[0], s->x[1]);
        o->area = V;
        if (V > 0) {
            coarse_gradient(b, s->v[0], s->v[1], V, o->grad);
            double off = 0.5 * (o->grad[1] + o->grad[2]);
            o->strain_rate[0] = o->grad[0];
            o->strain_rate[1] = o->strain_rate[2] = off;
            o->strain_rate[3] = o->grad[3];
        }
    }
    o->penalty_sum[0] = b->pen_sum[0];
    o->penalty_sum[1] = b->pen_sum[1];
    o->penalty_max = b->pen_max;
    o->pressure_max = b->pres_max;
    o->stiffness = b->stiffness;
    o->updates = b->updates;
    o->update_seconds = b->update_s;
    o->apply_seconds = b->apply_s;
    o->springs = b->ns;
    o->ties = b->nt;
    return CORE_OK;
}

size_t dem_boundary_edges(const dem_scene *s, const long **a, const long **bb,
                          const unsigned char **loaded)
{
    const dem_boundary *b = s->bnd;
    if (!b) {
        *a = *bb = NULL;
        *loaded = NULL;
        return 0;
    }
    *a = b->a;
    *bb = b->b;
    *loaded = b->loaded;
    return b->ne;
}

/* ---- checkpoints (called by checkpoint.c) ---------------------------------------------------- *
 * Everything but the update callback itself: of a boundary rebuilt by a caller's update (the
 * Delaunay mode of the Lua binding) the section 'boundary_update' holds the update's kind and
 * what its save_ctx writes; the loader's restorer of that kind re-attaches it. The nodes and
 * their g_a are a function of the edges (dem_set_boundary_edges rebuilds them in that order). */
core_status dem_boundary_save(const dem_scene *s, ckpt_writer *w, core_error *err)
{
    const dem_boundary *b = s->bnd;
    const int update = b->has_def && b->def.update;
    if (update && (!b->def.kind || !b->def.save_ctx || strlen(b->def.kind) > CKPT_TAG_MAX))
        return core_fail(err, CORE_ERR_STATE,
                         "the scene's boundary edges are rebuilt every %ld steps by an update "
                         "callback without a kind and save_ctx (dem_boundary_def), which a "
                         "checkpoint cannot restore",
                         b->def.every);
    core_status st = ckpt_section_begin(w, "boundary", CKPT_REQUIRED, err);
    if (st)
        return st;
    const dem_boundary_def *d = &b->def;
    ckpt_put_u32(w, (uint32_t)b->has_def);
    ckpt_put_f64(w, d->pressure);
    ckpt_put_f64(w, d->depth);
    ckpt_put_i64(w, d->every);
    ckpt_put_f64(w, d->penalty);
    ckpt_put_u32(w, (uint32_t)d->gradient);
    ckpt_put_f64s(w, d->target, 4);
    ckpt_put_f64s(w, d->mask, 4);
    ckpt_put_f64(w, d->tau);
    ckpt_put_u64(w, b->ne);
    for (size_t k = 0; k < b->ne; k++) {
        ckpt_put_i64(w, b->a[k]);
        ckpt_put_i64(w, b->b[k]);
        ckpt_put_u32(w, b->loaded[k]);
    }
    ckpt_put_u32(w, (uint32_t)b->closed);
    ckpt_put_u64(w, b->ns);
    for (size_t k = 0; k < b->ns; k++) {
        ckpt_put_i64(w, b->si[k]);
        ckpt_put_i64(w, b->sj[k]);
        ckpt_put_f64(w, b->sk[k]);
        ckpt_put_f64(w, b->srest[k]);
    }
    ckpt_put_u64(w, b->nt);
    for (size_t k = 0; k < b->nt; k++) {
        ckpt_put_i64(w, b->ti[k]);
        ckpt_put_i64(w, b->tw[k]);
        ckpt_put_i64(w, b->ta[k]);
    }
    ckpt_put_u64(w, b->nspin);
    for (size_t k = 0; k < b->nspin; k++) {
        ckpt_put_i64(w, b->spin_i[k]);
        ckpt_put_f64(w, b->spin_w[k]);
    }
    ckpt_put_i64(w, b->last_update);
    ckpt_put_i64(w, b->updates);
    ckpt_put_f64(w, b->update_s);
    ckpt_put_f64(w, b->apply_s);
    ckpt_put_f64s(w, b->pen_sum, 2);
    ckpt_put_f64(w, b->pen_max);
    ckpt_put_f64(w, b->pres_max);
    ckpt_put_f64(w, b->stiffness);
    ckpt_put_f64s(w, b->eint, 4);
    if ((st = ckpt_section_end(w, err)) || !update)
        return st;
    /* required: a grainlab without it would continue with edges that are never rebuilt */
    if ((st = ckpt_section_begin(w, "boundary_update", CKPT_REQUIRED, err)))
        return st;
    ckpt_put_str(w, b->def.kind);
    b->def.save_ctx(b->def.ctx, w);
    return ckpt_section_end(w, err);
}

static core_status corrupt(ckpt_section *sec, const char *what, core_error *err)
{
    return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (section '%s': %s)",
                     ckpt_reader_path(sec->r), sec->tag, what);
}

/* A particle index stored in the file: [0, n), or "'PATH' is corrupt (section 'boundary': WHAT
 * joins particle index V, outside [0, n))" (before any call that would print V + 1). */
static core_status index_in(ckpt_section *sec, const char *what, size_t k, int64_t v, size_t n,
                            core_error *err)
{
    if (v >= 0 && (uint64_t)v < n)
        return CORE_OK;
    return core_fail(err, CORE_ERR_IO,
                     "'%s' is corrupt (section '%s': %s %zu joins particle index %lld, outside "
                     "[0, %zu))",
                     ckpt_reader_path(sec->r), sec->tag, what, k + 1, (long long)v, n);
}

/* Finite values, or "... WHAT = V, a finite number expected". */
static core_status finite_all(ckpt_section *sec, const char *what, const double *v, size_t n,
                              core_error *err)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(v[k]))
            return core_fail(err, CORE_ERR_IO,
                             "'%s' is corrupt (section '%s': %s = %g, a finite number expected)",
                             ckpt_reader_path(sec->r), sec->tag, what, v[k]);
    return CORE_OK;
}

/* Reads a count of records of at least `size` bytes each (bounded by the section). */
static core_status count(ckpt_section *sec, size_t size, size_t *n, core_error *err)
{
    uint64_t c;
    core_status st = ckpt_get_u64(sec, &c, err);
    if (st)
        return st;
    if (c > (sec->size - sec->pos) / size)
        return corrupt(sec, "bad count", err);
    *n = (size_t)c;
    return CORE_OK;
}

core_status dem_boundary_load(dem_scene *s, ckpt_section *sec, core_error *err)
{
    uint32_t has_def = 0, gradient = 0, closed = 0;
    int64_t every = 0;
    dem_boundary_def d = dem_default_boundary_def();
    core_status st = ckpt_get_u32(sec, &has_def, err);
    if (!st)
        st = ckpt_get_f64(sec, &d.pressure, err);
    if (!st)
        st = ckpt_get_f64(sec, &d.depth, err);
    if (!st)
        st = ckpt_get_i64(sec, &every, err);
    if (!st)
        st = ckpt_get_f64(sec, &d.penalty, err);
    if (!st)
        st = ckpt_get_u32(sec, &gradient, err);
    if (!st)
        st = ckpt_get_f64s(sec, d.target, 4, err);
    if (!st)
        st = ckpt_get_f64s(sec, d.mask, 4, err);
    if (!st)
        st = ckpt_get_f64(sec, &d.tau, err);
    if (st)
        return st;
    if (has_def > 1 || gradient > 1 || every < 0 || every > CKPT_COUNTER_MAX)
        return corrupt(sec, "bad definition flags or update interval", err);
    d.every = (long)every;
    d.gradient = (int)gradient;
    if ((st = ensure(s, err)))
        return st;
    if (has_def && (st = dem_set_boundary(s, &d, err)))
        return corrupt(sec, err->msg, err);
    size_t ne = 0;
    if ((st = count(sec, 20, &ne, err)))
        return st;
    long *a = malloc((ne ? ne : 1) * sizeof *a), *bb = malloc((ne ? ne : 1) * sizeof *bb);
    unsigned char *loaded = malloc(ne ? ne : 1);
    for (size_t k = 0; k < ne && a && bb && loaded && !st; k++) {
        int64_t x, y;
        uint32_t l;
        if (!(st = ckpt_get_i64(sec, &x, err)) && !(st = ckpt_get_i64(sec, &y, err)) &&
            !(st = ckpt_get_u32(sec, &l, err)) && !(st = index_in(sec, "edge", k, x, s->n, err)) &&
            !(st = index_in(sec, "edge", k, y, s->n, err))) {
            a[k] = (long)x;
            bb[k] = (long)y;
            loaded[k] = (unsigned char)(l != 0);
        }
    }
    if (!st && (!a || !bb || !loaded))
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory loading the boundary");
    if (!st)
        st = ckpt_get_u32(sec, &closed, err);
    if (!st && closed > 1)
        st = corrupt(sec, "bad closed flag", err);
    if (!st && ne > 0 && dem_set_boundary_edges(s, ne, a, bb, loaded, (int)closed, err))
        st = corrupt(sec, err->msg, err);
    free(a), free(bb), free(loaded);
    if (st)
        return st;
    dem_boundary *b = s->bnd;
    size_t ns = 0, nt = 0, nspin = 0;
    if ((st = count(sec, 32, &ns, err)))
        return st;
    for (size_t k = 0; k < ns && !st; k++) {
        int64_t i, j;
        double kk, rest;
        if (!(st = ckpt_get_i64(sec, &i, err)) && !(st = ckpt_get_i64(sec, &j, err)) &&
            !(st = ckpt_get_f64(sec, &kk, err)) && !(st = ckpt_get_f64(sec, &rest, err)) &&
            !(st = index_in(sec, "spring", k, i, s->n, err)) &&
            !(st = index_in(sec, "spring", k, j, s->n, err)) &&
            !(st = finite_all(sec, "a spring's rest length", &rest, 1, err))) {
            long li = (long)i, lj = (long)j;
            if (dem_add_springs(s, 1, &li, &lj, kk, &rest, err))
                st = corrupt(sec, err->msg, err);
        }
    }
    if (!st)
        st = count(sec, 24, &nt, err);
    for (size_t k = 0; k < nt && !st; k++) {
        int64_t i, wall, axis;
        if (!(st = ckpt_get_i64(sec, &i, err)) && !(st = ckpt_get_i64(sec, &wall, err)) &&
            !(st = ckpt_get_i64(sec, &axis, err))) {
            /* not dem_tie_to_wall: it would also set the velocity, which is stored already */
            if (i < 0 || (size_t)i >= s->n || wall < 0 || wall >= s->nwalls || axis < 0 ||
                axis >= s->dim)
                return corrupt(sec, "bad tie", err);
            if ((st = push_tie(b, (long)i, (int)wall, (int)axis, err)))
                return st;
        }
    }
    if (!st)
        st = count(sec, 16, &nspin, err);
    if (!st && nspin > sizeof b->spin_i / sizeof b->spin_i[0])
        return corrupt(sec, "too many spins", err);
    for (size_t k = 0; k < nspin && !st; k++) {
        int64_t i;
        if (!(st = ckpt_get_i64(sec, &i, err)) && !(st = ckpt_get_f64(sec, &b->spin_w[k], err))) {
            if (i < 0 || (size_t)i >= s->n || !isfinite(b->spin_w[k]))
                return corrupt(sec, "bad spin", err);
            b->spin_i[k] = (long)i;
        }
    }
    if (st)
        return st;
    b->nspin = nspin;
    int64_t last_update, updates;
    if (!st)
        st = ckpt_get_i64(sec, &last_update, err);
    if (!st)
        st = ckpt_get_i64(sec, &updates, err);
    if (!st)
        st = ckpt_get_f64(sec, &b->update_s, err);
    if (!st)
        st = ckpt_get_f64(sec, &b->apply_s, err);
    if (!st)
        st = ckpt_get_f64s(sec, b->pen_sum, 2, err);
    if (!st)
        st = ckpt_get_f64(sec, &b->pen_max, err);
    if (!st)
        st = ckpt_get_f64(sec, &b->pres_max, err);
    if (!st)
        st = ckpt_get_f64(sec, &b->stiffness, err);
    if (!st)
        st = ckpt_get_f64s(sec, b->eint, 4, err);
    if (st)
        return st;
    if (last_update < 0 || last_update > s->steps || updates < 0 || updates > CKPT_COUNTER_MAX)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s': last update at step %lld, %lld updates; "
                         "the scene is at step %ld)",
                         ckpt_reader_path(sec->r), sec->tag, (long long)last_update,
                         (long long)updates, s->steps);
    const double sums[] = {b->update_s, b->apply_s,  b->pen_sum[0], b->pen_sum[1],
                           b->pen_max,  b->pres_max, b->stiffness,  b->eint[0],
                           b->eint[1],  b->eint[2],  b->eint[3]};
    if ((st = finite_all(sec, "a sum of the boundary's statistics", sums, 11, err)))
        return st;
    b->last_update = (long)last_update;
    b->updates = (long)updates;
    return ckpt_section_done(sec, err);
}

core_status dem_boundary_load_update(dem_scene *s, ckpt_section *sec,
                                     const dem_boundary_restorer *restorer, core_error *err)
{
    char kind[CKPT_TAG_MAX + 1];
    core_status st = ckpt_get_str(sec, kind, sizeof kind, err);
    if (st)
        return st;
    for (const char *c = kind; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_'))
            return corrupt(sec, "bad update kind", err);
    dem_boundary *b = s->bnd;
    if (!b || !b->has_def || b->def.update)
        return corrupt(sec, "an update without a boundary definition", err);
    if (!restorer || strcmp(restorer->kind, kind) != 0)
        return core_fail(err, CORE_ERR_STATE,
                         "'%s': the scene's boundary edges are rebuilt every %ld steps by a '%s' "
                         "update, which this loader cannot re-attach",
                         ckpt_reader_path(sec->r), b->def.every, kind);
    /* Only the update's fields change: dem_set_boundary would also reset the integral term and
     * the step of the last update, which are loaded already. */
    dem_boundary_def d = b->def;
    if ((st = restorer->restore(sec, s, &d, err)))
        return st;
    b->def.update = d.update;
    b->def.ctx = d.ctx;
    b->def.free_ctx = d.free_ctx;
    b->def.kind = d.kind;
    b->def.save_ctx = d.save_ctx;
    return ckpt_section_done(sec, err);
}
