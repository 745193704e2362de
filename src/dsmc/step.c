/* The DSMC step (paper Sec. 4): free flight with gravity and walls, the in-place counting sort
 * into cells, and the collisions of Eq. 1 in every cell. Threads split particles (flight) and
 * cells (collisions); every cell and every wall hit draws from its own random stream, and each
 * cell's particles are taken in identity order, so the result does not depend on the number of
 * threads, nor on the number of MPI ranks (domain.c). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/comm.h"
#include "core/interrupt.h"
#include "core/threads.h"
#include "dsmc/dsmc_internal.h"

enum { STREAM_COLLIDE = 1, STREAM_WALL = 2 };

/* Below this many particles a step is a few hundred microseconds and threads cost more than they
 * bring (barriers; on a loaded machine, a descheduled thread stalls every step). */
#define DSMC_PARALLEL_MIN 50000

dsmc_run_def dsmc_default_run_def(void)
{
    return (dsmc_run_def){.steps = 0, .dt = 0, .time_end = -1};
}

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
 * particles in identity order through a small permutation (cell_perm) instead, and the arrays
 * are put in that order only between runs (dsmc_order_cells), for everything that reads them.
 * The price of that independence, one process, one thread, against the code before identities
 * (callgrind instructions; speed from 3 alternating runs each on a quiet machine): the cooling
 * benchmark (20 per cell) +18% (642 M against 542 M for 10^5 particles x 20 steps: the ranks
 * 68 M, the indirection in the collisions 18 M, the identities carried by the sort 6 M) and
 * 0.87x the speed; Herrmann's Fig. 2 gas (0.7 per cell) +8% and 0.87x (the identities add a
 * tenth to the bytes the sort moves). Ranks by an insertion sort cost +28% and 0.70-0.80x on
 * the former (3 times the mispredicted branches), ordering the arrays every step +33%. */

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
static void cell_perm_big(const uint32_t *id, size_t N, uint64_t *key, uint32_t *P)
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

static inline void cell_perm(const uint32_t *id, size_t N, uint64_t *key, uint32_t *P)
{
    if (N > 4) {
        cell_perm_big(id, N, key, P);
        return;
    }
    /* most cells of a dilute gas (Fig. 2's: 0.7 per cell): in place, without a call */
    for (size_t k = 0; k < N; k++) {
        uint32_t r = 0, x = id[k];
        for (size_t j = 0; j < N; j++)
            r += id[j] < x;
        P[r] = (uint32_t)k;
    }
}

/* Puts the particles [a, a + N) of one cell in identity order, through a buffer (an insertion
 * sort moving whole particles when out of memory). */
static void order_cell(dsmc_scene *s, size_t a, size_t N)
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
    cell_perm(id, N, key, P);
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
            order_cell(s, s->start[c], s->start[c + 1] - s->start[c]);
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

/* ---- free flight ------------------------------------------------------------------------------
 */
typedef struct wall_state {
    bool active;
    double pos, vel; /* along the axis, at the end of the step */
} wall_state;

/* Reflects component k of particle i off the wall of `side` that it has crossed. The crossing
 * happened a time tr ago, estimated from the normal speed relative to the wall; the particle
 * leaves with its new normal velocity for that time. */
static void reflect(const dsmc_scene *s, int side, const wall_state *ws, double dt, double *x,
                    double v[3], rng *r)
{
    const dsmc_wall_def *w = &s->walls[side];
    int axis = side / 2;
    double sign = side % 2 == 0 ? 1 : -1;      /* inward normal along the axis */
    double rel = sign * (ws->vel - v[axis]);   /* approach speed in the wall frame, > 0 */
    double depth = sign * (ws->pos - x[axis]); /* how far behind the wall, > 0 */
    double tr = rel > 0 ? fmin(depth / rel, dt) : 0;
    double vn; /* outgoing normal speed relative to the wall, > 0 */
    if (w->kind == DSMC_WALL_DIFFUSE) {
        double sd = sqrt(w->temperature / s->mass);
        double u = rng_uniform(r);
        vn = sd * sqrt(-2 * log(1 - u)); /* flux-weighted: Rayleigh */
        for (int k = 0; k < s->D; k++)
            if (k != axis)
                v[k] = w->velocity[k] + sd * rng_normal(r);
    } else {
        vn = w->restitution * (rel > 0 ? rel : -rel);
    }
    v[axis] = ws->vel + sign * vn;
    x[axis] = ws->pos + sign * vn * tr;
}

typedef struct flight_totals {
    long wall_hits;
    int bad;
    long stranded;  /* particles still beyond a wall after the bounce budget (put on it) */
    long strand_id; /* the smallest identity among them (LONG_MAX: none) */
} flight_totals;

/* The constants of one flight step, read once: stores into the particle arrays could alias the
 * scene, so the loop must not read them through it. */
typedef struct flight_consts {
    double dt, hdt2, g[3], lo[3], hi[3], L[3], inv_h[3];
    int cells[3], sh;
    bool per[3];
    wall_state ws[6];
    uint64_t seed, step;
} flight_consts;

