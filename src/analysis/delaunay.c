/* The Delaunay mesh of particle centres: qhull's triangulation (reentrant API, errors captured
 * in memory, never printed), the alpha rule that peels the sliver triangles bridging concave
 * gaps of the outline, and the counter-clockwise boundary loop (Padbidri Sec. 2.5, Fig. 2.2). */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libqhull_r/qhull_ra.h>

#include "analysis/analysis.h"

analysis_delaunay_def analysis_default_delaunay_def(void)
{
    return (analysis_delaunay_def){.alpha = 1.5, .radius = NULL};
}

void analysis_mesh_destroy(analysis_mesh *m)
{
    if (!m)
        return;
    free(m->tri);
    free(m->loop);
    free(m->x0);
    free(m->y0);
    free(m);
}

/* Refusals before qhull sees the points: non-finite values, collinearity. (Duplicates show up
 * as points that are no vertex; see duplicate_error.) */
static core_status check_points(const double *x, const double *y, size_t np, core_error *err)
{
    if (np < 3)
        return core_fail(err, CORE_ERR_ARG,
                         "a Delaunay triangulation needs at least 3 particles, got %zu", np);
    for (size_t i = 0; i < np; i++)
        if (!isfinite(x[i]) || !isfinite(y[i]))
            return core_fail(err, CORE_ERR_ARG, "particle %zu has a non-finite position (%g, %g)",
                             i + 1, x[i], y[i]);
    /* Collinear: every point within a relative 1e-12 of the line through the first point and the
     * farthest from it. */
    size_t far = 0;
    double d2max = 0, scale = 0;
    for (size_t i = 1; i < np; i++) {
        double dx = x[i] - x[0], dy = y[i] - y[0], d2 = dx * dx + dy * dy;
        if (d2 > d2max) {
            d2max = d2;
            far = i;
        }
    }
    if (d2max == 0)
        return core_fail(err, CORE_ERR_ARG, "all %zu particles have the same position (%g, %g)", np,
                         x[0], y[0]);
    scale = sqrt(d2max);
    double ux = (x[far] - x[0]) / scale, uy = (y[far] - y[0]) / scale, off = 0;
    for (size_t i = 0; i < np; i++)
        off = fmax(off, fabs((x[i] - x[0]) * uy - (y[i] - y[0]) * ux));
    if (off <= 1e-12 * scale)
        return core_fail(err, CORE_ERR_ARG,
                         "all %zu particle centres are collinear: they span no area to "
                         "triangulate", np);
    return CORE_OK;
}

static double tri_area(const double *x, const double *y, long a, long b, long c)
{
    return 0.5 * ((x[b] - x[a]) * (y[c] - y[a]) - (x[c] - x[a]) * (y[b] - y[a]));
}

/* A triangle flat to rounding: twice its area below ANALYSIS_FLAT times its longest edge
 * squared. qhull makes them of points collinear up to rounding on the hull (three grains in a
 * row along a wall); they only ever lie on the outline, and a strain over such a cell is noise
 * amplified 1e12 times, so the peeling removes them whatever alpha. */
static int flat(const double *x, const double *y, const long *v)
{
    double l2 = 0;
    for (int k = 0; k < 3; k++) {
        double dx = x[v[(k + 1) % 3]] - x[v[k]], dy = y[v[(k + 1) % 3]] - y[v[k]];
        l2 = fmax(l2, dx * dx + dy * dy);
    }
    return 2 * fabs(tri_area(x, y, v[0], v[1], v[2])) <= ANALYSIS_FLAT * l2;
}

