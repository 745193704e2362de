/* The MPM step's grid and contact (Sec. 2 step 2, Sec. 3): the frictional multi-field contact's
 * sparse per-grain nodal fields (Eqs. 5-7 per grain, the normals of Eq. 24), the grid momentum
 * update (Eq. 9) with the walls and planes, the contact rule (Eqs. 12-24), and the nodal
 * velocities of the MUSL remap and of USF. */
#include <math.h>
#include <string.h>

#include "mpm/step_internal.h"

/* First moments of the nodal mass about each node, sum_p N_ip m_p (x_p - x_i) (minimum image on
 * periodic axes), for the gap test of friction walls. */
static void moments(mpm_scene *s)
{
    memset(s->nmx, 0, s->nnodes * sizeof(double));
    memset(s->nmy, 0, s->nnodes * sizeof(double));
    const int ns = s->ns, nnx = s->nnx;
    const double ox = s->def.origin[0] - s->gl[0] * s->hx, oy = s->def.origin[1] - s->gl[1] * s->hy;
    const double Lx = s->def.size[0], Ly = s->def.size[1];
    for (size_t p = 0; p < s->np; p++)
        for (int k = 0; k < ns; k++) {
            const int i = s->sn[ns * p + k];
            double dx = s->x[p] - (ox + (i % nnx) * s->hx), dy = s->y[p] - (oy + (i / nnx) * s->hy);
            if (s->def.periodic[0])
                dx -= Lx * floor(dx / Lx + 0.5);
            if (s->def.periodic[1])
                dy -= Ly * floor(dy / Ly + 0.5);
            const double wm = s->sw[ns * p + k] * s->m[p];
            s->nmx[i] += wm * dx;
            s->nmy[i] += wm * dy;
        }
}

/* The wall rule of plane pl on one nodal velocity, relative to the wall's velocity. For a
 * friction wall, decide sets *flag to Eq. 12 (the material moves into the wall); without decide
 * the flag of the momentum update is reused (as for grain contact, see remap). */
static inline void wall_rule(const mpm_plane *pl, double *vx, double *vy, unsigned char *flags,
                             unsigned char bit, bool decide, bool near)
{
    double rx = *vx - pl->v[0], ry = *vy - pl->v[1];
    const double vn = rx * pl->n[0] + ry * pl->n[1];
    switch (pl->kind) {
    case MPM_WALL_NOSLIP: rx = ry = 0; break;
    case MPM_WALL_SLIP:
        rx -= vn * pl->n[0];
        ry -= vn * pl->n[1];
        break;
    case MPM_WALL_FRICTION: {
        if (decide)
            *flags = (unsigned char)(vn > 0 && near ? *flags | bit : *flags & ~bit);
        if (!(*flags & bit))
            return;
        rx -= vn * pl->n[0];
        ry -= vn * pl->n[1];
        const double t = hypot(rx, ry);
        if (t > 0) {
            const double c = fmin(pl->mu * fabs(vn), t) / t;
            rx -= c * rx;
            ry -= c * ry;
        }
        break;
    }
    case MPM_WALL_NONE: return;
    }
    *vx = pl->v[0] + rx;
    *vy = pl->v[1] + ry;
}

/* The gap test of friction plane k at node i: the centroid of the node's material (weighted by
 * the shape functions) is within wall_gap cells of where a gap-free layer would put it. */
static inline bool near_plane(const mpm_scene *s, int k, size_t i)
{
    if (!s->dref[k])
        return true;
    const mpm_plane *pl = &s->planes[k];
    const int I = (int)(i % (size_t)s->nnx), J = (int)(i / (size_t)s->nnx);
    const double inv = s->nm[i] > 0 ? 1 / s->nm[i] : 0;
    const double cx = s->def.origin[0] + (I - s->gl[0]) * s->hx + s->nmx[i] * inv;
    const double cy = s->def.origin[1] + (J - s->gl[1]) * s->hy + s->nmy[i] * inv;
    const double d = -((cx - pl->point[0]) * pl->n[0] + (cy - pl->point[1]) * pl->n[1]);
    const double h = s->hx < s->hy ? s->hx : s->hy;
    return d <= s->dref[k][i] + s->def.wall_gap * h;
}

/* The wall rules of the planes at node i on one velocity (*vx, *vy) with contact flags *win (a
 * node's or a pair's). */
