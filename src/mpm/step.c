/* The MPM time step (Sec. 2 of the paper, steps 1-3): stencil, particle-to-grid transfer (lumped
 * mass Eqs. 5-6, internal force Eqs. 7-8), the grid momentum update (Eq. 9) with wall conditions,
 * the frictional multi-field contact (Sec. 3, Eqs. 12-24) on sparse per-grain nodal fields, the
 * grid-to-particle update (Eqs. 10-11, FLIP with an optional PIC blend) and the constitutive
 * update; the CFL time step and the run loop with Ctrl-C and instability checks. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <stdlib.h>

#include "core/clock.h"
#include "core/clones.h"
#include "core/interrupt.h"
#include "core/threads.h"
#include "mpm/material_inline.h"
#include "mpm/mpm_internal.h"

#ifdef GRAINLAB_HAVE_OPENMP
#include <omp.h>
#define THREAD_ID() omp_get_thread_num()
#else
#define THREAD_ID() 0
#endif

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

enum { T_STENCIL, T_P2G, T_NORMALS, T_GRID, T_CONTACT, T_G2P, T_REMAP, T_MATERIAL, T_CHECK };
const char *const mpm_stage_names[MPM_NSTAGES] = {"stencil", "p2g",   "normals",  "grid", "contact",
                                                  "g2p",     "remap", "material", "check"};

void mpm_timings(const mpm_scene *s, double seconds[MPM_NSTAGES], long *steps)
{
    for (int k = 0; k < MPM_NSTAGES; k++)
        seconds[k] = s->tstage[k];
    *steps = s->tsteps;
}

/* Thread 0 charges the time since its last reading to stage k (inside the step's parallel
 * region, after a barrier; tl is its last reading). */
#define STAGE_DONE(k)                                                                              \
    do {                                                                                           \
        if (t == 0) {                                                                              \
            const double now_ = clock_wall();                                                      \
            s->tstage[k] += now_ - tl;                                                             \
            tl = now_;                                                                             \
        }                                                                                          \
    } while (0)

/* n grain-aligned ranges of about np / n points each: range t is points [tp[t], tp[t+1]), its
 * first grain tg[t] (tg may be NULL). */
static void grain_ranges(const mpm_scene *s, int n, size_t *tp, size_t *tg)
{
    size_t g = 0, gprev = 0;
    tp[0] = 0;
    if (tg)
        tg[0] = 0;
    for (int t = 1; t < n; t++) {
        const size_t want = s->np * (size_t)t / (size_t)n;
        while (g < s->ngrains && s->gstart[g] + s->gcount[g] <= want)
            g++;
        if (g < s->ngrains && want - s->gstart[g] > s->gstart[g] + s->gcount[g] - want)
            g++; /* the boundary nearer to the target */
        if (g <= gprev)
            g = gprev + 1 < s->ngrains ? gprev + 1 : s->ngrains;
        gprev = g;
        if (tg)
            tg[t] = g;
        tp[t] = g < s->ngrains ? s->gstart[g] : s->np;
    }
    if (tg)
        tg[n] = s->ngrains;
    tp[n] = s->np;
}

/* A thread or chunk count for this scene: n within [1, min(64, grains)], 1 below 8192 points. */
static int clamp_count(const mpm_scene *s, int n)
{
    if (s->np < 8192)
        n = 1;
    if (n > 64)
        n = 64;
    if (n > (int)s->ngrains)
        n = (int)s->ngrains;
    return n < 1 ? 1 : n;
}

/* The frictional scatter's per-thread scratch (records and factors of the largest grain) and
 * the per-grain pair ranges, sized for the current grains and s->ntcap threads. */
static core_status contact_scratch(mpm_scene *s, core_error *err)
{
    /* a grain has at most ns pairs per point */
    size_t gmax = 1;
    for (size_t g = 0; g < s->ngrains; g++)
        gmax = s->gcount[g] > gmax ? s->gcount[g] : gmax;
    const size_t need = (size_t)s->ns * gmax;
    if (need > s->reccap) {
        free(s->trec);
        const size_t bytes = (size_t)s->ntcap * (need + 1) * sizeof(struct mpm_pair_rec);
        s->trec = aligned_alloc(64, (bytes + 63) / 64 * 64);
        free(s->tfin);
        s->tfin = malloc((size_t)s->ntcap * need * sizeof *s->tfin);
        s->reccap = s->trec && s->tfin ? need : 0;
        if (!s->trec || !s->tfin)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact records", need);
    }
    if (s->ngrains > s->gpcap) {
        size_t **per_grain[2] = {&s->gps, &s->gpc};
        for (int k = 0; k < 2; k++) {
            size_t *a = realloc(*per_grain[k], s->ngrains * sizeof *a);
            if (!a)
                return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu grains", s->ngrains);
            *per_grain[k] = a;
        }
        s->gpcap = s->ngrains;
    }
    if (gmax > s->faccap) {
        free(s->tfac);
        const size_t bytes = (size_t)s->ntcap * gmax * sizeof(struct mpm_point_fac);
        s->tfac = aligned_alloc(64, (bytes + 63) / 64 * 64);
        s->faccap = s->tfac ? gmax : 0;
        if (!s->tfac)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact records", gmax);
    }
    return CORE_OK;
}

/* Threads: every parallel region runs s->nt threads, thread t on points [tp[t], tp[t+1]); the
 * noslip transfers scatter by chunks (mpm_internal.h). The ranges and all reductions are fixed
 * for a thread count (friction: for any thread count; noslip: for a chunk count), so results are
 * the same bits run after run. */
