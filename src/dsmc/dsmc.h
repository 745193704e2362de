/* grainlab DSMC: granular gases by Direct Simulation Monte Carlo in 2D and 3D (Herrmann & Mueller,
 * granular-simulation-scales.txt Sec. 4, after Bird). Each step: free flight under gravity with
 * walls and periodic axes, an in-place counting sort of the particles into cells, then in every
 * cell M_c = N_c (N_c - 1) sigma v_max tau / (2 V_c) candidate pairs (Eq. 1), each accepted with
 * probability |v_i - v_j| / v_max and collided with a random impact parameter and restitution e.
 *
 * Per particle the scene stores its position, its velocity, its cell index and a 4-byte identity
 * (the order of addition; it orders each cell, see dsmc_internal.h), nothing more (the paper's
 * "low memory demand": 40 bytes in 2D, 56 in 3D); everything else is per cell.
 *
 * Usage: fill a dsmc_scene_def from dsmc_default_scene_def(), create the scene, add particles
 * (dsmc_fill or dsmc_add), set walls, then dsmc_run. Every call that can fail returns a
 * core_status and explains itself in a core_error. Nothing here knows about Lua. */
#ifndef GRAINLAB_DSMC_H
#define GRAINLAB_DSMC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

typedef struct dsmc_scene dsmc_scene;

/* ---- scene ----------------------------------------------------------------------------------- */
typedef enum dsmc_excluded {
    DSMC_EXCLUDED_NONE,        /* point particles with a cross-section: chi = 1 */
    DSMC_EXCLUDED_FREE_VOLUME, /* the paper's V_c -> V_c - V_b / nu_rcp per cell (default);
                                * equivalent to chi = 1 / (1 - nu / nu_rcp) */
    DSMC_EXCLUDED_ENSKOG       /* Eq. 1 times the Enskog chi(nu) of the cell: Henderson
                                * (1 - 7 nu / 16) / (1 - nu)^2 in 2D, Carnahan-Starling
                                * (1 - nu / 2) / (1 - nu)^3 in 3D */
} dsmc_excluded;

typedef struct dsmc_scene_def {
    int dim;               /* 2 (disks moving in a plane) or 3 (spheres) */
    double lo[3], hi[3];   /* the box, m */
    int cells[3];          /* cells per axis (>= 1); cell sides must be at least a diameter */
    bool periodic[3];      /* a periodic axis wraps particles and has no walls */
    double gravity[3];     /* m/s^2 */
    double restitution;    /* e in [0, 1] for particle collisions */
    double radius;         /* R > 0, m: sigma_2D = 4R, sigma_3D = 4 pi R^2 (Eq. 1) */
    double mass;           /* kg > 0; 0: from density (sphere 4/3 pi R^3 rho, also in 2D) */
    double density;        /* kg/m^3, used when mass = 0 */
    dsmc_excluded excluded;
    double packing_limit;  /* nu_rcp; 0: 0.82 in 2D, 0.64 in 3D */
    uint64_t seed;         /* collisions and diffuse walls; results do not depend on threads */
} dsmc_scene_def;

dsmc_scene_def dsmc_default_scene_def(void); /* 2D unit box, 10 x 10 cells, periodic, e = 1,
                                              * R = 1 mm, rho = 2650, free volume */
core_status dsmc_create(const dsmc_scene_def *def, dsmc_scene **out, core_error *err);
void dsmc_destroy(dsmc_scene *s);
const dsmc_scene_def *dsmc_def(const dsmc_scene *s);
double dsmc_mass(const dsmc_scene *s);
double dsmc_cross_section(const dsmc_scene *s);  /* sigma of Eq. 1: 4R (2D), 4 pi R^2 (3D) */
double dsmc_particle_volume(const dsmc_scene *s); /* pi R^2 (2D), 4/3 pi R^3 (3D) */
double dsmc_volume(const dsmc_scene *s);          /* box area (2D) or volume (3D) */
size_t dsmc_cell_count(const dsmc_scene *s);
void dsmc_cell_size(const dsmc_scene *s, double h[3]);
/* Bytes allocated for the particle arrays (position, velocity, cell index, identity) on this
 * rank and for the per-cell arrays (carried remainder, sort offsets). */
