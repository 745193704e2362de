/* render.coarse_grain: the fields of analysis.coarse_grain (or avg:fields()) drawn as a PNG by
 * render_cg (src/render/cg.c): options, the fields' grid, the values shown, arrows and glyphs. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lua/lua_coarse_grain.h"
#include "lua/lua_render.h"
#include "render/cg.h"

static const char *const RCG_FIELDS[] = {
    "file",        "show",     "tensor",        "glyphs", "glyph_every", "arrows",
    "arrow_every", "colormap", "interpolation", "range",  "width",       "height",
    "title",       "label",    "colorbar",      "box",    NULL};
static const char *const SHOWS[] = {
    "psd",     "pressure", "major",       "minor",           "xx",           "xy",   "yx", "yy",
    "density", "speed",    "temperature", "volume_fraction", "displacement", "none", NULL};
static const char *const TENSORS[] = {"stress", "contact", "kinetic", "internal", "fabric", NULL};
static const char *const ARROWS[] = {"velocity", "displacement", NULL};
static const char *const CMAPS[] = {"viridis", "gray", NULL};
static const char *const INTERP[] = {"nearest", "bilinear", NULL};

static int l_image_gc(lua_State *L)
{
    render_image_free(lua_touserdata(L, 1));
    return 0;
}

/* "bad argument #1 to 'coarse_grain' (fields of analysis.coarse_grain expected, WHY)" */
static int fields_error(lua_State *L, const char *call, const char *why)
{
    return luaL_error(L,
                      "bad argument #1 to '%s' (the fields of analysis.coarse_grain (a grid) "
                      "expected, %s)",
                      call, why);
}

/* The array t[key] (t at tab, or t[key1][key2] when key2) of exactly n numbers or NaN, as a
 * userdata buffer left on the stack. */
