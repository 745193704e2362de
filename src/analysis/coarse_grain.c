/* Coarse-graining kernels (coarse_grain.h): the Gaussian and Lucy functions, their exact line
 * integrals along branch vectors, the sums at evaluation points over a bin list of the items that
 * reach them, the derived fields and their invariants, and the .vti and CSV writers. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/coarse_grain.h"
#include "core/fileio.h"
#include "core/vtk.h"

#define CG_PI 3.14159265358979323846

analysis_cg_def analysis_cg_default_def(void)
{
    analysis_cg_def d;
    memset(&d, 0, sizeof d);
    d.dim = 2;
    d.kernel = ANALYSIS_CG_GAUSS;
    d.width = 1;
    d.cutoff = 0;
    d.depth = 1;
    return d;
}

double analysis_cg_reach(const analysis_cg_def *def)
{
    if (def->kernel == ANALYSIS_CG_LUCY)
        return def->width;
    return def->cutoff > 0 ? def->cutoff : 3 * def->width;
}

/* The kernel's constants: P normalises phi over its support (the disk or ball of radius c). */
typedef struct kernel {
    int lucy;
    double w, c, c2, P;
    double inv2w2;     /* Gauss: 1 / (2 w^2) */
    double gline;      /* Gauss: P sqrt(pi / 2) w, the line integral's factor */
    double isq2w;      /* Gauss: 1 / (sqrt 2 w) */
    double k2, k3, k4; /* Lucy: 6 / c^2, 8 / c^3, 3 / c^4 */
} kernel;

static void kernel_init(const analysis_cg_def *def, kernel *k)
{
    memset(k, 0, sizeof *k);
    k->lucy = def->kernel == ANALYSIS_CG_LUCY;
    k->w = def->width;
    k->c = analysis_cg_reach(def);
    k->c2 = k->c * k->c;
    if (k->lucy) {
        /* 2D: int_0^1 (1 - 6x^2 + 8x^3 - 3x^4) 2 pi x dx = pi / 5; 3D: 4 pi (1/3 - 6/5 + 4/3 - 3/7)
         * = 16 pi / 105 */
        k->P = def->dim == 2 ? 5 / (CG_PI * k->c2) : 105 / (16 * CG_PI * k->c2 * k->c);
        k->k2 = 6 / k->c2;
        k->k3 = 8 / (k->c2 * k->c);
        k->k4 = 3 / (k->c2 * k->c2);
    } else {
        const double w = k->w, X = k->c / w, e = exp(-0.5 * X * X);
        /* 2D: int over the disk of radius c = 2 pi w^2 (1 - e^{-X^2/2}); 3D: (2 pi)^{3/2} w^3
         * (erf(X / sqrt 2) - sqrt(2 / pi) X e^{-X^2/2}), X = c / w */
        if (def->dim == 2)
            k->P = 1 / (2 * CG_PI * w * w * (1 - e));
        else
            k->P = 1 / (pow(2 * CG_PI, 1.5) * w * w * w *
                        (erf(X / sqrt(2.0)) - sqrt(2 / CG_PI) * X * e));
        k->inv2w2 = 1 / (2 * w * w);
        k->gline = k->P * sqrt(CG_PI / 2) * w;
        k->isq2w = 1 / (sqrt(2.0) * w);
    }
}

/* phi at squared distance r2 (< c^2 checked by the caller). */
static inline double phi_r2(const kernel *k, double r2)
{
    if (k->lucy) {
        const double x2 = r2 / k->c2, x = sqrt(x2);
        return k->P * (1 + x2 * (-6 + x * (8 - 3 * x)));
    }
    return k->P * exp(-r2 * k->inv2w2);
}

/* erf(hi) - erf(lo), hi > lo, from erfc where both are on one side (no cancellation near 1). */
static inline double erf_diff(double lo, double hi)
{
    if (lo >= 0)
        return erfc(lo) - erfc(hi);
    if (hi <= 0)
        return erfc(-hi) - erfc(-lo);
    return erf(hi) - erf(lo);
}

/* Lucy's antiderivative along the line, in q, at squared distance t2 from it (t = sqrt t2):
 * int (1 - 6 rho^2/c^2 + 8 rho^3/c^3 - 3 rho^4/c^4) dq with rho^2 = t^2 + q^2, using
 * int (t^2 + q^2)^{3/2} dq = q (2 q^2 + 5 t^2) rho / 8 + 3/8 t^4 asinh(q / t). */
static inline double lucy_G(const kernel *k, double q, double t2, double t)
{
    const double q2 = q * q, rho = sqrt(q2 + t2);
    double h = q * (2 * q2 + 5 * t2) * rho / 8;
    if (t > 0)
        h += 0.375 * t2 * t2 * asinh(q / t);
    return q - k->k2 * (t2 * q + q2 * q / 3) + k->k3 * h -
           k->k4 * (t2 * t2 * q + (2.0 / 3.0) * t2 * q2 * q + q2 * q2 * q / 5);
}

