/* The Lua module `dem`: scenes of disks (2D) or spheres (3D) over src/dem. Translates and checks
 * arguments, calls the kernels, raises their errors named after the call. This file: the scene,
 * its materials and particles, and the registration of the methods of lua_dem_contact.c,
 * lua_dem_walls.c, lua_dem_run.c and lua_dem_measure.c. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

static const char *SCENE = "dem.scene";

typedef struct lscene {
    dem_scene *s;
} lscene;

/* The scene as its run left it: decomposed over the ranks after a distributed run (s:run only). */
dem_scene *ldem_check_scene_local(lua_State *L, int idx)
{
    lscene *u = luaL_checkudata(L, idx, SCENE);
    if (!u->s)
        luaL_error(L, "the dem.scene was closed");
    return u->s;
}

/* Every other call sees the whole scene: after a distributed run it is gathered back to every
 * rank first (collective: every rank of an SPMD script makes the same calls). */
static dem_scene *replicated(lua_State *L, dem_scene *s, const char *call)
{
    core_error err;
    if (dem_replicate(s, &err) != CORE_OK)
        bind_raise(L, call, &err);
    return s;
}

dem_scene *ldem_check_scene(lua_State *L, int idx)
{
    return replicated(L, ldem_check_scene_local(L, idx), "scene");
}

struct dem_scene *bind_check_dem_scene(lua_State *L, int idx, const char *call)
{
    lscene *u = bind_check_udata(L, idx, SCENE, call);
    if (!u->s)
        luaL_error(L, "%s: the dem.scene was closed", call);
    return replicated(L, u->s, call);
}

void ldem_add_methods(lua_State *L, const bind_fn *methods, const bind_fields *fields)
{
    luaL_getmetatable(L, SCENE);
    lua_getfield(L, -1, "__index");
    bind_register(L, -1, methods);
    lua_pop(L, 2);
    if (fields)
        bind_type_fields(L, SCENE, fields);
}

void ldem_push_vector(lua_State *L, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int d = 0; d < n; d++) {
        lua_pushnumber(L, v[d]);
        lua_rawseti(L, -2, d + 1);
    }
}

/* ---- dem.scene{...} ------------------------------------------------------------------------ */
static const char *const SCENE_FIELDS[] = {"dim",       "box",  "gravity", "periodic",
                                           "thickness", "skin", NULL};

static int l_scene(lua_State *L)
{
    bind_check_table(L, 1, "scene");
    bind_check_fields(L, 1, "scene", SCENE_FIELDS);
    dem_scene_def def = dem_default_scene_def();
    def.dim = (int)bind_field_integer(L, 1, "scene", "dim", 2, 2, 3, 0);
    bind_field_box(L, 1, "scene", "box", def.dim, def.lo, def.hi);
    bind_field_vector(L, 1, "scene", "gravity", def.dim, def.gravity, 0);
    if (lua_getfield(L, 1, "periodic") != LUA_TNIL) {
        char expected[64];
        snprintf(expected, sizeof expected, "array of %d booleans", def.dim);
        if (lua_type(L, -1) != LUA_TTABLE || luaL_len(L, -1) != def.dim)
            bind_field_error(L, 1, "scene", "periodic", expected);
        for (int d = 0; d < def.dim; d++) {
            int t = lua_rawgeti(L, -1, d + 1);
            def.periodic[d] = lua_toboolean(L, -1);
            lua_pop(L, 1);
            if (t != LUA_TBOOLEAN)
                bind_field_error(L, 1, "scene", "periodic", expected);
        }
    }
    lua_pop(L, 1);
    def.thickness = bind_field_number(L, 1, "scene", "thickness", 0, BIND_NONNEG);
    if (def.dim == 3 && def.thickness > 0) {
        lua_getfield(L, 1, "thickness");
        bind_field_error(L, 1, "scene", "thickness", "nothing in 3D (thickness is for 2D disks)");
    }
    def.skin = bind_field_number(L, 1, "scene", "skin", 0, BIND_NONNEG);

    struct dem_scene **slot = bind_new_dem_scene(L);
    core_error err;
    if (dem_create(&def, slot, &err) != CORE_OK)
        return bind_raise(L, "scene", &err);
    return 1;
}

