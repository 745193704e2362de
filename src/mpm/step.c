/* The MPM time step (Sec. 2 of the paper, steps 1-3): stencil, particle-to-grid transfer (lumped
 * mass Eqs. 5-6, internal force Eqs. 7-8), the grid momentum update (Eq. 9) with wall conditions,
 * the frictional multi-field contact (Sec. 3, Eqs. 12-24) on sparse per-grain nodal fields, the
 * grid-to-particle update (Eqs. 10-11, FLIP with an optional PIC blend) and the constitutive
 * update; the CFL time step and the run loop with Ctrl-C and instability checks. */
#include <math.h>
#include <string.h>

#include "core/interrupt.h"
#include "mpm/mpm_internal.h"

mpm_run_def mpm_default_run_def(void)
{
    return (mpm_run_def){.steps = 0, .time_end = -1, .dt = 0, .cfl = MPM_DEFAULT_CFL};
}

static double max_speed(const mpm_scene *s)
{
    double v2 = 0;
    for (size_t p = 0; p < s->np; p++) {
        double w = s->vx[p] * s->vx[p] + s->vy[p] * s->vy[p];
        if (w > v2)
            v2 = w;
    }
    return sqrt(v2);
}

core_status mpm_timestep_info(const mpm_scene *s, double cfl, mpm_timestep *out, core_error *err)
{
    if (!(cfl > 0 && cfl <= 1))
        return core_fail(err, CORE_ERR_ARG, "cfl must be in (0, 1], got %g", cfl);
    if (s->np == 0)
        return core_fail(err, CORE_ERR_STATE, "the scene has no material points: add a grain first");
    double c = 0;
    for (size_t g = 0; g < s->ngrains; g++) {
        double cg = mpm_wave_speed(&s->mats[s->mat[s->gstart[g]]]);
        if (cg > c)
            c = cg;
    }
    out->wave_speed = c;
    out->max_speed = max_speed(s);
    double h = s->hx < s->hy ? s->hx : s->hy;
    out->limit = h / (c + out->max_speed);
    out->dt_auto = cfl * out->limit;
    return CORE_OK;
}

/* Each point's four nodes, weights N_i(x_p) and gradients G_pi (Eq. 8), linear tensor-product
 * shape functions. Points are inside the grid here (checked at the end of every step). */
static void stencil(mpm_scene *s)
{
    const double ox = s->def.origin[0], oy = s->def.origin[1];
    const int nx = s->def.cells[0], ny = s->def.cells[1], nnx = s->nnx;
    const bool px = s->def.periodic[0], py = s->def.periodic[1];
    const double ihx = s->inv_hx, ihy = s->inv_hy;
    for (size_t p = 0; p < s->np; p++) {
        double xi = (s->x[p] - ox) * ihx, eta = (s->y[p] - oy) * ihy;
        int i = (int)floor(xi), j = (int)floor(eta);
        if (i > nx - 1)
            i = nx - 1; /* a point exactly on the upper edge */
        if (i < 0)
            i = 0;
        if (j > ny - 1)
            j = ny - 1;
        if (j < 0)
            j = 0;
        double fx = xi - i, fy = eta - j;
        int i1 = i + 1, j1 = j + 1;
        if (px && i1 == nx)
            i1 = 0;
        if (py && j1 == ny)
            j1 = 0;
        int *n = &s->sn[MPM_STENCIL * p];
        double *w = &s->sw[MPM_STENCIL * p], *gx = &s->sgx[MPM_STENCIL * p],
               *gy = &s->sgy[MPM_STENCIL * p];
        n[0] = j * nnx + i;
        n[1] = j * nnx + i1;
        n[2] = j1 * nnx + i;
        n[3] = j1 * nnx + i1;
        w[0] = (1 - fx) * (1 - fy);
        w[1] = fx * (1 - fy);
        w[2] = (1 - fx) * fy;
        w[3] = fx * fy;
        gx[0] = -(1 - fy) * ihx;
        gx[1] = (1 - fy) * ihx;
        gx[2] = -fy * ihx;
        gx[3] = fy * ihx;
        gy[0] = -(1 - fx) * ihy;
        gy[1] = -fx * ihy;
        gy[2] = (1 - fx) * ihy;
        gy[3] = fx * ihy;
    }
}

