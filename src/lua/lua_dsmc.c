/* The Lua module `dsmc`: granular gases by direct simulation Monte Carlo over src/dsmc. Translates
 * and checks arguments, calls the kernels, raises their errors named after the call. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dsmc/dsmc.h"
#include "lua/bind.h"

static const char *SCENE = "dsmc.scene";
static const char AXES[3] = {'x', 'y', 'z'};

typedef struct lscene {
    dsmc_scene *s;
} lscene;

static dsmc_scene *check_scene(lua_State *L, int idx)
{
    lscene *u = luaL_checkudata(L, idx, SCENE);
    if (!u->s)
        luaL_error(L, "the dsmc.scene was closed");
    return u->s;
}

/* The scene of a call that needs all of it (particles, per-cell fields, files): on a scene
 * distributed over ranks by its last run, gathers it back to every rank first (collective: every
 * rank of an SPMD script makes the same call). The one guard of those entry points. */
static dsmc_scene *whole_scene(lua_State *L, int idx, const char *call)
{
    dsmc_scene *s = check_scene(L, idx);
    core_error err;
    if (dsmc_gather(s, &err))
        bind_raise(L, call, &err);
    return s;
}

static void set_number(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

static void push_vec(lua_State *L, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int k = 0; k < n; k++) {
        lua_pushnumber(L, v[k]);
        lua_rawseti(L, -2, k + 1);
    }
}

/* ---- dsmc.scene{...} ------------------------------------------------------------------------ */
static const char *const EXCLUDED_NAMES[] = {"none", "free_volume", "enskog", NULL};

/* A field holding `dim` numbers, each accepted by ok(); out unchanged when absent. */
static int read_numbers(lua_State *L, int arg, const char *call, const char *field, int dim,
                        const char *expected, int integer, double *out)
{
    int t = lua_getfield(L, arg, field);
    if (t == LUA_TNIL) {
        lua_pop(L, 1);
        return 0;
    }
    if (t != LUA_TTABLE || luaL_len(L, -1) != dim)
        bind_field_error(L, arg, call, field, expected);
    for (int k = 0; k < dim; k++) {
        lua_rawgeti(L, -1, k + 1);
        int ok = integer ? lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 1 &&
                               lua_tointeger(L, -1) <= (1 << 24)
                         : lua_type(L, -1) == LUA_TNUMBER && fabs(lua_tonumber(L, -1)) <= 1e100;
        double v = lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (!ok)
            bind_field_error(L, arg, call, field, expected);
        out[k] = v;
    }
    lua_pop(L, 1);
    return 1;
}

static void read_box(lua_State *L, int arg, int dim, dsmc_scene_def *def)
{
    int has_box = lua_getfield(L, arg, "box") != LUA_TNIL;
    lua_pop(L, 1);
    int has_size = lua_getfield(L, arg, "size") != LUA_TNIL;
    lua_pop(L, 1);
    if (has_box == has_size) {
        lua_getfield(L, arg, "box");
        bind_field_error(L, arg, "scene", "box",
                         has_box ? "'box' or 'size', not both" : "'box' or 'size' (one of them)");
    }
    if (has_size) {
        char e2[64];
        snprintf(e2, sizeof e2, "array of %d positive numbers", dim);
        double size[3];
        read_numbers(L, arg, "scene", "size", dim, e2, 0, size);
        for (int k = 0; k < dim; k++) {
            if (!(size[k] > 0)) {
                lua_getfield(L, arg, "size");
                bind_field_error(L, arg, "scene", "size", e2);
            }
            def->lo[k] = 0;
            def->hi[k] = size[k];
        }
        return;
    }
    bind_field_box(L, arg, "scene", "box", dim, def->lo, def->hi);
}

static const char *const SCENE_FIELDS[] = {
    "dim",    "box",  "size",    "cells",           "periodic",      "gravity", "restitution",
    "radius", "mass", "density", "excluded_volume", "packing_limit", "seed",    NULL};

static int l_scene(lua_State *L)
{
    bind_check_table(L, 1, "scene");
    bind_check_fields(L, 1, "scene", SCENE_FIELDS);
    dsmc_scene_def def = dsmc_default_scene_def();
    def.dim = (int)bind_field_integer(L, 1, "scene", "dim", 2, 2, 3, 0);
    int D = def.dim;
    read_box(L, 1, D, &def);
    char expected[64];
    snprintf(expected, sizeof expected, "array of %d integers in [1, 16777216]", D);
    double cells[3];
    if (!read_numbers(L, 1, "scene", "cells", D, expected, 1, cells)) {
        lua_pushnil(L);
        bind_field_error(L, 1, "scene", "cells", expected);
    }
    for (int k = 0; k < D; k++)
        def.cells[k] = (int)cells[k];
    snprintf(expected, sizeof expected, "array of %d numbers", D);
    read_numbers(L, 1, "scene", "gravity", D, expected, 0, def.gravity);
    int t = lua_getfield(L, 1, "periodic");
    if (t == LUA_TBOOLEAN) {
        for (int k = 0; k < D; k++)
            def.periodic[k] = lua_toboolean(L, -1);
    } else if (t != LUA_TNIL) {
        snprintf(expected, sizeof expected, "a boolean or an array of %d booleans", D);
        if (t != LUA_TTABLE || luaL_len(L, -1) != D)
            bind_field_error(L, 1, "scene", "periodic", expected);
        for (int k = 0; k < D; k++) {
            int tk = lua_rawgeti(L, -1, k + 1);
            def.periodic[k] = lua_toboolean(L, -1);
            lua_pop(L, 1);
            if (tk != LUA_TBOOLEAN)
                bind_field_error(L, 1, "scene", "periodic", expected);
        }
    }
    lua_pop(L, 1);
    def.restitution = bind_field_number(L, 1, "scene", "restitution", 1, 0);
    if (!(def.restitution >= 0 && def.restitution <= 1)) {
        lua_getfield(L, 1, "restitution");
        return bind_field_error(L, 1, "scene", "restitution", "number in [0, 1]");
    }
    def.radius = bind_field_number(L, 1, "scene", "radius", 0, BIND_REQUIRED | BIND_POSITIVE);
    int has_mass = lua_getfield(L, 1, "mass") != LUA_TNIL;
    int has_density = lua_getfield(L, 1, "density") != LUA_TNIL;
    lua_pop(L, 2);
    if (has_mass && has_density) {
        lua_getfield(L, 1, "density");
        return bind_field_error(L, 1, "scene", "density", "nothing when 'mass' is given");
    }
    def.mass = bind_field_number(L, 1, "scene", "mass", 0, has_mass ? BIND_POSITIVE : 0);
    def.density = bind_field_number(L, 1, "scene", "density", def.density, BIND_POSITIVE);
    def.excluded = (dsmc_excluded)bind_field_option(L, 1, "scene", "excluded_volume",
                                                    EXCLUDED_NAMES, DSMC_EXCLUDED_FREE_VOLUME, 0);
    def.packing_limit = bind_field_number(L, 1, "scene", "packing_limit", 0, BIND_POSITIVE);
    if (def.packing_limit >= 1) {
        lua_getfield(L, 1, "packing_limit");
        return bind_field_error(L, 1, "scene", "packing_limit", "number in (0, 1)");
    }
    def.seed = (uint64_t)bind_field_integer(L, 1, "scene", "seed", 1, 0, LUA_MAXINTEGER, 0);
    lscene *u = lua_newuserdatauv(L, sizeof *u, 0);
    u->s = NULL;
    luaL_setmetatable(L, SCENE);
    core_error err;
    if (dsmc_create(&def, &u->s, &err) != CORE_OK)
        return bind_raise(L, "scene", &err);
    return 1;
}

