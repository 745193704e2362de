/* Argument and table-field checking: every error names the call, the field and the value. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lua/bind.h"

static const char *number_kind(unsigned flags);

/* The largest magnitude any number crossing the bindings may have, unless the flags allow inf.
 * No SI quantity of a granular scene comes near it, and products of three such numbers (a
 * stiffness times an overlap squared, m v^2) stay finite in double precision (1e300 < 1.8e308),
 * so no kernel turns an accepted input into inf or NaN. */
#define BIND_MAX_MAGNITUDE 1e100

static int too_large(double v, unsigned flags)
{
    return !(flags & BIND_ALLOW_INF) && isfinite(v) && fabs(v) > BIND_MAX_MAGNITUDE;
}

/* "positive number" or, for a finite value above the cap, "positive number of magnitude at most
 * 1e+100": the limit is in the message only when it is what the value broke. */
static const char *expected_kind(unsigned flags, double v, char *buf, size_t size)
{
    if (!too_large(v, flags))
        return number_kind(flags);
    snprintf(buf, size, "%s of magnitude at most %g", number_kind(flags), BIND_MAX_MAGNITUDE);
    return buf;
}

/* The argument number the user sees: a method's self is not counted, as in luaL_argerror. */
static int user_arg(lua_State *L, int arg)
{
    lua_Debug ar;
    if (lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.namewhat &&
        strcmp(ar.namewhat, "method") == 0)
        return arg - 1;
    return arg;
}

void bind_describe(lua_State *L, int idx, char *buf, size_t size)
{
    switch (lua_type(L, idx)) {
    case LUA_TNUMBER: /* as print shows it: 3, 1.5, 1e+09, -nan */
        snprintf(buf, size, "%s", luaL_tolstring(L, idx, NULL));
        lua_pop(L, 1);
        break;
    case LUA_TSTRING: {
        size_t len;
        const char *s = lua_tolstring(L, idx, &len);
        char text[48];
        size_t n = 0; /* a NUL byte shown as \0, not ending the text there */
        for (size_t i = 0; i < len && n < 40; i++) {
            if (s[i] == '\0') {
                text[n++] = '\\';
                text[n++] = '0';
            } else {
                text[n++] = s[i];
            }
        }
        text[n] = '\0';
        snprintf(buf, size, len > 40 || n > 40 ? "'%.37s...'" : "'%s'", text);
        break;
    }
    case LUA_TBOOLEAN:
        snprintf(buf, size, "%s", lua_toboolean(L, idx) ? "true" : "false");
        break;
    default:
        snprintf(buf, size, "%s", luaL_typename(L, idx));
    }
}

int bind_field_error(lua_State *L, int arg, const char *call, const char *field,
                     const char *expected)
{
    char got[64];
    bind_describe(L, -1, got, sizeof got);
    return luaL_error(L, "bad field '%s' in argument #%d to '%s' (%s expected, got %s)", field,
                      user_arg(L, arg), call, expected, got);
}

int bind_arg_error(lua_State *L, int arg, const char *call, const char *expected)
{
    char got[64];
    bind_describe(L, arg, got, sizeof got);
    return luaL_error(L, "bad argument #%d to '%s' (%s expected, got %s)", user_arg(L, arg), call,
                      expected, got);
}

/* A file name crosses into C as a C string: a NUL byte inside it would end the name there
 * (writing "a" for "a\0b.txt"), so the Lua length must equal the C length. */
static int is_path(lua_State *L, int idx)
{
    size_t len;
    const char *path = lua_tolstring(L, idx, &len);
    return len > 0 && strlen(path) == len;
}

const char *bind_arg_path(lua_State *L, int arg, const char *call)
{
    /* A number would be converted into a file name ("1"): only a string is a path. */
    if (lua_type(L, arg) != LUA_TSTRING)
        bind_arg_error(L, arg, call, "file path (string)");
    if (!is_path(L, arg))
        bind_arg_error(L, arg, call, "non-empty file path without NUL bytes");
    return lua_tostring(L, arg);
}

