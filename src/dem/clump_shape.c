/* The mass properties of a clump: area or volume, centre and inertia of the UNION of its
 * members (overlaps counted once), by quadrature: lines across the bounding box, each cut
 * exactly by the members (the union of their chords), so that only the integral across the
 * lines is numerical (the midpoint rule), and the principal axes from a Jacobi rotation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem/dem_internal.h"

/* The union of k intervals [lo, hi) (sorted here) and its moments: length, int t, int t^2. */
static void union_moments(double *lo, double *hi, int k, double m[3])
{
    for (int a = 1; a < k; a++) /* insertion sort by lo: k is a few members */
        for (int b = a; b > 0 && lo[b] < lo[b - 1]; b--) {
            double t = lo[b];
            lo[b] = lo[b - 1], lo[b - 1] = t;
            t = hi[b];
            hi[b] = hi[b - 1], hi[b - 1] = t;
        }
    m[0] = m[1] = m[2] = 0;
    for (int a = 0; a < k;) {
        double l = lo[a], h = hi[a];
        for (a++; a < k && lo[a] <= h; a++)
            h = fmax(h, hi[a]);
        m[0] += h - l;
        m[1] += 0.5 * (h * h - l * l);
        m[2] += (h * h * h - l * l * l) / 3;
    }
}

/* Raw moments S[0] = int 1, S[1..3] = int x_a, S[4..9] = int x_a x_b (xx, yy, zz, xy, xz, yz)
 * of the union, with `res` lines along the longest side of the bounding box. Planar: lines
 * along y over x (disks); else lines along z over (x, y) (spheres). */
static void integrate(const dem_clump_member *m, int n, int planar, int res, double S[10])
{
    double lo[3], hi[3], ext = 0;
    for (int d = 0; d < 3; d++) {
        lo[d] = INFINITY, hi[d] = -INFINITY;
        for (int k = 0; k < n; k++) {
            lo[d] = fmin(lo[d], m[k].offset[d] - m[k].radius);
            hi[d] = fmax(hi[d], m[k].offset[d] + m[k].radius);
        }
        ext = fmax(ext, hi[d] - lo[d]);
    }
    const double h = ext / res;
    int nl[2];
    for (int d = 0; d < 2; d++)
        nl[d] = (int)ceil((hi[d] - lo[d]) / h - 1e-9);
    if (planar)
        nl[1] = 1;
    double a[DEM_CLUMP_MAX_MEMBERS], b[DEM_CLUMP_MAX_MEMBERS];
    memset(S, 0, 10 * sizeof(double));
    for (int iy = 0; iy < nl[1]; iy++) {
        double Sy[10] = {0}; /* one row of lines: summed apart, then added (less rounding) */
        const double y = lo[1] + (iy + 0.5) * h;
        for (int ix = 0; ix < nl[0]; ix++) {
            const double x = lo[0] + (ix + 0.5) * h;
            int k = 0;
            for (int q = 0; q < n; q++) {
                double dx = x - m[q].offset[0], rr = m[q].radius * m[q].radius - dx * dx;
                double c = m[q].offset[1];
                if (!planar) {
                    double dy = y - m[q].offset[1];
                    rr -= dy * dy;
                    c = m[q].offset[2];
                }
                if (rr > 0) {
                    double w = sqrt(rr);
                    a[k] = c - w, b[k] = c + w, k++;
                }
            }
            if (!k)
                continue;
            double mm[3];
            union_moments(a, b, k, mm);
            if (planar) { /* the line is along y at x */
                double r[10] = {mm[0], x * mm[0], mm[1], 0, x * x * mm[0], mm[2], 0, x * mm[1],
                                0, 0};
                for (int e = 0; e < 10; e++)
                    Sy[e] += r[e];
            } else { /* along z at (x, y) */
                double r[10] = {mm[0],         x * mm[0], y * mm[0], mm[1],     x * x * mm[0],
                                y * y * mm[0], mm[2],     x * y * mm[0], x * mm[1], y * mm[1]};
                for (int e = 0; e < 10; e++)
                    Sy[e] += r[e];
            }
        }
        for (int e = 0; e < 10; e++)
            S[e] += Sy[e];
    }
    const double w = planar ? h : h * h;
    for (int e = 0; e < 10; e++)
        S[e] *= w;
}

/* Cyclic Jacobi rotations of a symmetric 3x3 matrix A (row-major): eigenvalues in ev, their
 * eigenvectors in the columns of V. */
static void jacobi3(double A[9], double ev[3], double V[9])
{
    for (int k = 0; k < 9; k++)
        V[k] = k % 4 == 0;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(A[1]) + fabs(A[2]) + fabs(A[5]);
        if (off <= 1e-300 + 1e-17 * (fabs(A[0]) + fabs(A[4]) + fabs(A[8])))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = A[3 * p + q];
                if (apq == 0)
                    continue;
                double th = (A[3 * q + q] - A[3 * p + p]) / (2 * apq);
                double t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
                double c = 1 / sqrt(t * t + 1), sn = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    double akp = A[3 * k + p], akq = A[3 * k + q];
                    A[3 * k + p] = c * akp - sn * akq;
                    A[3 * k + q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    double apk = A[3 * p + k], aqk = A[3 * q + k];
                    A[3 * p + k] = c * apk - sn * aqk;
                    A[3 * q + k] = sn * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = V[3 * k + p], vkq = V[3 * k + q];
                    V[3 * k + p] = c * vkp - sn * vkq;
                    V[3 * k + q] = sn * vkp + c * vkq;
                }
            }
    }
    for (int k = 0; k < 3; k++)
        ev[k] = A[4 * k];
}

