/* Contact forces: the normal laws (Herrmann Eq. 1a/1b, Padbidri Eq. 2.16), the tangential laws
 * (Herrmann Eq. 2a/2b, Padbidri Eq. 1.3/2.18) with slip including rotation (Eq. 2.A6) and the
 * moments they produce (Eq. 1.4). Pair forces go to per-pair storage, then each particle gathers
 * its own in a fixed order: no atomics, and the same sums for any number of threads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/clones.h"
#include "dem/cohesion.h"
#include "dem/dem_internal.h"

#include "dem/laws.inc"

/* A law outside its list's range never gets here: dem_set_contact and the checkpoint reader check
 * every law against its list's count. */
#define LAW_OUT_OF_RANGE() __builtin_unreachable()

/* Normal force magnitude, positive when repulsive: the normal law's elastic force, its damping,
 * the clip, then the attraction of a law that has one. gamma is the pair's viscous coefficient, or
 * its Brilliantov damping time. ddelta is the rate of overlap, positive while the particles
 * approach: ddelta = -(v_i - v_j).n with n from j to i. (Padbidri's Eq. 2.A3 prints
 * +(v^k - v^j).n; with that sign the damping would push separating grains together.) */
static inline double normal_force(const dem_contact_def *c, double k, double gamma, double delta,
                                  double sqrt_delta, double ddelta)
{
    double f;
    switch (c->normal) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_NORMAL_##ID:                                                                          \
        f = normal_##name(c, k, delta, sqrt_delta);                                                \
        break;
        DEM_NORMAL_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
    switch (c->damping) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_DAMPING_##ID:                                                                         \
        f = damping_##name(f, k, gamma, sqrt_delta, ddelta);                                       \
        break;
        DEM_DAMPING_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
    if (c->clip && f < 0)
        f = 0;
    switch (c->normal) { /* the laws with a tension column of 1 */
#define TENSION_0(ID, name)
#define TENSION_1(ID, name)                                                                        \
    case DEM_NORMAL_##ID:                                                                          \
        f += normal_##name##_tension(c, k, delta, sqrt_delta);                                     \
        break;
#define LAW_(a, ID, name, k, tension, ...) TENSION_##tension(ID, name)
        DEM_NORMAL_LAWS(LAW_, _)
#undef LAW_
#undef TENSION_1
#undef TENSION_0
    default:
        break;
    }
    return f;
}

/* The damping law alone: f plus its dashpot. */
static inline double damping_force(const dem_contact_def *c, double f, double k, double gamma,
                                   double sqrt_delta, double ddelta)
{
    switch (c->damping) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_DAMPING_##ID:                                                                         \
        return damping_##name(f, k, gamma, sqrt_delta, ddelta);
        DEM_DAMPING_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
}

/* A cohesive pair's constants (cohesion.h): R*, E* (from k = 4/3 E* sqrt(R*)), Gamma, and the
 * scene's bridge: V, gamma cos(theta), the rupture separation. */
typedef struct coh_pair {
    double R, E, G, V, gcos, rupture;
} coh_pair;

/* How far beyond touch (> 0) a contact that holds may be pulled before it breaks. */
static inline double coh_reach(const dem_contact_def *c, const coh_pair *h)
{
    return c->normal == DEM_NORMAL_JKR ? coh_jkr_pulloff_distance(h->R, h->E, h->G) : h->rupture;
}

/* One cohesive contact (JKR, DMT, or a normal law with a liquid bridge) at overlap delta (< 0: a
 * JKR contact or a bridge that holds): *fn the normal force (> 0 repulsive), *fnt the normal
 * load of the friction limit, *sqe the sqrt(delta) that the damping and the tangential spring
 * take. Returns 1 when the surfaces touch (a tangential force acts). As for the tension column of
 * laws.h, the clip keeps only the damping from pulling: the adhesion is added after it. The
 * friction limit of JKR and DMT is LAMMPS's, |F_ne + 2 F_pulloff| with F_ne the elastic force
 * including the adhesion (pull-off forces 3/2 pi Gamma R and 2 pi Gamma R); a bridge's is the
 * contact's repulsion, which carries the bridge's pull. */
