/* MPM measurements: energies, momentum, per-grain centre of mass and spin. */
#include <math.h>
#include <stdlib.h>

#include "mpm/mpm_internal.h"

void mpm_measure_energy(const mpm_scene *s, mpm_energy *e)
{
    double ke = 0, el = 0, pl = 0, pot = 0;
    const double g0 = s->def.gravity[0], g1 = s->def.gravity[1];
    for (size_t p = 0; p < s->np; p++) {
        const mpm_material *m = &s->mats[s->mat[p]];
        ke += 0.5 * s->m[p] * (s->vx[p] * s->vx[p] + s->vy[p] * s->vy[p]);
        double be[4] = {s->be[0][p], s->be[1][p], s->be[2][p], s->be[3][p]};
        el += s->v0[p] * mpm_elastic_energy_density(m, be);
        double ep = s->eps_p[p];
        if (m->model == MPM_VONMISES) /* the continuum models' dissipation is not tracked */
            pl += s->v0[p] * (m->yield * ep + 0.5 * m->hardening * ep * ep);
        pot -= s->m[p] * (g0 * s->x[p] + g1 * s->y[p]);
    }
    e->kinetic = ke;
    e->elastic = el;
    e->plastic = pl;
    e->potential = pot;
    e->total = ke + el + pl + pot;
}

void mpm_measure_momentum(const mpm_scene *s, double p[2], double *lz)
{
    double px = 0, py = 0, l = 0;
    for (size_t i = 0; i < s->np; i++) {
        px += s->m[i] * s->vx[i];
        py += s->m[i] * s->vy[i];
        l += s->m[i] * (s->x[i] * s->vy[i] - s->y[i] * s->vx[i]);
    }
    p[0] = px;
    p[1] = py;
    *lz = l;
}

/* Minimum-image offset of a coordinate from a reference on a periodic axis. */
static double offset(const mpm_scene *s, int a, double x, double ref)
{
    double d = x - ref;
    if (s->def.periodic[a]) {
        double L = s->def.size[a];
        d -= L * floor(d / L + 0.5);
    }
    return d;
}

core_status mpm_grain(const mpm_scene *s, size_t id, mpm_grain_info *out, core_error *err)
{
    if (id >= s->ngrains)
        return core_fail(err, CORE_ERR_ARG, "grain %zu does not exist (the scene has %zu)", id + 1,
                         s->ngrains);
    const size_t p0 = s->gstart[id], n = s->gcount[id];
    const double rx = s->x[p0], ry = s->y[p0];
    double M = 0, cx = 0, cy = 0, px = 0, py = 0;
    for (size_t p = p0; p < p0 + n; p++) {
        M += s->m[p];
        cx += s->m[p] * offset(s, 0, s->x[p], rx);
        cy += s->m[p] * offset(s, 1, s->y[p], ry);
        px += s->m[p] * s->vx[p];
        py += s->m[p] * s->vy[p];
    }
    cx /= M;
    cy /= M;
    out->mass = M;
    out->velocity[0] = px / M;
    out->velocity[1] = py / M;
    double L = 0, I = 0;
    for (size_t p = p0; p < p0 + n; p++) {
        double dx = offset(s, 0, s->x[p], rx) - cx, dy = offset(s, 1, s->y[p], ry) - cy;
        L += s->m[p] * (dx * (s->vy[p] - out->velocity[1]) - dy * (s->vx[p] - out->velocity[0]));
        I += s->m[p] * (dx * dx + dy * dy);
    }
    cx += rx;
    cy += ry;
    for (int a = 0; a < 2; a++) {
        double *c = a ? &cy : &cx, o = s->def.origin[a], Lp = s->def.size[a];
        if (s->def.periodic[a])
            *c -= Lp * floor((*c - o) / Lp);
    }
    out->center[0] = cx;
    out->center[1] = cy;
    out->angular_momentum = L;
    out->inertia = I;
    out->omega = I > 0 ? L / I : 0;
    out->points = n;
    return CORE_OK;
}

/* A mu_i point's inertial number over its last step, gdot_p d / sqrt(p / rho_s) (0 where the
 * point is disconnected or unloaded, and for the other models). */
static double inertial_number(const mpm_scene *s, size_t p)
{
    const mpm_material *m = &s->mats[s->mat[p]];
    const double pr = -(s->sig[0][p] + s->sig[1][p] + s->sig[3][p]) / 3;
    if (m->model != MPM_MU_I || !s->rate || !(pr > 0))
        return 0;
    return s->rate[p] * m->grain_diameter / sqrt(pr / m->grain_density);
}

