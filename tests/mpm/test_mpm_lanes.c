/* The MPM step's lanes against their scalar reference (the same scene with no_lanes,
 * mpm_internal.h), bit for bit, point by point: the stress update (constitutive in
 * src/mpm/stress.c: blocks of points, two at a time in SSE2 lanes, the logarithms scalar, the
 * possibly plastic points and the end-of-step check's suspects finished one at a time; the
 * reference is material_update_zz point by point) and G2P (to_points: two points at a time, the
 * last one of an odd range alone; the reference one at a time). The scenes hold what the lanes
 * must route right: von Mises points that yield next to elastic ones, blocks holding points of
 * two materials (runs of each in its lanes), a point count that is odd and not a multiple of
 * the block (the remainders), points crossing a periodic edge (wrapped by the check), both
 * update orders (MUSL checks each point right after its update, USF later), both shape
 * functions, and a run that inverts a point (the same point reported). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "mpm/mpm.h"
#include "mpm/mpm_internal.h"

/* Small disks alternating between a von Mises material that yields on impact and an elastic
 * one with the same moduli, in two rows moving into each other; the lower row straddles the
 * periodic y edge and moves down across it. */
static mpm_scene *scene(mpm_update update, mpm_shape_fn shape, mpm_contact_model model, bool scalar)
{
    core_error err;
    mpm_scene_def def = mpm_default_scene_def();
    def.cells[0] = def.cells[1] = 40;
    def.size[0] = def.size[1] = 4;
    def.periodic[1] = true;
    def.gravity[1] = -9.8;
    def.update = update;
    def.shape = shape;
    mpm_scene *s = NULL;
    assert_int_equal(mpm_create(&def, &s, &err), CORE_OK);
    s->no_lanes = scalar;
    mpm_material vm = mpm_default_material(), el = mpm_default_material();
    vm.model = MPM_VONMISES;
    vm.yield = 2e4;
    vm.hardening = 1e5;
    int mats[2] = {mpm_add_material(s, &vm, &err), mpm_add_material(s, &el, &err)};
    assert_true(mats[0] >= 0 && mats[1] >= 0);
    for (int k = 0; k < 10; k++) {
        mpm_grain_def g = mpm_default_grain_def();
        g.shape = MPM_DISK;
        g.center[0] = 0.6 + 0.7 * (k / 2);
        g.center[1] = k % 2 ? 0.72 : 0.03;
        g.radius = 0.33;
        g.material = mats[k % 2 ^ (k / 2 % 2)];
        g.points_per_cell = 3;
        g.velocity[0] = k % 4 < 2 ? 2 : -2; /* neighbouring columns move into each other */
        g.velocity[1] = k % 2 ? -3 : -1;    /* the rows too, the lower one across y = 0 */
        g.omega = 0.5 * k;
        assert_true(mpm_add_grain(s, &g, &err) >= 0);
    }
    mpm_grain_def r = mpm_default_grain_def(); /* 9 points at rest: an odd count */
    r.shape = MPM_RECT;
    r.lo[0] = 3.7, r.lo[1] = 2.0, r.hi[0] = 3.8, r.hi[1] = 2.1;
    r.material = mats[1];
    r.points_per_cell = 3;
    assert_true(mpm_add_grain(s, &r, &err) >= 0);
    if (model == MPM_CONTACT_FRICTION)
        assert_int_equal(mpm_set_friction(s, 0.3, &err), CORE_OK);
    const size_t n = mpm_point_count(s);
    assert_true(n % 2 == 1); /* a lane and a block remainder */
    return s;
}

/* The two scenes' points, every field, bit for bit. */
static void same_points(const mpm_scene *a, const mpm_scene *b)
{
    mpm_points pa, pb;
    mpm_get_points(a, &pa);
    mpm_get_points(b, &pb);
    const size_t n = mpm_point_count(a);
    assert_int_equal(mpm_point_count(b), n);
    const double *fa[] = {pa.x,        pa.y,        pa.vx,       pa.vy,       pa.ux,
                          pa.uy,       pa.F[0],     pa.F[1],     pa.F[2],     pa.F[3],
                          pa.sigma[0], pa.sigma[1], pa.sigma[2], pa.sigma[3], pa.eps_p};
    const double *fb[] = {pb.x,        pb.y,        pb.vx,       pb.vy,       pb.ux,
                          pb.uy,       pb.F[0],     pb.F[1],     pb.F[2],     pb.F[3],
                          pb.sigma[0], pb.sigma[1], pb.sigma[2], pb.sigma[3], pb.eps_p};
    for (size_t k = 0; k < sizeof fa / sizeof *fa; k++)
        assert_memory_equal(fa[k], fb[k], n * sizeof(double));
}

static void lanes_are_scalar(mpm_update update, mpm_shape_fn shape, mpm_contact_model model)
{
    mpm_scene *sc[2];
    for (int k = 0; k < 2; k++) {
        sc[k] = scene(update, shape, model, k == 1);
        core_error err;
        mpm_run_def r = mpm_default_run_def();
        r.steps = 30;
        long done = 0;
        assert_int_equal(mpm_run(sc[k], &r, &done, &err), CORE_OK);
        assert_int_equal(done, 30);
    }
    same_points(sc[0], sc[1]);
    /* the comparison covered plastic points and wrapped ones */
    mpm_points p;
    mpm_get_points(sc[0], &p);
    size_t plastic = 0, wrapped = 0;
    for (size_t i = 0; i < mpm_point_count(sc[0]); i++) {
        plastic += p.eps_p[i] > 0;
        wrapped += p.y[i] > 2; /* started in [-0.3, 0.36]: below 0 wraps to near 4 */
    }
    assert_true(plastic > 0);
    assert_true(wrapped > 0);
    mpm_destroy(sc[0]);
    mpm_destroy(sc[1]);
}

static void musl_linear_friction(void **state)
{
    (void)state;
    lanes_are_scalar(MPM_MUSL, MPM_SHAPE_LINEAR, MPM_CONTACT_FRICTION);
}

static void usf_bspline_noslip(void **state)
{
    (void)state;
    lanes_are_scalar(MPM_USF, MPM_SHAPE_BSPLINE, MPM_CONTACT_NOSLIP);
}

/* A step far beyond the CFL limit inverts points: both paths stop at the same step naming the
 * same point, with the same points left behind. */
static void inversion_same_point(void **state)
{
    (void)state;
    mpm_scene *sc[2];
    char msg[2][512];
    for (int k = 0; k < 2; k++) {
        sc[k] = scene(MPM_MUSL, MPM_SHAPE_LINEAR, MPM_CONTACT_NOSLIP, k == 1);
        core_error err;
        mpm_run_def r = mpm_default_run_def();
        r.steps = 50;
        r.dt = 2e-2;
        long done = 0;
        assert_int_equal(mpm_run(sc[k], &r, &done, &err), CORE_ERR_UNSTABLE);
        strcpy(msg[k], err.msg);
    }
    assert_non_null(strstr(msg[0], "inverted"));
    assert_string_equal(msg[0], msg[1]);
    same_points(sc[0], sc[1]);
    mpm_destroy(sc[0]);
    mpm_destroy(sc[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(musl_linear_friction),
        cmocka_unit_test(usf_bspline_noslip),
        cmocka_unit_test(inversion_same_point),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
