/* The cohesive contact laws of src/dem/cohesion.h without a scene: the JKR contact radius solved
 * from the overlap against bisection in long double, the landmarks of the JKR curve (the snap at
 * touch -4/3, the pull-off force -3/2 and the break -5/6 of pi Gamma R*, at the separation
 * -(3/4)(pi^2 Gamma^2 R/E^2)^{1/3}), the Hertz limit, and the liquid bridge's force and rupture. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "dem/cohesion.h"

static const double R = 2.4e-5, E = 7.25e8, G = 0.04;

/* u from y on the stable branch by bisection, in long double */
static long double u_ref(long double y)
{
    long double lo = COH_JKR_UC, hi = 2 + sqrtl(y > 0 ? y : 0);
    for (int it = 0; it < 200; it++) {
        long double mid = 0.5L * (lo + hi);
        if (mid * mid - sqrtl(mid) < y)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5L * (lo + hi);
}

static void jkr_radius(void **state)
{
    (void)state;
    double worst = 0;
    for (int k = 0; k <= 20000; k++) { /* y from y_c to 100, dense near y_c */
        const double t = k / 20000.0, y = COH_JKR_YC + (100 - COH_JKR_YC) * t * t * t;
        const double u = coh_jkr_u(y), ref = (double)u_ref(y);
        const double err = fabs(u - ref) / ref;
        worst = err > worst ? err : worst;
    }
    /* near y_c the root is ill-conditioned: |du| ~ sqrt(|dy|) */
    assert_true(worst < 1e-7);
    for (double y = -0.4; y < 100; y = y * 1.7 + 0.3) /* away from y_c: to rounding */
        assert_true(fabs(coh_jkr_u(y) - (double)u_ref(y)) <= 4e-16 * (double)u_ref(y));
}

static void jkr_landmarks(void **state)
{
    (void)state;
    const double pgr = COH_PI * G * R, A = cbrt(2 * COH_PI * G * R * R / E), D = A * A / R;
    double fh, fa, sq;
    coh_jkr(R, E, G, 0, &fh, &fa, &sq); /* touch: u = 1 */
    assert_true(fabs((fh - fa) / pgr + 4.0 / 3.0) < 1e-14);
    assert_true(fabs(sq - A / sqrt(R)) < 1e-14 * sq);
    const double dc = -coh_jkr_pulloff_distance(R, E, G);
    assert_true(fabs(dc / D - COH_JKR_YC) < 1e-14); /* the two forms of delta_c agree */
    coh_jkr(R, E, G, dc, &fh, &fa, &sq);
    assert_true(fabs((fh - fa) / pgr + 5.0 / 6.0) < 1e-6);
    double least = 0; /* the pull-off force: the least force along the branch */
    for (int k = 0; k <= 100000; k++) {
        coh_jkr(R, E, G, dc + (0 - dc) * k / 100000.0, &fh, &fa, &sq);
        least = fmin(least, (fh - fa) / pgr);
    }
    assert_true(fabs(least + 1.5) < 1e-9);
    coh_jkr(R, E, 0, 1e-7, &fh, &fa, &sq); /* no adhesion: Hertz */
    assert_true(fa == 0 && fabs(fh - 4.0 / 3.0 * E * sqrt(R) * 1e-7 * sqrt(1e-7)) < 1e-15 * fh);
}

static void capillary(void **state)
{
    (void)state;
    const double V = 1e-16, gc = 0.072 * cos(0.3), f0 = 4 * COH_PI * R * gc;
    assert_true(coh_capillary(R, V, gc, 0) == f0);
    assert_true(coh_capillary(R, V, gc, -1e-9) == f0);
    /* Rabinovich's form with d_sp, against the one the kernel evaluates */
    for (double S = 1e-9; S < 1e-5; S *= 1.5) {
        const double dsp = 0.5 * S * (-1 + sqrt(1 + V / (COH_PI * R * S * S)));
        const double ref = f0 / (1 + S / (2 * dsp));
        assert_true(fabs(coh_capillary(R, V, gc, S) - ref) < 1e-9 * f0);
    }
    assert_true(fabs(coh_capillary_rupture(V, 0.3) - 1.15 * cbrt(V)) < 1e-15 * cbrt(V));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(jkr_radius),
                                       cmocka_unit_test(jkr_landmarks),
                                       cmocka_unit_test(capillary)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
