/* MPM materials: Hencky (logarithmic-strain) hyperelasticity in plane strain and von Mises
 * plasticity with linear isotropic hardening by radial return in principal log strains
 * (Simo 1992). This is the constitutive part of step 3 of the paper's algorithm (Sec. 2). */
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

core_status mpm_check_material(const mpm_material *m, core_error *err)
{
    if (m->model != MPM_ELASTIC && m->model != MPM_VONMISES)
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
    return CORE_OK;
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
    return material_update(m, f, be, eps_p, J, sigma);
}
