/* The Lua module `dem`: scenes of disks (2D) or spheres (3D) over src/dem. Translates and checks
 * arguments, calls the kernels, raises their errors named after the call. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"

static const char *SCENE = "dem.scene";

typedef struct lscene {
    dem_scene *s;
} lscene;

/* The scene as its run left it: decomposed over the ranks after a distributed run (s:run only). */
static dem_scene *check_scene_local(lua_State *L, int idx)
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

static dem_scene *check_scene(lua_State *L, int idx)
{
    return replicated(L, check_scene_local(L, idx), "scene");
}

struct dem_scene *bind_check_dem_scene(lua_State *L, int idx, const char *call)
{
    lscene *u = bind_check_udata(L, idx, SCENE, call);
    if (!u->s)
        luaL_error(L, "%s: the dem.scene was closed", call);
    return replicated(L, u->s, call);
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
static int material_index(lua_State *L, int scene, int arg, const char *call, const char *field,
                          int absent)
{
    dem_scene *s = check_scene(L, scene);
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
        lua_pop(L, 6);
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
static void default_material_notice(lua_State *L, dem_scene *s, int scene, int arg,
                                    const char *call)
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
            bind_entry_name(L, entry, sizeof entry) ? entry : call, q.young / 1e9, q.density,
            cost);
    fflush(stderr);
}

/* ---- s:contact{...} ------------------------------------------------------------------------ */
/* The laws' names: dem_normal_names and its kin, from laws.h's lists. */

static const char *const CONTACT_FIELDS[] = {"normal",
                                             "stiffness",
                                             "beta",
                                             "damping",
                                             "gamma_n",
                                             "damping_time",
                                             "restitution",
                                             "impact_velocity",
                                             "tangential",
                                             "gamma_t",
                                             "kt",
                                             "v_r",
                                             "exponent",
                                             "clip",
                                             "rolling",
                                             "rolling_resistance",
                                             "rolling_friction",
                                             "rolling_stiffness",
                                             "rolling_damping",
                                             "rolling_rate",
                                             NULL};

/* The normal laws whose k is s:contact's stiffness (moduli 0), or comes from the materials
 * (moduli 1), as "'linear' or 'power'" (quoted) or "hertz" (plain). */
static void normal_names_by_k(int moduli, int quoted, char *buf, size_t size)
{
    int count = 0;
    for (int i = 0; dem_normal_names[i]; i++)
        count += dem_normal_from_moduli((dem_normal_law)i) == moduli;
    buf[0] = 0;
    for (int i = 0, k = 0; dem_normal_names[i]; i++) {
        if (dem_normal_from_moduli((dem_normal_law)i) != moduli)
            continue;
        const char *parts[4] = {k == 0 ? "" : k == count - 1 ? " or " : ", ", quoted ? "'" : "",
                                dem_normal_names[i], quoted ? "'" : ""};
        for (int p = 0; p < 4; p++)
            strncat(buf, parts[p], size - 1 - strlen(buf));
        k++;
    }
}

/* A field given although the chosen law ignores it is refused: a typo'd law must not leave the
 * user believing a value took effect. `why` names the field and value that give it meaning. */
static void only_with(lua_State *L, const char *field, int meaningful, const char *why)
{
    if (!meaningful && lua_getfield(L, 2, field) != LUA_TNIL) {
        char expected[320];
        snprintf(expected, sizeof expected, "nothing unless %s", why);
        bind_field_error(L, 2, "contact", field, expected);
    }
    lua_settop(L, 2);
}

