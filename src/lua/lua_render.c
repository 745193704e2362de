/* The Lua module `render`: PNG frames of DEM scenes, images read back as pixels, line plots;
 * grid fields and point clouds are in lua_render_field.c.
 * Translates and checks arguments, calls src/render, raises its errors named after the call. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem/dem.h"
#include "core/progress.h"
#include "lua/bind.h"
#include "lua/lua_render.h"
#include "render/render.h"

static const char *IMAGE = "render.image";
static const char *CONTEXT = "render.context";     /* registry: the shared GL context */
static const char *FRAMES = "grainlab.render.frames"; /* registry: pattern -> next frame */

/* ---- the shared context, created on first use and closed with the state ------------------- */
static int l_context_gc(lua_State *L)
{
    render_context **u = lua_touserdata(L, 1);
    render_context_destroy(*u);
    *u = NULL;
    return 0;
}

render_context *bind_render_context(lua_State *L, const char *call)
{
    if (lua_getfield(L, LUA_REGISTRYINDEX, CONTEXT) == LUA_TUSERDATA) {
        render_context *rc = *(render_context **)lua_touserdata(L, -1);
        lua_pop(L, 1);
        return rc;
    }
    lua_pop(L, 1);
    render_context **u = lua_newuserdatauv(L, sizeof *u, 0);
    *u = NULL;
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, l_context_gc);
    lua_setfield(L, -2, "__gc");
    lua_setmetatable(L, -2);
    core_error err;
    if (render_context_create(u, &err) != CORE_OK)
        bind_raise(L, call, &err);
    lua_setfield(L, LUA_REGISTRYINDEX, CONTEXT);
    return *u;
}

static dem_scene *check_dem(lua_State *L, int arg, const char *call)
{
    return bind_check_dem_scene(L, arg, call);
}

/* ---- images ---------------------------------------------------------------------------------- */
render_image *bind_push_image(lua_State *L)
{
    render_image *img = lua_newuserdatauv(L, sizeof *img, 0);
    memset(img, 0, sizeof *img);
    luaL_setmetatable(L, IMAGE);
    return img;
}

static render_image *check_image(lua_State *L, int idx)
{
    render_image *img = luaL_checkudata(L, idx, IMAGE);
    if (!img->rgba)
        luaL_error(L, "the render.image was freed");
    return img;
}

static int l_image_gc(lua_State *L)
{
    render_image_free(luaL_checkudata(L, 1, IMAGE));
    return 0;
}

static int l_image_size(lua_State *L)
{
    render_image *img = check_image(L, 1);
    lua_pushinteger(L, img->width);
    lua_pushinteger(L, img->height);
    return 2;
}

static int l_image_pixel(lua_State *L)
{
    render_image *img = check_image(L, 1);
    lua_Integer x = luaL_checkinteger(L, 2), y = luaL_checkinteger(L, 3);
    if (x < 1 || x > img->width || y < 1 || y > img->height)
        return luaL_error(L, "bad argument #%d to 'pixel' (pixel in [1, %d] x [1, %d] expected, "
                             "got (%d, %d))", x < 1 || x > img->width ? 1 : 2, img->width,
                          img->height, (int)x, (int)y);
    const unsigned char *p = img->rgba + ((size_t)(y - 1) * img->width + (size_t)(x - 1)) * 4;
    lua_pushinteger(L, p[0]);
    lua_pushinteger(L, p[1]);
    lua_pushinteger(L, p[2]);
    return 3;
}

static int l_image_save(lua_State *L)
{
    render_image *img = check_image(L, 1);
    const char *path = bind_arg_path(L, 2, "save");
    core_error err;
    if (render_write_png(img, path, &err) != CORE_OK)
        return bind_raise(L, "save", &err);
    lua_pushstring(L, path);
    return 1;
}

static int l_image_tostring(lua_State *L)
{
    render_image *img = luaL_checkudata(L, 1, IMAGE);
    lua_pushfstring(L, "render.image (%d x %d)", img->width, img->height);
    return 1;
}

/* ---- scene options ----------------------------------------------------------------------- */
static const char *const COLORS[] = {"grain", "speed", "rotation", "material", "clump", NULL};
const char *const bind_render_colormaps[] = {"viridis", "gray", NULL};
static const char *const SHOW[] = {"force_chains", "rotation", "walls", "colorbar", "box",
                                   "displacement", NULL};

/* Arrays read from the options live in Lua userdata left on the stack, so an argument error
 * half-way leaks nothing. */
