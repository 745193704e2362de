/* Distributed runs: the DEM scene decomposed over MPI ranks (core/comm.h), LAMMPS-style spatial
 * decomposition with the one-rank answer bit for bit.
 *
 * - Replicated while building, distributed while running. Scripts are SPMD: building calls run
 *   on every rank, so the scene is the same everywhere. dem_run decomposes it (no communication:
 *   every rank has everything and keeps its part); dem_replicate gathers it back for any call
 *   that needs the whole scene.
 * - The regions are a recursive coordinate bisection by particle count (rcb below): cuts on the
 *   longest axis of each box, placed so that the counts split as the rank counts do. Rebalanced
 *   at a list rebuild when the work lost to the imbalance since the last rebuild exceeds what a
 *   rebalance costs (see DEM_REBALANCE_COST).
 * - A rank holds its owned particles (position inside its region at the last rebuild) and ghosts:
 *   every particle within 2 r_max + skin of the region (min image on periodic axes; a ghost keeps
 *   its coordinates, the pair kernel's min image does the rest). Local arrays are sorted by global
 *   id (the index on one rank), so the Verlet list (i < j), each particle's force sum (its pairs
 *   as i in j order, then as j) and the history carry-over are those of one rank: owned particles
 *   get the same bits. Ghost-ghost pairs are skipped; ghosts are integrated with partial forces
 *   and overwritten by the halo before every force evaluation.
 * - Every force evaluation: a global rebuild test (comm_any of max displacement > skin/2, so every
 *   rank rebuilds on one rank's steps), then either the halo (x, v, omega of each ghost from its
 *   owner: what the pair kernel reads; Gear's and two timescales' predictions are in x and v) or
 *   a rebuild: each owner sends each of its particles, with every per-particle array (a table:
 *   particle_arrays) and the tangential history of its pairs as first index (a bundle), to the
 *   particle's new owner and to every rank that needs it as a ghost, in one all-to-all. A particle
 *   may cross any number of regions in one interval. The receiver sorts by id and builds its
 *   list; a pair takes its history from its first particle's bundle (the owner's, exact).
 * - Wall forces are gathered as (wall, id, force) and added in id order: a servo wall moves as on
 *   one rank. The energy watch and the automatic dt use reductions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/comm.h"
#include "core/memory.h"
#include "dem/dem_internal.h"

/* When to rebalance. A step takes as long as its busiest rank: an imbalance b = max/mean owned
 * costs (b - 1) steps of work per step. A rebalance (all-gather of the positions, new regions,
 * the migration of the particles that change rank) was measured at 2-4 steps of work (3000
 * disks on 2 ranks: 5 ms for the gather and the cut, 16 ms for the rebuild with migration, 4.9 ms
 * per step). So rebalance when the work lost over the last rebuild interval, (b - 1) x steps,
 * exceeds DEM_REBALANCE_COST steps, and not for b under DEM_REBALANCE_MIN (the cuts themselves
 * are only as good as a particle or two). A dense pile, rebuilt every few hundred steps,
 * rebalances from b ~ 1.02; a fast flow rebuilt every 20 steps waits until b ~ 1.2. The variable
 * GRAINLAB_DEM_REBALANCE = b replaces the rule by a fixed threshold (for measurements). */
#define DEM_REBALANCE_COST 4.0
#define DEM_REBALANCE_MIN 1.02

static double rebalance_threshold(void)
{
    const char *e = getenv("GRAINLAB_DEM_REBALANCE");
    double v = e ? strtod(e, NULL) : 0;
    return v >= 1 ? v : 0;
}

typedef struct rcb_node {
    int axis, rank; /* rank >= 0: a leaf */
    double cut;
    int left, right;
} rcb_node;

struct dem_domain {
    int P, me;
    size_t n_global;
    double gcut;       /* ghost distance: 2 r_max + skin, with a rounding margin */
    double threshold;  /* > 0: rebalance above this max/mean owned (else the cost rule) */
    long last_rebuild; /* s->steps at the last rebuild or decomposition */
    rcb_node *node;
    int nnode;
    double (*box)[2][3]; /* region of each rank: [r][0] lo, [r][1] hi */
    /* halo: per peer, local indices to send (owned) and to receive into (ghosts) */
    int npeer;
    int *peer;
    size_t *send_start, *recv_start, *send_idx, *recv_idx;
    double *sbuf, *rbuf;
    size_t nsend_cap, nrecv_cap;
    /* history bundles of the local particles (rebuild) */
    size_t *hb_start;
    uint32_t *hb_j;
    double *hb_h;
    int walls_pending;    /* wall forces not summed over the ranks yet */
    core_status deferred; /* this rank's first error of the step (forces) */
    core_error deferred_err;
};

void dem_domain_stats_get(const dem_scene *s, dem_domain_stats *out)
{
    *out = s->dstats;
    if (out->ranks > 1) {
        double v[4] = {out->halo_bytes, out->halo_messages, out->rebuild_bytes,
                       out->rebuild_messages};
        comm_sum_double(v, 4);
        out->halo_bytes = v[0], out->halo_messages = v[1];
        out->rebuild_bytes = v[2], out->rebuild_messages = v[3];
        double t[3] = {out->rebuild_s, out->rebalance_s, out->comm_s};
        comm_max_double(t, 3);
        out->rebuild_s = t[0], out->rebalance_s = t[1], out->comm_s = t[2];
    }
}

/* Fewest and most owned particles over the ranks (one reduction), into the stats. */
static void owned_range(dem_scene *s, long migrated)
{
    int64_t own = 0;
    for (size_t i = 0; i < s->n; i++)
        own += !s->ghost[i];
    int64_t v[3] = {own, -own, migrated};
    comm_max_i64(v, 2);
    comm_sum_i64(v + 2, 1);
    s->dstats.owned_max = (long)v[0];
    s->dstats.owned_min = (long)-v[1];
    s->dstats.migrations += (long)v[2];
}

size_t dem_domain_count(const dem_scene *s) { return s->dom ? s->dom->n_global : s->n; }
int dem_distributed(const dem_scene *s) { return s->dom != NULL; }