const char *bind_field_path(lua_State *L, int arg, const char *call, const char *field,
                            unsigned flags)
{
    if (lua_getfield(L, arg, field) == LUA_TNIL) {
        if (flags & BIND_REQUIRED)
            bind_field_error(L, arg, call, field, "file path (string)");
        lua_pop(L, 1);
        return NULL;
    }
    if (lua_type(L, -1) != LUA_TSTRING)
        bind_field_error(L, arg, call, field, "file path (string)");
    if (!is_path(L, -1))
        bind_field_error(L, arg, call, field, "non-empty file path without NUL bytes");
    const char *path = lua_tostring(L, -1);
    lua_pop(L, 1); /* still referenced by the table */
    return path;
}

double bind_arg_number(lua_State *L, int arg, const char *call, unsigned flags)
{
    double v = lua_tonumber(L, arg);
    char buf[96];
    if (lua_type(L, arg) != LUA_TNUMBER || isnan(v) || (!(flags & BIND_ALLOW_INF) && isinf(v)) ||
        ((flags & BIND_POSITIVE) && !(v > 0)) || ((flags & BIND_NONNEG) && !(v >= 0)) ||
        too_large(v, flags))
        bind_arg_error(L, arg, call, expected_kind(flags, v, buf, sizeof buf));
    return v;
}

lua_Integer bind_arg_integer(lua_State *L, int arg, const char *call, lua_Integer min,
                             lua_Integer max)
{
    int isint;
    lua_Integer v = lua_tointegerx(L, arg, &isint);
    if (!isint || lua_type(L, arg) != LUA_TNUMBER || v < min || v > max) {
        char expected[96];
        if (min == LUA_MININTEGER && max == LUA_MAXINTEGER)
            snprintf(expected, sizeof expected, "integer");
        else if (max == LUA_MAXINTEGER)
            snprintf(expected, sizeof expected, "integer >= %lld", (long long)min);
        else
            snprintf(expected, sizeof expected, "integer in [%lld, %lld]", (long long)min,
                     (long long)max);
        bind_arg_error(L, arg, call, expected);
    }
    return v;
}

void bind_arg_vector(lua_State *L, int arg, const char *call, int n, double *out)
{
    char expected[64];
    snprintf(expected, sizeof expected, "array of %d finite numbers", n);
    if (lua_type(L, arg) != LUA_TTABLE || lua_rawlen(L, arg) != (size_t)n)
        bind_arg_error(L, arg, call, expected);
    for (int k = 0; k < n; k++) {
        lua_rawgeti(L, arg, k + 1);
        int isnum;
        double v = lua_tonumberx(L, -1, &isnum);
        if (!isnum || lua_type(L, -1) != LUA_TNUMBER || !isfinite(v) || too_large(v, 0)) {
            char got[64];
            bind_describe(L, -1, got, sizeof got);
            luaL_error(L, "bad argument #%d to '%s' (%s%s expected, got %s at entry %d)",
                       user_arg(L, arg), call, expected,
                       too_large(v, 0) ? " of magnitude at most 1e+100" : "", got, k + 1);
        }
        lua_pop(L, 1);
        out[k] = v;
    }
}

void *bind_check_self(lua_State *L, int arg, const char *tname, const char *call)
{
    void *u = luaL_testudata(L, arg, tname);
    if (!u) {
        char got[64];
        bind_describe(L, arg, got, sizeof got);
        luaL_error(L,
                   "bad argument #%d to '%s' (%s expected, got %s; a method is called with "
                   "':', as s:%s(...))",
                   user_arg(L, arg) > 0 ? user_arg(L, arg) : arg, call, tname, got, call);
    }
    return u;
}

void *bind_check_udata(lua_State *L, int arg, const char *tname, const char *call)
{
    void *u = luaL_testudata(L, arg, tname);
    if (!u) /* numbered as the user counts (a method's self is not #1) */
        bind_arg_error(L, arg, call, tname);
    return u;
}

void bind_check_table(lua_State *L, int arg, const char *call)
{
    if (lua_type(L, arg) != LUA_TTABLE)
        luaL_error(L, "bad argument #%d to '%s' (table expected, got %s)", user_arg(L, arg), call,
                   luaL_typename(L, arg));
}

