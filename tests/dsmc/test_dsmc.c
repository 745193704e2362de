/* DSMC kernels without Lua, against kinetic theory re-derived here: relaxation to
 * Maxwell-Boltzmann (kurtosis), the equilibrium collision rate omega tau / 2, conservation at
 * e = 1, Haff's law in its collision-count form, walls, thread independence and bad input. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/threads.h"
#include "dsmc/dsmc.h"
#include "dsmc/dsmc_internal.h" /* test_layout scrambles the particle arrays */

static const double PI = 3.14159265358979323846;

/* A periodic box of N particles at packing nu with about `per_cell` particles per cell, point
 * particles (chi = 1); v0 > 0: all speeds equal to v0 (not Maxwellian), v0 < 0: Maxwellian with
 * T/m = v0^2. */
static dsmc_scene *gas(int D, size_t N, double nu, int per_cell, double e, double v0)
{
    dsmc_scene_def d = dsmc_default_scene_def();
    d.dim = D;
    d.radius = 1e-3;
    d.restitution = e;
    d.excluded = DSMC_EXCLUDED_NONE;
    double vp = D == 2 ? PI * d.radius * d.radius : 4.0 / 3.0 * PI * pow(d.radius, 3);
    double L = pow((double)N * vp / nu, 1.0 / D);
    int c = (int)floor(pow((double)N / per_cell, 1.0 / D));
    for (int k = 0; k < D; k++) {
        d.lo[k] = 0;
        d.hi[k] = L;
        d.cells[k] = c;
        d.periodic[k] = true;
    }
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = N;
    if (v0 > 0)
        f.speed = v0;
    else
        f.temperature = dsmc_mass(s) * v0 * v0;
    f.seed = 7;
    assert_int_equal(dsmc_fill(s, &f, &err), CORE_OK);
    return s;
}

/* Kinetic theory, from the mean relative speed of two Maxwellian particles: in d dimensions
 * g = v_i - v_j has d Gaussian components of variance 2T/m, so <|g|> = sqrt(pi T/m) (2D, a
 * Rayleigh variable) and 4 sqrt(T/(pi m)) (3D, a Maxwell variable); the collision frequency is
 * omega = n sigma <|g|> with the cross-sections 4R (2D) and 4 pi R^2 (3D) of Eq. 1. */
static double omega_theory(int D, double n, double R, double t_over_m)
{
    double g = D == 2 ? sqrt(PI * t_over_m) : 4 * sqrt(t_over_m / PI);
    double sigma = D == 2 ? 4 * R : 4 * PI * R * R;
    return n * sigma * g;
}

static void run(dsmc_scene *s, long steps, double dt)
{
    dsmc_run_def r = dsmc_default_run_def();
    r.steps = steps;
    r.dt = dt;
    long done;
    core_error err;
    assert_int_equal(dsmc_run(s, &r, &done, &err), CORE_OK);
    assert_int_equal(done, steps);
}

/* Elastic limit: from equal speeds the distribution relaxes to Maxwell-Boltzmann, whose
 * kurtosis <v^4>/<v^2>^2 is E[q^2]/E[q]^2 for q = |v|^2 ~ (T/m) chi^2_d: (d + 2)/d. Energy and
 * momentum stay at their initial values to round-off; the accepted collisions per particle per
 * step are omega tau / 2 (each collision involves two particles). */