static core_status threads_setup(mpm_scene *s, core_error *err)
{
    const int nt = clamp_count(s, threads_get());
    const int nc = s->contact == MPM_CONTACT_FRICTION ? 1 : clamp_count(s, threads_max());
    if (nc > s->nccap || !s->cp) {
        size_t *a = realloc(s->cp, (size_t)(nc + 1) * sizeof *a);
        if (!a)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d chunks", nc);
        s->cp = a;
        free(s->tbuf);
        s->tbuf = malloc((size_t)nc * 2 * s->nnodes * sizeof *s->tbuf);
        free(s->nrec);
        const size_t bytes = (size_t)nc * s->nnodes * sizeof *s->nrec;
        s->nrec = aligned_alloc(64, (bytes + 63) / 64 * 64);
        if (!s->tbuf || !s->nrec)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d chunks", nc);
        s->nccap = nc;
    }
    s->nc = nc;
    grain_ranges(s, nc, s->cp, NULL);
    if (nt > s->ntcap || !s->tp) {
        size_t **ranges[4] = {&s->tp, &s->tg, &s->tq, &s->tc};
        for (int r = 0; r < 4; r++) {
            size_t *a = realloc(*ranges[r], (size_t)(nt + 1) * sizeof *a);
            if (!a)
                return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
            *ranges[r] = a;
        }
        free(s->tmark);
        /* per thread nnodes + 1 marks: the last stays -1 (grain_scatter) */
        s->tmark = malloc((size_t)nt * (s->nnodes + 1) * sizeof *s->tmark);
        if (!s->tmark)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
        for (size_t i = 0; i < (size_t)nt * (s->nnodes + 1); i++)
            s->tmark[i] = -1;
        free(s->tnear);
        s->tnear = calloc((size_t)nt * s->nnodes, 1);
        if (!s->tnear)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
        s->ntcap = nt;
        s->reccap = s->faccap = 0; /* the records below are per thread */
    }
    s->nt = nt;
    grain_ranges(s, nt, s->tp, s->tg);
    for (int u = 0; u <= nt; u++)
        s->tq[u] = (size_t)s->ns * s->tp[u]; /* thread u's pairs (friction), grain_scatter */
    if (s->contact == MPM_CONTACT_FRICTION)
        return contact_scratch(s, err);
    return CORE_OK;
}

mpm_run_def mpm_default_run_def(void)
{
    return (mpm_run_def){.steps = 0, .time_end = -1, .dt = 0, .cfl = MPM_DEFAULT_CFL};
}