/* ---- particles ------------------------------------------------------------------------------ */
static const char *const FILL_FIELDS[] = {"n",        "temperature", "speed", "region",
                                          "velocity", "seed",        NULL};

static int l_fill(lua_State *L)
{
    dsmc_scene *s = whole_scene(L, 1, "fill");
    int D = dsmc_def(s)->dim;
    bind_check_table(L, 2, "fill");
    bind_check_fields(L, 2, "fill", FILL_FIELDS);
    dsmc_fill_def f = dsmc_default_fill_def();
    f.n = (size_t)bind_field_integer(L, 2, "fill", "n", 0, 1, LUA_MAXINTEGER, BIND_REQUIRED);
    f.temperature = bind_field_number(L, 2, "fill", "temperature", 0, BIND_POSITIVE);
    f.speed = bind_field_number(L, 2, "fill", "speed", 0, BIND_POSITIVE);
    if ((f.temperature > 0) == (f.speed > 0)) {
        lua_getfield(L, 2, "temperature");
        return bind_field_error(L, 2, "fill", "temperature",
                                f.speed > 0 ? "nothing when 'speed' is given"
                                            : "positive number (or give 'speed')");
    }
    char expected[64];
    snprintf(expected, sizeof expected, "array of %d numbers", D);
    read_numbers(L, 2, "fill", "velocity", D, expected, 0, f.velocity);
    f.seed = (uint64_t)bind_field_integer(L, 2, "fill", "seed", 1, 0, LUA_MAXINTEGER, 0);
    if (lua_getfield(L, 2, "region") != LUA_TNIL) {
        int r = lua_gettop(L);
        snprintf(expected, sizeof expected, "{{lower corner}, {upper corner}} with %d numbers each",
                 D);
        if (lua_type(L, r) != LUA_TTABLE || luaL_len(L, r) != 2)
            bind_field_error(L, 2, "fill", "region", expected);
        for (int c = 0; c < 2; c++) {
            lua_rawgeti(L, r, c + 1);
            for (int k = 0; k < D; k++) {
                int ok = lua_type(L, -1) == LUA_TTABLE && luaL_len(L, -1) == D;
                if (ok) {
                    lua_rawgeti(L, -1, k + 1);
                    ok = lua_type(L, -1) == LUA_TNUMBER && fabs(lua_tonumber(L, -1)) <= 1e100;
                    (c == 0 ? f.lo : f.hi)[k] = lua_tonumber(L, -1);
                    lua_pop(L, 1);
                }
                if (!ok) {
                    lua_settop(L, r);
                    bind_field_error(L, 2, "fill", "region", expected);
                }
            }
            lua_pop(L, 1);
        }
    }
    lua_pop(L, 1);
    core_error err;
    if (dsmc_fill(s, &f, &err))
        return bind_raise(L, "fill", &err);
    lua_pushinteger(L, (lua_Integer)dsmc_count(s));
    return 1;
}

/* s:add{ x = {...}, y = {...}, vx = {...}, vy = {...} }: arrays of equal length. */
static const char *const ADD_FIELDS[] = {"x", "y", "z", "vx", "vy", "vz", NULL};

static int l_add(lua_State *L)
{
    dsmc_scene *s = whole_scene(L, 1, "add");
    int D = dsmc_def(s)->dim;
    bind_check_table(L, 2, "add");
    bind_check_fields(L, 2, "add", ADD_FIELDS);
    static const char *const names[6] = {"x", "y", "z", "vx", "vy", "vz"};
    double *a[6] = {NULL, NULL, NULL, NULL, NULL, NULL};
    lua_Integer n = -1;
    for (int q = 0; q < 6; q++) {
        int k = q % 3;
        if (k >= D) {
            if (lua_getfield(L, 2, names[q]) != LUA_TNIL)
                bind_field_error(L, 2, "add", names[q], "nothing in 2D");
            lua_pop(L, 1);
            continue;
        }
        if (lua_getfield(L, 2, names[q]) != LUA_TTABLE ||
            (n >= 0 && luaL_len(L, -1) != n) || luaL_len(L, -1) < 1)
            bind_field_error(L, 2, "add", names[q],
                             n >= 0 ? "array as long as 'x'" : "non-empty array of numbers");
        n = luaL_len(L, -1);
        a[q] = lua_newuserdatauv(L, (size_t)n * sizeof(double), 0); /* freed by the GC */
        for (lua_Integer i = 0; i < n; i++) {
            lua_rawgeti(L, -2, i + 1);
            int isnum;
            a[q][i] = lua_tonumberx(L, -1, &isnum);
            if (!isnum || lua_type(L, -1) != LUA_TNUMBER || !(fabs(a[q][i]) <= 1e100))
                return luaL_error(L,
                                  "bad field '%s' in argument #1 to 'add' (array of finite "
                                  "numbers of magnitude at most 1e+100 expected, entry %d is not)",
                                  names[q], (int)i + 1);
            lua_pop(L, 1);
        }
        lua_remove(L, -2); /* the userdata stays on the stack while we work */
    }
    core_error err;
    core_status st = dsmc_add(s, (size_t)n, a[0], a[1], a[2], a[3], a[4], a[5], &err);
    if (st)
        return bind_raise(L, "add", &err);
    lua_pushinteger(L, (lua_Integer)dsmc_count(s));
    return 1;
}