/* qhull's Delaunay triangles of the points, counter-clockwise: *tri (3 per triangle). */
static core_status run_qhull(const double *x, const double *y, size_t np, long **tri,
                             size_t *ntri, core_error *err)
{
    coordT *pts = malloc(2 * np * sizeof *pts);
    char *msg = NULL;
    size_t msglen = 0;
    FILE *errfile = open_memstream(&msg, &msglen);
    if (!pts || !errfile) {
        free(pts);
        if (errfile)
            fclose(errfile);
        free(msg);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu points", np);
    }
    /* Centred and scaled: qhull's precision tests are relative to the coordinates' size. */
    double cx = 0, cy = 0, s = 0;
    for (size_t i = 0; i < np; i++) {
        cx += x[i];
        cy += y[i];
    }
    cx /= (double)np;
    cy /= (double)np;
    for (size_t i = 0; i < np; i++)
        s = fmax(s, fmax(fabs(x[i] - cx), fabs(y[i] - cy)));
    for (size_t i = 0; i < np; i++) {
        pts[2 * i] = (x[i] - cx) / s;
        pts[2 * i + 1] = (y[i] - cy) / s;
    }
    qhT qh_qh;
    qhT *qh = &qh_qh;
    qh_zero(qh, errfile);
    /* d: Delaunay; Qbb: scale the paraboloid; Qc: keep coplanar points; Qz: a point at infinity
     * (cocircular input); Qt: triangulated output; Q12: no error on wide facets. */
    char flags[] = "qhull d Qbb Qc Qz Qt Q12";
    int code = qh_new_qhull(qh, 2, (int)np, pts, False, flags, NULL, errfile);
    core_status st = CORE_OK;
    long *t = NULL;
    size_t n = 0;
    if (code == 0) {
        facetT *facet;
        vertexT *vertex, **vertexp;
        size_t cap = 0;
        FORALLfacets {
            if (!facet->upperdelaunay)
                cap++;
        }
        t = malloc((cap ? cap : 1) * 3 * sizeof *t);
        if (!t) {
            st = core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu triangles", cap);
        } else {
            FORALLfacets {
                if (facet->upperdelaunay)
                    continue;
                long v[3];
                int k = 0, ok = 1;
                FOREACHvertex_(facet->vertices) {
                    int id = qh_pointid(qh, vertex->point);
                    if (k < 3)
                        v[k] = id;
                    k++;
                    if (id < 0 || (size_t)id >= np)
                        ok = 0; /* the point at infinity */
                }
                if (!ok || k != 3)
                    continue;
                if (tri_area(x, y, v[0], v[1], v[2]) < 0) {
                    long tmp = v[1];
                    v[1] = v[2];
                    v[2] = tmp;
                }
                memcpy(t + 3 * n, v, sizeof v);
                n++;
            }
        }
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong, totlong;
    qh_memfreeshort(qh, &curlong, &totlong);
    fclose(errfile);
    free(pts);
    if (code != 0) {
        /* qhull's message: its first line says what went wrong. */
        char first[300] = "";
        if (msg) {
            size_t k = 0;
            while (msg[k] && msg[k] != '\n' && k + 1 < sizeof first) {
                first[k] = msg[k];
                k++;
            }
            first[k] = 0;
        }
        st = core_fail(err, CORE_ERR_ARG, "qhull could not triangulate the %zu centres (code %d)%s%s",
                       np, code, first[0] ? ": " : "", first);
    }
    free(msg);
    if (st == CORE_OK && n == 0)
        st = core_fail(err, CORE_ERR_ARG, "the triangulation of the %zu centres has no triangles "
                       "(degenerate input)", np);
    if (st != CORE_OK) {
        free(t);
        return st;
    }
    *tri = t;
    *ntri = n;
    return CORE_OK;
}

static int by_value(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* Half the median Delaunay edge: the radius assumed when none is given. */
static double median_edge(const double *x, const double *y, const long *tri, size_t nt)
{
    double *len = malloc(3 * nt * sizeof *len);
    if (!len)
        return 0;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            long a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            len[3 * t + k] = hypot(x[b] - x[a], y[b] - y[a]);
        }
    qsort(len, 3 * nt, sizeof *len, by_value);
    double m = len[3 * nt / 2];
    free(len);
    return m;
}

/* Particle i is no vertex of the triangulation: name its twin (exact, else the nearest). */
static core_status duplicate_error(const double *x, const double *y, size_t np, size_t i,
                                   core_error *err)
{
    size_t best = i;
    double d2min = INFINITY;
    for (size_t j = 0; j < np; j++) {
        double dx = x[j] - x[i], dy = y[j] - y[i], d2 = dx * dx + dy * dy;
        if (j != i && d2 < d2min) {
            d2min = d2;
            best = j;
        }
    }
    size_t a = i < best ? i : best, b = i < best ? best : i;
    if (d2min == 0)
        return core_fail(err, CORE_ERR_ARG,
                         "particles %zu and %zu have the same position (%g, %g): the "
                         "triangulation of centres needs distinct points", a + 1, b + 1, x[i], y[i]);
    return core_fail(err, CORE_ERR_ARG,
                     "particle %zu at (%g, %g) is not a vertex of the triangulation: it nearly "
                     "coincides with particle %zu (%.3g apart)", i + 1, x[i], y[i], best + 1,
                     sqrt(d2min));
}

/* The working arrays of the peeling, over the nt triangles tri of np particles. */
typedef struct peel_work {
    const long *tri;
    size_t np, nt;
    unsigned char *used;      /* particle is a vertex */
    long *bcount;             /* boundary edges at each particle */
    size_t *inc_start, *fill; /* CSR lists of the triangles at each particle */
    long *inc;
    long *nb; /* the neighbour across each edge, -1: none */
    unsigned char *alive, *queued;
    long *stack;
} peel_work;

static void work_free(peel_work *w)
{
    free(w->used);
    free(w->bcount);
    free(w->inc_start);
    free(w->fill);
    free(w->inc);
    free(w->nb);
    free(w->alive);
    free(w->queued);
    free(w->stack);
}

/* Returns 0 when out of memory (what was allocated is in w, for work_free). */
static int work_alloc(peel_work *w, const long *tri, size_t np, size_t nt)
{
    w->tri = tri;
    w->np = np;
    w->nt = nt;
    w->used = calloc(np, 1);
    w->bcount = calloc(np, sizeof *w->bcount);
    w->inc_start = calloc(np + 1, sizeof *w->inc_start);
    w->fill = calloc(np, sizeof *w->fill);
    w->inc = malloc(3 * nt * sizeof *w->inc);
    w->nb = malloc(3 * nt * sizeof *w->nb);
    w->alive = malloc(nt);
    w->queued = calloc(nt ? nt : 1, 1);
    w->stack = malloc(nt * sizeof *w->stack);
    return w->used && w->bcount && w->inc_start && w->fill && w->inc && w->nb && w->alive &&
           w->queued && w->stack;
}

/* Every particle must be a vertex: one that is not lies (within qhull's precision) on top of
 * another. */
static core_status check_vertices(const double *x, const double *y, peel_work *w, core_error *err)
{
    for (size_t k = 0; k < 3 * w->nt; k++)
        w->used[w->tri[k]] = 1;
    for (size_t i = 0; i < w->np; i++)
        if (!w->used[i])
            return duplicate_error(x, y, w->np, i, err);
    return CORE_OK;
}

/* Neighbours across each edge k = (v[k], v[k+1]): the other triangle at vertex a that also has b
 * (triangles per vertex in CSR lists; a vertex has about 6); every triangle alive, and the
 * boundary edges counted at their particles. */
static void edge_neighbours(peel_work *w)
{
    const long *tri = w->tri;
    const size_t np = w->np, nt = w->nt;
    size_t *inc_start = w->inc_start, *fill = w->fill;
    long *inc = w->inc, *nb = w->nb;
    for (size_t q = 0; q < 3 * nt; q++)
        inc_start[tri[q] + 1]++;
    for (size_t i = 0; i < np; i++)
        inc_start[i + 1] += inc_start[i];
    for (size_t q = 0; q < 3 * nt; q++)
        inc[fill[tri[q]]++ + inc_start[tri[q]]] = (long)(q / 3);
    for (size_t t = 0; t < nt; t++) {
        w->alive[t] = 1;
        for (int k = 0; k < 3; k++) {
            long a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3], o = -1;
            for (size_t q = inc_start[a]; q < inc_start[a + 1] && o < 0; q++) {
                long u = inc[q];
                if (u != (long)t && (tri[3 * u] == b || tri[3 * u + 1] == b || tri[3 * u + 2] == b))
                    o = u;
            }
            nb[3 * t + k] = o;
        }
    }
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            if (nb[3 * t + k] < 0) {
                w->bcount[tri[3 * t + k]]++;
                w->bcount[tri[3 * t + (k + 1) % 3]]++;
            }
}

