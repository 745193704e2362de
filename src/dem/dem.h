/* grainlab DEM: soft-sphere discrete elements in 2D (disks) and 3D (spheres).
 * Physics: Herrmann & Mueller (2000) Sec. 2 (Eqs. 1a, 1b, 2a, 2b, Gear predictor-corrector) and
 * Padbidri (2010) Ch. 1-2 (Hertz + Brilliantov Eq. 2.16, regularised Coulomb Eq. 2.18, slip with
 * rotation Eq. 2.A6, Verlet Eq. 1.6, quasistatic coefficient Eq. 2.13/2.B1, two timescales Sec. 2.4).
 *
 * Usage: fill a dem_scene_def from dem_default_scene_def(), create the scene, set the contact law,
 * add materials, particles and walls, then call dem_run. Every call that can fail returns a
 * core_status and explains itself in a core_error. Nothing here knows about Lua. */
#ifndef GRAINLAB_DEM_H
#define GRAINLAB_DEM_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "core/progress.h"
#include "dem/laws.h"

typedef struct dem_scene dem_scene;

/* ---- scene ------------------------------------------------------------------------------- */
typedef struct dem_scene_def {
    int dim;              /* 2 (disks) or 3 (spheres) */
    double lo[3], hi[3];  /* the domain: a particle leaving it on an axis that is not periodic
                           * stops the run with an error (unless an outflow opens that side) */
    bool periodic[3];
    double gravity[3];    /* m/s^2 */
    /* 2D only: > 0 makes disks cylinders of this thickness (m = rho pi r^2 t, I = m r^2 / 2);
     * 0 (default) makes them spheres moving in the plane (m = rho 4/3 pi r^3, I = 2/5 m r^2). */
    double thickness;
    double skin;          /* Verlet-list skin, m; 0 = automatic (0.2 of the largest radius) */
} dem_scene_def;

dem_scene_def dem_default_scene_def(void);
core_status dem_create(const dem_scene_def *def, dem_scene **out, core_error *err);
void dem_destroy(dem_scene *s);
int dem_dim(const dem_scene *s);
/* Distributed runs (MPI, more than one rank): dem_run decomposes the scene over the ranks; this
 * gathers it back to every rank, as one rank would hold it (collective: every rank calls it). A
 * no-op when the scene is not decomposed. Every call below other than dem_run and the scalar
 * queries (time, steps, walls) needs the whole scene: the bindings call this first. */
core_status dem_replicate(dem_scene *s, core_error *err);
int dem_distributed(const dem_scene *s);
/* Distributed: the wall forces of the last evaluation, summed over the ranks in the one-rank
 * order, before dem_wall_force reads them (collective; a no-op when already summed or on one
 * rank). */
core_status dem_sync_walls(dem_scene *s, core_error *err);
/* What the decomposition did so far (all zero until a run on more than one rank): list rebuilds
 * while decomposed, rebalances of the regions, particles that changed rank (summed over ranks),
 * and the fewest and most particles a rank owned after the last rebuild. The same on every rank. */
typedef struct dem_domain_stats {
    int ranks;
    long rebuilds, rebalances, migrations, owned_min, owned_max;
    /* traffic to other ranks summed over the ranks: halo exchanges (every force evaluation
     * without a rebuild), and rebuilds (migration, ghosts, history), in bytes and messages */
    double halo_bytes, halo_messages, rebuild_bytes, rebuild_messages;
    long halos;
    /* wall-clock seconds in rebuilds (all of it: migration, list) and in the rebalances' own
     * part (gathering positions, new regions), the slowest rank's */
    double rebuild_s, rebalance_s;
    double comm_s; /* inside communication calls during runs (core/comm.h), the slowest rank */
} dem_domain_stats;
/* Collective when the scene ran on more than one rank (the traffic is summed over the ranks). */
void dem_domain_stats_get(const dem_scene *s, dem_domain_stats *out);

/* ---- materials ----------------------------------------------------------------------------- */
typedef struct dem_material {
    double density;      /* kg/m^3 */
    double young;        /* Pa (Hertz laws) */
    double poisson;      /* [0, 0.5) */
    double friction;     /* Coulomb mu >= 0; a pair uses the smaller of its two */
    double restitution;  /* (0, 1]: the damping's restitution unless the contact sets one (a
                          * pair takes the smaller of its two); 1 = none */
    double rolling_friction; /* rolling resistance mu_r >= 0 (the torque limit is mu_r R_eff
                              * F_n); a pair uses the smaller of its two; 0 (default) = none */
    double adhesion; /* work of adhesion Gamma >= 0, J/m^2 (JKR, DMT); a pair takes the geometric
                      * mean of its two, unless the contact gives one; 0 (default) = none */
} dem_material;

dem_material dem_default_material(void); /* quartz: 2650, 30 GPa, 0.3, 0.45, 0.5 */
/* Returns the material index (>= 0) or -1 with err filled. */
int dem_add_material(dem_scene *s, const dem_material *m, core_error *err);

/* ---- contact laws -------------------------------------------------------------------------- */
/* dem_normal_law, dem_damping_law, dem_tangential_law, dem_rolling_law and their names
 * (dem_normal_names, ...): one row per law in laws.h. */
