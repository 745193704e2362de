/* Line plots: series as lines and/or markers, axes with nice ticks (linear or decades), grid,
 * labels, title and a legend. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/render_internal.h"

render_plot_def render_default_plot_def(void)
{
    render_plot_def d;
    memset(&d, 0, sizeof d);
    return d;
}

/* Tableau-10: distinct on white, also to most colour-blind readers. */
static const unsigned char SERIES_RGB[10][3] = {
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189},
    {140, 86, 75}, {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};

typedef struct axis {
    int log;
    double lim[2];
    double ticks[40], minor[80];
    int nticks, nminor;
    char labels[40][48];
} axis;

/* 10 followed by the exponent in superscript digits. */
static void decade_label(int e, char *buf, size_t size)
{
    static const char *const SUP[10] = {"\xe2\x81\xb0", "\xc2\xb9", "\xc2\xb2", "\xc2\xb3",
                                        "\xe2\x81\xb4", "\xe2\x81\xb5", "\xe2\x81\xb6",
                                        "\xe2\x81\xb7", "\xe2\x81\xb8", "\xe2\x81\xb9"};
    char digits[16];
    snprintf(digits, sizeof digits, "%d", e < 0 ? -e : e);
    snprintf(buf, size, "10%s", e < 0 ? "\xe2\x81\xbb" : "");
    for (const char *d = digits; *d; d++)
        strncat(buf, SUP[*d - '0'], size - strlen(buf) - 1);
}

/* Limits: the data range padded by 4% on each side (so markers at the extremes stay whole), in
 * log10 units on a log axis. Ticks: decades on a log axis (1, 2, 5 steps when it spans less
 * than two), nice linear steps otherwise. */
static void axis_setup(axis *a, double mn, double mx)
{
    a->nminor = a->nticks = 0;
    double span = mx - mn;
    if (span <= 0)
        span = a->log ? 1 : (mn != 0 ? 0.2 * fabs(mn) : 2);
    if (mx == mn) {
        mn -= 0.5 * span;
        mx += 0.5 * span;
    }
    a->lim[0] = mn - 0.04 * span;
    a->lim[1] = mx + 0.04 * span;
    if (a->log) {
        double l0 = ceil(a->lim[0] - 1e-9), l1 = floor(a->lim[1] + 1e-9);
        if (l1 - l0 >= 1) {
            int every = (int)ceil((l1 - l0 + 1) / 9);
            for (double e = l0; e <= l1 && a->nticks < 40; e += every) {
                a->ticks[a->nticks] = e;
                decade_label((int)e, a->labels[a->nticks], sizeof a->labels[0]);
                a->nticks++;
            }
        } else {
            static const int M[3] = {1, 2, 5};
            for (double e = floor(a->lim[0]); e <= a->lim[1] && a->nticks < 40; e += 1)
                for (int k = 0; k < 3 && a->nticks < 40; k++) {
                    double v = log10(M[k]) + e;
                    if (v < a->lim[0] || v > a->lim[1])
                        continue;
                    a->ticks[a->nticks] = v;
                    ticks_format(M[k] * pow(10, e), pow(10, e), M[k] * pow(10, e),
                                 a->labels[a->nticks], sizeof a->labels[0]);
                    a->nticks++;
                }
        }
        if (a->lim[1] - a->lim[0] <= 6)
            for (double e = floor(a->lim[0]); e <= a->lim[1]; e += 1)
                for (int k = 2; k <= 9 && a->nminor < 80; k++) {
                    double v = e + log10(k);
                    if (v >= a->lim[0] && v <= a->lim[1])
                        a->minor[a->nminor++] = v;
                }
        return;
    }
    double step;
    a->nticks = ticks_linear(a->lim[0], a->lim[1], 6, a->ticks, 40, &step);
    double vmax = 0;
    for (int k = 0; k < a->nticks; k++)
        vmax = fmax(vmax, fabs(a->ticks[k]));
    for (int k = 0; k < a->nticks; k++)
        ticks_format(a->ticks[k], step, vmax, a->labels[k], sizeof a->labels[0]);
}

static double map(const axis *a, double v, const double px[2])
{
    return px[0] + (v - a->lim[0]) / (a->lim[1] - a->lim[0]) * (px[1] - px[0]);
}

static void marker(render_context *rc, int shape, double x, double y, double r, rgba8 c)
{
    if (shape == 0)
        canvas_disk(rc, x, y, r, 0, c);
    else if (shape == 1)
        canvas_rect(rc, x - 0.9 * r, y - 0.9 * r, x + 0.9 * r, y + 0.9 * r, c);
    else /* diamond: a square turned by 45 degrees */
        canvas_segment(rc, x - 0.6 * r, y - 0.6 * r, x + 0.6 * r, y + 0.6 * r, 1.7 * r, 0, c);
}