static inline void planes_at(const mpm_scene *s, double *vx, double *vy, size_t i,
                             unsigned char *win, bool decide)
{
    const unsigned char w = s->nwall[i];
    if (w)
        for (int k = 0; k < s->nplanes; k++)
            if (w & (1u << k))
                wall_rule(&s->planes[k], vx, vy, win, (unsigned char)(1u << k), decide,
                          !decide || near_plane(s, k, i));
}

/* Wall and plane conditions on centre-of-mass node i, then the velocity of a prescribed grain
 * whose points touch it. */
static inline void node_walls(mpm_scene *s, double *vx, double *vy, size_t i, bool decide)
{
    planes_at(s, &vx[i], &vy[i], i, &s->nwin[i], decide);
    if (s->npres && s->nforce[i]) {
        vx[i] = s->pv[s->nforce[i] - 1][0];
        vy[i] = s->pv[s->nforce[i] - 1][1];
    }
}

/* The same for the grain field of pair q at a shared node (entry nnodes + q); a prescribed
 * grain's own field takes its velocity everywhere. */
static inline void pair_walls(mpm_scene *s, double *vx, double *vy, size_t q, bool decide)
{
    const size_t e = s->nnodes + q;
    planes_at(s, &vx[e], &vy[e], (size_t)s->pnode[q], &s->pwin[q], decide);
    const int k = s->npres ? s->gpres[s->pgrain[q]] : -1;
    if (k >= 0) {
        vx[e] = s->pv[k][0];
        vy[e] = s->pv[k][1];
    }
}

/* The sparse per-grain nodal fields of the frictional contact, and from them the centre-of-mass
 * field. One entry per (grain, node) pair that a grain's points touch, found grain by grain
 * (points are stored grain by grain) with a per-node scratch mark that is reset after each grain:
 * the cost is linear in the points, and no grains x nodes array exists. Entry nnodes + q of the
 * nodal arrays holds the grain's mass (Eq. 16), momentum (Eq. 5) and force (Eq. 7) over its own
 * points; the centre-of-mass entries are their sums (Eqs. 5-7 over all points), so no separate
 * transfer is needed. pnx, pny hold the gradient of the grain's mass field at the node, outward:
 * sum_p m_p grad N_i(x_p) over the grain, with the transfer's shape functions or (normals
 * 'averaged' and 'own' with linear transfers) with quadratic B-splines (Eq. 24), read at shared
 * nodes only (the contact rule sums a shared
 * node's gradients along its chain, so that 2 g - g_all of two grains are exactly opposite). A
 * point moves with its grain's field at nodes shared by two or more grains and with the
 * centre-of-mass node elsewhere, so an isolated grain evolves exactly as with noslip.
 *
 * Inside the parallel region; thread t takes its grains. Their pairs are written from tq[t] =
 * ns tp[t] (a grain has at most ns pairs per point) and stay there. A grain's
 * pairs are numbered in the order its points first touch their nodes; while the grain is
 * scattered, their sums build up in the thread's records (one cache line per pair, two sums per
 * SSE2 operation, mark[i] the record of node i), and are then copied into the nodal and pair
 * arrays. */