typedef struct dem_contact_def {
    dem_normal_law normal;
    double stiffness;        /* k for LINEAR / POWER, N/m^beta */
    double beta;             /* POWER exponent */
    dem_damping_law damping;
    double gamma_n;          /* VISCOUS: N s/m; < 0 = from a restitution */
    double damping_time;     /* BRILLIANTOV: a fixed T in seconds; < 0 = from a restitution */
    double restitution;      /* < 0 = unset: the materials' (the smaller of a pair's two); in
                              * (0, 1] = every pair (walls too) rebounds with e from a head-on
                              * impact at impact_velocity (with damping NONE only 1; not with a
                              * given gamma_n or damping_time) */
    double impact_velocity;  /* m/s: the speed at which a restitution holds (the linear spring
                              * with viscous damping: every speed) */
    dem_tangential_law tangential;
    double gamma_t;          /* VISCOUS tangential, N s/m */
    double kt;               /* SPRING stiffness, N/m; < 0 = 2/7 of the normal stiffness scale */
    double v_r;              /* REGULARIZED characteristic velocity, m/s */
    double exponent;         /* REGULARIZED c (large) */
    bool clip;               /* no attractive normal force (default true) */
    bool rolling;            /* allocate rotations even without a tangential law */
    dem_rolling_law rolling_law; /* rolling resistance (allocates rotations); NONE default */
    double rolling_friction;     /* mu_r of every pair and wall; < 0 (default) = the materials' */
    double rolling_stiffness;    /* EPSD k_r, N m/rad; < 0 (default) = k_t R_eff^2, with k_t the
                                  * tangential spring stiffness (kt, or 2/7 of the normal one) */
    double rolling_damping; /* EPSD damping ratio eta_r in [0, 1]: C_r = 2 eta_r sqrt(I_r k_r) */
    double rolling_rate;    /* CONSTANT w_c, rad/s; 0 (default) = automatic: the rate below
                             * which the full torque would stop the relative rotation of the
                             * contact within 10 steps (rolling.inc) */
    double adhesion;        /* JKR, DMT: the work of adhesion Gamma of every pair, J/m^2; < 0
                             * (default) = the materials' (cohesion.h) */
    dem_cohesion_law cohesion; /* a liquid bridge added to the normal law; NONE default */
    double liquid_volume;      /* CAPILLARY: the volume V of each bridge, m^3 */
    double surface_tension;    /* CAPILLARY: the liquid's gamma, N/m */
    double contact_angle;      /* CAPILLARY: theta in [0, pi), rad */
} dem_contact_def;

dem_contact_def dem_default_contact_def(void); /* Hertz, no damping, no friction, clip */
core_status dem_set_contact(dem_scene *s, const dem_contact_def *def, core_error *err);
const dem_contact_def *dem_contact(const dem_scene *s);

/* ---- particles ----------------------------------------------------------------------------- */
enum { DEM_FIXED = 1, DEM_PRESCRIBED = 2 }; /* flags: fixed in place / moves at its velocity */

typedef struct dem_particle_def {
    double x[3], v[3], omega[3]; /* omega: only [2] in 2D */
    double radius;
    int material;
    unsigned flags;
} dem_particle_def;

/* Returns the particle index (>= 0) or -1 with err filled. */
long dem_add_particle(dem_scene *s, const dem_particle_def *p, core_error *err);
size_t dem_count(const dem_scene *s);

/* Bulk access, in particle order: component d of positions/velocities, radii, masses;
 * omega: angular velocity component (2D: only d = 2; NULL arrays when rotations are off). */
const double *dem_positions(const dem_scene *s, int d);
const double *dem_velocities(const dem_scene *s, int d);
const double *dem_angular_velocities(const dem_scene *s, int d);
const double *dem_radii(const dem_scene *s);
/* 2D orientation angles (rad, integrated from omega; NULL when rotations are off or in 3D). */
const double *dem_angles(const dem_scene *s);

/* ---- clumps: rigid bodies made of overlapping disks or spheres (clump.c) -------------------- *
 * A clump's members are particles of the scene (ids first .. first + count - 1) that carry no
 * dynamics of their own: each step the forces and torques on them are summed onto the body,
 * the body moves (2D: its angle; 3D: a quaternion by the NO_SQUISH splitting, Miller et al.
 * 2002), and the members are placed and given velocities from it. Members of one clump never
 * touch each other. Mass, centre and inertia are those of the union of the members, integrated
 * numerically (dem_clump_shape_compute). */
enum { DEM_CLUMP_MAX_MEMBERS = 256 };
typedef struct dem_clump_member {
    double offset[3]; /* in the members' own frame (2D: [2] = 0) */
    double radius;
} dem_clump_member;

typedef struct dem_clump_shape {
    int dim, planar;    /* planar: 2D disks of unit thickness; else spheres (in 2D: centres in
                         * the plane) */
    int resolution;     /* quadrature lines along the longest side of the bounding box */
    double measure;     /* area (planar) or volume of the union */
    double centre[3];   /* of the union, in the members' frame */
    double tensor[9];   /* central inertia tensor per unit density (planar: per unit thickness) */
    double moments[3];  /* principal moments, ascending (2D: [2] = the moment about z) */
    double axes[9];     /* row-major; column k: principal axis k in the members' frame (2D: I) */
    double rel_error;   /* largest relative change of the measure and moments from half the
                         * resolution: an estimate of (an upper bound on) the quadrature error */
} dem_clump_shape;

/* Checks the members (radius > 0 and finite, offsets finite, 1..DEM_CLUMP_MAX_MEMBERS members
 * that form one connected body: each overlaps or touches another) and integrates the union.
 * resolution 0: the default, 4096 lines for planar disks, 1024 for spheres in 2D, 512 in 3D. */
core_status dem_clump_shape_compute(const dem_clump_member *m, int n, int dim, int planar,
                                    int resolution, dem_clump_shape *out, core_error *err);