/* The alpha rule: peel boundary triangles whose outer edge is too long for its pair, and
 * (whatever alpha) those flat to rounding (see flat()). A triangle can only become
 * peelable when a neighbour is peeled (bcount never decreases), so the stack holds the
 * boundary triangles, then the neighbours of each peeled one. A triangle waits on the stack
 * at most once (queued), which bounds the stack by nt: without that, a small mesh whose
 * triangles all touch the hull (a square and its centre) pushes nt + 2 x peeled entries and
 * overflowed it. The number peeled goes to *peeled_out. */
static core_status peel(const double *x, const double *y, const analysis_delaunay_def *dp,
                        peel_work *w, size_t *peeled_out, core_error *err)
{
    const analysis_delaunay_def d = *dp;
    const long *tri = w->tri, *nb = w->nb;
    const size_t nt = w->nt;
    long *bcount = w->bcount, *stack = w->stack;
    unsigned char *alive = w->alive, *queued = w->queued;
    size_t peeled = 0;
    double rdef = 0;
    if (d.alpha > 0 && !d.radius && !((rdef = 0.5 * median_edge(x, y, tri, nt)) > 0))
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the edges of %zu particles",
                         w->np);
    /* Two passes: the flat triangles first, else an alpha peel next to one can put its third
     * particle on the outline and leave it stuck (a row of centres on a wall). */
    for (int pass = 0; pass < (d.alpha > 0 ? 2 : 1); pass++) {
        size_t top = 0;
        for (size_t t = 0; t < nt; t++)
            for (int k = 0; k < 3 && alive[t]; k++) {
                long o = nb[3 * t + k];
                if (o < 0 || !alive[o]) {
                    stack[top++] = (long)t;
                    queued[t] = 1;
                    break;
                }
            }
        while (top > 0) {
            long t = stack[--top];
            queued[t] = 0;
            if (!alive[t])
                continue;
            int nbnd = 0, bk = -1;
            for (int k = 0; k < 3; k++) {
                long o = nb[3 * t + k];
                if (o < 0 || !alive[o]) {
                    nbnd++;
                    bk = k;
                }
            }
            /* Only a triangle with one boundary edge and its third particle inside: peeling it
             * neither pinches the outline nor drops a particle from the mesh (a stray particle
             * stays attached by long edges, so pressure on them pulls it back). */
            if (nbnd != 1 || bcount[tri[3 * t + (bk + 2) % 3]] > 0)
                continue;
            long a = tri[3 * t + bk], b = tri[3 * t + (bk + 1) % 3];
            double ra = d.radius ? d.radius[a] : rdef, rb = d.radius ? d.radius[b] : rdef;
            int too_long = pass == 1 && hypot(x[b] - x[a], y[b] - y[a]) > d.alpha * (ra + rb);
            if (!too_long && !flat(x, y, tri + 3 * t))
                continue;
            alive[t] = 0;
            peeled++;
            for (int k = 0; k < 3; k++) {
                long o = nb[3 * t + k];
                long p = tri[3 * t + k], q = tri[3 * t + (k + 1) % 3];
                int delta = (o < 0 || !alive[o]) ? -1 : 1;
                bcount[p] += delta;
                bcount[q] += delta;
                if (o >= 0 && alive[o] && !queued[o]) {
                    stack[top++] = o;
                    queued[o] = 1;
                }
            }
        }
    }
    *peeled_out = peeled;
    return CORE_OK;
}

