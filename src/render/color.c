/* Colour maps (viridis, lightness-linear grey), well-separated label colours, and the tick
 * functions shared by colour bars and plots. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/render_internal.h"

/* matplotlib's viridis (van der Walt & Smith, CC0), every 8th of its 256 entries and the last:
 * linear interpolation between them stays within 2/255 of the full table. */
static const double VIRIDIS[33][3] = {
    {0.267004, 0.004874, 0.329415}, {0.277018, 0.050344, 0.375715}, {0.282327, 0.094955, 0.417331},
    {0.282884, 0.135920, 0.453427}, {0.278826, 0.175490, 0.483397}, {0.270595, 0.214069, 0.507052},
    {0.258965, 0.251537, 0.524736}, {0.244972, 0.287675, 0.537260}, {0.229739, 0.322361, 0.545706},
    {0.214298, 0.355619, 0.551184}, {0.199430, 0.387607, 0.554642}, {0.185556, 0.418570, 0.556753},
    {0.172719, 0.448791, 0.557885}, {0.160665, 0.478540, 0.558115}, {0.149039, 0.508051, 0.557250},
    {0.137770, 0.537492, 0.554906}, {0.127568, 0.566949, 0.550556}, {0.120565, 0.596422, 0.543611},
    {0.120638, 0.625828, 0.533488}, {0.132268, 0.655014, 0.519661}, {0.157851, 0.683765, 0.501686},
    {0.196571, 0.711827, 0.479221}, {0.246070, 0.738910, 0.452024}, {0.304148, 0.764704, 0.419943},
    {0.369214, 0.788888, 0.382914}, {0.440137, 0.811138, 0.340967}, {0.515992, 0.831158, 0.294279},
    {0.595839, 0.848717, 0.243329}, {0.678489, 0.863742, 0.189503}, {0.762373, 0.876424, 0.137064},
    {0.845561, 0.887322, 0.099702}, {0.926106, 0.897330, 0.104071}, {0.993248, 0.906157, 0.143936}};

static unsigned char to8(double v)
{
    return (unsigned char)lround(v <= 0 ? 0 : v >= 1 ? 255 : v * 255);
}

/* sRGB encoding of linear intensity. */
static double srgb(double lin)
{
    return lin <= 0.0031308 ? 12.92 * lin : 1.055 * pow(lin, 1 / 2.4) - 0.055;
}

void render_colormap_rgb(render_colormap map, double t, unsigned char rgb[3])
{
    if (isnan(t)) {
        rgb[0] = rgb[1] = rgb[2] = 128;
        return;
    }
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    if (map == RENDER_GRAY) {
        /* CIE L* = 100 t to luminance Y, then sRGB: equal steps in t look equal. */
        double L = 100 * t;
        double Y = L > 8 ? pow((L + 16) / 116, 3) : L / 903.2962962962963;
        rgb[0] = rgb[1] = rgb[2] = to8(srgb(Y));
        return;
    }
    /* Knot k sits at index 8k of the 256-entry table (the last at 255). */
    double pos = t * 255;
    int k = (int)(pos / 8);
    if (k > 31)
        k = 31;
    double t0 = 8.0 * k, t1 = k == 31 ? 255 : 8.0 * (k + 1);
    double u = (pos - t0) / (t1 - t0);
    for (int c = 0; c < 3; c++)
        rgb[c] = to8(VIRIDIS[k][c] + (VIRIDIS[k + 1][c] - VIRIDIS[k][c]) * u);
}

/* Hues stepped by the golden angle (neighbouring ids far apart on the wheel) at three
 * lightness/chroma levels, converted from OKLCh so the steps are perceptually even. */
