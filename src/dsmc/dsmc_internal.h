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

    /* Per particle: position, velocity, cell index. Nothing else. */
    size_t n, cap;
    double *x[3], *v[3];
    uint32_t *cell;

    /* Per cell: the fractional candidate remainder carried between steps (Eq. 1), and the
     * transient start offsets of the sorted particles (ncells + 1) and insertion cursors. */
    double *remainder;
    size_t *start, *next;

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

/* Sorts the particles in place by cell index and fills start[] (ncells + 1 offsets). */
void dsmc_sort(dsmc_scene *s);
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
