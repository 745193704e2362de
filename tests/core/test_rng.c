/* The random streams: published xoshiro256** outputs, splitmix64 seeding and jump-ahead against
 * an independent implementation (values derived in Python from the published algorithms), and
 * the statistics of the derived distributions. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "core/rng.h"

/* Blackman & Vigna's reference generator from state {1, 2, 3, 4}. */
static void test_reference_outputs(void **state)
{
    (void)state;
    rng r = {{1, 2, 3, 4}};
    assert_int_equal(rng_next(&r), 11520);
    assert_int_equal(rng_next(&r), 0);
    assert_int_equal(rng_next(&r), 1509978240);
    assert_int_equal(rng_next(&r), 1215971899390074240ULL);
}

static void test_seeding_and_streams(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 0, 0);
    assert_int_equal(r.s[0], 0xe220a8397b1dcdafULL); /* splitmix64(0), first output */
    assert_int_equal(r.s[3], 0xf88bb8a8724c81ecULL);
    assert_int_equal(rng_next(&r), 0x99ec5f36cb75f2b4ULL);

    rng_seed(&r, 42, 0);
    assert_int_equal(rng_next(&r), 0x15780b2e0c2ec716ULL);
    rng_seed(&r, 42, 1);
    assert_int_equal(rng_next(&r), 0x50086ef83cbf4f4aULL);
    assert_int_equal(rng_next(&r), 0xba285ec21347d703ULL);
    rng_seed(&r, 42, 2);
    assert_int_equal(rng_next(&r), 0x8677623ee7544e81ULL);
}

static void test_reproducible(void **state)
{
    (void)state;
    rng a, b;
    rng_seed(&a, 7, 3);
    rng_seed(&b, 7, 3);
    for (int i = 0; i < 1000; i++) {
        assert_int_equal(rng_next(&a), rng_next(&b));
        assert_true(rng_normal(&a) == rng_normal(&b));
    }
}

/* Mean 1/2 and variance 1/12 of U[0,1): with n = 10^6 the standard errors are 2.9e-4 and
 * 8.3e-5 (var of (u-1/2)^2 is 1/180); the tolerances are five of them. */
static void test_uniform_moments(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 1, 0);
    const int n = 1000000;
    double sum = 0, sum2 = 0, lo = 1, hi = 0;
    for (int i = 0; i < n; i++) {
        double u = rng_uniform(&r);
        sum += u;
        sum2 += (u - 0.5) * (u - 0.5);
        lo = fmin(lo, u);
        hi = fmax(hi, u);
    }
    assert_true(lo >= 0 && hi < 1);
    assert_true(fabs(sum / n - 0.5) < 5 * sqrt(1.0 / 12 / n));
    assert_true(fabs(sum2 / n - 1.0 / 12) < 5 * sqrt(1.0 / 180 / n));
}

/* Standard normal: mean 0, variance 1, kurtosis 3; standard errors 1e-3, 1.4e-3, 4.9e-3 for
 * n = 10^6 (var of x^2 is 2, of x^4 is 96). */
static void test_normal_moments(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 2, 0);
    const int n = 1000000;
    double m1 = 0, m2 = 0, m4 = 0;
    for (int i = 0; i < n; i++) {
        double x = rng_normal(&r);
        m1 += x;
        m2 += x * x;
        m4 += x * x * x * x;
    }
    m1 /= n, m2 /= n, m4 /= n;
    assert_true(fabs(m1) < 5e-3);
    assert_true(fabs(m2 - 1) < 5 * sqrt(2.0 / n));
    assert_true(fabs(m4 - 3) < 5 * sqrt(96.0 / n));
}

/* rng_below: a chi-square test over 10 bins (9 degrees of freedom; the 0.999 quantile is 27.9),
 * and a bound that is not a power of two so modulo bias would show. */
static void test_below_unbiased(void **state)
{
    (void)state;
    rng r;
    rng_seed(&r, 3, 0);
    enum { BINS = 10 };
    const int n = 1000000;
    long count[BINS] = {0};
    for (int i = 0; i < n; i++) {
        uint64_t k = rng_below(&r, BINS);
        assert_true(k < BINS);
        count[k]++;
    }
    double chi2 = 0, expect = (double)n / BINS;
    for (int k = 0; k < BINS; k++)
        chi2 += (count[k] - expect) * (count[k] - expect) / expect;
    assert_true(chi2 < 27.9);
    /* n = 3 * 2^62: a plain modulo would map [0, 2^62) twice and give P(k < n/2) = 0.625. */
    uint64_t big = 3ULL << 62, below_half = 0;
    for (int i = 0; i < 100000; i++)
        below_half += rng_below(&r, big) < big / 2;
    assert_true(fabs(below_half / 1e5 - 0.5) < 5 * 0.5 / sqrt(1e5));
}

/* Different streams of one seed are uncorrelated: sample correlation within 5/sqrt(n). */
static void test_streams_uncorrelated(void **state)
{
    (void)state;
    rng a, b;
    rng_seed(&a, 9, 0);
    rng_seed(&b, 9, 1);
    const int n = 200000;
    double sab = 0;
    for (int i = 0; i < n; i++)
        sab += (rng_uniform(&a) - 0.5) * (rng_uniform(&b) - 0.5);
    double corr = sab / n * 12; /* divide by the variance 1/12 */
    assert_true(fabs(corr) < 5 / sqrt((double)n));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_outputs), cmocka_unit_test(test_seeding_and_streams),
        cmocka_unit_test(test_reproducible),      cmocka_unit_test(test_uniform_moments),
        cmocka_unit_test(test_normal_moments),    cmocka_unit_test(test_below_unbiased),
        cmocka_unit_test(test_streams_uncorrelated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
