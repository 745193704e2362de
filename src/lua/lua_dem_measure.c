/* The dem bindings: s:measure (energy, stress, coordination, slip, contacts, displacement) and
 * s:set_reference. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/progress.h"
#include "dem/dem.h"
#include "lua/bind.h"
#include "lua/lua_dem.h"

/* ---- measurements --------------------------------------------------------------------------- */
typedef struct contact_lists {
    lua_State *L;
    int tables[8];
    lua_Integer n;
    int dim;
} contact_lists;

static void add_contact(const dem_contact_info *c, void *ctx)
{
    contact_lists *cl = ctx;
    lua_State *L = cl->L;
    cl->n++;
    double vals[8] = {(double)(c->i + 1), 0,         c->fn, c->ft, c->normal[0], c->normal[1],
                      c->normal[2],       c->overlap};
    for (int k = 0; k < 8; k++) {
        if (k == 6 && cl->dim == 2)
            continue;
        if (k == 0 || k == 1) {
            lua_Integer v = k == 0 ? c->i + 1 : (c->j >= 0 ? c->j + 1 : c->j);
            lua_pushinteger(L, v);
        } else {
            lua_pushnumber(L, vals[k]);
        }
        lua_rawseti(L, cl->tables[k], cl->n);
    }
}

static const char *const STRESS_FIELDS[] = {"volume", NULL};

static const char *const DISPLACEMENT_FIELDS[] = {"affine", "center", NULL};

/* The modes that take no options: a table given to them may hold no key. */
static const char *const NO_FIELDS[] = {NULL};

static int measure_energy(lua_State *L, dem_scene *s)
{
    dem_energy e;
    dem_measure_energy(s, &e);
    lua_createtable(L, 0, 5);
    const char *names[] = {"kinetic", "rotational", "elastic", "potential", "total"};
    double vals[] = {e.kinetic, e.rotational, e.elastic, e.potential, e.total};
    for (int k = 0; k < 5; k++) {
        lua_pushnumber(L, vals[k]);
        lua_setfield(L, -2, names[k]);
    }
    return 1;
}

static int measure_stress(lua_State *L, dem_scene *s, int has_opts)
{
    const int D = dem_dim(s);
    double volume = 0;
    if (has_opts)
        volume = bind_field_number(L, 3, "measure", "volume", 0, BIND_POSITIVE);
    double sig[3][3];
    long nc = dem_measure_stress(s, volume, sig);
    static const char *const comp[3][3] = {
        {"xx", "xy", "xz"}, {"yx", "yy", "yz"}, {"zx", "zy", "zz"}};
    lua_createtable(L, 0, 11);
    double tr = 0;
    for (int a = 0; a < D; a++) {
        tr += sig[a][a];
        for (int b = 0; b < D; b++) {
            lua_pushnumber(L, sig[a][b]);
            lua_setfield(L, -2, comp[a][b]);
        }
    }
    lua_pushnumber(L, tr / D);
    lua_setfield(L, -2, "pressure");
    lua_pushinteger(L, nc);
    lua_setfield(L, -2, "contacts");
    return 1;
}

static int measure_coordination(lua_State *L, dem_scene *s)
{
    double z, zr;
    dem_measure_coordination(s, &z, &zr);
    lua_createtable(L, 0, 2);
    lua_pushnumber(L, z);
    lua_setfield(L, -2, "z");
    lua_pushnumber(L, zr);
    lua_setfield(L, -2, "z_no_rattlers");
    return 1;
}

static int measure_contacts(lua_State *L, dem_scene *s)
{
    const int D = dem_dim(s);
    static const char *const names[8] = {"i", "j", "fn", "ft", "nx", "ny", "nz", "overlap"};
    contact_lists cl = {.L = L, .n = 0, .dim = D};
    lua_createtable(L, 0, 8);
    int result = lua_gettop(L);
    for (int k = 0; k < 8; k++) {
        if (k == 6 && D == 2) {
            cl.tables[k] = 0;
            continue;
        }
        lua_newtable(L);
        cl.tables[k] = lua_gettop(L);
    }
    dem_each_contact(s, add_contact, &cl);
    for (int k = 7; k >= 0; k--) {
        if (k == 6 && D == 2)
            continue;
        lua_setfield(L, result, names[k]);
    }
    lua_pushinteger(L, cl.n);
    lua_setfield(L, result, "count");
    return 1;
}