/* Whether the walls of axis k reflect like mirrors: both fixed, specular with restitution 1,
 * and no gravity along the axis. Then any number of crossings in one step is a fold of the
 * free flight about the two walls (the trajectory in a box of period 2L). */
static bool mirror_axis(const dsmc_scene *s, const flight_consts *fc, int k)
{
    for (int side = 2 * k; side < 2 * k + 2; side++) {
        const dsmc_wall_def *w = &s->walls[side];
        if (w->kind != DSMC_WALL_SPECULAR || w->restitution != 1 || w->amplitude != 0)
            return false;
    }
    return fc->g[k] == 0;
}

/* Walls for one particle that is outside the walls on a non-periodic axis (the slow path). A
 * particle may cross both walls of a thin box: up to 4 reflections are followed one by one;
 * beyond them, mirror walls fold the rest of the flight in closed form (O(1) for any dt), and
 * other walls (moving, diffuse, inelastic, under gravity) put the particle on the wall it is
 * behind and count it in *stranded: a step that long is refused by the run (dsmc_run). */
static __attribute__((noinline)) long walls_one(const dsmc_scene *s, const flight_consts *fc, int D,
                                                uint64_t id, double x[3], double v[3],
                                                int *stranded)
{
    long hits = 0;
    for (int k = 0; k < D; k++) {
        if (fc->per[k])
            continue;
        const wall_state *ws = fc->ws;
        for (int bounce = 0; bounce < 4; bounce++) {
            int side = x[k] < ws[2 * k].pos ? 2 * k : x[k] > ws[2 * k + 1].pos ? 2 * k + 1 : -1;
            if (side < 0)
                break;
            rng r = {{0, 0, 0, 0}};
            if (s->walls[side].kind == DSMC_WALL_DIFFUSE)
                dsmc_stream(&r, fc->seed, STREAM_WALL, fc->step, id * 8 + (uint64_t)bounce);
            reflect(s, side, &ws[side], fc->dt, x, v, &r);
            hits++;
        }
        const double lo = ws[2 * k].pos, hi = ws[2 * k + 1].pos, L = hi - lo;
        if (!(x[k] < lo || x[k] > hi))
            continue;
        const double u = x[k] - lo;
        if (mirror_axis(s, fc, k) && fabs(u) < 1e12 * L) { /* beyond: digits of x left */
            const double c = floor(u / L);                   /* walls crossed: |c| */
            double m = u - 2 * L * floor(u / (2 * L));       /* in [0, 2L) */
            if (m > L) {
                m = 2 * L - m;
                v[k] = -v[k];
            }
            x[k] = fmin(fmax(lo + m, lo), hi);
            hits += (long)fabs(c);
            continue;
        }
        *stranded = 1;
        x[k] = x[k] < lo ? lo : hi;
    }
    return hits;
}

/* The flight loop for a dimension D, walls W (some axis below D not periodic) and gravity G
 * (some component not zero) known at compile time: a periodic box without gravity, the common
 * gas, pays nothing for the walls and gravity it does not have (9 of its 149 instructions per
 * particle before; a zero gravity added +0.0, which only turns a -0.0 into +0.0). */
static inline __attribute__((always_inline)) flight_totals
flight_dim(dsmc_scene *s, const flight_consts *fc, size_t bcount[DSMC_SORT_BLOCKS], const int D,
           const bool W, const bool G)
{
    const long n = (long)s->n;
    double *const X[3] = {s->x[0], s->x[1], s->x[2]}, *const V[3] = {s->v[0], s->v[1], s->v[2]};
    uint32_t *const cell = s->cell;
    const double dt = fc->dt, hdt2 = fc->hdt2;
    double g[3], lo[3], hi[3], L[3], ih[3], wlo[3], whi[3];
    int nc[3];
    bool per[3], any_wall = false;
    for (int k = 0; k < 3; k++) {
        g[k] = fc->g[k];
        lo[k] = fc->lo[k];
        hi[k] = fc->hi[k];
        L[k] = fc->L[k];
        ih[k] = fc->inv_h[k];
        nc[k] = fc->cells[k];
        per[k] = fc->per[k];
        wlo[k] = per[k] ? -INFINITY : fc->ws[2 * k].pos;
        whi[k] = per[k] ? INFINITY : fc->ws[2 * k + 1].pos;
        any_wall = any_wall || (k < D && !per[k]);
    }
    const int sh = fc->sh;
    long hits = 0, stranded = 0, strand_id = LONG_MAX;
    int bad = 0;
    for (int b = 0; b < DSMC_SORT_BLOCKS; b++)
        bcount[b] = 0;
#pragma omp parallel for schedule(dynamic, 8192) \
    reduction(+ : hits, stranded, bcount[:DSMC_SORT_BLOCKS]) reduction(| : bad) \
    reduction(min : strand_id) if (n >= DSMC_PARALLEL_MIN)
    for (long i = 0; i < n; i++) {
        double x[3], v[3];
        int out = 0;
        for (int k = 0; k < D; k++) {
            x[k] = G ? X[k][i] + V[k][i] * dt + g[k] * hdt2 : X[k][i] + V[k][i] * dt;
            v[k] = G ? V[k][i] + g[k] * dt : V[k][i];
            if (!W || per[k]) {
                if (x[k] < lo[k])
                    x[k] += L[k];
                else if (x[k] >= hi[k])
                    x[k] -= L[k];
                if (!(x[k] >= lo[k] && x[k] < hi[k])) /* more than a box in one step */
                    x[k] -= L[k] * floor((x[k] - lo[k]) / L[k]);
            } else {
                out |= x[k] < wlo[k] || x[k] > whi[k];
            }
        }
        if (W && any_wall && out) {
            int st = 0;
            hits += walls_one(s, fc, D, s->id[i], x, v, &st);
            if (st) {
                stranded++;
                strand_id = (long)s->id[i] < strand_id ? (long)s->id[i] : strand_id;
            }
        }
        size_t c = 0;
        double chk = 0;
        for (int k = D - 1; k >= 0; k--) {
            X[k][i] = x[k];
            V[k][i] = v[k];
            chk += x[k] + v[k];
            double f = (x[k] - lo[k]) * ih[k];
            int ci = !(f >= 0) ? 0 : f >= nc[k] ? nc[k] - 1 : (int)f; /* NaN: 0 */
            c = c * (size_t)nc[k] + (size_t)ci;
        }
        bad |= !isfinite(chk);
        cell[i] = (uint32_t)c;
        bcount[c >> sh]++;
    }
    return (flight_totals){hits, bad, stranded, strand_id};
}

