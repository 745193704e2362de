/* Frames of 2D DEM scenes: disks coloured by id, label or a scalar through a colour map,
 * rotation markers, force chains, walls, the box, a title, a stamp and a colour bar. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render_internal.h"

render_grains_def render_default_grains_def(void)
{
    render_grains_def d;
    memset(&d, 0, sizeof d);
    d.color = RENDER_COLOR_GRAIN;
    d.colormap = RENDER_VIRIDIS;
    d.box = true;
    return d;
}

typedef struct chain {
    long i, j;
    double nx, ny, overlap, fn;
} chain;

typedef struct chain_list {
    chain *c;
    size_t n, cap;
    int oom;
} chain_list;

static void collect_chain(const dem_contact_info *ci, void *ctx)
{
    chain_list *l = ctx;
    if (ci->j < 0 || !(ci->fn > 0) || l->oom)
        return;
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 1024;
        chain *c = realloc(l->c, cap * sizeof *c);
        if (!c) {
            l->oom = 1;
            return;
        }
        l->c = c;
        l->cap = cap;
    }
    chain *c = &l->c[l->n++];
    c->i = ci->i;
    c->j = ci->j;
    c->nx = ci->normal[0];
    c->ny = ci->normal[1];
    c->overlap = ci->overlap;
    c->fn = ci->fn;
}

static int by_force(const void *a, const void *b)
{
    const chain *x = a, *y = b;
    if (x->fn != y->fn)
        return x->fn < y->fn ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static const char *const COLOR_LABELS[] = {"grain", "speed (m/s)", "angular velocity (rad/s)",
                                           "value", "label"};

/* Clips the line p + s t to the box; returns 0 when it misses. */
static int clip_line(const double p[2], const double t[2], const double lo[2], const double hi[2],
                     double a[2], double b[2])
{
    double s0 = -INFINITY, s1 = INFINITY;
    for (int d = 0; d < 2; d++) {
        double pad = 1e-9 * (hi[d] - lo[d]);
        if (fabs(t[d]) < 1e-300) {
            if (p[d] < lo[d] - pad || p[d] > hi[d] + pad)
                return 0;
            continue;
        }
        double u = (lo[d] - pad - p[d]) / t[d], v = (hi[d] + pad - p[d]) / t[d];
        if (u > v) {
            double w = u;
            u = v;
            v = w;
        }
        s0 = u > s0 ? u : s0;
        s1 = v < s1 ? v : s1;
    }
    if (!(s1 > s0))
        return 0;
    for (int d = 0; d < 2; d++) {
        a[d] = p[d] + s0 * t[d];
        b[d] = p[d] + s1 * t[d];
    }
    return 1;
}