typedef struct dem_clump_def {
    const dem_clump_member *members;
    int n;
    const dem_clump_shape *shape; /* of these members for this scene (planar when the scene's
                                   * thickness > 0); NULL: computed here */
    int material;
    double x[3];     /* the centre of mass */
    double q[4];     /* 3D: orientation (w, x, y, z), unit, members' frame to world */
    double angle;    /* 2D: orientation, rad */
    double v[3], omega[3]; /* 2D: omega[2] */
} dem_clump_def;
/* Returns the clump's index (>= 0) or -1 with err filled. */
long dem_add_clump(dem_scene *s, const dem_clump_def *c, core_error *err);
size_t dem_clump_count(const dem_scene *s);
typedef struct dem_clump_state {
    double mass, x[3], v[3], omega[3], L[3]; /* L: angular momentum about the centre, world */
    double q[4];       /* 3D: principal (body) frame to world */
    double angle;      /* 2D */
    double moments[3]; /* principal moments (2D: [2]) */
    size_t first, count;
} dem_clump_state;
core_status dem_clump_get(const dem_scene *s, size_t k, dem_clump_state *out, core_error *err);
/* The clump of particle i (>= 0), or -1 for a particle of no clump. */
long dem_particle_clump(const dem_scene *s, size_t i);
/* Material index of each particle. */
const int *dem_particle_materials(const dem_scene *s);
const double *dem_masses(const dem_scene *s);
core_status dem_set_velocity(dem_scene *s, size_t i, const double v[3], core_error *err);

/* ---- walls --------------------------------------------------------------------------------- */
typedef struct dem_wall_def {
    double point[3], normal[3]; /* normal points into the domain */
    double velocity[3];         /* the wall translates at this velocity */
    double friction;            /* < 0: the smaller of the particle's and the wall material's */
    int material;               /* < 0: the particle's material */
} dem_wall_def;

int dem_add_wall(dem_scene *s, const dem_wall_def *w, core_error *err); /* wall id or -1 */
core_status dem_remove_wall(dem_scene *s, int id, core_error *err);
core_status dem_set_wall_velocity(dem_scene *s, int id, const double v[3], core_error *err);
/* Wall slots (removed walls keep their id); geometry of wall id now, *active = 0 if removed or
 * not a plane (dem_wall_outline draws the others). */
int dem_wall_count(const dem_scene *s);
core_status dem_wall_geometry(const dem_scene *s, int id, double point[3], double normal[3],
                              int *active, core_error *err);
/* Current position of the wall's reference point. */
core_status dem_wall_point(const dem_scene *s, int id, double p[3], core_error *err);
/* Normal force the wall exerted on the particles at the last force evaluation (N): contacts,
 * plus the force that holds the particles tied to it (dem_tie_to_wall). */
core_status dem_wall_force(const dem_scene *s, int id, double *fn, core_error *err);
/* Force control: the wall becomes a body of mass `mass` moving along its normal, pushed towards
 * the particles by `force` and held back by their contact force, with velocity damping `rate`
 * (1/s): M dv/dt = force - F_contact - M rate v. Quasistatically a servo of gain 1/(M rate);
 * the mass filters the contact noise. mass = 0 switches it off (the wall keeps its velocity). */
core_status dem_wall_servo(dem_scene *s, int id, double force, double mass, double rate,
                           core_error *err);

/* ---- walls beyond planes (walls.c) --------------------------------------------------------- *
 * Segments and polylines (2D), triangles and triangle meshes (3D), circles (2D) and cylinders (3D,
 * infinite or finite along their axis, open at the ends), with the particles inside (a drum) or
 * outside (a post). A particle's contact is at the closest point of the wall's surface, edges and
 * end points included; on a polyline or mesh each element in contact gives a hit, and a hit whose
 * closest point is an end point, vertex or edge is dropped when another element sharing that
 * feature is as close (ties: the lower element index keeps it), so a particle on a shared vertex
 * or edge feels one force, while one in a concave corner feels both faces. At most
 * DEM_WALL_MAXHIT hits per particle and wall (the closest). Walls are two-sided except cylinders.
 * The stiffness is the flat-wall one (R* = the particle radius) whatever the wall's curvature.
 * Each such wall moves as a rigid body: its centre translates at `velocity` and it turns at
 * `omega` about the centre (2D: omega[2]), constants or a piecewise-linear table of the scene time
 * (held at the end values outside it), sampled by the step itself (no callback in the step). */
enum { DEM_WALL_MAXHIT = 4 };

typedef enum dem_wall_kind {
    DEM_WALL_PLANE,     /* dem_add_wall */
    DEM_WALL_SEGMENTS,  /* 2D: a polyline of n points (n - 1 segments; n with closed) */
    DEM_WALL_TRIANGLES, /* 3D: n triangles (a mesh: vertices shared by equal coordinates) */
    DEM_WALL_CYLINDER   /* 2D circle, 3D cylinder */
} dem_wall_kind;

typedef struct dem_shape_def {
    dem_wall_kind kind;
    size_t n;             /* SEGMENTS: points; TRIANGLES: triangles */
    const double *points; /* SEGMENTS: 3 n (x, y, ignored); TRIANGLES: 9 n (three corners) */
    int closed;           /* SEGMENTS: the last point joins the first */
    int has_center;       /* 0: the mean of the points (SEGMENTS, TRIANGLES) */
    double center[3];     /* centre of rotation, of the torque and (CYLINDER) of the cylinder */
    double radius;        /* CYLINDER */
    double axis[3];       /* CYLINDER, 3D */
    double length;        /* CYLINDER, 3D: 0 = infinite */
    int inside;           /* CYLINDER: the particles are inside (1) or outside (0) */
    double velocity[3], omega[3]; /* constant motion (2D: omega[2] only) */
    size_t nmotion;       /* > 0: the motion table instead, nmotion rows of 7: t, v[3], omega[3] */
    const double *motion; /* times strictly increasing */
    double friction;      /* < 0: the smaller of the particle's and the wall material's */
    int material;         /* < 0: the particle's material */
} dem_shape_def;