static void elastic(int D)
{
    const size_t N = 10000;
    dsmc_scene *s = gas(D, N, 0.005, 20, 1.0, 1.0);
    dsmc_moments m0, m;
    dsmc_measure_moments(s, &m0);
    double V = dsmc_volume(s), R = dsmc_def(s)->radius;
    double w = omega_theory(D, (double)(N - 1) / V, R, m0.t_over_m);
    double dt = 0.2 / w; /* omega tau = 0.2 */
    run(s, 60, dt);      /* 12 collisions per particle: relaxed */
    dsmc_measure_moments(s, &m);
    double kin = m0.kinetic_energy;
    assert_true(fabs(m.kinetic_energy - kin) <= 1e-12 * kin);
    double pscale = dsmc_mass(s) * sqrt(2 * kin / dsmc_mass(s) * (double)N);
    for (int k = 0; k < D; k++)
        assert_true(fabs(m.momentum[k] - m0.momentum[k]) <= 1e-12 * pscale);

    /* Kurtosis averaged over 60 snapshots 2 collision times apart (6e5 samples, standard error
     * about 2/sqrt(6e5) = 0.003 in 2D). */
    double ksum = 0;
    const int snaps = 60, batch = 10;
    double bsum[10] = {0};
    dsmc_reset_stats(s);
    for (int k = 0; k < snaps; k++) {
        dsmc_stats st0, st1;
        dsmc_get_stats(s, &st0);
        run(s, 10, dt);
        dsmc_get_stats(s, &st1);
        bsum[k % batch] += (st1.collisions - st0.collisions) / (double)N / 10;
        dsmc_measure_moments(s, &m);
        ksum += m.kurtosis;
    }
    double K = ksum / snaps, Kth = (D + 2.0) / D;
    printf("  %dD: kurtosis %.5f (Maxwell-Boltzmann %.5f, rel. error %.2e)\n", D, K, Kth,
           K / Kth - 1);
    assert_true(fabs(K / Kth - 1) < 0.01);

    /* Collisions per particle per step against omega tau / 2; the standard error from the
     * scatter of 10 interleaved batch means. */
    double mean = 0, var = 0;
    for (int b = 0; b < batch; b++)
        mean += bsum[b] / (snaps / batch);
    mean /= batch;
    for (int b = 0; b < batch; b++) {
        double x = bsum[b] / (snaps / batch) - mean;
        var += x * x;
    }
    double se = sqrt(var / (batch - 1) / batch);
    dsmc_measure_moments(s, &m);
    double theory = 0.5 * omega_theory(D, (double)(N - 1) / V, R, m.t_over_m) * dt;
    printf("  %dD: collisions/particle/step %.6f, omega tau/2 %.6f, diff %.2f standard errors\n",
           D, mean, theory, (mean - theory) / se);
    assert_true(fabs(mean - theory) <= 3 * se);
    assert_true(fabs(m.kinetic_energy - kin) <= 1e-12 * kin);
    dsmc_destroy(s);
}

static void test_elastic_2d(void **state)
{
    (void)state;
    elastic(2);
}

static void test_elastic_3d(void **state)
{
    (void)state;
    elastic(3);
}

/* Haff's law per collision: each collision removes (1 - e^2)/4 m (g.n)^2 with <(g.n)^2> over
 * collisions giving dT/dc = -(1 - e^2) T / d for a Maxwellian, c = 2 N_coll / N. The homogeneous
 * cooling state's a2 (van Noije & Ernst 1998) multiplies the cooling rate by (1 + 3 a2/16) and
 * the collision rate by (1 - a2/16) (<|g|^p> ~ 1 + a2 p (p - 2)/16). */
static void haff_count(int D, double e)
{
    const size_t N = 10000;
    dsmc_scene *s = gas(D, N, 0.005, 20, e, -1.0);
    dsmc_moments m;
    double dt = 0.1 / dsmc_collision_frequency(s);
    run(s, 20, dt); /* one collision per particle: from Maxwell-Boltzmann towards the cooling state */
    dt = 0.1 / dsmc_collision_frequency(s);
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (; k < 60; k++) {
        dsmc_measure_moments(s, &m);
        double c = 2 * dsmc_total_collisions(s) / (double)N, y = log(m.temperature);
        sx += c;
        sy += y;
        sxx += c * c;
        sxy += c * y;
        run(s, 10, dt);
        dt = 0.1 / dsmc_collision_frequency(s);
    }
    double slope = (k * sxy - sx * sy) / (k * sxx - sx * sx);
    double a2 = 16 * (1 - e) * (1 - 2 * e * e) /
                (9 + 24 * D - e * (41 - 8 * D) + 30 * e * e * (1 - e));
    double theory = -(1 - e * e) / D * (1 + 3 * a2 / 16) / (1 - a2 / 16);
    printf("  %dD e = %.2f: d ln T / dc = %.5f, theory %.5f (a2 = %.4f), rel. error %.2e\n", D,
           e, slope, theory, a2, slope / theory - 1);
    assert_true(fabs(slope / theory - 1) < 0.015);
    dsmc_destroy(s);
}

