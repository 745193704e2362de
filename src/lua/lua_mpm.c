/* The Lua module `mpm` and mpm.scene: material-point scenes over src/mpm. Translates and checks
 * arguments, calls the kernels, raises their errors named after the call. mpm.material is in
 * lua_mpm_material.c, the scene's measurements in lua_mpm_measure.c. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/comm.h"
#include "core/progress.h"
#include "lua/bind.h"
#include "lua/lua_mpm.h"
#include "mpm/mpm.h"

static const char *SCENE = "mpm.scene";
static const char *MATERIAL = "mpm.material";

typedef struct lscene {
    mpm_scene *s;
} lscene;

mpm_scene *bind_mpm_check(lua_State *L, int idx)
{
    lscene *u = luaL_checkudata(L, idx, SCENE);
    if (!u->s)
        luaL_error(L, "the mpm.scene was closed");
    return u->s;
}

void bind_mpm_set_number(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

void bind_mpm_push_pair(lua_State *L, const double v[2])
{
    lua_createtable(L, 2, 0);
    for (int d = 0; d < 2; d++) {
        lua_pushnumber(L, v[d]);
        lua_rawseti(L, -2, d + 1);
    }
}

/* ---- mpm.scene{...} ---------------------------------------------------------------------------
 */
static const char *const WALL_NAMES[] = {"noslip", "slip", "none", "friction", NULL};
static const char *const SHAPE_NAMES[] = {"linear", "bspline", NULL};
static const char *const NORMAL_NAMES[] = {"averaged", "own", "linear", NULL};
static const char *const UPDATE_NAMES[] = {"usl", "musl", "usf", NULL};

static void read_pair(lua_State *L, int arg, const char *field, const char *expected, int *is_int,
                      double out[2], int required)
{
    int t = lua_getfield(L, arg, field);
    if (t == LUA_TNIL && !required) {
        lua_pop(L, 1);
        return;
    }
    if (t != LUA_TTABLE || luaL_len(L, -1) != 2)
        bind_field_error(L, arg, "scene", field, expected);
    for (int k = 0; k < 2; k++) {
        lua_rawgeti(L, -1, k + 1);
        int ok = is_int ? lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 1 &&
                              lua_tointeger(L, -1) <= (1 << 20)
                        : lua_type(L, -1) == LUA_TNUMBER && lua_tonumber(L, -1) > 0 &&
                              lua_tonumber(L, -1) <= 1e100;
        double v = lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (!ok)
            bind_field_error(L, arg, "scene", field, expected);
        out[k] = v;
        if (is_int)
            is_int[k] = (int)v;
    }
    lua_pop(L, 1);
}

/* One wall: a name, or {kind = name, mu = , velocity = {vx, vy}} (a table at the stack top). */
static void read_wall(lua_State *L, const char *field, mpm_wall *kind, double *mu, double v[2])
{
    static const char *const fields[] = {"kind", "mu", "velocity", NULL};
    const char *expected = "'noslip', 'slip', 'none' or {kind = 'noslip'|'slip'|'friction', "
                           "mu =, velocity = {vx, vy}}";
    int w = -1;
    if (lua_type(L, -1) == LUA_TSTRING) {
        for (int i = 0; WALL_NAMES[i]; i++)
            if (strcmp(lua_tostring(L, -1), WALL_NAMES[i]) == 0)
                w = i;
        if (w == MPM_WALL_FRICTION)
            bind_field_error(L, 1, "scene", field,
                             "{kind = 'friction', mu = ...} (a friction "
                             "wall needs mu)");
        if (w < 0)
            bind_field_error(L, 1, "scene", field, expected);
        *kind = (mpm_wall)w;
        return;
    }
    if (lua_type(L, -1) != LUA_TTABLE)
        bind_field_error(L, 1, "scene", field, expected);
    int t = lua_gettop(L);
    bind_check_fields(L, t, "scene", fields);
    char sub[48];
    snprintf(sub, sizeof sub, "%s.kind", field);
    w = -1;
    if (lua_getfield(L, t, "kind") == LUA_TSTRING)
        for (int i = 0; WALL_NAMES[i]; i++)
            if (strcmp(lua_tostring(L, -1), WALL_NAMES[i]) == 0)
                w = i;
    if (w < 0)
        bind_field_error(L, 1, "scene", sub, "one of 'noslip', 'slip', 'none', 'friction'");
    lua_pop(L, 1);
    *kind = (mpm_wall)w;
    snprintf(sub, sizeof sub, "%s.mu", field);
    int tm = lua_getfield(L, t, "mu");
    if (tm != LUA_TNIL || *kind == MPM_WALL_FRICTION) {
        if (tm != LUA_TNUMBER || !(lua_tonumber(L, -1) >= 0) || !isfinite(lua_tonumber(L, -1)))
            bind_field_error(L, 1, "scene", sub, "non-negative number");
        *mu = lua_tonumber(L, -1);
    }
    lua_pop(L, 1);
    snprintf(sub, sizeof sub, "%s.velocity", field);
    if (lua_getfield(L, t, "velocity") != LUA_TNIL) {
        int ok = lua_type(L, -1) == LUA_TTABLE && luaL_len(L, -1) == 2;
        for (int k = 0; ok && k < 2; k++) {
            lua_rawgeti(L, -1, k + 1);
            v[k] = lua_tonumberx(L, -1, &ok);
            ok = ok && isfinite(v[k]);
            lua_pop(L, 1);
        }
        if (!ok)
            bind_field_error(L, 1, "scene", sub, "array of 2 finite numbers");
    }
    lua_pop(L, 1);
}

