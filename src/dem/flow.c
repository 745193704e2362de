/* Particles in and out during a run: inserters (a region, a rate or a count or a mass, a size
 * distribution, a velocity; positions drawn from the inserter's own random stream, never
 * overlapping) and outflows (a box, or an open side of the domain), applied between steps. A
 * removal compacts every per-particle array (domain_gather.c's table), the pair list with its
 * history and the walls' candidates in place, so the list stays valid without a rebuild; an
 * insertion appends particles and asks for a rebuild (the history of the others carries over by
 * index). Their checkpoint section: flow_checkpoint.c. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "core/rng.h"
#include "dem/dem_internal.h"
#include "dem/flow_internal.h"

dem_inserter_def dem_default_inserter_def(void)
{
    dem_inserter_def d;
    memset(&d, 0, sizeof d);
    d.count = -1;
    d.size = DEM_SIZE_CONSTANT;
    d.seed = 1;
    d.every = 1;
    d.attempts = 50;
    return d;
}

/* The flow state on first use, with tags for the particles there are. */
core_status dem_flow_on(dem_scene *s, core_error *err)
{
    if (s->flow)
        return CORE_OK;
    dem_flow *f = calloc(1, sizeof *f);
    if (!f)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the flow state");
    if (dem_alloc_array(&s->tag, s->cap, err)) {
        free(f);
        return err ? err->status : CORE_ERR_NOMEM;
    }
    for (size_t i = 0; i < s->n; i++)
        s->tag[i] = (double)i;
    f->next_tag = (double)s->n;
    s->flow = f;
    return CORE_OK;
}

void dem_flow_tag_new(dem_scene *s, size_t i)
{
    s->tag[i] = s->flow->next_tag;
    s->flow->next_tag += 1;
}

/* The first particle of [0, s->n) whose tag + 1 is one of the sorted ids, or -1 (and *k the id's
 * position). A scene without tags numbers its particles by index. */
long dem_flow_tag_clash(const dem_scene *s, const long long *ids, size_t n, size_t *k)
{
    for (size_t i = 0; i < s->n && n > 0; i++) {
        const long long want = (s->tag ? (long long)s->tag[i] : (long long)i) + 1;
        size_t a = 0, b = n;
        while (a < b) {
            const size_t m = a + (b - a) / 2;
            if (ids[m] < want)
                a = m + 1;
            else
                b = m;
        }
        if (a < n && ids[a] == want) {
            *k = a;
            return (long)i;
        }
    }
    return -1;
}

core_status dem_flow_adopt_tags(dem_scene *s, size_t first, const long long *ids, size_t n,
                                core_error *err)
{
    core_status st = dem_flow_on(s, err);
    if (st)
        return st;
    for (size_t k = 0; k < n; k++) {
        s->tag[first + k] = (double)(ids[k] - 1);
        if (ids[k] > s->flow->next_tag) /* tags are never reused: the next one is above all */
            s->flow->next_tag = (double)ids[k];
    }
    return CORE_OK;
}

void dem_flow_free(dem_scene *s)
{
    dem_flow *f = s->flow;
    if (f) {
        for (int q = 0; q < f->nins; q++)
            free(f->ins[q].radii), free(f->ins[q].cum);
        free(f->ins), free(f->out), free(f->near), free(f->gone);
        free(f);
    }
    s->flow = NULL;
    free(s->tag);
    s->tag = NULL;
}

const double *dem_tags(const dem_scene *s) { return s->tag; }
int dem_inserter_count(const dem_scene *s) { return s->flow ? s->flow->nins : 0; }
int dem_outflow_count(const dem_scene *s) { return s->flow ? s->flow->nout : 0; }
int dem_flow_inserting(const dem_scene *s) { return s->flow && s->flow->nins > 0; }

core_status dem_inserter_counts(const dem_scene *s, int id, dem_flow_counts *out, core_error *err)
{
    if (id < 0 || id >= dem_inserter_count(s))
        return core_fail(err, CORE_ERR_ARG, "no inserter %d", id + 1);
    *out = s->flow->ins[id].c;
    return CORE_OK;
}

core_status dem_outflow_counts(const dem_scene *s, int id, dem_flow_counts *out, core_error *err)
{
    if (id < 0 || id >= dem_outflow_count(s))
        return core_fail(err, CORE_ERR_ARG, "no outflow %d", id + 1);
    *out = s->flow->out[id].c;
    return CORE_OK;
}

