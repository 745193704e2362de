/* The dem bindings: running a scene (s:timestep, s:run), what drives it (gravity, drag, external
 * forces, the quasistatic coefficient, mass and stiffness scaling) and particles in and out
 * during a run (s:inserter, s:outflow, s:flow). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

/* ---- time stepping -------------------------------------------------------------------------- */
static void push_timestep(lua_State *L, const dem_timestep *t)
{
    lua_createtable(L, 0, 4);
    lua_pushnumber(L, t->contact_time);
    lua_setfield(L, -2, "contact_time");
    lua_pushnumber(L, t->limit);
    lua_setfield(L, -2, "limit");
    lua_pushnumber(L, t->dt_auto);
    lua_setfield(L, -2, "dt_auto");
    lua_pushnumber(L, t->impact_velocity);
    lua_setfield(L, -2, "impact_velocity");
}

static const char *const TIMESTEP_FIELDS[] = {"impact_velocity", NULL};

static int l_timestep(lua_State *L)
{
    dem_scene *s = ldem_check_scene_local(L, 1); /* walls and dt: the same on every rank */
    double v = 0;
    if (!lua_isnoneornil(L, 2)) {
        bind_check_table(L, 2, "timestep");
        bind_check_fields(L, 2, "timestep", TIMESTEP_FIELDS);
        v = bind_field_number(L, 2, "timestep", "impact_velocity", 0, BIND_POSITIVE);
    }
    dem_timestep t;
    core_error err;
    if (dem_timestep_info(s, v, &t, &err))
        return bind_raise(L, "timestep", &err);
    push_timestep(L, &t);
    return 1;
}

static const char *const INTEGRATOR_NAMES[] = {"velocity_verlet", "position_verlet", "gear",
                                               "two_timescales", NULL};

typedef struct dem_advance_ctx {
    dem_scene *s;
    dem_run_def *run;
} dem_advance_ctx;

static core_status dem_advance(void *ctx, long n, progress *p, long *done, core_error *err)
{
    dem_advance_ctx *c = ctx;
    c->run->steps = n;
    c->run->progress = p; /* counts the steps taken, also those before an interruption */
    core_status st = dem_run(c->s, c->run, err);
    *done = st == CORE_OK ? n : (long)(p->done - p->base);
    return st;
}

static const char *const RUN_FIELDS[] = {"steps",      "time",     "dt", "force", "impact_velocity",
                                         "integrator", "m",        "n",  "q",     "every",
                                         "on_step",    "progress", NULL};

/* Once per scene, a run whose contacts take no damping (damping = "none", the default) while a
 * material asks a restitution below 1 says so: the contacts are elastic, and the material's e
 * would take effect only with damping = "viscous" or "brilliantov". --quiet silences it. */
static void undamped_restitution_notice(lua_State *L, const dem_scene *s, int scene)
{
    if (dem_contact(s)->damping != DEM_DAMPING_NONE)
        return;
    int worst = -1, nmat = dem_material_count(s);
    for (int k = 0; k < nmat; k++) {
        const dem_material *m = dem_material_get(s, k);
        if (m->restitution < 1 && (worst < 0 || m->restitution < dem_material_get(s, worst)->restitution))
            worst = k;
    }
    if (worst < 0)
        return;
    lua_getiuservalue(L, scene, 1);
    int said = lua_getfield(L, -1, "undamped_noticed") != LUA_TNIL;
    lua_pop(L, 1);
    if (!said) {
        lua_pushboolean(L, 1);
        lua_setfield(L, -2, "undamped_noticed");
    }
    lua_pop(L, 1);
    if (said || progress_default_style() == PROGRESS_QUIET)
        return;
    fprintf(stderr,
            "grainlab: warning: run: the contacts have no damping (damping = \"none\"), so every "
            "collision is elastic (e = 1), but material %d asks restitution %g; call "
            "s:contact{ damping = \"viscous\" } (or \"brilliantov\" with hertz) for it to take "
            "effect\n",
            worst + 1, dem_material_get(s, worst)->restitution);
    fflush(stderr);
}

