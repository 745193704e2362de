/* Frames of grid fields (cells through a colour map, vectors as arrows) and point clouds, on plain
 * arrays: the images MPM and DSMC are drawn with. Same layout as DEM frames: title band, the
 * scene fitted into the rest, a colour bar on the right. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"

render_field_def render_default_field_def(void)
{
    render_field_def d;
    memset(&d, 0, sizeof d);
    d.interp = RENDER_NEAREST;
    d.colormap = RENDER_VIRIDIS;
    d.colorbar = true;
    d.box = true;
    return d;
}

render_points_def render_default_points_def(void)
{
    render_points_def d;
    memset(&d, 0, sizeof d);
    d.colormap = RENDER_VIRIDIS;
    d.colorbar = true;
    d.box = true;
    return d;
}

/* ---- shared layout -------------------------------------------------------------------------- */
typedef struct frame {
    int W, H, m, ay0, band, show_bar;
    double fs, sc, ox, oy, bw, bh;
    double lo[2], hi[2], range[2];
    colorbar bar;
} frame;

static core_status check_size(int width, int height, core_error *err)
{
    int W = width ? width : RENDER_DEFAULT_WIDTH;
    if (W < RENDER_MIN_SIZE || W > RENDER_MAX_SIZE ||
        (height && (height < RENDER_MIN_SIZE || height > RENDER_MAX_SIZE)))
        return core_fail(err, CORE_ERR_ARG, "image size %d x %d outside [%d, %d] pixels", W,
                         height, RENDER_MIN_SIZE, RENDER_MAX_SIZE);
    return CORE_OK;
}

static core_status check_range(const double range[2], core_error *err)
{
    if (range[0] > range[1] || !isfinite(range[0]) || !isfinite(range[1]))
        return core_fail(err, CORE_ERR_ARG, "colour range [%g, %g] is not increasing", range[0],
                         range[1]);
    return CORE_OK;
}

/* The colour-map limits: the given ones, or the min and max of the finite values (widened around
 * a single value, [0, 1] without any). */
static void data_range(const double given[2], double mn, double mx, double out[2])
{
    if (given[0] < given[1]) {
        out[0] = given[0];
        out[1] = given[1];
        return;
    }
    if (!(mn <= mx))
        mn = 0, mx = 1;
    if (mx == mn) {
        double d = mn != 0 ? 0.5 * fabs(mn) : 0.5;
        mn -= d;
        mx += d;
    }
    out[0] = mn;
    out[1] = mx;
}

/* Image size, margins, title band and colour bar band, and the scene's rectangle [lo, hi] fitted
 * into the rest with its top-left corner on a whole pixel. */
static core_status frame_layout(render_context *rc, frame *f, int width, int height, int has_top,
                                int show_bar, const char *bar_label, core_error *err)
{
    int W = width ? width : RENDER_DEFAULT_WIDTH, H = height;
    const double hx = f->hi[0] - f->lo[0], hy = f->hi[1] - f->lo[1];
    f->fs = canvas_font_px(W, H ? H : W);
    f->m = (int)lround(0.8 * f->fs);
    f->ay0 = f->m + (has_top ? (int)lround(1.7 * f->fs) : 0);
    f->show_bar = show_bar;
    f->band = show_bar ? colorbar_layout(rc, &f->bar, f->range, bar_label, f->fs) : 0;
    int ax0 = f->m, ax1 = W - f->m - f->band;
    if (ax1 - ax0 < 4)
        return core_fail(err, CORE_ERR_ARG, "image width %d leaves no room for the scene", W);
    if (!H) {
        double h = f->ay0 + (ax1 - ax0) * hy / hx + f->m;
        H = h > RENDER_MAX_SIZE ? RENDER_MAX_SIZE
            : h < RENDER_MIN_SIZE ? RENDER_MIN_SIZE
                                  : (int)lround(h);
    }
    int ay1 = H - f->m;
    if (ay1 - f->ay0 < 4)
        return core_fail(err, CORE_ERR_ARG, "image height %d leaves no room for the scene", H);
    f->W = W;
    f->H = H;
    f->sc = fmin((ax1 - ax0) / hx, (ay1 - f->ay0) / hy);
    f->bw = hx * f->sc;
    f->bh = hy * f->sc;
    f->ox = round(ax0 + 0.5 * ((ax1 - ax0) - f->bw));
    f->oy = round(f->ay0 + 0.5 * ((ay1 - f->ay0) - f->bh));
    return CORE_OK;
}

