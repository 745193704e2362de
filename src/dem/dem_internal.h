/* The DEM scene's layout, shared by the files of src/dem/ only. Particle data is structure-of-
 * arrays; arrays a scene does not need (rotations without a tangential law, contact history
 * without the spring law, integrator state for other integrators) stay NULL. */
#ifndef GRAINLAB_DEM_INTERNAL_H
#define GRAINLAB_DEM_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "dem/dem.h"
#include "dem/power.h"

#define DEM_PI 3.14159265358979323846

/* Contact history slots (pairs and walls): [0..2] the tangential spring force and [3] its last
 * stiffness (SPRING law), [4..6] the rolling spring torque (rolling EPSD; 2D: [4] only, the z
 * component), [7] 1 while a cohesive contact holds: a JKR contact or a liquid bridge formed at
 * touch that has not yet broken (cohesion.h; pairs and planes). Slots a scene's laws do not use
 * stay NULL. */
#define DEM_HIST 8
#define DEM_HIST_ROLL 4
#define DEM_HIST_BOND 7

typedef struct dem_shape dem_shape; /* walls beyond planes (walls.c) */
enum { DEM_SHAPE_LOAD = 7 };        /* per candidate: force[3], torque[3], f_n */

typedef struct dem_wall {
    int active;
    double point[3], normal[3], velocity[3];
    double friction;
    int material;
    double *hist[DEM_HIST]; /* per particle: see DEM_HIST */
    uint32_t *cand;        /* particles within r + skin of the wall at the last list build */
    double *cand_fn;       /* distributed runs: each candidate's normal force (domain.c) */
    size_t ncand, cap_cand;
    double *cand_par;      /* k, gamma, mu of each candidate (3 per candidate; a plane's cand,
                            * a shaped wall's shape candidates), computed once per candidate list;
                            * cand_par_ok = 0 whenever the list or the laws change (law_parameters
                            * solves the Brilliantov damping time per call: per contact and step
                            * it was 3 % of a pile's step) */
    int cand_par_ok;
    double point_build[3]; /* the wall's point at the last list build (skin test) */
    double fn;             /* normal force the wall exerts on the particles, last evaluation */
    int servo;             /* force-controlled: the wall is a damped body pushed with servo_force */
    double servo_force, servo_mass, servo_rate;
    dem_shape *shape; /* NULL: a plane (point, normal); else its geometry and motion */
} dem_wall;

/* The Verlet list: pairs (i < j) closer than r_i + r_j + skin at the last build, sorted by i then
 * j, with per-pair law parameters, the contact history, and the force of the last evaluation. */
typedef struct dem_pairs {
    size_t n, cap;
    uint32_t *i, *j;
    double *k;        /* normal stiffness (k or K) of the pair */
    double *gamma;    /* viscous normal damping of the pair, N s/m */
    double *mu;       /* friction of the pair */
    double *hist[DEM_HIST]; /* SPRING law: the tangential force on i ([0..2]; 2D: [0] along t)
                             * and [3] the spring stiffness of the last step (for the unloading
                             * rescale); rolling EPSD: [4..6] the rolling spring torque on i;
                             * JKR, capillary: [7] the contact holds (DEM_HIST_BOND) */
    double *rt[3];          /* rolling resistance: the rolling torque on i of the evaluation
                             * (j gets the opposite; 2D: rt[2] only), scratch between the pair
                             * kernel and the gather; NULL without a rolling law */
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
    double reach;          /* how far beyond touch a cohesive contact holds, at most (the pair
                            * list's cutoff adds it; 0 without cohesion) */

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
    double damp_c;         /* viscous from s:contact's restitution: c(e) (restitution.c) */
    double *mat_damp;      /* per material (cap_mat): the coefficient of its restitution when
                            * the law takes the materials' (restitution.c); a pair takes the
                            * larger of its two, the smaller restitution */
    dem_power slip_pow;    /* x^(1/exponent) of the regularised Coulomb law */

    dem_wall *walls;
    int nwalls, cap_walls;
    int nshaped; /* walls beyond planes (walls.c): 0 keeps every step on the planes' path */

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
    struct dem_flow *flow;    /* inserters and outflows (flow.c); NULL when none */
    double *tag;              /* stable particle numbers (flow.c); NULL until flow is used */

    /* Distributed runs (domain.c): NULL on one rank and whenever the scene is replicated. While
     * decomposed, the arrays above hold this rank's owned particles and its ghosts (copies of
     * other ranks' particles within a cutoff + skin of its region), sorted by global id, so
     * that pair lists, force sums and history carry-over follow the one-rank order. */
    struct dem_domain *dom;
    uint32_t *gid;         /* global id (the one-rank index) of each local particle */
    unsigned char *ghost;  /* 1: a copy, integrated here but overwritten by the halo */
    dem_domain_stats dstats; /* kept when the scene is gathered back */

    /* Energy watch (unstable.c): in a scene without drivers the mechanical energy must not
     * grow; checked every DEM_WATCH_EVERY steps against the lowest energy since the reference,
     * which any change to the scene from outside a step resets (dem_invalidate). */
    int watch_on;
    long watch_next, watch_min_step;
    double watch_min, watch_min_t, watch_scale;

    /* Clumps (clump.c): NULL in a scene without them, which then pays nothing for them. */
    struct dem_clumps *clumps;

    /* The run in progress (integrate.c), for the likely cause of an instability (unstable.c). */
    const dem_run_def *run;
};