core_status dem_flow_check_run(const dem_scene *s, core_error *err)
{
    /* tags alone (a LAMMPS file's ids) travel with their particles (domain_gather.c's table) */
    if (comm_size() > 1 && (s->flow->nins > 0 || s->flow->nout > 0))
        return core_fail(err, CORE_ERR_STATE,
                         "particle insertion and removal (inserters, outflows) do not yet run "
                         "distributed (comm_size() > 1): run this scene on one rank");
    if (s->bnd && s->flow->nout > 0)
        return core_fail(err, CORE_ERR_STATE,
                         "outflows cannot remove particles from a scene with boundary conditions "
                         "(their edges, springs and ties name particles by id)");
    return CORE_OK;
}

static double particle_mass(const dem_scene *s, int mat, double r)
{
    double vol = (s->dim == 2 && s->thickness > 0) ? DEM_PI * r * r * s->thickness
                                                   : 4.0 / 3.0 * DEM_PI * r * r * r;
    return s->mats[mat].density * vol;
}

double dem_inserter_rmin(const dem_inserter_def *d)
{
    if (d->size != DEM_SIZE_DISCRETE)
        return d->r0;
    double r = INFINITY; /* weights NULL: an inserter's own list, of positive weights only */
    for (size_t k = 0; k < d->nsizes; k++)
        if (!d->weights || d->weights[k] > 0)
            r = fmin(r, d->radii[k]);
    return r;
}

double dem_inserter_rmax(const dem_inserter_def *d)
{
    if (d->size == DEM_SIZE_CONSTANT)
        return d->r0;
    if (d->size == DEM_SIZE_UNIFORM)
        return d->r1;
    double r = 0;
    for (size_t k = 0; k < d->nsizes; k++)
        if (!d->weights || d->weights[k] > 0)
            r = fmax(r, d->radii[k]);
    return r;
}

int dem_flow_probe(dem_scene *s, int q, double *k, double *gamma, double *m_eff)
{
    if (q < 0 || q >= dem_inserter_count(s))
        return 0;
    const dem_inserter_def *d = &s->flow->ins[q].def;
    double r = dem_inserter_rmin(d), m = particle_mass(s, d->material, r);
    dem_probe_parameters(s, d->material, r, m, k, gamma);
    *m_eff = 0.5 * m;
    return 1;
}

/* ---- adding inserters and outflows ------------------------------------------------------------
 */
/* The region's bounding box, which must lie in the domain. */
core_status dem_inserter_region(const dem_scene *s, const dem_inserter_def *d, double lo[3],
                                double hi[3], core_error *err)
{
    for (int a = 0; a < s->dim; a++) {
        lo[a] = d->ball ? d->center[a] - d->extent : d->lo[a];
        hi[a] = d->ball ? d->center[a] + d->extent : d->hi[a];
        if (!(hi[a] > lo[a]))
            return core_fail(err, CORE_ERR_ARG, "the region is empty on axis %d ([%g, %g])", a + 1,
                             lo[a], hi[a]);
        if (lo[a] < s->lo[a] || hi[a] > s->hi[a])
            return core_fail(err, CORE_ERR_ARG,
                             "the region [%g, %g] on axis %d is not inside the domain [%g, %g]",
                             lo[a], hi[a], a + 1, s->lo[a], s->hi[a]);
    }
    return CORE_OK;
}

/* How many particles of the smallest radius the region's volume holds (N v <= V; a bound, not
 * a packing). */
static double region_capacity(const dem_scene *s, const dem_inserter_def *d)
{
    const int D = s->dim;
    const double r = dem_inserter_rmin(d);
    double vol = 1;
    if (d->ball)
        vol = D == 2 ? DEM_PI * d->extent * d->extent : 4.0 / 3.0 * DEM_PI * pow(d->extent, 3);
    else
        for (int a = 0; a < D; a++)
            vol *= d->hi[a] - d->lo[a];
    const double v = D == 2 ? DEM_PI * r * r : 4.0 / 3.0 * DEM_PI * r * r * r;
    return fmin(floor(vol / v), 1e15);
}