/* A plot being drawn: its axes, the frame's pixels [px] x [py] and the sizes of its parts. */
typedef struct plot_frame {
    const render_plot_def *def;
    int W, H;
    axis ax, ay;
    double fs, tfs, lh;  /* font sizes of labels and title, line height */
    int m, tick, gap;    /* margin, tick length, gap between a tick and its label */
    double px[2], py[2]; /* the frame: columns left, right; rows bottom, top */
    double lw, mr;       /* line width, marker radius */
    rgba8 ink;
} plot_frame;

/* The data ranges (log10 on log axes) and the axes over them. */
static core_status data_ranges(plot_frame *p, core_error *err)
{
    const render_plot_def *def = p->def;
    double xmn = INFINITY, xmx = -INFINITY, ymn = INFINITY, ymx = -INFINITY;
    for (int k = 0; k < def->nseries; k++) {
        const render_series *s = &def->series[k];
        if (s->n && (!s->x || !s->y))
            return core_fail(err, CORE_ERR_ARG, "series %d has no data", k + 1);
        for (size_t i = 0; i < s->n; i++) {
            double x = s->x[i], y = s->y[i];
            if (!isfinite(x) || !isfinite(y))
                continue; /* a gap in the line */
            if ((def->xlog && x <= 0) || (def->ylog && y <= 0))
                return core_fail(
                    err, CORE_ERR_ARG, "series %d point %zu: %s = %g cannot be shown on a log axis",
                    k + 1, i + 1, def->xlog && x <= 0 ? "x" : "y", def->xlog && x <= 0 ? x : y);
            x = def->xlog ? log10(x) : x;
            y = def->ylog ? log10(y) : y;
            xmn = fmin(xmn, x), xmx = fmax(xmx, x), ymn = fmin(ymn, y), ymx = fmax(ymx, y);
        }
    }
    if (!(xmn <= xmx))
        return core_fail(err, CORE_ERR_ARG, "no finite data points to plot");
    axis_setup(&p->ax, xmn, xmx);
    axis_setup(&p->ay, ymn, ymx);
    return CORE_OK;
}

/* Font sizes, margins, and the frame inside room for the tick labels, axis labels and title. */
static core_status plot_layout(render_context *rc, plot_frame *p, core_error *err)
{
    const render_plot_def *def = p->def;
    const int W = p->W, H = p->H;
    const axis *ax = &p->ax, *ay = &p->ay;
    double fs = p->fs = canvas_font_px(W, H) * 1.1;
    double tfs = p->tfs = fs * 1.15, lh = p->lh = ceil(1.25 * fs);
    int m = p->m = (int)lround(0.8 * fs), tick = p->tick = (int)lround(0.4 * fs),
        gap = p->gap = (int)lround(0.35 * fs);
    double ylw = 0;
    for (int k = 0; k < ay->nticks; k++)
        ylw = fmax(ylw, canvas_text_width(rc, ay->labels[k], fs));
    double last_xl = ax->nticks ? canvas_text_width(rc, ax->labels[ax->nticks - 1], fs) : 0;
    double left = m + (def->ylabel && *def->ylabel ? lh + gap : 0) + ylw + gap + tick;
    double right = W - m - fmax(0, 0.5 * last_xl - m);
    double top = m + (def->title && *def->title ? ceil(1.3 * tfs) + gap : 0) + 0.5 * fs;
    double bottom = H - m - (def->xlabel && *def->xlabel ? lh + gap : 0) - lh - tick;
    double *px = p->px, *py = p->py; /* py[0]: bottom row */
    px[0] = floor(left) + 0.5;
    px[1] = floor(right) - 0.5;
    py[0] = floor(bottom) - 0.5;
    py[1] = floor(top) + 0.5;
    if (px[1] - px[0] < 8 || py[0] - py[1] < 8)
        return core_fail(err, CORE_ERR_ARG, "image %d x %d is too small for the plot", W, H);
    p->lw = fmax(1.5, fs / 7);
    p->mr = fmax(3, 0.3 * fs);
    p->ink = rgba(25, 25, 25, 255);
    return CORE_OK;
}