size_t dem_domain_bundle(const dem_scene *s, size_t i, const uint32_t **gj, const double **h)
{
    const dem_domain *dm = s->dom;
    if (!dm || !dm->hb_start) {
        *gj = NULL, *h = NULL;
        return 0;
    }
    *gj = dm->hb_j + dm->hb_start[i];
    *h = dm->hb_h + (size_t)dem_hist_width(s) * dm->hb_start[i];
    return dm->hb_start[i + 1] - dm->hb_start[i];
}

static void free_bundles(dem_domain *dm)
{
    free(dm->hb_start), free(dm->hb_j), free(dm->hb_h);
    dm->hb_start = NULL, dm->hb_j = NULL, dm->hb_h = NULL;
}

static void free_halo(dem_domain *dm)
{
    free(dm->peer), free(dm->send_start), free(dm->recv_start), free(dm->send_idx);
    free(dm->recv_idx), free(dm->sbuf), free(dm->rbuf);
    dm->peer = NULL, dm->send_start = dm->recv_start = dm->send_idx = dm->recv_idx = NULL;
    dm->sbuf = dm->rbuf = NULL;
    dm->npeer = 0, dm->nsend_cap = dm->nrecv_cap = 0;
}

void dem_domain_free(dem_scene *s)
{
    dem_domain *dm = s->dom;
    if (dm) {
        free_bundles(dm);
        free_halo(dm);
        free(dm->node), free(dm->box);
        free(dm);
    }
    s->dom = NULL;
    free(s->gid), free(s->ghost);
    s->gid = NULL, s->ghost = NULL;
    for (int w = 0; w < s->nwalls; w++) {
        free(s->walls[w].cand_fn);
        s->walls[w].cand_fn = NULL;
    }
}

/* ---- the per-particle arrays ---------------------------------------------------------------- *
 * Every array of s->cap entries the scene has now: what migrates with a particle and what the
 * gather puts back. A new per-particle array in dem_scene belongs here too. */
typedef dem_parray parray;

static int particle_arrays(dem_scene *s, parray *a)
{
    int n = 0;
#define ADD_HOT(ptr, sz, hot)                                                                      \
    do {                                                                                           \
        if (ptr)                                                                                   \
            a[n++] = (parray){(void **)&(ptr), (sz), (hot)};                                       \
    } while (0)
#define ADD(ptr, sz) ADD_HOT(ptr, sz, -1)
    for (int d = 0; d < 3; d++) {
        ADD_HOT(s->x[d], sizeof(double), DEM_HOT_X + d);
        ADD_HOT(s->v[d], sizeof(double), DEM_HOT_V + d);
        ADD_HOT(s->f[d], sizeof(double), DEM_HOT_F + d);
        ADD_HOT(s->x_build[d], sizeof(double), DEM_HOT_XB + d);
        ADD(s->fext[d], sizeof(double));
        ADD(s->x_ref[d], sizeof(double));
        ADD(s->x_prev[d], sizeof(double));
        ADD_HOT(s->w[d], sizeof(double), DEM_HOT_W + d);
        ADD_HOT(s->tq[d], sizeof(double), DEM_HOT_TQ + d);
        for (int k = 0; k < 6; k++) {
            ADD(s->gear[k][d], sizeof(double));
            ADD(s->gear_w[k][d], sizeof(double));
        }
    }
    ADD_HOT(s->r, sizeof(double), DEM_HOT_R);
    ADD_HOT(s->m, sizeof(double), DEM_HOT_M);
    ADD_HOT(s->inv_m, sizeof(double), DEM_HOT_INV_M);
    ADD_HOT(s->inv_inertia, sizeof(double), DEM_HOT_INV_I);
    ADD_HOT(s->angle, sizeof(double), DEM_HOT_ANGLE);
    ADD(s->mat, sizeof(int));
    ADD(s->flags, sizeof(unsigned char));
    ADD(s->tag, sizeof(double));
    for (int w = 0; w < s->nwalls; w++)
        for (int k = 0; k < DEM_HIST; k++)
            ADD(s->walls[w].hist[k], sizeof(double));
#undef ADD
#undef ADD_HOT
    return n;
}

static int max_arrays(const dem_scene *s) { return 3 * 21 + 8 + DEM_HIST * s->nwalls; }

int dem_particle_arrays(dem_scene *s, dem_parray *a) { return particle_arrays(s, a); }
int dem_max_particle_arrays(const dem_scene *s) { return max_arrays(s); }

static size_t record_bytes(const parray *a, int na)
{
    size_t b = 0;
    for (int k = 0; k < na; k++)
        b += a[k].size;
    return b;
}

static char *pack_particle(char *out, const parray *a, int na, size_t i)
{
    for (int k = 0; k < na; k++) {
        memcpy(out, (const char *)*a[k].p + i * a[k].size, a[k].size);
        out += a[k].size;
    }
    return out;
}

static const char *unpack_particle(const char *in, const parray *a, int na, size_t i)
{
    for (int k = 0; k < na; k++) {
        memcpy((char *)*a[k].p + i * a[k].size, in, a[k].size);
        in += a[k].size;
    }
    return in;
}

/* Every table array (and gid, ghost when distributed) to hold at least n particles. */
static core_status resize(dem_scene *s, const parray *a, int na, size_t n, int local,
                          core_error *err)
{
    size_t cap = s->cap > n ? s->cap : n;
    if (cap == 0)
        cap = 1;
    for (int k = 0; k < na; k++) {
        void *q = a[k].hot >= 0 ? core_realloc_staggered(*a[k].p, cap * a[k].size, a[k].hot)
                                : realloc(*a[k].p, cap * a[k].size);
        if (!q)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu particles", cap);
        *a[k].p = q;
    }
    s->cap = cap;
    if (local) {
        uint32_t *g = realloc(s->gid, cap * sizeof *g);
        if (g)
            s->gid = g;
        unsigned char *h = realloc(s->ghost, cap);
        if (h)
            s->ghost = h;
        if (!g || !h)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu particles", cap);
    }
    return CORE_OK;
}

/* ---- regions: recursive coordinate bisection ------------------------------------------------ */
typedef struct rcb_item {
    double c[3];
    uint32_t gid;
} rcb_item;

static int rcb_axis_g;
static int cmp_item(const void *pa, const void *pb)
{
    const rcb_item *a = pa, *b = pb;
    double x = a->c[rcb_axis_g], y = b->c[rcb_axis_g];
    if (x != y)
        return x < y ? -1 : 1;
    return (a->gid > b->gid) - (a->gid < b->gid);
}