dem_shape_def dem_default_shape_def(void); /* inside, no motion, no friction override */
int dem_add_shape_wall(dem_scene *s, const dem_shape_def *def, core_error *err); /* id or -1 */
dem_wall_kind dem_wall_kind_of(const dem_scene *s, int id); /* PLANE for a bad id */
/* The force the particles exert on the wall (N, the reaction of the contact forces) and its
 * torque about the wall's centre at the last force evaluation. Planes: the normal part only,
 * -fn normal, and no torque (they have no centre). */
core_status dem_wall_load(const dem_scene *s, int id, double force[3], double torque[3],
                          core_error *err);
/* The wall's surface now as line strips (2D: polylines; 3D: polygons): nv[k] points of strip k
 * follow each other in pts (3 per point). Returns the number of strips, 0 for planes; NULL arrays
 * just count (*npts gets the points). Cylinders: `segments` points around. */
int dem_wall_outline(const dem_scene *s, int id, int segments, int *nv, double *pts, size_t *npts);

/* ---- time stepping ------------------------------------------------------------------------- */
typedef enum dem_integrator {
    DEM_VELOCITY_VERLET,   /* default */
    DEM_POSITION_VERLET,   /* Padbidri Eq. 1.6 */
    DEM_GEAR5,             /* Gear 5th-order predictor-corrector (Herrmann Sec. 2) */
    DEM_TWO_TIMESCALES     /* Padbidri Sec. 2.4: m cycles of (one step n dt, q steps dt) */
} dem_integrator;

typedef struct dem_timestep {
    double contact_time;   /* of the stiffest, lightest pair at the impact velocity, s */
    double impact_velocity;
    double limit;          /* largest dt accepted without force: contact_time / 10 */
    double dt_auto;        /* contact_time / 50 */
} dem_timestep;

/* impact_velocity <= 0: the larger of the fastest particle and sqrt(2 |g| height), at least
 * 0.1 m/s. */
core_status dem_timestep_info(const dem_scene *s, double impact_velocity, dem_timestep *out,
                              core_error *err);

typedef struct dem_run_def {
    long steps;            /* steps of dt (for TWO_TIMESCALES: small-step equivalents, a
                            * multiple of m (n + q)) */
    double dt;
    dem_integrator integrator;
    int tt_m, tt_n, tt_q;  /* TWO_TIMESCALES: cycles of one step n dt and q steps dt; m only names
                            * the macro step N_S = m (n + q) of the paper (the cycle repeats) */
    progress *progress;    /* may be NULL */
    /* How dt was chosen, for the likely cause an instability names (a blow-up is blamed on dt
     * only when the user forced it above the limit): */
    bool dt_auto;          /* dt is the automatic step (dem_timestep.dt_auto) */
    double dt_limit;       /* the stability limit dt (for TWO_TIMESCALES n dt) was checked
                            * against; 0 = unknown */
    double dt_speed;       /* the impact velocity of that limit, m/s; 0 = unknown */
} dem_run_def;

dem_run_def dem_default_run_def(void);

/* Advances the scene. Stops between steps on Ctrl-C (CORE_ERR_INTERRUPTED, scene intact) and on
 * instability (CORE_ERR_UNSTABLE naming the step and the particle). */
core_status dem_run(dem_scene *s, const dem_run_def *run, core_error *err);

double dem_time(const dem_scene *s);
long dem_steps_done(const dem_scene *s);
long dem_force_evaluations(const dem_scene *s);
/* Mass scaling: multiplies every mass and moment of inertia (Padbidri Sec. 2.2). */
core_status dem_scale_mass(dem_scene *s, double factor, core_error *err);

/* Multiplies every material's Young's modulus and the linear/power stiffness (a stiffness ramp
 * for preparing samples). */
core_status dem_scale_stiffness(dem_scene *s, double factor, core_error *err);
/* Background drag: every free particle feels -rate m v and -rate I omega (rate in 1/s; 0 = off,
 * the default). For settling samples only: it is not a contact law. */
core_status dem_set_drag(dem_scene *s, double rate, core_error *err);
double dem_drag(const dem_scene *s);
void dem_box(const dem_scene *s, double lo[3], double hi[3], double gravity[3]);
/* Sets gravity (m/s^2; components beyond the scene's dimension must be 0): a tilted box is a
 * rotated gravity. Takes effect at the next step; resets the energy watch's reference (the
 * potential energy changes with it). */
core_status dem_set_gravity(dem_scene *s, const double g[3], core_error *err);

/* External forces on particles (N), added every step until changed or cleared; arrays are
 * allocated on first use. Used for pressure boundary conditions applied as particle forces. */
core_status dem_set_external_force(dem_scene *s, size_t i, const double f[3], core_error *err);
void dem_clear_external_forces(dem_scene *s);