static int l_contact(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    bind_refuse_running(L, 1, "contact",
                        "the contact law cannot change under the time step its "
                        "run was checked at: change it between runs");
    bind_check_table(L, 2, "contact");
    bind_check_fields(L, 2, "contact", CONTACT_FIELDS);
    dem_contact_def c = dem_default_contact_def();
    c.normal = (dem_normal_law)bind_field_option(L, 2, "contact", "normal", dem_normal_names,
                                                 DEM_NORMAL_HERTZ, 0);
    c.damping = (dem_damping_law)bind_field_option(L, 2, "contact", "damping", dem_damping_names,
                                                   DEM_DAMPING_NONE, 0);
    c.tangential = (dem_tangential_law)bind_field_option(L, 2, "contact", "tangential",
                                                         dem_tangent_names, DEM_TANGENT_NONE, 0);
    lua_settop(L, 2);
    if (c.damping == DEM_DAMPING_BRILLIANTOV && c.normal != DEM_NORMAL_HERTZ) {
        lua_getfield(L, 2, "damping");
        return bind_field_error(L, 2, "contact", "damping",
                                "'none' or 'viscous' with the linear and power laws (brilliantov "
                                "damping needs normal = 'hertz'; viscous damping honours a "
                                "restitution with every law)");
    }
    char given[96], moduli[96], why[256];
    normal_names_by_k(0, 1, given, sizeof given);
    normal_names_by_k(1, 0, moduli, sizeof moduli);
    snprintf(why, sizeof why, "'normal' is %s (%s takes the materials' moduli)", given, moduli);
    only_with(L, "stiffness", !dem_normal_from_moduli(c.normal), why);
    only_with(L, "beta", c.normal == DEM_NORMAL_POWER, "'normal' is 'power'");
    only_with(L, "gamma_n", c.damping == DEM_DAMPING_VISCOUS, "'damping' is 'viscous'");
    only_with(L, "damping_time", c.damping == DEM_DAMPING_BRILLIANTOV,
              "'damping' is 'brilliantov'");
    only_with(L, "gamma_t", c.tangential == DEM_TANGENT_VISCOUS, "'tangential' is 'viscous'");
    only_with(L, "kt", c.tangential == DEM_TANGENT_SPRING, "'tangential' is 'spring'");
    only_with(L, "v_r", c.tangential == DEM_TANGENT_REGULARIZED,
              "'tangential' is 'coulomb_regularized'");
    only_with(L, "exponent", c.tangential == DEM_TANGENT_REGULARIZED,
              "'tangential' is 'coulomb_regularized'");
    unsigned need_k = dem_normal_from_moduli(c.normal) ? 0 : BIND_REQUIRED;
    c.stiffness = bind_field_number(L, 2, "contact", "stiffness", 0, BIND_POSITIVE | need_k);
    c.beta = bind_field_number(L, 2, "contact", "beta", c.normal == DEM_NORMAL_LINEAR ? 1 : 1.5,
                               BIND_POSITIVE);
    /* Absent optional values are -1 ("not given"); given ones must be in range. */
    c.gamma_n = bind_field_number(L, 2, "contact", "gamma_n", -1, 0);
    if (c.gamma_n < 0 && lua_getfield(L, 2, "gamma_n") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "gamma_n", "non-negative number");
    c.damping_time = bind_field_number(L, 2, "contact", "damping_time", -1, 0);
    if (c.damping_time < 0 && lua_getfield(L, 2, "damping_time") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "damping_time", "non-negative number");
    double e = bind_field_number(L, 2, "contact", "restitution", -1, 0);
    if (c.damping_time >= 0 && lua_getfield(L, 2, "restitution") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "restitution",
                                "nothing when 'damping_time' is given: give damping_time (one T "
                                "for every pair) or restitution (a T per pair), not both");
    lua_settop(L, 2);
    if (c.gamma_n >= 0 && lua_getfield(L, 2, "restitution") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "restitution",
                                "nothing when 'gamma_n' is given: give gamma_n (one coefficient "
                                "for every pair) or restitution (one per pair), not both");
    lua_settop(L, 2);
    if (e >= 0 || lua_getfield(L, 2, "restitution") != LUA_TNIL) {
        lua_getfield(L, 2, "restitution");
        if (!(e > 0 && e <= 1))
            return bind_field_error(L, 2, "contact", "restitution", "number in (0, 1]");
        if (c.damping == DEM_DAMPING_NONE && e < 1)
            return bind_field_error(L, 2, "contact", "restitution",
                                    c.normal == DEM_NORMAL_HERTZ
                                        ? "1 when 'damping' is 'none' (for a rebound below 1 "
                                          "give damping = 'viscous' or 'brilliantov')"
                                        : "1 when 'damping' is 'none' (for a rebound below 1 "
                                          "give damping = 'viscous')");
        lua_pop(L, 1);
    }
    /* The speed at which a restitution holds: meaningful when the damping comes from one (the
     * contact's or the materials') and e depends on speed, i.e. all but the linear spring with
     * viscous damping. */
    const char *no_speed =
        c.damping == DEM_DAMPING_NONE ? "nothing unless 'damping' is 'viscous' or 'brilliantov' "
                                        "(the speed at which a restitution holds)"
        : c.gamma_n >= 0      ? "nothing when 'gamma_n' is given (the speed at which a "
                                "restitution holds)"
        : c.damping_time >= 0 ? "nothing when 'damping_time' is given (the speed at which a "
                                "restitution holds)"
        : c.damping == DEM_DAMPING_VISCOUS && c.beta == 1
            ? "nothing with viscous damping of a linear spring (beta = 1): its restitution holds "
              "at every speed"
            : NULL;
    if (no_speed && lua_getfield(L, 2, "impact_velocity") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "impact_velocity", no_speed);
    lua_settop(L, 2);
    double v_imp = bind_field_number(L, 2, "contact", "impact_velocity", 1, BIND_POSITIVE);
    lua_settop(L, 2);
    c.gamma_t = bind_field_number(L, 2, "contact", "gamma_t", 0, BIND_NONNEG);
    c.kt = bind_field_number(L, 2, "contact", "kt", -1, 0);
    if (c.kt <= 0 && lua_getfield(L, 2, "kt") != LUA_TNIL)
        return bind_field_error(L, 2, "contact", "kt", "positive number");
    c.v_r = bind_field_number(L, 2, "contact", "v_r", c.v_r, BIND_POSITIVE);
    c.exponent = bind_field_number(L, 2, "contact", "exponent", c.exponent, BIND_POSITIVE);
    c.clip = bind_field_boolean(L, 2, "contact", "clip", 1);
    c.rolling = bind_field_boolean(L, 2, "contact", "rolling", 0);
    /* Rolling resistance (dem.h, rolling.inc) */
    c.rolling_law = (dem_rolling_law)bind_field_option(L, 2, "contact", "rolling_resistance",
                                                       dem_rolling_names, DEM_ROLLING_NONE, 0);
    lua_settop(L, 2);
    const int roll = c.rolling_law != DEM_ROLLING_NONE;
    only_with(L, "rolling_friction", roll, "'rolling_resistance' is 'epsd' or 'constant'");
    only_with(L, "rolling_stiffness", c.rolling_law == DEM_ROLLING_EPSD,
              "'rolling_resistance' is 'epsd'");
    only_with(L, "rolling_damping", c.rolling_law == DEM_ROLLING_EPSD,
              "'rolling_resistance' is 'epsd'");
    only_with(L, "rolling_rate", c.rolling_law == DEM_ROLLING_CONSTANT,
              "'rolling_resistance' is 'constant'");
    /* absent: -1, the materials' mu_r and k_t R_eff^2 (dem.h) */
    c.rolling_friction = bind_field_number(L, 2, "contact", "rolling_friction", -1, BIND_NONNEG);
    c.rolling_stiffness =
        bind_field_number(L, 2, "contact", "rolling_stiffness", -1, BIND_POSITIVE);
    c.rolling_damping = bind_field_number(L, 2, "contact", "rolling_damping", 0, BIND_NONNEG);
    if (c.rolling_damping > 1) {
        lua_getfield(L, 2, "rolling_damping");
        return bind_field_error(L, 2, "contact", "rolling_damping", "number in [0, 1]");
    }
    c.rolling_rate = bind_field_number(L, 2, "contact", "rolling_rate", 0, BIND_POSITIVE);
    /* From a restitution (this one, else the materials') each pair gets its own damping when
     * the pair list is built: nothing depends on the particles present now. */
    c.restitution = e;
    c.impact_velocity = v_imp;
    core_error err;
    if (dem_set_contact(s, &c, &err) != CORE_OK)
        return bind_raise(L, "contact", &err);
    if (c.damping == DEM_DAMPING_BRILLIANTOV && c.damping_time >= 0) {
        lua_pushnumber(L, c.damping_time);
        return 1;
    }
    return 0;
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
    dem_scene *s = check_scene(L, 1);
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
    p.material = material_index(L, 1, 2, call, "material", 0);
    refuse_smaller_during_run(L, s, call, &p);
    core_error err;
    long i = dem_add_particle(s, &p, &err);
    if (i < 0)
        return bind_raise(L, call, &err);
    default_material_notice(L, s, 1, 2, call);
    lua_pushinteger(L, i + 1);
    return 1;
}

static int l_add_disk(lua_State *L) { return add_particle(L, "add_disk", 2); }
static int l_add_sphere(lua_State *L) { return add_particle(L, "add_sphere", 3); }

static size_t particle_arg(lua_State *L, dem_scene *s, int arg, const char *call)
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

/* s:damping_time(i, j) or s:damping_time(i, { wall = w }): the pair's Brilliantov T as the force
 * loop uses it (per pair when solved from a restitution). */
static const char *const DAMPING_TIME_FIELDS[] = {"wall", NULL};

static int l_damping_time(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    size_t i = particle_arg(L, s, 2, "damping_time"), j = 0;
    int wall = -1;
    if (lua_istable(L, 3)) {
        bind_check_fields(L, 3, "damping_time", DAMPING_TIME_FIELDS);
        wall = (int)bind_field_integer(L, 3, "damping_time", "wall", 0, 1, INT_MAX, BIND_REQUIRED) -
               1; /* 1.5 is no wall id */
    } else
        j = particle_arg(L, s, 3, "damping_time");
    if (dem_contact(s)->damping != DEM_DAMPING_BRILLIANTOV)
        return luaL_error(L, "damping_time: the contact law has no brilliantov damping");
    core_error err;
    double T;
    if (dem_pair_damping(s, i, j, wall, &T, &err) != CORE_OK)
        return bind_raise(L, "damping_time", &err);
    lua_pushnumber(L, T);
    return 1;
}