/* psi = (1/L) int_{a0 - L}^{a0} phi(sqrt(t2 + q^2)) dq, the cut clipping q to |q| < sqrt(c^2 -
 * t2): the segment from the particle (q = a0) to its other end (q = a0 - L), a point at squared
 * distance t2 from its line. */
static inline double psi_line(const kernel *k, double a0, double t2, double L)
{
    if (t2 >= k->c2)
        return 0;
    const double h = sqrt(k->c2 - t2);
    const double lo = fmax(a0 - L, -h), hi = fmin(a0, h);
    if (!(hi > lo))
        return 0;
    if (k->lucy)
        return k->P * (lucy_G(k, hi, t2, sqrt(t2)) - lucy_G(k, lo, t2, sqrt(t2))) / L;
    return k->gline * exp(-t2 * k->inv2w2) * erf_diff(lo * k->isq2w, hi * k->isq2w) / L;
}

/* Below this length (relative to the reach) a branch is a point: psi is phi at x_i. */
#define CG_SHORT 1e-9

double analysis_cg_phi(const analysis_cg_def *def, double r)
{
    kernel k;
    kernel_init(def, &k);
    return r * r < k.c2 ? phi_r2(&k, r * r) : 0;
}

double analysis_cg_psi(const analysis_cg_def *def, const double *d, const double *b)
{
    kernel k;
    kernel_init(def, &k);
    const int D = def->dim;
    double L2 = 0, d2 = 0, a0 = 0;
    for (int a = 0; a < D; a++) {
        L2 += b[a] * b[a];
        d2 += d[a] * d[a];
    }
    const double L = sqrt(L2);
    if (!(L > CG_SHORT * k.c))
        return d2 < k.c2 ? phi_r2(&k, d2) : 0;
    for (int a = 0; a < D; a++)
        a0 -= d[a] * b[a] / L;
    return psi_line(&k, a0, fmax(0, d2 - a0 * a0), L);
}

/* ---- layout ------------------------------------------------------------------------------------
 */
void analysis_cg_layout_of(int dim, const analysis_cg_particles *p, const analysis_cg_contacts *c,
                           analysis_cg_layout *out)
{
    const int D = dim, T = dim * dim;
    int has[ANALYSIS_CG_NCHANNELS] = {0}, ncomp[ANALYSIS_CG_NCHANNELS] = {0};
    const int contacts = c != NULL;
    has[ANALYSIS_CG_DENSITY] = has[ANALYSIS_CG_MOMENTUM] = has[ANALYSIS_CG_FLUX] = 1;
    has[ANALYSIS_CG_CONTACT] = contacts;
    has[ANALYSIS_CG_TRACTION] = contacts && c->wall != NULL;
    has[ANALYSIS_CG_VOLUME] = p->volume != NULL;
    has[ANALYSIS_CG_FABRIC] = p->fabric != NULL && p->volume != NULL;
    has[ANALYSIS_CG_DISP] = p->disp[0] != NULL;
    has[ANALYSIS_CG_STRESS] = p->stress != NULL;
    ncomp[ANALYSIS_CG_DENSITY] = ncomp[ANALYSIS_CG_VOLUME] = 1;
    ncomp[ANALYSIS_CG_MOMENTUM] = ncomp[ANALYSIS_CG_TRACTION] = ncomp[ANALYSIS_CG_DISP] = D;
    ncomp[ANALYSIS_CG_FLUX] = ncomp[ANALYSIS_CG_CONTACT] = ncomp[ANALYSIS_CG_FABRIC] =
        ncomp[ANALYSIS_CG_STRESS] = T;
    out->dim = dim;
    int at = 0;
    for (int q = 0; q < ANALYSIS_CG_NCHANNELS; q++) {
        out->offset[q] = has[q] ? at : -1;
        out->ncomp[q] = has[q] ? ncomp[q] : 0;
        at += out->ncomp[q];
    }
    out->stride = at;
}

/* ---- the bin list ------------------------------------------------------------------------------
 * Items are the particles (0 .. n-1) and the contacts (n ..). Each item, with every periodic
 * image whose support reaches the evaluation points' box, is entered in each bin its support
 * overlaps, in item order; a point sums the entries of its bin in that order. */
typedef struct entry {
    uint32_t item;
    int16_t k[3]; /* the image: shift k[a] periods along axis a */
} entry;

typedef struct bins {
    int nb[3];
    double lo[3], size[3];
    size_t *start; /* nbins + 1 */
    entry *e;
} bins;

static int bin_of(const bins *b, int a, double x)
{
    double f = floor((x - b->lo[a]) / b->size[a]);
    if (!(f >= 0))
        return 0;
    if (f >= b->nb[a] - 1)
        return b->nb[a] - 1;
    return (int)f;
}

/* The support box of item q (without image shift). */
static void item_box(int D, const analysis_cg_particles *p, const analysis_cg_contacts *c, size_t q,
                     double reach, double lo[3], double hi[3])
{
    if (q < p->n) {
        for (int a = 0; a < D; a++) {
            lo[a] = p->x[a][q] - reach;
            hi[a] = p->x[a][q] + reach;
        }
        return;
    }
    const size_t k = q - p->n;
    const size_t i = (size_t)c->i[k];
    for (int a = 0; a < D; a++) {
        const double x0 = p->x[a][i], x1 = x0 - c->b[a][k];
        lo[a] = fmin(x0, x1) - reach;
        hi[a] = fmax(x0, x1) + reach;
    }
}

