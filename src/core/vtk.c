/* The VTK XML writer: arrays are collected in memory, then the XML header (with each array's
 * offset into the appended block) and the raw appended data are written in one pass. */
#include "core/vtk.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"

typedef enum vtk_type { T_F64, T_I64, T_I32, T_U8 } vtk_type;

static const char *const TYPE_NAMES[] = {"Float64", "Int64", "Int32", "UInt8"};
static const size_t TYPE_SIZES[] = {8, 8, 4, 1};

typedef struct vtk_array {
    vtk_section sec;
    char name[128];
    vtk_type type;
    int ncomp;
    size_t ntuples;
    void *data;
} vtk_array;

struct vtk_file {
    int image; /* ImageData (else UnstructuredGrid) */
    size_t npoints, ncells;
    int n[3];
    double origin[3], spacing[3];
    vtk_array *arr;
    size_t narr, cap;
    char active[2][3][128]; /* [point, cell][Scalars, Vectors, Tensors] */
};

static const char *const ATTRIBUTES[3] = {"Scalars", "Vectors", "Tensors"};

const char *vtk_byte_order(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b ? "LittleEndian" : "BigEndian";
}

static core_status new_file(vtk_file **out, core_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for a VTK file");
    return CORE_OK;
}

core_status vtk_unstructured(size_t npoints, size_t ncells, vtk_file **out, core_error *err)
{
    core_status st = new_file(out, err);
    if (st)
        return st;
    (*out)->npoints = npoints;
    (*out)->ncells = ncells;
    return CORE_OK;
}

core_status vtk_image(const int n[3], const double origin[3], const double spacing[3],
                      vtk_file **out, core_error *err)
{
    *out = NULL;
    size_t np = 1, nc = 1;
    for (int a = 0; a < 3; a++) {
        if (n[a] < 1)
            return core_fail(err, CORE_ERR_ARG, "image points on axis %d must be >= 1, got %d", a,
                             n[a]);
        if (!(spacing[a] > 0))
            return core_fail(err, CORE_ERR_ARG, "image spacing on axis %d must be > 0, got %g", a,
                             spacing[a]);
        np *= (size_t)n[a];
        if (n[a] > 1)
            nc *= (size_t)(n[a] - 1);
    }
    core_status st = new_file(out, err);
    if (st)
        return st;
    vtk_file *f = *out;
    f->image = 1;
    f->npoints = np;
    f->ncells = nc;
    for (int a = 0; a < 3; a++) {
        f->n[a] = n[a];
        f->origin[a] = origin[a];
        f->spacing[a] = spacing[a];
    }
    return CORE_OK;
}

void vtk_file_free(vtk_file *f)
{
    if (!f)
        return;
    for (size_t k = 0; k < f->narr; k++)
        free(f->arr[k].data);
    free(f->arr);
    free(f);
}

static const char *section_name(vtk_section sec)
{
    switch (sec) {
    case VTK_FIELD_DATA: return "field data";
    case VTK_POINT_DATA: return "point data";
    case VTK_CELL_DATA: return "cell data";
    case VTK_POINTS: return "points";
    case VTK_CELLS: return "cells";
    }
    return "?";
}

