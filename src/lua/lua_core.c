/* grainlab.* functions backed by core/: version, clocks, threads, random streams, progress
 * reporters and whole-file writes. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/clock.h"
#include "core/fileio.h"
#include "core/progress.h"
#include "core/rng.h"
#include "core/threads.h"
#include "lua/bind.h"

static double t_start; /* set when the state opens: grainlab.elapsed() counts from there */

/* ---- clocks and threads ------------------------------------------------------------------ */
static int l_clock(lua_State *L)
{
    lua_pushnumber(L, clock_wall());
    return 1;
}

static int l_cpu_clock(lua_State *L)
{
    lua_pushnumber(L, clock_cpu());
    return 1;
}

static int l_elapsed(lua_State *L)
{
    lua_pushnumber(L, clock_wall() - t_start);
    return 1;
}

static int l_threads(lua_State *L)
{
    if (lua_type(L, 1) == LUA_TSTRING && strcmp(lua_tostring(L, 1), "auto") == 0) {
        threads_set_auto();
    } else if (!lua_isnoneornil(L, 1)) {
        int isint;
        lua_Integer n = lua_tointegerx(L, 1, &isint);
        if (!isint || n < 1 || n > 4096) {
            char got[64];
            bind_describe(L, 1, got, sizeof got);
            return luaL_error(L,
                              "bad argument #1 to 'threads' (integer in [1, 4096] or \"auto\" "
                              "expected, got %s)",
                              got);
        }
        threads_set((int)n);
    }
    lua_pushinteger(L, threads_get());
    lua_pushstring(L, threads_auto() ? "auto" : "fixed");
    threads_tune_stats st;
    threads_tune_get_stats(&st);
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, st.probes);
    lua_setfield(L, -2, "probes");
    lua_pushinteger(L, st.switches);
    lua_setfield(L, -2, "switches");
    lua_pushinteger(L, st.steps_one);
    lua_setfield(L, -2, "steps_one_thread");
    lua_pushinteger(L, st.steps_all);
    lua_setfield(L, -2, "steps_all_threads");
    return 3;
}

/* ---- random streams ---------------------------------------------------------------------- */
static const char *RNG = "grainlab.rng";

static const char *const RNG_FIELDS[] = {"seed", "stream", NULL};

static int l_rng_new(lua_State *L)
{
    lua_settop(L, 1);
    if (lua_isnil(L, 1)) { /* grainlab.rng() and grainlab.rng(nil): all defaults */
        lua_newtable(L);
        lua_replace(L, 1);
    }
    bind_check_table(L, 1, "rng");
    bind_check_fields(L, 1, "rng", RNG_FIELDS);
    lua_Integer seed = bind_field_integer(L, 1, "rng", "seed", 0, 0, LUA_MAXINTEGER, 0);
    lua_Integer stream = bind_field_integer(L, 1, "rng", "stream", 0, 0, 1 << 20, 0);
    rng *r = lua_newuserdatauv(L, sizeof *r, 0);
    rng_seed(r, (uint64_t)seed, (uint64_t)stream);
    luaL_setmetatable(L, RNG);
    return 1;
}

static int l_rng_uniform(lua_State *L)
{
    rng *r = luaL_checkudata(L, 1, RNG);
    double a = lua_isnoneornil(L, 2) ? 0.0 : bind_arg_number(L, 2, "uniform", 0);
    double b = lua_isnoneornil(L, 3) ? 1.0 : bind_arg_number(L, 3, "uniform", 0);
    luaL_argcheck(L, b >= a, 3, "upper bound below lower bound");
    lua_pushnumber(L, a + (b - a) * rng_uniform(r));
    return 1;
}

static int l_rng_normal(lua_State *L)
{
    rng *r = luaL_checkudata(L, 1, RNG);
    double mean = lua_isnoneornil(L, 2) ? 0.0 : bind_arg_number(L, 2, "normal", 0);
    double sd = lua_isnoneornil(L, 3) ? 1.0 : bind_arg_number(L, 3, "normal", BIND_NONNEG);
    lua_pushnumber(L, mean + sd * rng_normal(r));
    return 1;
}

