/* The DSMC run (paper Sec. 4): the step's stages in order — free flight (flight.c), the sort
 * into cells (sort.c), the collisions of Eq. 1 (collide.c) — with the migration of a distributed
 * run between flight and collisions (domain.c), the checks that stop a run, and its statistics.
 * Every stage gives the same bits on any number of threads and MPI ranks. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/comm.h"
#include "core/interrupt.h"
#include "core/threads.h"
#include "dsmc/dsmc_internal.h"

dsmc_run_def dsmc_default_run_def(void)
{
    return (dsmc_run_def){.steps = 0, .dt = 0, .time_end = -1};
}

static bool verdict_any(const dsmc_verdict *v)
{
    return v->packed_cells || v->capped_cells || v->stranded;
}

/* The likely cause of values out of range, from the run's numbers only (every rank gives the
 * same words): DSMC's collisions conserve or lose energy, so only a huge step, gravity or speed
 * given can overflow. */
static void out_of_range(const dsmc_scene *s, double dt, char *buf, size_t n)
{
    double g = 0, L = INFINITY;
    for (int k = 0; k < s->D; k++) {
        g += s->def.gravity[k] * s->def.gravity[k];
        L = fmin(L, s->h[k] * s->def.cells[k]);
    }
    g = sqrt(g);
    if (g > 0 && 0.5 * g * dt * dt > L)
        snprintf(buf, n,
                 "the time step dt = %.3g s is out of range for the gravity: one step moves a "
                 "particle |g| dt^2 / 2 = %.3g m against a box of %.3g m; use dt = \"auto\" or a "
                 "smaller dt",
                 dt, 0.5 * g * dt * dt, L);
    else
        snprintf(buf, n,
                 "the time step dt = %.3g s or the speeds given are out of range (speeds near the "
                 "largest double); use dt = \"auto\" and speeds of the gas's scale",
                 dt);
}

static core_status overflow_error(const dsmc_scene *s, double dt, core_error *err)
{
    char cause[300];
    out_of_range(s, dt, cause, sizeof cause);
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "step %ld (t = %.6g s): a cell's number of collision candidates overflowed "
                     "(relative speeds near the largest double); likely cause: %s",
                     s->steps - 1, s->t, cause);
}

/* "x 0.075-0.08 m, y 0-0.005 m": where cell c lies. */
static void cell_where(const dsmc_scene *s, int64_t c, char *buf, size_t size)
{
    size_t len = 0;
    for (int k = 0; k < s->D && len < size; k++) {
        int64_t i = c % s->def.cells[k];
        c /= s->def.cells[k];
        double a = s->def.lo[k] + (double)i * s->h[k];
        int w = snprintf(buf + len, size - len, "%s%c %.4g-%.4g m", k ? ", " : "", "xyz"[k], a,
                         a + s->h[k]);
        len += w > 0 ? (size_t)w : 0;
    }
}

/* The verdict on the step just completed (agreed over ranks first: collective when multi) as
 * the run's error, with the numbers and the likely cause. */
