/* The boundary-condition methods of dem.scene (over src/dem/boundary.c): s:boundary,
 * boundary_info, boundary_edges, springs, tie, spin. This file is also the small layer that
 * couples the DEM with src/analysis: the Delaunay boundary update handed to the DEM as a callback,
 * and its save and restore in checkpoints. */
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/analysis.h"
#include "core/checkpoint.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_analysis.h"

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
        bind_field_fail(L, arg, call, label, want, got);
    }
    for (int r = 0; r < 2; r++) {
        if (lua_rawgeti(L, -1, r + 1) != LUA_TTABLE || lua_rawlen(L, -1) != 2) {
            char row[64];
            bind_describe(L, -1, row, sizeof row);
            if (lua_type(L, -1) == LUA_TTABLE)
                snprintf(got, sizeof got, "%d entries in row %d", (int)lua_rawlen(L, -1), r + 1);
            else
                snprintf(got, sizeof got, "%s as row %d", row, r + 1);
            bind_field_fail(L, arg, call, label, want, got);
        }
        for (int c = 0; c < 2; c++) {
            lua_rawgeti(L, -1, c + 1);
            out[2 * r + c] = lua_tonumber(L, -1);
            if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(out[2 * r + c]) ||
                fabs(out[2 * r + c]) > 1e100) { /* the bindings' magnitude cap */
                char v[48];
                bind_describe(L, -1, v, sizeof v);
                snprintf(got, sizeof got, "%s at row %d, column %d", v, r + 1, c + 1);
                bind_field_fail(L, arg, call, label, want, got);
            }
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* Readers for a table nested in argument arg (mbc): errors name the field as 'mbc.K' of that
 * argument (args.c's readers would number the nested table by its stack slot). */
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
        bind_field_fail(L, arg, call, label, positive ? "positive number" : "non-negative number",
                        got);
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
    bind_push_tensor(L, bi.grad);
    lua_setfield(L, -2, "gradient");
    bind_push_tensor(L, bi.strain_rate);
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

/* A field of another mode would be ignored without a word: refused, naming it. */
static void refuse_other_modes(lua_State *L, const char *call, int mode)
{
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
            bind_field_fail(L, 2, call, not_in[mode][k], want, got);
        }
        lua_pop(L, 1);
    }
}

/* The minimal boundary conditions' options besides those of def: K (0: chosen), kappa, the
 * rate the choice of K divides by, and the step the choice must stay stable for. */
typedef struct mbc_opts {
    double K, kappa, rate, mdt;
} mbc_opts;

/* mbc = { strain_rate = | gradient =, mask =, K =, kappa =, rate =, dt =, tau = } into def and
 * o; returns 0 when mbc is absent. The table stays on the stack. */