static void test_haff_count(void **state)
{
    (void)state;
    haff_count(2, 0.8);
    haff_count(3, 0.5);
}

/* Closed specular walls at e = 1 keep the energy and every particle inside; diffuse walls at
 * T_w bring an elastic gas to T_w. */
static void test_walls(void **state)
{
    (void)state;
    dsmc_scene *s = gas(2, 4000, 0.01, 10, 1.0, 1.0);
    const dsmc_scene_def *d = dsmc_def(s);
    double L = d->hi[0];
    dsmc_scene_def d2 = *d;
    d2.periodic[0] = d2.periodic[1] = false;
    dsmc_scene *w;
    core_error err;
    assert_int_equal(dsmc_create(&d2, &w, &err), CORE_OK);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = 4000;
    f.temperature = dsmc_mass(w) * 1.0;
    assert_int_equal(dsmc_fill(w, &f, &err), CORE_OK);
    dsmc_moments m0, m;
    dsmc_measure_moments(w, &m0);
    run(w, 400, 0.02 * L);
    dsmc_measure_moments(w, &m);
    assert_true(fabs(m.kinetic_energy / m0.kinetic_energy - 1) < 1e-12);
    dsmc_particles p;
    dsmc_get_particles(w, &p);
    for (size_t i = 0; i < dsmc_count(w); i++)
        assert_true(p.x[0][i] >= 0 && p.x[0][i] <= L && p.x[1][i] >= 0 && p.x[1][i] <= L);
    dsmc_stats st;
    dsmc_get_stats(w, &st);
    assert_true(st.wall_hits > 1000);

    dsmc_wall_def wd = dsmc_default_wall_def();
    wd.kind = DSMC_WALL_DIFFUSE;
    wd.temperature = dsmc_mass(w) * 4.0; /* T/m = 4 m^2/s^2, four times the gas */
    for (int side = 0; side < 4; side++)
        assert_int_equal(dsmc_set_wall(w, side, &wd, &err), CORE_OK);
    run(w, 800, 0.02 * L);
    double T = 0;
    for (int k = 0; k < 20; k++) {
        run(w, 20, 0.02 * L);
        dsmc_measure_moments(w, &m);
        T += m.t_over_m / 20;
    }
    printf("  diffuse walls at T/m = 4: gas T/m = %.4f\n", T);
    assert_true(fabs(T / 4 - 1) < 0.03);
    dsmc_destroy(w);
    dsmc_destroy(s);
}

/* A 2D unit box walled in x (periodic in y), 4 x 4 cells, R = 1 mm, e = 1, no gravity, with
 * particles at (x[i], y[i]) moving at (vx[i], vy[i]). */
static dsmc_scene *box_with(size_t n, const double *x, const double *y, const double *vx,
                            const double *vy)
{
    dsmc_scene_def d = dsmc_default_scene_def();
    d.periodic[0] = false;
    d.cells[0] = d.cells[1] = 4;
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    assert_int_equal(dsmc_add(s, n, x, y, NULL, vx, vy, NULL, &err), CORE_OK);
    return s;
}

/* Steps far longer than a flight across the box: mirror walls (fixed, specular, e_w = 1) fold
 * the flight in closed form, any number of crossings at the cost of one; other walls refuse the
 * step, naming the particle. */