/* Padbidri's quasistatic coefficient (Eq. 2.13; 2D form from 2.B1 with the force per boundary
 * particle f0 = p 2R L / sqrt(2N)): phi = m eps^2 N^{2/3} / (4 p R) in 3D and
 * phi = m eps^2 N / (2 p R) in 2D, with m and R the mean particle mass and radius, p the pressure
 * (Pa) and eps the strain rate (1/s). psi = N^{-1/3} (3D) or (2N)^{-1/2} (2D) (Eq. 2.14). */
core_status dem_quasistatic(const dem_scene *s, double pressure, double strain_rate, double *phi,
                            double *psi, core_error *err);

/* ---- measurements -------------------------------------------------------------------------- */
typedef struct dem_energy {
    double kinetic, rotational, elastic, potential, total; /* J; potential from gravity */
} dem_energy;
void dem_measure_energy(dem_scene *s, dem_energy *e);

typedef struct dem_contact_info {
    long i, j;             /* j < 0: wall number -(j+1) */
    double fn, ft;         /* normal (>= 0 repulsive) and tangential force magnitudes */
    double normal[3];      /* from j to i */
    double point[3];
    double overlap;
    double force[3];       /* the force on i (pairs: normal + tangential; walls: normal only) */
} dem_contact_info;
/* Calls fn for each contact (pairs and walls) in a fixed order. */
void dem_each_contact(dem_scene *s, void (*visit)(const dem_contact_info *c, void *ctx),
                      void *ctx);
/* The same contacts in the same order, with force the whole force on i for wall contacts too:
 * the normal part plus the friction, rebuilt as the force loop makes it (the spring's stored
 * force, or the viscous or regularised law against the slip now). */
void dem_each_contact_full(dem_scene *s, void (*visit)(const dem_contact_info *c, void *ctx),
                           void *ctx);
/* The periodic axes given at creation. */
void dem_periodic(const dem_scene *s, bool periodic[3]);

/* Assembly stress sigma_ab = (1/V) sum_c branch_a f_b over particle pairs (V = domain volume,
 * or area in 2D unless given). Returns the number of contacts. */
long dem_measure_stress(dem_scene *s, double volume, double sigma[3][3]);
/* Mean contacts per particle counting walls, and (rattlers excluded) per particle with >= 2. */
void dem_measure_coordination(dem_scene *s, double *z_all, double *z_no_rattlers);
/* Mean |slip velocity| over particle-particle contacts (Padbidri Fig. 2.4). */
double dem_measure_slip(dem_scene *s);
/* Reference state for displacements. */
core_status dem_set_reference(dem_scene *s, core_error *err);
/* Displacement since the reference minus the affine field grad_u . (X_ref - center); grad_u may
 * be NULL (plain displacement). out[d] arrays of dem_count() values. */
core_status dem_measure_displacement(const dem_scene *s, const double grad_u[3][3],
                                     const double center[3], double *out[3], core_error *err);

/* Brilliantov damping, f = K d^{3/2} + T K d^{1/2} d'. In lengths d* = (m_eff v^2 / K)^{2/5}
 * and times d* / v the head-on contact is x'' = -x^{3/2} - lambda x^{1/2} x', x(0) = 0,
 * x'(0) = 1, with lambda = T v / d* = T (K / m_eff)^{2/5} v^{1/5}: the restitution depends on the
 * pair (m_eff, K = 4/3 E* sqrt(R*)) and the speed only through lambda. dem_brilliantov_lambda
 * solves lambda(e) once (bisection on an RK4 integration; clip: the force is never attractive,
 * as the contact law's clip); a pair's damping time is then T = lambda (m_eff / K)^{2/5} v^{-1/5}.
 */
core_status dem_brilliantov_lambda(double e, bool clip, double *lambda, core_error *err);
/* The restitution of the dimensionless contact for a given lambda (the inverse of the above). */
double dem_brilliantov_restitution(double lambda, bool clip);
/* T for one pair of effective mass m_eff and stiffness K at speed v (clipped law). */
core_status dem_brilliantov_time(double e, double m_eff, double K, double v, double *T,
                                 core_error *err);
/* Every normal law with viscous or Brilliantov damping: in lengths d* = (m* v^2 / k)^{1/(beta+1)}
 * and times d* / v the head-on contact is x'' = -x^beta - c x^a x', x(0) = 0, x'(0) = 1, with
 * a = 0, c = gamma d* / (m* v) (viscous) or a = 1/2, c = T v / d* (Brilliantov; beta = 3/2: c is
 * lambda above). dem_contact_restitution gives e(c) (adaptive Dormand-Prince to 1e-11, the end
 * located within the step; clip: the grains part when the force falls to zero, then fly apart;
 * 0 when the contact never ends); dem_contact_damping solves c(e). A pair then takes
 * gamma = c m* v / d* or T = c d* / v: for beta = 1 with viscous damping gamma = c sqrt(m* k)
 * holds at every speed, otherwise e holds at the speed v it was solved for. */
double dem_contact_restitution(double beta, double a, double c, bool clip);
core_status dem_contact_damping(double e, double beta, double a, bool clip, double *c,
                                core_error *err);
/* The normal damping the force loop uses for particles i and j (0-based), or, when wall >= 0,
 * for particle i against wall `wall` (j ignored): the Brilliantov time T in s, or the viscous
 * gamma in N s/m (0 without damping). */
core_status dem_pair_damping(const dem_scene *s, size_t i, size_t j, int wall, double *out,
                             core_error *err);

