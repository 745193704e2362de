/* Continuum measures on the Delaunay cells: constant-strain-triangle gradients (Bagi 1996,
 * Satake 2004), the boundary integral of Eq. 3.1/3.2, L_II, Christoffersen's stress per particle
 * and per cell, and a raster of cell values for maps (Padbidri Figs. 3.10-3.11). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"

void analysis_cell_areas(const analysis_mesh *m, const double *x, const double *y, double *area)
{
    for (size_t c = 0; c < m->ncells; c++) {
        const long *v = m->tri + 3 * c;
        area[c] = 0.5 * ((x[v[1]] - x[v[0]]) * (y[v[2]] - y[v[0]]) -
                         (x[v[2]] - x[v[0]]) * (y[v[1]] - y[v[0]]));
    }
}

core_status analysis_cell_gradients(const analysis_mesh *m, const double *x, const double *y,
                                    const double *ux, const double *uy, double *grad,
                                    core_error *err)
{
    for (size_t c = 0; c < m->ncells; c++) {
        const long *v = m->tri + 3 * c;
        double a2 = (x[v[1]] - x[v[0]]) * (y[v[2]] - y[v[0]]) -
                    (x[v[2]] - x[v[0]]) * (y[v[1]] - y[v[0]]);
        if (!(a2 > 0))
            return core_fail(err, CORE_ERR_STATE,
                             "cell %zu (particles %ld, %ld, %ld) has area %g <= 0 in this "
                             "configuration: it is inverted; rebuild the mesh", c + 1, v[0] + 1,
                             v[1] + 1, v[2] + 1, 0.5 * a2);
        double g[4] = {0, 0, 0, 0};
        for (int k = 0; k < 3; k++) {
            long a = v[k], b = v[(k + 1) % 3], cc = v[(k + 2) % 3];
            /* grad N_a = (y_b - y_c, x_c - x_b) / (2A) */
            double nx = (y[b] - y[cc]) / a2, ny = (x[cc] - x[b]) / a2;
            g[0] += ux[a] * nx;
            g[1] += ux[a] * ny;
            g[2] += uy[a] * nx;
            g[3] += uy[a] * ny;
        }
        memcpy(grad + 4 * c, g, sizeof g);
    }
    return CORE_OK;
}

void analysis_boundary_gradient(const analysis_mesh *m, const double *x, const double *y,
                                const double *ux, const double *uy, double grad[4], double *V)
{
    double g[4] = {0, 0, 0, 0}, area = 0;
    for (size_t k = 0; k < m->nloop; k++) {
        long a = m->loop[k], b = m->loop[(k + 1) % m->nloop];
        /* Eq. 3.1: the edge integral of u (x) n with u linear: L (u_a + u_b)/2 (x) n, and
         * L n = (dy, -dx) outward for a counter-clockwise loop. */
        double nx = y[b] - y[a], ny = -(x[b] - x[a]);
        double mx = 0.5 * (ux[a] + ux[b]), my = 0.5 * (uy[a] + uy[b]);
        g[0] += mx * nx;
        g[1] += mx * ny;
        g[2] += my * nx;
        g[3] += my * ny;
        area += 0.5 * (x[a] * y[b] - x[b] * y[a]);
    }
    for (int i = 0; i < 4; i++)
        grad[i] = g[i] / area;
    if (V)
        *V = area;
}

void analysis_mean_tensor(const analysis_mesh *m, const double *x, const double *y,
                          const double *cell, double mean[4])
{
    double s[4] = {0, 0, 0, 0}, total = 0;
    for (size_t c = 0; c < m->ncells; c++) {
        const long *v = m->tri + 3 * c;
        double a = 0.5 * ((x[v[1]] - x[v[0]]) * (y[v[2]] - y[v[0]]) -
                          (x[v[2]] - x[v[0]]) * (y[v[1]] - y[v[0]]));
        if (!isfinite(cell[4 * c]))
            continue;
        for (int i = 0; i < 4; i++)
            s[i] += a * cell[4 * c + i];
        total += a;
    }
    for (int i = 0; i < 4; i++)
        mean[i] = total > 0 ? s[i] / total : NAN;
}

void analysis_sym(const double g[4], double e[4])
{
    double off = 0.5 * (g[1] + g[2]);
    e[0] = g[0];
    e[1] = off;
    e[2] = off;
    e[3] = g[3];
}

double analysis_lii(const double L[4])
{
    double h = 0.5 * (L[0] + L[3]);
    double a = L[0] - h, d = L[3] - h;
    return sqrt(0.5 * (a * a + d * d + L[1] * L[1] + L[2] * L[2]));
}

