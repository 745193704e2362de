/* What a particle carries between ranks, and the gather back: every per-particle array of the
 * scene (a table, packed into records for a migration, a gather or a removal) and dem_replicate,
 * which makes a distributed scene (domain.c) the one rank's scene again. */
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "core/memory.h"
#include "dem/dem_internal.h"

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

int dem_particle_arrays(dem_scene *s, dem_parray *a) { return particle_arrays(s, a); }
int dem_max_particle_arrays(const dem_scene *s) { return max_arrays(s); }
size_t dem_parray_bytes(const dem_parray *a, int na) { return record_bytes(a, na); }
char *dem_parray_pack(char *out, const dem_parray *a, int na, size_t i)
{
    return pack_particle(out, a, na, i);
}
const char *dem_parray_unpack(const char *in, const dem_parray *a, int na, size_t i)
{
    return unpack_particle(in, a, na, i);
}
core_status dem_parray_resize(dem_scene *s, const dem_parray *a, int na, size_t n, int local,
                              core_error *err)
{
    return resize(s, a, na, n, local, err);
}

/* ---- gather back: the scene as one rank holds it ----------------------------------------------
 */
typedef struct pair_rec {
    uint32_t i, j;
    double v[9 + DEM_HIST]; /* k, gamma, mu, f[3], c[3], hist[DEM_HIST] */
} pair_rec;

static int cmp_pair(const void *pa, const void *pb)
{
    const pair_rec *a = pa, *b = pb;
    return dem_order2(a->i, a->j, b->i, b->j);
}

static int cmp_u32x2(const void *pa, const void *pb)
{
    const uint32_t *a = pa, *b = pb;
    return dem_order2(a[0], a[1], b[0], b[1]);
}

/* The list, as one rank built it (each pair from its first particle's owner, ap sorted), and
 * the walls' candidates from the (wall, id) pairs of all ranks (allw, bw bytes). */
static core_status restore_list(dem_scene *s, const pair_rec *ap, size_t np, void *allw, size_t bw,
                                core_error *err)
{
    dem_pairs *p = &s->pairs;
    core_status st = CORE_OK;
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
    return st;
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
    pair_rec *ap = allr;
    size_t np = br / sizeof *ap;
    qsort(ap, np, sizeof *ap, cmp_pair);
    if (list)
        st = restore_list(s, ap, np, allw, bw, err);
    free(allr), free(allw);
    dem_domain_free(s);
    if (!list)
        s->need_rebuild = 1;
    return st;
}