static int l_particles(lua_State *L)
{
    dsmc_scene *s = whole_scene(L, 1, "particles");
    int D = dsmc_def(s)->dim;
    size_t n = dsmc_count(s);
    dsmc_particles p;
    dsmc_get_particles(s, &p);
    static const char *const xs[3] = {"x", "y", "z"}, *const vs[3] = {"vx", "vy", "vz"};
    lua_createtable(L, 0, 8);
    for (int k = 0; k < D; k++) {
        bind_push_array(L, p.x[k], n, xs[k]);
        bind_push_array(L, p.v[k], n, vs[k]);
    }
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        double q = 0;
        for (int k = 0; k < D; k++)
            q += p.v[k][i] * p.v[k][i];
        lua_pushnumber(L, sqrt(q));
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "speed");
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        lua_pushinteger(L, (lua_Integer)p.id[i] + 1);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "id");
    lua_pushinteger(L, (lua_Integer)n);
    lua_setfield(L, -2, "count");
    return 1;
}

/* ---- walls ---------------------------------------------------------------------------------- */
static int side_of(lua_State *L, int D, const char *name)
{
    static const char *const generic[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    static const char *const n2[4] = {"left", "right", "bottom", "top"};
    static const char *const n3[6] = {"left", "right", "front", "back", "bottom", "top"};
    for (int k = 0; k < 2 * D; k++)
        if (strcmp(name, generic[k]) == 0 || strcmp(name, D == 2 ? n2[k] : n3[k]) == 0)
            return k;
    (void)L;
    return -1;
}

static const char *const WALL_FIELDS[] = {"side",        "kind",      "restitution",
                                          "temperature", "amplitude", "frequency",
                                          "phase",       "velocity",  NULL};

static int l_wall(lua_State *L)
{
    static const char *const kinds[] = {"specular", "diffuse", NULL};
    dsmc_scene *s = check_scene(L, 1);
    int D = dsmc_def(s)->dim;
    bind_check_table(L, 2, "wall");
    bind_check_fields(L, 2, "wall", WALL_FIELDS);
    const char *name = bind_field_string(L, 2, "wall", "side", NULL, BIND_REQUIRED);
    int side = side_of(L, D, name);
    if (side < 0) {
        lua_getfield(L, 2, "side");
        return bind_field_error(L, 2, "wall", "side",
                                D == 2 ? "one of 'left', 'right', 'bottom', 'top' (or 'xlo', "
                                         "'xhi', 'ylo', 'yhi')"
                                       : "one of 'left', 'right', 'front', 'back', 'bottom', "
                                         "'top' (or 'xlo' ... 'zhi')");
    }
    dsmc_wall_def w = dsmc_default_wall_def();
    w.kind = (dsmc_wall_kind)bind_field_option(L, 2, "wall", "kind", kinds, 0, 0);
    w.restitution = bind_field_number(L, 2, "wall", "restitution", 1, 0);
    if (!(w.restitution >= 0 && w.restitution <= 1)) {
        lua_getfield(L, 2, "restitution");
        return bind_field_error(L, 2, "wall", "restitution", "number in [0, 1]");
    }
    if (w.kind == DSMC_WALL_DIFFUSE)
        w.temperature = bind_field_number(L, 2, "wall", "temperature", 0,
                                          BIND_REQUIRED | BIND_POSITIVE);
    else if (lua_getfield(L, 2, "temperature") != LUA_TNIL)
        return bind_field_error(L, 2, "wall", "temperature", "nothing unless 'kind' is 'diffuse'");
    w.amplitude = bind_field_number(L, 2, "wall", "amplitude", 0, BIND_NONNEG);
    w.frequency = bind_field_number(L, 2, "wall", "frequency", 0, BIND_NONNEG);
    w.phase = bind_field_number(L, 2, "wall", "phase", 0, 0);
    for (int k = 0; k < 2 && !(w.amplitude > 0); k++) { /* an oscillation needs its amplitude */
        const char *f = k ? "phase" : "frequency";
        if (lua_getfield(L, 2, f) != LUA_TNIL)
            return bind_field_error(L, 2, "wall", f, "nothing unless 'amplitude' is > 0");
        lua_pop(L, 1);
    }
    if (w.amplitude > 0 && !(w.frequency > 0)) {
        lua_getfield(L, 2, "frequency");
        return bind_field_error(L, 2, "wall", "frequency", "positive number with an amplitude");
    }
    char expected[64];
    snprintf(expected, sizeof expected, "array of %d numbers", D);
    read_numbers(L, 2, "wall", "velocity", D, expected, 0, w.velocity);
    core_error err;
    if (dsmc_set_wall(s, side, &w, &err))
        return bind_raise(L, "wall", &err);
    return 0;
}

/* ---- running -------------------------------------------------------------------------------- */
static void push_validity(lua_State *L, const dsmc_validity *v)
{
    lua_createtable(L, 0, 12);
    set_number(L, "density", v->density);
    set_number(L, "packing", v->packing);
    set_number(L, "chi", v->chi);
    set_number(L, "mean_free_path", v->mean_free_path);
    set_number(L, "knudsen", v->knudsen);
    set_number(L, "cell_size", v->cell_size);
    set_number(L, "collision_time", v->collision_time);
    set_number(L, "dt", v->dt);
    lua_pushboolean(L, v->collisional);
    lua_setfield(L, -2, "collisional");
    lua_pushboolean(L, v->cells_ok);
    lua_setfield(L, -2, "cells_ok");
    lua_pushboolean(L, v->dt_ok);
    lua_setfield(L, -2, "dt_ok");
}

/* The paper's three conditions, each violation on its own line with its numbers. */
static void warn_validity(const dsmc_validity *v)
{
    if (!v->collisional)
        fprintf(stderr, "dsmc run: warning: not in the collisional regime (condition i): mean free "
                        "path %.3g m against the box's smallest side %.3g m (Knudsen number "
                        "%.3g >= 1)\n", v->mean_free_path, v->mean_free_path / v->knudsen,
                v->knudsen);
    if (!v->cells_ok)
        fprintf(stderr, "dsmc run: warning: cells larger than the mean free path (condition ii): "
                        "cell side %.3g m >= mean free path %.3g m (density %.4g /m^d, packing "
                        "%.3g, chi %.4g); use more cells\n", v->cell_size, v->mean_free_path,
                v->density, v->packing, v->chi);
    if (!v->dt_ok)
        fprintf(stderr, "dsmc run: warning: time step above the mean collision time (condition "
                        "iii): dt %.3g s >= 1/omega = %.3g s; use dt below %.3g s\n", v->dt,
                v->collision_time, v->collision_time);
    fflush(stderr);
}

typedef struct advance_ctx {
    dsmc_scene *s;
    dsmc_run_def *run;
} advance_ctx;

static core_status advance(void *ctx, long n, struct progress *p, long *done, core_error *err)
{
    (void)p;
    advance_ctx *c = ctx;
    c->run->steps = n;
    return dsmc_run(c->s, c->run, done, err);
}

static const char *const RUN_FIELDS[] = {"steps",   "time",     "dt",   "force", "every",
                                         "on_step", "progress", "warn", NULL};

static int l_run(lua_State *L)
{
    dsmc_scene *s = check_scene(L, 1);
    bind_refuse_running(L, 1, "run", "return false from on_step to stop it");
    bind_check_table(L, 2, "run");
    bind_check_fields(L, 2, "run", RUN_FIELDS);
    if (dsmc_count(s) < 2)
        return luaL_error(L, "run: the scene has %d particles (fill it first)",
                          (int)dsmc_count(s));
    dsmc_run_def run = dsmc_default_run_def();
    dsmc_validity v;
    core_error err;
    if (dsmc_check_validity(s, 0, &v, &err))
        return bind_raise(L, "run", &err);
    lua_getfield(L, 2, "dt");
    if (lua_isnil(L, -1) ||
        (lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "auto") == 0)) {
        run.dt = 0.1 * v.collision_time; /* a tenth of the mean collision time */
        if (!isfinite(run.dt))
            return luaL_error(L, "run: dt = 'auto' needs moving particles (the gas is at rest); "
                                 "give dt");
    } else {
        run.dt = bind_field_number(L, 2, "run", "dt", 0, BIND_POSITIVE);
        /* The paper's condition (iii) as a limit, as DEM's and MPM's stability limits: beyond
         * the mean collision time the candidates of Eq. 1 grow with dt (work without physics:
         * pairs meet several times in a step) and the result drifts (docs/dsmc.md). */
        if (run.dt > v.collision_time && !bind_field_boolean(L, 2, "run", "force", 0)) {
            char msg[400]; /* lua_pushfstring knows no %g */
            snprintf(msg, sizeof msg,
                     "run: dt = %g s exceeds the mean collision time 1/omega = %.3g s (the "
                     "paper's condition iii, at the gas's density and temperature); use dt = "
                     "\"auto\" (%.3g s), a smaller dt, or force = true",
                     run.dt, v.collision_time, 0.1 * v.collision_time);
            return luaL_error(L, "%s", msg);
        }
    }
    lua_pop(L, 1);
    (void)bind_field_boolean(L, 2, "run", "force", 0); /* checked whatever dt is */
    long steps;
    double time;
    int by_steps = bind_steps_or_time(L, 2, "run", &steps, &time);
    int warn = bind_field_boolean(L, 2, "run", "warn", 1);
    v.dt = run.dt;
    v.dt_ok = v.collision_time > run.dt;
    if (warn)
        warn_validity(&v);
    double t0 = dsmc_time(s);
    long expect = steps;
    if (!by_steps) {
        run.time_end = t0 + time;
        expect = bind_time_steps(L, 2, "run", time, run.dt);
        steps = LUA_MAXINTEGER;
    }
    long s0 = dsmc_steps_done(s);
    advance_ctx ctx = {s, &run};
    bind_run r = {"dsmc run", steps, expect, advance, &ctx, 0, run.dt, 0};
    int stopped = bind_run_chunks(L, 1, 2, "run", &r);
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, dsmc_steps_done(s) - s0);
    lua_setfield(L, -2, "steps");
    set_number(L, "time", dsmc_time(s) - t0);
    set_number(L, "dt", run.dt);
    lua_pushboolean(L, stopped);
    lua_setfield(L, -2, "stopped");
    return 1;
}