static void read_walls(lua_State *L, mpm_scene_def *def)
{
    static const char *const sides[] = {"left", "right", "bottom", "top", NULL};
    const char *expected = "a wall or a table {left =, right =, bottom =, top =} of walls";
    int t = lua_getfield(L, 1, "walls");
    if (t == LUA_TNIL) {
        lua_pop(L, 1);
        return;
    }
    if (t == LUA_TSTRING || (t == LUA_TTABLE && lua_getfield(L, -1, "kind") != LUA_TNIL)) {
        if (t == LUA_TTABLE)
            lua_pop(L, 1);
        mpm_wall w = MPM_WALL_NOSLIP;
        double mu = 0, v[2] = {0, 0};
        read_wall(L, "walls", &w, &mu, v);
        for (int k = 0; k < 4; k++) {
            def->walls[k] = w;
            def->wall_mu[k] = mu;
            def->wall_velocity[k][0] = v[0];
            def->wall_velocity[k][1] = v[1];
        }
        lua_pop(L, 1);
        return;
    }
    if (t != LUA_TTABLE)
        bind_field_error(L, 1, "scene", "walls", expected);
    lua_pop(L, 1); /* the nil kind */
    int tab = lua_gettop(L);
    for (lua_pushnil(L); lua_next(L, tab); lua_pop(L, 1)) { /* a typo names the field */
        int known = 0;
        for (int k = 0; sides[k] && !known; k++)
            known = lua_type(L, -2) == LUA_TSTRING && strcmp(lua_tostring(L, -2), sides[k]) == 0;
        if (!known) {
            lua_pushvalue(L, tab);
            bind_field_error(L, 1, "scene", "walls", expected);
        }
    }
    if (lua_rawlen(L, tab) == 0 && (lua_pushnil(L), lua_next(L, tab) == 0))
        bind_field_error(L, 1, "scene", "walls", expected); /* {}: no wall named */
    lua_settop(L, tab);
    for (int k = 0; k < 4; k++) {
        if (lua_getfield(L, tab, sides[k]) == LUA_TNIL) {
            lua_pop(L, 1);
            continue;
        }
        char field[32];
        snprintf(field, sizeof field, "walls.%s", sides[k]);
        read_wall(L, field, &def->walls[k], &def->wall_mu[k], def->wall_velocity[k]);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

static const char *const SCENE_FIELDS[] = {"cells",   "size",     "origin", "periodic",
                                           "gravity", "walls",    "update", "pic",
                                           "shape",   "wall_gap", NULL};

/* MPM has no decomposition: under mpirun every rank would run the whole scene and, with only
 * rank 0 writing, silently waste the others. Refused before anything is built. */
static void refuse_distributed(lua_State *L, const char *call)
{
    if (comm_size() > 1)
        luaL_error(L,
                   "%s: MPM does not run distributed yet (this run has %d ranks under "
                   "mpirun); run MPM scripts without mpirun (OpenMP threads still apply)",
                   call, comm_size());
}

static int l_scene(lua_State *L)
{
    refuse_distributed(L, "mpm.scene");
    bind_check_table(L, 1, "scene");
    bind_check_fields(L, 1, "scene", SCENE_FIELDS);
    mpm_scene_def def = mpm_default_scene_def();
    double cells[2];
    read_pair(L, 1, "cells", "array of 2 integers in [1, 1048576]", def.cells, cells, 1);
    read_pair(L, 1, "size", "array of 2 positive numbers of at most 1e+100", NULL, def.size, 1);
    bind_field_vector(L, 1, "scene", "origin", 2, def.origin, 0);
    bind_field_vector(L, 1, "scene", "gravity", 2, def.gravity, 0);
    if (lua_getfield(L, 1, "periodic") != LUA_TNIL) {
        if (lua_type(L, -1) != LUA_TTABLE || luaL_len(L, -1) != 2)
            bind_field_error(L, 1, "scene", "periodic", "array of 2 booleans");
        for (int d = 0; d < 2; d++) {
            int t = lua_rawgeti(L, -1, d + 1);
            def.periodic[d] = lua_toboolean(L, -1);
            lua_pop(L, 1);
            if (t != LUA_TBOOLEAN)
                bind_field_error(L, 1, "scene", "periodic", "array of 2 booleans");
        }
    }
    lua_pop(L, 1);
    read_walls(L, &def);
    def.update = (mpm_update)bind_field_option(L, 1, "scene", "update", UPDATE_NAMES, MPM_MUSL, 0);
    def.pic = bind_field_number(L, 1, "scene", "pic", 0, BIND_NONNEG);
    def.wall_gap = bind_field_number(L, 1, "scene", "wall_gap", def.wall_gap, BIND_NONNEG);
    def.shape =
        (mpm_shape_fn)bind_field_option(L, 1, "scene", "shape", SHAPE_NAMES, MPM_SHAPE_LINEAR, 0);
    if (def.pic > 1) {
        lua_getfield(L, 1, "pic");
        return bind_field_error(L, 1, "scene", "pic", "number in [0, 1]");
    }
    lscene *u = lua_newuserdatauv(L, sizeof *u, 1);
    u->s = NULL;
    luaL_setmetatable(L, SCENE);
    lua_newtable(L); /* mpm.material -> material index */
    lua_setiuservalue(L, -2, 1);
    core_error err;
    if (mpm_create(&def, &u->s, &err) != CORE_OK)
        return bind_raise(L, "scene", &err);
    return 1;
}

/* Material index of the mpm.material in field `material` of the table at arg (registered with
 * the scene on first use). */
static int material_of(lua_State *L, int scene, int arg, const char *call)
{
    mpm_scene *s = bind_mpm_check(L, scene);
    lua_getfield(L, arg, "material");
    const mpm_material *m = luaL_testudata(L, -1, MATERIAL);
    if (!m)
        return bind_field_error(L, arg, call, "material", "mpm.material");
    lua_getiuservalue(L, scene, 1);
    lua_pushvalue(L, -2);
    if (lua_rawget(L, -2) == LUA_TNUMBER) {
        int idx = (int)lua_tointeger(L, -1);
        lua_pop(L, 3);
        return idx;
    }
    lua_pop(L, 1);
    core_error err;
    int idx = mpm_add_material(s, m, &err);
    if (idx < 0)
        return bind_raise(L, call, &err);
    lua_pushvalue(L, -2);
    lua_pushinteger(L, idx);
    lua_rawset(L, -3);
    lua_pop(L, 2);
    return idx;
}

/* ---- grains ---------------------------------------------------------------------------------- */
static const char *const DISK_FIELDS[] = {"center",   "radius", "material", "points_per_cell",
                                          "velocity", "omega",  "clip",     "hydrostatic",
                                          NULL};
static const char *const RECT_FIELDS[] = {
    "lo", "hi", "material", "points_per_cell", "velocity", "omega", "clip", "hydrostatic", NULL};
static const char *const POLYGON_FIELDS[] = {"vertices", "material", "points_per_cell", "velocity",
                                             "omega",    "clip",     "hydrostatic",     NULL};

static int add_grain(lua_State *L, const char *call, mpm_shape shape)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    const bind_run *r = bind_running(L, 1);
    if (r && r->dt > 0 && !r->forced) /* with dt = 'auto' the CFL condition holds every step */
        bind_refuse_running(L, 1, call, "a new grain can raise the wave speed the run's fixed dt "
                                        "was checked against: add grains between runs, or run "
                                        "with dt = 'auto'");
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call,
                      shape == MPM_DISK   ? DISK_FIELDS
                      : shape == MPM_RECT ? RECT_FIELDS
                                          : POLYGON_FIELDS);
    mpm_grain_def g = mpm_default_grain_def();
    g.shape = shape;
    if (shape == MPM_POLYGON) {
        const char *expected = "array of at least 3 vertices {x, y}";
        if (lua_getfield(L, 2, "vertices") != LUA_TTABLE || luaL_len(L, -1) < 3)
            return bind_field_error(L, 2, call, "vertices", expected);
        int nv = (int)luaL_len(L, -1);
        double *v = lua_newuserdatauv(L, (size_t)nv * 2 * sizeof *v, 0); /* freed by the GC */
        for (int i = 0; i < nv; i++) {
            int ok = lua_rawgeti(L, -2, i + 1) == LUA_TTABLE && luaL_len(L, -1) == 2;
            for (int a = 0; ok && a < 2; a++) {
                lua_rawgeti(L, -1, a + 1);
                v[2 * i + a] = lua_tonumberx(L, -1, &ok);
                ok = ok && lua_type(L, -1) == LUA_TNUMBER && fabs(v[2 * i + a]) <= 1e100;
                lua_pop(L, 1);
            }
            if (!ok)
                return luaL_error(L,
                                  "bad field 'vertices' in argument #1 to '%s' (%s expected, "
                                  "vertex %d is not a pair of finite numbers)",
                                  call, expected, i + 1);
            lua_pop(L, 1);
        }
        g.vertices = v;
        g.nvertices = nv;
        lua_replace(L, -2); /* keep v on the stack while the grain is added */
    } else if (shape == MPM_DISK) {
        bind_field_vector(L, 2, call, "center", 2, g.center, BIND_REQUIRED);
        g.radius = bind_field_number(L, 2, call, "radius", 0, BIND_REQUIRED | BIND_POSITIVE);
    } else {
        bind_field_vector(L, 2, call, "lo", 2, g.lo, BIND_REQUIRED);
        bind_field_vector(L, 2, call, "hi", 2, g.hi, BIND_REQUIRED);
    }
    g.points_per_cell = (int)bind_field_integer(L, 2, call, "points_per_cell", 2, 1, 64, 0);
    bind_field_vector(L, 2, call, "velocity", 2, g.velocity, 0);
    g.omega = bind_field_number(L, 2, call, "omega", 0, 0);
    g.clip = bind_field_boolean(L, 2, call, "clip", 0);
    int hydro = bind_field_boolean(L, 2, call, "hydrostatic", 0);
    g.material = material_of(L, 1, 2, call);
    core_error err;
    long id = mpm_add_grain(s, &g, &err);
    if (id < 0)
        return bind_raise(L, call, &err);
    if (hydro && mpm_hydrostatic(s, (size_t)id, &err))
        return bind_raise(L, call, &err);
    size_t other;
    double overlap = mpm_grain_overlap(s, (size_t)id, &other);
    if (overlap > 0)
        fprintf(stderr,
                "grainlab: warning: %s: grain %ld overlaps grain %zu by %g m; overlapping "
                "grains share material points' cells from the start (with 'friction' they are "
                "pushed apart, with 'noslip' glued)\n",
                call, id + 1, other + 1, overlap);
    lua_pushinteger(L, id + 1);
    return 1;
}

