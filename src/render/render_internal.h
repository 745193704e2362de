/* The renderer's canvas, shared by the files of src/render/ only: a pixel canvas (origin at the
 * top-left corner, y downwards, pixel centres at +0.5) drawn by GL through three primitives —
 * anti-aliased disks, anti-aliased segments and rectangles, and FreeType text — plus tick helpers. */
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
void ticks_format(double v, double step, char *buf, size_t size);

static inline rgba8 rgba(unsigned char r, unsigned char g, unsigned char b, unsigned char a)
{
    rgba8 c = {r, g, b, a};
    return c;
}

#endif
