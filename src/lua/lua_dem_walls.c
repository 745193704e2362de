/* The dem bindings: walls, planes (s:add_wall) and beyond (polylines, meshes, cylinders), their
 * motion, servo and loads. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

/* ---- walls ---------------------------------------------------------------------------------- */
static const char *const WALL_FIELDS[] = {"point",    "normal",   "velocity",
                                          "friction", "material", NULL};

static int l_add_wall(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
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
    w.material = ldem_material_index(L, 1, 2, "add_wall", "material", -1);
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
    dem_scene *s = ldem_check_scene(L, 1);
    core_error err;
    if (dem_remove_wall(s, wall_arg(L, 2, "remove_wall"), &err))
        return bind_raise(L, "remove_wall", &err);
    return 0;
}

static int l_wall_velocity(lua_State *L)
{
    dem_scene *s = ldem_check_scene_local(L, 1); /* walls and dt: the same on every rank */
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
    dem_scene *s = ldem_check_scene_local(L, 1); /* walls and dt: the same on every rank */
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
    dem_scene *s = ldem_check_scene_local(L, 1); /* walls and dt: the same on every rank */
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

static int l_wall_point(lua_State *L)
{
    dem_scene *s = ldem_check_scene_local(L, 1); /* walls and dt: the same on every rank */
    double p[3];
    core_error err;
    if (dem_wall_point(s, wall_arg(L, 2, "wall_point"), p, &err))
        return bind_raise(L, "wall_point", &err);
    ldem_push_vector(L, p, dem_dim(s));
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
    dem_scene *s = ldem_check_scene(L, 1);
    const int D = dem_dim(s);
    if (!def->has_center)
        def->has_center = bind_field_vector(L, 2, call, "center", D, def->center, 0);
    read_motion(L, 2, call, s, def);
    def->friction = bind_field_number(L, 2, call, "friction", -1, 0);
    if (def->friction < 0 && lua_getfield(L, 2, "friction") != LUA_TNIL)
        return bind_field_error(L, 2, call, "friction", "non-negative number");
    def->material = ldem_material_index(L, 1, 2, call, "material", -1);
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
    dem_scene *s = ldem_check_scene(L, 1);
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
    dem_scene *s = ldem_check_scene(L, 1);
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
    dem_scene *s = ldem_check_scene(L, 1);
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
    dem_scene *s = ldem_check_scene_local(L, 1);
    core_error serr;
    if (dem_sync_walls(s, &serr) != CORE_OK)
        return bind_raise(L, "wall_load", &serr);
    double f[3], t[3];
    core_error err;
    if (dem_wall_load(s, wall_arg(L, 2, "wall_load"), f, t, &err))
        return bind_raise(L, "wall_load", &err);
    ldem_push_vector(L, f, dem_dim(s));
    if (dem_dim(s) == 2)
        lua_pushnumber(L, t[2]);
    else
        ldem_push_vector(L, t, 3);
    return 2;
}

void ldem_open_walls(lua_State *L)
{
    static const bind_fn methods[] = {
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
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fields[] = {
        {"add_wall", NULL, WALL_FIELDS},    {"add_polyline", NULL, POLYLINE_FIELDS},
        {"add_mesh", NULL, MESH_FIELDS},    {"add_cylinder", NULL, CYLINDER_FIELDS},
        {"wall_servo", NULL, SERVO_FIELDS}, {NULL, NULL, NULL}};
    ldem_add_methods(L, methods, fields);
}