int dem_add_inserter(dem_scene *s, const dem_inserter_def *d, core_error *err)
{
    const int D = s->dim;
    double lo[3], hi[3];
    if (d->ball && !(d->extent > 0 && isfinite(d->extent)))
        return core_fail(err, CORE_ERR_ARG, "the region's radius must be > 0, got %g", d->extent),
               -1;
    if (!dem_finite_n(d->lo, D) || !dem_finite_n(d->hi, D) || !dem_finite_n(d->center, D) ||
        !dem_finite_n(d->velocity, D))
        return core_fail(err, CORE_ERR_ARG, "region and velocity must be finite"), -1;
    if (dem_inserter_region(s, d, lo, hi, err))
        return -1;
    if (!(d->rate >= 0 && isfinite(d->rate)))
        return core_fail(err, CORE_ERR_ARG, "rate must be >= 0, got %g", d->rate), -1;
    if (!(d->mass >= 0 && isfinite(d->mass)))
        return core_fail(err, CORE_ERR_ARG, "mass must be >= 0, got %g", d->mass), -1;
    if (d->rate == 0 && d->count < 0 && d->mass == 0)
        return core_fail(err, CORE_ERR_ARG, "an inserter needs a rate, a count or a mass"), -1;
    if (!(d->spread >= 0 && isfinite(d->spread)))
        return core_fail(err, CORE_ERR_ARG, "spread must be >= 0, got %g", d->spread), -1;
    if (d->every < 1 || d->attempts < 1)
        return core_fail(err, CORE_ERR_ARG, "every and attempts must be >= 1"), -1;
    if (d->material < 0 || d->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "unknown material %d", d->material), -1;
    if (d->size == DEM_SIZE_CONSTANT || d->size == DEM_SIZE_UNIFORM) {
        double r1 = d->size == DEM_SIZE_UNIFORM ? d->r1 : d->r0;
        if (!(d->r0 > 0 && isfinite(d->r0)) || !(r1 >= d->r0 && isfinite(r1)))
            return core_fail(err, CORE_ERR_ARG, "radii must be > 0 (and min <= max), got %g, %g",
                             d->r0, r1),
                   -1;
    } else if (d->size == DEM_SIZE_DISCRETE) {
        double wsum = 0;
        if (d->nsizes < 1)
            return core_fail(err, CORE_ERR_ARG, "a discrete size distribution needs radii"), -1;
        for (size_t k = 0; k < d->nsizes; k++) {
            if (!(d->radii[k] > 0 && isfinite(d->radii[k])))
                return core_fail(err, CORE_ERR_ARG, "radius %zu must be > 0, got %g", k + 1,
                                 d->radii[k]),
                       -1;
            if (!(d->weights[k] >= 0 && isfinite(d->weights[k])))
                return core_fail(err, CORE_ERR_ARG, "weight %zu must be >= 0, got %g", k + 1,
                                 d->weights[k]),
                       -1;
            wsum += d->weights[k];
        }
        if (!(wsum > 0))
            return core_fail(err, CORE_ERR_ARG, "the weights must not all be zero"), -1;
    } else {
        return core_fail(err, CORE_ERR_ARG, "unknown size distribution"), -1;
    }
    /* The sizes as dem_add_particle will judge them, so that no event fails on them. */
    double rbig = dem_inserter_rmax(d), extent = INFINITY, reach = 0;
    for (int a = 0; a < D; a++) {
        extent = fmin(extent, s->hi[a] - s->lo[a]);
        reach = fmax(reach, fmax(fabs(s->lo[a]), fabs(s->hi[a])));
    }
    if (rbig > 0.5 * extent || dem_inserter_rmin(d) < 1e-9 * reach)
        return core_fail(err, CORE_ERR_ARG,
                         "radii must lie in [%g, %g] (1e-9 of the largest box coordinate, half "
                         "the box's smallest extent; field 'radius' or 'radii')",
                         1e-9 * reach, 0.5 * extent),
               -1;
    if (dem_flow_on(s, err))
        return -1;
    dem_flow *f = s->flow;
    if (f->nins == f->cap_ins) {
        int cap = f->cap_ins ? 2 * f->cap_ins : 4;
        inserter *p = realloc(f->ins, (size_t)cap * sizeof *p);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate inserters"), -1;
        f->ins = p;
        f->cap_ins = cap;
    }
    inserter in;
    memset(&in, 0, sizeof in);
    in.def = *d;
    if (d->size == DEM_SIZE_DISCRETE) {
        in.radii = malloc(d->nsizes * sizeof *in.radii);
        in.cum = malloc(d->nsizes * sizeof *in.cum);
        if (!in.radii || !in.cum) {
            free(in.radii), free(in.cum);
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the size distribution"), -1;
        }
        /* The radii of positive weight only, with their cumulative weights. */
        double wsum = 0, acc = 0;
        size_t m = 0;
        for (size_t k = 0; k < d->nsizes; k++)
            wsum += d->weights[k];
        for (size_t k = 0; k < d->nsizes; k++) {
            if (!(d->weights[k] > 0))
                continue;
            in.radii[m] = d->radii[k];
            acc += d->weights[k];
            in.cum[m++] = acc / wsum;
        }
        in.cum[m - 1] = 1;
        in.def.nsizes = m;
    }
    in.def.radii = in.radii;
    in.def.weights = NULL; /* the cumulative weights stand for them */
    rng_seed(&in.rng, (uint64_t)d->seed, (uint64_t)f->nins);
    in.t0 = s->time;
    in.next_step = s->steps;
    f->ins[f->nins] = in;
    return f->nins++;
}

