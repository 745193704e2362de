/* Frames of DEM scenes: disks (2D) or shaded spheres seen by a camera (3D), coloured by id, label
 * or a scalar through a colour map, rotation markers, force chains, walls, the box, a title, a
 * stamp and a colour bar. */
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
    d.camera.azimuth = -60;
    d.camera.elevation = 25;
    d.camera.fov = 30;
    return d;
}

/* ---- 3D camera ------------------------------------------------------------------------------ */
typedef struct camera3 {
    double c[3], eye[3];    /* box centre; eye position (perspective) */
    double f[3], r[3], u[3]; /* forward (away from the eye), right, up on the image */
    int perspective;
} camera3;

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int d = 0; d < 3; d++)
        v[d] /= n;
}

static void camera_setup(const render_camera *cam, const double lo[3], const double hi[3],
                         const double g[3], camera3 *p)
{
    /* up: against the strongest gravity component, z without gravity */
    int up = 2;
    double sign = 1;
    if (fabs(g[0]) + fabs(g[1]) + fabs(g[2]) > 0) {
        up = fabs(g[0]) >= fabs(g[1]) && fabs(g[0]) >= fabs(g[2]) ? 0
             : fabs(g[1]) >= fabs(g[2])                           ? 1
                                                                  : 2;
        sign = g[up] > 0 ? -1 : 1;
    }
    double U[3] = {0, 0, 0}, A[3] = {0, 0, 0}, B[3] = {0, 0, 0};
    U[up] = sign;
    A[(up + 1) % 3] = 1;
    cross(U, A, B); /* A, B, U right-handed */
    const double deg = 3.14159265358979323846 / 180;
    double az = cam->azimuth * deg, el = cam->elevation * deg, diag = 0;
    for (int d = 0; d < 3; d++) {
        p->c[d] = 0.5 * (lo[d] + hi[d]);
        double to_eye = cos(el) * (cos(az) * A[d] + sin(az) * B[d]) + sin(el) * U[d];
        p->f[d] = -to_eye;
        diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    }
    if (fabs(cos(el)) < 1e-9) { /* looking straight down or up: right is A */
        for (int d = 0; d < 3; d++)
            p->r[d] = A[d];
    } else {
        cross(p->f, U, p->r);
        normalize(p->r);
    }
    cross(p->r, p->f, p->u);
    p->perspective = cam->perspective;
    double dist = 0.5 * sqrt(diag) / tan(0.5 * cam->fov * deg);
    for (int d = 0; d < 3; d++)
        p->eye[d] = p->c[d] - p->f[d] * dist;
}

/* Image-plane position, projected radius and depth of a sphere; 0 when it is behind the eye. */
static int project(const camera3 *p, const double q[3], double rad, double *X, double *Y,
                   double *R, double *z)
{
    const double *o = p->perspective ? p->eye : p->c;
    double rel[3] = {q[0] - o[0], q[1] - o[1], q[2] - o[2]};
    double x = 0, y = 0, zz = 0;
    for (int d = 0; d < 3; d++) {
        x += rel[d] * p->r[d];
        y += rel[d] * p->u[d];
        zz += rel[d] * p->f[d];
    }
    *z = zz;
    if (!p->perspective) {
        *X = x, *Y = y, *R = rad;
        return 1;
    }
    if (zz <= rad * 1.0001)
        return 0;
    *X = x / zz, *Y = y / zz, *R = rad / sqrt(zz * zz - rad * rad);
    return 1;
}

typedef struct depth_key {
    double z;
    size_t i;
} depth_key;

