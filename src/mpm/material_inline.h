/* The constitutive update of material.c as inline functions, so that the step's stress update
 * (src/mpm/stress.c) inlines it; material.c's mpm_material_update and mpm_elastic_energy_density
 * call the same code. */
#ifndef GRAINLAB_MPM_MATERIAL_INLINE_H
#define GRAINLAB_MPM_MATERIAL_INLINE_H

#include <math.h>
#include <stdbool.h>

#include "mpm/mpm.h"

/* The in-plane block [a b; b c]: eigenvalues l1 >= l2 and, for the first eigenvector at angle
 * th, dir = {cos^2 th, sin^2 th, cos th sin th}, from cos 2th = (a - c) / 2r, sin 2th = b / r
 * (no trigonometric calls). */
static inline void eig2(double a, double b, double c, double *l1, double *l2, double dir[3])
{
    double mean = 0.5 * (a + c), half = 0.5 * (a - c);
    double r = sqrt(half * half + b * b);
    *l1 = mean + r;
    *l2 = mean - r;
    double c2t = r > 0 ? half / r : 1, s2t = r > 0 ? b / r : 0;
    dir[0] = 0.5 * (1 + c2t);
    dir[1] = 0.5 * (1 - c2t);
    dir[2] = 0.5 * s2t;
}

/* Principal log strains of b_e (eps_i = ln(lambda_i) / 2) and the principal directions; lz is
 * ln(b_e,zz) / 2, the caller's (cached) value. lz > -inf is b_e,zz > 0. */
static inline bool log_strains(const double be[3], double lz, double eps[3], double dir[3])
{
    double l1, l2;
    eig2(be[0], be[1], be[2], &l1, &l2, dir);
    if (!(l2 > 0) || !(lz > -INFINITY))
        return false;
    eps[0] = 0.5 * log(l1);
    eps[1] = 0.5 * log(l2);
    eps[2] = lz;
    return true;
}

/* Trial b_e = f b_e f^T (in plane; plane strain keeps the zz stretch): tr = {xx, xy, yy}. */
static inline void trial_be(const double f[4], const double be[3], double tr[3])
{
    const double b00 = be[0], b01 = be[1], b11 = be[2];
    double t00 = f[0] * b00 + f[1] * b01, t01 = f[0] * b01 + f[1] * b11;
    double t10 = f[2] * b00 + f[3] * b01, t11 = f[2] * b01 + f[3] * b11;
    tr[0] = t00 * f[0] + t01 * f[1];
    tr[1] = t00 * f[2] + t01 * f[3];
    tr[2] = t10 * f[2] + t11 * f[3];
}

/* The volumetric-deviatoric split of the principal log strains: *ev = tr eps, e = eps - ev / 3;
 * returns |e|^2. */
static inline double dev_split(const double eps[3], double *ev, double e[3])
{
    const double v = eps[0] + eps[1] + eps[2];
    double en2 = 0;
    for (int i = 0; i < 3; i++) {
        e[i] = eps[i] - v / 3;
        en2 += e[i] * e[i];
    }
    *ev = v;
    return en2;
}

/* The von Mises yield test's quick side: (2 G |e|)^2 below q^2 by more than any rounding (the
 * margin 1e-9) is elastic without the square root; the other points take the radial return's
 * test as written (material_return), so the decision is the same. Branch-free, for the step's
 * lanes. */
static inline bool within_yield(const mpm_material *m, double en2, double eps_p)
{
    const double k23 = sqrt(2.0 / 3.0), G2 = 2 * m->shear;
    const double q = k23 * (m->yield + m->hardening * eps_p);
    return G2 * G2 * en2 < q * q * (1 - 1e-9);
}

/* Kirchhoff stress tau = K ev + 2 G e in principal axes, back to the tensor along dir
 * (eig2's), and sigma = tau / J. */
static inline void stress_of(const mpm_material *m, double ev, const double e[3],
                             const double dir[3], double J, double sigma[4])
{
    const double K = m->bulk, G = m->shear;
    double tau[3];
    for (int i = 0; i < 3; i++)
        tau[i] = K * ev + 2 * G * e[i];
    const double c2 = dir[0], s2 = dir[1], csn = dir[2];
    const double inv_j = 1 / J;
    sigma[0] = (tau[0] * c2 + tau[1] * s2) * inv_j;
    sigma[1] = (tau[0] * s2 + tau[1] * c2) * inv_j;
    sigma[2] = (tau[0] - tau[1]) * csn * inv_j;
    sigma[3] = tau[2] * inv_j;
}

