/* Clumps: rigid bodies whose members are particles of the scene. The members' forces and
 * torques are summed onto the body; the body is integrated by velocity Verlet, its rotation in
 * 3D by the NO_SQUISH splitting of the free rotor (Miller et al. 2002, Eqs. 2.15-2.24: the
 * conjugate quaternion momentum turned about the principal axes 3, 2, 1, 2, 3), which keeps
 * the quaternion unit and conserves |L| of a free body to rounding; the members are placed and
 * given velocities from the body. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/comm.h"
#include "dem/dem_internal.h"

/* ---- quaternions (w, x, y, z): body frame to world ---------------------------------------- */
static void quat_matrix(const double q[4], double R[9])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

static void quat_mul(const double a[4], const double b[4], double c[4])
{
    c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

/* The unit quaternion of a rotation matrix (Shepperd's choice of the largest pivot). */
static void matrix_quat(const double R[9], double q[4])
{
    double tr = R[0] + R[4] + R[8];
    if (tr > 0) {
        double s = 2 * sqrt(tr + 1);
        q[0] = 0.25 * s, q[1] = (R[7] - R[5]) / s, q[2] = (R[2] - R[6]) / s;
        q[3] = (R[3] - R[1]) / s;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        double s = 2 * sqrt(1 + R[0] - R[4] - R[8]);
        q[0] = (R[7] - R[5]) / s, q[1] = 0.25 * s, q[2] = (R[1] + R[3]) / s;
        q[3] = (R[2] + R[6]) / s;
    } else if (R[4] > R[8]) {
        double s = 2 * sqrt(1 + R[4] - R[0] - R[8]);
        q[0] = (R[2] - R[6]) / s, q[1] = (R[1] + R[3]) / s, q[2] = 0.25 * s;
        q[3] = (R[5] + R[7]) / s;
    } else {
        double s = 2 * sqrt(1 + R[8] - R[0] - R[4]);
        q[0] = (R[3] - R[1]) / s, q[1] = (R[2] + R[6]) / s, q[2] = (R[5] + R[7]) / s;
        q[3] = 0.25 * s;
    }
}

static void mat_vec(const double R[9], const double v[3], double o[3])
{
    for (int r = 0; r < 3; r++)
        o[r] = R[3 * r] * v[0] + R[3 * r + 1] * v[1] + R[3 * r + 2] * v[2];
}

static void mat_tvec(const double R[9], const double v[3], double o[3])
{
    for (int c = 0; c < 3; c++)
        o[c] = R[c] * v[0] + R[3 + c] * v[1] + R[6 + c] * v[2];
}

/* Miller et al. Eq. 2.21: the free rotation about principal axis k (1..3) for a time dt of the
 * conjugate momentum p = 2 S(q) (0, L_body) and of q. */
static void no_squish_rotate(int k, double p[4], double q[4], const double I[3], double dt)
{
    double kp[4], kq[4];
    if (k == 1) {
        kq[0] = -q[1], kp[0] = -p[1], kq[1] = q[0], kp[1] = p[0];
        kq[2] = q[3], kp[2] = p[3], kq[3] = -q[2], kp[3] = -p[2];
    } else if (k == 2) {
        kq[0] = -q[2], kp[0] = -p[2], kq[1] = -q[3], kp[1] = -p[3];
        kq[2] = q[0], kp[2] = p[0], kq[3] = q[1], kp[3] = p[1];
    } else {
        kq[0] = -q[3], kp[0] = -p[3], kq[1] = q[2], kp[1] = p[2];
        kq[2] = -q[1], kp[2] = -p[1], kq[3] = q[0], kp[3] = p[0];
    }
    double phi = (p[0] * kq[0] + p[1] * kq[1] + p[2] * kq[2] + p[3] * kq[3]) / (4 * I[k - 1]);
    double c = cos(dt * phi), s = sin(dt * phi);
    for (int a = 0; a < 4; a++) {
        p[a] = c * p[a] + s * kp[a];
        q[a] = c * q[a] + s * kq[a];
    }
}

/* 3D: the body's rotation by dt at constant L (world), then omega from L. */
static void rotate_3d(dem_body *b, double dt)
{
    double R[9], Lb[3], p[4], q[4];
    quat_matrix(b->q, R);
    mat_tvec(R, b->L, Lb);
    const double l4[4] = {0, Lb[0], Lb[1], Lb[2]};
    quat_mul(b->q, l4, p);
    for (int a = 0; a < 4; a++)
        p[a] *= 2, q[a] = b->q[a];
    no_squish_rotate(3, p, q, b->moment, 0.5 * dt);
    no_squish_rotate(2, p, q, b->moment, 0.5 * dt);
    no_squish_rotate(1, p, q, b->moment, dt);
    no_squish_rotate(2, p, q, b->moment, 0.5 * dt);
    no_squish_rotate(3, p, q, b->moment, 0.5 * dt);
    double nq = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int a = 0; a < 4; a++)
        b->q[a] = q[a] / nq;
    /* L stays the world's: each sub-rotation is the exact flow of a rotation-invariant part
     * of the kinetic energy */
}