static double *fields_array(lua_State *L, int tab, const char *key1, const char *key2, size_t n,
                            const char *call)
{
    char name[64];
    snprintf(name, sizeof name, "%s%s%s", key1, key2 ? "." : "", key2 ? key2 : "");
    char why[160];
    lua_getfield(L, tab, key1);
    if (key2) {
        if (!lua_istable(L, -1)) {
            snprintf(why, sizeof why, "no table '%s'", key1);
            fields_error(L, call, why);
        }
        lua_getfield(L, -1, key2);
        lua_remove(L, -2);
    }
    if (!lua_istable(L, -1) || lua_rawlen(L, -1) != n) {
        snprintf(why, sizeof why, "no array '%s' of %d numbers", name, (int)n);
        fields_error(L, call, why);
    }
    double *v = lua_newuserdatauv(L, (n ? n : 1) * sizeof *v, 0);
    lua_insert(L, -2);
    for (size_t k = 0; k < n; k++) {
        lua_rawgeti(L, -1, (lua_Integer)k + 1);
        v[k] = lua_tonumber(L, -1);
        if (lua_type(L, -1) != LUA_TNUMBER || isinf(v[k]) || fabs(v[k]) > 1e100) {
            snprintf(why, sizeof why, "a number (or NaN) at entry %d of '%s'", (int)k + 1, name);
            fields_error(L, call, why);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    return v;
}

/* What render.coarse_grain draws: the renderer's definition, and the options that choose what is
 * read from the fields and where the image goes. */
typedef struct rcg_plot {
    render_cg_def d;
    const char *file, *label;
    int show, tensor, glyphs, every, arrows;
    char autolabel[96]; /* the colour bar's label when `label` is not given */
} rcg_plot;

/* The options (argument #2) into p, in the order the usage line lists them. */
static void read_options(lua_State *L, const char *call, rcg_plot *p)
{
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, RCG_FIELDS);
    p->file = bind_field_path(L, 2, call, "file", BIND_REQUIRED);
    p->show = bind_field_option(L, 2, call, "show", SHOWS, 0, 0);
    p->tensor = bind_field_option(L, 2, call, "tensor", TENSORS, 0, 0);
    const int invariant = p->show <= 3;
    p->glyphs = bind_field_boolean(L, 2, call, "glyphs", invariant);
    p->every = (int)bind_field_integer(L, 2, call, "glyph_every", 0, 0, 100000, 0);
    p->arrows = bind_field_option(L, 2, call, "arrows", ARROWS, -1, 0);
    p->d = render_default_cg_def();
    render_cg_def *d = &p->d;
    d->field.arrow_every = (int)bind_field_integer(L, 2, call, "arrow_every", 0, 0, 100000, 0);
    d->field.colormap =
        (render_colormap)bind_field_option(L, 2, call, "colormap", CMAPS, RENDER_VIRIDIS, 0);
    d->field.interp =
        (render_interp)bind_field_option(L, 2, call, "interpolation", INTERP, RENDER_NEAREST, 0);
    if (lua_getfield(L, 2, "range") != LUA_TNIL) {
        int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == 2;
        for (int k = 0; ok && k < 2; k++) {
            lua_rawgeti(L, -1, k + 1);
            int isnum;
            d->field.range[k] = lua_tonumberx(L, -1, &isnum);
            ok = isnum && lua_type(L, -1) == LUA_TNUMBER && fabs(d->field.range[k]) <= 1e100;
            lua_pop(L, 1);
        }
        if (!ok || !(d->field.range[0] < d->field.range[1]))
            bind_field_error(L, 2, call, "range", "{lo, hi} with lo < hi");
    }
    lua_pop(L, 1);
    d->field.width =
        (int)bind_field_integer(L, 2, call, "width", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    d->field.height =
        (int)bind_field_integer(L, 2, call, "height", 0, RENDER_MIN_SIZE, RENDER_MAX_SIZE, 0);
    d->field.title = bind_field_string(L, 2, call, "title", NULL, 0);
    p->label = bind_field_string(L, 2, call, "label", NULL, 0);
    d->field.colorbar = bind_field_boolean(L, 2, call, "colorbar", 1);
    d->field.box = bind_field_boolean(L, 2, call, "box", 1);
    if (p->show == 13 && p->arrows < 0 && !p->glyphs) {
        lua_getfield(L, 2, "show");
        bind_field_error(L, 2, call, "show", "a field ('none' draws arrows or glyphs only)");
    }
}

/* The grid of the fields (argument #1): cells and region of a 2D grid (3D: one layer in z) into
 * d; returns the number of cells. */
static size_t read_grid(lua_State *L, const char *call, render_cg_def *d)
{
    lua_getfield(L, 1, "dim");
    const lua_Integer dim = lua_tointeger(L, -1);
    lua_pop(L, 1);
    if (dim != 2 && dim != 3)
        fields_error(L, call, "no dim 2 or 3");
    int cells[3] = {1, 1, 1};
    if (lua_getfield(L, 1, "cells") != LUA_TTABLE || lua_rawlen(L, -1) != (size_t)dim)
        fields_error(L, call, "no 'cells' (fields at points cannot be drawn)");
    for (int a = 0; a < dim; a++) {
        lua_rawgeti(L, -1, a + 1);
        int isint;
        lua_Integer v = lua_tointegerx(L, -1, &isint);
        if (!isint || v < 1 || v > 100000)
            fields_error(L, call, "'cells' of positive integers");
        cells[a] = (int)v;
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    if (dim == 3 && cells[2] != 1)
        fields_error(L, call, "a 2D grid (3D: one layer of cells in z)");
    double lo[3], hi[3];
    if (lua_getfield(L, 1, "region") != LUA_TTABLE || lua_rawlen(L, -1) != 2)
        fields_error(L, call, "no 'region'");
    for (int c = 0; c < 2; c++) {
        lua_rawgeti(L, -1, c + 1);
        for (int a = 0; a < 2; a++) {
            lua_rawgeti(L, -1, a + 1);
            int isnum;
            (c ? hi : lo)[a] = lua_tonumberx(L, -1, &isnum);
            if (!isnum || !isfinite((c ? hi : lo)[a]))
                fields_error(L, call, "'region' of finite corners");
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    const size_t n = (size_t)cells[0] * (size_t)cells[1];
    d->field.nx = cells[0];
    d->field.ny = cells[1];
    d->field.extent[0][0] = lo[0];
    d->field.extent[0][1] = lo[1];
    d->field.extent[1][0] = hi[0];
    d->field.extent[1][1] = hi[1];
    return n;
}

/* The values shown (field `show`, of `tensor` for its components and invariants) and their
 * automatic label; the arrays stay on the stack. */
static void read_values(lua_State *L, const char *call, rcg_plot *p, size_t n)
{
    render_cg_def *d = &p->d;
    const int show = p->show, tensor = p->tensor;
    static const char *const names[14] = {"principal difference",
                                          "pressure",
                                          "major principal value",
                                          "minor principal value",
                                          "xx",
                                          "xy",
                                          "yx",
                                          "yy",
                                          "density (kg/m^3)",
                                          "speed (m/s)",
                                          "granular temperature (m^2/s^2)",
                                          "volume fraction",
                                          "displacement (m)",
                                          ""};
    if (show <= 7) {
        d->field.values = fields_array(L, 1, TENSORS[tensor], SHOWS[show], n, call);
        if (tensor == 0 && show <= 3) {
            static const char *const stress[4] = {"principal stress difference", "pressure",
                                                  "major principal stress",
                                                  "minor principal stress"};
            snprintf(p->autolabel, sizeof p->autolabel, "%s (Pa)", stress[show]);
        } else {
            snprintf(p->autolabel, sizeof p->autolabel, "%s%s: %s%s", TENSORS[tensor],
                     tensor == 1 || tensor == 2 || tensor == 3 ? " stress" : "", names[show],
                     tensor == 4 ? "" : " (Pa)");
        }
    } else if (show == 8 || show == 10 || show == 11) {
        d->field.values = fields_array(L, 1, SHOWS[show], NULL, n, call);
        snprintf(p->autolabel, sizeof p->autolabel, "%s", names[show]);
    } else if (show == 9 || show == 12) {
        const char *vec = show == 9 ? "velocity" : "displacement";
        double *vx = fields_array(L, 1, vec, "x", n, call);
        double *vy = fields_array(L, 1, vec, "y", n, call);
        double *m = lua_newuserdatauv(L, n * sizeof *m, 0);
        for (size_t k = 0; k < n; k++)
            m[k] = hypot(vx[k], vy[k]);
        d->field.values = m;
        snprintf(p->autolabel, sizeof p->autolabel, "%s", names[show]);
    }
    d->field.colorbar_label = p->label ? p->label : p->autolabel;
}

/* The arrows (a vector field) and glyphs (the tensor's major direction) drawn over the values. */
static void read_overlays(lua_State *L, const char *call, rcg_plot *p, size_t n)
{
    render_cg_def *d = &p->d;
    const int tensor = p->tensor, arrows = p->arrows, glyphs = p->glyphs, every = p->every;
    if (arrows >= 0) {
        d->field.arrows[0] = fields_array(L, 1, ARROWS[arrows], "x", n, call);
        d->field.arrows[1] = fields_array(L, 1, ARROWS[arrows], "y", n, call);
        d->field.arrow_unit = arrows == 0 ? "m/s" : "m";
    }
    if (glyphs) {
        double *dx = fields_array(L, 1, TENSORS[tensor], "dx", n, call);
        double *dy = fields_array(L, 1, TENSORS[tensor], "dy", n, call);
        double *ang = lua_newuserdatauv(L, n * sizeof *ang, 0);
        for (size_t k = 0; k < n; k++)
            ang[k] = atan2(dy[k], dx[k]);
        d->glyph_angle = ang;
        d->glyph_value = fields_array(L, 1, TENSORS[tensor], "psd", n, call);
        d->glyph_every = every;
    }
}

/* Renders p, writes the PNG and pushes { file, width, height, range }. */
static int draw(lua_State *L, const char *call, rcg_plot *p)
{
    const render_cg_def *d = &p->d;
    const char *file = p->file;
    render_context *rc = bind_render_context(L, call);
    render_image *img = lua_newuserdatauv(L, sizeof *img, 0);
    memset(img, 0, sizeof *img);
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, l_image_gc);
    lua_setfield(L, -2, "__gc");
    lua_setmetatable(L, -2);
    core_error err;
    render_view view;
    if (render_cg(rc, d, img, &view, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    if (render_write_png(img, file, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, img->width);
    lua_setfield(L, -2, "width");
    lua_pushinteger(L, img->height);
    lua_setfield(L, -2, "height");
    lua_createtable(L, 2, 0);
    for (int k = 0; k < 2; k++) {
        lua_pushnumber(L, view.range[k]);
        lua_rawseti(L, -2, k + 1);
    }
    lua_setfield(L, -2, "range");
    lua_pushstring(L, file);
    lua_setfield(L, -2, "file");
    return 1;
}

static int l_render_cg(lua_State *L)
{
    const char *call = "coarse_grain";
    lua_settop(L, 2);
    if (!lua_istable(L, 1))
        return bind_arg_error(L, 1, call, "table (the fields of analysis.coarse_grain)");
    rcg_plot p;
    memset(&p, 0, sizeof p);
    read_options(L, call, &p);
    const size_t n = read_grid(L, call, &p.d);
    read_values(L, call, &p, n);
    read_overlays(L, call, &p, n);
    return draw(L, call, &p);
}

void bind_open_coarse_grain_render(lua_State *L)
{
    static const bind_fn render_fns[] = {
        {"coarse_grain", l_render_cg,
         "render.coarse_grain(fields, { file =, show = 'psd', tensor = 'stress', glyphs =, "
         "glyph_every =, arrows = 'velocity'|'displacement', arrow_every =, colormap = "
         "'viridis', interpolation = 'nearest', range =, width =, height =, title =, label =, "
         "colorbar = true, box = true })",
         "Draws the fields of analysis.coarse_grain (or avg:fields(); a grid, 2D or one layer "
         "of a 3D one) as a PNG, written whole: show = 'psd', 'pressure', 'major', 'minor' or a "
         "component 'xx', 'xy', 'yx', 'yy' of `tensor` ('stress', 'contact', 'kinetic', "
         "'internal', 'fabric'), or 'density', 'speed', 'temperature', 'volume_fraction', "
         "'displacement' (magnitude), or 'none'. glyphs (default: when an invariant is shown): "
         "a segment along the tensor's major principal direction in every glyph_every-th cell, "
         "its length proportional to the principal difference. arrows: the velocity or "
         "displacement field. Returns { file, width, height, range }."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields render_fields[] = {{"coarse_grain", NULL, RCG_FIELDS},
                                                {NULL, NULL, NULL}};
    lua_getglobal(L, "render");
    bind_register(L, -1, render_fns);
    bind_register_fields(L, -1, render_fields);
    lua_pop(L, 1);
}
