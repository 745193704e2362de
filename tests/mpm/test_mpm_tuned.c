/* MPM steps under the thread tuner of auto mode (core/threads.h): a step the tuner runs on one
 * thread gives the bits of a step on all threads, for noslip (its transfers scatter by chunks
 * whose number is the processor count in auto mode, mpm_internal.h) and for friction (every
 * grain's entries built by one thread). The machine is a faked 2-processor one whose run queue is
 * contended (the tuner's clock and waiting meter are simulated), so the tuner runs some steps on
 * one thread; the run is compared, point by point and bit for bit, with the same run on 2 fixed
 * threads. Checked too: the tuner did run steps on one thread and on two (else the comparison
 * proves nothing). Without OpenMP there is nothing to tune: skipped. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "core/threads.h"
#include "mpm/mpm.h"

static double now_s, waited_s;

/* Every reading of the clock is 0.02 s later, and our two threads wait on the run queue for
 * half of it: a contended machine, on which the tuner probes one thread after 0.1 s. */
static double fake_wall(void)
{
    now_s += 0.02;
    waited_s += 0.02;
    return now_s;
}
static double fake_waited(void) { return waited_s; }

/* About 10,000 points in 8 grains moving into each other: the noslip chunks on 2 processors
 * (grains 0-3, 4-7) share nodes, where the order of the chunks' sums shows. */
static mpm_scene *scene(mpm_contact_model model)
{
    core_error err;
    mpm_scene_def def = mpm_default_scene_def();
    def.cells[0] = def.cells[1] = 60;
    def.size[0] = def.size[1] = 6;
    def.periodic[1] = true;
    def.gravity[0] = 0.5;
    def.gravity[1] = -9.8;
    mpm_scene *s = NULL;
    assert_int_equal(mpm_create(&def, &s, &err), CORE_OK);
    mpm_material m = mpm_default_material();
    m.model = MPM_VONMISES;
    m.yield = 2e4;
    const int mat = mpm_add_material(s, &m, &err);
    assert_true(mat >= 0);
    for (int k = 0; k < 8; k++) {
        mpm_grain_def g = mpm_default_grain_def();
        g.shape = MPM_DISK;
        g.center[0] = 0.9 + 1.4 * (k / 2); /* columns of two: grains 0-3 and 4-7 side by side */
        g.center[1] = 1.5 + 2.5 * (k % 2) + 0.2 * (k / 2 % 2);
        g.radius = 0.62;
        g.material = mat;
        g.points_per_cell = 3;
        g.velocity[0] = k / 2 % 2 == 0 ? 1 : -1; /* columns 1 and 2 move into each other */
        g.velocity[1] = 0.3 * k;
        assert_true(mpm_add_grain(s, &g, &err) >= 0);
    }
    if (model == MPM_CONTACT_FRICTION)
        assert_int_equal(mpm_set_friction(s, 0.4, &err), CORE_OK);
    return s;
}

static void run(mpm_scene *s)
{
    core_error err;
    mpm_run_def r = mpm_default_run_def();
    r.steps = 40;
    long done = 0;
    assert_int_equal(mpm_run(s, &r, &done, &err), CORE_OK);
    assert_int_equal(done, 40);
}

static void same_bits(mpm_contact_model model)
{
    threads_tune_fake(2, NULL, NULL);
    threads_set(2);
    mpm_scene *fixed = scene(model);
    assert_true(mpm_point_count(fixed) > 8192); /* threads start at 8192 points */
    run(fixed);

    now_s = 100, waited_s = 0;
    threads_tune_fake(2, fake_wall, fake_waited);
    mpm_scene *tuned = scene(model);
    run(tuned);
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    assert_true(st.steps_one > 0); /* the tuner did run steps on one thread */
    assert_true(st.steps_all > 0);

    mpm_points a, b;
    mpm_get_points(fixed, &a);
    mpm_get_points(tuned, &b);
    const size_t n = mpm_point_count(fixed);
    assert_int_equal(mpm_point_count(tuned), n);
    const double *fa[] = {a.x, a.y, a.vx, a.vy, a.sigma[0], a.sigma[1], a.sigma[2], a.eps_p};
    const double *fb[] = {b.x, b.y, b.vx, b.vy, b.sigma[0], b.sigma[1], b.sigma[2], b.eps_p};
    for (size_t k = 0; k < sizeof fa / sizeof *fa; k++)
        assert_memory_equal(fa[k], fb[k], n * sizeof(double));
    mpm_destroy(fixed);
    mpm_destroy(tuned);
}

static int setup(void **state)
{
    (void)state;
    threads_tune_fake(2, NULL, NULL);
    if (threads_get() != 2) /* a build without OpenMP: nothing to tune */
        skip();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    threads_tune_fake(0, NULL, NULL);
    return 0;
}

static void noslip_tuned_is_fixed(void **state)
{
    (void)state;
    same_bits(MPM_CONTACT_NOSLIP);
}

static void friction_tuned_is_fixed(void **state)
{
    (void)state;
    same_bits(MPM_CONTACT_FRICTION);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(noslip_tuned_is_fixed, setup, teardown),
        cmocka_unit_test_setup_teardown(friction_tuned_is_fixed, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
