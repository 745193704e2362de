/* The MPM step's stress update (Sec. 2 step 3, continued): each point's velocity gradient,
 * deformation gradient and constitutive update (material_inline.h, the laws of material.c) in
 * blocks of points, two at a time in SSE2 lanes, fused with the end-of-step check of the point
 * (non-finite values, a point leaving the grid, the periodic wrap). */
#include <math.h>

#include "mpm/material_inline.h"
#include "mpm/step_internal.h"

/* The end-of-step check's bounds per axis: [lo, hi) of a periodic axis, [lo, hi] (the slack
 * beyond the grid included) of another. Taken once per pass: inside the point loop, stores to
 * the point arrays could alias the scene's fields, which would be reloaded at every point. */
typedef struct {
    double lo[2], hi[2];
    bool periodic[2];
} check_bounds;

static inline check_bounds bounds_of(const mpm_scene *s)
{
    check_bounds b;
    for (int a = 0; a < 2; a++) {
        const double o = s->def.origin[a], L = s->def.size[a];
        b.periodic[a] = s->def.periodic[a];
        b.lo[a] = b.periodic[a] ? o : o - s->slack[a][0];
        b.hi[a] = b.periodic[a] ? o + L : o + L + s->slack[a][1];
    }
    return b;
}

/* A coordinate outside its periodic axis wrapped back (rare: out of line). */
static __attribute__((noinline, cold)) void wrap_axis(const mpm_scene *s, int a, double *c)
{
    const double o = s->def.origin[a], L = s->def.size[a];
    *c -= L * floor((*c - o) / L);
    if (*c >= o + L) /* rounding of a value just below o */
        *c = o;
}

/* The end-of-step check of a point at (*x, *y) with velocity (vx, vy) and in-plane stress sig:
 * wraps it on periodic axes; true when it is non-finite or outside the grid on an axis that is
 * not periodic. */
static inline bool point_bad_at(const mpm_scene *s, const check_bounds *b, double *x, double *y,
                                double vx, double vy, const double sig[3])
{
    /* 0 * v is 0 for finite v and NaN for inf or NaN: one test for all seven */
    const double z = 0 * *x + 0 * *y + 0 * vx + 0 * vy + 0 * sig[0] + 0 * sig[1] + 0 * sig[2];
    if (!(z == 0))
        return true;
    double *c[2] = {x, y};
    bool bad = false;
    for (int a = 0; a < 2; a++) {
        const double v = *c[a];
        if (b->periodic[a]) {
            if (v < b->lo[a] || v >= b->hi[a])
                wrap_axis(s, a, c[a]);
        } else if (v < b->lo[a] || v > b->hi[a]) {
            bad = true;
        }
    }
    return bad;
}

static inline bool point_bad(mpm_scene *s, const check_bounds *b, size_t p)
{
    const double sig[3] = {s->sig[0][p], s->sig[1][p], s->sig[2][p]};
    return point_bad_at(s, b, &s->x[p], &s->y[p], s->vx[p], s->vy[p], sig);
}

/* Whether the end-of-step check (point_bad_at) may have anything to do for a point: a
 * non-finite value, or a coordinate outside [lo, hi) (a periodic one to wrap, another that is
 * bad; a non-periodic one at hi exactly is a suspect that point_bad_at then clears).
 * Branch-free, for the stress update's lanes. */
static inline bool point_suspect(const check_bounds *b, double x, double y, double vx, double vy,
                                 const double sig[3])
{
    /* s - s is 0 for a finite sum and NaN for a non-finite value (or a sum that overflows: a
     * suspect too, which point_bad_at clears) */
    const double sum = x + y + vx + vy + sig[0] + sig[1] + sig[2];
    return !(sum - sum == 0) | (x < b->lo[0]) | (x >= b->hi[0]) | (y < b->lo[1]) | (y >= b->hi[1]);
}