static int far_first(const void *a, const void *b)
{
    const depth_key *x = a, *y = b;
    if (x->z != y->z)
        return x->z > y->z ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
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
    if (x->i != y->i)
        return x->i < y->i ? -1 : 1;
    return x->j < y->j ? -1 : x->j > y->j;
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

/* The section of the box by the plane through p with normal n: its corners in order around
 * the polygon (at most 6; 2 when the plane only touches an edge). Returns their number. */
static int box_section(const double lo[3], const double hi[3], const double p[3], const double n[3],
                       double poly[6][3])
{
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), diag = 0, c[8][3], dist[8];
    if (!(nn > 0))
        return 0;
    for (int d = 0; d < 3; d++)
        diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    double tol = 1e-9 * sqrt(diag);
    for (int k = 0; k < 8; k++) {
        dist[k] = 0;
        for (int d = 0; d < 3; d++) {
            c[k][d] = (k >> d) & 1 ? hi[d] : lo[d];
            dist[k] += (c[k][d] - p[d]) * n[d] / nn;
        }
    }
    double pts[12 + 8][3];
    int m = 0;
    for (int k = 0; k < 8; k++) /* corners on the plane (a wall on a face of the box) */
        if (fabs(dist[k]) <= tol)
            memcpy(pts[m++], c[k], sizeof c[k]);
    for (int a = 0; a < 8; a++) /* edges crossing it */
        for (int bit = 1; bit < 8; bit <<= 1) {
            int b = a | bit;
            if (b == a || fabs(dist[a]) <= tol || fabs(dist[b]) <= tol ||
                (dist[a] > 0) == (dist[b] > 0))
                continue;
            double t = dist[a] / (dist[a] - dist[b]);
            for (int d = 0; d < 3; d++)
                pts[m][d] = c[a][d] + t * (c[b][d] - c[a][d]);
            m++;
        }
    if (m < 2)
        return 0;
    /* order around the centroid, by angle in a basis (u, v) of the plane */
    double ctr[3] = {0, 0, 0}, u[3], v[3], un[3] = {n[0] / nn, n[1] / nn, n[2] / nn};
    for (int k = 0; k < m; k++)
        for (int d = 0; d < 3; d++)
            ctr[d] += pts[k][d] / m;
    int least = fabs(un[0]) <= fabs(un[1]) && fabs(un[0]) <= fabs(un[2]) ? 0
                : fabs(un[1]) <= fabs(un[2])                             ? 1
                                                                         : 2;
    double e[3] = {0, 0, 0};
    e[least] = 1;
    cross(un, e, u);
    normalize(u);
    cross(un, u, v);
    double ang[20];
    for (int k = 0; k < m; k++) {
        double x = 0, y = 0;
        for (int d = 0; d < 3; d++) {
            x += (pts[k][d] - ctr[d]) * u[d];
            y += (pts[k][d] - ctr[d]) * v[d];
        }
        ang[k] = atan2(y, x);
    }
    for (int i = 1; i < m; i++) /* insertion sort: at most 6 distinct points */
        for (int j = i; j > 0 && ang[j] < ang[j - 1]; j--) {
            double t = ang[j];
            ang[j] = ang[j - 1];
            ang[j - 1] = t;
            double q[3];
            memcpy(q, pts[j], sizeof q);
            memcpy(pts[j], pts[j - 1], sizeof q);
            memcpy(pts[j - 1], q, sizeof q);
        }
    int out = 0;
    for (int k = 0; k < m && out < 6; k++) {
        double d2 = 0;
        if (out)
            for (int d = 0; d < 3; d++)
                d2 += (pts[k][d] - poly[out - 1][d]) * (pts[k][d] - poly[out - 1][d]);
        if (!out || d2 > tol * tol)
            memcpy(poly[out++], pts[k], sizeof pts[k]);
    }
    return out;
}

/* ---- walls beyond planes ------------------------------------------------------------------ *
 * Their outlines now (dem_wall_outline: the wall's current pose, so a moving wall moves), taken
 * before anything is drawn. */
enum { SHAPE_SEGMENTS = 96 }; /* points around a circle or a cylinder's rim */

typedef struct shape_lines {
    double *pts;   /* 3 per point, strip after strip */
    int *nv, *cyl; /* points of each strip; 1: a rim of a 3D cylinder (paired with the next) */
    int n;
} shape_lines;

static void shape_lines_free(shape_lines *o)
{
    free(o->pts);
    free(o->nv);
    free(o->cyl);
}

