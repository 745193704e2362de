/* dem_power_eval (src/dem/power.h), the x^a of the regularised Coulomb law, against x^a in long
 * double: log-uniform and uniform x in (0, 1) for several exponents; against libm's pow at the
 * bin edges; and the inputs it hands to pow (0, subnormal, tiny, >= 1, NaN). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "core/rng.h"
#include "dem/power.h"

/* The largest relative error over 200000 x; of libm's pow instead when p is NULL. */
static double worst_rel(const dem_power *p, double a, int log_uniform)
{
    rng r;
    rng_seed(&r, 7, 0);
    double worst = 0;
    for (int i = 0; i < 200000; i++) {
        double u = rng_uniform(&r);
        double x = log_uniform ? exp2(-100 * u) : u;
        /* the exact x^a (long double), a being the double exponent itself */
        double ref = (double)powl((long double)x, (long double)a);
        double got = p ? dem_power_eval(p, x) : pow(x, a);
        double rel = ref > 0 ? fabs(got - ref) / ref : fabs(got);
        if (rel > worst)
            worst = rel;
    }
    return worst;
}

static void test_against_pow(void **state)
{
    (void)state;
    const double as[] = {0.1, 1.0 / 3, 0.5, 0.05, 1.0, 1.0 / 7, 0.9};
    for (size_t k = 0; k < sizeof as / sizeof *as; k++) {
        dem_power p;
        dem_power_init(&p, as[k]);
        double w1 = worst_rel(&p, as[k], 1), w2 = worst_rel(&p, as[k], 0);
        print_message("a = %.4f: largest relative error %.2e (log-uniform x), %.2e (uniform x); "
                      "libm pow %.2e, %.2e\n",
                      as[k], w1, w2, worst_rel(NULL, as[k], 1), worst_rel(NULL, as[k], 0));
        assert_true(w1 <= 6e-16); /* 3 ulp */
        assert_true(w2 <= 6e-16);
    }
}

static void test_edges(void **state)
{
    (void)state;
    dem_power p;
    dem_power_init(&p, 0.1);
    /* bin edges and ends of the mantissa range */
    for (int k = 0; k <= DEM_POW_BINS; k++) {
        double m = 1 + (double)k / DEM_POW_BINS;
        for (int e = 1; e <= 3; e++) {
            double x = ldexp(m, -e);
            if (x >= 1)
                continue;
            double xs[3] = {nextafter(x, 0), x, nextafter(x, 1)};
            for (int q = 0; q < 3; q++)
                assert_true(fabs(dem_power_eval(&p, xs[q]) - pow(xs[q], 0.1)) <=
                            4e-16 * pow(xs[q], 0.1));
        }
    }
    /* the inputs that go to pow */
    assert_true(dem_power_eval(&p, 0.0) == 0.0);
    assert_true(dem_power_eval(&p, 1e-310) == pow(1e-310, 0.1));
    assert_true(dem_power_eval(&p, ldexp(1, -200)) == pow(ldexp(1, -200), 0.1));
    assert_true(dem_power_eval(&p, 1.0) == 1.0);
    assert_true(dem_power_eval(&p, 3.0) == pow(3.0, 0.1));
    assert_true(isnan(dem_power_eval(&p, NAN)));
    assert_true(dem_power_eval(&p, nextafter(1, 0)) <= 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_against_pow),
                                       cmocka_unit_test(test_edges)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
