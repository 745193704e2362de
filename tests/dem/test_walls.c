/* Walls beyond planes (src/dem/walls.c) through the public API, no Lua: the closest point on
 * segments, triangles and cylinders, and the one-force-per-feature rule. A particle touching a
 * wall by 5e-10 of its radius (placements that overlap more are refused) is listed by
 * dem_each_contact with the wall's hits; the counts, normals and contact points are checked
 * against their closed forms (1e-12). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "dem/dem.h"

#define DEM_TEST_PI 3.14159265358979323846

enum { MAXC = 16 };
typedef struct seen {
    int n;
    dem_contact_info c[MAXC];
} seen;

static void visit(const dem_contact_info *c, void *ctx)
{
    seen *s = ctx;
    if (c->j < 0 && s->n < MAXC)
        s->c[s->n++] = *c;
}

static dem_scene *scene(int dim)
{
    dem_scene_def def = dem_default_scene_def();
    def.dim = dim;
    for (int d = 0; d < 3; d++)
        def.lo[d] = -2, def.hi[d] = 2, def.gravity[d] = 0;
    dem_scene *s = NULL;
    core_error err;
    assert_int_equal(dem_create(&def, &s, &err), CORE_OK);
    dem_material m = dem_default_material();
    assert_true(dem_add_material(s, &m, &err) >= 0);
    return s;
}

/* The wall contacts of one particle at x (radius r) against the walls already in s. */
static seen touch(dem_scene *s, const double *x, double r)
{
    dem_particle_def p = {.radius = r, .material = 0};
    for (int d = 0; d < 3; d++)
        p.x[d] = x[d];
    core_error err;
    assert_true(dem_add_particle(s, &p, &err) >= 0);
    seen out = {0};
    dem_each_contact(s, visit, &out);
    return out;
}

static int polyline(dem_scene *s, const double (*pts)[3], size_t n, int closed)
{
    dem_shape_def d = dem_default_shape_def();
    d.kind = DEM_WALL_SEGMENTS;
    d.points = &pts[0][0];
    d.n = n;
    d.closed = closed;
    core_error err;
    int id = dem_add_shape_wall(s, &d, &err);
    if (id < 0)
        print_message("%s\n", err.msg);
    return id;
}

static const double EPS = 5e-10; /* overlap as a fraction of r: below the placement check */

static void test_segments(void **state)
{
    (void)state;
    const double r = 0.1;
    /* a straight polyline of two segments: over the shared vertex and near it, one contact
     * with the normal (0, 1) at the foot of the centre */
    const double flat[3][3] = {{-1, 0, 0}, {0, 0, 0}, {1, 0, 0}};
    const double xs[] = {0, 1e-12, -1e-12, 0.05, -0.05};
    for (size_t k = 0; k < sizeof xs / sizeof *xs; k++) {
        dem_scene *s = scene(2);
        assert_int_equal(polyline(s, flat, 3, 0), 0);
        const double x[3] = {xs[k], r * (1 - EPS), 0};
        seen c = touch(s, x, r);
        assert_int_equal(c.n, 1);
        assert_true(fabs(c.c[0].normal[0]) < 1e-12 && fabs(c.c[0].normal[1] - 1) < 1e-12);
        assert_true(fabs(c.c[0].point[0] - xs[k]) < 1e-12 && fabs(c.c[0].point[1]) < 1e-12);
        assert_true(fabs(c.c[0].overlap - r * EPS) < 1e-15);
        dem_destroy(s);
    }
    /* beyond a segment's end e = (1, 0): the normal runs from e through the centre */
    {
        dem_scene *s = scene(2);
        polyline(s, flat, 3, 0);
        const double a = 0.7, x[3] = {1 + r * (1 - EPS) * cos(a), r * (1 - EPS) * sin(a), 0};
        seen c = touch(s, x, r);
        assert_int_equal(c.n, 1);
        assert_true(fabs(c.c[0].normal[0] - cos(a)) < 1e-12);
        assert_true(fabs(c.c[0].normal[1] - sin(a)) < 1e-12);
        assert_true(fabs(c.c[0].point[0] - 1) < 1e-15 && fabs(c.c[0].point[1]) < 1e-15);
        dem_destroy(s);
    }
    /* a convex corner (the polyline bends down): over the vertex, between the two faces'
     * normals, one contact at the vertex */
    {
        dem_scene *s = scene(2);
        const double bend[3][3] = {{-1, 0, 0}, {0, 0, 0}, {1, -1, 0}};
        polyline(s, bend, 3, 0);
        const double a = 1.2, x[3] = {r * (1 - EPS) * cos(a), r * (1 - EPS) * sin(a), 0};
        seen c = touch(s, x, r);
        assert_int_equal(c.n, 1);
        assert_true(fabs(c.c[0].point[0]) < 1e-15 && fabs(c.c[0].point[1]) < 1e-15);
        dem_destroy(s);
    }
    /* a concave corner: two faces, two contacts, normals along the faces' */
    {
        dem_scene *s = scene(2);
        const double vee[3][3] = {{-1, 1, 0}, {0, 0, 0}, {1, 1, 0}};
        polyline(s, vee, 3, 0);
        const double x[3] = {0, r * sqrt(2) * (1 - EPS), 0};
        seen c = touch(s, x, r);
        assert_int_equal(c.n, 2);
        for (int k = 0; k < 2; k++)
            assert_true(fabs(fabs(c.c[k].normal[0]) - sqrt(0.5)) < 1e-9 &&
                        fabs(c.c[k].normal[1] - sqrt(0.5)) < 1e-9);
        assert_true(c.c[0].normal[0] * c.c[1].normal[0] < 0);
        dem_destroy(s);
    }
    /* refusals: a segment of no length, a closed polyline of 2 points */
    {
        dem_scene *s = scene(2);
        const double dup[3][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}};
        assert_true(polyline(s, dup, 3, 0) < 0);
        assert_true(polyline(s, flat, 2, 1) < 0);
        dem_destroy(s);
    }
}