void render_label_rgb(long id, unsigned char rgb[3])
{
    static const double LEVEL[3][2] = {{0.72, 0.13}, {0.58, 0.14}, {0.84, 0.10}};
    unsigned long u = (unsigned long)(id < 0 ? -id : id);
    double h = fmod(u * 0.6180339887498949, 1.0) * 2 * 3.14159265358979323846;
    const double *lc = LEVEL[u % 3];
    double L = lc[0], a = lc[1] * cos(h), b = lc[1] * sin(h);
    double l_ = L + 0.3963377774 * a + 0.2158037573 * b;
    double m_ = L - 0.1055613458 * a - 0.0638541728 * b;
    double s_ = L - 0.0894841775 * a - 1.2914855480 * b;
    double l = l_ * l_ * l_, m = m_ * m_ * m_, s = s_ * s_ * s_;
    double r = 4.0767416621 * l - 3.3077115913 * m + 0.2309699292 * s;
    double g = -1.2684380046 * l + 2.6097574011 * m - 0.3413193965 * s;
    double bl = -0.0041960863 * l - 0.7034186147 * m + 1.7076147010 * s;
    rgb[0] = to8(srgb(r < 0 ? 0 : r));
    rgb[1] = to8(srgb(g < 0 ? 0 : g));
    rgb[2] = to8(srgb(bl < 0 ? 0 : bl));
}