static int rcb(dem_scene *s, dem_domain *dm, rcb_item *it, size_t n, int r0, int r1,
               const double blo[3], const double bhi[3])
{
    int id = dm->nnode++;
    rcb_node *nd = &dm->node[id];
    if (r1 - r0 == 1) {
        *nd = (rcb_node){.axis = 0, .rank = r0, .cut = 0, .left = -1, .right = -1};
        for (int d = 0; d < 3; d++)
            dm->box[r0][0][d] = blo[d], dm->box[r0][1][d] = bhi[d];
        return id;
    }
    /* The longest axis of the box (clamped to the scene's box: outer faces are open). */
    int axis = 0;
    double ext[3], lo[3], hi[3];
    for (int d = 0; d < s->dim; d++) {
        lo[d] = fmax(blo[d], s->lo[d]);
        hi[d] = fmin(bhi[d], s->hi[d]);
        ext[d] = hi[d] - lo[d];
        if (ext[d] > ext[axis])
            axis = d;
    }
    int nl = (r1 - r0) / 2;
    size_t target = (size_t)((double)n * nl / (r1 - r0) + 0.5);
    rcb_axis_g = axis;
    qsort(it, n, sizeof *it, cmp_item);
    double cut;
    if (n == 0)
        cut = lo[axis] + 0.5 * ext[axis];
    else if (target == 0)
        cut = 0.5 * (fmin(lo[axis], it[0].c[axis]) + it[0].c[axis]);
    else if (target >= n)
        cut = 0.5 * (it[n - 1].c[axis] + fmax(hi[axis], it[n - 1].c[axis]));
    else
        cut = it[target - 1].c[axis] + 0.5 * (it[target].c[axis] - it[target - 1].c[axis]);
    size_t nleft = 0;
    while (nleft < n && it[nleft].c[axis] < cut)
        nleft++;
    double bl[3], bh[3];
    memcpy(bl, blo, sizeof bl);
    memcpy(bh, bhi, sizeof bh);
    bh[axis] = cut;
    int left = rcb(s, dm, it, nleft, r0, r0 + nl, bl, bh);
    bh[axis] = bhi[axis];
    bl[axis] = cut;
    int right = rcb(s, dm, it + nleft, n - nleft, r0 + nl, r1, bl, bh);
    dm->node[id] = (rcb_node){.axis = axis, .rank = -1, .cut = cut, .left = left, .right = right};
    return id;
}

static core_status build_regions(dem_scene *s, dem_domain *dm, rcb_item *it, size_t n,
                                 core_error *err)
{
    free(dm->node), free(dm->box);
    dm->node = malloc((size_t)(2 * dm->P) * sizeof *dm->node);
    dm->box = malloc((size_t)dm->P * sizeof *dm->box);
    if (!dm->node || !dm->box)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the decomposition");
    double blo[3], bhi[3];
    for (int d = 0; d < 3; d++) {
        int per = d < s->dim && s->periodic[d];
        blo[d] = per ? s->lo[d] : -INFINITY;
        bhi[d] = per ? s->hi[d] : INFINITY;
    }
    dm->nnode = 0;
    rcb(s, dm, it, n, 0, dm->P, blo, bhi);
    return CORE_OK;
}

static int owner_of(const dem_domain *dm, const double c[3])
{
    int k = 0;
    while (dm->node[k].rank < 0)
        k = c[dm->node[k].axis] < dm->node[k].cut ? dm->node[k].left : dm->node[k].right;
    return dm->node[k].rank;
}

/* Whether the point is within the ghost distance of rank r's region (min image). */
static int near_region(const dem_scene *s, const dem_domain *dm, int r, const double c[3])
{
    double d2 = 0;
    for (int d = 0; d < s->dim; d++) {
        double a = dm->box[r][0][d], b = dm->box[r][1][d], best = INFINITY;
        for (int img = -1; img <= 1; img++) {
            if (img != 0 && !s->periodic[d])
                continue;
            double x = c[d] + img * s->len[d];
            double dd = x < a ? a - x : x > b ? x - b : 0;
            best = fmin(best, dd);
        }
        d2 += best * best;
        if (d2 >= dm->gcut * dm->gcut)
            return 0;
    }
    return 1;
}

static void position(const dem_scene *s, double *const src[3], size_t i, double c[3])
{
    for (int d = 0; d < 3; d++)
        c[d] = d < s->dim ? src[d][i] : 0;
}

static double ghost_cut(const dem_scene *s)
{
    double skin = s->skin_def > 0 ? s->skin_def : 0.2 * s->r_max;
    return (2 * s->r_max + skin) * (1 + 1e-9) + 1e-300;
}

/* ---- halo lists ------------------------------------------------------------------------------ *
 * From the positions c (the ones ownership was decided on): each owned particle goes to every
 * rank whose region is within the ghost distance, each ghost comes from its owner. Both sides
 * compute the same function of the same bits, and both lists are in id order. */