static int l_set_velocity(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    size_t i = particle_arg(L, s, 2, "set_velocity");
    double v[3] = {0, 0, 0};
    bind_arg_vector(L, 3, "set_velocity", dem_dim(s), v);
    core_error err;
    if (dem_set_velocity(s, i, v, &err))
        return bind_raise(L, "set_velocity", &err);
    return 0;
}

/* ---- walls ---------------------------------------------------------------------------------- */
static const char *const WALL_FIELDS[] = {"point",    "normal",   "velocity",
                                          "friction", "material", NULL};

static int l_add_wall(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    const int D = dem_dim(s);
    bind_check_table(L, 2, "add_wall");
    bind_check_fields(L, 2, "add_wall", WALL_FIELDS);
    dem_wall_def w;
    memset(&w, 0, sizeof w);
    bind_field_vector(L, 2, "add_wall", "point", D, w.point, BIND_REQUIRED);
    bind_field_vector(L, 2, "add_wall", "normal", D, w.normal, BIND_REQUIRED);
    bind_field_vector(L, 2, "add_wall", "velocity", D, w.velocity, 0);
    w.friction = bind_field_number(L, 2, "add_wall", "friction", -1, 0);
    if (w.friction < 0 && lua_getfield(L, 2, "friction") != LUA_TNIL)
        return bind_field_error(L, 2, "add_wall", "friction", "non-negative number");
    w.material = material_index(L, 1, 2, "add_wall", "material", -1);
    core_error err;
    int id = dem_add_wall(s, &w, &err);
    if (id < 0)
        return bind_raise(L, "add_wall", &err);
    lua_pushinteger(L, id + 1);
    return 1;
}

/* A wall id: a positive integer (the kernel says whether that wall exists). */
static int wall_arg(lua_State *L, int arg, const char *call)
{
    return (int)(bind_arg_integer(L, arg, call, 1, INT_MAX) - 1);
}

static int l_remove_wall(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    core_error err;
    if (dem_remove_wall(s, wall_arg(L, 2, "remove_wall"), &err))
        return bind_raise(L, "remove_wall", &err);
    return 0;
}

static int l_wall_velocity(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1); /* walls and dt: the same on every rank */
    double v[3] = {0, 0, 0};
    const int id = wall_arg(L, 2, "wall_velocity");
    bind_arg_vector(L, 3, "wall_velocity", dem_dim(s), v);
    core_error err;
    if (dem_set_wall_velocity(s, id, v, &err))
        return bind_raise(L, "wall_velocity", &err);
    return 0;
}

static int l_wall_force(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1); /* walls and dt: the same on every rank */
    core_error serr;
    if (dem_sync_walls(s, &serr) != CORE_OK)
        return bind_raise(L, "wall_force", &serr);
    double fn;
    core_error err;
    if (dem_wall_force(s, wall_arg(L, 2, "wall_force"), &fn, &err))
        return bind_raise(L, "wall_force", &err);
    lua_pushnumber(L, fn);
    return 1;
}

static const char *const SERVO_FIELDS[] = {"force", "mass", "rate", NULL};

static int l_wall_servo(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1); /* walls and dt: the same on every rank */
    const int id = wall_arg(L, 2, "wall_servo");
    double force = 0, mass = 0, rate = 0;
    if (!lua_isnoneornil(L, 3)) {
        bind_check_table(L, 3, "wall_servo");
        bind_check_fields(L, 3, "wall_servo", SERVO_FIELDS);
        force = bind_field_number(L, 3, "wall_servo", "force", 0, BIND_REQUIRED | BIND_NONNEG);
        mass = bind_field_number(L, 3, "wall_servo", "mass", 0, BIND_REQUIRED | BIND_POSITIVE);
        rate = bind_field_number(L, 3, "wall_servo", "rate", 0, BIND_NONNEG);
    }
    core_error err;
    if (dem_wall_servo(s, id, force, mass, rate, &err))
        return bind_raise(L, "wall_servo", &err);
    return 0;
}

static void push_vector(lua_State *L, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int d = 0; d < n; d++) {
        lua_pushnumber(L, v[d]);
        lua_rawseti(L, -2, d + 1);
    }
}

static int l_wall_point(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1); /* walls and dt: the same on every rank */
    double p[3];
    core_error err;
    if (dem_wall_point(s, wall_arg(L, 2, "wall_point"), p, &err))
        return bind_raise(L, "wall_point", &err);
    push_vector(L, p, dem_dim(s));
    return 1;
}

/* ---- walls beyond planes --------------------------------------------------------------------- */
/* The argument number the user sees (a method's self is not counted), as args.c says it. */
static int shown_arg(lua_State *L, int arg)
{
    lua_Debug ar;
    if (lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.namewhat &&
        strcmp(ar.namewhat, "method") == 0)
        return arg - 1;
    return arg;
}

/* A field holding an array of arrays of `per` finite numbers (points, motion rows), or for
 * triangles (nest = 3) an array of arrays of 3 such arrays. Returns the number of outer entries;
 * the numbers go into a userdata buffer left on the stack (freed by the GC, also on error).
 * Absent: 0 and nothing pushed, or an error with `required`. */
static size_t read_rows(lua_State *L, int arg, const char *call, const char *field, int per,
                        int nest, int required, double **out)
{
    char expected[96];
    if (nest > 1)
        snprintf(expected, sizeof expected, "array of triangles (3 arrays of %d finite numbers)",
                 per);
    else
        snprintf(expected, sizeof expected, "array of arrays of %d finite numbers", per);
    int t = lua_getfield(L, arg, field);
    if (t == LUA_TNIL && !required) {
        lua_pop(L, 1);
        return 0;
    }
    if (t != LUA_TTABLE || luaL_len(L, -1) < 1)
        return (size_t)bind_field_error(L, arg, call, field, expected);
    const lua_Integer n = luaL_len(L, -1);
    if (n > (1 << 22))
        return (size_t)bind_field_error(L, arg, call, field, "at most 4194304 entries");
    const int vals = per * nest;
    double *buf = lua_newuserdatauv(L, (size_t)n * (size_t)vals * sizeof *buf, 0);
    lua_insert(L, -2); /* buffer below the table */
    for (lua_Integer k = 1; k <= n; k++) {
        lua_rawgeti(L, -1, k);
        for (int m = 0; m < nest; m++) {
            if (nest > 1) {
                if (lua_type(L, -1) != LUA_TTABLE || luaL_len(L, -1) != nest)
                    goto bad;
                lua_rawgeti(L, -1, m + 1);
            }
            if (lua_type(L, -1) != LUA_TTABLE || luaL_len(L, -1) != per)
                goto bad;
            for (int d = 0; d < per; d++) {
                lua_rawgeti(L, -1, d + 1);
                int isnum;
                double v = lua_tonumberx(L, -1, &isnum);
                if (!isnum || lua_type(L, -1) != LUA_TNUMBER || !isfinite(v) || fabs(v) > 1e100)
                    goto bad;
                lua_pop(L, 1);
                buf[((size_t)(k - 1) * (size_t)nest + (size_t)m) * (size_t)per + (size_t)d] = v;
            }
            if (nest > 1)
                lua_pop(L, 1);
        }
        lua_pop(L, 1);
        continue;
    bad : {
        char got[64];
        bind_describe(L, -1, got, sizeof got);
        return (size_t)luaL_error(L,
                                  "bad field '%s' in argument #%d to '%s' (%s expected, got %s "
                                  "in entry %d)",
                                  field, shown_arg(L, arg), call, expected, got, (int)k);
    }
    }
    lua_pop(L, 1); /* the table; the buffer stays */
    *out = buf;
    return (size_t)n;
}

