/* grainlab MPM: the material point method in 2D (plane strain) on a uniform background grid.
 * Physics: Bardenhagen, Brackbill & Sulsky (1998), Sec. 2: lumped mass (Eqs. 5-6), internal
 * force (Eqs. 7-8), grid momentum (Eq. 9), point update (Eqs. 10-11), linear tensor-product
 * shape functions. The single centre-of-mass velocity field is the "noslip" contact model; the
 * "friction" model adds per-grain nodal fields compared with it (Sec. 3, Eqs. 12-24).
 *
 * Usage: fill an mpm_scene_def from mpm_default_scene_def(), create the scene, add materials and
 * grains, then call mpm_run. Every call that can fail returns a core_status and explains itself
 * in a core_error. Nothing here knows about Lua. */
#ifndef GRAINLAB_MPM_H
#define GRAINLAB_MPM_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"

typedef struct mpm_scene mpm_scene;

/* ---- scene --------------------------------------------------------------------------------- */
/* A rigid wall acts on the grid nodes on and beyond it, on the centre-of-mass field and on every
 * grain's own field, relative to the wall's velocity. */
typedef enum mpm_wall {
    MPM_WALL_NOSLIP,  /* the wall's velocity (default; zero for a fixed wall) */
    MPM_WALL_SLIP,    /* the wall's normal velocity, free tangential motion, pulling as well */
    MPM_WALL_NONE,    /* no condition: a point reaching the edge stops the run */
    MPM_WALL_FRICTION /* the grain contact rule against a rigid body (Eqs. 12-23): material moving
                       * into the wall takes its normal velocity and loses tangential velocity up
                       * to mu times that correction; material moving away is free */
} mpm_wall;

/* Shape functions of the transfers. Linear: the paper's tensor-product hat functions, 4 nodes per
 * point; the gradient jumps when a point crosses a cell edge ("cell-crossing noise").
 * Quadratic B-spline: 9 nodes per point, C1 gradients, one ghost node layer beyond each wall. */
typedef enum mpm_shape_fn { MPM_SHAPE_LINEAR, MPM_SHAPE_BSPLINE } mpm_shape_fn;

enum { MPM_LEFT, MPM_RIGHT, MPM_BOTTOM, MPM_TOP };

typedef enum mpm_update {
    /* Update stress last (the paper's step order, Sec. 2 steps 1-3): the velocity gradient comes
     * from v_i^{n+1} of Eq. 9, which holds f_i / m_i and so blows up at nearly empty nodes when a
     * grain crosses cells (measured: a spinning elastic disk, omega R = 1 m/s, 10 cells across,
     * inverts a point at step 75). */
    MPM_USL,
    /* Modified USL (default): after Eq. 11 the new point momenta are mapped back to the grid
     * (Eq. 5 with v_p^{n+1}) and the velocity gradient is taken from that field, a mass-weighted
     * mean that stays bounded at any nodal mass. Positions and velocities are as in USL. */
    MPM_MUSL,
    /* Update stress first: the velocity gradient from v_i^n of the P2G momenta (walls and, with
     * friction, the contact rule applied to them), the stress updated, then the internal force
     * from the new stress and the momentum update (Eq. 9) as in USL. Measured against MUSL: the
     * same bar period, the incline (pi/6, 0.5, h = R/8) -0.85% against -1.76%, but two disks
     * meeting head-on (frictionless contact) end with 1.66 times the initial energy (MUSL 0.99):
     * the contact rule on v_i^n decides contacts one step apart from the momentum update's. MUSL
     * stays the default. */
    MPM_USF
} mpm_update;

typedef struct mpm_scene_def {
    int cells[2];         /* nx, ny >= 1 */
    double origin[2];     /* lower-left corner, m */
    double size[2];       /* Lx, Ly, m */
    bool periodic[2];     /* a periodic axis has no walls and wraps points */
    double gravity[2];    /* m/s^2 */
    mpm_wall walls[4];    /* MPM_LEFT, MPM_RIGHT, MPM_BOTTOM, MPM_TOP (ignored on periodic axes) */
    double wall_mu[4];    /* Coulomb coefficient of a MPM_WALL_FRICTION wall */
    double wall_velocity[4][2]; /* a moving wall's velocity (tangential part for friction/slip) */
    mpm_shape_fn shape;
    /* Gap test of friction walls and planes against contact "at a distance": a node takes the
     * wall rule only when the centroid of its material (weighted by the shape functions) lies
     * within wall_gap cells of where a gap-free layer of material would put it; 0 = off (every
     * node behind the wall is in contact whenever material moves into it). */
    double wall_gap;
    mpm_update update;
    double pic;           /* PIC fraction of the velocity update in [0, 1]: 0 = pure FLIP (Eq. 11,
                           * default), 1 = pure PIC (v_p = sum_i N_i v_i^{n+1}) */
} mpm_scene_def;