struct ckpt_writer; /* core/checkpoint.h */
struct ckpt_section;
/* ---- boundary conditions of the biaxial laboratory (Padbidri Ch. 3) ----------------------- *
 * 2D only. A pressure boundary is a list of directed edges a -> b between particles, outward
 * normal (dy, -dx)/L: every force evaluation, each loaded edge pushes both its particles inward
 * with p depth L / 2 (tractions on the boundary of the Delaunay continuum, Fig. 2.2). When the
 * edges form one closed counter-clockwise loop they also give the coarse velocity gradient of the
 * enclosed assembly, H = (1/V) sum_a v_a (x) g_a with g_a = sum of (L n)/2 of a's edges (Eq.
 * 3.2-3.3), and carry the penalty of the minimal boundary conditions: Phi = K/2 sum_ij
 * mask_ij dE_ij^2 (Eq. 3.4), dE = sym(H) - target (or H - target when `gradient`), so that
 * F_a = -dPhi/dv_a = -(K/V) (mask o dE) g_a (Eq. 3.5). sum_a g_a = 0 on a closed loop: the
 * penalty forces have zero sum (and zero moment for a symmetric dE). The edges come from the
 * caller (dem_set_boundary_edges), or from `update`, called every `every` steps inside dem_run
 * (e.g. a Delaunay triangulation of the centres; src/dem knows nothing of how). */
typedef struct dem_boundary_def {
    double pressure;   /* Pa on the loaded edges; 0 = none */
    double depth;      /* m, out of plane: a traction p on an edge of length L is the force p depth L */
    long every;        /* steps between calls of update (0: never) */
    core_status (*update)(void *ctx, dem_scene *s, core_error *err);
    void *ctx;
    void (*free_ctx)(void *ctx); /* called when the boundary is replaced or the scene destroyed */
    double penalty;    /* K (N s m) of the minimal boundary conditions; 0 = off */
    int gradient;      /* 0: penalise sym(H) - target (strain rate); 1: H - target */
    double target[4];  /* xx, xy, yx, yy, 1/s */
    double mask[4];    /* component weights (0 or 1); symmetric when !gradient */
    /* > 0: the error penalised is dE + (integral of dE dt) / tau, so that the accumulated strain
     * error is driven back too (a proportional-integral penalty; with an explicit step, K is
     * limited, and the rate penalty alone then lags under load); 0: the rate only (Eq. 3.4). */
    double tau;
    /* Checkpoints: a function pointer cannot go into a file, so the installer of `update` names
     * it (`kind`, at most 15 characters, e.g. "delaunay") and writes what ctx holds with
     * save_ctx (core/checkpoint.h put functions); dem_load_with hands that back to the caller's
     * dem_boundary_restorer of the same kind. An update without a kind cannot be saved. */
    const char *kind;
    void (*save_ctx)(const void *ctx, struct ckpt_writer *w);
} dem_boundary_def;

dem_boundary_def dem_default_boundary_def(void); /* no pressure, every 250, no penalty */
/* Replaces the boundary definition (the edges are kept; the old ctx is freed). */
core_status dem_set_boundary(dem_scene *s, const dem_boundary_def *def, core_error *err);
/* Removes the boundary, its edges, springs and ties. */
void dem_clear_boundary(dem_scene *s);
/* Sets the edges (copied). loaded: per edge, NULL = all loaded. closed: the edges form one
 * counter-clockwise loop (needed for the penalty and the coarse gradient). */
core_status dem_set_boundary_edges(dem_scene *s, size_t n, const long *a, const long *b,
                                   const unsigned char *loaded, int closed, core_error *err);
/* Calls the update now (also done by dem_run every `every` steps). */
core_status dem_update_boundary(dem_scene *s, core_error *err);

/* Linear springs between particle pairs (a membrane chain, Padbidri Sec. 3.2): f = k (d - rest)
 * along the line of centres; rest NULL = the current distances. */
core_status dem_add_springs(dem_scene *s, size_t n, const long *i, const long *j, double k,
                            const double *rest, core_error *err);
/* Ties particle i's velocity component `axis` to wall `wall`'s (membrane ends move with the
 * plates): that component of its velocity is the wall's and its force is zeroed. */
core_status dem_tie_to_wall(dem_scene *s, size_t i, int wall, int axis, core_error *err);

/* Prescribes particle i's spin (2D angular velocity, rad/s): omega is set and the torque zeroed
 * at every evaluation; its translation stays free (Padbidri Ch. 4, the forced particle). Calling
 * again updates omega (a ramp). Needs rotations (a tangential law or rolling). */
core_status dem_set_spin(dem_scene *s, size_t i, double omega, core_error *err);

typedef struct dem_boundary_info {
    size_t edges, loaded, nodes;
    int closed;
    double area;              /* inside the loop now (closed only), m^2 */
    double grad[4];           /* coarse velocity gradient H now (Eq. 3.2), 1/s */
    double strain_rate[4];    /* sym(H) */
    double penalty_sum[2];    /* net penalty force of the last evaluation, N */
    double penalty_max;       /* largest |F_a| of the last evaluation, N */
    double pressure_max;      /* largest pressure force on a particle, N */
    double stiffness;         /* K sum_a |g_a|^2 / (V^2 m_min): the penalty's rate, 1/s */
    long updates;             /* calls of update */
    double update_seconds;    /* CPU time (process) spent in update */
    double apply_seconds;     /* CPU time spent applying pressure, penalty, springs, ties */
    size_t springs, ties;
} dem_boundary_info;
core_status dem_boundary_info_get(dem_scene *s, dem_boundary_info *out, core_error *err);
/* Edges now (pointers into the scene, valid until the edges change): a, b, loaded. */
size_t dem_boundary_edges(const dem_scene *s, const long **a, const long **b,
                          const unsigned char **loaded);
