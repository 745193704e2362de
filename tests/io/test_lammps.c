/* src/dem/lammps.c without Lua: a data file written and read back gives the same particles to the
 * bit (2D and 3D), a malformed file is refused with its line, a refused load leaves the scene as it
 * was, and dump frames append. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "dem/dem.h"

static char dir[64];

static const char *tmp(const char *name)
{
    static char buf[4][160];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static dem_scene *make(int dim, int n)
{
    dem_scene_def def = dem_default_scene_def();
    def.dim = dim;
    for (int a = 0; a < dim; a++)
        def.lo[a] = 0, def.hi[a] = 0.02;
    def.periodic[0] = true;
    dem_scene *s;
    core_error err;
    assert_int_equal(dem_create(&def, &s, &err), CORE_OK);
    dem_material m = dem_default_material();
    assert_int_equal(dem_add_material(s, &m, &err), 0);
    m.density = 1234.5678901234567;
    assert_int_equal(dem_add_material(s, &m, &err), 1);
    dem_contact_def c = dem_default_contact_def();
    c.tangential = DEM_TANGENT_SPRING;
    assert_int_equal(dem_set_contact(s, &c, &err), CORE_OK);
    for (int i = 0; i < n; i++) {
        dem_particle_def p = {{0.001 + 0.0019 * (i % 10), 0.001 + 0.0019 * (i / 10), 0},
                              {0.1 * sin(i), 0.1 * cos(i), 0},
                              {0, 0, 0},
                              0.0005 + 1e-5 * (i % 7),
                              i % 2,
                              0};
        if (dim == 3) {
            p.x[2] = 0.01 + 1e-4 * i / 3.0;
            p.v[2] = -0.01 * i;
            p.omega[0] = 1.0 / (i + 1);
            p.omega[1] = -2.0 / (i + 3);
        }
        p.omega[2] = 3.0 / (i + 7);
        assert_true(dem_add_particle(s, &p, &err) >= 0);
    }
    return s;
}

static void assert_same(const dem_scene *a, const dem_scene *b)
{
    size_t n = dem_count(a);
    assert_int_equal(dem_count(b), n);
    int D = dem_dim(a);
    for (size_t i = 0; i < n; i++) {
        for (int d = 0; d < D; d++) {
            assert_true(dem_positions(a, d)[i] == dem_positions(b, d)[i]);
            assert_true(dem_velocities(a, d)[i] == dem_velocities(b, d)[i]);
        }
        for (int d = D == 2 ? 2 : 0; d < 3; d++)
            assert_true(dem_angular_velocities(a, d)[i] == dem_angular_velocities(b, d)[i]);
        assert_true(dem_radii(a)[i] == dem_radii(b)[i]);
        assert_true(dem_masses(a)[i] == dem_masses(b)[i]);
        assert_int_equal(dem_particle_materials(a)[i], dem_particle_materials(b)[i]);
    }
}

/* Reads path into a fresh scene of the same kind as like, each type with the file's density. */
static dem_scene *read_into_copy(const dem_scene *like, const char *path)
{
    dem_lammps_data d;
    core_error err;
    assert_int_equal(dem_lammps_read(path, &d, &err), CORE_OK);
    dem_scene_def def = dem_default_scene_def();
    def.dim = dem_dim(like);
    double g[3];
    dem_box(like, def.lo, def.hi, g);
    def.periodic[0] = true;
    dem_scene *s;
    assert_int_equal(dem_create(&def, &s, &err), CORE_OK);
    dem_lammps_type types[8];
    int tm[8];
    assert_true(d.ntypes <= 8);
    for (int t = 0; t < d.ntypes; t++)
        types[t] = (dem_lammps_type){1, dem_default_material(), DEM_LAMMPS_DENSITY_FILE, 0};
    size_t first;
    assert_int_equal(dem_lammps_add(s, &d, types, tm, &first, &err), CORE_OK);
    assert_int_equal(first, 0);
    assert_int_equal(d.flat, dem_dim(like) == 2);
    dem_lammps_free(&d);
    return s;
}

