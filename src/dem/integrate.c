/* Time stepping: velocity Verlet (default), position Verlet (Padbidri Eq. 1.6), Gear's 5th-order
 * predictor-corrector (Herrmann Sec. 2) and Padbidri's two-timescales schedule (Sec. 2.4); the
 * run loop with Ctrl-C and instability checks (unstable.c names their likely cause); the
 * contact-time step rule (Padbidri Sec. 2.3). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clones.h"
#include "core/comm.h"
#include "core/interrupt.h"
#include "core/threads.h"
#include "dem/dem_internal.h"

dem_run_def dem_default_run_def(void)
{
    return (dem_run_def){.steps = 0, .dt = 0, .integrator = DEM_VELOCITY_VERLET, .tt_m = 5,
                         .tt_n = 5, .tt_q = 5, .progress = NULL};
}

/* Arrays the run needs that the scene may not have yet. */
static core_status prepare(dem_scene *s, const dem_run_def *run, core_error *err)
{
    const int D = s->dim;
    if (s->nmat == 0 || (dem_domain_count(s) == 0 && !dem_flow_inserting(s)))
        return core_fail(err, CORE_ERR_STATE, "the scene has no particles: add some first");
    if (dem_tangent_history(s->contact.tangential)) {
        for (int w = 0; w < s->nwalls; w++) {
            if (!s->walls[w].active || s->walls[w].hist[0])
                continue;
            for (int d = 0; d < 4; d++) {
                if (d >= D && d < 3)
                    continue; /* components up to dim, and [3] the last stiffness */
                if (dem_alloc_array(&s->walls[w].hist[d], s->cap, err))
                    return err->status;
                memset(s->walls[w].hist[d], 0, s->cap * sizeof(double));
            }
        }
    }
    for (int w = 0; w < s->nwalls && dem_bonds(&s->contact); w++) { /* cohesion.h: planes */
        double **h = &s->walls[w].hist[DEM_HIST_BOND];
        if (!s->walls[w].active || s->walls[w].shape || *h)
            continue;
        if (dem_alloc_array(h, s->cap, err))
            return err->status;
        memset(*h, 0, s->cap * sizeof(double));
    }
    for (int w = 0; w < s->nwalls; w++) /* the rolling spring's, per particle (rolling.inc) */
        for (int d = 0; d < dem_rolling_slots(s) && s->walls[w].active; d++) {
            double **h = &s->walls[w].hist[DEM_HIST_ROLL + d];
            if (*h)
                continue;
            if (dem_alloc_array(h, s->cap, err))
                return err->status;
            memset(*h, 0, s->cap * sizeof(double));
        }
    if (run->integrator == DEM_POSITION_VERLET && !s->x_prev[0])
        for (int d = 0; d < D; d++)
            if (dem_alloc_array(&s->x_prev[d], s->cap, err))
                return err->status;
    if (run->integrator == DEM_GEAR5 && !s->gear[0][0]) {
        for (int k = 0; k < 6; k++) {
            for (int d = 0; d < D; d++)
                if (dem_alloc_array(&s->gear[k][d], s->cap, err))
                    return err->status;
            for (int d = (D == 2 ? 2 : 0); s->rot && d < 3; d++)
                if (dem_alloc_array(&s->gear_w[k][d], s->cap, err))
                    return err->status;
        }
        s->gear_ready = 0;
    }
    return CORE_OK;
}

/* A particle outside the domain on an axis that is not periodic (index, or (size_t)-1). */
static size_t check_domain(const dem_scene *s)
{
    size_t bad = (size_t)-1;
    const long n = (long)s->n;
    const int D = s->dim;
    for (int d = 0; d < D; d++) {
        if (s->periodic[d])
            continue;
        const double lo = s->lo[d], hi = s->hi[d];
        const unsigned char *gh = s->ghost; /* distributed: a ghost's state is its owner's */
#pragma omp parallel for schedule(static) reduction(min : bad) if (n > 4096)
        for (long i = 0; i < n; i++)
            if ((s->x[d][i] < lo || s->x[d][i] > hi) && (size_t)i < bad && !(gh && gh[i]))
                bad = (size_t)i;
    }
    return bad;
}

/* Largest squared displacement of a particle since the last list build; distributed, of an
 * owned particle (a ghost moves with its owner, which the rank holding it measures). gh: the
 * ghost flags or NULL, a constant where this is inlined, so the one-rank loop has no mask. */
static inline __attribute__((always_inline)) double
displacement2_masked(const dem_scene *s, const unsigned char *restrict gh)
{
    const long n = (long)s->n;
    double m = 0;
    if (s->dim == 2) {
        const double *restrict x = s->x[0], *restrict y = s->x[1];
        const double *restrict xb = s->x_build[0], *restrict yb = s->x_build[1];
#pragma omp parallel for schedule(static) reduction(max : m) if (n > 4096)
        for (long i = 0; i < n; i++) {
            double dx = x[i] - xb[i], dy = y[i] - yb[i], d2 = dx * dx + dy * dy;
            if (gh && gh[i])
                d2 = 0;
            m = d2 > m ? d2 : m;
        }
    } else {
#pragma omp parallel for schedule(static) reduction(max : m) if (n > 4096)
        for (long i = 0; i < n; i++) {
            double d2 = 0;
            for (int d = 0; d < 3; d++) {
                double dx = s->x[d][i] - s->x_build[d][i];
                d2 += dx * dx;
            }
            if (gh && gh[i])
                d2 = 0;
            m = d2 > m ? d2 : m;
        }
    }
    return m;
}