/* The motion fields shared by the shaped walls: velocity, omega (2D: a number), and motion: a
 * table of rows {t, velocity..., omega...} or a function(t) -> velocity, omega tabulated by this
 * call from the scene's time every motion_step until motion_until (never called in a step). */
static int read_motion(lua_State *L, int arg, const char *call, dem_scene *s, dem_shape_def *def)
{
    const int D = dem_dim(s), nw = D == 2 ? 1 : 3, per = 1 + D + nw;
    bind_field_vector(L, arg, call, "velocity", D, def->velocity, 0);
    if (D == 2)
        def->omega[2] = bind_field_number(L, arg, call, "omega", 0, 0);
    else
        bind_field_vector(L, arg, call, "omega", 3, def->omega, 0);
    const int t = lua_getfield(L, arg, "motion");
    lua_pop(L, 1);
    const int has_step = lua_getfield(L, arg, "motion_step") != LUA_TNIL;
    lua_pop(L, 1);
    const int has_until = lua_getfield(L, arg, "motion_until") != LUA_TNIL;
    lua_pop(L, 1);
    /* the messages of a mismatch name both fields: either may be the mistake */
    if (t != LUA_TFUNCTION && (has_step || has_until)) {
        lua_getfield(L, arg, has_step ? "motion_step" : "motion_until");
        return bind_field_error(L, arg, call, has_step ? "motion_step" : "motion_until",
                                "nil ('motion' is not a function)");
    }
    if (t == LUA_TFUNCTION && !(has_step && has_until)) {
        lua_getfield(L, arg, has_step ? "motion_until" : "motion_step");
        return bind_field_error(L, arg, call, has_step ? "motion_until" : "motion_step",
                                "number (with a function as 'motion')");
    }
    double *rows = NULL;
    size_t n = 0;
    if (t == LUA_TFUNCTION) {
        const double step =
            bind_field_number(L, arg, call, "motion_step", 0, BIND_REQUIRED | BIND_POSITIVE);
        const double until = bind_field_number(L, arg, call, "motion_until", 0, BIND_REQUIRED);
        const double t0 = dem_time(s);
        if (!(until > t0)) {
            lua_getfield(L, arg, "motion_until");
            return bind_field_error(L, arg, call, "motion_until", "time after the scene's time");
        }
        /* rows at t0 + k step while before `until`, then `until` itself */
        while (n < 1000000 && t0 + (double)n * step < until)
            n++;
        if (n == 1000000) {
            lua_getfield(L, arg, "motion_step");
            return bind_field_error(L, arg, call, "motion_step", "step giving at most 1e6 rows");
        }
        n++;
        rows = lua_newuserdatauv(L, n * 7 * sizeof *rows, 0);
        for (size_t k = 0; k < n; k++) {
            const double tk = k + 1 == n ? until : t0 + (double)k * step;
            lua_getfield(L, arg, "motion");
            lua_pushnumber(L, tk);
            lua_call(L, 1, 2); /* here, before any step: never inside one */
            double *r = rows + 7 * k;
            memset(r, 0, 7 * sizeof *r);
            r[0] = tk;
            int ok = lua_type(L, -2) == LUA_TTABLE && luaL_len(L, -2) == D;
            for (int d = 0; ok && d < D; d++) {
                lua_rawgeti(L, -2, d + 1);
                r[1 + d] = lua_tonumber(L, -1);
                ok = lua_type(L, -1) == LUA_TNUMBER && isfinite(r[1 + d]);
                lua_pop(L, 1);
            }
            if (ok && D == 2) {
                r[6] = lua_tonumber(L, -1);
                ok = (lua_type(L, -1) == LUA_TNUMBER && isfinite(r[6])) || lua_isnil(L, -1);
            } else if (ok && !lua_isnil(L, -1)) {
                ok = lua_type(L, -1) == LUA_TTABLE && luaL_len(L, -1) == 3;
                for (int d = 0; ok && d < 3; d++) {
                    lua_rawgeti(L, -1, d + 1);
                    r[4 + d] = lua_tonumber(L, -1);
                    ok = lua_type(L, -1) == LUA_TNUMBER && isfinite(r[4 + d]);
                    lua_pop(L, 1);
                }
            }
            lua_pop(L, 2);
            if (!ok) {
                char tb[64];
                snprintf(tb, sizeof tb, "%.17g", tk);
                return luaL_error(L,
                                  "bad field 'motion' in argument #%d to '%s' (function "
                                  "returning velocity {%d numbers}, omega (%s) expected "
                                  "at t = %s)",
                                  shown_arg(L, arg), call, D, D == 2 ? "a number" : "{3 numbers}",
                                  tb);
            }
        }
    } else if (t != LUA_TNIL) {
        double *raw = NULL;
        if (t != LUA_TTABLE) {
            lua_getfield(L, arg, "motion");
            return bind_field_error(L, arg, call, "motion",
                                    "table of rows {t, velocity, omega} or function");
        }
        n = read_rows(L, arg, call, "motion", per, 1, 1, &raw);
        rows = lua_newuserdatauv(L, n * 7 * sizeof *rows, 0);
        for (size_t k = 0; k < n; k++) {
            double *r = rows + 7 * k;
            memset(r, 0, 7 * sizeof *r);
            r[0] = raw[per * k];
            for (int d = 0; d < D; d++)
                r[1 + d] = raw[per * k + 1 + (size_t)d];
            for (int d = 0; d < nw; d++)
                r[(D == 2 ? 6 : 4) + d] = raw[per * k + 1 + (size_t)D + (size_t)d];
        }
    }
    /* a constant besides a (valid) motion: the constant is the mistake */
    const char *konst[2] = {"velocity", "omega"};
    for (int k = 0; k < 2 && t != LUA_TNIL; k++) {
        if (lua_getfield(L, arg, konst[k]) != LUA_TNIL)
            return bind_field_error(L, arg, call, konst[k], "nil (a motion is given)");
        lua_pop(L, 1);
    }
    def->nmotion = n;
    def->motion = rows; /* on the stack until the call returns */
    return 0;
}

/* The fields every shaped wall takes, after its own. */
#define SHAPE_COMMON_FIELDS                                                                        \
    "center", "velocity", "omega", "motion", "motion_step", "motion_until", "friction", "material"

