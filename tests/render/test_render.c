/* The renderer at pixel level, without Lua: disk area from anti-aliased coverage, colour maps
 * against matplotlib's values, plot axes and a data point where the axes say, identical renders,
 * text inside its box, grid fields (cell colours, no-value cells, bilinear, arrows) and point
 * clouds, and refused sizes, scenes, grids and paths that leave no file behind. */
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
    assert_true(dem_add_material(s, &(dem_material){2650, 30e9, 0.3, 0.45, 0.5, 0, 0}, &err) >= 0);
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

/* Walls: in 2D a thick dark line on the outer side of the wall, the inner side clean; in 3D the
 * outline of the plane's section of the box (seen edge-on here: the camera looks along +y, so a
 * plane x = c or z = c is a line on the image); a plane that misses the box draws nothing. */
static int dark_gray(const unsigned char *c)
{
    return c[0] < 200 && abs(c[0] - c[1]) < 8 && abs(c[1] - c[2]) < 8;
}

static void test_walls(void **state)
{
    (void)state;
    core_error err;
    render_view view;
    render_image img, none;
    /* 2D: a wall at x = 0.75 facing -x (the domain is on its left) */
    dem_scene *s = one_disk(0.1, 2);
    render_grains_def def = render_default_grains_def();
    def.width = def.height = 400;
    def.box = false;
    render_wall w2[2] = {{.point = {0.75, 0, 0}, .normal = {-1, 0, 0}},
                         {.point = {2, 0, 0}, .normal = {1, 0, 0}}}; /* outside the box */
    def.walls = w2;
    def.nwalls = 2;
    assert_int_equal(render_dem(rc, s, &def, &img, &view, &err), CORE_OK);
    double X = view.origin[0] + 0.75 * view.scale;
    int ymid = (int)(view.origin[1] + 0.5 * view.scale);
    int dark = 0;
    for (int x = (int)X; x <= (int)X + 3; x++)
        dark += dark_gray(px(&img, x, ymid));
    if (dark < 2)
        fail_msg("2D wall at column %.1f: only %d dark pixels beside it", X, dark);
    const unsigned char *inner = px(&img, (int)X - 3, ymid);
    near_rgb(inner, 255, 255, 255, 0, "inner side of the 2D wall");
    def.nwalls = 1; /* the wall outside the box adds nothing */
    assert_int_equal(render_dem(rc, s, &def, &none, NULL, &err), CORE_OK);
    assert_memory_equal(img.rgba, none.rgba, (size_t)img.width * img.height * 4);
    render_image_free(&none);
    def.nwalls = 0;
    assert_int_equal(render_dem(rc, s, &def, &none, NULL, &err), CORE_OK);
    near_rgb(px(&none, (int)X + 1, ymid), 255, 255, 255, 0, "no walls: nothing at the wall");
    render_image_free(&none);
    render_image_free(&img);
    dem_destroy(s);

    /* 3D, orthographic, looking along +y: image x = world x, image y = world z */
    s = one_disk(0.1, 3);
    def = render_default_grains_def();
    def.width = def.height = 400;
    def.box = false;
    def.camera.azimuth = -90;
    def.camera.elevation = 0;
    render_wall w3[3] = {{.point = {0.75, 0, 0}, .normal = {-1, 0, 0}},
                         {.point = {0, 0, 0.25}, .normal = {0, 0, 1}},
                         {.point = {0, 0, 5}, .normal = {0, 0, -1}}};
    def.walls = w3;
    def.nwalls = 3;
    assert_int_equal(render_dem(rc, s, &def, &img, &view, &err), CORE_OK);
    def.nwalls = 0;
    assert_int_equal(render_dem(rc, s, &def, &none, NULL, &err), CORE_OK);
    int cx = (int)(view.origin[0] + 0.75 * view.scale),
        cy = (int)(view.origin[1] + 0.5 * view.scale);
    int hx = (int)(view.origin[0] + 0.5 * view.scale),
        hy = (int)(view.origin[1] + 0.75 * view.scale);
    dark = 0;
    for (int k = -1; k <= 1; k++)
        dark += dark_gray(px(&img, cx + k, cy)) + dark_gray(px(&img, hx, hy + k));
    if (dark < 2)
        fail_msg("3D walls x = 0.75 and z = 0.25: %d dark pixels at (%d, %d) and (%d, %d)", dark,
                 cx, cy, hx, hy);
    near_rgb(px(&none, cx, cy), 255, 255, 255, 0, "3D without walls");
    near_rgb(px(&none, hx, hy), 255, 255, 255, 0, "3D without walls");
    long changed = 0;
    for (size_t i = 0; i < (size_t)img.width * img.height * 4; i++)
        changed += img.rgba[i] != none.rgba[i];
    if (changed < 400) /* two lines across the box, each some 300 px long */
        fail_msg("3D walls changed only %ld channel values", changed);
    render_image_free(&none);
    render_image_free(&img);
    dem_destroy(s);
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

/* ---- grid fields and point clouds ---------------------------------------------------------- */
/* The pixel at the centre of cell (i, j) of a field drawn with view. */
static const unsigned char *cell_px(const render_image *img, const render_view *v, int nx, int ny,
                                    int i, int j)
{
    double dx = (v->hi[0] - v->lo[0]) / nx, dy = (v->hi[1] - v->lo[1]) / ny;
    int x = (int)floor(v->origin[0] + (i + 0.5) * dx * v->scale);
    int y = (int)floor(v->origin[1] + (ny - j - 0.5) * dy * v->scale);
    return px(img, x, y);
}

/* A 4 x 2 gradient (value i + 4 j, first row at the bottom) in grey: each cell's centre pixel has
 * exactly the colour map's colour, the largest value is white; NaN and masked cells show the
 * background; bilinear interpolation halfway between two cell centres gives their mean. */
static void test_field_cells(void **state)
{
    (void)state;
    double values[8];
    for (int k = 0; k < 8; k++)
        values[k] = k;
    render_field_def def = render_default_field_def();
    def.width = 400;
    def.nx = 4;
    def.ny = 2;
    def.extent[0][0] = -1;
    def.extent[1][0] = 3;
    def.extent[1][1] = 2; /* square cells */
    def.values = values;
    def.colormap = RENDER_GRAY;
    def.range[1] = 7;
    render_image img;
    render_view view;
    core_error err;
    assert_int_equal(render_field(rc, &def, &img, &view, &err), CORE_OK);
    assert_true(view.range[0] == 0 && view.range[1] == 7);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            unsigned char c[3];
            render_colormap_rgb(RENDER_GRAY, (i + 4 * j) / 7.0, c);
            char what[32];
            snprintf(what, sizeof what, "cell (%d, %d)", i, j);
            near_rgb(cell_px(&img, &view, 4, 2, i, j), c[0], c[1], c[2], 0, what);
        }
    near_rgb(cell_px(&img, &view, 4, 2, 3, 1), 255, 255, 255, 0, "largest value is white");
    near_rgb(cell_px(&img, &view, 4, 2, 0, 0), 0, 0, 0, 0, "smallest value is black");
    render_image_free(&img);

    /* no value: NaN, or masked; the page's white, or the background given */
    unsigned char mask[8] = {1, 1, 1, 1, 1, 1, 0, 1}, bg[3] = {10, 200, 30};
    values[1] = NAN;
    def.mask = mask;
    def.colormap = RENDER_VIRIDIS;
    assert_int_equal(render_field(rc, &def, &img, &view, &err), CORE_OK);
    near_rgb(cell_px(&img, &view, 4, 2, 1, 0), 255, 255, 255, 0, "NaN cell");
    near_rgb(cell_px(&img, &view, 4, 2, 2, 1), 255, 255, 255, 0, "masked cell");
    render_image_free(&img);
    def.background = bg;
    def.interp = RENDER_BILINEAR;
    assert_int_equal(render_field(rc, &def, &img, &view, &err), CORE_OK);
    near_rgb(cell_px(&img, &view, 4, 2, 1, 0), 10, 200, 30, 0, "NaN cell, bilinear, background");
    near_rgb(cell_px(&img, &view, 4, 2, 2, 1), 10, 200, 30, 0, "masked cell, background");
    /* bilinear: the edge between cells (2, 0) and (3, 0) (values 2 and 3) is 2.5 */
    double cpx = view.scale; /* a cell is 1 x 1 */
    int x = (int)floor(view.origin[0] + 3 * cpx), y = (int)floor(view.origin[1] + 1.5 * cpx);
    unsigned char lo[3], hi[3];
    render_colormap_rgb(RENDER_VIRIDIS, 2.4 / 7, lo);
    render_colormap_rgb(RENDER_VIRIDIS, 2.6 / 7, hi);
    const unsigned char *p = px(&img, x, y);
    for (int c = 0; c < 3; c++)
        if (p[c] < (lo[c] < hi[c] ? lo[c] : hi[c]) || p[c] > (lo[c] > hi[c] ? lo[c] : hi[c]))
            fail_msg("bilinear between 2 and 3: channel %d = %d, not within [%d, %d]", c, p[c],
                     lo[c], hi[c]);
    render_image_free(&img);
}

