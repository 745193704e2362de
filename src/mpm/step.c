/* The MPM time step's driver (Sec. 2 of the paper, steps 1-3): the run loop with Ctrl-C and the
 * instability checks, the CFL time step, the step context (threads, their point ranges and
 * scratch, the stage timings), and each update scheme's and contact model's step as a table of
 * stages (transfer.c, contact.c, stress.c) run in one parallel region. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/clock.h"
#include "core/interrupt.h"
#include "core/threads.h"
#include "mpm/step_internal.h"

#ifdef GRAINLAB_HAVE_OPENMP
#include <omp.h>
#define THREAD_ID() omp_get_thread_num()
#else
#define THREAD_ID() 0
#endif

enum { T_STENCIL, T_P2G, T_NORMALS, T_GRID, T_CONTACT, T_G2P, T_REMAP, T_MATERIAL, T_CHECK };
const char *const mpm_stage_names[MPM_NSTAGES] = {"stencil", "p2g",   "normals",  "grid", "contact",
                                                  "g2p",     "remap", "material", "check"};

void mpm_timings(const mpm_scene *s, double seconds[MPM_NSTAGES], long *steps)
{
    const mpm_step *ctx = s->step;
    for (int k = 0; k < MPM_NSTAGES; k++)
        seconds[k] = ctx ? ctx->tstage[k] : 0;
    *steps = ctx ? ctx->tsteps : 0;
}

/* n grain-aligned ranges of about np / n points each: range t is points [tp[t], tp[t+1]), its
 * first grain tg[t] (tg may be NULL). */
static void grain_ranges(const mpm_scene *s, int n, size_t *tp, size_t *tg)
{
    size_t g = 0, gprev = 0;
    tp[0] = 0;
    if (tg)
        tg[0] = 0;
    for (int t = 1; t < n; t++) {
        const size_t want = s->np * (size_t)t / (size_t)n;
        while (g < s->ngrains && s->gstart[g] + s->gcount[g] <= want)
            g++;
        if (g < s->ngrains && want - s->gstart[g] > s->gstart[g] + s->gcount[g] - want)
            g++; /* the boundary nearer to the target */
        if (g <= gprev)
            g = gprev + 1 < s->ngrains ? gprev + 1 : s->ngrains;
        gprev = g;
        if (tg)
            tg[t] = g;
        tp[t] = g < s->ngrains ? s->gstart[g] : s->np;
    }
    if (tg)
        tg[n] = s->ngrains;
    tp[n] = s->np;
}

/* A thread or chunk count for this scene: n within [1, min(64, grains)], 1 below 8192 points. */
static int clamp_count(const mpm_scene *s, int n)
{
    if (s->np < 8192)
        n = 1;
    if (n > 64)
        n = 64;
    if (n > (int)s->ngrains)
        n = (int)s->ngrains;
    return n < 1 ? 1 : n;
}

/* The frictional scatter's per-thread scratch (records and factors of the largest grain) and
 * the per-grain pair ranges, sized for the current grains and ctx->ntcap threads. */
static core_status contact_scratch(const mpm_scene *s, mpm_step *ctx, core_error *err)
{
    /* a grain has at most ns pairs per point */
    size_t gmax = 1;
    for (size_t g = 0; g < s->ngrains; g++)
        gmax = s->gcount[g] > gmax ? s->gcount[g] : gmax;
    const size_t need = (size_t)s->ns * gmax;
    if (need > ctx->reccap) {
        free(ctx->trec);
        const size_t bytes = (size_t)ctx->ntcap * (need + 1) * sizeof(struct mpm_pair_rec);
        ctx->trec = aligned_alloc(64, (bytes + 63) / 64 * 64);
        free(ctx->tfin);
        ctx->tfin = malloc((size_t)ctx->ntcap * need * sizeof *ctx->tfin);
        ctx->reccap = ctx->trec && ctx->tfin ? need : 0;
        if (!ctx->trec || !ctx->tfin)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact records", need);
    }
    if (s->ngrains > ctx->gpcap) {
        size_t **per_grain[2] = {&ctx->gps, &ctx->gpc};
        for (int k = 0; k < 2; k++) {
            size_t *a = realloc(*per_grain[k], s->ngrains * sizeof *a);
            if (!a)
                return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu grains", s->ngrains);
            *per_grain[k] = a;
        }
        ctx->gpcap = s->ngrains;
    }
    if (gmax > ctx->faccap) {
        free(ctx->tfac);
        const size_t bytes = (size_t)ctx->ntcap * gmax * sizeof(struct mpm_point_fac);
        ctx->tfac = aligned_alloc(64, (bytes + 63) / 64 * 64);
        ctx->faccap = ctx->tfac ? gmax : 0;
        if (!ctx->tfac)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %zu contact records", gmax);
    }
    return CORE_OK;
}

