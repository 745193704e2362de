/* The alpha peeling of analysis_delaunay on every small and degenerate set we can enumerate:
 * all subsets of 3..8 points of 3x3 and 4x3 lattices (cocircular squares everywhere, collinear
 * hull points, equal radii so that peeling thresholds coincide), regular polygons with and
 * without their centre, collinear sets, duplicates. Each call ends in a clean refusal (status,
 * message, no mesh) or in a mesh that satisfies every invariant stated in check_mesh; ASan (the
 * sanitizer build) watches the memory. No Lua. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "analysis/analysis.h"

enum { NMAX = 16 };
static const double PI = 3.14159265358979323846;

/* One case: the points, optional radii, alpha, and a label for failure messages. */
typedef struct pcase {
    char label[160];
    size_t n;
    double x[NMAX], y[NMAX], r[NMAX];
    int has_r;
    double alpha;
} pcase;

typedef struct tally {
    long valid, refused, peeled, cases;
} tally;

static double area3(const double *x, const double *y, long a, long b, long c)
{
    return 0.5 * ((x[b] - x[a]) * (y[c] - y[a]) - (x[c] - x[a]) * (y[b] - y[a]));
}

static int by_double(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* Convex hull area by Andrew's monotone chain, independent of qhull. */
static double hull_area(const double *x, const double *y, size_t n)
{
    size_t idx[NMAX], h[2 * NMAX], k = 0;
    for (size_t i = 0; i < n; i++)
        idx[i] = i;
    for (size_t i = 1; i < n; i++) /* insertion sort by (x, y) */
        for (size_t j = i; j > 0; j--) {
            size_t a = idx[j - 1], b = idx[j];
            if (x[a] < x[b] || (x[a] == x[b] && y[a] <= y[b]))
                break;
            idx[j - 1] = b;
            idx[j] = a;
        }
    for (size_t i = 0; i < n; i++) {
        while (k >= 2 && area3(x, y, (long)h[k - 2], (long)h[k - 1], (long)idx[i]) <= 0)
            k--;
        h[k++] = idx[i];
    }
    for (size_t i = n - 1, lo = k + 1; i-- > 0;) {
        while (k >= lo && area3(x, y, (long)h[k - 2], (long)h[k - 1], (long)idx[i]) <= 0)
            k--;
        h[k++] = idx[i];
    }
    double A = 0;
    for (size_t i = 0; i + 1 < k; i++)
        A += 0.5 * (x[h[i]] * y[h[i + 1]] - x[h[i + 1]] * y[h[i]]);
    return A;
}

/* Is the triangle (a, b, c) (any rotation, same orientation) a cell of m? */
static int has_cell(const analysis_mesh *m, long a, long b, long c)
{
    for (size_t t = 0; t < m->ncells; t++)
        for (int k = 0; k < 3; k++)
            if (m->tri[3 * t + k] == a && m->tri[3 * t + (k + 1) % 3] == b &&
                m->tri[3 * t + (k + 2) % 3] == c)
                return 1;
    return 0;
}

/* Half the median edge over the full triangulation, counted per triangle as the kernel does. */
static double default_radius(const double *x, const double *y, const analysis_mesh *full)
{
    double len[6 * NMAX * 3];
    size_t n = 3 * full->ncells;
    assert_true(n <= sizeof len / sizeof *len);
    for (size_t t = 0; t < full->ncells; t++)
        for (int k = 0; k < 3; k++) {
            long a = full->tri[3 * t + k], b = full->tri[3 * t + (k + 1) % 3];
            len[3 * t + k] = hypot(x[b] - x[a], y[b] - y[a]);
        }
    qsort(len, n, sizeof *len, by_double);
    return 0.5 * len[n / 2];
}

#define FAIL(...) return snprintf(why, 256, __VA_ARGS__), why

/* Every invariant of a mesh built from c (with c->alpha), against full (the same points with
 * alpha = 0, itself checked first with full = NULL). Returns NULL, or what is wrong. */
static const char *check_mesh(const pcase *c, const analysis_mesh *m, const analysis_mesh *full,
                              char *why)
{
    const double *x = c->x, *y = c->y;
    size_t n = c->n;
    double alpha = full ? c->alpha : 0;
    double ext = 0;
    for (size_t i = 0; i < n; i++)
        ext = fmax(ext, fmax(fabs(x[i] - x[0]), fabs(y[i] - y[0])));
    const double tolA = 1e-10 * ext * ext;
    if (m->np != n)
        FAIL("np %zu, expected %zu", m->np, n);
    if (m->ncells < 1 || m->ncells + m->npeeled != m->ndelaunay)
        FAIL("%zu cells + %zu peeled != %zu Delaunay triangles", m->ncells, m->npeeled,
             m->ndelaunay);
    if (m->nloop < 3 || m->nloop > n)
        FAIL("boundary loop of %zu for %zu particles", m->nloop, n);
    /* Cells: indices in range and distinct, counter-clockwise with a positive area. */
    unsigned char used[NMAX] = {0};
    double sum = 0;
    for (size_t t = 0; t < m->ncells; t++) {
        const long *v = m->tri + 3 * t;
        for (int k = 0; k < 3; k++)
            if (v[k] < 0 || (size_t)v[k] >= n)
                FAIL("cell %zu has vertex %ld out of range", t, v[k]);
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            FAIL("cell %zu repeats a vertex (%ld %ld %ld)", t, v[0], v[1], v[2]);
        double A = area3(x, y, v[0], v[1], v[2]), l2 = 0;
        for (int k = 0; k < 3; k++)
            l2 =
                fmax(l2, pow(x[v[(k + 1) % 3]] - x[v[k]], 2) + pow(y[v[(k + 1) % 3]] - y[v[k]], 2));
        if (!(2 * A > ANALYSIS_FLAT * l2)) /* counter-clockwise and not flat */
            FAIL("cell %zu (%ld %ld %ld) has area %g (longest edge %g)", t, v[0], v[1], v[2], A,
                 sqrt(l2));
        sum += A;
        used[v[0]] = used[v[1]] = used[v[2]] = 1;
    }
    for (size_t i = 0; i < n; i++)
        if (!used[i])
            FAIL("particle %zu is in no cell", i);
    if (fabs(sum - m->area) > tolA)
        FAIL("area %.17g, cells sum to %.17g", m->area, sum);
    /* Directed edges: each once (consistent orientation, at most two cells per edge); the
     * boundary edges (reverse absent) each belong to exactly one cell, and are the loop's. */
    size_t ne = 3 * m->ncells, nbe = 0;
    long ea[3 * 6 * NMAX], eb[3 * 6 * NMAX];
    int bnd[3 * 6 * NMAX];
    assert_true(ne <= sizeof ea / sizeof *ea);
    for (size_t t = 0; t < m->ncells; t++)
        for (int k = 0; k < 3; k++) {
            ea[3 * t + k] = m->tri[3 * t + k];
            eb[3 * t + k] = m->tri[3 * t + (k + 1) % 3];
        }
    int bcount[NMAX] = {0};
    for (size_t e = 0; e < ne; e++) {
        bnd[e] = 1;
        for (size_t f = 0; f < ne; f++) {
            if (f != e && ea[f] == ea[e] && eb[f] == eb[e])
                FAIL("edge %ld -> %ld is in two cells with the same orientation", ea[e], eb[e]);
            if (ea[f] == eb[e] && eb[f] == ea[e])
                bnd[e] = 0;
        }
        if (bnd[e]) {
            nbe++;
            bcount[ea[e]]++;
            bcount[eb[e]]++;
        }
    }
    if (nbe != m->nloop)
        FAIL("%zu boundary edges, a loop of %zu", nbe, m->nloop);
    unsigned char onloop[NMAX] = {0};
    double shoelace = 0;
    for (size_t k = 0; k < m->nloop; k++) {
        long a = m->loop[k], b = m->loop[(k + 1) % m->nloop];
        if (a < 0 || (size_t)a >= n || onloop[a])
            FAIL("loop entry %zu (%ld) out of range or repeated", k, a);
        onloop[a] = 1;
        int found = 0;
        for (size_t e = 0; e < ne && !found; e++)
            found = bnd[e] && ea[e] == a && eb[e] == b;
        if (!found)
            FAIL("loop step %ld -> %ld is no boundary edge", a, b);
        shoelace += 0.5 * (x[a] * y[b] - x[b] * y[a]);
    }
    if (fabs(shoelace - m->area) > tolA)
        FAIL("the loop encloses %.17g, the cells %.17g", shoelace, m->area);
    double hull = hull_area(x, y, n);
    if (m->area > hull + tolA)
        FAIL("area %.17g above the convex hull's %.17g", m->area, hull);
    if (!full) {
        /* alpha = 0: the whole hull but flat slivers, and Delaunay (no point strictly inside
         * a cell's circumcircle; the exact lattices need no tolerance, the rest does). */
        if (fabs(m->area - hull) > tolA)
            FAIL("alpha = 0: %zu peeled, area %.17g, hull %.17g", m->npeeled, m->area, hull);
        for (size_t t = 0; t < m->ncells; t++) {
            const long *v = m->tri + 3 * t;
            for (size_t p = 0; p < n; p++) {
                double M[3][3];
                for (int k = 0; k < 3; k++) {
                    double dx = x[v[k]] - x[p], dy = y[v[k]] - y[p];
                    M[k][0] = dx;
                    M[k][1] = dy;
                    M[k][2] = dx * dx + dy * dy;
                }
                double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                             M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                             M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
                if (det > 1e-9 * ext * ext * ext * ext)
                    FAIL("particle %zu is inside the circumcircle of cell %zu", p, t);
            }
        }
        return NULL;
    }
    /* Peeled: the kept cells are cells of the alpha = 0 mesh; each removed one has an edge
     * longer than alpha (r_a + r_b) (only such a triangle can be peeled, but for flat ones,
     * which the alpha = 0 mesh has peeled too). */
    if (m->ndelaunay != full->ndelaunay)
        FAIL("%zu Delaunay triangles, %zu with alpha = 0", m->ndelaunay, full->ndelaunay);
    double rdef = c->has_r ? 0 : default_radius(x, y, full);
#define RAD(i) (c->has_r ? c->r[i] : rdef)
    for (size_t t = 0; t < m->ncells; t++)
        if (!has_cell(full, m->tri[3 * t], m->tri[3 * t + 1], m->tri[3 * t + 2]))
            FAIL("cell %zu is not a Delaunay triangle", t);
    for (size_t t = 0; t < full->ncells; t++) {
        const long *v = full->tri + 3 * t;
        if (has_cell(m, v[0], v[1], v[2]))
            continue;
        int longe = 0;
        for (int k = 0; k < 3; k++) {
            long a = v[k], b = v[(k + 1) % 3];
            longe |= hypot(x[b] - x[a], y[b] - y[a]) > alpha * (RAD(a) + RAD(b));
        }
        if (!longe)
            FAIL("triangle (%ld %ld %ld) was peeled without a long edge", v[0], v[1], v[2]);
    }
    /* The peeling stopped at a fixed point: no kept cell is still peelable (one boundary edge,
     * longer than alpha (r_a + r_b), and its third particle off the boundary). */
    for (size_t t = 0; t < m->ncells; t++) {
        int nb = 0, kb = -1;
        for (int k = 0; k < 3; k++)
            if (bnd[3 * t + k]) {
                nb++;
                kb = k;
            }
        if (nb != 1)
            continue;
        long a = m->tri[3 * t + kb], b = m->tri[3 * t + (kb + 1) % 3],
             o = m->tri[3 * t + (kb + 2) % 3];
        if (hypot(x[b] - x[a], y[b] - y[a]) > alpha * (RAD(a) + RAD(b)) && bcount[o] == 0)
            FAIL("cell %zu (%ld %ld %ld) is still peelable", t, a, b, o);
    }
#undef RAD
    return NULL;
}

static void describe(const pcase *c, char *buf, size_t size)
{
    int k = snprintf(buf, size, "%s, alpha %g:", c->label, c->alpha);
    for (size_t i = 0; i < c->n && k > 0 && (size_t)k < size; i++)
        k += c->has_r ? snprintf(buf + k, size - (size_t)k, " (%.17g, %.17g r %.17g)", c->x[i],
                                 c->y[i], c->r[i])
                      : snprintf(buf + k, size - (size_t)k, " (%.17g, %.17g)", c->x[i], c->y[i]);
}

/* Runs c. refusal: NULL = a valid mesh is required; "" = a refusal or a valid mesh are both
 * fine; otherwise a refusal whose message contains it is required. */
static void run_case(const pcase *c, const char *refusal, analysis_mesh **cache, tally *tl)
{
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.alpha = c->alpha;
    def.radius = c->has_r ? c->r : NULL;
    analysis_mesh *m = NULL, *full = NULL;
    core_error err;
    core_error_clear(&err);
    core_status st = analysis_delaunay(c->x, c->y, c->n, &def, &m, &err);
    char what[2048], why[256];
    const char *bad = NULL;
    tl->cases++;
    if (st != CORE_OK) {
        tl->refused++;
        if (m)
            bad = "a refusal left a mesh";
        else if (!err.msg[0] || err.status != st)
            bad = "a refusal without a message";
        else if (!refusal || (refusal[0] && !strstr(err.msg, refusal)))
            bad = err.msg;
    } else if (refusal && refusal[0]) {
        bad = "accepted, expected a refusal";
    } else {
        tl->valid++;
        tl->peeled += (long)m->npeeled;
        /* The alpha = 0 mesh depends on the points only: cache holds it across radii. */
        analysis_delaunay_def d0 = def;
        d0.alpha = 0;
        core_error err0;
        if (cache && *cache) {
            bad = check_mesh(c, m, *cache, why);
        } else if (analysis_delaunay(c->x, c->y, c->n, &d0, &full, &err0) != CORE_OK) {
            bad = "accepted with alpha, refused with alpha = 0";
        } else if (!(bad = check_mesh(c, full, NULL, why))) {
            bad = check_mesh(c, m, full, why);
            if (cache) {
                *cache = full;
                full = NULL;
            }
        }
    }
    if (bad) {
        describe(c, what, sizeof what);
        print_error("%s\n  -> %s%s%s\n", what, bad, refusal && refusal[0] ? "; expected " : "",
                    refusal ? refusal : "");
    }
    analysis_mesh_destroy(m);
    analysis_mesh_destroy(full);
    if (bad)
        fail();
}

/* Collinear lattice points, decided exactly on their integer lattice coordinates. */
static int collinear(const int *ix, const int *iy, size_t n)
{
    for (size_t i = 2; i < n; i++)
        if ((ix[1] - ix[0]) * (iy[i] - iy[0]) != (ix[i] - ix[0]) * (iy[1] - iy[0]))
            return 0;
    return 1;
}

/* Radius choices for n points: none (half the median edge), all equal at thresholds that
 * coincide with the lattice's unit edges and diagonals from below and above, and unequal. */
enum { NRADII = 6 };
static const int ALL_RADII[NRADII] = {0, 1, 2, 3, 4, 5};
static void set_radii(pcase *c, int choice, double h)
{
    static const double equal[] = {0, 0.25, 1.0 / 3, 0.3, 0.5, 0};
    c->has_r = choice != 0;
    for (size_t i = 0; i < c->n; i++)
        c->r[i] = h * (choice == 5 ? 0.2 + 0.15 * (double)((i * 7) % 3) : equal[choice]);
}

/* Every subset of 3..8 points of an nx x ny lattice of spacing h at (x0, y0), every radius
 * choice, alpha 1.5 and 1: collinear subsets must be refused, all others must give a mesh. */
static void lattice_subsets(int nx, int ny, double h, double x0, double y0, const int *radii,
                            int nradii, int nalpha, tally *tl)
{
    int np = nx * ny;
    for (unsigned mask = 0; mask < (1u << np); mask++) {
        int bits = __builtin_popcount(mask);
        if (bits < 3 || bits > 8)
            continue;
        pcase c = {0};
        int ix[NMAX], iy[NMAX];
        for (int p = 0; p < np; p++)
            if (mask & (1u << p)) {
                ix[c.n] = p % nx;
                iy[c.n] = p / nx;
                c.x[c.n] = x0 + h * ix[c.n];
                c.y[c.n] = y0 + h * iy[c.n];
                c.n++;
            }
        int col = collinear(ix, iy, c.n);
        analysis_mesh *full = NULL;
        for (int rc = 0; rc < nradii; rc++) {
            set_radii(&c, radii[rc], h);
            for (int a = 0; a < nalpha; a++) {
                c.alpha = a ? 1.0 : 1.5;
                snprintf(c.label, sizeof c.label, "%dx%d lattice subset %#x, radii %d", nx, ny,
                         mask, rc);
                run_case(&c, col ? "collinear" : NULL, &full, tl);
                if (col)
                    break;
            }
            if (col)
                break;
        }
        analysis_mesh_destroy(full);
    }
}

static void test_lattice_3x3(void **state)
{
    (void)state;
    tally tl = {0};
    lattice_subsets(3, 3, 1, 0, 0, ALL_RADII, NRADII, 2, &tl);
    print_message("3x3 lattice: %ld cases, %ld meshes (%ld triangles peeled), %ld refused\n",
                  tl.cases, tl.valid, tl.peeled, tl.refused);
    assert_true(tl.valid > 3000 && tl.peeled > 1000);
}

/* The same subsets at grain scale, away from the origin: coordinates no longer exact. */
static void test_lattice_3x3_scaled(void **state)
{
    (void)state;
    tally tl = {0};
    lattice_subsets(3, 3, 1.3e-3, 0.0517, 0.0213, ALL_RADII, NRADII, 2, &tl);
    print_message("3x3 lattice at 1.3 mm: %ld cases, %ld meshes (%ld peeled), %ld refused\n",
                  tl.cases, tl.valid, tl.peeled, tl.refused);
    assert_true(tl.valid > 3000 && tl.peeled > 1000);
}

static void test_lattice_4x3(void **state)
{
    (void)state;
    tally tl = {0};
    /* 3718 subsets: two radius choices (unit edges long; unequal radii) and alpha 1.5 keep it
     * quick under ASan */
    static const int radii[] = {3, 5};
    lattice_subsets(4, 3, 1, 0, 0, radii, 2, 1, &tl);
    print_message("4x3 lattice: %ld cases, %ld meshes (%ld peeled), %ld refused\n", tl.cases,
                  tl.valid, tl.peeled, tl.refused);
    assert_true(tl.valid > 7000 && tl.peeled > 2000);
}

/* Regular k-gons (cocircular: qhull's degenerate case), with and without the centre, rotated,
 * at two scales, with equal radii just below, at and above the thresholds of the side and of
 * the centre's spokes. */
static void test_polygons(void **state)
{
    (void)state;
    tally tl = {0};
    for (int k = 3; k <= 12; k++)
        for (int centre = 0; centre < 2; centre++)
            for (int scale = 0; scale < 2; scale++)
                for (int rot = 0; rot < 3; rot++) {
                    double R = scale ? 2.7e-3 : 1, ox = scale ? 0.0131 : 0, oy = scale ? -0.27 : 0;
                    double side = 2 * R * sin(PI / k);
                    const double fr[] = {0, side / 3, side / 2.9, side / 3.1, R / 3, R / 2.9};
                    for (int rc = 0; rc < 6; rc++) {
                        pcase c = {0};
                        for (int i = 0; i < k; i++) {
                            double th = 2 * PI * i / k + rot * 0.37;
                            c.x[c.n] = ox + R * cos(th);
                            c.y[c.n] = oy + R * sin(th);
                            c.n++;
                        }
                        if (centre) {
                            c.x[c.n] = ox;
                            c.y[c.n] = oy;
                            c.n++;
                        }
                        c.has_r = rc != 0;
                        for (size_t i = 0; i < c.n; i++)
                            c.r[i] = fr[rc];
                        c.alpha = 1.5;
                        snprintf(c.label, sizeof c.label,
                                 "%d-gon%s, scale %d, rotation %d, "
                                 "radii %d",
                                 k, centre ? " and centre" : "", scale, rot, rc);
                        run_case(&c, NULL, NULL, &tl);
                    }
                }
    print_message("polygons: %ld cases, %ld meshes (%ld peeled), %ld refused\n", tl.cases, tl.valid,
                  tl.peeled, tl.refused);
    assert_int_equal(tl.refused, 0);
    assert_true(tl.peeled > 0);
}

/* A square and its centre, radii 0.3 (the square's sides are long: 1 > 0.9).
 * One side triangle is peeled, then the centre is on the boundary and nothing else goes. */
static void test_square_centre(void **state)
{
    (void)state;
    pcase c = {.label = "square and centre",
               .n = 5,
               .x = {0, 1, 0, 1, 0.5},
               .y = {0, 0, 1, 1, 0.5},
               .r = {0.3, 0.3, 0.3, 0.3, 0.3},
               .has_r = 1,
               .alpha = 1.5};
    tally tl = {0};
    run_case(&c, NULL, NULL, &tl);
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.radius = c.r;
    analysis_mesh *m = NULL;
    core_error err;
    assert_int_equal(analysis_delaunay(c.x, c.y, c.n, &def, &m, &err), CORE_OK);
    assert_int_equal(m->ndelaunay, 4);
    assert_int_equal(m->npeeled, 1);
    assert_int_equal(m->nloop, 5);
    assert_true(fabs(m->area - 0.75) < 1e-15);
    analysis_mesh_destroy(m);
}

/* Grains in a row along a wall, collinear up to rounding (tilted rows, centres off the line by
 * a few ulps), with one to three grains above: qhull's flat slivers on the outline. Every cell
 * kept must have a usable area, whatever alpha. */
static void test_rows(void **state)
{
    (void)state;
    tally tl = {0};
    const double tilt[] = {0, 0.3, 1.1, -0.7};
    for (int k = 3; k <= 8; k++)
        for (int t = 0; t < 4; t++)
            for (int jitter = 0; jitter < 4; jitter++)
                for (int above = 1; above <= 3; above++)
                    for (int rc = 0; rc < 2; rc++)
                        for (int a = 0; a < 2; a++) {
                            pcase c = {0};
                            double h = 1.1e-3, ux = cos(tilt[t]), uy = sin(tilt[t]);
                            for (int i = 0; i < k; i++) {
                                /* off the line by 0, +-1, +-2 ulps of the coordinates */
                                double off = jitter * 1.2e-19 * (double)((i * 7 + jitter) % 5 - 2);
                                c.x[c.n] = 0.0371 + h * i * ux - off * uy;
                                c.y[c.n] = 0.0113 + h * i * uy + off * ux;
                                c.n++;
                            }
                            for (int j = 0; j < above; j++) { /* nestled on the row */
                                double s = h * (0.5 + 1.7 * j), n = h * (0.866 + 0.1 * j);
                                c.x[c.n] = 0.0371 + s * ux - n * uy;
                                c.y[c.n] = 0.0113 + s * uy + n * ux;
                                c.n++;
                            }
                            c.has_r = rc;
                            for (size_t i = 0; i < c.n; i++)
                                c.r[i] = h / 2;
                            c.alpha = a ? 1.5 : 0;
                            snprintf(c.label, sizeof c.label,
                                     "row of %d, tilt %g, jitter %d, "
                                     "%d above, radii %d",
                                     k, tilt[t], jitter, above, rc);
                            run_case(&c, NULL, NULL, &tl);
                        }
    print_message("rows: %ld cases, %ld meshes (%ld peeled), %ld refused\n", tl.cases, tl.valid,
                  tl.peeled, tl.refused);
    assert_int_equal(tl.refused, 0);
}

/* Refusals: collinear sets of every size and direction, duplicates, all at one point, too
 * few points, bad radii. */
static void test_refusals(void **state)
{
    (void)state;
    tally tl = {0};
    for (int n = 3; n <= 8; n++)
        for (int dir = 0; dir < 4; dir++) {
            pcase c = {0};
            const double dx[] = {1, 0, 1, 0.3}, dy[] = {0, 1, 1, -0.7};
            for (int i = 0; i < n; i++) {
                double s = i * i * 0.25 + i; /* uneven spacing */
                c.x[i] = 0.5 + dx[dir] * s;
                c.y[i] = -2 + dy[dir] * s;
            }
            c.n = (size_t)n;
            c.alpha = 1.5;
            snprintf(c.label, sizeof c.label, "%d collinear, direction %d", n, dir);
            run_case(&c, "collinear", NULL, &tl);
            /* A point off the line makes it triangulable. */
            c.x[n] = c.x[n - 1] + 0.01;
            c.y[n] = c.y[n - 1] + 0.02;
            c.n++;
            run_case(&c, NULL, NULL, &tl);
        }
    /* Duplicates in every lattice set of 3..7 points of the 3x3 lattice with a copy of one of
     * them appended (or inserted first): named by both particles. */
    for (unsigned mask = 0; mask < 512; mask += 7) {
        int bits = __builtin_popcount(mask);
        if (bits < 3 || bits > 7)
            continue;
        pcase c = {0};
        int ix[NMAX], iy[NMAX];
        for (int p = 0; p < 9; p++)
            if (mask & (1u << p)) {
                c.x[c.n] = ix[c.n] = p % 3;
                c.y[c.n] = iy[c.n] = p / 3;
                c.n++;
            }
        if (collinear(ix, iy, c.n))
            continue; /* refused as collinear first */
        c.x[c.n] = c.x[1];
        c.y[c.n] = c.y[1];
        char want[64];
        snprintf(want, sizeof want, "particles 2 and %zu have the same position", c.n + 1);
        c.n++;
        c.alpha = 1.5;
        snprintf(c.label, sizeof c.label, "lattice %#x with particle 2 twice", mask);
        run_case(&c, want, NULL, &tl);
    }
    pcase same = {
        .label = "all at one point", .n = 4, .x = {1, 1, 1, 1}, .y = {2, 2, 2, 2}, .alpha = 1.5};
    run_case(&same, "same position", NULL, &tl);
    pcase two = {.label = "two", .n = 2, .x = {0, 1}, .y = {0, 1}, .alpha = 1.5};
    run_case(&two, "at least 3 particles, got 2", NULL, &tl);
    pcase rad = {.label = "bad radius",
                 .n = 3,
                 .x = {0, 1, 0},
                 .y = {0, 0, 1},
                 .r = {0.5, 0, 0.5},
                 .has_r = 1,
                 .alpha = 1.5};
    run_case(&rad, "particle 2 has radius 0", NULL, &tl);
    rad.r[1] = NAN;
    run_case(&rad, "particle 2 has radius nan", NULL, &tl);
    rad.r[1] = -1;
    run_case(&rad, "particle 2 has radius -1", NULL, &tl);
    rad.r[1] = INFINITY;
    run_case(&rad, "particle 2 has radius inf", NULL, &tl);
    /* Nearly coincident at 1e-15 of the size: refused or kept, but clean either way. */
    pcase near = {.label = "near twin",
                  .n = 5,
                  .x = {0, 1, 0, 1, 1 + 1e-15},
                  .y = {0, 0, 1, 1, 1},
                  .alpha = 1.5};
    run_case(&near, "", NULL, &tl);
    print_message("refusals: %ld cases, %ld refused\n", tl.cases, tl.refused);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_square_centre),      cmocka_unit_test(test_lattice_3x3),
        cmocka_unit_test(test_lattice_3x3_scaled), cmocka_unit_test(test_lattice_4x3),
        cmocka_unit_test(test_polygons),           cmocka_unit_test(test_rows),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