core_status render_dem(render_context *rc, dem_scene *s, const render_grains_def *def,
                       render_image *out, render_view *view, core_error *err)
{
    out->rgba = NULL;
    out->width = out->height = 0;
    if (dem_dim(s) != 2)
        return core_fail(err, CORE_ERR_ARG, "only 2D scenes are drawn so far (this one is 3D)");
    int W = def->width ? def->width : RENDER_DEFAULT_WIDTH, H = def->height;
    if (W < RENDER_MIN_SIZE || W > RENDER_MAX_SIZE || (H && (H < RENDER_MIN_SIZE ||
                                                             H > RENDER_MAX_SIZE)))
        return core_fail(err, CORE_ERR_ARG, "image size %d x %d outside [%d, %d] pixels", W, H,
                         RENDER_MIN_SIZE, RENDER_MAX_SIZE);
    const size_t n = dem_count(s);
    const double *x = dem_positions(s, 0), *y = dem_positions(s, 1), *r = dem_radii(s);
    int mapped = def->color == RENDER_COLOR_SPEED || def->color == RENDER_COLOR_ROTATION ||
                 def->color == RENDER_COLOR_VALUES;
    if (def->color == RENDER_COLOR_VALUES && n && !def->values)
        return core_fail(err, CORE_ERR_ARG, "colour by values without values");
    if (def->color == RENDER_COLOR_LABELS && n && !def->labels)
        return core_fail(err, CORE_ERR_ARG, "colour by labels without labels");
    if (def->range[0] > def->range[1] || !isfinite(def->range[0]) || !isfinite(def->range[1]))
        return core_fail(err, CORE_ERR_ARG, "colour range [%g, %g] is not increasing",
                         def->range[0], def->range[1]);

    double lo[3], hi[3], g[3];
    dem_box(s, lo, hi, g);
    const double hx = hi[0] - lo[0], hy = hi[1] - lo[1];

    /* ---- per-grain scalar and its range ---- */
    double *val = NULL;
    double range[2] = {0, 1};
    if (mapped) {
        val = malloc((n ? n : 1) * sizeof *val);
        if (!val)
            return core_fail(err, CORE_ERR_NOMEM, "render: out of memory");
        const double *vx = dem_velocities(s, 0), *vy = dem_velocities(s, 1);
        const double *w = dem_angular_velocities(s, 2);
        for (size_t i = 0; i < n; i++)
            val[i] = def->color == RENDER_COLOR_SPEED      ? hypot(vx[i], vy[i])
                     : def->color == RENDER_COLOR_ROTATION ? (w ? w[i] : 0)
                                                           : def->values[i];
        if (def->range[0] < def->range[1]) {
            range[0] = def->range[0];
            range[1] = def->range[1];
        } else {
            double mn = INFINITY, mx = -INFINITY;
            for (size_t i = 0; i < n; i++)
                if (isfinite(val[i])) {
                    mn = val[i] < mn ? val[i] : mn;
                    mx = val[i] > mx ? val[i] : mx;
                }
            if (!(mn <= mx))
                mn = 0, mx = 1;
            if (mx == mn) { /* one value: put it mid-map */
                double d = mn != 0 ? 0.5 * fabs(mn) : 0.5;
                mn -= d;
                mx += d;
            }
            range[0] = mn;
            range[1] = mx;
        }
    }

    /* ---- layout ---- */
    double fs = canvas_font_px(W, H ? H : W);
    int m = (int)lround(0.8 * fs);
    int has_top = (def->title && *def->title) || (def->stamp && *def->stamp);
    int ay0 = m + (has_top ? (int)lround(1.7 * fs) : 0);
    int show_bar = mapped && def->colorbar;
    double ticks[16], step = 1;
    int nticks = 0;
    char labels[16][64];
    const char *bar_label = def->colorbar_label ? def->colorbar_label : COLOR_LABELS[def->color];
    int bar_w = (int)lround(1.1 * fs), gap = (int)lround(0.8 * fs);
    int tick_len = (int)lround(0.35 * fs), lgap = (int)lround(0.3 * fs);
    double maxlabel = 0;
    int band = 0;
    if (show_bar) {
        nticks = ticks_linear(range[0], range[1], 5, ticks, 16, &step);
        for (int k = 0; k < nticks; k++) {
            ticks_format(ticks[k], step, labels[k], sizeof labels[k]);
            double tw = canvas_text_width(rc, labels[k], fs);
            maxlabel = tw > maxlabel ? tw : maxlabel;
        }
        band = gap + bar_w + tick_len + lgap + (int)ceil(maxlabel) +
               (bar_label && *bar_label ? (int)lround(0.5 * fs + 1.3 * fs) : 0);
    }
    int ax0 = m, ax1 = W - m - band;
    if (ax1 - ax0 < 4) {
        free(val);
        return core_fail(err, CORE_ERR_ARG, "image width %d leaves no room for the scene", W);
    }
    if (!H) {
        double h = ay0 + (ax1 - ax0) * hy / hx + m;
        H = h > RENDER_MAX_SIZE ? RENDER_MAX_SIZE : h < RENDER_MIN_SIZE ? RENDER_MIN_SIZE
                                                                         : (int)lround(h);
    }
    int ay1 = H - m;
    if (ay1 - ay0 < 4) {
        free(val);
        return core_fail(err, CORE_ERR_ARG, "image height %d leaves no room for the scene", H);
    }
    double sc = fmin((ax1 - ax0) / hx, (ay1 - ay0) / hy);
    double bw = hx * sc, bh = hy * sc;
    double ox = ax0 + 0.5 * ((ax1 - ax0) - bw), oy = ay0 + 0.5 * ((ay1 - ay0) - bh);
    if (view) {
        memcpy(view->lo, lo, sizeof view->lo);
        memcpy(view->hi, hi, sizeof view->hi);
        view->scale = sc;
        view->origin[0] = ox;
        view->origin[1] = oy;
        view->range[0] = range[0];
        view->range[1] = range[1];
    }
#define PX(X) (ox + ((X) - lo[0]) * sc)
#define PY(Y) (oy + (hi[1] - (Y)) * sc)

    /* Contacts first: if they cannot be had, nothing has been drawn. */
    chain_list chains = {0};
    if (def->force_chains && n) {
        dem_each_contact(s, collect_chain, &chains);
        if (chains.oom) {
            free(chains.c);
            free(val);
            return core_fail(err, CORE_ERR_NOMEM, "render: out of memory for force chains");
        }
    }

    core_status st = canvas_begin(rc, W, H, err);
    if (st != CORE_OK) {
        free(chains.c);
        free(val);
        return st;
    }

    /* ---- grains ---- */
    double mean_r = 0;
    for (size_t i = 0; i < n; i++)
        mean_r += r[i];
    mean_r = n ? mean_r / n * sc : 1;
    const double span = range[1] - range[0];
    for (size_t i = 0; i < n; i++) {
        unsigned char c[3];
        if (mapped)
            render_colormap_rgb(def->colormap, (val[i] - range[0]) / span, c);
        else
            render_label_rgb(def->color == RENDER_COLOR_LABELS ? def->labels[i] : (long)i, c);
        if (chains.n || def->force_chains) /* pale grains under the chains */
            for (int k = 0; k < 3; k++)
                c[k] = (unsigned char)(c[k] + (255 - c[k]) * 0.6);
        double rp = r[i] * sc;
        double edge = rp >= 3 ? fmin(1.2, 0.1 * rp) : 0;
        canvas_disk(rc, PX(x[i]), PY(y[i]), rp, edge, rgba(c[0], c[1], c[2], 255));
    }

    /* ---- rotation markers ---- */
    if (def->rotation)
        for (size_t i = 0; i < n; i++) {
            double rp = r[i] * sc;
            if (rp < 2.5)
                continue;
            double a = def->angles ? def->angles[i] : 0;
            double ex = x[i] + 0.92 * r[i] * cos(a), ey = y[i] + 0.92 * r[i] * sin(a);
            canvas_segment(rc, PX(x[i]), PY(y[i]), PX(ex), PY(ey), fmin(3, fmax(1, 0.15 * rp)),
                           1, rgba(25, 25, 25, 230));
        }

    /* ---- force chains: strongest on top ---- */
    if (chains.n) {
        qsort(chains.c, chains.n, sizeof *chains.c, by_force);
        double fbig = chains.c[chains.n - 1].fn;
        double wmax = fmax(1.5, 0.8 * mean_r);
        for (size_t k = 0; k < chains.n; k++) {
            const chain *c = &chains.c[k];
            double u = c->fn / fbig;
            /* The far end is the partner's image along the normal (from j to i), which is
             * also right across a periodic edge. */
            double d = r[c->i] + r[c->j] - c->overlap;
            unsigned char gray = (unsigned char)lround(200 * (1 - u));
            double x0 = x[c->i], y0 = y[c->i];
            double x1 = x0 - c->nx * d, y1 = y0 - c->ny * d;
            canvas_segment(rc, PX(x0), PY(y0), PX(x1), PY(y1), fmax(0.3, wmax * u), 1,
                           rgba(gray, gray, gray, 255));
        }
    }

    /* ---- walls and box ---- */
    rgba8 wall_c = rgba(60, 60, 60, 255);
    double ww = fmax(2, lround(0.25 * fs));
    for (int k = 0; k < def->nwalls; k++) {
        const render_wall *wl = &def->walls[k];
        double nn = hypot(wl->normal[0], wl->normal[1]);
        if (!(nn > 0))
            continue;
        double nx = wl->normal[0] / nn, ny = wl->normal[1] / nn, t[2] = {-ny, nx}, a[2], b[2];
        if (!clip_line(wl->point, t, lo, hi, a, b))
            continue;
        /* the stroke lies outside the domain, its inner edge on the wall */
        double sx = -nx * 0.5 * ww, sy = ny * 0.5 * ww;
        canvas_segment(rc, PX(a[0]) + sx, PY(a[1]) + sy, PX(b[0]) + sx, PY(b[1]) + sy, ww, 1,
                       wall_c);
    }
    if (def->box) {
        rgba8 bc = rgba(150, 150, 150, 255);
        double l = ox - 0.5, rt = ox + bw + 0.5, tp = oy - 0.5, bt = oy + bh + 0.5;
        canvas_segment(rc, l - 0.5, tp, rt + 0.5, tp, 1, 0, bc);
        canvas_segment(rc, l - 0.5, bt, rt + 0.5, bt, 1, 0, bc);
        canvas_segment(rc, l, tp, l, bt, 1, 0, bc);
        canvas_segment(rc, rt, tp, rt, bt, 1, 0, bc);
    }

    /* ---- text ---- */
    rgba8 ink = rgba(20, 20, 20, 255);
    double ty = ay0 - lround(0.45 * fs);
    if (def->title && *def->title)
        canvas_text(rc, def->title, fs, m, ty, 0, 1, 0, ink);
    if (def->stamp && *def->stamp)
        canvas_text(rc, def->stamp, fs, W - m - band, ty, 1, 1, 0, ink);

    /* ---- colour bar: one rectangle per pixel row ---- */
    if (show_bar) {
        double bx0 = ox + bw + gap, bx1 = bx0 + bar_w;
        double y0 = round(oy), y1 = round(oy + bh);
        int rows = (int)(y1 - y0);
        for (int k = 0; k < rows; k++) {
            unsigned char c[3];
            render_colormap_rgb(def->colormap, 1 - (k + 0.5) / rows, c);
            canvas_rect(rc, bx0, y0 + k, bx1, y0 + k + 1, rgba(c[0], c[1], c[2], 255));
        }
        rgba8 fc = rgba(80, 80, 80, 255);
        canvas_segment(rc, bx0 - 1, y0 - 0.5, bx1 + 1, y0 - 0.5, 1, 0, fc);
        canvas_segment(rc, bx0 - 1, y1 + 0.5, bx1 + 1, y1 + 0.5, 1, 0, fc);
        canvas_segment(rc, bx0 - 0.5, y0, bx0 - 0.5, y1, 1, 0, fc);
        canvas_segment(rc, bx1 + 0.5, y0, bx1 + 0.5, y1, 1, 0, fc);
        for (int k = 0; k < nticks; k++) {
            double ty_ = y1 - (ticks[k] - range[0]) / span * rows;
            ty_ = floor(ty_) + 0.5;
            canvas_segment(rc, bx1 + 1, ty_, bx1 + 1 + tick_len, ty_, 1, 0, fc);
            canvas_text(rc, labels[k], fs, bx1 + 1 + tick_len + lgap, ty_, 0, 0.5, 0, ink);
        }
        if (bar_label && *bar_label)
            canvas_text(rc, bar_label, fs, bx1 + 1 + tick_len + lgap + maxlabel + 0.5 * fs,
                        0.5 * (y0 + y1), 0.5, 0, 1, ink);
    }
#undef PX
#undef PY
    free(chains.c);
    free(val);
    return canvas_end(rc, out, err);
}
