/* The VTK XML writer without Lua: the header's offsets point at the appended blocks, each block
 * is its byte count (UInt64) followed by the raw values, names are escaped, and bad arrays are
 * refused with a message. (VTK's own readers check the files of every engine in io_vtk.) */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "core/error.h"
#include "core/vtk.h"

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/grainlab_vtk_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd);
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    *len = fread(buf, 1, (size_t)n, f);
    buf[*len] = '\0';
    fclose(f);
    return buf;
}

/* The block at `offset` of the appended data: its size header and a pointer to its bytes. */
static const char *block(const char *file, size_t len, uint64_t offset, uint64_t *bytes)
{
    const char *start = strstr(file, "<AppendedData encoding=\"raw\">");
    assert_non_null(start);
    start = strchr(start, '_') + 1;
    assert_true((size_t)(start - file) + offset + 8 <= len);
    memcpy(bytes, start + offset, 8);
    return start + offset + 8;
}

static uint64_t offset_of(const char *file, const char *name)
{
    char key[128];
    snprintf(key, sizeof key, "Name=\"%s\"", name);
    const char *p = strstr(file, key);
    assert_non_null(p);
    p = strstr(p, "offset=\"");
    assert_non_null(p);
    return strtoull(p + 8, NULL, 10);
}

static void test_unstructured_blocks(void **state)
{
    (void)state;
    core_error err;
    vtk_file *f;
    assert_int_equal(vtk_unstructured(3, 2, &f, &err), CORE_OK);
    double *x = vtk_f64(f, VTK_POINTS, "Points", 3, 3, &err);
    assert_non_null(x);
    for (int k = 0; k < 9; k++)
        x[k] = 0.1 * k;
    int64_t *conn = vtk_cells(f, VTK_CELL_LINE, 2, &err);
    assert_non_null(conn);
    conn[0] = 0, conn[1] = 1, conn[2] = 1, conn[3] = 2;
    double *r = vtk_f64(f, VTK_POINT_DATA, "r<&>\"'", 1, 3, &err);
    r[0] = 1.0 / 3, r[1] = -0.0, r[2] = 1e-300;
    int32_t *c = vtk_i32(f, VTK_CELL_DATA, "c", 1, 2, &err);
    c[0] = -7, c[1] = 1 << 30;
    assert_int_equal(vtk_set_time(f, 2.5, 42, &err), CORE_OK);
    assert_int_equal(vtk_set_active(f, VTK_CELL_DATA, "Scalars", "c", &err), CORE_OK);
    char path[300];
    snprintf(path, sizeof path, "%s/a.vtu", dir);
    assert_int_equal(vtk_file_write(f, path, &err), CORE_OK);
    vtk_file_free(f);

    size_t len = 0;
    char *file = slurp(path, &len);
    assert_non_null(file);
    assert_non_null(
        strstr(file, "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""));
    assert_non_null(strstr(file, "header_type=\"UInt64\""));
    assert_non_null(strstr(file, "<Piece NumberOfPoints=\"3\" NumberOfCells=\"2\">"));
    assert_non_null(strstr(file, "<CellData Scalars=\"c\">"));
    assert_non_null(strstr(file, "Name=\"r&lt;&amp;&gt;&quot;&apos;\""));
    uint64_t bytes;
    const char *b = block(file, len, offset_of(file, "Points"), &bytes);
    assert_int_equal(bytes, 9 * sizeof(double));
    double back[9];
    memcpy(back, b, sizeof back);
    for (int k = 0; k < 9; k++)
        assert_true(back[k] == 0.1 * k);
    b = block(file, len, offset_of(file, "r&lt;&amp;&gt;&quot;&apos;"), &bytes);
    assert_int_equal(bytes, 3 * sizeof(double));
    memcpy(back, b, 3 * sizeof(double));
    assert_true(back[0] == 1.0 / 3 && back[2] == 1e-300);
    b = block(file, len, offset_of(file, "c"), &bytes);
    int32_t ci[2];
    memcpy(ci, b, sizeof ci);
    assert_int_equal(bytes, 8);
    assert_int_equal(ci[0], -7);
    assert_int_equal(ci[1], 1 << 30);
    b = block(file, len, offset_of(file, "offsets"), &bytes);
    int64_t off[2];
    memcpy(off, b, sizeof off);
    assert_int_equal(off[0], 2);
    assert_int_equal(off[1], 4);
    b = block(file, len, offset_of(file, "types"), &bytes);
    assert_int_equal(bytes, 2);
    assert_int_equal(b[0], VTK_CELL_LINE);
    b = block(file, len, offset_of(file, "TimeValue"), &bytes);
    memcpy(back, b, 8);
    assert_true(back[0] == 2.5);
    assert_non_null(strstr(file, "NumberOfTuples=\"1\""));
    const char *tail = "\n  </AppendedData>\n</VTKFile>\n"; /* right after the last block */
    b = block(file, len, offset_of(file, "types"), &bytes);
    assert_int_equal(b + bytes + strlen(tail), file + len);
    assert_memory_equal(b + bytes, tail, strlen(tail));
    free(file);
}

static void test_image_header(void **state)
{
    (void)state;
    core_error err;
    vtk_file *f;
    const int n[3] = {4, 3, 1};
    const double o[3] = {-0.1, 0.2, 0}, h[3] = {0.1, 0.25, 1};
    assert_int_equal(vtk_image(n, o, h, &f, &err), CORE_OK);
    assert_non_null(vtk_f64(f, VTK_POINT_DATA, "m", 1, 12, &err));
    assert_non_null(vtk_f64(f, VTK_CELL_DATA, "p", 1, 6, &err));
    /* an image has no explicit points or cells */
    assert_null(vtk_f64(f, VTK_POINTS, "Points", 3, 12, &err));
    assert_int_equal(err.status, CORE_ERR_ARG);
    char path[300];
    snprintf(path, sizeof path, "%s/g.vti", dir);
    assert_int_equal(vtk_file_write(f, path, &err), CORE_OK);
    vtk_file_free(f);
    size_t len = 0;
    char *file = slurp(path, &len);
    assert_non_null(strstr(file,
                           "<ImageData WholeExtent=\"0 3 0 2 0 0\" Origin=\"-0.10000000000000001 "
                           "0.20000000000000001 0\" Spacing=\"0.10000000000000001 0.25 1\">"));
    assert_non_null(strstr(file, "<Piece Extent=\"0 3 0 2 0 0\">"));
    free(file);
}

static void test_refusals(void **state)
{
    (void)state;
    core_error err;
    vtk_file *f;
    assert_int_equal(vtk_unstructured(3, 1, &f, &err), CORE_OK);
    assert_null(vtk_f64(f, VTK_POINT_DATA, "v", 3, 2, &err));
    assert_string_equal(err.msg, "VTK array 'v' has 2 values, the point data need 3");
    assert_null(vtk_f64(f, VTK_CELL_DATA, "v", 1, 3, &err));
    assert_string_equal(err.msg, "VTK array 'v' has 3 values, the cell data need 1");
    assert_non_null(vtk_f64(f, VTK_POINT_DATA, "v", 3, 3, &err));
    assert_null(vtk_f64(f, VTK_POINT_DATA, "v", 1, 3, &err));
    assert_string_equal(err.msg, "VTK array 'v' is already in the point data");
    assert_null(vtk_f64(f, VTK_POINTS, "Points", 2, 3, &err));
    assert_null(vtk_f64(f, VTK_POINT_DATA, "", 1, 3, &err));
    assert_null(vtk_f64(f, VTK_POINT_DATA, "w", 10, 3, &err));
    char path[300];
    snprintf(path, sizeof path, "%s/nopoints.vtu", dir);
    assert_int_equal(vtk_file_write(f, path, &err), CORE_ERR_STATE);
    assert_int_equal(access(path, F_OK), -1);
    assert_non_null(vtk_f64(f, VTK_POINTS, "Points", 3, 3, &err));
    assert_non_null(vtk_cells(f, VTK_CELL_TRIANGLE, 3, &err));
    snprintf(path, sizeof path, "%s/missing/x.vtu", dir);
    assert_int_equal(vtk_file_write(f, path, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "No such file or directory"));
    vtk_file_free(f);
    const int bad[3] = {0, 1, 1};
    const double o[3] = {0, 0, 0}, h[3] = {1, 1, 1};
    assert_int_equal(vtk_image(bad, o, h, &f, &err), CORE_ERR_ARG);
}

static void test_pvd(void **state)
{
    (void)state;
    core_error err;
    char path[300];
    snprintf(path, sizeof path, "%s/run.pvd", dir);
    const double t[2] = {0.1, 1e-3 / 3};
    const char *files[2] = {"run_0001.vtu", "a&b.vtu"};
    assert_int_equal(vtk_pvd_write(path, 2, t, files, NULL, &err), CORE_OK);
    size_t len = 0;
    char *file = slurp(path, &len);
    assert_non_null(strstr(file, "<VTKFile type=\"Collection\""));
    assert_non_null(strstr(file, "<DataSet timestep=\"0.10000000000000001\" group=\"\" part=\"0\" "
                                 "file=\"run_0001.vtu\"/>"));
    assert_non_null(strstr(file, "timestep=\"0.00033333333333333332\""));
    assert_non_null(strstr(file, "file=\"a&amp;b.vtu\""));
    free(file);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unstructured_blocks),
        cmocka_unit_test(test_image_header),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_pvd),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