static void test_triangles(void **state)
{
    (void)state;
    const double r = 0.1;
    /* a hexagonal fan of six triangles around the origin, and a sphere over the centre vertex,
     * over a shared edge, over a face: one contact each, normal (0, 0, 1) */
    double tri[6][3][3];
    for (int k = 0; k < 6; k++) {
        const double a0 = k * DEM_TEST_PI / 3, a1 = ((k + 1) % 6) * DEM_TEST_PI / 3;
        const double c[3][3] = {{0, 0, 0}, {cos(a0), sin(a0), 0}, {cos(a1), sin(a1), 0}};
        for (int m = 0; m < 3; m++)
            for (int d = 0; d < 3; d++)
                tri[k][m][d] = c[m][d];
    }
    /* the fan's shared edges end on the rim at angles k pi / 3 (cos and sin of the same double
     * in both triangles, so the corners are shared) */
    const double spots[][2] = {{0, 0}, {0.3, 0}, {0.15, 0.15 * tan(DEM_TEST_PI / 3)}, {0.3, 0.1}};
    for (size_t k = 0; k < sizeof spots / sizeof *spots; k++) {
        dem_scene *s = scene(3);
        dem_shape_def d = dem_default_shape_def();
        d.kind = DEM_WALL_TRIANGLES;
        d.points = &tri[0][0][0];
        d.n = 6;
        core_error err;
        assert_int_equal(dem_add_shape_wall(s, &d, &err), 0);
        const double x[3] = {spots[k][0], spots[k][1], r * (1 - EPS)};
        seen c = touch(s, x, r);
        print_message("fan, spot %zu: %d contact(s)\n", k, c.n);
        assert_int_equal(c.n, 1);
        assert_true(fabs(c.c[0].normal[2] - 1) < 1e-12);
        assert_true(fabs(c.c[0].point[0] - x[0]) < 1e-12 && fabs(c.c[0].point[2]) < 1e-15);
        dem_destroy(s);
    }
    /* a repeated triangle would push twice: refused; triangles in 2D: refused */
    dem_scene *s = scene(3);
    dem_shape_def d = dem_default_shape_def();
    d.kind = DEM_WALL_TRIANGLES;
    double two[2][3][3];
    for (int m = 0; m < 3; m++)
        for (int q = 0; q < 3; q++)
            two[0][m][q] = two[1][2 - m][q] = tri[0][m][q];
    d.points = &two[0][0][0];
    d.n = 2;
    core_error err;
    assert_true(dem_add_shape_wall(s, &d, &err) < 0);
    print_message("%s\n", err.msg);
    dem_destroy(s);
    s = scene(2);
    d.n = 1;
    assert_true(dem_add_shape_wall(s, &d, &err) < 0);
    dem_destroy(s);
}

static void test_cylinders(void **state)
{
    (void)state;
    const double r = 0.1, R = 0.5;
    core_error err;
    /* inside a circle: the normal points to the centre; outside: away from it */
    for (int inside = 0; inside < 2; inside++) {
        dem_scene *s = scene(2);
        dem_shape_def d = dem_default_shape_def();
        d.kind = DEM_WALL_CYLINDER;
        d.radius = R;
        d.inside = inside;
        d.center[0] = 0.2, d.center[1] = -0.1;
        assert_int_equal(dem_add_shape_wall(s, &d, &err), 0);
        const double a = 2.1, l = inside ? R - r * (1 - EPS) : R + r * (1 - EPS);
        const double x[3] = {0.2 + l * cos(a), -0.1 + l * sin(a), 0};
        seen c = touch(s, x, r);
        assert_int_equal(c.n, 1);
        const double sg = inside ? -1 : 1;
        assert_true(fabs(c.c[0].normal[0] - sg * cos(a)) < 1e-12);
        assert_true(fabs(c.c[0].normal[1] - sg * sin(a)) < 1e-12);
        assert_true(fabs(c.c[0].point[0] - (0.2 + R * cos(a))) < 1e-12);
        dem_destroy(s);
    }
    /* a finite 3D cylinder along (1, 1, 0)/sqrt 2, length 1: radial on the side, the rim past
     * the end */
    dem_scene *s = scene(3);
    dem_shape_def d = dem_default_shape_def();
    d.kind = DEM_WALL_CYLINDER;
    d.radius = R;
    d.inside = 0;
    d.axis[0] = d.axis[1] = 1;
    d.length = 1;
    assert_int_equal(dem_add_shape_wall(s, &d, &err), 0);
    const double q = sqrt(0.5);
    const double x[3] = {0.2 * q, 0.2 * q, R + r * (1 - EPS)}; /* over the side, 0.2 along */
    seen c = touch(s, x, r);
    assert_int_equal(c.n, 1);
    assert_true(fabs(c.c[0].normal[2] - 1) < 1e-12);
    dem_destroy(s);
    s = scene(3);
    assert_int_equal(dem_add_shape_wall(s, &d, &err), 0);
    const double e[3] = {0.5 * q, 0.5 * q, R}; /* a rim point */
    const double y[3] = {e[0] + 0.6 * r * q, e[1] + 0.6 * r * q, e[2] + 0.8 * r * (1 - EPS)};
    c = touch(s, y, r);
    assert_int_equal(c.n, 1);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(c.c[0].point[k] - e[k]) < 1e-12);
    assert_true(fabs(c.c[0].normal[2] - 0.8) < 1e-9);
    dem_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_segments),
                                       cmocka_unit_test(test_triangles),
                                       cmocka_unit_test(test_cylinders)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
