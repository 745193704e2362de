/* The DSMC scene distributed over MPI ranks (paper Sec. 4, Fig. 2): decomposition by cells, no
 * halos, since particles collide only with the particles of their own cell.
 *
 * Replicated while building, distributed while running: scene building is collective and leaves
 * the whole scene on every rank; the first dsmc_run on more than one rank cuts the grid into
 * contiguous ranges of blocks of cells (block = 2^blk_shift consecutive cells of the linear index,
 * so a range is a slab along the slowest axis with a staircase edge), balanced by particle count,
 * and every rank keeps the particles of its range. After each flight the particles whose new cell
 * another rank owns travel there (one all-to-all); when the counts per rank drift apart the grid
 * is cut again. Anything that needs the whole scene calls dsmc_gather first, which puts it back
 * on every rank.
 *
 * Nothing here changes a result: collisions draw per cell from the cell's own stream, in the
 * cell's identity order (step.c), wall hits per particle identity, and sums over particles are
 * taken per block then over blocks in order (dsmc_block_sum). So any number of ranks gives the
 * same bits as one. */
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "dsmc/dsmc_internal.h"

/* When the busiest rank holds more than BALANCE_LIMIT times the mean, at most every
 * BALANCE_EVERY steps, the ranks share their block counts (an all-gather of at most 4096
 * integers) and cut again if the new cut is better by BALANCE_DRIFT (a cut cannot beat the
 * block granularity, nor a gas packed in one block). A new cut costs about one migration of the
 * particles that change owner; a step costs in proportion to the busiest rank's count. */
#define BALANCE_LIMIT 1.05
#define BALANCE_DRIFT 0.025
#define BALANCE_EVERY 20

static size_t block_first_cell(const dsmc_scene *s, size_t b)
{
    size_t c = b << s->blk_shift;
    return c < s->ncells ? c : s->ncells;
}

static void set_range(dsmc_scene *s)
{
    int me = comm_rank();
    s->blk_lo = s->cuts[me];
    s->blk_hi = s->cuts[me + 1];
    s->cell_lo = block_first_cell(s, s->blk_lo);
    s->cell_hi = block_first_cell(s, s->blk_hi);
}

/* Cuts nblk blocks with the given particle counts into K ranges of nearly equal sums: cut r
 * where the prefix sum is closest to r N / K. Returns the largest range sum over the mean. */
static double make_cuts(size_t *cuts, int K, const uint64_t *count, size_t nblk)
{
    uint64_t total = 0;
    for (size_t b = 0; b < nblk; b++)
        total += count[b];
    cuts[0] = 0;
    size_t b = 0;
    uint64_t prefix = 0; /* sum of count[0 .. b - 1] */
    for (int r = 1; r < K; r++) {
        uint64_t target = (uint64_t)((double)total * r / K);
        while (b < nblk && prefix + count[b] <= target) {
            prefix += count[b];
            b++;
        }
        /* prefix <= target < prefix + count[b]: take block b too when that lands nearer */
        if (b < nblk && prefix + count[b] - target < target - prefix) {
            prefix += count[b];
            b++;
        }
        cuts[r] = b;
    }
    cuts[K] = nblk;
    uint64_t most = 0, sum = 0;
    for (int r = 0; r < K; r++) {
        sum = 0;
        for (size_t q = cuts[r]; q < cuts[r + 1]; q++)
            sum += count[q];
        most = sum > most ? sum : most;
    }
    return total ? (double)most * K / (double)total : 1;
}