/* ---- measurements --------------------------------------------------------------------------- */
static void push_cells(lua_State *L, const dsmc_scene *s, const double *a, const char *name)
{
    bind_push_array(L, a, dsmc_cell_count(s), name);
}

/* {{lo...}, {hi...}}: the scene's box. */
static void push_box(lua_State *L, const dsmc_scene_def *d)
{
    lua_createtable(L, 2, 0);
    push_vec(L, d->lo, d->dim);
    lua_rawseti(L, -2, 1);
    push_vec(L, d->hi, d->dim);
    lua_rawseti(L, -2, 2);
}

static void push_grid(lua_State *L, const dsmc_scene *s)
{
    const dsmc_scene_def *d = dsmc_def(s);
    int D = d->dim;
    static const char *const nn[3] = {"nx", "ny", "nz"};
    for (int k = 0; k < D; k++) {
        lua_pushinteger(L, d->cells[k]);
        lua_setfield(L, -2, nn[k]);
    }
    push_box(L, d);
    lua_setfield(L, -2, "extent");
}

static void measure_stats(lua_State *L, dsmc_scene *s)
{
    dsmc_stats st;
    dsmc_get_stats(s, &st);
    double N = (double)dsmc_count(s), steps = st.steps > 0 ? (double)st.steps : NAN;
    lua_createtable(L, 0, 16);
    lua_pushinteger(L, st.steps);
    lua_setfield(L, -2, "steps");
    set_number(L, "particles", N);
    set_number(L, "particle_moves", st.particle_moves);
    set_number(L, "cpu_s", st.cpu_s);
    set_number(L, "wall_s", st.wall_s);
    set_number(L, "particle_moves_per_cpu_s", st.particle_moves / st.cpu_s);
    set_number(L, "particle_moves_per_s", st.particle_moves / st.wall_s);
    set_number(L, "attempts", st.attempts);
    set_number(L, "collisions", st.collisions);
    set_number(L, "accepted", st.collisions); /* SPARTA: collision attempts vs collisions */
    set_number(L, "attempts_per_particle_per_step", st.attempts / st.particle_moves);
    set_number(L, "collisions_per_particle_per_step", st.collisions / st.particle_moves);
    set_number(L, "acceptance", st.collisions / st.attempts);
    set_number(L, "wall_hits", st.wall_hits);
    set_number(L, "vmax_raised", st.vmax_raised);
    set_number(L, "cells_overpacked", st.cells_overpacked);
    set_number(L, "time", st.time);
    /* measured collision frequency per particle: 2 collisions / (N t) */
    set_number(L, "collision_frequency", 2 * st.collisions / (N * st.time));
    set_number(L, "collision_frequency_theory", dsmc_collision_frequency(s));
    set_number(L, "total_collisions", dsmc_total_collisions(s));
    /* a distributed run's traffic (0 on one rank): totals over ranks, and per step per rank */
    set_number(L, "comm_bytes", st.comm_bytes);
    set_number(L, "comm_messages", st.comm_messages);
    set_number(L, "comm_s", st.comm_s);
    set_number(L, "ranks", (double)dsmc_ranks(s));
    set_number(L, "imbalance", st.imbalance);
    set_number(L, "comm_bytes_per_step_per_rank", st.comm_bytes / (steps * dsmc_ranks(s)));
    set_number(L, "comm_messages_per_step_per_rank", st.comm_messages / (steps * dsmc_ranks(s)));
}

