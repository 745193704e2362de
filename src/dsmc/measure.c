/* DSMC measurements: moments of the velocity distribution (temperature, kurtosis, a2), the
 * kinetic-theory collision frequency, per-cell fields, layer profiles and histograms. */
#include <math.h>
#include <string.h>

#include "dsmc/dsmc_internal.h"

/* Sums of |c|^2 and |c|^4 over particles a .. a + N - 1, c = v - u the peculiar velocity. */
static void peculiar_sums(const dsmc_scene *s, size_t a, size_t N, const double *u, double *s2,
                          double *s4)
{
    double q2 = 0, q4 = 0;
    for (size_t i = a; i < a + N; i++) {
        double q = 0;
        for (int k = 0; k < s->D; k++) {
            double d = s->v[k][i] - u[k];
            q += d * d;
        }
        q2 += q;
        q4 += q * q;
    }
    *s2 = q2;
    *s4 = q4;
}

void dsmc_measure_moments(const dsmc_scene *s, dsmc_moments *out)
{
    memset(out, 0, sizeof *out);
    const int D = s->D;
    size_t n = s->n;
    out->n = n;
    if (n == 0) {
        out->kurtosis = out->a2 = NAN;
        return;
    }
    double sum[3] = {0, 0, 0}, ke = 0;
    for (int k = 0; k < D; k++)
        for (size_t i = 0; i < n; i++) {
            sum[k] += s->v[k][i];
            ke += s->v[k][i] * s->v[k][i];
        }
    double u[3] = {0, 0, 0};
    for (int k = 0; k < D; k++) {
        u[k] = sum[k] / (double)n;
        out->mean_velocity[k] = u[k];
        out->momentum[k] = s->mass * sum[k];
    }
    out->kinetic_energy = 0.5 * s->mass * ke;
    double s2, s4;
    peculiar_sums(s, 0, n, u, &s2, &s4);
    double m2 = s2 / (double)n, m4 = s4 / (double)n;
    out->t_over_m = m2 / D;
    out->temperature = s->mass * out->t_over_m;
    out->kurtosis = m2 > 0 ? m4 / (m2 * m2) : NAN;
    out->a2 = (double)D / (D + 2) * out->kurtosis - 1;
}

double dsmc_collision_frequency(const dsmc_scene *s)
{
    if (s->n < 2)
        return 0;
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    double V = dsmc_volume(s), n = (double)(s->n - 1) / V;
    double chi = dsmc_chi(s, (double)s->n * s->vpart / V), sd = 2 * s->def.radius;
    double w = s->D == 2 ? 2 * sqrt(DSMC_PI) * n * sd : 4 * sqrt(DSMC_PI) * n * sd * sd;
    return w * chi * sqrt(m.t_over_m);
}

void dsmc_measure_fields(const dsmc_scene *s, const dsmc_fields *f)
{
    const int D = s->D;
    const double Vc = s->cell_volume;
    for (size_t c = 0; c < s->ncells; c++) {
        size_t a = s->start[c], N = s->start[c + 1] - a;
        double u[3] = {0, 0, 0};
        for (int k = 0; k < D; k++) {
            for (size_t i = a; i < a + N; i++)
                u[k] += s->v[k][i];
            u[k] = N ? u[k] / (double)N : NAN;
        }
        double s2, s4;
        peculiar_sums(s, a, N, u, &s2, &s4);
        if (f->count)
            f->count[c] = (double)N;
        if (f->density)
            f->density[c] = (double)N / Vc;
        if (f->packing)
            f->packing[c] = (double)N * s->vpart / Vc;
        for (int k = 0; k < D; k++)
            if (f->u[k])
                f->u[k][c] = u[k];
        if (f->temperature)
            f->temperature[c] = N >= 2 ? s->mass * s2 / (D * (double)(N - 1)) : NAN;
        if (f->a2) {
            double m2 = s2 / (double)N, m4 = s4 / (double)N;
            f->a2[c] = N >= 2 && m2 > 0 ? (double)D / (D + 2) * m4 / (m2 * m2) - 1 : NAN;
        }
    }
}

core_status dsmc_measure_profile(const dsmc_scene *s, int axis, int nbins, double *center,
                                 double *count, double *density, double *packing,
                                 double *temperature, core_error *err)
{
    const int D = s->D;
    if (axis < 0 || axis >= D)
        return core_fail(err, CORE_ERR_ARG, "axis must be in [1, %d], got %d", D, axis + 1);
    if (nbins < 1)
        return core_fail(err, CORE_ERR_ARG, "bins must be >= 1, got %d", nbins);
    double lo = s->def.lo[axis], w = (s->def.hi[axis] - lo) / nbins;
    double layer = w * dsmc_volume(s) / (s->def.hi[axis] - lo);
    for (int b = 0; b < nbins; b++) {
        double N = 0, sv[3] = {0, 0, 0}, sq = 0;
        for (size_t i = 0; i < s->n; i++) {
            int bi = (int)floor((s->x[axis][i] - lo) / w);
            bi = bi < 0 ? 0 : bi >= nbins ? nbins - 1 : bi;
            if (bi != b)
                continue;
            N++;
            for (int k = 0; k < D; k++) {
                sv[k] += s->v[k][i];
                sq += s->v[k][i] * s->v[k][i];
            }
        }
        double u2 = 0;
        for (int k = 0; k < D; k++)
            u2 += N > 0 ? sv[k] * sv[k] / N : 0;
        if (center)
            center[b] = lo + (b + 0.5) * w;
        if (count)
            count[b] = N;
        if (density)
            density[b] = N / layer;
        if (packing)
            packing[b] = N * s->vpart / layer;
        if (temperature)
            temperature[b] = N >= 2 ? s->mass * (sq - u2) / (D * (N - 1)) : NAN;
    }
    return CORE_OK;
}

core_status dsmc_measure_histogram(const dsmc_scene *s, int what, int nbins, double lo,
                                   double hi, double *counts, double *outside, core_error *err)
{
    if (nbins < 1)
        return core_fail(err, CORE_ERR_ARG, "bins must be >= 1, got %d", nbins);
    if (!(hi > lo) || !isfinite(lo) || !isfinite(hi))
        return core_fail(err, CORE_ERR_ARG, "range [%g, %g] is empty", lo, hi);
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    const int D = s->D;
    double w = (hi - lo) / nbins, out = 0;
    for (int b = 0; b < nbins; b++)
        counts[b] = 0;
    for (size_t i = 0; i < s->n; i++) {
        double q = 0;
        for (int k = 0; k < D; k++) {
            double d = s->v[k][i] - m.mean_velocity[k];
            if (what == 0) {
                double f = floor((d - lo) / w);
                if (f >= 0 && f < nbins)
                    counts[(int)f]++;
                else
                    out++;
            }
            q += d * d;
        }
        if (what == 1) {
            double f = floor((sqrt(q) - lo) / w);
            if (f >= 0 && f < nbins)
                counts[(int)f]++;
            else
                out++;
        }
    }
    if (outside)
        *outside = out;
    return CORE_OK;
}
