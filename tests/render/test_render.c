/* The renderer at pixel level, without Lua: disk area from anti-aliased coverage, colour maps
 * against matplotlib's values, plot axes and a data point where the axes say, identical renders,
 * text inside its box, and refused sizes, scenes and paths that leave no file behind. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "dem/dem.h"
#include "render/render.h"
#include "render/render_internal.h"

static render_context *rc;
static char dir[256];

static int setup(void **state)
{
    (void)state;
    core_error err;
    if (render_context_create(&rc, &err) != CORE_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    snprintf(dir, sizeof dir, "/tmp/grainlab_render_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    render_context_destroy(rc);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd);
}

static int entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static dem_scene *one_disk(double radius, int dim)
{
    dem_scene_def def = dem_default_scene_def();
    def.dim = dim;
    for (int d = 0; d < 3; d++) {
        def.lo[d] = 0;
        def.hi[d] = 1;
        def.gravity[d] = 0;
    }
    dem_scene *s;
    core_error err;
    assert_int_equal(dem_create(&def, &s, &err), CORE_OK);
    assert_true(dem_add_material(s, &(dem_material){2650, 30e9, 0.3, 0.45, 0.5}, &err) >= 0);
    dem_particle_def p = {.x = {0.5, 0.5, 0.5}, .radius = radius};
    assert_true(dem_add_particle(s, &p, &err) >= 0);
    return s;
}

static const unsigned char *px(const render_image *img, int x, int y)
{
    return img->rgba + ((size_t)y * img->width + x) * 4;
}

/* A black disk (grey map at 0) on white: each pixel's darkness is its coverage, and the covered
 * area is pi r^2 within 1% — as a sum of coverage, and for disks above 20 px (where counting
 * lattice points is itself that exact) as a count of pixels more than half covered. */
static void test_disk_area(void **state)
{
    (void)state;
    for (int k = 0; k < 3; k++) {
        double radius = (double[]){0.2, 0.05, 0.013}[k];
        dem_scene *s = one_disk(radius, 2);
        double value = 0;
        render_grains_def def = render_default_grains_def();
        def.width = def.height = 512;
        def.box = false;
        def.color = RENDER_COLOR_VALUES;
        def.values = &value;
        def.colormap = RENDER_GRAY;
        def.range[0] = 0;
        def.range[1] = 1;
        render_image img;
        render_view view;
        core_error err;
        assert_int_equal(render_dem(rc, s, &def, &img, &view, &err), CORE_OK);
        assert_int_equal(img.width, 512);
        assert_int_equal(img.height, 512);
        double cover = 0;
        long half = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) {
                double c = (255 - px(&img, x, y)[0]) / 255.0;
                cover += c;
                half += c > 0.5;
            }
        double rp = radius * view.scale, expect = 3.14159265358979323846 * rp * rp;
        if (fabs(cover / expect - 1) > 0.01 || (rp > 20 && fabs(half / expect - 1) > 0.01))
            fail_msg("disk of %.2f px: coverage %.1f, pixels %ld, pi r^2 = %.1f", rp, cover, half,
                     expect);
        /* the centre is where the view says */
        int cx = (int)floor(view.origin[0] + 0.5 * view.scale);
        int cy = (int)floor(view.origin[1] + 0.5 * view.scale);
        assert_int_equal(px(&img, cx, cy)[0], 0);
        render_image_free(&img);
        dem_destroy(s);
    }
}

static void near_rgb(const unsigned char *got, int r, int g, int b, int tol, const char *what)
{
    if (abs(got[0] - r) > tol || abs(got[1] - g) > tol || abs(got[2] - b) > tol)
        fail_msg("%s: (%d, %d, %d), expected (%d, %d, %d) +- %d", what, got[0], got[1], got[2], r,
                 g, b, tol);
}

/* matplotlib: viridis(0) #440154, (0.25) #3b528b, (0.5) #21918c, (0.75) #5ec962, (1) #fde725;
 * grey is linear in L*: 0.5 -> L* 50 -> sRGB 119. */