static inline __attribute__((always_inline)) void grain_scatter_with(mpm_scene *s, mpm_step *ctx,
                                                                     int t, const int ns,
                                                                     const bool volumes,
                                                                     const bool spline_normals)
{
    const size_t nn = s->nnodes;
    int *const mark = ctx->tmark + (size_t)t * (nn + 1);
    struct mpm_pair_rec *const rec = ctx->trec + (size_t)t * (ctx->reccap + 1) + 1;
    const size_t base = (size_t)ns * ctx->tp[t];
    /* the arrays as locals: the stores below cannot change them, and the compiler need not
     * reload them */
    double *const pm = s->nm + nn, *const ppx = s->npx + nn, *const ppy = s->npy + nn;
    double *const pfx = s->nfx + nn, *const pfy = s->nfy + nn;
    double *const pnx = s->pnx, *const pny = s->pny, *const pvol = s->pvol;
    int *const pnode = s->pnode, *const pgrain = s->pgrain;
    struct mpm_point_fac *const fac = ctx->tfac + (size_t)t * ctx->faccap;
    size_t q = base;
    for (size_t g = ctx->tg[t]; g < ctx->tg[t + 1]; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g];
        /* three passes over the grain's points (in cache), each with few live pointers: the
         * stencils, each point's factors, the sums */
        stencil_range(s, p0, p1, ns);
        point_factors(s, p0, p1, fac);
        int nr = 0; /* the grain's pairs so far: records [0, nr), pairs q .. q + nr - 1 */
        ctx->gps[g] = q - base;
        for (size_t p = p0; p < p1; p++) {
            const struct mpm_point_fac *const f = &fac[p - p0];
            const int *n = &s->sn[ns * p];
            const double *w = &s->sw[ns * p], *gx = &s->sgx[ns * p], *gy = &s->sgy[ns * p];
            int *sv = &s->sv[ns * p];
            for (int k = 0; k < ns; k++) {
                const int i = n[k];
                const v2d wk = {w[k], w[k]}, gxk = {gx[k], gx[k]}, gyk = {gy[k], gy[k]};
                int r = mark[i];
                if (r < 0) {
                    r = nr++;
                    mark[i] = r;
                    pnode[q + (size_t)r] = i;
                    pgrain[q + (size_t)r] = (int)g;
                    rec[r] = (struct mpm_pair_rec){{0, 0}, {0, 0}, {0, 0}, {0, 0}};
                }
                struct mpm_pair_rec *const e = &rec[r];
                e->mpx += wk * f->mpx;
                if (volumes)
                    e->pyv += wk * f->pyv;
                else
                    e->pyv[0] += w[k] * f->pyv[0];
                e->f += wk * f->fg - (f->sa * gxk + f->sb * gyk);
                if (!spline_normals) {
                    const v2d mm = {f->mpx[0], f->mpx[0]}, gk = {gx[k], gy[k]};
                    e->n += mm * gk;
                }
                sv[k] = (int)q + r; /* the pair, renumbered after packing */
            }
        }
        for (int r = 0; r < nr; r++) {
            const size_t e = q + (size_t)r;
            mark[pnode[e]] = -1;
            pm[e] = rec[r].mpx[0];
            ppx[e] = rec[r].mpx[1];
            ppy[e] = rec[r].pyv[0];
            pvol[e] = rec[r].pyv[1];
            pfx[e] = rec[r].f[0];
            pfy[e] = rec[r].f[1];
            pnx[e] = rec[r].n[0];
            pny[e] = rec[r].n[1];
        }
        q += (size_t)nr;
        ctx->gpc[g] = (size_t)nr;
    }
    ctx->tc[t] = q - base;
}

/* grain_scatter_with with constant options for the common case (linear shapes, spline normals,
 * no separation check): the stencil loop unrolls and the per-entry tests go. */
STAGE static void grain_scatter(mpm_scene *s, mpm_step *ctx, int t)
{
    const bool spline_normals = s->opt.normals != MPM_NORMALS_LINEAR && s->ns != 9;
    const bool volumes = s->opt.separation > 0;
    if (s->ns == 4 && spline_normals && !volumes)
        grain_scatter_with(s, ctx, t, 4, false, true);
    else
        grain_scatter_with(s, ctx, t, s->ns, volumes, spline_normals);
}

/* Thread t's pairs chained per node within the thread (pnext, -1 after the thread's last pair
 * at a node), its first pair at each node left in its marks (right after its scatter). */
STAGE static void pair_chains(mpm_scene *s, const mpm_step *ctx, int t)
{
    int *const mark = ctx->tmark + (size_t)t * (s->nnodes + 1);
    const int *const pnode = s->pnode;
    int *const pnext = s->pnext;
    for (size_t q = pairs_end(ctx, t); q-- > ctx->tq[t];) {
        const int i = pnode[q];
        pnext[q] = mark[i];
        mark[i] = (int)q;
    }
}

/* Every node (every thread's pair_chains done): its chain linked on through the threads' chains
 * (nhead, pnext), walked for the grain count, the centre-of-mass field as the sum of the grain
 * fields (Eqs. 5-7 over all points) and the prescribed grain forcing the node (the last one in
 * grain order, as mark_forced); zeros where no point reaches. */