static void update_omega(const dem_scene *s, dem_body *b)
{
    if (s->dim == 2) {
        b->omega[2] = b->L[2] / b->moment[2];
        return;
    }
    double R[9], Lb[3];
    quat_matrix(b->q, R);
    mat_tvec(R, b->L, Lb);
    for (int d = 0; d < 3; d++)
        Lb[d] /= b->moment[d];
    mat_vec(R, Lb, b->omega);
}

static void body_matrix(const dem_scene *s, const dem_body *b, double R[9])
{
    if (s->dim == 2) {
        double cs = cos(b->angle), sn = sin(b->angle);
        double R2[9] = {cs, -sn, 0, sn, cs, 0, 0, 0, 1};
        memcpy(R, R2, sizeof R2);
    } else {
        quat_matrix(b->q, R);
    }
}

/* Members from the body: positions (with `place`), velocities, spins, angles. */
static void place_members(dem_scene *s, dem_body *b, int place)
{
    const dem_clumps *c = s->clumps;
    double R[9];
    body_matrix(s, b, R);
    for (size_t i = b->first; i < b->first + b->count; i++) {
        double r[3];
        mat_vec(R, c->off + 3 * i, r);
        const double wr[3] = {b->omega[1] * r[2] - b->omega[2] * r[1],
                              b->omega[2] * r[0] - b->omega[0] * r[2],
                              b->omega[0] * r[1] - b->omega[1] * r[0]};
        for (int d = 0; d < s->dim; d++) {
            if (place)
                s->x[d][i] = b->x[d] + r[d];
            s->v[d][i] = b->v[d] + wr[d];
        }
        if (s->rot)
            for (int d = s->dim == 2 ? 2 : 0; d < 3; d++)
                s->w[d][i] = b->omega[d];
        if (s->angle)
            s->angle[i] = b->angle;
    }
}

/* Force and torque on the body from its members' forces (the members' shares of gravity act
 * at the centre: a body's weight has no torque about it). The lever arms come from the body's
 * pose, not from the members' positions, which the particles' own drift has moved on. */
static void body_load(const dem_scene *s, dem_body *b)
{
    memset(b->f, 0, sizeof b->f);
    memset(b->t, 0, sizeof b->t);
    double R[9];
    body_matrix(s, b, R);
    for (size_t i = b->first; i < b->first + b->count; i++) {
        double r[3], f[3] = {0, 0, 0};
        mat_vec(R, s->clumps->off + 3 * i, r);
        for (int d = 0; d < s->dim; d++) {
            b->f[d] += s->f[d][i];
            f[d] = s->f[d][i] - s->m[i] * s->gravity[d];
        }
        b->t[0] += r[1] * f[2] - r[2] * f[1];
        b->t[1] += r[2] * f[0] - r[0] * f[2];
        b->t[2] += r[0] * f[1] - r[1] * f[0];
        if (s->rot)
            for (int d = s->dim == 2 ? 2 : 0; d < 3; d++)
                b->t[d] += s->tq[d][i];
    }
}

static void kick_body(const dem_scene *s, dem_body *b, double h)
{
    body_load(s, b);
    for (int d = 0; d < s->dim; d++)
        b->v[d] += h * b->f[d] / b->mass;
    for (int d = s->dim == 2 ? 2 : 0; d < 3; d++)
        b->L[d] += h * b->t[d];
}

void dem_clumps_kick_drift(dem_scene *s, double h, double dt)
{
    dem_clumps *c = s->clumps;
    for (size_t k = 0; k < c->n; k++) {
        dem_body *b = &c->b[k];
        kick_body(s, b, h);
        update_omega(s, b);
        for (int d = 0; d < s->dim; d++)
            b->x[d] += dt * b->v[d];
        if (s->dim == 2)
            b->angle += dt * b->omega[2];
        else
            rotate_3d(b, dt);
        update_omega(s, b);
        place_members(s, b, 1);
    }
}

void dem_clumps_kick(dem_scene *s, double h)
{
    dem_clumps *c = s->clumps;
    for (size_t k = 0; k < c->n; k++) {
        dem_body *b = &c->b[k];
        kick_body(s, b, h);
        update_omega(s, b);
        place_members(s, b, 0);
    }
}