/* Raises the error for the unknown key on top of the stack, a key of the options table of
 * argument arg of call (nested: of its field `nested`, "mbc"; mode: the mode the list goes with):
 *   bad argument #2 to 'measure' (unknown field 'volum'; did you mean 'volume'? …)
 *   bad field 'mbc' in argument #1 to 'boundary' (unknown field 'k'; did you mean 'K'? …)
 *   bad argument #2 to 'measure' (unknown field 'foo'; measure('energy') takes no options) */
static int unknown_field(lua_State *L, int arg, const char *call, const char *nested,
                         const char *mode, const char *const fields[])
{
    char key[64];
    bind_describe(L, -1, key, sizeof key);
    const char *near =
        lua_type(L, -1) == LUA_TSTRING ? bind_closest_name(lua_tostring(L, -1), fields) : NULL;
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    luaL_where(L, 1); /* as luaL_error: the position of the user's call */
    luaL_addvalue(&b);
    if (nested) {
        lua_pushfstring(L, "bad field '%s' in argument #%d to '%s' (unknown field %s", nested,
                        user_arg(L, arg), call, key);
    } else {
        lua_pushfstring(L, "bad argument #%d to '%s' (unknown field %s", user_arg(L, arg), call,
                        key);
    }
    luaL_addvalue(&b);
    if (!fields[0]) {
        luaL_addstring(&b, "; ");
        luaL_addstring(&b, call);
        if (mode) {
            luaL_addstring(&b, "('");
            luaL_addstring(&b, mode);
            luaL_addstring(&b, "')");
        }
        luaL_addstring(&b, " takes no options)");
        luaL_pushresult(&b);
        return lua_error(L);
    }
    if (near) {
        luaL_addstring(&b, "; did you mean '");
        luaL_addstring(&b, near);
        luaL_addstring(&b, "'? Valid fields");
    } else {
        luaL_addstring(&b, "; valid fields");
    }
    if (mode) {
        luaL_addstring(&b, " for '");
        luaL_addstring(&b, mode);
        luaL_addchar(&b, '\'');
    }
    luaL_addstring(&b, ": ");
    for (int i = 0; fields[i]; i++) {
        if (i)
            luaL_addstring(&b, ", ");
        luaL_addstring(&b, fields[i]);
    }
    luaL_addchar(&b, ')');
    luaL_pushresult(&b);
    return lua_error(L);
}

/* Every key of the table at tab is a string in fields, or unknown_field raises. */
static void check_keys(lua_State *L, int tab, int arg, const char *call, const char *nested,
                       const char *mode, const char *const fields[])
{
    tab = lua_absindex(L, tab);
    lua_pushnil(L);
    while (lua_next(L, tab)) {
        lua_pop(L, 1);
        int known = 0;
        if (lua_type(L, -1) == LUA_TSTRING) {
            const char *key = lua_tostring(L, -1);
            for (int i = 0; fields[i] && !known; i++)
                known = strcmp(key, fields[i]) == 0;
        }
        if (!known)
            unknown_field(L, arg, call, nested, mode, fields);
    }
}

void bind_check_fields(lua_State *L, int arg, const char *call, const char *const fields[])
{
    arg = lua_absindex(L, arg);
    check_keys(L, arg, arg, call, NULL, NULL, fields);
}

void bind_check_nested_fields(lua_State *L, int tab, int arg, const char *call, const char *name,
                              const char *const fields[])
{
    check_keys(L, tab, arg, call, name, NULL, fields);
}

int bind_mode_options(lua_State *L, int arg, const char *call, const char *mode,
                      const char *const fields[])
{
    if (lua_isnoneornil(L, arg))
        return 0;
    if (lua_type(L, arg) != LUA_TTABLE) {
        char expected[96];
        if (fields[0])
            snprintf(expected, sizeof expected, "options table for '%s'", mode);
        else
            snprintf(expected, sizeof expected, "nothing ('%s' takes no options)", mode);
        bind_arg_error(L, arg, call, expected);
    }
    check_keys(L, arg, arg, call, NULL, mode, fields);
    return 1;
}

