/* MPM and DSMC checkpoints without Lua: a saved and reloaded scene continues with the same bits
 * as the original (memcmp of every point or particle array), and a load that fails returns no
 * scene. The Lua tests (tests/mpm/test_checkpoint_mpm.lua, tests/dsmc/test_checkpoint_dsmc.lua)
 * cover bad files and the bindings. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <unistd.h>

#include "dsmc/dsmc.h"
#include "mpm/mpm.h"

static char path[64];

static void make_path(void)
{
    snprintf(path, sizeof path, "/tmp/grainlab_ckpt_c_%ld.ckpt", (long)getpid());
}

static void test_dsmc_continuation(void **state)
{
    (void)state;
    make_path();
    dsmc_scene_def d = dsmc_default_scene_def();
    d.dim = 3;
    for (int k = 0; k < 3; k++) {
        d.hi[k] = 0.05;
        d.cells[k] = 5;
    }
    d.periodic[2] = false;
    d.gravity[2] = -9.81;
    d.restitution = 0.8;
    d.seed = 5;
    core_error err;
    dsmc_scene *a = NULL, *b = NULL, *c = NULL;
    assert_int_equal(dsmc_create(&d, &a, &err), CORE_OK);
    assert_int_equal(dsmc_create(&d, &b, &err), CORE_OK);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = 2000;
    f.speed = 1;
    assert_int_equal(dsmc_fill(a, &f, &err), CORE_OK);
    assert_int_equal(dsmc_fill(b, &f, &err), CORE_OK);
    dsmc_wall_def w = dsmc_default_wall_def();
    w.kind = DSMC_WALL_DIFFUSE;
    w.temperature = 1e-6;
    assert_int_equal(dsmc_set_wall(a, DSMC_ZHI, &w, &err), CORE_OK);
    assert_int_equal(dsmc_set_wall(b, DSMC_ZHI, &w, &err), CORE_OK);
    dsmc_run_def r = dsmc_default_run_def();
    r.dt = 2e-4;
    long done;
    r.steps = 80;
    assert_int_equal(dsmc_run(a, &r, &done, &err), CORE_OK);
    r.steps = 40;
    assert_int_equal(dsmc_run(b, &r, &done, &err), CORE_OK);
    assert_int_equal(dsmc_save(b, path, "test", &err), CORE_OK);
    dsmc_destroy(b);
    assert_int_equal(dsmc_load(path, &c, &err), CORE_OK);
    assert_int_equal(dsmc_run(c, &r, &done, &err), CORE_OK);
    dsmc_particles pa, pc;
    dsmc_get_particles(a, &pa);
    dsmc_get_particles(c, &pc);
    assert_int_equal(dsmc_count(a), dsmc_count(c));
    for (int k = 0; k < 3; k++) {
        assert_memory_equal(pa.x[k], pc.x[k], dsmc_count(a) * sizeof(double));
        assert_memory_equal(pa.v[k], pc.v[k], dsmc_count(a) * sizeof(double));
    }
    assert_true(dsmc_total_collisions(a) > 0);
    assert_true(dsmc_total_collisions(a) == dsmc_total_collisions(c));
    /* the wrong engine: refused, nothing returned */
    mpm_scene *m = (mpm_scene *)&m; /* not NULL: the load must clear it */
    assert_int_equal(mpm_load(path, &m, &err), CORE_ERR_ARG);
    assert_null(m);
    assert_non_null(strstr(err.msg, "is a dsmc checkpoint, not an mpm one"));
    dsmc_destroy(a);
    dsmc_destroy(c);
    remove(path);
}

static void test_mpm_continuation(void **state)
{
    (void)state;
    make_path();
    mpm_scene_def d = mpm_default_scene_def();
    d.cells[0] = d.cells[1] = 20;
    d.size[0] = d.size[1] = 2;
    d.gravity[1] = -9.8;
    d.walls[MPM_BOTTOM] = MPM_WALL_FRICTION;
    d.wall_mu[MPM_BOTTOM] = 0.5;
    mpm_scene *s[2] = {NULL, NULL}, *c = NULL;
    core_error err;
    for (int k = 0; k < 2; k++) {
        assert_int_equal(mpm_create(&d, &s[k], &err), CORE_OK);
        mpm_material mat = mpm_default_material();
        mat.model = MPM_VONMISES;
        mat.yield = 5e4;
        assert_int_equal(mpm_add_material(s[k], &mat, &err), 0);
        mpm_grain_def g = mpm_default_grain_def();
        g.center[0] = 0.6;
        g.center[1] = 0.32;
        g.radius = 0.3;
        g.velocity[0] = 0.8;
        assert_int_equal(mpm_add_grain(s[k], &g, &err), 0);
        g.center[0] = 1.25;
        g.velocity[0] = -0.6;
        assert_int_equal(mpm_add_grain(s[k], &g, &err), 1);
        assert_int_equal(mpm_set_friction(s[k], 0.3, &err), CORE_OK);
    }
    mpm_run_def r = mpm_default_run_def();
    long done;
    r.steps = 60;
    assert_int_equal(mpm_run(s[0], &r, &done, &err), CORE_OK);
    r.steps = 30;
    assert_int_equal(mpm_run(s[1], &r, &done, &err), CORE_OK);
    assert_int_equal(mpm_save(s[1], path, "test", &err), CORE_OK);
    mpm_destroy(s[1]);
    assert_int_equal(mpm_load(path, &c, &err), CORE_OK);
    assert_int_equal(mpm_run(c, &r, &done, &err), CORE_OK);
    mpm_points pa, pc;
    mpm_get_points(s[0], &pa);
    mpm_get_points(c, &pc);
    const size_t n = mpm_point_count(s[0]) * sizeof(double);
    assert_int_equal(mpm_point_count(s[0]), mpm_point_count(c));
    assert_memory_equal(pa.x, pc.x, n);
    assert_memory_equal(pa.y, pc.y, n);
    assert_memory_equal(pa.vx, pc.vx, n);
    assert_memory_equal(pa.vy, pc.vy, n);
    for (int k = 0; k < 4; k++) {
        assert_memory_equal(pa.F[k], pc.F[k], n);
        assert_memory_equal(pa.sigma[k], pc.sigma[k], n);
    }
    assert_memory_equal(pa.eps_p, pc.eps_p, n);
    assert_true(mpm_time(s[0]) == mpm_time(c));
    mpm_destroy(s[0]);
    mpm_destroy(c);
    remove(path);
    /* a missing file: refused, nothing returned */
    assert_int_equal(mpm_load(path, &c, &err), CORE_ERR_IO);
    assert_null(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_dsmc_continuation),
                                       cmocka_unit_test(test_mpm_continuation)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
