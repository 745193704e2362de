/* grainlab's headless renderer: an OSMesa (llvmpipe) off-screen context draws anti-aliased disks,
 * segments and FreeType text; images are written as PNG through core/fileio (temp + rename).
 *
 * Usage: create one render_context and reuse it (it holds the GL context, the shaders and the
 * font); fill a render_grains_def from render_default_grains_def() and call render_dem, or a
 * render_plot_def for render_plot, a render_field_def for render_field (grid fields of MPM and
 * DSMC), a render_points_def for render_points (point clouds); write the image with
 * render_write_png. The same input gives
 * the same pixels on the same machine. Nothing here knows about Lua. */
#ifndef GRAINLAB_RENDER_H
#define GRAINLAB_RENDER_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "dem/dem.h"

enum {
    RENDER_MIN_SIZE = 16,   /* pixels per side, both limits included */
    RENDER_MAX_SIZE = 8192,
    RENDER_DEFAULT_WIDTH = 1024
};

typedef struct render_context render_context;

/* Starts the off-screen GL context and loads the font (DejaVu Sans from fonts-dejavu-core, or
 * the file named by the environment variable GRAINLAB_FONT). */
core_status render_context_create(render_context **out, core_error *err);
void render_context_destroy(render_context *rc);

/* ---- images -------------------------------------------------------------------------------- */
typedef struct render_image {
    int width, height;
    unsigned char *rgba; /* width * height * 4 bytes, top row first, opaque */
} render_image;

void render_image_free(render_image *img);
/* Writes an 8-bit RGB PNG whole (temporary file + rename): on failure no file is left. */
core_status render_write_png(const render_image *img, const char *path, core_error *err);
/* Expands a frame pattern with one printf-style integer conversion ("out/frame_%05d.png",
 * flags 0 and a width only; "%%" is a literal percent) with frame. A path without '%' is
 * copied unchanged. */
core_status render_frame_path(const char *pattern, long frame, char *out, size_t size,
                              core_error *err);

/* ---- colours ------------------------------------------------------------------------------- */
typedef enum render_colormap {
    RENDER_VIRIDIS, /* matplotlib's viridis (CC0), perceptually uniform, dark blue -> yellow */
    RENDER_GRAY     /* linear in CIE lightness L*: black -> white */
} render_colormap;

/* t in [0, 1] (clamped; NaN gives mid grey) to 8-bit sRGB. */
void render_colormap_rgb(render_colormap map, double t, unsigned char rgb[3]);
/* Well-separated colours for integer labels (grain ids, materials, series): consecutive ids
 * differ strongly in hue and lightness. */
void render_label_rgb(long id, unsigned char rgb[3]);

/* ---- 2D grain frames ----------------------------------------------------------------------- */
typedef enum render_color_by {
    RENDER_COLOR_GRAIN,    /* well-separated colours by grain id */
    RENDER_COLOR_SPEED,    /* |v| through the colour map */
    RENDER_COLOR_ROTATION, /* angular velocity omega_z (2D) or |omega| (3D), rad/s */
    RENDER_COLOR_VALUES,   /* def.values[i] through the colour map */
    RENDER_COLOR_LABELS    /* def.labels[i] as well-separated colours (materials, clusters) */
} render_color_by;

typedef struct render_wall {
    double point[3], normal[3]; /* a line (2D, z ignored) or plane through point, normal into
                                 * the domain */
} render_wall;

/* 3D scenes: the camera looks at the box's centre from the direction given by azimuth (degrees,
 * around the up axis, which is opposite to gravity, or z without gravity) and elevation (degrees
 * above the horizontal). Perspective: field of view fov (degrees, in (0, 90)), the camera as close
 * as keeps the whole box in view. */
typedef struct render_camera {
    double azimuth, elevation;
    bool perspective;
    double fov;
} render_camera;