/* Moves every particle, finds its cell and counts the particles per sort range (bcount). */
static flight_totals flight(dsmc_scene *s, double dt, size_t bcount[DSMC_SORT_BLOCKS])
{
    flight_consts fc;
    memset(&fc, 0, sizeof fc);
    fc.dt = dt;
    fc.hdt2 = 0.5 * dt * dt;
    for (int k = 0; k < 3; k++) {
        fc.g[k] = s->def.gravity[k];
        fc.lo[k] = s->def.lo[k];
        fc.hi[k] = s->def.hi[k];
        fc.L[k] = fc.hi[k] - fc.lo[k];
        fc.inv_h[k] = s->inv_h[k];
        fc.cells[k] = s->def.cells[k];
        fc.per[k] = s->def.periodic[k];
    }
    for (int side = 0; side < 6; side++) {
        fc.ws[side].active = side < 2 * s->D && !s->def.periodic[side / 2];
        if (fc.ws[side].active)
            dsmc_wall_motion(s, side, s->t + dt, &fc.ws[side].pos, &fc.ws[side].vel);
    }
    fc.sh = dsmc_sort_shift(s->ncells);
    fc.seed = s->def.seed;
    fc.step = (uint64_t)s->steps;
    bool W = false, G = false;
    for (int k = 0; k < s->D; k++) {
        W = W || !fc.per[k];
        G = G || fc.g[k] != 0;
    }
    if (s->D == 2)
        return W ? (G ? flight_dim(s, &fc, bcount, 2, true, true)
                      : flight_dim(s, &fc, bcount, 2, true, false))
                 : (G ? flight_dim(s, &fc, bcount, 2, false, true)
                      : flight_dim(s, &fc, bcount, 2, false, false));
    return W ? (G ? flight_dim(s, &fc, bcount, 3, true, true)
                  : flight_dim(s, &fc, bcount, 3, true, false))
             : (G ? flight_dim(s, &fc, bcount, 3, false, true)
                  : flight_dim(s, &fc, bcount, 3, false, false));
}

/* ---- collisions (Eq. 1) -----------------------------------------------------------------------
 */
typedef struct collide_totals {
    long attempts, collisions, raised, overpacked;
    long overflow; /* cells whose number of candidates was not a number (speeds overflowed) */
} collide_totals;

/* A cell may take at most this many candidate pairs per particle in one step (Eq. 1): about
 * half as many collisions per particle, i.e. a step some 50 times the cell's collision time.
 * Beyond it the cell is left alone and the run stops (dsmc_run): the work of a step stays in
 * proportion to its particles, whatever dt is asked. */
#define DSMC_CANDIDATES_PER_PARTICLE 100

/* What stops a run after a step completes, reduced over threads and ranks to one culprit each
 * (a total order: the result does not depend on the thread or rank count). */
typedef struct dsmc_verdict {
    int64_t packed_cells, packed_cell, packed_n; /* cells past close packing; the fullest */
    int64_t capped_cells, capped_cell, capped_n; /* cells over the candidate cap; the worst */
    double capped_m;                             /* its candidate pairs */
    int64_t stranded, strand_id;                 /* particles put on a wall; the first id */
} dsmc_verdict;

static void verdict_clear(dsmc_verdict *v)
{
    memset(v, 0, sizeof *v);
    v->packed_cell = v->capped_cell = v->strand_id = INT64_MAX;
}

