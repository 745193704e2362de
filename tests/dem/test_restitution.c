/* Damping from a restitution (src/dem): the general dimensionless contact of every normal law
 * with viscous or Brilliantov damping against closed forms; Brilliantov damping: every pair,
 * whatever its radii, masses and materials, and a particle against a wall, rebounds from a
 * head-on impact at the impact velocity with the requested e. The dimensionless solve is checked against its own first-order limit
 * (re-derived here by quadrature), and the scenes against the requested e within the time-step
 * error (dt = contact time / 400 gives |e - e_asked| ~ 1e-4; tolerance 1e-3). No Lua. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "dem/dem.h"

/* First order in lambda: the energy lost on the elastic path is lambda * I with
 * I = int x^{1/2} x'^2 dtau over the contact = 2 xm^{3/2} int_0^1 u^{1/2} sqrt(1 - u^{5/2}) du,
 * xm = (5/4)^{2/5}; with E0 = 1/2, e = sqrt(1 - 2 lambda I) ~ 1 - lambda I. Substituting
 * u = 1 - w^2 removes the square-root endpoint singularity (Simpson, 2e5 intervals). */
static double first_order_I(void)
{
    const int n = 200000;
    double sum = 0;
    for (int k = 0; k <= n; k++) {
        double w = (double)k / n, u = 1 - w * w;
        double f = sqrt(u) * sqrt(1 - pow(u, 2.5)) * 2 * w;
        sum += f * (k == 0 || k == n ? 1 : k % 2 ? 4 : 2);
    }
    double xm = pow(1.25, 0.4);
    return 2 * pow(xm, 1.5) * sum / (3.0 * n);
}

static void test_dimensionless(void **state)
{
    (void)state;
    core_error err;
    assert_true(fabs(dem_brilliantov_restitution(0, true) - 1) < 1e-9); /* elastic */
    double I = first_order_I(), lam = 1e-4;
    double slope = (1 - dem_brilliantov_restitution(lam, true)) / lam;
    assert_true(fabs(slope / I - 1) < 1e-3);
    /* e falls with lambda; the solve inverts it; e = 1 is lambda = 0 */
    double prev = 1;
    for (double l = 0.01; l < 50; l *= 2) {
        double e = dem_brilliantov_restitution(l, true);
        assert_true(e < prev && e > 0);
        prev = e;
    }
    const double es[] = {0.05, 0.3, 0.7, 0.95, 0.999};
    for (size_t k = 0; k < sizeof es / sizeof *es; k++) {
        double l;
        assert_int_equal(dem_brilliantov_lambda(es[k], true, &l, &err), CORE_OK);
        assert_true(fabs(dem_brilliantov_restitution(l, true) - es[k]) < 1e-9);
    }
    double l1;
    assert_int_equal(dem_brilliantov_lambda(1, true, &l1, &err), CORE_OK);
    assert_true(l1 == 0);
    /* without the clip the force turns attractive near the end: more is lost for the same
     * lambda, so the same e needs less damping */
    double lc, ln;
    assert_int_equal(dem_brilliantov_lambda(0.5, true, &lc, &err), CORE_OK);
    assert_int_equal(dem_brilliantov_lambda(0.5, false, &ln, &err), CORE_OK);
    assert_true(ln < lc);
    assert_int_not_equal(dem_brilliantov_lambda(0, true, &l1, &err), CORE_OK);
    assert_int_not_equal(dem_brilliantov_lambda(1.5, true, &l1, &err), CORE_OK);
    assert_int_not_equal(dem_brilliantov_lambda(NAN, true, &l1, &err), CORE_OK);
}

typedef struct {
    int dim;
    double thickness, r1, r2, E1, E2, e, v_asked, v_run;
    int wall; /* particle 1 against a wall (of material E2 when E2 > 0, else its own) */
} impact;