/* Threads: every parallel region runs ctx->nt threads, thread t on points [tp[t], tp[t+1]); the
 * noslip transfers scatter by chunks (step_internal.h). The ranges and all reductions are fixed
 * for a thread count (friction: for any thread count; noslip: for a chunk count), so results are
 * the same bits run after run. */
static core_status threads_setup(const mpm_scene *s, mpm_step *ctx, core_error *err)
{
    const int nt = clamp_count(s, threads_get());
    const int nc = s->contact == MPM_CONTACT_FRICTION ? 1 : clamp_count(s, threads_max());
    if (nc > ctx->nccap || !ctx->cp) {
        size_t *a = realloc(ctx->cp, (size_t)(nc + 1) * sizeof *a);
        if (!a)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d chunks", nc);
        ctx->cp = a;
        free(ctx->tbuf);
        ctx->tbuf = malloc((size_t)nc * 2 * s->nnodes * sizeof *ctx->tbuf);
        free(ctx->nrec);
        const size_t bytes = (size_t)nc * s->nnodes * sizeof *ctx->nrec;
        ctx->nrec = aligned_alloc(64, (bytes + 63) / 64 * 64);
        if (!ctx->tbuf || !ctx->nrec)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d chunks", nc);
        ctx->nccap = nc;
    }
    ctx->nc = nc;
    grain_ranges(s, nc, ctx->cp, NULL);
    if (nt > ctx->ntcap || !ctx->tp) {
        size_t **ranges[4] = {&ctx->tp, &ctx->tg, &ctx->tq, &ctx->tc};
        for (int r = 0; r < 4; r++) {
            size_t *a = realloc(*ranges[r], (size_t)(nt + 1) * sizeof *a);
            if (!a)
                return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
            *ranges[r] = a;
        }
        free(ctx->tmark);
        /* per thread nnodes + 1 marks: the last stays -1 (grain_scatter) */
        ctx->tmark = malloc((size_t)nt * (s->nnodes + 1) * sizeof *ctx->tmark);
        if (!ctx->tmark)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
        for (size_t i = 0; i < (size_t)nt * (s->nnodes + 1); i++)
            ctx->tmark[i] = -1;
        free(ctx->tnear);
        ctx->tnear = calloc((size_t)nt * s->nnodes, 1);
        if (!ctx->tnear)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for %d threads", nt);
        ctx->ntcap = nt;
        ctx->reccap = ctx->faccap = 0; /* the records below are per thread */
    }
    ctx->nt = nt;
    grain_ranges(s, nt, ctx->tp, ctx->tg);
    for (int u = 0; u <= nt; u++)
        ctx->tq[u] = (size_t)s->ns * ctx->tp[u]; /* thread u's pairs (friction), grain_scatter */
    if (s->contact == MPM_CONTACT_FRICTION)
        return contact_scratch(s, ctx, err);
    return CORE_OK;
}

void mpm_step_free(mpm_step *ctx)
{
    if (!ctx)
        return;
    size_t *ranges[] = {ctx->tp, ctx->tg, ctx->tq, ctx->tc, ctx->gps, ctx->gpc, ctx->cp};
    for (size_t k = 0; k < sizeof ranges / sizeof *ranges; k++)
        free(ranges[k]);
    free(ctx->tmark);
    free(ctx->tnear);
    free(ctx->trec);
    free(ctx->tfin);
    free(ctx->tfac);
    free(ctx->tbuf);
    free(ctx->nrec);
    free(ctx);
}

mpm_run_def mpm_default_run_def(void)
{
    return (mpm_run_def){.steps = 0, .time_end = -1, .dt = 0, .cfl = MPM_DEFAULT_CFL};
}