/* Calls (or counts, when fill is 0) the entries of item q: every image and every bin. */
static size_t item_entries(const bins *b, int D, const double period[3], const bool *periodic,
                           const double qlo[3], const double qhi[3], const double lo[3],
                           const double hi[3], uint32_t q, size_t *cursor, entry *out)
{
    int k0[3] = {0, 0, 0}, k1[3] = {0, 0, 0};
    for (int a = 0; a < D; a++) {
        if (periodic[a]) {
            k0[a] = (int)ceil((qlo[a] - hi[a]) / period[a]);
            k1[a] = (int)floor((qhi[a] - lo[a]) / period[a]);
        } else if (hi[a] < qlo[a] || lo[a] > qhi[a]) {
            return 0;
        }
        if (k1[a] < k0[a])
            return 0;
    }
    size_t count = 0;
    int k[3];
    for (k[2] = k0[2]; k[2] <= k1[2]; k[2]++)
        for (k[1] = k0[1]; k[1] <= k1[1]; k[1]++)
            for (k[0] = k0[0]; k[0] <= k1[0]; k[0]++) {
                int b0[3] = {0, 0, 0}, b1[3] = {0, 0, 0};
                for (int a = 0; a < D; a++) {
                    const double s = periodic[a] ? k[a] * period[a] : 0;
                    b0[a] = bin_of(b, a, lo[a] + s);
                    b1[a] = bin_of(b, a, hi[a] + s);
                }
                for (int z = b0[2]; z <= b1[2]; z++)
                    for (int y = b0[1]; y <= b1[1]; y++)
                        for (int x = b0[0]; x <= b1[0]; x++) {
                            const size_t bin =
                                ((size_t)z * (size_t)b->nb[1] + (size_t)y) * (size_t)b->nb[0] +
                                (size_t)x;
                            if (out) {
                                entry *e = &out[cursor[bin]++];
                                e->item = q;
                                for (int a = 0; a < 3; a++)
                                    e->k[a] = (int16_t)k[a];
                            } else {
                                cursor[bin]++;
                            }
                            count++;
                        }
            }
    return count;
}

static void bins_free(bins *b)
{
    free(b->start);
    free(b->e);
}

static core_status bins_build(bins *b, int D, const analysis_cg_def *def,
                              const analysis_cg_particles *p, const analysis_cg_contacts *c,
                              double reach, size_t npts, const double *const pts[3],
                              core_error *err)
{
    memset(b, 0, sizeof *b);
    double qlo[3] = {0, 0, 0}, qhi[3] = {0, 0, 0}, period[3] = {1, 1, 1};
    for (int a = 0; a < D; a++) {
        qlo[a] = INFINITY;
        qhi[a] = -INFINITY;
        for (size_t k = 0; k < npts; k++) {
            qlo[a] = fmin(qlo[a], pts[a][k]);
            qhi[a] = fmax(qhi[a], pts[a][k]);
        }
        period[a] = def->hi[a] - def->lo[a];
    }
    const int cap = D == 2 ? 512 : 64; /* bins per axis */
    for (int a = 0; a < 3; a++) {
        b->nb[a] = 1;
        b->lo[a] = qlo[a];
        b->size[a] = 1;
        if (a >= D)
            continue;
        const double ext = qhi[a] - qlo[a];
        b->size[a] = fmax(reach, ext / cap);
        b->nb[a] = (int)fmin(cap, fmax(1, ceil(ext / b->size[a])));
    }
    const size_t nbins = (size_t)b->nb[0] * (size_t)b->nb[1] * (size_t)b->nb[2];
    const size_t nitems = p->n + (c ? c->n : 0);
    b->start = calloc(nbins + 1, sizeof *b->start);
    size_t *cursor = calloc(nbins + 1, sizeof *cursor);
    if (!b->start || !cursor) {
        free(cursor);
        bins_free(b);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu bins", nbins);
    }
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    size_t total = 0;
    for (size_t q = 0; q < nitems; q++) {
        item_box(D, p, c, q, reach, lo, hi);
        total +=
            item_entries(b, D, period, def->periodic, qlo, qhi, lo, hi, (uint32_t)q, cursor, NULL);
    }
    for (size_t k = 0; k < nbins; k++)
        b->start[k + 1] = b->start[k] + cursor[k];
    b->e = malloc((total ? total : 1) * sizeof *b->e);
    if (!b->e) {
        free(cursor);
        bins_free(b);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu kernel entries", total);
    }
    memcpy(cursor, b->start, nbins * sizeof *cursor);
    for (size_t q = 0; q < nitems; q++) {
        item_box(D, p, c, q, reach, lo, hi);
        item_entries(b, D, period, def->periodic, qlo, qhi, lo, hi, (uint32_t)q, cursor, b->e);
    }
    free(cursor);
    return CORE_OK;
}

