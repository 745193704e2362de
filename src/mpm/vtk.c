/* MPM scenes as VTK XML for ParaView: the material points as vertices (.vtu) and the grid as an
 * image (.vti) with nodal mass and velocity and the cell fields of mpm_field (the continuum
 * models' rate, inertial number and mean pressure only in scenes that have such a material).
 * Public accessors of mpm.h only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/vtk.h"
#include "mpm/mpm.h"

core_status mpm_vtk_points(const mpm_scene *s, const char *path, core_error *err)
{
    const size_t n = mpm_point_count(s);
    vtk_file *f;
    core_status st = vtk_unstructured(n, n, &f, err);
    if (st)
        return st;
    mpm_points p;
    mpm_get_points(s, &p);
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, n, err);
    int64_t *conn = x ? vtk_cells(f, VTK_CELL_VERTEX, 1, err) : NULL;
    int64_t *id = conn ? vtk_i64(f, VTK_POINT_DATA, "id", 1, n, err) : NULL;
    int32_t *grain = id ? vtk_i32(f, VTK_POINT_DATA, "grain", 1, n, err) : NULL;
    int32_t *mat = grain ? vtk_i32(f, VTK_POINT_DATA, "material", 1, n, err) : NULL;
    double *m = mat ? vtk_f64(f, VTK_POINT_DATA, "mass", 1, n, err) : NULL;
    double *vol = m ? vtk_f64(f, VTK_POINT_DATA, "volume", 1, n, err) : NULL;
    double *v = vol ? vtk_f64(f, VTK_POINT_DATA, "velocity", 3, n, err) : NULL;
    double *u = v ? vtk_f64(f, VTK_POINT_DATA, "displacement", 3, n, err) : NULL;
    double *sig = u ? vtk_f64(f, VTK_POINT_DATA, "stress", 9, n, err) : NULL;
    double *F = sig ? vtk_f64(f, VTK_POINT_DATA, "deformation_gradient", 9, n, err) : NULL;
    double *pr = F ? vtk_f64(f, VTK_POINT_DATA, "pressure", 1, n, err) : NULL;
    double *ep = pr ? vtk_f64(f, VTK_POINT_DATA, "eps_p", 1, n, err) : NULL;
    /* the continuum models' plastic shear rate and mean pressure -tr(sigma) / 3 */
    double *rate = ep && p.rate ? vtk_f64(f, VTK_POINT_DATA, "rate", 1, n, err) : NULL;
    double *pm = rate ? vtk_f64(f, VTK_POINT_DATA, "mean_pressure", 1, n, err) : NULL;
    if (!ep || (p.rate && !pm))
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    for (size_t i = 0; i < n; i++) {
        conn[i] = (int64_t)i;
        id[i] = (int64_t)i + 1;
        grain[i] = p.grain[i] + 1;
        mat[i] = p.material[i] + 1;
        m[i] = p.mass[i];
        const double J = p.F[0][i] * p.F[3][i] - p.F[1][i] * p.F[2][i];
        vol[i] = p.volume0[i] * J;
        const double xs[3] = {p.x[i], p.y[i], 0}, vs[3] = {p.vx[i], p.vy[i], 0},
                     us[3] = {p.ux[i], p.uy[i], 0};
        memcpy(x + 3 * i, xs, sizeof xs);
        memcpy(v + 3 * i, vs, sizeof vs);
        memcpy(u + 3 * i, us, sizeof us);
        /* Plane strain: the 3 x 3 tensors, row-major, as ParaView reads 9-component arrays. */
        const double sxx = p.sigma[0][i], syy = p.sigma[1][i], sxy = p.sigma[2][i],
                     szz = p.sigma[3][i];
        const double st9[9] = {sxx, sxy, 0, sxy, syy, 0, 0, 0, szz};
        const double F9[9] = {p.F[0][i], p.F[1][i], 0, p.F[2][i], p.F[3][i], 0, 0, 0, 1};
        memcpy(sig + 9 * i, st9, sizeof st9);
        memcpy(F + 9 * i, F9, sizeof F9);
        pr[i] = -(sxx + syy) / 2; /* as m:field('pressure') */
        ep[i] = p.eps_p[i];
        if (rate) {
            rate[i] = p.rate[i];
            pm[i] = -(sxx + syy + szz) / 3; /* as m:field('mean_pressure') */
        }
    }
    st = vtk_set_time(f, mpm_time(s), mpm_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Vectors", "velocity", err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Tensors", "stress", err);
    return vtk_file_finish(f, path, st, err);
}