static double max_speed(const mpm_scene *s)
{
    double v2 = 0;
#pragma omp parallel for schedule(static) reduction(max : v2) if (s->np > 8192)
    for (size_t p = 0; p < s->np; p++) {
        double w = s->vx[p] * s->vx[p] + s->vy[p] * s->vy[p];
        if (w > v2)
            v2 = w;
    }
    return sqrt(v2);
}

core_status mpm_timestep_info(const mpm_scene *s, double cfl, mpm_timestep *out, core_error *err)
{
    if (!(cfl > 0 && cfl <= 1))
        return core_fail(err, CORE_ERR_ARG, "cfl must be in (0, 1], got %g", cfl);
    if (s->np == 0)
        return core_fail(err, CORE_ERR_STATE,
                         "the scene has no material points: add a grain first");
    double c = 0;
    for (size_t g = 0; g < s->ngrains; g++) {
        double cg = mpm_wave_speed(&s->mats[s->mat[s->gstart[g]]]);
        if (cg > c)
            c = cg;
    }
    out->wave_speed = c;
    out->max_speed = max_speed(s);
    double h = s->hx < s->hy ? s->hx : s->hy;
    out->limit = h / (c + out->max_speed);
    out->dt_auto = cfl * out->limit;
    return CORE_OK;
}

/* Whether the first bad point (point_bad) is finite but outside the grid (1) or not (0). */
static int bad_why(const mpm_scene *s, size_t first)
{
    return isfinite(s->x[first]) && isfinite(s->y[first]) && isfinite(s->vx[first]) &&
           isfinite(s->vy[first]) && isfinite(s->sig[0][first]) && isfinite(s->sig[1][first]) &&
           isfinite(s->sig[2][first]);
}

/* The step being taken when a check fails is s->steps + 1. */
static core_status unstable(const mpm_scene *s, size_t p, const char *what, const char *cause,
                            core_error *err)
{
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "point %zu of grain %d %s at step %ld (t = %.6g s, at x = %.6g, y = %.6g); "
                     "likely cause: %s",
                     p + 1, s->grain[p] + 1, what, s->steps + 1, s->time, s->x[p], s->y[p], cause);
}

/* ---- the likely cause of an instability ------------------------------------------------------
 * From what the scene shows, in this order: a time step the user forced above the CFL limit (only
 * then is dt blamed); a point out of the grid by an edge without a wall; a material so soft that
 * gravity alone strains its grain by more than half (a modulus in the wrong units). */
enum { MPM_BAD_INVERTED, MPM_BAD_LEFT, MPM_BAD_NONFINITE };
#define MPM_SOFT_STRAIN 0.5 /* rho g h / G over the grain's height h */

