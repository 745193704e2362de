/* The DEM scene's layout, shared by the files of src/dem/ only. Particle data is structure-of-
 * arrays; arrays a scene does not need (rotations without a tangential law, contact history
 * without the spring law, integrator state for other integrators) stay NULL. */
#ifndef GRAINLAB_DEM_INTERNAL_H
#define GRAINLAB_DEM_INTERNAL_H

#include <stdint.h>

#include "dem/dem.h"
#include "dem/power.h"

#define DEM_PI 3.14159265358979323846

typedef struct dem_wall {
    int active;
    double point[3], normal[3], velocity[3];
    double friction;
    int material;
    double *hist[4];       /* SPRING law, per particle: see dem_pairs.hist */
    uint32_t *cand;        /* particles within r + skin of the wall at the last list build */
    size_t ncand, cap_cand;
    double point_build[3]; /* the wall's point at the last list build (skin test) */
    double fn;             /* normal force the wall exerts on the particles, last evaluation */
    int servo;             /* force-controlled: the wall is a damped body pushed with servo_force */
    double servo_force, servo_mass, servo_rate;
} dem_wall;

/* The Verlet list: pairs (i < j) closer than r_i + r_j + skin at the last build, sorted by i then
 * j, with per-pair law parameters, the contact history, and the force of the last evaluation. */
typedef struct dem_pairs {
    size_t n, cap;
    uint32_t *i, *j;
    double *k;        /* normal stiffness (k or K) of the pair */
    double *gamma;    /* viscous normal damping of the pair, N s/m */
    double *mu;       /* friction of the pair */
    double *hist[4];  /* SPRING law: the tangential force on i ([0..2]; 2D: [0] along t) and
                       * [3] the spring stiffness of the last step (for the unloading rescale) */
    double *f[3];     /* force on i of the last evaluation (j gets the opposite) */
    double *c[3];     /* n x f_t: torque on i is -r_i c, on j -r_j c (2D: c[2] only) */
    size_t np;        /* particles when the list was built */
    size_t *start;    /* pairs of particle i: [start[i], start[i+1]) (np + 1) */
    size_t *jstart;   /* pairs where particle i is j: jpair[jstart[i] .. jstart[i+1]) */
    uint32_t *jpair;
} dem_pairs;

struct dem_scene {
    int dim;
    double lo[3], hi[3], len[3];
    bool periodic[3];
    double gravity[3];
    double thickness;
    double drag;           /* background drag rate, 1/s */
    double skin_def;       /* as given (0 = automatic) */
    double skin;           /* in use */

    size_t n, cap;
    double *x[3], *v[3], *f[3];
    double *r, *m, *inv_m, *inv_inertia;
    int *mat;
    unsigned char *flags;
    double r_max;

    int rot;               /* rotational state allocated */
    double *w[3], *tq[3];  /* 2D: w[2], tq[2] only */
    double *angle;         /* 2D orientation, integrated from w[2] (allocated with rotations) */

    double *x_build[3];    /* positions at the last list build (skin test) */
    double *fext[3];       /* external forces (NULL until set) */
    double *x_ref[3];      /* reference for displacements (NULL until set) */
    double *x_prev[3];     /* position Verlet: the last step's displacement x(t) - x(t-dt) */
    double *gear[6][3];    /* Gear: scaled derivatives of positions */
    double *gear_w[6][3];  /* Gear: scaled derivatives of rotation angles */
    int gear_ready, prev_ready, forces_ready;
    int suspect;           /* a kick saw a non-finite velocity: run the full checks */
    double gear_dt, prev_dt;

    dem_material *mats;
    int nmat, cap_mat;
    dem_contact_def contact;
    double brill_c;        /* Brilliantov from a restitution: lambda(e) v^{-1/5} (dem.h) */
    dem_power slip_pow;    /* x^(1/exponent) of the regularised Coulomb law */

    dem_wall *walls;
    int nwalls, cap_walls;

    dem_pairs pairs;
    int need_rebuild;
    int ncell[3];
    double cell_size[3];
    size_t *cell_start;
    uint32_t *cell_items;
    size_t cell_cap;

    double time;
    long steps;
    long force_evals;
    int last_integrator;
    long tt_phase;

    struct dem_boundary *bnd; /* boundary conditions (boundary.c); NULL when none */

    /* Energy watch (integrate.c): in a scene without drivers the mechanical energy must not
     * grow; checked every DEM_WATCH_EVERY steps against the lowest energy since the reference,
     * which any change to the scene from outside a step resets (dem_invalidate). */
    int watch_on;
    long watch_next, watch_min_step;
    double watch_min, watch_min_t, watch_scale;
};

/* neighbor.c */
core_status dem_build_pairs(dem_scene *s, core_error *err);
void dem_free_pairs(dem_pairs *p);
void dem_pair_parameters(dem_scene *s, size_t i, size_t j, double *k, double *gamma, double *mu);
void dem_wall_parameters(const dem_scene *s, const dem_wall *w, size_t i, double *k,
                         double *gamma, double *mu);

/* forces.c: the force evaluation, instantiated for 2D and 3D. dem_compute_forces fills f and tq
 * (pairs, walls, gravity) and returns the index of a particle that went through a wall, or
 * (size_t)-1. */
size_t dem_compute_forces(dem_scene *s, double dt);
double dem_normal_force(const dem_contact_def *c, double k, double gamma, double delta,
                        double ddelta);
double dem_elastic_energy(const dem_contact_def *c, double k, double delta);

/* scene.c */
/* The scene changed outside a step: forces, integrator state and (if `list`) the pair list
 * must be recomputed before the next step. */
void dem_invalidate(dem_scene *s, int list);
core_status dem_ensure_rotation(dem_scene *s, core_error *err);
core_status dem_alloc_array(double **a, size_t n, core_error *err);

/* boundary.c: pressure tractions, the minimal-boundary penalty, springs and ties, added after
 * the contact forces; the update of the edges every `every` steps (called by dem_run). */
typedef struct dem_boundary dem_boundary;
core_status dem_boundary_apply(dem_scene *s, double dt, core_error *err);
core_status dem_boundary_due(dem_scene *s, core_error *err);
/* Checkpoints (checkpoint.c): the boundary's section and, for a boundary rebuilt by an update
 * callback, the update's (its kind and ctx; the save refuses an update without a kind). */
struct ckpt_writer;
struct ckpt_section;
core_status dem_boundary_save(const dem_scene *s, struct ckpt_writer *w, core_error *err);
core_status dem_boundary_load(dem_scene *s, struct ckpt_section *sec, core_error *err);
core_status dem_boundary_load_update(dem_scene *s, struct ckpt_section *sec,
                                     const dem_boundary_restorer *restorer, core_error *err);

#endif
