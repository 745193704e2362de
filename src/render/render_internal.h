/* The renderer's canvas, shared by the files of src/render/ only: a pixel canvas (origin at the
 * top-left corner, y downwards, pixel centres at +0.5) drawn by GL through three primitives —
 * anti-aliased disks, anti-aliased segments and rectangles, and FreeType text — plus axis ticks
 * and their labels. */
#ifndef GRAINLAB_RENDER_INTERNAL_H
#define GRAINLAB_RENDER_INTERNAL_H

#include "render/render.h"

typedef struct rgba8 {
    unsigned char r, g, b, a;
} rgba8;

/* Starts a white canvas of w x h pixels. */
core_status canvas_begin(render_context *rc, int w, int h, core_error *err);
/* Finishes drawing and copies the pixels into out (allocated here). */
core_status canvas_end(render_context *rc, render_image *out, core_error *err);

/* A filled disk of radius r pixels; edge > 0 darkens a rim of that width; edge < 0 shades it as
 * a sphere lit from the upper left. Disks below 0.7 px are drawn at 0.7 px with their alpha
 * reduced to keep the covered area. */
void canvas_disk(render_context *rc, double x, double y, double r, double edge, rgba8 c);
/* A segment of full width w; round caps when round, else it ends exactly at its end points
 * (a rectangle when drawn along an axis). Widths below 1 px are drawn 1 px wide, fainter. */
void canvas_segment(render_context *rc, double x0, double y0, double x1, double y1, double w,
                    int round, rgba8 c);
void canvas_rect(render_context *rc, double x0, double y0, double x1, double y1, rgba8 c);
/* An arrow from (x0, y0) to (x1, y1) along the unit vector (dx, dy): a round-capped shaft of
 * width w and a head of two strokes of length hl at 25 degrees to it. */
void canvas_arrow(render_context *rc, double x0, double y0, double x1, double y1, double dx,
                  double dy, double w, double hl, rgba8 c);
/* A block of w x h pixels (RGBA, top row first) copied with its top-left corner on the whole
 * pixel (x, y); pixels of alpha 0 leave the canvas as it is. Exact: no filtering. */
void canvas_pixels(render_context *rc, int x, int y, int w, int h, const unsigned char *rgba);

/* Text of pixel size px anchored at (x, y): ha 0 left, 0.5 centre, 1 right of the advance box;
 * va 0 top, 0.5 middle, 1 bottom of the ascent-descent box. vertical: rotated 90 degrees
 * counter-clockwise (reads bottom to top). Returns the advance width. */
double canvas_text(render_context *rc, const char *utf8, double px, double x, double y, double ha,
                   double va, int vertical, rgba8 c);
double canvas_text_width(render_context *rc, const char *utf8, double px);

/* Font pixel size for an image: readable at any width. */
double canvas_font_px(int width, int height);

/* Up to max "nice" ticks (1, 2, 5 x 10^k steps) inside [lo, hi]; returns their number. */
int ticks_linear(double lo, double hi, int target, double *ticks, int max, double *step);
/* A tick label for v on a grid of spacing step ("0.25", "1.5e-05", "−3"). */
/* Tick label for v in a set of ticks `step` apart whose largest magnitude is vmax (labels of one
 * set share their notation, exponent and precision). */
void ticks_format(double v, double step, double vmax, char *buf, size_t size);

/* A vertical colour bar with ticks and a rotated label, right of a scene (grains, fields, points). */
typedef struct colorbar {
    double range[2], fs, step, maxlabel;
    double ticks[16];
    char labels[16][64];
    int nticks, bar_w, gap, tick_len, lgap;
    const char *label;
} colorbar;
/* Ticks and labels for range at font size fs; returns the width of the band it needs right of
 * the scene (gap, bar, ticks, labels and the label). */
int colorbar_layout(render_context *rc, colorbar *cb, const double range[2], const char *label,
                    double fs);
/* Draws the bar gap pixels right of column right, from row top to row bottom (rounded). */
void colorbar_draw(render_context *rc, const colorbar *cb, render_colormap map, double right,
                   double top, double bottom);
/* A reference arrow of a round length (1, 2 or 5 x 10^k, at most umax) for arrows drawn k * sc
 * pixels per unit, followed by its value and unit ("0.02 m"; unit may be NULL) right-aligned at
 * column right, the text's box ending at row bottom; head: the head length's upper limit. */
void reference_arrow(render_context *rc, double umax, double k, double sc, const char *unit,
                     double right, double bottom, double fs, double w, double head, rgba8 c);

static inline rgba8 rgba(unsigned char r, unsigned char g, unsigned char b, unsigned char a)
{
    rgba8 c = {r, g, b, a};
    return c;
}

#endif