static bool verdict_any(const dsmc_verdict *v)
{
    return v->packed_cells || v->capped_cells || v->stranded;
}

static void verdict_merge(dsmc_verdict *a, const dsmc_verdict *b)
{
    a->packed_cells += b->packed_cells;
    if (b->packed_n > a->packed_n || (b->packed_n == a->packed_n && b->packed_cell < a->packed_cell))
        a->packed_n = b->packed_n, a->packed_cell = b->packed_cell;
    a->capped_cells += b->capped_cells;
    if (b->capped_m > a->capped_m || (b->capped_m == a->capped_m && b->capped_cell < a->capped_cell))
        a->capped_m = b->capped_m, a->capped_cell = b->capped_cell, a->capped_n = b->capped_n;
    a->stranded += b->stranded;
    if (b->strand_id < a->strand_id)
        a->strand_id = b->strand_id;
}

/* The most particles whose centres can lie in one cell at the packing limit nu_rcp: their
 * bodies fill the cell widened by a radius on every side, so N v_b <= nu_rcp prod(h_k + 2R). */
static double fit_per_cell(const dsmc_scene *s)
{
    double vol = 1;
    for (int k = 0; k < s->D; k++)
        vol *= s->h[k] + 2 * s->def.radius;
    return floor(s->def.packing_limit * vol / s->vpart);
}

/* ln P(N >= k) of a Poisson count of mean mu, bounded above (k > mu): the terms from k on fall
 * at least by mu / (k + 1) each. */
static double poisson_log_tail(double mu, double k)
{
    return -mu + k * log(mu) - lgamma(k + 1) - log(1 - mu / (k + 1));
}

/* The count from which a cell is past close packing for the run's check: more than fit in it
 * (fit_per_cell), and beyond the reach of the cells' Poisson noise in a gas DSMC can describe:
 * P(N >= threshold) < 1e-20 per cell and step at a mean occupancy mu of the larger of the gas's
 * mean and that of the densest gas whose mean free path (chi = 1) still spans the cell
 * (condition ii): V_c / (2 sqrt2 sigma h_max) in 2D, V_c / (sqrt2 sigma h_max) in 3D. In cells
 * of one diameter (2D) that noise stays below 14, where 4 fit. */
static double packed_threshold(const dsmc_scene *s)
{
    double hmax = 0;
    for (int k = 0; k < s->D; k++)
        hmax = fmax(hmax, s->h[k]);
    double mu = s->cell_volume / ((s->D == 2 ? 2 * sqrt(2.0) : sqrt(2.0)) * s->sigma * hmax);
    mu = fmax(mu, (double)dsmc_count(s) / (double)s->ncells);
    const double lim = log(1e-20);
    double lo = floor(mu) + 1, hi = lo + 20 * sqrt(mu) + 100; /* tail(hi) < 1e-20 */
    while (hi - lo > 1) {
        double mid = floor(0.5 * (lo + hi));
        if (poisson_log_tail(mu, mid) < lim)
            hi = mid;
        else
            lo = mid;
    }
    return fmax(fit_per_cell(s) + 1, hi);
}

/* Post-collision velocities: the normal component of g = v_i - v_j reversed and scaled by e, the
 * tangential one kept; n from the random impact parameter b (|b| < 2R): sin(theta) = b / 2R is
 * the angle between g and n. 2D: b uniform in [-2R, 2R]. */
static inline void collide_2d(double *vi, double *vj, double gx, double gy, double g, double e1h,
                              rng *r)
{
    double sn = 2 * rng_uniform(r) - 1, cs = sqrt(1 - sn * sn);
    double nx = (cs * gx - sn * gy) / g, ny = (cs * gy + sn * gx) / g;
    double f = e1h * g * cs; /* (1 + e)/2 (g . n) */
    vi[0] -= f * nx;
    vi[1] -= f * ny;
    vj[0] += f * nx;
    vj[1] += f * ny;
}

/* 3D: b uniform over the disk of radius 2R: (a, b) uniform in the unit disk (rejection), so
 * sin^2(theta) = a^2 + b^2 is uniform in [0, 1]. */
static inline void collide_3d(double *vi, double *vj, const double gv[3], double g, double e1h,
                              rng *r)
{
    double u[3] = {gv[0] / g, gv[1] / g, gv[2] / g}, e1[3];
    if (fabs(u[0]) < 0.6) { /* u x (1, 0, 0) */
        e1[0] = 0;
        e1[1] = u[2];
        e1[2] = -u[1];
    } else { /* u x (0, 1, 0) */
        e1[0] = -u[2];
        e1[1] = 0;
        e1[2] = u[0];
    }
    double l = 1 / sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    e1[0] *= l;
    e1[1] *= l;
    e1[2] *= l;
    double e2[3] = {u[1] * e1[2] - u[2] * e1[1], u[2] * e1[0] - u[0] * e1[2],
                    u[0] * e1[1] - u[1] * e1[0]};
    double a, b, s2;
    do {
        a = 2 * rng_uniform(r) - 1;
        b = 2 * rng_uniform(r) - 1;
        s2 = a * a + b * b;
    } while (s2 >= 1);
    double cs = sqrt(1 - s2), f = e1h * g * cs;
    for (int k = 0; k < 3; k++) {
        double nk = cs * u[k] + a * e1[k] + b * e2[k];
        vi[k] -= f * nk;
        vj[k] += f * nk;
    }
}

