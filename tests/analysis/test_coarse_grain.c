/* Coarse-graining kernels without Lua: both kernels integrate to 1 over their support in 2D and
 * 3D; the closed-form line integrals equal brute-force quadrature; the grid integrals of the
 * fields equal the particle and contact totals (to round-off with the Gaussian cut far out); the
 * divergence of a pair's contact stress is its force density; periodic images; the same bits on
 * 1 and 2 threads; invariants of known tensors; bad input refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "analysis/coarse_grain.h"
#include "core/rng.h"
#include "core/threads.h"

#define PI 3.14159265358979323846

/* Gauss-Legendre nodes and weights on [-1, 1], 20 points (Golub-Welsch by Newton). */
static void gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(PI * (i + 0.75) / (n + 0.5)), pp = 0;
        for (int it = 0; it < 100; it++) {
            double p1 = 1, p2 = 0;
            for (int j = 1; j <= n; j++) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2 * j - 1) * z * p2 - (j - 1) * p3) / j;
            }
            pp = n * (z * p1 - p2) / (z * z - 1);
            double z1 = z;
            z = z1 - p1 / pp;
            if (fabs(z - z1) < 1e-16)
                break;
        }
        x[i] = z;
        w[i] = 2 / ((1 - z * z) * pp * pp);
    }
}

/* int_a^b f by 20-point Gauss-Legendre on m panels. */
static double integrate(double (*f)(double, void *), void *ctx, double a, double b, int m)
{
    double x[20], w[20], s = 0, h = (b - a) / m;
    gauss_legendre(20, x, w);
    for (int p = 0; p < m; p++) {
        double c = a + (p + 0.5) * h;
        for (int i = 0; i < 20; i++)
            s += w[i] * 0.5 * h * f(c + 0.5 * h * x[i], ctx);
    }
    return s;
}

typedef struct radial {
    analysis_cg_def def;
} radial;

static double radial_f(double r, void *ctx)
{
    radial *q = ctx;
    double shell = q->def.dim == 2 ? 2 * PI * r : 4 * PI * r * r;
    return analysis_cg_phi(&q->def, r) * shell;
}

static void test_normalised(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int kern = 0; kern < 2; kern++)
            for (int cut = 0; cut < 3; cut++) {
                radial q;
                q.def = analysis_cg_default_def();
                q.def.dim = dim;
                q.def.kernel = kern ? ANALYSIS_CG_LUCY : ANALYSIS_CG_GAUSS;
                q.def.width = 0.37;
                q.def.cutoff = kern ? 0 : (cut == 0 ? 0 : cut == 1 ? 1.5 * 0.37 : 8 * 0.37);
                double c = analysis_cg_reach(&q.def);
                double total = integrate(radial_f, &q, 0, c, 64);
                assert_true(fabs(total - 1) < 1e-13);
                assert_true(analysis_cg_phi(&q.def, c * 1.0000001) == 0);
            }
}

typedef struct line {
    analysis_cg_def def;
    double d[3], b[3];
} line;

static double line_f(double s, void *ctx)
{
    line *q = ctx;
    double r2 = 0;
    for (int a = 0; a < q->def.dim; a++) {
        double e = q->d[a] + s * q->b[a];
        r2 += e * e;
    }
    return analysis_cg_phi(&q->def, sqrt(r2));
}

/* psi against quadrature of phi along the segment (many panels: the integrand has the cut's
 * jump or the kink of Lucy's support edge, which the panels resolve to ~1e-12). */
