/* What the MPM step's files share (step.c the driver, transfer.c, contact.c, stress.c): the
 * step context that holds the threads' point ranges and scratch, the per-thread records of the
 * transfers, the grid axes and shape functions, the transfer's point factors, and the stages the
 * driver runs in its parallel region. */
#ifndef GRAINLAB_MPM_STEP_INTERNAL_H
#define GRAINLAB_MPM_STEP_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "core/clones.h"
#include "mpm/mpm_internal.h"

/* The step's stages stay separate functions so that a profiler (callgrind) counts each; each
 * is compiled for the baseline and for AVX2 (GRAINLAB_CLONES: the same bits). */
#define STAGE __attribute__((noinline)) GRAINLAB_CLONES

/* Two doubles in the lanes of one SSE2 register (GCC's vector extension; NEON on arm64, scalar
 * code elsewhere): each lane's arithmetic is the IEEE operation of the scalar code, so a vector
 * sum gives the bits of the two scalar ones. */
typedef double v2d __attribute__((vector_size(16)));

/* The sums of one (grain, node) pair while its grain is scattered (grain_scatter), as pairs of
 * lanes: (mass, momentum x), (momentum y, volume), (force x, force y), (mass gradient x, y); one
 * cache line per pair. */
struct mpm_pair_rec {
    v2d mpx, pyv, f, n;
};

/* A point's factors of those sums: (m, m v_x), (m v_y, V), m g, (sigma_xx, sigma_xy) V and
 * (sigma_xy, sigma_yy) V. */
struct mpm_point_fac {
    v2d mpx, pyv, fg, sa, sb;
};

/* A node's sums during the noslip transfer (to_grid), in SSE2 lanes as the frictional scatter's
 * records: (mass, momentum x), (momentum y, unused), (force x, force y). */
struct mpm_node_rec {
    v2d mpx, py, f;
};

/* The step context (step.c's, cached in the scene from its first run): the threads, their
 * scratch and the stage timings, apart from the scene's physical state.
 *
 * Threads: nt contiguous point ranges [tp[t], tp[t+1]) aligned to grains (tg[t] the first grain
 * of range t), so that a grain's points, its per-grain field entries and the nodes only it
 * touches belong to one thread; thread t's pairs (friction) are [tq[t], tq[t] + tc[t]) with
 * tq[t] = ns tp[t], in grain order, gaps between the threads' ranges; per-thread scratch: marks
 * (nt x nnodes). */
typedef struct mpm_step {
    int nt, ntcap;
    size_t *tp, *tg, *tq, *tc;
    int *tmark;           /* nt x (nnodes + 1), the last of each -1 */
    unsigned char *tnear; /* nt x nnodes, zero outside grain_finish */
    /* per-thread scratch of the frictional scatter: one record per (grain, node) pair of the
     * grain being scattered (its sums, see grain_scatter), reccap records per thread */
    struct mpm_pair_rec *trec;
    int *tfin; /* and reccap ints: a grain's pairs' final stencil entries */
    size_t reccap;
    struct mpm_point_fac *tfac; /* and the factors of a grain's points, faccap per thread */
    size_t faccap;
    size_t *gps, *gpc, gpcap; /* grain g's pairs: gpc[g] from tq[its thread] + gps[g] */
    /* The noslip transfers' chunks: nc grain-aligned point ranges [cp[c], cp[c+1]); thread t
     * scatters chunks t, t + nt, ... each into its own node records (to_grid: nrec, nnodes per
     * chunk; the remap and USF: tbuf, x and y per node, 2 nnodes doubles per chunk), added up in
     * chunk order into the nodal arrays. nc is the processor count in auto mode whatever the
     * thread count of the moment (so the tuner may run a noslip step on one thread: the same
     * bits), else the thread count. */
    int nc, nccap;
    size_t *cp;
    double *tbuf;
    struct mpm_node_rec *nrec;

    /* the step being taken: its time step, and each thread's first inverted point and first
     * point the end-of-step check finds bad, or (size_t)-1 */
    double dt;
    size_t tbad[64], tcheck[64];

    double tstage[MPM_NSTAGES]; /* mpm_timings */
    long tsteps;
} mpm_step;

/* One grid axis as axis_node needs it, taken into locals once per pass: the loops store ints
 * (stencils, marks), which could alias the scene's int fields, so reading those inside them
 * would reload these at every call. */
typedef struct {
    int n, ghost, nodes;
    bool periodic;
} grid_axis;