static int l_add_disk(lua_State *L) { return add_grain(L, "add_disk", MPM_DISK); }
static int l_add_rect(lua_State *L) { return add_grain(L, "add_rect", MPM_RECT); }
static int l_add_polygon(lua_State *L) { return add_grain(L, "add_polygon", MPM_POLYGON); }

/* ---- contact --------------------------------------------------------------------------------- */
static const char *const CONTACT_FIELDS[] = {"model",      "mu",       "normals", "separation",
                                             "strain_cap", "conserve", NULL};

static int l_contact(lua_State *L)
{
    static const char *const names[] = {"noslip", "friction", NULL};
    mpm_scene *s = bind_mpm_check(L, 1);
    bind_check_table(L, 2, "contact");
    bind_check_fields(L, 2, "contact", CONTACT_FIELDS);
    int model = bind_field_option(L, 2, "contact", "model", names, 0, BIND_REQUIRED);
    core_error err;
    mpm_contact_options o = mpm_default_contact_options();
    o.normals =
        (mpm_normals)bind_field_option(L, 2, "contact", "normals", NORMAL_NAMES, o.normals, 0);
    o.separation = bind_field_number(L, 2, "contact", "separation", o.separation, BIND_NONNEG);
    if (o.separation > 1) {
        lua_getfield(L, 2, "separation");
        return bind_field_error(L, 2, "contact", "separation", "number in [0, 1]");
    }
    o.strain_cap = bind_field_number(L, 2, "contact", "strain_cap", o.strain_cap, BIND_NONNEG);
    o.conserve = bind_field_boolean(L, 2, "contact", "conserve", o.conserve);
    if (mpm_set_contact_options(s, &o, &err))
        return bind_raise(L, "contact", &err);
    if (model == MPM_CONTACT_FRICTION) {
        double mu = bind_field_number(L, 2, "contact", "mu", 0, BIND_REQUIRED | BIND_NONNEG);
        if (mpm_set_friction(s, mu, &err))
            return bind_raise(L, "contact", &err);
        return 0;
    }
    if (lua_getfield(L, 2, "mu") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "mu", "nothing for model 'noslip'");
    if (mpm_set_contact(s, (mpm_contact_model)model, &err))
        return bind_raise(L, "contact", &err);
    return 0;
}