static void frame_view(const frame *f, render_view *view)
{
    if (!view)
        return;
    memcpy(view->lo, f->lo, sizeof view->lo);
    memcpy(view->hi, f->hi, sizeof view->hi);
    view->scale = f->sc;
    view->origin[0] = f->ox;
    view->origin[1] = f->oy;
    view->range[0] = f->range[0];
    view->range[1] = f->range[1];
}

/* The box outline just outside the pixels [x0, x1) x [y0, y1). */
static void frame_box(render_context *rc, double x0, double y0, double x1, double y1)
{
    rgba8 bc = rgba(150, 150, 150, 255);
    double l = x0 - 0.5, rt = x1 + 0.5, tp = y0 - 0.5, bt = y1 + 0.5;
    canvas_segment(rc, l - 0.5, tp, rt + 0.5, tp, 1, 0, bc);
    canvas_segment(rc, l - 0.5, bt, rt + 0.5, bt, 1, 0, bc);
    canvas_segment(rc, l, tp, l, bt, 1, 0, bc);
    canvas_segment(rc, rt, tp, rt, bt, 1, 0, bc);
}

static void frame_text(render_context *rc, const frame *f, const char *title, const char *stamp)
{
    rgba8 ink = rgba(20, 20, 20, 255);
    double ty = f->ay0 - lround(0.45 * f->fs);
    if (title && *title)
        canvas_text(rc, title, f->fs, f->m, ty, 0, 1, 0, ink);
    if (stamp && *stamp)
        canvas_text(rc, stamp, f->fs, f->W - f->m - f->band, ty, 1, 1, 0, ink);
}

/* ---- grid fields ---------------------------------------------------------------------------- */
static int cell_shown(const render_field_def *def, size_t k)
{
    return (!def->mask || def->mask[k]) && isfinite(def->values[k]);
}

/* Pixel colours of the field inside the scene's rectangle (nc x nr pixels from its top-left
 * corner), alpha 0 where a cell has no value. */
static void field_pixels(const render_field_def *def, const frame *f, int nc, int nr,
                         const unsigned char *cell_rgba, unsigned char *px)
{
    const int nx = def->nx, ny = def->ny;
    const double span = f->range[1] - f->range[0];
    const double wx = def->extent[1][0] - def->extent[0][0];
    const double wy = def->extent[1][1] - def->extent[0][1];
    for (int r = 0; r < nr; r++) {
        /* cell coordinates of the pixel centre: y from the top of the extent */
        double fy = (f->hi[1] - (r + 0.5) / f->sc - def->extent[0][1]) / wy * ny;
        int j = (int)floor(fy);
        j = j < 0 ? 0 : j >= ny ? ny - 1 : j;
        for (int c = 0; c < nc; c++) {
            double fx = ((c + 0.5) / f->sc + f->lo[0] - def->extent[0][0]) / wx * nx;
            int i = (int)floor(fx);
            i = i < 0 ? 0 : i >= nx ? nx - 1 : i;
            unsigned char *p = px + ((size_t)r * nc + c) * 4;
            size_t k = (size_t)j * nx + i;
            if (def->interp == RENDER_NEAREST || !cell_shown(def, k)) {
                memcpy(p, cell_rgba + 4 * k, 4);
                continue;
            }
            /* bilinear between cell centres, over the cells that have values */
            double u = fx - 0.5, v = fy - 0.5;
            int i0 = (int)floor(u), j0 = (int)floor(v);
            double t = u - i0, s = v - j0, sum = 0, wsum = 0;
            for (int b = 0; b < 2; b++)
                for (int a = 0; a < 2; a++) {
                    int ii = i0 + a, jj = j0 + b;
                    ii = ii < 0 ? 0 : ii >= nx ? nx - 1 : ii;
                    jj = jj < 0 ? 0 : jj >= ny ? ny - 1 : jj;
                    size_t kk = (size_t)jj * nx + ii;
                    double w = (a ? t : 1 - t) * (b ? s : 1 - s);
                    if (w > 0 && cell_shown(def, kk)) {
                        sum += w * def->values[kk];
                        wsum += w;
                    }
                }
            render_colormap_rgb(def->colormap, (sum / wsum - f->range[0]) / span, p);
            p[3] = 255;
        }
    }
}