static const char *const HISTOGRAM_FIELDS[] = {"bins", "range", "quantity", NULL};

static const char *const PROFILE_FIELDS[] = {"axis", "bins", NULL};

static const char *const VALIDITY_FIELDS[] = {"dt", NULL};

/* The modes that take no options: a table given to them may hold no key. */
static const char *const NO_FIELDS[] = {NULL};

/* measure('temperature') and measure('a2'): the moments, and for a2 also per cell. */
static int measure_moments(lua_State *L, dsmc_scene *s, int a2_cells)
{
    const int D = dsmc_def(s)->dim;
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    double N = (double)m.n;
    lua_createtable(L, 0, 14);
    set_number(L, "temperature", m.temperature);
    set_number(L, "t_over_m", m.t_over_m);
    set_number(L, "kinetic_energy", m.kinetic_energy);
    push_vec(L, m.momentum, D);
    lua_setfield(L, -2, "momentum");
    push_vec(L, m.mean_velocity, D);
    lua_setfield(L, -2, "mean_velocity");
    set_number(L, "kurtosis", m.kurtosis);
    set_number(L, "a2", m.a2);
    set_number(L, "n", N);
    set_number(L, "collisions", dsmc_total_collisions(s));
    set_number(L, "collisions_per_particle", N > 0 ? 2 * dsmc_total_collisions(s) / N : 0);
    set_number(L, "collision_frequency", dsmc_collision_frequency(s));
    set_number(L, "time", dsmc_time(s));
    if (a2_cells) {
        size_t nc = dsmc_cell_count(s);
        double *a2 = malloc(nc * sizeof *a2);
        if (!a2)
            return luaL_error(L, "measure: out of memory");
        dsmc_fields f = {0};
        f.a2 = a2;
        dsmc_measure_fields(s, &f);
        push_cells(L, s, a2, "cells");
        free(a2);
        push_grid(L, s);
    }
    return 1;
}

/* measure('fields'): count, density, packing, velocity, temperature and a2 per cell. */
static int measure_fields(lua_State *L, dsmc_scene *s)
{
    const int D = dsmc_def(s)->dim;
    size_t nc = dsmc_cell_count(s);
    double *buf = malloc(9 * nc * sizeof *buf);
    if (!buf)
        return luaL_error(L, "measure: out of memory");
    dsmc_fields f = {.count = buf, .density = buf + nc, .packing = buf + 2 * nc,
                     .u = {buf + 3 * nc, buf + 4 * nc, D == 3 ? buf + 5 * nc : NULL},
                     .temperature = buf + 6 * nc, .a2 = buf + 7 * nc};
    dsmc_measure_fields(s, &f);
    lua_createtable(L, 0, 12);
    push_cells(L, s, f.count, "count");
    push_cells(L, s, f.density, "density");
    push_cells(L, s, f.packing, "packing");
    static const char *const un[3] = {"ux", "uy", "uz"};
    for (int k = 0; k < D; k++)
        push_cells(L, s, f.u[k], un[k]);
    push_cells(L, s, f.temperature, "temperature");
    push_cells(L, s, f.a2, "a2");
    free(buf);
    push_grid(L, s);
    return 1;
}