static collide_totals collide(dsmc_scene *s, double dt, dsmc_verdict *verdict)
{
    const int D = s->D;
    const long c_lo = (long)s->cell_lo, nc = (long)s->cell_hi;
    const size_t *start = s->start;
    double *rem = s->remainder;
    double *V[3] = {s->v[0], s->v[1], s->v[2]};
    const double e1h = 0.5 * (1 + s->def.restitution);
    const double base = s->sigma * dt / 2, Vc = s->cell_volume;
    const double vb = s->vpart, rcp = s->def.packing_limit;
    const dsmc_excluded excl = s->def.excluded;
    const uint64_t seed = s->def.seed, step = (uint64_t)s->steps;
    const size_t packed = (size_t)packed_threshold(s);
    long attempts = 0, collisions = 0, raised = 0, overpacked = 0, overflow = 0;
    verdict_clear(verdict);
#pragma omp parallel for schedule(dynamic, 64) \
    reduction(+ : attempts, collisions, raised, overpacked, overflow) if (s->n >= DSMC_PARALLEL_MIN)
    for (long c = c_lo; c < nc; c++) {
        size_t a = start[c], N = start[c + 1] - a;
        if (N < 2)
            continue;
        if (N >= packed) { /* collided all the same: the step completes, the run stops after it */
            dsmc_verdict mine;
            verdict_clear(&mine);
            mine.packed_cells = 1;
            mine.packed_cell = c;
            mine.packed_n = (int64_t)N;
#pragma omp critical(dsmc_verdict)
            verdict_merge(verdict, &mine);
        }
        /* The cell's particles in identity order: P[k] is the k-th (offset from a). Out of
         * memory for a large cell: the arrays themselves are put in order, P = NULL. */
        uint64_t kbuf[64];
        uint32_t pbuf[64], *P = pbuf;
        uint64_t *key = kbuf;
        void *heap = NULL;
        if (N > 64) {
            heap = malloc(N * (sizeof *key + sizeof *P));
            key = heap;
            P = heap ? (uint32_t *)(key + N) : NULL;
            if (!heap)
                order_cell(s, a, N);
        }
        if (P)
            cell_perm(s->id + a, N, key, P);
        /* v_max: twice the largest speed about the cell's mean velocity bounds every pair's
         * relative speed at the start of the step; raised when a collision exceeds it. The
         * mean sums in identity order, so its bits do not depend on the layout. */
        double u[3] = {0, 0, 0};
        for (int k = 0; k < D; k++) {
            const double *vk = V[k] + a;
            double sum = 0;
            for (size_t i = 0; i < N; i++)
                sum += vk[P ? P[i] : i];
            u[k] = sum / (double)N;
        }
        double m2 = 0;
        for (size_t i = 0; i < N; i++) {
            double q = 0;
            for (int k = 0; k < D; k++) {
                double d = V[k][a + i] - u[k];
                q += d * d;
            }
            m2 = q > m2 ? q : m2;
        }
        double vmax = 2 * sqrt(m2);
        if (vmax == 0) {
            free(heap);
            continue;
        }
        double Nd = (double)N, Veff = Vc, chi = 1;
        if (excl == DSMC_EXCLUDED_FREE_VOLUME) {
            Veff = Vc - Nd * vb / rcp;
            if (Veff < 0.01 * Vc) {
                Veff = 0.01 * Vc;
                overpacked++;
            }
        } else if (excl == DSMC_EXCLUDED_ENSKOG) {
            double nu = Nd * vb / Vc;
            if (nu > 0.99 * rcp) {
                nu = 0.99 * rcp;
                overpacked++;
            }
            chi = D == 2 ? (1 - 7 * nu / 16) / ((1 - nu) * (1 - nu))
                         : (1 - nu / 2) / ((1 - nu) * (1 - nu) * (1 - nu));
        }
        double M = Nd * (Nd - 1) * base * vmax * chi / Veff + rem[c];
        if (!(M < 1e15)) { /* speeds near the overflow (or not finite): the step fails */
            overflow++;
            free(heap);
            continue;
        }
        /* dt far above the cell's collision time. The cap counts the candidates of the dilute
         * limit: chi is bounded (the free volume at 1 % of the cell, Enskog's at 0.99 nu_rcp),
         * and a few particles over the free volume of a small cell, a Poisson fluctuation of a
         * valid gas, must not trip it. */
        if (M * Veff > DSMC_CANDIDATES_PER_PARTICLE * Nd * Vc * chi) {
            dsmc_verdict mine;
            verdict_clear(&mine);
            mine.capped_cells = 1;
            mine.capped_cell = c;
            mine.capped_n = (int64_t)N;
            mine.capped_m = M;
#pragma omp critical(dsmc_verdict)
            verdict_merge(verdict, &mine);
            free(heap);
            continue;
        }
        double Mi = floor(M);
        rem[c] = M - Mi;
        long m = (long)Mi;
        if (m == 0) {
            free(heap);
            continue;
        }
        rng r;
        dsmc_stream(&r, seed, STREAM_COLLIDE, step, (uint64_t)c);
        attempts += m;
        for (long t = 0; t < m; t++) {
            size_t i = rng_below(&r, N), j = rng_below(&r, N - 1);
            if (j >= i)
                j++;
            i = a + (P ? P[i] : i);
            j = a + (P ? P[j] : j);
            double gv[3] = {0, 0, 0}, g2 = 0;
            for (int k = 0; k < D; k++) {
                gv[k] = V[k][i] - V[k][j];
                g2 += gv[k] * gv[k];
            }
            if (g2 > vmax * vmax) {
                vmax = sqrt(g2);
                raised++;
            }
            double z = rng_uniform(&r) * vmax;
            if (z * z >= g2 || g2 == 0)
                continue;
            collisions++;
            double g = sqrt(g2);
            if (D == 2) {
                double vi[2] = {V[0][i], V[1][i]}, vj[2] = {V[0][j], V[1][j]};
                collide_2d(vi, vj, gv[0], gv[1], g, e1h, &r);
                V[0][i] = vi[0];
                V[1][i] = vi[1];
                V[0][j] = vj[0];
                V[1][j] = vj[1];
            } else {
                double vi[3], vj[3];
                for (int k = 0; k < 3; k++) {
                    vi[k] = V[k][i];
                    vj[k] = V[k][j];
                }
                collide_3d(vi, vj, gv, g, e1h, &r);
                for (int k = 0; k < 3; k++) {
                    V[k][i] = vi[k];
                    V[k][j] = vj[k];
                }
            }
        }
        free(heap);
    }
    return (collide_totals){attempts, collisions, raised, overpacked, overflow};
}

