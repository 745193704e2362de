/* Coarse-grained fields with principal-direction glyphs: render_field draws the colours, bar and
 * arrows; the glyphs go over its pixels on a second canvas of the same size. */
#include <math.h>
#include <string.h>

#include "render/cg.h"
#include "render/render_internal.h"

render_cg_def render_default_cg_def(void)
{
    render_cg_def d;
    memset(&d, 0, sizeof d);
    d.field = render_default_field_def();
    d.glyph_rgb[0] = 200;
    d.glyph_rgb[1] = 20;
    d.glyph_rgb[2] = 30;
    return d;
}

core_status render_cg(render_context *rc, const render_cg_def *def, render_image *out,
                      render_view *view, core_error *err)
{
    render_view v;
    render_image base = {0, 0, NULL};
    core_status st = render_field(rc, &def->field, &base, &v, err);
    if (st != CORE_OK || !def->glyph_angle) {
        *out = base;
        if (view)
            *view = v;
        return st;
    }
    if (def->glyph_every < 0) {
        render_image_free(&base);
        return core_fail(err, CORE_ERR_ARG, "glyph spacing %d: >= 0 expected", def->glyph_every);
    }
    const render_field_def *f = &def->field;
    const int nx = f->nx, ny = f->ny;
    const double dx = (f->extent[1][0] - f->extent[0][0]) / nx;
    const double dy = (f->extent[1][1] - f->extent[0][1]) / ny;
    int every = def->glyph_every;
    if (every == 0) { /* about 28 glyphs across the wider side */
        int wide = nx > ny ? nx : ny;
        every = wide / 28 > 1 ? wide / 28 : 1;
    }
    /* glyphs at the centres of blocks of every x every cells (whole blocks only, so that no
     * glyph leaves the extent), with the values of the cell at (or just past) the centre */
    double vmax = 0;
    for (int j0 = 0; j0 + every <= ny; j0 += every)
        for (int i0 = 0; i0 + every <= nx; i0 += every) {
            size_t k = (size_t)(j0 + every / 2) * (size_t)nx + (size_t)(i0 + every / 2);
            double g = def->glyph_value ? def->glyph_value[k] : 1;
            if (isfinite(g) && isfinite(def->glyph_angle[k]) && (!f->mask || f->mask[k]))
                vmax = fmax(vmax, fabs(g));
        }
    if ((st = canvas_begin(rc, base.width, base.height, err)) != CORE_OK) {
        render_image_free(&base);
        return st;
    }
    canvas_pixels(rc, 0, 0, base.width, base.height, base.rgba);
    render_image_free(&base);
    const double spacing = every * fmin(dx, dy) * v.scale; /* pixels between glyphs */
    const double lw = fmax(1.0, 0.07 * spacing);
    const rgba8 c = rgba(def->glyph_rgb[0], def->glyph_rgb[1], def->glyph_rgb[2], 255);
    for (int j0 = 0; vmax > 0 && j0 + every <= ny; j0 += every)
        for (int i0 = 0; i0 + every <= nx; i0 += every) {
            size_t k = (size_t)(j0 + every / 2) * (size_t)nx + (size_t)(i0 + every / 2);
            double g = def->glyph_value ? fabs(def->glyph_value[k]) : 1, a = def->glyph_angle[k];
            if (!isfinite(g) || !isfinite(a) || (f->mask && !f->mask[k]))
                continue;
            double half = 0.5 * 0.9 * spacing * g / vmax;
            if (half < lw) /* shorter than it is wide: left out, as short arrows are */
                continue;
            double x = f->extent[0][0] + (i0 + 0.5 * every) * dx;
            double y = f->extent[0][1] + (j0 + 0.5 * every) * dy;
            double px = (x - v.lo[0]) * v.scale + v.origin[0];
            double py = (v.hi[1] - y) * v.scale + v.origin[1];
            double ux = cos(a) * half, uy = -sin(a) * half; /* pixels: y downwards */
            canvas_segment(rc, px - ux, py - uy, px + ux, py + uy, lw, 1, c);
        }
    if (view)
        *view = v;
    return canvas_end(rc, out, err);
}
