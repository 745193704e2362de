/* The Lua module `analysis` (Delaunay-cell continuum over src/analysis) and the boundary-
 * condition methods of dem.scene (over src/dem/boundary.c). This file is also the small layer
 * that couples the two: the Delaunay boundary update handed to the DEM as a callback. */
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"
#include "core/checkpoint.h"
#include "core/clock.h"
#include "dem/dem.h"
#include "lua/bind.h"

static const char *MESH = "analysis.mesh";

typedef struct lmesh {
    analysis_mesh *m;
    long *ids; /* mesh vertex -> particle index (0-based); NULL: the identity */
} lmesh;

static lmesh *check_mesh(lua_State *L, int idx)
{
    lmesh *u = luaL_checkudata(L, idx, MESH);
    if (!u->m)
        luaL_error(L, "the analysis.mesh was closed");
    return u;
}

/* A scratch buffer owned by the Lua stack (freed by the GC, also on errors). */
static double *scratch(lua_State *L, size_t n)
{
    return lua_newuserdatauv(L, (n ? n : 1) * sizeof(double), 0);
}

/* The argument number the user sees (a method's self does not count), as args.c does. */
static int user_argn(lua_State *L, int arg)
{
    lua_Debug ar;
    if (lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.namewhat &&
        strcmp(ar.namewhat, "method") == 0)
        return arg - 1;
    return arg;
}

/* "bad field 'F' in argument #N to 'call' (EXPECTED expected, got GOT)" with GOT given. */
static int field_fail(lua_State *L, int arg, const char *call, const char *name,
                      const char *expected, const char *got)
{
    return luaL_error(L, "bad field '%s' in argument #%d to '%s' (%s expected, got %s)", name,
                      user_argn(L, arg), call, expected, got);
}

static void nested_check_fields(lua_State *L, int tab, int arg, const char *call, const char *name,
                                const char *const fields[]);

/* The field error for the value on top, entry k (1-based) of the array `name`. */
static int entry_error(lua_State *L, int arg, const char *call, const char *name,
                       const char *expected, size_t k)
{
    char val[64], got[96];
    bind_describe(L, -1, val, sizeof val);
    snprintf(got, sizeof got, "%s at entry %zu", val, k);
    return field_fail(L, arg, call, name, expected, got);
}

/* Reads field `key` of the table at tab as an array of exactly n finite numbers (n = 0: any
 * length, returned in *n); errors name field `name` of argument arg. The buffer stays on the
 * stack (freed by the GC, also on errors). */
static double *read_array_at(lua_State *L, int tab, const char *key, int arg, const char *call,
                             const char *name, size_t *n, int required)
{
    int t = lua_getfield(L, tab, key);
    if (t == LUA_TNIL && !required) {
        lua_pop(L, 1);
        return NULL;
    }
    char what[96];
    if (*n)
        snprintf(what, sizeof what, "array of %zu finite numbers", *n);
    else
        snprintf(what, sizeof what, "array of finite numbers");
    if (t != LUA_TTABLE)
        bind_field_error(L, arg, call, name, what);
    size_t len = lua_rawlen(L, -1);
    if (*n && len != *n) {
        char got[64];
        snprintf(got, sizeof got, "%zu values", len);
        field_fail(L, arg, call, name, what, got);
    }
    int arr = lua_gettop(L);
    double *v = scratch(L, len);
    lua_insert(L, arr); /* the buffer below the array */
    arr++;
    for (size_t i = 0; i < len; i++) {
        lua_rawgeti(L, arr, (lua_Integer)i + 1);
        int isnum = lua_type(L, -1) == LUA_TNUMBER;
        v[i] = lua_tonumber(L, -1);
        if (!isnum || !isfinite(v[i]) || fabs(v[i]) > 1e100) /* the bindings' magnitude cap */
            entry_error(L, arg, call, name, what, i + 1);
        lua_pop(L, 1);
    }
    lua_pop(L, 1); /* the array; the buffer stays */
    *n = len;
    return v;
}

static double *read_array(lua_State *L, int arg, const char *call, const char *name, size_t *n,
                          int required)
{
    return read_array_at(L, arg, name, arg, call, name, n, required);
}

/* Reads field `key` of the table at tab as an array of particle ids, integers in [1, max],
 * into a 0-based buffer left on the stack; distinct: a repeated id is refused, naming both
 * entries. Errors name field `label` of argument arg. Absent and not required: NULL. The
 * length goes to *n. */
static long *read_ids_at(lua_State *L, int tab, const char *key, int arg, const char *call,
                         const char *label, size_t max, int distinct, int required, size_t *n)
{
    tab = lua_absindex(L, tab);
    int t = lua_getfield(L, tab, key);
    if (t == LUA_TNIL && !required) {
        lua_pop(L, 1);
        return NULL;
    }
    if (t != LUA_TTABLE) {
        char got[64];
        bind_describe(L, -1, got, sizeof got);
        field_fail(L, arg, call, label, "array of particle ids", got);
    }
    int arr = lua_gettop(L);
    size_t len = lua_rawlen(L, arr);
    long *ids = lua_newuserdatauv(L, (len ? len : 1) * sizeof *ids, 0);
    lua_insert(L, arr); /* the buffer below the array */
    arr++;
    /* first[id - 1] = the entry that first named id (1-based), for distinct */
    size_t *first = distinct ? lua_newuserdatauv(L, (max ? max : 1) * sizeof *first, 0) : NULL;
    if (first)
        memset(first, 0, (max ? max : 1) * sizeof *first);
    char expected[64];
    snprintf(expected, sizeof expected, "particle ids in [1, %zu]", max);
    for (size_t k = 0; k < len; k++) {
        lua_rawgeti(L, arr, (lua_Integer)k + 1);
        int isint = 0;
        lua_Integer id = lua_type(L, -1) == LUA_TNUMBER ? lua_tointegerx(L, -1, &isint) : 0;
        if (!isint || id < 1 || (lua_Unsigned)id > max)
            entry_error(L, arg, call, label, expected, k + 1);
        if (first && first[id - 1]) {
            char got[96];
            snprintf(got, sizeof got, "%lld at entries %zu and %zu", (long long)id, first[id - 1],
                     k + 1);
            field_fail(L, arg, call, label, "distinct particle ids", got);
        }
        if (first)
            first[id - 1] = k + 1;
        lua_pop(L, 1);
        ids[k] = (long)id - 1;
    }
    lua_pop(L, first ? 2 : 1); /* the marks and the array; the ids stay */
    *n = len;
    return ids;
}

static long *read_ids(lua_State *L, int arg, const char *call, const char *name, size_t max,
                      int distinct, int required, size_t *n)
{
    return read_ids_at(L, arg, name, arg, call, name, max, distinct, required, n);
}

static void push_tensor(lua_State *L, const double t[4])
{
    static const char *const comp[4] = {"xx", "xy", "yx", "yy"};
    lua_createtable(L, 0, 4);
    for (int q = 0; q < 4; q++) {
        lua_pushnumber(L, t[q]);
        lua_setfield(L, -2, comp[q]);
    }
}

/* Per-cell tensors as arrays xx, xy, yx, yy of the table on top. */
static void set_tensor_arrays(lua_State *L, const double *t, size_t n, const char *prefix)
{
    static const char *const comp[4] = {"xx", "xy", "yx", "yy"};
    for (int q = 0; q < 4; q++) {
        lua_createtable(L, (int)n, 0);
        for (size_t c = 0; c < n; c++) {
            lua_pushnumber(L, t[4 * c + q]);
            lua_rawseti(L, -2, (lua_Integer)c + 1);
        }
        char name[32];
        snprintf(name, sizeof name, "%s%s", prefix, comp[q]);
        lua_setfield(L, -2, name);
    }
}

/* ---- analysis.delaunay ------------------------------------------------------------------------ */
static const char *const DELAUNAY_FIELDS[] = {"alpha", "ids", NULL};
/* A state table {x =, y =, vx =, vy =} (mesh:cells, strain, strain_rate, raster's state). */
static const char *const STATE_FIELDS[] = {"x", "y", "vx", "vy", NULL};
static const char *const STRESS_FIELDS[] = {"depth", NULL};
static const char *const RASTER_FIELDS[] = {"nx", "ny", "extent", "state", NULL};