static int read_mbc(lua_State *L, const char *call, dem_boundary_def *def, mbc_opts *o)
{
    o->kappa = 20;
    o->rate = o->K = o->mdt = 0;
    int has_mbc = lua_getfield(L, 2, "mbc") != LUA_TNIL;
    int mbc = lua_gettop(L);
    if (!has_mbc)
        return 0;
    if (!lua_istable(L, mbc)) {
        char got[64];
        bind_describe(L, mbc, got, sizeof got);
        bind_field_fail(L, 2, call, "mbc", "table", got);
    }
    bind_check_nested_fields(L, mbc, 2, call, "mbc", MBC_FIELDS);
    int has_e = lua_getfield(L, mbc, "strain_rate") != LUA_TNIL;
    int has_g = lua_getfield(L, mbc, "gradient") != LUA_TNIL;
    if (has_e && has_g) {
        char got[64];
        bind_describe(L, -1, got, sizeof got);
        bind_field_fail(
            L, 2, call, "mbc.gradient",
            "nil (exactly one of strain_rate and gradient; 'mbc.strain_rate' is given)", got);
    }
    lua_pop(L, 2);
    if (!has_e && !has_g)
        bind_field_fail(
            L, 2, call, "mbc.strain_rate",
            "2x2 matrix (exactly one of strain_rate and gradient; nor is 'mbc.gradient' given)",
            "nil");
    def->gradient = has_g;
    read_matrix(L, mbc, has_g ? "gradient" : "strain_rate", 2, call,
                has_g ? "mbc.gradient" : "mbc.strain_rate", def->target);
    if (lua_getfield(L, mbc, "mask") != LUA_TNIL) {
        read_matrix(L, mbc, "mask", 2, call, "mbc.mask", def->mask);
        /* a weight of 0.5 or 2 is no component switched on or off */
        for (int q = 0; q < 4; q++)
            if (def->mask[q] != 0 && def->mask[q] != 1) {
                char got[64];
                snprintf(got, sizeof got, "%g at row %d, column %d", def->mask[q], q / 2 + 1,
                         q % 2 + 1);
                bind_field_fail(L, 2, call, "mbc.mask",
                                "2x2 matrix of 0 (component free) and 1 (component held)", got);
            }
    }
    lua_pop(L, 1);
    o->K = nested_number(L, mbc, "K", 2, call, "mbc.K", 0, 1);
    o->kappa = nested_number(L, mbc, "kappa", 2, call, "mbc.kappa", 20, 1);
    o->rate = nested_number(L, mbc, "rate", 2, call, "mbc.rate", 0, 1);
    o->mdt = nested_number(L, mbc, "dt", 2, call, "mbc.dt", 0, 1);
    def->tau = nested_number(L, mbc, "tau", 2, call, "mbc.tau", o->mdt > 0 ? 1000 * o->mdt : 0, 0);
    if (o->rate == 0)
        for (int q = 0; q < 4; q++)
            o->rate = fmax(o->rate, fabs(def->target[q]) * (def->mask[q] != 0));
    return 1;
}

/* mode = 'edges': the fixed edges a -> b. */
static void set_fixed_edges(lua_State *L, dem_scene *s, const char *call, dem_boundary_def *def)
{
    if (lua_getfield(L, 2, "edges") != LUA_TTABLE)
        bind_field_error(L, 2, call, "edges", "{a = {ids}, b = {ids}}");
    int et = lua_gettop(L);
    lua_getfield(L, et, "a");
    lua_getfield(L, et, "b");
    if (!lua_istable(L, -1) || !lua_istable(L, -2) || lua_rawlen(L, -1) != lua_rawlen(L, -2))
        bind_field_error(L, 2, call, "edges", "{a = {ids}, b = {ids}} of equal length");
    lua_pop(L, 2);
    /* Each id an integer in range before it becomes a C index. */
    size_t n = 0, nb2 = 0;
    const long *a = bind_read_ids_at(L, et, "a", 2, call, "edges.a", dem_count(s), 0, 1, &n);
    const long *b = bind_read_ids_at(L, et, "b", 2, call, "edges.b", dem_count(s), 0, 1, &nb2);
    int closed = bind_field_boolean(L, 2, call, "closed", 0);
    def->update = NULL;
    core_error err;
    if (dem_set_boundary(s, def, &err) || dem_set_boundary_edges(s, n, a, b, NULL, closed, &err))
        bind_raise(L, call, &err);
}

/* mode = 'delaunay': the update installed and run once, so the edges exist (a failed
 * triangulation leaves the scene as it was). */
static void set_delaunay_edges(lua_State *L, dem_scene *s, const char *call,
                               dem_boundary_def *def, double alpha, int lateral)
{
    /* Read everything that can raise before the context is allocated. */
    int band = bind_field_boolean(L, 2, call, "band", 1);
    size_t nids = 0;
    const long *ids = bind_read_ids(L, 2, call, "ids", dem_count(s), 1, 0, &nids);
    if (ids && nids < 3) {
        char got[64];
        snprintf(got, sizeof got, "%d ids", (int)nids);
        bind_field_fail(L, 2, call, "ids", "array of at least 3 particle ids", got);
    }
    core_error err;
    if (delaunay_attach(def, alpha, lateral, band, ids, nids, NULL, 0, &err))
        bind_raise(L, call, &err);
    /* Build the edges first (a failed triangulation leaves the scene as it was). */
    double penalty = def->penalty;
    def->penalty = 0;
    if (dem_set_boundary(s, def, &err)) {
        free_delaunay_ctx(def->ctx);
        bind_raise(L, call, &err);
    }
    if (dem_update_boundary(s, &err)) {
        dem_clear_boundary(s);
        bind_raise(L, call, &err);
    }
    def->penalty = penalty;
}