static void test_line_integral(void **state)
{
    (void)state;
    rng g;
    rng_seed(&g, 3, 0);
    for (int dim = 2; dim <= 3; dim++)
        for (int kern = 0; kern < 2; kern++)
            for (int trial = 0; trial < 100; trial++) {
                line q;
                q.def = analysis_cg_default_def();
                q.def.dim = dim;
                q.def.kernel = kern ? ANALYSIS_CG_LUCY : ANALYSIS_CG_GAUSS;
                q.def.width = 1;
                double c = analysis_cg_reach(&q.def);
                for (int a = 0; a < 3; a++) {
                    q.d[a] = a < dim ? (rng_uniform(&g) * 2 - 1) * 1.2 * c : 0;
                    q.b[a] = a < dim ? (rng_uniform(&g) * 2 - 1) * (trial % 3 ? 0.5 : 2.5) * c : 0;
                }
                if (trial == 7) /* the point on the line */
                    for (int a = 0; a < 3; a++)
                        q.d[a] = -0.3 * q.b[a];
                double psi = analysis_cg_psi(&q.def, q.d, q.b);
                /* split [0, 1] where |d + s b| = c: phi jumps (Gauss) or has its support's edge */
                double A = 0, B = 0, C = -c * c, cuts[4] = {0, 1, 0, 1};
                int nc = 2;
                for (int a = 0; a < dim; a++) {
                    A += q.b[a] * q.b[a];
                    B += 2 * q.d[a] * q.b[a];
                    C += q.d[a] * q.d[a];
                }
                double disc = B * B - 4 * A * C;
                if (disc > 0)
                    for (int sg = -1; sg <= 1; sg += 2) {
                        double s = (-B + sg * sqrt(disc)) / (2 * A);
                        if (s > 0 && s < 1)
                            cuts[nc++] = s;
                    }
                for (int i = 0; i < nc; i++) /* sort */
                    for (int j = i + 1; j < nc; j++)
                        if (cuts[j] < cuts[i]) {
                            double t = cuts[i];
                            cuts[i] = cuts[j];
                            cuts[j] = t;
                        }
                double ref = 0;
                for (int i = 0; i + 1 < nc; i++)
                    ref += integrate(line_f, &q, cuts[i], cuts[i + 1], 40);
                double peak = analysis_cg_phi(&q.def, 0);
                if (fabs(psi - ref) > 1e-9 * peak)
                    fail_msg("dim %d kernel %d trial %d: psi %.17g, quadrature %.17g", dim, kern,
                             trial, psi, ref);
            }
}

/* A random cluster: n particles with velocities, contacts between near pairs with random
 * forces, and two wall contacts. */
enum { NP = 60, NC = 160 };
typedef struct cluster {
    double x[3][NP], v[3][NP], m[NP], vol[NP], fab[9 * NP];
    long ci[NC];
    double b[3][NC], f[3][NC];
    unsigned char wall[NC];
    size_t nc;
    analysis_cg_particles p;
    analysis_cg_contacts c;
} cluster;

static void make_cluster(cluster *k, int dim, unsigned long long seed)
{
    rng g;
    rng_seed(&g, seed, 0);
    memset(k, 0, sizeof *k);
    for (int i = 0; i < NP; i++) {
        for (int a = 0; a < dim; a++) {
            k->x[a][i] = rng_uniform(&g) * 4;
            k->v[a][i] = rng_uniform(&g) - 0.5;
        }
        k->m[i] = 0.5 + rng_uniform(&g);
        k->vol[i] = 0.1 + 0.1 * rng_uniform(&g);
        for (int q = 0; q < dim * dim; q++)
            k->fab[dim * dim * i + q] = rng_uniform(&g);
    }
    size_t nc = 0;
    for (int i = 0; i < NP && nc < NC - 2; i++)
        for (int j = i + 1; j < NP && nc < NC - 2; j++) {
            double d2 = 0;
            for (int a = 0; a < dim; a++)
                d2 += (k->x[a][i] - k->x[a][j]) * (k->x[a][i] - k->x[a][j]);
            if (d2 > 1.2)
                continue;
            k->ci[nc] = i;
            for (int a = 0; a < dim; a++) {
                k->b[a][nc] = k->x[a][i] - k->x[a][j];
                k->f[a][nc] = rng_uniform(&g) - 0.3;
            }
            nc++;
        }
    for (int w = 0; w < 2; w++) { /* two wall contacts: the line ends at a contact point */
        k->ci[nc] = w;
        for (int a = 0; a < dim; a++) {
            k->b[a][nc] = a == 1 ? 0.2 : 0;
            k->f[a][nc] = a == 1 ? 1.5 : 0.2;
        }
        k->wall[nc] = 1;
        nc++;
    }
    k->nc = nc;
    k->p.n = NP;
    for (int a = 0; a < dim && a < 3; a++) {
        k->p.x[a] = k->x[a];
        k->p.v[a] = k->v[a];
    }
    k->p.mass = k->m;
    k->p.volume = k->vol;
    k->p.fabric = k->fab;
    k->c.n = nc;
    k->c.i = k->ci;
    for (int a = 0; a < dim && a < 3; a++) {
        k->c.b[a] = k->b[a];
        k->c.f[a] = k->f[a];
    }
    k->c.wall = k->wall;
}