mpm_scene_def mpm_default_scene_def(void);
core_status mpm_create(const mpm_scene_def *def, mpm_scene **out, core_error *err);
void mpm_destroy(mpm_scene *s);
const mpm_scene_def *mpm_def(const mpm_scene *s);
/* Cell sizes hx, hy. */
void mpm_cell_size(const mpm_scene *s, double h[2]);

/* ---- materials ------------------------------------------------------------------------------
 * Every model is Hencky (logarithmic-strain) hyperelastic in plane strain: Kirchhoff stress
 * tau = K ln(J) I + 2 G dev(ln V_e), with V_e the elastic left stretch carried as b_e = V_e^2.
 * It is objective under the large rotations of rolling and spinning grains (a small-strain rate
 * form is not, and Jaumann-rate hypoelasticity creates or loses energy in closed cycles), it has
 * a stored energy for the energy balance, and von Mises radial return is exact in log-strain
 * space (Simo 1992) with the small-strain formula. The plastic models return in the principal
 * log strains of the trial b_e (the zz stretch the third, plane strain); the two granular
 * continuum models (src/mpm/continuum.c) model the granular material itself rather than a grain:
 * - Drucker-Prager: sqrt(J2) <= eta p + xi c (p = -tr(tau)/3 compression positive), plastic
 *   potential sqrt(J2) - etabar p (non-associated: dilatancy angle psi <= friction angle phi),
 *   eta, xi, etabar matched to Mohr-Coulomb in plane strain at the limit state: a plane-strain
 *   element flowing plastically carries exactly t = P sin phi + c cos phi (t = (s1 - s3) / 2,
 *   P = -(s1 + s3) / 2 in plane) with the dilation rate of Mohr-Coulomb's psi (mpm_dp_match).
 *   A trial state beyond the cone's apex (tension beyond p = -xi c / eta, any tension for c = 0)
 *   returns to the apex: the tension cut-off.
 * - mu(I) (Jop, Forterre & Pouliquen 2006, in MPM after Dunatunga & Kamrin 2015): sqrt(J2) =
 *   mu(I) p while flowing, mu(I) = mu_s + (mu_2 - mu_s) / (I_0 / I + 1), I = gdot_p d /
 *   sqrt(p / rho_s) with gdot_p the plastic shear rate, found per step in closed form (a
 *   quadratic); elastic below mu_s p. The plastic flow is isochoric and the pressure follows the
 *   density, p = -K ln J (density = the close-packed density rho_c at J = 1); a point dilated to
 *   J >= 1 (rho <= rho_c) is disconnected: stress-free, its elastic strain reset. */
typedef enum mpm_model {
    MPM_ELASTIC,
    MPM_VONMISES,       /* J2 plasticity, linear isotropic hardening: q = yield + hardening eps_p */
    MPM_DRUCKER_PRAGER, /* pressure-dependent yield, non-associated, tension cut-off */
    MPM_MU_I            /* the mu(I) rheology with a disconnected (stress-free) state */
} mpm_model;

typedef struct mpm_material {
    mpm_model model;
    double density;    /* kg/m^3 (mu_i: the close-packed bulk density rho_c) */
    double shear;      /* G, Pa */
    double bulk;       /* K, Pa */
    double yield;      /* von Mises yield stress (equivalent, q = sqrt(3/2)|s|), Pa */
    double hardening;  /* H = d q / d eps_p, Pa (>= 0) */
    /* drucker_prager */
    double friction;   /* phi, degrees in (0, 90) */
    double dilatancy;  /* psi, degrees in [0, phi] */
    double cohesion;   /* c, Pa >= 0 */
    /* mu_i */
    double mu_s, mu_2; /* 0 < mu_s < mu_2 */
    double i0;         /* I_0 > 0 */
    double grain_diameter; /* d, m */
    double grain_density;  /* rho_s >= density, kg/m^3 */
    /* derived by mpm_add_material (mpm_material_prepare), not input: drucker_prager's eta, xi
     * and etabar */
    double dp[3];
} mpm_material;

