/* DSMC scenes as VTK XML for ParaView: the particles as vertices (.vtu) and the per-cell fields
 * as an image (.vti). Public accessors of dsmc.h only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/vtk.h"
#include "dsmc/dsmc.h"

core_status dsmc_vtk_particles(const dsmc_scene *s, const char *path, core_error *err)
{
    const size_t n = dsmc_count(s);
    const dsmc_scene_def *def = dsmc_def(s);
    vtk_file *f;
    core_status st = vtk_unstructured(n, n, &f, err);
    if (st)
        return st;
    dsmc_particles p;
    dsmc_get_particles(s, &p);
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, n, err);
    int64_t *conn = x ? vtk_cells(f, VTK_CELL_VERTEX, 1, err) : NULL;
    int64_t *id = conn ? vtk_i64(f, VTK_POINT_DATA, "id", 1, n, err) : NULL;
    double *r = id ? vtk_f64(f, VTK_POINT_DATA, "radius", 1, n, err) : NULL;
    double *v = r ? vtk_f64(f, VTK_POINT_DATA, "velocity", 3, n, err) : NULL;
    double *m = v ? vtk_f64(f, VTK_POINT_DATA, "mass", 1, n, err) : NULL;
    int64_t *cell = m ? vtk_i64(f, VTK_POINT_DATA, "cell", 1, n, err) : NULL;
    if (!cell)
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    const double mass = dsmc_mass(s);
    for (size_t i = 0; i < n; i++) {
        conn[i] = (int64_t)i;
        id[i] = (int64_t)p.id[i] + 1;
        r[i] = def->radius;
        m[i] = mass;
        cell[i] = (int64_t)p.cell[i] + 1;
        for (int d = 0; d < 3; d++) {
            x[3 * i + d] = p.x[d] ? p.x[d][i] : 0;
            v[3 * i + d] = p.v[d] ? p.v[d][i] : 0;
        }
    }
    st = vtk_set_time(f, dsmc_time(s), dsmc_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_POINT_DATA, "Vectors", "velocity", err);
    return vtk_file_finish(f, path, st, err);
}

core_status dsmc_vtk_cells(const dsmc_scene *s, const char *path, core_error *err)
{
    const dsmc_scene_def *def = dsmc_def(s);
    const int D = def->dim;
    double h[3];
    dsmc_cell_size(s, h);
    int n[3] = {def->cells[0] + 1, def->cells[1] + 1, D == 3 ? def->cells[2] + 1 : 1};
    double origin[3] = {def->lo[0], def->lo[1], D == 3 ? def->lo[2] : 0};
    double spacing[3] = {h[0], h[1], D == 3 ? h[2] : 1};
    vtk_file *f;
    core_status st = vtk_image(n, origin, spacing, &f, err);
    if (st)
        return st;
    const size_t nc = dsmc_cell_count(s);
    double *count = vtk_f64(f, VTK_CELL_DATA, "count", 1, nc, err);
    double *density = count ? vtk_f64(f, VTK_CELL_DATA, "density", 1, nc, err) : NULL;
    double *packing = density ? vtk_f64(f, VTK_CELL_DATA, "packing", 1, nc, err) : NULL;
    double *u = packing ? vtk_f64(f, VTK_CELL_DATA, "velocity", 3, nc, err) : NULL;
    double *temp = u ? vtk_f64(f, VTK_CELL_DATA, "temperature", 1, nc, err) : NULL;
    double *a2 = temp ? vtk_f64(f, VTK_CELL_DATA, "a2", 1, nc, err) : NULL;
    double *uc = a2 ? malloc(3 * nc * sizeof *uc) : NULL;
    if (!uc) {
        if (a2)
            core_fail(err, CORE_ERR_NOMEM, "out of memory for the cells of '%s'", path);
        return vtk_file_finish(f, path, err ? err->status : CORE_ERR_NOMEM, err);
    }
    dsmc_fields fl = {.count = count,
                      .density = density,
                      .packing = packing,
                      .u = {uc, uc + nc, D == 3 ? uc + 2 * nc : NULL},
                      .temperature = temp,
                      .a2 = a2};
    dsmc_measure_fields(s, &fl);
    for (size_t c = 0; c < nc; c++)
        for (int d = 0; d < 3; d++)
            u[3 * c + d] = d < D ? uc[d * nc + c] : 0;
    free(uc);
    st = vtk_set_time(f, dsmc_time(s), dsmc_steps_done(s), err);
    if (!st)
        st = vtk_set_active(f, VTK_CELL_DATA, "Scalars", "temperature", err);
    return vtk_file_finish(f, path, st, err);
}
