/* Checkpoints of a DEM boundary rebuilt by an update callback, without Lua (src/dem/boundary.c,
 * checkpoint.c): the callback is never in the file, its kind and what its save_ctx writes are;
 * a loader with a restorer of that kind continues with the same bits (the toy update below
 * unloads one edge of the loop, chosen by a counter kept in its ctx, so a ctx not restored
 * changes the forces); without a restorer, with another kind's, or with one that
 * fails, the load is refused and returns no scene; an update without a kind is refused at save.
 * The Lua tests (tests/dem/test_checkpoint_dem.lua, tests/cli/test_checkpoint.sh) cover the
 * Delaunay update of s:boundary. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <unistd.h>

#include "core/checkpoint.h"
#include "dem/dem.h"

enum { N = 24, EVERY = 7 };
static const double PI = 3.14159265358979323846;
static char path[80];

typedef struct toy {
    long turn; /* calls so far: edge turn % N carries no pressure */
} toy;

static int toys_freed;

static void toy_free(void *p)
{
    toys_freed++;
    free(p);
}

static core_status toy_update(void *ctx, dem_scene *s, core_error *err)
{
    toy *t = ctx;
    long a[N], b[N];
    unsigned char loaded[N];
    for (int k = 0; k < N; k++) {
        a[k] = k;
        b[k] = (k + 1) % N;
        loaded[k] = k != t->turn % N;
    }
    t->turn++;
    return dem_set_boundary_edges(s, N, a, b, loaded, 1, err);
}

static void toy_save(const void *ctx, ckpt_writer *w) { ckpt_put_i64(w, ((const toy *)ctx)->turn); }

static core_status toy_restore(ckpt_section *sec, const dem_scene *s, dem_boundary_def *def,
                               core_error *err)
{
    (void)s;
    long turn;
    core_status st = ckpt_get_int_in(sec, 0, 1L << 40, "turn", &turn, err);
    if (st)
        return st;
    toy *t = malloc(sizeof *t);
    if (!t)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory");
    t->turn = turn;
    def->update = toy_update;
    def->ctx = t;
    def->free_ctx = toy_free;
    def->kind = "toy";
    def->save_ctx = toy_save;
    return CORE_OK;
}

static core_status failing_restore(ckpt_section *sec, const dem_scene *s, dem_boundary_def *def,
                                   core_error *err)
{
    (void)sec, (void)s, (void)def;
    return core_fail(err, CORE_ERR_NOMEM, "the restorer ran out of memory");
}

/* A ring of disks pushed in by the pressure on its loop, rebuilt by the toy every EVERY steps. */
static dem_scene *ring(int kind)
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
    for (int k = 0; k < N; k++) {
        double th = 2 * PI * k / N, R = 0.3 + 0.02 * sin(3 * th);
        dem_particle_def p;
        memset(&p, 0, sizeof p);
        p.x[0] = R * cos(th);
        p.x[1] = R * sin(th);
        p.v[0] = 0.01 * sin(5 * th);
        p.radius = 0.01;
        assert_true(dem_add_particle(s, &p, &err) >= 0);
    }
    dem_boundary_def b = dem_default_boundary_def();
    b.pressure = 3e3;
    b.depth = 0.01;
    b.every = EVERY;
    b.update = toy_update;
    b.ctx = calloc(1, sizeof(toy));
    assert_non_null(b.ctx);
    b.free_ctx = toy_free;
    if (kind) {
        b.kind = "toy";
        b.save_ctx = toy_save;
    }
    assert_int_equal(dem_set_boundary(s, &b, &err), CORE_OK);
    assert_int_equal(dem_update_boundary(s, &err), CORE_OK);
    return s;
}

static void run(dem_scene *s, long steps)
{
    dem_run_def r = dem_default_run_def();
    r.steps = steps;
    r.dt = 1e-4;
    core_error err;
    assert_int_equal(dem_run(s, &r, &err), CORE_OK);
}

static void assert_same_bits(const dem_scene *a, const dem_scene *b)
{
    assert_int_equal(dem_count(a), dem_count(b));
    for (int d = 0; d < 2; d++) {
        assert_memory_equal(dem_positions(a, d), dem_positions(b, d), N * sizeof(double));
        assert_memory_equal(dem_velocities(a, d), dem_velocities(b, d), N * sizeof(double));
    }
    const long *aa, *ab, *ba, *bb;
    const unsigned char *al, *bl;
    assert_int_equal(dem_boundary_edges(a, &aa, &ab, &al), dem_boundary_edges(b, &ba, &bb, &bl));
    assert_memory_equal(aa, ba, N * sizeof *aa);
    assert_memory_equal(al, bl, N);
}