static void test_colormaps(void **state)
{
    (void)state;
    unsigned char c[3];
    render_colormap_rgb(RENDER_VIRIDIS, 0, c);
    near_rgb(c, 0x44, 0x01, 0x54, 1, "viridis(0)");
    render_colormap_rgb(RENDER_VIRIDIS, 0.25, c);
    near_rgb(c, 0x3b, 0x52, 0x8b, 2, "viridis(0.25)");
    render_colormap_rgb(RENDER_VIRIDIS, 0.5, c);
    near_rgb(c, 0x21, 0x91, 0x8c, 2, "viridis(0.5)");
    render_colormap_rgb(RENDER_VIRIDIS, 0.75, c);
    near_rgb(c, 0x5e, 0xc9, 0x62, 2, "viridis(0.75)");
    render_colormap_rgb(RENDER_VIRIDIS, 1, c);
    near_rgb(c, 0xfd, 0xe7, 0x25, 1, "viridis(1)");
    render_colormap_rgb(RENDER_VIRIDIS, 7, c);
    near_rgb(c, 0xfd, 0xe7, 0x25, 1, "viridis clamps above 1");
    render_colormap_rgb(RENDER_GRAY, 0, c);
    near_rgb(c, 0, 0, 0, 0, "gray(0)");
    render_colormap_rgb(RENDER_GRAY, 0.5, c);
    near_rgb(c, 119, 119, 119, 1, "gray(0.5)");
    render_colormap_rgb(RENDER_GRAY, 1, c);
    near_rgb(c, 255, 255, 255, 0, "gray(1)");
    /* label colours: neighbouring ids are far apart */
    for (long id = 0; id < 500; id++) {
        unsigned char a[3], b[3];
        render_label_rgb(id, a);
        render_label_rgb(id + 1, b);
        double d = sqrt(pow(a[0] - b[0], 2) + pow(a[1] - b[1], 2) + pow(a[2] - b[2], 2));
        if (d < 60)
            fail_msg("label colours %ld and %ld too close (%.0f)", id, id + 1, d);
    }
}

/* A line from (0, 0) to (10, 5) and a marker at (4, 2): the limits hold the data with 4%
 * padding, the frame is drawn at the pixel rows and columns the axes report, and the marker's
 * centre pixel has the second series' colour exactly. */
static void test_plot_axes(void **state)
{
    (void)state;
    double x1[] = {0, 10}, y1[] = {0, 5}, x2[] = {4}, y2[] = {2};
    render_series series[2] = {{x1, y1, 2, "line", RENDER_LINE}, {x2, y2, 1, NULL, RENDER_POINTS}};
    render_plot_def def = render_default_plot_def();
    def.width = 640;
    def.height = 480;
    def.title = "axes";
    def.xlabel = "x";
    def.ylabel = "y";
    def.series = series;
    def.nseries = 2;
    render_image img;
    render_plot_axes ax;
    core_error err;
    assert_int_equal(render_plot(rc, &def, &img, &ax, &err), CORE_OK);
    assert_true(fabs(ax.xlim[0] + 0.4) < 1e-12 && fabs(ax.xlim[1] - 10.4) < 1e-12);
    assert_true(fabs(ax.ylim[0] + 0.2) < 1e-12 && fabs(ax.ylim[1] - 5.2) < 1e-12);
    assert_true(ax.px[0] > 20 && ax.px[1] < 640 && ax.py[1] > 20 && ax.py[0] < 480);
    int mid_x = (int)(0.5 * (ax.px[0] + ax.px[1])), mid_y = (int)(0.5 * (ax.py[0] + ax.py[1]));
    near_rgb(px(&img, (int)floor(ax.px[0]), mid_y), 25, 25, 25, 0, "left axis");
    near_rgb(px(&img, (int)floor(ax.px[1]), mid_y), 25, 25, 25, 0, "right axis");
    near_rgb(px(&img, mid_x, (int)floor(ax.py[0])), 25, 25, 25, 0, "bottom axis");
    near_rgb(px(&img, mid_x, (int)floor(ax.py[1])), 25, 25, 25, 0, "top axis");
    near_rgb(px(&img, (int)floor(ax.px[0]) - 2, mid_y), 255, 255, 255, 0, "outside the axis");
    double X = ax.px[0] + (4 - ax.xlim[0]) / (ax.xlim[1] - ax.xlim[0]) * (ax.px[1] - ax.px[0]);
    double Y = ax.py[0] + (2 - ax.ylim[0]) / (ax.ylim[1] - ax.ylim[0]) * (ax.py[1] - ax.py[0]);
    near_rgb(px(&img, (int)floor(X), (int)floor(Y)), 255, 127, 14, 0, "marker at (4, 2)");
    /* and the line passes through (5, 2.5) */
    X = ax.px[0] + (5 - ax.xlim[0]) / (ax.xlim[1] - ax.xlim[0]) * (ax.px[1] - ax.px[0]);
    Y = ax.py[0] + (2.5 - ax.ylim[0]) / (ax.ylim[1] - ax.ylim[0]) * (ax.py[1] - ax.py[0]);
    near_rgb(px(&img, (int)floor(X), (int)floor(Y)), 31, 119, 180, 40, "line at (5, 2.5)");
    render_image_free(&img);

    /* log axes: decades */
    double lx[] = {1, 10, 100, 1000}, ly[] = {1, 1e-1, 1e-2, 1e-3};
    render_series ls = {lx, ly, 4, "decay", RENDER_BOTH};
    def.series = &ls;
    def.nseries = 1;
    def.xlog = def.ylog = true;
    assert_int_equal(render_plot(rc, &def, &img, &ax, &err), CORE_OK);
    assert_true(ax.xlim[0] < 0 && ax.xlim[0] > -0.2 && ax.xlim[1] > 3 && ax.xlim[1] < 3.2);
    X = ax.px[0] + (2 - ax.xlim[0]) / (ax.xlim[1] - ax.xlim[0]) * (ax.px[1] - ax.px[0]);
    Y = ax.py[0] + (-2 - ax.ylim[0]) / (ax.ylim[1] - ax.ylim[0]) * (ax.py[1] - ax.py[0]);
    near_rgb(px(&img, (int)floor(X), (int)floor(Y)), 31, 119, 180, 0, "marker at (100, 0.01)");
    render_image_free(&img);
    ly[2] = 0;
    assert_int_equal(render_plot(rc, &def, &img, &ax, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "log axis"));
}

