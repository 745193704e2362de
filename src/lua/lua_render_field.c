/* render.field and render.points of the Lua module `render`: grid fields and point clouds on
 * plain arrays (MPM, DSMC). Translates and checks arguments, calls src/render, raises its errors
 * named after the call. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lua/bind.h"
#include "lua/lua_render.h"
#include "render/render.h"

/* luaL_error with C's printf formats (lua_pushfstring has no %lld nor %zu). */
static int fail_printf(lua_State *L, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return luaL_error(L, "%s", msg);
}

static const char *const INTERPS[] = {"nearest", "bilinear", NULL};

/* The grid's shape: from nx and ny when given, else from the first array of rows read. */
typedef struct grid_shape {
    lua_Integer nx, ny;
} grid_shape;

enum { GRID_NUMBERS, GRID_FLAGS };

/* Checks entry v (on top of the stack) of an array of numbers (NaN allowed: no value) or flags
 * (booleans) and stores it; where: " at entry 5" or " at row 2, entry 3". */
static void grid_entry(lua_State *L, const char *call, const char *name, int kind, void *out,
                       size_t k, const char *where)
{
    if (kind == GRID_FLAGS) {
        if (lua_type(L, -1) == LUA_TBOOLEAN) {
            ((unsigned char *)out)[k] = (unsigned char)lua_toboolean(L, -1);
            return;
        }
    } else if (lua_type(L, -1) == LUA_TNUMBER) {
        double v = lua_tonumber(L, -1);
        if (isnan(v) || fabs(v) <= 1e100) {
            ((double *)out)[k] = v;
            return;
        }
    }
    char got[64];
    bind_describe(L, -1, got, sizeof got);
    fail_printf(L, "bad field '%s' in argument #1 to '%s' (%s expected, got %s%s)", name, call,
                kind == GRID_FLAGS ? "booleans"
                : lua_type(L, -1) == LUA_TNUMBER && !isinf(lua_tonumber(L, -1))
                    ? "numbers (NaN for no value) of magnitude at most 1e+100"
                    : "numbers (NaN for no value)",
                got, where);
}

/* Reads field key of the table at tbl (named name in errors: "values", "arrows.u") as nx * ny
 * cells: a flat array, row-major from the bottom row (needs nx and ny), or an array of ny rows of
 * nx entries each (the first row at the bottom). The buffer is a userdata left on the stack;
 * NULL (nothing pushed) when the field is absent. */
static void *read_grid(lua_State *L, int tbl, const char *key, const char *name, const char *call,
                       grid_shape *g, int kind)
{
    if (lua_getfield(L, tbl, key) == LUA_TNIL) {
        lua_pop(L, 1);
        return NULL;
    }
    const char *kinds = kind == GRID_FLAGS ? "booleans" : "numbers";
    char what[160];
    snprintf(what, sizeof what, "array of %s, or array of rows", kinds);
    if (!lua_istable(L, -1))
        bind_field_error(L, 1, call, name, what);
    int arr = lua_gettop(L);
    size_t len = lua_rawlen(L, arr);
    int rows = len > 0 && lua_rawgeti(L, arr, 1) == LUA_TTABLE;
    size_t width = rows ? lua_rawlen(L, -1) : 0;
    if (len > 0)
        lua_pop(L, 1);
    if (len == 0)
        bind_field_error(L, 1, call, name, what);
    if (rows) {
        if (g->ny && (lua_Integer)len != g->ny)
            fail_printf(L, "bad field '%s' in argument #1 to '%s' (%lld rows expected, got %zu "
                          "rows)", name, call, (long long)g->ny, len);
        if (g->nx && (lua_Integer)width != g->nx)
            fail_printf(L, "bad field '%s' in argument #1 to '%s' (rows of %lld entries expected, "
                          "got %zu at row 1)", name, call, (long long)g->nx, width);
        if (width == 0)
            fail_printf(L, "bad field '%s' in argument #1 to '%s' (non-empty rows expected, got "
                          "an empty row 1)", name, call);
        g->ny = (lua_Integer)len;
        g->nx = (lua_Integer)width;
    } else {
        if (!g->nx || !g->ny) {
            lua_pushnil(L);
            bind_field_error(L, 1, call, g->nx ? "ny" : "nx",
                             "positive integer (with a flat array of cells)");
        }
        if (len % (size_t)g->ny != 0 || (lua_Integer)(len / (size_t)g->ny) != g->nx)
            fail_printf(L, "bad field '%s' in argument #1 to '%s' (nx * ny = %lld %s expected, "
                          "got %zu)", name, call, (long long)(g->nx * g->ny), kinds, len);
    }
    size_t n = (size_t)g->nx * (size_t)g->ny, esize = kind == GRID_FLAGS ? 1 : sizeof(double);
    void *out = lua_newuserdatauv(L, n * esize, 0);
    lua_insert(L, arr); /* below the array */
    arr++;
    char where[64];
    if (!rows) {
        for (size_t k = 0; k < n; k++) {
            lua_rawgeti(L, arr, (lua_Integer)k + 1);
            snprintf(where, sizeof where, " at entry %zu", k + 1);
            grid_entry(L, call, name, kind, out, k, where);
            lua_pop(L, 1);
        }
    } else {
        for (lua_Integer j = 0; j < g->ny; j++) {
            int t = lua_rawgeti(L, arr, j + 1);
            if (t != LUA_TTABLE || (lua_Integer)lua_rawlen(L, -1) != g->nx) {
                char got[64];
                bind_describe(L, -1, got, sizeof got);
                if (t == LUA_TTABLE)
                    snprintf(got, sizeof got, "%zu", (size_t)lua_rawlen(L, -1));
                fail_printf(L, "bad field '%s' in argument #1 to '%s' (rows of %lld %s expected, "
                              "got %s at row %lld)", name, call, (long long)g->nx, kinds, got,
                           (long long)j + 1);
            }
            for (lua_Integer i = 0; i < g->nx; i++) {
                lua_rawgeti(L, -1, i + 1);
                snprintf(where, sizeof where, " at row %lld, entry %lld", (long long)j + 1,
                         (long long)i + 1);
                grid_entry(L, call, name, kind, out, (size_t)(j * g->nx + i), where);
                lua_pop(L, 1);
            }
            lua_pop(L, 1);
        }
    }
    lua_pop(L, 1); /* the array; the buffer stays */
    return out;
}

