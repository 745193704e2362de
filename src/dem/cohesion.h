/* Cohesive contacts: the DMT and JKR normal laws and the capillary bridge (laws.h), as functions
 * of one pair's R* = r_i r_j / (r_i + r_j), its stiffness k = 4/3 E* sqrt(R*) and work of
 * adhesion Gamma (J/m^2, twice LAMMPS's surface energy gamma). Included by forces.c and
 * neighbor.c; plain C, no scene. */
#ifndef GRAINLAB_DEM_COHESION_H
#define GRAINLAB_DEM_COHESION_H

#include <math.h>

#define COH_PI 3.14159265358979323846

/* JKR in its parametric form (Johnson, Kendall & Roberts 1971; Johnson, Contact Mechanics, 1985,
 * Sec. 5.5), a the contact radius:
 *   F = 4 E* a^3 / (3 R) - sqrt(8 pi Gamma E* a^3),   delta = a^2 / R - sqrt(2 pi Gamma a / E*).
 * In units a = A u, A^3 = 2 pi Gamma R^2 / E*, delta = D y with D = A^2 / R, F = pi Gamma R f:
 *   y = u^2 - sqrt(u),   f = 8/3 u^3 - 4 u^{3/2}.
 * At touch (y = 0) u = 1 and f = -4/3; the force is least, f = -3/2 (the pull-off force
 * 3/2 pi Gamma R), at u^{3/2} = 3/4. With the overlap imposed the contact is stable while
 * dy/du > 0, u > u_c = 4^{-2/3}, and breaks at y_c = u_c^2 - sqrt(u_c) = -3/4 4^{-1/3}, where
 * f = -5/6:
 *   delta_c = D y_c = -(3/4) (pi^2 Gamma^2 R / E*^2)^{1/3}
 * (fixed grips, Johnson 1985 Sec. 5.5; derived here from d delta / du = 0). */
#define COH_JKR_YC (-0.47247039371057745) /* -3/4 4^{-1/3} */
#define COH_JKR_UC 0.39685026299204984 /* 4^{-2/3} */

/* u from y >= y_c on the stable branch: Newton from u0 = 1 + sqrt(max(y, 0)), where
 * g(u) = u^2 - sqrt(u) - y >= 0 (g(1) = -y for y < 0; (1 + s)^2 - sqrt(1 + s) >= s^2 + 2 s + 1 -
 * (1 + s/2) for s = sqrt(y) >= 0). g is increasing and convex for u > u_c, so the iterates fall
 * monotonically onto the root and never leave [root, u0]: no bracket to guard. Quadratic
 * convergence except next to y_c (g' -> 0), where 60 steps bound the work. */
static inline double coh_jkr_u(double y)
{
    double u = 1 + sqrt(y > 0 ? y : 0);
    for (int it = 0; it < 60; it++) {
        const double su = sqrt(u), g = u * u - su - y, dg = 2 * u - 0.5 / su;
        if (!(g > 0) || !(dg > 0))
            break;
        const double step = g / dg;
        u -= step;
        if (step <= 1e-15 * u)
            break;
    }
    return u > COH_JKR_UC ? u : COH_JKR_UC;
}

/* The separation at which a JKR contact breaks, |delta_c| (> 0), for R*, E*, Gamma. */
static inline double coh_jkr_pulloff_distance(double R, double E, double G)
{
    return 0.75 * cbrt(COH_PI * COH_PI * G * G * R / (E * E));
}

/* One JKR contact at overlap delta (> delta_c): its Hertzian part fh = 4 E* a^3 / (3 R) and
 * adhesive part fa = sqrt(8 pi Gamma E* a^3) (F = fh - fa), and sq = a / sqrt(R), the sqrt(delta)
 * of a Hertz contact of the same radius (the damping's and the tangential spring's scale). */
static inline void coh_jkr(double R, double E, double G, double delta, double *fh, double *fa,
                           double *sq)
{
    if (!(G > 0)) { /* Hertz */
        const double s = sqrt(delta > 0 ? delta : 0);
        *fh = 4.0 / 3.0 * E * sqrt(R) * delta * s;
        *fa = 0;
        *sq = s;
        return;
    }
    const double A = cbrt(2 * COH_PI * G * R * R / E), D = A * A / R;
    const double u = coh_jkr_u(delta / D), u32 = u * sqrt(u), pgr = COH_PI * G * R;
    *fh = 8.0 / 3.0 * pgr * u * u * u;
    *fa = 4 * pgr * u32;
    *sq = A * u / sqrt(R);
}

/* The capillary bridge (Rabinovich, Esayanur & Moudgil 2005, Langmuir 21, 11251: the sphere-sphere
 * force without the term of the filling angle, their simplified form): between spheres of
 * harmonic-mean radius 2 R* at separation S >= 0, with a bridge of volume V, surface tension
 * gamma and contact angle theta,
 *   F = 4 pi R* gamma cos(theta) / (1 + S / (2 d_sp)),
 *   d_sp = S/2 (-1 + sqrt(1 + V / (pi R* S^2))),
 * that is F = 4 pi R* gamma cos(theta) (1 - S / sqrt(S^2 + V / (pi R*))): attractive, and
 * 4 pi R* gamma cos(theta) at contact (S <= 0). The bridge forms at touch and ruptures at
 * S_c = (1 + theta/2) V^{1/3} (Lian, Thornton & Adams 1993, as Rabinovich et al. use). */
static inline double coh_capillary(double R, double V, double gamma_cos, double S)
{
    const double f0 = 4 * COH_PI * R * gamma_cos;
    if (!(S > 0))
        return f0;
    return f0 * (1 - S / sqrt(S * S + V / (COH_PI * R)));
}

static inline double coh_capillary_rupture(double V, double theta)
{
    return (1 + 0.5 * theta) * cbrt(V);
}

#endif