/* domain.c: the decomposition over MPI ranks (comm.h). dem_domain_start decomposes a replicated
 * scene at the start of a run when there is more than one rank; dem_replicate (dem.h) gathers it
 * back. While decomposed, forces() calls dem_domain_rebuild instead of dem_build_pairs (migration,
 * ghosts, history, then the list) or dem_domain_halo (ghost positions and velocities) first, and
 * every rank agrees on each error with dem_domain_agree. */
typedef struct dem_domain dem_domain;
core_status dem_domain_start(dem_scene *s, core_error *err);
core_status dem_domain_rebuild(dem_scene *s, core_error *err);
void dem_domain_halo(dem_scene *s);
/* Every rank's wall forces summed in global-id order (the one-rank order): now when `now`, else
 * at the next dem_sync_walls or dem_replicate. */
core_status dem_domain_walls_due(dem_scene *s, int now, core_error *err);
/* An error of this rank in a force evaluation, kept (the first one) until the end of the step;
 * dem_domain_deferred returns it (and forgets it). */
void dem_domain_defer(dem_scene *s, core_status st, const core_error *err);
core_status dem_domain_deferred(dem_scene *s, core_error *err);
/* All ranks return the status of the lowest-numbered failing rank, with its message. */
core_status dem_domain_agree(dem_scene *s, core_status st, core_error *err);
/* The same, and *flag becomes the or of every rank's *flag (one reduction for both). */
core_status dem_domain_agree_flag(dem_scene *s, core_status st, int *flag, core_error *err);
void dem_domain_free(dem_scene *s);
size_t dem_domain_count(const dem_scene *s); /* particles on all ranks */
/* History of the pairs of local particle i as first index (sorted by the partner's global id),
 * carried to its new rank by the last rebuild: n entries, partner ids and dem_hist_width(s)
 * values each. */
size_t dem_domain_bundle(const dem_scene *s, size_t i, const uint32_t **gj, const double **h);
/* The global id (1-based in messages: + 1) of local particle i. */
static inline size_t dem_gid(const dem_scene *s, size_t i) { return s->gid ? s->gid[i] : i; }

/* Every one of a[0..n) finite. */
static inline int dem_finite_n(const double *a, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(a[k]))
            return 0;
    return 1;
}

/* Lexicographic order of two pairs of keys: (wall, id), (i, j). */
static inline int dem_order2(uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1)
{
    if (a0 != b0)
        return (a0 > b0) - (a0 < b0);
    return (a1 > b1) - (a1 < b1);
}

/* Every per-particle array of s->cap entries the scene has now (domain_gather.c): the table a
 * migration, a gather and a removal (flow.c) go through. a[] needs dem_max_particle_arrays. */
typedef struct dem_parray {
    void **p;
    size_t size;
    int hot; /* >= 0: a staggered array of that number (DEM_HOT_*), resized as such */
} dem_parray;
int dem_particle_arrays(dem_scene *s, dem_parray *a);
int dem_max_particle_arrays(const dem_scene *s);
/* A particle's record: its bytes, i's arrays packed into out / unpacked from in (each returns
 * the end of the record), and every array (and gid, ghost when `local`) made to hold n. */