static int l_delaunay(lua_State *L)
{
    const char *call = "delaunay";
    double alpha = 1.5;
    long *ids = NULL;
    size_t nids = 0;
    int has_opts = !lua_isnoneornil(L, 2);
    if (has_opts) {
        bind_check_table(L, 2, call);
        bind_check_fields(L, 2, call, DELAUNAY_FIELDS);
        alpha = bind_field_number(L, 2, call, "alpha", 1.5, BIND_NONNEG);
    }
    const double *x, *y, *r = NULL;
    size_t n;
    dem_scene *s = NULL;
    if (luaL_testudata(L, 1, "dem.scene")) {
        s = bind_check_dem_scene(L, 1, call);
        if (dem_dim(s) != 2)
            return luaL_error(L, "%s: the Delaunay cells are 2D; this dem.scene is 3D", call);
        n = dem_count(s);
        x = dem_positions(s, 0);
        y = dem_positions(s, 1);
        r = dem_radii(s);
    } else {
        static const char *const fields[] = {"x", "y", "radius", NULL};
        bind_check_table(L, 1, call);
        bind_check_fields(L, 1, call, fields);
        n = 0;
        x = read_array(L, 1, call, "x", &n, 1);
        y = read_array(L, 1, call, "y", &n, 1);
        r = read_array(L, 1, call, "radius", &n, 0);
        for (size_t i = 0; r && i < n; i++)
            if (!(r[i] > 0)) {
                lua_getfield(L, 1, "radius");
                lua_rawgeti(L, -1, (lua_Integer)i + 1);
                return entry_error(L, 1, call, "radius", "array of positive radii", i + 1);
            }
    }
    /* ids: entries of the table (or scene particles), distinct, so that the mesh's vertices
     * map back to one particle each. */
    if (has_opts && (ids = read_ids(L, 2, call, "ids", n, 1, 0, &nids))) {
        if (nids < 3) { /* the triangulation's own minimum, named after the field */
            lua_getfield(L, 2, "ids");
            return bind_field_error(L, 2, call, "ids", "array of at least 3 distinct particle ids");
        }
        double *sx = scratch(L, nids), *sy = scratch(L, nids), *sr = r ? scratch(L, nids) : NULL;
        for (size_t k = 0; k < nids; k++) {
            sx[k] = x[ids[k]];
            sy[k] = y[ids[k]];
            if (sr)
                sr[k] = r[ids[k]];
        }
        x = sx;
        y = sy;
        r = sr;
        n = nids;
    }
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.alpha = alpha;
    def.radius = r;
    lmesh *u = lua_newuserdatauv(L, sizeof *u, 0);
    u->m = NULL;
    u->ids = NULL;
    luaL_setmetatable(L, MESH);
    core_error err;
    if (ids) {
        u->ids = malloc((nids ? nids : 1) * sizeof *u->ids);
        if (!u->ids)
            return luaL_error(L, "%s: out of memory", call);
        memcpy(u->ids, ids, nids * sizeof *ids);
    }
    if (analysis_delaunay(x, y, n, &def, &u->m, &err) != CORE_OK)
        return bind_raise(L, call, &err);
    return 1;
}

/* Current positions (and velocities) of the mesh's vertices from a dem.scene or a table
 * {x =, y = [, vx =, vy =]} at arg; buffers stay on the stack. Without arg: the build positions. */
static void config_at(lua_State *L, lmesh *u, int arg, int uarg, const char *nest, const char *call,
                      const double **x, const double **y, const double **vx, const double **vy);

static void config(lua_State *L, lmesh *u, int arg, const char *call, const double **x,
                   const double **y, const double **vx, const double **vy)
{
    config_at(L, u, arg, arg, NULL, call, x, y, vx, vy);
}

/* config() of the state at stack index arg, which is argument uarg itself (nest NULL) or its
 * field `nest` (raster's state): errors name 'x' or 'state.x' of argument uarg. */
static void config_at(lua_State *L, lmesh *u, int arg, int uarg, const char *nest, const char *call,
                      const double **x, const double **y, const double **vx, const double **vy)
{
    const analysis_mesh *m = u->m;
    size_t n = m->np;
    if (lua_isnoneornil(L, arg)) {
        *x = m->x0;
        *y = m->y0;
        if (vx)
            *vx = *vy = NULL;
        return;
    }
    if (luaL_testudata(L, arg, "dem.scene")) {
        dem_scene *s = bind_check_dem_scene(L, arg, call);
        size_t need = 0;
        for (size_t k = 0; k < n; k++)
            need = u->ids ? (size_t)u->ids[k] + 1 > need ? (size_t)u->ids[k] + 1 : need : n;
        /* lua_pushfstring knows %I (lua_Integer), not %zu */
        if (!u->ids && dem_count(s) != n)
            luaL_error(L, "%s: the mesh has %I particles, the scene %I", call, (lua_Integer)n,
                       (lua_Integer)dem_count(s));
        if (dem_count(s) < need)
            luaL_error(L, "%s: the mesh uses particle %I, the scene has %I", call,
                       (lua_Integer)need, (lua_Integer)dem_count(s));
        const double *src[4] = {dem_positions(s, 0), dem_positions(s, 1), dem_velocities(s, 0),
                                dem_velocities(s, 1)};
        double *dst[4];
        for (int q = 0; q < 4; q++) {
            dst[q] = scratch(L, n);
            for (size_t k = 0; k < n; k++)
                dst[q][k] = src[q][u->ids ? (size_t)u->ids[k] : k];
        }
        *x = dst[0];
        *y = dst[1];
        if (vx) {
            *vx = dst[2];
            *vy = dst[3];
        }
        return;
    }
    if (nest) {
        if (!lua_istable(L, arg)) {
            char got[64];
            bind_describe(L, arg, got, sizeof got);
            field_fail(L, uarg, call, nest, "dem.scene or {x =, y =}", got);
        }
        nested_check_fields(L, arg, uarg, call, nest, STATE_FIELDS);
    } else {
        bind_check_table(L, arg, call);
        bind_check_fields(L, arg, call, STATE_FIELDS);
    }
    static const char *const keys[4] = {"x", "y", "vx", "vy"};
    const double **out[4] = {x, y, vx, vy};
    size_t len = n;
    /* vx, vy are read (checked) even where only positions are used: a state table made for
     * strain_rate passes to strain as it is, but garbage in it is not ignored. */
    const double *unused[2];
    if (!vx) {
        out[2] = &unused[0];
        out[3] = &unused[1];
    }
    for (int q = 0; q < 4; q++) {
        char label[48];
        snprintf(label, sizeof label, "%s%s%s", nest ? nest : "", nest ? "." : "", keys[q]);
        *out[q] = read_array_at(L, arg, keys[q], uarg, call, label, &len, q < 2 || vx != NULL);
    }
}

static int l_mesh_info(lua_State *L)
{
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    lua_createtable(L, 0, 6);
    lua_pushinteger(L, (lua_Integer)m->np);
    lua_setfield(L, -2, "particles");
    lua_pushinteger(L, (lua_Integer)m->ncells);
    lua_setfield(L, -2, "cells");
    lua_pushinteger(L, (lua_Integer)m->ndelaunay);
    lua_setfield(L, -2, "delaunay");
    lua_pushinteger(L, (lua_Integer)m->npeeled);
    lua_setfield(L, -2, "peeled");
    lua_pushinteger(L, (lua_Integer)m->nloop);
    lua_setfield(L, -2, "boundary");
    lua_pushnumber(L, m->area);
    lua_setfield(L, -2, "area");
    return 1;
}

static lua_Integer pid(const lmesh *u, long v) { return (u->ids ? u->ids[v] : v) + 1; }

static int l_mesh_cells(lua_State *L)
{
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    const double *x, *y;
    config(L, u, 2, "cells", &x, &y, NULL, NULL);
    double *area = scratch(L, m->ncells);
    analysis_cell_areas(m, x, y, area);
    double *cx = scratch(L, m->ncells), *cy = scratch(L, m->ncells);
    for (size_t c = 0; c < m->ncells; c++) {
        const long *v = m->tri + 3 * c;
        cx[c] = (x[v[0]] + x[v[1]] + x[v[2]]) / 3;
        cy[c] = (y[v[0]] + y[v[1]] + y[v[2]]) / 3;
    }
    lua_createtable(L, 0, 6);
    static const char *const names[3] = {"a", "b", "c"};
    for (int q = 0; q < 3; q++) {
        lua_createtable(L, (int)m->ncells, 0);
        for (size_t c = 0; c < m->ncells; c++) {
            lua_pushinteger(L, pid(u, m->tri[3 * c + q]));
            lua_rawseti(L, -2, (lua_Integer)c + 1);
        }
        lua_setfield(L, -2, names[q]);
    }
    bind_push_array(L, area, m->ncells, "area");
    bind_push_array(L, cx, m->ncells, "cx");
    bind_push_array(L, cy, m->ncells, "cy");
    return 1;
}