static int l_run(lua_State *L)
{
    dem_scene *s = ldem_check_scene_local(L, 1); /* a run continues a decomposed scene as it is */
    bind_refuse_running(L, 1, "run", "return false from on_step to stop it");
    bind_check_table(L, 2, "run");
    bind_check_fields(L, 2, "run", RUN_FIELDS);
    dem_run_def run = dem_default_run_def();
    run.integrator = (dem_integrator)bind_field_option(L, 2, "run", "integrator", INTEGRATOR_NAMES,
                                                       DEM_VELOCITY_VERLET, 0);
    run.tt_m = (int)bind_field_integer(L, 2, "run", "m", 5, 1, 100000, 0);
    run.tt_n = (int)bind_field_integer(L, 2, "run", "n", 5, 1, 100000, 0);
    run.tt_q = (int)bind_field_integer(L, 2, "run", "q", 5, 0, 100000, 0);
    double v_imp = bind_field_number(L, 2, "run", "impact_velocity", 0, BIND_POSITIVE);
    int force = bind_field_boolean(L, 2, "run", "force", 0);
    dem_timestep ts;
    core_error err;
    if (dem_timestep_info(s, v_imp, &ts, &err))
        return bind_raise(L, "run", &err);
    lua_getfield(L, 2, "dt");
    if (lua_isnil(L, -1) ||
        (lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "auto") == 0)) {
        /* Two timescales: the large step n dt is the one that must be the automatic step. */
        run.dt = run.integrator == DEM_TWO_TIMESCALES ? ts.dt_auto / run.tt_n : ts.dt_auto;
        run.dt_auto = true;
    } else {
        lua_pop(L, 1);
        run.dt = bind_field_number(L, 2, "run", "dt", 0, BIND_POSITIVE);
        lua_pushnil(L);
        /* For two timescales the large step n dt is the one that must stay stable. */
        double big = run.integrator == DEM_TWO_TIMESCALES ? run.tt_n * run.dt : run.dt;
        if (big > ts.limit && !force) {
            char msg[512]; /* lua_pushfstring knows no %g */
            snprintf(msg, sizeof msg,
                     "run: dt = %g s exceeds the stability limit %g s (1/10 of the contact time "
                     "%g s of the stiffest, lightest pair at impact velocity %g m/s%s); use dt = "
                     "\"auto\" (%g s), a smaller dt, or force = true",
                     big, ts.limit, ts.contact_time, ts.impact_velocity,
                     ts.limit < ts.contact_time / 10 ? ", or of the damping rate" : "", ts.dt_auto);
            return luaL_error(L, "%s", msg);
        }
    }
    lua_pop(L, 1);
    undamped_restitution_notice(L, s, 1);
    run.dt_limit = ts.limit;
    run.dt_speed = ts.impact_velocity;
    long steps;
    double time;
    if (!bind_steps_or_time(L, 2, "run", &steps, &time))
        steps = bind_time_steps(L, 2, "run", time, run.dt);
    double t0 = dem_time(s);
    long s0 = dem_steps_done(s), f0 = dem_force_evaluations(s);
    dem_advance_ctx ctx = {s, &run};
    /* dt for two timescales: the large step n dt is the one checked against the limit */
    bind_run r = {"dem run",
                  steps,
                  steps,
                  dem_advance,
                  &ctx,
                  1,
                  run.integrator == DEM_TWO_TIMESCALES ? run.tt_n * run.dt : run.dt,
                  force};
    int stopped = bind_run_chunks(L, 1, 2, "run", &r);
    lua_createtable(L, 0, 5);
    lua_pushinteger(L, dem_steps_done(s) - s0);
    lua_setfield(L, -2, "steps");
    lua_pushinteger(L, dem_force_evaluations(s) - f0);
    lua_setfield(L, -2, "force_evaluations");
    lua_pushnumber(L, dem_time(s) - t0);
    lua_setfield(L, -2, "time");
    lua_pushnumber(L, run.dt);
    lua_setfield(L, -2, "dt");
    lua_pushboolean(L, stopped);
    lua_setfield(L, -2, "stopped");
    return 1;
}

static int l_scale_mass(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const bind_run *r = bind_running(L, 1);
    if (r && !r->forced && luaL_checknumber(L, 2) < 1) /* lighter: shorter contact times */
        bind_refuse_running(L, 1, "scale_mass",
                            "a factor below 1 shortens the stability limit "
                            "the run's dt was checked at: scale between runs");
    core_error err;
    if (dem_scale_mass(s, bind_arg_number(L, 2, "scale_mass", BIND_POSITIVE), &err))
        return bind_raise(L, "scale_mass", &err);
    return 0;
}