/* Drucker-Prager's eta, xi and etabar for friction angle phi and dilatancy psi (degrees): the
 * plane-strain match at the limit state, etabar = sqrt(3) sin psi / sqrt(3 + sin^2 psi),
 * A = sqrt(1 - etabar^2 / 3), eta = sin phi / (A + etabar sin phi / 3), xi = cos phi (1 - eta
 * etabar / 3) / A. For psi = phi it is the usual associated match eta = 3 tan phi / sqrt(9 + 12
 * tan^2 phi), xi = 3 / sqrt(9 + 12 tan^2 phi); for psi = 0, eta = sin phi and xi = cos phi. */
void mpm_dp_match(double phi, double psi, double *eta, double *xi, double *etabar);
/* Fills the derived fields (dp) of a material from its inputs. */
void mpm_material_prepare(mpm_material *m);

mpm_material mpm_default_material(void); /* elastic, the paper's incline disk: 3000, 2.5 MPa, 10 MPa */
/* Checks a material (positive density and moduli, yield > 0 for von Mises, the angles and
 * friction coefficients of the continuum models). */
core_status mpm_check_material(const mpm_material *m, core_error *err);
/* Returns the material index (>= 0) or -1 with err filled. */
int mpm_add_material(mpm_scene *s, const mpm_material *m, core_error *err);
/* The P-wave speed sqrt((K + 4G/3) / rho). */
double mpm_wave_speed(const mpm_material *m);

/* One constitutive update of a point (step 3 of Sec. 2): the incremental deformation gradient
 * f = I + dt L (row-major xx, xy, yx, yy) updates b_e (xx, xy, yy, zz) and eps_p; J is the total
 * det F after the step. Writes the Cauchy stress (xx, yy, xy, zz). Returns false when the step
 * inverts the point (det f <= 0). Public so that C tests can drive a single point. The rate
 * dependent mu_i model takes the step's duration from mpm_material_step; here (dt = 0) it is
 * the quasi-static limit I -> 0, a yield cone at mu_s. */
bool mpm_material_update(const mpm_material *m, const double f[4], double be[4], double *eps_p,
                         double J, double sigma[4]);
/* The same over a step of dt seconds; *rate (may be NULL) receives the plastic shear rate
 * gdot_p = dgamma_p / dt of the continuum models (0 for the others). */
bool mpm_material_step(const mpm_material *m, const double f[4], double dt, double be[4],
                       double *eps_p, double *rate, double J, double sigma[4]);
/* Stored (Hencky) energy per reference volume of b_e, J/m^3. */
double mpm_elastic_energy_density(const mpm_material *m, const double be[4]);

/* ---- grains ---------------------------------------------------------------------------------- */
typedef enum mpm_shape { MPM_DISK, MPM_RECT, MPM_POLYGON } mpm_shape;

typedef struct mpm_grain_def {
    mpm_shape shape;
    double center[2], radius; /* MPM_DISK */
    double lo[2], hi[2];      /* MPM_RECT */
    const double *vertices;   /* MPM_POLYGON: x0, y0, x1, y1, ... (a simple polygon, either
                               * orientation; read during mpm_add_grain only) */
    int nvertices;
    int material;
    int points_per_cell;      /* n: the cell is split into n x n sub-cells, a point at the centre
                               * of each sub-cell inside the shape (paper: n = 2 or 3) */
    double velocity[2];       /* initial rigid motion: v = velocity + omega x (x - centroid) */
    double omega;
    bool clip;                /* keep only the points inside the grid (grains cut by an edge) */
} mpm_grain_def;

mpm_grain_def mpm_default_grain_def(void);
/* Fills the shape with points; returns the grain index (>= 0) or -1 with err filled. The shape
 * must lie inside the grid on axes that are not periodic. */
long mpm_add_grain(mpm_scene *s, const mpm_grain_def *g, core_error *err);
size_t mpm_grain_count(const mpm_scene *s);
size_t mpm_point_count(const mpm_scene *s);
/* The deepest overlap of grain id's shape with an earlier grain's (disks: r1 + r2 - distance,
 * rectangles and mixed pairs: the smaller side of the bounding boxes' intersection; minimum
 * image on periodic axes). Returns the depth (0: none) and that grain in *other. */