typedef struct render_grains_def {
    int width, height;          /* 0: width 1024, height from the box's aspect */
    render_camera camera;       /* 3D only: default azimuth -60, elevation 25, orthographic */
    render_color_by color;
    const double *values;       /* RENDER_COLOR_VALUES: one per grain */
    const int *labels;          /* RENDER_COLOR_LABELS: one per grain */
    render_colormap colormap;
    double range[2];            /* colour-map limits; range[0] == range[1]: min and max of data */
    bool force_chains;          /* 2D: segments between contacting centres, width and shade ~ fn */
    bool rotation;              /* 2D: a radius line at each grain's orientation angle */
    const double *angles;       /* orientation per grain (rad) for the markers; NULL: 0 */
    bool box;                   /* outline of the scene's box */
    bool colorbar;              /* colour bar with ticks (colour-map modes only) */
    const double *arrows[2];    /* 2D: a vector per grain (e.g. displacement, m) drawn as an arrow
                                 * from its centre; NULL: none */
    double arrow_scale;         /* arrow length per unit of vector; 0: the longest arrow is three
                                 * mean radii. A reference arrow is drawn in the title band. */
    const render_wall *walls;   /* clipped to the box. 2D: thick lines on their outer side;
                                 * 3D: the outline of the plane's section of the box, with the
                                 * box's edges behind the grains (no depth test) */
    int nwalls;
    bool shapes;                /* the scene's walls beyond planes (polylines, circles, meshes,
                                 * cylinders) where they are now: 2D a line along the surface over
                                 * the grains; 3D their edges and rims behind the spheres */
    const char *title;          /* UTF-8 or NULL, top left */
    const char *stamp;          /* UTF-8 or NULL, top right (e.g. "t = 0.125 s") */
    const char *colorbar_label; /* NULL: from the colour mode ("speed (m/s)", ...) */
} render_grains_def;

render_grains_def render_default_grains_def(void); /* grain colours, viridis, box outline */

/* Where the box landed: pixel = (x - lo) * scale + origin (y downwards from the top). In 3D, x
 * and y are the camera's image-plane coordinates (perspective: divided by the depth). */
typedef struct render_view {
    double lo[2], hi[2];
    double scale;        /* pixels per metre */
    double origin[2];    /* pixel position of (lo[0], hi[1]): the top-left corner of the box */
    double range[2];     /* colour-map limits used */
} render_view;

/* Draws a scene: 2D disks, or 3D shaded spheres far to near (force chains, rotation markers and
 * arrows are 2D only). Fails (CORE_ERR_ARG) on a bad size, camera or missing arrays. */
core_status render_dem(render_context *rc, dem_scene *s, const render_grains_def *def,
                       render_image *out, render_view *view, core_error *err);

/* ---- grid fields (MPM, DSMC) ------------------------------------------------------------------
 * nx x ny cells over the rectangle extent, cell-centred: cell (i, j) covers
 * [x0 + i dx, x0 + (i + 1) dx] x [y0 + j dy, y0 + (j + 1) dy] and is element j * nx + i of the
 * arrays (row-major, the first row at the bottom, y = y0). Each pixel takes the colour of the cell
 * its centre falls in (RENDER_NEAREST), or the bilinear interpolation between the centres of the
 * four nearest cells with values, clamped at the edges (RENDER_BILINEAR). A cell without a value
 * (NaN, or mask 0) shows the background in its whole area, in both modes. Arrows shorter than
 * two line widths are left out. */
typedef enum render_interp { RENDER_NEAREST, RENDER_BILINEAR } render_interp;