/* Sums on a grid over [lo, hi] with cells of size h; returns the grid's integrals of every
 * channel (times the cell volume) in tot. */
static void grid_integrals(const analysis_cg_def *def, const cluster *k, double lo, double hi,
                           int cells, const analysis_cg_layout *l, double *tot)
{
    const int D = def->dim;
    int nc[3] = {cells, cells, D == 3 ? cells : 1};
    double glo[3] = {lo, lo, lo}, ghi[3] = {hi, hi, hi};
    size_t n = analysis_cg_grid_count(D, nc);
    double *pts[3] = {malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                      malloc(n * sizeof(double))};
    analysis_cg_grid_points(D, nc, glo, ghi, pts);
    double *out = malloc(n * (size_t)l->stride * sizeof(double));
    core_error err;
    assert_int_equal(
        analysis_cg_sums(def, &k->p, &k->c, l, n, (const double *const *)pts, out, &err), CORE_OK);
    double cell = pow((hi - lo) / cells, D);
    for (int q = 0; q < l->stride; q++) {
        double s = 0;
        for (size_t i = 0; i < n; i++)
            s += out[i * (size_t)l->stride + (size_t)q];
        tot[q] = s * cell;
    }
    for (int a = 0; a < 3; a++)
        free(pts[a]);
    free(out);
}

