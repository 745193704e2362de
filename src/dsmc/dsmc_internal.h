/* The DSMC scene's layout, shared by the files of src/dsmc/ only. */
#ifndef GRAINLAB_DSMC_INTERNAL_H
#define GRAINLAB_DSMC_INTERNAL_H

#include "core/rng.h"
#include "dsmc/dsmc.h"

#define DSMC_PI 3.14159265358979323846

struct dsmc_scene {
    dsmc_scene_def def;
    int D;
    double mass, sigma, vpart; /* particle mass, cross-section of Eq. 1, particle volume */
    double h[3], inv_h[3];     /* cell sides and their inverses */
    double cell_volume;
    size_t ncells;

    /* Per particle: position, velocity, cell index and identity (the order of addition). The
     * identity gives the particles of a cell an order that does not depend on where they sit in
     * the arrays (between steps every cell is sorted by it; its random pair choices index that
     * order) and keys a wall hit's stream: so the result is the same whatever the array layout,
     * thread count or decomposition over ranks. */
    size_t n, cap;
    double *x[3], *v[3];
    uint32_t *cell, *id;
    uint64_t next_id; /* the identity of the next particle added */

    /* Per cell: the fractional candidate remainder carried between steps (Eq. 1), and the
     * transient start offsets of the sorted particles (ncells + 1) and insertion cursors. */
    double *remainder;
    size_t *start, *next;

    /* Blocks of 2^blk_shift consecutive cells (nblk of them): the unit in which the grid is
     * cut between ranks and in which sums over particles are taken (per block in cell order,
     * then blocks in order), so a sum has the same bits on any number of ranks. */
    int blk_shift;
    size_t nblk;

    /* A distributed run (domain.c): this rank holds only the particles of blocks
     * [blk_lo, blk_hi) (its cells [cell_lo, cell_hi)); n_global particles in all. The remainders
     * of other ranks' cells are stale here until dsmc_gather. Not distributed: the whole scene,
     * replicated on every rank, cell range the whole grid. */
    bool distributed;
    size_t blk_lo, blk_hi, cell_lo, cell_hi, n_global;
    size_t *cuts;           /* comm_size() + 1 block offsets: rank r owns [cuts[r], cuts[r + 1]) */
    long last_balance;      /* step of the last cut */
    double balance_best;    /* the imbalance (max / mean particles) that cut reached */

    dsmc_wall_def walls[6];
    double t;
    long steps;
    dsmc_stats stats;
    double total_collisions;
};

/* A per-(purpose, step, index) random stream: the state is seeded by splitmix64 from a hash of
 * the scene seed and the three numbers, so every cell and every wall hit draws the same numbers
 * whatever the thread that handles it. */
void dsmc_stream(rng *r, uint64_t seed, uint64_t purpose, uint64_t step, uint64_t index);

/* Sorts the particles in place by cell index, each cell by identity, and fills start[]
 * (ncells + 1 offsets). */
void dsmc_sort(dsmc_scene *s);
/* The sort of a step: by cell only (the particles per sort range already counted, over
 * dsmc_sort_shift ranges; NULL: counted here); within a cell the order is the layout's. */
void dsmc_sort_counted(dsmc_scene *s, const size_t *bcount);
/* Puts every cell of this rank in identity order (after dsmc_sort_counted). */
void dsmc_order_cells(dsmc_scene *s);
#define DSMC_SORT_BLOCKS 64
int dsmc_sort_shift(size_t ncells);

/* The identity order of a cell's N particles (sort.c): P[k] = the slot (from the cell's first) of
 * the k-th smallest identity. key: N scratch entries (cells of more than 32 only). */