/* The update from the trial state on: tr (trial_be), its principal log strains eps and
 * directions dir (log_strains). Radial return for von Mises: f = |s| - sqrt(2/3) (yield + H
 * eps_p) with s = 2 G e. Writes be (the trial itself when elastic) and sigma; a plastic update
 * also sets *eps_p, *bzz and *lz = ln(*bzz) / 2 (the logarithm of the stored value, so a cache
 * rebuilt from b_e,zz holds the same bits). Returns whether the update was plastic. */
static inline bool material_return(const mpm_material *m, const double tr[3], const double eps[3],
                                   const double dir[3], double J, double be[3], double *bzz,
                                   double *lz, double *eps_p, double sigma[4])
{
    double ev, e[3];
    const double en2 = dev_split(eps, &ev, e);
    bool plastic = false;
    if (m->model == MPM_VONMISES && !within_yield(m, en2, *eps_p)) {
        const double G = m->shear, k23 = sqrt(2.0 / 3.0), G2 = 2 * G;
        const double q = k23 * (m->yield + m->hardening * *eps_p);
        const double en = sqrt(en2);
        double ftrial = G2 * en - q;
        if (en > 0 && ftrial > 0) {
            double dgamma = ftrial / (2 * G + 2.0 / 3.0 * m->hardening);
            double scale = 1 - dgamma / en;
            for (int i = 0; i < 3; i++)
                e[i] *= scale;
            *eps_p += k23 * dgamma;
            plastic = true;
        }
    }
    /* Back to tensors: b_e = sum exp(2 eps_i) n_i n_i. */
    if (plastic) {
        double ep[3];
        for (int i = 0; i < 3; i++)
            ep[i] = e[i] + ev / 3;
        const double c2 = dir[0], s2 = dir[1], csn = dir[2];
        double l1 = exp(2 * ep[0]), l2 = exp(2 * ep[1]);
        be[0] = l1 * c2 + l2 * s2;
        be[1] = (l1 - l2) * csn;
        be[2] = l1 * s2 + l2 * c2;
        *bzz = exp(2 * ep[2]);
        *lz = 0.5 * log(*bzz);
    } else {
        be[0] = tr[0];
        be[1] = tr[1];
        be[2] = tr[2];
    }
    stress_of(m, ev, e, dir, J, sigma);
    return plastic;
}

/* The granular continuum models' update (src/mpm/continuum.c), from the trial state on as
 * material_return, over a step of dt seconds (dt = 0: mu_i's quasi-static limit); *rate (may
 * be NULL) receives the plastic shear rate. Returns whether the update was plastic. */
bool mpm_continuum_return(const mpm_material *m, double dt, const double tr[3],
                          const double eps[3], const double dir[3], double J, double be[3],
                          double *bzz, double *lz, double *eps_p, double *rate, double sigma[4]);

/* material_return for every model: elastic and von Mises inline, the continuum models through
 * mpm_continuum_return. */
static inline bool material_point(const mpm_material *m, double dt, const double tr[3],
                                  const double eps[3], const double dir[3], double J, double be[3],
                                  double *bzz, double *lz, double *eps_p, double *rate,
                                  double sigma[4])
{
    if (m->model == MPM_ELASTIC || m->model == MPM_VONMISES)
        return material_return(m, tr, eps, dir, J, be, bzz, lz, eps_p, sigma);
    return mpm_continuum_return(m, dt, tr, eps, dir, J, be, bzz, lz, eps_p, rate, sigma);
}

/* mpm_material_step (mpm.h) with the out-of-plane stretch split off: be holds the in-plane
 * b_e (xx, xy, yy); *lz is ln(b_e,zz) / 2, which only a plastic update changes (the zz stretch
 * of plane strain is elastic-constant otherwise), so the caller caches it instead of taking a
 * logarithm of b_e,zz every step; a plastic update sets *bzz and *lz (material_return), an
 * elastic one leaves both. Returns -1 (inverted), 0 (elastic) or 1 (plastic). */
static inline int material_update_zz(const mpm_material *m, const double f[4], double dt,
                                     double be[3], double *bzz, double *lz, double *eps_p,
                                     double *rate, double J, double sigma[4])
{
    if (!(f[0] * f[3] - f[1] * f[2] > 0) || !(J > 0))
        return -1;
    double tr[3], eps[3], dir[3];
    trial_be(f, be, tr);
    if (!log_strains(tr, *lz, eps, dir))
        return -1;
    return material_point(m, dt, tr, eps, dir, J, be, bzz, lz, eps_p, rate, sigma);
}

/* mpm_material_step (mpm.h). */
static inline bool material_update(const mpm_material *m, const double f[4], double dt,
                                   double be[4], double *eps_p, double *rate, double J,
                                   double sigma[4])
{
    double lz = 0.5 * log(be[3]);
    return material_update_zz(m, f, dt, be, &be[3], &lz, eps_p, rate, J, sigma) >= 0;
}

#endif