static core_status collect_shapes(dem_scene *s, shape_lines *o, core_error *err)
{
    memset(o, 0, sizeof *o);
    const int nw = dem_wall_count(s);
    size_t np = 0;
    int ns = 0;
    for (int id = 0; id < nw; id++) {
        size_t k = 0;
        ns += dem_wall_outline(s, id, SHAPE_SEGMENTS, NULL, NULL, &k);
        np += k;
    }
    if (ns == 0)
        return CORE_OK;
    o->pts = malloc(3 * np * sizeof *o->pts);
    o->nv = malloc((size_t)ns * sizeof *o->nv);
    o->cyl = malloc((size_t)ns * sizeof *o->cyl);
    if (!o->pts || !o->nv || !o->cyl) {
        shape_lines_free(o);
        memset(o, 0, sizeof *o);
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory for the walls");
    }
    size_t q = 0;
    for (int id = 0; id < nw; id++) {
        size_t k = 0;
        const int m = dem_wall_outline(s, id, SHAPE_SEGMENTS, o->nv + o->n, o->pts + 3 * q, &k);
        const int rims = dem_dim(s) == 3 && dem_wall_kind_of(s, id) == DEM_WALL_CYLINDER;
        for (int j = 0; j < m; j++)
            o->cyl[o->n + j] = rims && j == 0 && m == 2;
        o->n += m;
        q += k;
    }
    return CORE_OK;
}
/* ---- a frame of a scene: what is worked out before anything is drawn ------------------------ */
typedef struct dem_frame {
    const render_grains_def *def;
    int D, W, H; /* H: 0 until the layout sets it from the box's aspect */
    int mapped;  /* coloured through the colour map (speed, rotation, values) */
    size_t n, nshow;
    double box_lo[3], box_hi[3], g[3];
    double *val;     /* the per-grain scalar when mapped */
    double range[2]; /* its colour-map limits */
    /* geometry: 2D as it is; 3D projected (x, y, r point into proj), drawn far to near (order) */
    const double *x, *y, *r;
    double *proj, box2[8][2];
    depth_key *order;
    camera3 cam;
    double lo[2], hi[2];
    /* layout: margin, title band, colour bar band, the box's pixels and scale */
    double fs, sc, bw, bh, ox, oy, ww, mean_r;
    int m, ay0, band, show_bar;
    colorbar bar;
    rgba8 wall_c;
    /* contacts and wall outlines, taken before anything is drawn */
    chain_list chains;
    shape_lines shapes;
} dem_frame;

static void frame_free(dem_frame *f)
{
    shape_lines_free(&f->shapes);
    free(f->chains.c);
    free(f->val);
    free(f->proj);
    free(f->order);
}

/* Pixel column and row of scene (image-plane) coordinates. */
static double col_of(const dem_frame *f, double X) { return f->ox + (X - f->lo[0]) * f->sc; }

static double row_of(const dem_frame *f, double Y) { return f->oy + (f->hi[1] - Y) * f->sc; }

static core_status check_def(dem_scene *s, const render_grains_def *def, core_error *err)
{
    const int D = dem_dim(s);
    if (D == 3 && (def->force_chains || def->rotation || def->arrows[0]))
        return core_fail(err, CORE_ERR_ARG,
                         "force chains, rotation markers and arrows are drawn "
                         "in 2D scenes only");
    if (def->arrows[0] &&
        (!def->arrows[1] || !(def->arrow_scale >= 0) || !isfinite(def->arrow_scale)))
        return core_fail(err, CORE_ERR_ARG, "arrows need two arrays and a scale >= 0");
    if (D == 3 && (!(def->camera.fov > 0 && def->camera.fov < 90) ||
                   !isfinite(def->camera.azimuth) || !isfinite(def->camera.elevation)))
        return core_fail(err, CORE_ERR_ARG,
                         "camera: finite angles and fov in (0, 90) degrees "
                         "expected, got fov %g",
                         def->camera.fov);
    int W = def->width ? def->width : RENDER_DEFAULT_WIDTH, H = def->height;
    if (W < RENDER_MIN_SIZE || W > RENDER_MAX_SIZE ||
        (H && (H < RENDER_MIN_SIZE || H > RENDER_MAX_SIZE)))
        return core_fail(err, CORE_ERR_ARG, "image size %d x %d outside [%d, %d] pixels", W, H,
                         RENDER_MIN_SIZE, RENDER_MAX_SIZE);
    const size_t n = dem_count(s);
    if (def->color == RENDER_COLOR_VALUES && n && !def->values)
        return core_fail(err, CORE_ERR_ARG, "colour by values without values");
    if (def->color == RENDER_COLOR_LABELS && n && !def->labels)
        return core_fail(err, CORE_ERR_ARG, "colour by labels without labels");
    if (def->range[0] > def->range[1] || !isfinite(def->range[0]) || !isfinite(def->range[1]))
        return core_fail(err, CORE_ERR_ARG, "colour range [%g, %g] is not increasing",
                         def->range[0], def->range[1]);
    return CORE_OK;
}