static core_status build_halo(dem_scene *s, double *const pos[3], core_error *err)
{
    dem_domain *dm = s->dom;
    const int P = dm->P;
    free_halo(dm);
    size_t *ns = calloc((size_t)P, sizeof *ns), *nr = calloc((size_t)P, sizeof *nr);
    int *own = malloc((s->n ? s->n : 1) * sizeof *own);
    if (!ns || !nr || !own) {
        free(ns), free(nr), free(own);
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the halo");
    }
    for (size_t i = 0; i < s->n; i++) {
        double c[3];
        position(s, pos, i, c);
        if (s->ghost[i]) {
            own[i] = owner_of(dm, c);
            nr[own[i]]++;
        } else {
            own[i] = -1;
            for (int r = 0; r < P; r++)
                if (r != dm->me && near_region(s, dm, r, c))
                    ns[r]++;
        }
    }
    int np = 0;
    for (int r = 0; r < P; r++)
        np += (ns[r] || nr[r]);
    dm->npeer = np;
    dm->peer = malloc((size_t)(np ? np : 1) * sizeof *dm->peer);
    dm->send_start = calloc((size_t)np + 1, sizeof *dm->send_start);
    dm->recv_start = calloc((size_t)np + 1, sizeof *dm->recv_start);
    int *slot = malloc((size_t)P * sizeof *slot);
    if (!dm->peer || !dm->send_start || !dm->recv_start || !slot) {
        free(ns), free(nr), free(own), free(slot);
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the halo");
    }
    np = 0;
    for (int r = 0; r < P; r++) {
        slot[r] = -1;
        if (ns[r] || nr[r]) {
            slot[r] = np;
            dm->peer[np] = r;
            dm->send_start[np + 1] = dm->send_start[np] + ns[r];
            dm->recv_start[np + 1] = dm->recv_start[np] + nr[r];
            np++;
        }
    }
    size_t ts = dm->send_start[np], tr = dm->recv_start[np];
    dm->send_idx = malloc((ts ? ts : 1) * sizeof *dm->send_idx);
    dm->recv_idx = malloc((tr ? tr : 1) * sizeof *dm->recv_idx);
    if (!dm->send_idx || !dm->recv_idx) {
        free(ns), free(nr), free(own), free(slot);
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the halo");
    }
    for (int k = 0; k < np; k++)
        ns[dm->peer[k]] = dm->send_start[k], nr[dm->peer[k]] = dm->recv_start[k];
    for (size_t i = 0; i < s->n; i++) {
        if (own[i] >= 0) {
            dm->recv_idx[nr[own[i]]++] = i;
            continue;
        }
        double c[3];
        position(s, pos, i, c);
        for (int r = 0; r < P; r++)
            if (r != dm->me && near_region(s, dm, r, c))
                dm->send_idx[ns[r]++] = i;
    }
    free(ns), free(nr), free(own), free(slot);
    return CORE_OK;
}

static int halo_width(const dem_scene *s)
{
    return 2 * s->dim + (s->rot ? (s->dim == 2 ? 1 : 3) : 0);
}

void dem_domain_halo(dem_scene *s)
{
    dem_domain *dm = s->dom;
    const int D = s->dim, W = halo_width(s), np = dm->npeer;
    const int d0 = D == 2 ? 2 : 0;
    size_t ts = dm->send_start[np], tr = dm->recv_start[np];
    if (ts * W > dm->nsend_cap) {
        free(dm->sbuf);
        dm->sbuf = malloc(ts * W * sizeof(double));
        dm->nsend_cap = dm->sbuf ? ts * W : 0;
    }
    if (tr * W > dm->nrecv_cap) {
        free(dm->rbuf);
        dm->rbuf = malloc(tr * W * sizeof(double));
        dm->nrecv_cap = dm->rbuf ? tr * W : 0;
    }
    if ((ts && !dm->sbuf) || (tr && !dm->rbuf))
        comm_abort(70); /* a rank that cannot hold its halo cannot go on */
    for (size_t e = 0; e < ts; e++) {
        size_t i = dm->send_idx[e];
        double *b = dm->sbuf + e * W;
        for (int d = 0; d < D; d++)
            *b++ = s->x[d][i], *b++ = s->v[d][i];
        if (s->rot)
            for (int d = d0; d < 3; d++)
                *b++ = s->w[d][i];
    }
    const void *sp[np ? np : 1];
    void *rp[np ? np : 1];
    size_t sb[np ? np : 1], rb[np ? np : 1];
    for (int k = 0; k < np; k++) {
        sp[k] = dm->sbuf + dm->send_start[k] * W;
        sb[k] = (dm->send_start[k + 1] - dm->send_start[k]) * W * sizeof(double);
        rp[k] = dm->rbuf + dm->recv_start[k] * W;
        rb[k] = (dm->recv_start[k + 1] - dm->recv_start[k]) * W * sizeof(double);
    }
    comm_exchange(np, dm->peer, sp, sb, rp, rb, 0xde3);
    for (int k = 0; k < np; k++)
        if (sb[k])
            s->dstats.halo_bytes += (double)sb[k], s->dstats.halo_messages++;
    s->dstats.halos++;
    for (size_t e = 0; e < tr; e++) {
        size_t i = dm->recv_idx[e];
        const double *b = dm->rbuf + e * W;
        for (int d = 0; d < D; d++)
            s->x[d][i] = *b++, s->v[d][i] = *b++;
        if (s->rot)
            for (int d = d0; d < 3; d++)
                s->w[d][i] = *b++;
    }
}

/* ---- decomposition of a replicated scene ------------------------------------------------------
 */