static void check_totals(const analysis_cg_def *def, const cluster *k, const analysis_cg_layout *l,
                         const double *tot, double tol)
{
    const int D = def->dim;
    double mass = 0, mom[3] = {0}, flux[9] = {0}, vir[9] = {0}, tr[3] = {0}, vol = 0;
    for (int i = 0; i < NP; i++) {
        mass += k->m[i];
        vol += k->vol[i];
        for (int a = 0; a < D; a++) {
            mom[a] += k->m[i] * k->v[a][i];
            for (int b = 0; b < D; b++)
                flux[a * D + b] += k->m[i] * k->v[a][i] * k->v[b][i];
        }
    }
    for (size_t q = 0; q < k->nc; q++)
        for (int a = 0; a < D; a++) {
            for (int b = 0; b < D; b++)
                vir[a * D + b] += k->b[a][q] * k->f[b][q];
            if (k->wall[q])
                tr[a] += k->f[a][q];
        }
#define NEAR(got, want, scale)                                                                     \
    do {                                                                                           \
        if (fabs((got) - (want)) > tol * (scale))                                                  \
            fail_msg("%s: grid %.17g, total %.17g (tol %g)", #want, (got), (want), tol);           \
    } while (0)
    NEAR(tot[l->offset[ANALYSIS_CG_DENSITY]], mass, mass);
    NEAR(tot[l->offset[ANALYSIS_CG_VOLUME]], vol, vol);
    for (int a = 0; a < D; a++) {
        NEAR(tot[l->offset[ANALYSIS_CG_MOMENTUM] + a], mom[a], mass);
        NEAR(tot[l->offset[ANALYSIS_CG_TRACTION] + a], tr[a], 2);
        for (int b = 0; b < D; b++) {
            NEAR(tot[l->offset[ANALYSIS_CG_FLUX] + a * D + b], flux[a * D + b], mass);
            NEAR(tot[l->offset[ANALYSIS_CG_CONTACT] + a * D + b], vir[a * D + b], (double)k->nc);
        }
    }
#undef NEAR
}

/* Weinhart et al. (2012): the fields integrate to the totals. With the Gaussian cut at 8 w
 * (phi there is e^-32 = 1.3e-14 of its peak) the kernel and its line integrals are smooth to
 * round-off, and the grid's midpoint sums integrate them to round-off at a spacing of w / 2
 * (spectral accuracy); the cut at 3 w leaves a jump of 1 % of the peak (1e-4 to 1e-5); Lucy is
 * C2 and converges as h^4.5. */
static void test_exact_totals(void **state)
{
    (void)state;
    static cluster k;
    for (int dim = 2; dim <= 3; dim++) {
        make_cluster(&k, dim, 11 + (unsigned long long)dim);
        analysis_cg_def def = analysis_cg_default_def();
        def.dim = dim;
        def.width = 0.4;
        def.cutoff = 8 * 0.4;
        analysis_cg_layout l;
        analysis_cg_layout_of(dim, &k.p, &k.c, &l);
        double tot[64];
        /* region [-4, 8] holds every support (x in [0, 4], reach 3.2); h = 12/60 = w/2 */
        grid_integrals(&def, &k, -4, 8, dim == 2 ? 60 : 40, &l, tot);
        check_totals(&def, &k, &l, tot, dim == 2 ? 1e-12 : 2e-5);
        def.kernel = ANALYSIS_CG_LUCY;
        def.width = 1.2;
        grid_integrals(&def, &k, -2, 6, dim == 2 ? 128 : 48, &l, tot);
        check_totals(&def, &k, &l, tot, dim == 2 ? 1e-6 : 1e-3);
    }
}

/* d_a sigma_ab = f_b (phi(r - x_j) - phi(r - x_i)) for one pair (the line integral's orientation
 * and scale), checked by central differences at points around the pair. */
static void test_divergence(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int kern = 0; kern < 2; kern++) {
            double xi[3] = {0.3, 0.2, 0.1}, xj[3] = {-0.4, 0.5, -0.2}, f[3] = {0.7, -0.2, 0.4};
            double px[3][2], pv[3][2] = {{0}}, m[2] = {1, 1};
            long ci[1] = {0};
            double b[3][1], fc[3][1];
            analysis_cg_particles p;
            memset(&p, 0, sizeof p);
            p.n = 2;
            p.mass = m;
            analysis_cg_contacts c;
            memset(&c, 0, sizeof c);
            c.n = 1;
            c.i = ci;
            for (int a = 0; a < dim; a++) {
                px[a][0] = xi[a];
                px[a][1] = xj[a];
                p.x[a] = px[a];
                p.v[a] = pv[a];
                b[a][0] = xi[a] - xj[a];
                fc[a][0] = f[a];
                c.b[a] = b[a];
                c.f[a] = fc[a];
            }
            analysis_cg_def def = analysis_cg_default_def();
            def.dim = dim;
            def.kernel = kern ? ANALYSIS_CG_LUCY : ANALYSIS_CG_GAUSS;
            def.width = kern ? 2.0 : 0.6;
            analysis_cg_layout l;
            analysis_cg_layout_of(dim, &p, &c, &l);
            const double h = 1e-4;
            double r0s[3][3] = {{0.1, 0.05, 0.0}, {-0.6, 0.9, 0.3}, {0.5, -0.3, -0.1}};
            for (int t = 0; t < 3; t++) {
                double *r0 = r0s[t];
                double div[3] = {0, 0, 0};
                for (int a = 0; a < dim; a++) {
                    double q[2][3], o[128];
                    for (int s = 0; s < 2; s++) {
                        for (int e = 0; e < 3; e++)
                            q[s][e] = r0[e];
                        q[s][a] += s ? h : -h;
                    }
                    double xs[2] = {q[0][0], q[1][0]}, ys[2] = {q[0][1], q[1][1]},
                           zs[2] = {q[0][2], q[1][2]};
                    const double *pts[3] = {xs, ys, zs};
                    core_error err;
                    assert_int_equal(analysis_cg_sums(&def, &p, &c, &l, 2, pts, o, &err), CORE_OK);
                    const double *out[2] = {o, o + l.stride};
                    for (int bb = 0; bb < dim; bb++)
                        div[bb] += (out[1][l.offset[ANALYSIS_CG_CONTACT] + a * dim + bb] -
                                    out[0][l.offset[ANALYSIS_CG_CONTACT] + a * dim + bb]) /
                                   (2 * h);
                }
                double ri = 0, rj = 0;
                for (int a = 0; a < dim; a++) {
                    ri += (r0[a] - xi[a]) * (r0[a] - xi[a]);
                    rj += (r0[a] - xj[a]) * (r0[a] - xj[a]);
                }
                double dphi = analysis_cg_phi(&def, sqrt(rj)) - analysis_cg_phi(&def, sqrt(ri));
                for (int bb = 0; bb < dim; bb++)
                    if (fabs(div[bb] - f[bb] * dphi) > 1e-6 * analysis_cg_phi(&def, 0))
                        fail_msg("dim %d kernel %d point %d: div %g, f dphi %g", dim, kern, t,
                                 div[bb], f[bb] * dphi);
            }
        }
}