struct dem_scene **bind_new_dem_scene(lua_State *L)
{
    lscene *u = lua_newuserdatauv(L, sizeof *u, 1);
    u->s = NULL; /* safe before the kernel scene exists: __gc and every method check it */
    luaL_setmetatable(L, SCENE);
    lua_newtable(L); /* grainlab.material -> material index */
    lua_setiuservalue(L, -2, 1);
    return &u->s;
}

/* Material index for the field `field` of the table at arg: a grainlab.material (registered on
 * first use) or, when absent, grainlab's default quartz. */
int ldem_material_index(lua_State *L, int scene, int arg, const char *call, const char *field,
                        int absent)
{
    dem_scene *s = ldem_check_scene(L, scene);
    int t = lua_getfield(L, arg, field);
    if (t == LUA_TNIL && absent != -2) {
        lua_pop(L, 1);
        if (absent == -1)
            return -1;
        lua_pushliteral(L, "default");
    } else if (t != LUA_TTABLE || !luaL_getmetafield(L, -1, "__name") ||
               strcmp(lua_tostring(L, -1), "grainlab.material") != 0) {
        if (t == LUA_TTABLE)
            lua_settop(L, lua_gettop(L)); /* leave the value on top for the message */
        return bind_field_error(L, arg, call, field, "grainlab.material");
    } else {
        lua_pop(L, 1); /* __name */
    }
    lua_getiuservalue(L, scene, 1);
    lua_pushvalue(L, -2);
    if (lua_rawget(L, -2) == LUA_TNUMBER) {
        int idx = (int)lua_tointeger(L, -1);
        lua_pop(L, 3);
        return idx;
    }
    lua_pop(L, 1);
    dem_material m = dem_default_material();
    if (lua_type(L, -2) == LUA_TTABLE) {
        lua_getfield(L, -2, "density");
        m.density = lua_tonumber(L, -1);
        lua_getfield(L, -3, "young");
        m.young = lua_tonumber(L, -1);
        lua_getfield(L, -4, "poisson");
        m.poisson = lua_tonumber(L, -1);
        lua_getfield(L, -5, "friction");
        m.friction = lua_tonumber(L, -1);
        lua_getfield(L, -6, "restitution");
        m.restitution = lua_tonumber(L, -1);
        lua_getfield(L, -7, "rolling_friction");
        m.rolling_friction = lua_tonumber(L, -1);
        lua_getfield(L, -8, "work_of_adhesion");
        m.adhesion = lua_tonumber(L, -1);
        lua_pop(L, 7);
    }
    core_error err;
    int idx = dem_add_material(s, &m, &err);
    if (idx < 0)
        return bind_raise(L, call, &err);
    lua_pushvalue(L, -2);
    lua_pushinteger(L, idx);
    lua_rawset(L, -3);
    lua_pop(L, 2);
    return idx;
}

/* Once per scene, the first particle (or inserter) that takes the default material says so, and
 * what it costs: quartz's 30 GPa makes contacts short and dt = "auto" small (80 disks for
 * 0.02 s: 2.4 million steps). Called after the particle is in, with the material field of the
 * table at arg absent; --quiet silences it. Named after the library entry the script called
 * (grainlab.pack.deposit) when the particle came from one. */
void ldem_default_material_notice(lua_State *L, dem_scene *s, int scene, int arg, const char *call)
{
    if (lua_getfield(L, arg, "material") != LUA_TNIL) {
        lua_pop(L, 1);
        return;
    }
    lua_getiuservalue(L, scene, 1);
    int said = lua_getfield(L, -1, "default_noticed") != LUA_TNIL;
    lua_pop(L, 1);
    if (said) {
        lua_pop(L, 2);
        return;
    }
    lua_pushboolean(L, 1);
    lua_setfield(L, -2, "default_noticed");
    lua_pop(L, 2);
    dem_timestep ts; /* collective when decomposed: every rank makes the same calls */
    int known = dem_timestep_info(s, 0, &ts, NULL) == CORE_OK && ts.dt_auto > 0;
    if (progress_default_style() == PROGRESS_QUIET)
        return;
    const dem_material q = dem_default_material();
    char entry[96], cost[192] = "";
    if (known)
        snprintf(cost, sizeof cost,
                 ": its contact time sets dt = \"auto\" to %.3g s here, %.3g steps per simulated "
                 "second",
                 ts.dt_auto, 1 / ts.dt_auto);
    fprintf(stderr,
            "grainlab: note: %s: no material given, using the default quartz (E = %.3g GPa, "
            "rho = %.4g kg/m^3)%s; pass material = grainlab.material{...}\n",
            bind_entry_name(L, entry, sizeof entry) ? entry : call, q.young / 1e9, q.density, cost);
    fflush(stderr);
}