static double field_value(const mpm_scene *s, mpm_field_kind kind, size_t p)
{
    const double sxx = s->sig[0][p], syy = s->sig[1][p], sxy = s->sig[2][p];
    switch (kind) {
    case MPM_FIELD_VX: return s->vx[p];
    case MPM_FIELD_VY: return s->vy[p];
    case MPM_FIELD_SPEED: return hypot(s->vx[p], s->vy[p]);
    case MPM_FIELD_UX: return s->ux[p];
    case MPM_FIELD_UY: return s->uy[p];
    case MPM_FIELD_UMAG: return hypot(s->ux[p], s->uy[p]);
    case MPM_FIELD_SXX: return sxx;
    case MPM_FIELD_SYY: return syy;
    case MPM_FIELD_SXY: return sxy;
    case MPM_FIELD_PRESSURE: return -(sxx + syy) / 2;
    case MPM_FIELD_PSD: return 2 * hypot(0.5 * (sxx - syy), sxy);
    case MPM_FIELD_EPS_P: return s->eps_p[p];
    case MPM_FIELD_GRAIN: return s->grain[p] + 1;
    case MPM_FIELD_MASS: return 1;
    case MPM_FIELD_RATE: return s->rate ? s->rate[p] : 0;
    case MPM_FIELD_INERTIAL: return inertial_number(s, p);
    case MPM_FIELD_MEAN_PRESSURE: return -(sxx + syy + s->sig[3][p]) / 3;
    }
    return 0;
}

/* The cell holding a point (points on the upper edge belong to the last cell). */
static size_t cell_of(const mpm_scene *s, size_t p)
{
    const int nx = s->def.cells[0], ny = s->def.cells[1];
    int i = (int)floor((s->x[p] - s->def.origin[0]) * s->inv_hx);
    int j = (int)floor((s->y[p] - s->def.origin[1]) * s->inv_hy);
    i = i < 0 ? 0 : (i >= nx ? nx - 1 : i);
    j = j < 0 ? 0 : (j >= ny ? ny - 1 : j);
    return (size_t)j * (size_t)nx + (size_t)i;
}

void mpm_field(const mpm_scene *s, mpm_field_kind kind, double *out)
{
    const size_t nc = (size_t)s->def.cells[0] * (size_t)s->def.cells[1];
    double *mass = calloc(nc, sizeof *mass);
    for (size_t c = 0; c < nc; c++)
        out[c] = 0;
    if (!mass) { /* measurements never fail: fall back to unweighted NAN-free zeros */
        return;
    }
    for (size_t p = 0; p < s->np; p++) {
        size_t c = cell_of(s, p);
        mass[c] += s->m[p];
        out[c] += kind == MPM_FIELD_MASS ? s->m[p] : s->m[p] * field_value(s, kind, p);
    }
    for (size_t c = 0; c < nc; c++) {
        if (kind == MPM_FIELD_MASS)
            continue;
        out[c] = mass[c] > 0 ? out[c] / mass[c] : NAN;
    }
    free(mass);
}

void mpm_column_uy(const mpm_scene *s, double *out)
{
    const int nx = s->def.cells[0];
    double *mass = calloc((size_t)nx, sizeof *mass);
    for (int i = 0; i < nx; i++)
        out[i] = 0;
    if (!mass)
        return;
    for (size_t p = 0; p < s->np; p++) {
        size_t c = cell_of(s, p) % (size_t)nx;
        mass[c] += s->m[p];
        out[c] += s->m[p] * s->uy[p];
    }
    for (int i = 0; i < nx; i++)
        out[i] = mass[i] > 0 ? out[i] / mass[i] : NAN;
    free(mass);
}

double mpm_shear_strain(const mpm_scene *s)
{
    double M = 0, mx = 0, mu = 0;
    for (size_t p = 0; p < s->np; p++) {
        double x0 = s->x[p] - s->ux[p]; /* reference position (x is not wrapped in shear) */
        M += s->m[p];
        mx += s->m[p] * x0;
        mu += s->m[p] * s->uy[p];
    }
    if (!(M > 0))
        return 0;
    mx /= M;
    mu /= M;
    double cxu = 0, cxx = 0;
    for (size_t p = 0; p < s->np; p++) {
        double dx = s->x[p] - s->ux[p] - mx;
        cxu += s->m[p] * dx * (s->uy[p] - mu);
        cxx += s->m[p] * dx * dx;
    }
    return cxx > 0 ? cxu / cxx : 0;
}