size_t dem_parray_bytes(const dem_parray *a, int na);
char *dem_parray_pack(char *out, const dem_parray *a, int na, size_t i);
const char *dem_parray_unpack(const char *in, const dem_parray *a, int na, size_t i);
core_status dem_parray_resize(dem_scene *s, const dem_parray *a, int na, size_t n, int local,
                              core_error *err);

/* flow.c: inserters and outflows, between steps (dem_run calls dem_flow_step before the first
 * step and after every step when s->flow is set): removal, then insertion, keeping every
 * per-particle array, the pair list with its history and the integrators' state consistent. */
typedef struct dem_flow dem_flow;
/* step: the steps completed (the step is counted after the checks that follow this call). */
core_status dem_flow_step(dem_scene *s, long step, core_error *err);
/* What a run must refuse (more than one rank; removal with boundary conditions). */
core_status dem_flow_check_run(const dem_scene *s, core_error *err);
/* The scene may start a run without particles: an inserter will bring them. */
int dem_flow_inserting(const dem_scene *s);
/* The smallest particle inserter q can make (for the stable step): its k and gamma against
 * itself and the effective mass; 0 when q does not exist. */
int dem_flow_probe(dem_scene *s, int q, double *k, double *gamma, double *m_eff);
void dem_flow_tag_new(dem_scene *s, size_t i); /* a particle was appended: its tag */
/* LAMMPS ids as tags (lammps.c): ids sorted, unique, each id - 1 the tag of particle first + k;
 * tag_clash finds a particle of the scene whose tag + 1 is already one of them (-1: none). */
long dem_flow_tag_clash(const dem_scene *s, const long long *ids, size_t n, size_t *k);
core_status dem_flow_adopt_tags(dem_scene *s, size_t first, const long long *ids, size_t n,
                                core_error *err);
void dem_flow_free(dem_scene *s);
core_status dem_flow_save(const dem_scene *s, struct ckpt_writer *w, core_error *err);
struct dem_reader; /* dem/checkpoint_reader.h: the section being read, with its sticky status */
core_status dem_flow_load(dem_scene *s, struct dem_reader *r);

/* forces.c: the normal law's exponent (laws.h, normal_NAME_beta) */
double dem_law_beta(const dem_contact_def *c);

/* unstable.c: a run stopped at particle i (local index) that `what` ("went through a wall"),
 * with the likely cause in the message; the energy watch every DEM_WATCH_EVERY steps. */
core_status dem_unstable(dem_scene *s, size_t i, const char *what, core_error *err);
core_status dem_energy_watch(dem_scene *s, double dt, core_error *err);

/* checkpoint_save.c: the law's damping solved from a restitution is saved in a section of its
 * own ("damping"), which a scene with this law cannot load without. */
int dem_checkpoint_damping(const dem_contact_def *c);

/* restitution.c: damping from a restitution (dem.h, dem_contact_damping) */
/* The law takes each pair's damping from its materials' restitution through a solved
 * coefficient (mat_damp): viscous without gamma_n (except the unclipped linear spring, a closed
 * form), Brilliantov without damping_time; neither with s:contact's restitution. */
int dem_damping_solved(const dem_contact_def *c);
/* Viscous: c(e); Brilliantov: lambda(e) v^{-1/5} (v = impact_velocity). */
core_status dem_damping_coefficient(const dem_contact_def *c, double e, double *out,
                                    core_error *err);
/* The coefficients of n materials (0 each when the law does not take them). */
core_status dem_damping_table(const dem_contact_def *c, const dem_material *mats, int n,
                              double *out, core_error *err);

/* neighbor.c */
/* The law parameters of two particles of material mat, radius r and mass m each. */
void dem_probe_parameters(const dem_scene *s, int mat, double r, double m, double *k,
                          double *gamma);
void dem_wrap_positions(dem_scene *s);
/* After p->i, j and n are filled: p->start, jstart and jpair from them. */
core_status dem_pairs_index(dem_scene *s, core_error *err);
core_status dem_build_pairs(dem_scene *s, core_error *err);
void dem_free_pairs(dem_pairs *p);
void dem_pair_parameters(dem_scene *s, size_t i, size_t j, double *k, double *gamma, double *mu);
void dem_wall_parameters(const dem_scene *s, const dem_wall *w, size_t i, double *k,
                         double *gamma, double *mu);