static void frame_start(dem_frame *f, dem_scene *s, const render_grains_def *def)
{
    memset(f, 0, sizeof *f);
    f->def = def;
    f->D = dem_dim(s);
    f->W = def->width ? def->width : RENDER_DEFAULT_WIDTH;
    f->H = def->height;
    f->n = dem_count(s);
    f->mapped = def->color == RENDER_COLOR_SPEED || def->color == RENDER_COLOR_ROTATION ||
                def->color == RENDER_COLOR_VALUES;
    f->range[0] = 0;
    f->range[1] = 1;
    dem_box(s, f->box_lo, f->box_hi, f->g);
}

/* The per-grain scalar of a mapped colour and its range. */
static core_status grain_values(dem_frame *f, dem_scene *s, core_error *err)
{
    const render_grains_def *def = f->def;
    const size_t n = f->n;
    const int D = f->D;
    if (!f->mapped)
        return CORE_OK;
    double *val = f->val = malloc((n ? n : 1) * sizeof *val);
    if (!val)
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory");
    const double *v[3] = {NULL, NULL, NULL}, *w[3] = {NULL, NULL, NULL};
    for (int d = 0; d < D; d++) {
        v[d] = dem_velocities(s, d);
        w[d] = D == 3 || d == 0 ? dem_angular_velocities(s, D == 3 ? d : 2) : NULL;
    }
    for (size_t i = 0; i < n; i++) {
        double v2 = 0, w2 = 0;
        for (int d = 0; d < D; d++) {
            v2 += v[d][i] * v[d][i];
            w2 += w[d] ? w[d][i] * w[d][i] : 0;
        }
        val[i] = def->color == RENDER_COLOR_SPEED      ? sqrt(v2)
                 : def->color == RENDER_COLOR_ROTATION ? (D == 2 ? (w[0] ? w[0][i] : 0) : sqrt(w2))
                                                       : def->values[i];
    }
    if (def->range[0] < def->range[1]) {
        f->range[0] = def->range[0];
        f->range[1] = def->range[1];
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
        f->range[0] = mn;
        f->range[1] = mx;
    }
    return CORE_OK;
}

/* The image-plane geometry: 2D as it is; 3D projected by the camera, the visible spheres sorted
 * far to near, the box's corners projected and the extent their bounds. */
static core_status scene_geometry(dem_frame *f, dem_scene *s, core_error *err)
{
    const size_t n = f->n;
    const double *box_lo = f->box_lo, *box_hi = f->box_hi;
    double *lo = f->lo, *hi = f->hi;
    lo[0] = box_lo[0];
    lo[1] = box_lo[1];
    hi[0] = box_hi[0];
    hi[1] = box_hi[1];
    const double *x = dem_positions(s, 0), *y = dem_positions(s, 1), *r = dem_radii(s);
    f->x = x;
    f->y = y;
    f->r = r;
    f->nshow = n;
    if (f->D != 3)
        return CORE_OK;
    camera_setup(&f->def->camera, box_lo, box_hi, f->g, &f->cam);
    double *proj = f->proj = malloc((n ? n : 1) * 3 * sizeof *proj);
    depth_key *order = f->order = malloc((n ? n : 1) * sizeof *order);
    if (!proj || !order)
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory");
    const double *z = dem_positions(s, 2);
    size_t nshow = 0;
    for (size_t i = 0; i < n; i++) {
        double q[3] = {x[i], y[i], z[i]}, depth;
        if (project(&f->cam, q, r[i], &proj[i], &proj[n + i], &proj[2 * n + i], &depth))
            order[nshow++] = (depth_key){depth, i};
    }
    qsort(order, nshow, sizeof *order, far_first);
    f->nshow = nshow;
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    double(*box2)[2] = f->box2;
    for (int k = 0; k < 8; k++) {
        double q[3] = {k & 1 ? box_hi[0] : box_lo[0], k & 2 ? box_hi[1] : box_lo[1],
                       k & 4 ? box_hi[2] : box_lo[2]},
               R, depth;
        project(&f->cam, q, 0, &box2[k][0], &box2[k][1], &R, &depth);
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], box2[k][d]);
            hi[d] = fmax(hi[d], box2[k][d]);
        }
    }
    f->x = proj;
    f->y = proj + n;
    f->r = proj + 2 * n;
    return CORE_OK;
}

