/* VTK XML files for ParaView (.vtu unstructured grids, .vti images, .pvd collections) with the
 * data appended as raw binary (header_type UInt64, the machine's byte order), written whole.
 *
 * Usage: create a vtk_file for a grid shape, ask it for each array (it returns a buffer it owns,
 * for the caller to fill), then vtk_file_write. The file knows nothing of grainlab's engines; the
 * exporters that fill it live in each engine's folder (dem/vtk.c, mpm/vtk.c, dsmc/vtk.c,
 * analysis/vtk.c). */
#ifndef GRAINLAB_CORE_VTK_H
#define GRAINLAB_CORE_VTK_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

typedef struct vtk_file vtk_file;

/* Where an array goes. VTK_POINTS takes one 3-component array (the point coordinates);
 * VTK_CELLS the unstructured grid's connectivity, offsets and types (see vtk_cells);
 * VTK_FIELD_DATA arrays describe the whole data set (e.g. TimeValue). */
typedef enum vtk_section {
    VTK_FIELD_DATA,
    VTK_POINT_DATA,
    VTK_CELL_DATA,
    VTK_POINTS,
    VTK_CELLS
} vtk_section;

/* VTK cell types used by grainlab (vtkCellType.h). */
enum {
    VTK_CELL_VERTEX = 1,
    VTK_CELL_LINE = 3,
    VTK_CELL_POLY_LINE = 4,
    VTK_CELL_TRIANGLE = 5,
    VTK_CELL_POLYGON = 7,
    VTK_CELL_QUAD = 9
};

/* An UnstructuredGrid piece of npoints points and ncells cells (.vtu). */
core_status vtk_unstructured(size_t npoints, size_t ncells, vtk_file **out, core_error *err);

/* An ImageData of n[0] x n[1] x n[2] points (use 1 on unused axes) starting at origin with the
 * given spacing (.vti); it has (n[a] - 1) cells along each axis with n[a] > 1. */
core_status vtk_image(const int n[3], const double origin[3], const double spacing[3],
                      vtk_file **out, core_error *err);

void vtk_file_free(vtk_file *f);

/* A new array of ntuples x ncomp values in section sec, zero-filled, owned by f; NULL on error
 * (a bad count for the section, a duplicate name, out of memory) with err filled. ntuples must
 * match the section: the points for VTK_POINTS / VTK_POINT_DATA, the cells for VTK_CELL_DATA. */
double *vtk_f64(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                core_error *err);
int64_t *vtk_i64(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                 core_error *err);
int32_t *vtk_i32(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                 core_error *err);

/* The cell arrays of an unstructured grid, all cells of one type with nv vertices each: returns
 * the connectivity (ncells x nv point indices, 0-based) for the caller to fill; offsets and
 * types are filled here. */
int64_t *vtk_cells(vtk_file *f, int type, int nv, core_error *err);
/* The same for cells of different types: cell c has type types[c] and nverts[c] vertices. */
int64_t *vtk_cells_mixed(vtk_file *f, const int *types, const int *nverts, core_error *err);

/* Marks an array of the section as the active Scalars, Vectors or Tensors (ParaView's default
 * for colouring and glyphs). */
core_status vtk_set_active(vtk_file *f, vtk_section sec, const char *attribute, const char *name,
                           core_error *err);

/* Field data TimeValue (s; ParaView shows it as the data set's time) and the step count. */
core_status vtk_set_time(vtk_file *f, double time, long step, core_error *err);

/* Writes the file whole (temporary file + rename). */
core_status vtk_file_write(const vtk_file *f, const char *path, core_error *err);
/* The exporters' last step: writes f when st is CORE_OK, frees it either way, returns the status. */
core_status vtk_file_finish(vtk_file *f, const char *path, core_status st, core_error *err);

/* A .pvd collection: n data sets with their times, written whole. files are written as given
 * (relative to the .pvd's directory). part may be NULL (all part 0). */
core_status vtk_pvd_write(const char *path, size_t n, const double *times, const char *const *files,
                          const int *part, core_error *err);

/* "LittleEndian" or "BigEndian": this machine's byte order, as the files declare it. */
const char *vtk_byte_order(void);

#endif