/* A grain id in [1, count] at arg, as a 0-based index. */
size_t bind_mpm_grain_arg(lua_State *L, mpm_scene *s, int arg, const char *call)
{
    int isint;
    lua_Integer id = lua_tointegerx(L, arg, &isint);
    if (!isint || lua_type(L, arg) != LUA_TNUMBER || id < 1 || (size_t)id > mpm_grain_count(s)) {
        char expected[64];
        snprintf(expected, sizeof expected, "grain id in [1, %zu]", mpm_grain_count(s));
        bind_arg_error(L, arg, call, expected);
    }
    return (size_t)(id - 1);
}

/* m:prescribe(grain, {vx, vy}) */
static int l_prescribe(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    size_t id = bind_mpm_grain_arg(L, s, 2, "prescribe");
    double v[2];
    bind_arg_vector(L, 3, "prescribe", 2, v);
    core_error err;
    if (mpm_prescribe(s, id, v, &err))
        return bind_raise(L, "prescribe", &err);
    return 0;
}

/* m:plane{ point = {x, y}, normal = {nx, ny}, kind = 'friction', mu = 0.5, velocity = {0, 0} } */
static const char *const PLANE_FIELDS[] = {"point", "normal", "kind", "mu", "velocity", NULL};

static int l_plane(lua_State *L)
{
    static const char *const kinds[] = {"noslip", "slip", "friction", NULL};
    static const mpm_wall kind_of[] = {MPM_WALL_NOSLIP, MPM_WALL_SLIP, MPM_WALL_FRICTION};
    mpm_scene *s = bind_mpm_check(L, 1);
    bind_check_table(L, 2, "plane");
    bind_check_fields(L, 2, "plane", PLANE_FIELDS);
    mpm_plane_def d = {{0, 0}, {0, 1}, MPM_WALL_FRICTION, 0, {0, 0}};
    bind_field_vector(L, 2, "plane", "point", 2, d.point, BIND_REQUIRED);
    bind_field_vector(L, 2, "plane", "normal", 2, d.normal, BIND_REQUIRED);
    d.kind = kind_of[bind_field_option(L, 2, "plane", "kind", kinds, 2, 0)];
    d.mu = bind_field_number(L, 2, "plane", "mu", 0,
                             BIND_NONNEG | (d.kind == MPM_WALL_FRICTION ? BIND_REQUIRED : 0));
    bind_field_vector(L, 2, "plane", "velocity", 2, d.velocity, 0);
    if (hypot(d.normal[0], d.normal[1]) == 0) {
        lua_getfield(L, 2, "normal");
        return bind_field_error(L, 2, "plane", "normal", "non-zero vector");
    }
    core_error err;
    if (mpm_add_plane(s, &d, &err))
        return bind_raise(L, "plane", &err);
    return 0;
}