/* Margins, the title band, the colour bar's band and the box fitted into the rest; the image
 * height from the box's aspect when none is given. */
static core_status frame_layout(render_context *rc, dem_frame *f, core_error *err)
{
    const render_grains_def *def = f->def;
    const double hx = f->hi[0] - f->lo[0], hy = f->hi[1] - f->lo[1];
    const int W = f->W;
    int H = f->H;
    double fs = f->fs = canvas_font_px(W, H ? H : W);
    int m = f->m = (int)lround(0.8 * fs);
    int has_top = (def->title && *def->title) || (def->stamp && *def->stamp) || def->arrows[0];
    int ay0 = f->ay0 = m + (has_top ? (int)lround(1.7 * fs) : 0);
    f->show_bar = f->mapped && def->colorbar;
    const char *bar_label = def->colorbar_label ? def->colorbar_label : COLOR_LABELS[def->color];
    f->band = f->show_bar ? colorbar_layout(rc, &f->bar, f->range, bar_label, fs) : 0;
    int ax0 = m, ax1 = W - m - f->band;
    if (ax1 - ax0 < 4)
        return core_fail(err, CORE_ERR_ARG, "image width %d leaves no room for the scene", W);
    if (!H) {
        double h = ay0 + (ax1 - ax0) * hy / hx + m;
        H = h > RENDER_MAX_SIZE   ? RENDER_MAX_SIZE
            : h < RENDER_MIN_SIZE ? RENDER_MIN_SIZE
                                  : (int)lround(h);
    }
    f->H = H;
    int ay1 = H - m;
    if (ay1 - ay0 < 4)
        return core_fail(err, CORE_ERR_ARG, "image height %d leaves no room for the scene", H);
    double sc = f->sc = fmin((ax1 - ax0) / hx, (ay1 - ay0) / hy);
    f->bw = hx * sc;
    f->bh = hy * sc;
    f->ox = ax0 + 0.5 * ((ax1 - ax0) - f->bw);
    f->oy = ay0 + 0.5 * ((ay1 - ay0) - f->bh);
    f->wall_c = rgba(60, 60, 60, 255);
    f->ww = fmax(2, lround(0.25 * fs));
    double mean_r = 0; /* in pixels: the width of chains, arrows and their heads */
    for (size_t i = 0; i < f->n; i++)
        mean_r += f->r[i];
    f->mean_r = f->n ? mean_r / f->n * sc : 1;
    return CORE_OK;
}

static void frame_view(const dem_frame *f, render_view *view)
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

/* Contacts and wall outlines: if they cannot be had, nothing has been drawn. */
static core_status collect_overlays(dem_frame *f, dem_scene *s, core_error *err)
{
    if (f->def->force_chains && f->n) {
        dem_each_contact(s, collect_chain, &f->chains);
        if (f->chains.oom)
            return core_fail(err, CORE_ERR_NOMEM, "render: out of memory for force chains");
    }
    if (f->def->shapes && collect_shapes(s, &f->shapes, err) != CORE_OK)
        return err ? err->status : CORE_ERR_NOMEM;
    return CORE_OK;
}

