/* MPM materials: Hencky (logarithmic-strain) hyperelasticity in plane strain and von Mises
 * plasticity with linear isotropic hardening by radial return in principal log strains
 * (Simo 1992), and the checks of every model's parameters (the granular continuum models'
 * returns are in continuum.c). This is the constitutive part of step 3 of the paper's algorithm
 * (Sec. 2). */
#include <math.h>

#include "mpm/material_inline.h"
#include "mpm/mpm_internal.h"

mpm_material mpm_default_material(void)
{
    return (mpm_material){.model = MPM_ELASTIC,
                          .density = 3000,
                          .shear = 2.5e6,
                          .bulk = 10e6,
                          .yield = 0,
                          .hardening = 0};
}

/* A parameter outside its range: "NAME must be WHAT, got V". */
static core_status bad(core_error *err, const char *name, const char *what, double v)
{
    return core_fail(err, CORE_ERR_ARG, "%s must be %s, got %g", name, what, v);
}

core_status mpm_check_material(const mpm_material *m, core_error *err)
{
    if (m->model != MPM_ELASTIC && m->model != MPM_VONMISES && m->model != MPM_DRUCKER_PRAGER &&
        m->model != MPM_MU_I)
        return core_fail(err, CORE_ERR_ARG, "unknown material model %d", (int)m->model);
    const double v[3] = {m->density, m->shear, m->bulk};
    static const char *const names[3] = {"density", "shear modulus", "bulk modulus"};
    for (int k = 0; k < 3; k++)
        if (!(v[k] > 0) || !isfinite(v[k]))
            return core_fail(err, CORE_ERR_ARG, "%s must be > 0, got %g", names[k], v[k]);
    if (m->model == MPM_VONMISES) {
        if (!(m->yield > 0) || !isfinite(m->yield))
            return core_fail(err, CORE_ERR_ARG, "von Mises yield stress must be > 0, got %g",
                             m->yield);
        if (!(m->hardening >= 0) || !isfinite(m->hardening))
            return core_fail(err, CORE_ERR_ARG, "hardening must be >= 0, got %g", m->hardening);
    }
    if (m->model == MPM_DRUCKER_PRAGER) {
        if (!(m->friction > 0 && m->friction < 90))
            return bad(err, "the friction angle", "in (0, 90) degrees", m->friction);
        if (!(m->dilatancy >= 0 && m->dilatancy <= m->friction))
            return bad(err, "the dilatancy angle", "in [0, friction angle] degrees",
                       m->dilatancy);
        if (!(m->cohesion >= 0) || !isfinite(m->cohesion))
            return bad(err, "cohesion", ">= 0", m->cohesion);
    }
    if (m->model == MPM_MU_I) {
        if (!(m->mu_s > 0) || !isfinite(m->mu_s))
            return bad(err, "mu_s", "> 0", m->mu_s);
        if (!(m->mu_2 > m->mu_s) || !isfinite(m->mu_2))
            return bad(err, "mu_2", "> mu_s", m->mu_2);
        if (!(m->i0 > 0) || !isfinite(m->i0))
            return bad(err, "i0", "> 0", m->i0);
        if (!(m->grain_diameter > 0) || !isfinite(m->grain_diameter))
            return bad(err, "the grain diameter", "> 0", m->grain_diameter);
        if (!(m->grain_density >= m->density) || !isfinite(m->grain_density))
            return bad(err, "the grain density", ">= density (the close-packed bulk density)",
                       m->grain_density);
    }
    return CORE_OK;
}

void mpm_dp_match(double phi, double psi, double *eta, double *xi, double *etabar)
{
    const double rad = acos(-1.0) / 180;
    const double sf = sin(phi * rad), cf = cos(phi * rad), sp = sin(psi * rad);
    const double eb = sqrt(3.0) * sp / sqrt(3 + sp * sp);
    const double A = sqrt(1 - eb * eb / 3);
    *eta = sf / (A + eb * sf / 3);
    *xi = cf * (1 - *eta * eb / 3) / A;
    *etabar = eb;
}

void mpm_material_prepare(mpm_material *m)
{
    m->dp[0] = m->dp[1] = m->dp[2] = 0;
    if (m->model == MPM_DRUCKER_PRAGER)
        mpm_dp_match(m->friction, m->dilatancy, &m->dp[0], &m->dp[1], &m->dp[2]);
}

double mpm_wave_speed(const mpm_material *m)
{
    return sqrt((m->bulk + 4.0 / 3.0 * m->shear) / m->density);
}

double mpm_elastic_energy_density(const mpm_material *m, const double be[4])
{
    double eps[3], dir[3];
    if (!log_strains(be, 0.5 * log(be[3]), eps, dir))
        return NAN;
    double ev = eps[0] + eps[1] + eps[2], e2 = 0;
    for (int i = 0; i < 3; i++) {
        double e = eps[i] - ev / 3;
        e2 += e * e;
    }
    return 0.5 * m->bulk * ev * ev + m->shear * e2;
}

bool mpm_material_update(const mpm_material *m, const double f[4], double be[4], double *eps_p,
                         double J, double sigma[4])
{
    return mpm_material_step(m, f, 0, be, eps_p, NULL, J, sigma);
}

bool mpm_material_step(const mpm_material *m, const double f[4], double dt, double be[4],
                       double *eps_p, double *rate, double J, double sigma[4])
{
    if (m->model == MPM_ELASTIC || m->model == MPM_VONMISES) {
        if (rate)
            *rate = 0;
        return material_update(m, f, dt, be, eps_p, rate, J, sigma);
    }
    mpm_material mc = *m; /* the derived coefficients, whoever filled the struct */
    mpm_material_prepare(&mc);
    return material_update(&mc, f, dt, be, eps_p, rate, J, sigma);
}
