/* Delaunay-cell kernels without Lua: an affine displacement gives exactly that strain in every
 * cell and in the boundary integral (Eq. 3.1); the alpha rule keeps one simple loop; degenerate
 * input is refused with a clear message; Christoffersen's stress of a loaded pair. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "analysis/analysis.h"
#include "core/rng.h"

/* n disks placed by random sequential addition (no overlaps) in a circle or a square. */
static size_t random_assembly(size_t n, int circle, double *x, double *y, double *r)
{
    rng g;
    rng_seed(&g, 7, 0);
    size_t k = 0;
    for (long tries = 0; k < n && tries < 1000000; tries++) {
        double px = rng_uniform(&g) * 2 - 1, py = rng_uniform(&g) * 2 - 1;
        double pr = 0.02 + 0.02 * rng_uniform(&g);
        if (circle && px * px + py * py > 1)
            continue;
        int ok = 1;
        for (size_t q = 0; q < k && ok; q++)
            ok = hypot(px - x[q], py - y[q]) >= pr + r[q];
        if (ok) {
            x[k] = px;
            y[k] = py;
            r[k] = pr;
            k++;
        }
    }
    return k;
}

static void test_affine_exact(void **state)
{
    (void)state;
    enum { N = 600 };
    static double x[N], y[N], r[N], ux[N], uy[N], xs[N], ys[N];
    for (int shape = 0; shape < 2; shape++) {
        size_t n = random_assembly(N, shape, x, y, r);
        assert_int_equal(n, N);
        analysis_delaunay_def def = analysis_default_delaunay_def();
        def.radius = r;
        analysis_mesh *m = NULL;
        core_error err;
        assert_int_equal(analysis_delaunay(x, y, n, &def, &m, &err), CORE_OK);
        assert_true(m->ncells > n); /* about 2n triangles */
        assert_true(m->nloop > 20);
        /* Every particle on the loop at most once; the loop is counter-clockwise. */
        double area = 0;
        for (size_t k = 0; k < m->nloop; k++) {
            long a = m->loop[k], b = m->loop[(k + 1) % m->nloop];
            area += 0.5 * (x[a] * y[b] - x[b] * y[a]);
        }
        assert_true(fabs(area - m->area) <= 1e-12 * m->area);
        const double G[4] = {0.013, -0.021, 0.007, -0.034}; /* a general gradient */
        for (size_t i = 0; i < n; i++) {
            ux[i] = G[0] * (x[i] - 0.3) + G[1] * (y[i] + 0.1) + 1e-3; /* plus a translation */
            uy[i] = G[2] * (x[i] - 0.3) + G[3] * (y[i] + 0.1) - 2e-3;
        }
        double *grad = malloc(4 * m->ncells * sizeof *grad);
        assert_non_null(grad);
        assert_int_equal(analysis_cell_gradients(m, x, y, ux, uy, grad, &err), CORE_OK);
        double worst = 0;
        for (size_t c = 0; c < m->ncells; c++)
            for (int q = 0; q < 4; q++)
                worst = fmax(worst, fabs(grad[4 * c + q] - G[q]));
        print_message("affine %s: %zu cells, %zu peeled, loop %zu, worst |grad - G| = %.3g\n",
                      shape ? "circle" : "square", m->ncells, m->npeeled, m->nloop, worst);
        assert_true(worst <= 1e-12);
        double H[4], V, mean[4];
        analysis_boundary_gradient(m, x, y, ux, uy, H, &V);
        analysis_mean_tensor(m, x, y, grad, mean);
        for (int q = 0; q < 4; q++) {
            assert_true(fabs(H[q] - G[q]) <= 1e-12);
            assert_true(fabs(mean[q] - H[q]) <= 1e-12);
        }
        /* The same in the deformed configuration: velocities L x over current positions. */
        for (size_t i = 0; i < n; i++) {
            xs[i] = x[i] + ux[i];
            ys[i] = y[i] + uy[i];
        }
        assert_int_equal(analysis_cell_gradients(m, xs, ys, ux, uy, grad, &err), CORE_OK);
        analysis_boundary_gradient(m, xs, ys, ux, uy, H, &V);
        analysis_mean_tensor(m, xs, ys, grad, mean);
        /* u = G (X - c) + t; in terms of x = X + u: u = G (I + G)^-1 (x - ...) : a constant
         * gradient again, the same in every cell and on the boundary. */
        for (size_t c = 1; c < m->ncells; c++)
            for (int q = 0; q < 4; q++)
                assert_true(fabs(grad[4 * c + q] - grad[q]) <= 1e-12);
        for (int q = 0; q < 4; q++)
            assert_true(fabs(H[q] - grad[q]) <= 1e-12 && fabs(mean[q] - H[q]) <= 1e-12);
        double e[4];
        analysis_sym(G, e);
        assert_true(e[1] == e[2] && fabs(e[1] - (-0.007)) < 1e-15);
        free(grad);
        analysis_mesh_destroy(m);
    }
}

static void test_lii(void **state)
{
    (void)state;
    const double iso[4] = {2, 0, 0, 2}, shear[4] = {0, 1, 0, 0}, spin[4] = {0, 1, -1, 0};
    assert_true(fabs(analysis_lii(iso)) < 1e-15);           /* no distortion */
    assert_true(fabs(analysis_lii(shear) - sqrt(0.5)) < 1e-15);
    assert_true(fabs(analysis_lii(spin) - 1) < 1e-15);
}

/* Alpha rule: a notch in a lattice is followed, a far outlier is cut loose to the hull only
 * through long edges that get peeled. */