static void likely_cause(const mpm_scene *s, size_t p, int kind, const mpm_run_def *run,
                         const mpm_timestep *ts, char *buf, size_t n)
{
    if (run->dt > 0 && run->dt > ts->limit) {
        snprintf(buf, n,
                 "the time step is too large: dt = %.3g s is %.3g times the CFL limit %.3g s "
                 "(forced); use dt = \"auto\" or a smaller dt",
                 run->dt, run->dt / ts->limit, ts->limit);
        return;
    }
    static const char *const edge[4] = {"left", "right", "bottom", "top"};
    if (kind == MPM_BAD_LEFT) {
        const double c[2] = {s->x[p], s->y[p]};
        for (int a = 0; a < 2; a++) {
            const double o = s->def.origin[a], L = s->def.size[a];
            int e = c[a] < o ? 2 * a : c[a] > o + L ? 2 * a + 1 : -1;
            if (s->def.periodic[a] || e < 0 || s->def.walls[e] != MPM_WALL_NONE)
                continue;
            snprintf(buf, n,
                     "no wall on the %s edge of the grid: give it one (walls = { %s = 'noslip' "
                     "}, or 'slip', 'friction') or make the %c axis periodic",
                     edge[e], edge[e], a ? 'y' : 'x');
            return;
        }
    }
    const double g =
        sqrt(s->def.gravity[0] * s->def.gravity[0] + s->def.gravity[1] * s->def.gravity[1]);
    const int gr = s->grain[p];
    const mpm_material *m = &s->mats[s->mat[p]];
    double h = 0; /* the grain's height along gravity */
    if (g > 0) {
        const int a = fabs(s->def.gravity[1]) >= fabs(s->def.gravity[0]); /* 1: y */
        h = s->def.size[a];
        if (s->gdef && gr >= 0 && (size_t)gr < s->ngrains) {
            const mpm_grain_def *gd = &s->gdef[gr];
            if (gd->shape == MPM_DISK)
                h = 2 * gd->radius;
            else if (gd->shape == MPM_RECT)
                h = gd->hi[a] - gd->lo[a];
        }
    }
    double strain = m->shear > 0 ? m->density * g * h / m->shear : 0;
    if (strain > MPM_SOFT_STRAIN) {
        snprintf(buf, n,
                 "the material is too soft for the load: shear = %.3g Pa gives strains of %.3g "
                 "under gravity alone (rho g h / G over the grain's height h = %.3g m); check the "
                 "units (Pa)",
                 m->shear, strain, h);
        return;
    }
    const bool fixed = run->dt > 0;
    if (kind == MPM_BAD_LEFT)
        snprintf(buf, n,
                 "a point faster than the step allows through a wall (dt = %.3g s, CFL limit "
                 "%.3g s at the start of the run)%s",
                 fixed ? run->dt : ts->dt_auto, ts->limit,
                 fixed ? "; use dt = \"auto\" or a smaller dt" : "; use a smaller cfl");
    else if (fixed)
        snprintf(buf, n,
                 "the time step dt = %.3g s (CFL limit %.3g s at the start of the run) is too "
                 "large for the wave speed, or a point is too strongly compressed between walls "
                 "or grains; use dt = \"auto\" or a smaller dt",
                 run->dt, ts->limit);
    else
        snprintf(buf, n,
                 "a point too strongly compressed between walls or grains, or a grain too coarse "
                 "(too few cells across) for its deformation (dt = \"auto\" keeps to the CFL "
                 "limit; a smaller cfl rarely helps)");
}

/* ---- the step as a table of stages -----------------------------------------------------------
 * Each update scheme's and contact model's step, in the order the threads run it in the step's
 * parallel region: a stage (step_internal.h), whether a barrier follows it, and the timing entry
 * thread 0 charges at its end with the time since the last charge (T_NONE: the next stage's).
 * A stage's own barriers are inside it (with friction the threads' points feed their own pairs
 * and nodes, so fewer barriers separate the stages than with noslip's chunks). */
enum { T_NONE = -1 };
typedef struct {
    mpm_stage_fn *run;
    bool barrier;
    int timer;
} step_stage;

/* Columns: the stage, a barrier after it, the timing entry it ends. */
static const step_stage NOSLIP_USL[] = {
    {mpm_stage_stencil, true, T_NONE},
    {mpm_stage_forced, false, T_STENCIL},
    {mpm_stage_to_grid, false, T_NONE},
    {mpm_stage_moments, false, T_P2G},
    {mpm_stage_grid, true, T_GRID},
    {mpm_stage_to_points, true, T_G2P},
    {mpm_stage_stress_check, false, T_MATERIAL},
    {NULL, false, T_NONE},
};
static const step_stage NOSLIP_MUSL[] = {
    {mpm_stage_stencil, true, T_NONE},
    {mpm_stage_forced, false, T_STENCIL},
    {mpm_stage_to_grid, false, T_NONE},
    {mpm_stage_moments, false, T_P2G},
    {mpm_stage_grid, true, T_GRID},
    {mpm_stage_to_points, true, T_G2P},
    {mpm_stage_remap_scatter, false, T_NONE},
    {mpm_stage_remap_velocities, false, T_REMAP},
    {mpm_stage_stress_check, false, T_MATERIAL},
    {NULL, false, T_NONE},
};
static const step_stage NOSLIP_USF[] = {
    {mpm_stage_stencil, true, T_NONE},     {mpm_stage_forced, false, T_STENCIL},
    {mpm_stage_to_grid, false, T_NONE},    {mpm_stage_moments, false, T_P2G},
    {mpm_stage_velocities, false, T_NONE}, {mpm_stage_stress, true, T_MATERIAL},
    {mpm_stage_forces, false, T_P2G},      {mpm_stage_grid, true, T_GRID},
    {mpm_stage_to_points, true, T_G2P},    {NULL, false, T_NONE},
};
/* With friction the stencil is computed in the grain scatter, and a thread's points read only
 * its own pairs and the nodes only its grains reach: no barrier after the grid update or G2P. */
