/* The DSMC step's collisions (paper Sec. 4, Eq. 1): in every cell, candidate pairs in proportion
 * to its particles, relative speed and excluded volume, accepted with probability g / v_max, and
 * the normal relative velocity reversed and scaled by the restitution. Every cell draws from its
 * own random stream and takes its particles in identity order, so the result does not depend on
 * the number of threads or ranks. Cells past close packing or over the candidate cap stop the run
 * (the verdict, read by dsmc_run). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dsmc/dsmc_internal.h"

void dsmc_verdict_clear(dsmc_verdict *v)
{
    memset(v, 0, sizeof *v);
    v->packed_cell = v->capped_cell = v->strand_id = INT64_MAX;
}

void dsmc_verdict_merge(dsmc_verdict *a, const dsmc_verdict *b)
{
    a->packed_cells += b->packed_cells;
    if (b->packed_n > a->packed_n || (b->packed_n == a->packed_n && b->packed_cell < a->packed_cell))
        a->packed_n = b->packed_n, a->packed_cell = b->packed_cell;
    a->capped_cells += b->capped_cells;
    if (b->capped_m > a->capped_m || (b->capped_m == a->capped_m && b->capped_cell < a->capped_cell))
        a->capped_m = b->capped_m, a->capped_cell = b->capped_cell, a->capped_n = b->capped_n;
    a->stranded += b->stranded;
    if (b->strand_id < a->strand_id)
        a->strand_id = b->strand_id;
}

/* The most particles whose centres can lie in one cell at the packing limit nu_rcp: their
 * bodies fill the cell widened by a radius on every side, so N v_b <= nu_rcp prod(h_k + 2R). */
double dsmc_fit_per_cell(const dsmc_scene *s)
{
    double vol = 1;
    for (int k = 0; k < s->D; k++)
        vol *= s->h[k] + 2 * s->def.radius;
    return floor(s->def.packing_limit * vol / s->vpart);
}

/* ln P(N >= k) of a Poisson count of mean mu, bounded above (k > mu): the terms from k on fall
 * at least by mu / (k + 1) each. */
static double poisson_log_tail(double mu, double k)
{
    return -mu + k * log(mu) - lgamma(k + 1) - log(1 - mu / (k + 1));
}

/* The count from which a cell is past close packing for the run's check: more than fit in it
 * (dsmc_fit_per_cell), and beyond the reach of the cells' Poisson noise in a gas DSMC can describe:
 * P(N >= threshold) < 1e-20 per cell and step at a mean occupancy mu of the larger of the gas's
 * mean and that of the densest gas whose mean free path (chi = 1) still spans the cell
 * (condition ii): V_c / (2 sqrt2 sigma h_max) in 2D, V_c / (sqrt2 sigma h_max) in 3D. In cells
 * of one diameter (2D) that noise stays below 14, where 4 fit. */
static double packed_threshold(const dsmc_scene *s)
{
    double hmax = 0;
    for (int k = 0; k < s->D; k++)
        hmax = fmax(hmax, s->h[k]);
    double mu = s->cell_volume / ((s->D == 2 ? 2 * sqrt(2.0) : sqrt(2.0)) * s->sigma * hmax);
    mu = fmax(mu, (double)dsmc_count(s) / (double)s->ncells);
    const double lim = log(1e-20);
    double lo = floor(mu) + 1, hi = lo + 20 * sqrt(mu) + 100; /* tail(hi) < 1e-20 */
    while (hi - lo > 1) {
        double mid = floor(0.5 * (lo + hi));
        if (poisson_log_tail(mu, mid) < lim)
            hi = mid;
        else
            lo = mid;
    }
    return fmax(dsmc_fit_per_cell(s) + 1, hi);
}

/* Post-collision velocities: the normal component of g = v_i - v_j reversed and scaled by e, the
 * tangential one kept; n from the random impact parameter b (|b| < 2R): sin(theta) = b / 2R is
 * the angle between g and n. 2D: b uniform in [-2R, 2R]. */
static inline void collide_2d(double *vi, double *vj, double gx, double gy, double g, double e1h,
                              rng *r)
{
    double sn = 2 * rng_uniform(r) - 1, cs = sqrt(1 - sn * sn);
    double nx = (cs * gx - sn * gy) / g, ny = (cs * gy + sn * gx) / g;
    double f = e1h * g * cs; /* (1 + e)/2 (g . n) */
    vi[0] -= f * nx;
    vi[1] -= f * ny;
    vj[0] += f * nx;
    vj[1] += f * ny;
}

/* 3D: b uniform over the disk of radius 2R: (a, b) uniform in the unit disk (rejection), so
 * sin^2(theta) = a^2 + b^2 is uniform in [0, 1]. */