/* The kept cells and the boundary loop (each boundary vertex has one outgoing edge) into m. */
static core_status build_mesh(const double *x, const double *y, peel_work *w, size_t peeled,
                              analysis_mesh *m, core_error *err)
{
    const long *tri = w->tri, *nb = w->nb;
    const size_t np = w->np, nt = w->nt;
    const unsigned char *alive = w->alive;
    m->np = np;
    m->ndelaunay = nt;
    m->npeeled = peeled;
    m->ncells = nt - peeled;
    m->tri = malloc((m->ncells ? m->ncells : 1) * 3 * sizeof *m->tri);
    m->x0 = malloc(np * sizeof *m->x0);
    m->y0 = malloc(np * sizeof *m->y0);
    long *next = w->stack; /* reuse: next[v] of the boundary, np entries needed */
    long *nextbuf = NULL;
    if (nt < np) {
        nextbuf = malloc(np * sizeof *nextbuf);
        next = nextbuf;
    }
    if (!m->tri || !m->x0 || !m->y0 || !next) {
        free(nextbuf);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the mesh of %zu particles", np);
    }
    memcpy(m->x0, x, np * sizeof *x);
    memcpy(m->y0, y, np * sizeof *y);
    for (size_t i = 0; i < np; i++)
        next[i] = -1;
    size_t c = 0, nbe = 0;
    long start = -1;
    int bad = 0;
    for (size_t t = 0; t < nt; t++) {
        if (!alive[t])
            continue;
        memcpy(m->tri + 3 * c, tri + 3 * t, 3 * sizeof *tri);
        m->area += tri_area(x, y, tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]);
        c++;
        for (int k = 0; k < 3; k++) {
            long o = nb[3 * t + k];
            if (o >= 0 && alive[o])
                continue;
            long a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            if (next[a] >= 0)
                bad = 1;
            next[a] = b;
            nbe++;
            if (start < 0 || a < start)
                start = a;
        }
    }
    m->loop = malloc((nbe ? nbe : 1) * sizeof *m->loop);
    if (!m->loop) {
        free(nextbuf);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the boundary loop");
    }
    size_t nl = 0;
    for (long v = start; !bad && nl < nbe; nl++) {
        m->loop[nl] = v;
        v = next[v];
        if (v < 0)
            bad = 1;
        else if (v == start) {
            nl++;
            break;
        }
    }
    free(nextbuf);
    if (bad || nl != nbe)
        return core_fail(err, CORE_ERR_STATE,
                         "the boundary of the mesh is not one simple loop "
                         "(%zu edges, a loop of %zu): report this input",
                         nbe, nl);
    m->nloop = nl;
    return CORE_OK;
}

