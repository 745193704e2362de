/* The MPM step's transfers (Sec. 2 of the paper, steps 1 and 3): each point's stencil (shape
 * functions), the centre-of-mass particle-to-grid transfer of noslip contact (lumped mass
 * Eqs. 5-6, internal force Eqs. 7-8), the grid-to-particle update (Eqs. 10-11, FLIP with an
 * optional PIC blend), and the scatters of the MUSL remap's momenta and of USF's forces. The
 * frictional contact's own transfer, grain by grain, is in contact.c. */
#include <string.h>

#include "mpm/step_internal.h"

/* The stencil of points [pa, pb) (noslip; with friction grain_scatter computes each point's
 * stencil as it scatters it). */
STAGE static void stencil(mpm_scene *s, size_t pa, size_t pb)
{
    if (s->ns == 4)
        stencil_range(s, pa, pb, 4);
    else
        stencil_range(s, pa, pb, s->ns);
}

/* The nodes a prescribed grain's points touch take its velocity (nforce = 1 + its index). */
STAGE static void mark_forced(mpm_scene *s)
{
    if (!s->npres)
        return;
    memset(s->nforce, 0, s->nnodes * sizeof *s->nforce);
    const int ns = s->ns;
    for (size_t g = 0; g < s->ngrains; g++) {
        if (s->gpres[g] < 0)
            continue;
        for (size_t p = s->gstart[g]; p < s->gstart[g] + s->gcount[g]; p++)
            for (int k = 0; k < ns; k++)
                s->nforce[s->sn[ns * p + k]] = 1 + s->gpres[g];
    }
}

/* Step 1: lumped mass (Eq. 6), momentum (Eq. 5), internal force (Eq. 7) and gravity m_i g, for
 * points [pa, pb) into the node records r, in blocks whose factors are computed first; each
 * lane's sums are the scalar ones in point order. */
enum { TG_BLOCK = 128 }; /* 10 kB of factors */
static inline __attribute__((always_inline)) void
to_grid_range(const mpm_scene *s, size_t pa, size_t pb, struct mpm_node_rec *r, const int ns)
{
    struct mpm_point_fac fac[TG_BLOCK];
    const int *const sn = s->sn;
    const double *const sw = s->sw, *const sgx = s->sgx, *const sgy = s->sgy;
    for (size_t b0 = pa; b0 < pb; b0 += TG_BLOCK) {
        const size_t b1 = pb - b0 < TG_BLOCK ? pb : b0 + TG_BLOCK;
        point_factors(s, b0, b1, fac);
        for (size_t p = b0; p < b1; p++) {
            const struct mpm_point_fac *const f = &fac[p - b0];
            const int *n = &sn[ns * p];
            const double *w = &sw[ns * p], *gx = &sgx[ns * p], *gy = &sgy[ns * p];
            for (int k = 0; k < ns; k++) {
                const v2d wk = {w[k], w[k]}, gxk = {gx[k], gx[k]}, gyk = {gy[k], gy[k]};
                struct mpm_node_rec *const e = &r[n[k]];
                e->mpx += wk * f->mpx;
                e->py[0] += w[k] * f->pyv[0];
                e->f += wk * f->fg - (f->sa * gxk + f->sb * gyk);
            }
        }
    }
}

/* The centre-of-mass transfer (noslip), inside the parallel region: thread t scatters its chunks'
 * points into their node records, then the records are added up in chunk order into the nodal
 * arrays (the same sums as chunk 0 into the arrays and the others added to them). */
STAGE static void to_grid(mpm_scene *s, const mpm_step *ctx, int t)
{
    const size_t nn = s->nnodes;
    for (int c = t; c < ctx->nc; c += ctx->nt) {
        struct mpm_node_rec *const r = ctx->nrec + (size_t)c * nn;
        memset(r, 0, nn * sizeof *r);
        if (s->ns == 4)
            to_grid_range(s, ctx->cp[c], ctx->cp[c + 1], r, 4);
        else
            to_grid_range(s, ctx->cp[c], ctx->cp[c + 1], r, s->ns);
    }
    const struct mpm_node_rec *const rec = ctx->nrec;
    const int nc = ctx->nc;
    double *const nm = s->nm, *const npx = s->npx, *const npy = s->npy, *const nfx = s->nfx,
                  *const nfy = s->nfy;
#pragma omp barrier
#pragma omp for schedule(static)
    for (size_t i = 0; i < nn; i++) {
        v2d mpx = rec[i].mpx, py = rec[i].py, f = rec[i].f;
        for (int c = 1; c < nc; c++) {
            mpx += rec[(size_t)c * nn + i].mpx;
            py += rec[(size_t)c * nn + i].py;
            f += rec[(size_t)c * nn + i].f;
        }
        nm[i] = mpx[0];
        npx[i] = mpx[1];
        npy[i] = py[0];
        nfx[i] = f[0];
        nfy[i] = f[1];
    }
}

