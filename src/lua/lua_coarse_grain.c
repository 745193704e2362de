/* analysis.coarse_grain and analysis.cg_average (over src/analysis/coarse_grain.c): a DEM scene's
 * particles and contacts, or an MPM scene's points, gathered into the kernel's arrays; the
 * fields back as Lua tables of arrays, or into .vti and CSV files. render.coarse_grain, which
 * draws them, is in lua_coarse_grain_render.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/coarse_grain.h"
#include "core/clock.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_coarse_grain.h"
#include "mpm/mpm.h"

#define CG_PI 3.14159265358979323846
#define AVERAGE "analysis.cg_average"
/* evaluation points: a 100^3 or 1000^2 grid (the fields' Lua tables take ~1 kB per point) */
enum { CG_MAX_POINTS = 1 << 20 };
enum { KIND_NONE, KIND_DEM, KIND_MPM };

static const char *const CG_FIELDS[] = {"kernel",       "width",  "cutoff", "cells",
                                        "region",       "points", "depth",  "contacts",
                                        "displacement", "vtk",    "csv",    NULL};
/* cg_average: the same without the files (avg:fields writes them) */
static const char *const AVG_FIELDS[] = {"kernel", "width", "cutoff",   "cells",        "region",
                                         "points", "depth", "contacts", "displacement", NULL};
static const char *const POINTS_FIELDS[] = {"x", "y", "z", NULL};
static const char *const OUT_FIELDS[] = {"vtk", "csv", NULL};
static const char *const KERNELS[] = {"gauss", "lucy", NULL};

/* What the fields are computed on: the kernel, the evaluation points and the options. */
typedef struct cg_setup {
    analysis_cg_def def;
    int kind; /* KIND_DEM or KIND_MPM */
    int grid; /* 1: cells over region; 0: given points */
    int cells[3];
    double lo[3], hi[3];
    size_t n; /* evaluation points */
    double *pts[3];
    int contacts, displacement;
    analysis_cg_layout layout;
} cg_setup;

/* Scratch a sample reuses (grown as needed), and the running sums of an average. */
typedef struct cg_state {
    cg_setup set;
    size_t cap_c, nc; /* contacts */
    long *ci;
    double *cb[3], *cf[3];
    unsigned char *cw;
    int oom;
    size_t cap_p; /* per-particle scratch */
    double *vol, *fab, *disp[3], *stress;
    double *sums; /* n x stride: the last sample */
    double *acc;  /* n x stride: the sum of the samples (averages) */
    long samples;
    double t_first, t_last; /* scene times of the first and last sample */
    double seconds;         /* wall time of the samples (gathering and sums) */
    double cpu_seconds;     /* their CPU time (all threads) */
} cg_state;

static void state_free(cg_state *w)
{
    free(w->ci);
    free(w->cw);
    for (int a = 0; a < 3; a++) {
        free(w->cb[a]);
        free(w->cf[a]);
        free(w->disp[a]);
        free(w->set.pts[a]);
    }
    free(w->vol);
    free(w->fab);
    free(w->stress);
    free(w->sums);
    free(w->acc);
    memset(w, 0, sizeof *w);
}

static int l_state_gc(lua_State *L)
{
    cg_state *w = luaL_checkudata(L, 1, AVERAGE);
    state_free(w);
    return 0;
}

/* A new state userdata (freed by the GC, also when a later check raises). */
static cg_state *new_state(lua_State *L)
{
    cg_state *w = lua_newuserdatauv(L, sizeof *w, 0);
    memset(w, 0, sizeof *w);
    luaL_setmetatable(L, AVERAGE);
    return w;
}

static void *grow(void *p, size_t n, size_t size, int *oom)
{
    void *q = realloc(p, (n ? n : 1) * size);
    if (!q)
        *oom = 1;
    return q ? q : p;
}

/* ---- options --------------------------------------------------------------------------------- */
/* Reads field `key` of the table at tab (field `label` of argument arg in messages) as an array of
 * finite numbers into a malloc'd buffer; the length goes to *n (checked against *n when > 0). */