int dem_add_outflow(dem_scene *s, const dem_outflow_def *d, core_error *err)
{
    const int D = s->dim;
    if (d->side >= 0) {
        if (d->side >= 2 * D)
            return core_fail(err, CORE_ERR_ARG, "no side %d in %dD", d->side, D), -1;
        if (s->periodic[d->side / 2])
            return core_fail(err, CORE_ERR_ARG,
                             "axis %d is periodic: nothing leaves through its sides",
                             d->side / 2 + 1),
                   -1;
    } else {
        if (!dem_finite_n(d->lo, D) || !dem_finite_n(d->hi, D))
            return core_fail(err, CORE_ERR_ARG, "the box must be finite"), -1;
        for (int a = 0; a < D; a++)
            if (!(d->hi[a] > d->lo[a]))
                return core_fail(err, CORE_ERR_ARG, "the box is empty on axis %d ([%g, %g])", a + 1,
                                 d->lo[a], d->hi[a]),
                       -1;
    }
    if (dem_flow_on(s, err))
        return -1;
    dem_flow *f = s->flow;
    if (f->nout == f->cap_out) {
        int cap = f->cap_out ? 2 * f->cap_out : 4;
        outflow *p = realloc(f->out, (size_t)cap * sizeof *p);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate outflows"), -1;
        f->out = p;
        f->cap_out = cap;
    }
    f->out[f->nout] = (outflow){.def = *d};
    return f->nout++;
}

/* ---- removal ----------------------------------------------------------------------------------
 */