/* ---- the sums
 * ------------------------------------------------------------------------------------ */
typedef struct ctx {
    kernel k;
    const analysis_cg_particles *p;
    const analysis_cg_contacts *c;
    const analysis_cg_layout *l;
    const bins *b;
    double period[3];
    double *cl; /* per contact: L, then the unit vector e from x_i towards the other end */
    double scale[ANALYSIS_CG_NCHANNELS]; /* 1 / depth for the per-area channels in 2D */
} ctx;

/* The sums at point r (D a constant after inlining). */
static inline __attribute__((always_inline)) void eval_point(const ctx *x, int D, const double *r,
                                                             double *out)
{
    const analysis_cg_particles *p = x->p;
    const analysis_cg_contacts *c = x->c;
    const analysis_cg_layout *l = x->l;
    const kernel *k = &x->k;
    const int T = D * D;
    const int oR = l->offset[ANALYSIS_CG_DENSITY], oP = l->offset[ANALYSIS_CG_MOMENTUM],
              oM = l->offset[ANALYSIS_CG_FLUX], oC = l->offset[ANALYSIS_CG_CONTACT],
              oT = l->offset[ANALYSIS_CG_TRACTION], oV = l->offset[ANALYSIS_CG_VOLUME],
              oF = l->offset[ANALYSIS_CG_FABRIC], oU = l->offset[ANALYSIS_CG_DISP],
              oS = l->offset[ANALYSIS_CG_STRESS];
    double acc[64];
    for (int q = 0; q < l->stride; q++)
        acc[q] = 0;
    const bins *b = x->b;
    size_t bin = 0;
    for (int a = D - 1; a >= 0; a--)
        bin = bin * (size_t)b->nb[a] + (size_t)bin_of(b, a, r[a]);
    for (size_t e = b->start[bin]; e < b->start[bin + 1]; e++) {
        const entry *en = &b->e[e];
        double sh[3];
        for (int a = 0; a < D; a++)
            sh[a] = en->k[a] ? en->k[a] * x->period[a] : 0;
        if (en->item < p->n) {
            const size_t i = en->item;
            double d[3], r2 = 0;
            for (int a = 0; a < D; a++) {
                d[a] = r[a] - (p->x[a][i] + sh[a]);
                r2 += d[a] * d[a];
            }
            if (!(r2 < k->c2))
                continue;
            const double ph = phi_r2(k, r2), mp = p->mass[i] * ph;
            double v[3] = {0, 0, 0};
            for (int a = 0; a < D; a++)
                v[a] = p->v[0] ? p->v[a][i] : 0;
            acc[oR] += mp;
            for (int a = 0; a < D; a++) {
                acc[oP + a] += mp * v[a];
                for (int bb = 0; bb < D; bb++)
                    acc[oM + a * D + bb] += mp * v[a] * v[bb];
            }
            if (oV >= 0) {
                const double vp = p->volume[i] * ph;
                acc[oV] += vp;
                if (oF >= 0)
                    for (int q = 0; q < T; q++)
                        acc[oF + q] += vp * p->fabric[(size_t)T * i + (size_t)q];
            }
            if (oU >= 0)
                for (int a = 0; a < D; a++)
                    acc[oU + a] += mp * p->disp[a][i];
            if (oS >= 0)
                for (int q = 0; q < T; q++)
                    acc[oS + q] += ph * p->stress[(size_t)T * i + (size_t)q];
            continue;
        }
        const size_t q = en->item - p->n, i = (size_t)c->i[q];
        const double *cl = x->cl + 4 * q, L = cl[0];
        double d[3], d2 = 0, a0 = 0;
        for (int a = 0; a < D; a++) {
            d[a] = r[a] - (p->x[a][i] + sh[a]);
            d2 += d[a] * d[a];
            a0 += d[a] * cl[1 + a];
        }
        double ps;
        if (L > 0)
            ps = psi_line(k, a0, fmax(0, d2 - a0 * a0), L);
        else
            ps = d2 < k->c2 ? phi_r2(k, d2) : 0;
        if (ps != 0)
            for (int a = 0; a < D; a++)
                for (int bb = 0; bb < D; bb++)
                    acc[oC + a * D + bb] += c->b[a][q] * c->f[bb][q] * ps;
        if (oT >= 0 && c->wall[q]) { /* the wall's force at the contact point x_i - b */
            double r2 = 0;
            for (int a = 0; a < D; a++) {
                const double dc = d[a] + c->b[a][q];
                r2 += dc * dc;
            }
            if (r2 < k->c2) {
                const double ph = phi_r2(k, r2);
                for (int a = 0; a < D; a++)
                    acc[oT + a] += c->f[a][q] * ph;
            }
        }
    }
    for (int ch = 0; ch < ANALYSIS_CG_NCHANNELS; ch++)
        for (int q = 0; q < l->ncomp[ch]; q++)
            out[l->offset[ch] + q] = acc[l->offset[ch] + q] * x->scale[ch];
}

