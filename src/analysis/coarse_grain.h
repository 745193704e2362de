/* Coarse-graining: continuum fields from discrete particles and their contacts (Goldhirsch 2010;
 * Weinhart, Thornton, Luding & Bokhove 2012, "From discrete particles to continuum fields near a
 * boundary"; the kernels and field names of MercuryCG). Plain C over plain arrays: no engine,
 * no Lua. The bindings gather a DEM scene's particles and contacts, or an MPM scene's points.
 *
 * A kernel phi of width w, normalised over its support (integral 1 in 2D or 3D), turns particle
 * sums into fields at any point r:
 *   density          rho(r)   = sum_i m_i phi(r - x_i)
 *   momentum         p(r)     = sum_i m_i v_i phi(r - x_i),     velocity V = p / rho
 *   momentum flux    M(r)     = sum_i m_i v_i (x) v_i phi(r - x_i)
 *   kinetic stress   sk(r)    = M - rho V (x) V  (= sum_i m_i v'_i (x) v'_i phi, v' = v_i - V(r))
 *   contact stress   sc_ab(r) = sum_c b_a f_b psi_c(r),  psi_c(r) = int_0^1 phi(r - x_i + s b) ds
 * with, per contact c, f the force on particle i and b its branch vector: from the partner's
 * centre (its periodic image) to x_i, or from the contact point to x_i for a wall (Weinhart et al.
 * 2012: walls enter as boundary contacts whose line ends at the contact point, so that the
 * divergence of the stress away from walls balances the body force exactly, and the wall's force
 * appears as the boundary force density t(r) = sum_walls f phi(r - x_c)). Stresses are positive
 * in compression, as grainlab's DEM measures them: a static packing satisfies
 * d_a sigma_ab = rho g_b + t_b. The line integral psi is computed exactly (closed forms for both
 * kernels, the cut included). Every sum runs in the order of the items (particles, then
 * contacts), whatever the number of threads: the fields have the same bits on any count. */
#ifndef GRAINLAB_ANALYSIS_COARSE_GRAIN_H
#define GRAINLAB_ANALYSIS_COARSE_GRAIN_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"

typedef enum analysis_cg_kernel {
    /* phi = P exp(-r^2 / (2 w^2)) for r < cutoff (default 3 w), P normalising it over the cut
     * disk or ball (MercuryCG's Gauss) */
    ANALYSIS_CG_GAUSS,
    /* phi = P (1 - 6 x^2 + 8 x^3 - 3 x^4), x = r / w < 1: the cutoff is w (MercuryCG's Lucy) */
    ANALYSIS_CG_LUCY
} analysis_cg_kernel;

typedef struct analysis_cg_def {
    int dim; /* 2 or 3 */
    analysis_cg_kernel kernel;
    double width;        /* w > 0 */
    double cutoff;       /* Gauss: where phi is cut, in (0, 10 w]; 0 = 3 w. Lucy: unused */
    bool periodic[3];    /* periodic axes wrap the kernel across [lo, hi] */
    double lo[3], hi[3]; /* the period on periodic axes */
    double depth;        /* 2D: the fields per area are divided by it (> 0; 1 = per m) */
} analysis_cg_def;

analysis_cg_def analysis_cg_default_def(void); /* 2D Gauss, w 1, cutoff 3 w, depth 1 */
/* The kernel's reach (the cutoff) and its value at distance r (the normalised phi). */
double analysis_cg_reach(const analysis_cg_def *def);
double analysis_cg_phi(const analysis_cg_def *def, double r);
/* psi at the point d relative to x_i for the segment from x_i to x_i - b (dim components). */
double analysis_cg_psi(const analysis_cg_def *def, const double *d, const double *b);

/* What the particles bring; NULL arrays leave their channels out (zeros). */
typedef struct analysis_cg_particles {
    size_t n;
    const double *x[3]; /* positions (dim of them) */
    const double *v[3]; /* velocities (NULL: at rest) */
    const double *mass;
    const double *volume;  /* particle volume (2D: area): the volume fraction */
    const double *fabric;  /* dim x dim per particle: sum over its contacts of n (x) n */
    const double *disp[3]; /* displacements: the mass-weighted displacement field */
    const double *stress;  /* dim x dim per particle, row-major: a point's own stress times
                            * its volume (MPM points), compression positive */
} analysis_cg_particles;

/* Contacts: line from x_i (the particle's position) to x_i - b. */
typedef struct analysis_cg_contacts {
    size_t n;
    const long *i;             /* the particle that feels f (0-based) */
    const double *b[3];        /* branch vector, m */
    const double *f[3];        /* force on i, N */
    const unsigned char *wall; /* 1: a wall contact (its contact point x_i - b carries the
                                * boundary force density); NULL: none is */
} analysis_cg_contacts;