void dsmc_memory(const dsmc_scene *s, size_t *particle_bytes, size_t *cell_bytes);
/* Largest number of particles the box holds at the packing limit: nu_rcp V / V_particle. */
size_t dsmc_capacity(const dsmc_scene *s);
/* The chi that Eq. 1 applies at packing fraction nu for the scene's excluded-volume model. */
double dsmc_chi(const dsmc_scene *s, double nu);

/* ---- particles ------------------------------------------------------------------------------- */
typedef struct dsmc_fill_def {
    size_t n;                 /* particles to add */
    double lo[3], hi[3];      /* region (inside the box); lo == hi on every axis: the whole box */
    double temperature;       /* > 0: Maxwellian with T / m = <|v - u|^2> / d (T in J) */
    double speed;             /* > 0 (and temperature 0): all speeds equal, random directions */
    double velocity[3];       /* drift u added to every particle */
    uint64_t seed;
} dsmc_fill_def;

dsmc_fill_def dsmc_default_fill_def(void);
/* Adds n particles at uniform random positions in the region. Refuses more particles than fit
 * at the packing limit. */
core_status dsmc_fill(dsmc_scene *s, const dsmc_fill_def *f, core_error *err);
/* Adds n particles from arrays (z, vz ignored in 2D; z may be NULL then). */
core_status dsmc_add(dsmc_scene *s, size_t n, const double *x, const double *y, const double *z,
                     const double *vx, const double *vy, const double *vz, core_error *err);
size_t dsmc_count(const dsmc_scene *s); /* all particles, on every rank */

typedef struct dsmc_particles {
    const double *x[3], *v[3]; /* x[2], v[2] NULL in 2D */
    const uint32_t *cell;      /* cell index after the last sort */
    const uint32_t *id;        /* identity: the order of addition, from 0 */
} dsmc_particles;
void dsmc_get_particles(const dsmc_scene *s, dsmc_particles *p);

/* ---- walls ----------------------------------------------------------------------------------
 * Sides are numbered 2 axis + (0 low, 1 high): DSMC_XLO, DSMC_XHI, DSMC_YLO, ... A side of an
 * axis that is not periodic is a wall; each is specular with restitution 1 unless set. */
enum { DSMC_XLO, DSMC_XHI, DSMC_YLO, DSMC_YHI, DSMC_ZLO, DSMC_ZHI };

typedef enum dsmc_wall_kind {
    DSMC_WALL_SPECULAR, /* v_n -> u_n - e_w (v_n - u_n) in the wall frame, tangential kept */
    DSMC_WALL_DIFFUSE   /* re-emitted from the flux Maxwellian at the wall temperature, plus u */
} dsmc_wall_kind;

typedef struct dsmc_wall_def {
    dsmc_wall_kind kind;
    double restitution;  /* e_w in [0, 1] (specular) */
    double temperature;  /* J (diffuse, > 0) */
    /* Prescribed motion along the normal: the wall sits at side + A (1 + sin(2 pi f t + phase))
     * inward of its side (low side: lo + ..., high side: hi - ...), so it stays inside the box,
     * and moves with velocity A 2 pi f cos(2 pi f t + phase). A = 0: fixed. */
    double amplitude, frequency, phase;
    double velocity[3];  /* constant wall velocity; only its tangential components count */
} dsmc_wall_def;

dsmc_wall_def dsmc_default_wall_def(void); /* specular, e_w = 1, fixed */
core_status dsmc_set_wall(dsmc_scene *s, int side, const dsmc_wall_def *w, core_error *err);
const dsmc_wall_def *dsmc_wall(const dsmc_scene *s, int side);
/* Where the wall of `side` is at time t and its normal velocity (along +axis). */
void dsmc_wall_motion(const dsmc_scene *s, int side, double t, double *pos, double *vel);