static void eval_2(const ctx *x, const double *r, double *out) { eval_point(x, 2, r, out); }
static void eval_3(const ctx *x, const double *r, double *out) { eval_point(x, 3, r, out); }

static int finite_all(const double *a, size_t n, size_t *bad)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(a[k])) {
            *bad = k;
            return 0;
        }
    return 1;
}

static core_status check_def(const analysis_cg_def *def, core_error *err)
{
    if (def->dim != 2 && def->dim != 3)
        return core_fail(err, CORE_ERR_ARG, "dimension %d (2 or 3 expected)", def->dim);
    if (!(def->width > 0) || !isfinite(def->width))
        return core_fail(err, CORE_ERR_ARG, "width %g (positive expected)", def->width);
    if (def->kernel == ANALYSIS_CG_GAUSS && def->cutoff != 0 &&
        !(def->cutoff > 0 && def->cutoff <= 10 * def->width))
        return core_fail(err, CORE_ERR_ARG, "cutoff %g (in (0, 10 w] = (0, %g] expected)",
                         def->cutoff, 10 * def->width);
    if (def->dim == 2 && !(def->depth > 0 && isfinite(def->depth)))
        return core_fail(err, CORE_ERR_ARG, "depth %g (positive expected)", def->depth);
    const double reach = analysis_cg_reach(def);
    static const char axis[3] = {'x', 'y', 'z'};
    for (int a = 0; a < def->dim; a++)
        if (def->periodic[a] && !(def->hi[a] - def->lo[a] >= reach))
            return core_fail(err, CORE_ERR_ARG,
                             "the periodic %c axis is %g long, shorter than the kernel's reach %g",
                             axis[a], def->hi[a] - def->lo[a], reach);
    return CORE_OK;
}

core_status analysis_cg_sums(const analysis_cg_def *def, const analysis_cg_particles *p,
                             const analysis_cg_contacts *c, const analysis_cg_layout *layout,
                             size_t npts, const double *const pts[3], double *out, core_error *err)
{
    core_status st = check_def(def, err);
    if (st)
        return st;
    const int D = def->dim, T = D * D;
    if (layout->dim != D || layout->stride > 64)
        return core_fail(err, CORE_ERR_ARG, "layout of dimension %d for a %dD definition",
                         layout->dim, D);
    static const char axis[3] = {'x', 'y', 'z'};
    size_t bad;
    const size_t nc = c ? c->n : 0;
    if (p->n + nc >= UINT32_MAX)
        return core_fail(err, CORE_ERR_ARG, "%zu particles and %zu contacts: too many", p->n, nc);
    for (int a = 0; a < D; a++) {
        if (!finite_all(p->x[a], p->n, &bad))
            return core_fail(err, CORE_ERR_ARG, "particle %zu: position %c is not finite", bad + 1,
                             axis[a]);
        if (p->v[0] && !finite_all(p->v[a], p->n, &bad))
            return core_fail(err, CORE_ERR_ARG, "particle %zu: velocity %c is not finite", bad + 1,
                             axis[a]);
        if (p->disp[0] && !finite_all(p->disp[a], p->n, &bad))
            return core_fail(err, CORE_ERR_ARG, "particle %zu: displacement %c is not finite",
                             bad + 1, axis[a]);
        if (!finite_all(pts[a], npts, &bad))
            return core_fail(err, CORE_ERR_ARG, "point %zu: coordinate %c is not finite", bad + 1,
                             axis[a]);
    }
    if (!finite_all(p->mass, p->n, &bad))
        return core_fail(err, CORE_ERR_ARG, "particle %zu: mass is not finite", bad + 1);
    if (p->volume && !finite_all(p->volume, p->n, &bad))
        return core_fail(err, CORE_ERR_ARG, "particle %zu: volume is not finite", bad + 1);
    if (p->fabric && !finite_all(p->fabric, (size_t)T * p->n, &bad))
        return core_fail(err, CORE_ERR_ARG, "particle %zu: fabric is not finite", bad / T + 1);
    if (p->stress && !finite_all(p->stress, (size_t)T * p->n, &bad))
        return core_fail(err, CORE_ERR_ARG, "particle %zu: stress is not finite", bad / T + 1);
    for (size_t q = 0; q < nc; q++)
        if (c->i[q] < 0 || (size_t)c->i[q] >= p->n)
            return core_fail(err, CORE_ERR_ARG, "contact %zu names particle %ld of %zu", q + 1,
                             c->i[q] + 1, p->n);
    for (int a = 0; a < D && nc; a++) {
        if (!finite_all(c->b[a], nc, &bad))
            return core_fail(err, CORE_ERR_ARG, "contact %zu: branch %c is not finite", bad + 1,
                             axis[a]);
        if (!finite_all(c->f[a], nc, &bad))
            return core_fail(err, CORE_ERR_ARG, "contact %zu: force %c is not finite", bad + 1,
                             axis[a]);
    }
    if (npts == 0)
        return CORE_OK;

    ctx x;
    memset(&x, 0, sizeof x);
    kernel_init(def, &x.k);
    x.p = p;
    x.c = c;
    x.l = layout;
    for (int a = 0; a < 3; a++)
        x.period[a] = a < D ? def->hi[a] - def->lo[a] : 0;
    for (int ch = 0; ch < ANALYSIS_CG_NCHANNELS; ch++)
        x.scale[ch] = 1;
    if (D == 2) { /* the per-area sums become per volume */
        static const int per_area[] = {ANALYSIS_CG_DENSITY, ANALYSIS_CG_MOMENTUM, ANALYSIS_CG_FLUX,
                                       ANALYSIS_CG_CONTACT, ANALYSIS_CG_TRACTION, ANALYSIS_CG_DISP,
                                       ANALYSIS_CG_STRESS};
        for (size_t q = 0; q < sizeof per_area / sizeof *per_area; q++)
            x.scale[per_area[q]] = 1 / def->depth;
    }
    if (nc) {
        x.cl = malloc(4 * nc * sizeof *x.cl);
        if (!x.cl)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contacts", nc);
        for (size_t q = 0; q < nc; q++) {
            double L2 = 0;
            for (int a = 0; a < D; a++)
                L2 += c->b[a][q] * c->b[a][q];
            const double L = sqrt(L2);
            double *cl = x.cl + 4 * q;
            cl[0] = L > CG_SHORT * x.k.c ? L : 0; /* 0: a point at x_i */
            for (int a = 0; a < 3; a++)
                cl[1 + a] = a < D && cl[0] > 0 ? -c->b[a][q] / L : 0;
        }
    }
    bins b;
    st = bins_build(&b, D, def, p, c, x.k.c, npts, pts, err);
    if (st) {
        free(x.cl);
        return st;
    }
    x.b = &b;
    const long np = (long)npts;
    const int stride = layout->stride;
#pragma omp parallel for schedule(dynamic, 16)
    for (long k = 0; k < np; k++) {
        double r[3] = {pts[0][k], pts[1][k], D == 3 ? pts[2][k] : 0};
        if (D == 2)
            eval_2(&x, r, out + (size_t)k * (size_t)stride);
        else
            eval_3(&x, r, out + (size_t)k * (size_t)stride);
    }
    bins_free(&b);
    free(x.cl);
    return CORE_OK;
}