/* Step 1: lumped mass (Eq. 6), momentum (Eq. 5), internal force (Eq. 7, m_p / rho_p = V_p) and
 * gravity m_i g. */
static void to_grid(mpm_scene *s)
{
    const size_t nn = s->nnodes;
    memset(s->nm, 0, nn * sizeof(double));
    memset(s->npx, 0, nn * sizeof(double));
    memset(s->npy, 0, nn * sizeof(double));
    memset(s->nfx, 0, nn * sizeof(double));
    memset(s->nfy, 0, nn * sizeof(double));
    const double gx0 = s->def.gravity[0], gy0 = s->def.gravity[1];
    for (size_t p = 0; p < s->np; p++) {
        const double m = s->m[p], px = m * s->vx[p], py = m * s->vy[p];
        const double V = s->v0[p] * (s->F[0][p] * s->F[3][p] - s->F[1][p] * s->F[2][p]);
        const double sxx = V * s->sig[0][p], syy = V * s->sig[1][p], sxy = V * s->sig[2][p];
        const int *n = &s->sn[MPM_STENCIL * p];
        const double *w = &s->sw[MPM_STENCIL * p], *gx = &s->sgx[MPM_STENCIL * p],
                     *gy = &s->sgy[MPM_STENCIL * p];
        for (int k = 0; k < MPM_STENCIL; k++) {
            const int i = n[k];
            s->nm[i] += w[k] * m;
            s->npx[i] += w[k] * px;
            s->npy[i] += w[k] * py;
            s->nfx[i] += w[k] * m * gx0 - (sxx * gx[k] + sxy * gy[k]);
            s->nfy[i] += w[k] * m * gy0 - (sxy * gx[k] + syy * gy[k]);
        }
    }
}

/* Wall conditions on the centre-of-mass nodes and on the grain fields (entries nnodes + q). */
static void apply_walls(const mpm_scene *s, double *vx, double *vy)
{
    for (size_t i = 0; i < s->nnodes; i++) {
        unsigned char w = s->nwall[i];
        if (w & 1)
            vx[i] = 0;
        if (w & 2)
            vy[i] = 0;
    }
    for (size_t q = 0; q < s->npairs; q++) {
        unsigned char w = s->nwall[s->pnode[q]];
        if (w & 1)
            vx[s->nnodes + q] = 0;
        if (w & 2)
            vy[s->nnodes + q] = 0;
    }
}

/* The sparse per-grain nodal fields of the frictional contact. One entry per (grain, node) pair
 * that a grain's points touch, found grain by grain (points are stored grain by grain) with a
 * per-node scratch mark that is reset after each grain: the cost is linear in the points, and no
 * grains x nodes array exists. Entry nnodes + q of the nodal arrays holds the grain's mass
 * (Eq. 16), momentum (Eq. 5) and force (Eq. 7) over its own points; pnx, pny hold sum_p m_p G_pi,
 * the gradient of the grain's mass field at the node taken with the linear shape functions
 * (Eq. 24 uses the gradient of a quadratic-B-spline density instead; both point out of the
 * grain). A point moves with its grain's field at nodes shared by two or more grains and with
 * the centre-of-mass node elsewhere, so an isolated grain evolves exactly as with noslip. */