core_status dem_domain_start(dem_scene *s, core_error *err)
{
    if (comm_size() == 1 || s->dom)
        return CORE_OK;
    dem_domain *dm = calloc(1, sizeof *dm);
    if (!dm)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the decomposition");
    dm->P = comm_size();
    dm->me = comm_rank();
    dm->n_global = s->n;
    dm->gcut = ghost_cut(s);
    dm->threshold = rebalance_threshold();
    dm->last_rebuild = s->steps;
    s->dom = dm;
    const size_t n = s->n;
    /* Decide on the positions the current list was built from (x_build), so that the list
     * itself is kept: no rebuild that one rank would not do. Without a valid list, the first
     * force evaluation would build one at these positions: build it now, on the whole scene
     * (every rank the same), carrying the history over as one rank does. */
    core_status st = CORE_OK;
    if (s->need_rebuild || !s->pairs.start || s->pairs.np != n) {
        s->dom = NULL; /* one rank's build */
        st = dem_build_pairs(s, err);
        s->dom = dm;
        if (st) {
            if (err) {
                char msg[sizeof err->msg];
                snprintf(msg, sizeof msg, "%s", err->msg);
                core_fail(err, st, "%s (at step %ld, t = %.6g s)", msg, s->steps + 1, s->time);
            }
            dem_domain_free(s);
            return st;
        }
    }
    const int keep = 1;
    double *const *pos = s->x_build;
    rcb_item *it = malloc((n ? n : 1) * sizeof *it);
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    uint32_t *map = malloc((n ? n : 1) * sizeof *map);
    unsigned char *gh = malloc(n ? n : 1);
    if (!it || !idx || !map || !gh)
        st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate the decomposition");
    if (!st) {
        for (size_t i = 0; i < n; i++) {
            position(s, pos, i, it[i].c);
            it[i].gid = (uint32_t)i;
        }
        st = build_regions(s, dm, it, n, err);
    }
    size_t nl = 0;
    if (!st) {
        for (size_t i = 0; i < n; i++) {
            double c[3];
            position(s, pos, i, c);
            int o = owner_of(dm, c);
            map[i] = UINT32_MAX;
            if (o == dm->me || near_region(s, dm, dm->me, c)) {
                gh[nl] = o != dm->me;
                map[i] = (uint32_t)nl;
                idx[nl++] = i;
            }
        }
        parray a[max_arrays(s)];
        int na = particle_arrays(s, a);
        for (size_t k = 0; k < nl; k++) /* idx[k] >= k: compacting in place is safe */
            for (int q = 0; q < na; q++)
                memmove((char *)*a[q].p + k * a[q].size, (char *)*a[q].p + idx[k] * a[q].size,
                        a[q].size);
        st = resize(s, a, na, nl, 1, err);
    }
    if (!st) {
        for (size_t k = 0; k < nl; k++)
            s->gid[k] = (uint32_t)idx[k], s->ghost[k] = gh[k];
        s->n = nl;
        if (keep) { /* the pairs touching an owned particle, renumbered (the order is kept) */
            dem_pairs *p = &s->pairs;
            size_t m = 0;
            for (size_t q = 0; q < p->n; q++) {
                uint32_t i = map[p->i[q]], j = map[p->j[q]];
                if (i == UINT32_MAX || j == UINT32_MAX || (gh[i] && gh[j]))
                    continue;
                p->i[m] = i, p->j[m] = j, p->k[m] = p->k[q], p->gamma[m] = p->gamma[q];
                p->mu[m] = p->mu[q];
                for (int d = 0; d < DEM_HIST; d++)
                    if (p->hist[d])
                        p->hist[d][m] = p->hist[d][q];
                for (int d = 0; d < 3; d++) {
                    if (p->f[d])
                        p->f[d][m] = p->f[d][q];
                    if (p->c[d])
                        p->c[d][m] = p->c[d][q];
                }
                m++;
            }
            p->n = m;
            st = dem_pairs_index(s, err);
            for (int w = 0; w < s->nwalls && !st; w++) {
                dem_wall *wl = &s->walls[w];
                size_t m2 = 0;
                for (size_t e = 0; e < wl->ncand; e++) {
                    uint32_t i = map[wl->cand[e]];
                    if (i != UINT32_MAX && !gh[i])
                        wl->cand[m2++] = i;
                }
                wl->ncand = m2;
                wl->cand_par_ok = 0;
                double *c = realloc(wl->cand_fn, (wl->cap_cand ? wl->cap_cand : 1) * sizeof *c);
                if (!c)
                    st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate wall candidates");
                else
                    wl->cand_fn = c;
            }
        }
    }
    if (!st)
        st = build_halo(s, pos, err);
    free(it), free(idx), free(map), free(gh);
    st = dem_domain_agree(s, st, err);
    if (!st) {
        s->dstats.ranks = dm->P;
        owned_range(s, 0);
    }
    if (st) /* the scene is lost on this rank: a half-decomposed scene is no scene */
        return st;
    return CORE_OK;
}

/* ---- errors every rank agrees on ----------------------------------------------------------- */
core_status dem_domain_agree(dem_scene *s, core_status st, core_error *err)
{
    return dem_domain_agree_flag(s, st, NULL, err);
}

core_status dem_domain_agree_flag(dem_scene *s, core_status st, int *flag, core_error *err)
{
    (void)s;
    if (comm_size() == 1)
        return st;
    int64_t v[2] = {st ? comm_rank() : comm_size(), flag && *flag ? -1 : 0};
    comm_min_i64(v, 2);
    if (flag)
        *flag = v[1] < 0;
    int64_t who = v[0];
    if (who == comm_size())
        return CORE_OK;
    core_error e;
    memset(&e, 0, sizeof e);
    if (comm_rank() == who && err)
        e = *err;
    else if (comm_rank() == who)
        e.status = st;
    comm_bcast(&e, sizeof e, (int)who);
    if (err)
        *err = e;
    return e.status ? e.status : CORE_ERR_STATE;
}

/* ---- rebuild: migration, ghosts, history, list ---------------------------------------------- */
typedef struct rec_ref {
    uint32_t gid, owned, nb;
    const char *p;
} rec_ref;

static int cmp_ref(const void *pa, const void *pb)
{
    const rec_ref *a = pa, *b = pb;
    return (a->gid > b->gid) - (a->gid < b->gid);
}

enum { HDR = 3 * sizeof(uint32_t) };

/* Rebalance when the load is off: every rank's owned positions to every rank, new regions. */
static core_status rebalance(dem_scene *s, core_error *err)
{
    dem_domain *dm = s->dom;
    /* the counts of the last rebuild: the particles have moved by less than a skin since */
    double mean = (double)dm->n_global / dm->P;
    const double b = s->dstats.owned_max / (mean > 0 ? mean : 1);
    const long interval = s->steps - dm->last_rebuild;
    int go = dm->threshold > 0 ? b > dm->threshold
                               : b > DEM_REBALANCE_MIN && (b - 1) * interval > DEM_REBALANCE_COST;
    if (!go || s->dstats.owned_max <= 1)
        return CORE_OK;
    size_t own = 0;
    for (size_t i = 0; i < s->n; i++)
        own += !s->ghost[i];
    rcb_item *mine = malloc((own ? own : 1) * sizeof *mine);
    if (!mine)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the rebalance");
    size_t m = 0;
    for (size_t i = 0; i < s->n; i++)
        if (!s->ghost[i]) {
            position(s, s->x, i, mine[m].c);
            mine[m++].gid = s->gid[i];
        }
    void *all = NULL;
    size_t bytes = 0;
    if (comm_allgatherv(mine, m * sizeof *mine, &all, &bytes, NULL)) {
        free(mine);
        return core_fail(err, CORE_ERR_NOMEM, "cannot gather positions for the rebalance");
    }
    free(mine);
    core_status st = build_regions(s, dm, all, bytes / sizeof(rcb_item), err);
    free(all);
    s->dstats.rebalances++;
    return st;
}