static void *add_array(vtk_file *f, vtk_section sec, const char *name, vtk_type type, int ncomp,
                       size_t ntuples, core_error *err)
{
    if (!name || !*name || strlen(name) >= sizeof f->arr[0].name) {
        core_fail(err, CORE_ERR_ARG, "VTK array names must have 1 to %zu characters",
                  sizeof f->arr[0].name - 1);
        return NULL;
    }
    if (ncomp < 1 || ncomp > 9) {
        core_fail(err, CORE_ERR_ARG, "VTK array '%s': components must be 1 to 9, got %d", name,
                  ncomp);
        return NULL;
    }
    size_t want = ntuples;
    if (sec == VTK_POINT_DATA || sec == VTK_POINTS)
        want = f->npoints;
    else if (sec == VTK_CELL_DATA)
        want = f->ncells;
    if (ntuples != want) {
        core_fail(err, CORE_ERR_ARG, "VTK array '%s' has %zu values, the %s need %zu", name,
                  ntuples, section_name(sec), want);
        return NULL;
    }
    if (f->image && (sec == VTK_POINTS || sec == VTK_CELLS)) {
        core_fail(err, CORE_ERR_ARG, "VTK array '%s': an image has no explicit %s", name,
                  section_name(sec));
        return NULL;
    }
    for (size_t k = 0; k < f->narr; k++)
        if (f->arr[k].sec == sec && !strcmp(f->arr[k].name, name)) {
            core_fail(err, CORE_ERR_ARG, "VTK array '%s' is already in the %s", name,
                      section_name(sec));
            return NULL;
        }
    if (f->narr == f->cap) {
        size_t cap = f->cap ? 2 * f->cap : 16;
        vtk_array *a = realloc(f->arr, cap * sizeof *a);
        if (!a) {
            core_fail(err, CORE_ERR_NOMEM, "out of memory for VTK array '%s'", name);
            return NULL;
        }
        f->arr = a;
        f->cap = cap;
    }
    size_t count = ntuples * (size_t)ncomp;
    if (ntuples && count / ntuples != (size_t)ncomp) {
        core_fail(err, CORE_ERR_ARG, "VTK array '%s' is too large", name);
        return NULL;
    }
    void *data = calloc(count ? count : 1, TYPE_SIZES[type]);
    if (!data) {
        core_fail(err, CORE_ERR_NOMEM, "out of memory for VTK array '%s' (%zu values)", name,
                  count);
        return NULL;
    }
    vtk_array *a = &f->arr[f->narr++];
    a->sec = sec;
    strcpy(a->name, name);
    a->type = type;
    a->ncomp = ncomp;
    a->ntuples = ntuples;
    a->data = data;
    return data;
}

double *vtk_f64(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                core_error *err)
{
    if (sec == VTK_POINTS && ncomp != 3) {
        core_fail(err, CORE_ERR_ARG, "VTK points have 3 components, got %d", ncomp);
        return NULL;
    }
    return add_array(f, sec, name, T_F64, ncomp, ntuples, err);
}

int64_t *vtk_i64(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                 core_error *err)
{
    return add_array(f, sec, name, T_I64, ncomp, ntuples, err);
}

int32_t *vtk_i32(vtk_file *f, vtk_section sec, const char *name, int ncomp, size_t ntuples,
                 core_error *err)
{
    return add_array(f, sec, name, T_I32, ncomp, ntuples, err);
}

int64_t *vtk_cells(vtk_file *f, int type, int nv, core_error *err)
{
    if (nv < 1 || nv > 8) {
        core_fail(err, CORE_ERR_ARG, "VTK cells have 1 to 8 vertices here, got %d", nv);
        return NULL;
    }
    const size_t nc = f->ncells;
    int64_t *conn = add_array(f, VTK_CELLS, "connectivity", T_I64, 1, nc * (size_t)nv, err);
    int64_t *off = conn ? add_array(f, VTK_CELLS, "offsets", T_I64, 1, nc, err) : NULL;
    uint8_t *types = off ? add_array(f, VTK_CELLS, "types", T_U8, 1, nc, err) : NULL;
    if (!types)
        return NULL;
    for (size_t c = 0; c < nc; c++) {
        off[c] = (int64_t)((c + 1) * (size_t)nv);
        types[c] = (uint8_t)type;
    }
    return conn;
}

int64_t *vtk_cells_mixed(vtk_file *f, const int *types, const int *nverts, core_error *err)
{
    const size_t nc = f->ncells;
    size_t total = 0;
    for (size_t c = 0; c < nc; c++) {
        if (nverts[c] < 1 || types[c] < 1 || types[c] > 255) {
            core_fail(err, CORE_ERR_ARG, "VTK cell %zu: type %d with %d vertices", c, types[c],
                      nverts[c]);
            return NULL;
        }
        total += (size_t)nverts[c];
    }
    int64_t *conn = add_array(f, VTK_CELLS, "connectivity", T_I64, 1, total, err);
    int64_t *off = conn ? add_array(f, VTK_CELLS, "offsets", T_I64, 1, nc, err) : NULL;
    uint8_t *ty = off ? add_array(f, VTK_CELLS, "types", T_U8, 1, nc, err) : NULL;
    if (!ty)
        return NULL;
    int64_t end = 0;
    for (size_t c = 0; c < nc; c++) {
        end += nverts[c];
        off[c] = end;
        ty[c] = (uint8_t)types[c];
    }
    return conn;
}

