/* VTK XML output for ParaView from Lua: s:write_vtk on DEM, MPM and DSMC scenes, mesh:write_vtk
 * on Delaunay meshes, and grainlab.vtk.series, a .pvd time series filled from on_step. Checks
 * the arguments and calls the exporters of each engine (dem/vtk.c, mpm/vtk.c, dsmc/vtk.c,
 * analysis/vtk.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"
#include "core/vtk.h"
#include "dem/dem.h"
#include "dsmc/dsmc.h"
#include "lua/bind.h"
#include "mpm/mpm.h"

static const char *SERIES = "grainlab.vtk.series";

enum { K_DEM, K_MPM, K_DSMC, K_NKINDS };
static const char *const KIND_NAMES[K_NKINDS] = {"dem.scene", "mpm.scene", "dsmc.scene"};

/* The kind of scene at idx, or -1. */
static int scene_kind(lua_State *L, int idx)
{
    for (int k = 0; k < K_NKINDS; k++)
        if (luaL_testudata(L, idx, KIND_NAMES[k]))
            return k;
    return -1;
}

/* ---- options --------------------------------------------------------------------------------- */
typedef struct write_opts {
    int contacts, walls, grid, cells, clumps; /* -1: not given (the kind's default) */
} write_opts;

/* The options of each kind's write_vtk (the very lists the calls check), and all of them for a
 * series, whose kind is known at its first frame only. */
static const char *const DEM_FIELDS[] = {"contacts", "walls", "clumps", NULL};
static const char *const MPM_FIELDS[] = {"grid", NULL};
static const char *const DSMC_FIELDS[] = {"cells", NULL};
static const char *const *const KIND_FIELDS[K_NKINDS] = {DEM_FIELDS, MPM_FIELDS, DSMC_FIELDS};
static const char *const OPT_FIELDS[] = {"contacts", "walls", "grid", "cells", "clumps", NULL};
/* Which kind each option belongs to. */
static const int OPT_KIND[] = {K_DEM, K_DEM, K_MPM, K_DSMC, K_DEM};

static write_opts read_opts(lua_State *L, int arg, const char *call, const char *const *fields)
{
    write_opts o = {-1, -1, -1, -1, -1};
    if (lua_isnoneornil(L, arg))
        return o;
    bind_check_table(L, arg, call);
    bind_check_fields(L, arg, call, fields);
    o.contacts = bind_field_boolean(L, arg, call, "contacts", -1);
    o.walls = bind_field_boolean(L, arg, call, "walls", -1);
    o.grid = bind_field_boolean(L, arg, call, "grid", -1);
    o.cells = bind_field_boolean(L, arg, call, "cells", -1);
    o.clumps = bind_field_boolean(L, arg, call, "clumps", -1);
    return o;
}

/* Refuses options given for another kind of scene (a typo-like mistake: they would do nothing). */
static void check_opts_kind(lua_State *L, const write_opts *o, int kind, const char *call)
{
    const int given[] = {o->contacts, o->walls, o->grid, o->cells, o->clumps};
    for (int k = 0; OPT_FIELDS[k]; k++)
        if (given[k] >= 0 && OPT_KIND[k] != kind)
            luaL_error(L, "%s: option '%s' is for a %s, not a %s", call, OPT_FIELDS[k],
                       KIND_NAMES[OPT_KIND[k]], KIND_NAMES[kind]);
}

/* ---- writing one frame ------------------------------------------------------------------------
 */
#define MAX_PARTS 4
#define PATH_MAX_LEN 4096

typedef struct part {
    const char *suffix; /* "" for the main file, else "contacts", "walls", "clumps", "grid",
                         * "cells" */
    const char *ext;    /* "vtu" or "vti" */
    char path[PATH_MAX_LEN];
} part;

/* stem[_suffix][_NNNN].ext */
static void part_path(lua_State *L, part *p, const char *stem, long frame, const char *call)
{
    char num[32] = "";
    if (frame > 0)
        snprintf(num, sizeof num, "_%04ld", frame);
    int len = snprintf(p->path, sizeof p->path, "%s%s%s%s.%s", stem, *p->suffix ? "_" : "",
                       p->suffix, num, p->ext);
    if (len < 0 || (size_t)len >= sizeof p->path)
        luaL_error(L, "%s: file name too long (%d characters)", call, len);
}