static core_status check_field_def(const render_field_def *def, core_error *err)
{
    core_status st = check_size(def->width, def->height, err);
    if (st != CORE_OK)
        return st;
    if (def->nx < 1 || def->ny < 1)
        return core_fail(err, CORE_ERR_ARG, "grid of %d x %d cells: at least 1 x 1 expected",
                         def->nx, def->ny);
    const double(*e)[2] = def->extent;
    if (!isfinite(e[0][0]) || !isfinite(e[0][1]) || !isfinite(e[1][0]) || !isfinite(e[1][1]) ||
        !(e[1][0] > e[0][0]) || !(e[1][1] > e[0][1]))
        return core_fail(err, CORE_ERR_ARG,
                         "extent {{%g, %g}, {%g, %g}}: finite corners with x1 > x0, y1 > y0 "
                         "expected",
                         e[0][0], e[0][1], e[1][0], e[1][1]);
    if (!def->values && !def->arrows[0])
        return core_fail(err, CORE_ERR_ARG, "a field needs values, arrows or both");
    if (def->arrows[0] && (!def->arrows[1] || !(def->arrow_scale >= 0) ||
                           !isfinite(def->arrow_scale) || def->arrow_every < 0))
        return core_fail(err, CORE_ERR_ARG,
                         "arrows need two arrays, a scale >= 0 and a spacing "
                         ">= 0");
    return check_range(def->range, err);
}

/* The frame's rectangle (the extent) and colour range; returns the number of cells shown. */
static size_t field_frame(const render_field_def *def, frame *f)
{
    const double(*e)[2] = def->extent;
    const size_t ncell = (size_t)def->nx * (size_t)def->ny;
    memset(f, 0, sizeof *f);
    f->lo[0] = e[0][0];
    f->lo[1] = e[0][1];
    f->hi[0] = e[1][0];
    f->hi[1] = e[1][1];
    f->range[0] = 0;
    f->range[1] = 1;
    size_t shown = 0;
    if (def->values) {
        double mn = INFINITY, mx = -INFINITY;
        for (size_t k = 0; k < ncell; k++)
            if (cell_shown(def, k)) {
                shown++;
                mn = def->values[k] < mn ? def->values[k] : mn;
                mx = def->values[k] > mx ? def->values[k] : mx;
            }
        data_range(def->range, mn, mx, f->range);
    }
    return shown;
}

/* The field's nc x nr pixels (those whose centre lies inside the extent) in *pixels, allocated
 * here: the cells' colours, then each pixel's. */
static core_status field_image(const render_field_def *def, const frame *f, int nc, int nr,
                               unsigned char **pixels, core_error *err)
{
    const size_t ncell = (size_t)def->nx * (size_t)def->ny;
    unsigned char *cells = malloc(ncell * 4);
    *pixels = malloc((size_t)nc * nr * 4);
    if (!cells || !*pixels) {
        free(cells);
        free(*pixels);
        *pixels = NULL;
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory for a %d x %d field", def->nx,
                         def->ny);
    }
    const double span = f->range[1] - f->range[0];
    for (size_t k = 0; k < ncell; k++) {
        unsigned char *c = cells + 4 * k;
        if (cell_shown(def, k)) {
            render_colormap_rgb(def->colormap, (def->values[k] - f->range[0]) / span, c);
            c[3] = 255;
        } else if (def->background) { /* opaque: drawn */
            memcpy(c, def->background, 3);
            c[3] = 255;
        } else {
            memset(c, 0, 4);
        }
    }
    field_pixels(def, f, nc, nr, cells, *pixels);
    free(cells);
    return CORE_OK;
}

/* A field without a single value: a note in the scene saying why it is empty. */
static void empty_note(render_context *rc, const render_field_def *def, const frame *f)
{
    const size_t ncell = (size_t)def->nx * (size_t)def->ny;
    char note[96];
    snprintf(note, sizeof note, "no values: all %zu cells are NaN%s", ncell,
             def->mask ? " or masked" : "");
    double px = f->fs;
    double w = canvas_text_width(rc, note, px);
    if (w > 0.9 * f->bw) /* fits the scene's width */
        px *= 0.9 * f->bw / w;
    canvas_text(rc, note, px, f->ox + 0.5 * f->bw, f->oy + 0.5 * f->bh, 0.5, 0.5, 0,
                rgba(180, 30, 30, 255));
}