core_status dem_domain_rebuild(dem_scene *s, core_error *err)
{
    dem_domain *dm = s->dom;
    const int P = dm->P;
    core_status st = CORE_OK;
    const double t0 = clock_wall();
    dem_wrap_positions(s); /* what one rank does first at a build */
    dm->gcut = ghost_cut(s);
    st = rebalance(s, err);
    s->dstats.rebalance_s += clock_wall() - t0;
    st = dem_domain_agree(s, st, err);
    if (st)
        return st;
    parray a[max_arrays(s)];
    int na = particle_arrays(s, a);
    const size_t rb = record_bytes(a, na);
    const dem_pairs *p = &s->pairs;
    const int hist = (p->hist[0] || p->hist[DEM_HIST_ROLL]) && p->start && p->np == s->n;
    /* a history entry: the partner's id and hw values (dem_hist_width) */
    const int hw = dem_hist_width(s);
    const size_t bentry = sizeof(uint32_t) + (size_t)hw * sizeof(double);
    /* Bundle sizes: the pairs of each owned particle as i whose history is not all zero bits. */
    size_t *nb = calloc(s->n ? s->n : 1, sizeof *nb);
    size_t *sbytes = calloc((size_t)P * 3, sizeof *sbytes);
    int *dest = malloc((size_t)P * sizeof *dest);
    if (!nb || !sbytes || !dest) {
        free(nb), free(sbytes), free(dest);
        return dem_domain_agree(s, core_fail(err, CORE_ERR_NOMEM, "cannot allocate the migration"),
                                err);
    }
    size_t *soff = sbytes + P, *fill = sbytes + 2 * P;
    long migrated = 0;
    static const double zeros[DEM_HIST] = {0};
    for (size_t i = 0; i < s->n; i++) {
        if (s->ghost[i])
            continue;
        if (hist)
            for (size_t q = p->start[i]; q < p->start[i + 1]; q++) {
                double h[DEM_HIST];
                for (int d = 0; d < hw; d++)
                    h[d] = p->hist[d] ? p->hist[d][q] : 0;
                nb[i] += memcmp(h, zeros, (size_t)hw * sizeof *h) != 0;
            }
        double c[3];
        position(s, s->x, i, c);
        int o = owner_of(dm, c);
        migrated += o != dm->me;
        for (int r = 0; r < P; r++)
            if (r == o || near_region(s, dm, r, c))
                sbytes[r] += HDR + rb + nb[i] * bentry;
    }
    size_t total = 0;
    for (int r = 0; r < P; r++)
        soff[r] = fill[r] = total, total += sbytes[r];
    char *sbuf = malloc(total ? total : 1);
    if (!sbuf) {
        free(nb), free(sbytes), free(dest);
        return dem_domain_agree(s, core_fail(err, CORE_ERR_NOMEM, "cannot allocate the migration"),
                                err);
    }
    for (size_t i = 0; i < s->n; i++) {
        if (s->ghost[i])
            continue;
        double c[3];
        position(s, s->x, i, c);
        int o = owner_of(dm, c);
        for (int r = 0; r < P; r++) {
            if (!(r == o || near_region(s, dm, r, c)))
                continue;
            char *b = sbuf + fill[r];
            uint32_t hdr[3] = {s->gid[i], r == o, (uint32_t)nb[i]};
            memcpy(b, hdr, HDR);
            b = pack_particle(b + HDR, a, na, i);
            if (nb[i])
                for (size_t q = p->start[i]; q < p->start[i + 1]; q++) {
                    double h[DEM_HIST];
                    for (int d = 0; d < hw; d++)
                        h[d] = p->hist[d] ? p->hist[d][q] : 0;
                    if (!memcmp(h, zeros, (size_t)hw * sizeof *h))
                        continue;
                    uint32_t gj = s->gid[p->j[q]];
                    memcpy(b, &gj, sizeof gj);
                    memcpy(b + sizeof gj, h, (size_t)hw * sizeof *h);
                    b += bentry;
                }
            fill[r] = (size_t)(b - sbuf);
        }
    }
    free(nb);
    void *recv = NULL;
    size_t *rbytes = malloc(2 * (size_t)P * sizeof *rbytes);
    if (!rbytes)
        comm_abort(70);
    for (int r = 0; r < P; r++)
        if (r != dm->me && sbytes[r])
            s->dstats.rebuild_bytes += (double)sbytes[r], s->dstats.rebuild_messages++;
    if (comm_alltoallv(sbuf, sbytes, soff, &recv, rbytes, rbytes + P)) {
        free(sbuf), free(sbytes), free(dest), free(rbytes);
        return dem_domain_agree(s, core_fail(err, CORE_ERR_NOMEM, "cannot allocate the migration"),
                                err);
    }
    size_t rtotal = rbytes[P - 1] + rbytes[2 * P - 1];
    free(sbuf), free(sbytes), free(dest), free(rbytes);
    /* Index the records, sort by id. */
    size_t nrec = 0, nent = 0;
    for (size_t off = 0; off < rtotal; nrec++) {
        uint32_t hdr[3];
        memcpy(hdr, (char *)recv + off, HDR);
        off += HDR + rb + hdr[2] * bentry;
        nent += hdr[2];
    }
    rec_ref *ref = malloc((nrec ? nrec : 1) * sizeof *ref);
    if (!ref) {
        free(recv);
        return dem_domain_agree(s, core_fail(err, CORE_ERR_NOMEM, "cannot allocate the migration"),
                                err);
    }
    for (size_t off = 0, k = 0; off < rtotal; k++) {
        uint32_t hdr[3];
        memcpy(hdr, (char *)recv + off, HDR);
        ref[k] = (rec_ref){hdr[0], hdr[1], hdr[2], (char *)recv + off + HDR};
        off += HDR + rb + hdr[2] * bentry;
    }
    qsort(ref, nrec, sizeof *ref, cmp_ref);
    st = resize(s, a, na, nrec, 1, err);
    free_bundles(dm);
    dm->hb_start = malloc((nrec + 1) * sizeof *dm->hb_start);
    dm->hb_j = malloc((nent ? nent : 1) * sizeof *dm->hb_j);
    dm->hb_h = malloc((nent ? nent : 1) * (size_t)hw * sizeof *dm->hb_h);
    if (!st && (!dm->hb_start || !dm->hb_j || !dm->hb_h))
        st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate the contact history");
    if (!st) {
        size_t e = 0;
        dm->hb_start[0] = 0;
        for (size_t k = 0; k < nrec; k++) {
            const char *b = unpack_particle(ref[k].p, a, na, k);
            s->gid[k] = ref[k].gid;
            s->ghost[k] = !ref[k].owned;
            for (uint32_t q = 0; q < ref[k].nb; q++, e++) {
                memcpy(&dm->hb_j[e], b, sizeof(uint32_t));
                memcpy(&dm->hb_h[(size_t)hw * e], b + sizeof(uint32_t),
                       (size_t)hw * sizeof(double));
                b += bentry;
            }
            dm->hb_start[k + 1] = e;
        }
        s->n = nrec;
        /* The old list's indices mean nothing now: its history is in the bundles. */
        s->pairs.np = 0;
    }
    free(ref);
    free(recv);
    if (!st)
        st = build_halo(s, s->x, err);
    if (!st)
        st = dem_build_pairs(s, err);
    free_bundles(dm);
    dm->last_rebuild = s->steps;
    s->dstats.rebuilds++;
    s->dstats.rebuild_s += clock_wall() - t0;
    owned_range(s, migrated);
    return dem_domain_agree(s, st, err);
}