STAGE static void node_sums(mpm_scene *s, const mpm_step *ctx)
{
    const size_t nn = s->nnodes, stride = nn + 1;
    const int nt = ctx->nt;
    /* the arrays as locals: the int stores below could alias the scene's fields */
    const int *const mark = ctx->tmark, *const pgrain = s->pgrain, *const gpres = s->gpres;
    int *const pnext = s->pnext, *const ngr = s->ngr, *const nhead = s->nhead;
    int *const nforce = s->npres ? s->nforce : NULL;
    double *const nm = s->nm, *const npx = s->npx, *const npy = s->npy, *const nfx = s->nfx,
                  *const nfy = s->nfy;
    const double *const pm = nm + nn, *const ppx = npx + nn, *const ppy = npy + nn,
                        *const pfx = nfx + nn, *const pfy = nfy + nn;
#pragma omp for schedule(static)
    for (size_t i = 0; i < nn; i++) {
        double m = 0, px = 0, py = 0, fx = 0, fy = 0;
        int n = 0, force = 0, head = -1, last = -1;
        for (int u = 0; u < nt; u++) {
            int r = mark[(size_t)u * stride + i];
            if (r < 0)
                continue;
            if (last >= 0)
                pnext[last] = r;
            else
                head = r;
            for (; r >= 0; r = pnext[r]) {
                m += pm[r];
                px += ppx[r];
                py += ppy[r];
                fx += pfx[r];
                fy += pfy[r];
                if (nforce && gpres[pgrain[r]] >= 0)
                    force = 1 + gpres[pgrain[r]];
                n++;
                last = r;
            }
        }
        ngr[i] = n;
        nhead[i] = head;
        nm[i] = m;
        npx[i] = px;
        npy[i] = py;
        nfx[i] = fx;
        nfy[i] = fy;
        if (nforce)
            nforce[i] = force;
    }
}

/* Thread t's marks back to -1 (after node_sums) and pshared of its pairs. */
STAGE static void pair_kinds(mpm_scene *s, const mpm_step *ctx, int t)
{
    int *const mark = ctx->tmark + (size_t)t * (s->nnodes + 1);
    for (size_t q = ctx->tq[t]; q < pairs_end(ctx, t); q++) {
        const int i = s->pnode[q];
        mark[i] = -1;
        s->pshared[q] = s->ngr[i] > 1;
    }
}

/* Sets (v = 1) or clears (v = 0) near[] at the B-spline base nodes of the points whose 3 x 3
 * nodes include node i: the bases up to two nodes below i on each axis. */
static inline void mark_bases(const mpm_scene *s, unsigned char *near, int i, unsigned char v)
{
    const int nnx = s->nnx, I = i % nnx, J = i / nnx;
    for (int b = 0; b < 3; b++) {
        int Jb = J - b;
        if (Jb < 0) {
            if (!s->def.periodic[1])
                break;
            Jb += s->nny;
        }
        for (int a = 0; a < 3; a++) {
            int Ib = I - a;
            if (Ib < 0) {
                if (!s->def.periodic[0])
                    break;
                Ib += nnx;
            }
            near[Jb * nnx + Ib] = v;
        }
    }
}

/* After the node sums, each grain (in any order, by any thread t): its points' stencil entries
 * (sv: the grain's pair at shared nodes, else the node) and, with spline normals (Eq. 24 with
 * linear transfers), its B-spline mass gradients at its shared pairs, from the points whose 3 x 3
 * B-spline nodes include one of them (in point order, into the records, two components per SSE2
 * operation). near[] flags the B-spline bases of such points, so a point far from every shared
 * node of its grain costs one lookup. */