/* Arrows from the cell centres, every k-th cell, with a reference arrow. */
static void field_arrows(render_context *rc, const render_field_def *def, const frame *f)
{
    const double(*e)[2] = def->extent;
    const int nx = def->nx, ny = def->ny;
    const double *U = def->arrows[0], *V = def->arrows[1];
    const double dx = (e[1][0] - e[0][0]) / nx, dy = (e[1][1] - e[0][1]) / ny;
    const double cell_px = fmin(dx, dy) * f->sc;
    int every = def->arrow_every;
    if (every == 0) {
        every = (int)ceil(1.5 * f->fs / cell_px - 1e-9);
        every = every < 1 ? 1 : every;
    }
    /* the first arrow half a spacing in, or mid-grid on a side shorter than the spacing */
    const int offx = every / 2 < nx ? every / 2 : (nx - 1) / 2;
    const int offy = every / 2 < ny ? every / 2 : (ny - 1) / 2;
    double umax = 0;
    for (int j = offy; j < ny; j += every)
        for (int i = offx; i < nx; i += every) {
            size_t k = (size_t)j * nx + i;
            if ((!def->mask || def->mask[k]) && isfinite(U[k]) && isfinite(V[k]))
                umax = fmax(umax, hypot(U[k], V[k]));
        }
    const double spacing = every * fmin(dx, dy); /* scene units */
    double ks = def->arrow_scale;
    if (ks == 0)
        ks = umax > 0 ? 0.9 * spacing / umax : 1;
    const double sp_px = spacing * f->sc;
    const double aw = fmin(2.5, fmax(1.2, 0.07 * sp_px)), head = fmax(3, 0.3 * sp_px);
    rgba8 ac = rgba(190, 30, 30, 255), halo = rgba(255, 255, 255, 150);
    /* on a coloured field a pale halo keeps the arrows readable on dark cells */
    for (int pass = def->values ? 0 : 1; pass < 2; pass++)
        for (int j = offy; j < ny; j += every)
            for (int i = offx; i < nx; i += every) {
                size_t k = (size_t)j * nx + i;
                if ((def->mask && !def->mask[k]) || !isfinite(U[k]) || !isfinite(V[k]))
                    continue;
                double len = hypot(U[k], V[k]) * ks * f->sc;
                if (len < 2 * aw) /* a speck, not an arrow */
                    continue;
                double x0 = f->ox + (i + 0.5) * dx * f->sc;
                double y0 = f->oy + (ny - j - 0.5) * dy * f->sc;
                double ux = U[k] * ks * f->sc / len, uy = -V[k] * ks * f->sc / len;
                canvas_arrow(rc, x0, y0, x0 + ux * len, y0 + uy * len, ux, uy, pass ? aw : aw + 2,
                             fmin(0.35 * len, head), pass ? ac : halo);
            }
    double right =
        f->W - f->m - f->band -
        (def->stamp && *def->stamp ? canvas_text_width(rc, def->stamp, f->fs) + 2 * f->fs : 0);
    reference_arrow(rc, umax, ks, f->sc, def->arrow_unit, right, f->ay0 - lround(0.45 * f->fs),
                    f->fs, aw, head, ac);
}

core_status render_field(render_context *rc, const render_field_def *def, render_image *out,
                         render_view *view, core_error *err)
{
    out->rgba = NULL;
    out->width = out->height = 0;
    core_status st = check_field_def(def, err);
    if (st != CORE_OK)
        return st;
    frame f;
    const size_t shown = field_frame(def, &f);
    /* A field without a single value would be a blank frame with a colour bar of nothing: it gets
     * no bar and a note saying why it is empty instead. */
    const int empty = def->values && shown == 0;
    int has_top = (def->title && *def->title) || (def->stamp && *def->stamp) || def->arrows[0];
    const char *bar_label = def->colorbar_label ? def->colorbar_label : "value";
    if ((st = frame_layout(rc, &f, def->width, def->height, has_top,
                           def->values && def->colorbar && !empty, bar_label, err)) != CORE_OK)
        return st;
    frame_view(&f, view);

    /* the field's pixels: those whose centre lies inside the extent */
    int nc = (int)ceil(f.bw - 0.5), nr = (int)ceil(f.bh - 0.5);
    nc = nc < 1 ? 1 : nc;
    nr = nr < 1 ? 1 : nr;
    unsigned char *pixels = NULL;
    if (def->values && (st = field_image(def, &f, nc, nr, &pixels, err)) != CORE_OK)
        return st;
    if ((st = canvas_begin(rc, f.W, f.H, err)) != CORE_OK) {
        free(pixels);
        return st;
    }
    if (pixels)
        canvas_pixels(rc, (int)f.ox, (int)f.oy, nc, nr, pixels);
    free(pixels);
    if (empty)
        empty_note(rc, def, &f);
    if (def->arrows[0])
        field_arrows(rc, def, &f);
    if (def->box)
        frame_box(rc, f.ox, f.oy, f.ox + nc, f.oy + nr);
    frame_text(rc, &f, def->title, def->stamp);
    if (f.show_bar)
        colorbar_draw(rc, &f.bar, def->colormap, f.ox + f.bw, f.oy, f.oy + f.bh);
    return canvas_end(rc, out, err);
}