typedef struct scene_opts {
    render_grains_def def;
    int want_arrows;
    int show_walls; /* 'walls' in show: refused beside walls = false */
    long frame;     /* < 0: none given */
} scene_opts;

/* A buffer of size bytes placed below the value on top of the stack. */
void *bind_buffer_below_top(lua_State *L, size_t size)
{
    void *p = lua_newuserdatauv(L, size ? size : 1, 0);
    lua_insert(L, -2);
    return p;
}

/* The table at idx has no keys but 1..#t: {a = ...} is no list, and must not read as an empty one.
 */
static int pure_array(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    size_t n = lua_rawlen(L, idx), count = 0;
    for (lua_pushnil(L); lua_next(L, idx); lua_pop(L, 1))
        count++;
    return count == n;
}

static void read_show(lua_State *L, int arg, const char *call, scene_opts *o)
{
    render_grains_def *d = &o->def;
    int t = lua_getfield(L, arg, "show");
    if (t == LUA_TNIL) { /* defaults: box, and a colour bar when a colour map is used */
        lua_pop(L, 1);
        d->box = true;
        d->colorbar = true;
        return;
    }
    d->box = false;
    char expected[160] = "";
    for (int k = 0; SHOW[k]; k++) {
        size_t len = strlen(expected);
        snprintf(expected + len, sizeof expected - len, "%s'%s'", k ? ", " : "", SHOW[k]);
    }
    char what[200];
    snprintf(what, sizeof what, "array of %s", expected);
    /* A list, as the defaults it replaces: a single name ("walls") would read as a list of one
     * while dropping the box and colour bar unasked. */
    if (t == LUA_TSTRING) {
        for (int k = 0; SHOW[k]; k++)
            if (strcmp(SHOW[k], lua_tostring(L, -1)) == 0)
                snprintf(what, sizeof what, "array of names (show = { '%s' })", SHOW[k]);
        bind_field_error(L, arg, call, "show", what);
    }
    if (t != LUA_TTABLE || !pure_array(L, -1))
        bind_field_error(L, arg, call, "show", what);
    lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, -1, i);
        const char *s = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
        int k = 0;
        while (SHOW[k] && strcmp(SHOW[k], s) != 0)
            k++;
        if (!SHOW[k])
            bind_field_error(L, arg, call, "show", what);
        lua_pop(L, 1);
        switch (k) {
        case 0: d->force_chains = true; break;
        case 1: d->rotation = true; break;
        case 2: o->show_walls = 1; break; /* walls are drawn unless walls = false */
        case 3: d->colorbar = true; break;
        case 4: d->box = true; break;
        default: o->want_arrows = 1; break;
        }
    }
    lua_pop(L, 1);
}

/* walls: nil or true (the default) draws the scene's own walls where they are now (removed
 * ones not), false none, an array the walls given. */