static core_status check_input(const double *x, const double *y, size_t np,
                               const analysis_delaunay_def *d, core_error *err)
{
    if (!(d->alpha >= 0) || !isfinite(d->alpha))
        return core_fail(err, CORE_ERR_ARG, "alpha must be >= 0 (0: keep the convex hull), got %g",
                         d->alpha);
    core_status st = check_points(x, y, np, err);
    if (st)
        return st;
    for (size_t i = 0; d->radius && i < np; i++)
        if (!(d->radius[i] > 0) || !isfinite(d->radius[i]))
            return core_fail(err, CORE_ERR_ARG,
                             "particle %zu has radius %g: the alpha rule needs "
                             "positive finite radii",
                             i + 1, d->radius[i]);
    return CORE_OK;
}

core_status analysis_delaunay(const double *x, const double *y, size_t np,
                              const analysis_delaunay_def *def, analysis_mesh **out,
                              core_error *err)
{
    analysis_delaunay_def d = def ? *def : analysis_default_delaunay_def();
    core_status st = check_input(x, y, np, &d, err);
    if (st)
        return st;
    long *tri = NULL;
    size_t nt = 0;
    if ((st = run_qhull(x, y, np, &tri, &nt, err)))
        return st;
    peel_work w;
    memset(&w, 0, sizeof w);
    int ok = work_alloc(&w, tri, np, nt);
    analysis_mesh *m = calloc(1, sizeof *m);
    size_t peeled = 0;
    if (!ok || !m)
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory for the mesh of %zu particles", np);
    if (!st)
        st = check_vertices(x, y, &w, err);
    if (!st) {
        edge_neighbours(&w);
        st = peel(x, y, &d, &w, &peeled, err);
    }
    if (!st)
        st = build_mesh(x, y, &w, peeled, m, err);
    if (!st) {
        *out = m;
        m = NULL;
    }
    analysis_mesh_destroy(m);
    free(tri);
    work_free(&w);
    return st;
}