/* ---- ticks --------------------------------------------------------------------------------- */
int ticks_linear(double lo, double hi, int target, double *ticks, int max, double *step)
{
    if (!(hi > lo) || target < 1) {
        *step = 1;
        if (max > 0 && isfinite(lo)) {
            ticks[0] = lo;
            return 1;
        }
        return 0;
    }
    double raw = (hi - lo) / target;
    double p = pow(10, floor(log10(raw)));
    double f = raw / p;
    double s = (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
    *step = s;
    int n = 0;
    for (double k = ceil(lo / s - 1e-9); n < max; k += 1) {
        double v = k * s;
        if (v > hi + 1e-9 * s)
            break;
        ticks[n++] = fabs(v) < 1e-12 * s ? 0 : v;
    }
    return n;
}

void ticks_format(double v, double step, double vmax, char *buf, size_t size)
{
    char tmp[64];
    vmax = fabs(vmax);
    if (v == 0) {
        snprintf(tmp, sizeof tmp, "0");
    } else if (vmax >= 1e5 || vmax < 1e-3) {
        /* One exponent and one precision for the whole set (that of its largest value), with
         * enough mantissa digits to tell neighbours apart: 2.0e6, 1.5e6, 1.0e6, 0.5e6. */
        int e = (int)floor(log10(vmax));
        int digits = e - (int)floor(log10(step));
        if (digits < 0)
            digits = 0;
        if (digits > 6)
            digits = 6;
        snprintf(tmp, sizeof tmp, "%.*fe%d", digits, v / pow(10, e), e);
    } else {
        int dec = step >= 1 ? 0 : (int)ceil(-log10(step) - 1e-9);
        if (dec > 8)
            dec = 8;
        snprintf(tmp, sizeof tmp, "%.*f", dec, v);
    }
    /* a true minus sign (U+2212) reads better than a hyphen */
    if (tmp[0] == '-')
        snprintf(buf, size, "\xe2\x88\x92%s", tmp + 1);
    else
        snprintf(buf, size, "%s", tmp);
}

/* ---- colour bars and reference arrows ------------------------------------------------------ */
int colorbar_layout(render_context *rc, colorbar *cb, const double range[2], const char *label,
                    double fs)
{
    cb->range[0] = range[0];
    cb->range[1] = range[1];
    cb->fs = fs;
    cb->label = label;
    cb->bar_w = (int)lround(1.1 * fs);
    cb->gap = (int)lround(0.8 * fs);
    cb->tick_len = (int)lround(0.35 * fs);
    cb->lgap = (int)lround(0.3 * fs);
    cb->maxlabel = 0;
    cb->nticks = ticks_linear(range[0], range[1], 5, cb->ticks, 16, &cb->step);
    double vmax = 0;
    for (int k = 0; k < cb->nticks; k++)
        vmax = fmax(vmax, fabs(cb->ticks[k]));
    for (int k = 0; k < cb->nticks; k++) {
        ticks_format(cb->ticks[k], cb->step, vmax, cb->labels[k], sizeof cb->labels[k]);
        double tw = canvas_text_width(rc, cb->labels[k], fs);
        cb->maxlabel = tw > cb->maxlabel ? tw : cb->maxlabel;
    }
    return cb->gap + cb->bar_w + cb->tick_len + cb->lgap + (int)ceil(cb->maxlabel) +
           (label && *label ? (int)lround(0.5 * fs + 1.3 * fs) : 0);
}

/* One rectangle per pixel row, so the bar shows every colour the map has at this size. */
void colorbar_draw(render_context *rc, const colorbar *cb, render_colormap map, double right,
                   double top, double bottom)
{
    double bx0 = right + cb->gap, bx1 = bx0 + cb->bar_w;
    double y0 = round(top), y1 = round(bottom);
    int rows = (int)(y1 - y0);
    for (int k = 0; k < rows; k++) {
        unsigned char c[3];
        render_colormap_rgb(map, 1 - (k + 0.5) / rows, c);
        canvas_rect(rc, bx0, y0 + k, bx1, y0 + k + 1, rgba(c[0], c[1], c[2], 255));
    }
    rgba8 fc = rgba(80, 80, 80, 255), ink = rgba(20, 20, 20, 255);
    canvas_segment(rc, bx0 - 1, y0 - 0.5, bx1 + 1, y0 - 0.5, 1, 0, fc);
    canvas_segment(rc, bx0 - 1, y1 + 0.5, bx1 + 1, y1 + 0.5, 1, 0, fc);
    canvas_segment(rc, bx0 - 0.5, y0, bx0 - 0.5, y1, 1, 0, fc);
    canvas_segment(rc, bx1 + 0.5, y0, bx1 + 0.5, y1, 1, 0, fc);
    const double span = cb->range[1] - cb->range[0];
    for (int k = 0; k < cb->nticks; k++) {
        double ty = y1 - (cb->ticks[k] - cb->range[0]) / span * rows;
        ty = floor(ty) + 0.5;
        canvas_segment(rc, bx1 + 1, ty, bx1 + 1 + cb->tick_len, ty, 1, 0, fc);
        canvas_text(rc, cb->labels[k], cb->fs, bx1 + 1 + cb->tick_len + cb->lgap, ty, 0, 0.5, 0,
                    ink);
    }
    if (cb->label && *cb->label)
        canvas_text(rc, cb->label, cb->fs,
                    bx1 + 1 + cb->tick_len + cb->lgap + cb->maxlabel + 0.5 * cb->fs,
                    0.5 * (y0 + y1), 0.5, 0, 1, ink);
}

void reference_arrow(render_context *rc, double umax, double k, double sc, const char *unit,
                     double right, double bottom, double fs, double w, double head, rgba8 c)
{
    if (!(umax > 0) || !isfinite(umax))
        return;
    double ref = pow(10, floor(log10(umax)));
    ref *= umax / ref >= 5 ? 5 : umax / ref >= 2 ? 2 : 1;
    double len = ref * k * sc;
    char label[96], num[48];
    ticks_format(ref, ref, ref, num, sizeof num);
    if (unit && *unit)
        snprintf(label, sizeof label, "%s %s", num, unit);
    else
        snprintf(label, sizeof label, "%s", num);
    double tw = canvas_text_width(rc, label, fs);
    double yb = bottom - 0.35 * fs, x1 = right - tw - 0.5 * fs;
    double x0 = x1 - len, hl = fmin(0.35 * len, head);
    canvas_arrow(rc, x0, yb, x1, yb, 1, 0, w, hl, c);
    canvas_text(rc, label, fs, right, bottom, 1, 1, 0, rgba(20, 20, 20, 255));
}
