/* grainlab analysis: the Delaunay-cell continuum of a 2D particle assembly (Padbidri Sec. 2.5,
 * 3.2; Bagi 1996, Satake 2004, Christoffersen et al. 1981). Plain C over plain arrays: no DEM,
 * no Lua. The triangulation is qhull's (reentrant libqhull_r, Debian libqhull-dev).
 *
 * A mesh is the Delaunay triangulation of the centres, with the sliver triangles that bridge
 * concave gaps of the outline peeled off (alpha rule below), and its counter-clockwise boundary
 * loop. The mesh keeps a copy of the positions it was built on: the reference configuration for
 * strains. Per cell (constant-strain triangle): displacement or velocity gradient from the linear
 * interpolation of its three particles' values, strain = its symmetric part, L_II; per particle
 * and per cell: Christoffersen's stress from contact forces. The boundary integral (Eq. 3.1)
 * gives the coarse gradient of the assembly, equal to the area-weighted sum of cell gradients.
 *
 * Tensors are 2x2, stored row-major as {xx, xy, yx, yy}; a gradient G[i][j] = d u_i / d x_j.
 * Stresses are positive in compression (as grainlab's DEM measures them). */
#ifndef GRAINLAB_ANALYSIS_H
#define GRAINLAB_ANALYSIS_H

#include <stddef.h>

#include "core/error.h"

typedef struct analysis_mesh {
    size_t np;         /* particles given (vertices are 0 .. np-1) */
    size_t ncells;     /* triangles kept */
    long *tri;         /* 3 per cell, counter-clockwise in the build configuration */
    size_t nloop;      /* boundary loop: particle indices, counter-clockwise, not repeated */
    long *loop;
    size_t ndelaunay;  /* triangles of the full Delaunay triangulation */
    size_t npeeled;    /* of them removed by the alpha rule (flat ones included) */
    double area;       /* sum of the kept cells' areas in the build configuration */
    double *x0, *y0;   /* the build configuration (copies) */
} analysis_mesh;

#define ANALYSIS_FLAT 1e-12 /* relative flatness of a triangle peeled whatever alpha */

typedef struct analysis_delaunay_def {
    /* Alpha rule: a triangle with one edge (a, b) on the boundary is peeled off while that edge
     * is longer than alpha (r_a + r_b) and its third particle is not on the boundary yet (so the
     * outline never pinches and no particle ever leaves the mesh: every particle stays a vertex).
     * 0 = keep the convex hull. Whatever alpha, boundary triangles flat to rounding (twice
     * the area <= ANALYSIS_FLAT x the longest edge squared: centres in a row along a wall) are
     * peeled by the same rule, so every kept cell has a usable area. */
    double alpha;
    const double *radius; /* np radii; NULL: every radius is half the median Delaunay edge */
} analysis_delaunay_def;

analysis_delaunay_def analysis_default_delaunay_def(void); /* alpha = 1.5, radius NULL */

/* Triangulates the np centres (x[i], y[i]). Refuses, with a message naming the particles, fewer
 * than 3 points, non-finite coordinates, duplicate positions, and all-collinear centres; qhull's
 * own failures come back as CORE_ERR_ARG with its message (never on stderr). */
core_status analysis_delaunay(const double *x, const double *y, size_t np,
                              const analysis_delaunay_def *def, analysis_mesh **out,
                              core_error *err);
void analysis_mesh_destroy(analysis_mesh *m);

/* Signed areas of the cells in the configuration (x, y) (positive while not inverted). */
void analysis_cell_areas(const analysis_mesh *m, const double *x, const double *y, double *area);

/* Gradient of the nodal field (ux, uy) in each cell, over the configuration (x, y): the exact
 * gradient of the linear interpolant (constant-strain triangle). grad: 4 per cell. Fails when a
 * cell has zero or negative area in (x, y) (an inverted cell), naming it. */
core_status analysis_cell_gradients(const analysis_mesh *m, const double *x, const double *y,
                                    const double *ux, const double *uy, double *grad,
                                    core_error *err);

/* Eq. 3.1 / 3.2: the coarse gradient (1/V) sum over boundary edges of the edge integral of
 * u (x) n, u linear along the edge, n the outward normal in (x, y); V the area inside the loop.
 * By the divergence theorem it equals sum_cells A_c grad_c / V for the same configuration. */
void analysis_boundary_gradient(const analysis_mesh *m, const double *x, const double *y,
                                const double *ux, const double *uy, double grad[4], double *V);

/* Area-weighted mean of per-cell tensors (4 per cell) over the configuration (x, y). */
void analysis_mean_tensor(const analysis_mesh *m, const double *x, const double *y,
                          const double *cell, double mean[4]);

/* Symmetric part (strain or strain rate) of a gradient. */
void analysis_sym(const double g[4], double e[4]);

/* L_II of a velocity gradient L: sqrt(1/2 L':L'), L' = L - (tr L / 2) I, the magnitude of the
 * deviatoric velocity gradient (the rate of distortion, spin included; Padbidri Fig. 3.10). */
double analysis_lii(const double L[4]);

/* Contacts for Christoffersen's stress: the force (fx, fy) acts on particle i at the point
 * (px, py); particle j (j < 0: a wall or anything outside the assembly) gets the opposite. */
typedef struct analysis_contacts {
    size_t n;
    const long *i, *j;
    const double *px, *py, *fx, *fy;
} analysis_contacts;

/* Christoffersen's stress per particle, sigma_p = -(1/V_p) sum_c (x_c - X_p) (x) f_c over the
 * particle's contacts, with V_p = depth x (one third of the area of each cell it is a vertex
 * of). Positions (x, y) are the current ones; the mesh connectivity gives V_p in that
 * configuration. Particles in no cell get NaN. stress: 4 per particle; volume: np (may be NULL).
 * Summed, V_p sigma_p gives sum over contacts of branch (x) force, so the area-weighted mean of
 * the cell stresses below is the assembly stress of Christoffersen et al. (1981). */
core_status analysis_particle_stress(const analysis_mesh *m, const double *x, const double *y,
                                     const analysis_contacts *c, double depth, double *stress,
                                     double *volume, core_error *err);

/* Cell stress: the mean of its three particles' stresses (so sum_c A_c sigma_c =
 * sum_p (V_p / depth) sigma_p). cell: 4 per cell. */
void analysis_cell_stress(const analysis_mesh *m, const double *particle_stress, double *cell);

/* Samples per-cell values on an nx x ny grid over extent {x0, y0, x1, y1} (cell centres, row-
 * major from the bottom row), in the configuration (x, y); NaN where no cell covers the point. */
core_status analysis_rasterize(const analysis_mesh *m, const double *x, const double *y,
                               const double *values, int nx, int ny, const double extent[4],
                               double *out, core_error *err);

/* ---- output for other tools (analysis/vtk.c) ------------------------------------------------- */
/* One cell array: ncells x ncomp values (ncomp 1, 3, or 9 for a 3 x 3 tensor row-major). */
typedef struct analysis_vtk_field {
    const char *name;
    int ncomp;
    const double *values;
} analysis_vtk_field;

/* The cells as a VTK XML unstructured grid of triangles (.vtu), written whole: np points (x, y;
 * point data id, 1-based), the triangles tri (3 per cell, 0-based point indices) and the given
 * cell arrays; field data TimeValue = time. */
core_status analysis_vtk_cells(const char *path, size_t np, const double *x, const double *y,
                               size_t ncells, const long *tri, size_t nfields,
                               const analysis_vtk_field *fields, double time, core_error *err);

#endif
