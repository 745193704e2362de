/* The DSMC step's sort (paper Sec. 4): the in-place counting sort of the particles into cells,
 * and each cell's identity order, by which its collisions take its particles (collide.c) and
 * in which the arrays are left between runs. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "dsmc/dsmc_internal.h"

/* ---- sorting --------------------------------------------------------------------------------
 * Counting sort in place (American flag sort): count, prefix-sum, then swap every particle into
 * the next free slot of its bucket. Particles that stay in their cell (most of them, when the
 * step is below the collision time) are never moved, and no second particle buffer is needed.
 * Two passes so that threads can share the work and the result still does not depend on their
 * number: first a serial partition into DSMC_SORT_BLOCKS fixed ranges of cells (only the few
 * particles that crossed a range boundary move), then every range is sorted by cell on its own,
 * ranges in parallel. Measured on the 10^6-particle benchmark: the single serial sort took 60% of
 * a step (perf), and bound two threads to 1.3x at best.
 * Within a cell the order is left as the flag sort makes it, which depends on the order it
 * started from, and so on the decomposition over ranks: the collisions index each cell's
 * particles in identity order through a small permutation (dsmc_cell_perm) instead, and the
 * arrays are put in that order only between runs (dsmc_order_cells), for everything that reads
 * them.
 * What that independence costs one process: the ranks, the indirection in the collisions and
 * the identities the sort carries, most of it the ranks (callgrind). Ranks by an insertion sort
 * (three times the mispredicted branches) and ordering the arrays every step both cost more. */

static inline __attribute__((always_inline)) void swap_particles(dsmc_scene *s, size_t i, size_t j)
{
    for (int k = 0; k < s->D; k++) {
        double t = s->x[k][i];
        s->x[k][i] = s->x[k][j];
        s->x[k][j] = t;
        t = s->v[k][i];
        s->v[k][i] = s->v[k][j];
        s->v[k][j] = t;
    }
    uint32_t c = s->cell[i];
    s->cell[i] = s->cell[j];
    s->cell[j] = c;
    c = s->id[i];
    s->id[i] = s->id[j];
    s->id[j] = c;
}

/* Sorts particles [lo, hi) by key(cell) into buckets [0, nb), key(c) = (c - c0) >> shift (the
 * counts per bucket given, or counted here when counts is NULL); writes the buckets' start offsets
 * (absolute) to start[0 .. nb - 1] only (the last bucket ends at hi), so ranges sorted side by side
 * never write the same entry; next[] is scratch of nb entries. Each swap puts one misplaced
 * particle in place: the slots of the target bucket that already hold its particles are skipped,
 * instead of shifting them along. */
static void flag_sort(dsmc_scene *s, size_t lo, size_t hi, size_t *start, size_t *next, size_t nb,
                      uint32_t c0, int shift, const size_t *counts)
{
    uint32_t *cl = s->cell;
#define KEY(c) (((c)-c0) >> shift)
    if (counts) {
        memcpy(next, counts, nb * sizeof *next);
    } else {
        memset(next, 0, nb * sizeof *next);
        for (size_t i = lo; i < hi; i++)
            next[KEY(cl[i])]++;
    }
    size_t acc = lo;
    for (size_t b = 0; b < nb; b++) {
        size_t cnt = next[b];
        start[b] = next[b] = acc;
        acc += cnt;
    }
    for (size_t b = 0; b < nb; b++) {
        size_t end = b + 1 < nb ? start[b + 1] : hi;
        while (next[b] < end) {
            size_t i = next[b];
            size_t k = KEY(cl[i]);
            if (k == b) {
                next[b]++;
                continue;
            }
            size_t j = next[k];
            while (KEY(cl[j]) == k)
                j++;
            next[k] = j + 1;
            swap_particles(s, i, j);
        }
    }
#undef KEY
}

/* Cells per sort range: a power of two (a shift, not a division, per particle) giving at most
 * DSMC_SORT_BLOCKS ranges. */