/* ---- 3D: the box's edges and the walls' outlines behind the spheres ---- */
static void draw_box_3d(render_context *rc, const dem_frame *f)
{
    rgba8 bc = rgba(170, 170, 170, 255);
    const double(*box2)[2] = f->box2;
    for (int a = 0; a < 8; a++)
        for (int bit = 1; bit < 8; bit <<= 1)
            if (!(a & bit))
                canvas_segment(rc, col_of(f, box2[a][0]), row_of(f, box2[a][1]),
                               col_of(f, box2[a | bit][0]), row_of(f, box2[a | bit][1]), 1, 1, bc);
}

static void draw_planes_3d(render_context *rc, const dem_frame *f)
{
    const render_grains_def *def = f->def;
    for (int k = 0; k < def->nwalls; k++) {
        double poly[6][3], P[6][2], R, depth;
        int nv = box_section(f->box_lo, f->box_hi, def->walls[k].point, def->walls[k].normal, poly);
        int seen = 1;
        for (int i = 0; i < nv; i++)
            seen &= project(&f->cam, poly[i], 0, &P[i][0], &P[i][1], &R, &depth);
        for (int i = 0; seen && i < nv && nv >= 2; i++) {
            int j = (i + 1) % nv;
            if (nv == 2 && i == 1)
                break;
            canvas_segment(rc, col_of(f, P[i][0]), row_of(f, P[i][1]), col_of(f, P[j][0]),
                           row_of(f, P[j][1]), 0.5 * f->ww, 1, f->wall_c);
        }
    }
}

/* Triangles' edges, cylinders' rims and four lines along them. */
static void draw_shapes_3d(render_context *rc, const dem_frame *f)
{
    const shape_lines *sh = &f->shapes;
    const double *pt = sh->pts;
    for (int k = 0; k < sh->n; pt += 3 * sh->nv[k], k++) {
        const int nv = sh->nv[k], close = nv == 3; /* a triangle */
        double P0[2], P1[2], R, depth;
        for (int i = 0; i + 1 < nv + close; i++) {
            const int j = (i + 1) % nv;
            if (project(&f->cam, pt + 3 * i, 0, &P0[0], &P0[1], &R, &depth) &&
                project(&f->cam, pt + 3 * j, 0, &P1[0], &P1[1], &R, &depth))
                canvas_segment(rc, col_of(f, P0[0]), row_of(f, P0[1]), col_of(f, P1[0]),
                               row_of(f, P1[1]), 0.5 * f->ww, 1, f->wall_c);
        }
        const int step = nv > 8 ? (nv - 1) / 4 : 1;
        for (int i = 0; sh->cyl[k] && i + 1 < nv; i += step) {
            const double *b = pt + 3 * nv; /* the other rim, the same angles */
            if (project(&f->cam, pt + 3 * i, 0, &P0[0], &P0[1], &R, &depth) &&
                project(&f->cam, b + 3 * i, 0, &P1[0], &P1[1], &R, &depth))
                canvas_segment(rc, col_of(f, P0[0]), row_of(f, P0[1]), col_of(f, P1[0]),
                               row_of(f, P1[1]), 0.5 * f->ww, 1, f->wall_c);
        }
    }
}

/* ---- grains, their rotation markers, force chains and arrows ---- */
static void draw_grains(render_context *rc, const dem_frame *f)
{
    const render_grains_def *def = f->def;
    const double span = f->range[1] - f->range[0];
    for (size_t k = 0; k < f->nshow; k++) {
        size_t i = f->D == 3 ? f->order[k].i : k;
        unsigned char c[3];
        if (f->mapped)
            render_colormap_rgb(def->colormap, (f->val[i] - f->range[0]) / span, c);
        else
            render_label_rgb(def->color == RENDER_COLOR_LABELS ? def->labels[i] : (long)i, c);
        if (f->chains.n || def->force_chains) /* pale grains under the chains */
            for (int ch = 0; ch < 3; ch++)
                c[ch] = (unsigned char)(c[ch] + (255 - c[ch]) * 0.6);
        double rp = f->r[i] * f->sc;
        double edge = f->D == 3 ? -1 : rp >= 3 ? fmin(1.2, 0.1 * rp) : 0;
        canvas_disk(rc, col_of(f, f->x[i]), row_of(f, f->y[i]), rp, edge,
                    rgba(c[0], c[1], c[2], 255));
    }
}