/* ---- point clouds --------------------------------------------------------------------------- */
core_status render_points(render_context *rc, const render_points_def *def, render_image *out,
                          render_view *view, core_error *err)
{
    out->rgba = NULL;
    out->width = out->height = 0;
    core_status st = check_size(def->width, def->height, err);
    if (st != CORE_OK)
        return st;
    const size_t n = def->n;
    if (n && (!def->x || !def->y))
        return core_fail(err, CORE_ERR_ARG, "points without positions");
    double size = def->size == 0 ? 4 : def->size;
    if (!(size > 0) || !(size <= RENDER_MAX_SIZE))
        return core_fail(err, CORE_ERR_ARG, "point size %g: a diameter in (0, %d] pixels "
                                            "expected", def->size, RENDER_MAX_SIZE);
    if ((st = check_range(def->range, err)) != CORE_OK)
        return st;
    const double(*e)[2] = def->extent;
    int given = e[1][0] > e[0][0] || e[1][1] > e[0][1];
    if (given && (!isfinite(e[0][0]) || !isfinite(e[0][1]) || !isfinite(e[1][0]) ||
                  !isfinite(e[1][1]) || !(e[1][0] > e[0][0]) || !(e[1][1] > e[0][1])))
        return core_fail(err, CORE_ERR_ARG,
                         "extent {{%g, %g}, {%g, %g}}: finite corners with x1 > x0, y1 > y0 "
                         "expected", e[0][0], e[0][1], e[1][0], e[1][1]);

    frame f;
    memset(&f, 0, sizeof f);
    if (given) {
        f.lo[0] = e[0][0];
        f.lo[1] = e[0][1];
        f.hi[0] = e[1][0];
        f.hi[1] = e[1][1];
    } else { /* the bounding box, padded by 2% of its larger side */
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (size_t i = 0; i < n; i++)
            if (isfinite(def->x[i]) && isfinite(def->y[i])) {
                lo[0] = fmin(lo[0], def->x[i]);
                hi[0] = fmax(hi[0], def->x[i]);
                lo[1] = fmin(lo[1], def->y[i]);
                hi[1] = fmax(hi[1], def->y[i]);
            }
        if (!(lo[0] <= hi[0])) {
            lo[0] = lo[1] = 0;
            hi[0] = hi[1] = 1;
        }
        double big = fmax(hi[0] - lo[0], hi[1] - lo[1]);
        if (big == 0)
            big = lo[0] != 0 || lo[1] != 0 ? fmax(fabs(lo[0]), fabs(lo[1])) : 1;
        for (int d = 0; d < 2; d++) {
            double pad = 0.02 * big + (hi[d] == lo[d] ? 0.5 * big : 0);
            f.lo[d] = lo[d] - pad;
            f.hi[d] = hi[d] + pad;
        }
    }
    f.range[0] = 0;
    f.range[1] = 1;
    if (def->values) {
        double mn = INFINITY, mx = -INFINITY;
        for (size_t i = 0; i < n; i++)
            if (isfinite(def->values[i])) {
                mn = def->values[i] < mn ? def->values[i] : mn;
                mx = def->values[i] > mx ? def->values[i] : mx;
            }
        data_range(def->range, mn, mx, f.range);
    }
    int has_top = (def->title && *def->title) || (def->stamp && *def->stamp);
    const char *bar_label = def->colorbar_label ? def->colorbar_label : "value";
    if ((st = frame_layout(rc, &f, def->width, def->height, has_top,
                           def->values && def->colorbar, bar_label, err)) != CORE_OK)
        return st;
    frame_view(&f, view);
    if ((st = canvas_begin(rc, f.W, f.H, err)) != CORE_OK)
        return st;

    const double span = f.range[1] - f.range[0];
    for (size_t i = 0; i < n; i++) {
        double x = def->x[i], y = def->y[i];
        if (!(x >= f.lo[0] && x <= f.hi[0] && y >= f.lo[1] && y <= f.hi[1]))
            continue; /* outside, or not finite */
        unsigned char c[3] = {31, 119, 180};
        if (def->values)
            render_colormap_rgb(def->colormap, (def->values[i] - f.range[0]) / span, c);
        canvas_disk(rc, f.ox + (x - f.lo[0]) * f.sc, f.oy + (f.hi[1] - y) * f.sc, 0.5 * size, 0,
                    rgba(c[0], c[1], c[2], 255));
    }
    if (def->box)
        frame_box(rc, f.ox, f.oy, f.ox + f.bw, f.oy + f.bh);
    frame_text(rc, &f, def->title, def->stamp);
    if (f.show_bar)
        colorbar_draw(rc, &f.bar, def->colormap, f.ox + f.bw, f.oy, f.oy + f.bh);
    return canvas_end(rc, out, err);
}