static double max_displacement2(const dem_scene *s)
{
    return s->ghost ? displacement2_masked(s, s->ghost) : displacement2_masked(s, NULL);
}

/* Forces at the current state; the list is rebuilt first when a particle moved more than half
 * the skin since the last build, or a wall did. disp2 < 0: not known, measure it. */
static core_status forces_distributed(dem_scene *s, double dt, double disp2, core_error *err);

static core_status forces(dem_scene *s, double dt, double disp2, core_error *err)
{
    if (s->dom)
        return forces_distributed(s, dt, disp2, err);
    const double lim = 0.25 * s->skin * s->skin;
    if (!s->need_rebuild && s->pairs.start) {
        if (disp2 < 0)
            disp2 = max_displacement2(s);
        if (disp2 > lim)
            s->need_rebuild = 1;
        for (int w = 0; w < s->nwalls && !s->need_rebuild; w++) {
            const dem_wall *wl = &s->walls[w];
            double d2 = 0;
            for (int d = 0; d < s->dim; d++)
                d2 += (wl->point[d] - wl->point_build[d]) * (wl->point[d] - wl->point_build[d]);
            if (wl->active && d2 > lim)
                s->need_rebuild = 1;
        }
        if (s->nshaped && !s->need_rebuild && dem_shapes_moved(s)) /* turning walls */
            s->need_rebuild = 1;
    } else {
        s->need_rebuild = 1;
    }
    if (s->need_rebuild) {
        core_status st = dem_build_pairs(s, err);
        if (st) {
            if (err) { /* say when it happened */
                char msg[sizeof err->msg];
                snprintf(msg, sizeof msg, "%s", err->msg);
                core_fail(err, st, "%s (at step %ld, t = %.6g s)", msg, s->steps + 1, s->time);
            }
            return st;
        }
    }
    size_t t = dem_compute_forces(s, dt);
    if (t != (size_t)-1)
        return dem_unstable(s, t, "went through a wall", err);
    if (s->bnd) {
        core_status st = dem_boundary_apply(s, dt, err);
        if (st)
            return st;
    }
    s->forces_ready = 1;
    return CORE_OK;
}

/* The same on a decomposed scene: every rank takes the same branch (one rebuild test for all,
 * one verdict on errors), so that the collective calls match. */
static int walls_moved(const dem_scene *s, double lim)
{
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        double d2 = 0;
        for (int d = 0; d < s->dim; d++)
            d2 += (wl->point[d] - wl->point_build[d]) * (wl->point[d] - wl->point_build[d]);
        if (wl->active && d2 > lim)
            return 1;
    }
    return 0;
}

static core_status forces_distributed(dem_scene *s, double dt, double disp2, core_error *err)
{
    const double lim = 0.25 * s->skin * s->skin;
    int need = s->need_rebuild || !s->pairs.start || walls_moved(s, lim) ||
               (disp2 < 0 ? max_displacement2(s) : disp2) > lim;
    core_status st;
    if (comm_any(need)) {
        if ((st = dem_domain_rebuild(s, err))) {
            if (err) {
                char msg[sizeof err->msg];
                snprintf(msg, sizeof msg, "%s", err->msg);
                core_fail(err, st, "%s (at step %ld, t = %.6g s)", msg, s->steps + 1, s->time);
            }
            return st;
        }
    } else {
        dem_domain_halo(s);
    }
    size_t t = dem_compute_forces(s, dt);
    /* A servo wall moves with the sum of every rank's forces: now. Otherwise the sum waits for
     * a query (dem_sync_walls) and costs nothing per step. */
    int servo = 0;
    for (int w = 0; w < s->nwalls; w++)
        servo |= s->walls[w].active && s->walls[w].servo;
    st = dem_domain_walls_due(s, servo, err);
    if (!st && t != (size_t)-1)
        st = dem_unstable(s, t, "went through a wall", err);
    /* A local error waits for the end of the step, where every rank agrees on the first one:
     * the rest of the step makes the same collective calls on every rank. */
    dem_domain_defer(s, st, err);
    s->forces_ready = 1;
    return CORE_OK;
}

static void move_walls(dem_scene *s, double dt)
{
    for (int w = 0; w < s->nwalls; w++) {
        dem_wall *wl = &s->walls[w];
        if (wl->servo && wl->active) { /* force control: a damped body along the normal */
            double vn = 0;
            for (int d = 0; d < s->dim; d++)
                vn += wl->velocity[d] * wl->normal[d];
            vn += dt * ((wl->servo_force - wl->fn) / wl->servo_mass - wl->servo_rate * vn);
            for (int d = 0; d < s->dim; d++)
                wl->velocity[d] = vn * wl->normal[d];
        }
        for (int d = 0; d < s->dim; d++)
            wl->point[d] += dt * wl->velocity[d];
    }
    if (s->nshaped) /* walls beyond planes, rigid bodies that also turn (walls.c) */
        dem_shapes_move(s, dt);
}

