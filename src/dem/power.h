/* x^a for one fixed exponent 0 < a <= 1 and 0 <= x < 1, within 3 ulp (libm's pow: 1) and about
 * 3 times faster: the regularised Coulomb law (Padbidri Eq. 2.18, f = mu f_n (s / v_R)^(1/c))
 * evaluates it at every sticking contact every step, and libm's pow was 24% of a biaxial step.
 *
 * With x = 2^e (1 + f), f in [0, 1): x^a = 2^(e a) * m0^a * (1 + t)^a, where m0 is the centre of
 * the 1/256-wide bin of 1 + f holding x and t = (1 + f) / m0 - 1, |t| < 1/513. 2^(e a) for
 * e = 0 .. -DEM_POW_EMIN and m0^a are tabulated (in long double) when the exponent is set;
 * (1 + t)^a is its binomial series to t^6 (truncation below 1e-19). Other x (tiny, subnormal,
 * >= 1, NaN) go to pow. Checked against x^a in long double in tests/dem/test_power.c. */
#ifndef GRAINLAB_DEM_POWER_H
#define GRAINLAB_DEM_POWER_H

#include <math.h>
#include <stdint.h>
#include <string.h>

enum { DEM_POW_BINS = 256, DEM_POW_EMIN = 100 };

typedef struct {
    double a;                       /* the exponent; 0 when unset (then pow is used) */
    double scale[DEM_POW_EMIN + 1]; /* 2^(-e a), e = 0 .. DEM_POW_EMIN */
    double root[DEM_POW_BINS];      /* m0^a for each bin */
    double inv[DEM_POW_BINS];       /* 1 / m0 */
    double c[6];                    /* binomial coefficients C(a, k), k = 1 .. 6 */
} dem_power;

/* Fills the tables for exponent a (0 < a <= 1). */
void dem_power_init(dem_power *p, double a);

static inline double dem_power_eval(const dem_power *p, double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    const int e = (int)((u >> 52) & 0x7ff) - 1023; /* x >= 0: no sign bit when x is in range */
    if (p->a == 1)
        return x;
    if (!(p->a > 0) || e >= 0 || e < -DEM_POW_EMIN || (u >> 63))
        return pow(x, p->a);
    const int k = (int)((u >> 44) & (DEM_POW_BINS - 1));
    uint64_t mb = (u & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL; /* 1 + f */
    double m;
    memcpy(&m, &mb, sizeof m);
    const double t = m * p->inv[k] - 1;
    const double *c = p->c;
    const double t2 = t * t; /* Estrin's scheme: a short dependency chain */
    const double s1 = t * ((c[0] + t * c[1]) + t2 * ((c[2] + t * c[3]) + t2 * (c[4] + t * c[5])));
    const double r = p->root[k];
    return p->scale[-e] * (r + r * s1); /* (1 + t)^a - 1 = s1 is small: one rounding fewer */
}

#endif