typedef struct render_field_def {
    int width, height;          /* 0: width 1024, height from the extent's aspect */
    int nx, ny;                 /* cells along x and y, >= 1 */
    double extent[2][2];        /* {{x0, y0}, {x1, y1}} with x1 > x0, y1 > y0 */
    const double *values;       /* nx * ny; NULL: no colours (arrows only) */
    const unsigned char *mask;  /* NULL, or nx * ny flags: 0 hides the cell */
    const unsigned char *background; /* NULL, or the RGB of cells without a value (NULL: the
                                      * page's white; with RENDER_GRAY white reads as large) */
    render_interp interp;
    render_colormap colormap;   /* principal stress difference: RENDER_GRAY (white = large) */
    double range[2];            /* colour-map limits; range[0] == range[1]: min and max of data */
    bool colorbar;              /* with ticks and colorbar_label (when there are values) */
    bool box;                   /* outline of the extent */
    const double *arrows[2];    /* NULL, or nx * ny vector components (u, v) drawn as arrows from
                                 * the cell centres; NaN or hidden cells: none */
    double arrow_scale;         /* scene length per unit of vector; 0: the longest arrow is 0.9 of
                                 * the arrow spacing. A reference arrow sits in the title band. */
    int arrow_every;            /* an arrow every k-th cell along x and y; 0: k such that arrows
                                 * are at least 1.5 font sizes apart */
    const char *arrow_unit;     /* after the reference arrow's value ("m/s"); NULL: none */
    const char *title, *stamp, *colorbar_label; /* UTF-8 or NULL */
} render_field_def;

render_field_def render_default_field_def(void); /* nearest, viridis, colour bar, box */

/* view: as for render_dem (lo, hi = the extent). Fails (CORE_ERR_ARG) on a bad size, grid,
 * extent, range or scale, or with neither values nor arrows. Values of which not one cell is
 * shown (all NaN or masked) draw no colour bar but a note "no values: all N cells are NaN" across
 * the extent: never a silently blank frame. */
core_status render_field(render_context *rc, const render_field_def *def, render_image *out,
                         render_view *view, core_error *err);

/* ---- point clouds (material points, DSMC particles) ------------------------------------------ */
typedef struct render_points_def {
    int width, height;          /* 0: width 1024, height from the extent's aspect */
    const double *x, *y;        /* positions (scene units); non-finite ones are not drawn */
    size_t n;
    const double *values;       /* NULL: one colour; else through the colour map (NaN: grey) */
    render_colormap colormap;
    double range[2];            /* colour-map limits; range[0] == range[1]: min and max of data */
    double size;                /* diameter in pixels (anti-aliased disks); 0: 4 */
    double extent[2][2];        /* the scene's rectangle; x1 <= x0 or y1 <= y0 (the default):
                                 * the points' bounding box padded by 2%. Points whose centre lies
                                 * outside are not drawn. */
    bool colorbar, box;
    const char *title, *stamp, *colorbar_label;
} render_points_def;

render_points_def render_default_points_def(void); /* viridis, 4 px, colour bar, box */

/* Points are drawn in input order (later ones on top). view: as for render_dem. */
core_status render_points(render_context *rc, const render_points_def *def, render_image *out,
                          render_view *view, core_error *err);

/* ---- line plots ---------------------------------------------------------------------------- */
/* RENDER_HIDDEN: the series only widens the axes (equal extents for a rose, a common origin). */
typedef enum render_plot_style {
    RENDER_LINE,
    RENDER_POINTS,
    RENDER_BOTH,
    RENDER_HIDDEN
} render_plot_style;

typedef struct render_series {
    const double *x, *y;
    size_t n;
    const char *label;   /* NULL: not in the legend */
    render_plot_style style;
} render_series;

typedef struct render_plot_def {
    int width, height;   /* 0: 800 x 560 */
    const char *title, *xlabel, *ylabel;
    bool xlog, ylog;
    const render_series *series;
    int nseries;
} render_plot_def;

render_plot_def render_default_plot_def(void);

/* Where the axes landed: pixel x = px[0] + (X - lim[0]) / (lim[1] - lim[0]) * (px[1] - px[0])
 * with X = log10(x) on a log axis (limits then also in log10), the same for y (py[0] is the
 * bottom pixel row of the frame, py[1] the top one). */
typedef struct render_plot_axes {
    double xlim[2], ylim[2];
    double px[2], py[2];
} render_plot_axes;

core_status render_plot(render_context *rc, const render_plot_def *def, render_image *out,
                        render_plot_axes *axes, core_error *err);

#endif