static inline __attribute__((always_inline)) void
grain_finish_with(mpm_scene *s, const mpm_step *ctx, int t, const bool spline)
{
    const int ns = s->ns;
    const size_t nn = s->nnodes;
    const double ox = s->def.origin[0], oy = s->def.origin[1];
    const double ihx = s->inv_hx, ihy = s->inv_hy;
    const v2d ih = {ihx, ihy};
    const int nnx = s->nnx, skip = (int)nn; /* mark[nn] = -1 always */
    const grid_axis ax = axis_of(s, 0), ay = axis_of(s, 1);
    int *const mark = ctx->tmark + (size_t)t * (nn + 1);
    unsigned char *const near = ctx->tnear + (size_t)t * nn;
    /* rec[-1]: a dummy record for the nodes that are not shared pairs of the grain */
    struct mpm_pair_rec *const rec = ctx->trec + (size_t)t * (ctx->reccap + 1) + 1;
    int *const fin = ctx->tfin + (size_t)t * ctx->reccap;
    const double *const xs = s->x, *const ys = s->y, *const xm = s->m;
    /* grains in any order, by any thread: a grain's normals are its own (its pairs, in its
     * points' order), and the threads' loads differ (the shared nodes are not evenly spread) */
#pragma omp for schedule(dynamic, 4) nowait
    for (size_t g = 0; g < s->ngrains; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g];
        int u = 0; /* the thread that scattered the grain, whose pairs start at tq[u] */
        while (g >= ctx->tg[u + 1])
            u++;
        const size_t r0 = ctx->tq[u] + ctx->gps[g], r1 = r0 + ctx->gpc[g];
        /* each pair's final entry, then the points' entries through it (sv holds the pairs
         * as scattered: the grain's from ns * tp[u] + gps[g]) */
        bool shared = false;
        for (size_t r = r0; r < r1; r++) {
            const int i = s->pnode[r];
            const bool sh = s->ngr[i] > 1; /* not pshared: another thread's, no barrier */
            fin[r - r0] = sh ? (int)(nn + r) : i;
            if (spline && sh) {
                mark[i] = (int)(r - r0);
                rec[r - r0].n = (v2d){0, 0};
                mark_bases(s, near, i, 1);
                shared = true;
            }
        }
        const size_t sv0 = (size_t)ns * ctx->tp[u] + ctx->gps[g];
        for (size_t e = (size_t)ns * p0; e < (size_t)ns * p1; e++)
            s->sv[e] = fin[(size_t)s->sv[e] - sv0];
        if (shared)
            for (size_t p = p0; p < p1; p++) {
                const double xi = (xs[p] - ox) * ihx, eta = (ys[p] - oy) * ihy;
                const int bi = ifloor(xi - 0.5), bj = ifloor(eta - 0.5);
                int I[3], J[3];
                I[0] = axis_node(ax, bi);
                J[0] = axis_node(ay, bj);
                if (I[0] >= 0 && J[0] >= 0 && !near[J[0] * nnx + I[0]])
                    continue;
                double wx[3], dx[3], wy[3], dy[3];
                bspline_at(xi, bi, wx, dx);
                bspline_at(eta, bj, wy, dy);
                const double m = xm[p];
                v2d ma[3];
                for (int a = 0; a < 3; a++)
                    ma[a] = (v2d){m * dx[a], m * wx[a]};
                if (I[0] >= 0 && J[0] >= 0) {
                    I[1] = next_node(ax, I[0]);
                    I[2] = next_node(ax, I[1]);
                    J[1] = next_node(ay, J[0]);
                    J[2] = next_node(ay, J[1]);
                } else {
                    for (int a = 1; a < 3; a++) {
                        I[a] = axis_node(ax, bi + a);
                        J[a] = axis_node(ay, bj + a);
                    }
                }
                /* lanes x, y: m dx_a wy_b / h_x and m wx_a dy_b / h_y, in the scalar order */
                if ((I[0] | I[1] | I[2] | J[0] | J[1] | J[2]) >= 0) {
                    for (int b = 0; b < 3; b++) {
                        const int *const row = mark + (size_t)J[b] * (size_t)nnx;
                        const v2d wb = {wy[b], dy[b]};
                        for (int a = 0; a < 3; a++)
                            rec[row[I[a]]].n += ma[a] * wb * ih;
                    }
                    continue;
                }
                /* near the edge of the grid: a node outside reads the mark of an untouched one */
                for (int b = 0; b < 3; b++) {
                    const v2d wb = {wy[b], dy[b]};
                    for (int a = 0; a < 3; a++) {
                        const int r = mark[J[b] < 0 || I[a] < 0 ? skip : J[b] * nnx + I[a]];
                        rec[r].n += ma[a] * wb * ih;
                    }
                }
            }
        for (size_t r = r0; r < r1; r++) {
            const int i = s->pnode[r];
            if (spline && s->ngr[i] > 1) {
                s->pnx[r] = rec[r - r0].n[0];
                s->pny[r] = rec[r - r0].n[1];
                mark[i] = -1;
                mark_bases(s, near, i, 0);
            }
        }
    }
}

/* grain_finish_with with the normals' choice a constant. */
STAGE static void grain_finish(mpm_scene *s, const mpm_step *ctx, int t)
{
    if (s->opt.normals != MPM_NORMALS_LINEAR && s->ns != 9)
        grain_finish_with(s, ctx, t, true);
    else
        grain_finish_with(s, ctx, t, false);
}

/* Step 2: v_i^n from Eq. 5 and v_i^{n+1} from Eq. 9. v_i^n = p_i / m_i is a mass-weighted mean of
 * point velocities, bounded at any mass; only the acceleration f_i / m_i blows up at nearly empty
 * nodes, so nodes lighter than m_min keep v_i^{n+1} = v_i^n (a zero velocity there would put a
 * spurious strain rate v / h into their neighbours' points). */
static inline void grid_entry(mpm_scene *s, size_t i, double dt)
{
    const double m = s->nm[i];
    if (m > 0) {
        const double inv = 1 / m;
        s->nvx[i] = s->npx[i] * inv;
        s->nvy[i] = s->npy[i] * inv;
        const double k = m > s->m_min ? dt * inv : 0;
        s->nax[i] = s->nvx[i] + k * s->nfx[i];
        s->nay[i] = s->nvy[i] + k * s->nfy[i];
    } else {
        s->nvx[i] = s->nvy[i] = s->nax[i] = s->nay[i] = 0;
    }
}