static void test_continuation(void **state)
{
    (void)state;
    core_error err;
    dem_scene *a = ring(1), *b = ring(1), *c = NULL;
    run(a, 100);
    run(b, 60);
    assert_int_equal(dem_save(b, path, "test", &err), CORE_OK);
    dem_destroy(b);
    const dem_boundary_restorer r = {"toy", toy_restore};
    assert_int_equal(dem_load_with(path, &r, &c, &err), CORE_OK);
    dem_boundary_info before, after;
    assert_int_equal(dem_boundary_info_get(c, &before, &err), CORE_OK);
    run(c, 40);
    assert_int_equal(dem_boundary_info_get(c, &after, &err), CORE_OK);
    assert_true(after.updates >= before.updates + 5); /* rebuilt after the load */
    assert_same_bits(a, c);
    /* the pressure moved the ring: a comparison of unmoved particles would prove nothing */
    double moved = 0;
    dem_scene *fresh = ring(1);
    for (int k = 0; k < N; k++)
        moved = fmax(moved, fabs(dem_positions(c, 0)[k] - dem_positions(fresh, 0)[k]));
    assert_true(moved > 1e-9);
    dem_destroy(fresh);
    dem_destroy(a);
    dem_destroy(c);
}

/* The same round trip, but the loaded ctx starts its count again: the unloaded edge, and with it
 * the bits, differ (so the test above can fail). */
static core_status forgetful_restore(ckpt_section *sec, const dem_scene *s, dem_boundary_def *def,
                                     core_error *err)
{
    core_status st = toy_restore(sec, s, def, err);
    if (!st)
        ((toy *)def->ctx)->turn = 0;
    return st;
}

static void test_ctx_matters(void **state)
{
    (void)state;
    core_error err;
    dem_scene *a = ring(1), *b = ring(1), *c = NULL;
    run(a, 100);
    run(b, 60);
    assert_int_equal(dem_save(b, path, "test", &err), CORE_OK);
    dem_destroy(b);
    const dem_boundary_restorer r = {"toy", forgetful_restore};
    assert_int_equal(dem_load_with(path, &r, &c, &err), CORE_OK);
    run(c, 40);
    const long *aa, *ab, *ca, *cb;
    const unsigned char *al, *cl;
    dem_boundary_edges(a, &aa, &ab, &al);
    dem_boundary_edges(c, &ca, &cb, &cl);
    assert_true(memcmp(al, cl, N) != 0);
    assert_true(memcmp(dem_positions(a, 0), dem_positions(c, 0), N * sizeof(double)) != 0 ||
                memcmp(dem_positions(a, 1), dem_positions(c, 1), N * sizeof(double)) != 0);
    dem_destroy(a);
    dem_destroy(c);
}

static void test_refusals(void **state)
{
    (void)state;
    core_error err;
    /* an update without a kind: refused at save, nothing written */
    unlink(path);
    dem_scene *s = ring(0);
    assert_int_equal(dem_save(s, path, "test", &err), CORE_ERR_STATE);
    assert_non_null(strstr(err.msg, "update callback without a kind"));
    assert_int_equal(access(path, F_OK), -1);
    dem_destroy(s);

    s = ring(1);
    run(s, 10);
    assert_int_equal(dem_save(s, path, "test", &err), CORE_OK);
    dem_destroy(s);
    dem_scene *c = (dem_scene *)&err; /* must come back NULL */
    assert_int_equal(dem_load(path, &c, &err), CORE_ERR_STATE);
    assert_null(c);
    assert_non_null(strstr(err.msg, "by a 'toy' update, which this loader cannot re-attach"));
    const dem_boundary_restorer other = {"delaunay", toy_restore};
    assert_int_equal(dem_load_with(path, &other, &c, &err), CORE_ERR_STATE);
    assert_null(c);
    int freed = toys_freed;
    const dem_boundary_restorer failing = {"toy", failing_restore};
    assert_int_equal(dem_load_with(path, &failing, &c, &err), CORE_ERR_NOMEM);
    assert_null(c);
    assert_string_equal(err.msg, "the restorer ran out of memory");
    assert_int_equal(toys_freed, freed);
    const dem_boundary_restorer r = {"toy", toy_restore};
    assert_int_equal(dem_load_with(path, &r, &c, &err), CORE_OK);
    dem_destroy(c);
    assert_int_equal(toys_freed, freed + 1); /* the loaded ctx belongs to the scene */
    unlink(path);
}

int main(void)
{
    snprintf(path, sizeof path, "/tmp/grainlab_bnd_ckpt_%ld.ckpt", (long)getpid());
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_continuation),
        cmocka_unit_test(test_ctx_matters),
        cmocka_unit_test(test_refusals),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    unlink(path);
    return rc;
}