/* ---- particles ------------------------------------------------------------------------------ */
static const char *const PARTICLE_FIELDS[] = {"pos",   "radius", "material",   "vel",
                                              "omega", "fixed",  "prescribed", NULL};
/* From the on_step of a run (not forced), a particle may join only if the stability limit that
 * run's dt was checked against still holds: the limit comes from the smallest particle of each
 * material (contact times grow with size), so the new one must be no smaller than those. */
static void refuse_smaller_during_run(lua_State *L, dem_scene *s, const char *call,
                                      const dem_particle_def *p)
{
    const bind_run *r = bind_running(L, 1);
    if (!r || r->forced)
        return;
    const double *rad = dem_radii(s);
    const int *mat = dem_particle_materials(s);
    double rmin = INFINITY;
    for (size_t i = 0; i < dem_count(s); i++)
        if (mat[i] == p->material && rad[i] < rmin)
            rmin = rad[i];
    if (p->radius >= rmin)
        return;
    char why[320];
    if (isinf(rmin))
        snprintf(why, sizeof why,
                 "a particle of a material new to the scene could shorten the "
                 "stability limit the run's dt = %g s was checked at: add it between runs, or run "
                 "with force = true",
                 r->dt);
    else
        snprintf(why, sizeof why,
                 "a particle smaller than any of its material (radius %g m < %g "
                 "m) could shorten the stability limit the run's dt = %g s was checked at: add it "
                 "between runs, or run with force = true",
                 p->radius, rmin, r->dt);
    lua_pushstring(L, why);
    bind_refuse_running(L, 1, call, lua_tostring(L, -1));
}

static int add_particle(lua_State *L, const char *call, int want_dim)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    if (D != want_dim)
        return luaL_error(L, "%s: this is a %dD scene (use %s)", call, D,
                          D == 2 ? "add_disk" : "add_sphere");
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, PARTICLE_FIELDS);
    dem_particle_def p;
    memset(&p, 0, sizeof p);
    bind_field_vector(L, 2, call, "pos", D, p.x, BIND_REQUIRED);
    p.radius = bind_field_number(L, 2, call, "radius", 0, BIND_REQUIRED | BIND_POSITIVE);
    bind_field_vector(L, 2, call, "vel", D, p.v, 0);
    if (D == 2)
        p.omega[2] = bind_field_number(L, 2, call, "omega", 0, 0);
    else
        bind_field_vector(L, 2, call, "omega", 3, p.omega, 0);
    if (bind_field_boolean(L, 2, call, "fixed", 0))
        p.flags |= DEM_FIXED;
    if (bind_field_boolean(L, 2, call, "prescribed", 0))
        p.flags |= DEM_PRESCRIBED;
    if ((p.flags & DEM_FIXED) && (p.flags & DEM_PRESCRIBED))
        return luaL_error(L, "%s: a particle is either fixed or prescribed, not both", call);
    p.material = ldem_material_index(L, 1, 2, call, "material", 0);
    refuse_smaller_during_run(L, s, call, &p);
    core_error err;
    long i = dem_add_particle(s, &p, &err);
    if (i < 0)
        return bind_raise(L, call, &err);
    ldem_default_material_notice(L, s, 1, 2, call);
    lua_pushinteger(L, i + 1);
    return 1;
}

static int l_add_disk(lua_State *L) { return add_particle(L, "add_disk", 2); }
static int l_add_sphere(lua_State *L) { return add_particle(L, "add_sphere", 3); }

size_t ldem_particle_arg(lua_State *L, dem_scene *s, int arg, const char *call)
{
    int isint;
    lua_Integer i = lua_tointegerx(L, arg, &isint);
    if (!isint || lua_type(L, arg) != LUA_TNUMBER || i < 1 || (size_t)i > dem_count(s)) {
        char expected[64];
        snprintf(expected, sizeof expected, "particle id in [1, %zu]", dem_count(s));
        bind_arg_error(L, arg, call, expected);
    }
    return (size_t)(i - 1);
}

