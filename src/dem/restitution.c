/* Damping from a restitution, for every normal law with viscous or Brilliantov damping. In
 * lengths d* = (m* v^2 / k)^{1/(beta+1)} and times d* / v, the head-on contact m* d'' = -k d^beta
 * - D(d) d' at impact speed v is x'' = -x^beta - c x^a x', x(0) = 0, x'(0) = 1, with
 *   viscous (D = gamma):              a = 0,   c = gamma d* / (m* v),
 *   brilliantov (D = T k d^{1/2}):    a = 1/2, c = T v / d*            (beta = 3/2: lambda, dem.h),
 * so e depends on the pair and the speed only through c. c(e) is solved once per restitution (a
 * scene's materials, or its s:contact restitution) and scaled per pair when the list is built
 * (neighbor.c). With clip the force is never attractive: the grains part when it falls to zero
 * while they separate, and leave at that speed (for the linear law this is the closed form of
 * Schwager & Poeschel 2007, e = exp(-z (pi - 2 asin z) / sqrt(1 - z^2)), z = c/2). At the end,
 * Brilliantov's lambda(e) by a fixed-step RK4 (dem.h) and the damping a pair or wall contact
 * takes (dem_pair_damping). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem/dem_internal.h"

typedef struct contact_ode {
    double beta, a, c;
    bool clip;
} contact_ode;

static double power_of(double x, double p)
{
    return p == 0 ? 1 : p == 0.5 ? sqrt(x) : p == 1 ? x : p == 1.5 ? x * sqrt(x) : p == 2 ? x * x
                                                                                   : pow(x, p);
}

/* The force on the dimensionless contact, repulsive positive, before the clip. */
static double ode_force(const contact_ode *o, double x, double u)
{
    double xx = x > 0 ? x : 0;
    return power_of(xx, o->beta) + o->c * power_of(xx, o->a) * u;
}

static void ode_rhs(const contact_ode *o, const double y[2], double dy[2])
{
    double f = ode_force(o, y[0], y[1]);
    dy[0] = y[1];
    dy[1] = o->clip && f < 0 ? 0 : -f;
}

/* One Dormand-Prince 5(4) step of length h from y; returns the error estimate against the
 * tolerance (<= 1: accept). */
static double dopri_step(const contact_ode *o, const double y[2], double h, double out[2])
{
    static const double a21 = 1.0 / 5, a31 = 3.0 / 40, a32 = 9.0 / 40, a41 = 44.0 / 45,
                        a42 = -56.0 / 15, a43 = 32.0 / 9, a51 = 19372.0 / 6561,
                        a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729,
                        a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                        a64 = 49.0 / 176, a65 = -5103.0 / 18656, b1 = 35.0 / 384,
                        b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784, b6 = 11.0 / 84,
                        e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
                        e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;
    double k1[2], k2[2], k3[2], k4[2], k5[2], k6[2], k7[2], t[2];
    ode_rhs(o, y, k1);
    for (int i = 0; i < 2; i++)
        t[i] = y[i] + h * a21 * k1[i];
    ode_rhs(o, t, k2);
    for (int i = 0; i < 2; i++)
        t[i] = y[i] + h * (a31 * k1[i] + a32 * k2[i]);
    ode_rhs(o, t, k3);
    for (int i = 0; i < 2; i++)
        t[i] = y[i] + h * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i]);
    ode_rhs(o, t, k4);
    for (int i = 0; i < 2; i++)
        t[i] = y[i] + h * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i]);
    ode_rhs(o, t, k5);
    for (int i = 0; i < 2; i++)
        t[i] = y[i] + h * (a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i] + a65 * k5[i]);
    ode_rhs(o, t, k6);
    for (int i = 0; i < 2; i++)
        out[i] = y[i] + h * (b1 * k1[i] + b3 * k3[i] + b4 * k4[i] + b5 * k5[i] + b6 * k6[i]);
    ode_rhs(o, out, k7);
    double err = 0;
    for (int i = 0; i < 2; i++) {
        double ei = h * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i] + e6 * k6[i] +
                         e7 * k7[i]);
        double scale = 1e-13 + 1e-11 * fmax(fabs(y[i]), fabs(out[i]));
        err = fmax(err, fabs(ei) / scale);
    }
    return err;
}

/* The contact is over: separating, and (clip) the force has fallen to zero, after which the
 * grains fly apart at constant speed, or (no clip) the overlap is gone. */
