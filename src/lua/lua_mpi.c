/* grainlab.mpi: the SPMD script's view of a distributed run (rank, size, barrier, bcast, traffic
 * counters), and, on ranks other than 0, the Lua file functions that write turned into no-ops so
 * that every file a script writes is written once, by rank 0 (reads work on every rank). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/comm.h"
#include "lua/bind.h"

static int l_rank(lua_State *L)
{
    lua_pushinteger(L, comm_rank());
    return 1;
}

static int l_size(lua_State *L)
{
    lua_pushinteger(L, comm_size());
    return 1;
}

static int l_barrier(lua_State *L)
{
    (void)L;
    comm_barrier();
    return 0;
}

static int l_stats(lua_State *L)
{
    comm_stats st;
    comm_get_stats(&st);
    lua_createtable(L, 0, 4);
    lua_pushnumber(L, st.bytes);
    lua_setfield(L, -2, "bytes");
    lua_pushnumber(L, st.messages);
    lua_setfield(L, -2, "messages");
    lua_pushnumber(L, st.seconds);
    lua_setfield(L, -2, "seconds");
    lua_pushinteger(L, st.calls);
    lua_setfield(L, -2, "calls");
    return 1;
}

static int l_reset_stats(lua_State *L)
{
    (void)L;
    comm_reset_stats();
    return 0;
}

/* ---- bcast: a Lua value serialised on the root, rebuilt on every other rank ------------------
 * Tags: n nil, f false, t true, i integer, d float, s string (length then bytes), T table (pairs
 * then e). The root measures first (every error is raised there, before anything is sent),
 * then fills a buffer the GC owns, so an error in between leaks nothing. */
enum { BCAST_DEPTH = 100 };

/* Bytes the value at idx needs, or -1 with a message in why. */
static int64_t measure(lua_State *L, int idx, int depth, const char **why)
{
    switch (lua_type(L, idx)) {
    case LUA_TNIL:
    case LUA_TBOOLEAN: return 1;
    case LUA_TNUMBER: return 9;
    case LUA_TSTRING: return 9 + (int64_t)lua_rawlen(L, idx);
    case LUA_TTABLE: {
        if (depth >= BCAST_DEPTH) {
            *why = "tables nested deeper than 100 levels (or a cycle)";
            return -1;
        }
        luaL_checkstack(L, 3, "bcast");
        int64_t n = 2;
        idx = lua_absindex(L, idx);
        lua_pushnil(L);
        while (lua_next(L, idx)) {
            int64_t k = measure(L, -2, depth + 1, why),
                    v = k < 0 ? -1 : measure(L, -1, depth + 1, why);
            if (k < 0 || v < 0) {
                lua_pop(L, 2);
                return -1;
            }
            n += k + v;
            lua_pop(L, 1);
        }
        return n;
    }
    default:
        *why = lua_type(L, idx) == LUA_TFUNCTION ? "a function cannot be sent"
               : lua_type(L, idx) == LUA_TUSERDATA || lua_type(L, idx) == LUA_TLIGHTUSERDATA
                   ? "a userdata (a scene, a file) cannot be sent"
                   : "a thread cannot be sent";
        return -1;
    }
}

static unsigned char *put(unsigned char *p, const void *v, size_t n)
{
    memcpy(p, v, n);
    return p + n;
}

static unsigned char *encode(lua_State *L, int idx, unsigned char *p)
{
    switch (lua_type(L, idx)) {
    case LUA_TNIL: *p++ = 'n'; return p;
    case LUA_TBOOLEAN: *p++ = lua_toboolean(L, idx) ? 't' : 'f'; return p;
    case LUA_TNUMBER:
        if (lua_isinteger(L, idx)) {
            int64_t i = (int64_t)lua_tointeger(L, idx);
            *p++ = 'i';
            return put(p, &i, 8);
        } else {
            double d = (double)lua_tonumber(L, idx);
            *p++ = 'd';
            return put(p, &d, 8);
        }
    case LUA_TSTRING: {
        size_t len;
        const char *s = lua_tolstring(L, idx, &len);
        uint64_t n = len;
        *p++ = 's';
        p = put(p, &n, 8);
        return put(p, s, len);
    }
    default: { /* a table: measure() let nothing else through */
        idx = lua_absindex(L, idx);
        *p++ = 'T';
        lua_pushnil(L);
        while (lua_next(L, idx)) {
            p = encode(L, -2, p);
            p = encode(L, -1, p);
            lua_pop(L, 1);
        }
        *p++ = 'e';
        return p;
    }
    }
}