/* Every node with its walls; with friction the nodes of one grain (ngr = 1; shared nodes are
 * contact_update's, and the nodes no point reaches are never read). No barrier at the end (the
 * callers' next step decides). */
STAGE static void grid_update(mpm_scene *s, double dt)
{
    const int *const ngr = s->contact == MPM_CONTACT_FRICTION ? s->ngr : NULL;
#pragma omp for schedule(static) nowait
    for (size_t i = 0; i < s->nnodes; i++) {
        if (ngr && ngr[i] != 1)
            continue;
        grid_entry(s, i, dt);
        node_walls(s, s->nax, s->nay, i, true);
    }
}

/* The contact rule's constants for a step. */
typedef struct {
    double mu, sep, cap;
    bool own, conserve;
} contact_rule;

/* The sums over a shared node's pairs that the rule reads: the grains' mass gradients (tg) and
 * nodal volumes (vol), added along the node's chain in pair order. */
typedef struct {
    v2d tg;
    double vol;
} pair_sums;

static inline contact_rule rule_of(const mpm_scene *s, double dt)
{
    return (contact_rule){.mu = s->mu,
                          .sep = s->opt.separation * s->hx * s->hy,
                          .cap = s->opt.strain_cap * (s->hx < s->hy ? s->hx : s->hy) / dt,
                          .own = s->opt.normals == MPM_NORMALS_OWN,
                          .conserve = s->opt.conserve};
}

/* The contact rule for pair q at shared node i: the grain's velocity (vx, vy at entry nnodes + q)
 * against the centre-of-mass velocity at its node. With decide, Eq. 12 (the grain overtakes the
 * centre-of-mass field along its normal) and the separation check mark the pair in contact for
 * this step; without, the marks of the momentum update are reused (see nodal_velocity). A marked
 * pair gets the normal correction (Eq. 14) and Coulomb friction (Eqs. 18-23), capped by the
 * strain cap; *cx, *cy: the correction (0 without). Returns the pair's mark, which the caller
 * stores (one byte store per pair: after a store through a char pointer the compiler reloads
 * every field of the scene). */
static inline bool pair_rule(mpm_scene *s, size_t i, size_t q, double *vx, double *vy, bool decide,
                             const contact_rule *c, const pair_sums *ps, double *cx, double *cy)
{
    const size_t e = s->nnodes + q;
    *cx = *cy = 0;
    bool in = !decide; /* without decide, only marked pairs come here */
    if (!(s->nm[e] > 0))
        return in;
    double gx = s->pnx[q], gy = s->pny[q];
    if (!c->own) {
        /* The grain's mass gradient against that of everything else at the node,
         * g - (g_all - g) = 2 g - g_all: at a node of two grains their normals are then
         * exactly opposite and the corrections conserve momentum. */
        gx = 2 * gx - ps->tg[0];
        gy = 2 * gy - ps->tg[1];
    }
    const double len = sqrt(gx * gx + gy * gy);
    if (!(len > 0))
        return in;
    const double nx = gx / len, ny = gy / len;
    const double dvx = vx[e] - vx[i], dvy = vy[e] - vy[i];
    const double dn = dvx * nx + dvy * ny;
    if (decide)
        in = dn > 0 && !(c->sep > 0 && ps->vol < c->sep); /* Eq. 12, separation */
    if (!in)
        return false;
    const double tx = dvx - dn * nx, ty = dvy - dn * ny, t = sqrt(tx * tx + ty * ty);
    /* Eq. 14: the normal velocity becomes the centre-of-mass one (the force of Eq. 15);
     * Eqs. 18-23: sticking would remove the whole relative tangential velocity t (Eq. 18);
     * Coulomb caps the removal at mu times the normal correction |dn|, i.e.
     * mu' = min(mu, t / dn) (Eq. 21) along -t / |t| (Eqs. 20, 22), which is Eq. 23. */
    double ux = -dn * nx, uy = -dn * ny;
    if (t > 0) {
        const double k = fmin(c->mu * fabs(dn), t) / t;
        ux -= k * tx;
        uy -= k * ty;
    }
    if (c->cap > 0) {
        const double k = sqrt(ux * ux + uy * uy);
        if (k > c->cap) {
            ux *= c->cap / k;
            uy *= c->cap / k;
        }
    }
    vx[e] += ux;
    vy[e] += uy;
    *cx = ux;
    *cy = uy;
    return true;
}