static int l_scale_stiffness(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const bind_run *r = bind_running(L, 1);
    if (r && !r->forced && luaL_checknumber(L, 2) > 1) /* stiffer: shorter contact times */
        bind_refuse_running(L, 1, "scale_stiffness",
                            "a factor above 1 shortens the stability "
                            "limit the run's dt was checked at: scale "
                            "between runs");
    core_error err;
    if (dem_scale_stiffness(s, bind_arg_number(L, 2, "scale_stiffness", BIND_POSITIVE), &err))
        return bind_raise(L, "scale_stiffness", &err);
    return 0;
}

static int l_drag(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    if (!lua_isnoneornil(L, 2)) {
        core_error err;
        if (dem_set_drag(s, bind_arg_number(L, 2, "drag", BIND_NONNEG), &err))
            return bind_raise(L, "drag", &err);
    }
    lua_pushnumber(L, dem_drag(s));
    return 1;
}

/* s:gravity([{gx, gy[, gz]}]): sets gravity when given; returns it. */
static int l_gravity(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    if (!lua_isnoneornil(L, 2)) {
        double g[3] = {0, 0, 0};
        bind_arg_vector(L, 2, "gravity", D, g);
        core_error err;
        if (dem_set_gravity(s, g, &err))
            return bind_raise(L, "gravity", &err);
    }
    double lo[3], hi[3], g[3];
    dem_box(s, lo, hi, g);
    lua_createtable(L, D, 0);
    for (int d = 0; d < D; d++) {
        lua_pushnumber(L, g[d]);
        lua_rawseti(L, -2, d + 1);
    }
    return 1;
}

/* s:set_forces{ ids = {...}, fx = {...}, fy = {...}[, fz = {...}] } */
static const char *const FORCES_FIELDS[] = {"ids", "fx", "fy", "fz", NULL};

static int l_set_forces(lua_State *L)
{
    static const char *const comp[3] = {"fx", "fy", "fz"};
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    bind_check_table(L, 2, "set_forces");
    bind_check_fields(L, 2, "set_forces", FORCES_FIELDS);
    if (D == 2 && lua_getfield(L, 2, "fz") != LUA_TNIL)
        return bind_field_error(L, 2, "set_forces", "fz", "nothing in a 2D scene");
    lua_settop(L, 2);
    if (lua_getfield(L, 2, "ids") != LUA_TTABLE)
        return bind_field_error(L, 2, "set_forces", "ids", "array of particle ids");
    lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    for (int d = 0; d < D; d++)
        if (lua_getfield(L, 2, comp[d]) != LUA_TTABLE || (lua_Integer)lua_rawlen(L, -1) != n)
            return bind_field_error(L, 2, "set_forces", comp[d], "array as long as 'ids'");
    int base = lua_gettop(L) - D; /* ids at base, components after */
    for (lua_Integer k = 1; k <= n; k++) {
        lua_rawgeti(L, base, k);
        int isint;
        lua_Integer id = lua_tointegerx(L, -1, &isint);
        if (!isint || lua_type(L, -1) != LUA_TNUMBER || id < 1 || (size_t)id > dem_count(s)) {
            char expected[64];
            snprintf(expected, sizeof expected, "particle ids in [1, %zu]", dem_count(s));
            return bind_field_error(L, 2, "set_forces", "ids", expected);
        }
        lua_pop(L, 1);
        double f[3] = {0, 0, 0};
        for (int d = 0; d < D; d++) {
            lua_rawgeti(L, base + 1 + d, k);
            f[d] = lua_tonumber(L, -1);
            if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(f[d]) || fabs(f[d]) > 1e100)
                return bind_field_error(L, 2, "set_forces", comp[d],
                                        "arrays of finite forces (N) of magnitude at most 1e+100");
            lua_pop(L, 1);
        }
        core_error err;
        if (dem_set_external_force(s, (size_t)(id - 1), f, &err))
            return luaL_error(L, "set_forces: entry %d: %s", (int)k, err.msg);
    }
    lua_settop(L, 2);
    return 0;
}

static int l_clear_forces(lua_State *L)
{
    dem_clear_external_forces(ldem_check_scene(L, 1));
    return 0;
}