/* The displacement, optionally relative to an affine field. */
static int measure_displacement(lua_State *L, dem_scene *s, int has_opts)
{
    const int D = dem_dim(s);
    double grad[3][3] = {{0}}, center[3] = {0, 0, 0};
    int affine = 0;
    if (has_opts) {
        /* affine: D rows of D finite numbers, the shape checked before any row is
         * indexed (a number as a row used to crash lua_rawgeti). */
        if (lua_getfield(L, 3, "affine") != LUA_TNIL) {
            lua_Debug ar;
            int uarg = lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.namewhat &&
                               strcmp(ar.namewhat, "method") == 0
                           ? 2
                           : 3;
            char got[128] = "", v[64];
            int ok = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == (size_t)D;
            if (!ok && lua_type(L, -1) == LUA_TTABLE)
                snprintf(got, sizeof got, "%d rows", (int)lua_rawlen(L, -1));
            else if (!ok)
                bind_describe(L, -1, got, sizeof got);
            for (int a = 0; a < D && ok; a++) {
                int rt = lua_rawgeti(L, -1, a + 1);
                if (rt != LUA_TTABLE || lua_rawlen(L, -1) != (size_t)D) {
                    if (rt == LUA_TTABLE)
                        snprintf(got, sizeof got, "%d entries in row %d",
                                 (int)lua_rawlen(L, -1), a + 1);
                    else {
                        bind_describe(L, -1, v, sizeof v);
                        snprintf(got, sizeof got, "%s as row %d", v, a + 1);
                    }
                    ok = 0;
                }
                for (int b = 0; b < D && ok; b++) {
                    lua_rawgeti(L, -1, b + 1);
                    grad[a][b] = lua_tonumber(L, -1);
                    if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(grad[a][b]) ||
                        fabs(grad[a][b]) > 1e100) { /* the bindings' magnitude cap */
                        bind_describe(L, -1, v, sizeof v);
                        snprintf(got, sizeof got, "%s at row %d, column %d", v, a + 1, b + 1);
                        ok = 0;
                    }
                    lua_pop(L, 1);
                }
                lua_pop(L, 1);
            }
            if (!ok)
                return luaL_error(L,
                                  "bad field 'affine' in argument #%d to 'measure' (%dx%d "
                                  "matrix of finite numbers (displacement gradient) "
                                  "expected, got %s)",
                                  uarg, D, D, got);
            affine = 1;
        }
        lua_pop(L, 1);
        bind_field_vector(L, 3, "measure", "center", D, center, 0);
    }
    size_t n = dem_count(s);
    double *out[3] = {NULL, NULL, NULL};
    for (int d = 0; d < D; d++) {
        out[d] = malloc((n ? n : 1) * sizeof(double));
        if (!out[d]) {
            for (int k = 0; k < d; k++)
                free(out[k]);
            return luaL_error(L, "measure: out of memory");
        }
    }
    core_error err;
    core_status st = dem_measure_displacement(s, affine ? (const double(*)[3])grad : NULL,
                                              center, out, &err);
    if (st == CORE_OK) {
        static const char *const names[3] = {"x", "y", "z"};
        lua_createtable(L, 0, D);
        for (int d = 0; d < D; d++) {
            lua_createtable(L, (int)n, 0);
            for (size_t i = 0; i < n; i++) {
                lua_pushnumber(L, out[d][i]);
                lua_rawseti(L, -2, (lua_Integer)i + 1);
            }
            lua_setfield(L, -2, names[d]);
        }
    }
    for (int d = 0; d < D; d++)
        free(out[d]);
    if (st != CORE_OK)
        return bind_raise(L, "measure", &err);
    return 1;
}

static int l_measure(lua_State *L)
{
    static const char *const what_names[] = {
        "energy", "stress", "coordination", "slip", "contacts", "displacement", NULL};
    static const char *const *const what_fields[] = {NO_FIELDS, STRESS_FIELDS, NO_FIELDS,
                                                     NO_FIELDS, NO_FIELDS,     DISPLACEMENT_FIELDS};
    dem_scene *s = ldem_check_scene(L, 1);
    int what = bind_check_option(L, 2, NULL, what_names);
    int has_opts = bind_mode_options(L, 3, "measure", what_names[what], what_fields[what]);
    switch (what) {
    case 0:
        return measure_energy(L, s);
    case 1:
        return measure_stress(L, s, has_opts);
    case 2:
        return measure_coordination(L, s);
    case 3:
        lua_pushnumber(L, dem_measure_slip(s));
        return 1;
    case 4:
        return measure_contacts(L, s);
    default:
        return measure_displacement(L, s, has_opts);
    }
}

static int l_set_reference(lua_State *L)
{
    dem_scene *s = ldem_check_scene(L, 1);
    core_error err;
    if (dem_set_reference(s, &err))
        return bind_raise(L, "set_reference", &err);
    return 0;
}

void ldem_open_measure(lua_State *L)
{
    static const bind_fn methods[] = {
        {"measure", l_measure,
         "s:measure('energy'|'stress'|'coordination'|'slip'|'contacts'|'displacement', opts)",
         "energy: kinetic, rotational, elastic, potential, total (J). stress: assembly stress "
         "sum(branch x force)/V (opts.volume; compression positive) with pressure. "
         "coordination: z, z_no_rattlers. slip: mean |slip velocity| at contacts. contacts: "
         "arrays i, j (negative j: wall), fn, ft, nx, ny, (nz), overlap. displacement: since "
         "set_reference, minus opts.affine (displacement gradient) about opts.center."},
        {"set_reference", l_set_reference, "s:set_reference()",
         "Remembers the current positions for displacement measurements."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fields fields[] = {{"measure", "energy", NO_FIELDS},
                                         {"measure", "stress", STRESS_FIELDS},
                                         {"measure", "coordination", NO_FIELDS},
                                         {"measure", "slip", NO_FIELDS},
                                         {"measure", "contacts", NO_FIELDS},
                                         {"measure", "displacement", DISPLACEMENT_FIELDS},
                                         {NULL, NULL, NULL}};
    ldem_add_methods(L, methods, fields);
}