/* A periodic axis: the field equals that of the particle and its images placed by hand. */
static void test_periodic(void **state)
{
    (void)state;
    double x[2][1] = {{0.1}, {0.5}}, m[1] = {2};
    double x3[2][3] = {{0.1, 1.1, -0.9}, {0.5, 0.5, 0.5}}, m3[3] = {2, 2, 2};
    analysis_cg_particles p, p3;
    memset(&p, 0, sizeof p);
    memset(&p3, 0, sizeof p3);
    p.n = 1;
    p.x[0] = x[0];
    p.x[1] = x[1];
    p.mass = m;
    p3.n = 3;
    p3.x[0] = x3[0];
    p3.x[1] = x3[1];
    p3.mass = m3;
    analysis_cg_def def = analysis_cg_default_def();
    def.width = 0.15;
    def.periodic[0] = true;
    def.lo[0] = 0;
    def.hi[0] = 1;
    analysis_cg_def plain = def;
    plain.periodic[0] = false;
    double xs[5] = {0.0, 0.05, 0.5, 0.95, 0.999}, ys[5] = {0.5, 0.45, 0.5, 0.6, 0.5};
    const double *pts[3] = {xs, ys, NULL};
    analysis_cg_layout l;
    analysis_cg_layout_of(2, &p, NULL, &l);
    double a[5 * 8], b[5 * 8];
    core_error err;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 5, pts, a, &err), CORE_OK);
    assert_int_equal(analysis_cg_sums(&plain, &p3, NULL, &l, 5, pts, b, &err), CORE_OK);
    for (int k = 0; k < 5; k++)
        assert_true(a[k * l.stride] == b[k * l.stride]);
    assert_true(a[4 * l.stride] > 0); /* x = 0.999 sees the particle at 0.1 across the edge */
    /* a period shorter than the reach is refused */
    def.hi[0] = 0.3;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 5, pts, a, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "periodic x axis"));
}

static void test_threads_same_bits(void **state)
{
    (void)state;
    static cluster k;
    for (int dim = 2; dim <= 3; dim++) {
        make_cluster(&k, dim, 5);
        analysis_cg_def def = analysis_cg_default_def();
        def.dim = dim;
        def.width = 0.3;
        analysis_cg_layout l;
        analysis_cg_layout_of(dim, &k.p, &k.c, &l);
        int cells[3] = {37, 29, dim == 3 ? 11 : 1};
        double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {4.5, 4.5, 4.5};
        size_t n = analysis_cg_grid_count(dim, cells);
        double *pts[3];
        for (int a = 0; a < 3; a++)
            pts[a] = malloc(n * sizeof(double));
        analysis_cg_grid_points(dim, cells, lo, hi, pts);
        double *o1 = malloc(n * (size_t)l.stride * sizeof(double));
        double *o2 = malloc(n * (size_t)l.stride * sizeof(double));
        core_error err;
        threads_set(1);
        assert_int_equal(
            analysis_cg_sums(&def, &k.p, &k.c, &l, n, (const double *const *)pts, o1, &err),
            CORE_OK);
        threads_set(2);
        assert_int_equal(
            analysis_cg_sums(&def, &k.p, &k.c, &l, n, (const double *const *)pts, o2, &err),
            CORE_OK);
        threads_set_auto();
        assert_memory_equal(o1, o2, n * (size_t)l.stride * sizeof(double));
        for (int a = 0; a < 3; a++)
            free(pts[a]);
        free(o1);
        free(o2);
    }
}