/* Pushes t[field]; returns 0 (with nothing pushed) when absent and not required. */
static int get_field(lua_State *L, int arg, const char *call, const char *field, unsigned flags,
                     const char *expected)
{
    if (lua_getfield(L, arg, field) == LUA_TNIL) {
        if (flags & BIND_REQUIRED)
            bind_field_error(L, arg, call, field, expected);
        lua_pop(L, 1);
        return 0;
    }
    return 1;
}

static const char *number_kind(unsigned flags)
{
    if (flags & BIND_POSITIVE)
        return "positive number";
    if (flags & BIND_NONNEG)
        return "non-negative number";
    return (flags & BIND_ALLOW_INF) ? "number" : "finite number";
}

double bind_field_number(lua_State *L, int arg, const char *call, const char *field, double def,
                         unsigned flags)
{
    const char *expected = number_kind(flags);
    if (!get_field(L, arg, call, field, flags, expected))
        return def;
    int isnum;
    double v = lua_tonumberx(L, -1, &isnum);
    char buf[96];
    if (!isnum || lua_type(L, -1) != LUA_TNUMBER || isnan(v) ||
        (!(flags & BIND_ALLOW_INF) && isinf(v)) || ((flags & BIND_POSITIVE) && !(v > 0)) ||
        ((flags & BIND_NONNEG) && !(v >= 0)) || too_large(v, flags))
        bind_field_error(L, arg, call, field, expected_kind(flags, v, buf, sizeof buf));
    lua_pop(L, 1);
    return v;
}

lua_Integer bind_field_integer(lua_State *L, int arg, const char *call, const char *field,
                               lua_Integer def, lua_Integer min, lua_Integer max, unsigned flags)
{
    char expected[96];
    if (min == 0 && max == LUA_MAXINTEGER)
        snprintf(expected, sizeof expected, "non-negative integer");
    else if (min == 1 && max == LUA_MAXINTEGER)
        snprintf(expected, sizeof expected, "positive integer");
    else
        snprintf(expected, sizeof expected, "integer in [%lld, %lld]", (long long)min,
                 (long long)max);
    if (!get_field(L, arg, call, field, flags, expected))
        return def;
    int isint;
    lua_Integer v = lua_tointegerx(L, -1, &isint);
    if (!isint || lua_type(L, -1) != LUA_TNUMBER || v < min || v > max)
        bind_field_error(L, arg, call, field, expected);
    lua_pop(L, 1);
    return v;
}

const char *bind_field_string(lua_State *L, int arg, const char *call, const char *field,
                              const char *def, unsigned flags)
{
    if (!get_field(L, arg, call, field, flags, "string"))
        return def;
    if (lua_type(L, -1) != LUA_TSTRING)
        bind_field_error(L, arg, call, field, "string");
    const char *s = lua_tostring(L, -1);
    lua_pop(L, 1); /* still referenced by the table */
    return s;
}

int bind_field_option(lua_State *L, int arg, const char *call, const char *field,
                      const char *const names[], int def, unsigned flags)
{
    char expected[256] = "one of ";
    for (int i = 0; names[i]; i++) {
        size_t n = strlen(expected);
        snprintf(expected + n, sizeof expected - n, "%s'%s'", i ? ", " : "", names[i]);
    }
    if (!get_field(L, arg, call, field, flags, expected))
        return def;
    if (lua_type(L, -1) == LUA_TSTRING) {
        const char *s = lua_tostring(L, -1);
        for (int i = 0; names[i]; i++)
            if (strcmp(s, names[i]) == 0) {
                lua_pop(L, 1);
                return i;
            }
    }
    return bind_field_error(L, arg, call, field, expected);
}