/* Removes the particles marked in gone[] (n_gone of them), keeping the order of the others. */
static core_status compact(dem_scene *s, const unsigned char *gone, core_error *err)
{
    const size_t n = s->n;
    uint32_t *map = malloc((n ? n : 1) * sizeof *map);
    if (!map)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the removal map");
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        map[i] = gone[i] ? UINT32_MAX : (uint32_t)m++;
    dem_pairs *p = &s->pairs;
    const int D = s->dim, d0 = D == 2 ? 2 : 0;
    /* The forces of the last evaluation, which the next step's first kick uses, lose what the
     * removed particles contributed (as the gather adds it: +f on i, -f on j, -r c torque). */
    if (s->forces_ready && p->start) {
        for (size_t q = 0; q < p->n; q++) {
            const uint32_t i = p->i[q], j = p->j[q];
            if (i >= n || j >= n || gone[i] == gone[j])
                continue;
            const uint32_t k = gone[i] ? j : i;
            const double sign = gone[i] ? 1 : -1;
            for (int d = 0; d < D; d++)
                s->f[d][k] += sign * p->f[d][q];
            for (int d = d0; d < 3 && s->rot && p->c[d]; d++)
                s->tq[d][k] += s->r[k] * p->c[d][q];
        }
    }
    /* The pair list: pairs of two survivors, renumbered (the order stays (i, j)). */
    if (p->start) {
        size_t np_new = 0;
        for (size_t i = 0; i < p->np && i < n; i++)
            np_new += !gone[i];
        size_t w = 0;
        for (size_t q = 0; q < p->n; q++) {
            const uint32_t i = p->i[q], j = p->j[q];
            if (map[i] == UINT32_MAX || map[j] == UINT32_MAX)
                continue; /* its history goes with it */
            p->i[w] = map[i];
            p->j[w] = map[j];
            p->k[w] = p->k[q];
            p->gamma[w] = p->gamma[q];
            p->mu[w] = p->mu[q];
            for (int d = 0; d < DEM_HIST; d++) /* tangential and rolling (rolling.inc) */
                if (p->hist[d])
                    p->hist[d][w] = p->hist[d][q];
            for (int d = 0; d < 3; d++) {
                if (p->f[d])
                    p->f[d][w] = p->f[d][q];
                if (p->c[d])
                    p->c[d][w] = p->c[d][q];
            }
            w++;
        }
        p->n = w;
        const size_t keep = s->n;
        s->n = np_new; /* the incidence arrays cover the particles the list was built for */
        core_status st = dem_pairs_index(s, err);
        s->n = keep;
        if (st) {
            free(map);
            s->need_rebuild = 1;
            return st;
        }
    }
    for (int wi = 0; wi < s->nwalls; wi++) {
        dem_wall *wl = &s->walls[wi];
        size_t w = 0;
        for (size_t e = 0; e < wl->ncand; e++)
            if (wl->cand[e] < n && map[wl->cand[e]] != UINT32_MAX)
                wl->cand[w++] = map[wl->cand[e]];
        wl->ncand = w;
        wl->cand_par_ok = 0;
        if (wl->shape) { /* a wall beyond planes keeps its candidates in its shape (walls.c) */
            dem_shape *sh = wl->shape;
            w = 0;
            for (size_t e = 0; e < sh->ncand; e++)
                if (sh->cand[e] < n && map[sh->cand[e]] != UINT32_MAX)
                    sh->cand[w++] = map[sh->cand[e]];
            sh->ncand = w;
        }
    }
    dem_parray a[dem_max_particle_arrays(s)];
    const int na = dem_particle_arrays(s, a);
    for (int k = 0; k < na; k++) {
        char *base = *a[k].p;
        const size_t sz = a[k].size;
        for (size_t i = 0; i < n; i++)
            if (map[i] != UINT32_MAX && map[i] != i)
                memcpy(base + map[i] * sz, base + i * sz, sz);
    }
    s->n = m;
    free(map);
    return CORE_OK;
}

static int in_box(const dem_scene *s, size_t i, const double lo[3], const double hi[3])
{
    for (int d = 0; d < s->dim; d++)
        if (!(s->x[d][i] >= lo[d] && s->x[d][i] <= hi[d]))
            return 0;
    return 1;
}

/* Marks the particles each outflow takes (the first outflow that takes one counts it). */
static core_status removal(dem_scene *s, int *changed, core_error *err)
{
    dem_flow *f = s->flow;
    const size_t n = s->n;
    if (f->nout == 0 || n == 0)
        return CORE_OK;
    if (n > f->cap_gone) {
        unsigned char *g = realloc(f->gone, n);
        if (!g)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the removal marks");
        f->gone = g;
        f->cap_gone = n;
    }
    unsigned char *gone = f->gone;
    memset(gone, 0, n);
    size_t ngone = 0;
    for (int o = 0; o < f->nout; o++) {
        outflow *of = &f->out[o];
        if (of->def.side >= 0) {
            const int a = of->def.side / 2, upper = of->def.side % 2;
            const double *x = s->x[a], lim = upper ? s->hi[a] : s->lo[a];
            for (size_t i = 0; i < n; i++)
                if (!gone[i] && (upper ? x[i] > lim : x[i] < lim)) {
                    gone[i] = 1;
                    ngone++;
                    of->c.count++;
                    of->c.mass += s->m[i];
                }
        } else {
            for (size_t i = 0; i < n; i++)
                if (!gone[i] && !(s->flags[i] & DEM_FIXED) &&
                    in_box(s, i, of->def.lo, of->def.hi)) {
                    gone[i] = 1;
                    ngone++;
                    of->c.count++;
                    of->c.mass += s->m[i];
                }
        }
    }
    if (ngone == 0)
        return CORE_OK;
    *changed = 1;
    return compact(s, gone, err);
}

/* ---- insertion --------------------------------------------------------------------------------
 */

static double draw_radius(inserter *in)
{
    const dem_inserter_def *d = &in->def;
    if (d->size == DEM_SIZE_CONSTANT)
        return d->r0;
    double u = rng_uniform(&in->rng);
    if (d->size == DEM_SIZE_UNIFORM)
        return d->r0 + u * (d->r1 - d->r0);
    size_t k = 0;
    while (k + 1 < d->nsizes && !(u < in->cum[k]))
        k++;
    return in->radii[k];
}