static size_t check_finite(const dem_scene *s)
{
    size_t bad = (size_t)-1;
    const long n = (long)s->n;
    const int D = s->dim;
    const unsigned char *gh = s->ghost;
#pragma omp parallel for schedule(static) reduction(min : bad) if (n > 4096)
    for (long i = 0; i < n; i++)
        for (int d = 0; d < D; d++)
            if (!isfinite(s->x[d][i]) || !isfinite(s->v[d][i]))
                if ((size_t)i < bad && !(gh && gh[i]))
                    bad = (size_t)i;
    return bad;
}

/* ---- velocity Verlet ---------------------------------------------------------------------- *
 * Component-wise loops over contiguous arrays (they vectorise); the drift also returns the largest
 * displacement since the last list build, and the final kick raises s->suspect when a velocity is
 * not finite, so the per-particle checks run only when something is wrong. */
GRAINLAB_CLONES static void kick_rotation(dem_scene *s, double h)
{
    const long n = (long)s->n;
    const double *restrict ii = s->inv_inertia;
    for (int d = (s->dim == 2 ? 2 : 0); d < 3; d++) {
        double *restrict w = s->w[d];
        const double *restrict tq = s->tq[d];
#pragma omp parallel for schedule(static) if (n > 4096)
        for (long i = 0; i < n; i++)
            w[i] += h * tq[i] * ii[i];
    }
}

/* 2D orientation: theta += dt omega (omega at the half step in velocity Verlet). */
GRAINLAB_CLONES static void advance_angles(dem_scene *s, double dt)
{
    if (!s->angle)
        return;
    const long n = (long)s->n;
    double *restrict a = s->angle;
    const double *restrict w = s->w[2];
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; i++)
        a[i] += dt * w[i];
}

/* The fused 2D pass: kick, drift, the extent of the positions, the displacement since the build
 * (of owned particles only when GHOSTED), and with ROT the spin's kick and the angle's advance.
 * GHOSTED and ROT are literals in each expansion, so that each parallel loop (outlined before
 * any inlining) has no per-particle tests and vectorises. Every operation is per particle, so
 * the vector code (omp simd) gives the bits of the scalar one; the max, the min and the extent
 * do not depend on the order either. The extent is compared with the box after the loop (a NaN
 * is ignored there as it was by the per-particle comparisons; kick_check's test catches it). */
/* clang-format off: _Pragma takes one string literal */
#define KICK_DRIFT_2D_LOOP(GHOSTED, ROT)                                                           \
    do {                                                                                           \
    _Pragma("omp parallel for simd schedule(static) reduction(min : x0, y0) reduction(max : m, x1, y1) if (n > 4096)") \
    for (long i = 0; i < n; i++) {                                                                 \
        vx[i] += h * fx[i] * im[i];                                                                \
        vy[i] += h * fy[i] * im[i];                                                                \
        x[i] += dt * vx[i];                                                                        \
        y[i] += dt * vy[i];                                                                        \
        x0 = x[i] < x0 ? x[i] : x0;                                                                \
        x1 = x[i] > x1 ? x[i] : x1;                                                                \
        y0 = y[i] < y0 ? y[i] : y0;                                                                \
        y1 = y[i] > y1 ? y[i] : y1;                                                                \
        double ex = x[i] - xb[i], ey = y[i] - yb[i], d2 = ex * ex + ey * ey;                       \
        if (GHOSTED)                                                                               \
            d2 = gh[i] ? 0 : d2;                                                                   \
        m = d2 > m ? d2 : m;                                                                       \
        if (ROT) {                                                                                 \
            w[i] += h * tq[i] * ii[i];                                                             \
            a[i] += dt * w[i];                                                                     \
        }                                                                                          \
    }                                                                                              \
    } while (0)
/* clang-format on */

GRAINLAB_CLONES static double kick_drift_2d(dem_scene *s, double h, double dt, int rot)
{
    const long n = (long)s->n;
    const double *restrict im = s->inv_m;
    double *restrict x = s->x[0], *restrict y = s->x[1];
    double *restrict vx = s->v[0], *restrict vy = s->v[1];
    const double *restrict fx = s->f[0], *restrict fy = s->f[1];
    const double *restrict xb = s->x_build[0], *restrict yb = s->x_build[1];
    const unsigned char *restrict gh = s->ghost;
    double *restrict w = rot ? s->w[2] : NULL, *restrict a = rot ? s->angle : NULL;
    const double *restrict tq = rot ? s->tq[2] : NULL, *restrict ii = rot ? s->inv_inertia : NULL;
    const double xlo = s->periodic[0] ? -DBL_MAX : s->lo[0];
    const double xhi = s->periodic[0] ? DBL_MAX : s->hi[0];
    const double ylo = s->periodic[1] ? -DBL_MAX : s->lo[1];
    const double yhi = s->periodic[1] ? DBL_MAX : s->hi[1];
    double m = 0, x0 = DBL_MAX, x1 = -DBL_MAX, y0 = DBL_MAX, y1 = -DBL_MAX;
    if (gh)
        KICK_DRIFT_2D_LOOP(1, 0);
    else
        KICK_DRIFT_2D_LOOP(0, 0);
    if (rot) {
#pragma omp parallel for simd schedule(static) if (n > 4096)
        for (long i = 0; i < n; i++) {
            w[i] += h * tq[i] * ii[i];
            a[i] += dt * w[i];
        }
    }
    s->suspect |= (x0 < xlo) | (x1 > xhi) | (y0 < ylo) | (y1 > yhi);
    return m;
}
#undef KICK_DRIFT_2D_LOOP