static int owner_of(const dsmc_scene *s, uint32_t cell)
{
    size_t b = (size_t)cell >> s->blk_shift;
    int lo = 0, hi = comm_size();
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (s->cuts[mid] <= b)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Keeps the particles of this rank's cells [cell_lo, cell_hi) of a sorted array: they are
 * contiguous. */
static void keep_range(dsmc_scene *s)
{
    size_t a = s->start[s->cell_lo], e = s->start[s->cell_hi], n = e - a;
    for (int k = 0; k < s->D; k++) {
        memmove(s->x[k], s->x[k] + a, n * sizeof(double));
        memmove(s->v[k], s->v[k] + a, n * sizeof(double));
    }
    memmove(s->cell, s->cell + a, n * sizeof *s->cell);
    memmove(s->id, s->id + a, n * sizeof *s->id);
    s->n = n;
}

core_status dsmc_domain_split(dsmc_scene *s, core_error *err)
{
    const int K = comm_size();
    if (K == 1 || s->distributed)
        return CORE_OK;
    if (!s->cuts && !(s->cuts = malloc(((size_t)K + 1) * sizeof *s->cuts)))
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the decomposition");
    uint64_t *count = malloc((s->nblk ? s->nblk : 1) * sizeof *count);
    /* every rank holds the same scene, so every rank computes the same cuts; agree on memory */
    if (!comm_all(count != NULL)) {
        free(count);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the decomposition");
    }
    for (size_t b = 0; b < s->nblk; b++)
        count[b] = s->start[block_first_cell(s, b + 1)] - s->start[block_first_cell(s, b)];
    s->balance_best = make_cuts(s->cuts, K, count, s->nblk);
    free(count);
    s->n_global = s->n;
    set_range(s);
    keep_range(s);
    /* give back the other ranks' share (an eighth spare for arrivals); failing is harmless */
    (void)dsmc_resize(s, s->n + s->n / 8 + 1024);
    dsmc_sort(s); /* the offsets of the kept cells; nothing moves */
    s->distributed = true;
    s->last_balance = s->steps;
    return CORE_OK;
}

/* Sends every particle whose cell another rank owns (by s->cuts) to that rank and appends what
 * arrives. bcount (may be NULL) follows them. */
/* Sends the particles outside this rank's cells [cell_lo, cell_hi) to their owners and takes
 * in those that entered them. *bad in: this rank's flight found a non-finite particle (it then
 * sends nothing); out: some rank's did (the particles that moved are all stored, nothing is
 * lost, the caller stops the run). One all-to-all with the flags on its size exchange: a step
 * has no other synchronisation between its flight and its collisions. The leavers' slots are
 * filled from the end of the arrays, so only O(leavers) particles move (the arrays' order does
 * not matter: the collisions take each cell in identity order); a compaction that kept the
 * order moved every particle after the first leaver, 5% of a rank's step on Fig. 2's gas.
 * *lost: particles received but not stored (out of memory growing the arrays): the caller
 * agrees on it at its next reduction and stops. */
static core_status migrate(dsmc_scene *s, size_t *bcount, int *bad, int64_t *lost,
                           core_error *err)
{
    const int K = comm_size(), D = s->D;
    const int sh = dsmc_sort_shift(s->ncells);
    const uint32_t lo = (uint32_t)s->cell_lo, hi = (uint32_t)s->cell_hi;
    const size_t rec = 2 * (size_t)D * sizeof(double) + 2 * sizeof(uint32_t);
    size_t *sb = calloc(4 * (size_t)K, sizeof *sb);
    if (!sb) /* 4 K words: the process cannot go on */
        comm_abort(70);
    char *send = NULL;
    void *recv = NULL;
    core_status st = CORE_OK;
    size_t nleave = 0;
    *lost = 0;
    if (!*bad) {
        for (size_t i = 0; i < s->n; i++) {
            uint32_t c = s->cell[i];
            if (c < lo || c >= hi) {
                sb[owner_of(s, c)]++;
                nleave++;
            }
        }
    }
    send = malloc(nleave ? nleave * rec : 1);
    int64_t words[2] = {*bad != 0, send == NULL};
    size_t *so = sb + K, *rb = sb + 2 * K, *ro = sb + 3 * K;
    if (send && !*bad) {
        size_t acc = 0;
        for (int r = 0; r < K; r++) {
            so[r] = acc;
            acc += sb[r] * rec;
            ro[r] = so[r]; /* fill cursor */
            sb[r] *= rec;
        }
        size_t n = s->n;
        for (size_t i = 0; i < n;) {
            uint32_t c = s->cell[i];
            if (c >= lo && c < hi) {
                i++;
                continue;
            }
            int r = owner_of(s, c);
            char *p = send + ro[r];
            ro[r] += rec;
            for (int k = 0; k < D; k++) {
                memcpy(p, &s->x[k][i], sizeof(double));
                memcpy(p + (size_t)D * sizeof(double), &s->v[k][i], sizeof(double));
                p += sizeof(double);
            }
            p += (size_t)D * sizeof(double);
            memcpy(p, &s->id[i], sizeof(uint32_t));
            memcpy(p + sizeof(uint32_t), &c, sizeof(uint32_t));
            if (bcount)
                bcount[c >> sh]--;
            n--; /* the last particle takes the slot, and is examined next */
            if (i < n) {
                for (int k = 0; k < D; k++) {
                    s->x[k][i] = s->x[k][n];
                    s->v[k][i] = s->v[k][n];
                }
                s->cell[i] = s->cell[n];
                s->id[i] = s->id[n];
            }
        }
        s->n = n;
    } else {
        memset(sb, 0, 2 * (size_t)K * sizeof *sb); /* takes part, sending nothing */
    }
    if (comm_alltoallv_max(send, sb, so, &recv, rb, ro, words, 2)) {
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory migrating particles between ranks");
        goto done;
    }
    *bad = words[0] != 0;
    if (words[1]) {
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory migrating particles between ranks");
        goto done;
    }
    {
        size_t nin = 0;
        for (int r = 0; r < K; r++)
            nin += rb[r] / rec;
        if (dsmc_reserve(s, s->n + nin, err) != CORE_OK) {
            *lost = (int64_t)nin;
            goto done;
        }
        const char *p = recv;
        for (size_t q = 0; q < nin; q++) {
            size_t i = s->n + q;
            for (int k = 0; k < D; k++) {
                memcpy(&s->x[k][i], p, sizeof(double));
                memcpy(&s->v[k][i], p + (size_t)D * sizeof(double), sizeof(double));
                p += sizeof(double);
            }
            p += (size_t)D * sizeof(double);
            memcpy(&s->id[i], p, sizeof(uint32_t));
            memcpy(&s->cell[i], p + sizeof(uint32_t), sizeof(uint32_t));
            p += 2 * sizeof(uint32_t);
            if (bcount)
                bcount[s->cell[i] >> sh]++;
        }
        s->n += nin;
    }
done:
    free(sb);
    free(send);
    free(recv);
    return st;
}

core_status dsmc_domain_migrate(dsmc_scene *s, size_t *bcount, int *bad, int64_t *lost,
                                core_error *err)
{
    if (!s->distributed) {
        *lost = 0;
        *bad = comm_any(*bad);
        return CORE_OK;
    }
    return migrate(s, bcount, bad, lost, err);
}

core_status dsmc_domain_balance(dsmc_scene *s, int64_t nmax, core_error *err)
{
    const int K = comm_size();
    if (!s->distributed || s->steps - s->last_balance < BALANCE_EVERY)
        return CORE_OK;
    double mean = (double)s->n_global / K, imb = mean > 0 ? (double)nmax / mean : 1;
    if (imb <= BALANCE_LIMIT)
        return CORE_OK;
    s->last_balance = s->steps;
    /* the counts of every block: each rank knows those of its own range */
    size_t nb = s->blk_hi - s->blk_lo;
    uint64_t *mine = malloc((nb ? nb : 1) * sizeof *mine);
    size_t *cuts = malloc(((size_t)K + 1) * sizeof *cuts);
    void *all = NULL, *rem = NULL;
    size_t bytes;
    core_status st = CORE_OK;
    if (!comm_all(mine && cuts)) {
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory rebalancing the ranks");
        goto done;
    }
    for (size_t b = 0; b < nb; b++)
        mine[b] = s->start[block_first_cell(s, s->blk_lo + b + 1)] -
                  s->start[block_first_cell(s, s->blk_lo + b)];
    if (comm_allgatherv(mine, nb * sizeof *mine, &all, &bytes, NULL)) {
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory rebalancing the ranks");
        goto done;
    }
    double best = make_cuts(cuts, K, all, s->nblk); /* the same on every rank */
    if (best > imb - BALANCE_DRIFT)
        goto done; /* not worth a migration */
    /* the owner of a cell may change: every rank gets every cell's remainder */
    if (comm_allgatherv(s->remainder + s->cell_lo, (s->cell_hi - s->cell_lo) * sizeof(double), &rem,
                        &bytes, NULL)) {
        st = core_fail(err, CORE_ERR_NOMEM, "out of memory rebalancing the ranks");
        goto done;
    }
    memcpy(s->remainder, rem, s->ncells * sizeof(double));
    free(s->cuts);
    s->cuts = cuts;
    cuts = NULL;
    s->balance_best = best;
    set_range(s);
    int bad = 0;
    int64_t lost = 0;
    if ((st = migrate(s, NULL, &bad, &lost, err)) == CORE_OK) {
        if (lost)
            st = core_fail(err, CORE_ERR_NOMEM,
                           "out of memory storing %lld particles migrated while rebalancing",
                           (long long)lost);
        dsmc_sort(s);
    }
done:
    free(mine);
    free(cuts);
    free(all);
    free(rem);
    return st;
}

core_status dsmc_gather(dsmc_scene *s, core_error *err)
{
    if (!s->distributed)
        return CORE_OK;
    const int D = s->D;
    void *out[8] = {NULL}, *rem = NULL;
    size_t bytes;
    int bad = 0, q = 0;
    /* this rank's cells are a contiguous range, in rank order, and its particles are sorted
     * by cell then identity: the concatenation in rank order is the one-rank array */
    for (int k = 0; k < D; k++) {
        bad = bad || comm_allgatherv(s->x[k], s->n * sizeof(double), &out[q++], &bytes, NULL);
        bad = bad || comm_allgatherv(s->v[k], s->n * sizeof(double), &out[q++], &bytes, NULL);
    }
    bad = bad || comm_allgatherv(s->cell, s->n * sizeof(uint32_t), &out[q++], &bytes, NULL);
    bad = bad || comm_allgatherv(s->id, s->n * sizeof(uint32_t), &out[q++], &bytes, NULL);
    bad = bad || comm_allgatherv(s->remainder + s->cell_lo,
                                 (s->cell_hi - s->cell_lo) * sizeof(double), &rem, &bytes, NULL);
    if (bad) { /* all ranks agree (comm.h): the scene stays distributed and intact */
        for (int k = 0; k < 8; k++)
            free(out[k]);
        free(rem);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory gathering %zu particles", s->n_global);
    }
    q = 0;
    for (int k = 0; k < D; k++) {
        free(s->x[k]);
        s->x[k] = out[q++];
        free(s->v[k]);
        s->v[k] = out[q++];
    }
    free(s->cell);
    s->cell = out[q++];
    free(s->id);
    s->id = out[q++];
    memcpy(s->remainder, rem, s->ncells * sizeof(double));
    free(rem);
    s->n = s->cap = s->n_global;
    s->distributed = false;
    s->blk_lo = 0;
    s->blk_hi = s->nblk;
    s->cell_lo = 0;
    s->cell_hi = s->ncells;
    dsmc_sort(s); /* the offsets of the whole grid; nothing moves */
    return CORE_OK;
}

bool dsmc_is_distributed(const dsmc_scene *s) { return s->distributed; }

int dsmc_ranks(const dsmc_scene *s)
{
    (void)s;
    return comm_size();
}

core_status dsmc_block_sum(const dsmc_scene *s, const double *local, size_t nper, double *out,
                           core_error *err)
{
    const double *v = local;
    void *all = NULL;
    if (s->distributed) {
        size_t bytes;
        if (comm_allgatherv(local, (s->blk_hi - s->blk_lo) * nper * sizeof(double), &all, &bytes,
                            NULL))
            return core_fail(err, CORE_ERR_NOMEM, "out of memory summing over ranks");
        v = all;
    }
    for (size_t q = 0; q < nper; q++)
        out[q] = 0;
    for (size_t b = 0; b < s->nblk; b++)
        for (size_t q = 0; q < nper; q++)
            out[q] += v[b * nper + q];
    free(all);
    return CORE_OK;
}