/* A uniform field (1, 0) on 5 x 5 cells of 0.2 m, arrows 0.1 m per unit: each arrow starts at its
 * cell centre and points right, so red ink lies 0.05 m right of a centre and none 0.05 m left of
 * it or above it. */
static void test_field_arrows(void **state)
{
    (void)state;
    double u[25], v[25];
    for (int k = 0; k < 25; k++)
        u[k] = 1, v[k] = 0;
    render_field_def def = render_default_field_def();
    def.width = def.height = 300;
    def.nx = def.ny = 5;
    def.extent[1][0] = def.extent[1][1] = 1;
    def.arrows[0] = u;
    def.arrows[1] = v;
    def.arrow_scale = 0.1;
    def.arrow_every = 1;
    render_image img;
    render_view view;
    core_error err;
    assert_int_equal(render_field(rc, &def, &img, &view, &err), CORE_OK);
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            double cx = view.origin[0] + (0.2 * i + 0.1) * view.scale;
            double cy = view.origin[1] + (1 - 0.2 * j - 0.1) * view.scale;
            double d = 0.05 * view.scale;
            near_rgb(px(&img, (int)floor(cx + d), (int)floor(cy)), 190, 30, 30, 0, "shaft");
            near_rgb(px(&img, (int)floor(cx - d), (int)floor(cy)), 255, 255, 255, 0, "behind");
            near_rgb(px(&img, (int)floor(cx + d), (int)floor(cy - d)), 255, 255, 255, 0, "above");
        }
    render_image_free(&img);
}