/* Grid, frame, ticks, tick labels, axis labels and title. */
static void draw_axes(render_context *rc, const plot_frame *p)
{
    const render_plot_def *def = p->def;
    const axis *ax = &p->ax, *ay = &p->ay;
    const double *px = p->px, *py = p->py, fs = p->fs;
    const int tick = p->tick, gap = p->gap, m = p->m;
    rgba8 ink = p->ink, grid = rgba(228, 228, 228, 255), minor = rgba(242, 242, 242, 255);
    for (int k = 0; k < ax->nminor; k++) {
        double x = floor(map(ax, ax->minor[k], px)) + 0.5;
        canvas_segment(rc, x, py[1], x, py[0], 1, 0, minor);
    }
    for (int k = 0; k < ay->nminor; k++) {
        double y = floor(map(ay, ay->minor[k], py)) + 0.5;
        canvas_segment(rc, px[0], y, px[1], y, 1, 0, minor);
    }
    for (int k = 0; k < ax->nticks; k++) {
        double x = floor(map(ax, ax->ticks[k], px)) + 0.5;
        canvas_segment(rc, x, py[1], x, py[0], 1, 0, grid);
        canvas_segment(rc, x, py[0], x, py[0] + tick, 1, 0, ink);
        canvas_text(rc, ax->labels[k], fs, x, py[0] + tick + gap, 0.5, 0, 0, ink);
    }
    for (int k = 0; k < ay->nticks; k++) {
        double y = floor(map(ay, ay->ticks[k], py)) + 0.5;
        canvas_segment(rc, px[0], y, px[1], y, 1, 0, grid);
        canvas_segment(rc, px[0] - tick, y, px[0], y, 1, 0, ink);
        canvas_text(rc, ay->labels[k], fs, px[0] - tick - gap, y, 1, 0.5, 0, ink);
    }
    canvas_segment(rc, px[0] - 0.5, py[0], px[1] + 0.5, py[0], 1, 0, ink);
    canvas_segment(rc, px[0] - 0.5, py[1], px[1] + 0.5, py[1], 1, 0, ink);
    canvas_segment(rc, px[0], py[1], px[0], py[0], 1, 0, ink);
    canvas_segment(rc, px[1], py[1], px[1], py[0], 1, 0, ink);
    if (def->title && *def->title)
        canvas_text(rc, def->title, p->tfs, 0.5 * (px[0] + px[1]), m, 0.5, 0, 0, ink);
    if (def->xlabel && *def->xlabel)
        canvas_text(rc, def->xlabel, fs, 0.5 * (px[0] + px[1]), p->H - m, 0.5, 1, 0, ink);
    if (def->ylabel && *def->ylabel)
        canvas_text(rc, def->ylabel, fs, m, 0.5 * (py[0] + py[1]), 0.5, 0, 1, ink);
}

static void draw_series(render_context *rc, const plot_frame *p)
{
    const render_plot_def *def = p->def;
    const axis *ax = &p->ax, *ay = &p->ay;
    const double *px = p->px, *py = p->py, lw = p->lw, mr = p->mr;
    for (int k = 0; k < def->nseries; k++) {
        const render_series *s = &def->series[k];
        const unsigned char *c3 = SERIES_RGB[k % 10];
        rgba8 c = rgba(c3[0], c3[1], c3[2], 255);
        double prev[2] = {NAN, NAN};
        if (s->style == RENDER_HIDDEN)
            continue;
        for (size_t i = 0; s->style != RENDER_POINTS && i < s->n; i++) {
            double x = s->x[i], y = s->y[i];
            if (!isfinite(x) || !isfinite(y)) {
                prev[0] = NAN;
                continue;
            }
            double X = map(ax, def->xlog ? log10(x) : x, px);
            double Y = map(ay, def->ylog ? log10(y) : y, py);
            if (isfinite(prev[0]))
                canvas_segment(rc, prev[0], prev[1], X, Y, lw, 1, c);
            else if (s->n == 1 || i + 1 == s->n || !isfinite(s->x[i + 1]) || !isfinite(s->y[i + 1]))
                canvas_disk(rc, X, Y, 0.5 * lw, 0, c); /* a lone point of a line */
            prev[0] = X;
            prev[1] = Y;
        }
        for (size_t i = 0; s->style != RENDER_LINE && i < s->n; i++) {
            double x = s->x[i], y = s->y[i];
            if (!isfinite(x) || !isfinite(y))
                continue;
            marker(rc, k % 3, map(ax, def->xlog ? log10(x) : x, px),
                   map(ay, def->ylog ? log10(y) : y, py), mr, c);
        }
    }
}

/* The top-left corner of a legend box of bw x bh pixels: at the frame corner whose box covers
 * the fewest data points. */
static void legend_corner(const plot_frame *p, double bw, double bh, double *x0, double *y0)
{
    const render_plot_def *def = p->def;
    const axis *ax = &p->ax, *ay = &p->ay;
    const double *px = p->px, *py = p->py, mr = p->mr;
    double inset = 0.8 * p->fs, best_x0 = 0, best_y0 = 0;
    long best = -1;
    for (int corner = 0; corner < 4; corner++) {
        double cx0 = corner % 2 == 0 ? px[1] - inset - bw : px[0] + inset;
        double cy0 = corner < 2 ? py[1] + inset : py[0] - inset - bh;
        long count = 0;
        for (int k = 0; k < def->nseries; k++)
            for (size_t i = 0; i < def->series[k].n; i++) {
                double x = def->series[k].x[i], y = def->series[k].y[i];
                if (!isfinite(x) || !isfinite(y))
                    continue;
                double X = map(ax, def->xlog ? log10(x) : x, px);
                double Y = map(ay, def->ylog ? log10(y) : y, py);
                count += X >= cx0 - mr && X <= cx0 + bw + mr && Y >= cy0 - mr && Y <= cy0 + bh + mr;
            }
        if (best < 0 || count < best) {
            best = count;
            best_x0 = cx0;
            best_y0 = cy0;
        }
    }
    *x0 = best_x0;
    *y0 = best_y0;
}