/* ---- wall forces in id order ------------------------------------------------------------------
 */
typedef struct wall_term {
    uint32_t wall, gid;
    double fn;
} wall_term;

/* Lexicographic order of two pairs of keys: (wall, id), (i, j). */
static int order2(uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1)
{
    if (a0 != b0)
        return (a0 > b0) - (a0 < b0);
    return (a1 > b1) - (a1 < b1);
}

static int cmp_term(const void *pa, const void *pb)
{
    const wall_term *a = pa, *b = pb;
    return order2(a->wall, a->gid, b->wall, b->gid);
}

static core_status wall_sums(dem_scene *s, core_error *err);

core_status dem_domain_walls_due(dem_scene *s, int now, core_error *err)
{
    s->dom->walls_pending = !now;
    return now ? wall_sums(s, err) : CORE_OK;
}

core_status dem_sync_walls(dem_scene *s, core_error *err)
{
    if (!s->dom || !s->dom->walls_pending)
        return CORE_OK;
    s->dom->walls_pending = 0;
    return wall_sums(s, err);
}

void dem_domain_defer(dem_scene *s, core_status st, const core_error *err)
{
    dem_domain *dm = s->dom;
    if (st && !dm->deferred) {
        dm->deferred = st;
        if (err)
            dm->deferred_err = *err;
        else
            memset(&dm->deferred_err, 0, sizeof dm->deferred_err), dm->deferred_err.status = st;
    }
}

core_status dem_domain_deferred(dem_scene *s, core_error *err)
{
    dem_domain *dm = s->dom;
    core_status st = dm->deferred;
    if (st && err)
        *err = dm->deferred_err;
    dm->deferred = CORE_OK;
    return st;
}

static core_status wall_sums(dem_scene *s, core_error *err)
{
    size_t n = 0;
    for (int w = 0; w < s->nwalls; w++)
        if (s->walls[w].active)
            for (size_t e = 0; e < s->walls[w].ncand; e++)
                n += s->walls[w].cand_fn[e] != 0;
    wall_term *t = malloc((n ? n : 1) * sizeof *t);
    if (!t)
        comm_abort(70);
    n = 0;
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (!wl->active)
            continue;
        for (size_t e = 0; e < wl->ncand; e++)
            if (wl->cand_fn[e] != 0) /* +-0 adds nothing to a sum that starts at +0 */
                t[n++] = (wall_term){(uint32_t)w, s->gid[wl->cand[e]], wl->cand_fn[e]};
    }
    void *all = NULL;
    size_t bytes = 0;
    int bad = comm_allgatherv(t, n * sizeof *t, &all, &bytes, NULL);
    free(t);
    if (bad)
        return core_fail(err, CORE_ERR_NOMEM, "cannot gather the wall forces");
    wall_term *at = all;
    size_t na = bytes / sizeof *at;
    qsort(at, na, sizeof *at, cmp_term);
    for (int w = 0; w < s->nwalls; w++)
        s->walls[w].fn = 0;
    for (size_t k = 0; k < na; k++)
        s->walls[at[k].wall].fn += at[k].fn;
    free(all);
    return CORE_OK;
}

/* ---- gather back: the scene as one rank holds it ----------------------------------------------
 */
typedef struct pair_rec {
    uint32_t i, j;
    double v[16]; /* k, gamma, mu, f[3], c[3], hist[DEM_HIST] */
} pair_rec;

static int cmp_pair(const void *pa, const void *pb)
{
    const pair_rec *a = pa, *b = pb;
    return order2(a->i, a->j, b->i, b->j);
}

static int cmp_u32x2(const void *pa, const void *pb)
{
    const uint32_t *a = pa, *b = pb;
    return order2(a[0], a[1], b[0], b[1]);
}