static double *read_numbers(lua_State *L, int tab, const char *key, int arg, const char *call,
                            const char *label, size_t *n, const char *first)
{
    char what[128];
    if (*n)
        snprintf(what, sizeof what, "array of %zu finite numbers (the length of '%s')", *n, first);
    else
        snprintf(what, sizeof what, "non-empty array of finite numbers");
    if (lua_getfield(L, tab, key) != LUA_TTABLE)
        bind_field_error(L, arg, call, label, what);
    size_t len = lua_rawlen(L, -1);
    if ((*n && len != *n) || len == 0 || len > CG_MAX_POINTS)
        luaL_error(L, "bad field '%s' in argument #%d to '%s' (%s%s expected, got %d values)",
                   label, arg, call, what, len > CG_MAX_POINTS ? " (at most 1048576)" : "",
                   (int)len);
    double *v = malloc(len * sizeof *v);
    if (!v)
        luaL_error(L, "%s: out of memory for %d points", call, (int)len);
    for (size_t i = 0; i < len; i++) {
        lua_rawgeti(L, -1, (lua_Integer)i + 1);
        v[i] = lua_tonumber(L, -1);
        if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(v[i]) || fabs(v[i]) > 1e100) {
            free(v);
            char val[48];
            bind_describe(L, -1, val, sizeof val);
            luaL_error(L,
                       "bad field '%s' in argument #%d to '%s' (%s expected, got %s at entry %d)",
                       label, arg, call, what, val, (int)(i + 1));
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    *n = len;
    return v;
}

/* Reads the options at arg for a scene of kind `kind` (dim, box, periodic, thickness given) into
 * w->set. The points are malloc'd into the state (freed with it). */
static void read_setup(lua_State *L, int arg, const char *call, int kind, int dim,
                       const double box_lo[3], const double box_hi[3], const bool periodic[3],
                       double thickness, int files, cg_state *w)
{
    cg_setup *st = &w->set;
    bind_check_table(L, arg, call);
    bind_check_fields(L, arg, call, files ? CG_FIELDS : AVG_FIELDS);
    st->kind = kind;
    st->def = analysis_cg_default_def();
    st->def.dim = dim;
    st->def.kernel = bind_field_option(L, arg, call, "kernel", KERNELS, 0, 0) ? ANALYSIS_CG_LUCY
                                                                              : ANALYSIS_CG_GAUSS;
    st->def.width = bind_field_number(L, arg, call, "width", 0, BIND_REQUIRED | BIND_POSITIVE);
    if (lua_getfield(L, arg, "cutoff") != LUA_TNIL && st->def.kernel == ANALYSIS_CG_LUCY)
        bind_field_error(L, arg, call, "cutoff",
                         "nil with kernel 'lucy' (its cutoff is its width)");
    lua_pop(L, 1);
    st->def.cutoff = bind_field_number(L, arg, call, "cutoff", 0, BIND_POSITIVE);
    if (st->def.cutoff > 10 * st->def.width) {
        lua_getfield(L, arg, "cutoff");
        char what[64];
        snprintf(what, sizeof what, "cutoff at most 10 widths (%g)", 10 * st->def.width);
        bind_field_error(L, arg, call, "cutoff", what);
    }
    for (int a = 0; a < 3; a++) {
        st->def.periodic[a] = a < dim && periodic[a];
        st->def.lo[a] = box_lo[a];
        st->def.hi[a] = box_hi[a];
    }
    if (lua_getfield(L, arg, "depth") != LUA_TNIL && dim == 3)
        bind_field_error(L, arg, call, "depth", "nil in 3D (depth divides 2D fields)");
    lua_pop(L, 1);
    st->def.depth =
        bind_field_number(L, arg, call, "depth", thickness > 0 ? thickness : 1, BIND_POSITIVE);
    if (kind == KIND_MPM) {
        static const char *const dem_only[] = {"contacts", "displacement", NULL};
        for (int q = 0; dem_only[q]; q++) {
            if (lua_getfield(L, arg, dem_only[q]) != LUA_TNIL)
                bind_field_error(L, arg, call, dem_only[q], "nil for an mpm.scene (a DEM option)");
            lua_pop(L, 1);
        }
    }
    st->contacts = kind == KIND_DEM && bind_field_boolean(L, arg, call, "contacts", 1);
    st->displacement = kind == KIND_DEM && bind_field_boolean(L, arg, call, "displacement", 0);
    if (files) { /* checked here, written by the caller */
        bind_field_path(L, arg, call, "vtk", 0);
        bind_field_path(L, arg, call, "csv", 0);
    }

    const int has_cells = lua_getfield(L, arg, "cells") != LUA_TNIL;
    const int has_region = lua_getfield(L, arg, "region") != LUA_TNIL;
    const int has_points = lua_getfield(L, arg, "points") != LUA_TNIL;
    lua_pop(L, 3);
    if (has_points && (has_cells || has_region)) {
        lua_getfield(L, arg, "points");
        bind_field_error(L, arg, call, "points",
                         "nil when 'cells' or 'region' is given (a grid or points)");
    }
    if (!has_points && !has_cells) {
        lua_pushnil(L);
        bind_field_error(L, arg, call, "cells",
                         "{nx, ny[, nz]} (or 'points' = {x =, y =}: where the fields are wanted)");
    }
    if (has_points) {
        st->grid = 0;
        lua_getfield(L, arg, "points");
        const int tab = lua_gettop(L);
        if (!lua_istable(L, tab))
            bind_field_error(L, arg, call, "points", dim == 2 ? "{x =, y =}" : "{x =, y =, z =}");
        bind_check_nested_fields(L, tab, arg, call, "points", POINTS_FIELDS);
        if (dim == 2 && lua_getfield(L, tab, "z") != LUA_TNIL)
            bind_field_error(L, arg, call, "points.z", "nil in 2D");
        if (dim == 2)
            lua_pop(L, 1);
        static const char *const keys[3] = {"x", "y", "z"};
        static const char *const labels[3] = {"points.x", "points.y", "points.z"};
        size_t n = 0;
        for (int a = 0; a < dim; a++)
            w->set.pts[a] = read_numbers(L, tab, keys[a], arg, call, labels[a], &n, labels[0]);
        for (int a = dim; a < 3; a++) {
            w->set.pts[a] = calloc(n, sizeof(double));
            if (!w->set.pts[a])
                luaL_error(L, "%s: out of memory", call);
        }
        st->n = n;
        lua_pop(L, 1);
    } else {
        st->grid = 1;
        char what[64];
        snprintf(what, sizeof what, "array of %d positive integers (cells per axis)", dim);
        if (lua_getfield(L, arg, "cells") != LUA_TTABLE || lua_rawlen(L, -1) != (size_t)dim)
            bind_field_error(L, arg, call, "cells", what);
        double total = 1;
        for (int a = 0; a < 3; a++) {
            st->cells[a] = 1;
            if (a >= dim)
                continue;
            lua_rawgeti(L, -1, a + 1);
            int isint = 0;
            lua_Integer v = lua_type(L, -1) == LUA_TNUMBER ? lua_tointegerx(L, -1, &isint) : 0;
            lua_pop(L, 1);
            if (!isint || v < 1 || v > 100000)
                bind_field_error(L, arg, call, "cells", "positive integers of at most 100000");
            st->cells[a] = (int)v;
            total *= (double)v;
        }
        if (total > CG_MAX_POINTS)
            bind_field_error(L, arg, call, "cells", "at most 1048576 cells in all");
        lua_pop(L, 1);
        for (int a = 0; a < 3; a++) {
            st->lo[a] = box_lo[a];
            st->hi[a] = box_hi[a];
        }
        if (has_region)
            bind_field_box(L, arg, call, "region", dim, st->lo, st->hi);
        st->n = analysis_cg_grid_count(dim, st->cells);
        for (int a = 0; a < 3; a++) {
            w->set.pts[a] = calloc(st->n, sizeof(double));
            if (!w->set.pts[a])
                luaL_error(L, "%s: out of memory for %d points", call, (int)st->n);
        }
        analysis_cg_grid_points(dim, st->cells, st->lo, st->hi, w->set.pts);
    }
    /* the layout is fixed by the options, whatever a sample holds */
    analysis_cg_particles p;
    memset(&p, 0, sizeof p);
    analysis_cg_contacts c;
    memset(&c, 0, sizeof c);
    static const double dummy = 0;
    if (kind == KIND_DEM) {
        p.volume = &dummy;
        if (st->contacts)
            p.fabric = &dummy;
        if (st->displacement)
            p.disp[0] = &dummy;
    } else {
        p.volume = p.stress = &dummy;
    }
    static const unsigned char wall = 0;
    c.wall = &wall;
    analysis_cg_layout_of(dim, &p, st->contacts ? &c : NULL, &st->layout);
}

/* ---- a sample -----------------------------------------------------------------------------------
 */
typedef struct collect_ctx {
    cg_state *w;
    int dim;
    const double *x[3], *r;
    double *fab; /* dim x dim per particle, or NULL */
} collect_ctx;

static void collect(const dem_contact_info *c, void *ctx)
{
    collect_ctx *cc = ctx;
    cg_state *w = cc->w;
    const int D = cc->dim;
    if (w->oom)
        return;
    if (w->nc == w->cap_c) {
        size_t cap = w->cap_c ? 2 * w->cap_c : 4096;
        w->ci = grow(w->ci, cap, sizeof *w->ci, &w->oom);
        w->cw = grow(w->cw, cap, sizeof *w->cw, &w->oom);
        for (int a = 0; a < 3; a++) {
            w->cb[a] = grow(w->cb[a], cap, sizeof(double), &w->oom);
            w->cf[a] = grow(w->cf[a], cap, sizeof(double), &w->oom);
        }
        if (w->oom)
            return;
        w->cap_c = cap;
    }
    const size_t k = w->nc++, i = (size_t)c->i;
    w->ci[k] = c->i;
    w->cw[k] = c->j < 0;
    for (int a = 0; a < D; a++) {
        w->cf[a][k] = c->force[a];
        /* pairs: from j's image to i, dist n with dist = r_i + r_j - overlap (the pair's centre
         * distance); walls: from the contact point to i */
        w->cb[a][k] = c->j >= 0 ? (cc->r[i] + cc->r[c->j] - c->overlap) * c->normal[a]
                                : cc->x[a][i] - c->point[a];
    }
    if (cc->fab) /* n (x) n for both particles of a pair, for i of a wall contact */
        for (int a = 0; a < D; a++)
            for (int b = 0; b < D; b++) {
                const double nn = c->normal[a] * c->normal[b];
                cc->fab[(size_t)(D * D) * i + (size_t)(a * D + b)] += nn;
                if (c->j >= 0)
                    cc->fab[(size_t)(D * D) * (size_t)c->j + (size_t)(a * D + b)] += nn;
            }
}

/* Samples the scene at idx into w->sums. */
static void sample(lua_State *L, int idx, const char *call, cg_state *w)
{
    cg_setup *st = &w->set;
    const int D = st->def.dim, T = D * D;
    analysis_cg_particles p;
    memset(&p, 0, sizeof p);
    analysis_cg_contacts c;
    memset(&c, 0, sizeof c);
    core_error err;
    double t0 = 0, c0 = 0;
    if (st->kind == KIND_DEM) {
        dem_scene *s = bind_check_dem_scene(L, idx, call);
        t0 = clock_wall();
        c0 = clock_cpu();
        const size_t n = dem_count(s);
        if (n > w->cap_p) {
            w->vol = grow(w->vol, n, sizeof(double), &w->oom);
            w->fab = grow(w->fab, (size_t)T * n, sizeof(double), &w->oom);
            for (int a = 0; a < D; a++)
                w->disp[a] = grow(w->disp[a], n, sizeof(double), &w->oom);
            if (w->oom) {
                w->oom = 0;
                luaL_error(L, "%s: out of memory for %d particles", call, (int)n);
            }
            w->cap_p = n;
        }
        const double *r = dem_radii(s);
        p.n = n;
        for (int a = 0; a < D; a++) {
            p.x[a] = dem_positions(s, a);
            p.v[a] = dem_velocities(s, a);
        }
        p.mass = dem_masses(s);
        for (size_t i = 0; i < n; i++)
            w->vol[i] = D == 2 ? CG_PI * r[i] * r[i] : 4.0 / 3.0 * CG_PI * r[i] * r[i] * r[i];
        p.volume = w->vol;
        if (st->displacement) {
            if (dem_measure_displacement(s, NULL, NULL, w->disp, &err) != CORE_OK)
                bind_raise(L, call, &err);
            for (int a = 0; a < D; a++)
                p.disp[a] = w->disp[a];
        }
        w->nc = 0;
        if (st->contacts) {
            memset(w->fab, 0, (size_t)T * n * sizeof(double));
            collect_ctx cc = {w, D, {p.x[0], p.x[1], p.x[2]}, r, w->fab};
            dem_each_contact_full(s, collect, &cc);
            if (w->oom) {
                w->oom = 0;
                luaL_error(L, "%s: out of memory for the contacts", call);
            }
            p.fabric = w->fab;
            c.n = w->nc;
            c.i = w->ci;
            for (int a = 0; a < D; a++) {
                c.b[a] = w->cb[a];
                c.f[a] = w->cf[a];
            }
            static const unsigned char none = 0;
            c.wall = w->cw ? w->cw : &none;
        }
    } else {
        mpm_scene *m = bind_check_mpm_scene(L, idx, call);
        t0 = clock_wall();
        c0 = clock_cpu();
        mpm_points mp;
        mpm_get_points(m, &mp);
        const size_t n = mpm_point_count(m);
        if (n > w->cap_p) {
            w->vol = grow(w->vol, n, sizeof(double), &w->oom);
            w->stress = grow(w->stress, 4 * n, sizeof(double), &w->oom);
            if (w->oom) {
                w->oom = 0;
                luaL_error(L, "%s: out of memory for %d points", call, (int)n);
            }
            w->cap_p = n;
        }
        p.n = n;
        p.x[0] = mp.x;
        p.x[1] = mp.y;
        p.v[0] = mp.vx;
        p.v[1] = mp.vy;
        p.mass = mp.mass;
        for (size_t i = 0; i < n; i++) {
            /* the current volume V0 det F; V sigma, compression positive (sigma: xx, yy, xy, zz) */
            const double J = mp.F[0][i] * mp.F[3][i] - mp.F[1][i] * mp.F[2][i];
            const double V = mp.volume0[i] * J;
            w->vol[i] = V;
            w->stress[4 * i + 0] = -V * mp.sigma[0][i];
            w->stress[4 * i + 1] = -V * mp.sigma[2][i];
            w->stress[4 * i + 2] = -V * mp.sigma[2][i];
            w->stress[4 * i + 3] = -V * mp.sigma[1][i];
        }
        p.volume = w->vol;
        p.stress = w->stress;
    }
    if (!w->sums) {
        w->sums = malloc(st->n * (size_t)st->layout.stride * sizeof(double));
        if (!w->sums)
            luaL_error(L, "%s: out of memory for the fields of %d points", call, (int)st->n);
    }
    if (analysis_cg_sums(&st->def, &p, st->contacts ? &c : NULL, &st->layout, st->n,
                         (const double *const *)st->pts, w->sums, &err) != CORE_OK)
        bind_raise(L, call, &err);
    w->seconds += clock_wall() - t0;
    w->cpu_seconds += clock_cpu() - c0;
}

/* ---- results ----------------------------------------------------------------------------------
 */
static const char *const AXES[3] = {"x", "y", "z"};

/* Sets field `name` of the table on top to the array base[k * stride] of n values. */
static void push_strided(lua_State *L, const double *base, size_t stride, size_t n,
                         const char *name)
{
    lua_createtable(L, (int)n, 0);
    for (size_t k = 0; k < n; k++) {
        lua_pushnumber(L, base[k * stride]);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    lua_setfield(L, -2, name);
}

static void push_vector(lua_State *L, int D, const double *v, size_t n, const char *name)
{
    lua_createtable(L, 0, D);
    for (int a = 0; a < D; a++)
        push_strided(L, v + a, (size_t)D, n, AXES[a]);
    lua_setfield(L, -2, name);
}

/* A tensor table: components xx, xy, ... and the invariants of its symmetric part. */
static void push_tensor(lua_State *L, int D, const double *t, size_t n, const char *name,
                        double *scratch)
{
    const size_t T = (size_t)D * (size_t)D;
    lua_createtable(L, 0, (int)T + 8);
    for (int a = 0; a < D; a++)
        for (int b = 0; b < D; b++) {
            char comp[3] = {AXES[a][0], AXES[b][0], 0};
            push_strided(L, t + a * D + b, T, n, comp);
        }
    /* invariants: pressure, psd, major, minor, angle, dx, dy(, dz) into scratch (n x 8) */
    for (size_t k = 0; k < n; k++) {
        analysis_cg_invariants iv;
        analysis_cg_invariants_of(D, t + T * k, &iv);
        double *o = scratch + 8 * k;
        o[0] = iv.pressure;
        o[1] = iv.psd;
        o[2] = iv.principal[0];
        o[3] = iv.principal[D - 1];
        o[4] = iv.angle;
        for (int a = 0; a < 3; a++)
            o[5 + a] = iv.direction[a];
    }
    static const char *const inv[8] = {"pressure", "psd", "major", "minor",
                                       "angle",    "dx",  "dy",    "dz"};
    for (int q = 0; q < 5 + D; q++)
        if (q != 4 || D == 2)
            push_strided(L, scratch + q, 8, n, inv[q]);
    lua_setfield(L, -2, name);
}

/* The fields table of sums (n x stride, averaged over `samples`). */
static void push_fields(lua_State *L, const cg_state *w, const double *sums, double time,
                        analysis_cg_fields *f, double *scratch)
{
    const cg_setup *st = &w->set;
    const int D = st->def.dim;
    const size_t n = st->n;
    analysis_cg_derive(&st->layout, n, sums, f);
    lua_createtable(L, 0, 32);
    lua_pushinteger(L, D);
    lua_setfield(L, -2, "dim");
    lua_pushstring(L, st->def.kernel == ANALYSIS_CG_LUCY ? "lucy" : "gauss");
    lua_setfield(L, -2, "kernel");
    lua_pushnumber(L, st->def.width);
    lua_setfield(L, -2, "width");
    lua_pushnumber(L, analysis_cg_reach(&st->def));
    lua_setfield(L, -2, "cutoff");
    if (D == 2) {
        lua_pushnumber(L, st->def.depth);
        lua_setfield(L, -2, "depth");
    }
    lua_pushinteger(L, (lua_Integer)n);
    lua_setfield(L, -2, "n");
    lua_pushnumber(L, time);
    lua_setfield(L, -2, "time");
    lua_pushinteger(L, w->samples > 0 ? w->samples : 1);
    lua_setfield(L, -2, "samples");
    if (st->grid) {
        lua_createtable(L, D, 0);
        for (int a = 0; a < D; a++) {
            lua_pushinteger(L, st->cells[a]);
            lua_rawseti(L, -2, a + 1);
        }
        lua_setfield(L, -2, "cells");
        lua_createtable(L, 2, 0);
        for (int c = 0; c < 2; c++) {
            lua_createtable(L, D, 0);
            for (int a = 0; a < D; a++) {
                lua_pushnumber(L, c ? st->hi[a] : st->lo[a]);
                lua_rawseti(L, -2, a + 1);
            }
            lua_rawseti(L, -2, c + 1);
        }
        lua_setfield(L, -2, "region");
        double vol = 1;
        for (int a = 0; a < D; a++)
            vol *= (st->hi[a] - st->lo[a]) / st->cells[a];
        lua_pushnumber(L, vol);
        lua_setfield(L, -2, "cell_volume");
    }
    for (int a = 0; a < D; a++)
        bind_push_array(L, st->pts[a], n, AXES[a]);
    bind_push_array(L, f->density, n, "density");
    lua_createtable(L, 0, D);
    for (int a = 0; a < D; a++)
        bind_push_array(L, f->velocity[a], n, AXES[a]);
    lua_setfield(L, -2, "velocity");
    bind_push_array(L, f->temperature, n, "temperature");
    if (f->volume_fraction)
        bind_push_array(L, f->volume_fraction, n, "volume_fraction");
    push_tensor(L, D, f->kinetic, n, "kinetic", scratch);
    push_tensor(L, D, f->stress, n, "stress", scratch);
    if (f->contact)
        push_tensor(L, D, f->contact, n, "contact", scratch);
    if (f->internal)
        push_tensor(L, D, f->internal, n, "internal", scratch);
    if (f->fabric)
        push_tensor(L, D, f->fabric, n, "fabric", scratch);
    if (f->traction)
        push_vector(L, D, f->traction, n, "traction");
    if (f->displacement)
        push_vector(L, D, f->displacement, n, "displacement");
}

/* The columns the files get: every field, the total stress's pressure, psd and major direction. */
static size_t file_columns(const cg_state *w, const analysis_cg_fields *f, double *inv,
                           analysis_cg_column *cols)
{
    const int D = w->set.def.dim, T = D * D;
    const size_t n = w->set.n;
    for (size_t k = 0; k < n; k++) { /* pressure, psd, direction (D) */
        analysis_cg_invariants iv;
        analysis_cg_invariants_of(D, f->stress + (size_t)T * k, &iv);
        double *o = inv + (size_t)(2 + D) * k;
        o[0] = iv.pressure;
        o[1] = iv.psd;
        for (int a = 0; a < D; a++)
            o[2 + a] = iv.direction[a];
    }
    size_t m = 0;
#define COL(nm, nc, v)                                                                             \
    do {                                                                                           \
        if (v) {                                                                                   \
            cols[m].name = nm;                                                                     \
            cols[m].ncomp = nc;                                                                    \
            cols[m].values = v;                                                                    \
            m++;                                                                                   \
        }                                                                                          \
    } while (0)
    COL("density", 1, f->density);
    COL("temperature", 1, f->temperature);
    COL("volume_fraction", 1, f->volume_fraction);
    COL("stress", T, f->stress);
    COL("kinetic", T, f->kinetic);
    COL("contact", T, f->contact);
    COL("internal", T, f->internal);
    COL("fabric", T, f->fabric);
    COL("traction", D, f->traction);
    COL("displacement", D, f->displacement);
#undef COL
    return m;
}

/* Writes opts.vtk and opts.csv (table at arg, may be absent) of the fields f. */
static void write_files(lua_State *L, int arg, const char *call, const cg_state *w,
                        const analysis_cg_fields *f, double time)
{
    if (lua_isnoneornil(L, arg))
        return;
    const char *vtk = bind_field_path(L, arg, call, "vtk", 0);
    const char *csv = bind_field_path(L, arg, call, "csv", 0);
    if (!vtk && !csv)
        return;
    const cg_setup *st = &w->set;
    const int D = st->def.dim;
    const size_t n = st->n;
    if (vtk && !st->grid) {
        lua_getfield(L, arg, "vtk");
        bind_field_error(L, arg, call, "vtk", "nil with points (.vti is for grids; use csv)");
    }
    double *inv = lua_newuserdatauv(L, (n ? n : 1) * (size_t)(2 + D) * sizeof(double), 0);
    /* velocity: D columns interleaved for the writers */
    double *vel = lua_newuserdatauv(L, (n ? n : 1) * (size_t)D * sizeof(double), 0);
    for (size_t k = 0; k < n; k++)
        for (int a = 0; a < D; a++)
            vel[(size_t)D * k + (size_t)a] = f->velocity[a][k];
    analysis_cg_column cols[16];
    size_t m = file_columns(w, f, inv, cols);
    cols[m++] = (analysis_cg_column){"velocity", D, vel};
    /* pressure and psd: strided views copied out */
    double *pp = lua_newuserdatauv(L, (n ? n : 1) * 2 * sizeof(double), 0);
    double *dir = lua_newuserdatauv(L, (n ? n : 1) * (size_t)D * sizeof(double), 0);
    for (size_t k = 0; k < n; k++) {
        pp[k] = inv[(size_t)(2 + D) * k];
        pp[n + k] = inv[(size_t)(2 + D) * k + 1];
        for (int a = 0; a < D; a++)
            dir[(size_t)D * k + (size_t)a] = inv[(size_t)(2 + D) * k + 2 + (size_t)a];
    }
    cols[m++] = (analysis_cg_column){"pressure", 1, pp};
    cols[m++] = (analysis_cg_column){"psd", 1, pp + n};
    cols[m++] = (analysis_cg_column){"direction", D, dir};
    core_error err;
    if (vtk && analysis_cg_write_vti(vtk, D, st->cells, st->lo, st->hi, m, cols, time, &err))
        bind_raise(L, call, &err);
    if (csv && analysis_cg_write_csv(csv, D, n, (const double *const *)st->pts, m, cols, &err))
        bind_raise(L, call, &err);
    lua_pop(L, 4);
}

/* ---- analysis.coarse_grain --------------------------------------------------------------------
 */
static int scene_kind(lua_State *L, int idx)
{
    if (luaL_testudata(L, idx, "dem.scene"))
        return KIND_DEM;
    if (luaL_testudata(L, idx, "mpm.scene"))
        return KIND_MPM;
    return KIND_NONE;
}

/* The setup of the options at arg for the scene at idx, into a new state pushed on the stack. */
static cg_state *setup_for(lua_State *L, int idx, int arg, const char *call, int files)
{
    const int kind = scene_kind(L, idx);
    if (kind == KIND_NONE)
        bind_arg_error(L, idx, call, "dem.scene or mpm.scene");
    int dim;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, thickness = 0;
    bool periodic[3] = {false, false, false};
    if (kind == KIND_DEM) {
        dem_scene *s = bind_check_dem_scene(L, idx, call);
        double g[3];
        dim = dem_dim(s);
        dem_box(s, lo, hi, g);
        dem_periodic(s, periodic);
        thickness = dem_thickness(s);
    } else {
        mpm_scene *m = bind_check_mpm_scene(L, idx, call);
        const mpm_scene_def *d = mpm_def(m);
        dim = 2;
        for (int a = 0; a < 2; a++) {
            lo[a] = d->origin[a];
            hi[a] = d->origin[a] + d->size[a];
            periodic[a] = d->periodic[a];
        }
    }
    cg_state *w = new_state(L);
    read_setup(L, arg, call, kind, dim, lo, hi, periodic, thickness, files, w);
    return w;
}

static double scene_time(lua_State *L, int idx, int kind)
{
    return kind == KIND_DEM ? dem_time(bind_check_dem_scene(L, idx, "coarse_grain"))
                            : mpm_time(bind_check_mpm_scene(L, idx, "coarse_grain"));
}

/* Pushes the fields of sums; frees them on every path (a userdata holds them). */
typedef struct fields_box {
    analysis_cg_fields f;
} fields_box;

static int l_fields_box_gc(lua_State *L)
{
    fields_box *b = lua_touserdata(L, 1);
    analysis_cg_fields_free(&b->f);
    return 0;
}

static analysis_cg_fields *new_fields(lua_State *L, const cg_state *w, const char *call)
{
    fields_box *b = lua_newuserdatauv(L, sizeof *b, 0);
    memset(b, 0, sizeof *b);
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, l_fields_box_gc);
    lua_setfield(L, -2, "__gc");
    lua_setmetatable(L, -2);
    core_error err;
    if (analysis_cg_fields_alloc(&w->set.layout, w->set.n, &b->f, &err) != CORE_OK)
        bind_raise(L, call, &err);
    return &b->f;
}

static int l_coarse_grain(lua_State *L)
{
    const char *call = "coarse_grain";
    cg_state *w = setup_for(L, 1, 2, call, 1); /* [3] the state */
    sample(L, 1, call, w);
    const double time = scene_time(L, 1, w->set.kind);
    analysis_cg_fields *f = new_fields(L, w, call); /* [4] */
    double *scratch = lua_newuserdatauv(L, (w->set.n ? w->set.n : 1) * 8 * sizeof(double), 0);
    push_fields(L, w, w->sums, time, f, scratch);
    lua_pushnumber(L, w->seconds);
    lua_setfield(L, -2, "seconds");
    const int result = lua_gettop(L);
    write_files(L, 2, call, w, f, time);
    lua_settop(L, result);
    return 1;
}

/* ---- analysis.cg_average ----------------------------------------------------------------------
 */
static cg_state *check_average(lua_State *L, int idx)
{
    return bind_check_self(L, idx, AVERAGE, "cg_average");
}

static int l_cg_average(lua_State *L)
{
    const char *call = "cg_average";
    cg_state *w = setup_for(L, 1, 2, call, 0);
    w->acc = calloc(w->set.n * (size_t)w->set.layout.stride, sizeof(double));
    if (!w->acc)
        return luaL_error(L, "%s: out of memory for %d points", call, (int)w->set.n);
    return 1;
}

static int l_avg_add(lua_State *L)
{
    const char *call = "add";
    cg_state *w = check_average(L, 1);
    const int kind = scene_kind(L, 2);
    if (kind == KIND_NONE)
        return bind_arg_error(L, 2, call, w->set.kind == KIND_DEM ? "dem.scene" : "mpm.scene");
    if (kind != w->set.kind)
        return luaL_error(L, "%s: this average was made for a %s, not a %s", call,
                          w->set.kind == KIND_DEM ? "dem.scene" : "mpm.scene",
                          kind == KIND_DEM ? "dem.scene" : "mpm.scene");
    if (kind == KIND_DEM && dem_dim(bind_check_dem_scene(L, 2, call)) != w->set.def.dim)
        return luaL_error(L, "%s: this average is %dD, the scene %dD", call, w->set.def.dim,
                          dem_dim(bind_check_dem_scene(L, 2, call)));
    sample(L, 2, call, w);
    const double t0 = clock_wall(), c0 = clock_cpu();
    const size_t m = w->set.n * (size_t)w->set.layout.stride;
    for (size_t k = 0; k < m; k++)
        w->acc[k] += w->sums[k];
    const double time = scene_time(L, 2, kind);
    if (w->samples == 0)
        w->t_first = time;
    w->t_last = time;
    w->samples++;
    w->seconds += clock_wall() - t0;
    w->cpu_seconds += clock_cpu() - c0;
    lua_settop(L, 1);
    return 1;
}

static int l_avg_fields(lua_State *L)
{
    const char *call = "fields";
    cg_state *w = check_average(L, 1);
    lua_settop(L, 2); /* the options (or nil) stay at 2 */
    if (!lua_isnoneornil(L, 2)) {
        bind_check_table(L, 2, call);
        bind_check_fields(L, 2, call, OUT_FIELDS);
    }
    if (w->samples == 0)
        return luaL_error(L, "%s: no samples yet (call avg:add(scene) first, e.g. in on_step)",
                          call);
    const size_t m = w->set.n * (size_t)w->set.layout.stride;
    double *mean = lua_newuserdatauv(L, (m ? m : 1) * sizeof(double), 0);
    for (size_t k = 0; k < m; k++)
        mean[k] = w->acc[k] / (double)w->samples;
    analysis_cg_fields *f = new_fields(L, w, call);
    double *scratch = lua_newuserdatauv(L, (w->set.n ? w->set.n : 1) * 8 * sizeof(double), 0);
    push_fields(L, w, mean, w->t_last, f, scratch);
    lua_pushnumber(L, w->t_first);
    lua_setfield(L, -2, "time_first");
    lua_pushnumber(L, w->seconds);
    lua_setfield(L, -2, "seconds");
    const int result = lua_gettop(L);
    write_files(L, 2, call, w, f, w->t_last);
    lua_settop(L, result);
    return 1;
}

static int l_avg_reset(lua_State *L)
{
    cg_state *w = check_average(L, 1);
    memset(w->acc, 0, w->set.n * (size_t)w->set.layout.stride * sizeof(double));
    w->samples = 0;
    w->seconds = w->cpu_seconds = 0;
    lua_settop(L, 1);
    return 1;
}

static int l_avg_info(lua_State *L)
{
    cg_state *w = check_average(L, 1);
    lua_createtable(L, 0, 6);
    lua_pushinteger(L, w->samples);
    lua_setfield(L, -2, "samples");
    lua_pushinteger(L, (lua_Integer)w->set.n);
    lua_setfield(L, -2, "points");
    lua_pushnumber(L, w->seconds);
    lua_setfield(L, -2, "seconds");
    lua_pushnumber(L, w->cpu_seconds);
    lua_setfield(L, -2, "cpu_seconds");
    lua_pushnumber(L, w->t_first);
    lua_setfield(L, -2, "time_first");
    lua_pushnumber(L, w->t_last);
    lua_setfield(L, -2, "time_last");
    lua_pushinteger(L, (lua_Integer)w->nc);
    lua_setfield(L, -2, "contacts");
    return 1;
}

static int l_avg_tostring(lua_State *L)
{
    cg_state *w = luaL_checkudata(L, 1, AVERAGE);
    lua_pushfstring(L, "analysis.cg_average (%s, %d points, %d samples)",
                    w->set.def.kernel == ANALYSIS_CG_LUCY ? "lucy" : "gauss", (int)w->set.n,
                    (int)w->samples);
    return 1;
}

#define OPTIONS_DOC                                                                                \
    "kernel 'gauss' (exp(-r^2/2w^2) cut at `cutoff`, default 3 w, normalised over the cut "        \
    "support) or 'lucy' (the polynomial 1 - 6x^2 + 8x^3 - 3x^4 of x = r/w: its cutoff is w); "     \
    "cells = {nx, ny[, nz]} over region (default: the scene's box), fields at the cell centres, "  \
    "x fastest from the bottom row; or points = {x =, y =[, z =]}; depth (2D: the fields per "     \
    "area divided by it; default the scene's thickness, else 1: per metre); contacts = true "      \
    "(DEM: contact stress, fabric, wall traction); displacement = false (DEM, since "              \
    "s:set_reference); vtk = 'f.vti' (grids) and csv = 'f.csv' write the fields whole."

void bind_open_coarse_grain(lua_State *L)
{
    static const bind_fn methods[] = {
        {"add", l_avg_add, "avg:add(scene)",
         "Adds the fields of the scene now (a dem.scene or mpm.scene, of the kind the average "
         "was made for) to the running sums; cheap to call from on_step: no Lua tables are made. "
         "Returns avg."},
        {"fields", l_avg_fields, "avg:fields{ vtk = 'f.vti', csv = 'f.csv' }",
         "The time-averaged fields, as analysis.coarse_grain returns them: density, momentum, "
         "momentum flux and stresses averaged over the samples, then velocity = <p>/<rho>, "
         "kinetic stress = <M> - <rho> V V and temperature from the averages (MercuryCG's time "
         "average); samples, time (of the last sample), time_first. vtk, csv: write them."},
        {"reset", l_avg_reset, "avg:reset()", "Forgets the samples. Returns avg."},
        {"info", l_avg_info, "avg:info()",
         "samples, points, seconds (wall) and cpu_seconds spent sampling, time_first, "
         "time_last, contacts (of the last sample)."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg meta[] = {{"__gc", l_state_gc},
                                    {"__close", l_state_gc},
                                    {"__tostring", l_avg_tostring},
                                    {NULL, NULL}};
    bind_new_type(L, AVERAGE, methods, meta,
                  "A time average of coarse-grained fields from analysis.cg_average: add samples "
                  "with avg:add(scene), read them with avg:fields().");
    static const bind_fields avg_fields[] = {{"fields", NULL, OUT_FIELDS}, {NULL, NULL, NULL}};
    bind_type_fields(L, AVERAGE, avg_fields);

    static const bind_fn fns[] = {
        {"coarse_grain", l_coarse_grain,
         "analysis.coarse_grain(scene, { kernel = 'gauss', width =, cutoff = 3 width, cells = "
         "{nx, ny}, region = {{x0, y0}, {x1, y1}}, points = {x =, y =}, depth =, contacts = "
         "true, displacement = false, vtk =, csv = })",
         "Continuum fields of a DEM scene (particles and contacts) or an MPM scene (points) by "
         "kernel coarse-graining (Weinhart et al. 2012, Goldhirsch 2010; MercuryCG's "
         "kernels). " OPTIONS_DOC
         " Returns a table: dim, kernel, width, cutoff, depth (2D), n, time, cells, region, "
         "cell_volume (grids), x, y(, z) (the points), density, velocity = {x =, y =}, "
         "temperature (tr kinetic / (dim rho)), volume_fraction, and tensors (compression "
         "positive; each a table of components xx, xy, ... and pressure = tr/dim, psd "
         "(largest - smallest principal value), major, minor, angle (2D) and dx, dy(, dz) of the "
         "major principal direction): kinetic, stress (total), contact (DEM: sum b (x) f psi, "
         "the branch b from the partner or the wall's contact point to the particle, psi the "
         "kernel integrated exactly along it), internal (MPM: the points' own stress), fabric "
         "(DEM: the volume-weighted mean of each particle's sum of n (x) n, trace = the "
         "coordination number); traction (DEM: the walls' force density at their contact "
         "points) and displacement. Fields are NaN where the density is 0. seconds: time "
         "spent."},
        {"cg_average", l_cg_average,
         "analysis.cg_average(scene, { kernel =, width =, cutoff =, cells =, region =, points =, "
         "depth =, contacts =, displacement = })",
         "A time average of coarse-grained fields over a run, with the options of "
         "analysis.coarse_grain (scene fixes the kind, dimension, box and defaults; it is not "
         "sampled). Add samples with avg:add(scene) (from on_step), read avg:fields()."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fn_fields[] = {
        {"coarse_grain", NULL, CG_FIELDS}, {"cg_average", NULL, AVG_FIELDS}, {NULL, NULL, NULL}};
    lua_getglobal(L, "analysis");
    bind_register(L, -1, fns);
    bind_register_fields(L, -1, fn_fields);
    lua_pop(L, 1);
    bind_open_coarse_grain_render(L);
}
