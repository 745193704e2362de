/* The chunked run loop the method bindings share: `every`, `on_step` (returning false stops the
 * run), progress reporting, the scenes being run (so that a call from on_step cannot pull the
 * state from under its own run), and kernel errors raised named after the call. */
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "core/interrupt.h"
#include "core/progress.h"
#include "lua/bind.h"

/* registry[RUNNING][scene userdata] = light pointer to the bind_run of its run in progress. */
static const char *RUNNING = "grainlab.running";
static const char *GUARD = "grainlab.run_guard";
static int depth; /* runs in progress, nested ones included (one Lua state per process) */

static void push_running_table(lua_State *L)
{
    if (lua_getfield(L, LUA_REGISTRYINDEX, RUNNING) == LUA_TTABLE)
        return;
    lua_pop(L, 1);
    lua_newtable(L);
    lua_createtable(L, 0, 1);
    lua_pushliteral(L, "k"); /* a scene is never kept alive by being listed */
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
    lua_pushvalue(L, -1);
    lua_setfield(L, LUA_REGISTRYINDEX, RUNNING);
}

int bind_run_depth(void) { return depth; }

const bind_run *bind_running(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    push_running_table(L);
    lua_pushvalue(L, idx);
    const bind_run *r = lua_rawget(L, -2) == LUA_TLIGHTUSERDATA ? lua_touserdata(L, -1) : NULL;
    lua_pop(L, 2);
    return r;
}

void bind_refuse_running(lua_State *L, int idx, const char *call, const char *why)
{
    if (!bind_running(L, idx))
        return;
    const char *type = "scene";
    if (luaL_getmetafield(L, idx, "__name") == LUA_TSTRING)
        type = lua_tostring(L, -1); /* stays on the stack until the error */
    luaL_error(L, "%s: this %s is %srunning (called from its on_step); %s", call, type,
               strcmp(call, "run") == 0 ? "already " : "", why);
}

/* The scene is no longer running. Done in C by the run loop itself before it raises or returns:
 * the guard's __close, a Lua call, may never run its body when a Ctrl-C or SIGTERM hook raises
 * at the call; it only covers errors the loop does not see (out of memory). */
static void disarm(lua_State *L, int guard)
{
    int *armed = luaL_checkudata(L, guard, GUARD);
    if (*armed) {
        *armed = 0;
        depth--;
        push_running_table(L);
        lua_getiuservalue(L, guard, 1);
        lua_pushnil(L);
        lua_rawset(L, -3);
        lua_pop(L, 1);
    }
}

static int guard_close(lua_State *L)
{
    disarm(L, 1);
    return 0;
}

/* Marks the scene at idx as running r until disarm(), or until the value pushed here (its index
 * is returned) goes out of scope. */
static int push_guard(lua_State *L, int idx, const bind_run *r)
{
    idx = lua_absindex(L, idx);
    int *armed = lua_newuserdatauv(L, sizeof *armed, 1);
    *armed = 0;
    if (luaL_newmetatable(L, GUARD)) {
        lua_pushcfunction(L, guard_close);
        lua_setfield(L, -2, "__close");
        lua_pushcfunction(L, guard_close);
        lua_setfield(L, -2, "__gc");
    }
    lua_setmetatable(L, -2);
    lua_pushvalue(L, idx);
    lua_setiuservalue(L, -2, 1);
    push_running_table(L);
    lua_pushvalue(L, idx);
    lua_pushlightuserdata(L, (void *)r);
    lua_rawset(L, -3);
    lua_pop(L, 1);
    *armed = 1;
    depth++;
    lua_toclose(L, -1);
    return lua_gettop(L);
}