/* Two consecutive doubles as a vector and back (memcpy: any alignment, no aliasing question;
 * one unaligned load or store). */
static inline v2d v2_load(const double *p)
{
    v2d v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline void v2_store(double *p, v2d v) { memcpy(p, &v, sizeof v); }

/* Point p's sums of G2P: a = sum_i N_i a_i and dv = sum_i N_i (a_i - v_i), x and y in the two
 * lanes, each lane's sums in the scalar order. */
static inline __attribute__((always_inline)) void
g2p_gather(const int *sf, const double *sw, const double *nax, const double *nay, const double *nvx,
           const double *nvy, size_t p, const int ns, v2d *a, v2d *dv)
{
    const int *n = &sf[ns * p];
    const double *w = &sw[ns * p];
    v2d sa = {0, 0}, sd = {0, 0};
    for (int k = 0; k < ns; k++) {
        const int i = n[k];
        const v2d wk = {w[k], w[k]}, na = {nax[i], nay[i]}, nv = {nvx[i], nvy[i]};
        sa += wk * na;
        sd += wk * (na - nv);
    }
    *a = sa;
    *dv = sd;
}

/* Thread t's zeroes in the entries its points feed with friction (its pairs at shared nodes,
 * the nodes only its grains touch; the others are not read: nodes no point reaches have no
 * mass) of the arrays a, b, before it scatters into them. */
static void zero_own(mpm_scene *s, const mpm_step *ctx, int t, double *a, double *b)
{
    const size_t nn = s->nnodes;
    const int *const pnode = s->pnode;
    const unsigned char *const pshared = s->pshared;
    for (size_t q = ctx->tq[t]; q < pairs_end(ctx, t); q++) {
        const size_t e = pshared[q] ? nn + q : (size_t)pnode[q];
        a[e] = b[e] = 0;
    }
}

/* The momenta m_p v_p of points [pa, pb) into the entries they feed, in point order and each
 * point's in stencil order: the MUSL remap's Eq. 5. */
static inline __attribute__((always_inline)) void
momenta_into(const int *restrict sf, const double *restrict sw, const double *restrict xm,
             const double *restrict vx, const double *restrict vy, size_t pa, size_t pb,
             const int ns, double *restrict npx, double *restrict npy)
{
    for (size_t p = pa; p < pb; p++) {
        const int *const n = &sf[ns * p];
        const double *const w = &sw[ns * p];
        const double A = xm[p] * vx[p], B = xm[p] * vy[p];
        for (int k = 0; k < ns; k++) {
            npx[n[k]] += w[k] * A;
            npy[n[k]] += w[k] * B;
        }
    }
}

/* Step 3: positions (Eq. 10) and velocities (Eq. 11, blended with PIC) of thread t's points,
 * grain by grain; a prescribed grain's points keep its velocity exactly. With remap (friction
 * and MUSL) each grain's points then scatter their new momenta into npx, npy (the remap's
 * scatter, fused: the grain's stencils are still in the cache, and the points' order is the
 * remap's), after the thread has zeroed the entries its points feed: nothing reads npx, npy
 * between the contact stage's barrier and the remap's node loop, and every entry a thread's
 * points feed is its own. */
static inline __attribute__((always_inline)) void
to_points_with(mpm_scene *s, const mpm_step *ctx, double dt, int t, const int ns, const bool remap)
{
    const double pic = s->def.pic, flip = 1 - pic;
    const int *const sf = s->sf;
    const double *const sw = s->sw;
    const double *const nax = s->nax, *const nay = s->nay, *const nvx = s->nvx, *const nvy = s->nvy;
    double *const x = s->x, *const y = s->y, *const ux = s->ux, *const uy = s->uy;
    double *const vx = s->vx, *const vy = s->vy;
    const bool lanes = !s->no_lanes; /* the lanes below, or one point at a time (the tests') */
    if (remap)
        zero_own(s, ctx, t, s->npx, s->npy);
    for (size_t g = ctx->tg[t]; g < ctx->tg[t + 1]; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g];
        size_t p = p0;
        /* two points at a time: their gathers, then the updates with the points in the lanes */
        for (; lanes && p + 1 < p1; p += 2) {
            v2d a[2], dv[2];
            g2p_gather(sf, sw, nax, nay, nvx, nvy, p, ns, &a[0], &dv[0]);
            g2p_gather(sf, sw, nax, nay, nvx, nvy, p + 1, ns, &a[1], &dv[1]);
            const v2d ax = {a[0][0], a[1][0]}, ay = {a[0][1], a[1][1]};
            const v2d dvx = {dv[0][0], dv[1][0]}, dvy = {dv[0][1], dv[1][1]};
            const v2d dx = dt * ax, dy = dt * ay;
            v2_store(&x[p], v2_load(&x[p]) + dx);
            v2_store(&y[p], v2_load(&y[p]) + dy);
            v2_store(&ux[p], v2_load(&ux[p]) + dx);
            v2_store(&uy[p], v2_load(&uy[p]) + dy);
            v2_store(&vx[p], flip * (v2_load(&vx[p]) + dvx) + pic * ax);
            v2_store(&vy[p], flip * (v2_load(&vy[p]) + dvy) + pic * ay);
        }
        for (; p < p1; p++) {
            v2d a, dv;
            g2p_gather(sf, sw, nax, nay, nvx, nvy, p, ns, &a, &dv);
            const double ax = a[0], ay = a[1], dvx = dv[0], dvy = dv[1];
            x[p] += dt * ax;
            y[p] += dt * ay;
            ux[p] += dt * ax;
            uy[p] += dt * ay;
            vx[p] = flip * (vx[p] + dvx) + pic * ax;
            vy[p] = flip * (vy[p] + dvy) + pic * ay;
        }
        const int k = s->npres ? s->gpres[g] : -1;
        if (k >= 0)
            for (p = p0; p < p1; p++) {
                vx[p] = s->pv[k][0];
                vy[p] = s->pv[k][1];
            }
        if (remap)
            momenta_into(sf, sw, s->m, vx, vy, p0, p1, ns, s->npx, s->npy);
    }
}