/* ---- distributed runs (dsmc/domain.c) -------------------------------------------------------
 * Under mpirun every rank builds the same scene; dsmc_run on more than one rank then keeps on
 * each rank only the particles of its cells (contiguous ranges of the cell index, balanced by
 * particle count) and migrates them between ranks as they move. The results are the same bits
 * on any number of ranks. dsmc_run, dsmc_gather, dsmc_measure_moments, dsmc_check_validity and
 * dsmc_collision_frequency are collective then (every rank calls them, in the same order);
 * everything else that reads particles (dsmc_get_particles, the fields, profiles and histograms,
 * VTK, checkpoints) needs the whole scene: call dsmc_gather first, which puts it back on every
 * rank (a no-op when it is there already). */
core_status dsmc_gather(dsmc_scene *s, core_error *err);
bool dsmc_is_distributed(const dsmc_scene *s);
/* The ranks the scene's runs are spread over (comm_size(); 1 without mpirun). */
int dsmc_ranks(const dsmc_scene *s);

/* ---- running --------------------------------------------------------------------------------- */
/* The paper's validity conditions for a step tau, with the particle-weighted mean density
 * n_w = sum N_c (N_c - 1) / sum (N_c V_c) (the density of partners the average particle sees;
 * unbiased by the cells' Poisson noise, which N_c^2 would add as 1/V_c) and the temperature:
 * (i) collisional regime: the mean free path below the box's smallest side (Knudsen number < 1);
 * (ii) the mean free path larger than the largest cell side; (iii) the mean collision time 1/omega
 * larger than tau. lambda = 1 / (2 sqrt2 n sigma_d chi) (2D), 1 / (sqrt2 pi n sigma_d^2 chi) (3D),
 * omega = 2 sqrt(pi) chi n sigma_d sqrt(T/m) (2D), 4 sqrt(pi) chi n sigma_d^2 sqrt(T/m) (3D). */
typedef struct dsmc_validity {
    double density;         /* n_w, 1/m^d */
    double packing;         /* nu at n_w */
    double chi;
    double mean_free_path;  /* m */
    double knudsen;         /* mean_free_path / smallest box side */
    double cell_size;       /* largest cell side, m */
    double collision_time;  /* 1 / omega, s */
    double dt;
    bool collisional, cells_ok, dt_ok;
} dsmc_validity;

core_status dsmc_check_validity(const dsmc_scene *s, double dt, dsmc_validity *out,
                                core_error *err);

typedef struct dsmc_run_def {
    long steps;      /* at most this many steps (>= 0) */
    double dt;       /* > 0 */
    double time_end; /* < 0: none; else stop when the scene time reaches it (the last step is
                      * shortened to land on it) */
} dsmc_run_def;

dsmc_run_def dsmc_default_run_def(void);
/* Advances the scene; *done = steps taken. Stops between steps on Ctrl-C
 * (CORE_ERR_INTERRUPTED, scene intact) and on non-finite velocities (CORE_ERR_UNSTABLE). */
core_status dsmc_run(dsmc_scene *s, const dsmc_run_def *run, long *done, core_error *err);
double dsmc_time(const dsmc_scene *s);
long dsmc_steps_done(const dsmc_scene *s);

/* ---- statistics (SPARTA's vocabulary) -------------------------------------------------------- */
typedef struct dsmc_stats {
    long steps;
    double particle_moves;   /* sum over steps of the particle count */
    double attempts;         /* candidate pairs (Eq. 1) */
    double collisions;       /* accepted pairs */
    double wall_hits;
    double vmax_raised;      /* candidates whose |g| exceeded the cell's v_max */
    double cells_overpacked; /* cell-steps whose free volume fell below 1% of the cell */
    double time;             /* simulated, s */
    double cpu_s, wall_s;    /* spent in dsmc_run: CPU of all ranks, wall of the slowest */
    /* A distributed run's traffic (core/comm.h counters, during dsmc_run): bytes and messages
     * sent, summed over ranks, and the wall time inside communication of the slowest rank. */
    double comm_bytes, comm_messages, comm_s;
    double imbalance; /* particles on the busiest rank over the mean, at the end of the last run */
} dsmc_stats;