/* The legend of the labelled series, in a corner inside the frame. */
static void draw_legend(render_context *rc, const plot_frame *p)
{
    const render_plot_def *def = p->def;
    const double fs = p->fs, lw = p->lw, mr = p->mr;
    const int gap = p->gap;
    int nl = 0;
    double lwid = 0;
    for (int k = 0; k < def->nseries; k++)
        if (def->series[k].label && *def->series[k].label &&
            def->series[k].style != RENDER_HIDDEN) {
            nl++;
            lwid = fmax(lwid, canvas_text_width(rc, def->series[k].label, fs));
        }
    if (!nl)
        return;
    double sample = 2.2 * fs, pad = 0.6 * fs, rowh = p->lh;
    double bw = pad + sample + gap + lwid + pad, bh = 2 * pad + nl * rowh - (rowh - fs);
    double best_x0, best_y0;
    legend_corner(p, bw, bh, &best_x0, &best_y0);
    double x0 = floor(best_x0) + 0.5, y0 = floor(best_y0) + 0.5;
    double x1 = floor(x0 + bw) + 0.5, y1 = floor(y0 + bh) + 0.5;
    canvas_rect(rc, x0, y0, x1, y1, rgba(255, 255, 255, 235));
    rgba8 edge = rgba(190, 190, 190, 255);
    canvas_segment(rc, x0 - 0.5, y0, x1 + 0.5, y0, 1, 0, edge);
    canvas_segment(rc, x0 - 0.5, y1, x1 + 0.5, y1, 1, 0, edge);
    canvas_segment(rc, x0, y0, x0, y1, 1, 0, edge);
    canvas_segment(rc, x1, y0, x1, y1, 1, 0, edge);
    int row = 0;
    for (int k = 0; k < def->nseries; k++) {
        const render_series *s = &def->series[k];
        if (!s->label || !*s->label || s->style == RENDER_HIDDEN)
            continue;
        const unsigned char *c3 = SERIES_RGB[k % 10];
        rgba8 c = rgba(c3[0], c3[1], c3[2], 255);
        double yc = y0 + pad + row * rowh + 0.5 * fs, xs = x0 + pad;
        if (s->style != RENDER_POINTS)
            canvas_segment(rc, xs, yc, xs + sample, yc, lw, 1, c);
        if (s->style != RENDER_LINE)
            marker(rc, k % 3, xs + 0.5 * sample, yc, mr, c);
        canvas_text(rc, s->label, fs, xs + sample + gap, yc, 0, 0.5, 0, p->ink);
        row++;
    }
}

core_status render_plot(render_context *rc, const render_plot_def *def, render_image *out,
                        render_plot_axes *axes, core_error *err)
{
    out->rgba = NULL;
    out->width = out->height = 0;
    int W = def->width ? def->width : 800, H = def->height ? def->height : 560;
    if (W < RENDER_MIN_SIZE || W > RENDER_MAX_SIZE || H < RENDER_MIN_SIZE || H > RENDER_MAX_SIZE)
        return core_fail(err, CORE_ERR_ARG, "image size %d x %d outside [%d, %d] pixels", W, H,
                         RENDER_MIN_SIZE, RENDER_MAX_SIZE);
    if (def->nseries < 1)
        return core_fail(err, CORE_ERR_ARG, "no series to plot");
    plot_frame p = {.def = def, .W = W, .H = H, .ax = {.log = def->xlog}, .ay = {.log = def->ylog}};
    core_status st;
    if ((st = data_ranges(&p, err)) != CORE_OK || (st = plot_layout(rc, &p, err)) != CORE_OK)
        return st;
    if (axes) {
        memcpy(axes->xlim, p.ax.lim, sizeof axes->xlim);
        memcpy(axes->ylim, p.ay.lim, sizeof axes->ylim);
        memcpy(axes->px, p.px, sizeof axes->px);
        memcpy(axes->py, p.py, sizeof axes->py);
    }
    if ((st = canvas_begin(rc, W, H, err)) != CORE_OK)
        return st;
    draw_axes(rc, &p);
    draw_series(rc, &p);
    draw_legend(rc, &p);
    return canvas_end(rc, out, err);
}