static void read_walls(lua_State *L, int arg, const char *call, dem_scene *s, scene_opts *o)
{
    static const char *const WALL_FIELDS[] = {"point", "normal", NULL};
    const int D = dem_dim(s);
    const char *what = D == 2 ? "false, true or an array of { point = {x, y}, normal = {nx, ny} }"
                              : "false, true or an array of { point = {x, y, z}, normal = "
                                "{nx, ny, nz} }";
    int t = lua_getfield(L, arg, "walls");
    if (t == LUA_TBOOLEAN && !lua_toboolean(L, -1)) {
        if (o->show_walls) /* one of the two would be ignored */
            bind_field_error(L, arg, call, "walls", "true when show has 'walls'");
        lua_pop(L, 1);
        return;
    }
    if (t == LUA_TNIL || t == LUA_TBOOLEAN) { /* the scene's own walls */
        lua_pop(L, 1);
        int count = dem_wall_count(s), k = 0;
        /* left on the stack, alive until the call returns (nothing above it to keep) */
        render_wall *walls = lua_newuserdatauv(L, (size_t)(count ? count : 1) * sizeof *walls, 0);
        for (int id = 0; id < count; id++) {
            double p[3], nrm[3];
            int active;
            if (dem_wall_geometry(s, id, p, nrm, &active, NULL) == CORE_OK && active) {
                memcpy(walls[k].point, p, sizeof walls[k].point);
                memcpy(walls[k].normal, nrm, sizeof walls[k].normal);
                k++;
            }
        }
        o->def.walls = walls;
        o->def.nwalls = k;
        o->def.shapes = true; /* and the walls beyond planes, as they are now */
        return;
    }
    if (!lua_istable(L, -1) || !pure_array(L, -1))
        bind_field_error(L, arg, call, "walls", what);
    int n = (int)lua_rawlen(L, -1);
    render_wall *walls = bind_buffer_below_top(L, (size_t)n * sizeof *walls);
    int tbl = lua_gettop(L);
    for (int k = 0; k < n; k++) {
        if (lua_rawgeti(L, tbl, k + 1) != LUA_TTABLE)
            bind_field_error(L, arg, call, "walls", what);
        int w = lua_gettop(L);
        lua_pushnil(L);
        while (lua_next(L, w)) {
            lua_pop(L, 1);
            const char *key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
            if (strcmp(key, WALL_FIELDS[0]) && strcmp(key, WALL_FIELDS[1])) {
                lua_pushvalue(L, w);
                bind_field_error(L, arg, call, "walls", what);
            }
        }
        double v[2][3] = {{0, 0, 0}, {0, 0, 0}};
        for (int f = 0; f < 2; f++) {
            int ok =
                lua_getfield(L, w, WALL_FIELDS[f]) == LUA_TTABLE && lua_rawlen(L, -1) == (size_t)D;
            for (int d = 0; ok && d < D; d++) {
                lua_rawgeti(L, -1, d + 1);
                int isnum;
                v[f][d] = lua_tonumberx(L, -1, &isnum);
                ok = isnum && isfinite(v[f][d]);
                lua_pop(L, 1);
            }
            lua_pop(L, 1);
            if (!ok || (f == 1 && v[1][0] == 0 && v[1][1] == 0 && v[1][2] == 0)) {
                lua_pushvalue(L, w);
                bind_field_error(L, arg, call, "walls", what);
            }
        }
        memcpy(walls[k].point, v[0], sizeof v[0]);
        memcpy(walls[k].normal, v[1], sizeof v[1]);
        lua_pop(L, 1);
    }
    o->def.walls = walls;
    o->def.nwalls = n;
    lua_pop(L, 1);
}

/* displacement = { affine = {{a, b}, {c, d}}, center = {x, y}, scale = k }: arrows of the
 * displacement since s:set_reference() less the affine field, when show has 'displacement'. */
