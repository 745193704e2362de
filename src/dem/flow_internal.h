/* Inserters and outflows (flow.c), shared with their checkpoint section (flow_checkpoint.c). */
#ifndef GRAINLAB_DEM_FLOW_INTERNAL_H
#define GRAINLAB_DEM_FLOW_INTERNAL_H

#include "core/rng.h"
#include "dem/dem_internal.h"

typedef struct inserter {
    dem_inserter_def def; /* radii and weights point at the copies below */
    double *radii, *cum;  /* DISCRETE: radii and cumulative weights (last = 1) */
    rng rng;
    double t0;      /* the scene's time when it was added (the rate counts from it) */
    long next_step; /* the step of its next event */
    dem_flow_counts c;
    int done; /* count or mass reached */
} inserter;

typedef struct outflow {
    dem_outflow_def def;
    dem_flow_counts c;
} outflow;

struct dem_flow {
    inserter *ins;
    int nins, cap_ins;
    outflow *out;
    int nout, cap_out;
    double next_tag; /* the tag of the next particle */
    uint32_t *near;  /* scratch: particles near an inserter's region */
    size_t cap_near;
    unsigned char *gone; /* scratch: particles to remove */
    size_t cap_gone;
};

/* The flow state on first use, with tags for the particles there are. */
core_status dem_flow_on(dem_scene *s, core_error *err);
/* The smallest and largest radius an inserter can make. */
double dem_inserter_rmin(const dem_inserter_def *d);
double dem_inserter_rmax(const dem_inserter_def *d);
/* The region's bounding box, which must lie in the domain. */
core_status dem_inserter_region(const dem_scene *s, const dem_inserter_def *d, double lo[3],
                                double hi[3], core_error *err);

#endif