/* A position in the region for a particle of radius r wholly inside it (0: it does not fit). */
static int draw_position(const dem_scene *s, inserter *in, double r, double x[3])
{
    const dem_inserter_def *d = &in->def;
    const int D = s->dim;
    if (!d->ball) {
        for (int a = 0; a < D; a++) {
            double room = d->hi[a] - d->lo[a] - 2 * r;
            if (room < 0)
                return 0;
            x[a] = d->lo[a] + r + rng_uniform(&in->rng) * room;
        }
        return 1;
    }
    double R = d->extent - r;
    if (R < 0)
        return 0;
    for (int tries = 0; tries < 64; tries++) { /* rejection from the cube: pi/4 or pi/6 accepted */
        double u[3] = {0, 0, 0}, u2 = 0;
        for (int a = 0; a < D; a++) {
            u[a] = 2 * rng_uniform(&in->rng) - 1;
            u2 += u[a] * u[a];
        }
        if (u2 <= 1) {
            for (int a = 0; a < D; a++)
                x[a] = d->center[a] + R * u[a];
            return 1;
        }
    }
    return 0;
}

static double image(const dem_scene *s, int d, double dx)
{
    return s->periodic[d] ? dx - s->len[d] * nearbyint(dx / s->len[d]) : dx;
}

/* Whether a particle of radius r at x overlaps a wall or one of the near particles. */
static int blocked(const dem_scene *s, const uint32_t *near, size_t nnear, const double x[3],
                   double r)
{
    const int D = s->dim;
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        double dist = 0;
        if (wl->shape) { /* walls beyond planes: the distance to the nearest element */
            dist = dem_shape_distance(s, wl, x);
        } else {
            for (int d = 0; d < D; d++)
                dist += (x[d] - wl->point[d]) * wl->normal[d];
        }
        if (dist < r)
            return 1;
    }
    for (size_t e = 0; e < nnear; e++) {
        const uint32_t j = near[e];
        double d2 = 0;
        for (int d = 0; d < D; d++) {
            double dx = image(s, d, x[d] - s->x[d][j]);
            d2 += dx * dx;
        }
        const double rs = r + s->r[j];
        if (d2 < rs * rs)
            return 1;
    }
    return 0;
}

static core_status push_near(dem_flow *f, size_t *nnear, uint32_t i, core_error *err)
{
    if (*nnear == f->cap_near) {
        size_t cap = f->cap_near ? 2 * f->cap_near : 256;
        uint32_t *p = realloc(f->near, cap * sizeof *p);
        if (!p)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the insertion list");
        f->near = p;
        f->cap_near = cap;
    }
    f->near[(*nnear)++] = i;
    return CORE_OK;
}

/* The new particle's state as a force evaluation and the integrators would have it: it touches
 * nothing, so its force is its weight (and drag), the same operations as the gather's. */
static void init_new(dem_scene *s, size_t i)
{
    const int D = s->dim, d0 = D == 2 ? 2 : 0;
    for (int d = 0; d < D; d++) {
        double fd = s->m[i] * s->gravity[d];
        if (s->drag > 0)
            fd -= s->drag * s->m[i] * s->v[d][i];
        s->f[d][i] = fd;
        if (s->x_prev[d]) { /* position Verlet's backward step (integrate.c) */
            const double h = s->prev_dt;
            s->x_prev[d][i] = s->prev_ready ? h * s->v[d][i] - 0.5 * h * h * fd * s->inv_m[i] : 0;
        }
        if (s->gear[0][d]) { /* Gear's scaled derivatives, as its start does */
            const double h = s->gear_dt;
            s->gear[0][d][i] = s->x[d][i];
            s->gear[1][d][i] = h * s->v[d][i];
            s->gear[2][d][i] = 0.5 * h * h * fd * s->inv_m[i];
            s->gear[3][d][i] = s->gear[4][d][i] = s->gear[5][d][i] = 0;
        }
    }
    for (int d = d0; s->rot && d < 3; d++)
        for (int k = 0; k < 6; k++)
            if (s->gear_w[k][d])
                s->gear_w[k][d][i] = 0;
}