/* measure('histogram', { bins =, range =, quantity = }): of a velocity component or the speed. */
static int measure_histogram(lua_State *L, dsmc_scene *s, int has_opts)
{
    static const char *const qn[] = {"component", "speed", NULL};
    core_error err;
    int bins = 40, q = 0;
    dsmc_moments m;
    dsmc_measure_moments(s, &m);
    double sd = sqrt(m.t_over_m), range[2];
    if (has_opts) {
        bins = (int)bind_field_integer(L, 3, "measure", "bins", 40, 1, 100000, 0);
        q = bind_field_option(L, 3, "measure", "quantity", qn, 0, 0);
    }
    range[0] = q == 0 ? -5 * sd : 0;
    range[1] = 5 * sd;
    if (has_opts && read_numbers(L, 3, "measure", "range", 2, "array of 2 numbers", 0, range) &&
        !(range[1] > range[0])) {
        lua_getfield(L, 3, "range");
        return bind_field_error(L, 3, "measure", "range", "{lo, hi} with hi > lo");
    }
    double *counts = malloc((size_t)bins * sizeof *counts), outside;
    if (!counts)
        return luaL_error(L, "measure: out of memory");
    if (dsmc_measure_histogram(s, q, bins, range[0], range[1], counts, &outside, &err)) {
        free(counts);
        return bind_raise(L, "measure", &err);
    }
    double total = outside, w = (range[1] - range[0]) / bins;
    for (int b = 0; b < bins; b++)
        total += counts[b];
    lua_createtable(L, 0, 8);
    lua_createtable(L, bins, 0);
    for (int b = 0; b < bins; b++) {
        lua_pushnumber(L, range[0] + (b + 0.5) * w);
        lua_rawseti(L, -2, b + 1);
    }
    lua_setfield(L, -2, "centers");
    bind_push_array(L, counts, (size_t)bins, "counts");
    for (int b = 0; b < bins; b++)
        counts[b] = total > 0 ? counts[b] / (total * w) : 0;
    bind_push_array(L, counts, (size_t)bins, "pdf");
    free(counts);
    set_number(L, "outside", outside);
    set_number(L, "samples", total);
    set_number(L, "kurtosis", m.kurtosis);
    set_number(L, "t_over_m", m.t_over_m);
    lua_pushstring(L, qn[q]);
    lua_setfield(L, -2, "quantity");
    return 1;
}

/* measure('profile', { axis =, bins = }): layers along an axis. */
static int measure_profile(lua_State *L, dsmc_scene *s, int has_opts)
{
    const dsmc_scene_def *d = dsmc_def(s);
    const int D = d->dim;
    core_error err;
    int axis = D, bins = d->cells[D - 1];
    if (has_opts) {
        axis = (int)bind_field_integer(L, 3, "measure", "axis", D, 1, D, 0);
        bins = (int)bind_field_integer(L, 3, "measure", "bins", d->cells[axis - 1], 1, 1000000, 0);
    }
    double *buf = malloc(5 * (size_t)bins * sizeof *buf);
    if (!buf)
        return luaL_error(L, "measure: out of memory");
    size_t nb = (size_t)bins;
    dsmc_measure_profile(s, axis - 1, bins, buf, buf + nb, buf + 2 * nb, buf + 3 * nb,
                         buf + 4 * nb, &err);
    lua_createtable(L, 0, 6);
    bind_push_array(L, buf, nb, "position");
    bind_push_array(L, buf + nb, nb, "count");
    bind_push_array(L, buf + 2 * nb, nb, "density");
    bind_push_array(L, buf + 3 * nb, nb, "packing");
    bind_push_array(L, buf + 4 * nb, nb, "temperature");
    free(buf);
    lua_pushinteger(L, axis);
    lua_setfield(L, -2, "axis");
    return 1;
}

/* measure('validity', { dt = }): the paper's three conditions. */
static int measure_validity(lua_State *L, dsmc_scene *s, int has_opts)
{
    core_error err;
    double dt = 0;
    if (has_opts)
        dt = bind_field_number(L, 3, "measure", "dt", 0, BIND_NONNEG);
    dsmc_validity v;
    if (dsmc_check_validity(s, dt, &v, &err))
        return bind_raise(L, "measure", &err);
    push_validity(L, &v);
    return 1;
}

static int l_measure(lua_State *L)
{
    static const char *const what_names[] = {"temperature", "a2", "fields", "histogram", "stats",
                                             "profile", "validity", NULL};
    static const char *const *const what_fields[] = {
        NO_FIELDS, NO_FIELDS, NO_FIELDS, HISTOGRAM_FIELDS, NO_FIELDS, PROFILE_FIELDS,
        VALIDITY_FIELDS};
    dsmc_scene *s = check_scene(L, 1);
    int what = bind_check_option(L, 2, NULL, what_names);
    int has_opts = bind_mode_options(L, 3, "measure", what_names[what], what_fields[what]);
    if (what == 1 || what == 2 || what == 3 || what == 5) /* a2, fields, histogram, profile */
        whole_scene(L, 1, "measure");
    switch (what) {
    case 0: return measure_moments(L, s, 0);
    case 1: return measure_moments(L, s, 1);
    case 2: return measure_fields(L, s);
    case 3: return measure_histogram(L, s, has_opts);
    case 4: measure_stats(L, s); return 1;
    case 5: return measure_profile(L, s, has_opts);
    default: return measure_validity(L, s, has_opts);
    }
}

static int l_reset_stats(lua_State *L)
{
    dsmc_reset_stats(check_scene(L, 1));
    return 0;
}