int bind_field_vector(lua_State *L, int arg, const char *call, const char *field, int n,
                      double *out, unsigned flags)
{
    char expected[64];
    snprintf(expected, sizeof expected, "array of %d finite numbers", n);
    if (!get_field(L, arg, call, field, flags, expected))
        return 0;
    if (lua_type(L, -1) != LUA_TTABLE || luaL_len(L, -1) != n)
        bind_field_error(L, arg, call, field, expected);
    for (int k = 0; k < n; k++) {
        lua_rawgeti(L, -1, k + 1);
        int isnum;
        double v = lua_tonumberx(L, -1, &isnum);
        isnum = isnum && lua_type(L, -1) == LUA_TNUMBER; /* no "1.5" strings */
        lua_pop(L, 1);
        if (!isnum || !isfinite(v) || too_large(v, 0)) {
            char got[64];
            lua_rawgeti(L, -1, k + 1);
            bind_describe(L, -1, got, sizeof got);
            return luaL_error(L,
                              "bad field '%s' in argument #%d to '%s' (array of %d finite "
                              "numbers%s expected, got %s at entry %d)",
                              field, user_arg(L, arg), call, n,
                              isnum && too_large(v, 0) ? " of magnitude at most 1e+100" : "", got,
                              k + 1);
        }
        out[k] = v;
    }
    lua_pop(L, 1);
    return 1;
}

int bind_field_boolean(lua_State *L, int arg, const char *call, const char *field, int def)
{
    if (!get_field(L, arg, call, field, 0, "boolean"))
        return def;
    if (lua_type(L, -1) != LUA_TBOOLEAN)
        bind_field_error(L, arg, call, field, "boolean");
    int v = lua_toboolean(L, -1);
    lua_pop(L, 1);
    return v;
}

int bind_raise(lua_State *L, const char *call, const core_error *err)
{
    if (err->msg[0])
        return luaL_error(L, "%s: %s", call, err->msg);
    return luaL_error(L, "%s: %s", call, core_status_name(err->status));
}