static int l_set_velocity(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    size_t i = ldem_particle_arg(L, s, 2, "set_velocity");
    double v[3] = {0, 0, 0};
    bind_arg_vector(L, 3, "set_velocity", dem_dim(s), v);
    core_error err;
    if (dem_set_velocity(s, i, v, &err))
        return bind_raise(L, "set_velocity", &err);
    return 0;
}

static int l_particles(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    size_t n = dem_count(s);
    static const char *const xs[3] = {"x", "y", "z"}, *const vs[3] = {"vx", "vy", "vz"};
    static const char *const ws[3] = {"wx", "wy", "wz"};
    lua_createtable(L, 0, 10);
    for (int d = 0; d < D; d++) {
        bind_push_array(L, dem_positions(s, d), n, xs[d]);
        bind_push_array(L, dem_velocities(s, d), n, vs[d]);
    }
    if (D == 2 && dem_angular_velocities(s, 2))
        bind_push_array(L, dem_angular_velocities(s, 2), n, "omega");
    if (D == 2 && dem_angles(s)) /* the integrated rotation: exact time averages of omega */
        bind_push_array(L, dem_angles(s), n, "angle");
    for (int d = 0; D == 3 && d < 3; d++)
        if (dem_angular_velocities(s, d))
            bind_push_array(L, dem_angular_velocities(s, d), n, ws[d]);
    bind_push_array(L, dem_radii(s), n, "radius");
    bind_push_array(L, dem_masses(s), n, "mass");
    static const char *const fs[3] = {"fx", "fy", "fz"};
    for (int d = 0; d < D && dem_forces(s, d); d++) /* the last force evaluation's */
        bind_push_array(L, dem_forces(s, d), n, fs[d]);
    if (dem_tags(s)) { /* with inserters or outflows: numbers that survive removals */
        const double *tag = dem_tags(s);
        lua_createtable(L, (int)n, 0);
        for (size_t i = 0; i < n; i++) {
            lua_pushinteger(L, (lua_Integer)tag[i] + 1);
            lua_rawseti(L, -2, (lua_Integer)i + 1);
        }
        lua_setfield(L, -2, "tag");
    }
    lua_pushinteger(L, (lua_Integer)n);
    lua_setfield(L, -2, "count");
    return 1;
}

static int l_info(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    lua_createtable(L, 0, 6);
    double lo[3], hi[3], g[3];
    dem_box(s, lo, hi, g);
    lua_createtable(L, 2, 0);
    ldem_push_vector(L, lo, dem_dim(s));
    lua_rawseti(L, -2, 1);
    ldem_push_vector(L, hi, dem_dim(s));
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "box");
    ldem_push_vector(L, g, dem_dim(s));
    lua_setfield(L, -2, "gravity");
    lua_pushinteger(L, dem_dim(s));
    lua_setfield(L, -2, "dim");
    lua_pushinteger(L, (lua_Integer)dem_count(s));
    lua_setfield(L, -2, "count");
    if (dem_dim(s) == 2) {
        lua_pushnumber(L, dem_thickness(s));
        lua_setfield(L, -2, "thickness");
    }
    lua_pushnumber(L, dem_time(s));
    lua_setfield(L, -2, "time");
    lua_pushinteger(L, dem_steps_done(s));
    lua_setfield(L, -2, "steps");
    lua_pushinteger(L, dem_force_evaluations(s));
    lua_setfield(L, -2, "force_evaluations");
    const dem_contact_def *c = dem_contact(s);
    lua_pushstring(L, dem_normal_names[c->normal]);
    lua_setfield(L, -2, "normal");
    lua_pushstring(L, dem_damping_names[c->damping]);
    lua_setfield(L, -2, "damping");
    lua_pushstring(L, dem_tangent_names[c->tangential]);
    lua_setfield(L, -2, "tangential");
    lua_pushstring(L, dem_rolling_names[c->rolling_law]);
    lua_setfield(L, -2, "rolling_resistance");
    lua_pushstring(L, dem_cohesion_names[c->cohesion]);
    lua_setfield(L, -2, "cohesion");
    lua_pushnumber(L, c->damping_time);
    lua_setfield(L, -2, "damping_time");
    dem_domain_stats ds;
    dem_domain_stats_get(s, &ds);
    if (ds.ranks > 1) { /* after a run on more than one rank */
        lua_createtable(L, 0, 11);
        const char *names[7] = {"ranks",     "rebuilds",  "rebalances", "migrations",
                                "owned_min", "owned_max", "halos"};
        long vals[7] = {ds.ranks,     ds.rebuilds,  ds.rebalances, ds.migrations,
                        ds.owned_min, ds.owned_max, ds.halos};
        for (int k = 0; k < 7; k++) {
            lua_pushinteger(L, vals[k]);
            lua_setfield(L, -2, names[k]);
        }
        const char *tn[7] = {"halo_bytes", "halo_messages", "rebuild_bytes", "rebuild_messages",
                             "rebuild_s",  "rebalance_s",   "comm_s"};
        double tv[7] = {ds.halo_bytes, ds.halo_messages, ds.rebuild_bytes, ds.rebuild_messages,
                        ds.rebuild_s,  ds.rebalance_s,   ds.comm_s};
        for (int k = 0; k < 7; k++) {
            lua_pushnumber(L, tv[k]);
            lua_setfield(L, -2, tn[k]);
        }
        lua_setfield(L, -2, "distributed");
    }
    return 1;
}