/* Counters since the last dsmc_reset_stats (or creation). */
void dsmc_get_stats(const dsmc_scene *s, dsmc_stats *out);
void dsmc_reset_stats(dsmc_scene *s);
/* Accepted collisions since creation (for the collision-count form c = 2 N_coll / N). */
double dsmc_total_collisions(const dsmc_scene *s);

/* ---- measurements ---------------------------------------------------------------------------- */
typedef struct dsmc_moments {
    size_t n;
    double mean_velocity[3];
    double temperature;     /* m <|v - u|^2> / d, J */
    double t_over_m;        /* <|v - u|^2> / d, m^2/s^2 */
    double kinetic_energy;  /* sum m |v|^2 / 2, J */
    double momentum[3];     /* sum m v */
    double kurtosis;        /* <|v - u|^4> / <|v - u|^2>^2: (d + 2) / d for Maxwell-Boltzmann */
    double a2;              /* second Sonine coefficient d/(d+2) kurtosis - 1 */
} dsmc_moments;

void dsmc_measure_moments(const dsmc_scene *s, dsmc_moments *out);

/* Kinetic-theory collision frequency per particle for the scene's current state:
 * omega = 2 sqrt(pi) chi n sigma_d sqrt(T/m) (2D), 4 sqrt(pi) chi n sigma_d^2 sqrt(T/m) (3D), with
 * n = (N - 1) / V (the partners a particle has) and chi = dsmc_chi at the mean packing. */
double dsmc_collision_frequency(const dsmc_scene *s);

/* Per-cell fields, arrays of dsmc_cell_count entries indexed (k ny + j) nx + i: count,
 * number density (1/m^d), packing fraction, mean velocity (d arrays), temperature (J; unbiased:
 * m sum |v - u_c|^2 / (d (N_c - 1)), NaN below 2 particles) and a2 (NaN below 2 particles). The
 * caller provides the arrays (u[2] may be NULL in 2D); any may be NULL. */
typedef struct dsmc_fields {
    double *count, *density, *packing, *u[3], *temperature, *a2;
} dsmc_fields;
void dsmc_measure_fields(const dsmc_scene *s, const dsmc_fields *f);

/* Layers along `axis` (nbins equal slices of the box): particles per layer, number density,
 * packing, temperature about the layer's mean velocity (J, NaN below 2 particles). */
core_status dsmc_measure_profile(const dsmc_scene *s, int axis, int nbins, double *center,
                                 double *count, double *density, double *packing,
                                 double *temperature, core_error *err);

/* Histogram of `what` over nbins equal bins of [lo, hi]: 0 = each velocity component about the
 * mean (d samples per particle), 1 = speed |v - u|. Samples outside are counted in *outside. */
core_status dsmc_measure_histogram(const dsmc_scene *s, int what, int nbins, double lo,
                                   double hi, double *counts, double *outside, core_error *err);

/* ---- checkpoints (src/dsmc/checkpoint.c) ---------------------------------------------------
 * dsmc_save writes everything a bit-exact continuation needs into a grainlab checkpoint at path
 * (core/checkpoint.h: written whole through a temporary file and a rename); version is the
 * grainlab version recorded in its header. dsmc_load reads one into a new scene (*out), refusing
 * a missing, truncated, corrupt, foreign (another engine's) or newer file with nothing allocated
 * left behind. Running the loaded scene gives the same bits as continuing the saved one, with any
 * number of threads. */
core_status dsmc_save(const dsmc_scene *s, const char *path, const char *version, core_error *err);
core_status dsmc_load(const char *path, dsmc_scene **out, core_error *err);

/* ---- output for other tools (dsmc/vtk.c) ----------------------------------------------------- */
/* VTK XML for ParaView, written whole. Particles (.vtu): one vertex per particle with point data
 * id (the position in the current order, 1-based: particles are re-sorted by cell every step and
 * carry no identity), radius, velocity (3-vector, z = 0 in 2D), mass, cell (1-based). Cells
 * (.vti image over the box): cell data count, density, packing, velocity, temperature, a2, as
 * dsmc_measure_fields. */
core_status dsmc_vtk_particles(const dsmc_scene *s, const char *path, core_error *err);
core_status dsmc_vtk_cells(const dsmc_scene *s, const char *path, core_error *err);

#endif