static const char *const QUASISTATIC_FIELDS[] = {"pressure", "strain_rate", NULL};

static int l_quasistatic(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    bind_check_table(L, 2, "quasistatic");
    bind_check_fields(L, 2, "quasistatic", QUASISTATIC_FIELDS);
    double p = bind_field_number(L, 2, "quasistatic", "pressure", 0, BIND_REQUIRED | BIND_POSITIVE);
    double rate =
        bind_field_number(L, 2, "quasistatic", "strain_rate", 0, BIND_REQUIRED | BIND_POSITIVE);
    double phi, psi;
    core_error err;
    if (dem_quasistatic(s, p, rate, &phi, &psi, &err))
        return bind_raise(L, "quasistatic", &err);
    if (phi > 0.01 && progress_default_style() != PROGRESS_QUIET)
        fprintf(stderr,
                "grainlab: warning: quasistatic coefficient phi = %.3g is not << 1: the "
                "process is not macroscopically quasistatic (Padbidri Eq. 2.13); lower "
                "the mass scaling or the strain rate\n",
                phi);
    lua_createtable(L, 0, 2);
    lua_pushnumber(L, phi);
    lua_setfield(L, -2, "phi");
    lua_pushnumber(L, psi);
    lua_setfield(L, -2, "psi");
    return 1;
}

/* ---- particles in and out during a run (flow.c) --------------------------------------------- */
static const char *const INSERTER_FIELDS[] = {
    "box",     "center",   "extent", "rate",     "count", "mass",  "radius",   "radii",
    "weights", "velocity", "spread", "material", "seed",  "every", "attempts", NULL};

/* An array field of positive (radii) or non-negative (weights) finite numbers, n > 0 entries
 * (n_want > 0: exactly that many); a new userdata-free buffer on the Lua stack holds them. */
static double *number_list(lua_State *L, int arg, const char *call, const char *field,
                           size_t n_want, int positive, size_t *n)
{
    lua_getfield(L, arg, field);
    const char *expected = positive ? "non-empty array of positive numbers"
                                    : "non-empty array of non-negative numbers";
    if (!lua_istable(L, -1) || luaL_len(L, -1) < 1 ||
        (n_want > 0 && (size_t)luaL_len(L, -1) != n_want))
        bind_field_error(L, arg, call, field,
                         n_want > 0 ? "array of one weight per entry of 'radii'" : expected);
    *n = (size_t)luaL_len(L, -1);
    double *v = lua_newuserdatauv(L, *n * sizeof *v, 0);
    for (size_t k = 0; k < *n; k++) {
        int t = lua_rawgeti(L, -2, (lua_Integer)k + 1);
        v[k] = lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (t != LUA_TNUMBER || !isfinite(v[k]) || (positive ? !(v[k] > 0) : !(v[k] >= 0))) {
            lua_pop(L, 1); /* the buffer: the field's value on top for the message */
            bind_field_error(L, arg, call, field, expected);
        }
    }
    lua_remove(L, -2); /* keep the buffer, drop the field's value */
    return v;
}