/* The stress update works on blocks of CB points in passes, so that the arithmetic before and
 * after the (scalar, libm) logarithms runs two points at a time in SSE2 lanes: (A1) the
 * velocity gradient's gather (scalar: SSE2 has no gather) and the increment f; (A2, lanes) F,
 * the trial b_e and its eigen-split; (B) the two logarithms per point; (C, lanes) the elastic
 * return, b_e and sigma, with a flag on each point a lane cannot finish (possibly plastic, or one
 * the end-of-step check must look at); (D) the flagged points, scalar, in order. Each lane does
 * material_update_zz's operations in its order through the same functions, and IEEE arithmetic is
 * the same per lane as scalar, so the bits are the scalar update's. (C) runs over the block's
 * runs of points of one material. A block with an inverted point takes (B)-(D) one point at a
 * time (finish_point), as material_update_zz does. With s->no_lanes, (A2)-(D) are point_scalar
 * instead: the reference tests/mpm/test_mpm_lanes.c compares the lanes with. */
enum { CB = 64 }; /* the block (cblock): 7 kB, in L1; CB = 16 cost 7 instructions per point more */
typedef struct {
    double f[4][CB], tr[3][CB], dir[3][CB], lg[2][CB], J[CB];
    double flag[CB]; /* 1 or 0: doubles, which SSE2 selects as lanes (64-bit integers not) */
} cblock;

/* Point p's new in-plane b_e and stress stored, then with chk the end-of-step check (*first: the
 * first bad point). */
static inline void store_point(mpm_scene *s, const check_bounds *cb, bool chk, size_t p,
                               const double be[3], const double sig[4], size_t *first)
{
    s->be[0][p] = be[0];
    s->be[1][p] = be[1];
    s->be[2][p] = be[2];
    s->sig[0][p] = sig[0];
    s->sig[1][p] = sig[1];
    s->sig[2][p] = sig[2];
    s->sig[3][p] = sig[3];
    if (chk && point_bad_at(s, cb, &s->x[p], &s->y[p], s->vx[p], s->vy[p], sig) &&
        *first == (size_t)-1)
        *first = p;
}

/* Point j (p) of a block, scalar, from its log strains eps: material_point, the stores, and
 * with chk the end-of-step check (*first: the first bad point). */
static inline void finish_point(mpm_scene *s, const check_bounds *cb, bool chk, const cblock *T,
                                int j, size_t p, const double eps[3], double dt, size_t *first)
{
    const double tr[3] = {T->tr[0][j], T->tr[1][j], T->tr[2][j]};
    const double dir[3] = {T->dir[0][j], T->dir[1][j], T->dir[2][j]};
    double be[3], sig[4];
    material_point(&s->mats[s->mat[p]], dt, tr, eps, dir, T->J[j], be, &s->be[3][p], &s->lzz[p],
                   &s->eps_p[p], s->rate ? &s->rate[p] : NULL, sig);
    store_point(s, cb, chk, p, be, sig, first);
}

/* Point p from its increment f, scalar: F, material_update_zz, the stores, with chk the
 * end-of-step check; *bad: the first inverted point, *first: the first bad one. The stress
 * update's reference (s->no_lanes). */
static void point_scalar(mpm_scene *s, const check_bounds *cb, bool chk, const double f[4],
                         double dt, size_t p, size_t *bad, size_t *first)
{
    const double Fa = s->F[0][p], Fb = s->F[1][p], Fc = s->F[2][p], Fd = s->F[3][p];
    const double G0 = f[0] * Fa + f[1] * Fc, G1 = f[0] * Fb + f[1] * Fd;
    const double G2 = f[2] * Fa + f[3] * Fc, G3 = f[2] * Fb + f[3] * Fd;
    s->F[0][p] = G0;
    s->F[1][p] = G1;
    s->F[2][p] = G2;
    s->F[3][p] = G3;
    const double J = G0 * G3 - G1 * G2;
    double be[3] = {s->be[0][p], s->be[1][p], s->be[2][p]}, sig[4];
    if (material_update_zz(&s->mats[s->mat[p]], f, dt, be, &s->be[3][p], &s->lzz[p],
                           &s->eps_p[p], s->rate ? &s->rate[p] : NULL, J, sig) < 0) {
        if (*bad == (size_t)-1)
            *bad = p;
        return;
    }
    store_point(s, cb, chk, p, be, sig, first);
}

/* material_update_zz's and log_strains's conditions (det f > 0, J > 0, l2 > 0 and ln(b_e,zz) / 2
 * = lz > -inf), branch-free. */