/* ---- grids
 * --------------------------------------------------------------------------------------- */
size_t analysis_cg_grid_count(int dim, const int cells[3])
{
    size_t n = 1;
    for (int a = 0; a < dim; a++)
        n *= (size_t)cells[a];
    return n;
}

void analysis_cg_grid_points(int dim, const int cells[3], const double lo[3], const double hi[3],
                             double *const pts[3])
{
    const int nz = dim == 3 ? cells[2] : 1;
    size_t k = 0;
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < cells[1]; y++)
            for (int x = 0; x < cells[0]; x++, k++) {
                const int idx[3] = {x, y, z};
                for (int a = 0; a < dim; a++)
                    pts[a][k] = lo[a] + (idx[a] + 0.5) * ((hi[a] - lo[a]) / cells[a]);
            }
}

/* ---- derived fields ---------------------------------------------------------------------------
 */
core_status analysis_cg_fields_alloc(const analysis_cg_layout *l, size_t n, analysis_cg_fields *f,
                                     core_error *err)
{
    memset(f, 0, sizeof *f);
    const int D = l->dim;
    const size_t T = (size_t)D * (size_t)D, m = n ? n : 1;
    f->n = n;
    f->dim = D;
    int ok = 1;
#define CG_ALLOC(p, count)                                                                         \
    do {                                                                                           \
        (p) = malloc((count) * sizeof(double));                                                    \
        ok = ok && (p) != NULL;                                                                    \
    } while (0)
    CG_ALLOC(f->density, m);
    for (int a = 0; a < D; a++)
        CG_ALLOC(f->velocity[a], m);
    CG_ALLOC(f->kinetic, T * m);
    CG_ALLOC(f->stress, T * m);
    CG_ALLOC(f->temperature, m);
    if (l->offset[ANALYSIS_CG_CONTACT] >= 0)
        CG_ALLOC(f->contact, T * m);
    if (l->offset[ANALYSIS_CG_STRESS] >= 0)
        CG_ALLOC(f->internal, T * m);
    if (l->offset[ANALYSIS_CG_TRACTION] >= 0)
        CG_ALLOC(f->traction, (size_t)D * m);
    if (l->offset[ANALYSIS_CG_VOLUME] >= 0)
        CG_ALLOC(f->volume_fraction, m);
    if (l->offset[ANALYSIS_CG_FABRIC] >= 0)
        CG_ALLOC(f->fabric, T * m);
    if (l->offset[ANALYSIS_CG_DISP] >= 0)
        CG_ALLOC(f->displacement, (size_t)D * m);
#undef CG_ALLOC
    if (!ok) {
        analysis_cg_fields_free(f);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the fields of %zu points", n);
    }
    return CORE_OK;
}

