/* DSMC measurements: moments of the velocity distribution (temperature, kurtosis, a2), the
 * kinetic-theory collision frequency, per-cell fields, layer profiles and histograms. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
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

/* Sums over the particles of each block of this rank (block b at out[(b - blk_lo) * 4]):
 * pass 0: sum v_k (k < D) and sum |v|^2; pass 1: sum |v - u|^2 and |v - u|^4. */
static void block_sums(const dsmc_scene *s, int pass, const double *u, double *out)
{
    const int D = s->D;
    const long b0 = (long)s->blk_lo, b1 = (long)s->blk_hi;
#pragma omp parallel for schedule(dynamic, 16) if (s->n >= 200000)
    for (long b = b0; b < b1; b++) {
        size_t c0 = (size_t)b << s->blk_shift, c1 = ((size_t)b + 1) << s->blk_shift;
        c1 = c1 < s->ncells ? c1 : s->ncells;
        size_t a = s->start[c0], e = s->start[c1];
        double *o = out + (b - b0) * 4;
        o[0] = o[1] = o[2] = o[3] = 0;
        if (pass == 0) {
            double sum[3] = {0, 0, 0}, ke = 0;
            for (int k = 0; k < D; k++)
                for (size_t i = a; i < e; i++) {
                    sum[k] += s->v[k][i];
                    ke += s->v[k][i] * s->v[k][i];
                }
            o[0] = sum[0];
            o[1] = sum[1];
            o[2] = sum[2];
            o[3] = ke;
        } else {
            peculiar_sums(s, a, e - a, u, &o[0], &o[1]);
        }
    }
}

/* Per block, then blocks in order (dsmc_block_sum): the same bits on any number of ranks. */
void dsmc_measure_moments(const dsmc_scene *s, dsmc_moments *out)
{
    memset(out, 0, sizeof *out);
    const int D = s->D;
    size_t n = dsmc_count(s);
    out->n = n;
    if (n == 0) {
        out->kurtosis = out->a2 = NAN;
        return;
    }
    size_t nb = s->blk_hi - s->blk_lo;
    double *part = malloc((nb ? nb : 1) * 4 * sizeof *part), tot[4] = {0, 0, 0, 0}, u[3] = {0, 0, 0};
    core_error err;
    int ok = part != NULL;
    if (s->distributed)
        ok = comm_all(ok);
    if (ok) {
        block_sums(s, 0, NULL, part);
        ok = dsmc_block_sum(s, part, 4, tot, &err) == CORE_OK;
    }
    for (int k = 0; k < D; k++) {
        u[k] = tot[k] / (double)n;
        out->mean_velocity[k] = u[k];
        out->momentum[k] = s->mass * tot[k];
    }
    out->kinetic_energy = 0.5 * s->mass * tot[3];
    if (ok) {
        block_sums(s, 1, u, part);
        ok = dsmc_block_sum(s, part, 4, tot, &err) == CORE_OK;
    }
    free(part);
    if (!ok) { /* out of memory for a few kilobytes, on some rank: every rank says so */
        out->temperature = out->t_over_m = out->kinetic_energy = out->kurtosis = out->a2 = NAN;
        return;
    }
    double m2 = tot[0] / (double)n, m4 = tot[1] / (double)n;
    out->t_over_m = m2 / D;
    out->temperature = s->mass * out->t_over_m;
    out->kurtosis = m2 > 0 ? m4 / (m2 * m2) : NAN;
    out->a2 = (double)D / (D + 2) * out->kurtosis - 1;
}

double dsmc_collision_frequency(const dsmc_scene *s)
{
    size_t N = dsmc_count(s);
    if (N < 2)
        return 0;
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    double V = dsmc_volume(s), n = (double)(N - 1) / V;
    double chi = dsmc_chi(s, (double)N * s->vpart / V), sd = 2 * s->def.radius;
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