/* to_points_with with ns = 4 (linear shapes) a constant: the stencil loops unroll. */
STAGE static void to_points(mpm_scene *s, const mpm_step *ctx, double dt, int t, bool remap)
{
    if (s->ns == 4 && remap)
        to_points_with(s, ctx, dt, t, 4, true);
    else if (s->ns == 4)
        to_points_with(s, ctx, dt, t, 4, false);
    else
        to_points_with(s, ctx, dt, t, s->ns, remap);
}

/* The internal force and gravity (Eq. 7) of points [pa, pb) from their current stress into the
 * entries they feed (sf) of fx, fy, in point order: each point's m g w first, then its stress
 * terms (USF with friction; the noslip chunks' lanes do the same per lane). */
static inline __attribute__((always_inline)) void
forces_into(const mpm_scene *s, size_t pa, size_t pb, double *fx, double *fy, const int ns)
{
    const double gx0 = s->def.gravity[0], gy0 = s->def.gravity[1];
    for (size_t p = pa; p < pb; p++) {
        const double m = s->m[p];
        const double V = s->v0[p] * (s->F[0][p] * s->F[3][p] - s->F[1][p] * s->F[2][p]);
        const double A = m * gx0, B = m * gy0;
        const double sxx = V * s->sig[0][p], syy = V * s->sig[1][p], sxy = V * s->sig[2][p];
        const int *n = &s->sf[ns * p];
        const double *w = &s->sw[ns * p], *gx = &s->sgx[ns * p], *gy = &s->sgy[ns * p];
        for (int k = 0; k < ns; k++) {
            fx[n[k]] += w[k] * A;
            fy[n[k]] += w[k] * B;
        }
        for (int k = 0; k < ns; k++) {
            fx[n[k]] -= sxx * gx[k] + sxy * gy[k];
            fy[n[k]] -= sxy * gx[k] + syy * gy[k];
        }
    }
}

/* Points [pa, pb) of a noslip chunk into its node records r (x and y in the lanes of r[2 i],
 * r[2 i + 1]): momenta (as momenta_into) or forces (as forces_into), each lane's operations
 * theirs in their order. */
static inline __attribute__((always_inline)) void
scatter_lanes_range(const mpm_scene *s, size_t pa, size_t pb, double *r, bool force, const int ns)
{
    const double gx0 = s->def.gravity[0], gy0 = s->def.gravity[1];
    const int *const sf = s->sf;
    const double *const sw = s->sw, *const sgx = s->sgx, *const sgy = s->sgy;
    const double *const xm = s->m, *const vx = s->vx, *const vy = s->vy;
    for (size_t p = pa; p < pb; p++) {
        const double m = xm[p];
        v2d AB = {m * vx[p], m * vy[p]}, sa = {0, 0}, sb = {0, 0};
        if (force) {
            const double V = s->v0[p] * (s->F[0][p] * s->F[3][p] - s->F[1][p] * s->F[2][p]);
            const double sxx = V * s->sig[0][p], syy = V * s->sig[1][p], sxy = V * s->sig[2][p];
            AB = (v2d){m * gx0, m * gy0};
            sa = (v2d){sxx, sxy};
            sb = (v2d){sxy, syy};
        }
        const int *n = &sf[ns * p];
        const double *w = &sw[ns * p], *gx = &sgx[ns * p], *gy = &sgy[ns * p];
        for (int k = 0; k < ns; k++) {
            double *const e = &r[2 * (size_t)n[k]];
            v2_store(e, v2_load(e) + (v2d){w[k], w[k]} * AB);
        }
        if (force)
            for (int k = 0; k < ns; k++) {
                double *const e = &r[2 * (size_t)n[k]];
                const v2d gxk = {gx[k], gx[k]}, gyk = {gy[k], gy[k]};
                v2_store(e, v2_load(e) - (sa * gxk + sb * gyk));
            }
    }
}