GRAINLAB_CLONES static double kick_drift(dem_scene *s, double h, double dt)
{
    const long n = (long)s->n;
    const double *restrict im = s->inv_m;
    int out = 0;
    if (s->dim == 2) {
        if (s->rot && s->angle) /* 2D rotations come with their angle (dem_ensure_rotation) */
            return kick_drift_2d(s, h, dt, 1);
        double m = kick_drift_2d(s, h, dt, 0);
        if (s->rot) {
            kick_rotation(s, h);
            advance_angles(s, dt);
        }
        return m;
    }
    for (int d = 0; d < s->dim; d++) {
        double *restrict v = s->v[d], *restrict x = s->x[d];
        const double *restrict f = s->f[d];
        /* periodic axes never leave: an interval that contains every finite number */
        const double lo = s->periodic[d] ? -DBL_MAX : s->lo[d];
        const double hi = s->periodic[d] ? DBL_MAX : s->hi[d];
#pragma omp parallel for schedule(static) reduction(| : out) if (n > 4096)
        for (long i = 0; i < n; i++) {
            v[i] += h * f[i] * im[i];
            x[i] += dt * v[i];
            out |= (x[i] < lo) | (x[i] > hi);
        }
    }
    s->suspect |= out;
    if (s->rot) {
        kick_rotation(s, h);
        advance_angles(s, dt);
    }
    return max_displacement2(s);
}

/* The 2D final kick in one vector pass (with ROT, a literal, the spin's too). 0 v is 0 for a
 * finite v and NaN for an infinite or NaN one: the sum is 0 (of either sign, in any order)
 * exactly when every velocity is finite. */
/* clang-format off: _Pragma takes one string literal */
#define KICK_CHECK_2D_LOOP(ROT)                                                                    \
    do {                                                                                           \
    _Pragma("omp parallel for simd schedule(static) reduction(+ : chk) if (n > 4096)")              \
    for (long i = 0; i < n; i++) {                                                                 \
        vx[i] += h * fx[i] * im[i];                                                                \
        vy[i] += h * fy[i] * im[i];                                                                \
        chk += vx[i] * 0.0 + vy[i] * 0.0;                                                          \
        if (ROT)                                                                                   \
            w[i] += h * tq[i] * ii[i];                                                             \
    }                                                                                              \
    } while (0)
/* clang-format on */

GRAINLAB_CLONES static int kick_check_2d(dem_scene *s, double h)
{
    const long n = (long)s->n;
    const int rot = s->rot;
    const double *restrict im = s->inv_m;
    double *restrict vx = s->v[0], *restrict vy = s->v[1];
    const double *restrict fx = s->f[0], *restrict fy = s->f[1];
    double *restrict w = rot ? s->w[2] : NULL;
    const double *restrict tq = rot ? s->tq[2] : NULL, *restrict ii = rot ? s->inv_inertia : NULL;
    double chk = 0;
    if (rot)
        KICK_CHECK_2D_LOOP(1);
    else
        KICK_CHECK_2D_LOOP(0);
    return !(chk == 0);
}
#undef KICK_CHECK_2D_LOOP

GRAINLAB_CLONES static void kick_check(dem_scene *s, double h)
{
    const long n = (long)s->n;
    const double *restrict im = s->inv_m;
    int bad = 0;
    if (s->dim == 2) {
        s->suspect |= kick_check_2d(s, h);
        return;
    }
    for (int d = 0; d < s->dim; d++) {
        double *restrict v = s->v[d];
        const double *restrict f = s->f[d];
#pragma omp parallel for schedule(static) reduction(| : bad) if (n > 4096)
        for (long i = 0; i < n; i++) {
            v[i] += h * f[i] * im[i];
            bad |= !(fabs(v[i]) <= DBL_MAX);
        }
    }
    if (s->rot)
        kick_rotation(s, h);
    s->suspect |= bad;
}

static core_status step_velocity_verlet(dem_scene *s, double dt, core_error *err)
{
    core_status st;
    if (!s->forces_ready && (st = forces(s, dt, -1, err)))
        return st;
    double disp2 = kick_drift(s, 0.5 * dt, dt);
    if (s->clumps) { /* the members go where their bodies take them */
        dem_clumps_kick_drift(s, 0.5 * dt, dt);
        disp2 = -1;
    }
    move_walls(s, dt);
    s->time += dt;
    if ((st = forces(s, dt, disp2, err)))
        return st;
    kick_check(s, 0.5 * dt);
    if (s->clumps)
        dem_clumps_kick(s, 0.5 * dt);
    return CORE_OK;
}