static void grain_fields(mpm_scene *s)
{
    const size_t nn = s->nnodes;
    const double gx0 = s->def.gravity[0], gy0 = s->def.gravity[1];
    memset(s->ngr, 0, nn * sizeof(int));
    memset(s->tgx, 0, nn * sizeof(double));
    memset(s->tgy, 0, nn * sizeof(double));
    size_t q = 0;
    for (size_t g = 0; g < s->ngrains; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g], q0 = q;
        for (size_t p = p0; p < p1; p++) {
            const double m = s->m[p], px = m * s->vx[p], py = m * s->vy[p];
            const double V = s->v0[p] * (s->F[0][p] * s->F[3][p] - s->F[1][p] * s->F[2][p]);
            const double sxx = V * s->sig[0][p], syy = V * s->sig[1][p], sxy = V * s->sig[2][p];
            const int *n = &s->sn[MPM_STENCIL * p];
            const double *w = &s->sw[MPM_STENCIL * p], *gx = &s->sgx[MPM_STENCIL * p],
                         *gy = &s->sgy[MPM_STENCIL * p];
            for (int k = 0; k < MPM_STENCIL; k++) {
                const int i = n[k];
                int r = s->mark[i];
                if (r < 0) {
                    r = (int)q++;
                    s->mark[i] = r;
                    s->pnode[r] = i;
                    s->ngr[i]++;
                    const size_t e = nn + (size_t)r;
                    s->nm[e] = s->npx[e] = s->npy[e] = s->nfx[e] = s->nfy[e] = 0;
                    s->pnx[r] = s->pny[r] = 0;
                }
                const size_t e = nn + (size_t)r;
                s->nm[e] += w[k] * m;
                s->npx[e] += w[k] * px;
                s->npy[e] += w[k] * py;
                s->nfx[e] += w[k] * m * gx0 - (sxx * gx[k] + sxy * gy[k]);
                s->nfy[e] += w[k] * m * gy0 - (sxy * gx[k] + syy * gy[k]);
                s->pnx[r] += m * gx[k];
                s->pny[r] += m * gy[k];
                s->tgx[i] += m * gx[k];
                s->tgy[i] += m * gy[k];
                s->sv[MPM_STENCIL * p + k] = (int)e;
            }
        }
        for (size_t r = q0; r < q; r++)
            s->mark[s->pnode[r]] = -1;
    }
    s->npairs = q;
    for (size_t e = 0; e < MPM_STENCIL * s->np; e++)
        if (s->ngr[s->sn[e]] < 2)
            s->sv[e] = s->sn[e];
}

/* Step 2: v_i^n from Eq. 5 and v_i^{n+1} from Eq. 9. v_i^n = p_i / m_i is a mass-weighted mean of
 * point velocities, bounded at any mass; only the acceleration f_i / m_i blows up at nearly empty
 * nodes, so nodes lighter than m_min keep v_i^{n+1} = v_i^n (a zero velocity there would put a
 * spurious strain rate v / h into their neighbours' points). */
static void grid_update(mpm_scene *s, double dt)
{
    const double m_min = s->m_min;
    for (size_t i = 0; i < s->nnodes; i++) {
        double m = s->nm[i];
        if (m > 0) {
            double inv = 1 / m;
            s->nvx[i] = s->npx[i] * inv;
            s->nvy[i] = s->npy[i] * inv;
            double k = m > m_min ? dt * inv : 0;
            s->nax[i] = s->nvx[i] + k * s->nfx[i];
            s->nay[i] = s->nvy[i] + k * s->nfy[i];
        } else {
            s->nvx[i] = s->nvy[i] = s->nax[i] = s->nay[i] = 0;
        }
    }
    apply_walls(s, s->nax, s->nay);
}

/* The contact rule at nodes shared by two or more grains: each grain's velocity (vx, vy at entry
 * nnodes + q) against the centre-of-mass velocity at its node. With decide, Eq. 12 (the grain
 * overtakes the centre-of-mass field along its normal) marks the pair in contact for this step;
 * without, the marks of the momentum update are reused (see remap). Marked pairs get the normal
 * correction (Eq. 14) and Coulomb friction (Eqs. 18-23). */