void analysis_cg_fields_free(analysis_cg_fields *f)
{
    free(f->density);
    for (int a = 0; a < 3; a++)
        free(f->velocity[a]);
    free(f->kinetic);
    free(f->contact);
    free(f->internal);
    free(f->stress);
    free(f->temperature);
    free(f->traction);
    free(f->volume_fraction);
    free(f->fabric);
    free(f->displacement);
    memset(f, 0, sizeof *f);
}

void analysis_cg_derive(const analysis_cg_layout *l, size_t n, const double *sums,
                        analysis_cg_fields *f)
{
    const int D = l->dim, T = D * D, S = l->stride;
    const int oR = l->offset[ANALYSIS_CG_DENSITY], oP = l->offset[ANALYSIS_CG_MOMENTUM],
              oM = l->offset[ANALYSIS_CG_FLUX], oC = l->offset[ANALYSIS_CG_CONTACT],
              oT = l->offset[ANALYSIS_CG_TRACTION], oV = l->offset[ANALYSIS_CG_VOLUME],
              oF = l->offset[ANALYSIS_CG_FABRIC], oU = l->offset[ANALYSIS_CG_DISP],
              oS = l->offset[ANALYSIS_CG_STRESS];
    for (size_t k = 0; k < n; k++) {
        const double *s = sums + k * (size_t)S;
        const double rho = s[oR];
        const int has = rho > 0;
        double V[3] = {0, 0, 0};
        f->density[k] = rho;
        for (int a = 0; a < D; a++) {
            V[a] = has ? s[oP + a] / rho : NAN;
            f->velocity[a][k] = V[a];
        }
        double *kin = f->kinetic + (size_t)T * k, *tot = f->stress + (size_t)T * k, tr = 0;
        for (int a = 0; a < D; a++)
            for (int b = 0; b < D; b++) {
                /* Goldhirsch: sum m v'v' phi with v' = v - V(r) is M - rho V V */
                const double kv = has ? s[oM + a * D + b] - s[oP + a] * V[b] : NAN;
                kin[a * D + b] = kv;
                double t = has ? kv : 0;
                if (oC >= 0)
                    t += s[oC + a * D + b];
                if (oS >= 0)
                    t += s[oS + a * D + b];
                tot[a * D + b] = t;
            }
        for (int a = 0; a < D; a++)
            tr += kin[a * D + a];
        f->temperature[k] = has ? tr / (D * rho) : NAN;
        if (oC >= 0)
            memcpy(f->contact + (size_t)T * k, s + oC, (size_t)T * sizeof(double));
        if (oS >= 0)
            memcpy(f->internal + (size_t)T * k, s + oS, (size_t)T * sizeof(double));
        if (oT >= 0)
            memcpy(f->traction + (size_t)D * k, s + oT, (size_t)D * sizeof(double));
        if (oV >= 0)
            f->volume_fraction[k] = s[oV];
        if (oF >= 0)
            for (int q = 0; q < T; q++)
                f->fabric[(size_t)T * k + (size_t)q] = s[oV] > 0 ? s[oF + q] / s[oV] : NAN;
        if (oU >= 0)
            for (int a = 0; a < D; a++)
                f->displacement[(size_t)D * k + (size_t)a] = has ? s[oU + a] / rho : NAN;
    }
}

/* Eigenvalues and vectors of a symmetric 3 x 3 matrix by cyclic Jacobi rotations (a fixed
 * procedure: the same bits on every call). v[.][j] is the vector of w[j]. */
static void jacobi3(double A[3][3], double w[3], double v[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            v[i][j] = i == j;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(A[0][1]) + fabs(A[0][2]) + fabs(A[1][2]);
        double scale = fabs(A[0][0]) + fabs(A[1][1]) + fabs(A[2][2]) + off;
        if (off == 0 || off <= 1e-300 || off < 1e-17 * scale)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (A[p][q] == 0)
                    continue;
                const double theta = (A[q][q] - A[p][p]) / (2 * A[p][q]);
                const double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                const double cs = 1 / sqrt(t * t + 1), sn = t * cs;
                for (int k = 0; k < 3; k++) { /* A = J^T A J */
                    const double akp = A[k][p], akq = A[k][q];
                    A[k][p] = cs * akp - sn * akq;
                    A[k][q] = sn * akp + cs * akq;
                }
                for (int k = 0; k < 3; k++) {
                    const double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = cs * apk - sn * aqk;
                    A[q][k] = sn * apk + cs * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = cs * vkp - sn * vkq;
                    v[k][q] = sn * vkp + cs * vkq;
                }
            }
    }
    for (int i = 0; i < 3; i++)
        w[i] = A[i][i];
}