/* ---- time stepping ------------------------------------------------------------------------- */
static void push_timestep(lua_State *L, const mpm_timestep *t)
{
    lua_createtable(L, 0, 4);
    lua_pushnumber(L, t->wave_speed);
    lua_setfield(L, -2, "wave_speed");
    lua_pushnumber(L, t->max_speed);
    lua_setfield(L, -2, "max_speed");
    lua_pushnumber(L, t->limit);
    lua_setfield(L, -2, "limit");
    lua_pushnumber(L, t->dt_auto);
    lua_setfield(L, -2, "dt_auto");
}

static const char *const TIMESTEP_FIELDS[] = {"cfl", NULL};

static int l_timestep(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    double cfl = MPM_DEFAULT_CFL;
    if (!lua_isnoneornil(L, 2)) {
        bind_check_table(L, 2, "timestep");
        bind_check_fields(L, 2, "timestep", TIMESTEP_FIELDS);
        cfl = bind_field_number(L, 2, "timestep", "cfl", cfl, BIND_POSITIVE);
    }
    mpm_timestep t;
    core_error err;
    if (mpm_timestep_info(s, cfl, &t, &err))
        return bind_raise(L, "timestep", &err);
    push_timestep(L, &t);
    return 1;
}

typedef struct mpm_advance_ctx {
    mpm_scene *s;
    mpm_run_def *run;
} mpm_advance_ctx;

static core_status mpm_advance(void *ctx, long n, struct progress *p, long *done,
                               core_error *err)
{
    (void)p;
    mpm_advance_ctx *c = ctx;
    c->run->steps = n;
    return mpm_run(c->s, c->run, done, err);
}

static const char *const RUN_FIELDS[] = {"steps", "time",    "dt",       "cfl", "force",
                                         "every", "on_step", "progress", NULL};

static int l_run(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    bind_refuse_running(L, 1, "run", "return false from on_step to stop it");
    bind_check_table(L, 2, "run");
    bind_check_fields(L, 2, "run", RUN_FIELDS);
    mpm_run_def run = mpm_default_run_def();
    run.cfl = bind_field_number(L, 2, "run", "cfl", MPM_DEFAULT_CFL, BIND_POSITIVE);
    if (run.cfl > 1) {
        lua_getfield(L, 2, "cfl");
        return bind_field_error(L, 2, "run", "cfl", "number in (0, 1]");
    }
    int force = bind_field_boolean(L, 2, "run", "force", 0);
    mpm_timestep ts;
    core_error err;
    if (mpm_timestep_info(s, run.cfl, &ts, &err))
        return bind_raise(L, "run", &err);
    lua_getfield(L, 2, "dt");
    if (lua_isnil(L, -1) ||
        (lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "auto") == 0)) {
        run.dt = 0; /* re-evaluated every step from the CFL condition */
    } else {
        lua_pop(L, 1);
        run.dt = bind_field_number(L, 2, "run", "dt", 0, BIND_POSITIVE);
        lua_pushnil(L);
        if (run.dt > ts.limit && !force) {
            char msg[512];
            snprintf(msg, sizeof msg,
                     "run: dt = %g s exceeds the CFL limit %g s (h / (c + max|v|) with h = the "
                     "smaller cell side, wave speed c = %g m/s, fastest point %g m/s); use dt = "
                     "\"auto\" (%g s at cfl = %g), a smaller dt, or force = true",
                     run.dt, ts.limit, ts.wave_speed, ts.max_speed, ts.dt_auto, run.cfl);
            return luaL_error(L, "%s", msg);
        }
    }
    lua_pop(L, 1);
    long steps;
    double time;
    int by_steps = bind_steps_or_time(L, 2, "run", &steps, &time);
    double t0 = mpm_time(s);
    long expect = steps; /* for progress and the default `every` */
    if (!by_steps) {
        run.time_end = t0 + time;
        expect = bind_time_steps(L, 2, "run", time, run.dt > 0 ? run.dt : ts.dt_auto);
        steps = LUA_MAXINTEGER;
    }
    long s0 = mpm_steps_done(s);
    mpm_advance_ctx ctx = {s, &run};
    bind_run r = {"mpm run", steps, expect, mpm_advance, &ctx, 0, run.dt, force};
    int stopped = bind_run_chunks(L, 1, 2, "run", &r);
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, mpm_steps_done(s) - s0);
    lua_setfield(L, -2, "steps");
    lua_pushnumber(L, mpm_time(s) - t0);
    lua_setfield(L, -2, "time");
    lua_pushnumber(L, run.dt > 0 ? run.dt : ts.dt_auto);
    lua_setfield(L, -2, "dt");
    lua_pushboolean(L, stopped);
    lua_setfield(L, -2, "stopped");
    return 1;
}