static inline bool update_ok(const double f[4], double J, double l2, double lz)
{
    return (f[0] * f[3] - f[1] * f[2] > 0) & (J > 0) & (l2 > 0) & (lz > -INFINITY);
}

/* (A2) of point j (p): F, J, the trial b_e and its eigen-split into the block; returns whether
 * the update can go on (update_ok: 1, else 0). A function called from the simd loop, so that
 * its arrays are scalarised after inlining rather than made the loop's per-lane arrays. */
static inline __attribute__((always_inline)) double
lane_trial(cblock *T, int j, size_t p, double *F0, double *F1, double *F2, double *F3,
           const double *b0, const double *b1, const double *b2, const double *lzz)
{
    const double f[4] = {T->f[0][j], T->f[1][j], T->f[2][j], T->f[3][j]};
    const double Fa = F0[p], Fb = F1[p], Fc = F2[p], Fd = F3[p];
    const double G0 = f[0] * Fa + f[1] * Fc, G1 = f[0] * Fb + f[1] * Fd;
    const double G2 = f[2] * Fa + f[3] * Fc, G3 = f[2] * Fb + f[3] * Fd;
    F0[p] = G0;
    F1[p] = G1;
    F2[p] = G2;
    F3[p] = G3;
    const double J = G0 * G3 - G1 * G2;
    const double be[3] = {b0[p], b1[p], b2[p]};
    double tr[3], l1, l2, dir[3];
    trial_be(f, be, tr);
    eig2(tr[0], tr[1], tr[2], &l1, &l2, dir);
    const double ok = update_ok(f, J, l2, lzz[p]) ? 1.0 : 0.0;
    for (int c = 0; c < 3; c++) {
        T->tr[c][j] = tr[c];
        T->dir[c][j] = dir[c];
    }
    T->lg[0][j] = l1;
    T->lg[1][j] = l2;
    T->J[j] = J;
    return ok;
}

/* The arrays of the elastic pass (C). */
typedef struct {
    const double *lzz, *eps_p, *x, *y, *vx, *vy;
    double *b0, *b1, *b2, *s0, *s1, *s2, *s3;
} elastic_ctx;

/* (C) of point j (p), material m: the elastic return from the logarithms (T->lg), its b_e and
 * sigma stored; returns (and flags) 1 when (D) must look at the point: possibly plastic (vm, a
 * von Mises material, and not within_yield), or with chk a suspect for the end-of-step check;
 * else 0. */
static inline __attribute__((always_inline)) double
lane_elastic(cblock *T, int j, size_t p, const mpm_material *m, const check_bounds *cb,
             const elastic_ctx *restrict E, const bool vm, const bool chk)
{
    const double eps[3] = {0.5 * T->lg[0][j], 0.5 * T->lg[1][j], E->lzz[p]};
    const double dir[3] = {T->dir[0][j], T->dir[1][j], T->dir[2][j]};
    double ev, e[3], sig[4];
    const double en2 = dev_split(eps, &ev, e);
    stress_of(m, ev, e, dir, T->J[j], sig);
    E->b0[p] = T->tr[0][j];
    E->b1[p] = T->tr[1][j];
    E->b2[p] = T->tr[2][j];
    E->s0[p] = sig[0];
    E->s1[p] = sig[1];
    E->s2[p] = sig[2];
    E->s3[p] = sig[3];
    double f = 0;
    if (vm)
        f = within_yield(m, en2, E->eps_p[p]) ? f : 1.0;
    if (chk)
        f = point_suspect(cb, E->x[p], E->y[p], E->vx[p], E->vy[p], sig) ? 1.0 : f;
    T->flag[j] = f;
    return f;
}

/* The loop of (C) over points ja..jb-1 of the block, of one material m, with vm and chk
 * constants; returns the number of flagged points. */
static inline __attribute__((always_inline)) double
pass_elastic(cblock *T, int ja, int jb, size_t p0, const mpm_material *m, const check_bounds *cb,
             const elastic_ctx *E, const bool vm, const bool chk)
{
    /* local copies, which the stores cannot alias: held in registers, not reloaded */
    const elastic_ctx e = *E;
    const mpm_material mc = *m;
    double any = 0; /* a sum of 0s and 1s: exact in any order */
#pragma omp simd reduction(+ : any)
    for (int j = ja; j < jb; j++)
        any += lane_elastic(T, j, p0 + (size_t)j, &mc, cb, &e, vm, chk);
    return any;
}