static void test_invariants(void **state)
{
    (void)state;
    analysis_cg_invariants iv;
    /* 2D: principal values 5 and 1 along (1, 1) / sqrt 2 and (-1, 1) / sqrt 2 */
    double t2[4] = {3, 2, 2, 3};
    analysis_cg_invariants_of(2, t2, &iv);
    assert_true(fabs(iv.pressure - 3) < 1e-15);
    assert_true(fabs(iv.psd - 4) < 1e-14);
    assert_true(fabs(iv.angle - PI / 4) < 1e-15);
    assert_true(fabs(iv.principal[0] - 5) < 1e-14 && fabs(iv.principal[1] - 1) < 1e-14);
    /* a vertical major direction: angle pi/2, not -pi/2 */
    double tv[4] = {1, 0, 0, 4};
    analysis_cg_invariants_of(2, tv, &iv);
    assert_true(fabs(iv.angle - PI / 2) < 1e-15);
    /* 3D: R diag(7, 2, -1) R^T with R a rotation */
    double c = cos(0.3), s = sin(0.3), R[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
    double lam[3] = {2, 7, -1}, t3[9];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            t3[a * 3 + b] = 0;
            for (int k = 0; k < 3; k++)
                t3[a * 3 + b] += R[a][k] * lam[k] * R[b][k];
        }
    analysis_cg_invariants_of(3, t3, &iv);
    assert_true(fabs(iv.pressure - 8.0 / 3) < 1e-14);
    assert_true(fabs(iv.psd - 8) < 1e-13);
    assert_true(fabs(iv.principal[0] - 7) < 1e-13 && fabs(iv.principal[2] + 1) < 1e-13);
    /* the major direction is R's second column (-s, c, 0), its largest component positive */
    assert_true(fabs(iv.direction[0] + s) < 1e-13 && fabs(iv.direction[1] - c) < 1e-13);
    double tn[4] = {NAN, 0, 0, 1};
    analysis_cg_invariants_of(2, tn, &iv);
    assert_true(isnan(iv.pressure) && isnan(iv.psd));
}

static void test_bad_input(void **state)
{
    (void)state;
    double x[2][1] = {{0}, {0}}, m[1] = {1}, xs[1] = {0}, ys[1] = {NAN}, out[16];
    analysis_cg_particles p;
    memset(&p, 0, sizeof p);
    p.n = 1;
    p.x[0] = x[0];
    p.x[1] = x[1];
    p.mass = m;
    analysis_cg_layout l;
    analysis_cg_layout_of(2, &p, NULL, &l);
    analysis_cg_def def = analysis_cg_default_def();
    const double *pts[3] = {xs, ys, NULL};
    core_error err;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 1, pts, out, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "point 1: coordinate y"));
    ys[0] = 0;
    def.width = -1;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 1, pts, out, &err), CORE_ERR_ARG);
    def.width = 1;
    def.cutoff = 11;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 1, pts, out, &err), CORE_ERR_ARG);
    def.cutoff = 0;
    x[0][0] = INFINITY;
    assert_int_equal(analysis_cg_sums(&def, &p, NULL, &l, 1, pts, out, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "particle 1: position x"));
    x[0][0] = 0;
    long ci[1] = {3};
    double b[1] = {0}, f[1] = {0};
    analysis_cg_contacts c = {1, ci, {b, b, NULL}, {f, f, NULL}, NULL};
    analysis_cg_layout lc;
    analysis_cg_layout_of(2, &p, &c, &lc);
    assert_int_equal(analysis_cg_sums(&def, &p, &c, &lc, 1, pts, out, &err), CORE_ERR_ARG);
    assert_non_null(strstr(err.msg, "contact 1 names particle 4"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normalised),   cmocka_unit_test(test_line_integral),
        cmocka_unit_test(test_exact_totals), cmocka_unit_test(test_divergence),
        cmocka_unit_test(test_periodic),     cmocka_unit_test(test_threads_same_bits),
        cmocka_unit_test(test_invariants),   cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