static inline int cohesive_force(const dem_contact_def *c, const coh_pair *h, double k,
                                 double gamma, double delta, double sq, double ddelta, double *fn,
                                 double *fnt, double *sqe)
{
    if (c->normal == DEM_NORMAL_JKR || c->normal == DEM_NORMAL_DMT) {
        double fh, fa, se = sq;
        if (c->normal == DEM_NORMAL_JKR) {
            coh_jkr(h->R, h->E, h->G, delta, &fh, &fa, &se);
        } else {
            fh = k * delta * sq;
            fa = 2 * COH_PI * h->G * h->R;
        }
        double f = damping_force(c, fh, k, gamma, se, ddelta);
        if (c->clip && f < 0)
            f = 0;
        const double po = c->normal == DEM_NORMAL_JKR ? 1.5 * COH_PI * h->G * h->R : fa;
        *fn = f - fa;
        *fnt = fabs(fh - fa + 2 * po);
        *sqe = se;
        return 1;
    }
    if (delta > 0) {
        const double f = normal_force(c, k, gamma, delta, sq, ddelta);
        *fn = f - coh_capillary(h->R, h->V, h->gcos, 0);
        *fnt = f;
        *sqe = sq;
        return 1;
    }
    *fn = -coh_capillary(h->R, h->V, h->gcos, -delta);
    *fnt = 0;
    *sqe = 0;
    return 0;
}

double dem_normal_force(const dem_contact_def *c, double k, double gamma, double delta,
                        double ddelta)
{
    return normal_force(c, k, gamma, delta, sqrt(delta), ddelta);
}

double dem_elastic_energy(const dem_contact_def *c, double k, double delta)
{
    switch (c->normal) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_NORMAL_##ID:                                                                          \
        return normal_##name##_energy(c, k, delta);
        DEM_NORMAL_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
}

double dem_law_beta(const dem_contact_def *c)
{
    switch (c->normal) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_NORMAL_##ID:                                                                          \
        return normal_##name##_beta(c);
        DEM_NORMAL_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
}

/* Tangential spring stiffness: given, or the normal law's default (2/7 of d f / d delta). */
static inline double spring_stiffness(const dem_contact_def *c, double k, double delta,
                                      double sqrt_delta)
{
    if (c->kt > 0)
        return c->kt;
    switch (c->normal) {
#define LAW_(a, ID, name, ...)                                                                     \
    case DEM_NORMAL_##ID:                                                                          \
        return normal_##name##_kt(c, k, delta, sqrt_delta);
        DEM_NORMAL_LAWS(LAW_, _)
#undef LAW_
    default:
        LAW_OUT_OF_RANGE();
    }
}

/* Magnitude of the regularised Coulomb force (Padbidri Eq. 2.18), capped at mu f_n: the paper's
 * law is meant for slip rates near v_R; the cap keeps fast sliding Coulombic. */
static inline double regularized(const dem_contact_def *c, const dem_power *pw, double mu,
                                 double fn, double s)
{
    double x = s * (1 / c->v_r); /* the reciprocal is loop-invariant: hoisted out of the kernel */
    return x >= 1 ? mu * fn : mu * fn * dem_power_eval(pw, x); /* x^(1/c) */
}

#include "dem/rolling.inc"

#if defined(__GNUC__) && !defined(__clang__)
#define GATHER_NO_VECTORIZE __attribute__((optimize("no-tree-vectorize")))
#else
#define GATHER_NO_VECTORIZE
#endif

#define DIM 2
#include "dem/forces_dim.inc"
#undef DIM
#define DIM 3
#include "dem/forces_dim.inc"
#undef DIM

size_t dem_compute_forces(dem_scene *s, double dt)
{
    s->force_evals++;
    size_t t;
    const int roll = s->contact.rolling_law != DEM_ROLLING_NONE; /* rolling.inc */
    if (s->dim == 2) {
        pair_forces_2(s, dt);
        if (roll)
            roll_pairs(s, dt);
        gather_2(s);
        if (roll)
            roll_gather(s);
        t = walls_2(s, dt);
    } else {
        pair_forces_3(s, dt);
        if (roll)
            roll_pairs(s, dt);
        gather_3(s);
        if (roll)
            roll_gather(s);
        t = walls_3(s, dt);
    }
    if (s->nshaped) { /* walls beyond planes: a scene of planes never comes here */
        const size_t t2 = s->dim == 2 ? shape_walls_2(s, dt) : shape_walls_3(s, dt);
        t = t2 < t ? t2 : t;
    }
    return t;
}