static void *scene_ptr(lua_State *L, int idx, int kind, const char *call)
{
    if (kind == K_DEM)
        return bind_check_dem_scene(L, idx, call);
    if (kind == K_MPM)
        return bind_check_mpm_scene(L, idx, call);
    return bind_check_dsmc_scene(L, idx, call);
}

static double scene_time(void *s, int kind)
{
    if (kind == K_DEM)
        return dem_time(s);
    if (kind == K_MPM)
        return mpm_time(s);
    return dsmc_time(s);
}

/* Writes the files of the scene at idx for stem and frame (0: no number); returns the number of
 * parts, with their names in parts[]. Raises kernel errors named after call. */
static int write_frame(lua_State *L, int idx, int kind, const char *stem, long frame,
                       const write_opts *o, const char *call, part parts[MAX_PARTS])
{
    void *s = scene_ptr(L, idx, kind, call);
    check_opts_kind(L, o, kind, call);
    int n = 0;
    parts[n++] = (part){.suffix = "", .ext = "vtu"};
    if (kind == K_DEM) {
        if (o->contacts != 0)
            parts[n++] = (part){.suffix = "contacts", .ext = "vtu"};
        if (o->walls > 0 || (o->walls < 0 && dem_wall_count(s) > 0))
            parts[n++] = (part){.suffix = "walls", .ext = "vtu"};
        if (o->clumps > 0 || (o->clumps < 0 && dem_clump_count(s) > 0))
            parts[n++] = (part){.suffix = "clumps", .ext = "vtu"};
    } else if (kind == K_MPM) {
        if (o->grid != 0)
            parts[n++] = (part){.suffix = "grid", .ext = "vti"};
    } else if (o->cells != 0) {
        parts[n++] = (part){.suffix = "cells", .ext = "vti"};
    }
    core_error err;
    core_error_clear(&err);
    for (int k = 0; k < n; k++) {
        part_path(L, &parts[k], stem, frame, call);
        const char *path = parts[k].path, *suf = parts[k].suffix;
        core_status st;
        if (kind == K_DEM)
            st = !*suf                      ? dem_vtk_particles(s, path, &err)
                 : !strcmp(suf, "contacts") ? dem_vtk_contacts(s, path, &err)
                 : !strcmp(suf, "clumps")   ? dem_vtk_clumps(s, path, &err)
                                            : dem_vtk_walls(s, path, &err);
        else if (kind == K_MPM)
            st = !*suf ? mpm_vtk_points(s, path, &err) : mpm_vtk_grid(s, path, &err);
        else
            st = !*suf ? dsmc_vtk_particles(s, path, &err) : dsmc_vtk_cells(s, path, &err);
        if (st)
            return bind_raise(L, call, &err);
    }
    return n;
}

/* The stem of a path that must end in ext ("foo/pile.vtu" -> "foo/pile"), in a buffer on the
 * stack; a Lua error otherwise. */
static const char *stem_of(lua_State *L, int arg, const char *ext, const char *call)
{
    const char *path = bind_arg_path(L, arg, call);
    size_t len = strlen(path), el = strlen(ext);
    if (len <= el || strcmp(path + len - el, ext) != 0) {
        char got[64], msg[128];
        bind_describe(L, arg, got, sizeof got);
        snprintf(msg, sizeof msg, "file name ending in %s expected, got %s", ext, got);
        luaL_argerror(L, arg, msg);
    }
    lua_pushlstring(L, path, len - el);
    return lua_tostring(L, -1);
}

static void push_paths(lua_State *L, const part *parts, int n)
{
    lua_createtable(L, n, 0);
    for (int k = 0; k < n; k++) {
        lua_pushstring(L, parts[k].path);
        lua_rawseti(L, -2, k + 1);
    }
}