/* One point of 8 px at (0.3, 0.7) in [0, 1]^2: its centre pixel has the colour map's colour, a
 * pixel 6 px away is white, and the anti-aliased coverage sums to pi (4 px)^2 within 2%. */
static void test_points(void **state)
{
    (void)state;
    double x = 0.3, y = 0.7, value = 0.25;
    render_points_def def = render_default_points_def();
    def.width = def.height = 200;
    def.x = &x;
    def.y = &y;
    def.n = 1;
    def.values = &value;
    def.colormap = RENDER_GRAY;
    def.range[1] = 1;
    def.size = 8;
    def.extent[1][0] = def.extent[1][1] = 1;
    def.colorbar = def.box = false;
    render_image img;
    render_view view;
    core_error err;
    assert_int_equal(render_points(rc, &def, &img, &view, &err), CORE_OK);
    double X = view.origin[0] + x * view.scale, Y = view.origin[1] + (1 - y) * view.scale;
    unsigned char c[3];
    render_colormap_rgb(RENDER_GRAY, 0.25, c);
    near_rgb(px(&img, (int)floor(X), (int)floor(Y)), c[0], c[1], c[2], 0, "the point");
    near_rgb(px(&img, (int)floor(X) + 6, (int)floor(Y)), 255, 255, 255, 0, "beside it");
    double cover = 0;
    for (int yy = 0; yy < img.height; yy++)
        for (int xx = 0; xx < img.width; xx++)
            cover += (255 - px(&img, xx, yy)[0]) / (255.0 - c[0]);
    if (fabs(cover / (3.14159265358979323846 * 16) - 1) > 0.02)
        fail_msg("point coverage %.2f, pi r^2 = %.2f", cover, 3.14159265358979323846 * 16);
    render_image_free(&img);
}