/* The shaped-wall calls' common part: the centre, motion, friction and material, then the wall. */
static int shape_wall(lua_State *L, const char *call, dem_shape_def *def)
{
    dem_scene *s = check_scene(L, 1);
    const int D = dem_dim(s);
    if (!def->has_center)
        def->has_center = bind_field_vector(L, 2, call, "center", D, def->center, 0);
    read_motion(L, 2, call, s, def);
    def->friction = bind_field_number(L, 2, call, "friction", -1, 0);
    if (def->friction < 0 && lua_getfield(L, 2, "friction") != LUA_TNIL)
        return bind_field_error(L, 2, call, "friction", "non-negative number");
    def->material = material_index(L, 1, 2, call, "material", -1);
    core_error err;
    int id = dem_add_shape_wall(s, def, &err);
    if (id < 0)
        return bind_raise(L, call, &err);
    lua_pushinteger(L, id + 1);
    return 1;
}

static void check_shape_fields(lua_State *L, const char *call, const char *const fields[])
{
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, fields);
}

static const char *const POLYLINE_FIELDS[] = {"points", "closed", SHAPE_COMMON_FIELDS, NULL};

static int l_add_polyline(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    check_shape_fields(L, "add_polyline", POLYLINE_FIELDS);
    if (dem_dim(s) != 2)
        return luaL_error(L, "bad argument #1 to 'add_polyline' (2D scene expected, got a 3D "
                             "one: use add_mesh)");
    dem_shape_def def = dem_default_shape_def();
    def.kind = DEM_WALL_SEGMENTS;
    double *pts2 = NULL;
    size_t n = read_rows(L, 2, "add_polyline", "points", 2, 1, 1, &pts2);
    double *pts = lua_newuserdatauv(L, 3 * n * sizeof *pts, 0);
    for (size_t k = 0; k < n; k++)
        pts[3 * k] = pts2[2 * k], pts[3 * k + 1] = pts2[2 * k + 1], pts[3 * k + 2] = 0;
    def.n = n;
    def.points = pts;
    def.closed = bind_field_boolean(L, 2, "add_polyline", "closed", 0);
    return shape_wall(L, "add_polyline", &def);
}

static const char *const MESH_FIELDS[] = {"triangles", SHAPE_COMMON_FIELDS, NULL};

static int l_add_mesh(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    check_shape_fields(L, "add_mesh", MESH_FIELDS);
    if (dem_dim(s) != 3)
        return luaL_error(L, "bad argument #1 to 'add_mesh' (3D scene expected, got a 2D one: "
                             "use add_polyline)");
    dem_shape_def def = dem_default_shape_def();
    def.kind = DEM_WALL_TRIANGLES;
    double *pts = NULL;
    def.n = read_rows(L, 2, "add_mesh", "triangles", 3, 3, 1, &pts);
    def.points = pts;
    return shape_wall(L, "add_mesh", &def);
}

static const char *const CYLINDER_FIELDS[] = {
    "radius", "axis", "length", "inside", SHAPE_COMMON_FIELDS, NULL};

static int l_add_cylinder(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    const int D = dem_dim(s);
    check_shape_fields(L, "add_cylinder", CYLINDER_FIELDS);
    dem_shape_def def = dem_default_shape_def();
    def.kind = DEM_WALL_CYLINDER;
    bind_field_vector(L, 2, "add_cylinder", "center", D, def.center, BIND_REQUIRED);
    def.has_center = 1;
    def.radius =
        bind_field_number(L, 2, "add_cylinder", "radius", 0, BIND_REQUIRED | BIND_POSITIVE);
    if (D == 3) {
        bind_field_vector(L, 2, "add_cylinder", "axis", 3, def.axis, BIND_REQUIRED);
        def.length = bind_field_number(L, 2, "add_cylinder", "length", 0, BIND_NONNEG);
    } else {
        const char *f3[] = {"axis", "length"};
        for (int k = 0; k < 2; k++)
            if (lua_getfield(L, 2, f3[k]) != LUA_TNIL)
                return bind_field_error(L, 2, "add_cylinder", f3[k], "nil (a 2D circle)");
            else
                lua_pop(L, 1);
    }
    def.inside = bind_field_boolean(L, 2, "add_cylinder", "inside", 1);
    return shape_wall(L, "add_cylinder", &def);
}

/* s:wall_load(id) -> force on the wall {fx, fy[, fz]}, torque about its centre (2D: a number). */
static int l_wall_load(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1);
    core_error serr;
    if (dem_sync_walls(s, &serr) != CORE_OK)
        return bind_raise(L, "wall_load", &serr);
    double f[3], t[3];
    core_error err;
    if (dem_wall_load(s, wall_arg(L, 2, "wall_load"), f, t, &err))
        return bind_raise(L, "wall_load", &err);
    push_vector(L, f, dem_dim(s));
    if (dem_dim(s) == 2)
        lua_pushnumber(L, t[2]);
    else
        push_vector(L, t, 3);
    return 2;
}

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
    dem_scene *s = check_scene_local(L, 1); /* walls and dt: the same on every rank */
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

static int l_run(lua_State *L)
{
    dem_scene *s = check_scene_local(L, 1); /* a run continues a decomposed scene as it is */
    bind_refuse_running(L, 1, "run", "return false from on_step to stop it");
    bind_check_table(L, 2, "run");
    bind_check_fields(L, 2, "run", RUN_FIELDS);
    dem_run_def run = dem_default_run_def();
    run.integrator = (dem_integrator)bind_field_option(L, 2, "run", "integrator",
                                                       INTEGRATOR_NAMES, DEM_VELOCITY_VERLET, 0);
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
    if (lua_isnil(L, -1) || (lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "auto") == 0)) {
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
                     ts.limit < ts.contact_time / 10 ? ", or of the damping rate" : "",
                     ts.dt_auto);
            return luaL_error(L, "%s", msg);
        }
    }
    lua_pop(L, 1);
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
    bind_run r = {"dem run", steps, steps, dem_advance, &ctx, 1,
                  run.integrator == DEM_TWO_TIMESCALES ? run.tt_n * run.dt : run.dt, force};
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

/* ---- measurements --------------------------------------------------------------------------- */
typedef struct contact_lists {
    lua_State *L;
    int tables[8];
    lua_Integer n;
    int dim;
} contact_lists;

static void add_contact(const dem_contact_info *c, void *ctx)
{
    contact_lists *cl = ctx;
    lua_State *L = cl->L;
    cl->n++;
    double vals[8] = {(double)(c->i + 1), 0, c->fn, c->ft, c->normal[0], c->normal[1],
                      c->normal[2], c->overlap};
    for (int k = 0; k < 8; k++) {
        if (k == 6 && cl->dim == 2)
            continue;
        if (k == 0 || k == 1) {
            lua_Integer v = k == 0 ? c->i + 1 : (c->j >= 0 ? c->j + 1 : c->j);
            lua_pushinteger(L, v);
        } else {
            lua_pushnumber(L, vals[k]);
        }
        lua_rawseti(L, cl->tables[k], cl->n);
    }
}

static const char *const STRESS_FIELDS[] = {"volume", NULL};

static const char *const DISPLACEMENT_FIELDS[] = {"affine", "center", NULL};

/* The modes that take no options: a table given to them may hold no key. */
static const char *const NO_FIELDS[] = {NULL};