/* walls.c: walls beyond planes. The geometry is kept in the wall's body frame (relative to its
 * centre, at orientation `rot`), so a turning wall costs one rotation of the particle's position
 * per contact test, not a transform of its vertices per step. */
struct dem_shape {
    dem_wall_kind kind;
    size_t nv, ne;
    double *v;                    /* body-frame vertices, 3 each */
    uint32_t *e;                  /* elements: 2 (segments) or 3 (triangles) vertex ids each */
    double radius, axis[3], half; /* CYLINDER: half length (INFINITY: infinite) */
    int inside;
    double reach;            /* largest distance of a vertex (or rim) from the centre */
    int spins_in_place;      /* a cylinder turning about its own axis: turning moves no surface */
    double center[3];        /* now */
    double angle;            /* 2D orientation */
    double rot[9];           /* body to world, row-major (2D: from angle) */
    double vel[3], omega[3]; /* now (at the time of the next force evaluation) */
    size_t nt;               /* motion table rows (t, v[3], omega[3]); 0: constants */
    double *tab;
    double moved;               /* bound on any surface point's displacement since the list build */
    double force[3], torque[3]; /* on the wall at the last evaluation */
    uint32_t *cand;             /* particles within r + skin at the last list build (the wall's own
                                 * ncand stays 0: the planes' loop passes over the wall) */
    size_t ncand, cap_cand;
    double *cload; /* per candidate: force, torque on the wall, f_n (DEM_SHAPE_LOAD), summed in
                    * candidate order */
};

typedef struct dem_wall_hit {
    double dist;     /* of the centre from the surface along n (< 0: through it) */
    double n[3];     /* unit normal from the wall to the particle */
    double point[3]; /* the contact point on the surface */
    double vel[3];   /* the surface's velocity there: v + omega x (point - centre) */
} dem_wall_hit;

/* The hits of particle i (dist < r_i), closest first; 0 when none. */
int dem_shape_hits(const dem_scene *s, const dem_wall *wl, size_t i, dem_wall_hit *hit);
/* Smallest distance of x from the wall's surface (signed for cylinders). */
double dem_shape_distance(const dem_scene *s, const dem_wall *wl, const double *x);
/* Candidates of a shaped wall at a list build (within r + skin). */
core_status dem_shape_candidates(dem_scene *s, dem_wall *wl, core_error *err);
/* Moves every shaped wall by one step dt from time s->time; samples the motion at the new time. */
void dem_shapes_move(dem_scene *s, double dt);
/* A shaped wall's surface moved more than half the skin since the list build. */
int dem_shapes_moved(const dem_scene *s);
/* Samples the prescribed motion at time t into vel and omega. */
void dem_shape_sample(dem_shape *sh, double t);
void dem_shape_free(dem_shape *sh);
/* Any shaped wall moving (or tabulated to move): the scene is driven. */
int dem_shapes_driven(const dem_scene *s);
core_status dem_shapes_save(const dem_scene *s, struct ckpt_writer *w, core_error *err);
core_status dem_shapes_load(dem_scene *s, struct ckpt_section *sec, core_error *err);

/* forces.c: the force evaluation, instantiated for 2D and 3D. dem_compute_forces fills f and tq
 * (pairs, walls, gravity) and returns the index of a particle that went through a wall, or
 * (size_t)-1. */
size_t dem_compute_forces(dem_scene *s, double dt);
double dem_normal_force(const dem_contact_def *c, double k, double gamma, double delta,
                        double ddelta);
double dem_elastic_energy(const dem_contact_def *c, double k, double delta);

/* rolling.inc: the history slots the laws of s use (DEM_HIST_ROLL + d for d < this), and the
 * values per history entry moved between ranks (domain.c bundles): the tangential 4, and the
 * rolling 3 only with a rolling history (a scene without it sends what it sent before). */
static inline int dem_rolling_slots(const dem_scene *s)
{
    return dem_rolling_history(s->contact.rolling_law) ? (s->dim == 2 ? 1 : 3) : 0;
}
static inline int dem_hist_width(const dem_scene *s) { return dem_rolling_slots(s) ? DEM_HIST : 4; }

/* The laws that make a contact cohesive (cohesion.h); the ones that hold beyond touch keep the
 * history slot DEM_HIST_BOND. */