static void round_trip(int dim)
{
    dem_scene *s = make(dim, 40);
    core_error err;
    dem_run_def run = dem_default_run_def();
    run.steps = 20;
    run.dt = 1e-7;
    assert_int_equal(dem_run(s, &run, &err), CORE_OK);
    assert_int_equal(dem_write_lammps_data(s, tmp("a.data"), NULL, &err), CORE_OK);
    dem_scene *t = read_into_copy(s, tmp("a.data"));
    assert_same(s, t);
    dem_destroy(t);
    dem_destroy(s);
}

static void test_round_trip_3d(void **state) { (void)state, round_trip(3); }
static void test_round_trip_2d(void **state) { (void)state, round_trip(2); }

static void test_malformed(void **state)
{
    (void)state;
    FILE *f = fopen(tmp("bad.data"), "w");
    fputs("t\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
          "1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.5 0.5\n",
          f);
    fclose(f);
    dem_lammps_data d;
    core_error err;
    assert_int_equal(dem_lammps_read(tmp("bad.data"), &d, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "bad.data:12: an Atoms line has 6 values"));
    dem_lammps_free(&d);
}

static void test_refusal_leaves_scene(void **state)
{
    (void)state;
    dem_scene *s = make(3, 5);
    core_error err;
    FILE *f = fopen(tmp("far.data"), "w");
    fputs("t\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
          "1 1 0.001 1000 0.005 0.005 0.005\n2 1 0.001 1000 0.005 0.05 0.005\n",
          f);
    fclose(f);
    dem_lammps_data d;
    assert_int_equal(dem_lammps_read(tmp("far.data"), &d, &err), CORE_OK);
    dem_lammps_type ty = {1, dem_default_material(), DEM_LAMMPS_DENSITY_FILE, 0};
    int tm;
    size_t first;
    int nmat = dem_material_count(s);
    assert_int_equal(dem_lammps_add(s, &d, &ty, &tm, &first, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "far.data:12: atom 2: y = 0.050000000000000003 is outside"));
    assert_int_equal(dem_count(s), 5);
    assert_int_equal(dem_material_count(s), nmat);
    dem_lammps_free(&d);
    dem_destroy(s);
}

static void test_dump_append(void **state)
{
    (void)state;
    dem_scene *s = make(2, 12);
    core_error err;
    dem_lammps_write_def def = {0};
    assert_int_equal(dem_write_lammps_dump(s, tmp("f.dump"), &def, &err), CORE_OK);
    def.append = 1;
    assert_int_equal(dem_write_lammps_dump(s, tmp("f.dump"), &def, &err), CORE_OK);
    assert_int_equal(dem_write_lammps_dump(s, tmp("f.dump"), &def, &err), CORE_OK);
    FILE *f = fopen(tmp("f.dump"), "r");
    char line[512];
    int frames = 0, atoms = 0;
    while (fgets(line, sizeof line, f)) {
        frames += strcmp(line, "ITEM: TIMESTEP\n") == 0;
        atoms += strncmp(line, "ITEM: ATOMS id type radius mass x y z ", 38) == 0;
        if (strcmp(line, "ITEM: BOX BOUNDS pp ff pp\n") == 0)
            atoms += 100;
    }
    fclose(f);
    assert_int_equal(frames, 3);
    assert_int_equal(atoms, 303);
    dem_destroy(s);
}

static int cleanup(void **state)
{
    (void)state;
    const char *names[] = {"a.data", "bad.data", "far.data", "f.dump"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++)
        unlink(tmp(names[k]));
    return rmdir(dir);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/grainlab_lammps_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_3d), cmocka_unit_test(test_round_trip_2d),
        cmocka_unit_test(test_malformed), cmocka_unit_test(test_refusal_leaves_scene),
        cmocka_unit_test(test_dump_append)};
    return cmocka_run_group_tests(tests, NULL, cleanup);
}