static int l_inserter(lua_State *L)
{
    const char *call = "inserter";
    dem_scene *s = ldem_check_scene(L, 1);
    bind_refuse_running(L, 1, call, "add inserters between runs");
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, INSERTER_FIELDS);
    const int D = dem_dim(s);
    dem_inserter_def d = dem_default_inserter_def();
    int has_box = lua_getfield(L, 2, "box") != LUA_TNIL;
    lua_pop(L, 1);
    if (has_box) {
        bind_field_box(L, 2, call, "box", D, d.lo, d.hi);
        if (lua_getfield(L, 2, "center") != LUA_TNIL)
            bind_field_error(L, 2, call, "center", "nil with a box (one region)");
        if (lua_getfield(L, 2, "extent") != LUA_TNIL)
            bind_field_error(L, 2, call, "extent", "nil with a box (one region)");
        lua_pop(L, 2);
    } else {
        d.ball = 1;
        if (!bind_field_vector(L, 2, call, "center", D, d.center, 0)) {
            /* neither region: a disk/ball when an extent says so, else a box */
            int ball = lua_getfield(L, 2, "extent") != LUA_TNIL;
            lua_getfield(L, 2, ball ? "center" : "box");
            bind_field_error(L, 2, call, ball ? "center" : "box",
                             ball ? "a center with the extent"
                                  : "a box, or a center and an extent");
        }
        d.extent = bind_field_number(L, 2, call, "extent", 0, BIND_REQUIRED | BIND_POSITIVE);
    }
    d.rate = bind_field_number(L, 2, call, "rate", 0, BIND_NONNEG);
    d.count = (long)bind_field_integer(L, 2, call, "count", -1, 0, LONG_MAX, 0);
    d.mass = bind_field_number(L, 2, call, "mass", 0, BIND_POSITIVE);
    if (d.rate == 0 && d.count < 0 && d.mass == 0) {
        lua_getfield(L, 2, "count");
        bind_field_error(L, 2, call, "count", "a count, a rate or a mass (none given)");
    }
    double *radii = NULL, *weights = NULL;
    int has_radii = lua_getfield(L, 2, "radii") != LUA_TNIL;
    lua_pop(L, 1);
    if (has_radii) { /* the list checked first, so that a bad one is named as such */
        d.size = DEM_SIZE_DISCRETE;
        radii = number_list(L, 2, call, "radii", 0, 1, &d.nsizes);
    }
    lua_getfield(L, 2, "radii");
    int has_radius = lua_getfield(L, 2, "radius") != LUA_TNIL;
    if (has_radii == has_radius)
        bind_field_error(L, 2, call, "radius",
                         has_radii ? "nil with radii"
                                   : "a radius, {min, max}, or a field 'radii',");
    if (has_radius && lua_istable(L, -1)) {
        double r[2];
        bind_field_vector(L, 2, call, "radius", 2, r, BIND_REQUIRED);
        if (!(r[0] > 0 && r[1] >= r[0]))
            bind_field_error(L, 2, call, "radius", "{min, max} with 0 < min <= max");
        d.size = DEM_SIZE_UNIFORM;
        d.r0 = r[0];
        d.r1 = r[1];
    } else if (has_radius) {
        d.r0 = bind_field_number(L, 2, call, "radius", 0, BIND_REQUIRED | BIND_POSITIVE);
    }
    lua_pop(L, 2);
    if (has_radii) {
        if (lua_getfield(L, 2, "weights") != LUA_TNIL) {
            size_t nw;
            lua_pop(L, 1);
            weights = number_list(L, 2, call, "weights", d.nsizes, 0, &nw);
        } else {
            lua_pop(L, 1);
            weights = lua_newuserdatauv(L, d.nsizes * sizeof *weights, 0);
            for (size_t k = 0; k < d.nsizes; k++)
                weights[k] = 1;
        }
        d.radii = radii;
        d.weights = weights;
    } else if (lua_getfield(L, 2, "weights") != LUA_TNIL) {
        bind_field_error(L, 2, call, "weights", "nil without radii");
    } else {
        lua_pop(L, 1);
    }
    bind_field_vector(L, 2, call, "velocity", D, d.velocity, 0);
    d.spread = bind_field_number(L, 2, call, "spread", 0, BIND_NONNEG);
    d.seed = (unsigned long long)bind_field_integer(L, 2, call, "seed", 1, 0, LUA_MAXINTEGER, 0);
    d.every = (long)bind_field_integer(L, 2, call, "every", 1, 1, LONG_MAX, 0);
    d.attempts = (int)bind_field_integer(L, 2, call, "attempts", 50, 1, 1000000, 0);
    d.material = ldem_material_index(L, 1, 2, call, "material", 0);
    core_error err;
    int id = dem_add_inserter(s, &d, &err);
    if (id < 0)
        return bind_raise(L, call, &err);
    ldem_default_material_notice(L, s, 1, 2, call);
    lua_pushinteger(L, id + 1);
    return 1;
}

static const char *const OUTFLOW_FIELDS[] = {"box", "side", NULL};
static const char *const SIDE_NAMES[] = {"x-", "x+", "y-", "y+", "z-", "z+", NULL};