static void test_long_flight(void **state)
{
    (void)state;
    /* 0.3 + 10.25 = 10.55 unfolds to 0.55 after 10 crossings, moving on; 0.7 - 3.6 = -2.9 to
     * 0.9 after 3, turned round. Rows 0 and 3: they never share a cell. */
    const double x[2] = {0.3, 0.7}, y[2] = {0.1, 0.9}, vx[2] = {10.25, -3.6}, vy[2] = {0, 0};
    dsmc_scene *s = box_with(2, x, y, vx, vy);
    run(s, 1, 1.0);
    dsmc_particles p;
    dsmc_get_particles(s, &p);
    for (size_t i = 0; i < 2; i++) {
        const double want_x = p.id[i] == 0 ? 0.55 : 0.9, want_v = p.id[i] == 0 ? 10.25 : 3.6;
        assert_true(fabs(p.x[0][i] - want_x) < 1e-12);
        assert_true(fabs(p.v[0][i] - want_v) < 1e-12);
    }
    dsmc_stats st;
    dsmc_get_stats(s, &st);
    assert_true(st.wall_hits == 13);
    /* a million crossings in one step: the same cost, still inside */
    run(s, 1, 1e5);
    dsmc_get_particles(s, &p);
    for (size_t i = 0; i < 2; i++)
        assert_true(p.x[0][i] >= 0 && p.x[0][i] <= 1);
    dsmc_destroy(s);

    /* an inelastic wall has no fold: the step stops the run, naming particle 0 (particle 1
     * is back inside after 2 reflections) */
    const double vx2[2] = {40.25, -3.6};
    s = box_with(2, x, y, vx2, vy);
    dsmc_wall_def w = dsmc_default_wall_def();
    w.restitution = 0.5;
    core_error err;
    assert_int_equal(dsmc_set_wall(s, DSMC_XHI, &w, &err), CORE_OK);
    dsmc_run_def r = dsmc_default_run_def();
    r.steps = 3;
    r.dt = 1.0;
    long done;
    assert_int_equal(dsmc_run(s, &r, &done, &err), CORE_ERR_UNSTABLE);
    assert_int_equal(done, 1);
    printf("  %s\n", err.msg);
    assert_non_null(strstr(err.msg, "step 0 (t = 1 s): particle 0 crossed the walls of the box "
                                    "more than 4 times in one step of dt = 1 s"));
    dsmc_get_particles(s, &p);
    for (size_t i = 0; i < 2; i++)
        assert_true(p.x[0][i] >= 0 && p.x[0][i] <= 1);
    dsmc_destroy(s);
}

/* A step far above the collision time is refused cell by cell before its candidates are drawn
 * (at most 100 per particle): the run stops at once, the velocities of those cells untouched. */
static void test_candidate_cap(void **state)
{
    (void)state;
    dsmc_scene *s = gas(2, 2000, 0.05, 20, 1.0, -1.0);
    dsmc_moments m0, m;
    dsmc_measure_moments(s, &m0);
    dsmc_run_def r = dsmc_default_run_def();
    r.steps = 3;
    r.dt = 1e6;
    long done;
    core_error err;
    assert_int_equal(dsmc_run(s, &r, &done, &err), CORE_ERR_UNSTABLE);
    assert_int_equal(done, 1);
    printf("  %s\n", err.msg);
    assert_non_null(strstr(err.msg, "over the limit of 100 per particle"));
    assert_non_null(strstr(err.msg, "dt = 1e+06 s is far above the collision time there"));
    dsmc_stats st;
    dsmc_get_stats(s, &st);
    assert_true(st.attempts == 0); /* every cell was over: nothing drawn */
    dsmc_measure_moments(s, &m);
    assert_true(fabs(m.kinetic_energy / m0.kinetic_energy - 1) < 1e-12); /* order of the sum */
    dsmc_destroy(s);
}

/* A cell past close packing stops the run after the step: 60 particles at rest in one 1 cm cell
 * of R = 1 mm disks, where 0.82 (1.2 cm)^2 / (pi R^2) = 37 fit. */
static void test_past_close_packing(void **state)
{
    (void)state;
    dsmc_scene_def d = dsmc_default_scene_def();
    d.hi[0] = d.hi[1] = 0.1;
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    double x[60], y[60], v[60] = {0};
    for (int i = 0; i < 60; i++) {
        x[i] = 0.0405 + 0.0001 * (i % 10);
        y[i] = 0.0705 + 0.0001 * (i / 10);
    }
    assert_int_equal(dsmc_add(s, 60, x, y, NULL, v, v, NULL, &err), CORE_OK);
    dsmc_run_def r = dsmc_default_run_def();
    r.steps = 5;
    r.dt = 1e-3;
    long done;
    assert_int_equal(dsmc_run(s, &r, &done, &err), CORE_ERR_UNSTABLE);
    assert_int_equal(done, 1);
    printf("  %s\n", err.msg);
    assert_non_null(strstr(err.msg, "step 0 (t = 0.001 s): the cell at x 0.04-0.05 m, y 0.07-0.08 "
                                    "m holds 60 particles, a packing fraction of 1.88 where at "
                                    "most 37 fit at the packing limit 0.82: a state past close "
                                    "packing"));
    assert_non_null(strstr(err.msg, "particles placed or moved there"));
    dsmc_destroy(s);
    /* 37 (what fits) runs on */
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    assert_int_equal(dsmc_add(s, 37, x, y, NULL, v, v, NULL, &err), CORE_OK);
    run(s, 5, 1e-3);
    dsmc_destroy(s);
}