static int l_info(lua_State *L)
{
    dsmc_scene *s = check_scene(L, 1);
    const dsmc_scene_def *d = dsmc_def(s);
    int D = d->dim;
    lua_createtable(L, 0, 20);
    lua_pushinteger(L, D);
    lua_setfield(L, -2, "dim");
    push_box(L, d);
    lua_setfield(L, -2, "box");
    double cells[3] = {d->cells[0], d->cells[1], d->cells[2]}, h[3];
    push_vec(L, cells, D);
    lua_setfield(L, -2, "cells");
    dsmc_cell_size(s, h);
    push_vec(L, h, D);
    lua_setfield(L, -2, "cell_size");
    push_vec(L, d->gravity, D);
    lua_setfield(L, -2, "gravity");
    lua_pushinteger(L, (lua_Integer)dsmc_count(s));
    lua_setfield(L, -2, "count");
    set_number(L, "radius", d->radius);
    set_number(L, "mass", dsmc_mass(s));
    set_number(L, "density", d->density);
    set_number(L, "restitution", d->restitution);
    set_number(L, "cross_section", dsmc_cross_section(s));
    set_number(L, "volume", dsmc_volume(s));
    double nu = (double)dsmc_count(s) * dsmc_particle_volume(s) / dsmc_volume(s);
    set_number(L, "packing", nu);
    set_number(L, "chi", dsmc_chi(s, nu));
    set_number(L, "packing_limit", d->packing_limit);
    lua_pushinteger(L, (lua_Integer)dsmc_capacity(s));
    lua_setfield(L, -2, "capacity");
    lua_pushstring(L, EXCLUDED_NAMES[d->excluded]);
    lua_setfield(L, -2, "excluded_volume");
    size_t pb, cb;
    dsmc_memory(s, &pb, &cb);
    set_number(L, "particle_bytes", (double)pb);
    set_number(L, "cell_bytes", (double)cb);
    set_number(L, "time", dsmc_time(s));
    lua_pushinteger(L, dsmc_steps_done(s));
    lua_setfield(L, -2, "steps");
    return 1;
}

static int l_gc(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    bind_refuse_running(L, 1, "close", "it can be closed once its run has returned");
    dsmc_destroy(u->s);
    u->s = NULL;
    return 0;
}

static int l_tostring(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    if (!u->s) {
        lua_pushliteral(L, "dsmc.scene (closed)");
        return 1;
    }
    const dsmc_scene_def *d = dsmc_def(u->s);
    char buf[200];
    if (d->dim == 2)
        snprintf(buf, sizeof buf, "dsmc.scene 2D (%d x %d cells, %zu particles, e = %g, t = %g s)",
                 d->cells[0], d->cells[1], dsmc_count(u->s), d->restitution, dsmc_time(u->s));
    else
        snprintf(buf, sizeof buf,
                 "dsmc.scene 3D (%d x %d x %d cells, %zu particles, e = %g, t = %g s)",
                 d->cells[0], d->cells[1], d->cells[2], dsmc_count(u->s), d->restitution,
                 dsmc_time(u->s));
    lua_pushstring(L, buf);
    (void)AXES;
    return 1;
}