static core_status verdict_error(const dsmc_scene *s, dsmc_verdict *v, bool multi, double dt,
                                 core_error *err)
{
    if (multi) {
        void *all = NULL;
        size_t bytes = 0;
        if (comm_allgatherv(v, sizeof *v, &all, &bytes, NULL))
            return core_fail(err, CORE_ERR_NOMEM, "step %ld: out of memory gathering the "
                             "verdict of the ranks", s->steps - 1);
        dsmc_verdict m;
        dsmc_verdict_clear(&m);
        for (size_t r = 0; r < bytes / sizeof *v; r++) {
            dsmc_verdict one;
            memcpy(&one, (char *)all + r * sizeof *v, sizeof one);
            dsmc_verdict_merge(&m, &one);
        }
        free(all);
        *v = m;
    }
    const long step = s->steps - 1;
    char where[160], more[64] = "";
    if (v->packed_cells) {
        cell_where(s, v->packed_cell, where, sizeof where);
        if (v->packed_cells > 1)
            snprintf(more, sizeof more, " (and %lld more cells)", (long long)v->packed_cells - 1);
        bool grav = false;
        for (int k = 0; k < s->D; k++)
            grav = grav || s->def.gravity[k] != 0;
        const double e = s->def.restitution, hd = s->h[0] / (2 * s->def.radius);
        char cause[160];
        const char *advice = "use a restitution nearer 1, a stronger drive or fewer particles";
        if (e < 1)
            snprintf(cause, sizeof cause, "inelastic collapse (restitution %g)%s", e,
                     grav ? " under gravity" : "");
        else if (grav)
            snprintf(cause, sizeof cause, "gravity packing a bed its walls do not keep fluid");
        else {
            snprintf(cause, sizeof cause, "particles placed or moved there (an elastic gas "
                                          "does not cluster)");
            advice = "spread the particles over a larger region";
        }
        return core_fail(err, CORE_ERR_UNSTABLE,
                         "step %ld (t = %.6g s): the cell at %s holds %lld particles, a "
                         "packing fraction of %.3g where at most %.0f fit at the packing limit "
                         "%g: a state past close packing%s (DSMC keeps no distance between "
                         "particles). Likely cause: %s, in cells (%.3g diameters) wider than a "
                         "cluster's mean free path; %s",
                         step, s->t, where, (long long)v->packed_n,
                         (double)v->packed_n * s->vpart / s->cell_volume, dsmc_fit_per_cell(s),
                         s->def.packing_limit, more, cause, hd, advice);
    }
    if (v->capped_cells) {
        cell_where(s, v->capped_cell, where, sizeof where);
        if (v->capped_cells > 1)
            snprintf(more, sizeof more, " (and %lld more cells)", (long long)v->capped_cells - 1);
        return core_fail(err, CORE_ERR_UNSTABLE,
                         "step %ld (t = %.6g s): the cell at %s holds %lld particles and needs "
                         "%.3g candidate pairs in one step, over the limit of %d per particle%s: "
                         "dt = %g s is far above the collision time there, and those cells' "
                         "collisions were not done; use a smaller dt (dt = 'auto' is a tenth "
                         "of the mean collision time)",
                         step, s->t, where, (long long)v->capped_n, v->capped_m,
                         DSMC_CANDIDATES_PER_PARTICLE, more, dt);
    }
    if (v->stranded > 1)
        snprintf(more, sizeof more, " (and %lld more)", (long long)v->stranded - 1);
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "step %ld (t = %.6g s): particle %lld%s crossed the walls of the box more "
                     "than 4 times in one step of dt = %g s and was put on a wall: dt is far "
                     "above the flight time across the box; use a smaller dt",
                     step, s->t, (long long)v->strand_id, more, dt);
}

/* A run's state between its steps. */
typedef struct run_state {
    bool multi; /* several ranks: every decision (stop, rebalance) is taken by all together */
    double c0, w0;  /* CPU and wall clock at the start */
    comm_stats cs0; /* communication at the start */
    /* this rank's counts for the run, added to the statistics at the end (summed over ranks) */
    int64_t cnt[6]; /* moves, wall hits, attempts, collisions, raised, over */
    long nsteps;
    double tsum;
    bool sorted;          /* the arrays are sorted by cell (not between a flight and its sort) */
    int64_t lost;         /* particles this rank could not store at the last migration */
    int64_t overflow;     /* cells of the last step whose collision count overflowed */
    dsmc_verdict verdict; /* this rank's verdict on the last step */
    double last_dt;
} run_state;

static void run_start(run_state *rs, bool multi, double dt)
{
    memset(rs, 0, sizeof *rs);
    rs->multi = multi;
    rs->c0 = clock_cpu();
    rs->w0 = clock_wall();
    comm_get_stats(&rs->cs0);
    rs->sorted = true;
    dsmc_verdict_clear(&rs->verdict);
    rs->last_dt = dt;
}