/* extent = {{x0, y0}, {x1, y1}}; returns 0 when absent. */
static int read_extent(lua_State *L, int arg, const char *call, double e[2][2])
{
    if (lua_getfield(L, arg, "extent") == LUA_TNIL) {
        lua_pop(L, 1);
        return 0;
    }
    int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == 2;
    for (int c = 0; ok && c < 2; c++) {
        ok = lua_rawgeti(L, -1, c + 1) == LUA_TTABLE && lua_rawlen(L, -1) == 2;
        for (int d = 0; ok && d < 2; d++) {
            lua_rawgeti(L, -1, d + 1);
            int isnum;
            e[c][d] = lua_tonumberx(L, -1, &isnum);
            ok = isnum && lua_type(L, -1) == LUA_TNUMBER && isfinite(e[c][d]);
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    if (!ok || !(e[1][0] > e[0][0]) || !(e[1][1] > e[0][1]))
        bind_field_error(L, arg, call, "extent", "{{x0, y0}, {x1, y1}} with x0 < x1 and y0 < y1");
    lua_pop(L, 1);
    return 1;
}

/* stamp = 'text' */
static const char *read_stamp(lua_State *L, int arg, const char *call)
{
    return bind_field_string(L, arg, call, "stamp", NULL, 0);
}

/* arrows = { u = {...}, v = {...}, scale = k, every = n, unit = 'm/s' } */
static void read_field_arrows(lua_State *L, const char *call, grid_shape *g, render_field_def *d)
{
    static const char *const keys[] = {"u", "v", "scale", "every", "unit", NULL};
    int t = lua_getfield(L, 1, "arrows");
    if (t == LUA_TNIL) {
        lua_pop(L, 1);
        return;
    }
    if (t != LUA_TTABLE)
        bind_field_error(L, 1, call, "arrows", "table { u = {...}, v = {...}, scale =, every =, "
                                               "unit = }");
    int a = lua_gettop(L);
    lua_pushnil(L);
    while (lua_next(L, a)) {
        lua_pop(L, 1);
        int known = 0;
        for (int k = 0; keys[k]; k++)
            known |= lua_type(L, -1) == LUA_TSTRING && !strcmp(lua_tostring(L, -1), keys[k]);
        if (!known) {
            char key[64];
            bind_describe(L, -1, key, sizeof key);
            fail_printf(L, "bad field 'arrows' in argument #1 to '%s' (unknown key %s; valid keys: "
                          "u, v, scale, every, unit)", call, key);
        }
    }
    /* the buffers go below the arrows table, which stays on top until the end */
    d->arrows[0] = read_grid(L, a, "u", "arrows.u", call, g, GRID_NUMBERS);
    if (d->arrows[0])
        lua_insert(L, a++);
    d->arrows[1] = read_grid(L, a, "v", "arrows.v", call, g, GRID_NUMBERS);
    if (d->arrows[1])
        lua_insert(L, a++);
    if (!d->arrows[0] || !d->arrows[1]) {
        lua_pushnil(L);
        bind_field_error(L, 1, call, d->arrows[0] ? "arrows.v" : "arrows.u",
                         "array of numbers, or array of rows");
    }
    if (lua_getfield(L, a, "scale") != LUA_TNIL) {
        double k = lua_tonumber(L, -1);
        if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(k) || k <= 0)
            bind_field_error(L, 1, call, "arrows.scale", "positive number");
        d->arrow_scale = k;
    }
    lua_pop(L, 1);
    if (lua_getfield(L, a, "every") != LUA_TNIL) {
        int isint;
        lua_Integer k = lua_tointegerx(L, -1, &isint);
        if (!isint || lua_type(L, -1) != LUA_TNUMBER || k < 1 || k > INT32_MAX)
            bind_field_error(L, 1, call, "arrows.every", "positive integer");
        d->arrow_every = (int)k;
    }
    lua_pop(L, 1);
    t = lua_getfield(L, a, "unit");
    if (t == LUA_TSTRING)
        d->arrow_unit = lua_tostring(L, -1); /* alive in the arrows table */
    else if (t != LUA_TNIL)
        bind_field_error(L, 1, call, "arrows.unit", "string");
    lua_pop(L, 2);
}

/* Draws into a new render.image on the stack; writes it when file is given. */
static int finish_image(lua_State *L, render_image *img, int idx, const char *file, long frame,
                        const char *call)
{
    if (!file) {
        lua_pushvalue(L, idx);
        return 1;
    }
    return bind_write_image(L, img, file, frame, call);
}

/* render.field{...} */
static const char *const FIELD_FIELDS[] = {
    "file",   "frame", "width",      "height",        "values",   "nx",    "ny",
    "extent", "mask",  "background", "interpolation", "colormap", "range", "colorbar",
    "box",    "title", "stamp",      "label",         "arrows",   NULL};

static int l_field(lua_State *L)
{
    const char *call = "field";
    lua_settop(L, 1);
    bind_check_table(L, 1, call);
    bind_check_fields(L, 1, call, FIELD_FIELDS);
    render_field_def d = render_default_field_def();
    const char *file = bind_field_path(L, 1, call, "file", 0);
    long frame = (long)bind_field_integer(L, 1, call, "frame", -1, 0, LUA_MAXINTEGER, 0);
    d.width = (int)bind_field_integer(L, 1, call, "width", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    d.height = (int)bind_field_integer(L, 1, call, "height", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE,
                                       0);
    grid_shape g;
    g.nx = bind_field_integer(L, 1, call, "nx", 0, 1, LUA_MAXINTEGER, 0);
    g.ny = bind_field_integer(L, 1, call, "ny", 0, 1, LUA_MAXINTEGER, 0);
    if (g.nx > INT32_MAX || g.ny > INT32_MAX) {
        lua_getfield(L, 1, g.nx > INT32_MAX ? "nx" : "ny");
        bind_field_error(L, 1, call, g.nx > INT32_MAX ? "nx" : "ny", "integer in [1, 2147483647]");
    }
    d.values = read_grid(L, 1, "values", "values", call, &g, GRID_NUMBERS);
    read_field_arrows(L, call, &g, &d);
    if (!d.values && !d.arrows[0]) {
        lua_pushnil(L);
        bind_field_error(L, 1, call, "values", "array of numbers, or array of rows (or arrows)");
    }
    d.mask = read_grid(L, 1, "mask", "mask", call, &g, GRID_FLAGS);
    d.nx = (int)g.nx;
    d.ny = (int)g.ny;
    if (!read_extent(L, 1, call, d.extent)) {
        d.extent[1][0] = d.nx;
        d.extent[1][1] = d.ny;
    }
    if (lua_getfield(L, 1, "background") != LUA_TNIL) {
        int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == 3;
        unsigned char *bg = bind_buffer_below_top(L, 3);
        for (int c = 0; ok && c < 3; c++) {
            lua_rawgeti(L, -1, c + 1);
            int isint;
            lua_Integer v = lua_tointegerx(L, -1, &isint);
            ok = isint && lua_type(L, -1) == LUA_TNUMBER && v >= 0 && v <= 255;
            bg[c] = (unsigned char)v;
            lua_pop(L, 1);
        }
        if (!ok)
            bind_field_error(L, 1, call, "background", "{r, g, b} with integers in [0, 255]");
        d.background = bg;
    }
    lua_pop(L, 1);
    d.interp = (render_interp)bind_field_option(L, 1, call, "interpolation", INTERPS,
                                                RENDER_NEAREST, 0);
    d.colormap = (render_colormap)bind_field_option(L, 1, call, "colormap", bind_render_colormaps,
                                                    RENDER_VIRIDIS, 0);
    bind_read_range(L, 1, call, d.range);
    d.colorbar = bind_field_boolean(L, 1, call, "colorbar", 1);
    d.box = bind_field_boolean(L, 1, call, "box", 1);
    d.title = bind_field_string(L, 1, call, "title", NULL, 0);
    d.stamp = read_stamp(L, 1, call);
    d.colorbar_label = bind_field_string(L, 1, call, "label", NULL, 0);
    render_context *rc = bind_render_context(L, call);
    render_image *img = bind_push_image(L); /* freed by __gc even if an error follows */
    int idx = lua_gettop(L);
    core_error err;
    if (render_field(rc, &d, img, NULL, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    size_t shown = 0, ncell = (size_t)d.nx * (size_t)d.ny;
    for (size_t k = 0; d.values && k < ncell; k++)
        shown += (!d.mask || d.mask[k]) && isfinite(d.values[k]);
    if (d.values && !shown && progress_default_style() != PROGRESS_QUIET)
        fprintf(stderr, "grainlab: warning: field: all %zu values are NaN%s; the image says so "
                        "instead of showing colours\n", ncell, d.mask ? " or masked" : "");
    return finish_image(L, img, idx, file, frame, call);
}

/* An array of n finite numbers (n == (size_t)-1: any length, set here) as a userdata buffer left
 * on the stack; with nan, NaN entries are accepted. */
static double *read_numbers(lua_State *L, const char *call, const char *name, size_t *n, int nan,
                            const char *same_as)
{
    char what[96];
    if (*n == (size_t)-1)
        snprintf(what, sizeof what, "array of finite numbers");
    else
        snprintf(what, sizeof what, "array as long as '%s' (%zu)", same_as, *n);
    if (lua_getfield(L, 1, name) != LUA_TTABLE)
        bind_field_error(L, 1, call, name, what);
    int arr = lua_gettop(L);
    size_t len = lua_rawlen(L, arr);
    if (*n != (size_t)-1 && len != *n)
        bind_field_error(L, 1, call, name, what);
    double *v = lua_newuserdatauv(L, (len ? len : 1) * sizeof *v, 0);
    lua_insert(L, arr);
    arr++;
    for (size_t i = 0; i < len; i++) {
        lua_rawgeti(L, arr, (lua_Integer)i + 1);
        v[i] = lua_tonumber(L, -1);
        if (lua_type(L, -1) != LUA_TNUMBER || isinf(v[i]) || (!nan && isnan(v[i])) ||
            fabs(v[i]) > 1e100) {
            char got[64];
            bind_describe(L, -1, got, sizeof got);
            fail_printf(L,
                        "bad field '%s' in argument #1 to '%s' (%s%s expected, got %s at entry "
                        "%zu)",
                        name, call, nan ? "numbers (NaN: grey)" : "finite numbers",
                        fabs(v[i]) > 1e100 && isfinite(v[i]) ? " of magnitude at most 1e+100" : "",
                        got, i + 1);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    *n = len;
    return v;
}

/* render.points{...} */
static const char *const POINTS_FIELDS[] = {
    "file",     "frame", "width",    "height", "x",     "y",     "values", "size", "extent",
    "colormap", "range", "colorbar", "box",    "title", "stamp", "label",  NULL};

static int l_points(lua_State *L)
{
    const char *call = "points";
    lua_settop(L, 1);
    bind_check_table(L, 1, call);
    bind_check_fields(L, 1, call, POINTS_FIELDS);
    render_points_def d = render_default_points_def();
    const char *file = bind_field_path(L, 1, call, "file", 0);
    long frame = (long)bind_field_integer(L, 1, call, "frame", -1, 0, LUA_MAXINTEGER, 0);
    d.width = (int)bind_field_integer(L, 1, call, "width", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    d.height = (int)bind_field_integer(L, 1, call, "height", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE,
                                       0);
    size_t n = (size_t)-1;
    d.x = read_numbers(L, call, "x", &n, 0, NULL);
    d.y = read_numbers(L, call, "y", &n, 0, "x");
    if (lua_getfield(L, 1, "values") != LUA_TNIL) {
        lua_pop(L, 1);
        d.values = read_numbers(L, call, "values", &n, 1, "x");
    } else {
        lua_pop(L, 1);
    }
    d.n = n;
    if (lua_getfield(L, 1, "size") != LUA_TNIL) {
        double v = lua_tonumber(L, -1);
        if (lua_type(L, -1) != LUA_TNUMBER || !(v > 0) || v > RENDER_MAX_SIZE)
            bind_field_error(L, 1, call, "size", "diameter in (0, 8192] pixels");
        d.size = v;
    }
    lua_pop(L, 1);
    read_extent(L, 1, call, d.extent);
    d.colormap = (render_colormap)bind_field_option(L, 1, call, "colormap", bind_render_colormaps,
                                                    RENDER_VIRIDIS, 0);
    bind_read_range(L, 1, call, d.range);
    d.colorbar = bind_field_boolean(L, 1, call, "colorbar", 1);
    d.box = bind_field_boolean(L, 1, call, "box", 1);
    d.title = bind_field_string(L, 1, call, "title", NULL, 0);
    d.stamp = read_stamp(L, 1, call);
    d.colorbar_label = bind_field_string(L, 1, call, "label", NULL, 0);
    render_context *rc = bind_render_context(L, call);
    render_image *img = bind_push_image(L);
    int idx = lua_gettop(L);
    core_error err;
    if (render_points(rc, &d, img, NULL, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    return finish_image(L, img, idx, file, frame, call);
}

/* render.field and render.points onto the render table at idx. */
void bind_open_render_fields(lua_State *L, int idx)
{
    static const bind_fn fns[] = {
        {"field", l_field,
         "render.field{ file =, frame =, width = 1024, height =, values = {...} or {{row 1}, "
         "...}, nx =, ny =, extent = {{x0, y0}, {x1, y1}}, mask = {booleans}, background = {r, g, b}, "
         "interpolation = "
         "'nearest'|'bilinear', colormap = 'viridis'|'gray', range = {lo, hi}, colorbar = true, "
         "box = true, title =, stamp =, label =, arrows = { u = {...}, v = {...}, scale = k, "
         "every = n, unit = 'm/s' } }",
         "A grid field (MPM, DSMC): nx x ny cells over extent (default {{0, 0}, {nx, ny}}), "
         "cell-centred, either a flat array row-major from the bottom row (cell (i, j) is "
         "values[j * nx + i + 1], i and j from 0; nx and ny needed) or an array of rows, the first "
         "row at the bottom (y0). Each pixel shows its cell's value (nearest) or the bilinear "
         "interpolation between cell centres, through the colour map with limits range (default: "
         "min and max), with a colour bar labelled `label`. NaN or mask false: no value, the "
         "cell shows `background` (0-255; default white). Principal stress difference: colormap = 'gray' (white = "
         "large). arrows: a vector (u, v) per cell, same layout, drawn from the cell centres "
         "every n-th cell (default: about 1.5 font sizes apart), k scene units per unit "
         "(default: the longest arrow 0.9 of the spacing), with a reference arrow labelled with "
         "`unit`; values may then be left out. Writes file (PNG, whole; frame patterns as in "
         "render.png) and returns its name, or without file returns a render.image."},
        {"points", l_points,
         "render.points{ file =, frame =, width = 1024, height =, x = {...}, y = {...}, values = "
         "{...}, size = 4, extent = {{x0, y0}, {x1, y1}}, colormap = 'viridis'|'gray', range = "
         "{lo, hi}, colorbar = true, box = true, title =, stamp =, label = }",
         "A point cloud (material points, DSMC particles): anti-aliased dots of diameter size "
         "pixels at (x[i], y[i]), in order (later on top), coloured by values through the colour "
         "map (NaN: grey; without values, one colour) with a colour bar. extent: the scene's "
         "rectangle (default: the points' bounding box padded by 2%); points outside it are not "
         "drawn. Writes file (PNG, whole; frame patterns as in render.png) and returns its name, "
         "or without file returns a render.image."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {
        {"field", NULL, FIELD_FIELDS}, {"points", NULL, POINTS_FIELDS}, {NULL, NULL, NULL}};
    bind_register(L, idx, fns);
    bind_register_fields(L, idx, fn_fields);
}