/* Head-on impact at v_run; returns the measured restitution. */
static double collide(const impact *c)
{
    core_error err;
    dem_scene_def sd = dem_default_scene_def();
    sd.dim = c->dim;
    sd.thickness = c->thickness;
    for (int d = 0; d < 3; d++)
        sd.lo[d] = -0.01, sd.hi[d] = 0.01;
    dem_scene *s;
    assert_int_equal(dem_create(&sd, &s, &err), CORE_OK);
    dem_material m = dem_default_material();
    m.young = c->E1;
    int m1 = dem_add_material(s, &m, &err);
    m.young = c->E2 > 0 ? c->E2 : c->E1;
    int m2 = dem_add_material(s, &m, &err);
    dem_contact_def cd = dem_default_contact_def();
    cd.damping = DEM_DAMPING_BRILLIANTOV;
    cd.restitution = c->e;
    cd.impact_velocity = c->v_asked;
    /* before any particle: nothing is solved from the scene */
    assert_int_equal(dem_set_contact(s, &cd, &err), CORE_OK);
    const double gap = 1e-7, v = c->v_run;
    dem_particle_def p = {.radius = c->r1, .material = m1};
    if (c->wall) {
        dem_wall_def w = {.normal = {1, 0, 0}, .friction = -1, .material = c->E2 > 0 ? m2 : -1};
        assert_true(dem_add_wall(s, &w, &err) >= 0);
        p.x[0] = c->r1 + gap;
        p.v[0] = -v;
        assert_true(dem_add_particle(s, &p, &err) >= 0);
    } else {
        p.x[0] = -c->r1 - gap / 2;
        p.v[0] = v / 2;
        assert_true(dem_add_particle(s, &p, &err) >= 0);
        dem_particle_def q = {.x = {c->r2 + gap / 2}, .v = {-v / 2}, .radius = c->r2,
                              .material = m2};
        assert_true(dem_add_particle(s, &q, &err) >= 0);
    }
    dem_timestep ts;
    assert_int_equal(dem_timestep_info(s, v, &ts, &err), CORE_OK);
    dem_run_def rd = dem_default_run_def();
    rd.dt = ts.contact_time / 400;
    rd.steps = (long)ceil((gap / v + 6 * ts.contact_time) / rd.dt);
    assert_int_equal(dem_run(s, &rd, &err), CORE_OK);
    const double *vx = dem_velocities(s, 0);
    double e = c->wall ? vx[0] / v : (vx[1] - vx[0]) / v;
    dem_destroy(s);
    return e;
}

static void test_every_pair(void **state)
{
    (void)state;
    const double q = 30e9, E = 70e9;
    const impact cases[] = {
        /* dim thick r1 r2 E1 E2 e v v_run wall */
        {2, 0, 1e-3, 1e-3, q, q, 0.7, 1, 1, 0},          /* equal quartz disks */
        {2, 0, 0.7e-3, 1.3e-3, q, q, 0.7, 1, 1, 0},      /* radii (was 0.629) */
        {2, 0, 1e-3, 1e-3, q, E, 0.7, 1, 1, 0},          /* moduli (was 0.668) */
        {2, 0, 0.7e-3, 1.3e-3, q, E, 0.7, 1, 1, 0},      /* both (was 0.593) */
        {3, 0, 0.7e-3, 1.3e-3, q, E, 0.7, 1, 1, 0},      /* spheres */
        {2, 1e-3, 0.7e-3, 1.3e-3, q, E, 0.7, 1, 1, 0},   /* cylinders (m = rho pi r^2 t) */
        {2, 0, 0.7e-3, 0, q, 0, 0.7, 1, 1, 1},           /* a disk against a wall */
        {3, 0, 1.3e-3, 0, q, E, 0.7, 1, 1, 1},           /* a sphere against a stiffer wall */
        {2, 0, 0.7e-3, 1.3e-3, q, E, 0.05, 1, 1, 0},     /* nearly plastic */
        {2, 0, 0.7e-3, 1.3e-3, q, E, 1, 1, 1, 0},        /* elastic */
        {3, 0, 0.7e-3, 1.3e-3, q, E, 0.4, 0.05, 0.05, 0}, /* another impact velocity */
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        double e = collide(&cases[k]);
        print_message("case %zu: e = %.6f (asked %g)\n", k, e, cases[k].e);
        assert_true(fabs(e - cases[k].e) < 1e-3);
    }
    /* At other speeds e follows the Brilliantov law: higher when slower, lower when faster,
     * and the same for every pair (one lambda per speed). */
    impact slow = cases[3], fast = cases[3], slow_eq = cases[0];
    slow.v_run = slow_eq.v_run = 0.1;
    fast.v_run = 10;
    double es = collide(&slow), ef = collide(&fast), eq = collide(&slow_eq);
    print_message("v = 0.1: e = %.6f (equal pair %.6f); v = 10: e = %.6f\n", es, eq, ef);
    assert_true(es > 0.75 && ef < 0.65);
    assert_true(fabs(es - eq) < 1e-3);
}