/* s:write_vtk(path, opts), one function per scene type (help() keys its docs by function). */
static int write_vtk(lua_State *L, int kind)
{
    const char *call = "write_vtk";
    if (scene_kind(L, 1) != kind) {
        char got[64];
        bind_describe(L, 1, got, sizeof got);
        return luaL_error(L, "%s: a %s expected as self, got %s (call it as s:write_vtk(...))",
                          call, KIND_NAMES[kind], got);
    }
    write_opts o = read_opts(L, 3, call, KIND_FIELDS[kind]);
    const char *stem = stem_of(L, 2, ".vtu", call);
    part parts[MAX_PARTS];
    int n = write_frame(L, 1, kind, stem, 0, &o, call, parts);
    push_paths(L, parts, n);
    return 1;
}

static int l_dem_write_vtk(lua_State *L) { return write_vtk(L, K_DEM); }
static int l_mpm_write_vtk(lua_State *L) { return write_vtk(L, K_MPM); }
static int l_dsmc_write_vtk(lua_State *L) { return write_vtk(L, K_DSMC); }

/* ---- Delaunay meshes ------------------------------------------------------------------------- */
/* Calls mesh:method(scene [, opts]) and leaves the result table on the stack. */
static void call_method(lua_State *L, int mesh, const char *method, int scene, int opts)
{
    lua_getfield(L, mesh, method);
    lua_pushvalue(L, mesh);
    lua_pushvalue(L, scene);
    if (opts)
        lua_pushvalue(L, opts);
    lua_call(L, opts ? 3 : 2, 1);
}