static void draw_rotation(render_context *rc, const dem_frame *f)
{
    const double *x = f->x, *y = f->y, *r = f->r;
    for (size_t i = 0; i < f->n; i++) {
        double rp = r[i] * f->sc;
        if (rp < 2.5)
            continue;
        double a = f->def->angles ? f->def->angles[i] : 0;
        double ex = x[i] + 0.92 * r[i] * cos(a), ey = y[i] + 0.92 * r[i] * sin(a);
        canvas_segment(rc, col_of(f, x[i]), row_of(f, y[i]), col_of(f, ex), row_of(f, ey),
                       fmin(3, fmax(1, 0.15 * rp)), 1, rgba(25, 25, 25, 230));
    }
}

/* Force chains: the strongest on top. */
static void draw_chains(render_context *rc, dem_frame *f)
{
    chain_list *chains = &f->chains;
    const double *x = f->x, *y = f->y, *r = f->r;
    qsort(chains->c, chains->n, sizeof *chains->c, by_force);
    double fbig = chains->c[chains->n - 1].fn;
    double wmax = fmax(1.5, 0.8 * f->mean_r);
    for (size_t k = 0; k < chains->n; k++) {
        const chain *c = &chains->c[k];
        double u = c->fn / fbig;
        /* The far end is the partner's image along the normal (from j to i), which is
         * also right across a periodic edge. */
        double d = r[c->i] + r[c->j] - c->overlap;
        unsigned char gray = (unsigned char)lround(200 * (1 - u));
        double x0 = x[c->i], y0 = y[c->i];
        double x1 = x0 - c->nx * d, y1 = y0 - c->ny * d;
        canvas_segment(rc, col_of(f, x0), row_of(f, y0), col_of(f, x1), row_of(f, y1),
                       fmax(0.3, wmax * u), 1, rgba(gray, gray, gray, 255));
    }
}

/* Arrows, with a reference arrow of a round length in the title band. */
static void draw_arrows(render_context *rc, const dem_frame *f)
{
    const render_grains_def *def = f->def;
    const size_t n = f->n;
    const double *x = f->x, *y = f->y, sc = f->sc, mean_r = f->mean_r, fs = f->fs;
    const double *ux = def->arrows[0], *uy = def->arrows[1];
    double umax = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(ux[i]) && isfinite(uy[i]))
            umax = fmax(umax, hypot(ux[i], uy[i]));
    double k = def->arrow_scale; /* scene metres per unit */
    if (k == 0)
        k = umax > 0 ? 3 * (mean_r / sc) / umax : 1;
    rgba8 ac = rgba(190, 30, 30, 255);
    double aw = fmin(3, fmax(1.2, 0.12 * mean_r));
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(ux[i]) || !isfinite(uy[i]))
            continue;
        double len = hypot(ux[i], uy[i]) * k * sc;
        if (len < 0.5)
            continue;
        double x0 = col_of(f, x[i]), y0 = row_of(f, y[i]);
        double dx = ux[i] * k * sc / len, dy = -uy[i] * k * sc / len;
        double x1 = x0 + dx * len, y1 = y0 + dy * len;
        canvas_arrow(rc, x0, y0, x1, y1, dx, dy, aw, fmin(0.35 * len, fmax(3, 0.9 * mean_r)), ac);
    }
    double right = f->W - f->m - f->band -
                   (def->stamp && *def->stamp ? canvas_text_width(rc, def->stamp, fs) + 2 * fs : 0);
    reference_arrow(rc, umax, k, sc, "m", right, f->ay0 - lround(0.45 * fs), fs, aw,
                    fmax(3, 0.9 * mean_r), ac);
}

/* ---- 2D: walls and box over the grains ---- */
static void draw_planes_2d(render_context *rc, const dem_frame *f)
{
    const double ww = f->ww;
    for (int k = 0; k < f->def->nwalls; k++) {
        const render_wall *wl = &f->def->walls[k];
        double nn = hypot(wl->normal[0], wl->normal[1]);
        if (!(nn > 0))
            continue;
        double nx = wl->normal[0] / nn, ny = wl->normal[1] / nn, t[2] = {-ny, nx}, a[2], b[2];
        if (!clip_line(wl->point, t, f->lo, f->hi, a, b))
            continue;
        /* the stroke lies outside the domain, its inner edge on the wall */
        double sx = -nx * 0.5 * ww, sy = ny * 0.5 * ww;
        canvas_segment(rc, col_of(f, a[0]) + sx, row_of(f, a[1]) + sy, col_of(f, b[0]) + sx,
                       row_of(f, b[1]) + sy, ww, 1, f->wall_c);
    }
}