/* m:set_velocities{ vx = {...}, vy = {...} }: one entry per point. */
static const char *const VELOCITIES_FIELDS[] = {"vx", "vy", NULL};

static int l_set_velocities(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    bind_check_table(L, 2, "set_velocities");
    bind_check_fields(L, 2, "set_velocities", VELOCITIES_FIELDS);
    size_t n = mpm_point_count(s);
    char expected[96];
    snprintf(expected, sizeof expected, "array of %zu finite numbers (one per point)", n);
    double *v[2];
    static const char *const comp[2] = {"vx", "vy"};
    for (int d = 0; d < 2; d++) {
        if (lua_getfield(L, 2, comp[d]) != LUA_TTABLE || (size_t)luaL_len(L, -1) != n)
            return bind_field_error(L, 2, "set_velocities", comp[d], expected);
        v[d] = lua_newuserdatauv(L, (n ? n : 1) * sizeof(double), 0); /* freed by the GC */
        for (size_t i = 0; i < n; i++) {
            lua_rawgeti(L, -2, (lua_Integer)i + 1);
            int isnum;
            v[d][i] = lua_tonumberx(L, -1, &isnum);
            if (!isnum || lua_type(L, -1) != LUA_TNUMBER || !(fabs(v[d][i]) <= 1e100))
                return luaL_error(L,
                                  "bad field '%s' in argument #1 to 'set_velocities' (%s "
                                  "of magnitude at most 1e+100 expected, entry %d is not)",
                                  comp[d], expected, (int)i + 1);
            lua_pop(L, 1);
        }
    }
    core_error err;
    if (mpm_set_velocities(s, v[0], v[1], &err))
        return bind_raise(L, "set_velocities", &err);
    return 0;
}

static int l_info(lua_State *L)
{
    mpm_scene *s = bind_mpm_check(L, 1);
    const mpm_scene_def *d = mpm_def(s);
    lua_createtable(L, 0, 12);
    lua_createtable(L, 2, 0);
    for (int k = 0; k < 2; k++) {
        lua_pushinteger(L, d->cells[k]);
        lua_rawseti(L, -2, k + 1);
    }
    lua_setfield(L, -2, "cells");
    bind_mpm_push_pair(L, d->size);
    lua_setfield(L, -2, "size");
    bind_mpm_push_pair(L, d->origin);
    lua_setfield(L, -2, "origin");
    bind_mpm_push_pair(L, d->gravity);
    lua_setfield(L, -2, "gravity");
    double h[2];
    mpm_cell_size(s, h);
    bind_mpm_push_pair(L, h);
    lua_setfield(L, -2, "cell_size");
    lua_pushinteger(L, (lua_Integer)mpm_point_count(s));
    lua_setfield(L, -2, "points");
    lua_pushinteger(L, (lua_Integer)mpm_grain_count(s));
    lua_setfield(L, -2, "grains");
    bind_mpm_set_number(L, "time", mpm_time(s));
    lua_pushinteger(L, mpm_steps_done(s));
    lua_setfield(L, -2, "steps");
    lua_pushstring(L, UPDATE_NAMES[d->update]);
    lua_setfield(L, -2, "update");
    bind_mpm_set_number(L, "pic", d->pic);
    lua_pushstring(L, mpm_contact(s) == MPM_CONTACT_NOSLIP ? "noslip" : "friction");
    lua_setfield(L, -2, "contact");
    bind_mpm_set_number(L, "mu", mpm_friction(s));
    lua_pushstring(L, SHAPE_NAMES[d->shape]);
    lua_setfield(L, -2, "shape");
    mpm_contact_options o = mpm_get_contact_options(s);
    lua_pushstring(L, NORMAL_NAMES[o.normals]);
    lua_setfield(L, -2, "normals");
    bind_mpm_set_number(L, "separation", o.separation);
    bind_mpm_set_number(L, "strain_cap", o.strain_cap);
    lua_pushboolean(L, o.conserve);
    lua_setfield(L, -2, "conserve");
    return 1;
}