static void test_alpha_notch(void **state)
{
    (void)state;
    double x[200], y[200], r[200];
    size_t n = 0;
    for (int j = 0; j < 10; j++)
        for (int i = 0; i < 12; i++) {
            if (j >= 5 && i >= 4 && i <= 7)
                continue; /* a notch from the top, 4 disks wide and 5 deep */
            x[n] = i + 0.5 * (j % 2) + 1e-3 * ((i * 7 + j * 3) % 5);
            y[n] = j * 0.8660254 + 1e-3 * ((i * 3 + j * 5) % 7);
            r[n] = 0.5;
            n++;
        }
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.radius = r;
    analysis_mesh *m = NULL, *hull = NULL;
    core_error err;
    assert_int_equal(analysis_delaunay(x, y, n, &def, &m, &err), CORE_OK);
    def.alpha = 0;
    assert_int_equal(analysis_delaunay(x, y, n, &def, &hull, &err), CORE_OK);
    /* Three centres of the left side, (0, 0), (0.001, 1.73505) and (0.002, 3.4701), are exactly
     * collinear: qhull's zero-area triangle on them is peeled even at alpha = 0. */
    assert_int_equal(hull->npeeled, 1);
    double ha[400];
    analysis_cell_areas(hull, x, y, ha);
    double amin = INFINITY;
    for (size_t c = 0; c < hull->ncells; c++)
        amin = fmin(amin, ha[c]);
    assert_true(amin > 1e-9); /* the thinnest hull sliver left is a real one (jitter 1e-3) */
    assert_true(m->npeeled > 10);
    assert_true(m->area < hull->area - 10); /* the notch (~4 x 4.3) is not in the mesh */
    /* No boundary edge longer than alpha (r_a + r_b) = 1.5. */
    for (size_t k = 0; k < m->nloop; k++) {
        long a = m->loop[k], b = m->loop[(k + 1) % m->nloop];
        assert_true(hypot(x[b] - x[a], y[b] - y[a]) <= 1.5 + 1e-9);
    }
    print_message("notch: hull area %.3f, alpha-shape area %.3f, %zu peeled, loop %zu, "
                  "smallest hull cell %.3g\n", hull->area, m->area, m->npeeled, m->nloop, amin);
    analysis_mesh_destroy(m);
    analysis_mesh_destroy(hull);
}

static void expect_error(const double *x, const double *y, size_t n, const char *text)
{
    analysis_mesh *m = NULL;
    core_error err;
    core_error_clear(&err);
    assert_int_equal(analysis_delaunay(x, y, n, NULL, &m, &err), CORE_ERR_ARG);
    assert_null(m);
    print_message("refused: %s\n", err.msg);
    assert_non_null(strstr(err.msg, text));
}

static void test_degenerate(void **state)
{
    (void)state;
    double x[5] = {0, 1, 2, 3, 4}, y[5] = {0, 1, 2, 3, 4};
    expect_error(x, y, 5, "collinear");
    expect_error(x, y, 2, "at least 3 particles, got 2");
    expect_error(x, y, 0, "at least 3 particles, got 0");
    double xd[4] = {0, 1, 0, 1}, yd[4] = {0, 0, 1, 0};
    expect_error(xd, yd, 4, "particles 2 and 4 have the same position");
    double xn[4] = {0, 1, 0, NAN}, yn[4] = {0, 0, 1, 1};
    expect_error(xn, yn, 4, "particle 4 has a non-finite position");
    /* Nearly coincident (1e-15 apart at unit scale): qhull keeps one of them only. */
    double xc[4] = {0, 1, 0, 1 + 1e-15}, yc[4] = {0, 0, 1, 0};
    expect_error(xc, yc, 4, "nearly coincides");
    /* A bad alpha. */
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.alpha = -1;
    analysis_mesh *m = NULL;
    core_error err;
    assert_int_equal(analysis_delaunay(xd, yd, 3, &def, &m, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "alpha"));
}

/* Christoffersen: two disks pressed together by F along x, the outer faces loaded by walls:
 * each particle's stress is F 2r / V_p on xx only, and positive (compression). */
static void test_stress_pair(void **state)
{
    (void)state;
    double x[3] = {0, 2, 1}, y[3] = {0, 0, 1.7320508075688772}, depth = 0.5, F = 3;
    analysis_mesh *m = NULL;
    core_error err;
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.alpha = 0;
    assert_int_equal(analysis_delaunay(x, y, 3, &def, &m, &err), CORE_OK);
    long ci[3] = {0, 0, 1}, cj[3] = {1, -1, -1};
    double px[3] = {1, -1, 3}, py[3] = {0, 0, 0}, fx[3] = {-F, F, -F}, fy[3] = {0, 0, 0};
    analysis_contacts c = {3, ci, cj, px, py, fx, fy};
    double ps[12], vol[3], cell[4];
    assert_int_equal(analysis_particle_stress(m, x, y, &c, depth, ps, vol, &err), CORE_OK);
    double A = 0.5 * 2 * 1.7320508075688772;
    assert_true(fabs(vol[0] - depth * A / 3) < 1e-15);
    assert_true(fabs(ps[0] - 2 * F / vol[0]) < 1e-12 && fabs(ps[4] - 2 * F / vol[1]) < 1e-12);
    assert_true(ps[1] == 0 && ps[2] == 0 && ps[3] == 0 && ps[8] == 0);
    analysis_cell_stress(m, ps, cell);
    assert_true(fabs(cell[0] - 4 * F / (3 * vol[0])) < 1e-12);
    assert_int_equal(analysis_particle_stress(m, x, y, &c, 0, ps, vol, &err), CORE_ERR_ARG);
    analysis_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_affine_exact),
        cmocka_unit_test(test_lii),
        cmocka_unit_test(test_alpha_notch),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_stress_pair),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