static double max_speed(const mpm_scene *s)
{
    double v2 = 0;
#pragma omp parallel for schedule(static) reduction(max : v2) if (s->np > 8192)
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
        return core_fail(err, CORE_ERR_STATE,
                         "the scene has no material points: add a grain first");
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
STAGE static void to_grid(mpm_scene *s, int t)
{
    const size_t nn = s->nnodes;
    for (int c = t; c < s->nc; c += s->nt) {
        struct mpm_node_rec *const r = s->nrec + (size_t)c * nn;
        memset(r, 0, nn * sizeof *r);
        if (s->ns == 4)
            to_grid_range(s, s->cp[c], s->cp[c + 1], r, 4);
        else
            to_grid_range(s, s->cp[c], s->cp[c + 1], r, s->ns);
    }
    const struct mpm_node_rec *const rec = s->nrec;
    const int nc = s->nc;
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
static inline __attribute__((always_inline)) void
grain_scatter_with(mpm_scene *s, int t, const int ns, const bool volumes, const bool spline_normals)
{
    const size_t nn = s->nnodes;
    int *const mark = s->tmark + (size_t)t * (nn + 1);
    struct mpm_pair_rec *const rec = s->trec + (size_t)t * (s->reccap + 1) + 1;
    const size_t base = (size_t)ns * s->tp[t];
    /* the arrays as locals: the stores below cannot change them, and the compiler need not
     * reload them */
    double *const pm = s->nm + nn, *const ppx = s->npx + nn, *const ppy = s->npy + nn;
    double *const pfx = s->nfx + nn, *const pfy = s->nfy + nn;
    double *const pnx = s->pnx, *const pny = s->pny, *const pvol = s->pvol;
    int *const pnode = s->pnode, *const pgrain = s->pgrain;
    struct mpm_point_fac *const fac = s->tfac + (size_t)t * s->faccap;
    size_t q = base;
    for (size_t g = s->tg[t]; g < s->tg[t + 1]; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g];
        /* three passes over the grain's points (in cache), each with few live pointers: the
         * stencils, each point's factors, the sums */
        stencil_range(s, p0, p1, ns);
        point_factors(s, p0, p1, fac);
        int nr = 0; /* the grain's pairs so far: records [0, nr), pairs q .. q + nr - 1 */
        s->gps[g] = q - base;
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
        s->gpc[g] = (size_t)nr;
    }
    s->tc[t] = q - base;
}

/* grain_scatter_with with constant options for the common case (linear shapes, spline normals,
 * no separation check): the stencil loop unrolls and the per-entry tests go. */
STAGE static void grain_scatter(mpm_scene *s, int t)
{
    const bool spline_normals = s->opt.normals != MPM_NORMALS_LINEAR && s->ns != 9;
    const bool volumes = s->opt.separation > 0;
    if (s->ns == 4 && spline_normals && !volumes)
        grain_scatter_with(s, t, 4, false, true);
    else
        grain_scatter_with(s, t, s->ns, volumes, spline_normals);
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
static inline size_t pairs_end(const mpm_scene *s, int t) { return s->tq[t] + s->tc[t]; }

/* Thread t's pairs chained per node within the thread (pnext, -1 after the thread's last pair
 * at a node), its first pair at each node left in its marks (right after its scatter). */
STAGE static void pair_chains(mpm_scene *s, int t)
{
    int *const mark = s->tmark + (size_t)t * (s->nnodes + 1);
    const int *const pnode = s->pnode;
    int *const pnext = s->pnext;
    for (size_t q = pairs_end(s, t); q-- > s->tq[t];) {
        const int i = pnode[q];
        pnext[q] = mark[i];
        mark[i] = (int)q;
    }
}

/* Every node (every thread's pair_chains done): its chain linked on through the threads' chains
 * (nhead, pnext), walked for the grain count, the centre-of-mass field as the sum of the grain
 * fields (Eqs. 5-7 over all points) and the prescribed grain forcing the node (the last one in
 * grain order, as mark_forced); zeros where no point reaches. */
STAGE static void node_sums(mpm_scene *s)
{
    const size_t nn = s->nnodes, stride = nn + 1;
    const int nt = s->nt;
    /* the arrays as locals: the int stores below could alias the scene's fields */
    const int *const mark = s->tmark, *const pgrain = s->pgrain, *const gpres = s->gpres;
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
STAGE static void pair_kinds(mpm_scene *s, int t)
{
    int *const mark = s->tmark + (size_t)t * (s->nnodes + 1);
    for (size_t q = s->tq[t]; q < pairs_end(s, t); q++) {
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
static inline __attribute__((always_inline)) void grain_finish_with(mpm_scene *s, int t,
                                                                    const bool spline)
{
    const int ns = s->ns;
    const size_t nn = s->nnodes;
    const double ox = s->def.origin[0], oy = s->def.origin[1];
    const double ihx = s->inv_hx, ihy = s->inv_hy;
    const v2d ih = {ihx, ihy};
    const int nnx = s->nnx, skip = (int)nn; /* mark[nn] = -1 always */
    const grid_axis ax = axis_of(s, 0), ay = axis_of(s, 1);
    int *const mark = s->tmark + (size_t)t * (nn + 1);
    unsigned char *const near = s->tnear + (size_t)t * nn;
    /* rec[-1]: a dummy record for the nodes that are not shared pairs of the grain */
    struct mpm_pair_rec *const rec = s->trec + (size_t)t * (s->reccap + 1) + 1;
    int *const fin = s->tfin + (size_t)t * s->reccap;
    const double *const xs = s->x, *const ys = s->y, *const xm = s->m;
    /* grains in any order, by any thread: a grain's normals are its own (its pairs, in its
     * points' order), and the threads' loads differ (the shared nodes are not evenly spread) */
#pragma omp for schedule(dynamic, 4) nowait
    for (size_t g = 0; g < s->ngrains; g++) {
        const size_t p0 = s->gstart[g], p1 = p0 + s->gcount[g];
        int u = 0; /* the thread that scattered the grain, whose pairs start at tq[u] */
        while (g >= s->tg[u + 1])
            u++;
        const size_t r0 = s->tq[u] + s->gps[g], r1 = r0 + s->gpc[g];
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
        const size_t sv0 = (size_t)ns * s->tp[u] + s->gps[g];
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
STAGE static void grain_finish(mpm_scene *s, int t)
{
    if (s->opt.normals != MPM_NORMALS_LINEAR && s->ns != 9)
        grain_finish_with(s, t, true);
    else
        grain_finish_with(s, t, false);
}

/* Inside the parallel region: the stages above with the barriers between them; *tlp is thread
 * 0's last clock reading (STAGE_DONE). */
static void grain_fields(mpm_scene *s, int t, double *tlp)
{
    double tl = *tlp;
    grain_scatter(s, t);
    pair_chains(s, t); /* its own pairs: no barrier before */
#pragma omp barrier
    node_sums(s); /* its loop's barrier: every node done */
    pair_kinds(s, t);
    STAGE_DONE(T_P2G);
    grain_finish(s, t);
#pragma omp barrier
    *tlp = tl;
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
static void zero_own(mpm_scene *s, int t, double *a, double *b)
{
    const size_t nn = s->nnodes;
    const int *const pnode = s->pnode;
    const unsigned char *const pshared = s->pshared;
    for (size_t q = s->tq[t]; q < pairs_end(s, t); q++) {
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
static inline __attribute__((always_inline)) void to_points_with(mpm_scene *s, double dt, int t,
                                                                 const int ns, const bool remap)
{
    const double pic = s->def.pic, flip = 1 - pic;
    const int *const sf = s->sf;
    const double *const sw = s->sw;
    const double *const nax = s->nax, *const nay = s->nay, *const nvx = s->nvx, *const nvy = s->nvy;
    double *const x = s->x, *const y = s->y, *const ux = s->ux, *const uy = s->uy;
    double *const vx = s->vx, *const vy = s->vy;
    const bool lanes = !s->no_lanes; /* the lanes below, or one point at a time (the tests') */
    if (remap)
        zero_own(s, t, s->npx, s->npy);
    for (size_t g = s->tg[t]; g < s->tg[t + 1]; g++) {
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
STAGE static void to_points(mpm_scene *s, double dt, int t, bool remap)
{
    if (s->ns == 4 && remap)
        to_points_with(s, dt, t, 4, true);
    else if (s->ns == 4)
        to_points_with(s, dt, t, 4, false);
    else
        to_points_with(s, dt, t, s->ns, remap);
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
static inline __attribute__((always_inline)) void
scatter_sf_with(mpm_scene *s, int t, double *a, double *b, bool force, const int ns)
{
    const size_t nn = s->nnodes;
    if (s->contact != MPM_CONTACT_FRICTION) {
        /* by chunks, each into its x, y lanes per node (tbuf), added up in chunk order as
         * to_grid does */
        for (int c = t; c < s->nc; c += s->nt) {
            double *const r = s->tbuf + (size_t)c * 2 * nn;
            memset(r, 0, 2 * nn * sizeof *r);
            scatter_lanes_range(s, s->cp[c], s->cp[c + 1], r, force, ns);
        }
        const double *const r = s->tbuf;
        const int nc = s->nc;
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
    zero_own(s, t, a, b);
    if (force)
        forces_into(s, s->tp[t], s->tp[t + 1], a, b, ns);
    else
        momenta_into(s->sf, s->sw, s->m, s->vx, s->vy, s->tp[t], s->tp[t + 1], ns, a, b);
#pragma omp barrier
}

/* scatter_sf_with with ns = 4 (linear shapes) a constant: the stencil loops unroll. */
STAGE static void scatter_sf(mpm_scene *s, int t, double *a, double *b, bool force)
{
    if (s->ns == 4)
        scatter_sf_with(s, t, a, b, force, 4);
    else
        scatter_sf_with(s, t, a, b, force, s->ns);
}

/* MUSL: the updated point momenta mapped back (Eq. 5 with v_p^{n+1}) give the nodal velocities
 * the strain increment is taken from; with friction each grain's own field at shared nodes,
 * scattered by to_points. */
STAGE static void remap(mpm_scene *s, double dt, int t)
{
    if (s->contact == MPM_CONTACT_FRICTION) {
#pragma omp barrier
    } else {
        scatter_sf(s, t, s->npx, s->npy, false);
    }
    nodal_velocity(s, dt, false, true);
}

/* The end-of-step check's bounds per axis: [lo, hi) of a periodic axis, [lo, hi] (the slack
 * beyond the grid included) of another. Taken once per pass: inside the point loop, stores to
 * the point arrays could alias the scene's fields, which would be reloaded at every point. */
typedef struct {
    double lo[2], hi[2];
    bool periodic[2];
} check_bounds;

static inline check_bounds bounds_of(const mpm_scene *s)
{
    check_bounds b;
    for (int a = 0; a < 2; a++) {
        const double o = s->def.origin[a], L = s->def.size[a];
        b.periodic[a] = s->def.periodic[a];
        b.lo[a] = b.periodic[a] ? o : o - s->slack[a][0];
        b.hi[a] = b.periodic[a] ? o + L : o + L + s->slack[a][1];
    }
    return b;
}

/* A coordinate outside its periodic axis wrapped back (rare: out of line). */
static __attribute__((noinline, cold)) void wrap_axis(const mpm_scene *s, int a, double *c)
{
    const double o = s->def.origin[a], L = s->def.size[a];
    *c -= L * floor((*c - o) / L);
    if (*c >= o + L) /* rounding of a value just below o */
        *c = o;
}

/* The end-of-step check of a point at (*x, *y) with velocity (vx, vy) and in-plane stress sig:
 * wraps it on periodic axes; true when it is non-finite or outside the grid on an axis that is
 * not periodic. */
static inline bool point_bad_at(const mpm_scene *s, const check_bounds *b, double *x, double *y,
                                double vx, double vy, const double sig[3])
{
    /* 0 * v is 0 for finite v and NaN for inf or NaN: one test for all seven */
    const double z = 0 * *x + 0 * *y + 0 * vx + 0 * vy + 0 * sig[0] + 0 * sig[1] + 0 * sig[2];
    if (!(z == 0))
        return true;
    double *c[2] = {x, y};
    bool bad = false;
    for (int a = 0; a < 2; a++) {
        const double v = *c[a];
        if (b->periodic[a]) {
            if (v < b->lo[a] || v >= b->hi[a])
                wrap_axis(s, a, c[a]);
        } else if (v < b->lo[a] || v > b->hi[a]) {
            bad = true;
        }
    }
    return bad;
}

static inline bool point_bad(mpm_scene *s, const check_bounds *b, size_t p)
{
    const double sig[3] = {s->sig[0][p], s->sig[1][p], s->sig[2][p]};
    return point_bad_at(s, b, &s->x[p], &s->y[p], s->vx[p], s->vy[p], sig);
}

/* Whether the first bad point (point_bad) is finite but outside the grid (1) or not (0). */
static int bad_why(const mpm_scene *s, size_t first)
{
    return isfinite(s->x[first]) && isfinite(s->y[first]) && isfinite(s->vx[first]) &&
           isfinite(s->vy[first]) && isfinite(s->sig[0][first]) && isfinite(s->sig[1][first]) &&
           isfinite(s->sig[2][first]);
}

/* Whether the end-of-step check (point_bad_at) may have anything to do for a point: a
 * non-finite value, or a coordinate outside [lo, hi) (a periodic one to wrap, another that is
 * bad; a non-periodic one at hi exactly is a suspect that point_bad_at then clears).
 * Branch-free, for the stress update's lanes. */
static inline bool point_suspect(const check_bounds *b, double x, double y, double vx, double vy,
                                 const double sig[3])
{
    /* s - s is 0 for a finite sum and NaN for a non-finite value (or a sum that overflows: a
     * suspect too, which point_bad_at clears) */
    const double sum = x + y + vx + vy + sig[0] + sig[1] + sig[2];
    return !(sum - sum == 0) | (x < b->lo[0]) | (x >= b->hi[0]) | (y < b->lo[1]) | (y >= b->hi[1]);
}

/* The stress update works on blocks of CB points in passes, so that the arithmetic before and
 * after the (scalar, libm) logarithms runs two points at a time in SSE2 lanes: (A1) the
 * velocity gradient's gather (scalar: SSE2 has no gather) and the increment f; (A2, lanes) F,
 * the trial b_e and its eigen-split; (B) the two logarithms per point; (C, lanes) the elastic
 * return, b_e and sigma, with a flag on each point a lane cannot finish (possibly plastic, or one
 * the end-of-step check must look at); (D) the flagged points, scalar, in order. Each lane does
 * material_update_zz's operations in its order through the same helpers, and IEEE arithmetic is
 * the same per lane as scalar, so the bits are the scalar update's. (C) runs over the block's
 * runs of points of one material. A block with an inverted point takes (B)-(D) one point at a
 * time (finish_point), as material_update_zz does. With s->no_lanes, (A2)-(D) are point_scalar
 * instead: the reference tests/mpm/test_mpm_lanes.c compares the lanes with. */
enum { CB = 64 }; /* the block (cblock): 7 kB, in L1; CB = 16 cost 7 instructions per point more */
typedef struct {
    double f[4][CB], tr[3][CB], dir[3][CB], lg[2][CB], J[CB];
    double flag[CB]; /* 1 or 0: doubles, which SSE2 selects as lanes (64-bit integers not) */
} cblock;

/* Point p's new in-plane b_e and stress stored, then with chk the end-of-step check (*first: the
 * first bad point). */
static inline void store_point(mpm_scene *s, const check_bounds *cb, bool chk, size_t p,
                               const double be[3], const double sig[4], size_t *first)
{
    s->be[0][p] = be[0];
    s->be[1][p] = be[1];
    s->be[2][p] = be[2];
    s->sig[0][p] = sig[0];
    s->sig[1][p] = sig[1];
    s->sig[2][p] = sig[2];
    s->sig[3][p] = sig[3];
    if (chk && point_bad_at(s, cb, &s->x[p], &s->y[p], s->vx[p], s->vy[p], sig) &&
        *first == (size_t)-1)
        *first = p;
}

/* Point j (p) of a block, scalar, from its log strains eps: material_point, the stores, and
 * with chk the end-of-step check (*first: the first bad point). */
static inline void finish_point(mpm_scene *s, const check_bounds *cb, bool chk, const cblock *T,
                                int j, size_t p, const double eps[3], double dt, size_t *first)
{
    const double tr[3] = {T->tr[0][j], T->tr[1][j], T->tr[2][j]};
    const double dir[3] = {T->dir[0][j], T->dir[1][j], T->dir[2][j]};
    double be[3], sig[4];
    material_point(&s->mats[s->mat[p]], dt, tr, eps, dir, T->J[j], be, &s->be[3][p], &s->lzz[p],
                   &s->eps_p[p], s->rate ? &s->rate[p] : NULL, sig);
    store_point(s, cb, chk, p, be, sig, first);
}

/* Point p from its increment f, scalar: F, material_update_zz, the stores, with chk the
 * end-of-step check; *bad: the first inverted point, *first: the first bad one. The stress
 * update's reference (s->no_lanes). */
static void point_scalar(mpm_scene *s, const check_bounds *cb, bool chk, const double f[4],
                         double dt, size_t p, size_t *bad, size_t *first)
{
    const double Fa = s->F[0][p], Fb = s->F[1][p], Fc = s->F[2][p], Fd = s->F[3][p];
    const double G0 = f[0] * Fa + f[1] * Fc, G1 = f[0] * Fb + f[1] * Fd;
    const double G2 = f[2] * Fa + f[3] * Fc, G3 = f[2] * Fb + f[3] * Fd;
    s->F[0][p] = G0;
    s->F[1][p] = G1;
    s->F[2][p] = G2;
    s->F[3][p] = G3;
    const double J = G0 * G3 - G1 * G2;
    double be[3] = {s->be[0][p], s->be[1][p], s->be[2][p]}, sig[4];
    if (material_update_zz(&s->mats[s->mat[p]], f, dt, be, &s->be[3][p], &s->lzz[p],
                           &s->eps_p[p], s->rate ? &s->rate[p] : NULL, J, sig) < 0) {
        if (*bad == (size_t)-1)
            *bad = p;
        return;
    }
    store_point(s, cb, chk, p, be, sig, first);
}

/* material_update_zz's and log_strains's conditions (det f > 0, J > 0, l2 > 0 and ln(b_e,zz) / 2
 * = lz > -inf), branch-free. */
static inline bool update_ok(const double f[4], double J, double l2, double lz)
{
    return (f[0] * f[3] - f[1] * f[2] > 0) & (J > 0) & (l2 > 0) & (lz > -INFINITY);
}

/* (A2) of point j (p): F, J, the trial b_e and its eigen-split into the block; returns whether
 * the update can go on (update_ok: 1, else 0). A function called from the simd loop, so that
 * its arrays are scalarised after inlining rather than made the loop's per-lane arrays. */
static inline __attribute__((always_inline)) double
lane_trial(cblock *T, int j, size_t p, double *F0, double *F1, double *F2, double *F3,
           const double *b0, const double *b1, const double *b2, const double *lzz)
{
    const double f[4] = {T->f[0][j], T->f[1][j], T->f[2][j], T->f[3][j]};
    const double Fa = F0[p], Fb = F1[p], Fc = F2[p], Fd = F3[p];
    const double G0 = f[0] * Fa + f[1] * Fc, G1 = f[0] * Fb + f[1] * Fd;
    const double G2 = f[2] * Fa + f[3] * Fc, G3 = f[2] * Fb + f[3] * Fd;
    F0[p] = G0;
    F1[p] = G1;
    F2[p] = G2;
    F3[p] = G3;
    const double J = G0 * G3 - G1 * G2;
    const double be[3] = {b0[p], b1[p], b2[p]};
    double tr[3], l1, l2, dir[3];
    trial_be(f, be, tr);
    eig2(tr[0], tr[1], tr[2], &l1, &l2, dir);
    const double ok = update_ok(f, J, l2, lzz[p]) ? 1.0 : 0.0;
    for (int c = 0; c < 3; c++) {
        T->tr[c][j] = tr[c];
        T->dir[c][j] = dir[c];
    }
    T->lg[0][j] = l1;
    T->lg[1][j] = l2;
    T->J[j] = J;
    return ok;
}

/* The arrays of the elastic pass (C). */
typedef struct {
    const double *lzz, *eps_p, *x, *y, *vx, *vy;
    double *b0, *b1, *b2, *s0, *s1, *s2, *s3;
} elastic_ctx;

/* (C) of point j (p), material m: the elastic return from the logarithms (T->lg), its b_e and
 * sigma stored; returns (and flags) 1 when (D) must look at the point: possibly plastic (vm, a
 * von Mises material, and not within_yield), or with chk a suspect for the end-of-step check;
 * else 0. */
static inline __attribute__((always_inline)) double
lane_elastic(cblock *T, int j, size_t p, const mpm_material *m, const check_bounds *cb,
             const elastic_ctx *restrict E, const bool vm, const bool chk)
{
    const double eps[3] = {0.5 * T->lg[0][j], 0.5 * T->lg[1][j], E->lzz[p]};
    const double dir[3] = {T->dir[0][j], T->dir[1][j], T->dir[2][j]};
    double ev, e[3], sig[4];
    const double en2 = dev_split(eps, &ev, e);
    stress_of(m, ev, e, dir, T->J[j], sig);
    E->b0[p] = T->tr[0][j];
    E->b1[p] = T->tr[1][j];
    E->b2[p] = T->tr[2][j];
    E->s0[p] = sig[0];
    E->s1[p] = sig[1];
    E->s2[p] = sig[2];
    E->s3[p] = sig[3];
    double f = 0;
    if (vm)
        f = within_yield(m, en2, E->eps_p[p]) ? f : 1.0;
    if (chk)
        f = point_suspect(cb, E->x[p], E->y[p], E->vx[p], E->vy[p], sig) ? 1.0 : f;
    T->flag[j] = f;
    return f;
}

/* The loop of (C) over points ja..jb-1 of the block, of one material m, with vm and chk
 * constants; returns the number of flagged points. */
static inline __attribute__((always_inline)) double
pass_elastic(cblock *T, int ja, int jb, size_t p0, const mpm_material *m, const check_bounds *cb,
             const elastic_ctx *E, const bool vm, const bool chk)
{
    /* local copies, which the stores cannot alias: held in registers, not reloaded */
    const elastic_ctx e = *E;
    const mpm_material mc = *m;
    double any = 0; /* a sum of 0s and 1s: exact in any order */
#pragma omp simd reduction(+ : any)
    for (int j = ja; j < jb; j++)
        any += lane_elastic(T, j, p0 + (size_t)j, &mc, cb, &e, vm, chk);
    return any;
}

/* Step 3, continued: velocity gradient L = sum_i v_i G_pi, F <- (I + dt L) F, stress update.
 * Returns the first point that inverts, or (size_t)-1; with check, each point's end-of-step
 * check (point_bad_at) follows its update, and *check is the first bad point. */
static inline __attribute__((always_inline)) size_t constitutive_with(mpm_scene *s, double dt,
                                                                      int t, const double *vx,
                                                                      const double *vy,
                                                                      size_t *check, const int ns)
{
    size_t bad = (size_t)-1, first = (size_t)-1;
    /* the arrays as locals: stores through one could alias the scene's fields, which would be
     * reloaded; the lanes' iterations are independent (omp simd) */
    const int *const sf = s->sf, *const mat = s->mat;
    const double *const sgx = s->sgx, *const sgy = s->sgy;
    double *const F0 = s->F[0], *const F1 = s->F[1], *const F2 = s->F[2], *const F3 = s->F[3];
    double *const b0 = s->be[0], *const b1 = s->be[1], *const b2 = s->be[2];
    const double *const lzz = s->lzz;
    const mpm_material *const mats = s->mats;
    const check_bounds cb = bounds_of(s);
    const bool chk = check != NULL;
    const elastic_ctx E = {.lzz = lzz,
                           .eps_p = s->eps_p,
                           .x = s->x,
                           .y = s->y,
                           .vx = s->vx,
                           .vy = s->vy,
                           .b0 = b0,
                           .b1 = b1,
                           .b2 = b2,
                           .s0 = s->sig[0],
                           .s1 = s->sig[1],
                           .s2 = s->sig[2],
                           .s3 = s->sig[3]};
    cblock T;
    const size_t pe = s->tp[t + 1];
    for (size_t p0 = s->tp[t]; p0 < pe; p0 += CB) {
        const int nb = pe - p0 < CB ? (int)(pe - p0) : CB;
        /* (A1) */
        for (int j = 0; j < nb; j++) {
            const size_t p = p0 + (size_t)j;
            const int *n = &sf[ns * p];
            const double *gx = &sgx[ns * p], *gy = &sgy[ns * p];
            /* {L_xx, L_yx} and {L_xy, L_yy} in the lanes of two vectors (v2d), each lane's sum
             * in the scalar order */
            v2d Lx = {0, 0}, Ly = {0, 0};
            for (int k = 0; k < ns; k++) {
                const int i = n[k];
                const v2d v = {vx[i], vy[i]}, gxk = {gx[k], gx[k]}, gyk = {gy[k], gy[k]};
                Lx += v * gxk;
                Ly += v * gyk;
            }
            const v2d dx = dt * Lx, dy = dt * Ly;
            T.f[0][j] = 1 + dx[0];
            T.f[1][j] = dy[0];
            T.f[2][j] = dx[1];
            T.f[3][j] = 1 + dy[1];
            __asm__(""); /* keeps the loop over the points scalar: SSE2 has no gather */
        }
        if (s->no_lanes) {
            for (int j = 0; j < nb; j++) {
                const double f[4] = {T.f[0][j], T.f[1][j], T.f[2][j], T.f[3][j]};
                point_scalar(s, &cb, chk, f, dt, p0 + (size_t)j, &bad, &first);
            }
            continue;
        }
        /* (A2) */
        double nok = 0; /* a sum of 0s and 1s: exact in any order */
#pragma omp simd reduction(+ : nok)
        for (int j = 0; j < nb; j++)
            nok += lane_trial(&T, j, p0 + (size_t)j, F0, F1, F2, F3, b0, b1, b2, lzz);
        if (__builtin_expect(nok != nb, 0)) {
            /* (B)-(D) one point at a time */
            for (int j = 0; j < nb; j++) {
                const size_t p = p0 + (size_t)j;
                const double f[4] = {T.f[0][j], T.f[1][j], T.f[2][j], T.f[3][j]};
                if (!update_ok(f, T.J[j], T.lg[1][j], lzz[p])) {
                    if (bad == (size_t)-1)
                        bad = p;
                    continue;
                }
                const double eps[3] = {0.5 * log(T.lg[0][j]), 0.5 * log(T.lg[1][j]), lzz[p]};
                finish_point(s, &cb, chk, &T, j, p, eps, dt, &first);
            }
            continue;
        }
        /* (B) */
        for (int j = 0; j < nb; j++) {
            T.lg[0][j] = log(T.lg[0][j]);
            T.lg[1][j] = log(T.lg[1][j]);
        }
        /* (C), by runs of points of one material */
        double any = 0;
        int other = 0; /* points of another material than the first: a count that vectorises */
        for (int j = 1; j < nb; j++)
            other += mat[p0 + (size_t)j] != mat[p0];
        for (int ja = 0, jb; ja < nb; ja = jb) {
            const int mk = mat[p0 + (size_t)ja];
            if (!other)
                jb = nb;
            else
                for (jb = ja + 1; jb < nb && mat[p0 + (size_t)jb] == mk; jb++)
                    ;
            const mpm_material *const m = &mats[mk];
            if (m->model != MPM_ELASTIC && m->model != MPM_VONMISES) {
                /* the granular continuum models: every point in (D) */
                for (int j = ja; j < jb; j++)
                    T.flag[j] = 1;
                any += jb - ja;
                continue;
            }
            const bool vm = m->model == MPM_VONMISES;
            any += vm ? (chk ? pass_elastic(&T, ja, jb, p0, m, &cb, &E, true, true)
                             : pass_elastic(&T, ja, jb, p0, m, &cb, &E, true, false))
                      : (chk ? pass_elastic(&T, ja, jb, p0, m, &cb, &E, false, true)
                             : pass_elastic(&T, ja, jb, p0, m, &cb, &E, false, false));
        }
        /* (D) */
        if (any)
            for (int j = 0; j < nb; j++)
                if (T.flag[j]) {
                    const size_t p = p0 + (size_t)j;
                    const double eps[3] = {0.5 * T.lg[0][j], 0.5 * T.lg[1][j], lzz[p]};
                    finish_point(s, &cb, chk, &T, j, p, eps, dt, &first);
                }
    }
    if (check)
        *check = first;
    return bad;
}

/* constitutive_with with ns = 4 (linear shapes) a constant: the stencil loops unroll. */
STAGE static size_t constitutive(mpm_scene *s, double dt, int t, const double *vx, const double *vy,
                                 size_t *check)
{
    if (s->ns == 4)
        return constitutive_with(s, dt, t, vx, vy, check, 4);
    return constitutive_with(s, dt, t, vx, vy, check, s->ns);
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

/* ---- the likely cause of an instability ------------------------------------------------------
 * From what the scene shows, in this order: a time step the user forced above the CFL limit (only
 * then is dt blamed); a point out of the grid by an edge without a wall; a material so soft that
 * gravity alone strains its grain by more than half (a modulus in the wrong units). */
enum { MPM_BAD_INVERTED, MPM_BAD_LEFT, MPM_BAD_NONFINITE };
#define MPM_SOFT_STRAIN 0.5 /* rho g h / G over the grain's height h */

static void likely_cause(const mpm_scene *s, size_t p, int kind, const mpm_run_def *run,
                         const mpm_timestep *ts, char *buf, size_t n)
{
    if (run->dt > 0 && run->dt > ts->limit) {
        snprintf(buf, n,
                 "the time step is too large: dt = %.3g s is %.3g times the CFL limit %.3g s "
                 "(forced); use dt = \"auto\" or a smaller dt",
                 run->dt, run->dt / ts->limit, ts->limit);
        return;
    }
    static const char *const edge[4] = {"left", "right", "bottom", "top"};
    if (kind == MPM_BAD_LEFT) {
        const double c[2] = {s->x[p], s->y[p]};
        for (int a = 0; a < 2; a++) {
            const double o = s->def.origin[a], L = s->def.size[a];
            int e = c[a] < o ? 2 * a : c[a] > o + L ? 2 * a + 1 : -1;
            if (s->def.periodic[a] || e < 0 || s->def.walls[e] != MPM_WALL_NONE)
                continue;
            snprintf(buf, n,
                     "no wall on the %s edge of the grid: give it one (walls = { %s = 'noslip' "
                     "}, or 'slip', 'friction') or make the %c axis periodic",
                     edge[e], edge[e], a ? 'y' : 'x');
            return;
        }
    }
    const double g = sqrt(s->def.gravity[0] * s->def.gravity[0] +
                          s->def.gravity[1] * s->def.gravity[1]);
    const int gr = s->grain[p];
    const mpm_material *m = &s->mats[s->mat[p]];
    double h = 0; /* the grain's height along gravity */
    if (g > 0) {
        const int a = fabs(s->def.gravity[1]) >= fabs(s->def.gravity[0]); /* 1: y */
        h = s->def.size[a];
        if (s->gdef && gr >= 0 && (size_t)gr < s->ngrains) {
            const mpm_grain_def *gd = &s->gdef[gr];
            if (gd->shape == MPM_DISK)
                h = 2 * gd->radius;
            else if (gd->shape == MPM_RECT)
                h = gd->hi[a] - gd->lo[a];
        }
    }
    double strain = m->shear > 0 ? m->density * g * h / m->shear : 0;
    if (strain > MPM_SOFT_STRAIN) {
        snprintf(buf, n,
                 "the material is too soft for the load: shear = %.3g Pa gives strains of %.3g "
                 "under gravity alone (rho g h / G over the grain's height h = %.3g m); check the "
                 "units (Pa)",
                 m->shear, strain, h);
        return;
    }
    const bool fixed = run->dt > 0;
    if (kind == MPM_BAD_LEFT)
        snprintf(buf, n,
                 "a point faster than the step allows through a wall (dt = %.3g s, CFL limit "
                 "%.3g s at the start of the run)%s",
                 fixed ? run->dt : ts->dt_auto, ts->limit,
                 fixed ? "; use dt = \"auto\" or a smaller dt" : "; use a smaller cfl");
    else if (fixed)
        snprintf(buf, n,
                 "the time step dt = %.3g s (CFL limit %.3g s at the start of the run) is too "
                 "large for the wave speed, or a point is too strongly compressed between walls "
                 "or grains; use dt = \"auto\" or a smaller dt",
                 run->dt, ts->limit);
    else
        snprintf(buf, n,
                 "a point too strongly compressed between walls or grains, or a grain too coarse "
                 "(too few cells across) for its deformation (dt = \"auto\" keeps to the CFL "
                 "limit; a smaller cfl rarely helps)");
}

/* The check of every point, for USF (whose stress update comes before the positions'); the
 * other orders check each point right after its stress update (constitutive). Returns the first
 * bad point, or (size_t)-1. */
static size_t check_points(mpm_scene *s)
{
    size_t first = (size_t)-1;
    const check_bounds cb = bounds_of(s);
#pragma omp parallel for schedule(static) reduction(min : first) num_threads(s->nt) if (s->nt > 1)
    for (size_t p = 0; p < s->np; p++)
        if (point_bad(s, &cb, p))
            first = p < first ? p : first;
    return first;
}

static core_status run_steps(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err);

core_status mpm_run(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err)
{
    /* A step gives the same bits on any thread count the tuner may choose (core/threads.h):
     * with frictional contact every grain's nodal entries are built by one thread and packed in
     * grain order; noslip scatters by chunks whose number is fixed in auto mode (all
     * processors) and adds them in chunk order. */
    threads_tune_begin(s, s->np >= 8192);
    core_status st = run_steps(s, run, done, err);
    threads_tune_end();
    return st;
}

static core_status run_steps(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err)
{
    *done = 0;
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    if (!(run->dt >= 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be > 0 (or 0 for automatic), got %g", run->dt);
    if (run->dt == 0 && !(run->cfl > 0 && run->cfl <= 1))
        return core_fail(err, CORE_ERR_ARG, "cfl must be in (0, 1], got %g", run->cfl);
    if (s->np == 0)
        return core_fail(err, CORE_ERR_STATE,
                         "the scene has no material points: add a grain first");
    core_status st;
    const bool friction = s->contact == MPM_CONTACT_FRICTION;
    if (friction && (st = mpm_contact_reserve(s, err)))
        return st;
    if ((st = threads_setup(s, err)))
        return st;
    if (!s->lzz_ok) {
        for (size_t p = 0; p < s->np; p++)
            s->lzz[p] = 0.5 * log(s->be[3][p]);
        s->lzz_ok = true;
    }
    s->sf = friction ? s->sv : s->sn;
    const double h = s->hx < s->hy ? s->hx : s->hy;
    mpm_timestep ts;
    if ((st = mpm_timestep_info(s, run->cfl > 0 && run->cfl <= 1 ? run->cfl : 1, &ts, err)))
        return st;
    const bool musl = s->def.update == MPM_MUSL, usf = s->def.update == MPM_USF;
    size_t tbad[64], tcheck[64];
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
        const double t0 = clock_wall();
        double tlast = t0;
#pragma omp parallel num_threads(s->nt) if (s->nt > 1)
        {
            const int t = THREAD_ID();
            double tl = t0;
            if (friction) {
                grain_fields(s, t, &tl); /* the stencil and the centre-of-mass field too */
            } else {
                stencil(s, s->tp[t], s->tp[t + 1]);
#pragma omp barrier
#pragma omp master
                mark_forced(s);
#pragma omp barrier
                STAGE_DONE(T_STENCIL);
                to_grid(s, t);
            }
            if (!friction || s->nmx) {
#pragma omp barrier
#pragma omp master
                if (s->nmx)
                    moments(s);
#pragma omp barrier
            }
            STAGE_DONE(friction ? T_NORMALS : T_P2G);
            tbad[t] = (size_t)-1;
            if (usf) {
                nodal_velocity(s, dt, true, false); /* v_i^n, for the stress update */
                tbad[t] = constitutive(s, dt, t, s->nax, s->nay, NULL);
#pragma omp barrier
                STAGE_DONE(T_MATERIAL);
                scatter_sf(s, t, s->nfx, s->nfy, true); /* forces from the new stress */
                STAGE_DONE(T_P2G);
            }
            grid_update(s, dt);
            STAGE_DONE(T_GRID); /* thread 0's own time (no barrier) */
            if (friction) {
                contact_update(s, dt);
                STAGE_DONE(T_CONTACT);
            } else {
#pragma omp barrier
            }
            /* With friction a thread's points read only its own pairs and the nodes that only
             * its grains reach, which no thread writes again before the next barrier (the
             * remap's scatter, in to_points, zeroes and adds into the same entries, npx and
             * npy only), so no barrier follows. */
            to_points(s, dt, t, friction && musl);
            if (!friction) {
#pragma omp barrier
            }
            STAGE_DONE(T_G2P);
            if (musl) {
                remap(s, dt, t);
                STAGE_DONE(T_REMAP);
            }
            if (!usf)
                tbad[t] = constitutive(s, dt, t, s->nax, s->nay, &tcheck[t]);
            if (t == 0)
                tlast = tl;
        }
        const double tend = clock_wall(); /* the end of the region, then the checks */
        s->tstage[usf ? T_G2P : T_MATERIAL] += tend - tlast;
        char cause[400];
        for (int t = 0; t < s->nt; t++)
            if (tbad[t] != (size_t)-1) {
                likely_cause(s, tbad[t], MPM_BAD_INVERTED, run, &ts, cause, sizeof cause);
                return unstable(s, tbad[t], "was inverted (det F <= 0)", cause, err);
            }
        size_t bad = (size_t)-1;
        if (usf)
            bad = check_points(s);
        else
            for (int t = 0; t < s->nt; t++)
                bad = tcheck[t] < bad ? tcheck[t] : bad;
        const int why = bad != (size_t)-1 ? bad_why(s, bad) : 0;
        if (bad != (size_t)-1) {
            likely_cause(s, bad, why ? MPM_BAD_LEFT : MPM_BAD_NONFINITE, run, &ts, cause,
                         sizeof cause);
            return unstable(s, bad,
                            why ? "left the grid" : "has a non-finite position, velocity or stress",
                            cause, err);
        }
        s->time += dt;
        s->steps++;
        ++*done;
        s->tstage[T_CHECK] += clock_wall() - tend;
        s->tsteps++;
        if (threads_tune_step() && (st = threads_setup(s, err)))
            return st;
    }
    return CORE_OK;
}