/* The contact rule at shared node i (its velocity and its pairs' are final): each pair in pair
 * order (the node's chain, pair_rule); then (option conserve) the momentum the corrections
 * changed at the node (non-zero with three or more grains, or with the cap) is taken back evenly
 * from the corrected grains there, a common velocity shift that leaves their relative motion as
 * the rule made it. Node by node, by whichever thread takes the node (shared_node): the rule
 * reads only the node's entry and its pairs', which that thread has just set, so no barrier
 * separates it from the velocities, and the momentum sums need no pass of their own. */
static inline void contact_node(mpm_scene *s, size_t i, double *vx, double *vy, bool decide,
                                const contact_rule *c, const pair_sums *ps)
{
    const size_t nn = s->nnodes;
    double px = 0, py = 0, m = 0; /* the corrected pairs' momentum change and mass */
    bool any = false;
    for (int r = s->nhead[i]; r >= 0; r = s->pnext[r]) {
        const size_t q = (size_t)r;
        if (!decide && !s->pin[q])
            continue; /* the momentum update left it out of contact */
        double cx, cy;
        const bool in = pair_rule(s, i, q, vx, vy, decide, c, ps, &cx, &cy);
        if (decide)
            s->pin[q] = in;
        if (c->conserve && in) {
            const double mr = s->nm[nn + q];
            px += mr * cx;
            py += mr * cy;
            m += mr;
            any = true;
        }
    }
    if (!any || s->nwall[i] || (s->npres && s->nforce[i]))
        return;
    const double ex = px / m, ey = py / m;
    for (int r = s->nhead[i]; r >= 0; r = s->pnext[r])
        if (s->pin[r]) {
            vx[nn + (size_t)r] -= ex;
            vy[nn + (size_t)r] -= ey;
        }
}

/* v = p / m at entry i (the remap and USF: nodal_velocity). */
static inline void velocity_entry(mpm_scene *s, size_t i)
{
    const double m = s->nm[i];
    s->nax[i] = m > 0 ? s->npx[i] / m : 0;
    s->nay[i] = m > 0 ? s->npy[i] / m : 0;
}

/* The nodes of the contact loops per dynamic chunk: a node's work is its own (the same bits
 * whichever thread takes it), and the shared nodes are not evenly spread over the grid (on the
 * shear a static split left the second half of the nodes 1.25 times the first's contact work, in
 * instructions). */
enum { NODE_CHUNK = 256 };

/* Shared node i (every thread's scatter done): with a, b (not NULL), the node's entry of those
 * arrays first, the sum of its grains' (in pair order: the remap's momenta, USF's forces); the
 * velocities of its pairs and of the node, from the momentum update (grid, Eq. 9) or p / m (the
 * remap and USF, velocity_entry), their walls, the sums the rule reads, then the contact rule. */
static inline void shared_node(mpm_scene *s, size_t i, double dt, bool grid, bool decide, double *a,
                               double *b, const contact_rule *c)
{
    const size_t nn = s->nnodes;
    const bool sums = a != NULL;
    double sa = 0, sb = 0;
    pair_sums ps = {{0, 0}, 0};
    for (int r = s->nhead[i]; r >= 0; r = s->pnext[r]) {
        const size_t e = nn + (size_t)r;
        if (sums) {
            sa += a[e];
            sb += b[e];
        }
        if (grid)
            grid_entry(s, e, dt);
        else
            velocity_entry(s, e);
        pair_walls(s, s->nax, s->nay, (size_t)r, decide);
        if (!c->own)
            ps.tg += (v2d){s->pnx[r], s->pny[r]};
        if (c->sep > 0)
            ps.vol += s->pvol[r];
    }
    if (sums) {
        a[i] = sa;
        b[i] = sb;
    }
    if (grid)
        grid_entry(s, i, dt);
    else
        velocity_entry(s, i);
    node_walls(s, s->nax, s->nay, i, decide);
    contact_node(s, i, s->nax, s->nay, decide, c, &ps);
}

/* Step 2 for the grain fields at shared nodes: v_i^g and the updated v_i^g (Eqs. 5 and 9 over the
 * grain's points, with the centre-of-mass field's mass threshold), the walls, then the contact
 * rule. Applied after the momentum update (the paper's order) and not to the P2G velocities
 * (measured on the 0.5 m/s head-on collision: correcting v_i^g after P2G as well changed the
 * rebound speed by 1.5% and did not remove the energy error that the consistent marks below
 * fix), so a point's FLIP increment carries the whole correction. Node by node (shared_node:
 * the shared nodes' own momentum update too, which grid_update leaves out), then the barrier:
 * the points read their pairs next, whichever thread corrected them. */