static void contact_correct(mpm_scene *s, double *vx, double *vy, bool decide)
{
    const size_t nn = s->nnodes;
    const double mu = s->mu;
    for (size_t q = 0; q < s->npairs; q++) {
        const int i = s->pnode[q];
        const size_t e = nn + q;
        /* The grain's mass gradient against that of everything else at the node,
         * g - (g_all - g) = 2 g - g_all: at a node of two grains their normals are then exactly
         * opposite and the corrections conserve momentum (the grain's own gradient alone loses
         * 5% of the momentum when a disk hits one at rest head-on). */
        const double gx = 2 * s->pnx[q] - s->tgx[i], gy = 2 * s->pny[q] - s->tgy[i];
        const double len = hypot(gx, gy);
        if (decide)
            s->pin[q] = 0;
        if (s->ngr[i] < 2 || !(len > 0) || !(s->nm[e] > 0))
            continue;
        const double nx = gx / len, ny = gy / len;
        const double dvx = vx[e] - vx[i], dvy = vy[e] - vy[i];
        const double dn = dvx * nx + dvy * ny;
        if (decide)
            s->pin[q] = dn > 0; /* Eq. 12 */
        if (!s->pin[q])
            continue;
        const double tx = dvx - dn * nx, ty = dvy - dn * ny, t = hypot(tx, ty);
        /* Eq. 14: the normal velocity becomes the centre-of-mass one (the force of Eq. 15) */
        vx[e] -= dn * nx;
        vy[e] -= dn * ny;
        /* Eqs. 18-23: sticking would remove the whole relative tangential velocity t (Eq. 18);
         * Coulomb caps the removal at mu times the normal correction |dn|, i.e.
         * mu' = min(mu, t / dn) (Eq. 21) along -t / |t| (Eqs. 20, 22), which is Eq. 23. */
        if (t > 0) {
            const double c = fmin(mu * fabs(dn), t) / t;
            vx[e] -= c * tx;
            vy[e] -= c * ty;
        }
    }
}

/* Step 2 for the grain fields at shared nodes: v_i^g and the updated v_i^g (Eqs. 5 and 9 over the
 * grain's points, with the centre-of-mass field's mass threshold and walls), then the contact
 * rule. Applied after the momentum update (the paper's order) and not to the P2G velocities
 * (measured on the 0.5 m/s head-on collision: correcting v_i^g after P2G as well changed the
 * rebound speed by 1.5% and did not remove the energy error that the consistent marks below
 * fix), so a point's FLIP increment carries the whole correction. */
static void contact_update(mpm_scene *s, double dt)
{
    const size_t nn = s->nnodes;
    const double m_min = s->m_min;
    for (size_t q = 0; q < s->npairs; q++) {
        const int i = s->pnode[q];
        if (s->ngr[i] < 2)
            continue;
        const size_t e = nn + q;
        const double m = s->nm[e];
        if (!(m > 0)) {
            s->nvx[e] = s->nvy[e] = s->nax[e] = s->nay[e] = 0;
            continue;
        }
        const double inv = 1 / m, k = m > m_min ? dt * inv : 0;
        s->nvx[e] = s->npx[e] * inv;
        s->nvy[e] = s->npy[e] * inv;
        s->nax[e] = s->nvx[e] + k * s->nfx[e];
        s->nay[e] = s->nvy[e] + k * s->nfy[e];
        const unsigned char w = s->nwall[i];
        if (w & 1)
            s->nax[e] = 0;
        if (w & 2)
            s->nay[e] = 0;
    }
    contact_correct(s, s->nax, s->nay, true);
}

/* Step 3: positions (Eq. 10) and velocities (Eq. 11, blended with PIC). */
static void to_points(mpm_scene *s, double dt)
{
    const double pic = s->def.pic, flip = 1 - pic;
    for (size_t p = 0; p < s->np; p++) {
        const int *n = &s->sf[MPM_STENCIL * p];
        const double *w = &s->sw[MPM_STENCIL * p];
        double dvx = 0, dvy = 0, ax = 0, ay = 0;
        for (int k = 0; k < MPM_STENCIL; k++) {
            const int i = n[k];
            ax += w[k] * s->nax[i];
            ay += w[k] * s->nay[i];
            dvx += w[k] * (s->nax[i] - s->nvx[i]);
            dvy += w[k] * (s->nay[i] - s->nvy[i]);
        }
        s->x[p] += dt * ax;
        s->y[p] += dt * ay;
        s->vx[p] = flip * (s->vx[p] + dvx) + pic * ax;
        s->vy[p] = flip * (s->vy[p] + dvy) + pic * ay;
    }
}