static void test_identical(void **state)
{
    (void)state;
    dem_scene *s = one_disk(0.1, 2);
    core_error err;
    for (int i = 0; i < 40; i++) {
        dem_particle_def p = {.x = {0.05 + 0.022 * i, 0.2 + 0.015 * (i % 7)}, .radius = 0.01};
        assert_true(dem_add_particle(s, &p, &err) >= 0);
    }
    render_grains_def def = render_default_grains_def();
    def.width = 300;
    def.title = "same";
    def.stamp = "t = 1 s";
    def.rotation = true;
    render_image a, b;
    assert_int_equal(render_dem(rc, s, &def, &a, NULL, &err), CORE_OK);
    def.color = RENDER_COLOR_SPEED; /* something else in between */
    assert_int_equal(render_dem(rc, s, &def, &b, NULL, &err), CORE_OK);
    render_image_free(&b);
    def.color = RENDER_COLOR_GRAIN;
    assert_int_equal(render_dem(rc, s, &def, &b, NULL, &err), CORE_OK);
    assert_int_equal(a.width, b.width);
    assert_int_equal(a.height, b.height);
    assert_memory_equal(a.rgba, b.rgba, (size_t)a.width * a.height * 4);

    char p1[300], p2[300];
    snprintf(p1, sizeof p1, "%s/a.png", dir);
    snprintf(p2, sizeof p2, "%s/b.png", dir);
    assert_int_equal(render_write_png(&a, p1, &err), CORE_OK);
    assert_int_equal(render_write_png(&b, p2, &err), CORE_OK);
    FILE *f1 = fopen(p1, "rb"), *f2 = fopen(p2, "rb");
    int c1, c2;
    long n = 0;
    do {
        c1 = fgetc(f1);
        c2 = fgetc(f2);
        assert_int_equal(c1, c2);
        n++;
    } while (c1 != EOF);
    fclose(f1);
    fclose(f2);
    assert_true(n > 100);
    remove(p1);
    remove(p2);
    render_image_free(&a);
    render_image_free(&b);
    dem_destroy(s);
}

/* Glyphs land inside the advance box and the ascent-descent box of the text, and nowhere else. */
static void test_text(void **state)
{
    (void)state;
    core_error err;
    const char *text = "Grain 42 (m/s)";
    double size = 20, x0 = 30, y0 = 40;
    assert_int_equal(canvas_begin(rc, 400, 100, &err), CORE_OK);
    double adv = canvas_text(rc, text, size, x0, y0, 0, 0, 0, rgba(0, 0, 0, 255));
    render_image img;
    assert_int_equal(canvas_end(rc, &img, &err), CORE_OK);
    assert_true(adv > 5 * size && adv < 10 * size);
    long inside = 0, outside = 0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            int ink = px(&img, x, y)[0] < 128;
            int in = x >= x0 - 2 && x < x0 + adv + 2 && y >= y0 && y < y0 + 1.3 * size;
            inside += ink && in;
            outside += ink && !in;
        }
    assert_true(inside > 150);
    assert_int_equal(outside, 0);
    render_image_free(&img);
}

/* One sphere seen head-on: lit from the upper left, so the upper-left part of the disk is
 * brighter than the lower-right, with a highlight near the centre-left; its outline is round
 * (the area within 1%) in both projections. */