core_status vtk_set_active(vtk_file *f, vtk_section sec, const char *attribute, const char *name,
                           core_error *err)
{
    if (sec != VTK_POINT_DATA && sec != VTK_CELL_DATA)
        return core_fail(err, CORE_ERR_ARG, "only point and cell data have active arrays");
    for (int k = 0; k < 3; k++)
        if (!strcmp(attribute, ATTRIBUTES[k])) {
            if (strlen(name) >= sizeof f->active[0][0])
                return core_fail(err, CORE_ERR_ARG, "VTK array name too long");
            strcpy(f->active[sec == VTK_CELL_DATA][k], name);
            return CORE_OK;
        }
    return core_fail(err, CORE_ERR_ARG, "unknown VTK attribute '%s'", attribute);
}

core_status vtk_set_time(vtk_file *f, double time, long step, core_error *err)
{
    double *t = vtk_f64(f, VTK_FIELD_DATA, "TimeValue", 1, 1, err);
    int64_t *n = t ? vtk_i64(f, VTK_FIELD_DATA, "step", 1, 1, err) : NULL;
    if (!n)
        return err ? err->status : CORE_ERR_ARG;
    *t = time;
    *n = step;
    return CORE_OK;
}

/* Writes s with the five XML special characters escaped. */
static void put_escaped(FILE *fp, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", fp); break;
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '"': fputs("&quot;", fp); break;
        case '\'': fputs("&apos;", fp); break;
        default: fputc(*s, fp);
        }
    }
}

static size_t array_bytes(const vtk_array *a)
{
    return a->ntuples * (size_t)a->ncomp * TYPE_SIZES[a->type];
}

/* The <DataArray/> elements of one section, advancing *offset past each block (an 8-byte size
 * header and the data). */
static void put_section(FILE *fp, const vtk_file *f, vtk_section sec, const char *indent,
                        uint64_t *offset)
{
    for (size_t k = 0; k < f->narr; k++) {
        const vtk_array *a = &f->arr[k];
        if (a->sec != sec)
            continue;
        fprintf(fp, "%s<DataArray type=\"%s\" Name=\"", indent, TYPE_NAMES[a->type]);
        put_escaped(fp, a->name);
        fprintf(fp, "\" NumberOfComponents=\"%d\"", a->ncomp);
        if (sec == VTK_FIELD_DATA)
            fprintf(fp, " NumberOfTuples=\"%zu\"", a->ntuples);
        fprintf(fp, " format=\"appended\" offset=\"%llu\"/>\n", (unsigned long long)*offset);
        *offset += 8 + array_bytes(a);
    }
}

static void put_data_section(FILE *fp, const vtk_file *f, vtk_section sec, uint64_t *offset)
{
    const char *tag = sec == VTK_POINT_DATA ? "PointData" : "CellData";
    fprintf(fp, "      <%s", tag);
    for (int k = 0; k < 3; k++) {
        const char *name = f->active[sec == VTK_CELL_DATA][k];
        if (*name) {
            fprintf(fp, " %s=\"", ATTRIBUTES[k]);
            put_escaped(fp, name);
            fputc('"', fp);
        }
    }
    fprintf(fp, ">\n");
    put_section(fp, f, sec, "        ", offset);
    fprintf(fp, "      </%s>\n", tag);
}

static void put_blocks(FILE *fp, const vtk_file *f, vtk_section sec)
{
    for (size_t k = 0; k < f->narr; k++) {
        const vtk_array *a = &f->arr[k];
        if (a->sec != sec)
            continue;
        uint64_t bytes = array_bytes(a);
        fwrite(&bytes, sizeof bytes, 1, fp);
        if (bytes)
            fwrite(a->data, 1, (size_t)bytes, fp);
    }
}

static int has_section(const vtk_file *f, vtk_section sec)
{
    for (size_t k = 0; k < f->narr; k++)
        if (f->arr[k].sec == sec)
            return 1;
    return 0;
}