/* Measure, centre, central inertia tensor from the raw moments. */
static void finish(const double S[10], int planar, dem_clump_shape *o)
{
    o->measure = S[0];
    double c[3] = {S[1] / S[0], S[2] / S[0], S[3] / S[0]};
    double M[9]; /* central second moments int (x - c)_a (x - c)_b */
    const int ab[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    for (int e = 0; e < 6; e++) {
        int i = ab[e][0], j = ab[e][1];
        double v = S[4 + e] - S[0] * c[i] * c[j];
        M[3 * i + j] = M[3 * j + i] = v;
    }
    if (planar) /* a plate in the plane: z moments vanish */
        M[2] = M[5] = M[6] = M[7] = M[8] = c[2] = 0;
    memcpy(o->centre, c, sizeof c);
    const double tr = M[0] + M[4] + M[8];
    for (int k = 0; k < 9; k++)
        o->tensor[k] = (k % 4 == 0 ? tr : 0) - M[k];
}

static void principal(dem_clump_shape *o)
{
    if (o->dim == 2) { /* only the moment about z matters: the axes stay the members' frame */
        for (int k = 0; k < 9; k++)
            o->axes[k] = k % 4 == 0;
        o->moments[0] = o->tensor[0], o->moments[1] = o->tensor[4];
        o->moments[2] = o->tensor[8];
        return;
    }
    double A[9], ev[3], V[9];
    memcpy(A, o->tensor, sizeof A);
    jacobi3(A, ev, V);
    int idx[3] = {0, 1, 2}; /* ascending */
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (ev[idx[b]] < ev[idx[a]]) {
                int t = idx[a];
                idx[a] = idx[b], idx[b] = t;
            }
    for (int k = 0; k < 3; k++) {
        o->moments[k] = ev[idx[k]];
        for (int r = 0; r < 3; r++)
            o->axes[3 * r + k] = V[3 * r + idx[k]];
    }
    const double *X = o->axes; /* right-handed: det = +1 */
    double det = X[0] * (X[4] * X[8] - X[5] * X[7]) - X[1] * (X[3] * X[8] - X[5] * X[6]) +
                 X[2] * (X[3] * X[7] - X[4] * X[6]);
    if (det < 0)
        for (int r = 0; r < 3; r++)
            o->axes[3 * r + 2] = -o->axes[3 * r + 2];
}

/* Every member reaches every other through members that overlap or touch. */
static int connected(const dem_clump_member *m, int n, int *lone)
{
    unsigned char seen[DEM_CLUMP_MAX_MEMBERS] = {0};
    int stack[DEM_CLUMP_MAX_MEMBERS], top = 0, count = 1;
    seen[0] = 1, stack[top++] = 0;
    while (top) {
        int a = stack[--top];
        for (int b = 0; b < n; b++) {
            if (seen[b])
                continue;
            double d2 = 0;
            for (int d = 0; d < 3; d++)
                d2 += (m[a].offset[d] - m[b].offset[d]) * (m[a].offset[d] - m[b].offset[d]);
            double reach = (m[a].radius + m[b].radius) * (1 + 1e-12);
            if (d2 <= reach * reach)
                seen[b] = 1, stack[top++] = b, count++;
        }
    }
    for (int b = 0; b < n; b++)
        if (!seen[b]) {
            *lone = b;
            break;
        }
    return count == n;
}

core_status dem_clump_shape_compute(const dem_clump_member *m, int n, int dim, int planar,
                                    int resolution, dem_clump_shape *out, core_error *err)
{
    if (n < 1 || n > DEM_CLUMP_MAX_MEMBERS)
        return core_fail(err, CORE_ERR_ARG, "a clump needs 1 to %d members, got %d",
                         DEM_CLUMP_MAX_MEMBERS, n);
    if (dim != 2 && dim != 3)
        return core_fail(err, CORE_ERR_ARG, "dim must be 2 or 3, got %d", dim);
    if (resolution == 0)
        resolution = planar && dim == 2 ? 4096 : dim == 2 ? 1024 : 512;
    if (resolution < 16 || resolution > 1 << 16)
        return core_fail(err, CORE_ERR_ARG, "resolution must be in [16, 65536], got %d",
                         resolution);
    for (int k = 0; k < n; k++) {
        if (!(m[k].radius > 0) || !isfinite(m[k].radius))
            return core_fail(err, CORE_ERR_ARG, "member %d: radius must be > 0, got %g", k + 1,
                             m[k].radius);
        for (int d = 0; d < 3; d++)
            if (!isfinite(m[k].offset[d]) || (d >= dim && m[k].offset[d] != 0))
                return core_fail(err, CORE_ERR_ARG, "member %d: offset must be %d finite numbers",
                                 k + 1, dim);
    }
    int lone = 0;
    if (!connected(m, n, &lone))
        return core_fail(err, CORE_ERR_ARG,
                         "member %d neither overlaps nor touches the others: a clump's members "
                         "must form one connected body",
                         lone + 1);
    memset(out, 0, sizeof *out);
    out->dim = dim, out->planar = planar && dim == 2, out->resolution = resolution;
    double S[10], Sh[10];
    integrate(m, n, out->planar, resolution, S);
    integrate(m, n, out->planar, resolution / 2, Sh);
    dem_clump_shape half = *out;
    finish(Sh, out->planar, &half);
    principal(&half);
    finish(S, out->planar, out);
    principal(out);
    double e = fabs(half.measure - out->measure) / out->measure;
    for (int k = dim == 2 ? 2 : 0; k < 3; k++)
        e = fmax(e, fabs(half.moments[k] - out->moments[k]) / out->moments[k]);
    out->rel_error = e;
    return CORE_OK;
}
