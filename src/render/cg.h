/* Coarse-grained fields as images: a grid field (render_field) with the principal directions of a
 * tensor drawn over it as line glyphs (Weinhart et al. 2012's stress maps, Padbidri's principal
 * stress difference). Nothing here knows about Lua. */
#ifndef GRAINLAB_RENDER_CG_H
#define GRAINLAB_RENDER_CG_H

#include "render/render.h"

typedef struct render_cg_def {
    render_field_def field; /* the colours (and arrows): as render_field takes them */
    /* Glyphs: a segment at the centre of each block of glyph_every x glyph_every cells, along the
     * major principal direction angle[k] (rad from x) of the cell there, of length (value[k] / max
     * value) x 0.9 x the glyph spacing; NULL angle: none. Cells without a finite angle or
     * value, or masked, get none. */
    const double *glyph_angle;
    const double *glyph_value;  /* e.g. the principal stress difference; NULL: all full length */
    int glyph_every;            /* a glyph every k-th cell along x and y; 0: about 28 across */
    unsigned char glyph_rgb[3]; /* their colour */
} render_cg_def;

render_cg_def render_default_cg_def(void); /* render_default_field_def, dark red glyphs */

/* The field (render_field), then the glyphs over it. view: as render_field gives it. */
core_status render_cg(render_context *rc, const render_cg_def *def, render_image *out,
                      render_view *view, core_error *err);

#endif