core_status dem_clumps_check_run(const dem_scene *s, int integrator, core_error *err)
{
    if (!s->clumps || s->clumps->n == 0)
        return CORE_OK;
    if (comm_size() > 1)
        return core_fail(err, CORE_ERR_STATE, "clumps do not yet run distributed (comm_size() "
                         "> 1): run this scene on one rank");
    for (int d = 0; d < s->dim; d++)
        if (s->periodic[d])
            return core_fail(err, CORE_ERR_STATE,
                             "clumps do not yet run in a periodic box (axis %d is periodic)", d + 1);
    if (integrator == DEM_POSITION_VERLET || integrator == DEM_GEAR5)
        return core_fail(err, CORE_ERR_STATE, "clumps run with velocity Verlet or two "
                         "timescales only, not with integrator '%s'",
                         integrator == DEM_GEAR5 ? "gear" : "position_verlet");
    if (s->flow)
        return core_fail(err, CORE_ERR_STATE,
                         "clumps do not yet run with inserters or outflows");
    if (s->bnd)
        return core_fail(err, CORE_ERR_STATE, "clumps do not yet run with boundary conditions "
                         "(pressure tractions, the minimal boundary, springs, ties, spins)");
    return CORE_OK;
}

core_status dem_clumps_grow(dem_scene *s, size_t old_cap, size_t cap, core_error *err)
{
    dem_clumps *c = s->clumps;
    int32_t *bd = realloc(c->body, cap * sizeof *bd);
    if (bd)
        c->body = bd;
    double *off = realloc(c->off, 3 * cap * sizeof *off);
    if (off)
        c->off = off;
    if (!bd || !off)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu particles", cap);
    for (size_t i = old_cap; i < cap; i++)
        c->body[i] = -1;
    memset(c->off + 3 * old_cap, 0, 3 * (cap - old_cap) * sizeof *off);
    return CORE_OK;
}

void dem_clumps_free(dem_scene *s)
{
    if (!s->clumps)
        return;
    free(s->clumps->b), free(s->clumps->body), free(s->clumps->off);
    free(s->clumps);
    s->clumps = NULL;
}

void dem_clumps_energy(const dem_scene *s, double *kin, double *rot, double *pot)
{
    *kin = *rot = *pot = 0;
    const dem_clumps *c = s->clumps;
    for (size_t k = 0; c && k < c->n; k++) {
        const dem_body *b = &c->b[k];
        for (int d = 0; d < s->dim; d++) {
            *kin += 0.5 * b->mass * b->v[d] * b->v[d];
            *pot -= b->mass * s->gravity[d] * b->x[d];
        }
        for (int d = s->dim == 2 ? 2 : 0; d < 3; d++)
            *rot += 0.5 * b->omega[d] * b->L[d];
    }
}

size_t dem_clump_count(const dem_scene *s) { return s->clumps ? s->clumps->n : 0; }

long dem_particle_clump(const dem_scene *s, size_t i)
{
    return s->clumps && i < s->n ? s->clumps->body[i] : -1;
}

core_status dem_clump_get(const dem_scene *s, size_t k, dem_clump_state *o, core_error *err)
{
    if (k >= dem_clump_count(s))
        return core_fail(err, CORE_ERR_ARG, "clump %zu does not exist (the scene has %zu)", k + 1,
                         dem_clump_count(s));
    const dem_body *b = &s->clumps->b[k];
    memset(o, 0, sizeof *o);
    o->mass = b->mass, o->angle = b->angle, o->first = b->first, o->count = b->count;
    memcpy(o->x, b->x, sizeof o->x), memcpy(o->v, b->v, sizeof o->v);
    memcpy(o->omega, b->omega, sizeof o->omega), memcpy(o->L, b->L, sizeof o->L);
    memcpy(o->q, b->q, sizeof o->q), memcpy(o->moments, b->moment, sizeof o->moments);
    return CORE_OK;
}

static core_status ensure_clumps(dem_scene *s, core_error *err)
{
    if (s->clumps)
        return CORE_OK;
    s->clumps = calloc(1, sizeof *s->clumps);
    if (!s->clumps)
        return core_fail(err, CORE_ERR_NOMEM, "cannot allocate the clumps");
    core_status st = dem_clumps_grow(s, 0, s->cap, err);
    if (st)
        dem_clumps_free(s);
    return st;
}