/* Pushes the value at *p (the data came from encode on the root: trusted). */
static const unsigned char *decode(lua_State *L, const unsigned char *p)
{
    luaL_checkstack(L, 3, "bcast");
    switch (*p++) {
    case 'n': lua_pushnil(L); return p;
    case 't':
    case 'f': lua_pushboolean(L, p[-1] == 't'); return p;
    case 'i': {
        int64_t i;
        memcpy(&i, p, 8);
        lua_pushinteger(L, (lua_Integer)i);
        return p + 8;
    }
    case 'd': {
        double d;
        memcpy(&d, p, 8);
        lua_pushnumber(L, d);
        return p + 8;
    }
    case 's': {
        uint64_t n;
        memcpy(&n, p, 8);
        lua_pushlstring(L, (const char *)p + 8, (size_t)n);
        return p + 8 + n;
    }
    default: /* 'T' */
        lua_newtable(L);
        while (*p != 'e') {
            p = decode(L, p);
            p = decode(L, p);
            lua_rawset(L, -3);
        }
        return p + 1;
    }
}

static int l_bcast(lua_State *L)
{
    lua_settop(L, 2);
    int root = (int)(lua_isnil(L, 2) ? 0 : bind_arg_integer(L, 2, "bcast", 0, comm_size() - 1));
    /* The size goes first; a negative size means the root refused its value, and its message
     * follows, so that every rank raises the same error instead of waiting for data. */
    int64_t n = 0;
    const char *why = NULL;
    unsigned char *buf = NULL;
    if (comm_rank() == root) {
        n = measure(L, 1, 0, &why);
        if (n >= 0) {
            buf = lua_newuserdatauv(L, (size_t)n, 0);
            encode(L, 1, buf);
        } else {
            char got[64];
            bind_describe(L, 1, got, sizeof got);
            lua_pushfstring(L,
                            "bad argument #1 to 'bcast' (nil, boolean, number, string or table "
                            "of them expected, got %s: %s)",
                            got, why);
            n = -(int64_t)lua_rawlen(L, -1);
            buf = (unsigned char *)lua_tostring(L, -1);
        }
    }
    comm_bcast(&n, sizeof n, root);
    size_t bytes = (size_t)(n < 0 ? -n : n);
    if (comm_rank() != root)
        buf = lua_newuserdatauv(L, bytes ? bytes : 1, 0);
    comm_bcast(buf, bytes, root);
    if (n < 0) {
        lua_pushlstring(L, (const char *)buf, bytes);
        return lua_error(L);
    }
    decode(L, buf);
    return 1;
}

/* ---- files on ranks > 0 ------------------------------------------------------------------- */

/* Whether io.open(path, mode) would succeed on rank 0, found without creating, truncating or
 * changing anything: errors stay the same on every rank (a missing directory, a read-only
 * file), while only rank 0 writes. Returns 0 or an errno. */
static int could_open(const char *path, const char *mode)
{
    int fd = open(path, mode[0] == 'r' ? O_RDWR : O_WRONLY);
    if (fd >= 0) {
        close(fd);
        return 0;
    }
    if (errno != ENOENT || mode[0] == 'r')
        return errno;
    char tmp[4096 + 32];
    if (strlen(path) >= 4096)
        return ENAMETOOLONG;
    snprintf(tmp, sizeof tmp, "%s.tmp.XXXXXX", path);
    fd = mkstemp(tmp); /* the directory takes a new file (removed at once) */
    if (fd < 0)
        return errno;
    close(fd);
    unlink(tmp);
    return 0;
}

/* lua's l_checkmode (liolib.c) */
static int valid_mode(const char *mode)
{
    return *mode != '\0' && strchr("rwa", *(mode++)) != NULL &&
           (*mode != '+' || ((void)(++mode), 1)) && strspn(mode, "b") == strlen(mode);
}

static int writes(const char *mode) { return mode[0] != 'r' || strchr(mode, '+') != NULL; }