double mpm_grain_overlap(const mpm_scene *s, size_t id, size_t *other);

/* Initial stress of a grain at rest under the scene's gravity: the static pressure with
 * grad p = rho g (the paper's incline), p = 0 at the grain's highest point against g. Sets each
 * point's deformation and elastic stretch to the isotropic in-plane compression that gives
 * sigma_xx = sigma_yy = -p in the grain's material law. */
core_status mpm_hydrostatic(mpm_scene *s, size_t grain, core_error *err);

/* A grain with prescribed velocity moves rigidly at v: every node its points touch takes v (the
 * centre-of-mass field, and its own field with friction), so neighbours meet a rigid body that
 * drives them through the contact rule. Used by the shear test for the edge grains. */
core_status mpm_prescribe(mpm_scene *s, size_t grain, const double v[2], core_error *err);

/* A rigid half-space ("plane") with any normal, for walls not aligned with the grid: the nodes
 * with (x_i - point) . normal <= 0 belong to it (a staircase on the grid) and take the wall rule
 * with the plane's exact normal. normal points out of the body into the material. */
typedef struct mpm_plane_def {
    double point[2], normal[2];
    mpm_wall kind;       /* noslip, slip or friction */
    double mu;
    double velocity[2];
} mpm_plane_def;
#define MPM_MAX_PLANES 4
core_status mpm_add_plane(mpm_scene *s, const mpm_plane_def *p, core_error *err);

/* ---- contact ------------------------------------------------------------------------------- */
/* ---- contact --------------------------------------------------------------------------------
 * "friction" (Sec. 3): every grain also carries its own nodal field v_i^g (mass Eq. 16, momentum
 * and force over its own points), stored sparsely: one entry per (grain, node) pair the grain's
 * points touch, rebuilt every step at a cost linear in the points. At a node touched by two or
 * more grains, after the grid momentum update (Eq. 9), each grain's v_i^g is compared with the
 * centre-of-mass v_i: if it approaches (Eq. 12, (v_i^g - v_i) . n_i^g > 0) its normal velocity is
 * set to the centre-of-mass one (Eq. 14) and its tangential relative velocity is removed up to
 * mu times the normal correction (Coulomb, Eqs. 18-23). The P2G velocities are not corrected;
 * with MUSL the remapped grain fields are corrected again at the pairs found in contact at the
 * momentum update (re-testing Eq. 12 there switches contact on and off every other step and
 * creates energy). Each grain's points move with, and take their FLIP increment and strain rate
 * from, their own grain's field at shared nodes and the centre-of-mass field elsewhere; an
 * isolated grain therefore evolves exactly as with "noslip". Normal n_i^g: the gradient of the
 * grain's mass field with the linear shape functions (sum_p m_p G_pi over the grain) taken
 * against the gradient of everything else at the node, so two grains' normals are exactly
 * opposite and momentum is conserved; the paper (Eq. 24) uses the grain's own
 * quadratic-B-spline density gradient (not implemented). */
typedef enum mpm_contact_model {
    MPM_CONTACT_NOSLIP,   /* the single centre-of-mass field (Sec. 2, the basic algorithm) */
    MPM_CONTACT_FRICTION  /* per-grain fields with Coulomb friction (Eqs. 12-24) */
} mpm_contact_model;

/* Selects "noslip". MPM_CONTACT_FRICTION is refused here: it needs mu (mpm_set_friction). */
core_status mpm_set_contact(mpm_scene *s, mpm_contact_model model, core_error *err);
/* Selects "friction" with the Coulomb coefficient mu >= 0 (mu = 0: frictionless). */
core_status mpm_set_friction(mpm_scene *s, double mu, core_error *err);

/* Grain normals n_i^g at a shared node. */
typedef enum mpm_normals {
    /* 2 g - g_all with quadratic-B-spline gradients g of the grains' mass fields (default): the
     * grain's gradient against that of everything else, so two grains' normals are exactly
     * opposite and the corrections conserve momentum */
    MPM_NORMALS_AVERAGED,
    /* Eq. 24: each grain's own quadratic-B-spline density gradient */
    MPM_NORMALS_OWN,
    /* 2 g - g_all with the gradients of the linear shape functions */
    MPM_NORMALS_LINEAR
} mpm_normals;