/* ---- the run ----------------------------------------------------------------------------------
 */
/* The likely cause of values out of range, from the run's numbers only (every rank gives the
 * same words): DSMC's collisions conserve or lose energy, so only a huge step, gravity or speed
 * given can overflow. */
static void out_of_range(const dsmc_scene *s, double dt, char *buf, size_t n)
{
    double g = 0, L = INFINITY;
    for (int k = 0; k < s->D; k++) {
        g += s->def.gravity[k] * s->def.gravity[k];
        L = fmin(L, s->h[k] * s->def.cells[k]);
    }
    g = sqrt(g);
    if (g > 0 && 0.5 * g * dt * dt > L)
        snprintf(buf, n,
                 "the time step dt = %.3g s is out of range for the gravity: one step moves a "
                 "particle |g| dt^2 / 2 = %.3g m against a box of %.3g m; use dt = \"auto\" or a "
                 "smaller dt",
                 dt, 0.5 * g * dt * dt, L);
    else
        snprintf(buf, n,
                 "the time step dt = %.3g s or the speeds given are out of range (speeds near the "
                 "largest double); use dt = \"auto\" and speeds of the gas's scale",
                 dt);
}

static core_status overflow_error(const dsmc_scene *s, double dt, core_error *err)
{
    char cause[300];
    out_of_range(s, dt, cause, sizeof cause);
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "step %ld (t = %.6g s): a cell's number of collision candidates overflowed "
                     "(relative speeds near the largest double); likely cause: %s",
                     s->steps - 1, s->t, cause);
}

/* "x 0.075-0.08 m, y 0-0.005 m": where cell c lies. */
static void cell_where(const dsmc_scene *s, int64_t c, char *buf, size_t size)
{
    size_t len = 0;
    for (int k = 0; k < s->D && len < size; k++) {
        int64_t i = c % s->def.cells[k];
        c /= s->def.cells[k];
        double a = s->def.lo[k] + (double)i * s->h[k];
        int w = snprintf(buf + len, size - len, "%s%c %.4g-%.4g m", k ? ", " : "", "xyz"[k], a,
                         a + s->h[k]);
        len += w > 0 ? (size_t)w : 0;
    }
}

/* The verdict on the step just completed (agreed over ranks first: collective when multi) as
 * the run's error, with the numbers and the likely cause. */