/* 3D: a closed box with specular walls on every side at e = 1 keeps the energy and the
 * particles. */
static void test_walls_3d(void **state)
{
    (void)state;
    dsmc_scene_def d = dsmc_default_scene_def();
    d.dim = 3;
    d.radius = 1e-3;
    for (int k = 0; k < 3; k++) {
        d.lo[k] = 0;
        d.hi[k] = 0.1;
        d.cells[k] = 8;
        d.periodic[k] = false;
    }
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = 3000;
    f.temperature = dsmc_mass(s) * 1.0;
    assert_int_equal(dsmc_fill(s, &f, &err), CORE_OK);
    dsmc_moments m0, m;
    dsmc_measure_moments(s, &m0);
    run(s, 300, 2e-3);
    dsmc_measure_moments(s, &m);
    assert_true(fabs(m.kinetic_energy / m0.kinetic_energy - 1) < 1e-12);
    dsmc_particles p;
    dsmc_get_particles(s, &p);
    for (size_t i = 0; i < dsmc_count(s); i++)
        for (int k = 0; k < 3; k++)
            assert_true(p.x[k][i] >= 0 && p.x[k][i] <= 0.1);
    dsmc_stats st;
    dsmc_get_stats(s, &st);
    assert_true(st.wall_hits > 3000);
    dsmc_destroy(s);
}

/* The same seed gives the same bits on 1 and 2 threads: every cell has its own stream. */
static void test_threads(void **state)
{
    (void)state;
    enum { N = 60000 }; /* above the size where the kernels go parallel */
    double *out[2][4];
    for (int t = 0; t < 2; t++) {
        threads_set(t + 1);
        dsmc_scene *s = gas(2, N, 0.01, 10, 0.7, 1.0);
        run(s, 20, 1e-3);
        dsmc_particles p;
        dsmc_get_particles(s, &p);
        for (int k = 0; k < 2; k++) {
            out[t][k] = malloc(N * sizeof(double));
            out[t][k + 2] = malloc(N * sizeof(double));
            memcpy(out[t][k], p.x[k], N * sizeof(double));
            memcpy(out[t][k + 2], p.v[k], N * sizeof(double));
        }
        dsmc_destroy(s);
    }
    for (int k = 0; k < 4; k++) {
        assert_memory_equal(out[0][k], out[1][k], N * sizeof(double));
        free(out[0][k]);
        free(out[1][k]);
    }
    threads_set(threads_available());
}

/* The result does not depend on where the particles sit in the arrays, which the decomposition
 * over MPI ranks changes: a copy whose arrays are reversed (then sorted by cell only, so every
 * cell is in reverse order) gives the same bits, with diffuse walls drawing per particle. */
static dsmc_scene *walled_gas(int D, size_t N)
{
    dsmc_scene_def d = dsmc_default_scene_def();
    d.dim = D;
    d.radius = 1e-3;
    d.restitution = 0.8;
    double L = D == 2 ? 0.2 : 0.06;
    for (int k = 0; k < D; k++) {
        d.hi[k] = L;
        d.cells[k] = D == 2 ? 14 : 6;
    }
    d.periodic[D - 1] = false;
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    dsmc_wall_def w = dsmc_default_wall_def();
    w.kind = DSMC_WALL_DIFFUSE;
    w.temperature = dsmc_mass(s) * 2.0;
    assert_int_equal(dsmc_set_wall(s, 2 * (D - 1), &w, &err), CORE_OK);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = N;
    f.temperature = dsmc_mass(s) * 1.0;
    assert_int_equal(dsmc_fill(s, &f, &err), CORE_OK);
    return s;
}