static int l_rng_integer(lua_State *L)
{
    rng *r = luaL_checkudata(L, 1, RNG);
    lua_Integer lo = bind_arg_integer(L, 2, "integer", LUA_MININTEGER, LUA_MAXINTEGER);
    lua_Integer hi = bind_arg_integer(L, 3, "integer", lo, LUA_MAXINTEGER);
    uint64_t span = (uint64_t)hi - (uint64_t)lo + 1; /* 0 means the full 2^64 range */
    uint64_t u = span ? rng_below(r, span) : rng_next(r);
    lua_pushinteger(L, (lua_Integer)((uint64_t)lo + u));
    return 1;
}

static int l_rng_raw(lua_State *L)
{
    rng *r = luaL_checkudata(L, 1, RNG);
    lua_pushinteger(L, (lua_Integer)rng_next(r));
    return 1;
}

static int l_rng_tostring(lua_State *L)
{
    rng *r = luaL_checkudata(L, 1, RNG);
    lua_pushfstring(L, "grainlab.rng (state %p)", (void *)r);
    return 1;
}

/* ---- progress reporters ------------------------------------------------------------------ */
static const char *PROGRESS = "grainlab.progress";

static const char *const PROGRESS_FIELDS[] = {"label", "total", "unit", NULL};

static int l_progress_new(lua_State *L)
{
    bind_check_table(L, 1, "progress");
    bind_check_fields(L, 1, "progress", PROGRESS_FIELDS);
    const char *label = bind_field_string(L, 1, "progress", "label", "run", 0);
    double total = bind_field_number(L, 1, "progress", "total", 0, BIND_NONNEG);
    const char *unit = bind_field_string(L, 1, "progress", "unit", "steps", 0);
    progress *p = lua_newuserdatauv(L, sizeof *p, 0);
    p->active = 0;
    luaL_setmetatable(L, PROGRESS);
    progress_begin(p, label, total, unit);
    return 1;
}

/* The amount done at arg: a finite number >= 0 (NaN would print as "nan%" and stop the 10%
 * marks for good). */
static double check_done(lua_State *L, int arg, const char *call)
{
    double done = luaL_checknumber(L, arg);
    if (!(done >= 0) || !(done <= 1e100)) { /* NaN, inf and the bindings' magnitude cap */
        char got[64];
        bind_describe(L, arg, got, sizeof got);
        luaL_error(L, "bad argument #1 to '%s' (finite non-negative number expected, got %s)", call,
                   got);
    }
    return done;
}

static int l_progress_update(lua_State *L)
{
    progress *p = luaL_checkudata(L, 1, PROGRESS);
    double done = check_done(L, 2, "update");
    luaL_argcheck(L, p->active, 1, "progress reporter already finished");
    progress_update(p, done);
    return 0;
}

static int l_progress_gc(lua_State *L)
{
    progress *p = luaL_checkudata(L, 1, PROGRESS);
    p->active = 0; /* an abandoned reporter prints nothing when collected */
    return 0;
}

static int l_progress_finish(lua_State *L)
{
    progress *p = luaL_checkudata(L, 1, PROGRESS);
    if (!lua_isnoneornil(L, 2) && p->active)
        p->done = check_done(L, 2, "finish");
    progress_end(p);
    return 0;
}

/* ---- files ------------------------------------------------------------------------------- */
static int l_write_file(lua_State *L)
{
    /* strings only: a number would silently become a file name or the file's text */
    const char *path = bind_arg_path(L, 1, "write_file");
    if (lua_type(L, 2) != LUA_TSTRING)
        bind_arg_error(L, 2, "write_file", "string");
    size_t len;
    const char *data = lua_tolstring(L, 2, &len);
    core_error err;
    if (atomic_write(path, data, len, &err) != CORE_OK) {
        luaL_pushfail(L);
        lua_pushstring(L, err.msg);
        return 2;
    }
    lua_pushboolean(L, 1);
    return 1;
}