core_status dem_replicate(dem_scene *s, core_error *err)
{
    dem_domain *dm = s->dom;
    if (!dm)
        return CORE_OK;
    core_status st0 = dem_sync_walls(s, err);
    if (st0)
        return st0;
    parray a[max_arrays(s)];
    int na = particle_arrays(s, a);
    const size_t rb = record_bytes(a, na);
    const size_t recsz = sizeof(uint32_t) + rb;
    size_t own = 0;
    for (size_t i = 0; i < s->n; i++)
        own += !s->ghost[i];
    char *buf = malloc((own ? own : 1) * recsz);
    dem_pairs *p = &s->pairs;
    const int list = p->start && p->np == s->n;
    size_t npr = 0;
    if (list)
        for (size_t q = 0; q < p->n; q++)
            npr += !s->ghost[p->i[q]];
    pair_rec *pr = calloc(npr ? npr : 1, sizeof *pr);
    size_t ncw = 0;
    for (int w = 0; w < s->nwalls; w++)
        ncw += s->walls[w].ncand;
    uint32_t *cw = malloc((ncw ? ncw : 1) * 2 * sizeof *cw);
    if (!buf || !pr || !cw)
        comm_abort(70); /* collective: a rank that cannot gather cannot tell the others */
    char *b = buf;
    for (size_t i = 0; i < s->n; i++)
        if (!s->ghost[i]) {
            memcpy(b, &s->gid[i], sizeof(uint32_t));
            b = pack_particle(b + sizeof(uint32_t), a, na, i);
        }
    npr = 0;
    if (list)
        for (size_t q = 0; q < p->n; q++) {
            if (s->ghost[p->i[q]])
                continue;
            pair_rec *r = &pr[npr++];
            r->i = s->gid[p->i[q]], r->j = s->gid[p->j[q]];
            r->v[0] = p->k[q], r->v[1] = p->gamma[q], r->v[2] = p->mu[q];
            for (int d = 0; d < 3; d++) {
                r->v[3 + d] = p->f[d] ? p->f[d][q] : 0;
                r->v[6 + d] = p->c[d] ? p->c[d][q] : 0;
            }
            for (int d = 0; d < DEM_HIST; d++)
                r->v[9 + d] = p->hist[d] ? p->hist[d][q] : 0;
        }
    ncw = 0;
    for (int w = 0; w < s->nwalls; w++)
        for (size_t e = 0; e < s->walls[w].ncand; e++)
            cw[2 * ncw] = (uint32_t)w, cw[2 * ncw + 1] = s->gid[s->walls[w].cand[e]], ncw++;
    void *allp = NULL, *allr = NULL, *allw = NULL;
    size_t bp = 0, br = 0, bw = 0;
    int bad = comm_allgatherv(buf, own * recsz, &allp, &bp, NULL);
    bad |= comm_allgatherv(pr, npr * sizeof *pr, &allr, &br, NULL);
    bad |= comm_allgatherv(cw, ncw * 2 * sizeof *cw, &allw, &bw, NULL);
    free(buf), free(pr), free(cw);
    if (bad) {
        free(allp), free(allr), free(allw);
        return core_fail(err, CORE_ERR_NOMEM, "cannot gather the scene");
    }
    const size_t N = bp / recsz;
    core_status st = resize(s, a, na, N, 0, err);
    if (st) {
        free(allp), free(allr), free(allw);
        return st;
    }
    for (size_t k = 0; k < N; k++) {
        const char *r = (char *)allp + k * recsz;
        uint32_t g;
        memcpy(&g, r, sizeof g);
        unpack_particle(r + sizeof g, a, na, g);
    }
    s->n = N;
    free(allp);
    /* The list, as one rank built it (each pair from its first particle's owner). */
    pair_rec *ap = allr;
    size_t np = br / sizeof *ap;
    qsort(ap, np, sizeof *ap, cmp_pair);
    if (list) {
        dem_pairs old = *p;
        memset(p, 0, sizeof *p);
        dem_free_pairs(&old);
        /* the arrays the law needs, as the list build allocates them */
        size_t cap = np ? np : 1;
        p->i = malloc(cap * sizeof *p->i), p->j = malloc(cap * sizeof *p->j);
        p->k = malloc(cap * sizeof(double)), p->gamma = malloc(cap * sizeof(double));
        p->mu = malloc(cap * sizeof(double));
        int ok = p->i && p->j && p->k && p->gamma && p->mu;
        for (int d = 0; d < 3; d++) {
            if (d < s->dim)
                ok &= (p->f[d] = malloc(cap * sizeof(double))) != NULL;
            if (s->rot && (s->dim == 3 || d == 2))
                ok &= (p->c[d] = malloc(cap * sizeof(double))) != NULL;
            if (dem_tangent_history(s->contact.tangential) && d < s->dim)
                ok &= (p->hist[d] = malloc(cap * sizeof(double))) != NULL;
        }
        if (dem_tangent_history(s->contact.tangential))
            ok &= (p->hist[3] = malloc(cap * sizeof(double))) != NULL;
        for (int d = s->dim == 2 ? 2 : 0; d < 3 && s->contact.rolling_law; d++)
            ok &= (p->rt[d] = malloc(cap * sizeof(double))) != NULL;
        for (int d = 0; d < dem_rolling_slots(s); d++)
            ok &= (p->hist[DEM_HIST_ROLL + d] = malloc(cap * sizeof(double))) != NULL;
        p->cap = cap;
        p->n = np;
        if (!ok)
            st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate the pair list");
        for (size_t q = 0; q < np && !st; q++) {
            p->i[q] = ap[q].i, p->j[q] = ap[q].j;
            p->k[q] = ap[q].v[0], p->gamma[q] = ap[q].v[1], p->mu[q] = ap[q].v[2];
            for (int d = 0; d < 3; d++) {
                if (p->f[d])
                    p->f[d][q] = ap[q].v[3 + d];
                if (p->c[d])
                    p->c[d][q] = ap[q].v[6 + d];
                if (p->rt[d]) /* scratch of the next evaluation */
                    p->rt[d][q] = 0;
            }
            for (int d = 0; d < DEM_HIST; d++)
                if (p->hist[d])
                    p->hist[d][q] = ap[q].v[9 + d];
        }
        if (!st)
            st = dem_pairs_index(s, err);
        /* wall candidates: (wall, id) pairs sorted, i.e. each wall's in id order */
        uint32_t *acw = allw;
        size_t nw = bw / (2 * sizeof *acw);
        qsort(acw, nw, 2 * sizeof *acw, cmp_u32x2); /* by wall, then id */
        for (int w = 0; w < s->nwalls; w++)
            s->walls[w].ncand = 0, s->walls[w].cand_par_ok = 0;
        for (size_t k = 0; k < nw && !st; k++) {
            dem_wall *wl = &s->walls[acw[2 * k]];
            if (wl->ncand == wl->cap_cand) {
                size_t cap2 = wl->cap_cand ? 2 * wl->cap_cand : 256;
                uint32_t *c = realloc(wl->cand, cap2 * sizeof *c);
                if (!c) {
                    st = core_fail(err, CORE_ERR_NOMEM, "cannot allocate wall candidates");
                    break;
                }
                wl->cand = c, wl->cap_cand = cap2;
            }
            wl->cand[wl->ncand++] = acw[2 * k + 1];
        }
    }
    free(allr), free(allw);
    dem_domain_free(s);
    if (!list)
        s->need_rebuild = 1;
    return st;
}