core_status vtk_file_write(const vtk_file *f, const char *path, core_error *err)
{
    if (!f->image) {
        if (!has_section(f, VTK_POINTS))
            return core_fail(err, CORE_ERR_STATE, "VTK file '%s' has no points array", path);
        if (!has_section(f, VTK_CELLS))
            return core_fail(err, CORE_ERR_STATE, "VTK file '%s' has no cells", path);
    }
    atomic_file af;
    core_status st = atomic_open(&af, path, err);
    if (st)
        return st;
    FILE *fp = af.fp;
    const char *type = f->image ? "ImageData" : "UnstructuredGrid";
    fprintf(fp,
            "<?xml version=\"1.0\"?>\n"
            "<VTKFile type=\"%s\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n",
            type, vtk_byte_order());
    char extent[128] = "";
    if (f->image) {
        snprintf(extent, sizeof extent, "0 %d 0 %d 0 %d", f->n[0] - 1, f->n[1] - 1, f->n[2] - 1);
        fprintf(fp,
                "  <ImageData WholeExtent=\"%s\" Origin=\"%.17g %.17g %.17g\" "
                "Spacing=\"%.17g %.17g %.17g\">\n",
                extent, f->origin[0], f->origin[1], f->origin[2], f->spacing[0], f->spacing[1],
                f->spacing[2]);
    } else {
        fprintf(fp, "  <UnstructuredGrid>\n");
    }
    uint64_t offset = 0;
    if (has_section(f, VTK_FIELD_DATA)) {
        fprintf(fp, "    <FieldData>\n");
        put_section(fp, f, VTK_FIELD_DATA, "      ", &offset);
        fprintf(fp, "    </FieldData>\n");
    }
    if (f->image)
        fprintf(fp, "    <Piece Extent=\"%s\">\n", extent);
    else
        fprintf(fp, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", f->npoints,
                f->ncells);
    put_data_section(fp, f, VTK_POINT_DATA, &offset);
    put_data_section(fp, f, VTK_CELL_DATA, &offset);
    if (!f->image) {
        fprintf(fp, "      <Points>\n");
        put_section(fp, f, VTK_POINTS, "        ", &offset);
        fprintf(fp, "      </Points>\n      <Cells>\n");
        put_section(fp, f, VTK_CELLS, "        ", &offset);
        fprintf(fp, "      </Cells>\n");
    }
    fprintf(fp, "    </Piece>\n  </%s>\n  <AppendedData encoding=\"raw\">\n   _", type);
    /* The same order as the offsets above. */
    static const vtk_section order[5] = {VTK_FIELD_DATA, VTK_POINT_DATA, VTK_CELL_DATA, VTK_POINTS,
                                         VTK_CELLS};
    for (int k = 0; k < 5; k++)
        put_blocks(fp, f, order[k]);
    fprintf(fp, "\n  </AppendedData>\n</VTKFile>\n");
    if (ferror(fp)) {
        int e = errno;
        atomic_abort(&af);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    return atomic_commit(&af, err);
}

core_status vtk_pvd_write(const char *path, size_t n, const double *times, const char *const *files,
                          const int *part, core_error *err)
{
    atomic_file af;
    core_status st = atomic_open(&af, path, err);
    if (st)
        return st;
    FILE *fp = af.fp;
    fprintf(fp,
            "<?xml version=\"1.0\"?>\n"
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
            "  <Collection>\n",
            vtk_byte_order());
    for (size_t k = 0; k < n; k++) {
        /* %.17g: ParaView sorts and matches time steps by these values. */
        fprintf(fp, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"%d\" file=\"", times[k],
                part ? part[k] : 0);
        put_escaped(fp, files[k]);
        fprintf(fp, "\"/>\n");
    }
    fprintf(fp, "  </Collection>\n</VTKFile>\n");
    if (ferror(fp)) {
        int e = errno;
        atomic_abort(&af);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    return atomic_commit(&af, err);
}

core_status vtk_file_finish(vtk_file *f, const char *path, core_status st, core_error *err)
{
    if (st == CORE_OK)
        st = vtk_file_write(f, path, err);
    vtk_file_free(f);
    return st;
}