/* Several ranks, between steps: the interrupt (*intr), the last step's overflow, verdict and
 * lost particles agreed over the ranks, then the rebalance. Not CORE_OK: the run stops. */
static core_status agree_between_steps(dsmc_scene *s, const dsmc_run_def *run, run_state *rs,
                                       int *intr, core_error *err)
{
    core_status st = CORE_OK;
    int64_t q[5] = {*intr, (int64_t)s->n, rs->lost, rs->overflow, verdict_any(&rs->verdict)};
    comm_max_i64(q, 5);
    *intr = q[0] != 0;
    if (q[3])
        return overflow_error(s, run->dt, err);
    if (q[4]) {
        st = verdict_error(s, &rs->verdict, true, rs->last_dt, err);
        dsmc_verdict_clear(&rs->verdict);
        return st;
    }
    if (q[2]) {
        rs->sorted = false;
        return core_fail(err, CORE_ERR_NOMEM,
                         "step %ld: out of memory on a rank storing %lld particles that "
                         "migrated to it; the scene is incomplete",
                         s->steps - 1, (long long)q[2]);
    }
    if (!*intr && (st = dsmc_domain_balance(s, q[1], err)))
        rs->sorted = false; /* out of memory, maybe in the middle of a migration */
    return st;
}

/* One step: flight, the migration (several ranks), sort and collisions, then the counts. Not
 * CORE_OK: the run stops (on one rank also after a step whose verdict stops it). */
static core_status run_step(dsmc_scene *s, const dsmc_run_def *run, run_state *rs, long *done,
                            core_error *err)
{
    core_status st = CORE_OK;
    const bool multi = rs->multi;
    double dt = run->dt;
    if (run->time_end >= 0 && s->t + dt > run->time_end)
        dt = run->time_end - s->t;
    size_t bcount[DSMC_SORT_BLOCKS];
    dsmc_flight_totals ft = dsmc_flight(s, dt, bcount);
    rs->sorted = false;
    int bad = ft.bad;
    /* one synchronisation between flight and collisions: the migration, with the verdict */
    if (multi && (st = dsmc_domain_migrate(s, bcount, &bad, &rs->lost, err)))
        return st;
    if (bad) {
        char cause[300];
        out_of_range(s, dt, cause, sizeof cause);
        return core_fail(err, CORE_ERR_UNSTABLE,
                         "step %ld (t = %.6g s): a particle's position or velocity is not "
                         "finite; likely cause: %s",
                         s->steps, s->t, cause);
    }
    dsmc_sort_counted(s, bcount);
    rs->sorted = true;
    dsmc_collide_totals ct = dsmc_collide(s, dt, &rs->verdict);
    rs->verdict.stranded = ft.stranded;
    rs->verdict.strand_id = ft.strand_id == LONG_MAX ? INT64_MAX : ft.strand_id;
    rs->last_dt = dt;
    s->t += dt;
    s->steps++;
    ++*done;
    rs->overflow = ct.overflow; /* several ranks: agreed at the next reduction */
    if (!multi && rs->overflow)
        return overflow_error(s, run->dt, err);
    rs->nsteps++;
    rs->tsum += dt;
    rs->cnt[0] += (int64_t)s->n;
    rs->cnt[1] += ft.wall_hits;
    rs->cnt[2] += ct.attempts;
    rs->cnt[3] += ct.collisions;
    rs->cnt[4] += ct.raised;
    rs->cnt[5] += ct.overpacked;
    threads_tune_step();
    if (!multi && verdict_any(&rs->verdict)) /* several ranks: at the next reduction */
        return verdict_error(s, &rs->verdict, false, dt, err);
    return CORE_OK;
}

/* After the last step: the arrays put in cell and identity order, the last step's verdict of a
 * distributed run, and the run's counts and times added to the statistics. Returns st, or the
 * error the last step's agreement found. */