static void read_arrows(lua_State *L, int arg, const char *call, dem_scene *s, scene_opts *o)
{
    const char *what = "table { affine = {{a, b}, {c, d}}, center = {x, y}, scale = k >= 0 }";
    int t = lua_getfield(L, arg, "displacement");
    if (t != LUA_TNIL && t != LUA_TTABLE)
        bind_field_error(L, arg, call, "displacement", what);
    if (!o->want_arrows) {
        lua_pop(L, 1);
        return;
    }
    const int D = dem_dim(s);
    double grad[3][3] = {{0}}, center[3] = {0, 0, 0};
    int affine = 0;
    if (t == LUA_TTABLE) {
        int c = lua_gettop(L);
        lua_pushnil(L);
        while (lua_next(L, c)) {
            lua_pop(L, 1);
            const char *key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
            if (strcmp(key, "affine") && strcmp(key, "center") && strcmp(key, "scale")) {
                lua_pushvalue(L, c);
                bind_field_error(L, arg, call, "displacement", what);
            }
        }
        if (lua_getfield(L, c, "affine") != LUA_TNIL) {
            int ok = lua_istable(L, -1) && lua_rawlen(L, -1) == (size_t)D;
            for (int a = 0; ok && a < D; a++) {
                ok = lua_rawgeti(L, -1, a + 1) == LUA_TTABLE && lua_rawlen(L, -1) == (size_t)D;
                for (int b = 0; ok && b < D; b++) {
                    lua_rawgeti(L, -1, b + 1);
                    int isnum;
                    grad[a][b] = lua_tonumberx(L, -1, &isnum);
                    ok = isnum && isfinite(grad[a][b]);
                    lua_pop(L, 1);
                }
                lua_pop(L, 1);
            }
            if (!ok)
                bind_field_error(L, arg, call, "displacement.affine",
                                 "2 x 2 array of finite numbers (displacement gradient)");
            affine = 1;
        }
        lua_pop(L, 1);
        if (lua_getfield(L, c, "center") != LUA_TNIL) {
            int ok = lua_istable(L, -1) && lua_rawlen(L, -1) == (size_t)D;
            for (int a = 0; ok && a < D; a++) {
                lua_rawgeti(L, -1, a + 1);
                int isnum;
                center[a] = lua_tonumberx(L, -1, &isnum);
                ok = isnum && isfinite(center[a]);
                lua_pop(L, 1);
            }
            if (!ok)
                bind_field_error(L, arg, call, "displacement.center", "array of 2 finite numbers");
        }
        lua_pop(L, 1);
        if (lua_getfield(L, c, "scale") != LUA_TNIL) {
            int isnum;
            double k = lua_tonumberx(L, -1, &isnum);
            if (!isnum || !isfinite(k) || k < 0)
                bind_field_error(L, arg, call, "displacement.scale", "non-negative number");
            o->def.arrow_scale = k;
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    if (D != 2)
        return; /* render_dem refuses arrows in 3D with its own message */
    size_t n = dem_count(s);
    double *u = lua_newuserdatauv(L, (n ? n : 1) * 2 * sizeof *u, 0);
    double *out[3] = {u, u + n, NULL};
    core_error err;
    if (dem_measure_displacement(s, affine ? (const double(*)[3])grad : NULL, center, out, &err))
        bind_raise(L, call, &err);
    o->def.arrows[0] = u;
    o->def.arrows[1] = u + n;
}

/* camera = { azimuth =, elevation =, projection = 'orthographic'|'perspective', fov = } */
static void read_camera(lua_State *L, int arg, const char *call, render_camera *cam)
{
    static const char *const PROJ[] = {"orthographic", "perspective", NULL};
    const char *what = "table { azimuth =, elevation =, projection = 'orthographic'|'perspective', "
                       "fov = (0, 90) }";
    int t = lua_getfield(L, arg, "camera");
    if (t == LUA_TNIL) {
        lua_pop(L, 1);
        return;
    }
    if (t != LUA_TTABLE)
        bind_field_error(L, arg, call, "camera", what);
    int c = lua_gettop(L);
    lua_pushnil(L);
    while (lua_next(L, c)) {
        lua_pop(L, 1);
        const char *key = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
        if (strcmp(key, "azimuth") && strcmp(key, "elevation") && strcmp(key, "projection") &&
            strcmp(key, "fov")) {
            lua_pushvalue(L, c);
            bind_field_error(L, arg, call, "camera", what);
        }
    }
    /* the fields are checked as fields of the camera table, named camera.* */
    char name[32];
    const char *keys[3] = {"azimuth", "elevation", "fov"};
    double *dst[3] = {&cam->azimuth, &cam->elevation, &cam->fov};
    for (int k = 0; k < 3; k++) {
        int tt = lua_getfield(L, c, keys[k]);
        if (tt != LUA_TNIL) {
            int isnum;
            double v = lua_tonumberx(L, -1, &isnum);
            snprintf(name, sizeof name, "camera.%s", keys[k]);
            if (tt != LUA_TNUMBER || !isnum || !isfinite(v) || (k == 2 && !(v > 0 && v < 90)))
                bind_field_error(L, arg, call, name, k == 2 ? "number in (0, 90)" : "finite number");
            *dst[k] = v;
        }
        lua_pop(L, 1);
    }
    int tt = lua_getfield(L, c, "projection");
    if (tt != LUA_TNIL) {
        int k = 0;
        while (tt == LUA_TSTRING && PROJ[k] && strcmp(PROJ[k], lua_tostring(L, -1)))
            k++;
        if (tt != LUA_TSTRING || !PROJ[k])
            bind_field_error(L, arg, call, "camera.projection",
                             "one of 'orthographic', 'perspective'");
        cam->perspective = k == 1;
    }
    lua_pop(L, 2);
}

/* range = {lo, hi}: colour-map limits; absent: range left as it is ({0, 0}: the data's). */
void bind_read_range(lua_State *L, int arg, const char *call, double range[2])
{
    if (lua_getfield(L, arg, "range") != LUA_TNIL) {
        int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == 2;
        for (int k = 0; ok && k < 2; k++) {
            lua_rawgeti(L, -1, k + 1);
            int isnum;
            range[k] = lua_tonumberx(L, -1, &isnum);
            ok = isnum && lua_type(L, -1) == LUA_TNUMBER && fabs(range[k]) <= 1e100;
            lua_pop(L, 1);
        }
        if (!ok || !(range[0] < range[1]))
            bind_field_error(L, arg, call, "range", "{lo, hi} with lo < hi");
    }
    lua_pop(L, 1);
}

/* Labels for color = 'clump' (kept below the top of the stack): a clump's members share its
 * index, and each loose grain has one of its own after them. */
static const int *clump_labels(lua_State *L, const dem_scene *s)
{
    const size_t n = dem_count(s), nc = dem_clump_count(s);
    int *lab = bind_buffer_below_top(L, n * sizeof *lab);
    for (size_t i = 0; i < n; i++) {
        const long k = dem_particle_clump(s, i);
        lab[i] = k >= 0 ? (int)k : (int)(nc + i);
    }
    return lab;
}

static const char *const SCENE_OPTS_FIELDS[] = {
    "width", "height", "color", "colormap", "range",  "show",         "title",
    "stamp", "label",  "walls", "frame",    "camera", "displacement", NULL};

/* Reads the options table at arg (absent: all defaults) into o. Strings and arrays it points to
 * are kept alive on the stack until the call returns. */
static void read_scene_opts(lua_State *L, int scene, int arg, const char *call, dem_scene *s,
                            scene_opts *o)
{
    memset(o, 0, sizeof *o);
    o->def = render_default_grains_def();
    o->frame = -1;
    if (lua_isnoneornil(L, arg)) {
        lua_newtable(L);
        lua_replace(L, arg);
    }
    bind_check_table(L, arg, call);
    bind_check_fields(L, arg, call, SCENE_OPTS_FIELDS);
    render_grains_def *d = &o->def;
    d->width = (int)bind_field_integer(L, arg, call, "width", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    d->height = (int)bind_field_integer(L, arg, call, "height", 0, RENDER_MIN_SIZE,
                                        RENDER_MAX_SIZE, 0);
    d->colormap = (render_colormap)bind_field_option(L, arg, call, "colormap", bind_render_colormaps,
                                                     RENDER_VIRIDIS, 0);
    o->frame = (long)bind_field_integer(L, arg, call, "frame", -1, 0, LUA_MAXINTEGER, 0);
    d->title = bind_field_string(L, arg, call, "title", NULL, 0);
    d->colorbar_label = bind_field_string(L, arg, call, "label", NULL, 0);

    const size_t n = dem_count(s);
    int t = lua_getfield(L, arg, "color");
    if (t == LUA_TTABLE) {
        char what[96];
        snprintf(what, sizeof what, "array of %zu finite numbers (one per grain)", n);
        if (lua_rawlen(L, -1) != n)
            bind_field_error(L, arg, call, "color", what);
        double *values = bind_buffer_below_top(L, n * sizeof *values);
        for (size_t i = 0; i < n; i++) {
            lua_rawgeti(L, -1, (lua_Integer)i + 1);
            int isnum;
            values[i] = lua_tonumberx(L, -1, &isnum);
            lua_pop(L, 1);
            if (!isnum || !isfinite(values[i]))
                bind_field_error(L, arg, call, "color", what);
        }
        d->color = RENDER_COLOR_VALUES;
        d->values = values;
        lua_pop(L, 1);
    } else if (t == LUA_TNIL || t == LUA_TSTRING) {
        static const render_color_by BY[] = {RENDER_COLOR_GRAIN, RENDER_COLOR_SPEED,
                                             RENDER_COLOR_ROTATION, RENDER_COLOR_LABELS,
                                             RENDER_COLOR_LABELS};
        int k = 0;
        while (t == LUA_TSTRING && COLORS[k] && strcmp(COLORS[k], lua_tostring(L, -1)) != 0)
            k++;
        if (!COLORS[k])
            bind_field_error(L, arg, call, "color",
                             "one of 'grain', 'speed', 'rotation', 'material', 'clump' or an "
                             "array of numbers");
        d->color = BY[k];
        if (d->color == RENDER_COLOR_LABELS && strcmp(COLORS[k], "clump") != 0)
            d->labels = dem_particle_materials(s);
        else if (d->color == RENDER_COLOR_LABELS) /* a colour per clump, another per loose grain */
            d->labels = clump_labels(L, s);
        lua_pop(L, 1);
    } else {
        bind_field_error(L, arg, call, "color",
                         "one of 'grain', 'speed', 'rotation', 'material', 'clump' or an array of "
                         "numbers");
    }

    bind_read_range(L, arg, call, d->range);

    read_show(L, arg, call, o);
    read_walls(L, arg, call, s, o);
    read_camera(L, arg, call, &d->camera);
    read_arrows(L, arg, call, s, o);

    t = lua_getfield(L, arg, "stamp");
    if (t == LUA_TSTRING) {
        d->stamp = lua_tostring(L, -1);
    } else if (t == LUA_TBOOLEAN) {
        if (lua_toboolean(L, -1)) {
            char buf[64];
            snprintf(buf, sizeof buf, "t = %.6g s", dem_time(s));
            d->stamp = lua_pushstring(L, buf);
        }
    } else if (t != LUA_TNIL) {
        bind_field_error(L, arg, call, "stamp", "boolean or string");
    }
    if (d->rotation)
        d->angles = dem_angles(s); /* NULL (all 0) without rotational state or in 3D */
    (void)scene;
    /* leave the pushed strings on the stack: they keep title and stamp alive until the call ends */
}

static void draw_scene(lua_State *L, const char *call, int scene, int arg, render_image *img,
                       scene_opts *o)
{
    dem_scene *s = check_dem(L, scene, call);
    read_scene_opts(L, scene, arg, call, s, o);
    render_context *rc = bind_render_context(L, call);
    core_error err;
    if (render_dem(rc, s, &o->def, img, NULL, &err) != CORE_OK)
        bind_raise(L, call, &err);
}


/* render.png(scene, path, opts) */
static int l_png(lua_State *L)
{
    lua_settop(L, 3);
    check_dem(L, 1, "png");
    const char *pattern = bind_arg_path(L, 2, "png");
    scene_opts o;
    render_image *img = bind_push_image(L); /* freed by __gc even if an error follows */
    int idx = lua_gettop(L);
    draw_scene(L, "png", 1, 3, img, &o);
    lua_settop(L, idx);
    return bind_write_image(L, img, pattern, o.frame, "png");
}

/* Writes img to the file pattern (frame < 0: the pattern's own counter), frees its pixels and
 * returns the file name written. */
int bind_write_image(lua_State *L, render_image *img, const char *pattern, long frame,
                     const char *call)
{
    char path[4096];
    core_error err;
    if (strchr(pattern, '%') && frame < 0) { /* the pattern's own counter */
        if (lua_getfield(L, LUA_REGISTRYINDEX, FRAMES) != LUA_TTABLE) {
            lua_pop(L, 1);
            lua_newtable(L);
            lua_pushvalue(L, -1);
            lua_setfield(L, LUA_REGISTRYINDEX, FRAMES);
        }
        lua_getfield(L, -1, pattern);
        frame = (long)lua_tointeger(L, -1);
        lua_pop(L, 1);
        lua_pushinteger(L, frame + 1);
        lua_setfield(L, -2, pattern);
        lua_pop(L, 1);
    }
    if (render_frame_path(pattern, frame < 0 ? 0 : frame, path, sizeof path, &err) != CORE_OK ||
        render_write_png(img, path, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    render_image_free(img);
    lua_pushstring(L, path);
    return 1;
}

/* render.image(scene, opts) */
static int l_image(lua_State *L)
{
    lua_settop(L, 2);
    check_dem(L, 1, "image");
    scene_opts o;
    render_image *img = bind_push_image(L);
    int idx = lua_gettop(L);
    draw_scene(L, "image", 1, 2, img, &o);
    lua_pushvalue(L, idx);
    return 1;
}

/* ---- render.plot{...} ---------------------------------------------------------------------- */
static const char *const STYLES[] = {"line", "points", "both", "none", NULL};

/* Reads field `name` of the series table at st (series number k) into a new userdata buffer left
 * on the stack (so an error cannot leak it); *n: the length it must have, or (size_t)-1.
 * NaN and infinities are kept: they are gaps in the line. */
static double *series_array(lua_State *L, int st, int k, const char *name, size_t *n)
{
    char field[32], what[64];
    snprintf(field, sizeof field, "series[%d].%s", k, name);
    snprintf(what, sizeof what, "array of numbers");
    if (lua_getfield(L, st, name) != LUA_TTABLE)
        bind_field_error(L, 1, "plot", field, what);
    int arr = lua_gettop(L);
    size_t len = lua_rawlen(L, arr);
    if (*n != (size_t)-1 && len != *n) {
        snprintf(what, sizeof what, "array as long as series[%d].x (%zu)", k, *n);
        bind_field_error(L, 1, "plot", field, what);
    }
    double *v = lua_newuserdatauv(L, (len ? len : 1) * sizeof *v, 0);
    for (size_t i = 0; i < len; i++) {
        lua_rawgeti(L, arr, (lua_Integer)i + 1);
        int isnum;
        v[i] = lua_tonumberx(L, -1, &isnum);
        if (!isnum)
            bind_field_error(L, 1, "plot", field, what);
        lua_pop(L, 1);
    }
    lua_remove(L, arr);
    *n = len;
    return v;
}

static const char *const PLOT_FIELDS[] = {"file",   "width", "height", "title",  "xlabel",
                                          "ylabel", "xlog",  "ylog",   "series", NULL};

static int l_plot(lua_State *L)
{
    static const char *const sfields[] = {"x", "y", "label", "style", NULL};
    lua_settop(L, 1);
    bind_check_table(L, 1, "plot");
    bind_check_fields(L, 1, "plot", PLOT_FIELDS);
    render_plot_def def = render_default_plot_def();
    const char *file = bind_field_path(L, 1, "plot", "file", 0);
    def.width = (int)bind_field_integer(L, 1, "plot", "width", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    def.height = (int)bind_field_integer(L, 1, "plot", "height", 0, RENDER_MIN_SIZE,
                                         RENDER_MAX_SIZE, 0);
    def.title = bind_field_string(L, 1, "plot", "title", NULL, 0);
    def.xlabel = bind_field_string(L, 1, "plot", "xlabel", NULL, 0);
    def.ylabel = bind_field_string(L, 1, "plot", "ylabel", NULL, 0);
    def.xlog = bind_field_boolean(L, 1, "plot", "xlog", 0);
    def.ylog = bind_field_boolean(L, 1, "plot", "ylog", 0);
    const char *what = "non-empty array of { x = {...}, y = {...}, label =, style = }";
    if (lua_getfield(L, 1, "series") != LUA_TTABLE || lua_rawlen(L, -1) < 1 ||
        lua_rawlen(L, -1) > 1000)
        return bind_field_error(L, 1, "plot", "series", what);
    int ns = (int)lua_rawlen(L, -1), list = lua_gettop(L);
    render_series *series = lua_newuserdatauv(L, (size_t)ns * sizeof *series, 0);
    memset(series, 0, (size_t)ns * sizeof *series);
    for (int k = 1; k <= ns; k++) {
        char field[32];
        snprintf(field, sizeof field, "series[%d]", k);
        if (lua_rawgeti(L, list, k) != LUA_TTABLE)
            return bind_field_error(L, 1, "plot", field, "table { x = {...}, y = {...} }");
        int st = lua_gettop(L);
        luaL_checkstack(L, 8, "plot: too many series");
        lua_pushnil(L);
        while (lua_next(L, st)) {
            lua_pop(L, 1);
            int known = 0;
            for (int f = 0; sfields[f]; f++)
                known |= lua_type(L, -1) == LUA_TSTRING && !strcmp(lua_tostring(L, -1), sfields[f]);
            if (!known) {
                char key[64];
                bind_describe(L, -1, key, sizeof key);
                return luaL_error(L, "bad field 'series[%d]' in argument #1 to 'plot' (unknown key "
                                     "%s; valid keys: x, y, label, style)", k, key);
            }
        }
        render_series *s = &series[k - 1];
        size_t n = (size_t)-1;
        s->x = series_array(L, st, k, "x", &n);
        s->y = series_array(L, st, k, "y", &n);
        s->n = n;
        char sf[32];
        snprintf(sf, sizeof sf, "series[%d].label", k);
        if (lua_getfield(L, st, "label") == LUA_TSTRING)
            s->label = lua_tostring(L, -1);
        else if (!lua_isnil(L, -1))
            return bind_field_error(L, 1, "plot", sf, "string");
        lua_pop(L, 1);
        snprintf(sf, sizeof sf, "series[%d].style", k);
        int t = lua_getfield(L, st, "style");
        s->style = RENDER_LINE;
        if (t != LUA_TNIL) {
            int m = 0;
            while (t == LUA_TSTRING && STYLES[m] && strcmp(STYLES[m], lua_tostring(L, -1)))
                m++;
            if (t != LUA_TSTRING || !STYLES[m])
                return bind_field_error(L, 1, "plot", sf,
                                        "one of 'line', 'points', 'both', 'none'");
            s->style = (render_plot_style)m;
        }
        lua_pop(L, 1);
        /* the buffers and the series table stay on the stack until the call ends */
    }
    def.series = series;
    def.nseries = ns;
    render_context *rc = bind_render_context(L, "plot");
    render_image *img = bind_push_image(L);
    int idx = lua_gettop(L);
    core_error err;
    if (render_plot(rc, &def, img, NULL, &err) != CORE_OK)
        return bind_raise(L, "plot", &err);
    if (!file) {
        lua_pushvalue(L, idx);
        return 1;
    }
    if (render_write_png(img, file, &err) != CORE_OK)
        return bind_raise(L, "plot", &err);
    render_image_free(img);
    lua_pushstring(L, file);
    return 1;
}

void bind_open_render(lua_State *L)
{
    static const bind_fn methods[] = {
        {"size", l_image_size, "img:size()", "Width and height in pixels."},
        {"pixel", l_image_pixel, "img:pixel(x, y)",
         "Red, green and blue (0-255) of the pixel in column x and row y, both from 1 at the "
         "top-left corner."},
        {"save", l_image_save, "img:save(path)", "Writes the image as a PNG, whole."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_image_gc}, {"__close", l_image_gc}, {"__tostring", l_image_tostring},
        {NULL, NULL}};
    bind_new_type(L, IMAGE, methods, meta,
                  "An RGB image from render.image, render.plot, render.field or render.points.");
    static const bind_fn fns[] = {
        {"png", l_png,
         "render.png(scene, 'file.png', { width = 1024, height =, color = 'grain'|'speed'|"
         "'rotation'|'material'|'clump'|{values}, colormap = 'viridis'|'gray', range = {lo, "
         "hi}, show = "
         "{'force_chains', 'rotation', 'colorbar', 'box', 'displacement'}, title =, "
         "stamp = true|'text', displacement = { affine = {{..}, {..}}, center = {x, y}, scale = "
         "k }, "
         "label =, walls = true|false|{{point =, normal =}, ...}, frame = n, camera = { "
         "azimuth = -60, "
         "elevation = 25, projection = 'orthographic'|'perspective', fov = 30 } })",
         "Draws a DEM scene into a PNG written whole (temporary file + rename): 2D disks, or 3D "
         "shaded spheres seen by `camera` (degrees; up is against gravity). Width 1024 "
         "by default, height from the box's aspect; sizes in [16, 8192] pixels. color: grain "
         "(well-separated colours by id), speed |v|, rotation (omega), material, clump (one "
         "colour per clump, shared by its members; loose grains each their own), or an array "
         "with one number per grain, through the colour map with limits range (default: min and "
         "max). "
         "walls (default true): the scene's walls where they are now (removed ones not), "
         "planes clipped to the box: in 2D a thick line on the wall's outer side, in 3D the "
         "outline of the wall's section of the box, drawn with the box's edges behind the "
         "grains; polylines and circles (2D) a line along the surface over the grains; meshes "
         "and cylinders (3D) their triangles' edges, rims and four lines along the axis behind "
         "the grains; false: none; an array: those planes instead. "
         "show (default box, colorbar): force_chains draws segments between contacting "
         "centres, width and shade proportional to the normal force; rotation a radius line at "
         "each grain's angle (integrated from omega between frames); displacement arrows of the displacement since s:set_reference() less the "
         "affine field affine . (X_ref - center) (Padbidri Figs. 2.6-2.7), k scene metres per "
         "metre (default: longest arrow three mean radii) with a reference arrow; colorbar a bar with ticks and `label`. stamp = true writes the scene time. "
         "A file name with a frame number ('out/frame_%05d.png'; %% for a percent sign) takes "
         "opts.frame, or else counts 0, 1, 2... per pattern, so it suits run{ every =, on_step "
         "= function(s) render.png(s, 'out/f_%05d.png') end }. Returns the file name written."},
        {"image", l_image, "render.image(scene, opts)",
         "Draws like render.png (same options) and returns a render.image: img:size(), "
         "img:pixel(x, y), img:save(path)."},
        {"plot", l_plot,
         "render.plot{ file =, width = 800, height = 560, title =, xlabel =, ylabel =, xlog = "
         "false, ylog = false, series = { { x = {...}, y = {...}, label =, style = 'line'|"
         "'points'|'both'|'none' }, ... } }",
         "A line plot with nice ticks (decades on log axes), grid, labels and a legend of the "
         "labelled series. A 'none' series is not drawn; it only widens the axes. NaN in a "
         "series breaks its line. Writes file (PNG, whole) and returns its name, or without "
         "file returns a render.image."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"png", NULL, SCENE_OPTS_FIELDS},
                                            {"image", NULL, SCENE_OPTS_FIELDS},
                                            {"plot", NULL, PLOT_FIELDS},
                                            {NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    bind_open_render_fields(L, lua_gettop(L));
    bind_doc(L, -1, "render", "render",
             "Headless images: frames of DEM scenes (OSMesa, anti-aliased), grid fields and point "
             "clouds (MPM, DSMC), colour maps, text, colour bars and line plots, written as PNG.");
    lua_setglobal(L, "render");
}