/* The cell fields written to the grid file, named as m:field names them. */
static const struct {
    const char *name;
    mpm_field_kind kind;
} CELL_FIELDS[] = {
    {"vx", MPM_FIELD_VX},       {"vy", MPM_FIELD_VY},
    {"speed", MPM_FIELD_SPEED}, {"ux", MPM_FIELD_UX},
    {"uy", MPM_FIELD_UY},       {"displacement", MPM_FIELD_UMAG},
    {"sxx", MPM_FIELD_SXX},     {"syy", MPM_FIELD_SYY},
    {"sxy", MPM_FIELD_SXY},     {"pressure", MPM_FIELD_PRESSURE},
    {"psd", MPM_FIELD_PSD},     {"eps_p", MPM_FIELD_EPS_P},
    {"grain", MPM_FIELD_GRAIN}, {"mass", MPM_FIELD_MASS},
    /* scenes with drucker_prager or mu_i materials only (NCELL_CONTINUUM) */
    {"rate", MPM_FIELD_RATE},   {"inertial", MPM_FIELD_INERTIAL},
    {"mean_pressure", MPM_FIELD_MEAN_PRESSURE},
};
enum { NCELL_CONTINUUM = 3 };

core_status mpm_vtk_grid(const mpm_scene *s, const char *path, core_error *err)
{
    const mpm_scene_def *d = mpm_def(s);
    const int nx = d->cells[0], ny = d->cells[1];
    double h[2];
    mpm_cell_size(s, h);
    const int n[3] = {nx + 1, ny + 1, 1};
    const double origin[3] = {d->origin[0], d->origin[1], 0}, spacing[3] = {h[0], h[1], 1};
    vtk_file *f;
    core_status st = vtk_image(n, origin, spacing, &f, err);
    if (st)
        return st;
    const size_t nn = (size_t)(nx + 1) * (size_t)(ny + 1), nc = (size_t)nx * (size_t)ny;
    double *nm = vtk_f64(f, VTK_POINT_DATA, "mass", 1, nn, err);
    double *nv = nm ? vtk_f64(f, VTK_POINT_DATA, "velocity", 3, nn, err) : NULL;
    if (!nv)
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    mpm_points p;
    mpm_get_points(s, &p);
    const size_t nfields =
        sizeof CELL_FIELDS / sizeof CELL_FIELDS[0] - (p.rate ? 0 : NCELL_CONTINUUM);
    for (size_t k = 0; k < nfields; k++) {
        double *c = vtk_f64(f, VTK_CELL_DATA, CELL_FIELDS[k].name, 1, nc, err);
        if (!c)
            return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
        mpm_field(s, CELL_FIELDS[k].kind, c);
    }
    /* Nodal mass and velocity from a transfer of the current points with the linear
     * tensor-product shape functions (Eqs. 5-6): the solver's own nodal arrays are scratch of
     * its last step (and have ghost layers with B-splines). A periodic axis wraps its last node
     * onto the first, which the image repeats. */
    const size_t np = mpm_point_count(s);
    const int W = nx + 1;
    for (size_t q = 0; q < np; q++) {
        const double xi = (p.x[q] - d->origin[0]) / h[0], eta = (p.y[q] - d->origin[1]) / h[1];
        int i = (int)floor(xi), j = (int)floor(eta);
        i = i < 0 ? 0 : (i > nx - 1 ? nx - 1 : i);
        j = j < 0 ? 0 : (j > ny - 1 ? ny - 1 : j);
        const double fx = xi - i, fy = eta - j;
        const int i1 = d->periodic[0] && i + 1 == nx ? 0 : i + 1;
        const int j1 = d->periodic[1] && j + 1 == ny ? 0 : j + 1;
        const int node[4] = {j * W + i, j * W + i1, j1 * W + i, j1 * W + i1};
        const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
        for (int k = 0; k < 4; k++) {
            nm[node[k]] += w[k] * p.mass[q];
            nv[3 * node[k]] += w[k] * p.mass[q] * p.vx[q];
            nv[3 * node[k] + 1] += w[k] * p.mass[q] * p.vy[q];
        }
    }
    for (size_t k = 0; k < nn; k++)
        for (int c = 0; c < 2; c++)
            nv[3 * k + c] = nm[k] > 0 ? nv[3 * k + c] / nm[k] : 0;
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            int si = d->periodic[0] && i == nx ? 0 : i, sj = d->periodic[1] && j == ny ? 0 : j;
            if (si == i && sj == j)
                continue;
            const size_t to = (size_t)j * W + i, from = (size_t)sj * W + si;
            nm[to] = nm[from];
            memcpy(nv + 3 * to, nv + 3 * from, 3 * sizeof(double));
        }
    st = vtk_set_time(f, mpm_time(s), mpm_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_CELL_DATA, "Scalars", "pressure", err);
    return vtk_file_finish(f, path, st, err);
}
