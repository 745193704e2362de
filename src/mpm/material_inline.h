/* The constitutive update of material.c as inline functions, so that the step's stress update
 * (src/mpm/step.c) inlines it; material.c's mpm_material_update and mpm_elastic_energy_density
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

/* Principal log strains of b_e (eps_i = ln(lambda_i) / 2) and the principal directions. */
static inline bool log_strains(const double be[4], double eps[3], double dir[3])
{
    double l1, l2;
    eig2(be[0], be[1], be[2], &l1, &l2, dir);
    if (!(l2 > 0) || !(be[3] > 0))
        return false;
    eps[0] = 0.5 * log(l1);
    eps[1] = 0.5 * log(l2);
    eps[2] = 0.5 * log(be[3]);
    return true;
}

/* mpm_material_update (mpm.h). */
static inline bool material_update(const mpm_material *m, const double f[4], double be[4],
                                   double *eps_p, double J, double sigma[4])
{
    if (!(f[0] * f[3] - f[1] * f[2] > 0) || !(J > 0))
        return false;
    /* Trial b_e = f b_e f^T (in plane; plane strain keeps the zz stretch). */
    const double b00 = be[0], b01 = be[1], b11 = be[2];
    double t00 = f[0] * b00 + f[1] * b01, t01 = f[0] * b01 + f[1] * b11;
    double t10 = f[2] * b00 + f[3] * b01, t11 = f[2] * b01 + f[3] * b11;
    double tr[4] = {t00 * f[0] + t01 * f[1], t00 * f[2] + t01 * f[3], t10 * f[2] + t11 * f[3],
                    be[3]};
    double eps[3], dir[3];
    if (!log_strains(tr, eps, dir))
        return false;
    const double K = m->bulk, G = m->shear;
    double ev = eps[0] + eps[1] + eps[2], e[3], en = 0;
    for (int i = 0; i < 3; i++) {
        e[i] = eps[i] - ev / 3;
        en += e[i] * e[i];
    }
    en = sqrt(en);
    bool plastic = false;
    if (m->model == MPM_VONMISES && en > 0) {
        /* Radial return: f = |s| - sqrt(2/3) (yield + H eps_p) with s = 2 G e. */
        const double k23 = sqrt(2.0 / 3.0);
        double ftrial = 2 * G * en - k23 * (m->yield + m->hardening * *eps_p);
        if (ftrial > 0) {
            double dgamma = ftrial / (2 * G + 2.0 / 3.0 * m->hardening);
            double scale = 1 - dgamma / en;
            for (int i = 0; i < 3; i++)
                e[i] *= scale;
            *eps_p += k23 * dgamma;
            plastic = true;
        }
    }
    double tau[3];
    for (int i = 0; i < 3; i++) {
        eps[i] = e[i] + ev / 3;
        tau[i] = K * ev + 2 * G * e[i];
    }
    /* Back to tensors: b_e = sum exp(2 eps_i) n_i n_i (the trial itself when elastic), tau
     * likewise; sigma = tau / J. */
    const double c2 = dir[0], s2 = dir[1], csn = dir[2];
    if (plastic) {
        double l1 = exp(2 * eps[0]), l2 = exp(2 * eps[1]);
        be[0] = l1 * c2 + l2 * s2;
        be[1] = (l1 - l2) * csn;
        be[2] = l1 * s2 + l2 * c2;
        be[3] = exp(2 * eps[2]);
    } else {
        be[0] = tr[0];
        be[1] = tr[1];
        be[2] = tr[2];
    }
    double inv_j = 1 / J;
    sigma[0] = (tau[0] * c2 + tau[1] * s2) * inv_j;
    sigma[1] = (tau[0] * s2 + tau[1] * c2) * inv_j;
    sigma[2] = (tau[0] - tau[1]) * csn * inv_j;
    sigma[3] = tau[2] * inv_j;
    return true;
}

#endif