static int l_gc(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    bind_refuse_running(L, 1, "close", "it can be closed once its run has returned");
    mpm_destroy(u->s);
    u->s = NULL;
    return 0;
}

static int l_tostring(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    if (!u->s) {
        lua_pushliteral(L, "mpm.scene (closed)");
    } else {
        const mpm_scene_def *d = mpm_def(u->s);
        lua_pushfstring(L, "mpm.scene (%d x %d cells, %d grains, %d points, t = %f s)", d->cells[0],
                        d->cells[1], (int)mpm_grain_count(u->s), (int)mpm_point_count(u->s),
                        mpm_time(u->s));
    }
    return 1;
}

void bind_open_mpm(lua_State *L)
{
    static const bind_fn methods[] = {
        {"add_disk", l_add_disk,
         "m:add_disk{ center = {x, y}, radius = r, material = mat, points_per_cell = 2, "
         "velocity = {vx, vy}, omega = 0 }",
         "Fills a disk with n x n points per cell (points at the centres of the sub-cells inside "
         "the disk; the paper uses n = 2 or 3) and returns the grain id. The disk must lie inside "
         "the grid on axes that are not periodic. velocity and omega set a rigid initial motion "
         "about the grain's centroid. material: an mpm.material."},
        {"add_rect", l_add_rect,
         "m:add_rect{ lo = {x0, y0}, hi = {x1, y1}, material = mat, points_per_cell = 2, "
         "velocity = {vx, vy}, omega = 0 }",
         "Fills a rectangle with points like add_disk (bars, blocks); returns the grain id. "
         "Both take clip = true (keep only the points inside the grid: grains cut by an edge) "
         "and hydrostatic = true (initial static pressure with grad p = rho g, p = 0 at the "
         "grain's top, the paper's incline)."},
        {"add_polygon", l_add_polygon,
         "m:add_polygon{ vertices = {{x1, y1}, {x2, y2}, ...}, material = mat, points_per_cell = "
         "2, "
         "velocity =, omega =, clip =, hydrostatic = }",
         "Fills a simple polygon (either orientation, at least 3 vertices) with points like "
         "add_disk (angular grains); returns the grain id."},
        {"prescribe", l_prescribe, "m:prescribe(grain, {vx, vy})",
         "The grain moves rigidly at {vx, vy} from now on: every node its points touch takes "
         "that velocity, so its neighbours meet a moving rigid body through the contact rule "
         "(the shear test's edge grains)."},
        {"plane", l_plane,
         "m:plane{ point = {x, y}, normal = {nx, ny}, kind = 'friction'|'slip'|'noslip', mu =, "
         "velocity = {0, 0} }",
         "A rigid half-space not aligned with the grid (at most 4): the nodes behind the plane "
         "(normal points out of the body, into the material) take the wall rule with the "
         "plane's exact normal; the nodes form a staircase along it."},
        {"contact", l_contact,
         "m:contact{ model = 'noslip' | 'friction', mu = 0.3, normals = 'averaged'|'own'|'linear', "
         "separation = 0, strain_cap = 0, conserve = true }",
         "The grain contact model. 'noslip' (default): the single centre-of-mass velocity field "
         "of the basic algorithm (Sec. 2); grains stick on contact. 'friction' (Sec. 3; mu >= 0 "
         "required, 0 = frictionless): each grain also has its own nodal field, stored only at "
         "the nodes its points touch; where grains share a node and a grain approaches the "
         "centre-of-mass field (Eq. 12), its normal velocity is set to the centre-of-mass one "
         "(Eq. 14) and its tangential slip is reduced by at most mu times that correction "
         "(Coulomb, Eqs. 18-23), after the grid momentum update (not after P2G). Points move "
         "with their own grain's field, so grains separate again; an isolated grain moves "
         "exactly as with 'noslip'. normals: 'averaged' (default) the quadratic-B-spline "
         "gradient of the grain's mass field against that of everything else (opposite normals, "
         "momentum conserved), 'own' the grain's own B-spline density gradient (Eq. 24), "
         "'linear' as 'averaged' with linear-shape gradients. separation: a shared node is a "
         "contact only when the grains' nodal volumes fill this fraction of the cell (against "
         "contact at a distance; 0 = off). strain_cap: corrections limited to |dv| dt / h <= "
         "cap (0 = off). conserve (default true): the momentum the corrections change at a node "
         "(three or more grains, 'own' normals, the cap) is given back as a common velocity "
         "shift of the corrected grains there."},
        {"timestep", l_timestep, "m:timestep{ cfl = 0.4 }",
         "The CFL limit h / (c + max|v|) (h the smaller cell side, c = sqrt((K + 4G/3)/rho) the "
         "largest P-wave speed), the automatic step cfl x limit, the wave speed and the fastest "
         "point."},
        {"run", l_run,
         "m:run{ steps = N | time = T, dt = 'auto', cfl = 0.4, force = false, every =, "
         "on_step = function(m) end, progress = nil }",
         "Advances the scene (MUSL by default; update = 'usl' in mpm.scene for the paper's "
         "step order, which is unstable at nearly empty nodes, or 'usf', stress first). dt = "
         "'auto' takes cfl x h / (c + max|v|), "
         "re-evaluated every step; a fixed dt above the CFL limit is refused unless force = "
         "true. time = T lands exactly on T. on_step runs every `every` steps; returning false "
         "stops the run. Ctrl-C stops between steps with the scene intact; NaN, an inverted "
         "point or a point leaving the grid stop the run with an error naming the step, point "
         "and grain. Returns {steps, time, dt, stopped}. Progress on stderr: "
         "nil shows it once the run has taken 2 s, true at once, false never (--quiet: never). "
         "From on_step, calls that would invalidate the run (a nested run, close, ...) are "
         "refused."},
        {"set_velocities", l_set_velocities, "m:set_velocities{ vx = {...}, vy = {...} }",
         "Sets every point's velocity from arrays in point order (as m:points() lists them)."},
        {"info", l_info, "m:info()",
         "cells, size, origin, cell_size, gravity, points, grains, time, steps, update, pic, "
         "contact, mu (0 for noslip), shape, normals, separation, strain_cap, conserve."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_gc}, {"__close", l_gc}, {"__tostring", l_tostring}, {NULL, NULL}};
    bind_new_type(L, SCENE, methods, meta, "An MPM scene from mpm.scene{...}.");
    static const bind_fields method_fields[] = {{"add_disk", NULL, DISK_FIELDS},
                                                {"add_rect", NULL, RECT_FIELDS},
                                                {"add_polygon", NULL, POLYGON_FIELDS},
                                                {"contact", NULL, CONTACT_FIELDS},
                                                {"plane", NULL, PLANE_FIELDS},
                                                {"timestep", NULL, TIMESTEP_FIELDS},
                                                {"run", NULL, RUN_FIELDS},
                                                {"set_velocities", NULL, VELOCITIES_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, SCENE, method_fields);
    bind_open_mpm_measure(L);

    static const bind_fn fns[] = {
        {"scene", l_scene,
         "mpm.scene{ cells = {nx, ny}, size = {Lx, Ly}, origin = {0, 0}, periodic = {false, "
         "false}, gravity = {0, 0}, walls = 'noslip'|'slip'|'none'|{kind =, mu =, velocity =}|"
         "{left =, right =, bottom =, top =}, update = 'musl'|'usl'|'usf', pic = 0, "
         "shape = 'linear'|'bspline' }",
         "A new 2D (plane strain) MPM scene on a uniform grid of nx x ny cells. walls: the grid's "
         "boundary nodes on axes that are not periodic — 'noslip' fixes them (default), 'slip' "
         "fixes the normal velocity only, 'none' leaves them free (a point reaching the edge "
         "stops the run); {kind = 'friction', mu = 0.5} applies the grain contact rule against "
         "a rigid wall (Coulomb, only material moving into it); velocity = {vx, vy} moves a "
         "wall. shape: 'linear' (the paper's, 4 nodes per point) or 'bspline' (quadratic, 9 "
         "nodes, smooth across cell edges; a ghost node layer beyond each wall). update: 'musl' "
         "(default: the strain rate from remapped, mass-weighted nodal velocities, stable at "
         "nearly empty nodes) or 'usl' (the paper's step order). pic: PIC "
         "fraction of the point velocity update (0 = pure FLIP, Eq. 11)."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"scene", NULL, SCENE_FIELDS}, {NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    bind_open_mpm_material(L, -1);
    bind_doc(L, -1, "mpm", "mpm",
             "Material points: deformable grains on a background grid (Bardenhagen et al. 1998).");
    lua_setglobal(L, "mpm");
}

/* ---- for other bindings (lua_checkpoint_mpm.c) --------------------------------------------- */
mpm_scene *bind_check_mpm_scene(lua_State *L, int idx, const char *call)
{
    lscene *u = bind_check_udata(L, idx, SCENE, call);
    if (!u->s)
        luaL_error(L, "%s: the mpm.scene was closed", call);
    return u->s;
}

mpm_scene **bind_new_mpm_scene(lua_State *L)
{
    refuse_distributed(L, "mpm.load");
    lscene *u = lua_newuserdatauv(L, sizeof *u, 1);
    u->s = NULL;
    luaL_setmetatable(L, SCENE);
    lua_newtable(L); /* mpm.material -> material index (none yet: loaded materials have no
                      * Lua object, and a material used later is added anew) */
    lua_setiuservalue(L, -2, 1);
    return &u->s;
}