/* MUSL: the updated point momenta mapped back (Eq. 5 with v_p^{n+1}) give the nodal velocities
 * the strain increment is taken from; with friction each grain's own field at shared nodes. */
static void remap(mpm_scene *s)
{
    const size_t nn = s->nnodes + s->npairs;
    memset(s->npx, 0, nn * sizeof(double));
    memset(s->npy, 0, nn * sizeof(double));
    for (size_t p = 0; p < s->np; p++) {
        const double px = s->m[p] * s->vx[p], py = s->m[p] * s->vy[p];
        const int *n = &s->sf[MPM_STENCIL * p];
        const double *w = &s->sw[MPM_STENCIL * p];
        for (int k = 0; k < MPM_STENCIL; k++) {
            s->npx[n[k]] += w[k] * px;
            s->npy[n[k]] += w[k] * py;
        }
    }
    /* At shared nodes the points fed their grains' entries; the centre-of-mass momentum is
     * their sum. */
    for (size_t q = 0; q < s->npairs; q++)
        if (s->ngr[s->pnode[q]] > 1) {
            s->npx[s->pnode[q]] += s->npx[s->nnodes + q];
            s->npy[s->pnode[q]] += s->npy[s->nnodes + q];
        }
    for (size_t i = 0; i < nn; i++) {
        double m = s->nm[i];
        s->nax[i] = m > 0 ? s->npx[i] / m : 0;
        s->nay[i] = m > 0 ? s->npy[i] / m : 0;
    }
    apply_walls(s, s->nax, s->nay);
    /* The point velocities carry the grid-update correction only in part (each point gets a
     * weighted share), so the remapped grain fields still approach at contacts and are corrected
     * again, at the pairs that Eq. 12 put in contact at the momentum update. Both choices were
     * measured on two elastic disks (R = 4 cells) meeting head-on at 0.5 m/s each, noslip
     * ending with (kinetic + elastic) / initial kinetic = 1.01: no remap correction: 1.64;
     * remap correction re-deciding Eq. 12 on the remapped field (contact switching on and off
     * every other step): 1.58; the marks of the momentum update: 1.03. */
    contact_correct(s, s->nax, s->nay, false);
}

/* Step 3, continued: velocity gradient L = sum_i v_i G_pi, F <- (I + dt L) F, stress update.
 * Returns the first point that inverts, or (size_t)-1. */
static size_t constitutive(mpm_scene *s, double dt)
{
    size_t bad = (size_t)-1;
    for (size_t p = 0; p < s->np; p++) {
        const int *n = &s->sf[MPM_STENCIL * p];
        const double *gx = &s->sgx[MPM_STENCIL * p], *gy = &s->sgy[MPM_STENCIL * p];
        double L[4] = {0, 0, 0, 0};
        for (int k = 0; k < MPM_STENCIL; k++) {
            const int i = n[k];
            L[0] += s->nax[i] * gx[k];
            L[1] += s->nax[i] * gy[k];
            L[2] += s->nay[i] * gx[k];
            L[3] += s->nay[i] * gy[k];
        }
        double f[4] = {1 + dt * L[0], dt * L[1], dt * L[2], 1 + dt * L[3]};
        double F0 = s->F[0][p], F1 = s->F[1][p], F2 = s->F[2][p], F3 = s->F[3][p];
        s->F[0][p] = f[0] * F0 + f[1] * F2;
        s->F[1][p] = f[0] * F1 + f[1] * F3;
        s->F[2][p] = f[2] * F0 + f[3] * F2;
        s->F[3][p] = f[2] * F1 + f[3] * F3;
        double J = s->F[0][p] * s->F[3][p] - s->F[1][p] * s->F[2][p];
        double be[4] = {s->be[0][p], s->be[1][p], s->be[2][p], s->be[3][p]}, sig[4];
        if (!mpm_material_update(&s->mats[s->mat[p]], f, be, &s->eps_p[p], J, sig)) {
            if (bad == (size_t)-1)
                bad = p;
            continue;
        }
        for (int k = 0; k < 4; k++) {
            s->be[k][p] = be[k];
            s->sig[k][p] = sig[k];
        }
    }
    return bad;
}