/* The body from the definition and its shape: mass, moments, pose, momenta. */
static void init_body(const dem_scene *s, const dem_clump_def *c, const dem_clump_shape *sh,
                      dem_body *b)
{
    const double rho = s->mats[c->material].density;
    const double t = sh->planar ? s->thickness : 1;
    memset(b, 0, sizeof *b);
    b->mass = rho * t * sh->measure;
    for (int d = 0; d < 3; d++)
        b->moment[d] = rho * t * sh->moments[d];
    memcpy(b->x, c->x, sizeof b->x);
    memcpy(b->v, c->v, sizeof b->v);
    if (s->dim == 2) {
        b->angle = c->angle;
        b->L[2] = b->moment[2] * c->omega[2];
        b->omega[2] = c->omega[2];
        return;
    }
    double qa[4]; /* principal frame -> members' frame -> world */
    matrix_quat(sh->axes, qa);
    quat_mul(c->q, qa, b->q);
    double n = sqrt(b->q[0] * b->q[0] + b->q[1] * b->q[1] + b->q[2] * b->q[2] + b->q[3] * b->q[3]);
    for (int a = 0; a < 4; a++)
        b->q[a] /= n;
    double R[9], wb[3];
    quat_matrix(b->q, R);
    mat_tvec(R, c->omega, wb);
    for (int d = 0; d < 3; d++)
        wb[d] *= b->moment[d];
    mat_vec(R, wb, b->L);
    memcpy(b->omega, c->omega, sizeof b->omega);
}

static core_status check_def(const dem_scene *s, const dem_clump_def *c,
                             const dem_clump_shape *sh, core_error *err)
{
    if (c->material < 0 || c->material >= s->nmat)
        return core_fail(err, CORE_ERR_ARG, "unknown material %d", c->material);
    if (sh->dim != s->dim || sh->planar != (s->dim == 2 && s->thickness > 0))
        return core_fail(err, CORE_ERR_ARG, "the shape was computed for another kind of scene");
    for (int d = 0; d < 3; d++)
        if (!isfinite(c->x[d]) || !isfinite(c->v[d]) || !isfinite(c->omega[d]))
            return core_fail(err, CORE_ERR_ARG, "position, velocity and spin must be finite");
    if (s->dim == 3) {
        double n = 0;
        for (int a = 0; a < 4; a++)
            n += c->q[a] * c->q[a];
        if (!(fabs(n - 1) < 1e-9))
            return core_fail(err, CORE_ERR_ARG, "orientation must be a unit quaternion, got "
                             "|q|^2 = %g", n);
    } else if (!isfinite(c->angle)) {
        return core_fail(err, CORE_ERR_ARG, "orientation must be finite");
    }
    return CORE_OK;
}

long dem_add_clump(dem_scene *s, const dem_clump_def *c, core_error *err)
{
    dem_clump_shape own;
    const dem_clump_shape *sh = c->shape;
    const int planar = s->dim == 2 && s->thickness > 0;
    if (!sh) {
        if (dem_clump_shape_compute(c->members, c->n, s->dim, planar, 0, &own, err))
            return -1;
        sh = &own;
    }
    if (check_def(s, c, sh, err) || ensure_clumps(s, err))
        return -1;
    dem_clumps *cl = s->clumps;
    if (cl->n == cl->cap) {
        size_t cap = cl->cap ? 2 * cl->cap : 16;
        dem_body *nb = realloc(cl->b, cap * sizeof *nb);
        if (!nb)
            return core_fail(err, CORE_ERR_NOMEM, "cannot allocate %zu clumps", cap), -1;
        cl->b = nb, cl->cap = cap;
    }
    dem_body b;
    init_body(s, c, sh, &b);
    b.first = s->n, b.count = (size_t)c->n;
    double R[9];
    body_matrix(s, &b, R);
    for (int k = 0; k < c->n; k++) { /* members as particles, then made members */
        double rel[3], bo[3], r[3];
        for (int d = 0; d < 3; d++)
            rel[d] = c->members[k].offset[d] - sh->centre[d];
        mat_tvec(sh->axes, rel, bo); /* in the principal frame */
        mat_vec(R, bo, r);
        dem_particle_def p = {.radius = c->members[k].radius, .material = c->material};
        for (int d = 0; d < s->dim; d++)
            p.x[d] = b.x[d] + r[d];
        long i = dem_add_particle(s, &p, err);
        if (i < 0) {
            s->n = b.first; /* the members added so far go again */
            if (err) {
                char msg[sizeof err->msg];
                memcpy(msg, err->msg, sizeof msg);
                core_fail(err, err->status, "member %d: %s", k + 1, msg);
            }
            return -1;
        }
        memcpy(cl->off + 3 * (size_t)i, bo, sizeof bo);
    }
    for (size_t i = b.first; i < b.first + b.count; i++) {
        cl->body[i] = (int32_t)cl->n;
        s->m[i] = b.mass / (double)b.count; /* its share of the weight (and of the drag) */
        s->inv_m[i] = 1 / b.mass;           /* contacts damp with the body's mass */
    }
    cl->b[cl->n] = b;
    place_members(s, &cl->b[cl->n], 1);
    cl->n++;
    dem_invalidate(s, 1);
    return (long)cl->n - 1;
}