static core_status insert(dem_scene *s, int q, long step, int *changed, core_error *err)
{
    dem_flow *f = s->flow;
    inserter *in = &f->ins[q];
    const dem_inserter_def *d = &in->def;
    const int D = s->dim;
    if (in->done || step < in->next_step)
        return CORE_OK;
    in->next_step = step + d->every;
    /* Due so far: by the rate (the product rounded down, 1e-12 relative for the summed time),
     * or everything at once; capped by the count. */
    long due;
    if (d->rate > 0) {
        double x = floor(d->rate * (s->time - in->t0) * (1 + 1e-12));
        due = x > 1e15 ? (long)1e15 : (long)x;
    } else {
        due = d->count >= 0 ? d->count : (long)1e15;
    }
    if (d->count >= 0 && due > d->count)
        due = d->count;
    long want = due - in->c.count - in->c.skipped;
    if (want <= 0)
        return CORE_OK;
    /* No event places more particles than the region's volume holds at its smallest radius:
     * the rest of what is due is skipped without a draw (a count of 1e15 in a small box once
     * tried every one of them, `attempts` times each). */
    const double cap = region_capacity(s, d);
    if ((double)want > cap) {
        if (d->rate > 0 || d->count >= 0) /* a mass alone stops at its first skip anyway */
            in->c.skipped += want - (long)cap;
        want = (long)cap;
    }
    in->c.events++;
    /* The particles that can touch one placed in the region. */
    double lo[3], hi[3], reach = dem_inserter_rmax(d) + s->r_max;
    dem_inserter_region(s, d, lo, hi, NULL);
    size_t nnear = 0;
    for (size_t i = 0; i < s->n; i++) {
        int in_reach = 1;
        for (int a = 0; a < D && in_reach; a++) {
            double c = 0.5 * (lo[a] + hi[a]), half = 0.5 * (hi[a] - lo[a]) + reach;
            in_reach = fabs(image(s, a, s->x[a][i] - c)) <= half;
        }
        if (in_reach && push_near(f, &nnear, (uint32_t)i, err))
            return err ? err->status : CORE_ERR_NOMEM;
    }
    const int rate_or_count = d->rate > 0 || d->count >= 0;
    const int fr = s->forces_ready, gr = s->gear_ready, pr = s->prev_ready;
    int added = 0;
    core_status st = CORE_OK;
    for (long k = 0; k < want && !in->done; k++) {
        if (d->mass > 0 && in->c.mass >= d->mass) {
            in->done = 1;
            break;
        }
        dem_particle_def p;
        memset(&p, 0, sizeof p);
        p.radius = draw_radius(in);
        p.material = d->material;
        int placed = 0;
        for (int t = 0; t < d->attempts && !placed; t++)
            placed =
                draw_position(s, in, p.radius, p.x) && !blocked(s, f->near, nnear, p.x, p.radius);
        if (!placed) {
            in->c.skipped++;
            if (!rate_or_count) /* a mass alone: the region is full, stop here */
                in->done = 1;
            continue;
        }
        for (int a = 0; a < D; a++)
            p.v[a] = d->velocity[a] + d->spread * (2 * rng_uniform(&in->rng) - 1);
        long i = dem_add_particle(s, &p, err);
        if (i < 0) {
            st = err ? err->status : CORE_ERR_ARG;
            break;
        }
        init_new(s, (size_t)i);
        in->c.count++;
        in->c.mass += s->m[i];
        *changed = added = 1;
        if ((st = push_near(f, &nnear, (uint32_t)i, err)))
            break;
    }
    if (d->count >= 0 && in->c.count + in->c.skipped >= d->count)
        in->done = 1;
    if (d->mass > 0 && in->c.mass >= d->mass)
        in->done = 1;
    /* dem_add_particle invalidated everything; what is stale is the list only (init_new gave the
     * new particles the state the integrators keep). */
    if (added) {
        s->forces_ready = fr, s->gear_ready = gr, s->prev_ready = pr;
        s->need_rebuild = 1;
    }
    return st;
}

core_status dem_flow_step(dem_scene *s, long step, core_error *err)
{
    dem_flow *f = s->flow;
    int changed = 0;
    core_status st = removal(s, &changed, err);
    for (int q = 0; q < f->nins && !st; q++)
        st = insert(s, q, step, &changed, err);
    if (changed)
        s->watch_on = 0; /* energy came or went: the watch takes a new reference */
    return st;
}