static core_status verdict_error(const dsmc_scene *s, dsmc_verdict *v, bool multi, double dt,
                                 core_error *err)
{
    if (multi) {
        void *all = NULL;
        size_t bytes = 0;
        if (comm_allgatherv(v, sizeof *v, &all, &bytes, NULL))
            return core_fail(err, CORE_ERR_NOMEM, "step %ld: out of memory gathering the "
                             "verdict of the ranks", s->steps - 1);
        dsmc_verdict m;
        verdict_clear(&m);
        for (size_t r = 0; r < bytes / sizeof *v; r++) {
            dsmc_verdict one;
            memcpy(&one, (char *)all + r * sizeof *v, sizeof one);
            verdict_merge(&m, &one);
        }
        free(all);
        *v = m;
    }
    const long step = s->steps - 1;
    char where[160], more[64] = "";
    if (v->packed_cells) {
        cell_where(s, v->packed_cell, where, sizeof where);
        if (v->packed_cells > 1)
            snprintf(more, sizeof more, " (and %lld more cells)", (long long)v->packed_cells - 1);
        bool grav = false;
        for (int k = 0; k < s->D; k++)
            grav = grav || s->def.gravity[k] != 0;
        const double e = s->def.restitution, hd = s->h[0] / (2 * s->def.radius);
        char cause[160];
        const char *advice = "use a restitution nearer 1, a stronger drive or fewer particles";
        if (e < 1)
            snprintf(cause, sizeof cause, "inelastic collapse (restitution %g)%s", e,
                     grav ? " under gravity" : "");
        else if (grav)
            snprintf(cause, sizeof cause, "gravity packing a bed its walls do not keep fluid");
        else {
            snprintf(cause, sizeof cause, "particles placed or moved there (an elastic gas "
                                          "does not cluster)");
            advice = "spread the particles over a larger region";
        }
        return core_fail(err, CORE_ERR_UNSTABLE,
                         "step %ld (t = %.6g s): the cell at %s holds %lld particles, a "
                         "packing fraction of %.3g where at most %.0f fit at the packing limit "
                         "%g: a state past close packing%s (DSMC keeps no distance between "
                         "particles). Likely cause: %s, in cells (%.3g diameters) wider than a "
                         "cluster's mean free path; %s",
                         step, s->t, where, (long long)v->packed_n,
                         (double)v->packed_n * s->vpart / s->cell_volume, fit_per_cell(s),
                         s->def.packing_limit, more, cause, hd, advice);
    }
    if (v->capped_cells) {
        cell_where(s, v->capped_cell, where, sizeof where);
        if (v->capped_cells > 1)
            snprintf(more, sizeof more, " (and %lld more cells)", (long long)v->capped_cells - 1);
        return core_fail(err, CORE_ERR_UNSTABLE,
                         "step %ld (t = %.6g s): the cell at %s holds %lld particles and needs "
                         "%.3g candidate pairs in one step, over the limit of %d per particle%s: "
                         "dt = %g s is far above the collision time there, and those cells' "
                         "collisions were not done; use a smaller dt (dt = 'auto' is a tenth "
                         "of the mean collision time)",
                         step, s->t, where, (long long)v->capped_n, v->capped_m,
                         DSMC_CANDIDATES_PER_PARTICLE, more, dt);
    }
    if (v->stranded > 1)
        snprintf(more, sizeof more, " (and %lld more)", (long long)v->stranded - 1);
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "step %ld (t = %.6g s): particle %lld%s crossed the walls of the box more "
                     "than 4 times in one step of dt = %g s and was put on a wall: dt is far "
                     "above the flight time across the box; use a smaller dt",
                     step, s->t, (long long)v->strand_id, more, dt);
}