/* The out-of-plane thickness given at creation (0 for spheres in the plane and in 3D). */
double dem_thickness(const dem_scene *s);

/* ---- output for other tools (dem/vtk.c) ------------------------------------------------------ */
/* Total force on each particle at the last force evaluation (N; contacts, walls, gravity,
 * external and boundary forces), component d < dim; zeros before the first evaluation. */
const double *dem_forces(const dem_scene *s, int d);
/* VTK XML unstructured grids (.vtu) for ParaView, written whole. Particles: one vertex cell per
 * particle with point data id (1-based), radius, velocity, angular_velocity, force (3-vectors,
 * z = 0 in 2D), mass, material (1-based), angle (2D with rotations), clump (in a scene with
 * clumps: the clump id, 1-based, 0 for a grain of no clump). Contacts: a line per contact
 * from i's centre to j's (its image across a periodic boundary) or to the contact point on a wall,
 * cell data i, j (walls: minus the wall id), fn, ft, overlap, normal, force (on i),
 * normal_force, tangential_force (0 for walls, which report the normal force only). Walls: each
 * active wall's plane clipped to the box (a line in 2D, a polygon in 3D) with id, normal, force. */
core_status dem_vtk_particles(const dem_scene *s, const char *path, core_error *err);
core_status dem_vtk_contacts(dem_scene *s, const char *path, core_error *err);
core_status dem_vtk_walls(const dem_scene *s, const char *path, core_error *err);
/* One vertex per clump at its centre of mass: id (1-based, the particles' "clump" array), mass,
 * velocity, angular_velocity, angular_momentum, orientation (2D: the angle; 3D: the quaternion
 * w, x, y, z of the principal frame), inertia (principal moments), members and first_member
 * (the particle id of its first member). */
core_status dem_vtk_clumps(const dem_scene *s, const char *path, core_error *err);

/* ---- LAMMPS data and dump files (lammps.c, lammps_write.c) --------------------------------- *
 * Data files in atom_style sphere (LIGGGHTS: granular): Atoms "id type diameter density x y z
 * [ix iy iz]", Velocities "id vx vy vz wx wy wz". The density column is the material's density
 * (kg/m^3); LAMMPS's mass rule density 4/3 pi r^3 is grainlab's for spheres and for 2D disks
 * of thickness 0. Atom type k is material k - 1 unless a map is given. */
typedef struct dem_lammps_data {
    char *path;            /* for messages */
    char title[256];       /* the first line */
    size_t n;              /* atoms, sorted by id */
    int ntypes;
    double lo[3], hi[3];   /* xlo xhi, ylo yhi, zlo zhi */
    int has_velocities;
    int flat;              /* every z, vz, wx, wy is exactly 0 and zlo < 0 < zhi (a 2D file) */
    long long *id;
    int *type;
    double *radius, *density;
    double *x[3], *v[3], *w[3];  /* x as in the file */
    int *image[3];         /* image flags (0 when the file has none) */
    long *line;            /* the Atoms line of each atom */
} dem_lammps_data;

/* Parses the file strictly (every malformed line is an error "path:line: problem"); nothing of it
 * depends on a scene. Free with dem_lammps_free (also after a failure). */
core_status dem_lammps_read(const char *path, dem_lammps_data *out, core_error *err);
void dem_lammps_free(dem_lammps_data *d);

typedef enum dem_lammps_density {
    DEM_LAMMPS_DENSITY_STRICT,   /* the file's density must be the material's (1e-9 relative) */
    DEM_LAMMPS_DENSITY_FILE,     /* a copy of the material per distinct file density */
    DEM_LAMMPS_DENSITY_MATERIAL  /* the material's density; the file's is ignored */
} dem_lammps_density;

typedef struct dem_lammps_type {
    int mapped;                  /* 0: an atom of this type is an error */
    dem_material material;
    dem_lammps_density density;
    unsigned flags;              /* DEM_FIXED: the type's atoms are fixed particles */
} dem_lammps_type;

/* Adds every atom of d to s (all or nothing: on failure the scene is as before). types[t - 1]
 * describes atom type t; type_material[t - 1] receives the material index that carries the
 * type's own material (-1 when no atom used it). Positions outside the box are errors, or wrapped
 * on periodic axes; a 2D scene needs z = vz = wx = wy = 0. *first: index of the first atom. */
core_status dem_lammps_add(dem_scene *s, const dem_lammps_data *d, const dem_lammps_type *types,
                           int *type_material, size_t *first, core_error *err);

typedef struct dem_lammps_write_def {
    const int *type_of_material; /* [dem_material_count]: atom type, or 0 if unmapped; NULL:
                                  * material index + 1 */
    int ntypes;                  /* "atom types" in the header; 0: the largest type written */
    const char *title;           /* data file: the first line; NULL: a default */
    int append;                  /* dump: append a frame instead of writing a new file */
} dem_lammps_write_def;

/* A data file, written whole (temporary file + rename). A scene with clumps is written in
 * atom_style hybrid sphere molecular, Atoms "id type x y z diameter density mol ix iy iz", for
 * LAMMPS's fix rigid/small molecule: mol is the clump id (1-based) of a member of a clump of two
 * or more members, 0 for a grain of no clump and for a clump of one sphere (LAMMPS refuses a
 * rigid body of one particle). */
core_status dem_write_lammps_data(const dem_scene *s, const char *path,
                                  const dem_lammps_write_def *def, core_error *err);
/* One `dump custom` frame (id type radius mass x y z vx vy vz fx fy fz omegax omegay omegaz; a
 * scene with clumps adds mol after id, as in its data file): a new file written whole, or
 * appended; an append that fails is cut back to the old length. */