static int l_outflow(lua_State *L)
{
    const char *call = "outflow";
    dem_scene *s = ldem_check_scene(L, 1);
    bind_refuse_running(L, 1, call, "add outflows between runs");
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, OUTFLOW_FIELDS);
    const int D = dem_dim(s);
    dem_outflow_def d;
    memset(&d, 0, sizeof d);
    int has_box = lua_getfield(L, 2, "box") != LUA_TNIL;
    int has_side = lua_getfield(L, 2, "side") != LUA_TNIL;
    lua_pop(L, 2);
    d.side = -1;
    if (has_side) { /* each value checked first, so that a bad one is named as such */
        d.side = bind_field_option(L, 2, call, "side", SIDE_NAMES, 0, BIND_REQUIRED);
        if (d.side >= 2 * D) {
            lua_getfield(L, 2, "side");
            bind_field_error(L, 2, call, "side",
                             D == 2 ? "'x-', 'x+', 'y-' or 'y+' in 2D" : "a side name");
        }
    }
    if (has_box)
        bind_field_box(L, 2, call, "box", D, d.lo, d.hi);
    if (has_box == has_side) {
        lua_getfield(L, 2, "side");
        bind_field_error(L, 2, call, "side",
                         has_box ? "nil with a box (one region)" : "a side, or a field 'box',");
    }
    core_error err;
    int id = dem_add_outflow(s, &d, &err);
    if (id < 0)
        return bind_raise(L, call, &err);
    lua_pushinteger(L, id + 1);
    return 1;
}

static void push_counts(lua_State *L, const dem_flow_counts *c, int inserter)
{
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, c->count);
    lua_setfield(L, -2, inserter ? "inserted" : "removed");
    lua_pushnumber(L, c->mass);
    lua_setfield(L, -2, "mass");
    if (inserter) {
        lua_pushinteger(L, c->skipped);
        lua_setfield(L, -2, "skipped");
        lua_pushinteger(L, c->events);
        lua_setfield(L, -2, "events");
    }
}

static int l_flow(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    long ins = 0, skipped = 0, rem = 0;
    double ins_m = 0, rem_m = 0;
    dem_flow_counts c;
    lua_createtable(L, 0, 10);
    lua_createtable(L, dem_inserter_count(s), 0);
    for (int q = 0; q < dem_inserter_count(s); q++) {
        dem_inserter_counts(s, q, &c, NULL);
        ins += c.count, ins_m += c.mass, skipped += c.skipped;
        push_counts(L, &c, 1);
        lua_rawseti(L, -2, q + 1);
    }
    lua_setfield(L, -2, "inserters");
    lua_createtable(L, dem_outflow_count(s), 0);
    for (int o = 0; o < dem_outflow_count(s); o++) {
        dem_outflow_counts(s, o, &c, NULL);
        rem += c.count, rem_m += c.mass;
        push_counts(L, &c, 0);
        lua_rawseti(L, -2, o + 1);
    }
    lua_setfield(L, -2, "outflows");
    double present = 0;
    const double *m = dem_masses(s);
    for (size_t i = 0; i < dem_count(s); i++)
        present += m[i];
    const lua_Integer iv[4] = {ins, skipped, rem, (lua_Integer)dem_count(s)};
    const char *in_[4] = {"inserted", "skipped", "removed", "count"};
    for (int k = 0; k < 4; k++) {
        lua_pushinteger(L, iv[k]);
        lua_setfield(L, -2, in_[k]);
    }
    const double dv[4] = {ins_m, rem_m, present, dem_time(s)};
    const char *dn[4] = {"inserted_mass", "removed_mass", "mass", "time"};
    for (int k = 0; k < 4; k++) {
        lua_pushnumber(L, dv[k]);
        lua_setfield(L, -2, dn[k]);
    }
    return 1;
}

