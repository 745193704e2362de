/* MPM kernels without Lua: the single-point constitutive update against closed forms (Hencky
 * uniaxial strain, von Mises yield and hardening slope, rigid rotation), the scene's refusals
 * of bad input, and a continuation after mpm_hydrostatic on a scene that has run. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "mpm/mpm.h"

/* Drives one point through uniaxial strain (stretch along x, none along y and z) in `steps` equal
 * multiplicative increments up to log strain eps; returns q = sqrt(3/2)|dev tau| and the mean
 * Kirchhoff stress. */
static void uniaxial(const mpm_material *m, double eps, int steps, double *q, double *p,
                     double *eps_p)
{
    double be[4] = {1, 0, 1, 1}, sig[4] = {0, 0, 0, 0};
    double lam = exp(eps / steps), J = 1;
    *eps_p = 0;
    for (int k = 0; k < steps; k++) {
        double f[4] = {lam, 0, 0, 1};
        J *= lam;
        assert_true(mpm_material_update(m, f, be, eps_p, J, sig));
    }
    double tau[3] = {sig[0] * J, sig[1] * J, sig[3] * J};
    assert_true(fabs(sig[2]) < 1e-9 * fabs(sig[0]));
    double mean = (tau[0] + tau[1] + tau[2]) / 3, s2 = 0;
    for (int i = 0; i < 3; i++)
        s2 += (tau[i] - mean) * (tau[i] - mean);
    *q = sqrt(1.5 * s2);
    *p = mean;
}

/* Hencky in uniaxial strain: q = 2 G eps, mean stress K eps (exact in log strain). */
static void test_elastic_uniaxial(void **state)
{
    (void)state;
    mpm_material m = mpm_default_material();
    double q, p, ep;
    uniaxial(&m, 0.1, 37, &q, &p, &ep);
    assert_true(fabs(q - 2 * m.shear * 0.1) < 1e-9 * q);
    assert_true(fabs(p - m.bulk * 0.1) < 1e-9 * fabs(p));
    assert_true(ep == 0);
}

/* von Mises (HMX of the paper's shear test): elastic up to q = yield at eps = yield / (2G), then
 * q = yield + H eps_p with eps_p = (2 G eps - yield) / (3 G + H), i.e. the hardening slope
 * dq/deps = 2 G H / (3 G + H); the pressure stays K eps (plastic flow is isochoric). */
static void test_vonmises_uniaxial(void **state)
{
    (void)state;
    mpm_material m = {.model = MPM_VONMISES, .density = 1900, .shear = 7.5e9, .bulk = 11.4e9,
                      .yield = 0.3e9, .hardening = 0.01e9};
    const double G = m.shear, H = m.hardening, Y = m.yield, K = m.bulk;
    double q, p, ep;
    double eps_y = Y / (2 * G);
    uniaxial(&m, 0.999 * eps_y, 50, &q, &p, &ep);
    assert_true(ep == 0);
    assert_true(fabs(q - 2 * G * 0.999 * eps_y) < 1e-9 * q);
    for (int k = 1; k <= 4; k++) {
        double eps = k * 0.05;
        uniaxial(&m, eps, 200, &q, &p, &ep);
        double ep_ref = (2 * G * eps - Y) / (3 * G + H);
        assert_true(fabs(ep - ep_ref) < 1e-9 * ep_ref);
        assert_true(fabs(q - (Y + H * ep_ref)) < 1e-9 * q);
        assert_true(fabs(p - K * eps) < 1e-9 * fabs(p));
    }
    /* hardening slope between two strains beyond yield */
    double q1, q2;
    uniaxial(&m, 0.1, 100, &q1, &p, &ep);
    uniaxial(&m, 0.2, 100, &q2, &p, &ep);
    double slope = (q2 - q1) / 0.1, ref = 2 * G * H / (3 * G + H);
    assert_true(fabs(slope - ref) < 1e-6 * ref);
}

/* Objectivity: a stressed point rotated rigidly keeps its principal stresses, and a point rotated
 * from rest stays stress-free. */