static int l_mesh_boundary(lua_State *L)
{
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    lua_createtable(L, (int)m->nloop, 0);
    for (size_t k = 0; k < m->nloop; k++) {
        lua_pushinteger(L, pid(u, m->loop[k]));
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    return 1;
}

/* mesh:strain(now): displacements since the mesh was built, gradients over the build
 * configuration. */
static int l_mesh_strain(lua_State *L)
{
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    const double *x, *y;
    if (lua_isnoneornil(L, 2))
        return bind_arg_error(L, 2, "strain", "the current state (a dem.scene or {x =, y =})");
    config(L, u, 2, "strain", &x, &y, NULL, NULL);
    double *ux = scratch(L, m->np), *uy = scratch(L, m->np);
    for (size_t i = 0; i < m->np; i++) {
        ux[i] = x[i] - m->x0[i];
        uy[i] = y[i] - m->y0[i];
    }
    double *g = scratch(L, 4 * m->ncells), *e = scratch(L, 4 * m->ncells);
    core_error err;
    if (analysis_cell_gradients(m, m->x0, m->y0, ux, uy, g, &err))
        return bind_raise(L, "strain", &err);
    for (size_t c = 0; c < m->ncells; c++)
        analysis_sym(g + 4 * c, e + 4 * c);
    double H[4], E[4], mean[4], V;
    analysis_boundary_gradient(m, m->x0, m->y0, ux, uy, H, &V);
    analysis_sym(H, E);
    analysis_mean_tensor(m, m->x0, m->y0, g, mean);
    lua_createtable(L, 0, 10);
    set_tensor_arrays(L, e, m->ncells, "");
    push_tensor(L, E);
    lua_setfield(L, -2, "coarse");
    push_tensor(L, H);
    lua_setfield(L, -2, "coarse_gradient");
    push_tensor(L, mean);
    lua_setfield(L, -2, "mean_gradient");
    lua_pushnumber(L, E[0] + E[3]);
    lua_setfield(L, -2, "volumetric");
    lua_pushnumber(L, V);
    lua_setfield(L, -2, "area");
    return 1;
}

static int l_mesh_strain_rate(lua_State *L)
{
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    const double *x, *y, *vx, *vy;
    if (lua_isnoneornil(L, 2))
        return bind_arg_error(L, 2, "strain_rate",
                              "the current state (a dem.scene or {x =, y =, vx =, vy =})");
    config(L, u, 2, "strain_rate", &x, &y, &vx, &vy);
    double *g = scratch(L, 4 * m->ncells), *lii = scratch(L, m->ncells);
    core_error err;
    if (analysis_cell_gradients(m, x, y, vx, vy, g, &err))
        return bind_raise(L, "strain_rate", &err);
    double mean_lii = 0, total = 0, *area = scratch(L, m->ncells);
    analysis_cell_areas(m, x, y, area);
    for (size_t c = 0; c < m->ncells; c++) {
        lii[c] = analysis_lii(g + 4 * c);
        mean_lii += area[c] * lii[c];
        total += area[c];
    }
    double H[4], E[4], V;
    analysis_boundary_gradient(m, x, y, vx, vy, H, &V);
    analysis_sym(H, E);
    lua_createtable(L, 0, 10);
    set_tensor_arrays(L, g, m->ncells, "");
    bind_push_array(L, lii, m->ncells, "lii");
    lua_pushnumber(L, mean_lii / total);
    lua_setfield(L, -2, "mean_lii");
    push_tensor(L, H);
    lua_setfield(L, -2, "coarse_gradient");
    push_tensor(L, E);
    lua_setfield(L, -2, "coarse");
    return 1;
}

typedef struct contact_buf {
    size_t n, cap;
    long *i, *j;
    double *px, *py, *fx, *fy;
    const long *map; /* particle -> mesh vertex (or -1), NULL: identity */
} contact_buf;

static void collect(const dem_contact_info *c, void *ctx)
{
    contact_buf *b = ctx;
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        long *i = realloc(b->i, cap * sizeof *i), *j = i ? realloc(b->j, cap * sizeof *j) : NULL;
        if (i)
            b->i = i;
        if (j)
            b->j = j;
        double **arr[4] = {&b->px, &b->py, &b->fx, &b->fy};
        int ok = i && j;
        for (int q = 0; q < 4 && ok; q++) {
            double *p = realloc(*arr[q], cap * sizeof **arr[q]);
            if (p)
                *arr[q] = p;
            ok = p != NULL;
        }
        if (!ok)
            return; /* out of memory: the contact is dropped (reported by the caller) */
        b->cap = cap;
    }
    long i = c->i, j = c->j;
    if (b->map) {
        i = b->map[i];
        j = j >= 0 ? b->map[j] : -1;
    }
    b->i[b->n] = i;
    b->j[b->n] = j < 0 ? -1 : j;
    b->px[b->n] = c->point[0];
    b->py[b->n] = c->point[1];
    b->fx[b->n] = c->force[0];
    b->fy[b->n] = c->force[1];
    b->n++;
}

static void free_contacts(contact_buf *b)
{
    free(b->i);
    free(b->j);
    free(b->px);
    free(b->py);
    free(b->fx);
    free(b->fy);
}

/* mesh:stress(scene, {depth =}): Christoffersen's stress from the scene's contacts now. */
static int l_mesh_stress(lua_State *L)
{
    const char *call = "stress";
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    dem_scene *s = bind_check_dem_scene(L, 2, call);
    double depth = dem_thickness(s);
    if (!lua_isnoneornil(L, 3)) {
        bind_check_table(L, 3, call);
        bind_check_fields(L, 3, call, STRESS_FIELDS);
        depth = bind_field_number(L, 3, call, "depth", depth, BIND_POSITIVE);
    }
    if (!(depth > 0))
        return luaL_error(L, "%s: give opts.depth (m): the scene has no thickness", call);
    const double *x, *y;
    config(L, u, 2, call, &x, &y, NULL, NULL);
    long *map = NULL;
    if (u->ids) {
        map = lua_newuserdatauv(L, dem_count(s) * sizeof *map, 0);
        for (size_t i = 0; i < dem_count(s); i++)
            map[i] = -1;
        for (size_t k = 0; k < m->np; k++)
            map[u->ids[k]] = (long)k;
    }
    contact_buf cb = {0};
    cb.map = map;
    dem_each_contact(s, collect, &cb);
    double *ps = scratch(L, 4 * m->np), *cs = scratch(L, 4 * m->ncells);
    analysis_contacts c = {cb.n, cb.i, cb.j, cb.px, cb.py, cb.fx, cb.fy};
    core_error err;
    core_status st = analysis_particle_stress(m, x, y, &c, depth, ps, NULL, &err);
    free_contacts(&cb);
    if (st)
        return bind_raise(L, call, &err);
    analysis_cell_stress(m, ps, cs);
    double mean[4];
    analysis_mean_tensor(m, x, y, cs, mean);
    double *p = scratch(L, m->ncells), *pp = scratch(L, m->np);
    for (size_t k = 0; k < m->ncells; k++)
        p[k] = 0.5 * (cs[4 * k] + cs[4 * k + 3]);
    for (size_t k = 0; k < m->np; k++)
        pp[k] = 0.5 * (ps[4 * k] + ps[4 * k + 3]);
    lua_createtable(L, 0, 10);
    set_tensor_arrays(L, cs, m->ncells, "");
    bind_push_array(L, p, m->ncells, "pressure");
    bind_push_array(L, pp, m->np, "particle_pressure");
    push_tensor(L, mean);
    lua_setfield(L, -2, "mean");
    lua_pushnumber(L, 0.5 * (mean[0] + mean[3]));
    lua_setfield(L, -2, "mean_pressure");
    lua_pushinteger(L, (lua_Integer)cb.n);
    lua_setfield(L, -2, "contacts");
    return 1;
}