/* ---- position Verlet (Eq. 1.6) ------------------------------------------------------------- *
 * x(t+dt) = 2 x(t) - x(t-dt) + a dt^2, in the summed form that keeps the step displacement
 * u = x(t) - x(t-dt) instead of x(t-dt): u += a dt^2, x += u. It is the same recurrence, but does
 * not lose the small difference of two large positions every step (the plain form drifted 2e-6 m
 * in 1e6 steps of free fall, the summed one 1e-11). Velocities for the damping and friction laws,
 * and the ones reported, are u/dt, i.e. at t - dt/2. */
static core_status step_position_verlet(dem_scene *s, double dt, core_error *err)
{
    const int D = s->dim;
    long n = (long)s->n; /* distributed: a rebuild in forces() changes the local count */
    core_status st;
    if (!s->prev_ready) {
        if ((st = forces(s, dt, -1, err)))
            return st;
        n = (long)s->n;
        /* backward Taylor step: x(t) - x(t-dt) = v dt - a dt^2 / 2 */
        for (long i = 0; i < n; i++)
            for (int d = 0; d < D; d++)
                s->x_prev[d][i] = dt * s->v[d][i] - 0.5 * dt * dt * s->f[d][i] * s->inv_m[i];
        s->prev_ready = 1;
        s->prev_dt = dt;
    }
    if (dt != s->prev_dt) { /* u encodes the velocity with the old step: rescale it */
        for (long i = 0; i < n; i++)
            for (int d = 0; d < D; d++)
                s->x_prev[d][i] *= dt / s->prev_dt;
        s->prev_dt = dt;
    }
    if ((st = forces(s, dt, -1, err)))
        return st;
    n = (long)s->n;
    const int rot = s->rot;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; i++) {
        const double im = s->inv_m[i];
        for (int d = 0; d < D; d++) {
            double *u = &s->x_prev[d][i];
            if (s->flags[i] & DEM_PRESCRIBED)
                *u = dt * s->v[d][i];
            else
                *u += dt * dt * s->f[d][i] * im;
            s->x[d][i] += *u;
            if (!(s->flags[i] & DEM_PRESCRIBED))
                s->v[d][i] = *u / dt;
        }
        if (rot)
            for (int d = (D == 2 ? 2 : 0); d < 3; d++)
                s->w[d][i] += dt * s->tq[d][i] * s->inv_inertia[i];
    }
    advance_angles(s, dt);
    move_walls(s, dt);
    s->time += dt;
    return CORE_OK;
}

/* ---- Gear 5th-order predictor-corrector (Allen & Tildesley, Herrmann Sec. 2) ---------------- *
 * Six scaled derivatives g_k = dt^k/k! d^k x/dt^k per degree of freedom; the corrector for second-
 * order equations with velocity-dependent forces uses c = {3/16, 251/360, 1, 11/18, 1/6, 1/60}. */
static const double GEAR_C[6] = {3.0 / 16, 251.0 / 360, 1, 11.0 / 18, 1.0 / 6, 1.0 / 60};

static void gear_predict(double *g[6], long n)
{
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; i++) {
        g[0][i] += g[1][i] + g[2][i] + g[3][i] + g[4][i] + g[5][i];
        g[1][i] += 2 * g[2][i] + 3 * g[3][i] + 4 * g[4][i] + 5 * g[5][i];
        g[2][i] += 3 * g[3][i] + 6 * g[4][i] + 10 * g[5][i];
        g[3][i] += 4 * g[4][i] + 10 * g[5][i];
        g[4][i] += 5 * g[5][i];
    }
}