core_status dem_write_lammps_dump(const dem_scene *s, const char *path,
                                  const dem_lammps_write_def *def, core_error *err);

int dem_material_count(const dem_scene *s);
const dem_material *dem_material_get(const dem_scene *s, int index); /* NULL if out of range */

/* ---- checkpoints (checkpoint.c, checkpoint_save.c) ----------------------------------------- *
 * The whole state a run continues from, laid out by particle id (core/checkpoint.h container,
 * engine kind "dem"): run N + M steps, or N, save, load (in another process, with another thread
 * count), M: the same bits. Boundary conditions are stored (edges, pressure, the minimal-boundary
 * penalty and its integral, springs, ties, spins, the step of the last update) and an update
 * callback's kind and ctx (dem_boundary_def.kind, save_ctx), never the callback itself; an update
 * without a kind is refused. version: the grainlab version recorded in the file. */
core_status dem_save(const dem_scene *s, const char *path, const char *version, core_error *err);

/* Re-attaches a saved boundary update on load: `restore` reads what save_ctx wrote (sec is
 * positioned there and must be read to the end of it) and sets def->update, ctx, free_ctx, kind
 * and save_ctx; the rest of *def is the loaded definition. On failure it frees what it made. */
typedef struct dem_boundary_restorer {
    const char *kind;
    core_status (*restore)(struct ckpt_section *sec, const dem_scene *s, dem_boundary_def *def,
                           core_error *err);
} dem_boundary_restorer;
/* A new scene from a file; on any error nothing is returned (*out = NULL). A file whose boundary
 * is rebuilt by an update of another kind than restorer's (or restorer NULL) is refused. */
core_status dem_load_with(const char *path, const dem_boundary_restorer *restorer, dem_scene **out,
                          core_error *err);
/* dem_load_with without a restorer. */
core_status dem_load(const char *path, dem_scene **out, core_error *err);

/* ---- particles in and out during a run (flow.c) --------------------------------------------- *
 * Inserters add particles in a region (a box, or a disk/ball) at a rate or up to a count or a
 * mass, with a size distribution and a velocity, at positions drawn from the inserter's own
 * random stream (core/rng.h; serial, so the same seed gives the same bits for any thread count)
 * and never overlapping a particle or a wall: each particle gets `attempts` positions; one that
 * finds no free place is skipped and counted. Outflows remove the particles whose centre enters a
 * box (fixed particles excepted), or that leave the domain through an open side (a side that is
 * not periodic; without an outflow on it, a particle leaving the domain stops the run, as LAMMPS's
 * "lost atoms"). Removed particles are counted, with their mass, per outflow. Ids (indices) of
 * the particles after a removed one shift down by one; dem_tags gives each particle a number that
 * never changes (the index it had when the first inserter or outflow was added, or the order of
 * its creation after that). Both act between steps; a scene without them does no extra work. Not
 * distributed: a run on more than one rank is refused. */
typedef enum dem_size_law {
    DEM_SIZE_CONSTANT, /* radius r0 */
    DEM_SIZE_UNIFORM,  /* radius uniform in [r0, r1] */
    DEM_SIZE_DISCRETE  /* radii[k] with probability weights[k] / sum(weights) */
} dem_size_law;

typedef struct dem_inserter_def {
    int ball; /* 0: the box [lo, hi]; 1: the disk (2D) or ball (3D) center, extent */
    double lo[3], hi[3];
    double center[3], extent;
    double rate; /* particles per second (0: everything due at the first event) */
    long count;  /* total to insert (< 0: no limit; needs a rate or a mass) */
    double mass; /* total mass to insert, kg (<= 0: no limit): stops once reached */
    dem_size_law size;
    double r0, r1;
    size_t nsizes; /* DISCRETE: radii and weights (copied) */
    const double *radii, *weights;
    double velocity[3]; /* each particle: velocity + spread * uniform(-1, 1) per component */
    double spread;
    int material;
    unsigned long long seed;
    long every;   /* steps between insertion events (>= 1) */
    int attempts; /* positions tried per particle (>= 1) */
} dem_inserter_def;

/* box of zero size, rate 0, count -1, no mass limit, constant radius 0, every 1, 50 attempts */
dem_inserter_def dem_default_inserter_def(void);
/* The inserter id (>= 0), or -1 with err filled. Its first event is at the next step boundary
 * (the start of the next run); a rate counts from the scene's time now. */
int dem_add_inserter(dem_scene *s, const dem_inserter_def *def, core_error *err);

typedef struct dem_outflow_def {
    int side; /* -1: the box [lo, hi]; else 2 axis + (0 lower, 1 upper side) */
    double lo[3], hi[3];
} dem_outflow_def;
int dem_add_outflow(dem_scene *s, const dem_outflow_def *def, core_error *err);

typedef struct dem_flow_counts {
    long count;   /* inserted (inserters) or removed (outflows) so far */
    double mass;  /* their mass, kg */
    long skipped; /* inserters: particles due that found no free place */
    long events;  /* inserters: insertion events that had particles due */
} dem_flow_counts;
int dem_inserter_count(const dem_scene *s);
int dem_outflow_count(const dem_scene *s);
core_status dem_inserter_counts(const dem_scene *s, int id, dem_flow_counts *out, core_error *err);
core_status dem_outflow_counts(const dem_scene *s, int id, dem_flow_counts *out, core_error *err);
/* Stable particle numbers (0-based), NULL until the first inserter or outflow. */
const double *dem_tags(const dem_scene *s);

#endif