static const step_stage FRICTION_USL[] = {
    {mpm_stage_grain_scatter, true, T_NONE},
    {mpm_stage_node_sums, false, T_P2G},
    {mpm_stage_normals, true, T_NONE},
    {mpm_stage_moments, false, T_NORMALS},
    {mpm_stage_grid, false, T_GRID},
    {mpm_stage_contact, false, T_CONTACT},
    {mpm_stage_to_points, false, T_G2P},
    {mpm_stage_stress_check, false, T_MATERIAL},
    {NULL, false, T_NONE},
};
static const step_stage FRICTION_MUSL[] = {
    {mpm_stage_grain_scatter, true, T_NONE},
    {mpm_stage_node_sums, false, T_P2G},
    {mpm_stage_normals, true, T_NONE},
    {mpm_stage_moments, false, T_NORMALS},
    {mpm_stage_grid, false, T_GRID},
    {mpm_stage_contact, false, T_CONTACT},
    {mpm_stage_to_points_remap, true, T_G2P},
    {mpm_stage_remap_velocities, false, T_REMAP},
    {mpm_stage_stress_check, false, T_MATERIAL},
    {NULL, false, T_NONE},
};
static const step_stage FRICTION_USF[] = {
    {mpm_stage_grain_scatter, true, T_NONE},
    {mpm_stage_node_sums, false, T_P2G},
    {mpm_stage_normals, true, T_NONE},
    {mpm_stage_moments, false, T_NORMALS},
    {mpm_stage_velocities, false, T_NONE},
    {mpm_stage_stress, true, T_MATERIAL},
    {mpm_stage_forces, false, T_P2G},
    {mpm_stage_grid, false, T_GRID},
    {mpm_stage_contact, false, T_CONTACT},
    {mpm_stage_to_points, false, T_G2P},
    {NULL, false, T_NONE},
};

static const step_stage *stages_of(const mpm_scene *s)
{
    static const step_stage *const table[2][3] = {
        [MPM_CONTACT_NOSLIP] =
            {
                [MPM_USL] = NOSLIP_USL,
                [MPM_MUSL] = NOSLIP_MUSL,
                [MPM_USF] = NOSLIP_USF,
            },
        [MPM_CONTACT_FRICTION] =
            {
                [MPM_USL] = FRICTION_USL,
                [MPM_MUSL] = FRICTION_MUSL,
                [MPM_USF] = FRICTION_USF,
            },
    };
    return table[s->contact][s->def.update];
}

/* One step's stages in the parallel region on ctx->nt threads, each stage's time charged by
 * thread 0 (the region's closing barrier to the last stage). */
static void run_stages(mpm_scene *s, mpm_step *ctx, const step_stage *stages)
{
    const double t0 = clock_wall();
    double tlast = t0;
    int last = T_NONE;
#pragma omp parallel num_threads(ctx->nt) if (ctx->nt > 1)
    {
        const int t = THREAD_ID();
        double tl = t0;
        ctx->tbad[t] = (size_t)-1;
        for (const step_stage *g = stages; g->run; g++) {
            g->run(s, ctx, t);
            if (g->barrier) {
#pragma omp barrier
            }
            if (t == 0 && g->timer != T_NONE) {
                const double now = clock_wall();
                ctx->tstage[g->timer] += now - tl;
                tl = now;
                last = g->timer;
            }
        }
        if (t == 0)
            tlast = tl;
    }
    ctx->tstage[last] += clock_wall() - tlast;
}

/* After the stages: the first inverted point, then (USF: a pass of its own; else the stress
 * update's) the first point with a non-finite value or outside the grid, as an error naming
 * the point, the step and the likely cause. */