/* The general dimensionless contact x'' = -x^beta - c x^a x' (dem_contact_restitution) against
 * closed forms re-derived here: the linear spring-dashpot (z = c/2) rebounds unclipped with
 * e = exp(-pi z / sqrt(1 - z^2)); clipped, the force k x + c x' falls to zero at w t = pi - 2 asin z
 * and the grains leave at that speed, e = exp(-z (pi - 2 asin z) / sqrt(1 - z^2)) (z < 1),
 * exp(-2 z acosh z / sqrt(z^2 - 1)) (z > 1) (Schwager & Poeschel 2007). Brilliantov's case
 * (beta = 3/2, a = 1/2) against the fixed-step solve above. */
#define PI 3.14159265358979323846

static double linear_clipped(double z)
{
    if (z < 1)
        return exp(-z * (PI - 2 * asin(z)) / sqrt(1 - z * z));
    return exp(-2 * z * acosh(z) / sqrt(z * z - 1));
}

static void test_general_law(void **state)
{
    (void)state;
    core_error err;
    const double zs[] = {0.01, 0.1, 0.25, 0.5, 0.9};
    for (size_t k = 0; k < sizeof zs / sizeof *zs; k++) {
        double z = zs[k], open = exp(-PI * z / sqrt(1 - z * z));
        assert_true(fabs(dem_contact_restitution(1, 0, 2 * z, false) / open - 1) < 1e-8);
        assert_true(fabs(dem_contact_restitution(1, 0, 2 * z, true) / linear_clipped(z) - 1) < 1e-8);
    }
    for (double z = 1.5; z < 200; z *= 4) /* overdamped: the clip still lets the grains part */
        assert_true(fabs(dem_contact_restitution(1, 0, 2 * z, true) / linear_clipped(z) - 1) < 1e-7);
    /* the clip matters at the percent level: e = 0.7 unclipped is 0.718 clipped */
    double z7 = -log(0.7) / sqrt(PI * PI + log(0.7) * log(0.7));
    assert_true(fabs(linear_clipped(z7) - 0.7181) < 1e-3);
    for (double lam = 0.05; lam < 5; lam *= 3)
        assert_true(fabs(dem_contact_restitution(1.5, 0.5, lam, true) -
                         dem_brilliantov_restitution(lam, true)) < 2e-6);
    /* elastic at c = 0; e falls with c for every law; the solve inverts it */
    const double betas[] = {1, 1.5, 2};
    for (size_t b = 0; b < 3; b++)
        for (int clip = 0; clip < 2; clip++)
            for (int a2 = 0; a2 < 2; a2++) {
                double beta = betas[b], a = 0.5 * a2;
                assert_true(fabs(dem_contact_restitution(beta, a, 0, clip) - 1) < 1e-9);
                double prev = 1;
                for (double c = 0.02; c < 0.6; c *= 2) {
                    double e = dem_contact_restitution(beta, a, c, clip);
                    assert_true(e < prev && e > 0);
                    prev = e;
                }
                const double es[] = {0.05, 0.5, 0.9, 0.999};
                for (size_t k = 0; k < 4; k++) {
                    double c;
                    assert_int_equal(dem_contact_damping(es[k], beta, a, clip, &c, &err), CORE_OK);
                    assert_true(fabs(dem_contact_restitution(beta, a, c, clip) - es[k]) < 1e-9);
                }
            }
    double c;
    assert_int_equal(dem_contact_damping(1, 2, 0, true, &c, &err), CORE_OK);
    assert_true(c == 0);
    assert_int_equal(dem_contact_damping(1e-3, 1.5, 0, true, &c, &err), CORE_OK); /* heavy damping */
    assert_true(fabs(dem_contact_restitution(1.5, 0, c, true) - 1e-3) < 1e-9);
    assert_int_not_equal(dem_contact_damping(0, 1.5, 0, true, &c, &err), CORE_OK);
    assert_int_not_equal(dem_contact_damping(1.5, 1.5, 0, true, &c, &err), CORE_OK);
    assert_int_not_equal(dem_contact_damping(NAN, 1.5, 0, true, &c, &err), CORE_OK);
    assert_int_not_equal(dem_contact_damping(1e-300, 1.5, 0, true, &c, &err), CORE_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_dimensionless),
                                       cmocka_unit_test(test_every_pair),
                                       cmocka_unit_test(test_general_law)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