static int l_measure(lua_State *L)
{
    static const char *const what_names[] = {"energy", "stress", "coordination", "slip",
                                             "contacts", "displacement", NULL};
    static const char *const *const what_fields[] = {NO_FIELDS, STRESS_FIELDS, NO_FIELDS,
                                                     NO_FIELDS, NO_FIELDS, DISPLACEMENT_FIELDS};
    dem_scene *s = check_scene(L, 1);
    const int D = dem_dim(s);
    int what = bind_check_option(L, 2, NULL, what_names);
    int has_opts = bind_mode_options(L, 3, "measure", what_names[what], what_fields[what]);
    switch (what) {
    case 0: {
        dem_energy e;
        dem_measure_energy(s, &e);
        lua_createtable(L, 0, 5);
        const char *names[] = {"kinetic", "rotational", "elastic", "potential", "total"};
        double vals[] = {e.kinetic, e.rotational, e.elastic, e.potential, e.total};
        for (int k = 0; k < 5; k++) {
            lua_pushnumber(L, vals[k]);
            lua_setfield(L, -2, names[k]);
        }
        return 1;
    }
    case 1: {
        double volume = 0;
        if (has_opts)
            volume = bind_field_number(L, 3, "measure", "volume", 0, BIND_POSITIVE);
        double sig[3][3];
        long nc = dem_measure_stress(s, volume, sig);
        static const char *const comp[3][3] = {
            {"xx", "xy", "xz"}, {"yx", "yy", "yz"}, {"zx", "zy", "zz"}};
        lua_createtable(L, 0, 11);
        double tr = 0;
        for (int a = 0; a < D; a++) {
            tr += sig[a][a];
            for (int b = 0; b < D; b++) {
                lua_pushnumber(L, sig[a][b]);
                lua_setfield(L, -2, comp[a][b]);
            }
        }
        lua_pushnumber(L, tr / D);
        lua_setfield(L, -2, "pressure");
        lua_pushinteger(L, nc);
        lua_setfield(L, -2, "contacts");
        return 1;
    }
    case 2: {
        double z, zr;
        dem_measure_coordination(s, &z, &zr);
        lua_createtable(L, 0, 2);
        lua_pushnumber(L, z);
        lua_setfield(L, -2, "z");
        lua_pushnumber(L, zr);
        lua_setfield(L, -2, "z_no_rattlers");
        return 1;
    }
    case 3:
        lua_pushnumber(L, dem_measure_slip(s));
        return 1;
    case 4: {
        static const char *const names[8] = {"i", "j", "fn", "ft", "nx", "ny", "nz", "overlap"};
        contact_lists cl = {.L = L, .n = 0, .dim = D};
        lua_createtable(L, 0, 8);
        int result = lua_gettop(L);
        for (int k = 0; k < 8; k++) {
            if (k == 6 && D == 2) {
                cl.tables[k] = 0;
                continue;
            }
            lua_newtable(L);
            cl.tables[k] = lua_gettop(L);
        }
        dem_each_contact(s, add_contact, &cl);
        for (int k = 7; k >= 0; k--) {
            if (k == 6 && D == 2)
                continue;
            lua_setfield(L, result, names[k]);
        }
        lua_pushinteger(L, cl.n);
        lua_setfield(L, result, "count");
        return 1;
    }
    default: { /* displacement, optionally relative to an affine field */
        double grad[3][3] = {{0}}, center[3] = {0, 0, 0};
        int affine = 0;
        if (has_opts) {
            /* affine: D rows of D finite numbers, the shape checked before any row is
             * indexed (a number as a row used to crash lua_rawgeti). */
            if (lua_getfield(L, 3, "affine") != LUA_TNIL) {
                lua_Debug ar;
                int uarg = lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.namewhat &&
                                   strcmp(ar.namewhat, "method") == 0
                               ? 2
                               : 3;
                char got[128] = "", v[64];
                int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == (size_t)D;
                if (!ok && lua_type(L, -1) == LUA_TTABLE)
                    snprintf(got, sizeof got, "%d rows", (int)lua_rawlen(L, -1));
                else if (!ok)
                    bind_describe(L, -1, got, sizeof got);
                for (int a = 0; a < D && ok; a++) {
                    int rt = lua_rawgeti(L, -1, a + 1);
                    if (rt != LUA_TTABLE || lua_rawlen(L, -1) != (size_t)D) {
                        if (rt == LUA_TTABLE)
                            snprintf(got, sizeof got, "%d entries in row %d",
                                     (int)lua_rawlen(L, -1), a + 1);
                        else {
                            bind_describe(L, -1, v, sizeof v);
                            snprintf(got, sizeof got, "%s as row %d", v, a + 1);
                        }
                        ok = 0;
                    }
                    for (int b = 0; b < D && ok; b++) {
                        lua_rawgeti(L, -1, b + 1);
                        grad[a][b] = lua_tonumber(L, -1);
                        if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(grad[a][b]) ||
                            fabs(grad[a][b]) > 1e100) { /* the bindings' magnitude cap */
                            bind_describe(L, -1, v, sizeof v);
                            snprintf(got, sizeof got, "%s at row %d, column %d", v, a + 1, b + 1);
                            ok = 0;
                        }
                        lua_pop(L, 1);
                    }
                    lua_pop(L, 1);
                }
                if (!ok)
                    return luaL_error(L,
                                      "bad field 'affine' in argument #%d to 'measure' (%dx%d "
                                      "matrix of finite numbers (displacement gradient) "
                                      "expected, got %s)",
                                      uarg, D, D, got);
                affine = 1;
            }
            lua_pop(L, 1);
            bind_field_vector(L, 3, "measure", "center", D, center, 0);
        }
        size_t n = dem_count(s);
        double *out[3] = {NULL, NULL, NULL};
        for (int d = 0; d < D; d++) {
            out[d] = malloc((n ? n : 1) * sizeof(double));
            if (!out[d]) {
                for (int k = 0; k < d; k++)
                    free(out[k]);
                return luaL_error(L, "measure: out of memory");
            }
        }
        core_error err;
        core_status st = dem_measure_displacement(s, affine ? (const double(*)[3])grad : NULL,
                                                  center, out, &err);
        if (st == CORE_OK) {
            static const char *const names[3] = {"x", "y", "z"};
            lua_createtable(L, 0, D);
            for (int d = 0; d < D; d++) {
                lua_createtable(L, (int)n, 0);
                for (size_t i = 0; i < n; i++) {
                    lua_pushnumber(L, out[d][i]);
                    lua_rawseti(L, -2, (lua_Integer)i + 1);
                }
                lua_setfield(L, -2, names[d]);
            }
        }
        for (int d = 0; d < D; d++)
            free(out[d]);
        if (st != CORE_OK)
            return bind_raise(L, "measure", &err);
        return 1;
    }
    }
}