static void test_sphere_shading(void **state)
{
    (void)state;
    for (int persp = 0; persp < 2; persp++) {
        dem_scene *s = one_disk(0.2, 3);
        double value = 0.5;
        render_grains_def def = render_default_grains_def();
        def.width = def.height = 400;
        def.box = false;
        def.color = RENDER_COLOR_VALUES;
        def.values = &value;
        def.colormap = RENDER_GRAY;
        def.range[1] = 1;
        def.camera.azimuth = -90;
        def.camera.elevation = 0;
        def.camera.perspective = persp;
        render_image img;
        render_view view;
        core_error err;
        assert_int_equal(render_dem(rc, s, &def, &img, &view, &err), CORE_OK);
        /* the sphere's centre is the box's: the middle of the drawing area */
        double cx = view.origin[0] + 0.5 * (view.hi[0] - view.lo[0]) * view.scale;
        double cy = view.origin[1] + 0.5 * (view.hi[1] - view.lo[1]) * view.scale;
        double rp = persp ? 0.2 / sqrt(pow(0.5 * sqrt(3) / tan(15 * 3.14159265358979323846 / 180), 2) - 0.04) * view.scale
                          : 0.2 * view.scale;
        int d = (int)(0.5 * rp);
        const unsigned char *ul = px(&img, (int)(cx - d), (int)(cy - d));
        const unsigned char *lr = px(&img, (int)(cx + d), (int)(cy + d));
        if (!(ul[0] > lr[0] + 60))
            fail_msg("upper left %d not brighter than lower right %d", ul[0], lr[0]);
        long inside = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++)
                inside += px(&img, x, y)[0] < 255;
        double expect = 3.14159265358979323846 * rp * rp;
        if (fabs(inside / expect - 1) > 0.02)
            fail_msg("sphere outline %ld pixels, pi r^2 = %.0f (perspective %d)", inside, expect,
                     persp);
        render_image_free(&img);
        dem_destroy(s);
    }
}

static void test_errors(void **state)
{
    (void)state;
    dem_scene *s = one_disk(0.1, 2);
    render_grains_def def = render_default_grains_def();
    render_image img = {0};
    core_error err;
    int sizes[][2] = {{0, 100}, {100000, 0}, {100, 8193}, {15, 100}};
    for (int k = 0; k < 4; k++) {
        def.width = sizes[k][0] ? sizes[k][0] : 1;
        def.height = sizes[k][1];
        assert_int_equal(render_dem(rc, s, &def, &img, NULL, &err), CORE_ERR_ARG);
        assert_non_null(strstr(err.msg, "[16, 8192]"));
        assert_null(img.rgba);
    }
    def.width = 64;
    def.height = 0;
    def.color = RENDER_COLOR_VALUES; /* without values */
    assert_int_equal(render_dem(rc, s, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.color = RENDER_COLOR_GRAIN;
    def.range[0] = 2;
    def.range[1] = 1;
    assert_int_equal(render_dem(rc, s, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.range[0] = def.range[1] = 0;
    dem_scene *s3 = one_disk(0.1, 3);
    def.force_chains = true;
    assert_int_equal(render_dem(rc, s3, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "2D scenes only"));
    def.force_chains = false;
    def.camera.fov = 90;
    assert_int_equal(render_dem(rc, s3, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "fov in (0, 90)"));
    def.camera.fov = 30;
    dem_destroy(s3);

    /* an unwritable path: an error naming it, and no file (nor temporary) left */
    assert_int_equal(render_dem(rc, s, &def, &img, NULL, &err), CORE_OK);
    char path[300];
    snprintf(path, sizeof path, "%s/missing/x.png", dir);
    assert_int_equal(render_write_png(&img, path, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, path));
    assert_int_equal(entries(), 0);
    render_image_free(&img);
    dem_destroy(s);

    /* frame patterns */
    char out[64];
    assert_int_equal(render_frame_path("out/frame_%05d.png", 42, out, sizeof out, &err), CORE_OK);
    assert_string_equal(out, "out/frame_00042.png");
    assert_int_equal(render_frame_path("f%d_100%%.png", 7, out, sizeof out, &err), CORE_OK);
    assert_string_equal(out, "f7_100%.png");
    assert_int_equal(render_frame_path("plain.png", 7, out, sizeof out, &err), CORE_OK);
    assert_string_equal(out, "plain.png");
    assert_int_equal(render_frame_path("f%s.png", 7, out, sizeof out, &err), CORE_ERR_ARG);
    assert_int_equal(render_frame_path("f%d_%d.png", 7, out, sizeof out, &err), CORE_ERR_ARG);
    assert_int_equal(render_frame_path("f%d.png", 7, out, 4, &err), CORE_ERR_ARG);

    render_plot_def pd = render_default_plot_def();
    assert_int_equal(render_plot(rc, &pd, &img, NULL, &err), CORE_ERR_ARG); /* no series */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disk_area), cmocka_unit_test(test_colormaps),
        cmocka_unit_test(test_plot_axes), cmocka_unit_test(test_identical),
        cmocka_unit_test(test_text),      cmocka_unit_test(test_sphere_shading),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
