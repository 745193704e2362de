/* The Lua module `analysis`: the Delaunay-cell continuum over src/analysis (analysis.delaunay
 * and the analysis.mesh methods), and the readers of arrays and particle ids it shares with the
 * boundary conditions of dem.scene (lua_boundary.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"
#include "core/clock.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_analysis.h"

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
int bind_field_fail(lua_State *L, int arg, const char *call, const char *name,
                    const char *expected, const char *got)
{
    return luaL_error(L, "bad field '%s' in argument #%d to '%s' (%s expected, got %s)", name,
                      user_argn(L, arg), call, expected, got);
}

/* The field error for the value on top, entry k (1-based) of the array `name`. */
static int entry_error(lua_State *L, int arg, const char *call, const char *name,
                       const char *expected, size_t k)
{
    char val[64], got[96];
    bind_describe(L, -1, val, sizeof val);
    snprintf(got, sizeof got, "%s at entry %zu", val, k);
    return bind_field_fail(L, arg, call, name, expected, got);
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
        bind_field_fail(L, arg, call, name, what, got);
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

double *bind_read_array(lua_State *L, int arg, const char *call, const char *name, size_t *n,
                        int required)
{
    return read_array_at(L, arg, name, arg, call, name, n, required);
}

/* Reads field `key` of the table at tab as an array of particle ids, integers in [1, max],
 * into a 0-based buffer left on the stack; distinct: a repeated id is refused, naming both
 * entries. Errors name field `label` of argument arg. Absent and not required: NULL. The
 * length goes to *n. */
long *bind_read_ids_at(lua_State *L, int tab, const char *key, int arg, const char *call,
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
        bind_field_fail(L, arg, call, label, "array of particle ids", got);
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
            bind_field_fail(L, arg, call, label, "distinct particle ids", got);
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

long *bind_read_ids(lua_State *L, int arg, const char *call, const char *name, size_t max,
                    int distinct, int required, size_t *n)
{
    return bind_read_ids_at(L, arg, name, arg, call, name, max, distinct, required, n);
}

void bind_push_tensor(lua_State *L, const double t[4])
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
        x = bind_read_array(L, 1, call, "x", &n, 1);
        y = bind_read_array(L, 1, call, "y", &n, 1);
        r = bind_read_array(L, 1, call, "radius", &n, 0);
        for (size_t i = 0; r && i < n; i++)
            if (!(r[i] > 0)) {
                lua_getfield(L, 1, "radius");
                lua_rawgeti(L, -1, (lua_Integer)i + 1);
                return entry_error(L, 1, call, "radius", "array of positive radii", i + 1);
            }
    }
    /* ids: entries of the table (or scene particles), distinct, so that the mesh's vertices
     * map back to one particle each. */
    if (has_opts && (ids = bind_read_ids(L, 2, call, "ids", n, 1, 0, &nids))) {
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
            bind_field_fail(L, uarg, call, nest, "dem.scene or {x =, y =}", got);
        }
        bind_check_nested_fields(L, arg, uarg, call, nest, STATE_FIELDS);
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
    bind_push_tensor(L, E);
    lua_setfield(L, -2, "coarse");
    bind_push_tensor(L, H);
    lua_setfield(L, -2, "coarse_gradient");
    bind_push_tensor(L, mean);
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
    bind_push_tensor(L, H);
    lua_setfield(L, -2, "coarse_gradient");
    bind_push_tensor(L, E);
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
    bind_push_tensor(L, mean);
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

    bind_open_boundary(L);
}
