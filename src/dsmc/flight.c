/* The DSMC step's free flight (paper Sec. 4): every particle moves under gravity, wraps on
 * periodic axes or reflects off the walls (specular, diffuse, moving), and finds its cell. Each
 * wall hit draws from its own random stream, so the result does not depend on the threads. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "dsmc/dsmc_internal.h"

typedef struct wall_state {
    bool active;
    double pos, vel; /* along the axis, at the end of the step */
} wall_state;

/* Reflects component k of particle i off the wall of `side` that it has crossed. The crossing
 * happened a time tr ago, estimated from the normal speed relative to the wall; the particle
 * leaves with its new normal velocity for that time. */
static void reflect(const dsmc_scene *s, int side, const wall_state *ws, double dt, double *x,
                    double v[3], rng *r)
{
    const dsmc_wall_def *w = &s->walls[side];
    int axis = side / 2;
    double sign = side % 2 == 0 ? 1 : -1;      /* inward normal along the axis */
    double rel = sign * (ws->vel - v[axis]);   /* approach speed in the wall frame, > 0 */
    double depth = sign * (ws->pos - x[axis]); /* how far behind the wall, > 0 */
    double tr = rel > 0 ? fmin(depth / rel, dt) : 0;
    double vn; /* outgoing normal speed relative to the wall, > 0 */
    if (w->kind == DSMC_WALL_DIFFUSE) {
        double sd = sqrt(w->temperature / s->mass);
        double u = rng_uniform(r);
        vn = sd * sqrt(-2 * log(1 - u)); /* flux-weighted: Rayleigh */
        for (int k = 0; k < s->D; k++)
            if (k != axis)
                v[k] = w->velocity[k] + sd * rng_normal(r);
    } else {
        vn = w->restitution * (rel > 0 ? rel : -rel);
    }
    v[axis] = ws->vel + sign * vn;
    x[axis] = ws->pos + sign * vn * tr;
}

/* The constants of one flight step, read once: stores into the particle arrays could alias the
 * scene, so the loop must not read them through it. */
typedef struct flight_consts {
    double dt, hdt2, g[3], lo[3], hi[3], L[3], inv_h[3];
    int cells[3], sh;
    bool per[3];
    wall_state ws[6];
    uint64_t seed, step;
} flight_consts;

/* Whether the walls of axis k reflect like mirrors: both fixed, specular with restitution 1,
 * and no gravity along the axis. Then any number of crossings in one step is a fold of the
 * free flight about the two walls (the trajectory in a box of period 2L). */
static bool mirror_axis(const dsmc_scene *s, const flight_consts *fc, int k)
{
    for (int side = 2 * k; side < 2 * k + 2; side++) {
        const dsmc_wall_def *w = &s->walls[side];
        if (w->kind != DSMC_WALL_SPECULAR || w->restitution != 1 || w->amplitude != 0)
            return false;
    }
    return fc->g[k] == 0;
}

/* Walls for one particle that is outside the walls on a non-periodic axis (the slow path). A
 * particle may cross both walls of a thin box: up to 4 reflections are followed one by one;
 * beyond them, mirror walls fold the rest of the flight in closed form (O(1) for any dt), and
 * other walls (moving, diffuse, inelastic, under gravity) put the particle on the wall it is
 * behind and count it in *stranded: a step that long is refused by the run (dsmc_run). */
static __attribute__((noinline)) long walls_one(const dsmc_scene *s, const flight_consts *fc, int D,
                                                uint64_t id, double x[3], double v[3],
                                                int *stranded)
{
    long hits = 0;
    for (int k = 0; k < D; k++) {
        if (fc->per[k])
            continue;
        const wall_state *ws = fc->ws;
        for (int bounce = 0; bounce < 4; bounce++) {
            int side = x[k] < ws[2 * k].pos ? 2 * k : x[k] > ws[2 * k + 1].pos ? 2 * k + 1 : -1;
            if (side < 0)
                break;
            rng r = {{0, 0, 0, 0}};
            if (s->walls[side].kind == DSMC_WALL_DIFFUSE)
                dsmc_stream(&r, fc->seed, DSMC_STREAM_WALL, fc->step, id * 8 + (uint64_t)bounce);
            reflect(s, side, &ws[side], fc->dt, x, v, &r);
            hits++;
        }
        const double lo = ws[2 * k].pos, hi = ws[2 * k + 1].pos, L = hi - lo;
        if (!(x[k] < lo || x[k] > hi))
            continue;
        const double u = x[k] - lo;
        if (mirror_axis(s, fc, k) && fabs(u) < 1e12 * L) { /* beyond: digits of x left */
            const double c = floor(u / L);                   /* walls crossed: |c| */
            double m = u - 2 * L * floor(u / (2 * L));       /* in [0, 2L) */
            if (m > L) {
                m = 2 * L - m;
                v[k] = -v[k];
            }
            x[k] = fmin(fmax(lo + m, lo), hi);
            hits += (long)fabs(c);
            continue;
        }
        *stranded = 1;
        x[k] = x[k] < lo ? lo : hi;
    }
    return hits;
}

/* The flight loop for a dimension D, walls W (some axis below D not periodic) and gravity G
 * (some component not zero) known at compile time: a periodic box without gravity, the common
 * gas, pays nothing for the walls and gravity it does not have (9 of its 149 instructions per
 * particle before; a zero gravity added +0.0, which only turns a -0.0 into +0.0). */