static core_status step_gear(dem_scene *s, double dt, core_error *err)
{
    const int D = s->dim, rot = s->rot;
    long n = (long)s->n; /* distributed: a rebuild in forces() changes the local count */
    const int d0 = D == 2 ? 2 : 0;
    core_status st;
    if (!s->gear_ready) {
        if ((st = forces(s, dt, -1, err)))
            return st;
        n = (long)s->n;
        for (long i = 0; i < n; i++) {
            for (int d = 0; d < D; d++) {
                s->gear[0][d][i] = s->x[d][i];
                s->gear[1][d][i] = dt * s->v[d][i];
                s->gear[2][d][i] = 0.5 * dt * dt * s->f[d][i] * s->inv_m[i];
                s->gear[3][d][i] = s->gear[4][d][i] = s->gear[5][d][i] = 0;
            }
            for (int d = d0; rot && d < 3; d++) {
                s->gear_w[0][d][i] = 0;
                s->gear_w[1][d][i] = dt * s->w[d][i];
                s->gear_w[2][d][i] = 0.5 * dt * dt * s->tq[d][i] * s->inv_inertia[i];
                s->gear_w[3][d][i] = s->gear_w[4][d][i] = s->gear_w[5][d][i] = 0;
            }
        }
        s->gear_ready = 1;
        s->gear_dt = dt;
    } else if (dt != s->gear_dt) { /* rescale the scaled derivatives to the new step */
        double r = dt / s->gear_dt, rk = 1;
        for (int k = 1; k < 6; k++) {
            rk *= r;
            for (long i = 0; i < n; i++) {
                for (int d = 0; d < D; d++)
                    s->gear[k][d][i] *= rk;
                for (int d = d0; rot && d < 3; d++)
                    s->gear_w[k][d][i] *= rk;
            }
        }
        s->gear_dt = dt;
    }
    for (int d = 0; d < 3; d++) {
        if (d < D) {
            double *g[6] = {s->gear[0][d], s->gear[1][d], s->gear[2][d],
                            s->gear[3][d], s->gear[4][d], s->gear[5][d]};
            gear_predict(g, n);
        }
        if (rot && d >= d0) {
            double *g[6] = {s->gear_w[0][d], s->gear_w[1][d], s->gear_w[2][d],
                            s->gear_w[3][d], s->gear_w[4][d], s->gear_w[5][d]};
            gear_predict(g, n);
        }
    }
    /* The forces see the predicted positions and velocities. Fixed and prescribed particles just
     * move at their velocity. */
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; i++) {
        const int free_ = s->inv_m[i] > 0;
        for (int d = 0; d < D; d++) {
            if (free_) {
                s->x[d][i] = s->gear[0][d][i];
                s->v[d][i] = s->gear[1][d][i] / dt;
            } else {
                s->x[d][i] += dt * s->v[d][i];
                s->gear[0][d][i] = s->x[d][i];
                s->gear[1][d][i] = dt * s->v[d][i];
                for (int k = 2; k < 6; k++)
                    s->gear[k][d][i] = 0;
            }
        }
        for (int d = d0; rot && free_ && d < 3; d++)
            s->w[d][i] = s->gear_w[1][d][i] / dt;
    }
    move_walls(s, dt);
    s->time += dt;
    if ((st = forces(s, dt, -1, err)))
        return st;
    n = (long)s->n;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long i = 0; i < n; i++) {
        if (!(s->inv_m[i] > 0))
            continue;
        for (int d = 0; d < D; d++) {
            double corr = 0.5 * dt * dt * s->f[d][i] * s->inv_m[i] - s->gear[2][d][i];
            for (int k = 0; k < 6; k++)
                s->gear[k][d][i] += GEAR_C[k] * corr;
            s->x[d][i] = s->gear[0][d][i];
            s->v[d][i] = s->gear[1][d][i] / dt;
        }
        for (int d = d0; rot && d < 3; d++) {
            double corr = 0.5 * dt * dt * s->tq[d][i] * s->inv_inertia[i] - s->gear_w[2][d][i];
            for (int k = 0; k < 6; k++)
                s->gear_w[k][d][i] += GEAR_C[k] * corr;
            s->w[d][i] = s->gear_w[1][d][i] / dt;
        }
    }
    advance_angles(s, dt);
    return CORE_OK;
}

/* ---- the run loop --------------------------------------------------------------------------- */
/* Velocity Verlet's kicks flag non-finite velocities and positions outside the domain (suspect);
 * the other integrators, and the last step of a run, are checked in full. */
static int full_checks_due(const dem_scene *s, const dem_run_def *run, long done_after)
{
    return s->suspect || run->integrator == DEM_POSITION_VERLET ||
           run->integrator == DEM_GEAR5 || done_after >= run->steps;
}

/* The full checks: a non-finite position or velocity, or a particle outside the domain on an axis
 * that is neither periodic nor walled (named by its global id). */
static core_status full_checks(dem_scene *s, core_error *err)
{
    size_t bad = check_finite(s);
    if (bad != (size_t)-1)
        return dem_unstable(s, bad, "has a non-finite position or velocity", err);
    if ((bad = check_domain(s)) != (size_t)-1)
        return dem_unstable(s, bad,
                        "left the domain (a box side without a wall and not periodic)", err);
    return CORE_OK;
}

static core_status run_steps(dem_scene *s, const dem_run_def *run, core_error *err);

core_status dem_run(dem_scene *s, const dem_run_def *run, core_error *err)
{
    /* A DEM step gives the same bits on any thread count, so the tuner of a shared machine may
     * choose it (core/threads.h) once the step runs threaded (the loops' n > 4096). */
    threads_tune_begin(s, s->n > 4096);
    const bool multi = comm_size() > 1;
    comm_stats c0, c1; /* distributed: the time inside communication, for the stats */
    if (multi)
        comm_get_stats(&c0);
    s->run = run;
    core_status st = run_steps(s, run, err);
    s->run = NULL;
    if (multi) {
        comm_get_stats(&c1);
        s->dstats.comm_s += c1.seconds - c0.seconds;
    }
    threads_tune_end();
    return st;
}