static inline void collide_3d(double *vi, double *vj, const double gv[3], double g, double e1h,
                              rng *r)
{
    double u[3] = {gv[0] / g, gv[1] / g, gv[2] / g}, e1[3];
    if (fabs(u[0]) < 0.6) { /* u x (1, 0, 0) */
        e1[0] = 0;
        e1[1] = u[2];
        e1[2] = -u[1];
    } else { /* u x (0, 1, 0) */
        e1[0] = -u[2];
        e1[1] = 0;
        e1[2] = u[0];
    }
    double l = 1 / sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    e1[0] *= l;
    e1[1] *= l;
    e1[2] *= l;
    double e2[3] = {u[1] * e1[2] - u[2] * e1[1], u[2] * e1[0] - u[0] * e1[2],
                    u[0] * e1[1] - u[1] * e1[0]};
    double a, b, s2;
    do {
        a = 2 * rng_uniform(r) - 1;
        b = 2 * rng_uniform(r) - 1;
        s2 = a * a + b * b;
    } while (s2 >= 1);
    double cs = sqrt(1 - s2), f = e1h * g * cs;
    for (int k = 0; k < 3; k++) {
        double nk = cs * u[k] + a * e1[k] + b * e2[k];
        vi[k] -= f * nk;
        vj[k] += f * nk;
    }
}

/* The cell's particles in identity order: P[k] is the k-th (offset from a), returned. Out of
 * memory for a large cell: the arrays themselves are put in order, P = NULL. *heap: to free. */
static inline __attribute__((always_inline)) uint32_t *
cell_order(dsmc_scene *s, size_t a, size_t N, uint64_t kbuf[64], uint32_t pbuf[64], void **heap)
{
    uint32_t *P = pbuf;
    uint64_t *key = kbuf;
    *heap = NULL;
    if (N > 64) {
        *heap = malloc(N * (sizeof *key + sizeof *P));
        key = *heap;
        P = *heap ? (uint32_t *)(key + N) : NULL;
        if (!*heap)
            dsmc_order_cell(s, a, N);
    }
    if (P)
        dsmc_cell_perm(s->id + a, N, key, P);
    return P;
}

/* v_max: twice the largest speed about the cell's mean velocity bounds every pair's relative
 * speed at the start of the step; raised when a collision exceeds it. The mean sums in identity
 * order, so its bits do not depend on the layout. */
static inline __attribute__((always_inline)) double
cell_vmax(double *const V[3], const int D, size_t a, size_t N, const uint32_t *P)
{
    double u[3] = {0, 0, 0};
    for (int k = 0; k < D; k++) {
        const double *vk = V[k] + a;
        double sum = 0;
        for (size_t i = 0; i < N; i++)
            sum += vk[P ? P[i] : i];
        u[k] = sum / (double)N;
    }
    double m2 = 0;
    for (size_t i = 0; i < N; i++) {
        double q = 0;
        for (int k = 0; k < D; k++) {
            double d = V[k][a + i] - u[k];
            q += d * d;
        }
        m2 = q > m2 ? q : m2;
    }
    return 2 * sqrt(m2);
}

/* The excluded volume of a cell of Nd particles: the free volume *Veff (at least 1 % of the cell
 * V_c) or Enskog's *chi (nu at most 0.99 nu_rcp). Returns 1 when the cell's packing was capped. */
static inline __attribute__((always_inline)) long
excluded_volume(dsmc_excluded excl, const int D, double Nd, double vb, double Vc, double rcp,
                double *Veff, double *chi)
{
    long over = 0;
    if (excl == DSMC_EXCLUDED_FREE_VOLUME) {
        *Veff = Vc - Nd * vb / rcp;
        if (*Veff < 0.01 * Vc) {
            *Veff = 0.01 * Vc;
            over++;
        }
    } else if (excl == DSMC_EXCLUDED_ENSKOG) {
        double nu = Nd * vb / Vc;
        if (nu > 0.99 * rcp) {
            nu = 0.99 * rcp;
            over++;
        }
        *chi = D == 2 ? (1 - 7 * nu / 16) / ((1 - nu) * (1 - nu))
                      : (1 - nu / 2) / ((1 - nu) * (1 - nu) * (1 - nu));
    }
    return over;
}

typedef struct pair_counts {
    long collisions, raised;
} pair_counts;

/* The m candidate pairs of the cell's N particles [a, a + N) (P: their identity order), each
 * accepted with probability g / v_max, from the cell's stream r. */
