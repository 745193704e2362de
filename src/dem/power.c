/* Tables for dem_power_eval (see power.h). */
#include "dem/power.h"

void dem_power_init(dem_power *p, double a)
{
    memset(p, 0, sizeof *p);
    if (!(a > 0 && a <= 1))
        return; /* a stays 0: dem_power_eval falls back to pow */
    p->a = a;
    /* In long double: e * a rounded to double would cost up to 6e-16 of 2^(e a) at e = -100. */
    for (int e = 0; e <= DEM_POW_EMIN; e++)
        p->scale[e] = (double)powl(2.0L, -(long double)e * a);
    for (int k = 0; k < DEM_POW_BINS; k++) {
        double m0 = 1 + (k + 0.5) / DEM_POW_BINS;
        p->root[k] = (double)powl(m0, a);
        p->inv[k] = 1 / m0;
    }
    double ck = 1;
    for (int k = 1; k <= 6; k++) {
        ck *= (a - (k - 1)) / k;
        p->c[k - 1] = ck;
    }
}