/* The largest K the explicit steps of mdt keep stable, halved: the penalty damps the boundary's
 * collective motion at the rate K sum|g_a|^2 / (V^2 m_min); 0 when there are no edges. */
static double penalty_cap(dem_scene *s, double area, double mdt, double *g2_out)
{
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
    *g2_out = g2;
    return 0.5 * area * area * mmin / (g2 * mdt);
}

/* The minimal boundary conditions' penalty K on the boundary now set: the given K, or one
 * chosen from kappa, the pressure and the rate (capped by mdt's stability). */
static void set_penalty(lua_State *L, dem_scene *s, const char *call, dem_boundary_def *def,
                        int mode, const mbc_opts *o)
{
    dem_boundary_info bi;
    core_error err;
    double K = o->K;
    dem_boundary_info_get(s, &bi, &err);
    if (!bi.closed && mode == 1)
        bind_field_fail(L, 2, call, "closed",
                        "true (the minimal boundary conditions need a closed loop)", "false");
    if (!bi.closed)
        luaL_error(L, "%s: the minimal boundary conditions need a closed boundary "
                      "loop (mode 'delaunay', or edges with closed = true)", call);
    if (K == 0) {
        /* K so that a strain-rate error equal to the imposed rate gives forces kappa times
         * the typical contact force p d depth (d ~ |g_a|): K = kappa p depth V / rate. */
        if (!(def->pressure > 0)) {
            char got[64];
            snprintf(got, sizeof got, "%g", def->pressure);
            bind_field_fail(L, 2, call, "pressure",
                            "positive pressure (mbc without K chooses K from it)", got);
        }
        if (!(o->rate > 0))
            bind_field_fail(L, 2, call, "mbc.rate",
                            "positive rate (mbc without K and with a zero target chooses "
                            "K from it)",
                            "nil");
        K = o->kappa * def->pressure * def->depth * bi.area / o->rate;
        if (o->mdt > 0) {
            /* ... but at most half the explicit limit for steps of mdt. */
            double g2, kmax = penalty_cap(s, bi.area, o->mdt, &g2);
            if (g2 > 0 && K > kmax)
                K = kmax;
        }
    }
    def->penalty = K;
    if (dem_set_boundary(s, def, &err))
        bind_raise(L, call, &err);
}

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
    refuse_other_modes(L, call, mode);
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
    mbc_opts mbc;
    int has_mbc = read_mbc(L, call, &def, &mbc);
    if (mode == 1) /* fixed edges */
        set_fixed_edges(L, s, call, &def);
    else /* Delaunay, rebuilt every `every` steps */
        set_delaunay_edges(L, s, call, &def, alpha, lateral);
    if (has_mbc)
        set_penalty(L, s, call, &def, mode, &mbc);
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
    const long *li = bind_read_ids(L, 2, call, "i", dem_count(s), 0, 1, &n);
    const long *lj = bind_read_ids(L, 2, call, "j", dem_count(s), 0, 1, &nj);
    if (nj != n) {
        char got[64], want[64];
        snprintf(got, sizeof got, "%zu values", nj);
        snprintf(want, sizeof want, "as many ids as 'i' (%zu)", n);
        return bind_field_fail(L, 2, call, "j", want, got);
    }
    double *rest = bind_read_array(L, 2, call, "rest", &n, 0);
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
    const long *ids = bind_read_ids(L, 2, call, "ids", dem_count(s), 0, 1, &n);
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

/* The boundary-condition methods join the dem.scene methods (after bind_open_dem). */
void bind_open_boundary(lua_State *L)
{
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