static inline int dem_cohesive(const dem_contact_def *c)
{
    return c->normal == DEM_NORMAL_JKR || c->normal == DEM_NORMAL_DMT ||
           c->cohesion != DEM_COHESION_NONE;
}
static inline int dem_bonds(const dem_contact_def *c)
{
    return c->normal == DEM_NORMAL_JKR || c->cohesion != DEM_COHESION_NONE;
}
/* neighbor.c: the scene's reach (dem_scene.reach) under its laws, materials and largest radius;
 * the pair's work of adhesion. */
double dem_cohesion_reach(const dem_scene *s);
static inline double dem_pair_adhesion(const dem_scene *s, size_t i, size_t j)
{
    if (s->contact.adhesion >= 0)
        return s->contact.adhesion;
    return sqrt(s->mats[s->mat[i]].adhesion * s->mats[s->mat[j]].adhesion);
}
/* The same for particle i against wall w (its material, or i's own). */
static inline double dem_wall_adhesion(const dem_scene *s, const dem_wall *w, size_t i)
{
    if (s->contact.adhesion >= 0)
        return s->contact.adhesion;
    const int mi = s->mat[i], mw = w->material >= 0 ? w->material : mi;
    return sqrt(s->mats[mi].adhesion * s->mats[mw].adhesion);
}

/* clump.c: rigid bodies of member particles. body[i] is particle i's clump or -1; off holds
 * each member's offset in its body's principal frame (3 per particle). */
typedef struct dem_body {
    double x[3], v[3], q[4], L[3], omega[3], f[3], t[3];
    double mass, moment[3], angle;
    size_t first, count;
} dem_body;
typedef struct dem_clumps {
    dem_body *b;
    size_t n, cap;
    int32_t *body; /* per particle (scene cap) */
    double *off;   /* 3 per particle (scene cap) */
} dem_clumps;
/* What a run with clumps refuses (named in the error); CORE_OK without clumps. */
core_status dem_clumps_check_run(const dem_scene *s, int integrator, core_error *err);
/* Velocity Verlet's first half: the bodies' half kick from their members' forces, the drift and
 * rotation by dt, the members placed from the bodies. */
void dem_clumps_kick_drift(dem_scene *s, double h, double dt);
/* The second half kick, the members' velocities from the bodies. */
void dem_clumps_kick(dem_scene *s, double h);
/* The particle arrays grew to cap (scene.c's grow). */
core_status dem_clumps_grow(dem_scene *s, size_t old_cap, size_t cap, core_error *err);
/* Kinetic, rotational and gravitational energies of the bodies (measure.c skips members). */
void dem_clumps_energy(const dem_scene *s, double *kin, double *rot, double *pot);
void dem_clumps_free(dem_scene *s);
/* clump_checkpoint.c: the section "clumps", written only by a scene with clumps; the load runs
 * after the particles' section, in the open section of r. */
core_status dem_clumps_save(const dem_scene *s, struct ckpt_writer *w, core_error *err);
core_status dem_clumps_load(dem_scene *s, struct dem_reader *r);
static inline int dem_is_member(const dem_scene *s, size_t i)
{
    return s->clumps && s->clumps->body[i] >= 0;
}

/* scene.c */
/* The scene changed outside a step: forces, integrator state and (if `list`) the pair list
 * must be recomputed before the next step. */
void dem_invalidate(dem_scene *s, int list);
core_status dem_ensure_rotation(dem_scene *s, core_error *err);
core_status dem_alloc_array(double **a, size_t n, core_error *err);
/* The particle arrays the step's passes walk together (positions, velocities, forces, build
 * positions, spins, torques, angles, radii, masses, inverse masses and inertias) start staggered
 * in their blocks (core_realloc_staggered, number k below): allocated by dem_alloc_hot (scene.c,
 * checkpoint.c), freed by core_free_staggered with the same number, never by free. */
enum {
    DEM_HOT_X = 0, /* x[d]: 0..2 */
    DEM_HOT_V = 3,
    DEM_HOT_F = 6,
    DEM_HOT_XB = 9,
    DEM_HOT_W = 12,
    DEM_HOT_TQ = 15,
    DEM_HOT_ANGLE = 18,
    DEM_HOT_R,
    DEM_HOT_M,
    DEM_HOT_INV_M,
    DEM_HOT_INV_I
};
core_status dem_alloc_hot(double **a, size_t n, int k, core_error *err);

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