/* io.open on ranks > 0: reads as usual; a file opened for writing is the null device (after the
 * same checks rank 0's open makes), so writes go nowhere and reads from it give nothing. */
static int l_open_quiet(lua_State *L)
{
    const char *path = luaL_checkstring(L, 1);
    const char *mode = luaL_optstring(L, 2, "r");
    luaL_argcheck(L, valid_mode(mode), 2, "invalid mode");
    if (!writes(mode)) {
        lua_pushvalue(L, lua_upvalueindex(1));
        lua_insert(L, 1);
        lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
        return lua_gettop(L);
    }
    int e = could_open(path, mode);
    if (e) {
        luaL_pushfail(L);
        lua_pushfstring(L, "%s: %s", path, strerror(e));
        lua_pushinteger(L, e);
        return 3;
    }
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_pushliteral(L, "/dev/null");
    lua_pushstring(L, mode);
    lua_call(L, 2, LUA_MULTRET);
    return lua_gettop(L) - 2;
}

/* io.output(name) on ranks > 0: the same checks, then the null device. */
static int l_output_quiet(lua_State *L)
{
    if (lua_type(L, 1) == LUA_TSTRING) {
        const char *path = lua_tostring(L, 1);
        int e = could_open(path, "w");
        if (e)
            return luaL_error(L, "cannot open file '%s' (%s)", path, strerror(e));
        lua_settop(L, 0);
        lua_pushliteral(L, "/dev/null");
    }
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
    return lua_gettop(L);
}

/* os.remove and os.rename on ranks > 0: rank 0 does it (they would race it on a shared
 * filesystem, and fail where rank 0 succeeded). */
static int l_file_op_quiet(lua_State *L)
{
    luaL_checkstring(L, 1);
    lua_pushboolean(L, 1);
    return 1;
}

static void wrap(lua_State *L, const char *lib, const char *name, lua_CFunction fn)
{
    if (lua_getglobal(L, lib) != LUA_TTABLE) {
        lua_pop(L, 1);
        return;
    }
    lua_getfield(L, -1, name);
    lua_pushcclosure(L, fn, 1);
    lua_setfield(L, -2, name);
    lua_pop(L, 1);
}

void bind_open_mpi(lua_State *L, int idx)
{
    static const bind_fn fns[] = {
        {"rank", l_rank, "grainlab.mpi.rank()",
         "This process's rank, 0 to size() - 1 (0 in a run without mpirun)."},
        {"size", l_size, "grainlab.mpi.size()",
         "The number of ranks the script runs on (1 without mpirun)."},
        {"barrier", l_barrier, "grainlab.mpi.barrier()",
         "Waits until every rank has called it (collective). For example after rank 0 wrote a "
         "file that every rank then reads."},
        {"bcast", l_bcast, "grainlab.mpi.bcast(value[, root = 0])",
         "Returns root's value on every rank (collective): nil, a boolean, number or string, or "
         "a table of them (nested; no functions or userdata). For a choice only one rank may make "
         "(a clock, a file read once): every rank then goes the same way."},
        {"stats", l_stats, "grainlab.mpi.stats()",
         "This rank's traffic since the start or reset_stats(): { bytes, messages, seconds, calls "
         "} of the engines' communication (all zero on one rank)."},
        {"reset_stats", l_reset_stats, "grainlab.mpi.reset_stats()",
         "Sets this rank's traffic counters to zero."},
        {NULL, NULL, NULL, NULL}};
    lua_newtable(L);
    bind_register(L, lua_gettop(L), fns);
    lua_pushboolean(L, comm_available());
    lua_setfield(L, -2, "available");
    bind_doc(L, -1, "grainlab.mpi", "grainlab.mpi",
             "Distributed runs (mpirun -np K grainlab script.lua): every rank runs the same "
             "script; rank(), size(), barrier(), bcast(v), stats(). `available`: built with MPI. "
             "Output is written by rank 0 only. See docs/mpi.md.");
    lua_setfield(L, idx, "mpi");

    if (comm_rank() > 0) {
        wrap(L, "io", "open", l_open_quiet);
        wrap(L, "io", "output", l_output_quiet);
        wrap(L, "os", "remove", l_file_op_quiet);
        wrap(L, "os", "rename", l_file_op_quiet);
    }
}