static int l_particles(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
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

static int l_set_reference(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    core_error err;
    if (dem_set_reference(s, &err))
        return bind_raise(L, "set_reference", &err);
    return 0;
}

static int l_scale_mass(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    const bind_run *r = bind_running(L, 1);
    if (r && !r->forced && luaL_checknumber(L, 2) < 1) /* lighter: shorter contact times */
        bind_refuse_running(L, 1, "scale_mass", "a factor below 1 shortens the stability limit "
                                                "the run's dt was checked at: scale between runs");
    core_error err;
    if (dem_scale_mass(s, bind_arg_number(L, 2, "scale_mass", BIND_POSITIVE), &err))
        return bind_raise(L, "scale_mass", &err);
    return 0;
}

static int l_scale_stiffness(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    const bind_run *r = bind_running(L, 1);
    if (r && !r->forced && luaL_checknumber(L, 2) > 1) /* stiffer: shorter contact times */
        bind_refuse_running(L, 1, "scale_stiffness", "a factor above 1 shortens the stability "
                                                     "limit the run's dt was checked at: scale "
                                                     "between runs");
    core_error err;
    if (dem_scale_stiffness(s, bind_arg_number(L, 2, "scale_stiffness", BIND_POSITIVE), &err))
        return bind_raise(L, "scale_stiffness", &err);
    return 0;
}

static int l_drag(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
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
    dem_scene *s = check_scene(L, 1);
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
    dem_scene *s = check_scene(L, 1);
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
    dem_clear_external_forces(check_scene(L, 1));
    return 0;
}

static const char *const QUASISTATIC_FIELDS[] = {"pressure", "strain_rate", NULL};

static int l_quasistatic(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    bind_check_table(L, 2, "quasistatic");
    bind_check_fields(L, 2, "quasistatic", QUASISTATIC_FIELDS);
    double p = bind_field_number(L, 2, "quasistatic", "pressure", 0, BIND_REQUIRED | BIND_POSITIVE);
    double rate = bind_field_number(L, 2, "quasistatic", "strain_rate", 0,
                                    BIND_REQUIRED | BIND_POSITIVE);
    double phi, psi;
    core_error err;
    if (dem_quasistatic(s, p, rate, &phi, &psi, &err))
        return bind_raise(L, "quasistatic", &err);
    if (phi > 0.01 && progress_default_style() != PROGRESS_QUIET)
        fprintf(stderr, "grainlab: warning: quasistatic coefficient phi = %.3g is not << 1: the "
                        "process is not macroscopically quasistatic (Padbidri Eq. 2.13); lower "
                        "the mass scaling or the strain rate\n", phi);
    lua_createtable(L, 0, 2);
    lua_pushnumber(L, phi);
    lua_setfield(L, -2, "phi");
    lua_pushnumber(L, psi);
    lua_setfield(L, -2, "psi");
    return 1;
}

static int l_info(lua_State *L)
{
    dem_scene *s = check_scene(L, 1);
    lua_createtable(L, 0, 6);
    double lo[3], hi[3], g[3];
    dem_box(s, lo, hi, g);
    lua_createtable(L, 2, 0);
    push_vector(L, lo, dem_dim(s));
    lua_rawseti(L, -2, 1);
    push_vector(L, hi, dem_dim(s));
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "box");
    push_vector(L, g, dem_dim(s));
    lua_setfield(L, -2, "gravity");
    lua_pushinteger(L, dem_dim(s));
    lua_setfield(L, -2, "dim");
    lua_pushinteger(L, (lua_Integer)dem_count(s));
    lua_setfield(L, -2, "count");
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
    dem_scene *s = check_scene(L, 1);
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
    d.material = material_index(L, 1, 2, call, "material", 0);
    core_error err;
    int id = dem_add_inserter(s, &d, &err);
    if (id < 0)
        return bind_raise(L, call, &err);
    default_material_notice(L, s, 1, 2, call);
    lua_pushinteger(L, id + 1);
    return 1;
}

static const char *const OUTFLOW_FIELDS[] = {"box", "side", NULL};
static const char *const SIDE_NAMES[] = {"x-", "x+", "y-", "y+", "z-", "z+", NULL};

