/* The DEM boundary kernel without Lua (src/dem/boundary.c): on a ring of free disks with a
 * closed edge loop, the coarse velocity gradient (Eq. 3.2) of an affine velocity field is exact,
 * the minimal-boundary penalty forces sum to zero, one step moves the coarse strain rate towards
 * the target, and bad definitions are refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>

#include "dem/dem.h"

enum { N = 24 };
static const double PI = 3.14159265358979323846;

static dem_scene *ring(const double L[4])
{
    dem_scene_def def = dem_default_scene_def();
    def.dim = 2;
    def.lo[0] = def.lo[1] = -1;
    def.hi[0] = def.hi[1] = 1;
    def.gravity[0] = def.gravity[1] = 0;
    def.thickness = 0.01;
    dem_scene *s = NULL;
    core_error err;
    assert_int_equal(dem_create(&def, &s, &err), CORE_OK);
    dem_material m = dem_default_material();
    assert_true(dem_add_material(s, &m, &err) >= 0);
    for (int k = 0; k < N; k++) { /* an irregular ring, radius ~0.3, disks far apart */
        double th = 2 * PI * k / N, R = 0.3 + 0.02 * sin(3 * th);
        dem_particle_def p;
        memset(&p, 0, sizeof p);
        p.x[0] = R * cos(th);
        p.x[1] = R * sin(th);
        p.v[0] = L[0] * p.x[0] + L[1] * p.x[1] + 0.01; /* plus a translation */
        p.v[1] = L[2] * p.x[0] + L[3] * p.x[1] - 0.02;
        p.radius = 0.01;
        assert_true(dem_add_particle(s, &p, &err) >= 0);
    }
    long a[N], b[N];
    for (int k = 0; k < N; k++) {
        a[k] = k;
        b[k] = (k + 1) % N;
    }
    assert_int_equal(dem_set_boundary_edges(s, N, a, b, NULL, 1, &err), CORE_OK);
    return s;
}

static void test_coarse_gradient_and_penalty(void **state)
{
    (void)state;
    const double L[4] = {0.3, -0.7, 0.4, -0.2};
    dem_scene *s = ring(L);
    core_error err;
    dem_boundary_def def = dem_default_boundary_def();
    def.depth = 0.01;
    def.penalty = 1e-3;
    def.target[0] = 0.1; /* strain rate target: pure shear 0.1 */
    def.target[3] = -0.1;
    assert_int_equal(dem_set_boundary(s, &def, &err), CORE_OK);
    dem_boundary_info bi;
    assert_int_equal(dem_boundary_info_get(s, &bi, &err), CORE_OK);
    assert_true(bi.closed && bi.edges == N && bi.nodes == N && bi.area > 0.25);
    for (int q = 0; q < 4; q++)
        assert_true(fabs(bi.grad[q] - L[q]) < 1e-12); /* exact for an affine field */
    double e0 = fabs(bi.strain_rate[0] - 0.1) + fabs(bi.strain_rate[3] + 0.1) +
                2 * fabs(bi.strain_rate[1]);
    dem_run_def run = dem_default_run_def();
    run.steps = 1;
    run.dt = 1e-6;
    assert_int_equal(dem_run(s, &run, &err), CORE_OK);
    assert_int_equal(dem_boundary_info_get(s, &bi, &err), CORE_OK);
    print_message("penalty: max %.3g N, net (%.2e, %.2e) N\n", bi.penalty_max, bi.penalty_sum[0],
                  bi.penalty_sum[1]);
    assert_true(bi.penalty_max > 0);
    assert_true(fabs(bi.penalty_sum[0]) < 1e-13 * bi.penalty_max * N);
    assert_true(fabs(bi.penalty_sum[1]) < 1e-13 * bi.penalty_max * N);
    double e1 = fabs(bi.strain_rate[0] - 0.1) + fabs(bi.strain_rate[3] + 0.1) +
                2 * fabs(bi.strain_rate[1]);
    assert_true(e1 < e0); /* the penalty drives the rate towards the target */
    dem_destroy(s);
}

static void test_refusals(void **state)
{
    (void)state;
    const double L[4] = {0, 0, 0, 0};
    dem_scene *s = ring(L);
    core_error err;
    dem_boundary_def def = dem_default_boundary_def();
    def.depth = 0; /* no depth */
    assert_int_equal(dem_set_boundary(s, &def, &err), CORE_ERR_ARG);
    def.depth = 0.01;
    def.target[1] = 1; /* asymmetric strain rate */
    assert_int_equal(dem_set_boundary(s, &def, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "symmetric"));
    long a[2] = {0, 1}, b[2] = {1, 5};
    assert_int_equal(dem_set_boundary_edges(s, 2, a, b, NULL, 1, &err), CORE_ERR_ARG);
    long c[1] = {3}, d[1] = {3};
    assert_int_equal(dem_set_boundary_edges(s, 1, c, d, NULL, 0, &err), CORE_ERR_ARG);
    long i[1] = {0}, j[1] = {N};
    assert_int_equal(dem_add_springs(s, 1, i, j, 1e4, NULL, &err), CORE_ERR_ARG);
    assert_int_equal(dem_tie_to_wall(s, 0, 0, 1, &err), CORE_ERR_ARG); /* no wall */
    dem_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coarse_gradient_and_penalty),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