/* mesh:raster(values, {nx =, ny =, extent = {{x0, y0}, {x1, y1}}, state = scene}) */
static int l_mesh_raster(lua_State *L)
{
    const char *call = "raster";
    lmesh *u = check_mesh(L, 1);
    const analysis_mesh *m = u->m;
    luaL_checktype(L, 2, LUA_TTABLE);
    /* lua_pushfstring knows %I (lua_Integer), not %zu */
    if (lua_rawlen(L, 2) != m->ncells)
        return luaL_error(L,
                          "bad argument #1 to '%s' (array of %I cell values expected, got "
                          "%I values)",
                          call, (lua_Integer)m->ncells, (lua_Integer)lua_rawlen(L, 2));
    bind_check_table(L, 3, call);
    bind_check_fields(L, 3, call, RASTER_FIELDS);
    int nx = (int)bind_field_integer(L, 3, call, "nx", 0, 1, 8192, BIND_REQUIRED);
    int ny = (int)bind_field_integer(L, 3, call, "ny", 0, 1, 8192, BIND_REQUIRED);
    double ext[4], lo[2], hi[2];
    bind_field_box(L, 3, call, "extent", 2, lo, hi);
    ext[0] = lo[0];
    ext[1] = lo[1];
    ext[2] = hi[0];
    ext[3] = hi[1];
    /* Cell values: numbers; NaN is a value (no data), as the rasterizer writes outside cells. */
    double *vals = scratch(L, m->ncells);
    for (size_t c = 0; c < m->ncells; c++) {
        lua_rawgeti(L, 2, (lua_Integer)c + 1);
        if (lua_type(L, -1) != LUA_TNUMBER) {
            char got[64];
            bind_describe(L, -1, got, sizeof got);
            return luaL_error(L,
                              "bad argument #1 to '%s' (array of numbers expected, got %s at "
                              "entry %I)",
                              call, got, (lua_Integer)c + 1);
        }
        vals[c] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    lua_getfield(L, 3, "state");
    int state = lua_gettop(L);
    const double *x, *y;
    config_at(L, u, state, 3, "state", call, &x, &y, NULL, NULL);
    double *out = scratch(L, (size_t)nx * (size_t)ny);
    core_error err;
    if (analysis_rasterize(m, x, y, vals, nx, ny, ext, out, &err))
        return bind_raise(L, call, &err);
    lua_createtable(L, nx * ny, 0);
    for (long k = 0; k < (long)nx * ny; k++) {
        lua_pushnumber(L, out[k]);
        lua_rawseti(L, -2, k + 1);
    }
    return 1;
}

static int l_mesh_gc(lua_State *L)
{
    lmesh *u = luaL_checkudata(L, 1, MESH);
    analysis_mesh_destroy(u->m);
    free(u->ids);
    u->m = NULL;
    u->ids = NULL;
    return 0;
}

static int l_mesh_tostring(lua_State *L)
{
    lmesh *u = luaL_checkudata(L, 1, MESH);
    if (!u->m)
        lua_pushliteral(L, "analysis.mesh (closed)");
    else
        lua_pushfstring(L, "analysis.mesh (%d particles, %d cells, boundary of %d)",
                        (int)u->m->np, (int)u->m->ncells, (int)u->m->nloop);
    return 1;
}

/* ---- boundary conditions on dem.scene --------------------------------------------------------- */
/* The coupling: every `every` steps the DEM calls this, which triangulates the centres (all
 * particles, or the listed ones) and hands the boundary loop back as the pressure edges.
 * lateral: edges facing a wall (plate_edge) carry no pressure: the plates carry the load there. */
typedef struct delaunay_ctx {
    double alpha;
    int lateral;
    long *ids; /* NULL: all particles */
    size_t nids;
    int band;  /* triangulate only a band along the previous loop */
    long *loop; /* previous loop (particle indices) */
    size_t nloop;
    long *sel; /* scratch: the band's particles */
    unsigned char *mark;
    size_t cap_sel, cap_mark;
} delaunay_ctx;

static void free_delaunay_ctx(void *p)
{
    delaunay_ctx *c = p;
    if (c) {
        free(c->ids);
        free(c->loop);
        free(c->sel);
        free(c->mark);
    }
    free(c);
}

/* The particles (of ids, or all) in the grid cells, 3 mean diameters wide, at and around those
 * of the previous loop: within 250 steps no other particle can reach the outline. Returns the
 * count (0 when there is no previous loop or memory ran out: triangulate all). */
static size_t band_particles(delaunay_ctx *c, dem_scene *s)
{
    if (!c->band || c->nloop == 0)
        return 0;
    size_t n = c->ids ? c->nids : dem_count(s);
    const double *x = dem_positions(s, 0), *y = dem_positions(s, 1), *r = dem_radii(s);
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY, rm = 0;
    for (size_t k = 0; k < n; k++) {
        size_t i = c->ids ? (size_t)c->ids[k] : k;
        xlo = fmin(xlo, x[i]), xhi = fmax(xhi, x[i]), ylo = fmin(ylo, y[i]), yhi = fmax(yhi, y[i]);
        rm += r[i];
    }
    double h = 6 * rm / (double)n; /* 3 mean diameters */
    long nx = (long)((xhi - xlo) / h) + 1, ny = (long)((yhi - ylo) / h) + 1;
    if (nx * ny > 4 * (long)n + 64)
        return 0;
    size_t cells = (size_t)(nx * ny);
    if (c->cap_mark < cells) {
        unsigned char *m = realloc(c->mark, cells);
        if (!m)
            return 0;
        c->mark = m;
        c->cap_mark = cells;
    }
    if (c->cap_sel < n) {
        long *q = realloc(c->sel, n * sizeof *q);
        if (!q)
            return 0;
        c->sel = q;
        c->cap_sel = n;
    }
    memset(c->mark, 0, cells);
    for (size_t k = 0; k < c->nloop; k++) {
        long i = c->loop[k];
        long cx = (long)((x[i] - xlo) / h), cy = (long)((y[i] - ylo) / h);
        for (long dy = -1; dy <= 1; dy++)
            for (long dx = -1; dx <= 1; dx++)
                if (cx + dx >= 0 && cx + dx < nx && cy + dy >= 0 && cy + dy < ny)
                    c->mark[(cy + dy) * nx + cx + dx] = 1;
    }
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        size_t i = c->ids ? (size_t)c->ids[k] : k;
        long cx = (long)((x[i] - xlo) / h), cy = (long)((y[i] - ylo) / h);
        if (c->mark[cy * nx + cx])
            c->sel[m++] = (long)i;
    }
    return m < 3 ? 0 : m;
}

/* An edge a -> b faces a plate when its outward normal points against the wall's (n . w < -1/2)
 * and both particles lie within their radius plus two mean diameters dm of the wall (the top
 * layer, with the valleys between its grains, up to 4 radii deep in a deposited sample): the
 * plate carries the load there, the edge gets no pressure. */
static int plate_edge(dem_scene *s, long a, long b, double dm)
{
    const double *x = dem_positions(s, 0), *y = dem_positions(s, 1), *r = dem_radii(s);
    double nx = y[b] - y[a], ny = -(x[b] - x[a]), L = hypot(nx, ny);
    if (!(L > 0))
        return 0;
    for (int w = 0; w < dem_wall_count(s); w++) {
        double pt[3], nrm[3];
        int active;
        if (dem_wall_geometry(s, w, pt, nrm, &active, NULL) || !active)
            continue;
        if ((nx * nrm[0] + ny * nrm[1]) / L > -0.5)
            continue;
        dem_wall_point(s, w, pt, NULL);
        double da = (x[a] - pt[0]) * nrm[0] + (y[a] - pt[1]) * nrm[1];
        double db = (x[b] - pt[0]) * nrm[0] + (y[b] - pt[1]) * nrm[1];
        if (da < r[a] + 2 * dm && db < r[b] + 2 * dm)
            return 1;
    }
    return 0;
}

static core_status delaunay_update(void *ctxp, dem_scene *s, core_error *err)
{
    delaunay_ctx *c = ctxp;
    size_t n = c->ids ? c->nids : dem_count(s);
    const double *x = dem_positions(s, 0), *y = dem_positions(s, 1), *r = dem_radii(s);
    double *buf = NULL;
    const long *pick = c->ids;
    size_t nb = band_particles(c, s);
    if (nb > 0) {
        pick = c->sel;
        n = nb;
    }
    if (pick) {
        buf = malloc(3 * n * sizeof *buf);
        if (!buf)
            return core_fail(err, CORE_ERR_NOMEM, "out of memory for the boundary update");
        for (size_t k = 0; k < n; k++) {
            buf[k] = x[pick[k]];
            buf[n + k] = y[pick[k]];
            buf[2 * n + k] = r[pick[k]];
        }
        x = buf;
        y = buf + n;
        r = buf + 2 * n;
    }
    double dmean = 0; /* the triangulated particles' mean diameter */
    for (size_t k = 0; k < n; k++)
        dmean += 2 * r[k] / (double)n;
    analysis_delaunay_def def = analysis_default_delaunay_def();
    def.alpha = c->alpha;
    def.radius = r;
    analysis_mesh *m = NULL;
    core_status st = analysis_delaunay(x, y, n, &def, &m, err);
    free(buf);
    if (st)
        return st;
    size_t nl = m->nloop;
    long *a = malloc(2 * nl * sizeof *a);
    unsigned char *loaded = malloc(nl ? nl : 1);
    if (!a || !loaded) {
        free(a);
        free(loaded);
        analysis_mesh_destroy(m);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the boundary update");
    }
    long *b = a + nl;
    for (size_t k = 0; k < nl; k++) {
        long va = m->loop[k], vb = m->loop[(k + 1) % nl];
        a[k] = pick ? pick[va] : va;
        b[k] = pick ? pick[vb] : vb;
    }
    long *keep = realloc(c->loop, (nl ? nl : 1) * sizeof *keep);
    if (keep) {
        memcpy(keep, a, nl * sizeof *keep);
        c->loop = keep;
        c->nloop = nl;
    }
    for (size_t k = 0; k < nl; k++)
        loaded[k] = !(c->lateral && plate_edge(s, a[k], b[k], dmean));
    st = dem_set_boundary_edges(s, nl, a, b, loaded, 1, err);
    free(a);
    free(loaded);
    analysis_mesh_destroy(m);
    return st;
}