static int l_gc(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    bind_refuse_running(L, 1, "close", "it can be closed once its run has returned");
    dem_destroy(u->s);
    u->s = NULL;
    return 0;
}

static int l_tostring(lua_State *L)
{
    lscene *u = luaL_checkudata(L, 1, SCENE);
    if (!u->s)
        lua_pushliteral(L, "dem.scene (closed)");
    else
        lua_pushfstring(L, "dem.scene (%dD, %d particles, t = %f s)", dem_dim(u->s),
                        (int)dem_count(u->s), dem_time(u->s));
    return 1;
}

void bind_open_dem(lua_State *L)
{
    static const bind_fn methods[] = {
        {"add_disk", l_add_disk,
         "s:add_disk{ pos = {x, y}, radius = r, material = m, vel = {vx, vy}, omega = w, "
         "fixed = false, prescribed = false }",
         "Adds a disk to a 2D scene; returns its id. fixed: never moves; prescribed: moves at "
         "vel whatever the forces. material: a grainlab.material (default quartz)."},
        {"add_sphere", l_add_sphere,
         "s:add_sphere{ pos = {x, y, z}, radius = r, material = m, vel = {...}, omega = {...} }",
         "Adds a sphere to a 3D scene; returns its id."},
        {"set_velocity", l_set_velocity, "s:set_velocity(id, {vx, vy})",
         "Sets a particle's velocity."},
        {"particles", l_particles, "s:particles()",
         "Arrays x, y (z), vx, vy (vz), omega (2D) or wx, wy, wz (3D), angle (2D: the integrated "
         "rotation in rad), radius and mass; fx, fy (fz): the total force (N) of the last force "
         "evaluation (zero before any run); count; tag (with inserters or outflows, or the ids "
         "of a LAMMPS data file with gaps): a number each particle keeps while ids shift on "
         "removals, and the id VTK and LAMMPS files give it."},
        {"info", l_info, "s:info()",
         "dim, box, gravity, count, thickness (2D; 0: sphere masses), time, steps, "
         "force_evaluations, the laws."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_gc}, {"__close", l_gc}, {"__tostring", l_tostring}, {NULL, NULL}};
    bind_new_type(L, SCENE, methods, meta, "A DEM scene from dem.scene{...}.");
    static const bind_fields method_fields[] = {{"add_disk", NULL, PARTICLE_FIELDS},
                                                {"add_sphere", NULL, PARTICLE_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, SCENE, method_fields);
    ldem_open_contact(L);
    ldem_open_walls(L);
    ldem_open_run(L);
    ldem_open_measure(L);
    static const bind_fn fns[] = {
        {"scene", l_scene,
         "dem.scene{ dim = 2, box = {{x0, y0}, {x1, y1}}, gravity = {0, -9.81}, periodic = "
         "{false, false}, thickness = 0, skin = 0 }",
         "A new DEM scene. 2D particles are spheres moving in the plane unless thickness > 0 "
         "makes them cylinders (m = rho pi r^2 t, I = m r^2/2). skin: Verlet-list skin (0: 0.2 "
         "of the largest radius)."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"scene", NULL, SCENE_FIELDS}, {NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    bind_doc(L, -1, "dem", "dem",
             "Discrete elements: soft disks and spheres with contact laws, walls, integrators.");
    lua_setglobal(L, "dem");
    ldem_open_clump(L);
}
