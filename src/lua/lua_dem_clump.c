/* The dem bindings of clumps: dem.clump_template{...} and its info, s:add_clump{...},
 * s:clump(id) and s:clump_count(). The members, the mass properties and the motion are
 * src/dem/clump.c's and clump_shape.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

static const char *TEMPLATE = "dem.clump_template";

typedef struct ltemplate {
    int dim, n, resolution; /* resolution 0: dem_clump_shape_compute's default */
    dem_clump_member m[DEM_CLUMP_MAX_MEMBERS];
    int have[2];              /* shapes computed: [0] spheres, [1] planar disks */
    dem_clump_shape shape[2];
} ltemplate;

static const char *const MEMBER_FIELDS[] = {"offset", "radius", NULL};

/* Members from the array t.members (argument arg); the dimension from the first offset, or
 * `dim` when > 0. */
static int read_members(lua_State *L, int arg, const char *call, int dim, dem_clump_member *m)
{
    if (lua_getfield(L, arg, "members") != LUA_TTABLE)
        bind_field_error(L, arg, call, "members", "non-empty array of {offset = {...}, radius}");
    const int tab = lua_gettop(L);
    lua_Integer n = luaL_len(L, tab);
    if (n < 1 || n > DEM_CLUMP_MAX_MEMBERS) {
        char what[96];
        snprintf(what, sizeof what, "array of 1 to %d members", DEM_CLUMP_MAX_MEMBERS);
        bind_field_error(L, arg, call, "members", what);
    }
    char name[64];
    for (lua_Integer k = 1; k <= n; k++) {
        snprintf(name, sizeof name, "members[%d]", (int)k);
        if (lua_rawgeti(L, tab, k) != LUA_TTABLE)
            bind_field_error(L, arg, call, name, "table {offset = {...}, radius = r}");
        const int mt = lua_gettop(L);
        bind_check_nested_fields(L, mt, arg, call, name, MEMBER_FIELDS);
        dem_clump_member *q = &m[k - 1];
        memset(q, 0, sizeof *q);
        snprintf(name, sizeof name, "members[%d].offset", (int)k);
        lua_getfield(L, mt, "offset");
        int len = lua_type(L, -1) == LUA_TTABLE ? (int)luaL_len(L, -1) : 0;
        if (dim == 0 && (len == 2 || len == 3))
            dim = len;
        if (len != dim) {
            char what[64];
            snprintf(what, sizeof what, "%s of %d numbers", dim ? "array" : "array (2D or 3D)",
                     dim ? dim : 2);
            bind_field_error(L, arg, call, name, what);
        }
        for (int d = 0; d < dim; d++) {
            lua_rawgeti(L, -1, d + 1);
            int ok;
            q->offset[d] = lua_tonumberx(L, -1, &ok);
            if (!ok || !isfinite(q->offset[d])) {
                lua_pop(L, 1);
                bind_field_error(L, arg, call, name, "array of finite numbers");
            }
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
        snprintf(name, sizeof name, "members[%d].radius", (int)k);
        lua_getfield(L, mt, "radius");
        int ok;
        q->radius = lua_tonumberx(L, -1, &ok);
        if (!ok || !(q->radius > 0) || !isfinite(q->radius))
            bind_field_error(L, arg, call, name, "positive number");
        lua_pop(L, 2);
    }
    lua_pop(L, 1);
    return (int)n * 4 + dim - 2; /* packed: n and the dimension (2D offsets keep z = 0) */
}

/* The template's shape for one kind of scene (cached). */
static const dem_clump_shape *template_shape(lua_State *L, ltemplate *t, int planar,
                                             const char *call)
{
    if (t->have[planar])
        return &t->shape[planar];
    core_error err; /* resolution 0: the engine's default for this kind of shape */
    if (dem_clump_shape_compute(t->m, t->n, t->dim, planar, t->resolution, &t->shape[planar], &err))
        bind_raise(L, call, &err);
    t->have[planar] = 1;
    return &t->shape[planar];
}

static const char *const TEMPLATE_FIELDS[] = {"members", "resolution", NULL};

static ltemplate *new_template(lua_State *L, int arg, const char *call, int dim)
{
    ltemplate *t = lua_newuserdatauv(L, sizeof *t, 0);
    memset(t, 0, sizeof *t);
    luaL_setmetatable(L, TEMPLATE);
    int packed = read_members(L, arg, call, dim, t->m);
    t->n = packed / 4, t->dim = packed % 4 + 2;
    t->resolution = (int)bind_field_integer(L, arg, call, "resolution", 0, 16, 1 << 16, 0);
    core_error err; /* the members checked now (connected), the integrals when first needed */
    dem_clump_shape probe;
    if (dem_clump_shape_compute(t->m, t->n, t->dim, 0, 16, &probe, &err))
        bind_raise(L, call, &err);
    return t;
}

static int l_clump_template(lua_State *L)
{
    bind_check_table(L, 1, "clump_template");
    bind_check_fields(L, 1, "clump_template", TEMPLATE_FIELDS);
    new_template(L, 1, "clump_template", 0);
    return 1;
}

static void set_num(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

static void push_shape(lua_State *L, const dem_clump_shape *sh)
{
    lua_newtable(L);
    set_num(L, sh->dim == 2 && sh->planar ? "area" : "volume", sh->measure);
    ldem_push_vector(L, sh->centre, sh->dim);
    lua_setfield(L, -2, "centre");
    if (sh->dim == 2) {
        set_num(L, "inertia", sh->moments[2]);
    } else {
        ldem_push_vector(L, sh->moments, 3);
        lua_setfield(L, -2, "moments");
        lua_createtable(L, 3, 0);
        for (int k = 0; k < 3; k++) {
            double a[3] = {sh->axes[k], sh->axes[3 + k], sh->axes[6 + k]};
            ldem_push_vector(L, a, 3);
            lua_rawseti(L, -2, k + 1);
        }
        lua_setfield(L, -2, "axes");
        lua_createtable(L, 3, 0);
        for (int r = 0; r < 3; r++) {
            ldem_push_vector(L, sh->tensor + 3 * r, 3);
            lua_rawseti(L, -2, r + 1);
        }
        lua_setfield(L, -2, "tensor");
    }
    set_num(L, "error", sh->rel_error);
    lua_pushinteger(L, sh->resolution);
    lua_setfield(L, -2, "resolution");
}

static int l_template_info(lua_State *L)
{
    ltemplate *t = bind_check_self(L, 1, TEMPLATE, "info");
    lua_settop(L, 1);
    push_shape(L, template_shape(L, t, 0, "info"));
    lua_pushinteger(L, t->n);
    lua_setfield(L, -2, "members");
    lua_pushinteger(L, t->dim);
    lua_setfield(L, -2, "dim");
    if (t->dim == 2) {
        push_shape(L, template_shape(L, t, 1, "info"));
        lua_setfield(L, -2, "disks");
    }
    return 1;
}

static int l_template_members(lua_State *L)
{
    ltemplate *t = bind_check_self(L, 1, TEMPLATE, "members");
    lua_createtable(L, t->n, 0);
    for (int k = 0; k < t->n; k++) {
        lua_createtable(L, 0, 2);
        lua_createtable(L, t->dim, 0);
        for (int d = 0; d < t->dim; d++) {
            lua_pushnumber(L, t->m[k].offset[d]);
            lua_rawseti(L, -2, d + 1);
        }
        lua_setfield(L, -2, "offset");
        lua_pushnumber(L, t->m[k].radius);
        lua_setfield(L, -2, "radius");
        lua_rawseti(L, -2, k + 1);
    }
    return 1;
}

static int l_template_tostring(lua_State *L)
{
    ltemplate *t = luaL_checkudata(L, 1, TEMPLATE);
    lua_pushfstring(L, "dem.clump_template (%dD, %d members)", t->dim, t->n);
    return 1;
}

/* ---- s:add_clump{...} ------------------------------------------------------------------------ */
static const char *const CLUMP_FIELDS[] = {"template", "members",  "material", "position",
                                           "orientation", "velocity", "spin", "resolution",
                                           NULL};
static const char *const AXIS_ANGLE_FIELDS[] = {"axis", "angle", NULL};

/* 3D orientation: {w, x, y, z} (unit within 1e-6, then normalised) or {axis = {...}, angle}. */
static void read_orientation3(lua_State *L, int arg, const char *call, double q[4])
{
    q[0] = 1, q[1] = q[2] = q[3] = 0;
    if (lua_getfield(L, arg, "orientation") == LUA_TNIL) {
        lua_pop(L, 1);
        return;
    }
    const int o = lua_gettop(L);
    const char *what = "unit quaternion {w, x, y, z} or {axis = {x, y, z}, angle = a}";
    if (lua_type(L, o) != LUA_TTABLE)
        bind_field_error(L, arg, call, "orientation", what);
    lua_getfield(L, o, "axis");
    int axis = !lua_isnil(L, -1);
    lua_pop(L, 1);
    if (axis) {
        bind_check_nested_fields(L, o, arg, call, "orientation", AXIS_ANGLE_FIELDS);
        double a[3] = {0, 0, 0};
        bind_field_vector(L, o, call, "axis", 3, a, BIND_REQUIRED);
        double ang = bind_field_number(L, o, call, "angle", 0, BIND_REQUIRED);
        double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        if (!(n > 0)) {
            lua_getfield(L, o, "axis");
            bind_field_error(L, arg, call, "orientation.axis", "non-zero vector");
        }
        q[0] = cos(0.5 * ang);
        for (int d = 0; d < 3; d++)
            q[d + 1] = sin(0.5 * ang) * a[d] / n;
    } else {
        double n2 = 0;
        for (int k = 0; k < 4; k++) {
            lua_rawgeti(L, o, k + 1);
            int ok;
            q[k] = lua_tonumberx(L, -1, &ok);
            lua_pop(L, 1);
            if (!ok || !isfinite(q[k]) || luaL_len(L, o) != 4)
                bind_field_error(L, arg, call, "orientation", what);
            n2 += q[k] * q[k];
        }
        if (!(fabs(sqrt(n2) - 1) <= 1e-6))
            bind_field_error(L, arg, call, "orientation", what);
        for (int k = 0; k < 4; k++)
            q[k] /= sqrt(n2);
    }
    lua_pop(L, 1);
}

static int l_add_clump(lua_State *L)
{
    const char *call = "add_clump";
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, CLUMP_FIELDS);
    bind_refuse_running(L, 1, call, "clumps join between runs");
    lua_getfield(L, 2, "template");
    lua_getfield(L, 2, "members");
    int has_t = !lua_isnil(L, -2), has_m = !lua_isnil(L, -1);
    lua_pop(L, 2);
    if (has_t == has_m)
        return luaL_error(L, "%s: give field 'template' (a dem.clump_template) or field "
                          "'members', %s", call, has_t ? "not both" : "got neither");
    ltemplate *t;
    if (has_t) {
        lua_getfield(L, 2, "template");
        t = luaL_testudata(L, -1, TEMPLATE);
        if (!t)
            bind_field_error(L, 2, call, "template", "dem.clump_template");
        if (lua_getfield(L, 2, "resolution") != LUA_TNIL)
            return luaL_error(L, "%s: resolution belongs to the template (dem.clump_template)",
                              call);
        lua_pop(L, 1);
    } else {
        t = new_template(L, 2, call, D);
    }
    const int tidx = lua_gettop(L); /* keeps the template alive */
    if (t->dim != D)
        return luaL_error(L, "%s: the template is %dD, the scene %dD", call, t->dim, D);
    dem_clump_def c;
    memset(&c, 0, sizeof c);
    c.members = t->m, c.n = t->n;
    c.shape = template_shape(L, t, dem_thickness(s) > 0, call);
    bind_field_vector(L, 2, call, "position", D, c.x, BIND_REQUIRED);
    bind_field_vector(L, 2, call, "velocity", D, c.v, 0);
    if (D == 2) {
        c.angle = bind_field_number(L, 2, call, "orientation", 0, 0);
        c.omega[2] = bind_field_number(L, 2, call, "spin", 0, 0);
    } else {
        read_orientation3(L, 2, call, c.q);
        bind_field_vector(L, 2, call, "spin", 3, c.omega, 0);
    }
    c.material = ldem_material_index(L, 1, 2, call, "material", 0);
    core_error err;
    long k = dem_add_clump(s, &c, &err);
    if (k < 0)
        return bind_raise(L, call, &err);
    ldem_default_material_notice(L, s, 1, 2, call);
    lua_settop(L, tidx);
    lua_pushinteger(L, k + 1);
    return 1;
}

static int l_clump(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    size_t n = dem_clump_count(s);
    lua_Integer k = bind_arg_integer(L, 2, "clump", 1, n ? (lua_Integer)n : 1);
    dem_clump_state c;
    core_error err;
    if (dem_clump_get(s, (size_t)(k - 1), &c, &err))
        return bind_raise(L, "clump", &err);
    lua_newtable(L);
    set_num(L, "mass", c.mass);
    ldem_push_vector(L, c.x, D);
    lua_setfield(L, -2, "position");
    ldem_push_vector(L, c.v, D);
    lua_setfield(L, -2, "velocity");
    if (D == 2) {
        set_num(L, "orientation", c.angle);
        set_num(L, "spin", c.omega[2]);
        set_num(L, "inertia", c.moments[2]);
        set_num(L, "angular_momentum", c.L[2]);
    } else {
        ldem_push_vector(L, c.q, 4);
        lua_setfield(L, -2, "orientation");
        ldem_push_vector(L, c.omega, 3);
        lua_setfield(L, -2, "spin");
        ldem_push_vector(L, c.moments, 3);
        lua_setfield(L, -2, "inertia");
        ldem_push_vector(L, c.L, 3);
        lua_setfield(L, -2, "angular_momentum");
    }
    lua_createtable(L, (int)c.count, 0);
    for (size_t i = 0; i < c.count; i++) {
        lua_pushinteger(L, (lua_Integer)(c.first + i + 1));
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "members");
    return 1;
}

static int l_clump_count(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    lua_pushinteger(L, (lua_Integer)dem_clump_count(s));
    return 1;
}

void ldem_open_clump(lua_State *L)
{
    static const bind_fn methods[] = {
        {"add_clump", l_add_clump,
         "s:add_clump{ template = T or members = {{offset = {...}, radius = r}, ...}, material "
         "= m, position = {...}, orientation = a (2D) or {w, x, y, z} or {axis = {...}, angle = "
         "a} (3D), velocity = {...}, spin = w (2D) or {...} (3D), resolution = n }",
         "Adds a rigid clump; returns its id. position: its centre of mass; orientation turns "
         "the members' frame (offsets as given) into the world. Mass and inertia are those of "
         "the union of the members. Members become particles of the scene that move with the "
         "clump; members of one clump never touch. resolution: quadrature lines (members only; "
         "a template carries its own)."},
        {"clump", l_clump, "s:clump(id)",
         "A clump's mass, position (centre of mass), velocity, orientation (2D: angle; 3D: "
         "quaternion {w, x, y, z} of its principal frame), spin, inertia (principal moments), "
         "angular_momentum and the ids of its members."},
        {"clump_count", l_clump_count, "s:clump_count()", "The number of clumps."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fields[] = {{"add_clump", NULL, CLUMP_FIELDS}, {NULL, NULL, NULL}};
    ldem_add_methods(L, methods, fields);

    static const bind_fn tmethods[] = {
        {"info", l_template_info, "T:info()",
         "The union's mass properties per unit density: volume (spheres; 2D: centres in the "
         "plane), centre (in the members' frame), inertia (2D: about z through the centre) or "
         "moments, axes (principal, ascending; columns) and tensor (3D), error (the estimated "
         "relative quadrature error), resolution; in 2D also disks = the same for disks of unit "
         "thickness (area, inertia per unit thickness), as in scenes with thickness > 0."},
        {"members", l_template_members, "T:members()",
         "The members as given: {{offset = {...}, radius = r}, ...} in the members' frame."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {{"__tostring", l_template_tostring}, {NULL, NULL}};
    bind_new_type(L, TEMPLATE, tmethods, meta,
                  "A clump shape from dem.clump_template{...}, for s:add_clump{ template = T }.");
    static const bind_fn fns[] = {
        {"clump_template", l_clump_template,
         "dem.clump_template{ members = {{offset = {...}, radius = r}, ...}, resolution = n }",
         "A reusable clump shape: 1 to 256 disks (2D offsets) or spheres (3D offsets) that form "
         "one connected body (each overlaps or touches another). resolution: quadrature lines "
         "along the longest side (default 4096 for disks, 1024 for spheres in 2D, 512 in 3D)."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"clump_template", NULL, TEMPLATE_FIELDS},
                                            {NULL, NULL, NULL}};
    lua_getglobal(L, "dem");
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    lua_pop(L, 1);
}