STAGE static void contact_update(mpm_scene *s, double dt)
{
    const contact_rule c = rule_of(s, dt);
    /* USF: the forces were scattered from the new stress (scatter_sf), their sums are due */
    double *const a = s->def.update == MPM_USF ? s->nfx : NULL;
    double *const b = s->def.update == MPM_USF ? s->nfy : NULL;
    const int *const ngr = s->ngr; /* a local: the stores below could alias the scene */
#pragma omp for schedule(dynamic, NODE_CHUNK) nowait
    for (size_t i = 0; i < s->nnodes; i++)
        if (ngr[i] > 1)
            shared_node(s, i, dt, true, true, a, b, &c);
#pragma omp barrier
}

/* v = p / m on the centre-of-mass nodes and the grain entries, then the walls and the contact
 * rule: for the MUSL remap with the contact marks of the momentum update (decide = false), for
 * USF before the stress update with contacts decided on it (the momentum update decides again).
 * The point velocities carry the grid-update correction only in part (each point gets a weighted
 * share), so the remapped grain fields still approach at contacts and are corrected again, at
 * the pairs that Eq. 12 put in contact at the momentum update. Both choices were measured on two
 * elastic disks (R = 4 cells) meeting head-on at 0.5 m/s each, noslip ending with (kinetic +
 * elastic) / initial kinetic = 1.01: no remap correction: 1.64; remap correction re-deciding
 * Eq. 12 on the remapped field (contact switching on and off every other step): 1.58; the marks
 * of the momentum update: 1.03. */
STAGE static void nodal_velocity(mpm_scene *s, double dt, bool decide, bool sums)
{
    const size_t nn = s->nnodes;
    if (s->contact != MPM_CONTACT_FRICTION) {
#pragma omp for schedule(static)
        for (size_t i = 0; i < nn; i++) {
            velocity_entry(s, i);
            node_walls(s, s->nax, s->nay, i, decide);
        }
        return;
    }
    /* Node by node (the nodes no point reaches are never read; shared_node), then the barrier:
     * the points read their entries next */
    const contact_rule c = rule_of(s, dt);
    const int *const ngr = s->ngr; /* a local: the stores below could alias the scene */
#pragma omp for schedule(dynamic, NODE_CHUNK) nowait
    for (size_t i = 0; i < nn; i++) {
        const int n = ngr[i];
        if (n > 1) {
            shared_node(s, i, dt, false, decide, sums ? s->npx : NULL, sums ? s->npy : NULL, &c);
        } else if (n) {
            velocity_entry(s, i);
            node_walls(s, s->nax, s->nay, i, decide);
        }
    }
#pragma omp barrier
}

/* ---- the stages ------------------------------------------------------------------------------ */
/* Friction's P2G: thread t's grains scattered into their fields (the stencils too) and its pairs
 * chained per node; no barrier before the chains (its own pairs) */
void mpm_stage_grain_scatter(mpm_scene *s, mpm_step *ctx, int t)
{
    grain_scatter(s, ctx, t);
    pair_chains(s, ctx, t);
}

/* every thread's chains done: the centre-of-mass field, then the kinds of thread t's pairs
 * (node_sums' loop ends in a barrier) */
void mpm_stage_node_sums(mpm_scene *s, mpm_step *ctx, int t)
{
    node_sums(s, ctx);
    pair_kinds(s, ctx, t);
}

void mpm_stage_normals(mpm_scene *s, mpm_step *ctx, int t) { grain_finish(s, ctx, t); }

/* The gap test's first moments, by thread 0, when a friction plane has a gap (the scene's
 * nmx; nothing else) */
void mpm_stage_moments(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)ctx, (void)t;
    if (!s->nmx)
        return;
#pragma omp master
    moments(s);
#pragma omp barrier
}

void mpm_stage_grid(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)t;
    grid_update(s, ctx->dt);
}

void mpm_stage_contact(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)t;
    contact_update(s, ctx->dt);
}

/* USF: v_i^n with the walls and the contact rule, for the stress update */
void mpm_stage_velocities(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)t;
    nodal_velocity(s, ctx->dt, true, false);
}

/* MUSL: the velocities of the remapped momenta, with the contact marks of the momentum update */
void mpm_stage_remap_velocities(mpm_scene *s, mpm_step *ctx, int t)
{
    (void)t;
    nodal_velocity(s, ctx->dt, false, true);
}