static void test_layout(void **state)
{
    (void)state;
    for (int D = 2; D <= 3; D++) {
        enum { N = 3000 };
        dsmc_scene *a = walled_gas(D, N), *b = walled_gas(D, N);
        for (size_t i = 0, j = N - 1; i < j; i++, j--) {
            for (int k = 0; k < D; k++) {
                double t = b->x[k][i];
                b->x[k][i] = b->x[k][j];
                b->x[k][j] = t;
                t = b->v[k][i];
                b->v[k][i] = b->v[k][j];
                b->v[k][j] = t;
            }
            uint32_t c = b->cell[i];
            b->cell[i] = b->cell[j];
            b->cell[j] = c;
            c = b->id[i];
            b->id[i] = b->id[j];
            b->id[j] = c;
        }
        dsmc_sort_counted(b, NULL);
        size_t unordered = 0; /* cells not in identity order: the layouts differ */
        for (size_t i = 1; i < N; i++)
            unordered += b->cell[i] == b->cell[i - 1] && b->id[i] < b->id[i - 1];
        assert_true(unordered > N / 4);
        run(a, 30, 2e-3);
        run(b, 30, 2e-3);
        dsmc_stats sa, sb;
        dsmc_get_stats(a, &sa);
        dsmc_get_stats(b, &sb);
        assert_true(sa.collisions > 1000 && sa.wall_hits > 100);
        assert_true(sa.collisions == sb.collisions && sa.wall_hits == sb.wall_hits);
        for (int k = 0; k < D; k++) {
            assert_memory_equal(a->x[k], b->x[k], N * sizeof(double));
            assert_memory_equal(a->v[k], b->v[k], N * sizeof(double));
        }
        assert_memory_equal(a->id, b->id, N * sizeof(uint32_t));
        dsmc_destroy(a);
        dsmc_destroy(b);
    }
}

static void expect_create_error(dsmc_scene_def d, const char *text)
{
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_ERR_ARG);
    if (!strstr(err.msg, text))
        fail_msg("expected '%s' in '%s'", text, err.msg);
}

static void test_bad_input(void **state)
{
    (void)state;
    dsmc_scene_def d = dsmc_default_scene_def();
    d.restitution = 1.5;
    expect_create_error(d, "restitution must be in [0, 1], got 1.5");
    d = dsmc_default_scene_def();
    d.radius = -1;
    expect_create_error(d, "radius must be positive, got -1");
    d = dsmc_default_scene_def();
    d.mass = -2;
    expect_create_error(d, "mass must be positive, got -2");
    d = dsmc_default_scene_def();
    d.density = 0;
    expect_create_error(d, "density must be positive, got 0");
    d = dsmc_default_scene_def();
    d.cells[0] = 1000;
    expect_create_error(d, "cells along x are 0.001 m wide, smaller than a particle (diameter "
                           "0.002 m); use at most 500 cells");
    d = dsmc_default_scene_def();
    dsmc_scene *s;
    core_error err;
    assert_int_equal(dsmc_create(&d, &s, &err), CORE_OK);
    size_t cap = dsmc_capacity(s); /* 0.82 / (pi 1e-6) = 261014 */
    assert_int_equal(cap, (size_t)floor(0.82 / (PI * 1e-6)));
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = cap + 1;
    f.temperature = 1e-6;
    assert_int_equal(dsmc_fill(s, &f, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "the box holds at most 261014 at the packing limit"));
    dsmc_wall_def w = dsmc_default_wall_def();
    assert_int_equal(dsmc_set_wall(s, DSMC_YLO, &w, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "periodic axis"));
    dsmc_run_def r = dsmc_default_run_def();
    r.steps = 1;
    long done;
    assert_int_equal(dsmc_run(s, &r, &done, &err), CORE_ERR_ARG); /* dt = 0 */
    dsmc_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_elastic_2d), cmocka_unit_test(test_elastic_3d),
        cmocka_unit_test(test_haff_count), cmocka_unit_test(test_walls),
        cmocka_unit_test(test_walls_3d), cmocka_unit_test(test_long_flight),
        cmocka_unit_test(test_candidate_cap), cmocka_unit_test(test_past_close_packing), cmocka_unit_test(test_threads), cmocka_unit_test(test_layout),    cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