/* ---- the Delaunay update in checkpoints ---- *
 * s:save stores the update's parameters and the previous loop (the band of the next update is
 * taken along it) in the 'boundary_update' section; dem.load reads them back and attaches the
 * same update as s:boundary does (delaunay_attach), so that the rebuilds continue at the same
 * steps with the same edges. The callback pointer is never written. */
static const char DELAUNAY_KIND[] = "delaunay";

static void put_longs(ckpt_writer *w, const long *v, size_t n)
{
    ckpt_put_u64(w, n);
    for (size_t k = 0; k < n; k++)
        ckpt_put_i64(w, v[k]);
}

static void delaunay_save(const void *ctxp, ckpt_writer *w)
{
    const delaunay_ctx *c = ctxp;
    ckpt_put_f64(w, c->alpha);
    ckpt_put_u32(w, (uint32_t)c->lateral);
    ckpt_put_u32(w, (uint32_t)c->band);
    put_longs(w, c->ids, c->ids ? c->nids : 0);
    put_longs(w, c->loop, c->nloop);
}

/* The one installation of the Delaunay update on def, for s:boundary and dem.load: a new context
 * with copies of ids (NULL: all particles) and of the previous loop (NULL: none yet). */
static core_status delaunay_attach(dem_boundary_def *def, double alpha, int lateral, int band,
                                   const long *ids, size_t nids, const long *loop, size_t nloop,
                                   core_error *err)
{
    delaunay_ctx *c = calloc(1, sizeof *c);
    if (c) {
        c->ids = ids ? malloc((nids ? nids : 1) * sizeof *c->ids) : NULL;
        c->loop = nloop ? malloc(nloop * sizeof *c->loop) : NULL;
    }
    if (!c || (ids && !c->ids) || (nloop && !c->loop)) {
        free_delaunay_ctx(c);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory for the Delaunay boundary");
    }
    c->alpha = alpha;
    c->lateral = lateral;
    c->band = band;
    if (ids) {
        memcpy(c->ids, ids, nids * sizeof *ids);
        c->nids = nids;
    }
    if (nloop)
        memcpy(c->loop, loop, nloop * sizeof *loop);
    c->nloop = nloop;
    def->update = delaunay_update;
    def->ctx = c;
    def->free_ctx = free_delaunay_ctx;
    def->kind = DELAUNAY_KIND;
    def->save_ctx = delaunay_save;
    return CORE_OK;
}

/* Reads a count and that many particle ids in [0, n) into a new array (NULL when none). */
static core_status get_longs(ckpt_section *sec, size_t n, const char *what, long **out,
                             size_t *count, core_error *err)
{
    *out = NULL;
    *count = 0;
    uint64_t c = 0;
    core_status st = ckpt_get_u64(sec, &c, err);
    if (st)
        return st;
    if (c > (sec->size - sec->pos) / 8) /* before it sizes an allocation */
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is a corrupt dem checkpoint: %" PRIu64 " entries of %s",
                         ckpt_reader_path(sec->r), c, what);
    if (c == 0)
        return CORE_OK;
    *count = (size_t)c;
    long *v = malloc(*count * sizeof *v);
    if (!v)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    for (size_t k = 0; k < *count && !st; k++)
        st = ckpt_get_int_in(sec, 0, (long)n - 1, what, &v[k], err);
    if (st)
        free(v);
    else
        *out = v;
    return st;
}

static core_status delaunay_restore(ckpt_section *sec, const dem_scene *s, dem_boundary_def *def,
                                    core_error *err)
{
    const char *bad = "'%s' is a corrupt dem checkpoint: the Delaunay boundary's %s";
    const char *path = ckpt_reader_path(sec->r);
    double alpha = 0;
    uint32_t flag[2] = {0, 0}; /* sides = 'lateral', band */
    long *ids = NULL, *loop = NULL;
    size_t nids = 0, nloop = 0;
    core_status st = ckpt_get_finite(sec, "the Delaunay boundary's alpha", &alpha, err);
    if (!st && !(alpha >= 0))
        st = core_fail(err, CORE_ERR_IO, bad, path, "alpha is negative");
    for (int k = 0; k < 2 && !st; k++)
        if (!(st = ckpt_get_u32(sec, &flag[k], err)) && flag[k] > 1)
            st = core_fail(err, CORE_ERR_IO, bad, path,
                           k ? "band flag is not 0 or 1" : "sides flag is not 0 or 1");
    const size_t n = dem_count(s);
    if (!st)
        st = get_longs(sec, n, "a Delaunay boundary particle id", &ids, &nids, err);
    if (!st && nids > 0 && nids < 3)
        st = core_fail(err, CORE_ERR_IO, bad, path, "ids are fewer than 3");
    if (!st)
        st = get_longs(sec, n, "a Delaunay boundary loop id", &loop, &nloop, err);
    if (!st)
        st = delaunay_attach(def, alpha, (int)flag[0], (int)flag[1], ids, nids, loop, nloop, err);
    free(ids);
    free(loop);
    return st;
}

const dem_boundary_restorer *bind_dem_boundary_restorer(void)
{
    static const dem_boundary_restorer r = {DELAUNAY_KIND, delaunay_restore};
    return &r;
}

/* Field `key` of the table at tab as a 2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers;
 * errors name field `label` of argument arg (mbc is a table inside argument #1). */
static void read_matrix(lua_State *L, int tab, const char *key, int arg, const char *call,
                        const char *label, double out[4])
{
    const char *want = "2x2 matrix {{xx, xy}, {yx, yy}} of finite numbers";
    char got[128];
    tab = lua_absindex(L, tab);
    if (lua_getfield(L, tab, key) != LUA_TTABLE || lua_rawlen(L, -1) != 2) {
        if (lua_type(L, -1) == LUA_TTABLE)
            snprintf(got, sizeof got, "%d rows", (int)lua_rawlen(L, -1));
        else
            bind_describe(L, -1, got, sizeof got);
        field_fail(L, arg, call, label, want, got);
    }
    for (int r = 0; r < 2; r++) {
        if (lua_rawgeti(L, -1, r + 1) != LUA_TTABLE || lua_rawlen(L, -1) != 2) {
            char row[64];
            bind_describe(L, -1, row, sizeof row);
            if (lua_type(L, -1) == LUA_TTABLE)
                snprintf(got, sizeof got, "%d entries in row %d", (int)lua_rawlen(L, -1), r + 1);
            else
                snprintf(got, sizeof got, "%s as row %d", row, r + 1);
            field_fail(L, arg, call, label, want, got);
        }
        for (int c = 0; c < 2; c++) {
            lua_rawgeti(L, -1, c + 1);
            out[2 * r + c] = lua_tonumber(L, -1);
            if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(out[2 * r + c]) ||
                fabs(out[2 * r + c]) > 1e100) { /* the bindings' magnitude cap */
                char v[48];
                bind_describe(L, -1, v, sizeof v);
                snprintf(got, sizeof got, "%s at row %d, column %d", v, r + 1, c + 1);
                field_fail(L, arg, call, label, want, got);
            }
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* Readers for a table nested in argument arg (mbc): errors name the field as 'mbc.K' of that
 * argument (args.c's readers would number the nested table by its stack slot). */
static void nested_check_fields(lua_State *L, int tab, int arg, const char *call, const char *name,
                                const char *const fields[])
{
    bind_check_nested_fields(L, tab, arg, call, name, fields);
}

/* Field key of the nested table at tab: a finite number, > 0 (positive) or >= 0, def if absent. */
static double nested_number(lua_State *L, int tab, const char *key, int arg, const char *call,
                            const char *label, double def, int positive)
{
    if (lua_getfield(L, tab, key) == LUA_TNIL) {
        lua_pop(L, 1);
        return def;
    }
    double v = lua_tonumber(L, -1);
    /* finite, and within the bindings' magnitude cap (1e100) as the arrays are */
    if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(v) || fabs(v) > 1e100 ||
        (positive ? !(v > 0) : !(v >= 0))) {
        char got[64];
        bind_describe(L, -1, got, sizeof got);
        field_fail(L, arg, call, label, positive ? "positive number" : "non-negative number", got);
    }
    lua_pop(L, 1);
    return v;
}

static void push_boundary_info(lua_State *L, dem_scene *s)
{
    dem_boundary_info bi;
    core_error err;
    if (dem_boundary_info_get(s, &bi, &err))
        bind_raise(L, "boundary_info", &err);
    lua_createtable(L, 0, 16);
    lua_pushinteger(L, (lua_Integer)bi.edges);
    lua_setfield(L, -2, "edges");
    lua_pushinteger(L, (lua_Integer)bi.loaded);
    lua_setfield(L, -2, "loaded");
    lua_pushinteger(L, (lua_Integer)bi.nodes);
    lua_setfield(L, -2, "nodes");
    lua_pushboolean(L, bi.closed);
    lua_setfield(L, -2, "closed");
    lua_pushnumber(L, bi.area);
    lua_setfield(L, -2, "area");
    push_tensor(L, bi.grad);
    lua_setfield(L, -2, "gradient");
    push_tensor(L, bi.strain_rate);
    lua_setfield(L, -2, "strain_rate");
    lua_createtable(L, 2, 0);
    lua_pushnumber(L, bi.penalty_sum[0]);
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, bi.penalty_sum[1]);
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "penalty_sum");
    lua_pushnumber(L, bi.penalty_max);
    lua_setfield(L, -2, "penalty_max");
    lua_pushnumber(L, bi.pressure_max);
    lua_setfield(L, -2, "pressure_max");
    lua_pushnumber(L, bi.stiffness);
    lua_setfield(L, -2, "penalty_rate");
    lua_pushinteger(L, bi.updates);
    lua_setfield(L, -2, "updates");
    lua_pushnumber(L, bi.update_seconds);
    lua_setfield(L, -2, "update_seconds");
    lua_pushnumber(L, bi.apply_seconds);
    lua_setfield(L, -2, "apply_seconds");
    lua_pushinteger(L, (lua_Integer)bi.springs);
    lua_setfield(L, -2, "springs");
    lua_pushinteger(L, (lua_Integer)bi.ties);
    lua_setfield(L, -2, "ties");
}