/* Channels of the sums at each evaluation point (analysis_cg_layout gives their offsets). */
enum {
    ANALYSIS_CG_DENSITY,  /* 1 */
    ANALYSIS_CG_MOMENTUM, /* dim */
    ANALYSIS_CG_FLUX,     /* dim x dim, row-major */
    ANALYSIS_CG_CONTACT,  /* dim x dim: sum_c b_a f_b psi_c */
    ANALYSIS_CG_TRACTION, /* dim: boundary force density of wall contacts */
    ANALYSIS_CG_VOLUME,   /* 1: volume (area) fraction */
    ANALYSIS_CG_FABRIC,   /* dim x dim: sum_i V_i F_i phi (divided by the volume fraction later) */
    ANALYSIS_CG_DISP,     /* dim: sum_i m_i u_i phi */
    ANALYSIS_CG_STRESS,   /* dim x dim: sum_i S_i phi (MPM points' own stress) */
    ANALYSIS_CG_NCHANNELS
};

typedef struct analysis_cg_layout {
    int dim;
    int offset[ANALYSIS_CG_NCHANNELS]; /* -1: channel absent */
    int ncomp[ANALYSIS_CG_NCHANNELS];
    int stride; /* doubles per evaluation point */
} analysis_cg_layout;

/* The channels the given inputs fill: those of the particles' non-NULL arrays; the contact
 * stress whenever c is given (even with no contacts: a layout fixed for time averages), the
 * traction when c->wall is given. */
void analysis_cg_layout_of(int dim, const analysis_cg_particles *p, const analysis_cg_contacts *c,
                           analysis_cg_layout *out);

/* The sums at npts points (pts[d][k]) into out (npts x layout->stride, overwritten), OpenMP over
 * the points. Depth (2D) divides the mass, momentum, flux, stress and traction channels. Refuses
 * a bad definition, non-finite input, and a periodic axis shorter than the kernel's reach. */
core_status analysis_cg_sums(const analysis_cg_def *def, const analysis_cg_particles *p,
                             const analysis_cg_contacts *c, const analysis_cg_layout *layout,
                             size_t npts, const double *const pts[3], double *out, core_error *err);

/* The cell centres of a regular grid of cells[0] x cells[1] (x cells[2]) cells over [lo, hi],
 * x fastest (row-major from the bottom row, as render_field takes them). pts[d] hold npts each. */
size_t analysis_cg_grid_count(int dim, const int cells[3]);
void analysis_cg_grid_points(int dim, const int cells[3], const double lo[3], const double hi[3],
                             double *const pts[3]);

/* ---- derived fields -------------------------------------------------------------------------- *
 * From sums (instantaneous, or their time averages): velocity, kinetic and total stress,
 * granular temperature, volume-weighted fabric, displacement. NaN where the density (for
 * velocity, kinetic stress, temperature, displacement) or the volume fraction (fabric) is 0.
 * Total stress = contact + kinetic (DEM) or the points' stress + kinetic (MPM). */
typedef struct analysis_cg_fields {
    size_t n;
    int dim;
    double *density;         /* n */
    double *velocity[3];     /* n each */
    double *kinetic;         /* n x dim x dim */
    double *contact;         /* n x dim x dim, NULL without contacts */
    double *internal;        /* n x dim x dim, NULL without point stresses */
    double *stress;          /* total */
    double *temperature;     /* n: tr(kinetic) / (dim rho) */
    double *traction;        /* n x dim, NULL without wall contacts channel */
    double *volume_fraction; /* n, NULL without volumes */
    double *fabric;          /* n x dim x dim, NULL without fabric: sum V F phi / sum V phi */
    double *displacement;    /* n x dim, NULL without displacements */
} analysis_cg_fields;

core_status analysis_cg_fields_alloc(const analysis_cg_layout *l, size_t n, analysis_cg_fields *f,
                                     core_error *err);
void analysis_cg_fields_free(analysis_cg_fields *f);
void analysis_cg_derive(const analysis_cg_layout *l, size_t n, const double *sums,
                        analysis_cg_fields *f);

/* Invariants of a dim x dim tensor (row-major), from its symmetric part: pressure tr / dim,
 * principal values (descending; the first is the most compressive), the principal stress
 * difference (largest minus smallest) and the major principal direction (unit vector of the
 * first, its largest component positive; 2D angle = atan2(dy, dx) in (-pi/2, pi/2]). */
typedef struct analysis_cg_invariants {
    double pressure, psd, principal[3], direction[3], angle;
} analysis_cg_invariants;
void analysis_cg_invariants_of(int dim, const double *t, analysis_cg_invariants *out);

/* ---- output ------------------------------------------------------------------------------------
 * Named per-point arrays for the writers: ncomp 1 (scalar), dim (vector, written with 3
 * components in VTK) or dim x dim (tensor, 9 in VTK). */
typedef struct analysis_cg_column {
    const char *name;
    int ncomp;
    const double *values; /* n x ncomp */
} analysis_cg_column;

/* VTK ImageData (.vti) of the cell-centred grid: points at the cell centres, the columns as point
 * data, TimeValue; written whole. */
core_status analysis_cg_write_vti(const char *path, int dim, const int cells[3], const double lo[3],
                                  const double hi[3], size_t ncol, const analysis_cg_column *cols,
                                  double time, core_error *err);
/* CSV: a header line (x,y[,z], then name or name_xx, name_xy, ... per column) and one line per
 * point, numbers with 17 significant digits; written whole. */
core_status analysis_cg_write_csv(const char *path, int dim, size_t n, const double *const pts[3],
                                  size_t ncol, const analysis_cg_column *cols, core_error *err);

#endif
