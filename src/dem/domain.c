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
        dem_parray a[dem_max_particle_arrays(s)];
        int na = dem_particle_arrays(s, a);
        for (size_t k = 0; k < nl; k++) /* idx[k] >= k: compacting in place is safe */
            for (int q = 0; q < na; q++)
                memmove((char *)*a[q].p + k * a[q].size, (char *)*a[q].p + idx[k] * a[q].size,
                        a[q].size);
        st = dem_parray_resize(s, a, na, nl, 1, err);
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

/* Each owned particle's record, with its bundle of nb[i] history entries, into the send buffer
 * of its new owner and of every rank that needs it as a ghost (fill: each rank's write offset). */
static void pack_migration(dem_scene *s, char *sbuf, size_t *fill, const dem_parray *a, int na,
                           const size_t *nb)
{
    const dem_domain *dm = s->dom;
    const int P = dm->P;
    const dem_pairs *p = &s->pairs;
    const int hw = dem_hist_width(s);
    const size_t bentry = sizeof(uint32_t) + (size_t)hw * sizeof(double);
    static const double zeros[DEM_HIST] = {0};
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
            b = dem_parray_pack(b + HDR, a, na, i);
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
}

/* The received records, sorted by id, become the local particles (owned or ghosts) and their
 * bundles the history the list build takes (dem_domain_bundle). */
static core_status store_records(dem_scene *s, const rec_ref *ref, size_t nrec, size_t nent,
                                 const dem_parray *a, int na, core_error *err)
{
    dem_domain *dm = s->dom;
    const int hw = dem_hist_width(s);
    const size_t bentry = sizeof(uint32_t) + (size_t)hw * sizeof(double);
    core_status st;
    st = dem_parray_resize(s, a, na, nrec, 1, err);
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
            const char *b = dem_parray_unpack(ref[k].p, a, na, k);
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
    dem_parray a[dem_max_particle_arrays(s)];
    int na = dem_particle_arrays(s, a);
    const size_t rb = dem_parray_bytes(a, na);
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
    pack_migration(s, sbuf, fill, a, na, nb);
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
    st = store_records(s, ref, nrec, nent, a, na, err);
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

static int cmp_term(const void *pa, const void *pb)
{
    const wall_term *a = pa, *b = pb;
    return dem_order2(a->wall, a->gid, b->wall, b->gid);
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