/* Polylines and circles: a line along the surface, over the grains (a baffle inside a drum
 * crosses them); their contact points lie within its half width of the surface. */
static void draw_shapes_2d(render_context *rc, const dem_frame *f)
{
    const shape_lines *sh = &f->shapes;
    const double *pt = sh->pts;
    for (int k = 0; k < sh->n; pt += 3 * sh->nv[k], k++)
        for (int i = 0; i + 1 < sh->nv[k]; i++)
            canvas_segment(rc, col_of(f, pt[3 * i]), row_of(f, pt[3 * i + 1]),
                           col_of(f, pt[3 * i + 3]), row_of(f, pt[3 * i + 4]), 0.6 * f->ww, 1,
                           f->wall_c);
}

static void draw_box_2d(render_context *rc, const dem_frame *f)
{
    rgba8 bc = rgba(150, 150, 150, 255);
    double l = f->ox - 0.5, rt = f->ox + f->bw + 0.5, tp = f->oy - 0.5, bt = f->oy + f->bh + 0.5;
    canvas_segment(rc, l - 0.5, tp, rt + 0.5, tp, 1, 0, bc);
    canvas_segment(rc, l - 0.5, bt, rt + 0.5, bt, 1, 0, bc);
    canvas_segment(rc, l, tp, l, bt, 1, 0, bc);
    canvas_segment(rc, rt, tp, rt, bt, 1, 0, bc);
}

static void draw_text(render_context *rc, const dem_frame *f)
{
    const render_grains_def *def = f->def;
    rgba8 ink = rgba(20, 20, 20, 255);
    double ty = f->ay0 - lround(0.45 * f->fs);
    if (def->title && *def->title)
        canvas_text(rc, def->title, f->fs, f->m, ty, 0, 1, 0, ink);
    if (def->stamp && *def->stamp)
        canvas_text(rc, def->stamp, f->fs, f->W - f->m - f->band, ty, 1, 1, 0, ink);
}

core_status render_dem(render_context *rc, dem_scene *s, const render_grains_def *def,
                       render_image *out, render_view *view, core_error *err)
{
    out->rgba = NULL;
    out->width = out->height = 0;
    core_status st = check_def(s, def, err);
    if (st != CORE_OK)
        return st;
    dem_frame f;
    frame_start(&f, s, def);
    if ((st = grain_values(&f, s, err)) != CORE_OK ||
        (st = scene_geometry(&f, s, err)) != CORE_OK ||
        (st = frame_layout(rc, &f, err)) != CORE_OK) {
        frame_free(&f);
        return st;
    }
    frame_view(&f, view);
    if ((st = collect_overlays(&f, s, err)) != CORE_OK ||
        (st = canvas_begin(rc, f.W, f.H, err)) != CORE_OK) {
        frame_free(&f);
        return st;
    }
    if (f.D == 3 && def->box)
        draw_box_3d(rc, &f);
    if (f.D == 3 && def->nwalls)
        draw_planes_3d(rc, &f);
    if (f.D == 3 && f.shapes.n)
        draw_shapes_3d(rc, &f);
    draw_grains(rc, &f);
    if (def->rotation)
        draw_rotation(rc, &f);
    if (f.chains.n)
        draw_chains(rc, &f);
    if (def->arrows[0] && f.n)
        draw_arrows(rc, &f);
    if (f.D == 2) {
        draw_planes_2d(rc, &f);
        draw_shapes_2d(rc, &f);
        if (def->box)
            draw_box_2d(rc, &f);
    }
    draw_text(rc, &f);
    if (f.show_bar)
        colorbar_draw(rc, &f.bar, def->colormap, f.ox + f.bw, f.oy, f.oy + f.bh);
    frame_free(&f);
    return canvas_end(rc, out, err);
}