static core_status run_finish(dsmc_scene *s, const dsmc_run_def *run, run_state *rs,
                              core_status st, core_error *err)
{
    const bool multi = rs->multi;
    int64_t *cnt = rs->cnt;
    /* between runs the arrays are in cell then identity order, for everything that reads them
     * (unless a step stopped between its flight and its sort: non-finite, or out of memory) */
    if (rs->sorted)
        dsmc_order_cells(s);
    double cpu = clock_cpu() - rs->c0, wall = clock_wall() - rs->w0;
    comm_stats cs1;
    comm_get_stats(&cs1);
    /* summed: CPU of all ranks, bytes and messages they sent; the slowest: wall time, time in
     * communication, particles held (the imbalance) */
    double sum[3] = {cpu, cs1.bytes - rs->cs0.bytes, cs1.messages - rs->cs0.messages};
    double most[6] = {wall, cs1.seconds - rs->cs0.seconds, (double)s->n, (double)rs->lost,
                      (double)rs->overflow, (double)(multi && verdict_any(&rs->verdict))};
    if (s->distributed) {
        comm_sum_i64(cnt, 6);
        comm_sum_double(sum, 3);
        comm_max_double(most, 6);
    }
    if (s->distributed && st == CORE_OK && most[4] > 0) /* at the last step */
        st = overflow_error(s, run->dt, err);
    if (s->distributed && st == CORE_OK && most[5] > 0)
        st = verdict_error(s, &rs->verdict, true, rs->last_dt, err);
    if (most[3] > 0 && st == CORE_OK)
        st = core_fail(err, CORE_ERR_NOMEM,
                       "out of memory on a rank storing %.0f particles that migrated to it; "
                       "the scene is incomplete",
                       most[3]);
    cpu = sum[0];
    wall = most[0];
    s->stats.comm_bytes += sum[1];
    s->stats.comm_messages += sum[2];
    s->stats.comm_s += most[1];
    s->stats.imbalance = dsmc_count(s) ? most[2] * comm_size() / (double)dsmc_count(s) : 1;
    s->stats.steps += rs->nsteps;
    s->stats.particle_moves += (double)cnt[0];
    s->stats.wall_hits += (double)cnt[1];
    s->stats.attempts += (double)cnt[2];
    s->stats.collisions += (double)cnt[3];
    s->stats.vmax_raised += (double)cnt[4];
    s->stats.cells_overpacked += (double)cnt[5];
    s->stats.time += rs->tsum;
    s->total_collisions += (double)cnt[3];
    s->stats.cpu_s += cpu;
    s->stats.wall_s += wall;
    return st;
}

core_status dsmc_run(dsmc_scene *s, const dsmc_run_def *run, long *done, core_error *err)
{
    *done = 0;
    if (!(run->dt > 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be positive, got %g", run->dt);
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    const bool multi = comm_size() > 1;
    core_status st = CORE_OK;
    if (multi && (st = dsmc_domain_split(s, err)))
        return st;
    run_state rs;
    run_start(&rs, multi, run->dt);
    /* A step gives the same bits on any thread count: the tuner may choose it (core/threads.h)
     * when the step runs threaded. */
    threads_tune_begin(s, s->n >= DSMC_PARALLEL_MIN);
    while (*done < run->steps) {
        if (run->time_end >= 0 && s->t >= run->time_end * (1 - 1e-14))
            break;
        int intr = interrupt_pending();
        if (multi && (st = agree_between_steps(s, run, &rs, &intr, err)))
            break;
        if (intr) {
            st = core_fail(err, CORE_ERR_INTERRUPTED,
                           "interrupted at step %ld (t = %.6g s); the scene is intact", s->steps,
                           s->t);
            break;
        }
        if ((st = run_step(s, run, &rs, done, err)))
            break;
    }
    threads_tune_end();
    return run_finish(s, run, &rs, st, err);
}

void dsmc_get_stats(const dsmc_scene *s, dsmc_stats *out) { *out = s->stats; }
void dsmc_reset_stats(dsmc_scene *s) { memset(&s->stats, 0, sizeof s->stats); }