core_status dsmc_run(dsmc_scene *s, const dsmc_run_def *run, long *done, core_error *err)
{
    *done = 0;
    if (!(run->dt > 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be positive, got %g", run->dt);
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    /* several ranks: every decision below (stop, rebalance) is taken by all of them together */
    const bool multi = comm_size() > 1;
    core_status st = CORE_OK;
    if (multi && (st = dsmc_domain_split(s, err)))
        return st;
    double c0 = clock_cpu(), w0 = clock_wall();
    comm_stats cs0;
    comm_get_stats(&cs0);
    /* this rank's counts for the run, added to the statistics at the end (summed over ranks) */
    int64_t cnt[6] = {0, 0, 0, 0, 0, 0}; /* moves, wall hits, attempts, collisions, raised, over */
    long nsteps = 0;
    double tsum = 0;
    bool sorted = true;
    int64_t lost = 0;     /* particles this rank could not store at the last migration */
    int64_t overflow = 0; /* cells of the last step whose collision count overflowed */
    dsmc_verdict verdict; /* this rank's verdict on the last step */
    verdict_clear(&verdict);
    double last_dt = run->dt;
    /* A step gives the same bits on any thread count: the tuner may choose it (core/threads.h)
     * when the step runs threaded. */
    threads_tune_begin(s, s->n >= DSMC_PARALLEL_MIN);
    while (*done < run->steps) {
        if (run->time_end >= 0 && s->t >= run->time_end * (1 - 1e-14))
            break;
        int intr = interrupt_pending();
        if (multi) {
            int64_t q[5] = {intr, (int64_t)s->n, lost, overflow, verdict_any(&verdict)};
            comm_max_i64(q, 5);
            intr = q[0] != 0;
            if (q[3]) {
                st = overflow_error(s, run->dt, err);
                break;
            }
            if (q[4]) {
                st = verdict_error(s, &verdict, true, last_dt, err);
                verdict_clear(&verdict);
                break;
            }
            if (q[2]) {
                st = core_fail(err, CORE_ERR_NOMEM,
                               "step %ld: out of memory on a rank storing %lld particles that "
                               "migrated to it; the scene is incomplete",
                               s->steps - 1, (long long)q[2]);
                sorted = false;
                break;
            }
            if (!intr && (st = dsmc_domain_balance(s, q[1], err))) {
                sorted = false; /* out of memory, maybe in the middle of a migration */
                break;
            }
        }
        if (intr) {
            st = core_fail(err, CORE_ERR_INTERRUPTED,
                           "interrupted at step %ld (t = %.6g s); the scene is intact", s->steps,
                           s->t);
            break;
        }
        double dt = run->dt;
        if (run->time_end >= 0 && s->t + dt > run->time_end)
            dt = run->time_end - s->t;
        size_t bcount[DSMC_SORT_BLOCKS];
        flight_totals ft = flight(s, dt, bcount);
        sorted = false;
        int bad = ft.bad;
        /* one synchronisation between flight and collisions: the migration, with the verdict */
        if (multi && (st = dsmc_domain_migrate(s, bcount, &bad, &lost, err)))
            break;
        if (bad) {
            char cause[300];
            out_of_range(s, dt, cause, sizeof cause);
            st = core_fail(err, CORE_ERR_UNSTABLE,
                           "step %ld (t = %.6g s): a particle's position or velocity is not "
                           "finite; likely cause: %s",
                           s->steps, s->t, cause);
            break;
        }
        dsmc_sort_counted(s, bcount);
        sorted = true;
        collide_totals ct = collide(s, dt, &verdict);
        verdict.stranded = ft.stranded;
        verdict.strand_id = ft.strand_id == LONG_MAX ? INT64_MAX : ft.strand_id;
        last_dt = dt;
        s->t += dt;
        s->steps++;
        ++*done;
        overflow = ct.overflow; /* several ranks: agreed at the next reduction */
        if (!multi && overflow) {
            st = overflow_error(s, run->dt, err);
            break;
        }
        nsteps++;
        tsum += dt;
        cnt[0] += (int64_t)s->n;
        cnt[1] += ft.wall_hits;
        cnt[2] += ct.attempts;
        cnt[3] += ct.collisions;
        cnt[4] += ct.raised;
        cnt[5] += ct.overpacked;
        threads_tune_step();
        if (!multi && verdict_any(&verdict)) { /* several ranks: at the next reduction */
            st = verdict_error(s, &verdict, false, dt, err);
            break;
        }
    }
    threads_tune_end();
    /* between runs the arrays are in cell then identity order, for everything that reads them
     * (unless a step stopped between its flight and its sort: non-finite, or out of memory) */
    if (sorted)
        dsmc_order_cells(s);
    double cpu = clock_cpu() - c0, wall = clock_wall() - w0;
    comm_stats cs1;
    comm_get_stats(&cs1);
    /* summed: CPU of all ranks, bytes and messages they sent; the slowest: wall time, time in
     * communication, particles held (the imbalance) */
    double sum[3] = {cpu, cs1.bytes - cs0.bytes, cs1.messages - cs0.messages};
    double most[6] = {wall, cs1.seconds - cs0.seconds, (double)s->n, (double)lost,
                      (double)overflow, (double)(multi && verdict_any(&verdict))};
    if (s->distributed) {
        comm_sum_i64(cnt, 6);
        comm_sum_double(sum, 3);
        comm_max_double(most, 6);
    }
    if (s->distributed && st == CORE_OK && most[4] > 0) /* at the last step */
        st = overflow_error(s, run->dt, err);
    if (s->distributed && st == CORE_OK && most[5] > 0)
        st = verdict_error(s, &verdict, true, last_dt, err);
    if (most[3] > 0 && st == CORE_OK)
        st = core_fail(err, CORE_ERR_NOMEM,
                       "out of memory on a rank storing %.0f particles that migrated to it; "
                       "the scene is incomplete",
                       most[3]);
    cpu = sum[0];
    wall = most[0];
    s->stats.comm_bytes += sum[1];
    s->stats.comm_messages += sum[2];
    s->stats.comm_s += most[1];
    s->stats.imbalance = dsmc_count(s) ? most[2] * comm_size() / (double)dsmc_count(s) : 1;
    s->stats.steps += nsteps;
    s->stats.particle_moves += (double)cnt[0];
    s->stats.wall_hits += (double)cnt[1];
    s->stats.attempts += (double)cnt[2];
    s->stats.collisions += (double)cnt[3];
    s->stats.vmax_raised += (double)cnt[4];
    s->stats.cells_overpacked += (double)cnt[5];
    s->stats.time += tsum;
    s->total_collisions += (double)cnt[3];
    s->stats.cpu_s += cpu;
    s->stats.wall_s += wall;
    return st;
}

void dsmc_get_stats(const dsmc_scene *s, dsmc_stats *out) { *out = s->stats; }
void dsmc_reset_stats(dsmc_scene *s) { memset(&s->stats, 0, sizeof s->stats); }