void analysis_cg_invariants_of(int dim, const double *t, analysis_cg_invariants *out)
{
    memset(out, 0, sizeof *out);
    for (int a = 0; a < dim; a++)
        if (!isfinite(t[a * dim + a])) {
            out->pressure = out->psd = out->angle = NAN;
            for (int q = 0; q < 3; q++)
                out->principal[q] = out->direction[q] = NAN;
            return;
        }
    if (dim == 2) {
        const double sxx = t[0], syy = t[3], sxy = 0.5 * (t[1] + t[2]);
        const double m = 0.5 * (sxx + syy), rad = hypot(0.5 * (sxx - syy), sxy);
        out->pressure = m;
        out->principal[0] = m + rad;
        out->principal[1] = m - rad;
        out->psd = 2 * rad;
        double th = 0.5 * atan2(2 * sxy, sxx - syy); /* in [-pi/2, pi/2] */
        if (th <= -0.5 * CG_PI)
            th += CG_PI;
        out->angle = th;
        out->direction[0] = cos(th);
        out->direction[1] = sin(th);
        return;
    }
    double A[3][3], w[3], v[3][3];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            A[a][b] = 0.5 * (t[a * 3 + b] + t[b * 3 + a]);
    out->pressure = (A[0][0] + A[1][1] + A[2][2]) / 3;
    jacobi3(A, w, v);
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++) /* descending, ties in index order */
        for (int j = i + 1; j < 3; j++)
            if (w[order[j]] > w[order[i]]) {
                int s = order[i];
                order[i] = order[j];
                order[j] = s;
            }
    for (int i = 0; i < 3; i++)
        out->principal[i] = w[order[i]];
    out->psd = out->principal[0] - out->principal[2];
    int big = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(v[a][order[0]]) > fabs(v[big][order[0]]))
            big = a;
    const double sgn = v[big][order[0]] < 0 ? -1 : 1;
    for (int a = 0; a < 3; a++)
        out->direction[a] = sgn * v[a][order[0]];
    out->angle = atan2(out->direction[1], out->direction[0]);
}

/* ---- output -----------------------------------------------------------------------------------
 */
/* ParaView's layout of a column: scalars as they are, vectors with 3 components, tensors 3 x 3. */
static int vtk_ncomp(int dim, int ncomp) { return ncomp == 1 ? 1 : ncomp == dim ? 3 : 9; }

static void vtk_fill(int dim, int ncomp, const double *src, double *dst)
{
    if (ncomp == 1) {
        dst[0] = src[0];
    } else if (ncomp == dim) {
        for (int a = 0; a < 3; a++)
            dst[a] = a < dim ? src[a] : 0;
    } else {
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                dst[3 * a + b] = a < dim && b < dim ? src[a * dim + b] : 0;
    }
}

core_status analysis_cg_write_vti(const char *path, int dim, const int cells[3], const double lo[3],
                                  const double hi[3], size_t ncol, const analysis_cg_column *cols,
                                  double time, core_error *err)
{
    int n[3] = {1, 1, 1};
    double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    for (int a = 0; a < dim; a++) {
        n[a] = cells[a];
        spacing[a] = (hi[a] - lo[a]) / cells[a];
        origin[a] = lo[a] + 0.5 * spacing[a];
    }
    const size_t np = analysis_cg_grid_count(dim, cells);
    vtk_file *f;
    core_status st = vtk_image(n, origin, spacing, &f, err);
    if (st)
        return st;
    for (size_t k = 0; !st && k < ncol; k++) {
        const analysis_cg_column *c = &cols[k];
        const int vc = vtk_ncomp(dim, c->ncomp);
        double *v = vtk_f64(f, VTK_POINT_DATA, c->name, vc, np, err);
        if (!v) {
            st = err ? err->status : CORE_ERR_NOMEM;
            break;
        }
        for (size_t i = 0; i < np; i++)
            vtk_fill(dim, c->ncomp, c->values + i * (size_t)c->ncomp, v + i * (size_t)vc);
    }
    if (!st)
        st = vtk_set_time(f, time, 0, err);
    return vtk_file_finish(f, path, st, err);
}

core_status analysis_cg_write_csv(const char *path, int dim, size_t n, const double *const pts[3],
                                  size_t ncol, const analysis_cg_column *cols, core_error *err)
{
    static const char *const axis[3] = {"x", "y", "z"};
    atomic_file af;
    core_status st = atomic_open(&af, path, err);
    if (st)
        return st;
    FILE *fp = af.fp;
    for (int a = 0; a < dim; a++)
        fprintf(fp, "%s%s", a ? "," : "", axis[a]);
    for (size_t k = 0; k < ncol; k++) {
        const analysis_cg_column *c = &cols[k];
        if (c->ncomp == 1)
            fprintf(fp, ",%s", c->name);
        else if (c->ncomp == dim)
            for (int a = 0; a < dim; a++)
                fprintf(fp, ",%s_%s", c->name, axis[a]);
        else
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++)
                    fprintf(fp, ",%s_%s%s", c->name, axis[a], axis[b]);
    }
    fputc('\n', fp);
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < dim; a++)
            fprintf(fp, "%s%.17g", a ? "," : "", pts[a][i]);
        for (size_t k = 0; k < ncol; k++)
            for (int q = 0; q < cols[k].ncomp; q++)
                fprintf(fp, ",%.17g", cols[k].values[i * (size_t)cols[k].ncomp + (size_t)q]);
        fputc('\n', fp);
    }
    return atomic_commit(&af, err);
}