static inline grid_axis axis_of(const mpm_scene *s, int a)
{
    return (grid_axis){.n = s->def.cells[a],
                       .ghost = s->gl[a],
                       .nodes = a ? s->nny : s->nnx,
                       .periodic = s->def.periodic[a]};
}

/* Node index of grid node gi on axis ax (ghost layers and periodic wrap), or -1 outside. */
static inline int axis_node(grid_axis ax, int gi)
{
    if (ax.periodic)
        return gi < 0 ? gi + ax.n : (gi >= ax.n ? gi - ax.n : gi);
    const int I = gi + ax.ghost;
    return I >= 0 && I < ax.nodes ? I : -1;
}

/* axis_node for a cell index within [0, n) (the linear stencil's clamped cell): always a node. */
static inline int cell_node(grid_axis ax, int i) { return ax.periodic ? i : i + ax.ghost; }

/* The node after node I on the axis (axis_node(ax, gi + 1) for I = axis_node(ax, gi) >= 0):
 * wrapped on a periodic axis, -1 past the last node of another. */
static inline int next_node(grid_axis ax, int I)
{
    const int J = I + 1;
    if (ax.periodic)
        return J == ax.n ? 0 : J;
    return I >= 0 && J < ax.nodes ? J : -1;
}

/* floor(x) as an int for finite x in int range (grid coordinates): a truncation and a
 * correction below zero, cheaper than floor() without SSE4.1 and the same value. */
static inline int ifloor(double x)
{
    const int i = (int)x;
    return i - (x < (double)i);
}

/* Quadratic B-spline weights and derivatives (per grid unit) of the three nodes b, b + 1, b + 2
 * around a point at grid coordinate xi whose base node is b. */
static inline void bspline_at(double xi, int b, double w[3], double d[3])
{
    const double t = xi - b; /* in [0.5, 1.5) */
    w[0] = 0.5 * (1.5 - t) * (1.5 - t);
    w[1] = 0.75 - (t - 1) * (t - 1);
    w[2] = 0.5 * (t - 0.5) * (t - 0.5);
    d[0] = t - 1.5;
    d[1] = -2 * (t - 1);
    d[2] = t - 0.5;
}

/* bspline_at with its base node b = floor(xi - 1/2), returned. */
static inline int bspline(double xi, double w[3], double d[3])
{
    const int b = ifloor(xi - 0.5);
    bspline_at(xi, b, w, d);
    return b;
}

/* Each point's nodes, weights N_i(x_p) and gradients G_pi (Eq. 8): linear tensor-product shape
 * functions (4 nodes) or quadratic B-splines (9). Points are inside the grid here (checked at the
 * end of every step). */