static inline __attribute__((always_inline)) dsmc_flight_totals
flight_dim(dsmc_scene *s, const flight_consts *fc, size_t bcount[DSMC_SORT_BLOCKS], const int D,
           const bool W, const bool G)
{
    const long n = (long)s->n;
    double *const X[3] = {s->x[0], s->x[1], s->x[2]}, *const V[3] = {s->v[0], s->v[1], s->v[2]};
    uint32_t *const cell = s->cell;
    const double dt = fc->dt, hdt2 = fc->hdt2;
    double g[3], lo[3], hi[3], L[3], ih[3], wlo[3], whi[3];
    int nc[3];
    bool per[3], any_wall = false;
    for (int k = 0; k < 3; k++) {
        g[k] = fc->g[k];
        lo[k] = fc->lo[k];
        hi[k] = fc->hi[k];
        L[k] = fc->L[k];
        ih[k] = fc->inv_h[k];
        nc[k] = fc->cells[k];
        per[k] = fc->per[k];
        wlo[k] = per[k] ? -INFINITY : fc->ws[2 * k].pos;
        whi[k] = per[k] ? INFINITY : fc->ws[2 * k + 1].pos;
        any_wall = any_wall || (k < D && !per[k]);
    }
    const int sh = fc->sh;
    long hits = 0, stranded = 0, strand_id = LONG_MAX;
    int bad = 0;
    for (int b = 0; b < DSMC_SORT_BLOCKS; b++)
        bcount[b] = 0;
#pragma omp parallel for schedule(dynamic, 8192) \
    reduction(+ : hits, stranded, bcount[:DSMC_SORT_BLOCKS]) reduction(| : bad) \
    reduction(min : strand_id) if (n >= DSMC_PARALLEL_MIN)
    for (long i = 0; i < n; i++) {
        double x[3], v[3];
        int out = 0;
        for (int k = 0; k < D; k++) {
            x[k] = G ? X[k][i] + V[k][i] * dt + g[k] * hdt2 : X[k][i] + V[k][i] * dt;
            v[k] = G ? V[k][i] + g[k] * dt : V[k][i];
            if (!W || per[k]) {
                if (x[k] < lo[k])
                    x[k] += L[k];
                else if (x[k] >= hi[k])
                    x[k] -= L[k];
                if (!(x[k] >= lo[k] && x[k] < hi[k])) /* more than a box in one step */
                    x[k] -= L[k] * floor((x[k] - lo[k]) / L[k]);
            } else {
                out |= x[k] < wlo[k] || x[k] > whi[k];
            }
        }
        if (W && any_wall && out) {
            int st = 0;
            hits += walls_one(s, fc, D, s->id[i], x, v, &st);
            if (st) {
                stranded++;
                strand_id = (long)s->id[i] < strand_id ? (long)s->id[i] : strand_id;
            }
        }
        size_t c = 0;
        double chk = 0;
        for (int k = D - 1; k >= 0; k--) {
            X[k][i] = x[k];
            V[k][i] = v[k];
            chk += x[k] + v[k];
            double f = (x[k] - lo[k]) * ih[k];
            int ci = !(f >= 0) ? 0 : f >= nc[k] ? nc[k] - 1 : (int)f; /* NaN: 0 */
            c = c * (size_t)nc[k] + (size_t)ci;
        }
        bad |= !isfinite(chk);
        cell[i] = (uint32_t)c;
        bcount[c >> sh]++;
    }
    return (dsmc_flight_totals){hits, bad, stranded, strand_id};
}

/* Moves every particle, finds its cell and counts the particles per sort range (bcount). */
dsmc_flight_totals dsmc_flight(dsmc_scene *s, double dt, size_t bcount[DSMC_SORT_BLOCKS])
{
    flight_consts fc;
    memset(&fc, 0, sizeof fc);
    fc.dt = dt;
    fc.hdt2 = 0.5 * dt * dt;
    for (int k = 0; k < 3; k++) {
        fc.g[k] = s->def.gravity[k];
        fc.lo[k] = s->def.lo[k];
        fc.hi[k] = s->def.hi[k];
        fc.L[k] = fc.hi[k] - fc.lo[k];
        fc.inv_h[k] = s->inv_h[k];
        fc.cells[k] = s->def.cells[k];
        fc.per[k] = s->def.periodic[k];
    }
    for (int side = 0; side < 6; side++) {
        fc.ws[side].active = side < 2 * s->D && !s->def.periodic[side / 2];
        if (fc.ws[side].active)
            dsmc_wall_motion(s, side, s->t + dt, &fc.ws[side].pos, &fc.ws[side].vel);
    }
    fc.sh = dsmc_sort_shift(s->ncells);
    fc.seed = s->def.seed;
    fc.step = (uint64_t)s->steps;
    bool W = false, G = false;
    for (int k = 0; k < s->D; k++) {
        W = W || !fc.per[k];
        G = G || fc.g[k] != 0;
    }
    if (s->D == 2)
        return W ? (G ? flight_dim(s, &fc, bcount, 2, true, true)
                      : flight_dim(s, &fc, bcount, 2, true, false))
                 : (G ? flight_dim(s, &fc, bcount, 2, false, true)
                      : flight_dim(s, &fc, bcount, 2, false, false));
    return W ? (G ? flight_dim(s, &fc, bcount, 3, true, true)
                  : flight_dim(s, &fc, bcount, 3, true, false))
             : (G ? flight_dim(s, &fc, bcount, 3, false, true)
                  : flight_dim(s, &fc, bcount, 3, false, false));
}
