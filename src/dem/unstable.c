/* Why a run stops: the likely cause of an instability, named in the error that stops it, and the
 * energy watch of a scene without drivers (integrate.c calls both). */
#include <math.h>
#include <stdio.h>

#include "core/comm.h"
#include "dem/dem_internal.h"

/* ---- the likely cause of an instability ------------------------------------------------------
 * Read from what the scene shows, in this order: a time step the user forced above the stability
 * limit (only then is dt blamed); a particle that left the box by a side that has no wall;
 * contacts so soft that gravity alone, or an impact at the speed the step was chosen for,
 * squeezes a grain by a large part of its radius (no time step cures that: a modulus in the
 * wrong units, E = 5 Pa for 5 MPa). Local data only (particle i, the walls, the run's settings):
 * on several ranks only the one that holds the particle writes the message. */
#define DEM_SOFT_LOAD 0.1   /* overlap under a grain's own weight, of its radius */
#define DEM_SOFT_IMPACT 0.5 /* overlap of a head-on impact at the reference speed, of its radius */

static const char AXES[3] = {'x', 'y', 'z'};

/* A side of the box (axis d, sign +1 for hi, -1 for lo) that no wall closes: no plane faces it,
 * and no wall beyond planes (a drum, a hopper) may hold the particles in. */
static int side_open(const dem_scene *s, int d, int sign)
{
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (wl->active && (wl->shape || sign * wl->normal[d] < -0.5))
            return 0;
    }
    return 1;
}

/* The "k = ..." of a pair of particle i's material, as the user gave it. */
static void stiffness_text(const dem_scene *s, size_t i, char *buf, size_t n)
{
    const dem_contact_def *c = &s->contact;
    if (dem_normal_from_moduli(c->normal))
        snprintf(buf, n, "E = %.3g Pa", s->mats[s->mat[i]].young);
    else if (dem_law_beta(c) == 1)
        snprintf(buf, n, "k = %.3g N/m", c->stiffness);
    else
        snprintf(buf, n, "k = %.3g N/m^%g", c->stiffness, dem_law_beta(c));
}