/* The same field or cloud twice, something else in between: the same pixels. */
static void test_field_identical(void **state)
{
    (void)state;
    enum { NX = 37, NY = 23, NP = 500 };
    double values[NX * NY], u[NX * NY], v[NX * NY], x[NP], y[NP];
    for (int k = 0; k < NX * NY; k++) {
        values[k] = sin(0.3 * k) * cos(0.11 * k);
        u[k] = cos(0.2 * k);
        v[k] = sin(0.17 * k);
    }
    for (int k = 0; k < NP; k++) {
        x[k] = fmod(k * 0.618034, 1.0);
        y[k] = fmod(k * 0.414214, 1.0);
    }
    render_field_def fd = render_default_field_def();
    fd.width = 320;
    fd.nx = NX;
    fd.ny = NY;
    fd.extent[1][0] = 2;
    fd.extent[1][1] = 1;
    fd.values = values;
    fd.interp = RENDER_BILINEAR;
    fd.arrows[0] = u;
    fd.arrows[1] = v;
    fd.title = "same";
    render_points_def pd = render_default_points_def();
    pd.width = 320;
    pd.x = x;
    pd.y = y;
    pd.n = NP;
    pd.values = x;
    render_image a, b, other;
    core_error err;
    assert_int_equal(render_field(rc, &fd, &a, NULL, &err), CORE_OK);
    assert_int_equal(render_points(rc, &pd, &other, NULL, &err), CORE_OK);
    assert_int_equal(render_field(rc, &fd, &b, NULL, &err), CORE_OK);
    assert_int_equal(a.width, b.width);
    assert_int_equal(a.height, b.height);
    assert_memory_equal(a.rgba, b.rgba, (size_t)a.width * a.height * 4);
    render_image_free(&b);
    assert_int_equal(render_points(rc, &pd, &b, NULL, &err), CORE_OK);
    assert_memory_equal(other.rgba, b.rgba, (size_t)b.width * b.height * 4);
    render_image_free(&a);
    render_image_free(&b);
    render_image_free(&other);
}

static void test_field_errors(void **state)
{
    (void)state;
    double values[4] = {1, 2, 3, 4};
    render_image img = {0};
    core_error err;
    render_field_def def = render_default_field_def();
    def.nx = def.ny = 2;
    def.extent[1][0] = def.extent[1][1] = 1;
    def.values = values;
    def.width = 15;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "[16, 8192]"));
    def.width = 64;
    def.height = 9000;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.height = 0;
    def.nx = 0;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "0 x 2 cells"));
    def.nx = 2;
    def.extent[1][0] = 0;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "x1 > x0"));
    def.extent[1][0] = NAN;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.extent[1][0] = 1;
    def.range[0] = 2;
    def.range[1] = 1;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.range[0] = def.range[1] = 0;
    def.arrows[0] = values; /* without v */
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.arrows[1] = values;
    def.arrow_scale = -1;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    def.arrow_scale = 0;
    def.values = NULL;
    def.arrows[0] = def.arrows[1] = NULL;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "values, arrows or both"));
    assert_null(img.rgba);
    /* a single value: still drawn, mid-map */
    def.values = values;
    def.nx = def.ny = 1;
    def.width = 200;
    assert_int_equal(render_field(rc, &def, &img, NULL, &err), CORE_OK);
    render_image_free(&img);

    render_points_def pd = render_default_points_def();
    double x[2] = {0, 1};
    pd.x = x;
    pd.y = x;
    pd.n = 2;
    pd.size = -1;
    assert_int_equal(render_points(rc, &pd, &img, NULL, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "point size"));
    pd.size = 3;
    pd.width = 100000;
    assert_int_equal(render_points(rc, &pd, &img, NULL, &err), CORE_ERR_ARG);
    pd.width = 64;
    pd.y = NULL;
    assert_int_equal(render_points(rc, &pd, &img, NULL, &err), CORE_ERR_ARG);
    pd.y = x;
    pd.extent[1][0] = 1; /* x given, y not increasing */
    assert_int_equal(render_points(rc, &pd, &img, NULL, &err), CORE_ERR_ARG);
    assert_null(img.rgba);
    pd.n = 0; /* nothing to draw is fine */
    pd.extent[1][0] = 0;
    assert_int_equal(render_points(rc, &pd, &img, NULL, &err), CORE_OK);
    render_image_free(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disk_area),    cmocka_unit_test(test_colormaps),
        cmocka_unit_test(test_plot_axes),    cmocka_unit_test(test_identical),
        cmocka_unit_test(test_text),         cmocka_unit_test(test_sphere_shading),
        cmocka_unit_test(test_errors),       cmocka_unit_test(test_field_cells),
        cmocka_unit_test(test_walls),        cmocka_unit_test(test_field_arrows),
        cmocka_unit_test(test_points),       cmocka_unit_test(test_field_identical),
        cmocka_unit_test(test_field_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