/* Closes the reporter for a run ending early and raises the error on top of the stack (or err). */
static int fail(lua_State *L, int guard, progress *prog, const bind_run *r, const char *call,
                long done, const core_error *err)
{
    disarm(L, guard);
    /* this rank's own flag: an error path may be taken by some ranks only (the kernels' stop on
     * the flag is agreed by all ranks: CORE_ERR_INTERRUPTED) */
    int interrupted = (err && err->status == CORE_ERR_INTERRUPTED) || interrupt_pending_here();
    progress_end_early(prog, interrupted ? "interrupted" : "failed");
    char of[64] = "";
    if (r->expect > 0)
        snprintf(of, sizeof of, " of %s%ld", r->steps == r->expect ? "" : "about ", r->expect);
    if (interrupted) {
        /* The run says where it stopped; the CLI's Ctrl-C hook (raising "interrupted" in the next
         * Lua call, here the guard's __close) would replace that message. A termination's hook
         * stays: nothing may catch it. */
        if (!interrupt_terminating())
            lua_sethook(L, NULL, 0, 0);
        char where[160];
        snprintf(where, sizeof where, "step %ld%s of '%s'", done, of, r->label);
        interrupt_note(where);
        /* The interrupt is handled: it becomes the error raised below. The outermost run lowers
         * the flag (a run nested in on_step leaves it to the run around it), so that a script
         * catching the error runs its next run to the end, and a later Ctrl-C interrupts again
         * instead of counting as the second one. A termination stays (interrupt_clear). */
        if (depth == 0)
            interrupt_clear();
    }
    if (!err) { /* from on_step; a Ctrl-C there says where the run stood */
        if (interrupted && lua_type(L, -1) == LUA_TSTRING) {
            char msg[160];
            snprintf(
                msg, sizeof msg,
                " (in on_step: the run stopped at step %ld%s of this run; the scene is intact)",
                done, of);
            lua_pushstring(L, msg);
            lua_concat(L, 2);
        }
        return lua_error(L);
    }
    if (err->status == CORE_ERR_INTERRUPTED) {
        /* the kernels say "interrupted at step S (t = T s); ...": keep the time */
        char t[64] = "";
        const char *p = strstr(err->msg, "(t = ");
        if (p)
            snprintf(t, sizeof t, " %.*s", (int)strcspn(p, ")") + 1, p);
        int sig = interrupt_terminating();
        char msg[320]; /* lua_pushfstring knows no %ld */
        snprintf(msg, sizeof msg, "%s: %s at step %ld%s of this run%s; the scene is intact", call,
                 sig == SIGTERM ? "terminated (SIGTERM)"
                 : sig          ? "terminated"
                                : "interrupted",
                 done, of, t);
        return luaL_error(L, "%s", msg);
    }
    return bind_raise(L, call, err);
}

int bind_run_chunks(lua_State *L, int scene, int arg, const char *call, const bind_run *r)
{
    scene = lua_absindex(L, scene);
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
    bind_refuse_running(L, scene, call, "return false from on_step to stop it");
    int guard = push_guard(L, scene, r);

    /* Unasked, a run shows progress once it has taken a few seconds (so short runs stay silent),
     * and only the outermost run of nested ones (they would share one line). */
    progress prog;
    memset(&prog, 0, sizeof prog);
    if (want == 1 || (want == -1 && depth == 1 && progress_default_style() != PROGRESS_QUIET)) {
        progress_begin(&prog, r->label, (double)r->expect, "steps");
        if (want == -1)
            prog.delay = progress_unasked_delay();
    }
    /* A kernel without its own progress hook advances in pieces of 1/200 of the run, so the
     * reporter sees it move; the pieces depend only on the run's length, never on timing. */
    long piece =
        prog.active && !r->kernel_progress && r->expect >= 200 ? r->expect / 200 : LONG_MAX;
    long done = 0;
    int stopped = 0, finished = 0;
    core_error err;
    while (done < r->steps && !stopped && !finished) {
        long n = r->steps - done < every ? r->steps - done : every, got = 0;
        core_status st = CORE_OK;
        while (got < n) {
            long m = n - got < piece ? n - got : piece, k = 0;
            prog.base = (double)(done + got);
            st = r->advance(r->ctx, m, &prog, &k, &err);
            got += k;
            progress_update(&prog, (double)k);
            if (st != CORE_OK || k < m)
                break;
        }
        done += got;
        if (st != CORE_OK)
            return fail(L, guard, &prog, r, call, done, &err);
        finished = got < n; /* the kernel reached its end (e.g. an end time) */
        if (has_cb && got > 0) {
            lua_pushvalue(L, cb);
            lua_pushvalue(L, scene);
            if (lua_pcall(L, 1, 1, 0) != LUA_OK)
                return fail(L, guard, &prog, r, call, done, NULL);
            stopped = lua_type(L, -1) == LUA_TBOOLEAN && !lua_toboolean(L, -1);
            lua_pop(L, 1);
        }
    }
    if (stopped)
        progress_end_early(&prog, "stopped (on_step returned false)");
    else
        progress_end(&prog);
    disarm(L, guard);
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