static const char *const MODES[] = {"delaunay", "edges", "none", NULL};
static const char *const BOUNDARY_FIELDS[] = {"mode",   "pressure", "depth", "every",
                                              "alpha",  "sides",    "ids",   "edges",
                                              "closed", "mbc",      "band",  NULL};
static const char *const MBC_FIELDS[] = {"strain_rate", "gradient", "mask", "K", "kappa",
                                         "rate",        "dt",       "tau",  NULL};
static const char *const SIDES[] = {"all", "lateral", NULL};

/* s:boundary{ mode =, pressure =, depth =, every =, alpha =, sides =, ids =, edges =, closed =,
 *             mbc = { strain_rate = | gradient =, mask =, K =, kappa =, rate = } } */
static int l_boundary(lua_State *L)
{
    const char *call = "boundary";
    dem_scene *s = bind_check_dem_scene(L, 1, call);
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, BOUNDARY_FIELDS);
    if (dem_dim(s) != 2)
        return luaL_error(L, "%s: boundary conditions are 2D only", call);
    int mode = bind_field_option(L, 2, call, "mode", MODES, 0, 0);
    /* A field of another mode would be ignored without a word: refused, naming it. */
    static const char *const not_in[3][10] = {
        {"edges", "closed", NULL},
        {"every", "alpha", "sides", "ids", "band", NULL},
        {"pressure", "depth", "every", "alpha", "sides", "ids", "edges", "closed", "mbc", "band"}};
    for (int k = 0; k < 10 && not_in[mode][k]; k++) {
        if (lua_getfield(L, 2, not_in[mode][k]) != LUA_TNIL) {
            char want[80], got[64];
            snprintf(want, sizeof want, "nil (a field of another mode; 'mode' is '%s')",
                     MODES[mode]);
            bind_describe(L, -1, got, sizeof got);
            return field_fail(L, 2, call, not_in[mode][k], want, got);
        }
        lua_pop(L, 1);
    }
    if (mode == 2) {
        dem_clear_boundary(s);
        return 0;
    }
    dem_boundary_def def = dem_default_boundary_def();
    def.pressure = bind_field_number(L, 2, call, "pressure", 0, BIND_NONNEG);
    double thick = dem_thickness(s);
    def.depth = bind_field_number(L, 2, call, "depth", thick, BIND_POSITIVE);
    if (!(def.depth > 0))
        return luaL_error(L, "%s: give depth (m): the scene has no thickness (dem.scene{ "
                             "thickness = })", call);
    /* 0 would never rebuild the outline while saying it is rebuilt: edges that never change are
     * mode = 'edges'. */
    def.every = (long)bind_field_integer(L, 2, call, "every", 250, 1, LUA_MAXINTEGER, 0);
    double alpha = bind_field_number(L, 2, call, "alpha", 1.5, BIND_NONNEG);
    int lateral = bind_field_option(L, 2, call, "sides", SIDES, 0, 0);
    double kappa = 20, rate = 0, K = 0, mdt = 0;
    int has_mbc = lua_getfield(L, 2, "mbc") != LUA_TNIL;
    int mbc = lua_gettop(L);
    if (has_mbc) {
        if (!lua_istable(L, mbc)) {
            char got[64];
            bind_describe(L, mbc, got, sizeof got);
            return field_fail(L, 2, call, "mbc", "table", got);
        }
        nested_check_fields(L, mbc, 2, call, "mbc", MBC_FIELDS);
        int has_e = lua_getfield(L, mbc, "strain_rate") != LUA_TNIL;
        int has_g = lua_getfield(L, mbc, "gradient") != LUA_TNIL;
        if (has_e && has_g) {
            char got[64];
            bind_describe(L, -1, got, sizeof got);
            return field_fail(
                L, 2, call, "mbc.gradient",
                "nil (exactly one of strain_rate and gradient; 'mbc.strain_rate' is given)", got);
        }
        lua_pop(L, 2);
        if (!has_e && !has_g)
            return field_fail(
                L, 2, call, "mbc.strain_rate",
                "2x2 matrix (exactly one of strain_rate and gradient; nor is 'mbc.gradient' given)",
                "nil");
        def.gradient = has_g;
        read_matrix(L, mbc, has_g ? "gradient" : "strain_rate", 2, call,
                    has_g ? "mbc.gradient" : "mbc.strain_rate", def.target);
        if (lua_getfield(L, mbc, "mask") != LUA_TNIL) {
            read_matrix(L, mbc, "mask", 2, call, "mbc.mask", def.mask);
            /* a weight of 0.5 or 2 is no component switched on or off */
            for (int q = 0; q < 4; q++)
                if (def.mask[q] != 0 && def.mask[q] != 1) {
                    char got[64];
                    snprintf(got, sizeof got, "%g at row %d, column %d", def.mask[q], q / 2 + 1,
                             q % 2 + 1);
                    return field_fail(L, 2, call, "mbc.mask",
                                      "2x2 matrix of 0 (component free) and 1 (component held)",
                                      got);
                }
        }
        lua_pop(L, 1);
        K = nested_number(L, mbc, "K", 2, call, "mbc.K", 0, 1);
        kappa = nested_number(L, mbc, "kappa", 2, call, "mbc.kappa", 20, 1);
        rate = nested_number(L, mbc, "rate", 2, call, "mbc.rate", 0, 1);
        mdt = nested_number(L, mbc, "dt", 2, call, "mbc.dt", 0, 1);
        def.tau = nested_number(L, mbc, "tau", 2, call, "mbc.tau", mdt > 0 ? 1000 * mdt : 0, 0);
        if (rate == 0)
            for (int q = 0; q < 4; q++)
                rate = fmax(rate, fabs(def.target[q]) * (def.mask[q] != 0));
    }
    if (mode == 1) { /* fixed edges */
        if (lua_getfield(L, 2, "edges") != LUA_TTABLE)
            return bind_field_error(L, 2, call, "edges", "{a = {ids}, b = {ids}}");
        int et = lua_gettop(L);
        lua_getfield(L, et, "a");
        lua_getfield(L, et, "b");
        if (!lua_istable(L, -1) || !lua_istable(L, -2) || lua_rawlen(L, -1) != lua_rawlen(L, -2))
            return bind_field_error(L, 2, call, "edges", "{a = {ids}, b = {ids}} of equal length");
        lua_pop(L, 2);
        /* Each id an integer in range before it becomes a C index. */
        size_t n = 0, nb2 = 0;
        const long *a = read_ids_at(L, et, "a", 2, call, "edges.a", dem_count(s), 0, 1, &n);
        const long *b = read_ids_at(L, et, "b", 2, call, "edges.b", dem_count(s), 0, 1, &nb2);
        int closed = bind_field_boolean(L, 2, call, "closed", 0);
        def.update = NULL;
        core_error err;
        if (dem_set_boundary(s, &def, &err) || dem_set_boundary_edges(s, n, a, b, NULL, closed, &err))
            return bind_raise(L, call, &err);
    } else { /* Delaunay, rebuilt every `every` steps */
        /* Read everything that can raise before the context is allocated. */
        int band = bind_field_boolean(L, 2, call, "band", 1);
        size_t nids = 0;
        const long *ids = read_ids(L, 2, call, "ids", dem_count(s), 1, 0, &nids);
        if (ids && nids < 3) {
            char got[64];
            snprintf(got, sizeof got, "%d ids", (int)nids);
            return field_fail(L, 2, call, "ids", "array of at least 3 particle ids", got);
        }
        core_error err;
        if (delaunay_attach(&def, alpha, lateral, band, ids, nids, NULL, 0, &err))
            return bind_raise(L, call, &err);
        /* Build the edges first (a failed triangulation leaves the scene as it was). */
        double penalty = def.penalty;
        def.penalty = 0;
        if (dem_set_boundary(s, &def, &err)) {
            free_delaunay_ctx(def.ctx);
            return bind_raise(L, call, &err);
        }
        if (dem_update_boundary(s, &err)) {
            dem_clear_boundary(s);
            return bind_raise(L, call, &err);
        }
        def.penalty = penalty;
    }
    if (has_mbc) {
        dem_boundary_info bi;
        core_error err;
        dem_boundary_info_get(s, &bi, &err);
        if (!bi.closed && mode == 1)
            return field_fail(L, 2, call, "closed",
                              "true (the minimal boundary conditions need a closed loop)", "false");
        if (!bi.closed)
            return luaL_error(L, "%s: the minimal boundary conditions need a closed boundary "
                                 "loop (mode 'delaunay', or edges with closed = true)", call);
        if (K == 0) {
            /* K so that a strain-rate error equal to the imposed rate gives forces kappa times
             * the typical contact force p d depth (d ~ |g_a|): K = kappa p depth V / rate. */
            if (!(def.pressure > 0)) {
                char got[64];
                snprintf(got, sizeof got, "%g", def.pressure);
                return field_fail(L, 2, call, "pressure",
                                  "positive pressure (mbc without K chooses K from it)", got);
            }
            if (!(rate > 0))
                return field_fail(L, 2, call, "mbc.rate",
                                  "positive rate (mbc without K and with a zero target chooses "
                                  "K from it)",
                                  "nil");
            K = kappa * def.pressure * def.depth * bi.area / rate;
            if (mdt > 0) {
                /* ... but at most half the explicit limit for steps of mdt: the penalty damps
                 * the boundary's collective motion at the rate K sum|g_a|^2 / (V^2 m_min). */
                const long *ea, *eb;
                const unsigned char *ld;
                size_t ne = dem_boundary_edges(s, &ea, &eb, &ld);
                const double *x = dem_positions(s, 0), *y = dem_positions(s, 1);
                const double *mass = dem_masses(s);
                double g2 = 0, mmin = INFINITY;
                /* sum_a |g_a|^2 <= sum_a (L1^2 + L2^2)/2 = sum_edges L^2 */
                for (size_t k = 0; k < ne; k++) {
                    double L2 = (x[eb[k]] - x[ea[k]]) * (x[eb[k]] - x[ea[k]]) +
                                (y[eb[k]] - y[ea[k]]) * (y[eb[k]] - y[ea[k]]);
                    g2 += L2;
                    mmin = fmin(mmin, fmin(mass[ea[k]], mass[eb[k]]));
                }
                double kmax = 0.5 * bi.area * bi.area * mmin / (g2 * mdt);
                if (g2 > 0 && K > kmax)
                    K = kmax;
            }
        }
        def.penalty = K;
        if (dem_set_boundary(s, &def, &err))
            return bind_raise(L, call, &err);
    }
    push_boundary_info(L, s);
    lua_pushnumber(L, def.penalty);
    lua_setfield(L, -2, "K");
    return 1;
}