static int parted(const contact_ode *o, const double y[2])
{
    if (y[1] >= 0)
        return 0;
    if (y[0] <= 0)
        return 1;
    return o->clip && ode_force(o, y[0], y[1]) <= 0;
}

double dem_contact_restitution(double beta, double a, double c, bool clip)
{
    const contact_ode o = {beta, a, c, clip};
    double y[2] = {0, 1}, h = 1e-3, t = 0;
    /* A contact lasts about 3 (elastic) to a few hundred (heavily damped, unclipped) units;
     * one that has not ended by t = 1000 is taken as never ending (e = 0). */
    for (int it = 0; it < 200000 && t < 1000; it++) {
        double yn[2], err = dopri_step(&o, y, h, yn);
        if (!(err <= 1)) {
            h *= fmax(0.2, 0.9 * pow(err, -0.2));
            continue;
        }
        if (parted(&o, yn)) { /* the end within this step: bisect the step's length onto it */
            double lo = 0, hi = h, ye[2];
            for (int k = 0; k < 60; k++) {
                double mid = 0.5 * (lo + hi), ym[2];
                dopri_step(&o, y, mid, ym);
                if (parted(&o, ym))
                    hi = mid;
                else
                    lo = mid;
            }
            dopri_step(&o, y, hi, ye);
            return -ye[1];
        }
        y[0] = yn[0];
        y[1] = yn[1];
        t += h;
        h *= fmin(5, 0.9 * pow(fmax(err, 1e-10), -0.2));
    }
    return 0;
}

core_status dem_contact_damping(double e, double beta, double a, bool clip, double *c,
                                core_error *err)
{
    if (!(e > 0 && e <= 1))
        return core_fail(err, CORE_ERR_ARG, "restitution must be in (0, 1], got %g", e);
    if (e == 1) {
        *c = 0;
        return CORE_OK;
    }
    /* e falls monotonically with c: bracket, then regula falsi (Illinois) on the bracket. */
    double lo = 0, hi = 1, flo = 1 - e, fhi = dem_contact_restitution(beta, a, hi, clip) - e;
    while (fhi > 0) {
        lo = hi, flo = fhi;
        hi *= 2;
        if (hi > 1e9)
            return core_fail(err, CORE_ERR_ARG, "restitution %g is below what the damping reaches",
                             e);
        fhi = dem_contact_restitution(beta, a, hi, clip) - e;
    }
    int side = 0;
    for (int it = 0; it < 200 && hi - lo > 1e-13 * hi; it++) {
        double mid = (lo * fhi - hi * flo) / (fhi - flo);
        if (!(mid > lo && mid < hi)) /* rounding: fall back on bisection */
            mid = 0.5 * (lo + hi);
        double fm = dem_contact_restitution(beta, a, mid, clip) - e;
        if (fm == 0) {
            lo = hi = mid;
            break;
        }
        if (fm > 0) {
            lo = mid, flo = fm;
            if (side == 1)
                fhi *= 0.5;
            side = 1;
        } else {
            hi = mid, fhi = fm;
            if (side == -1)
                flo *= 0.5;
            side = -1;
        }
        if (fabs(fm) < 1e-14)
            lo = hi = mid;
    }
    *c = 0.5 * (lo + hi);
    return CORE_OK;
}

int dem_damping_solved(const dem_contact_def *c)
{
    if (c->restitution >= 0) /* s:contact's restitution: one coefficient (scene.c) */
        return 0;
    if (c->damping == DEM_DAMPING_VISCOUS) /* the unclipped linear spring has a closed form */
        return c->gamma_n < 0 && (c->clip || dem_law_beta(c) != 1);
    if (c->damping == DEM_DAMPING_BRILLIANTOV)
        return c->damping_time < 0;
    return 0;
}

/* The coefficient a restitution e gives under law c: viscous, the dimensionless c(e);
 * Brilliantov, lambda(e) v^{-1/5}, so that a pair's T is one power of its m* / K (neighbor.c). */
core_status dem_damping_coefficient(const dem_contact_def *c, double e, double *out,
                                    core_error *err)
{
    const int brill = c->damping == DEM_DAMPING_BRILLIANTOV;
    double beta = dem_law_beta(c), x;
    core_status st =
        dem_contact_damping(e, beta, dem_damping_exponent(c->damping), c->clip, &x, err);
    if (st != CORE_OK)
        return st;
    *out = brill ? x * pow(c->impact_velocity, -0.2) : x;
    return CORE_OK;
}

/* The coefficient of each of n materials under law c into out (the materials' restitution; the
 * same restitution is solved once). */