static inline __attribute__((always_inline)) pair_counts
collide_pairs(double *const V[3], const int D, size_t a, size_t N, const uint32_t *P, long m,
              double vmax, double e1h, rng *r)
{
    long collisions = 0, raised = 0;
    for (long t = 0; t < m; t++) {
        size_t i = rng_below(r, N), j = rng_below(r, N - 1);
        if (j >= i)
            j++;
        i = a + (P ? P[i] : i);
        j = a + (P ? P[j] : j);
        double gv[3] = {0, 0, 0}, g2 = 0;
        for (int k = 0; k < D; k++) {
            gv[k] = V[k][i] - V[k][j];
            g2 += gv[k] * gv[k];
        }
        if (g2 > vmax * vmax) {
            vmax = sqrt(g2);
            raised++;
        }
        double z = rng_uniform(r) * vmax;
        if (z * z >= g2 || g2 == 0)
            continue;
        collisions++;
        double g = sqrt(g2);
        if (D == 2) {
            double vi[2] = {V[0][i], V[1][i]}, vj[2] = {V[0][j], V[1][j]};
            collide_2d(vi, vj, gv[0], gv[1], g, e1h, r);
            V[0][i] = vi[0];
            V[1][i] = vi[1];
            V[0][j] = vj[0];
            V[1][j] = vj[1];
        } else {
            double vi[3], vj[3];
            for (int k = 0; k < 3; k++) {
                vi[k] = V[k][i];
                vj[k] = V[k][j];
            }
            collide_3d(vi, vj, gv, g, e1h, r);
            for (int k = 0; k < 3; k++) {
                V[k][i] = vi[k];
                V[k][j] = vj[k];
            }
        }
    }
    return (pair_counts){collisions, raised};
}

/* Cell c of N particles is past close packing: collided all the same, the step completes and
 * the run stops after it. */
static void note_packed(dsmc_verdict *verdict, long c, size_t N)
{
    dsmc_verdict mine;
    dsmc_verdict_clear(&mine);
    mine.packed_cells = 1;
    mine.packed_cell = c;
    mine.packed_n = (int64_t)N;
#pragma omp critical(dsmc_verdict)
    dsmc_verdict_merge(verdict, &mine);
}

/* Cell c of N particles needs M candidate pairs, over the cap: left alone, the run stops. */
static void note_capped(dsmc_verdict *verdict, long c, size_t N, double M)
{
    dsmc_verdict mine;
    dsmc_verdict_clear(&mine);
    mine.capped_cells = 1;
    mine.capped_cell = c;
    mine.capped_n = (int64_t)N;
    mine.capped_m = M;
#pragma omp critical(dsmc_verdict)
    dsmc_verdict_merge(verdict, &mine);
}

dsmc_collide_totals dsmc_collide(dsmc_scene *s, double dt, dsmc_verdict *verdict)
{
    const int D = s->D;
    const long c_lo = (long)s->cell_lo, nc = (long)s->cell_hi;
    const size_t *start = s->start;
    double *rem = s->remainder;
    double *V[3] = {s->v[0], s->v[1], s->v[2]};
    const double e1h = 0.5 * (1 + s->def.restitution);
    const double base = s->sigma * dt / 2, Vc = s->cell_volume;
    const double vb = s->vpart, rcp = s->def.packing_limit;
    const dsmc_excluded excl = s->def.excluded;
    const uint64_t seed = s->def.seed, step = (uint64_t)s->steps;
    const size_t packed = (size_t)packed_threshold(s);
    long attempts = 0, collisions = 0, raised = 0, overpacked = 0, overflow = 0;
    dsmc_verdict_clear(verdict);
#pragma omp parallel for schedule(dynamic, 64) \
    reduction(+ : attempts, collisions, raised, overpacked, overflow) if (s->n >= DSMC_PARALLEL_MIN)
    for (long c = c_lo; c < nc; c++) {
        size_t a = start[c], N = start[c + 1] - a;
        if (N < 2)
            continue;
        if (N >= packed)
            note_packed(verdict, c, N);
        uint64_t kbuf[64];
        uint32_t pbuf[64];
        void *heap;
        const uint32_t *P = cell_order(s, a, N, kbuf, pbuf, &heap);
        double vmax = cell_vmax(V, D, a, N, P);
        if (vmax == 0) {
            free(heap);
            continue;
        }
        double Nd = (double)N, Veff = Vc, chi = 1;
        overpacked += excluded_volume(excl, D, Nd, vb, Vc, rcp, &Veff, &chi);
        double M = Nd * (Nd - 1) * base * vmax * chi / Veff + rem[c];
        if (!(M < 1e15)) { /* speeds near the overflow (or not finite): the step fails */
            overflow++;
            free(heap);
            continue;
        }
        /* dt far above the cell's collision time. The cap counts the candidates of the dilute
         * limit: chi is bounded (the free volume at 1 % of the cell, Enskog's at 0.99 nu_rcp),
         * and a few particles over the free volume of a small cell, a Poisson fluctuation of a
         * valid gas, must not trip it. */
        if (M * Veff > DSMC_CANDIDATES_PER_PARTICLE * Nd * Vc * chi) {
            note_capped(verdict, c, N, M);
            free(heap);
            continue;
        }
        double Mi = floor(M);
        rem[c] = M - Mi;
        long m = (long)Mi;
        if (m == 0) {
            free(heap);
            continue;
        }
        rng r;
        dsmc_stream(&r, seed, DSMC_STREAM_COLLIDE, step, (uint64_t)c);
        attempts += m;
        pair_counts pc = collide_pairs(V, D, a, N, P, m, vmax, e1h, &r);
        collisions += pc.collisions;
        raised += pc.raised;
        free(heap);
    }
    return (dsmc_collide_totals){attempts, collisions, raised, overpacked, overflow};
}