static int l_outflow(lua_State *L)
{
    const char *call = "outflow";
    dem_scene *s = check_scene(L, 1);
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
    dem_scene *s = check_scene(L, 1);
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
        {"contact", l_contact,
         "s:contact{ normal = 'hertz'|'linear'|'power', stiffness =, beta =, damping = "
         "'none'|'viscous'|'brilliantov', gamma_n =, damping_time =, restitution =, "
         "impact_velocity =, tangential = 'none'|'viscous'|'spring'|'coulomb_regularized', "
         "gamma_t =, kt =, v_r =, exponent =, clip = true, rolling = false, rolling_resistance = "
         "'none'|'epsd'|'constant', rolling_friction =, rolling_stiffness =, rolling_damping = 0, "
         "rolling_rate = }",
         "Sets the contact law of the scene. Normal: linear f = k d (Herrmann Eq. 1a, beta = 1), "
         "power f = k d^beta (beta 1, 1.5 or 2), hertz f = 4/3 E* sqrt(R) d^1.5 (Padbidri Eq. "
         "1.1). Damping: viscous gamma_n d' (Eq. 1b), brilliantov T K d^0.5 d' (Eq. 2.16, hertz "
         "only). gamma_n or damping_time, when given, holds for every pair; otherwise each pair "
         "(walls too) gets its own from a restitution e, restitution = e here or else the smaller "
         "of the pair's two materials' restitution, so that a head-on impact at impact_velocity "
         "(default 1 m/s) rebounds with e whatever the radii, masses and materials: with "
         "d* = (m* v^2/k)^(1/(beta+1)), gamma = c(e) m* v/d* or T = lambda(e) (m*/K)^(2/5) "
         "v^(-1/5), K = 4/3 E* sqrt(R*). The linear spring with viscous damping holds e at every "
         "speed (no impact_velocity); elsewhere e moves with speed (viscous: lower when slower; "
         "brilliantov: higher when slower). damping = 'none' rebounds with 1 (restitution < 1 is "
         "refused). s:damping_time(i, j) gives a pair's T. Tangential: "
         "viscous -gamma_t s (Eq. 2a), spring (Cundall-Strack, Eq. 2b; kt defaults to 2/7 of "
         "the normal tangent stiffness), coulomb_regularized mu f_n min(1, (s/v_r)^(1/exponent)) "
         "(Eq. 2.18). clip = true forbids attractive normal forces; rolling = true allocates "
         "rotations without a tangential law. Rolling resistance (Ai et al. 2011; a torque "
         "against the relative rolling w_i - w_j, or w_i on a wall, at most mu_r R_eff |F_n|): "
         "epsd, type C, an elastic-plastic spring k_r (rolling_stiffness, N m/rad; default "
         "k_t R_eff^2) with a dashpot of damping ratio rolling_damping in [0, 1] below the "
         "limit; constant, type A, the limit torque against w, linear below rolling_rate w_c "
         "(rad/s; default: the rate that stops a contact's relative rotation in ten steps). "
         "mu_r: rolling_friction, or the smaller of the two materials' rolling_friction. Returns "
         "damping_time when one is given, else nothing."},
        {"add_disk", l_add_disk,
         "s:add_disk{ pos = {x, y}, radius = r, material = m, vel = {vx, vy}, omega = w, "
         "fixed = false, prescribed = false }",
         "Adds a disk to a 2D scene; returns its id. fixed: never moves; prescribed: moves at "
         "vel whatever the forces. material: a grainlab.material (default quartz)."},
        {"add_sphere", l_add_sphere,
         "s:add_sphere{ pos = {x, y, z}, radius = r, material = m, vel = {...}, omega = {...} }",
         "Adds a sphere to a 3D scene; returns its id."},
        {"add_wall", l_add_wall,
         "s:add_wall{ point = {...}, normal = {...}, velocity = {...}, friction = mu, material = m "
         "}",
         "Adds a planar wall (normal into the domain), optionally moving and with its own "
         "friction; returns the wall id."},
        {"add_polyline", l_add_polyline,
         "s:add_polyline{ points = {{x, y}, ...}, closed = false, center = {x, y}, velocity = "
         "{vx, vy}, omega = w, motion = rows or function, motion_step =, motion_until =, "
         "friction = mu, material = m }",
         "Adds a 2D wall made of segments joining the points (a single segment: two points; "
         "closed joins the last to the first). Contact at the closest point, end points "
         "included; a particle on a shared vertex feels one force. The wall moves as a rigid "
         "body: its centre (default the mean of the points) at velocity, turning at omega "
         "(rad/s) about it; or motion = {{t, vx, vy, w}, ...} piecewise linear in the scene "
         "time, or motion = function(t) return {vx, vy}, w end tabulated now every "
         "motion_step until motion_until (never called during a step). Returns the wall id."},
        {"add_mesh", l_add_mesh,
         "s:add_mesh{ triangles = {{{x,y,z}, {x,y,z}, {x,y,z}}, ...}, center =, velocity =, "
         "omega = {wx, wy, wz}, motion =, motion_step =, motion_until =, friction =, material = }",
         "Adds a 3D wall of triangles (a mesh: corners with equal coordinates are shared). "
         "Contact at the closest point, edges and corners included, one force per shared "
         "feature. Motion as add_polyline (rows {t, vx, vy, vz, wx, wy, wz}). Returns the wall "
         "id."},
        {"add_cylinder", l_add_cylinder,
         "s:add_cylinder{ center = {...}, radius = R, axis = {ax, ay, az}, length = 0, inside = "
         "true, velocity =, omega =, motion =, motion_step =, motion_until =, friction =, "
         "material = }",
         "Adds a circle (2D) or a cylinder (3D, along axis; length 0 = infinite, else open at "
         "its ends) with the particles inside (a drum) or outside (a post). It turns about its "
         "centre at omega: a rotating drum drags the particles by friction. Returns the wall "
         "id."},
        {"wall_load", l_wall_load, "s:wall_load(id)",
         "The force the particles exert on the wall ({fx, fy[, fz]}, N) and its torque about "
         "the wall's centre (2D: a number, N m) at the last force evaluation; for a plane the "
         "normal part only and no torque."},
        {"remove_wall", l_remove_wall, "s:remove_wall(id)", "Removes a wall during a run."},
        {"wall_velocity", l_wall_velocity, "s:wall_velocity(id, {vx, vy})",
         "Sets a wall's velocity."},
        {"wall_point", l_wall_point, "s:wall_point(id)", "The wall's reference point now."},
        {"wall_force", l_wall_force, "s:wall_force(id)",
         "Normal force (N) the wall exerted on the particles at the last force evaluation."},
        {"wall_servo", l_wall_servo,
         "s:wall_servo(id, { force =, mass =, rate = 0 }) or s:wall_servo(id)",
         "Force control: the wall moves along its normal as a body of this mass pushed with "
         "`force` "
         "against the contacts, velocity damped at `rate` (1/s); no table switches it off."},
        {"set_velocity", l_set_velocity, "s:set_velocity(id, {vx, vy})",
         "Sets a particle's velocity."},
        {"damping_time", l_damping_time, "s:damping_time(i, j) or s:damping_time(i, { wall = w })",
         "The Brilliantov damping time T (s) of particles i and j, or of particle i against wall "
         "w, "
         "as the force loop uses it (one T for all, or each pair's own when s:contact solved it "
         "from a restitution)."},
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
        {"measure", l_measure,
         "s:measure('energy'|'stress'|'coordination'|'slip'|'contacts'|'displacement', opts)",
         "energy: kinetic, rotational, elastic, potential, total (J). stress: assembly stress "
         "sum(branch x force)/V (opts.volume; compression positive) with pressure. "
         "coordination: z, z_no_rattlers. slip: mean |slip velocity| at contacts. contacts: "
         "arrays i, j (negative j: wall), fn, ft, nx, ny, (nz), overlap. displacement: since "
         "set_reference, minus opts.affine (displacement gradient) about opts.center."},
        {"particles", l_particles, "s:particles()",
         "Arrays x, y (z), vx, vy (vz), omega (2D) or wx, wy, wz (3D), angle (2D: the integrated "
         "rotation in rad), radius and mass; fx, fy (fz): the total force (N) of the last force "
         "evaluation (zero before any run); count; tag (with inserters or outflows, or the ids "
         "of a LAMMPS data file with gaps): a number each particle keeps while ids shift on "
         "removals, and the id VTK and LAMMPS files give it."},
        {"set_reference", l_set_reference, "s:set_reference()",
         "Remembers the current positions for displacement measurements."},
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
        {"info", l_info, "s:info()",
         "dim, box, gravity, count, time, steps, force_evaluations, the laws."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_gc}, {"__close", l_gc}, {"__tostring", l_tostring}, {NULL, NULL}};
    bind_new_type(L, SCENE, methods, meta, "A DEM scene from dem.scene{...}.");
    static const bind_fields method_fields[] = {{"contact", NULL, CONTACT_FIELDS},
                                                {"add_disk", NULL, PARTICLE_FIELDS},
                                                {"add_sphere", NULL, PARTICLE_FIELDS},
                                                {"add_wall", NULL, WALL_FIELDS},
                                                {"add_polyline", NULL, POLYLINE_FIELDS},
                                                {"add_mesh", NULL, MESH_FIELDS},
                                                {"add_cylinder", NULL, CYLINDER_FIELDS},
                                                {"wall_servo", NULL, SERVO_FIELDS},
                                                {"timestep", NULL, TIMESTEP_FIELDS},
                                                {"run", NULL, RUN_FIELDS},
                                                {"measure", "energy", NO_FIELDS},
                                                {"measure", "stress", STRESS_FIELDS},
                                                {"measure", "coordination", NO_FIELDS},
                                                {"measure", "slip", NO_FIELDS},
                                                {"measure", "contacts", NO_FIELDS},
                                                {"measure", "displacement", DISPLACEMENT_FIELDS},
                                                {"set_forces", NULL, FORCES_FIELDS},
                                                {"quasistatic", NULL, QUASISTATIC_FIELDS},
                                                {"damping_time", NULL, DAMPING_TIME_FIELDS},
                                                {"inserter", NULL, INSERTER_FIELDS},
                                                {"outflow", NULL, OUTFLOW_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, SCENE, method_fields);
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
}