core_status dem_damping_table(const dem_contact_def *c, const dem_material *mats, int n,
                              double *out, core_error *err)
{
    for (int k = 0; k < n; k++) {
        out[k] = 0;
        if (!dem_damping_solved(c))
            continue;
        int same = 0;
        while (same < k && mats[same].restitution != mats[k].restitution)
            same++;
        if (same < k) {
            out[k] = out[same];
            continue;
        }
        core_status st = dem_damping_coefficient(c, mats[k].restitution, &out[k], err);
        if (st != CORE_OK)
            return st;
    }
    return CORE_OK;
}

/* ---- Brilliantov damping time from a restitution ------------------------------------------ */
/* x'' = -x^{3/2} - lambda x^{1/2} x', x(0) = 0, x'(0) = 1 (lengths in d* = (m v^2/K)^{2/5}, times
 * in units of d* / v), integrated with RK4 until x returns to 0. With clip the force is never
 * attractive, so once it vanishes the particles separate at constant speed. */
double dem_brilliantov_restitution(double lambda, bool clip)
{
    const double h = 2e-4; /* of a contact lasting about 3.2 */
    double x = 0, u = 1;
    for (int step = 0; step < 1000000; step++) {
        double kx[4], ku[4], xs = x, us = u;
        for (int stage = 0; stage < 4; stage++) {
            double xx = xs > 0 ? xs : 0;
            double a = -xx * sqrt(xx) - lambda * sqrt(xx) * us;
            if (clip && a > 0)
                a = 0; /* no attraction */
            kx[stage] = us;
            ku[stage] = a;
            double c = stage < 2 ? 0.5 * h : h;
            if (stage < 3) {
                xs = x + c * kx[stage];
                us = u + c * ku[stage];
            }
        }
        double xn = x + h / 6 * (kx[0] + 2 * kx[1] + 2 * kx[2] + kx[3]);
        double un = u + h / 6 * (ku[0] + 2 * ku[1] + 2 * ku[2] + ku[3]);
        if (step > 0 && xn <= 0)
            return -un;
        x = xn;
        u = un;
    }
    return 0; /* overdamped: never came back */
}

core_status dem_brilliantov_lambda(double e, bool clip, double *lambda, core_error *err)
{
    if (!(e > 0 && e <= 1))
        return core_fail(err, CORE_ERR_ARG, "restitution must be in (0, 1], got %g", e);
    if (e == 1) {
        *lambda = 0;
        return CORE_OK;
    }
    /* e falls monotonically with lambda: bracket, then bisect. */
    double lo = 0, hi = 1;
    while (dem_brilliantov_restitution(hi, clip) > e) {
        lo = hi;
        hi *= 2;
        if (hi > 1e6)
            return core_fail(err, CORE_ERR_ARG,
                             "restitution %g is below what brilliantov damping reaches", e);
    }
    for (int it = 0; it < 60 && hi - lo > 1e-12 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        if (dem_brilliantov_restitution(mid, clip) > e)
            lo = mid;
        else
            hi = mid;
    }
    *lambda = 0.5 * (lo + hi);
    return CORE_OK;
}

core_status dem_brilliantov_time(double e, double m_eff, double K, double v, double *T,
                                 core_error *err)
{
    if (!(m_eff > 0) || !(K > 0) || !(v > 0))
        return core_fail(err, CORE_ERR_ARG, "mass, stiffness and speed must be > 0");
    double lambda;
    core_status st = dem_brilliantov_lambda(e, true, &lambda, err);
    if (st != CORE_OK)
        return st;
    *T = lambda * pow(m_eff / K, 0.4) * pow(v, -0.2);
    return CORE_OK;
}

core_status dem_pair_damping(const dem_scene *s, size_t i, size_t j, int wall, double *out,
                             core_error *err)
{
    if (i >= s->n || (wall < 0 && j >= s->n))
        return core_fail(err, CORE_ERR_ARG, "particle %zu out of range (the scene has %zu)",
                         (i >= s->n ? i : j) + 1, s->n);
    if (wall >= s->nwalls)
        return core_fail(err, CORE_ERR_ARG, "wall %d out of range (the scene has %d)", wall + 1,
                         s->nwalls);
    if (wall < 0 && i == j)
        return core_fail(err, CORE_ERR_ARG, "particle %zu paired with itself", i + 1);
    double k, mu;
    if (wall >= 0)
        dem_wall_parameters(s, &s->walls[wall], i, &k, out, &mu);
    else
        dem_pair_parameters((dem_scene *)s, i, j, &k, out, &mu);
    return CORE_OK;
}