static int l_boundary_info(lua_State *L)
{
    dem_scene *s = bind_check_dem_scene(L, 1, "boundary_info");
    push_boundary_info(L, s);
    return 1;
}

static int l_boundary_edges(lua_State *L)
{
    dem_scene *s = bind_check_dem_scene(L, 1, "boundary_edges");
    const long *a, *b;
    const unsigned char *loaded;
    size_t n = dem_boundary_edges(s, &a, &b, &loaded);
    lua_createtable(L, 0, 3);
    const char *names[3] = {"a", "b", "loaded"};
    for (int q = 0; q < 3; q++) {
        lua_createtable(L, (int)n, 0);
        for (size_t k = 0; k < n; k++) {
            if (q == 2)
                lua_pushboolean(L, loaded[k]);
            else
                lua_pushinteger(L, (q == 0 ? a[k] : b[k]) + 1);
            lua_rawseti(L, -2, (lua_Integer)k + 1);
        }
        lua_setfield(L, -2, names[q]);
    }
    return 1;
}

static const char *const SPRINGS_FIELDS[] = {"i", "j", "k", "rest", NULL};

static int l_springs(lua_State *L)
{
    const char *call = "springs";
    dem_scene *s = bind_check_dem_scene(L, 1, call);
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, SPRINGS_FIELDS);
    double k = bind_field_number(L, 2, call, "k", 0, BIND_REQUIRED | BIND_POSITIVE);
    /* Ids checked as integers in range before they become C indices. */
    size_t n = 0, nj = 0;
    const long *li = read_ids(L, 2, call, "i", dem_count(s), 0, 1, &n);
    const long *lj = read_ids(L, 2, call, "j", dem_count(s), 0, 1, &nj);
    if (nj != n) {
        char got[64], want[64];
        snprintf(got, sizeof got, "%zu values", nj);
        snprintf(want, sizeof want, "as many ids as 'i' (%zu)", n);
        return field_fail(L, 2, call, "j", want, got);
    }
    double *rest = read_array(L, 2, call, "rest", &n, 0);
    core_error err;
    if (dem_add_springs(s, n, li, lj, k, rest, &err))
        return bind_raise(L, call, &err);
    return 0;
}

static const char *const TIE_FIELDS[] = {"ids", "wall", "axis", NULL};

static int l_tie(lua_State *L)
{
    const char *call = "tie";
    dem_scene *s = bind_check_dem_scene(L, 1, call);
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, TIE_FIELDS);
    int wall = (int)bind_field_integer(L, 2, call, "wall", 0, 1, 1 << 30, BIND_REQUIRED) - 1;
    int axis = (int)bind_field_integer(L, 2, call, "axis", 2, 1, 2, 0) - 1;
    size_t n = 0;
    const long *ids = read_ids(L, 2, call, "ids", dem_count(s), 0, 1, &n);
    if (n == 0) { /* tying nothing is a mistake, not a no-op */
        lua_getfield(L, 2, "ids");
        return bind_field_error(L, 2, call, "ids", "non-empty array of particle ids");
    }
    for (size_t q = 0; q < n; q++) {
        core_error err;
        if (dem_tie_to_wall(s, (size_t)ids[q], wall, axis, &err))
            return bind_raise(L, call, &err);
    }
    return 0;
}

static const char *const SPIN_FIELDS[] = {"id", "omega", NULL};

static int l_spin(lua_State *L)
{
    const char *call = "spin";
    dem_scene *s = bind_check_dem_scene(L, 1, call);
    bind_check_table(L, 2, call);
    bind_check_fields(L, 2, call, SPIN_FIELDS);
    lua_Integer id = bind_field_integer(L, 2, call, "id", 0, 1, (lua_Integer)dem_count(s),
                                        BIND_REQUIRED);
    double w = bind_field_number(L, 2, call, "omega", 0, BIND_REQUIRED);
    core_error err;
    if (dem_set_spin(s, (size_t)id - 1, w, &err))
        return bind_raise(L, call, &err);
    return 0;
}

