/* MPM measurements: energies, momentum, per-grain centre of mass and spin. */
#include <math.h>

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
        if (m->model == MPM_VONMISES)
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
