/* Delaunay-cell fields as a VTK XML unstructured grid of triangles (.vtu) for ParaView. */
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"
#include "core/vtk.h"

core_status analysis_vtk_cells(const char *path, size_t np, const double *x, const double *y,
                               size_t ncells, const long *tri, size_t nfields,
                               const analysis_vtk_field *fields, double time, core_error *err)
{
    for (size_t c = 0; c < 3 * ncells; c++)
        if (tri[c] < 0 || (size_t)tri[c] >= np)
            return core_fail(err, CORE_ERR_ARG, "cell %zu names vertex %ld of %zu", c / 3 + 1,
                             tri[c] + 1, np);
    vtk_file *f;
    core_status st = vtk_unstructured(np, ncells, &f, err);
    if (st)
        return st;
    double *px = vtk_f64(f, VTK_POINTS, "Points", 3, np, err);
    int64_t *conn = px ? vtk_cells(f, VTK_CELL_TRIANGLE, 3, err) : NULL;
    int64_t *id = conn ? vtk_i64(f, VTK_POINT_DATA, "id", 1, np, err) : NULL;
    if (!id)
        st = err ? err->status : CORE_ERR_NOMEM;
    for (size_t i = 0; !st && i < np; i++) {
        px[3 * i] = x[i];
        px[3 * i + 1] = y[i];
        id[i] = (int64_t)i + 1;
    }
    for (size_t c = 0; !st && c < 3 * ncells; c++)
        conn[c] = tri[c];
    for (size_t k = 0; !st && k < nfields; k++) {
        const analysis_vtk_field *fl = &fields[k];
        double *v = vtk_f64(f, VTK_CELL_DATA, fl->name, fl->ncomp, ncells, err);
        if (!v) {
            st = err ? err->status : CORE_ERR_NOMEM;
            break;
        }
        memcpy(v, fl->values, ncells * (size_t)fl->ncomp * sizeof *v);
    }
    if (!st)
        st = vtk_set_time(f, time, 0, err);
    return vtk_file_finish(f, path, st, err);
}