static void likely_cause(const dem_scene *s, size_t i, char *buf, size_t n)
{
    const int D = s->dim;
    const dem_run_def *run = s->run;
    double dt = run ? run->dt * (run->integrator == DEM_TWO_TIMESCALES ? run->tt_n : 1) : 0;
    if (run && !run->dt_auto && run->dt_limit > 0 && dt > run->dt_limit) {
        snprintf(buf, n,
                 "the time step is too large: dt = %.3g s is %.3g times the stability limit "
                 "%.3g s (forced); use dt = \"auto\" or a smaller dt",
                 dt, dt / run->dt_limit, run->dt_limit);
        return;
    }
    for (int d = 0; d < D; d++) { /* out of the box: by which side, and is it open? */
        int sign = s->x[d][i] > s->hi[d] ? 1 : s->x[d][i] < s->lo[d] ? -1 : 0;
        if (s->periodic[d] || !sign || !side_open(s, d, sign))
            continue;
        char point[96], normal[32];
        int pl = 0, nl = 0;
        for (int e = 0; e < D; e++) {
            double p = e == d ? (sign > 0 ? s->hi[e] : s->lo[e]) : s->lo[e];
            pl += snprintf(point + pl, sizeof point - (size_t)pl, "%s%.6g", e ? ", " : "", p);
            nl += snprintf(normal + nl, sizeof normal - (size_t)nl, "%s%d", e ? ", " : "",
                           e == d ? -sign : 0);
        }
        snprintf(buf, n,
                 "no wall on the %c%c side of the box (%c = %.6g m): add one, s:add_wall{ point "
                 "= {%s}, normal = {%s} }, or make the %c axis periodic",
                 sign > 0 ? '+' : '-', AXES[d], AXES[d], sign > 0 ? s->hi[d] : s->lo[d], point,
                 normal, AXES[d]);
        return;
    }
    double g = 0, h = 0;
    for (int d = 0; d < D; d++) {
        g += s->gravity[d] * s->gravity[d];
        if (s->gravity[d] != 0)
            h = fmax(h, s->len[d]);
    }
    g = sqrt(g);
    const double r = s->r[i], m = s->m[i];
    const dem_contact_def *c = &s->contact;
    double beta = dem_law_beta(c);
    double k = 0, gamma = 0;
    if (r > 0 && m > 0 && isfinite(m))
        dem_probe_parameters(s, s->mat[i], r, m, &k, &gamma);
    char stiff[64];
    stiffness_text(s, i, stiff, sizeof stiff);
    if (k > 0) {
        /* on a grain like it: k delta^beta = m g */
        double load = pow(m * g / k, 1 / beta) / r;
        if (load > DEM_SOFT_LOAD) {
            snprintf(buf, n,
                     "the contact stiffness is too small for the load: %s gives overlaps of %.3g "
                     "times the radius (r = %.3g m) under gravity alone; check the units (Pa)",
                     stiff, load, r);
            return;
        }
        /* a head-on impact on a grain like it at the speed the step was chosen for, or of a
         * fall through the box: (beta + 1)/2 m_eff v^2 = k delta^(beta + 1), m_eff = m/2 */
        double v = run && run->dt_speed > 0 ? run->dt_speed : fmax(sqrt(2 * g * h), 0.1);
        double impact = pow((beta + 1) * 0.25 * m * v * v / k, 1 / (beta + 1)) / r;
        if (impact > DEM_SOFT_IMPACT) {
            snprintf(buf, n,
                     "the contact stiffness is too small for the impacts: %s gives overlaps of "
                     "%.3g times the radius (r = %.3g m) at %.3g m/s; check the units (Pa)",
                     stiff, impact, r, v);
            return;
        }
    }
    if (run && run->dt_limit > 0 && run->dt_speed > 0) {
        snprintf(buf, n,
                 "a contact faster or stiffer than the time step was chosen for (dt = %.3g s%s, "
                 "for impacts up to %.3g m/s at the limit %.3g s): a driver (a moving wall, a "
                 "prescribed particle, an inserter) or a fall from higher up; give run{ "
                 "impact_velocity = ... } the fastest impact, or a smaller dt",
                 dt, run->dt_auto ? ", \"auto\"" : "", run->dt_speed, run->dt_limit);
        return;
    }
    snprintf(buf, n,
             "the time step is too large for the contact stiffness or the impact speed (use dt = "
             "\"auto\" or a smaller dt)");
}

/* The step being taken when a check fails is s->steps + 1 (steps counts completed ones); i is the
 * local index. */
core_status dem_unstable(dem_scene *s, size_t i, const char *what, core_error *err)
{
    dem_invalidate(s, 1); /* a later run must not reuse this step's forces */
    char cause[400];
    likely_cause(s, i, cause, sizeof cause);
    return core_fail(err, CORE_ERR_UNSTABLE, "particle %zu %s at step %ld (t = %.6g s); likely cause: %s",
                     dem_gid(s, i) + 1, what, s->steps + 1, s->time, cause);
}

/* ---- energy watch ---------------------------------------------------------------------------- *
 * Without a driver (a moving or servo wall, a prescribed particle, an external force, a boundary
 * condition, gravity along a periodic axis) kinetic + rotational + elastic + gravitational energy
 * can only stay or fall: contacts conserve it (Hertz, springs) or dissipate it (damping, friction,
 * drag). Verlet at a stable step only makes it fluctuate, O(dt^2): measured at most 0.3% of the
 * mechanical energy at the stable limit (60 undamped disks, 20,000 steps), 2% at twice the limit,
 * while at three times it grows without bound. The watch stops a run whose energy rises more than
 * DEM_WATCH_GROWTH of the largest kinetic + rotational + elastic energy seen above the lowest total
 * since the reference. One O(N) energy sum every DEM_WATCH_EVERY steps (callgrind, 225 disks, 3
 * walls: +0.75% of the run's instructions; +1.5% when every 64 steps). Driven scenes are not
 * watched (their work is not accounted), nor are cohesive ones (cohesion.h: the elastic energy
 * counts the Hertzian part, not the adhesion's work, so grains that snap together gain kinetic
 * energy the sum does not balance). */