core_status analysis_particle_stress(const analysis_mesh *m, const double *x, const double *y,
                                     const analysis_contacts *c, double depth, double *stress,
                                     double *volume, core_error *err)
{
    if (!(depth > 0) || !isfinite(depth))
        return core_fail(err, CORE_ERR_ARG, "depth must be > 0 (m), got %g", depth);
    const size_t np = m->np;
    double *vol = volume ? volume : malloc(np * sizeof *vol);
    if (!vol)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu particle volumes", np);
    for (size_t i = 0; i < np; i++)
        vol[i] = 0;
    for (size_t k = 0; k < m->ncells; k++) {
        const long *v = m->tri + 3 * k;
        double a = 0.5 * ((x[v[1]] - x[v[0]]) * (y[v[2]] - y[v[0]]) -
                          (x[v[2]] - x[v[0]]) * (y[v[1]] - y[v[0]]));
        for (int q = 0; q < 3; q++)
            vol[v[q]] += depth * fabs(a) / 3;
    }
    memset(stress, 0, 4 * np * sizeof *stress);
    for (size_t k = 0; k < c->n; k++) {
        const double f[2] = {c->fx[k], c->fy[k]};
        const long ends[2] = {c->i[k], c->j[k]};
        for (int s = 0; s < 2; s++) {
            long p = ends[s];
            if (p < 0 || (size_t)p >= np)
                continue;
            double sg = s == 0 ? 1 : -1; /* j gets the opposite force */
            double bx = c->px[k] - x[p], by = c->py[k] - y[p];
            stress[4 * p + 0] += bx * sg * f[0];
            stress[4 * p + 1] += bx * sg * f[1];
            stress[4 * p + 2] += by * sg * f[0];
            stress[4 * p + 3] += by * sg * f[1];
        }
    }
    for (size_t p = 0; p < np; p++)
        for (int q = 0; q < 4; q++)
            stress[4 * p + q] = vol[p] > 0 ? -stress[4 * p + q] / vol[p] : NAN;
    if (!volume)
        free(vol);
    return CORE_OK;
}

void analysis_cell_stress(const analysis_mesh *m, const double *ps, double *cell)
{
    for (size_t k = 0; k < m->ncells; k++) {
        const long *v = m->tri + 3 * k;
        for (int q = 0; q < 4; q++)
            cell[4 * k + q] = (ps[4 * v[0] + q] + ps[4 * v[1] + q] + ps[4 * v[2] + q]) / 3;
    }
}

core_status analysis_rasterize(const analysis_mesh *m, const double *x, const double *y,
                               const double *values, int nx, int ny, const double ext[4],
                               double *out, core_error *err)
{
    if (nx < 1 || ny < 1)
        return core_fail(err, CORE_ERR_ARG, "raster size must be >= 1 x 1, got %d x %d", nx, ny);
    if (!(ext[2] > ext[0]) || !(ext[3] > ext[1]))
        return core_fail(err, CORE_ERR_ARG, "extent must have x1 > x0 and y1 > y0");
    const double hx = (ext[2] - ext[0]) / nx, hy = (ext[3] - ext[1]) / ny;
    for (long k = 0; k < (long)nx * ny; k++)
        out[k] = NAN;
    for (size_t c = 0; c < m->ncells; c++) {
        const long *v = m->tri + 3 * c;
        double xa = x[v[0]], ya = y[v[0]], xb = x[v[1]], yb = y[v[1]], xc = x[v[2]], yc = y[v[2]];
        double a2 = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya);
        if (!(a2 != 0))
            continue;
        double lo_x = fmin(xa, fmin(xb, xc)), hi_x = fmax(xa, fmax(xb, xc));
        double lo_y = fmin(ya, fmin(yb, yc)), hi_y = fmax(ya, fmax(yb, yc));
        int i0 = (int)fmax(0, floor((lo_x - ext[0]) / hx - 0.5));
        int i1 = (int)fmin(nx - 1, ceil((hi_x - ext[0]) / hx - 0.5));
        int j0 = (int)fmax(0, floor((lo_y - ext[1]) / hy - 0.5));
        int j1 = (int)fmin(ny - 1, ceil((hi_y - ext[1]) / hy - 0.5));
        for (int j = j0; j <= j1; j++) {
            double py = ext[1] + (j + 0.5) * hy;
            for (int i = i0; i <= i1; i++) {
                double px = ext[0] + (i + 0.5) * hx;
                double l0 = ((xb - px) * (yc - py) - (xc - px) * (yb - py)) / a2;
                double l1 = ((xc - px) * (ya - py) - (xa - px) * (yc - py)) / a2;
                double l2 = 1 - l0 - l1;
                if (l0 >= -1e-12 && l1 >= -1e-12 && l2 >= -1e-12)
                    out[(long)j * nx + i] = values[c];
            }
        }
    }
    return CORE_OK;
}