static void test_rotation(void **state)
{
    (void)state;
    mpm_material m = mpm_default_material();
    double be[4] = {1, 0, 1, 1}, sig[4], ep = 0;
    double f[4] = {1.01, 0, 0, 1};
    assert_true(mpm_material_update(&m, f, be, &ep, 1.01, sig));
    double s1 = sig[0], s2 = sig[1];
    double th = 0.01;
    double r[4] = {cos(th), -sin(th), sin(th), cos(th)};
    for (int k = 0; k < 157; k++) /* about pi/2 */
        assert_true(mpm_material_update(&m, r, be, &ep, 1.01, sig));
    double mean = 0.5 * (sig[0] + sig[1]), rad = hypot(0.5 * (sig[0] - sig[1]), sig[2]);
    assert_true(fabs(mean + rad - s1) < 1e-9 * fabs(s1));
    assert_true(fabs(mean - rad - s2) < 1e-9 * fabs(s1));
    double b2[4] = {1, 0, 1, 1};
    for (int k = 0; k < 100; k++)
        assert_true(mpm_material_update(&m, r, b2, &ep, 1, sig));
    for (int k = 0; k < 4; k++)
        assert_true(fabs(sig[k]) < 1e-6);
}

static void test_bad_input(void **state)
{
    (void)state;
    core_error err;
    mpm_scene_def def = mpm_default_scene_def();
    mpm_scene *s;
    def.cells[0] = 0;
    assert_int_equal(mpm_create(&def, &s, &err), CORE_ERR_ARG);
    def = mpm_default_scene_def();
    assert_int_equal(mpm_create(&def, &s, &err), CORE_OK);
    mpm_material m = mpm_default_material();
    m.shear = -1;
    assert_int_equal(mpm_add_material(s, &m, &err), -1);
    m = mpm_default_material();
    m.model = MPM_VONMISES;
    assert_int_equal(mpm_add_material(s, &m, &err), -1); /* no yield */
    m = mpm_default_material();
    assert_int_equal(mpm_add_material(s, &m, &err), 0);
    mpm_grain_def g = mpm_default_grain_def();
    g.center[0] = g.center[1] = 0.5;
    g.radius = 0.2;
    g.points_per_cell = 0;
    assert_int_equal(mpm_add_grain(s, &g, &err), -1);
    g.points_per_cell = 2;
    g.center[0] = 0.9;
    assert_int_equal(mpm_add_grain(s, &g, &err), -1);
    g.center[0] = 0.5;
    assert_int_equal(mpm_add_grain(s, &g, &err), 0);
    assert_int_equal(mpm_set_contact(s, MPM_CONTACT_FRICTION, &err), CORE_ERR_ARG);
    mpm_destroy(s);
}

/* Frictional contact (Eqs. 12-24): mu is validated; an isolated grain moves exactly as with the
 * single centre-of-mass field; a frictionless head-on hit on a disk at rest conserves momentum. */
static size_t run_pair(bool friction, double vb, double off, double *x, double p0[2], double p1[2])
{
    core_error err;
    mpm_scene_def def = mpm_default_scene_def();
    def.cells[0] = 60;
    def.cells[1] = 40;
    def.size[0] = 6;
    def.size[1] = 4;
    mpm_scene *s;
    assert_int_equal(mpm_create(&def, &s, &err), CORE_OK);
    mpm_material m = mpm_default_material();
    assert_int_equal(mpm_add_material(s, &m, &err), 0);
    mpm_grain_def g = mpm_default_grain_def();
    g.radius = 0.4;
    g.center[0] = 2.45;
    g.center[1] = 2;
    g.velocity[0] = 2;
    assert_int_equal(mpm_add_grain(s, &g, &err), 0);
    g.center[0] = 3.55 + off;
    g.velocity[0] = vb;
    assert_int_equal(mpm_add_grain(s, &g, &err), 1);
    if (friction) {
        assert_int_equal(mpm_set_friction(s, -1, &err), CORE_ERR_ARG);
        assert_int_equal(mpm_set_friction(s, 0, &err), CORE_OK);
        assert_int_equal(mpm_contact(s), MPM_CONTACT_FRICTION);
    }
    double lz;
    mpm_measure_momentum(s, p0, &lz);
    mpm_run_def run = mpm_default_run_def();
    run.steps = 100000;
    run.time_end = 0.5;
    long done;
    assert_int_equal(mpm_run(s, &run, &done, &err), CORE_OK);
    mpm_points pts;
    mpm_get_points(s, &pts);
    size_t n = mpm_point_count(s);
    assert_true(n <= 4096);
    for (size_t i = 0; i < n; i++)
        x[i] = pts.x[i];
    mpm_measure_momentum(s, p1, &lz);
    mpm_destroy(s);
    return n;
}