/* Step 3, continued, for points [pa, pb): velocity gradient L = sum_i v_i G_pi, F <- (I + dt L)
 * F, stress update. Returns the first point that inverts, or (size_t)-1; with check, each
 * point's end-of-step check (point_bad_at) follows its update, and *check is the first bad
 * point. */
static inline __attribute__((always_inline)) size_t
constitutive_with(mpm_scene *s, double dt, size_t pa, size_t pb, const double *vx, const double *vy,
                  size_t *check, const int ns)
{
    size_t bad = (size_t)-1, first = (size_t)-1;
    /* the arrays as locals: stores through one could alias the scene's fields, which would be
     * reloaded; the lanes' iterations are independent (omp simd) */
    const int *const sf = s->sf, *const mat = s->mat;
    const double *const sgx = s->sgx, *const sgy = s->sgy;
    double *const F0 = s->F[0], *const F1 = s->F[1], *const F2 = s->F[2], *const F3 = s->F[3];
    double *const b0 = s->be[0], *const b1 = s->be[1], *const b2 = s->be[2];
    const double *const lzz = s->lzz;
    const mpm_material *const mats = s->mats;
    const check_bounds cb = bounds_of(s);
    const bool chk = check != NULL;
    const elastic_ctx E = {.lzz = lzz,
                           .eps_p = s->eps_p,
                           .x = s->x,
                           .y = s->y,
                           .vx = s->vx,
                           .vy = s->vy,
                           .b0 = b0,
                           .b1 = b1,
                           .b2 = b2,
                           .s0 = s->sig[0],
                           .s1 = s->sig[1],
                           .s2 = s->sig[2],
                           .s3 = s->sig[3]};
    cblock T;
    const size_t pe = pb;
    for (size_t p0 = pa; p0 < pe; p0 += CB) {
        const int nb = pe - p0 < CB ? (int)(pe - p0) : CB;
        /* (A1) */
        for (int j = 0; j < nb; j++) {
            const size_t p = p0 + (size_t)j;
            const int *n = &sf[ns * p];
            const double *gx = &sgx[ns * p], *gy = &sgy[ns * p];
            /* {L_xx, L_yx} and {L_xy, L_yy} in the lanes of two vectors (v2d), each lane's sum
             * in the scalar order */
            v2d Lx = {0, 0}, Ly = {0, 0};
            for (int k = 0; k < ns; k++) {
                const int i = n[k];
                const v2d v = {vx[i], vy[i]}, gxk = {gx[k], gx[k]}, gyk = {gy[k], gy[k]};
                Lx += v * gxk;
                Ly += v * gyk;
            }
            const v2d dx = dt * Lx, dy = dt * Ly;
            T.f[0][j] = 1 + dx[0];
            T.f[1][j] = dy[0];
            T.f[2][j] = dx[1];
            T.f[3][j] = 1 + dy[1];
            __asm__(""); /* keeps the loop over the points scalar: SSE2 has no gather */
        }
        if (s->no_lanes) {
            for (int j = 0; j < nb; j++) {
                const double f[4] = {T.f[0][j], T.f[1][j], T.f[2][j], T.f[3][j]};
                point_scalar(s, &cb, chk, f, dt, p0 + (size_t)j, &bad, &first);
            }
            continue;
        }
        /* (A2) */
        double nok = 0; /* a sum of 0s and 1s: exact in any order */
#pragma omp simd reduction(+ : nok)
        for (int j = 0; j < nb; j++)
            nok += lane_trial(&T, j, p0 + (size_t)j, F0, F1, F2, F3, b0, b1, b2, lzz);
        if (__builtin_expect(nok != nb, 0)) {
            /* (B)-(D) one point at a time */
            for (int j = 0; j < nb; j++) {
                const size_t p = p0 + (size_t)j;
                const double f[4] = {T.f[0][j], T.f[1][j], T.f[2][j], T.f[3][j]};
                if (!update_ok(f, T.J[j], T.lg[1][j], lzz[p])) {
                    if (bad == (size_t)-1)
                        bad = p;
                    continue;
                }
                const double eps[3] = {0.5 * log(T.lg[0][j]), 0.5 * log(T.lg[1][j]), lzz[p]};
                finish_point(s, &cb, chk, &T, j, p, eps, dt, &first);
            }
            continue;
        }
        /* (B) */
        for (int j = 0; j < nb; j++) {
            T.lg[0][j] = log(T.lg[0][j]);
            T.lg[1][j] = log(T.lg[1][j]);
        }
        /* (C), by runs of points of one material */
        double any = 0;
        int other = 0; /* points of another material than the first: a count that vectorises */
        for (int j = 1; j < nb; j++)
            other += mat[p0 + (size_t)j] != mat[p0];
        for (int ja = 0, jb; ja < nb; ja = jb) {
            const int mk = mat[p0 + (size_t)ja];
            if (!other)
                jb = nb;
            else
                for (jb = ja + 1; jb < nb && mat[p0 + (size_t)jb] == mk; jb++)
                    ;
            const mpm_material *const m = &mats[mk];
            if (m->model != MPM_ELASTIC && m->model != MPM_VONMISES) {
                /* the granular continuum models: every point in (D) */
                for (int j = ja; j < jb; j++)
                    T.flag[j] = 1;
                any += jb - ja;
                continue;
            }
            const bool vm = m->model == MPM_VONMISES;
            any += vm ? (chk ? pass_elastic(&T, ja, jb, p0, m, &cb, &E, true, true)
                             : pass_elastic(&T, ja, jb, p0, m, &cb, &E, true, false))
                      : (chk ? pass_elastic(&T, ja, jb, p0, m, &cb, &E, false, true)
                             : pass_elastic(&T, ja, jb, p0, m, &cb, &E, false, false));
        }
        /* (D) */
        if (any)
            for (int j = 0; j < nb; j++)
                if (T.flag[j]) {
                    const size_t p = p0 + (size_t)j;
                    const double eps[3] = {0.5 * T.lg[0][j], 0.5 * T.lg[1][j], lzz[p]};
                    finish_point(s, &cb, chk, &T, j, p, eps, dt, &first);
                }
    }
    if (check)
        *check = first;
    return bad;
}