typedef struct mpm_contact_options {
    mpm_normals normals;
    /* Separation check against contact "at a distance": a shared node counts as a contact only
     * when the grains' nodal volumes sum_g sum_p N_ip V_p fill at least this fraction of the
     * node's volume (0 = off; a node inside a gap-free region holds about one cell volume). */
    double separation;
    /* Cap on the contact-imposed strain: a correction dv at a node is scaled so that
     * |dv| dt / h <= strain_cap (0 = off). */
    double strain_cap;
    /* Give back, at each node, the momentum the corrections changed (a common velocity shift of
     * the corrected grains there): non-zero with three or more grains at a node, with 'own'
     * normals, or with the strain cap. Default true. */
    bool conserve;
} mpm_contact_options;
mpm_contact_options mpm_default_contact_options(void);
core_status mpm_set_contact_options(mpm_scene *s, const mpm_contact_options *o, core_error *err);
mpm_contact_options mpm_get_contact_options(const mpm_scene *s);
mpm_contact_model mpm_contact(const mpm_scene *s);
double mpm_friction(const mpm_scene *s); /* mu, 0 for noslip */

/* ---- points (bulk access, in point order) --------------------------------------------------- */
typedef struct mpm_points {
    const double *x, *y, *vx, *vy, *mass, *volume0;
    const double *F[4];      /* total deformation gradient, xx, xy, yx, yy */
    const double *sigma[4];  /* Cauchy stress xx, yy, xy, zz (tension positive) */
    const double *eps_p;     /* equivalent plastic strain */
    const double *ux, *uy;   /* displacement since the grain was added (not wrapped) */
    const int *grain, *material;
    /* the plastic shear rate gdot_p of each point's last step (1/s; 0 for elastic and von Mises
     * materials), NULL when the scene has no drucker_prager or mu_i material */
    const double *rate;
} mpm_points;
void mpm_get_points(const mpm_scene *s, mpm_points *p);
/* Sets every point's velocity (arrays of mpm_point_count values, all finite). */
core_status mpm_set_velocities(mpm_scene *s, const double *vx, const double *vy, core_error *err);

/* ---- time stepping ----------------------------------------------------------------------- */
typedef struct mpm_timestep {
    double wave_speed;  /* largest P-wave speed of the materials in use */
    double max_speed;   /* fastest point */
    double limit;       /* CFL bound min(hx, hy) / (c + max|v|): no dt above it without force */
    double dt_auto;     /* cfl * limit */
} mpm_timestep;

#define MPM_DEFAULT_CFL 0.4
core_status mpm_timestep_info(const mpm_scene *s, double cfl, mpm_timestep *out, core_error *err);

typedef struct mpm_run_def {
    long steps;        /* at most this many steps (required >= 0) */
    double time_end;   /* < 0: none; else stop once the scene time reaches it (the last step is
                        * shortened to land on it) */
    double dt;         /* > 0: fixed step; 0: automatic, cfl * limit re-evaluated every step */
    double cfl;        /* for dt = 0, in (0, 1] */
} mpm_run_def;

mpm_run_def mpm_default_run_def(void);
/* Advances the scene; *done = steps taken. Stops between steps on Ctrl-C (CORE_ERR_INTERRUPTED,
 * scene intact) and on instability (CORE_ERR_UNSTABLE naming the step, the point and its grain:
 * non-finite values, an inverted point, a point leaving the grid). */
core_status mpm_run(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err);
double mpm_time(const mpm_scene *s);
long mpm_steps_done(const mpm_scene *s);

/* Wall time of each stage of the step, summed over the steps run since the scene was created or
 * loaded (not stored in checkpoints): the stencil, particle-to-grid (with the grain fields),
 * the contact normals, the grid update, the grid contact rule, grid-to-particle, the MUSL remap,
 * the material update and the end-of-step checks (with contact "friction" the stencil is taken
 * inside p2g, point by point, and its entry stays 0). Read on thread 0 after each stage; most end at
 * a barrier, so their time includes the wait for the slowest thread (p2g and normals share one). */
enum { MPM_NSTAGES = 9 };
extern const char *const mpm_stage_names[MPM_NSTAGES];
void mpm_timings(const mpm_scene *s, double seconds[MPM_NSTAGES], long *steps);