static inline __attribute__((always_inline)) void stencil_range(mpm_scene *s, size_t pa, size_t pb,
                                                                const int ns)
{
    const double ox = s->def.origin[0], oy = s->def.origin[1];
    const int nx = s->def.cells[0], ny = s->def.cells[1], nnx = s->nnx;
    const double ihx = s->inv_hx, ihy = s->inv_hy;
    const grid_axis ax = axis_of(s, 0), ay = axis_of(s, 1);
    for (size_t p = pa; p < pb; p++) {
        const double xi = (s->x[p] - ox) * ihx, eta = (s->y[p] - oy) * ihy;
        int *n = &s->sn[ns * p];
        double *w = &s->sw[ns * p], *gx = &s->sgx[ns * p], *gy = &s->sgy[ns * p];
        if (ns == 9) {
            double wx[3], dx[3], wy[3], dy[3];
            const int bi = bspline(xi, wx, dx), bj = bspline(eta, wy, dy);
            int k = 0;
            for (int b = 0; b < 3; b++) {
                const int J = axis_node(ay, bj + b);
                for (int a = 0; a < 3; a++, k++) {
                    n[k] = J * nnx + axis_node(ax, bi + a);
                    w[k] = wx[a] * wy[b];
                    gx[k] = dx[a] * wy[b] * ihx;
                    gy[k] = wx[a] * dy[b] * ihy;
                }
            }
            continue;
        }
        int i = ifloor(xi), j = ifloor(eta);
        if (i > nx - 1)
            i = nx - 1; /* a point exactly on the upper edge */
        if (i < 0)
            i = 0;
        if (j > ny - 1)
            j = ny - 1;
        if (j < 0)
            j = 0;
        const double fx = xi - i, fy = eta - j;
        const int i0 = cell_node(ax, i), i1 = next_node(ax, i0);
        const int j0 = cell_node(ay, j), j1 = next_node(ay, j0);
        n[0] = j0 * nnx + i0;
        n[1] = j0 * nnx + i1;
        n[2] = j1 * nnx + i0;
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

/* The factors of the transfer's sums for points [p0, p1) into fac[0 .. p1 - p0): m, m v, m g and
 * sigma V (Eq. 7, m_p / rho_p = V_p), paired for the lanes. A pass of its own: with the
 * scatter in the same loop, its dozen arrays and the scatter's spill the registers. */
static inline __attribute__((always_inline)) void
point_factors(const mpm_scene *s, size_t p0, size_t p1, struct mpm_point_fac *fac)
{
    const v2d grav = {s->def.gravity[0], s->def.gravity[1]};
    const double *const xm = s->m, *const vx = s->vx, *const vy = s->vy, *const v0 = s->v0;
    const double *const F0 = s->F[0], *const F1 = s->F[1], *const F2 = s->F[2], *const F3 = s->F[3];
    const double *const s0 = s->sig[0], *const s1 = s->sig[1], *const s2 = s->sig[2];
    for (size_t p = p0; p < p1; p++) {
        const double m = xm[p], px = m * vx[p], py = m * vy[p];
        const double V = v0[p] * (F0[p] * F3[p] - F1[p] * F2[p]);
        const double sxx = V * s0[p], syy = V * s1[p], sxy = V * s2[p];
        /* the lanes: m w, p_x w | p_y w, V w | w m g - sigma V G (Eq. 7) */
        fac[p - p0] = (struct mpm_point_fac){.mpx = {m, px},
                                             .pyv = {py, V},
                                             .fg = {m * grav[0], m * grav[1]},
                                             .sa = {sxx, sxy},
                                             .sb = {sxy, syy}};
    }
}

/* The end of thread t's pairs. They stay where its scatter wrote them, [tq[t], tq[t] + tc[t])
 * with tq[t] = ns tp[t] (a grain has at most ns pairs per point; set with the ranges,
 * threads_setup): no packing pass (a serial one moved the second thread's pairs, 10 arrays, on
 * one thread). Pair indices run in grain order with gaps between the threads' ranges that no
 * loop visits: the loops over pairs take a thread's range, the node sums follow the chains of
 * pair indices.
 *
 * The node sums of the frictional contact have no serial pass: each node's pairs are chained in
 * pair order (nhead, pnext), and the threads add them up node by node over even ranges of the
 * nodes (the static split of the node loops), in pair order along the chain: the same sums as
 * one thread adding all pairs in order, so the same bits on any thread count. The loops over
 * pairs take a thread's own pairs, which its grain scatter wrote (in its cache), not an even
 * split of all pairs (half of which would be the other thread's lines). */
static inline size_t pairs_end(const mpm_step *ctx, int t) { return ctx->tq[t] + ctx->tc[t]; }

/* ---- the stages ------------------------------------------------------------------------------
 * What each thread runs inside the driver's parallel region (run_stages in step.c, whose tables
 * list them per update scheme and contact model): thread t of ctx->nt, the time step ctx->dt. A
 * stage's own barriers (the implicit ones of its omp for loops among them) are inside it; the
 * driver adds those between stages. */
typedef void mpm_stage_fn(mpm_scene *s, mpm_step *ctx, int t);

/* transfer.c: shape functions, particle to grid (noslip), grid to particle, the scatters of the
 * remap and of USF's forces */
mpm_stage_fn mpm_stage_stencil, mpm_stage_forced, mpm_stage_to_grid, mpm_stage_forces,
    mpm_stage_to_points, mpm_stage_to_points_remap, mpm_stage_remap_scatter;
/* contact.c: the grain fields (friction), the gap test's moments, the grid update with the
 * walls, the contact rule, the nodal velocities of the remap and of USF */
mpm_stage_fn mpm_stage_grain_scatter, mpm_stage_node_sums, mpm_stage_normals, mpm_stage_moments,
    mpm_stage_grid, mpm_stage_contact, mpm_stage_velocities, mpm_stage_remap_velocities;
/* stress.c: the stress update, with (USL, MUSL) or without (USF) the end-of-step check */
mpm_stage_fn mpm_stage_stress, mpm_stage_stress_check;

/* stress.c: the end-of-step check of every point, for USF (the first bad point, or
 * (size_t)-1), on nt threads */
size_t mpm_check_points(mpm_scene *s, int nt);

#endif