static void test_friction(void **state)
{
    (void)state;
    static double xa[4096], xb[4096];
    double p0[2], pa[2], pb[2];
    /* far apart (B 1.5 m further right, moving away): the friction model changes nothing */
    size_t n = run_pair(false, 1, 1.5, xa, p0, pa);
    assert_int_equal(run_pair(true, 1, 1.5, xb, p0, pb), n);
    for (size_t i = 0; i < n; i++)
        assert_true(xa[i] == xb[i]);
    /* head-on on a disk at rest, mu = 0: momentum along the line of centres */
    run_pair(true, 0, 0, xb, p0, pb);
    assert_true(fabs(pb[0] - p0[0]) < 1e-9 * fabs(p0[0]));
    assert_true(fabs(pb[1]) < 1e-9 * fabs(p0[0]));
}

/* A yielding plastic block, 2 steps, then mpm_hydrostatic (which sets b_e, its zz stretch too
 * since the compression yields), then 5 steps: the same bits as with a save and a load before
 * the 5 steps. The step caches ln(b_e,zz) per point; a load rebuilds the cache from b_e,zz, so a
 * stale cache after mpm_hydrostatic would show here. */
static void hydro_run(bool reload, double out[][5], size_t *np)
{
    core_error err;
    mpm_scene_def def = mpm_default_scene_def();
    def.cells[0] = 12;
    def.cells[1] = 12;
    def.size[0] = 1.2;
    def.size[1] = 1.2;
    def.gravity[1] = -10;
    mpm_scene *s;
    assert_int_equal(mpm_create(&def, &s, &err), CORE_OK);
    mpm_material m = {.model = MPM_VONMISES, .density = 1000, .shear = 1e6, .bulk = 3e6,
                      .yield = 10, .hardening = 0};
    assert_int_equal(mpm_add_material(s, &m, &err), 0);
    mpm_grain_def g = mpm_default_grain_def();
    g.shape = MPM_RECT;
    g.lo[0] = 0.2;
    g.lo[1] = 0.05;
    g.hi[0] = 1.0;
    g.hi[1] = 0.85;
    assert_int_equal(mpm_add_grain(s, &g, &err), 0);
    mpm_run_def run = mpm_default_run_def();
    run.steps = 2;
    run.dt = 1e-4;
    long done;
    assert_int_equal(mpm_run(s, &run, &done, &err), CORE_OK);
    assert_int_equal(mpm_hydrostatic(s, 0, &err), CORE_OK);
    mpm_points pts;
    mpm_get_points(s, &pts);
    double ep = 0;
    for (size_t i = 0; i < mpm_point_count(s); i++)
        ep += pts.eps_p[i];
    assert_true(ep > 0); /* the compression yielded: b_e,zz is no longer 1 */
    if (reload) {
        char path[256];
        const char *dir = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/grainlab_mpm_hydro_%ld.ckpt", dir ? dir : "/tmp",
                 (long)getpid());
        assert_int_equal(mpm_save(s, path, "test", &err), CORE_OK);
        mpm_destroy(s);
        assert_int_equal(mpm_load(path, &s, &err), CORE_OK);
        remove(path);
    }
    run.steps = 5;
    assert_int_equal(mpm_run(s, &run, &done, &err), CORE_OK);
    mpm_get_points(s, &pts);
    *np = mpm_point_count(s);
    assert_true(*np <= 1024);
    for (size_t i = 0; i < *np; i++) {
        const double v[5] = {pts.x[i], pts.y[i], pts.sigma[0][i], pts.sigma[1][i],
                             pts.sigma[3][i]};
        memcpy(out[i], v, sizeof v);
    }
    mpm_destroy(s);
}

static void test_hydrostatic_after_run(void **state)
{
    (void)state;
    static double a[1024][5], b[1024][5];
    size_t na, nb;
    hydro_run(false, a, &na);
    hydro_run(true, b, &nb);
    assert_int_equal(na, nb);
    assert_true(na > 0);
    assert_memory_equal(a, b, na * sizeof a[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_elastic_uniaxial),
        cmocka_unit_test(test_vonmises_uniaxial),
        cmocka_unit_test(test_rotation),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_friction),
        cmocka_unit_test(test_hydrostatic_after_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