/* The step being taken when a check fails is s->steps + 1. */
static core_status unstable(const mpm_scene *s, size_t p, const char *what, const char *cause,
                            core_error *err)
{
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "point %zu of grain %d %s at step %ld (t = %.6g s, at x = %.6g, y = %.6g); "
                     "likely cause: %s",
                     p + 1, s->grain[p] + 1, what, s->steps + 1, s->time, s->x[p], s->y[p], cause);
}

/* Non-finite values, points outside the grid on axes that are not periodic; periodic axes wrap. */
static core_status check_points(mpm_scene *s, core_error *err)
{
    const mpm_scene_def *d = &s->def;
    for (size_t p = 0; p < s->np; p++) {
        double *c[2] = {&s->x[p], &s->y[p]};
        if (!isfinite(*c[0]) || !isfinite(*c[1]) || !isfinite(s->vx[p]) || !isfinite(s->vy[p]) ||
            !isfinite(s->sig[0][p]) || !isfinite(s->sig[1][p]) || !isfinite(s->sig[2][p]))
            return unstable(s, p, "has a non-finite position, velocity or stress",
                            "the time step is too large for the wave speed (use dt = \"auto\" or "
                            "a smaller cfl)", err);
        for (int a = 0; a < 2; a++) {
            double o = d->origin[a], L = d->size[a];
            if (d->periodic[a]) {
                if (*c[a] < o || *c[a] >= o + L)
                    *c[a] -= L * floor((*c[a] - o) / L);
                if (*c[a] >= o + L) /* rounding of a value just below o */
                    *c[a] = o;
            } else if (*c[a] < o || *c[a] > o + L) {
                return unstable(s, p, "left the grid",
                                "an edge without a wall (walls = 'none'), or a time step too "
                                "large for the speed", err);
            }
        }
    }
    return CORE_OK;
}

core_status mpm_run(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err)
{
    *done = 0;
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    if (!(run->dt >= 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be > 0 (or 0 for automatic), got %g", run->dt);
    if (run->dt == 0 && !(run->cfl > 0 && run->cfl <= 1))
        return core_fail(err, CORE_ERR_ARG, "cfl must be in (0, 1], got %g", run->cfl);
    if (s->np == 0)
        return core_fail(err, CORE_ERR_STATE, "the scene has no material points: add a grain first");
    core_status st0;
    const bool friction = s->contact == MPM_CONTACT_FRICTION;
    if (friction) {
        if ((st0 = mpm_contact_reserve(s, err)))
            return st0;
    } else {
        s->npairs = 0;
    }
    s->sf = friction ? s->sv : s->sn;
    const double h = s->hx < s->hy ? s->hx : s->hy;
    mpm_timestep ts;
    core_status st = mpm_timestep_info(s, run->cfl > 0 && run->cfl <= 1 ? run->cfl : 1, &ts, err);
    if (st)
        return st;
    while (*done < run->steps) {
        if (run->time_end >= 0 && s->time >= run->time_end * (1 - 1e-14))
            break;
        if (interrupt_pending())
            return core_fail(err, CORE_ERR_INTERRUPTED,
                             "interrupted at step %ld (t = %.6g s); the scene is intact", s->steps,
                             s->time);
        double dt = run->dt > 0 ? run->dt : run->cfl * h / (ts.wave_speed + max_speed(s));
        if (run->time_end >= 0 && s->time + dt > run->time_end)
            dt = run->time_end - s->time;
        stencil(s);
        to_grid(s);
        if (friction)
            grain_fields(s);
        grid_update(s, dt);
        if (friction)
            contact_update(s, dt);
        to_points(s, dt);
        if (s->def.update == MPM_MUSL)
            remap(s);
        size_t bad = constitutive(s, dt);
        if (bad != (size_t)-1)
            return unstable(s, bad, "was inverted (det F <= 0)",
                            "the time step is too large for the wave speed, or a point too "
                            "strongly compressed between walls", err);
        if ((st = check_points(s, err)))
            return st;
        s->time += dt;
        s->steps++;
        ++*done;
    }
    return CORE_OK;
}