void bind_open_core(lua_State *L, int idx)
{
    static const bind_fn fns[] = {
        {"clock", l_clock, "grainlab.clock()",
         "Seconds on a monotonic wall clock; only differences mean anything."},
        {"cpu_clock", l_cpu_clock, "grainlab.cpu_clock()",
         "CPU seconds used by the process so far, all threads together."},
        {"elapsed", l_elapsed, "grainlab.elapsed()",
         "Wall-clock seconds since grainlab started (the report's wall_s)."},
        {"threads", l_threads, "grainlab.threads([n | \"auto\"])",
         "Returns the number of worker threads the kernels use, the mode (\"auto\" or "
         "\"fixed\") and the tuner's counts {probes, switches, steps_one_thread, "
         "steps_all_threads}. With n, fixes the count first (same as --threads N); with "
         "\"auto\" (the default unless OMP_NUM_THREADS is set), all processors, and a run "
         "whose step gives the same bits on any count (DEM, DSMC, MPM with frictional "
         "contact) times its steps and runs on one thread while another process makes that "
         "faster (a busy core shared with a waiting thread)."},
        {"rng", l_rng_new, "grainlab.rng{ seed = 0, stream = 0 }",
         "A random stream (xoshiro256**, seeded through splitmix64) that gives the same numbers on "
         "every platform. Streams with the same seed and different `stream` numbers are "
         "independent (2^128 draws apart). Methods: uniform([a, b]), normal([mean, sd]), "
         "integer(lo, hi), raw()."},
        {"progress", l_progress_new, "grainlab.progress{ label = 'run', total = N, unit = 'steps' }",
         "A progress reporter on stderr: a bar with rate and ETA on a terminal, a line at every "
         "10% otherwise, nothing with --quiet. Methods: update(done), finish([done])."},
        {"write_file", l_write_file, "grainlab.write_file(path, data)",
         "Writes the string data to path whole (temporary file, then rename): a failure never "
         "leaves half a file. Returns true, or nil and a message."},
        {NULL, NULL, NULL, NULL}};
    static const bind_fn rng_methods[] = {
        {"uniform", l_rng_uniform, "r:uniform([a = 0, b = 1])", "A uniform number in [a, b)."},
        {"normal", l_rng_normal, "r:normal([mean = 0, sd = 1])", "A normal deviate."},
        {"integer", l_rng_integer, "r:integer(lo, hi)", "A uniform integer in [lo, hi], unbiased."},
        {"raw", l_rng_raw, "r:raw()",
         "The next 64-bit output of the generator as a Lua integer (two's complement)."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg rng_meta[] = {{"__tostring", l_rng_tostring}, {NULL, NULL}};
    static const bind_fn progress_methods[] = {
        {"update", l_progress_update, "p:update(done)", "Reports `done` units of work so far."},
        {"finish", l_progress_finish, "p:finish([done])", "Prints the closing line."},
        {NULL, NULL, NULL, NULL}};
    static const luaL_Reg progress_meta[] = {
        {"__close", l_progress_finish}, {"__gc", l_progress_gc}, {NULL, NULL}};

    t_start = clock_wall();
    bind_new_type(L, RNG, rng_methods, rng_meta, "A random stream from grainlab.rng{...}.");
    bind_new_type(L, PROGRESS, progress_methods, progress_meta,
                  "A progress reporter from grainlab.progress{...}.");
    bind_register(L, idx, fns);
    static const bind_fields fields[] = {
        {"rng", NULL, RNG_FIELDS}, {"progress", NULL, PROGRESS_FIELDS}, {NULL, NULL, NULL}};
    bind_register_fields(L, idx, fields);
    lua_pushliteral(L, GRAINLAB_VERSION);
    lua_setfield(L, idx, "version");
    lua_pushliteral(L, GRAINLAB_DEPS);
    lua_setfield(L, idx, "libraries");
}