void bind_open_dsmc(lua_State *L)
{
    static const bind_fn methods[] = {
        {"fill", l_fill,
         "s:fill{ n =, temperature = T | speed = v, region = {{lo}, {hi}}, velocity = {u}, "
         "seed = 1 }",
         "Adds n particles at uniform random positions in region (default: the whole box) with "
         "Maxwellian velocities at granular temperature T (J; T/m = <|v - u|^2>/d) or all with "
         "speed v in uniformly random directions, plus the drift velocity u. Refuses more "
         "particles than fit at the packing limit. Returns the particle count."},
        {"add", l_add, "s:add{ x = {...}, y = {...}, z = {...}, vx = {...}, vy = {...}, vz = {...} }",
         "Adds particles from arrays of equal length (z, vz in 3D only); positions inside the box. "
         "Returns the particle count."},
        {"wall", l_wall,
         "s:wall{ side = 'bottom', kind = 'specular'|'diffuse', restitution = 1, temperature =, "
         "amplitude = 0, frequency = 0, phase = 0, velocity = {...} }",
         "Sets the wall on a side of an axis that is not periodic (every such side starts as a "
         "specular wall with restitution 1). Sides: left/right (x), bottom/top (y) in 2D; "
         "left/right (x), front/back (y), bottom/top (z) in 3D; or xlo, xhi, ylo, yhi, zlo, zhi. "
         "specular: the normal velocity in the wall frame reversed and scaled by restitution. "
         "diffuse: re-emitted from the flux-weighted Maxwellian at temperature (J). amplitude A "
         "(m) and frequency f (Hz) make it vibrate inward from its side: position side + A (1 + "
         "sin(2 pi f t + phase)), velocity 2 pi f A cos(2 pi f t + phase). velocity: a constant "
         "tangential wall velocity (the normal component is ignored)."},
        {"run", l_run,
         "s:run{ steps = N | time = T, dt = 'auto', force = false, every =, on_step = "
         "function(s) end, progress =, warn = true }",
         "Advances the gas: free flight with gravity and walls, sorting into cells, collisions "
         "of Eq. 1 with v_max = twice the largest speed about the cell's mean velocity (raised "
         "when a pair exceeds it), a random impact parameter and restitution e. dt = 'auto' is "
         "a tenth of the mean collision time; a dt above the mean collision time is refused "
         "unless force = true. Before running, the paper's validity conditions "
         "(i) collisional regime, (ii) mean free path larger than the cell, (iii) mean collision "
         "time larger than dt are checked and each violation is warned with its numbers on "
         "stderr (warn = false: silent; s:measure('validity') returns them). The run stops with "
         "an error naming the step and the cell when a cell holds more than three times the "
         "particles that fit in it at the packing limit (a state past close packing), when a "
         "cell would need more than 100 candidate pairs per particle in one step, or when a "
         "particle crosses the box's walls more than 4 times in one step. on_step runs every "
         "`every` steps; returning false stops. Returns {steps, time, dt, stopped}. Progress on stderr: "
         "nil shows it once the run has taken 2 s, true at once, false never (--quiet: never). "
         "From on_step, calls that would invalidate the run (a nested run, close, ...) are "
         "refused."},
        {"measure", l_measure,
         "s:measure('temperature'|'a2'|'fields'|'histogram'|'stats'|'profile'|'validity', opts)",
         "temperature: temperature (J, m <|v - u|^2>/d), t_over_m, kinetic_energy, momentum, "
         "mean_velocity, kurtosis <|v-u|^4>/<|v-u|^2>^2, a2 = d/(d+2) kurtosis - 1, collisions "
         "(accepted, since creation), collisions_per_particle (c = 2 N_coll / N), "
         "collision_frequency (kinetic theory for the current state), time. a2: the same plus "
         "cells = a2 per cell. fields: per cell (index (k ny + j) nx + i, from 1) count, density "
         "(1/m^d), packing, ux, uy, uz, temperature (J, unbiased, NaN below 2 particles), a2; with "
         "nx, ny, nz, extent. histogram {bins = 40, range = {lo, hi}, quantity = 'component'|"
         "'speed'}: centers, counts, pdf, outside, kurtosis (about the mean velocity; default "
         "range 5 sqrt(T/m)). stats (SPARTA's vocabulary, since s:reset_stats()): steps, "
         "particle_moves, particle_moves_per_cpu_s, attempts, collisions (= accepted), "
         "attempts_per_particle_per_step, collisions_per_particle_per_step, acceptance, "
         "wall_hits, vmax_raised, collision_frequency (measured: 2 collisions / (N t)), "
         "collision_frequency_theory; under mpirun ranks, comm_bytes, comm_messages (sent, all "
         "ranks), comm_s (the slowest rank's), comm_bytes_per_step_per_rank and "
         "comm_messages_per_step_per_rank, imbalance (the busiest rank's particles over the mean, "
         "at the end of the last run). profile {axis = dim, bins = cells}: position, count, "
         "density, packing, temperature per layer. validity {dt = 0}: the paper's conditions "
         "with their numbers."},
        {"particles", l_particles, "s:particles()",
         "Arrays x, y, (z), vx, vy, (vz), speed and id (the particle's identity: its order of "
         "addition, from 1) over the particles, sorted by cell and within a cell by id; and "
         "count. The same on any number of MPI ranks."},
        {"reset_stats", l_reset_stats, "s:reset_stats()",
         "Zeroes the run statistics of s:measure('stats') (not the collision count since "
         "creation)."},
        {"info", l_info, "s:info()",
         "dim, box, cells, cell_size, gravity, count, radius, mass, density, restitution, "
         "cross_section (sigma of Eq. 1), volume, packing, chi, packing_limit, capacity, "
         "excluded_volume, time, steps, particle_bytes and cell_bytes (memory of the particle "
         "arrays: position, velocity, cell index; and of the per-cell arrays)."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_gc}, {"__close", l_gc}, {"__tostring", l_tostring}, {NULL, NULL}};
    bind_new_type(L, SCENE, methods, meta, "A DSMC granular gas from dsmc.scene{...}.");
    static const bind_fields method_fields[] = {{"fill", NULL, FILL_FIELDS},
                                                {"add", NULL, ADD_FIELDS},
                                                {"wall", NULL, WALL_FIELDS},
                                                {"run", NULL, RUN_FIELDS},
                                                {"measure", "temperature", NO_FIELDS},
                                                {"measure", "a2", NO_FIELDS},
                                                {"measure", "fields", NO_FIELDS},
                                                {"measure", "histogram", HISTOGRAM_FIELDS},
                                                {"measure", "stats", NO_FIELDS},
                                                {"measure", "profile", PROFILE_FIELDS},
                                                {"measure", "validity", VALIDITY_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, SCENE, method_fields);

    static const bind_fn fns[] = {
        {"scene", l_scene,
         "dsmc.scene{ dim = 2, box = {{x0, y0}, {x1, y1}} | size = {Lx, Ly}, cells = {nx, ny}, "
         "periodic = true | {bx, by}, gravity = {0, 0}, restitution = 1, radius =, density = "
         "2650 | mass =, excluded_volume = 'free_volume'|'enskog'|'none', packing_limit =, seed "
         "= 1 }",
         "A granular gas of equal spheres (disks moving in a plane in 2D; mass 4/3 pi R^3 rho "
         "unless mass is given) in a box of cells (sides at least a diameter). Axes are "
         "periodic by default; the sides of other axes are walls (s:wall). restitution e in [0, "
         "1]. excluded_volume: the paper's free volume V_c - V_b/nu_rcp in Eq. 1 (default; chi "
         "= 1/(1 - nu/nu_rcp)), the Enskog chi(nu) of the cell, or none (chi = 1). "
         "packing_limit nu_rcp: 0.82 (2D), 0.64 (3D). Results depend on the seed, not on the "
         "number of threads, nor on the number of MPI ranks (under mpirun the first run "
         "splits the grid between the ranks; queries that need every particle gather it "
         "back)."},
        {NULL, NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, -1, fns);
    static const bind_fields fn_fields[] = {{"scene", NULL, SCENE_FIELDS}, {NULL, NULL, NULL}};
    bind_register_fields(L, -1, fn_fields);
    bind_doc(L, -1, "dsmc", "dsmc",
             "Granular gases by direct simulation Monte Carlo (Herrmann & Mueller Sec. 4, after "
             "Bird): stochastic collisions within cells, 2D and 3D.");
    lua_setglobal(L, "dsmc");
}

/* ---- for other bindings (lua_checkpoint_mpm.c) --------------------------------------------- */
dsmc_scene *bind_check_dsmc_scene(lua_State *L, int idx, const char *call)
{
    lscene *u = bind_check_udata(L, idx, SCENE, call);
    if (!u->s)
        luaL_error(L, "%s: the dsmc.scene was closed", call);
    /* its callers (save, write_vtk) write the whole scene */
    core_error err;
    if (dsmc_gather(u->s, &err))
        bind_raise(L, call, &err);
    return u->s;
}

dsmc_scene **bind_new_dsmc_scene(lua_State *L)
{
    lscene *u = lua_newuserdatauv(L, sizeof *u, 0);
    u->s = NULL;
    luaL_setmetatable(L, SCENE);
    return &u->s;
}