/* Array field `name` of the table at t as n doubles into out (which has stride `stride`). */
static void get_array(lua_State *L, int t, const char *name, size_t n, double *out, int stride)
{
    lua_getfield(L, t, name);
    for (size_t c = 0; c < n; c++) {
        lua_rawgeti(L, -1, (lua_Integer)c + 1);
        out[c * (size_t)stride] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* The tensor arrays xx, xy, yx, yy of the table at t as n 3 x 3 row-major tensors (zz = 0). */
static void get_tensor(lua_State *L, int t, size_t n, double *out)
{
    static const char *const comp[4] = {"xx", "xy", "yx", "yy"};
    static const int slot[4] = {0, 1, 3, 4};
    memset(out, 0, 9 * n * sizeof *out);
    for (int q = 0; q < 4; q++)
        get_array(L, t, comp[q], n, out + slot[q], 9);
}

static double *scratch(lua_State *L, size_t n)
{
    double *p = lua_newuserdatauv(L, (n ? n : 1) * sizeof(double), 0);
    memset(p, 0, (n ? n : 1) * sizeof(double));
    return p;
}

static const char *const MESH_FIELDS[] = {"depth", "stress", "cells", NULL};

/* mesh:write_vtk(path, scene, { depth =, stress =, cells = { name = {...} } }) */
static int l_mesh_write_vtk(lua_State *L)
{
    const char *call = "write_vtk";
    luaL_checkudata(L, 1, "analysis.mesh");
    stem_of(L, 2, ".vtu", call); /* checks the name; the stem is not needed */
    lua_pop(L, 1);
    const char *path = lua_tostring(L, 2);
    dem_scene *s = bind_check_dem_scene(L, 3, call);
    if (dem_dim(s) != 2)
        return luaL_error(L, "%s: the Delaunay cells are 2D; this dem.scene is 3D", call);
    double depth = dem_thickness(s);
    int want_stress = -1, opts = 0, cells_t = 0;
    if (!lua_isnoneornil(L, 4)) {
        bind_check_table(L, 4, call);
        bind_check_fields(L, 4, call, MESH_FIELDS);
        depth = bind_field_number(L, 4, call, "depth", depth, BIND_POSITIVE);
        want_stress = bind_field_boolean(L, 4, call, "stress", -1);
        int t = lua_getfield(L, 4, "cells");
        if (t != LUA_TNIL && t != LUA_TTABLE)
            return bind_field_error(L, 4, call, "cells", "table of cell arrays");
        if (t == LUA_TTABLE)
            cells_t = lua_gettop(L);
        else
            lua_pop(L, 1);
    }
    if (want_stress > 0 && !(depth > 0))
        return luaL_error(L, "%s: give opts.depth (m): the scene has no thickness", call);
    int stress = want_stress < 0 ? depth > 0 : want_stress;
    if (stress) {
        lua_createtable(L, 0, 1);
        lua_pushnumber(L, depth);
        lua_setfield(L, -2, "depth");
        opts = lua_gettop(L);
    }

    call_method(L, 1, "cells", 3, 0);
    int cells = lua_gettop(L);
    lua_getfield(L, cells, "a");
    const size_t nc = lua_rawlen(L, -1);
    lua_pop(L, 1);
    long *tri = lua_newuserdatauv(L, (nc ? 3 * nc : 1) * sizeof *tri, 0);
    static const char *const corner[3] = {"a", "b", "c"};
    for (int q = 0; q < 3; q++) {
        lua_getfield(L, cells, corner[q]);
        for (size_t c = 0; c < nc; c++) {
            lua_rawgeti(L, -1, (lua_Integer)c + 1);
            tri[3 * c + (size_t)q] = (long)lua_tointeger(L, -1) - 1;
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    analysis_vtk_field fl[16];
    size_t nf = 0;
    double *area = scratch(L, nc);
    get_array(L, cells, "area", nc, area, 1);
    fl[nf++] = (analysis_vtk_field){"area", 1, area};

    call_method(L, 1, "strain", 3, 0);
    double *strain = scratch(L, 9 * nc);
    get_tensor(L, lua_gettop(L) - 1, nc, strain);
    fl[nf++] = (analysis_vtk_field){"strain", 9, strain};

    call_method(L, 1, "strain_rate", 3, 0);
    int sr = lua_gettop(L);
    double *grad = scratch(L, 9 * nc), *lii = scratch(L, nc);
    get_tensor(L, sr, nc, grad);
    get_array(L, sr, "lii", nc, lii, 1);
    fl[nf++] = (analysis_vtk_field){"velocity_gradient", 9, grad};
    fl[nf++] = (analysis_vtk_field){"lii", 1, lii};

    if (stress) {
        call_method(L, 1, "stress", 3, opts);
        int t = lua_gettop(L);
        double *sig = scratch(L, 9 * nc), *p = scratch(L, nc);
        get_tensor(L, t, nc, sig);
        get_array(L, t, "pressure", nc, p, 1);
        fl[nf++] = (analysis_vtk_field){"stress", 9, sig};
        fl[nf++] = (analysis_vtk_field){"pressure", 1, p};
    }
    if (cells_t) {
        lua_newtable(L); /* keeps the buffers alive */
        int holder = lua_gettop(L), nheld = 0;
        char what[96];
        snprintf(what, sizeof what, "array of %zu numbers", nc);
        lua_pushnil(L);
        while (lua_next(L, cells_t)) {
            if (lua_type(L, -2) != LUA_TSTRING) {
                lua_pushvalue(L, -2);
                return bind_field_error(L, 4, call, "cells", "table with string keys");
            }
            /* the key stays in the table, so its string outlives the loop */
            const char *name = lua_tostring(L, -2);
            char field[160];
            snprintf(field, sizeof field, "cells.%s", name);
            if (lua_type(L, -1) != LUA_TTABLE || lua_rawlen(L, -1) != nc)
                return bind_field_error(L, 4, call, field, what);
            if (nf == sizeof fl / sizeof fl[0])
                return luaL_error(L, "%s: at most %d extra cell arrays", call,
                                  (int)(sizeof fl / sizeof fl[0]) - 6);
            int vals = lua_gettop(L);
            double *v = scratch(L, nc);
            lua_rawseti(L, holder, ++nheld);
            for (size_t c = 0; c < nc; c++) {
                lua_rawgeti(L, vals, (lua_Integer)c + 1);
                int isnum;
                v[c] = lua_tonumberx(L, -1, &isnum);
                if (!isnum) /* NaN and infinities are fine: ParaView shows them as such */
                    return bind_field_error(L, 4, call, field, what);
                lua_pop(L, 1);
            }
            fl[nf++] = (analysis_vtk_field){name, 1, v};
            lua_pop(L, 1); /* the value; the key stays for lua_next */
        }
    }
    const size_t np = dem_count(s);
    core_error err;
    if (analysis_vtk_cells(path, np, dem_positions(s, 0), dem_positions(s, 1), nc, tri, nf, fl,
                           dem_time(s), &err))
        return bind_raise(L, call, &err);
    lua_pushstring(L, path);
    return 1;
}

/* ---- grainlab.vtk.series ------------------------------------------------------------------------
 */
typedef struct series_part {
    char suffix[16];
    size_t n, cap;
    double *t;
    char **files; /* names relative to the .pvd's directory */
} series_part;

typedef struct lseries {
    char *pvd;     /* the main .pvd */
    char *stem;    /* pvd without ".pvd" */
    size_t dirlen; /* length of the directory prefix of stem (up to and with the last '/') */
    long frames;
    int kind; /* -1 until the first add */
    series_part parts[MAX_PARTS + 1];
    int nparts;
} lseries;

static void series_free(lseries *u)
{
    for (int k = 0; k < u->nparts; k++) {
        for (size_t i = 0; i < u->parts[k].n; i++)
            free(u->parts[k].files[i]);
        free(u->parts[k].files);
        free(u->parts[k].t);
    }
    u->nparts = 0;
    free(u->pvd);
    free(u->stem);
    u->pvd = u->stem = NULL;
}

static int l_series_gc(lua_State *L)
{
    series_free(luaL_checkudata(L, 1, SERIES));
    return 0;
}

static lseries *check_series(lua_State *L, int idx)
{
    lseries *u = luaL_checkudata(L, idx, SERIES);
    if (!u->pvd)
        luaL_error(L, "the %s was closed", SERIES);
    return u;
}

/* grainlab.vtk.series(path.pvd, opts) */
static int l_series(lua_State *L)
{
    const char *call = "series";
    const char *path = bind_arg_path(L, 1, call);
    read_opts(L, 2, call, OPT_FIELDS); /* checked now, read again at each add */
    const char *stem = stem_of(L, 1, ".pvd", call);
    lseries *u = lua_newuserdatauv(L, sizeof *u, 1);
    memset(u, 0, sizeof *u);
    u->kind = -1;
    luaL_setmetatable(L, SERIES);
    u->pvd = malloc(strlen(path) + 1);
    u->stem = malloc(strlen(stem) + 1);
    if (!u->pvd || !u->stem) {
        series_free(u);
        return luaL_error(L, "%s: out of memory", call);
    }
    strcpy(u->pvd, path);
    strcpy(u->stem, stem);
    const char *slash = strrchr(stem, '/');
    u->dirlen = slash ? (size_t)(slash - stem) + 1 : 0;
    if (lua_istable(L, 2))
        lua_pushvalue(L, 2);
    else
        lua_newtable(L);
    lua_setiuservalue(L, -2, 1);
    return 1;
}

static series_part *series_part_of(lua_State *L, lseries *u, const char *suffix)
{
    for (int k = 0; k < u->nparts; k++)
        if (!strcmp(u->parts[k].suffix, suffix))
            return &u->parts[k];
    if (u->nparts == MAX_PARTS + 1)
        luaL_error(L, "add: too many parts in the series");
    series_part *p = &u->parts[u->nparts++];
    memset(p, 0, sizeof *p);
    snprintf(p->suffix, sizeof p->suffix, "%s", suffix);
    return p;
}

/* series:add(scene [, time]) */
static int l_series_add(lua_State *L)
{
    const char *call = "add";
    lseries *u = check_series(L, 1);
    int kind = scene_kind(L, 2);
    if (kind < 0) {
        char got[64], msg[128];
        bind_describe(L, 2, got, sizeof got);
        snprintf(msg, sizeof msg, "dem.scene, mpm.scene or dsmc.scene expected, got %s", got);
        return luaL_argerror(L, 2, msg);
    }
    if (u->kind >= 0 && kind != u->kind)
        return luaL_error(L, "%s: this series holds %s frames, got a %s", call, KIND_NAMES[u->kind],
                          KIND_NAMES[kind]);
    void *s = scene_ptr(L, 2, kind, call);
    double t = scene_time(s, kind);
    if (!lua_isnoneornil(L, 3)) /* a number (not "1.5"), finite, within the bindings' cap */
        t = bind_arg_number(L, 3, call, 0);
    lua_getiuservalue(L, 1, 1);
    write_opts o = read_opts(L, lua_gettop(L), call, OPT_FIELDS);
    part parts[MAX_PARTS];
    long frame = u->frames + 1;
    int n = write_frame(L, 2, kind, u->stem, frame, &o, call, parts);
    u->kind = kind;
    u->frames = frame;
    /* Record the frame, then rewrite each part's .pvd whole: a run that stops later still
     * leaves collections that list exactly the frames written. */
    for (int k = 0; k < n; k++) {
        series_part *p = series_part_of(L, u, parts[k].suffix);
        if (p->n == p->cap) {
            size_t cap = p->cap ? 2 * p->cap : 64;
            double *nt = realloc(p->t, cap * sizeof *nt);
            if (nt)
                p->t = nt;
            char **nf = nt ? realloc(p->files, cap * sizeof *nf) : NULL;
            if (!nf)
                return luaL_error(L, "%s: out of memory", call);
            p->files = nf;
            p->cap = cap;
        }
        char *name = malloc(strlen(parts[k].path + u->dirlen) + 1);
        if (!name)
            return luaL_error(L, "%s: out of memory", call);
        strcpy(name, parts[k].path + u->dirlen);
        p->t[p->n] = t;
        p->files[p->n++] = name;
        char pvd[PATH_MAX_LEN];
        if (*p->suffix)
            snprintf(pvd, sizeof pvd, "%s_%s.pvd", u->stem, p->suffix);
        else
            snprintf(pvd, sizeof pvd, "%s", u->pvd);
        core_error err;
        if (vtk_pvd_write(pvd, p->n, p->t, (const char *const *)p->files, NULL, &err))
            return bind_raise(L, call, &err);
    }
    push_paths(L, parts, n);
    return 1;
}

static int l_series_info(lua_State *L)
{
    lseries *u = check_series(L, 1);
    lua_createtable(L, 0, 4);
    lua_pushstring(L, u->pvd);
    lua_setfield(L, -2, "path");
    lua_pushinteger(L, u->frames);
    lua_setfield(L, -2, "frames");
    lua_pushstring(L, u->kind >= 0 ? KIND_NAMES[u->kind] : "none");
    lua_setfield(L, -2, "kind");
    lua_createtable(L, u->nparts, 0);
    for (int k = 0; k < u->nparts; k++) {
        char pvd[PATH_MAX_LEN];
        if (*u->parts[k].suffix)
            snprintf(pvd, sizeof pvd, "%s_%s.pvd", u->stem, u->parts[k].suffix);
        else
            snprintf(pvd, sizeof pvd, "%s", u->pvd);
        lua_pushstring(L, pvd);
        lua_rawseti(L, -2, k + 1);
    }
    lua_setfield(L, -2, "collections");
    return 1;
}

static int l_series_tostring(lua_State *L)
{
    lseries *u = luaL_checkudata(L, 1, SERIES);
    if (!u->pvd)
        lua_pushfstring(L, "%s (closed)", SERIES);
    else
        lua_pushfstring(L, "%s '%s' (%d frames)", SERIES, u->pvd, (int)u->frames);
    return 1;
}

/* ---- registration -----------------------------------------------------------------------------
 */
static const char *const WRITE_USAGE[K_NKINDS] = {
    "s:write_vtk(path.vtu, { contacts = true, walls = (scene has walls), clumps = (scene has "
    "clumps) })",
    "m:write_vtk(path.vtu, { grid = true })",
    "s:write_vtk(path.vtu, { cells = true })",
};
static const char *const WRITE_DOC[K_NKINDS] = {
    "VTK XML for ParaView, each file written whole. path.vtu: the particles as vertices with "
    "point data id, radius, velocity, angular_velocity, force (total, last evaluation), mass, "
    "material (and angle in 2D with rotations; clump in a scene with clumps: the member's clump "
    "id, 0 for a loose grain); vectors have 3 components (z = 0 in 2D). "
    "path_contacts.vtu: a line per contact (to j's centre, or the contact point on a wall) with "
    "cell data i, j (walls: minus the wall id), fn, ft, overlap, normal, force, normal_force, "
    "tangential_force. path_walls.vtu: the walls clipped to the box (lines in 2D, polygons in "
    "3D) with id, normal, force. path_clumps.vtu: a vertex per clump at its centre of mass "
    "with id, mass, velocity, angular_velocity, angular_momentum, orientation (2D: the angle; "
    "3D: the quaternion w, x, y, z), inertia (principal moments), members, first_member. "
    "Returns the paths written.",
    "VTK XML for ParaView. path.vtu: the material points with id, grain, material, mass, volume, "
    "velocity, displacement, stress and deformation_gradient (3 x 3, plane strain), pressure, "
    "eps_p. path_grid.vti: the grid nodes with mass and velocity (a linear-shape transfer of "
    "the points) and the cell fields of m:field. Returns the paths written.",
    "VTK XML for ParaView. path.vtu: the particles with id (current order), radius, velocity, "
    "mass, cell. path_cells.vti: the cell fields of s:measure('fields') (count, density, "
    "packing, velocity, temperature, a2). Returns the paths written.",
};

void bind_open_vtk(lua_State *L)
{
    static const lua_CFunction WRITE_FN[K_NKINDS] = {l_dem_write_vtk, l_mpm_write_vtk,
                                                     l_dsmc_write_vtk};
    for (int k = 0; k < K_NKINDS; k++) {
        const bind_fn m[] = {{"write_vtk", WRITE_FN[k], WRITE_USAGE[k], WRITE_DOC[k]},
                             {NULL, NULL, NULL, NULL}};
        luaL_getmetatable(L, KIND_NAMES[k]);
        lua_getfield(L, -1, "__index");
        bind_register(L, lua_gettop(L), m);
        lua_pop(L, 2);
        const bind_fields fields[] = {{"write_vtk", NULL, KIND_FIELDS[k]}, {NULL, NULL, NULL}};
        bind_type_fields(L, KIND_NAMES[k], fields);
    }
    static const bind_fn mesh_methods[] = {
        {"write_vtk", l_mesh_write_vtk,
         "mesh:write_vtk(path.vtu, scene, { depth = thickness, stress = (depth known), cells = "
         "{ name = {...} } })",
         "The Delaunay cells as VTK triangles over the scene's particles now (point data id), "
         "cell data area, strain (since the mesh was built) and velocity_gradient (3 x 3 "
         "tensors), lii, and with a depth stress (Christoffersen, compression positive) and "
         "pressure; cells adds arrays of one value per cell. Returns the path."},
        {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, "analysis.mesh");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), mesh_methods);
    lua_pop(L, 2);
    static const bind_fields mesh_fields[] = {{"write_vtk", NULL, MESH_FIELDS}, {NULL, NULL, NULL}};
    bind_type_fields(L, "analysis.mesh", mesh_fields);

    static const bind_fn methods[] = {
        {"add", l_series_add, "series:add(scene [, time])",
         "Writes the scene as frame N (stem_NNNN.vtu, stem_contacts_NNNN.vtu, ...; options as "
         "s:write_vtk) and rewrites each part's .pvd whole (stem.pvd, stem_contacts.pvd, ...), so "
         "that a run stopped at any point leaves valid collections. time defaults to the "
         "scene's. Returns the paths written."},
        {"info", l_series_info, "series:info()", "path, frames, kind, collections (.pvd files)."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {{"__gc", l_series_gc},
                                    {"__close", l_series_gc},
                                    {"__tostring", l_series_tostring},
                                    {NULL, NULL}};
    bind_new_type(L, SERIES, methods, meta,
                  "A ParaView time series from grainlab.vtk.series: one .pvd per part.");
    static const bind_fn fns[] = {
        {"series", l_series,
         "grainlab.vtk.series(path.pvd, { contacts =, walls =, clumps =, grid =, cells = })",
         "A time series for ParaView: call series:add(s) from on_step; open path.pvd (and "
         "stem_contacts.pvd, stem_walls.pvd, stem_clumps.pvd, stem_grid.pvd, stem_cells.pvd) "
         "in ParaView."},
        {NULL, NULL, NULL, NULL}};
    lua_getglobal(L, "grainlab");
    lua_newtable(L);
    bind_register(L, lua_gettop(L), fns);
    static const bind_fields series_fields[] = {{"series", NULL, OPT_FIELDS}, {NULL, NULL, NULL}};
    bind_register_fields(L, -1, series_fields);
    bind_doc(L, -1, "grainlab.vtk", "grainlab.vtk",
             "VTK XML output for ParaView: s:write_vtk, mesh:write_vtk, grainlab.vtk.series.");
    lua_setfield(L, -2, "vtk");
    lua_pop(L, 1);
}