int dsmc_sort_shift(size_t nc)
{
    int sh = 0;
    while ((nc + ((size_t)1 << sh) - 1) >> sh > DSMC_SORT_BLOCKS)
        sh++;
    return sh;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

typedef int32_t v4i32 __attribute__((vector_size(16)));

/* The ranks of N <= 4 NQ identities, 4 comparisons at a time with the counters in registers
 * (NQ is a constant: the compiler unrolls the inner loop). sid: the identities as ordered
 * signed values, padded with INT32_MAX, which is below none. */
static inline __attribute__((always_inline)) void rank_small(const v4i32 *sid, size_t N,
                                                             uint32_t *P, const int NQ)
{
    v4i32 r[8];
    for (int q = 0; q < NQ; q++)
        r[q] = (v4i32){0, 0, 0, 0};
    const int32_t *sp = (const int32_t *)sid;
    for (size_t j = 0; j < N; j++) {
        const int32_t y = sp[j];
        for (int q = 0; q < NQ; q++)
            r[q] -= y < sid[q]; /* true is -1 */
    }
    const int32_t *rp = (const int32_t *)r;
    for (size_t k = 0; k < N; k++)
        P[rp[k]] = (uint32_t)k;
}

/* The identity order of a cell's N particles: P[k] = the slot (from the cell's first) of the
 * k-th smallest identity. key: N scratch entries (cells of more than 32 only). Identities are
 * unique, so in a small cell each particle's rank is the number of smaller identities: N^2
 * comparisons without a branch, 4 at a time (GCC's vector extension: SSE2 on x86-64, NEON on
 * arm64; signed, as SSE2 has no unsigned comparison: the top bit flipped keeps the order).
 * Sorting the keys instead (an insertion sort: N^2/4 moves and a mispredicted branch per
 * particle) cost 118 instructions per particle on the cooling benchmark (20 per cell), more
 * than the collisions themselves. */
void dsmc_cell_perm_big(const uint32_t *id, size_t N, uint64_t *key, uint32_t *P)
{
    if (N <= 32) {
        v4i32 sid[8];
        int32_t *sp = (int32_t *)sid;
        const size_t nq = (N + 3) / 4;
        for (size_t k = 0; k < N; k++)
            sp[k] = (int32_t)(id[k] ^ 0x80000000u);
        for (size_t k = N; k < 4 * nq; k++)
            sp[k] = INT32_MAX;
        switch (nq) {
        case 1: rank_small(sid, N, P, 1); return;
        case 2: rank_small(sid, N, P, 2); return;
        case 3: rank_small(sid, N, P, 3); return;
        case 4: rank_small(sid, N, P, 4); return;
        case 5: rank_small(sid, N, P, 5); return;
        case 6: rank_small(sid, N, P, 6); return;
        case 7: rank_small(sid, N, P, 7); return;
        default: rank_small(sid, N, P, 8); return;
        }
    }
    for (size_t k = 0; k < N; k++)
        key[k] = (uint64_t)id[k] << 32 | (uint64_t)k;
    qsort(key, N, sizeof *key, cmp_u64);
    for (size_t k = 0; k < N; k++)
        P[k] = (uint32_t)key[k];
}

/* Puts the particles [a, a + N) of one cell in identity order, through a buffer (an insertion
 * sort moving whole particles when out of memory). */
void dsmc_order_cell(dsmc_scene *s, size_t a, size_t N)
{
    uint32_t *id = s->id + a;
    size_t i = 1;
    while (i < N && id[i - 1] < id[i])
        i++;
    if (i >= N)
        return;
    const int D = s->D;
    double *X[3] = {s->x[0] + a, s->x[1] + a, D == 3 ? s->x[2] + a : NULL};
    double *V[3] = {s->v[0] + a, s->v[1] + a, D == 3 ? s->v[2] + a : NULL};
    enum { SMALL = 64 };
    uint64_t kbuf[SMALL];
    double tbuf[SMALL];
    uint32_t pbuf[SMALL];
    uint64_t *key = kbuf;
    double *tmp = tbuf;
    uint32_t *P = pbuf;
    void *heap = NULL;
    if (N > SMALL) {
        heap = malloc(N * (sizeof *key + sizeof *tmp + sizeof *P));
        if (!heap) {
            for (; i < N; i++) {
                uint32_t ki = id[i];
                double x[3], v[3];
                for (int k = 0; k < D; k++) {
                    x[k] = X[k][i];
                    v[k] = V[k][i];
                }
                size_t j = i;
                for (; j > 0 && id[j - 1] > ki; j--) {
                    for (int k = 0; k < D; k++) {
                        X[k][j] = X[k][j - 1];
                        V[k][j] = V[k][j - 1];
                    }
                    id[j] = id[j - 1];
                }
                for (int k = 0; k < D; k++) {
                    X[k][j] = x[k];
                    V[k][j] = v[k];
                }
                id[j] = ki;
            }
            return;
        }
        key = heap;
        tmp = (double *)(key + N);
        P = (uint32_t *)(tmp + N);
    }
    dsmc_cell_perm(id, N, key, P);
    for (int q = 0; q < 2 * D; q++) {
        double *A = q < D ? X[q] : V[q - D];
        for (size_t k = 0; k < N; k++)
            tmp[k] = A[P[k]];
        memcpy(A, tmp, N * sizeof *tmp);
    }
    for (size_t k = 0; k < N; k++)
        key[k] = id[P[k]];
    for (size_t k = 0; k < N; k++)
        id[k] = (uint32_t)key[k];
    free(heap);
}

void dsmc_order_cells(dsmc_scene *s)
{
    const long c0 = (long)s->cell_lo, c1 = (long)s->cell_hi;
#pragma omp parallel for schedule(dynamic, 256) if (s->n >= DSMC_PARALLEL_MIN)
    for (long c = c0; c < c1; c++)
        if (s->start[c + 1] - s->start[c] > 1)
            dsmc_order_cell(s, s->start[c], s->start[c + 1] - s->start[c]);
}

void dsmc_sort_counted(dsmc_scene *s, const size_t *bcount)
{
    size_t nc = s->ncells;
    int sh = dsmc_sort_shift(nc);
    size_t width = (size_t)1 << sh, nb = (nc + width - 1) >> sh;
    size_t bstart[DSMC_SORT_BLOCKS + 1], bnext[DSMC_SORT_BLOCKS];
    flag_sort(s, 0, s->n, bstart, bnext, nb, 0, sh, bcount);
    bstart[nb] = s->n;
    size_t *start = s->start, *next = s->next;
    /* Only this rank's cells [cell_lo, cell_hi) hold particles (all of them on one rank): the
     * offsets of other ranks' cells are left alone, so the cost of a rank's sort goes with its
     * share of the grid, not with the whole grid. */
    const size_t lo = s->cell_lo, hi = s->cell_hi;
    const long b0 = hi > lo ? (long)(lo >> sh) : 0, b1 = hi > lo ? (long)((hi - 1) >> sh) + 1 : 0;
#pragma omp parallel for schedule(dynamic, 1) if (s->n >= DSMC_PARALLEL_MIN)
    for (long b = b0; b < b1; b++) {
        size_t c0 = (size_t)b * width, c1 = c0 + width < nc ? c0 + width : nc;
        c0 = c0 > lo ? c0 : lo;
        c1 = c1 < hi ? c1 : hi;
        flag_sort(s, bstart[b], bstart[b + 1], start + c0, next + c0, c1 - c0, (uint32_t)c0, 0,
                  NULL);
    }
    start[hi] = s->n;
    start[nc] = s->n;
}

void dsmc_sort(dsmc_scene *s)
{
    dsmc_sort_counted(s, NULL);
    dsmc_order_cells(s);
}