#define DEM_WATCH_EVERY 256
#define DEM_WATCH_GROWTH 0.1

static int driven(const dem_scene *s)
{
    if (s->bnd || s->fext[0] || dem_cohesive(&s->contact))
        return 1;
    for (int d = 0; d < s->dim; d++) /* gravity along a periodic axis: no bounded potential */
        if (s->periodic[d] && s->gravity[d] != 0)
            return 1;
    for (int w = 0; w < s->nwalls; w++) {
        const dem_wall *wl = &s->walls[w];
        if (wl->active &&
            (wl->servo || wl->velocity[0] != 0 || wl->velocity[1] != 0 || wl->velocity[2] != 0))
            return 1;
    }
    if (s->nshaped && dem_shapes_driven(s))
        return 1;
    int pres = 0;
    for (size_t i = 0; i < s->n && !pres; i++)
        pres = (s->flags[i] & DEM_PRESCRIBED) != 0;
    return s->dom ? comm_any(pres) : pres;
}

core_status dem_energy_watch(dem_scene *s, double dt, core_error *err)
{
    s->watch_next = s->steps + DEM_WATCH_EVERY;
    if (driven(s)) {
        s->watch_on = 0;
        return CORE_OK;
    }
    dem_energy e;
    dem_measure_energy(s, &e);
    double mobile = e.kinetic + e.rotational + e.elastic;
    if (!s->watch_on || !isfinite(e.total)) {
        s->watch_on = isfinite(e.total);
        s->watch_min = e.total;
        s->watch_min_step = s->steps;
        s->watch_min_t = s->time;
        s->watch_scale = mobile;
        return CORE_OK;
    }
    s->watch_scale = fmax(s->watch_scale, mobile);
    if (e.total < s->watch_min) {
        s->watch_min = e.total;
        s->watch_min_step = s->steps;
        s->watch_min_t = s->time;
        return CORE_OK;
    }
    double grow = e.total - s->watch_min, scale = s->watch_scale;
    /* round-off of the sum of terms that may be large and cancel (gravity's potential) */
    double noise = 1e-12 * (fabs(e.total) + fabs(e.potential) + scale);
    if (!(grow > DEM_WATCH_GROWTH * scale && grow > noise))
        return CORE_OK;
    dem_timestep ts;
    char limit[96] = "";
    if (dem_timestep_info(s, 0, &ts, NULL) == CORE_OK)
        snprintf(limit, sizeof limit, " (the stable limit at the current speeds is %.3g s)",
                 ts.limit);
    s->watch_on = 0;
    dem_invalidate(s, 1);
    const bool automatic = s->run && s->run->dt_auto; /* then "use dt = auto" would not help */
    return core_fail(err, CORE_ERR_UNSTABLE,
                     "energy grew in a scene without drivers: %.6g J at step %ld (t = %.6g s), "
                     "%.6g J at step %ld (t = %.6g s), +%.3g J = %.3g of the largest mechanical "
                     "energy %.6g J (kinetic + rotational + elastic; limit %.3g); likely cause: "
                     "the time step %.3g s%s is too large for the contact stiffness%s; %s",
                     s->watch_min, s->watch_min_step, s->watch_min_t, e.total, s->steps, s->time,
                     grow, grow / scale, scale, DEM_WATCH_GROWTH, dt, automatic ? " (\"auto\")" : "",
                     limit,
                     automatic ? "give run{ impact_velocity = ... } the fastest impact, or a "
                                 "smaller dt"
                               : "use dt = \"auto\" or a smaller dt, without force");
}