void bind_open_analysis(lua_State *L)
{
    static const bind_fn methods[] = {
        {"info", l_mesh_info, "mesh:info()",
         "particles, cells, delaunay (triangles before peeling), peeled, boundary (loop length), "
         "area (m^2, build configuration)."},
        {"cells", l_mesh_cells, "mesh:cells([state])",
         "Arrays a, b, c (particle ids of each cell, counter-clockwise), area, cx, cy (centroid) "
         "in the build configuration or in state (a dem.scene or {x =, y =})."},
        {"boundary", l_mesh_boundary, "mesh:boundary()",
         "The particle ids of the boundary loop, counter-clockwise."},
        {"strain", l_mesh_strain, "mesh:strain(state)",
         "Bagi-Satake strain of the displacement from the build configuration to state (a "
         "dem.scene or {x =, y =}), gradients over the build configuration (constant-strain "
         "triangles): per-cell arrays xx, xy, yx, yy (symmetric); coarse (Eq. 3.1 boundary "
         "integral, symmetric part), coarse_gradient, mean_gradient (area-weighted cell mean, "
         "equal to coarse_gradient), volumetric (tr coarse), area."},
        {"strain_rate", l_mesh_strain_rate, "mesh:strain_rate(state)",
         "Velocity gradient per cell over the current positions of state (a dem.scene or {x, y, "
         "vx, vy}): arrays xx, xy, yx, yy (L_ij = dv_i/dx_j), lii (L_II = sqrt(L':L'/2), L' = L "
         "- tr(L)/2 I), mean_lii (area-weighted), coarse_gradient and coarse (Eq. 3.2)."},
        {"stress", l_mesh_stress, "mesh:stress(scene, { depth = thickness })",
         "Christoffersen's stress (compression positive) from the scene's contacts now: per "
         "particle -(1/V_p) sum (x_c - X_p) f_c with V_p = depth x a third of its cells' area, "
         "per cell the mean of its three particles: arrays xx, xy, yx, yy, pressure ((xx + "
         "yy)/2), particle_pressure; mean (area-weighted tensor), mean_pressure, contacts. "
         "Wall contacts count with their normal force."},
        {"raster", l_mesh_raster,
         "mesh:raster(values, { nx =, ny =, extent = {{x0, y0}, {x1, y1}}, state = scene })",
         "Samples one value per cell on an nx x ny grid (row-major from the bottom row, NaN "
         "outside the cells) for render.field: cell maps (Padbidri Figs. 3.10, 3.11)."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {
        {"__gc", l_mesh_gc}, {"__close", l_mesh_gc}, {"__tostring", l_mesh_tostring}, {NULL, NULL}};
    bind_new_type(L, MESH, methods, meta,
                  "A Delaunay mesh of particle centres from analysis.delaunay; it keeps the "
                  "positions it was built on as the reference configuration.");
    static const bind_fields mesh_fields[] = {
        {"cells", NULL, STATE_FIELDS},       {"strain", NULL, STATE_FIELDS},
        {"strain_rate", NULL, STATE_FIELDS}, {"stress", NULL, STRESS_FIELDS},
        {"raster", NULL, RASTER_FIELDS},     {NULL, NULL, NULL}};
    bind_type_fields(L, MESH, mesh_fields);
    static const bind_fn fns[] = {
        {"delaunay", l_delaunay,
         "analysis.delaunay(scene | { x =, y =, radius = }, { alpha = 1.5, ids = {...} })",
         "Delaunay triangulation of 2D particle centres (qhull), with the boundary triangles "
         "peeled while their outer edge (a, b) is longer than alpha (r_a + r_b) and their third "
         "particle is inside (so the outline never pinches and every particle stays in the mesh; "
         "alpha = 0: the convex hull; without radii, r is half the median edge). Triangles "
         "flat to rounding on the outline (centres in a row along a wall) are peeled whatever "
         "alpha. ids: triangulate only these particles (distinct ids, entries of x/y or of the "
         "scene). Refuses fewer than 3 particles, collinear centres, duplicate positions and "
         "non-positive radii. Returns an analysis.mesh."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {{"delaunay", NULL, DELAUNAY_FIELDS},
                                            {NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    bind_doc(L, -1, "analysis", "analysis",
             "The Delaunay-cell continuum of a 2D assembly (Padbidri Sec. 2.5, 3.2): cells, "
             "boundary loop, Bagi-Satake strains and strain rates, L_II, Christoffersen stress.");
    lua_setglobal(L, "analysis");

    /* Boundary-condition methods join the dem.scene methods. */
    static const bind_fn scene_methods[] = {
        {"boundary", l_boundary,
         "s:boundary{ mode = 'delaunay'|'edges'|'none', pressure = 0, depth = thickness, every "
         "= 250, alpha = 1.5, sides = 'all'|'lateral', ids =, band = true, edges = {a =, b =}, "
         "closed = false, "
         "mbc = { strain_rate = {{xx, xy}, {yx, yy}} | gradient = {{..}, {..}}, mask = {{1, 1}, "
         "{1, 1}}, K =, kappa = 20, rate =, dt =, tau = 1000 dt } }",
         "Boundary conditions of the biaxial laboratory (Padbidri Ch. 3, 2D). Pressure p acts as "
         "tractions p depth L on boundary edges, split between their two particles. mode "
         "delaunay: the edges are the boundary loop of analysis.delaunay of the centres (or of "
         "`ids`) with `alpha`, rebuilt every `every` steps during runs (band = true: after the "
         "first, only the particles within about 3-6 mean diameters of the previous loop are "
         "triangulated, 4-5 times cheaper); sides = 'lateral' unloads "
         "the edges that face a wall (outward normal against the wall's within 60 degrees) with "
         "both particles within their radius plus two mean diameters of it: the plates carry the "
         "load there. mode edges: fixed edges a -> b "
         "(outward normal (dy, -dx)), e.g. a membrane chain; closed = true for a loop. mbc: "
         "minimal boundary conditions, the penalty force F_a = -(K/V) (mask o dE) g_a (Eqs. "
         "3.2-3.5) driving the coarse strain rate (or velocity gradient) to the target on the "
         "masked components; K defaults to kappa p depth V / rate, so that a rate error equal to "
         "the imposed rate gives forces kappa times the typical contact force p d depth, and, "
         "given dt, at most half the explicit stability limit 1/(dt sum|g_a|^2/(V^2 m_min)). "
         "tau > 0 (default 1000 dt when dt is given, else 0) adds the integral of the error over "
         "tau, so that the capped K does not let the strain lag (a proportional-integral "
         "penalty; tau = 0 is the paper's rate penalty alone). A run stops with an error when K is too stiff for its dt. mode none removes the boundary, "
         "springs and ties. A field of another mode (edges in mode delaunay, ids in mode edges, "
         "anything but mode in mode none) is refused, not ignored. Returns s:boundary_info() "
         "plus K."},
        {"boundary_info", l_boundary_info, "s:boundary_info()",
         "edges, loaded, nodes, closed, area (inside the loop), gradient and strain_rate (coarse, "
         "Eq. 3.2, from the velocities now), penalty_sum {fx, fy} and penalty_max (N, last "
         "evaluation), pressure_max, penalty_rate (1/s), updates, update_seconds (process CPU time in the "
         "triangulation), apply_seconds (CPU time applying the forces), springs, ties."},
        {"boundary_edges", l_boundary_edges, "s:boundary_edges()",
         "The pressure edges now: arrays a, b (particle ids) and loaded (booleans)."},
        {"springs", l_springs, "s:springs{ i = {...}, j = {...}, k = N_per_m, rest = {...} }",
         "Linear springs between particle pairs (membrane chains; Padbidri Table 3.1: 10 N/mm), "
         "rest lengths default to the current distances."},
        {"spin", l_spin, "s:spin{ id = i, omega = w }",
         "Prescribes particle i's angular velocity (rad/s; its torque is ignored, its translation "
         "stays free); call again to change it (a ramp). The forced particle of Padbidri Ch. 4."},
        {"tie", l_tie, "s:tie{ ids = {...}, wall = id, axis = 2 }",
         "Ties the particles' velocity component `axis` to the wall's (membrane ends move "
         "vertically with the plates)."},
        {NULL, NULL, NULL, NULL}};
    luaL_getmetatable(L, "dem.scene");
    lua_getfield(L, -1, "__index");
    bind_register(L, lua_gettop(L), scene_methods);
    lua_pop(L, 2);
    static const bind_fields method_fields[] = {{"boundary", NULL, BOUNDARY_FIELDS},
                                                {"springs", NULL, SPRINGS_FIELDS},
                                                {"spin", NULL, SPIN_FIELDS},
                                                {"tie", NULL, TIE_FIELDS},
                                                {NULL, NULL, NULL}};
    bind_type_fields(L, "dem.scene", method_fields);
}