void ldem_open_run(lua_State *L)
{
    static const bind_fn methods[] = {
        {"timestep", l_timestep, "s:timestep{ impact_velocity = v }",
         "The contact time of the stiffest, lightest pair at the impact velocity (default: the "
         "fastest particle or sqrt(2 g H), at least 0.1 m/s), the stability limit (1/10 of it, "
         "or less with stiff damping) and the automatic dt (1/5 of the limit)."},
        {"run", l_run,
         "s:run{ steps = N | time = T, dt = 'auto', force = false, integrator = "
         "'velocity_verlet'|'position_verlet'|'gear'|'two_timescales', m =, n =, q =, every =, "
         "on_step = function(s) end, progress = nil }",
         "Advances the scene. dt above the stability limit is refused unless force = true. "
         "two_timescales (Padbidri Sec. 2.4) takes cycles of one step n dt and q steps dt (m names "
         "the paper's macro step m(n + q) dt; the cycle simply repeats); steps count small-step "
         "equivalents. on_step runs every `every` steps; returning false stops "
         "the run. Ctrl-C stops between steps with the scene intact. Returns {steps, time, dt, "
         "force_evaluations, stopped}. Progress on stderr: "
         "nil shows it once the run has taken 2 s, true at once, false never (--quiet: never). "
         "From on_step, calls that would invalidate the run (a nested run, close, ...) are "
         "refused."},
        {"scale_mass", l_scale_mass, "s:scale_mass(factor)",
         "Multiplies all masses (mass scaling, Padbidri Sec. 2.2)."},
        {"scale_stiffness", l_scale_stiffness, "s:scale_stiffness(factor)",
         "Multiplies every Young's modulus and linear stiffness (a stiffness ramp for sample "
         "preparation)."},
        {"drag", l_drag, "s:drag([rate])",
         "Background drag -rate m v (and -rate I omega) on every particle, for settling samples; "
         "0 switches it off. Returns the rate."},
        {"gravity", l_gravity, "s:gravity([{gx, gy}])",
         "Sets gravity (m/s^2) when given, from the next step on: a tilted box is a rotated "
         "gravity (scripts/marginal_stability.lua). Returns it."},
        {"set_forces", l_set_forces, "s:set_forces{ ids = {...}, fx = {...}, fy = {...} }",
         "External forces (N) on the listed particles, applied every step until changed or "
         "cleared (pressure boundary conditions applied as particle forces)."},
        {"clear_forces", l_clear_forces, "s:clear_forces()", "Removes all external forces."},
        {"quasistatic", l_quasistatic, "s:quasistatic{ pressure = p, strain_rate = eps }",
         "Padbidri's quasistatic coefficient phi (Eq. 2.13; 2D: m eps^2 N / (2 p R) from "
         "2.B1) and size coefficient psi (Eq. 2.14) of the scene; warns when phi > 0.01. Mass "
         "scaling (s:scale_mass) multiplies phi by its factor."},
        {"inserter", l_inserter,
         "s:inserter{ box = {lo, hi} | center = {...}, extent = R, rate =, count =, mass =, "
         "radius = r | {min, max} | radii = {...}, weights = {...}, velocity = {...}, spread = 0, "
         "material = m, seed = 1, every = 1, attempts = 50 }",
         "Inserts particles during runs in a box, or a disk/ball of radius extent (each particle "
         "wholly inside), never overlapping a particle or a wall: rate per second (counted from "
         "now), or everything at once; count and mass cap the total. Radius constant, uniform in "
         "{min, max}, or drawn from radii with weights. Velocity plus spread x uniform(-1, 1) per "
         "component. Every `every` steps the particles due get `attempts` random positions each "
         "(the inserter's own stream from seed): one that finds no place is skipped and counted. "
         "Returns the inserter id; s:flow() gives the counts."},
        {"outflow", l_outflow,
         "s:outflow{ box = {lo, hi} } or s:outflow{ side = 'x-'|'x+'|'y-'|...}",
         "Removes the particles whose centre enters the box (fixed ones excepted) after each "
         "step, or that leave the domain through that side (not periodic; without an outflow a "
         "particle leaving the domain stops the run). Ids after a removed particle shift down: "
         "follow particles by s:particles().tag. Returns the outflow id."},
        {"flow", l_flow, "s:flow()",
         "Particles in and out: inserted, inserted_mass, skipped, removed, removed_mass, count "
         "and mass (present), time; inserters[k] = {inserted, mass, skipped, events}, "
         "outflows[k] = {removed, mass}."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fields[] = {{"timestep", NULL, TIMESTEP_FIELDS},
                                         {"run", NULL, RUN_FIELDS},
                                         {"set_forces", NULL, FORCES_FIELDS},
                                         {"quasistatic", NULL, QUASISTATIC_FIELDS},
                                         {"inserter", NULL, INSERTER_FIELDS},
                                         {"outflow", NULL, OUTFLOW_FIELDS},
                                         {NULL, NULL, NULL}};
    ldem_add_methods(L, methods, fields);
}