void bind_field_box(lua_State *L, int arg, const char *call, const char *field, int dim, double *lo,
                    double *hi)
{
    char expected[96];
    snprintf(expected, sizeof expected, "{{lower corner}, {upper corner}} with %d numbers each",
             dim);
    if (lua_getfield(L, arg, field) != LUA_TTABLE || luaL_len(L, -1) != 2)
        bind_field_error(L, arg, call, field, expected);
    for (int c = 0; c < 2; c++) {
        if (lua_rawgeti(L, -1, c + 1) != LUA_TTABLE || luaL_len(L, -1) != dim) {
            lua_pop(L, 1);
            bind_field_error(L, arg, call, field, expected);
        }
        for (int d = 0; d < dim; d++) {
            lua_rawgeti(L, -1, d + 1);
            int isnum;
            double v = lua_tonumberx(L, -1, &isnum);
            isnum = isnum && lua_type(L, -1) == LUA_TNUMBER;
            lua_pop(L, 1);
            if (!isnum || !isfinite(v) || too_large(v, 0)) {
                lua_pop(L, 1);
                bind_field_error(L, arg, call, field,
                                 isnum && too_large(v, 0)
                                     ? "box corners of magnitude at most 1e+100"
                                     : expected);
            }
            (c == 0 ? lo : hi)[d] = v;
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    for (int d = 0; d < dim; d++)
        if (!(hi[d] > lo[d])) {
            lua_getfield(L, arg, field);
            bind_field_error(L, arg, call, field, "upper corner above the lower one on every axis");
        }
}

int bind_steps_or_time(lua_State *L, int arg, const char *call, long *steps, double *time)
{
    *steps = (long)bind_field_integer(L, arg, call, "steps", -1, 0, LUA_MAXINTEGER, 0);
    *time = bind_field_number(L, arg, call, "time", -1, BIND_NONNEG);
    if (*steps >= 0 && *time >= 0) {
        lua_getfield(L, arg, "time");
        bind_field_error(L, arg, call, "time", "nothing when 'steps' is given (give one)");
    }
    if (*steps < 0 && *time < 0) {
        lua_pushnil(L);
        bind_field_error(L, arg, call, "steps", "step count (or field 'time')");
    }
    return *steps >= 0;
}

long bind_time_steps(lua_State *L, int arg, const char *call, double time, double dt)
{
    double n = ceil(time / dt - 1e-9);
    if (!(n <= 1e15)) {
        char expected[128];
        snprintf(expected, sizeof expected, "time of at most 1e15 steps of dt = %g s", dt);
        lua_getfield(L, arg, "time");
        bind_field_error(L, arg, call, "time", expected);
    }
    return n > 0 ? (long)n : 0;
}

/* Optimal string alignment distance (edits and adjacent swaps), capped: names are short. */
static size_t edit_distance(const char *a, const char *b)
{
    enum { CAP = 32 };
    size_t n = strlen(a), m = strlen(b);
    if (n > CAP || m > CAP)
        return (size_t)-1;
    size_t d[CAP + 1][CAP + 1];
    for (size_t i = 0; i <= n; i++)
        d[i][0] = i;
    for (size_t j = 0; j <= m; j++)
        d[0][j] = j;
    for (size_t i = 1; i <= n; i++)
        for (size_t j = 1; j <= m; j++) {
            size_t sub = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            size_t del = d[i - 1][j] + 1, ins = d[i][j - 1] + 1;
            size_t best = sub < del ? sub : del;
            best = ins < best ? ins : best;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[n][m];
}

const char *bind_closest_name(const char *s, const char *const names[])
{
    /* A unique prefix ("temp" for "temperature") is a clear enough intent. */
    const char *prefix = NULL;
    int nprefix = 0;
    size_t len = strlen(s);
    for (int i = 0; names[i] && len >= 2; i++)
        if (strncmp(s, names[i], len) == 0) {
            prefix = names[i];
            nprefix++;
        }
    if (nprefix == 1)
        return prefix;
    /* A name that differs only in case ("k" for "K"). */
    for (int i = 0; names[i]; i++) {
        size_t k = 0;
        while (s[k] && names[i][k] &&
               tolower((unsigned char)s[k]) == tolower((unsigned char)names[i][k]))
            k++;
        if (!s[k] && !names[i][k])
            return names[i];
    }
    /* Else the nearest name within a third of its length (at least one edit): "stres", "Stress",
     * "sterss" -> "stress", but nothing for a word that is merely short, nor for a name of one or
     * two letters (any other letter is one edit from "x"). */
    const char *best = NULL;
    size_t best_d = (size_t)-1;
    for (int i = 0; names[i]; i++) {
        if (strlen(names[i]) < 3)
            continue;
        size_t d = edit_distance(s, names[i]), limit = strlen(names[i]) / 3;
        if (d <= (limit > 1 ? limit : 1) && d < best_d) {
            best = names[i];
            best_d = d;
        }
    }
    return best;
}

int bind_check_option(lua_State *L, int arg, const char *def, const char *const names[])
{
    const char *s = def ? luaL_optstring(L, arg, def) : NULL;
    if (!def && lua_type(L, arg) == LUA_TSTRING)
        s = lua_tostring(L, arg);
    if (s)
        for (int i = 0; names[i]; i++)
            if (strcmp(s, names[i]) == 0)
                return i;
    char got[64]; /* before the buffer goes on the stack */
    if (s)
        bind_describe(L, arg, got, sizeof got);
    else
        snprintf(got, sizeof got, "%s", lua_isnone(L, arg) ? "no value" : luaL_typename(L, arg));
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    if (s) {
        luaL_addstring(&b, "invalid option ");
        luaL_addstring(&b, got);
        const char *near = bind_closest_name(s, names);
        if (near) {
            luaL_addstring(&b, "; did you mean '");
            luaL_addstring(&b, near);
            luaL_addstring(&b, "'?");
        }
        luaL_addchar(&b, near ? ' ' : ';');
        luaL_addstring(&b, near ? "Valid options: " : " valid options: ");
    } else {
        luaL_addstring(&b, "one of ");
    }
    for (int i = 0; names[i]; i++) {
        luaL_addstring(&b, i ? ", '" : "'");
        luaL_addstring(&b, names[i]);
        luaL_addchar(&b, '\'');
    }
    if (!s) {
        luaL_addstring(&b, " expected, got ");
        luaL_addstring(&b, got);
    }
    luaL_pushresult(&b);
    return luaL_argerror(L, arg, lua_tostring(L, -1));
}