static core_status step_checks(mpm_scene *s, const mpm_step *ctx, const mpm_run_def *run,
                               const mpm_timestep *ts, core_error *err)
{
    char cause[400];
    for (int t = 0; t < ctx->nt; t++)
        if (ctx->tbad[t] != (size_t)-1) {
            likely_cause(s, ctx->tbad[t], MPM_BAD_INVERTED, run, ts, cause, sizeof cause);
            return unstable(s, ctx->tbad[t], "was inverted (det F <= 0)", cause, err);
        }
    size_t bad = (size_t)-1;
    if (s->def.update == MPM_USF)
        bad = mpm_check_points(s, ctx->nt);
    else
        for (int t = 0; t < ctx->nt; t++)
            bad = ctx->tcheck[t] < bad ? ctx->tcheck[t] : bad;
    if (bad == (size_t)-1)
        return CORE_OK;
    const int why = bad_why(s, bad);
    likely_cause(s, bad, why ? MPM_BAD_LEFT : MPM_BAD_NONFINITE, run, ts, cause, sizeof cause);
    return unstable(s, bad, why ? "left the grid" : "has a non-finite position, velocity or stress",
                    cause, err);
}

/* The run's arguments, then what the steps need: the contact fields, the step context and its
 * threads, ln b_e,zz of every point, the points' stencil entries. */
static core_status run_prepare(mpm_scene *s, const mpm_run_def *run, core_error *err)
{
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    if (!(run->dt >= 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be > 0 (or 0 for automatic), got %g", run->dt);
    if (run->dt == 0 && !(run->cfl > 0 && run->cfl <= 1))
        return core_fail(err, CORE_ERR_ARG, "cfl must be in (0, 1], got %g", run->cfl);
    if (s->np == 0)
        return core_fail(err, CORE_ERR_STATE,
                         "the scene has no material points: add a grain first");
    core_status st;
    const bool friction = s->contact == MPM_CONTACT_FRICTION;
    if (friction && (st = mpm_contact_reserve(s, err)))
        return st;
    if (!s->step && !(s->step = calloc(1, sizeof *s->step)))
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the step");
    if ((st = threads_setup(s, s->step, err)))
        return st;
    if (!s->lzz_ok) {
        for (size_t p = 0; p < s->np; p++)
            s->lzz[p] = 0.5 * log(s->be[3][p]);
        s->lzz_ok = true;
    }
    s->sf = friction ? s->sv : s->sn;
    return CORE_OK;
}

static core_status run_steps(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err)
{
    *done = 0;
    core_status st = run_prepare(s, run, err);
    if (st)
        return st;
    mpm_step *const ctx = s->step;
    const step_stage *const stages = stages_of(s);
    const double h = s->hx < s->hy ? s->hx : s->hy;
    mpm_timestep ts;
    if ((st = mpm_timestep_info(s, run->cfl > 0 && run->cfl <= 1 ? run->cfl : 1, &ts, err)))
        return st;
    while (*done < run->steps) {
        if (run->time_end >= 0 && s->time >= run->time_end * (1 - 1e-14))
            break;
        if (interrupt_pending())
            return core_fail(err, CORE_ERR_INTERRUPTED,
                             "interrupted at step %ld (t = %.6g s); the scene is intact", s->steps,
                             s->time);
        double dt = run->dt > 0 ? run->dt : run->cfl * h / (ts.wave_speed + max_speed(s));
        if (run->time_end >= 0 && s->time + dt > run->time_end)
            dt = run->time_end - s->time;
        ctx->dt = dt;
        run_stages(s, ctx, stages);
        const double tend = clock_wall(); /* the end of the region, then the checks */
        if ((st = step_checks(s, ctx, run, &ts, err)))
            return st;
        s->time += dt;
        s->steps++;
        ++*done;
        ctx->tstage[T_CHECK] += clock_wall() - tend;
        ctx->tsteps++;
        if (threads_tune_step() && (st = threads_setup(s, ctx, err)))
            return st;
    }
    return CORE_OK;
}

core_status mpm_run(mpm_scene *s, const mpm_run_def *run, long *done, core_error *err)
{
    /* A step gives the same bits on any thread count the tuner may choose (core/threads.h):
     * with frictional contact every grain's nodal entries are built by one thread and packed in
     * grain order; noslip scatters by chunks whose number is fixed in auto mode (all
     * processors) and adds them in chunk order. */
    threads_tune_begin(s, s->np >= 8192);
    core_status st = run_steps(s, run, done, err);
    threads_tune_end();
    return st;
}