static core_status run_steps(dem_scene *s, const dem_run_def *run, core_error *err)
{
    if (run->steps < 0)
        return core_fail(err, CORE_ERR_ARG, "steps must be >= 0, got %ld", run->steps);
    if (!(run->dt > 0) || !isfinite(run->dt))
        return core_fail(err, CORE_ERR_ARG, "dt must be > 0, got %g", run->dt);
    if (run->integrator == DEM_TWO_TIMESCALES &&
        (run->tt_m < 1 || run->tt_n < 1 || run->tt_q < 0))
        return core_fail(err, CORE_ERR_ARG, "two timescales needs m >= 1, n >= 1, q >= 0 "
                         "(got %d, %d, %d)", run->tt_m, run->tt_n, run->tt_q);
    core_status st0;
    if (comm_size() > 1 && s->bnd)
        return core_fail(err, CORE_ERR_STATE,
                         "boundary conditions (pressure tractions, the minimal boundary, springs, "
                         "ties to walls, prescribed spins) do not yet run distributed "
                         "(comm_size() > 1): run this scene on one rank");
    if (comm_size() > 1 && dem_cohesive(&s->contact))
        return core_fail(err, CORE_ERR_STATE,
                         "cohesive contacts (normal 'jkr' or 'dmt', cohesion 'capillary') do not "
                         "yet run distributed (comm_size() > 1): run this scene on one rank");
    for (int w = 0; w < s->nwalls && comm_size() > 1; w++)
        if (s->walls[w].active && s->walls[w].shape)
            return core_fail(err, CORE_ERR_STATE,
                             "walls beyond planes (segments, polylines, triangles, circles, "
                             "cylinders; wall %d) do not yet run distributed (comm_size() > 1): "
                             "run this scene on one rank",
                             w + 1);
    if (s->flow && (st0 = dem_flow_check_run(s, err)))
        return st0;
    if (s->clumps && (st0 = dem_clumps_check_run(s, (int)run->integrator, err)))
        return st0;
    core_status st = prepare(s, run, err);
    if (st)
        return st;
    /* Particles in and out (flow.c) at the step boundaries: before the first step, and after
     * each one before the checks (a particle out through an open side is gone by then). */
    if (s->flow && run->steps > 0 && (st = dem_flow_step(s, s->steps, err)))
        return st;
    if (run->steps > 0 && (st = dem_domain_start(s, err)))
        return st;
    if ((int)run->integrator != s->last_integrator) {
        s->gear_ready = s->prev_ready = s->watch_on = 0;
        s->tt_phase = 0;
        s->last_integrator = (int)run->integrator;
    }
    long done = 0;
    const long cycle = run->tt_n + run->tt_q;
    int intr = 0; /* distributed: every rank's Ctrl-C, agreed at the end of each step */
    while (done < run->steps) {
        if (s->dom ? intr : interrupt_pending())
            return core_fail(err, CORE_ERR_INTERRUPTED,
                             "interrupted at step %ld (t = %.6g s); the scene is intact",
                             s->steps, s->time);
        if (s->bnd && (st = dem_boundary_due(s, err))) {
            dem_invalidate(s, 1);
            return st;
        }
        double h = run->dt;
        long advance = 1;
        switch (run->integrator) {
        case DEM_POSITION_VERLET:
            st = step_position_verlet(s, h, err);
            break;
        case DEM_GEAR5:
            st = step_gear(s, h, err);
            break;
        case DEM_TWO_TIMESCALES:
            /* Padbidri Sec. 2.4: within each cycle of n + q small-step times, one large step of
             * n dt, then q steps of dt; m cycles make the macro step m (n + q) dt. */
            if (s->tt_phase == 0 && run->steps - done >= run->tt_n) {
                h = run->tt_n * run->dt;
                advance = run->tt_n;
            }
            st = step_velocity_verlet(s, h, err);
            s->tt_phase = (s->tt_phase + advance) % cycle;
            break;
        default:
            st = step_velocity_verlet(s, h, err);
        }
        if (s->dom) { /* the checks on every rank, one verdict, the first failing rank's words */
            core_error derr;
            core_status d = dem_domain_deferred(s, &derr); /* consumed on every path */
            if (!st && d) {
                st = d;
                if (err)
                    *err = derr;
            }
            /* the checks in full when this rank's kicks flagged something, as on one rank
             * (each rank decides alone: they make no collective call) */
            if (!st && full_checks_due(s, run, done + advance))
                st = full_checks(s, err);
            intr = interrupt_pending();
            st = dem_domain_agree_flag(s, st, &intr, err);
            s->suspect = 0;
        }
        if (!st && s->flow)
            st = dem_flow_step(s, s->steps + 1, err);
        if (st) {
            dem_invalidate(s, 1);
            return st;
        }
        /* distributed: checked and agreed above; here after the outflows removed their leavers */
        if (!s->dom && full_checks_due(s, run, done + advance)) {
            s->suspect = 0;
            if ((st = full_checks(s, err)))
                return st;
        }
        s->steps++;
        done += advance;
        threads_tune_step();
        if (s->steps >= s->watch_next && (st = dem_energy_watch(s, h, err)))
            return st;
        if (run->progress)
            progress_update(run->progress, (double)done);
    }
    return CORE_OK;
}