void dsmc_cell_perm_big(const uint32_t *id, size_t N, uint64_t *key, uint32_t *P);
static inline void dsmc_cell_perm(const uint32_t *id, size_t N, uint64_t *key, uint32_t *P)
{
    if (N > 4) {
        dsmc_cell_perm_big(id, N, key, P);
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
/* Puts the particles [a, a + N) of one cell in identity order (sort.c). */
void dsmc_order_cell(dsmc_scene *s, size_t a, size_t N);

/* ---- the stages of a step: flight.c, sort.c, collide.c, driven by dsmc_run (step.c) ---- */
/* Below this many particles a step is a few hundred microseconds and threads cost more than they
 * bring (barriers; on a loaded machine, a descheduled thread stalls every step). */
#define DSMC_PARALLEL_MIN 50000
/* The purposes of dsmc_stream: a cell's collisions, a wall hit. */
enum { DSMC_STREAM_COLLIDE = 1, DSMC_STREAM_WALL = 2 };

typedef struct dsmc_flight_totals {
    long wall_hits;
    int bad;
    long stranded;  /* particles still beyond a wall after the bounce budget (put on it) */
    long strand_id; /* the smallest identity among them (LONG_MAX: none) */
} dsmc_flight_totals;
/* Moves every particle by dt (gravity, walls), finds its cell and counts the particles per sort
 * range (bcount) (flight.c). */
dsmc_flight_totals dsmc_flight(dsmc_scene *s, double dt, size_t bcount[DSMC_SORT_BLOCKS]);

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
/* No culprit; and a's culprits joined with b's (collide.c). */
void dsmc_verdict_clear(dsmc_verdict *v);
void dsmc_verdict_merge(dsmc_verdict *a, const dsmc_verdict *b);

typedef struct dsmc_collide_totals {
    long attempts, collisions, raised, overpacked;
    long overflow; /* cells whose number of candidates was not a number (speeds overflowed) */
} dsmc_collide_totals;
/* The collisions of Eq. 1 in every cell of this rank, after the sort; cells past close packing
 * or over the candidate cap go to *verdict (collide.c). */
dsmc_collide_totals dsmc_collide(dsmc_scene *s, double dt, dsmc_verdict *verdict);
/* The most particles whose centres can lie in one cell at the packing limit (collide.c). */
double dsmc_fit_per_cell(const dsmc_scene *s);

/* Grows the particle arrays to hold n (scene.c); dsmc_resize sets their capacity to cap >= n
 * (returns 0, or -1 when out of memory, the arrays as they were). */
core_status dsmc_reserve(dsmc_scene *s, size_t n, core_error *err);
int dsmc_resize(dsmc_scene *s, size_t cap);

/* ---- domain.c: the distributed run ----
 * Every call is collective when comm_size() > 1 and does nothing on one rank unless said. */
/* Cuts the replicated scene by blocks of cells, balanced by particle count; keeps this rank's. */
core_status dsmc_domain_split(dsmc_scene *s, core_error *err);
/* After a flight: particles whose cell another rank owns go there (bcount, the particles per
 * sort range, follows the leavers and the arrivals). *bad: in, this rank's flight met a
 * non-finite particle; out, some rank's did (agreed on the way; also when not distributed).
 * *lost: particles this rank received and could not store (out of memory): the caller agrees
 * on it at its next reduction. */
core_status dsmc_domain_migrate(dsmc_scene *s, size_t *bcount, int *bad, int64_t *lost,
                                core_error *err);
/* Between steps: cuts again when the particles per rank drifted apart (nmax: the largest count). */
core_status dsmc_domain_balance(dsmc_scene *s, int64_t nmax, core_error *err);
/* Sum over blocks of per-block values (nper values each, blocks [blk_lo, blk_hi) given here, in
 * order) into out[nper]: in block order, so the same bits on any number of ranks. */
core_status dsmc_block_sum(const dsmc_scene *s, const double *local, size_t nper, double *out,
                           core_error *err);
/* Cell index of a position (clamped to the grid). */
static inline uint32_t dsmc_cell_of(const dsmc_scene *s, double x, double y, double z)
{
    const double p[3] = {x, y, z};
    size_t idx = 0;
    for (int k = s->D - 1; k >= 0; k--) {
        double f = (p[k] - s->def.lo[k]) * s->inv_h[k];
        int i = f < 0 ? 0 : f >= s->def.cells[k] ? s->def.cells[k] - 1 : (int)f;
        idx = idx * (size_t)s->def.cells[k] + (size_t)i;
    }
    return (uint32_t)idx;
}

#endif