/* constitutive_with with ns = 4 (linear shapes) a constant: the stencil loops unroll. */
STAGE static size_t constitutive(mpm_scene *s, double dt, size_t pa, size_t pb, const double *vx,
                                 const double *vy, size_t *check)
{
    if (s->ns == 4)
        return constitutive_with(s, dt, pa, pb, vx, vy, check, 4);
    return constitutive_with(s, dt, pa, pb, vx, vy, check, s->ns);
}

/* The check of every point, for USF (whose stress update comes before the positions'); the
 * other orders check each point right after its stress update (constitutive). Returns the first
 * bad point, or (size_t)-1. */
size_t mpm_check_points(mpm_scene *s, int nt)
{
    size_t first = (size_t)-1;
    const check_bounds cb = bounds_of(s);
#pragma omp parallel for schedule(static) reduction(min : first) num_threads(nt) if (nt > 1)
    for (size_t p = 0; p < s->np; p++)
        if (point_bad(s, &cb, p))
            first = p < first ? p : first;
    return first;
}

/* ---- the stages ------------------------------------------------------------------------------ */
/* USF: the update from v_i^n, before the transfer; the check follows the positions' update
 * (mpm_check_points) */
void mpm_stage_stress(mpm_scene *s, mpm_step *ctx, int t)
{
    ctx->tbad[t] = constitutive(s, ctx->dt, ctx->tp[t], ctx->tp[t + 1], s->nax, s->nay, NULL);
}

/* USL and MUSL: the update at the end of the step, each point checked right after it */
void mpm_stage_stress_check(mpm_scene *s, mpm_step *ctx, int t)
{
    ctx->tbad[t] =
        constitutive(s, ctx->dt, ctx->tp[t], ctx->tp[t + 1], s->nax, s->nay, &ctx->tcheck[t]);
}