/* Scatters a per-point vector into the entries each point feeds (sf: its grain's entry at shared
 * nodes, the centre of mass elsewhere) of the arrays a, b: momentum m_p v_p (force = false; the
 * noslip remap) or the internal force and gravity (Eq. 7) from the current stress (force = true;
 * USF). Inside the parallel region. With friction every entry a point feeds belongs to its
 * thread (its grain's, or a node only its grain touches), and a shared node's centre of mass
 * takes the sum of the grains' entries in contact_update (shared_node); noslip scatters by
 * chunks (to_grid). */
static inline __attribute__((always_inline)) void scatter_sf_with(mpm_scene *s, const mpm_step *ctx,
                                                                  int t, double *a, double *b,
                                                                  bool force, const int ns)
{
    const size_t nn = s->nnodes;
    if (s->contact != MPM_CONTACT_FRICTION) {
        /* by chunks, each into its x, y lanes per node (tbuf), added up in chunk order as
         * to_grid does */
        for (int c = t; c < ctx->nc; c += ctx->nt) {
            double *const r = ctx->tbuf + (size_t)c * 2 * nn;
            memset(r, 0, 2 * nn * sizeof *r);
            scatter_lanes_range(s, ctx->cp[c], ctx->cp[c + 1], r, force, ns);
        }
        const double *const r = ctx->tbuf;
        const int nc = ctx->nc;
#pragma omp barrier
#pragma omp for schedule(static)
        for (size_t i = 0; i < nn; i++) {
            v2d v = v2_load(&r[2 * i]);
            for (int c = 1; c < nc; c++)
                v += v2_load(&r[2 * ((size_t)c * nn + i)]);
            a[i] = v[0];
            b[i] = v[1];
        }
        return;
    }
    zero_own(s, ctx, t, a, b);
    if (force)
        forces_into(s, ctx->tp[t], ctx->tp[t + 1], a, b, ns);
    else
        momenta_into(s->sf, s->sw, s->m, s->vx, s->vy, ctx->tp[t], ctx->tp[t + 1], ns, a, b);
#pragma omp barrier
}

/* scatter_sf_with with ns = 4 (linear shapes) a constant: the stencil loops unroll. */
STAGE static void scatter_sf(mpm_scene *s, const mpm_step *ctx, int t, double *a, double *b,
                             bool force)
{
    if (s->ns == 4)
        scatter_sf_with(s, ctx, t, a, b, force, 4);
    else
        scatter_sf_with(s, ctx, t, a, b, force, s->ns);
}

/* ---- the stages ------------------------------------------------------------------------------ */
void mpm_stage_stencil(mpm_scene *s, mpm_step *ctx, int t)
{
    stencil(s, ctx->tp[t], ctx->tp[t + 1]);
}

/* The nodes of the prescribed grains, by thread 0 (every stencil done; nothing without them) */
void mpm_stage_forced(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)ctx, (void)t;
    if (!s->npres)
        return;
#pragma omp master
    mark_forced(s);
#pragma omp barrier
}

void mpm_stage_to_grid(mpm_scene *s, mpm_step *ctx, int t) { to_grid(s, ctx, t); }

/* USF: the forces from the new stress */
void mpm_stage_forces(mpm_scene *s, mpm_step *ctx, int t)
{
    scatter_sf(s, ctx, t, s->nfx, s->nfy, true);
}

void mpm_stage_to_points(mpm_scene *s, mpm_step *ctx, int t)
{
    to_points(s, ctx, ctx->dt, t, false);
}

/* G2P with the MUSL remap's scatter fused (friction) */
void mpm_stage_to_points_remap(mpm_scene *s, mpm_step *ctx, int t)
{
    to_points(s, ctx, ctx->dt, t, true);
}

/* MUSL, noslip: the updated point momenta mapped back (Eq. 5 with v_p^{n+1}), for the nodal
 * velocities the strain increment is taken from */
void mpm_stage_remap_scatter(mpm_scene *s, mpm_step *ctx, int t)
{
    scatter_sf(s, ctx, t, s->npx, s->npy, false);
}