/* ---- time step (Padbidri Sec. 2.3) ---------------------------------------------------------- */
/* 2 int_0^1 (1 - x^p)^{-1/2} dx / 2 = B(1/p, 1/2) / p: the contact time of f = k d^beta is
 * t_c = 2 (d_max / v) I(beta + 1), with d_max from (beta+1)/2 m_eff v^2 = k d_max^{beta+1}. */
static double contact_integral(double p)
{
    return tgamma(1 / p) * tgamma(0.5) / tgamma(1 / p + 0.5) / p;
}

/* The contact time t and the damping rate b of a pair of stiffness k, damping gamma and
 * effective mass m_eff at impact speed v. */
static void contact_limits(const dem_scene *s, double k, double gamma, double m_eff, double v,
                           double *t, double *b)
{
    double beta = dem_law_beta(&s->contact);
    double dmax = pow((beta + 1) * m_eff * v * v / (2 * k), 1 / (beta + 1));
    *t = 2 * dmax / v * contact_integral(beta + 1);
    if (beta == 1)
        *t = DEM_PI * sqrt(m_eff / k); /* independent of speed */
    *b = gamma / (2 * m_eff);
    if (s->contact.damping == DEM_DAMPING_BRILLIANTOV) /* rate T k d^{1/2} / (2 m_eff) */
        *b = gamma * k * sqrt(dmax) / (2 * m_eff);
}

core_status dem_timestep_info(const dem_scene *s, double v_imp, dem_timestep *out,
                              core_error *err)
{
    const int D = s->dim;
    if ((dem_domain_count(s) == 0 && !dem_flow_inserting(s)) || s->nmat == 0)
        return core_fail(err, CORE_ERR_STATE, "the scene has no particles: add some first");
    if (!(v_imp > 0)) {
        double vmax2 = 0, h = 0, g = 0;
        for (size_t i = 0; i < s->n; i++) {
            if (s->ghost && s->ghost[i])
                continue;
            double v2 = 0;
            for (int d = 0; d < D; d++)
                v2 += s->v[d][i] * s->v[d][i];
            vmax2 = fmax(vmax2, v2);
        }
        if (s->dom) /* a max: exact, whatever the decomposition */
            comm_max_double(&vmax2, 1);
        for (int d = 0; d < D; d++) {
            g += s->gravity[d] * s->gravity[d];
            if (s->gravity[d] != 0)
                h = fmax(h, s->len[d]);
        }
        v_imp = fmax(fmax(sqrt(vmax2), sqrt(2 * sqrt(g) * h)), 0.1);
    }
    /* The lightest particle against itself, for each material it is made of: the shortest
     * contact time (t_c grows with size for every law here). */
    double tc = INFINITY, bmax = 0;
    for (int mat = 0; mat < s->nmat; mat++) {
        size_t i = (size_t)-1;
        for (size_t k = 0; k < s->n; k++)
            if (s->mat[k] == mat && (i == (size_t)-1 || s->r[k] < s->r[i]) &&
                !(s->ghost && s->ghost[k]))
                i = k;
        if (s->dom) {
            /* One rank's choice, the first smallest particle of the material, across ranks: the
             * smallest radius, then the smallest id; its owner alone computes the limits. */
            double rmin = i == (size_t)-1 ? INFINITY : s->r[i];
            comm_min_double(&rmin, 1);
            int64_t g = i != (size_t)-1 && s->r[i] == rmin ? (int64_t)dem_gid(s, i) : INT64_MAX;
            comm_min_i64(&g, 1);
            if (g == INT64_MAX)
                continue;
            if (i != (size_t)-1 && (int64_t)dem_gid(s, i) != g)
                i = (size_t)-1;
        }
        double t = INFINITY, b = 0; /* distributed: on the ranks without the particle */
        if (i != (size_t)-1) {
            double k, gamma, mu;
            dem_pair_parameters((dem_scene *)s, i, i, &k, &gamma, &mu);
            contact_limits(s, k, gamma, 0.5 * s->m[i], v_imp, &t, &b);
        }
        if (s->dom) { /* one rank computed them: min and max are its values, exactly */
            comm_min_double(&t, 1);
            comm_max_double(&b, 1);
        }
        tc = fmin(tc, t);
        bmax = fmax(bmax, b);
    }
    /* The smallest particle each inserter can bring (flow.c). */
    double k, gamma, m_eff;
    for (int q = 0; s->flow && dem_flow_probe((dem_scene *)s, q, &k, &gamma, &m_eff); q++) {
        double t, b;
        contact_limits(s, k, gamma, m_eff, v_imp, &t, &b);
        tc = fmin(tc, t);
        bmax = fmax(bmax, b);
    }
    out->impact_velocity = v_imp;
    out->contact_time = tc;
    out->limit = tc / 10;
    if (bmax > 0) /* a stiff dashpot needs b dt small, whatever the spring */
        out->limit = fmin(out->limit, 0.2 / bmax);
    out->dt_auto = out->limit / 5;
    return CORE_OK;
}
