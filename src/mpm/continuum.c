/* The granular continuum models of mpm.material: Drucker-Prager (matched to Mohr-Coulomb in
 * plane strain, non-associated, tension cut-off at the cone's apex) and the mu(I) rheology of Jop,
 * Forterre & Pouliquen (2006) with the disconnected state of Dunatunga & Kamrin (2015). Both
 * return in the principal logarithmic strains of the trial elastic stretch, as von Mises does
 * (material_inline.h): Kirchhoff stress tau = K ev I + 2 G e, with ev = tr(ln V_e) and e its
 * deviator, so that sqrt(J2) = sqrt(2) G |e| and p = -K ev. The plastic shear strain of a step,
 * dgamma, is the drop of sqrt(J2) over G (the engineering shear strain in simple shear); eps_p
 * grows by dgamma / sqrt(3), the von Mises equivalent of that shear. */
#include <math.h>

#include "mpm/material_inline.h"

/* b_e = sum exp(2 eps_i) n_i n_i from the principal log strains eps = e + ev / 3 along dir
 * (eig2's), with the zz stretch and its cached logarithm. */
static void be_of(const double e[3], double ev, const double dir[3], double be[3], double *bzz,
                  double *lz)
{
    double ep[3];
    for (int i = 0; i < 3; i++)
        ep[i] = e[i] + ev / 3;
    const double c2 = dir[0], s2 = dir[1], csn = dir[2];
    const double l1 = exp(2 * ep[0]), l2 = exp(2 * ep[1]);
    be[0] = l1 * c2 + l2 * s2;
    be[1] = (l1 - l2) * csn;
    be[2] = l1 * s2 + l2 * c2;
    *bzz = exp(2 * ep[2]);
    *lz = 0.5 * log(*bzz);
}

/* Drucker-Prager, f = sqrt(J2) - eta p - xi c J (the Kirchhoff form of sqrt(J2) - eta p - xi c
 * in Cauchy stress), potential sqrt(J2) - etabar p: the return to the cone (de Souza Neto, Peric
 * & Owen 2008, Sec. 8.3.3, in principal log strains) takes dgamma = f / (G + K eta etabar),
 * lowers sqrt(J2) by G dgamma and dilates by etabar dgamma; a trial state whose cone return
 * would pass the axis (sqrt(J2) < 0) returns to the apex instead, the isotropic tension p =
 * -xi c J / eta (zero stress without cohesion): the tension cut-off. Returns whether plastic. */
static bool dp_return(const mpm_material *m, const double tr[3], const double eps[3],
                      const double dir[3], double J, double be[3], double *bzz, double *lz,
                      double *dgamma, double sigma[4])
{
    double ev, e[3];
    const double en = sqrt(dev_split(eps, &ev, e));
    const double G = m->shear, K = m->bulk, eta = m->dp[0], xi = m->dp[1], etab = m->dp[2];
    const double q = sqrt(2.0) * G * en, p = -K * ev, cJ = m->cohesion * J;
    const double f = q - eta * p - xi * cJ;
    *dgamma = 0;
    if (!(f > 0)) {
        be[0] = tr[0];
        be[1] = tr[1];
        be[2] = tr[2];
        stress_of(m, ev, e, dir, J, sigma);
        return false;
    }
    const double dl = f / (G + K * eta * etab);
    if (q - G * dl >= 0) { /* the cone (q > 0 here: dl > 0) */
        const double scale = 1 - G * dl / q;
        for (int i = 0; i < 3; i++)
            e[i] *= scale;
        ev -= etab * dl;
        *dgamma = dl;
    } else { /* the apex */
        for (int i = 0; i < 3; i++)
            e[i] = 0;
        ev = xi * cJ / (eta * K);
        *dgamma = q / G;
    }
    be_of(e, ev, dir, be, bzz, lz);
    stress_of(m, ev, e, dir, J, sigma);
    return true;
}

/* mu(I) (Dunatunga & Kamrin 2015, Sec. 3, with the Hencky law of this file): a point dilated to
 * J >= 1 (its density at or below the close-packed one) is disconnected, stress-free, its
 * elastic strain reset; otherwise the pressure follows the density, ev = ln J, and the shear
 * is elastic while sqrt(J2) <= mu_s p. Beyond, the step's plastic shear rate x solves
 * sqrt(J2)_trial - G dt x = p mu(I(x)) with mu(I) = mu_s + (mu_2 - mu_s) x / (x + g0), g0 =
 * I_0 sqrt(p / rho_s) / d (I = x d / sqrt(p / rho_s), p the Cauchy pressure): with S = G dt,
 * a = sqrt(J2)_trial - mu_s p and D = (mu_2 - mu_s) p, S x^2 - (a - S g0 - D) x - a g0 = 0, whose
 * one positive root is taken in the form that does not cancel. dt = 0: the quasi-static limit,
 * a return to mu_s p. The tensor follows the trial deviator's direction (isochoric flow, Eq. 3.10
 * of their paper). Returns whether plastic (or disconnected). */
static bool mui_return(const mpm_material *m, double dt, const double eps[3], const double dir[3],
                       double J, double be[3], double *bzz, double *lz, double *dgamma,
                       double sigma[4])
{
    double ev, e[3];
    const double en = sqrt(dev_split(eps, &ev, e));
    const double G = m->shear, K = m->bulk;
    const double q = sqrt(2.0) * G * en;
    if (!(J < 1)) { /* disconnected: rho <= rho_c */
        *dgamma = q / G;
        be[0] = be[2] = 1;
        be[1] = 0;
        *bzz = 1;
        *lz = 0;
        for (int k = 0; k < 4; k++)
            sigma[k] = 0;
        return true;
    }
    ev = log(J);
    const double p = -K * ev; /* Kirchhoff pressure, > 0 */
    *dgamma = 0;
    bool plastic = false;
    if (q > m->mu_s * p) {
        double qn;
        if (dt > 0) {
            const double S = G * dt, a = q - m->mu_s * p, D = (m->mu_2 - m->mu_s) * p;
            const double g0 = m->i0 * sqrt(p / J / m->grain_density) / m->grain_diameter;
            const double B = a - S * g0 - D, disc = sqrt(B * B + 4 * S * a * g0);
            const double x = B > 0 ? (B + disc) / (2 * S) : disc - B > 0 ? 2 * a * g0 / (disc - B) : 0;
            *dgamma = dt * x;
            qn = q - G * *dgamma;
        } else {
            qn = m->mu_s * p;
            *dgamma = (q - qn) / G;
        }
        const double scale = qn / q;
        for (int i = 0; i < 3; i++)
            e[i] *= scale;
        plastic = true;
    }
    be_of(e, ev, dir, be, bzz, lz);
    stress_of(m, ev, e, dir, J, sigma);
    return plastic;
}

bool mpm_continuum_return(const mpm_material *m, double dt, const double tr[3],
                          const double eps[3], const double dir[3], double J, double be[3],
                          double *bzz, double *lz, double *eps_p, double *rate, double sigma[4])
{
    double dgamma;
    const bool plastic = m->model == MPM_MU_I
                             ? mui_return(m, dt, eps, dir, J, be, bzz, lz, &dgamma, sigma)
                             : dp_return(m, tr, eps, dir, J, be, bzz, lz, &dgamma, sigma);
    *eps_p += dgamma / sqrt(3.0);
    if (rate)
        *rate = dt > 0 ? dgamma / dt : 0;
    return plastic;
}
