/* The chunked run loop the method bindings share: `every`, `on_step` (returning false stops the
 * run), progress reporting, and kernel errors raised named after the call. */
#include "core/progress.h"
#include "lua/bind.h"

int bind_run_chunks(lua_State *L, int scene, int arg, const char *call, const bind_run *r)
{
    long every = (long)bind_field_integer(L, arg, call, "every", 0, 1, LUA_MAXINTEGER, 0);
    int has_cb = lua_getfield(L, arg, "on_step") != LUA_TNIL;
    /* a callable object (grainlab.recorder) is as good as a function */
    if (has_cb && lua_type(L, -1) != LUA_TFUNCTION) {
        if (luaL_getmetafield(L, -1, "__call") == LUA_TNIL)
            return bind_field_error(L, arg, call, "on_step", "function");
        lua_pop(L, 1);
    }
    int cb = lua_gettop(L);
    if (has_cb && every == 0)
        every = r->expect > 100 ? r->expect / 100 : 1;
    if (every == 0)
        every = r->steps > 0 ? r->steps : 1;
    int want = bind_field_boolean(L, arg, call, "progress", -1);
    progress prog;
    prog.active = 0;
    if (want == 1 ||
        (want == -1 && r->expect >= 1000 && progress_default_style() != PROGRESS_QUIET)) {
        progress_begin(&prog, r->label, (double)r->expect, "steps");
        if (want == -1 && prog.style != PROGRESS_BAR)
            prog.active = 0; /* unasked, lines would flood logs: only a bar on a terminal */
    }
    long done = 0;
    int stopped = 0, finished = 0;
    core_error err;
    while (done < r->steps && !stopped && !finished) {
        long n = r->steps - done < every ? r->steps - done : every, chunk = 0;
        core_status st = r->advance(r->ctx, n, &chunk, &err);
        done += chunk;
        if (prog.active)
            progress_update(&prog, (double)done);
        if (st != CORE_OK) {
            if (prog.active)
                progress_end(&prog);
            return bind_raise(L, call, &err);
        }
        finished = chunk < n; /* the kernel reached its end (e.g. an end time) */
        if (has_cb && chunk > 0) {
            lua_pushvalue(L, cb);
            lua_pushvalue(L, scene);
            if (lua_pcall(L, 1, 1, 0) != LUA_OK) {
                if (prog.active)
                    progress_end(&prog);
                return lua_error(L);
            }
            stopped = lua_type(L, -1) == LUA_TBOOLEAN && !lua_toboolean(L, -1);
            lua_pop(L, 1);
        }
    }
    if (prog.active)
        progress_end(&prog);
    lua_settop(L, cb - 1);
    return stopped;
}

void bind_push_array(lua_State *L, const double *a, size_t n, const char *name)
{
    lua_createtable(L, (int)n, 0);
    for (size_t i = 0; i < n; i++) {
        lua_pushnumber(L, a[i]);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, name);
}