/* ---- measurements -------------------------------------------------------------------------- */
typedef struct mpm_energy {
    double kinetic;    /* sum 1/2 m v^2 (per unit depth: J/m) */
    double elastic;    /* sum V0 W(b_e), Hencky energy */
    double plastic;    /* sum V0 (yield eps_p + H eps_p^2 / 2): the plastic work */
    double potential;  /* -sum m g . x */
    double total;
} mpm_energy;
void mpm_measure_energy(const mpm_scene *s, mpm_energy *e);

typedef struct mpm_grain_info {
    double mass;
    double center[2];          /* centre of mass (minimum image on periodic axes) */
    double velocity[2];
    double angular_momentum;   /* about the centre of mass, z component */
    double inertia;            /* sum m |x - c|^2 */
    double omega;              /* angular_momentum / inertia */
    size_t points;
} mpm_grain_info;
core_status mpm_grain(const mpm_scene *s, size_t id, mpm_grain_info *out, core_error *err);

/* Cell fields: the mass-weighted mean of a point quantity over the points in each cell (row-major,
 * nx * ny values; NAN in empty cells), and the mass per cell. */
typedef enum mpm_field_kind {
    MPM_FIELD_VX, MPM_FIELD_VY, MPM_FIELD_SPEED, MPM_FIELD_UX, MPM_FIELD_UY, MPM_FIELD_UMAG,
    MPM_FIELD_SXX, MPM_FIELD_SYY, MPM_FIELD_SXY, MPM_FIELD_PRESSURE,
    MPM_FIELD_PSD,   /* principal stress difference sigma_1 - sigma_2 (in-plane) */
    MPM_FIELD_EPS_P, MPM_FIELD_GRAIN, MPM_FIELD_MASS,
    MPM_FIELD_RATE,     /* plastic shear rate gdot_p of the continuum models (0 elsewhere) */
    MPM_FIELD_INERTIAL, /* mu_i: the inertial number gdot_p d / sqrt(p / rho_s) of the last step
                         * (p = -tr(sigma) / 3; 0 where disconnected and for other models) */
    MPM_FIELD_MEAN_PRESSURE /* -(sxx + syy + szz) / 3: the continuum models' p (PRESSURE is the
                             * in-plane mean) */
} mpm_field_kind;
void mpm_field(const mpm_scene *s, mpm_field_kind kind, double *out);
/* Mass-weighted mean vertical displacement per column of cells (nx values; NAN if empty). */
void mpm_column_uy(const mpm_scene *s, double *out);
/* Average shear strain of the material: the least-squares slope d u_y / d x over all points,
 * mass-weighted (exact for a uniform simple shear u_y = gamma x). */
double mpm_shear_strain(const mpm_scene *s);

/* Total linear momentum and angular momentum about the origin. */
void mpm_measure_momentum(const mpm_scene *s, double p[2], double *lz);

/* ---- checkpoints (src/mpm/checkpoint.c) ----------------------------------------------------
 * mpm_save writes everything a bit-exact continuation needs into a grainlab checkpoint at path
 * (core/checkpoint.h: written whole through a temporary file and a rename); version is the
 * grainlab version recorded in its header. mpm_load reads one into a new scene (*out), refusing a
 * missing, truncated, corrupt, foreign (another engine's) or newer file with nothing allocated
 * left behind. Running the loaded scene gives the same bits as continuing the saved one. */
core_status mpm_save(const mpm_scene *s, const char *path, const char *version, core_error *err);
core_status mpm_load(const char *path, mpm_scene **out, core_error *err);

/* ---- output for other tools (mpm/vtk.c) ------------------------------------------------------ */
/* VTK XML for ParaView, written whole. Points (.vtu): one vertex per material point with point
 * data id (1-based), grain, material (1-based), mass, volume (V0 det F), velocity, displacement
 * (3-vectors, z = 0), stress and deformation_gradient (3 x 3 row-major, plane strain: the zz
 * stress, F_zz = 1), pressure (-(xx + yy)/2, as mpm_field), eps_p, and with drucker_prager or
 * mu_i materials rate and mean_pressure. Grid (.vti, nodes as points): point data mass and
 * velocity from a linear-shape transfer of the current points, cell data the mpm_field kinds named
 * as the Lua m:field names them (vx, vy, speed, ux, uy, displacement, sxx, syy, sxy, pressure,
 * psd, eps_p, grain, mass; rate, inertial, mean_pressure with those materials). */
core_status mpm_vtk_points(const mpm_scene *s, const char *path, core_error *err);
core_status mpm_vtk_grid(const mpm_scene *s, const char *path, core_error *err);

#endif
